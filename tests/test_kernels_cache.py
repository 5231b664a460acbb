"""The compiled kernels' disk caches are dropped when any kernel module's source changes
(``host.kernels`` module docstring, "Stale caches"): numba keys a cache by its own file only,
so a caller compiled with a callee of another file would keep the old callee."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from host import kernels

REPO = Path(__file__).resolve().parents[1]

CALLER = """\
import numba
from kpkg.callee import value


@numba.njit(cache=True)
def twice():
    return 2 * value()
"""
CALLEE = """\
import numba


@numba.njit(cache=True)
def value():
    return {}
"""


def _run(root: Path, refresh: bool) -> int:
    """twice() of the package under root in a new process, after refresh_cache when asked."""
    code = textwrap.dedent(f"""\
        import sys
        from pathlib import Path
        sys.path.insert(0, {str(root)!r})
        if {refresh}:
            from host.kernels import refresh_cache
            pkg = Path({str(root)!r}) / "kpkg"
            refresh_cache(pkg / "__pycache__", [pkg / "callee.py", pkg / "caller.py"])
        from kpkg.caller import twice
        print(twice())
        """)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        [str(REPO), *filter(None, [os.environ.get("PYTHONPATH")])]))
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env=env, check=True, timeout=300)
    return int(out.stdout.split()[-1])


@pytest.mark.skipif(not kernels.COMPILED, reason="numba not installed: nothing is cached")
def test_callee_change_reaches_the_cached_caller(tmp_path: Path) -> None:
    pkg = tmp_path / "kpkg"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "caller.py").write_text(CALLER)
    (pkg / "callee.py").write_text(CALLEE.format(1))
    assert _run(tmp_path, refresh=True) == 2           # compiled and cached, stamp written
    (pkg / "callee.py").write_text(CALLEE.format(100))
    # numba alone: the caller's cache (its own file unchanged) still holds the old callee
    assert _run(tmp_path, refresh=False) == 2
    assert _run(tmp_path, refresh=True) == 200         # the stamp differs: caches dropped
    assert _run(tmp_path, refresh=True) == 200         # and cached again, stamp current
    assert not kernels.refresh_cache(pkg / "__pycache__", [pkg / "callee.py",
                                                          pkg / "caller.py"])


def test_sources_hash_follows_every_kernel_module(tmp_path: Path) -> None:
    files = kernels._module_files()
    assert [f.stem for f in files] == [m.rsplit(".", 1)[1] for m in kernels.KERNEL_MODULES]
    assert all(f.exists() for f in files)
    copies = []
    for f in files:
        copies.append(tmp_path / f.name)
        copies[-1].write_bytes(f.read_bytes())
    assert kernels.sources_hash(copies) == kernels.sources_hash(files)
    copies[0].write_bytes(copies[0].read_bytes() + b"\n")
    assert kernels.sources_hash(copies) != kernels.sources_hash(files)


def test_kernels_only_from_listed_modules() -> None:
    def stray() -> int:
        return 1
    with pytest.raises(ValueError, match="KERNEL_MODULES"):
        kernels.njit()(stray)


def test_every_kernel_module_is_listed() -> None:
    kernels._load_kernels()
    assert {k.__module__ if not hasattr(k, "py_func") else k.py_func.__module__
            for k in kernels._KERNELS.values()} == set(kernels.KERNEL_MODULES)


ANGLES = """\
import sys
import numpy as np
from host._angle_peaks import class_peaks
from host._angle_relax import first_components
rng = np.random.default_rng(5)
x = rng.standard_normal((64, 8)) + 1j * rng.standard_normal((64, 8))
ph = np.exp(1j * rng.uniform(0.0, 6.3, (64, 2)))
power, sin = class_peaks(x, np.arange(64), ph, 1024)
xc, a1, p1, maybe, split = first_components(x, ph, sin, np.full(64, 0.1), 12.0, 20.0, -10.0)
np.savez(sys.argv[1], power=power, sin=sin, xc=xc, a1=a1, p1=p1, maybe=maybe, split=split)
"""


@pytest.mark.skipif(not kernels.COMPILED, reason="numba not installed: nothing is cached")
def test_cached_kernels_give_the_compiled_bits(tmp_path: Path) -> None:
    """A process that compiles the angle kernels and one that loads them from the cache give
    the same bits (``host.kernels`` module docstring, "Cached = compiled"): the peak search
    calls ``_fine_search``, whose copy inside its caller's cached code differs in the last
    bit from its own compiled code, which a compiling process runs. A private cache
    (NUMBA_CACHE_DIR), so other processes' caches are not touched."""
    script = tmp_path / "angles.py"
    script.write_text(ANGLES)
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"), PYTHONPATH=os.pathsep.join(
        [str(REPO), *filter(None, [os.environ.get("PYTHONPATH")])]))
    outs = []
    for mode in ("compiled", "cached"):
        outs.append(tmp_path / f"{mode}.npz")
        run = subprocess.run([sys.executable, str(script), str(outs[-1])],
                             env=dict(env, NUMBA_DEBUG_CACHE="1"), check=True, timeout=600,
                             capture_output=True, text=True)
        loads = run.stdout.count("data loaded from")    # numba's cache log: loads from disk
        assert (loads > 0) == (mode == "cached"), f"{mode} run: {loads} kernels from the cache"
    compiled, cached = np.load(outs[0]), np.load(outs[1])
    for name in compiled.files:
        assert compiled[name].tobytes() == cached[name].tobytes(), name


@pytest.mark.skipif(not kernels.COMPILED, reason="numba not installed: nothing is cached")
def test_kernel_symbols_have_the_mangled_prefix() -> None:
    """The prefix :func:`host.kernels._load_callees` finds a callee's copy by is the start of
    the kernel's compiled symbol (numba's mangling), so cached callers still load it."""
    from host._angle_peaks import _interpolated_sin
    _interpolated_sin(3, 1.0, 2.0, 1.0, 16)
    for cres in _interpolated_sin.overloads.values():
        assert cres.fndesc.mangled_name.startswith(kernels._mangled_prefix(_interpolated_sin))
