"""The C allocator's settings for the host's frame loops (``radar process``).

Each frame allocates a few arrays of a few MB (the frame, the cube, the map). glibc serves
blocks that large with fresh ``mmap`` pages (above its mmap threshold) or returns them to the
system when the heap's top is freed (its trim threshold), so every frame touches new pages:
about a thousand page faults, some 1 ms a frame of the OpenRadar profile on a loaded 2-core
machine (docs/profiles.md "Compared with OpenRadar"), more than its FFTs. Raising both
thresholds keeps freed blocks in the heap for the next frame. Memory the process frees stays
mapped up to :data:`TRIM_THRESHOLD_BYTES`.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import sys

MMAP_THRESHOLD_BYTES = 64 << 20
"""Blocks below this come from the heap (glibc's default starts at 128 kB)."""
TRIM_THRESHOLD_BYTES = 256 << 20
"""Free memory at the heap's top is returned to the system only beyond this."""
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3
"""glibc's ``mallopt`` parameter numbers (``malloc.h``)."""


def keep_freed_memory() -> bool:
    """Raise glibc's mmap and trim thresholds (module docstring) for this process; whether
    it applied (False where the C library has no ``mallopt``: not glibc)."""
    if not sys.platform.startswith("linux"):
        return False
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
    except OSError:
        return False
    mallopt = getattr(libc, "mallopt", None)
    if mallopt is None:
        return False
    return bool(mallopt(_M_MMAP_THRESHOLD, MMAP_THRESHOLD_BYTES)) and \
        bool(mallopt(_M_TRIM_THRESHOLD, TRIM_THRESHOLD_BYTES))
