"""Bit-exact model of ``rtl/buffers/static_removal.sv``: static-clutter removal, each slow-time
vector (one TX slot and range bin, ``n_doppler`` words of ``num_rx`` lanes) less its mean over
the frame's first ``n_loops`` chirps, per lane and per I/Q, between the corner turn and the
Doppler FFT. The float definition is ``model.reference.remove_static``.

Arithmetic (the RTL's, exactly): ``s`` = the exact weighted sum ``sum w[n] x[n]`` of a
vector's first ``n_loops`` samples of one lane's I (or Q), the weights :func:`weights` (the
Doppler window's quantised periodic Hann, ``model.fft_rom.hann_window(n_loops)``, with the
pipeline's WINDOW on; all ones, the plain mean, with it off); the divisor ``D = sum w``
(:func:`divisor`: ``n_loops * 2^15`` windowed, ``n_loops`` plain); the mean
``m = floor((s * RECIP + 2^(SH-1)) / 2^SH)`` with ``SH = data_w + 2 clog2(D) + 1`` and
``RECIP = floor(2^SH / D) + 1`` (:func:`mean`) -- which is ``s / D`` rounded to nearest with
ties away from zero for every reachable ``s`` (:func:`mean_exact`, checked in
tests/test_static_removal.py). Subtracting the window-weighted mean leaves the windowed
zero-Doppler bin of every vector zero up to that rounding (``sum w (x - s/D) = 0``), where the
plain mean would leave a moving target's rectangular-window sidelobe there. Words
``d < n_loops``: ``x - m`` saturated to ``data_w`` bits; words ``d >= n_loops`` (zero fill)
pass unchanged; with the removal off everything passes.
"""

from __future__ import annotations

import numpy as np

from model.axis_packetizer import pack_iq, unpack_iq
from model.fft_rom import COEF_FRAC, ROM_SIZE, WINDOW_LENGTHS, hann_window


def _clog2(n: int) -> int:
    return (n - 1).bit_length()


def weights(n_loops: int, window: bool = True) -> np.ndarray:
    """int64 (n_loops,): the weight of each slow-time sample in the mean -- the Doppler
    window's quantised periodic Hann (Q1.16, ``model.fft_rom.hann_window``, the
    ``fft_win_rom`` coefficients; ``n_loops`` a power of two in 2..4096 or one of
    ``model.fft_rom.WINDOW_LENGTHS``) with ``window``, else ones."""
    if not window:
        return np.ones(n_loops, dtype=np.int64)
    if not (2 <= n_loops <= ROM_SIZE and (n_loops & (n_loops - 1) == 0
                                          or n_loops in WINDOW_LENGTHS)):
        raise ValueError(f"window-weighted mean needs n_loops a power of two in 2..{ROM_SIZE} "
                         f"or one of model.fft_rom.WINDOW_LENGTHS {WINDOW_LENGTHS}, got "
                         f"{n_loops}")
    return hann_window(n_loops)


def divisor(n_loops: int, window: bool = True) -> int:
    """sum of :func:`weights`: ``n_loops`` plain, ``n_loops * 2^15`` windowed (the RTL's
    constant; equal to the table's sum, checked in tests/test_static_removal.py and, for
    the lengths that are not powers of two, by ``model.fft_rom.check_window_sums``)."""
    return n_loops << (COEF_FRAC - 1) if window else n_loops


def shift_and_recip(div: int, data_w: int = 16) -> tuple[int, int]:
    """(SH, RECIP) of the reciprocal multiply dividing by ``div`` (RTL localparams)."""
    lb = _clog2(div)
    sh = data_w + 2 * lb + 1
    return sh, (1 << sh) // div + 1


def mean(sums: np.ndarray, div: int, data_w: int = 16) -> np.ndarray:
    """Rounded means of exact int64 weighted sums ``s`` (``|s| <= 2^(data_w-1) div``), as the
    RTL computes them: ``(s * RECIP + 2^(SH-1)) >> SH`` (arithmetic shift). int64, same
    shape."""
    sh, recip = shift_and_recip(div, data_w)
    s = np.asarray(sums, dtype=object if sh + data_w + _clog2(div) > 62 else np.int64)
    return np.asarray((s * recip + (1 << (sh - 1))) >> sh).astype(np.int64)


def mean_exact(sums: np.ndarray, div: int) -> np.ndarray:
    """``s / div`` rounded to nearest, ties away from zero (what :func:`mean` equals)."""
    s = np.asarray(sums, dtype=np.int64)
    mag = (2 * np.abs(s) + div) // (2 * div)
    return np.where(s < 0, -mag, mag)


def remove_static_planar(x: np.ndarray, n_loops: int | None = None, data_w: int = 16,
                         window: bool = True) -> tuple[np.ndarray, int]:
    """Integer-valued planar vectors ``(..., n_doppler, num_rx, 2)`` (I, Q last; slow time on
    axis -3) -> (the same shape, int64, less each lane's rounded weighted mean over the first
    ``n_loops`` (default n_doppler) slow-time samples (:func:`weights`: the Doppler window's
    when ``window``, else the plain mean) and saturated; the number of output words with a
    saturated value, the RTL's ``status_saturated`` events)."""
    v = np.asarray(x).astype(np.int64)
    n_loops = v.shape[-3] if n_loops is None else n_loops
    w = weights(n_loops, window)[:, None, None]
    m = mean((v[..., :n_loops, :, :] * w).sum(axis=-3, keepdims=True),
             divisor(n_loops, window), data_w)
    lo, hi = -(1 << (data_w - 1)), (1 << (data_w - 1)) - 1
    out = v.copy()
    d = v[..., :n_loops, :, :] - m
    out[..., :n_loops, :, :] = np.clip(d, lo, hi)
    saturated = int(((d < lo) | (d > hi)).any(axis=(-2, -1)).sum())
    return out, saturated


def static_removal(words: np.ndarray, n_doppler: int, n_loops: int | None = None,
                   enable: bool = True, window: bool = True) -> tuple[np.ndarray, int]:
    """One frame through the block. ``words``: uint32 ``(frame_words, num_rx)`` packed
    ``{Q, I}`` lanes, whole Doppler vectors of ``n_doppler`` words in stream order ->
    (the output words, same shape and order; saturated output words)."""
    if not enable:
        return np.asarray(words, dtype=np.uint32).copy(), 0
    w = np.asarray(words)
    c = unpack_iq(w).reshape(-1, n_doppler, w.shape[1])
    planar = np.stack([c.real, c.imag], axis=-1)
    out, sat = remove_static_planar(planar, n_loops, window=window)
    return pack_iq((out[..., 0] + 1j * out[..., 1]).reshape(w.shape)), sat
