"""The compiler of the host's kernels (the modules of :data:`KERNEL_MODULES`):
numba when it is installed, else the same Python functions run as they are (the same results,
much slower: a fallback, not a mode callers choose).

:func:`njit` registers every kernel; :func:`uncompiled_kernels` names those without a
compiled cache on disk (their first call compiles them: 20-30 s in all on a fresh checkout;
numba caches them in ``__pycache__``, and the next process loads them in about 0.5 s).
Some kernels run only on some data (RELAX: cells with several targets): a module registers
a :func:`warm_up` that calls them on a tiny input, and :func:`compile_data_dependent` runs
those, so that one run leaves every kernel cached (else the "compiling" note would come
back on every run whose data never reached them).

Stale caches. numba's disk cache of a kernel is keyed by its own source file (its
modification time and size): a kernel that calls a kernel of another file (RELAX and the
split in ``host._angle_relax`` call ``host._angle_peaks``' peak search, compiled into them)
keeps running the callee's old compiled code after only the callee's file changed (an
upgrade, a checkout), silently. So the caches are also keyed by the sources of all kernel
modules: :func:`sources_hash` (SHA-256 of their files, about 0.3 ms) is kept in
:data:`STAMP` beside the caches, and when it differs from the sources' (checked once per
cache directory, when its first kernel is registered, before any is loaded) the cache files
of those modules are deleted there (:func:`refresh_cache`); the next calls compile them
afresh. A module that registers kernels must be named in :data:`KERNEL_MODULES` (:func:`njit`
refuses others).

Cached = compiled. numba links a copy of every kernel a kernel calls into the caller's code
(and its cache file), optimised again with the caller, and the process's JIT linker
resolves a call the caller does not inline to the callee's code loaded first. A compiling
process always has the callee's own code loaded first (typing the caller compiles it); a
process loading the caller from the cache alone ran the copy. With ``fastmath`` the two are
not the same instructions (the peak search's ``_fine_search``: which square of a bin's
re^2 + im^2 a fused multiply-add takes), so the angles and what follows differed in the
last bit between a first run and the next (issue 29: 1,200 of 4,080 arrays). So a
kernel's load from the cache loads first, from the cache, every kernel whose copy its code
holds (:func:`_load_callees`): cached runs give the compiling runs' bits, in any order of
calls (the cached runs' bits changed, the compiling runs' did not;
``tests/test_kernels_cache.py``).
"""

from __future__ import annotations

import hashlib
import importlib
import os
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

try:
    import numba
except ImportError:                      # pragma: no cover - numba is a pinned dependency
    numba = None

COMPILED = numba is not None
"""Whether the kernels are compiled (numba importable)."""

KERNEL_MODULES = ("host._angle_kept", "host._angle_peaks", "host._angle_relax",
                  "host._cfar_os", "host._grouping", "host.cells", "host.cfar", "host.cube",
                  "host.dca1000", "host.pipeline", "host.record_points", "host.tdm")
"""Every module that registers kernels (:func:`njit`): their sources key the caches."""
STAMP = "host-kernels.sha256"
"""The file, in a cache directory, holding the :func:`sources_hash` its caches were made
from."""

_KERNELS: dict[str, Any] = {}
"""The registered kernels by module and name (two modules may use one name)."""
_WARM_UPS: list[Callable[[], None]] = []
_CHECKED: set[str] = set()


def njit(**options: Any) -> Callable[[Callable[..., Any]], Any]:
    """``numba.njit(cache=True, **options)`` when numba is available, else the function
    itself; the kernel is registered for :func:`uncompiled_kernels` under its name, and its
    cache directory's stale caches are dropped first (module docstring). ValueError for a
    module not in :data:`KERNEL_MODULES`."""
    def wrap(fn: Callable[..., Any]) -> Any:
        if fn.__module__ not in KERNEL_MODULES:
            raise ValueError(f"host.kernels: {fn.__module__}.{fn.__name__}: a kernel module "
                             f"must be listed in KERNEL_MODULES")
        kernel = numba.njit(cache=True, **options)(fn) if COMPILED else fn
        if COMPILED:
            _callees_first(kernel)
            path = getattr(getattr(kernel, "_cache", None), "_cache_path", None)
            if isinstance(path, str) and path not in _CHECKED:
                _CHECKED.add(path)
                refresh_cache(Path(path), _module_files())
        _KERNELS[f"{fn.__module__}.{fn.__name__}"] = kernel
        return kernel
    return wrap


def _callees_first(kernel: Any) -> None:
    """Make ``kernel``'s loads from numba's disk cache load the kernels it calls first
    (module docstring, "Cached = compiled"): its cache's rebuild step, which adds the
    cached object code to the process, is wrapped."""
    impl = getattr(getattr(kernel, "_cache", None), "_impl", None)
    rebuild = getattr(impl, "rebuild", None)
    if rebuild is None:
        return

    def rebuild_after_callees(target_context: Any, payload: Any) -> Any:
        _load_callees(kernel, payload[0])
        return rebuild(target_context, payload)
    impl.rebuild = rebuild_after_callees


def _load_callees(kernel: Any, libdata: Any) -> None:
    """Load from the cache every overload of each other kernel whose symbol the cached
    library ``libdata`` (numba's serialised form: name, "object", (object code, bitcode))
    names (the copies linked into it), as a compiling process has them loaded."""
    _, kind, data = libdata
    if kind != "object":
        return
    for other in _KERNELS.values():
        if other is not kernel and _mangled_prefix(other).encode() in data[0]:
            _load_cached(other)


def _mangled_prefix(kernel: Any) -> str:
    """The start of the symbol numba gives ``kernel``'s compiled code (Itanium mangling of
    its module and name, then its ABI tags)."""
    parts = kernel.py_func.__module__.split(".") + kernel.py_func.__qualname__.split(".")
    return "_ZN" + "".join(f"{len(p)}{p}" for p in parts) + "B"


def _load_cached(kernel: Any) -> None:
    """Load every overload of ``kernel`` that numba's disk cache holds for this process
    (its code and CPU); overloads already loaded are kept."""
    cache = kernel._cache
    codegen = kernel.targetctx.codegen()
    for key in cache._cache_file._load_index():
        sig = key[0]
        if key == cache._index_key(sig, codegen):
            kernel.compile(sig)


def _module_files() -> list[Path]:
    """The source files of :data:`KERNEL_MODULES`."""
    here = Path(__file__).resolve().parent
    return [here / f"{name.rsplit('.', 1)[1]}.py" for name in KERNEL_MODULES]


def sources_hash(sources: Sequence[Path]) -> str:
    """SHA-256 (hex) of the files ``sources``, names and contents, in the order given."""
    h = hashlib.sha256()
    for path in sources:
        h.update(path.name.encode() + b"\0" + path.read_bytes() + b"\0")
    return h.hexdigest()


def refresh_cache(cache_dir: Path, sources: Sequence[Path]) -> bool:
    """Drop the numba cache files (``<module>.<function>-<line>.*.nbi`` and ``.nbc``) of the
    modules ``sources`` (their files) in ``cache_dir`` unless its :data:`STAMP` holds the
    :func:`sources_hash` of ``sources``, then write that hash there. Whether caches were
    dropped. A directory that cannot be read or written is left as it is (numba then
    compiles or loads as it would)."""
    digest = sources_hash(sources)
    stamp = cache_dir / STAMP
    try:
        if stamp.exists() and stamp.read_text().strip() == digest:
            return False
        stems = {p.stem for p in sources}
        dropped = False
        if cache_dir.is_dir():
            for f in cache_dir.iterdir():
                if f.suffix in (".nbi", ".nbc") and f.name.split(".", 1)[0] in stems:
                    f.unlink(missing_ok=True)
                    dropped = True
        cache_dir.mkdir(parents=True, exist_ok=True)
        tmp = cache_dir / f"{STAMP}.{os.getpid()}"
        tmp.write_text(digest + "\n")
        os.replace(tmp, stamp)              # atomic: a concurrent reader sees old or new
        return dropped
    except OSError:
        return False


def uncompiled_kernels() -> list[str]:
    """The host's kernels without a compiled cache on
    disk (numba's index file in ``__pycache__``), sorted: their next call compiles them.
    [] when every kernel has one, when numba is absent (nothing compiles), or when numba's
    cache layout is not the expected one (then nothing is known)."""
    if not COMPILED:
        return []
    _load_kernels()
    missing = []
    for key, kernel in _KERNELS.items():
        cache_file = getattr(getattr(kernel, "_cache", None), "_cache_file", None)
        index = getattr(cache_file, "_index_path", None)
        if isinstance(index, str) and not os.path.exists(index):
            missing.append(key.rsplit(".", 1)[1])
    return sorted(missing)


def warm_up(fn: Callable[[], None]) -> Callable[[], None]:
    """Register ``fn``, which calls the module's data-dependent kernels on a tiny input
    (with the argument types of the real calls), for :func:`compile_data_dependent`."""
    _WARM_UPS.append(fn)
    return fn


def compile_data_dependent() -> None:
    """Compile (or load from the cache) the kernels that only some data reaches, now."""
    if not COMPILED:
        return
    _load_kernels()
    for fn in _WARM_UPS:
        fn()


def _load_kernels() -> None:
    """Import every kernel module of the host (so that :func:`uncompiled_kernels` knows all
    of them)."""
    for name in KERNEL_MODULES:
        importlib.import_module(name)
