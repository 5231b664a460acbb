"""The compiler of the host's kernels (``host._angle_peaks``, ``host._angle_relax``,
``host._angle_kept``,
``host.cfar``, ``host._cfar_os``, ``host.dca1000``, ``host.pipeline``, ``host.tdm``,
``host.record_points``):
numba when it is installed, else the same Python functions run as they are (the same results,
much slower: a fallback, not a mode callers choose).

:func:`njit` registers every kernel; :func:`uncompiled_kernels` names those without a
compiled cache on disk (their first call compiles them: 20-30 s in all on a fresh checkout;
numba caches them in ``__pycache__``, and the next process loads them in about 0.5 s).
Some kernels run only on some data (RELAX: cells with several targets): a module registers
a :func:`warm_up` that calls them on a tiny input, and :func:`compile_data_dependent` runs
those, so that one run leaves every kernel cached (else the "compiling" note would come
back on every run whose data never reached them).
"""

from __future__ import annotations

import os
from collections.abc import Callable
from typing import Any

try:
    import numba
except ImportError:                      # pragma: no cover - numba is a pinned dependency
    numba = None

COMPILED = numba is not None
"""Whether the kernels are compiled (numba importable)."""

_KERNELS: dict[str, Any] = {}
_WARM_UPS: list[Callable[[], None]] = []


def njit(**options: Any) -> Callable[[Callable[..., Any]], Any]:
    """``numba.njit(cache=True, **options)`` when numba is available, else the function
    itself; the kernel is registered for :func:`uncompiled_kernels` under its name."""
    def wrap(fn: Callable[..., Any]) -> Any:
        kernel = numba.njit(cache=True, **options)(fn) if COMPILED else fn
        _KERNELS[fn.__name__] = kernel
        return kernel
    return wrap


def uncompiled_kernels() -> list[str]:
    """The host's kernels without a compiled cache on
    disk (numba's index file in ``__pycache__``), sorted: their next call compiles them.
    [] when every kernel has one, when numba is absent (nothing compiles), or when numba's
    cache layout is not the expected one (then nothing is known)."""
    if not COMPILED:
        return []
    _load_kernels()
    missing = []
    for name, kernel in sorted(_KERNELS.items()):
        cache_file = getattr(getattr(kernel, "_cache", None), "_cache_file", None)
        index = getattr(cache_file, "_index_path", None)
        if isinstance(index, str) and not os.path.exists(index):
            missing.append(name)
    return missing


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
    import host._angle_kept  # noqa: F401
    import host._angle_relax  # noqa: F401
    import host.cfar  # noqa: F401
    import host.dca1000  # noqa: F401
    import host.pipeline  # noqa: F401
    import host.record_points  # noqa: F401
    import host.tdm  # noqa: F401
