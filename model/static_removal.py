"""Bit-exact model of ``rtl/buffers/static_removal.sv``: static-clutter removal, each slow-time
vector (one TX slot and range bin, ``n_doppler`` words of ``num_rx`` lanes) less its mean over
the frame's first ``n_loops`` chirps, per lane and per I/Q, between the corner turn and the
Doppler FFT. The float definition is ``model.reference.remove_static``.

Arithmetic (the RTL's, exactly): ``s`` = the exact sum of a vector's first ``n_loops`` samples
of one lane's I (or Q); the mean ``m = floor((s * RECIP + 2^(SH-1)) / 2^SH)`` with
``SH = SUM_W + clog2(n_loops) + 1``, ``SUM_W = data_w + clog2(n_loops)`` and
``RECIP = floor(2^SH / n_loops) + 1`` (:func:`mean`) -- which is ``s / n_loops`` rounded to
nearest with ties away from zero for every reachable ``s`` (:func:`mean_exact`, checked in
tests/test_static_removal.py). Words ``d < n_loops``: ``x - m`` saturated to ``data_w`` bits;
words ``d >= n_loops`` (zero fill) pass unchanged; with the removal off everything passes.
"""

from __future__ import annotations

import numpy as np

from model.axis_packetizer import pack_iq, unpack_iq


def _clog2(n: int) -> int:
    return (n - 1).bit_length()


def shift_and_recip(n_loops: int, data_w: int = 16) -> tuple[int, int]:
    """(SH, RECIP) of the reciprocal multiply for ``n_loops`` (RTL localparams)."""
    lb = _clog2(n_loops)
    sh = data_w + 2 * lb + 1
    return sh, (1 << sh) // n_loops + 1


def mean(sums: np.ndarray, n_loops: int, data_w: int = 16) -> np.ndarray:
    """Rounded means of exact int64 sums of ``n_loops`` samples, as the RTL computes them:
    ``(s * RECIP + 2^(SH-1)) >> SH`` (arithmetic shift). int64, same shape."""
    sh, recip = shift_and_recip(n_loops, data_w)
    s = np.asarray(sums, dtype=np.int64)
    return (s * np.int64(recip) + np.int64(1 << (sh - 1))) >> np.int64(sh)


def mean_exact(sums: np.ndarray, n_loops: int) -> np.ndarray:
    """``s / n_loops`` rounded to nearest, ties away from zero (what :func:`mean` equals)."""
    s = np.asarray(sums, dtype=np.int64)
    mag = (2 * np.abs(s) + n_loops) // (2 * n_loops)
    return np.where(s < 0, -mag, mag)


def remove_static_planar(x: np.ndarray, n_loops: int | None = None, data_w: int = 16
                         ) -> tuple[np.ndarray, int]:
    """Integer-valued planar vectors ``(..., n_doppler, num_rx, 2)`` (I, Q last; slow time on
    axis -3) -> (the same shape, int64, less each lane's rounded mean over the first
    ``n_loops`` (default n_doppler) slow-time samples and saturated; the number of output
    words with a saturated value, the RTL's ``status_saturated`` events)."""
    v = np.asarray(x).astype(np.int64)
    n_loops = v.shape[-3] if n_loops is None else n_loops
    m = mean(v[..., :n_loops, :, :].sum(axis=-3, keepdims=True), n_loops, data_w)
    lo, hi = -(1 << (data_w - 1)), (1 << (data_w - 1)) - 1
    out = v.copy()
    d = v[..., :n_loops, :, :] - m
    out[..., :n_loops, :, :] = np.clip(d, lo, hi)
    saturated = int(((d < lo) | (d > hi)).any(axis=(-2, -1)).sum())
    return out, saturated


def static_removal(words: np.ndarray, n_doppler: int, n_loops: int | None = None,
                   enable: bool = True) -> tuple[np.ndarray, int]:
    """One frame through the block. ``words``: uint32 ``(frame_words, num_rx)`` packed
    ``{Q, I}`` lanes, whole Doppler vectors of ``n_doppler`` words in stream order ->
    (the output words, same shape and order; saturated output words)."""
    if not enable:
        return np.asarray(words, dtype=np.uint32).copy(), 0
    w = np.asarray(words)
    c = unpack_iq(w).reshape(-1, n_doppler, w.shape[1])
    planar = np.stack([c.real, c.imag], axis=-1)
    out, sat = remove_static_planar(planar, n_loops)
    return pack_iq((out[..., 0] + 1j * out[..., 1]).reshape(w.shape)), sat
