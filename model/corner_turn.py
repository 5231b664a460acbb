"""Bit-exact model of ``rtl/buffers/corner_turn.sv`` (frame transpose between the range FFT and
the Doppler FFT) and of its in-place address generator.

Words are uint32 lane arrays: a stream of ``n`` words with ``num_rx`` lanes is an array of
shape ``(n, num_rx)`` (any integer dtype; the model only moves words).

Input order (range FFT output, chirps TX-interleaved): word ``i = (c * n_range + r)`` with
chirp ``c = d * num_tx + t`` sent by TX ``t``, i.e. the input frame reshapes to
``(n_doppler, num_tx, n_range, num_rx)``.
Output order (Doppler vectors): word ``j = (t * n_range + r) * n_doppler + d``, i.e.
``(num_tx, n_range, n_doppler, num_rx)``, TLAST after every ``n_doppler`` words
(``read_order=0``, the RTL's READ_ORDER = 0), or with ``read_order=1`` (on-chip detection)
``j = (r * num_tx + t) * n_doppler + d``, i.e. ``(n_range, num_tx, n_doppler, num_rx)``.
Order 0 maps output j to input ``p(j) = rotl(j, ROT)``; order 1 to a bit permutation
``p(j)[a] = j[sigma(a)]``; the in-place scheme writes frame k at ``p^k`` for both.

``n_loops < n_doppler`` (the RTL's N_LOOPS: fewer loops than the Doppler FFT length): a frame
is the ``n_loops`` chirps per TX (the input indices i < num_tx * n_range * n_loops) and each
output vector ``n_loops`` words (the output indices with d < n_loops); the memory and the
address scheme stay those of ``n_doppler`` loops, the counters skip the missing words.
"""

from __future__ import annotations

import numpy as np


def _log2(n: int, name: str) -> int:
    b = int(n).bit_length() - 1
    if n < 1 or (1 << b) != n:
        raise ValueError(f"{name}={n} must be a power of two")
    return b


def corner_turn(frame: np.ndarray, num_tx: int, n_range: int, n_doppler: int,
                read_order: int = 0, n_loops: int | None = None) -> np.ndarray:
    """Reorder one frame from chirp order to Doppler-vector order.

    frame: ``(num_tx * n_loops * n_range, num_rx)`` words in input order (``n_loops``
    default ``n_doppler``).
    Returns ``(num_tx * n_range * n_loops, num_rx)`` words in output order
    (``read_order`` 0: (t, r, d); 1: (r, t, d)).
    """
    frame = np.asarray(frame)
    num_rx = frame.shape[-1]
    cube = frame.reshape(n_doppler if n_loops is None else n_loops, num_tx, n_range, num_rx)
    axes = (1, 2, 0, 3) if read_order == 0 else (2, 1, 0, 3)
    return np.ascontiguousarray(cube.transpose(*axes)).reshape(-1, num_rx)


def sigma(num_tx: int, n_range: int, n_doppler: int) -> np.ndarray:
    """int ``(B,)``: READ_ORDER = 1 bit permutation, bit a of p(j) is bit sigma[a] of j."""
    bt, br, bd = (_log2(num_tx, "num_tx"), _log2(n_range, "n_range"),
                  _log2(n_doppler, "n_doppler"))
    a = np.arange(bt + br + bd)
    return np.where(a < br, bt + bd + a, np.where(a < br + bt, bd + a - br, a - br - bt))


def _permute(x: np.ndarray, perm: np.ndarray) -> np.ndarray:
    """Bit a of the result is bit perm[a] of x."""
    out = np.zeros_like(x)
    for a, src in enumerate(perm):
        out |= ((x >> int(src)) & 1) << a
    return out


def address_bits(num_tx: int, n_range: int, n_doppler: int) -> tuple[int, int]:
    """(B, ROT): address bits of one frame and the per-frame rotation of the in-place scheme."""
    bt, br, bd = (_log2(num_tx, "num_tx"), _log2(n_range, "n_range"),
                  _log2(n_doppler, "n_doppler"))
    return bt + br + bd, bt + br


def rotl(x: np.ndarray, s: int, bits: int) -> np.ndarray:
    """Rotate ``bits``-bit integers left by ``s`` (0 <= s < bits)."""
    x = np.asarray(x, dtype=np.int64)
    mask = (1 << bits) - 1
    return ((x << s) | (x >> (bits - s))) & mask if s else x & mask


def write_addresses(k: int, num_tx: int, n_range: int, n_doppler: int,
                    read_order: int = 0) -> np.ndarray:
    """int64 ``(frame_words,)``: memory slot of input word i of frame k, W_k(i) = p^k(i)."""
    b, rot = address_bits(num_tx, n_range, n_doppler)
    if read_order == 0:
        return rotl(np.arange(1 << b), (k * rot) % b, b)
    s = sigma(num_tx, n_range, n_doppler)
    perm = np.arange(b)
    for _ in range(k):
        perm = s[perm]
    return _permute(np.arange(1 << b, dtype=np.int64), perm)


def read_addresses(k: int, num_tx: int, n_range: int, n_doppler: int,
                   read_order: int = 0) -> np.ndarray:
    """int64 ``(frame_words,)``: slot read for output word j of frame k, R_k = W_{k+1}."""
    return write_addresses(k + 1, num_tx, n_range, n_doppler, read_order)


def in_place_stream(frames: list[np.ndarray], num_tx: int, n_range: int,
                    n_doppler: int, read_order: int = 0, n_loops: int | None = None
                    ) -> list[np.ndarray]:
    """Run the in-place address scheme on a one-frame memory (checks the method itself),
    writing and reading only the words of ``n_loops`` loops (default ``n_doppler``), in
    the RTL's order: word i of frame k+1 is written only after read i of frame k.

    frames: list of input frames ``(num_tx * n_loops * n_range, num_rx)``. Returns the
    output frames. Raises AssertionError if a slot would be overwritten before being read.
    """
    if not frames:
        return []
    b, _ = address_bits(num_tx, n_range, n_doppler)
    n_loops = n_doppler if n_loops is None else n_loops
    live_in = np.arange(num_tx * n_range * n_loops)            # input indices that exist
    live_out = np.flatnonzero(np.arange(1 << b) % n_doppler < n_loops)
    mem = np.zeros((1 << b,) + frames[0].shape[1:], dtype=frames[0].dtype)
    unread = np.zeros(1 << b, dtype=bool)
    out = []
    for k, f in enumerate(frames):
        wa = write_addresses(k, num_tx, n_range, n_doppler, read_order)[live_in]
        ra = read_addresses(k - 1, num_tx, n_range, n_doppler, read_order) if k else []
        done = 0                                        # frame k-1's reads issued
        for i, slot in zip(live_in, wa, strict=True):   # its reads j <= i came first
            while k and done < len(live_out) and live_out[done] <= i:
                unread[ra[live_out[done]]] = False
                done += 1
            assert not unread[slot], "in-place scheme overwrote an unread slot"
            mem[slot] = f[i]
        unread[:] = False
        ra = read_addresses(k, num_tx, n_range, n_doppler, read_order)[live_out]
        unread[ra] = True
        out.append(mem[ra].copy())
    return out


def frame_period(num_tx: int, n_range: int, n_doppler: int, read_order: int = 0) -> int:
    """Frames after which the in-place address pattern repeats: B / gcd(B, ROT) for order
    0, the order of the bit permutation sigma for order 1."""
    b, rot = address_bits(num_tx, n_range, n_doppler)
    if read_order == 0:
        return b // np.gcd(b, rot)
    s = sigma(num_tx, n_range, n_doppler)
    perm, k = s.copy(), 1
    while not np.array_equal(perm, np.arange(b)):
        perm, k = s[perm], k + 1
    return k
