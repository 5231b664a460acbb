"""Build and run a cocotb testbench on Verilator from pytest (the cocotb Python runner).

Thin wrapper over ``host.rtlsim.toolchain`` (shared with ``radar detect --backend rtl``):
one Verilator model per (toplevel, HDL parameter set) under
``sim_build/<toplevel>/<param-tag>/``, every cocotb test of the module in that one
simulation. HDL parameters reach the cocotb side as ``PARAM_<NAME>`` (read with
:func:`param`). Set ``WAVES=1`` to build with ``--trace`` and dump ``dump.vcd``.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Mapping, Sequence
from pathlib import Path

from host.rtlsim.toolchain import (  # noqa: F401 - re-exported for the testbenches
    REPO,
    RTL,
    SIM_BUILD,
    build_and_test,
    ensure_verilator_env,
    param,
    param_tag,
    rtl_sources,
)


def run_cocotb(
    toplevel: str,
    sources: Sequence[Path],
    test_module: str,
    test_dir: Path,
    parameters: Mapping[str, object] | None = None,
    extra_env: Mapping[str, str] | None = None,
    testcase: str | None = None,
) -> None:
    """Build ``toplevel`` for one parameter set (once) and run ``test_module``'s cocotb tests.

    ``test_dir`` is the folder holding ``test_module`` (added to the simulator's PYTHONPATH).
    Fails the calling pytest test if any cocotb test fails.
    """
    if str(test_dir) not in sys.path:
        sys.path.insert(0, str(test_dir))
    build_and_test(toplevel, sources, test_module, parameters, extra_env, testcase,
                   waves=os.environ.get("WAVES", "0") not in ("", "0"))
