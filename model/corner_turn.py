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

In-place address schemes (docs/buffers.md), frame k written at ``W_k`` and read at ``W_{k+1}``:
order 0 maps output j to input ``p(j) = j * M mod (N - 1)`` (``M = num_tx * n_range``,
``N`` words a frame, ``p(N-1) = N-1``), so ``W_k(i) = i * M^k mod (N - 1)``, for a power-of-two
frame the bit rotation ``rotl(i, k * log2 M mod log2 N)``. Order 1 with a power-of-two
num_tx: the bit permutation ``p(j)[a] = j[sigma(a)]``, ``W_k = p^k``; with any other num_tx
the memory is num_tx banks of ``n_range * n_doppler`` words, bank t holding TX t's chirps as
an in-place ``n_doppler x n_range`` transpose (rotation by log2 n_range).

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


def _pow2(n: int) -> bool:
    return n >= 1 and n & (n - 1) == 0


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
    """int ``(B,)``: READ_ORDER = 1 bit permutation (power-of-two num_tx), bit a of p(j) is bit
    sigma[a] of j."""
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


def rotl(x: np.ndarray, s: int, bits: int) -> np.ndarray:
    """Rotate ``bits``-bit integers left by ``s`` (0 <= s < bits)."""
    x = np.asarray(x, dtype=np.int64)
    mask = (1 << bits) - 1
    return ((x << s) | (x >> (bits - s))) & mask if s else x & mask


def stride(k: int, num_tx: int, n_range: int, n_doppler: int) -> int:
    """READ_ORDER 0 address step of frame k: ``M^k mod (N - 1)``, M = num_tx * n_range."""
    n = num_tx * n_range * n_doppler
    return pow(num_tx * n_range, k, n - 1)


def _bank_slot(k: int, t: np.ndarray, n: np.ndarray, n_range: int, n_doppler: int
               ) -> np.ndarray:
    """READ_ORDER 1, num_tx not a power of two: slot of bank word n of TX t in frame k's
    address pattern, ``t * n_range * n_doppler + rotl(n, k * log2 n_range)``."""
    br = _log2(n_range, "n_range")
    m = br + _log2(n_doppler, "n_doppler")
    return t * (1 << m) + rotl(n, (k * br) % m, m)


def write_addresses(k: int, num_tx: int, n_range: int, n_doppler: int,
                    read_order: int = 0) -> np.ndarray:
    """int64 ``(frame_words,)``: memory slot of input word i of frame k, W_k(i)."""
    n = num_tx * n_range * n_doppler
    i = np.arange(n, dtype=np.int64)
    if read_order == 0:
        return np.where(i == n - 1, n - 1, i * stride(k, num_tx, n_range, n_doppler) % (n - 1))
    if not _pow2(num_tx):   # input (d, t, r): bank t, bank word d * n_range + r
        d, rest = np.divmod(i, num_tx * n_range)
        t, r = np.divmod(rest, n_range)
        return _bank_slot(k, t, d * n_range + r, n_range, n_doppler)
    s = sigma(num_tx, n_range, n_doppler)
    perm = np.arange(len(s))
    for _ in range(k):
        perm = s[perm]
    return _permute(i, perm)


def read_addresses(k: int, num_tx: int, n_range: int, n_doppler: int,
                   read_order: int = 0) -> np.ndarray:
    """int64 ``(frame_words,)``: slot read for output word j of frame k: ``W_{k+1}(j)``, with
    TX banks bank word ``r * n_doppler + d`` of TX t in frame k+1's pattern."""
    if read_order == 1 and not _pow2(num_tx):   # output (r, t, d)
        j = np.arange(num_tx * n_range * n_doppler, dtype=np.int64)
        r, rest = np.divmod(j, num_tx * n_doppler)
        t, d = np.divmod(rest, n_doppler)
        return _bank_slot(k + 1, t, r * n_doppler + d, n_range, n_doppler)
    return write_addresses(k + 1, num_tx, n_range, n_doppler, read_order)


def _write_waits_for(i: np.ndarray, num_tx: int, n_range: int, n_doppler: int,
                     read_order: int) -> np.ndarray:
    """int64 like ``i``: the output index j of frame k whose read the RTL's writer waits for
    before writing input word i of frame k+1 (reads are issued in j order): j = i, or with
    TX banks bank t's read of bank word ``d * n_range + r`` (read as ``r' * n_doppler + d'``)."""
    if read_order == 0 or _pow2(num_tx):
        return np.asarray(i, dtype=np.int64)
    d, rest = np.divmod(np.asarray(i, dtype=np.int64), num_tx * n_range)
    t, r = np.divmod(rest, n_range)
    rb, db = np.divmod(d * n_range + r, n_doppler)
    return (rb * num_tx + t) * n_doppler + db


def in_place_stream(frames: list[np.ndarray], num_tx: int, n_range: int,
                    n_doppler: int, read_order: int = 0, n_loops: int | None = None
                    ) -> list[np.ndarray]:
    """Run the in-place address scheme on a one-frame memory (checks the method itself),
    writing and reading only the words of ``n_loops`` loops (default ``n_doppler``), in
    the RTL's order: word i of frame k+1 is written only after read i of frame k (TX banks:
    after its bank's read of the same bank word).

    frames: list of input frames ``(num_tx * n_loops * n_range, num_rx)``. Returns the
    output frames. Raises AssertionError if a slot would be overwritten before being read.
    """
    if not frames:
        return []
    n = num_tx * n_range * n_doppler
    n_loops = n_doppler if n_loops is None else n_loops
    live_in = np.arange(num_tx * n_range * n_loops)            # input indices that exist
    live_out = np.flatnonzero(np.arange(n) % n_doppler < n_loops)
    waits = _write_waits_for(live_in, num_tx, n_range, n_doppler, read_order)
    mem = np.zeros((n,) + frames[0].shape[1:], dtype=frames[0].dtype)
    unread = np.zeros(n, dtype=bool)
    out = []
    for k, f in enumerate(frames):
        wa = write_addresses(k, num_tx, n_range, n_doppler, read_order)[live_in]
        ra = read_addresses(k - 1, num_tx, n_range, n_doppler, read_order) if k else []
        done = 0                                        # frame k-1's reads issued
        for i, slot, g in zip(live_in, wa, waits, strict=True):  # its reads j <= g first
            while k and done < len(live_out) and live_out[done] <= g:
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
    """Frames after which the in-place address pattern repeats: the multiplicative order of
    M = num_tx * n_range modulo N - 1 for order 0 (B / gcd(B, log2 M) for a power-of-two
    frame of 2^B words), the order of the bit permutation sigma for order 1 (with TX banks,
    m / gcd(m, log2 n_range), m = log2(n_range * n_doppler))."""
    if read_order == 0:
        k = 1
        while stride(k, num_tx, n_range, n_doppler) != 1:
            k += 1
        return k
    if not _pow2(num_tx):
        br = _log2(n_range, "n_range")
        m = br + _log2(n_doppler, "n_doppler")
        return m // int(np.gcd(m, br))
    s = sigma(num_tx, n_range, n_doppler)
    perm, k = s.copy(), 1
    while not np.array_equal(perm, np.arange(len(s))):
        perm, k = s[perm], k + 1
    return k
