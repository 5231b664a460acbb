"""Oracle of ``host._angle_peaks``: the numpy fast peak search of the angle spectrum its
compiled kernels replaced (:func:`fine_peaks`: a coarse FFT picks the lobe, the fine grid
is evaluated exactly around it), the peak sine and power through it, and the steering
vectors from a few exponentials per row (:func:`_steering_rows`). The definition they are
held to is ``tests.oracles.angle`` (the ``n_fft``-point FFT's peak)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import scipy.fft

from host._angle_peaks import COARSE_FFT, SECOND_LOBE, ZOOM_HALF
from host._angle_peaks import zoom_tables as _zoom_tables


def fine_peaks(x: np.ndarray, n_fft: int, coarse: int = COARSE_FFT, half: int = ZOOM_HALF
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Maximum of |angle spectrum| on the ``n_fft``-point grid, found without the
    ``n_fft``-point FFT: a ``coarse``-point FFT (single precision) picks the lobe (the
    runner-up lobe too when it is within ``SECOND_LOBE`` of it) and a parabolic fit a
    starting fine bin; the spectrum is then evaluated exactly (double precision) on the
    2 half + 1 fine bins around it (one small matrix product after demodulating each row
    by the window centre) and the window moves uphill until its maximum is inside it: the
    fine-grid maximum of that lobe, as the ``n_fft``-point FFT finds it unless a third lobe
    is within the coarse grid's scalloping of it.

    x: complex (m, n). Returns (fine bin int (m,) in the unshifted order of
    ``_spectrum_unshifted``, magnitudes float (m,) of bins k - 1, k, k + 1)."""
    m, n = x.shape
    if not m:
        z = np.zeros(0)
        return np.zeros(0, np.int64), z, z, z
    coarse = min(coarse, n_fft)
    cm = np.abs(scipy.fft.ifft(x.astype(np.complex64), n=coarse, axis=-1, workers=1))
    return _peaks_from_coarse(np.asarray(x, dtype=np.complex128), cm, n_fft, half)


def _peaks_from_coarse(xd: np.ndarray, cm: np.ndarray, n_fft: int, half: int
                       ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """:func:`fine_peaks` of xd (complex128 (m, n)) from its coarse magnitudes cm (float
    (m, coarse); changed here)."""
    m = len(xd)
    coarse = cm.shape[1]
    rows = np.arange(m)
    kc = np.argmax(cm, axis=-1)
    k, a, b, c = _refine(xd, cm, kc, n_fft, half)   # before cm is changed below
    # runner-up lobe: the largest coarse bin outside the first lobe's 5 bins (a shoulder of
    # the first lobe climbs back to it: harmless)
    first = cm[rows, kc]
    for o in (-2, -1, 0, 1, 2):
        cm[rows, (kc + o) % coarse] = 0.0
    k2c = np.argmax(cm, axis=-1)
    two = np.flatnonzero(cm[rows, k2c] >= SECOND_LOBE * first)
    if len(two):
        k2, a2, b2, c2 = _refine(xd[two], cm[two], k2c[two], n_fft, half)
        better = b2 > b[two]
        w = two[better]
        k[w], a[w], b[w], c[w] = k2[better], a2[better], b2[better], c2[better]
    return k, a, b, c


def _refine(xd: np.ndarray, cm: np.ndarray, kc: np.ndarray, n_fft: int, half: int
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Fine-grid local maximum of |spectrum| of the rows of xd (complex (m, n)) uphill from
    coarse bin kc (int (m,)) of the coarse magnitudes cm (float (m, coarse)):
    :func:`fine_peaks`'s (k, |X(k - 1)|, |X(k)|, |X(k + 1)|)."""
    m, n = xd.shape
    coarse = cm.shape[1]
    step = n_fft // coarse
    rows = np.arange(m)
    ca, cb, cc = cm[rows, (kc - 1) % coarse], cm[rows, kc], cm[rows, (kc + 1) % coarse]
    den = ca - 2 * cb + cc
    with np.errstate(divide="ignore", invalid="ignore"):
        delta = np.where(den < 0, 0.5 * (ca - cc) / np.where(den < 0, den, 1.0), 0.0)
    centre = (kc * step + np.round(np.clip(delta, -0.5, 0.5) * step).astype(np.int64)) % n_fft
    demod, offs = _zoom_tables(n, n_fft, half)
    todo = rows
    max_it = n_fft // half + 2
    for it in range(max_it):
        if it == 0:             # all rows: no gathers
            mag = np.abs((xd * demod[centre]) @ offs)
            j = jb = np.argmax(mag, axis=-1)
            mag_t = mag
        else:
            mag_t = np.abs((xd[todo] * demod[centre[todo]]) @ offs)
            j = np.argmax(mag_t, axis=-1)
            mag[todo] = mag_t
            jb[todo] = j
        # uphill only when the edge is strictly higher (ties, as in a flat or zero spectrum,
        # stop here)
        edge = ((j == 0) & (mag_t[:, 0] > mag_t[:, 1])) | (j == 2 * half)
        if not edge.any() or it == max_it - 1:
            break
        todo = todo[edge]
        centre[todo] = (centre[todo] + j[edge] - half) % n_fft
    k = (centre + jb - half) % n_fft
    b = mag[rows, jb]
    a = mag[rows, np.clip(jb - 1, 0, 2 * half)]
    c = mag[rows, np.clip(jb + 1, 0, 2 * half)]
    return k, a, b, c


def _interpolated_sin(k0: np.ndarray, a: np.ndarray, b: np.ndarray, c: np.ndarray,
                      n_fft: int) -> np.ndarray:
    """sin(az) float (m,) of fine-grid peaks (unshifted bin k0 with magnitudes a, b, c at
    k0 - 1, k0, k0 + 1): ``tests.oracles.angle.peak_sin``'s parabolic interpolation."""
    k = (k0 + n_fft // 2) % n_fft                  # index in the fftshift order
    den = a - 2 * b + c
    with np.errstate(divide="ignore", invalid="ignore"):
        delta = np.where(den < 0, 0.5 * (a - c) / np.where(den < 0, den, 1.0), 0.0)
    s = 2.0 * (k + delta - n_fft // 2) / n_fft
    return (s + 1.0) % 2.0 - 1.0


def peak_sin_fast(x: np.ndarray, n_fft: int) -> tuple[np.ndarray, np.ndarray]:
    """``tests.oracles.angle.peak_sin_batch`` through :func:`fine_peaks` (same grid maximum,
    same interpolation; differs only where another lobe is within the coarse grid's
    scalloping of the strongest): (sin(az) float (m,), |peak|^2 float (m,))."""
    k0, a, b, c = fine_peaks(x, n_fft)
    return _interpolated_sin(k0, a, b, c, n_fft), b * b


def peak_power_fast(x: np.ndarray, n_fft: int) -> tuple[np.ndarray, np.ndarray]:
    """``tests.oracles.angle.peak_power_batch`` through :func:`fine_peaks`, x complex
    (..., n): (peak power float (...), and the peak's sin(az) float (...) as
    :func:`peak_sin_fast`)."""
    shape = x.shape[:-1]
    k0, a, b, c = fine_peaks(x.reshape(-1, x.shape[-1]), n_fft)
    return (b * b).reshape(shape), _interpolated_sin(k0, a, b, c, n_fft).reshape(shape)


def _steering_rows(s: np.ndarray, n: int) -> np.ndarray:
    """exp(-j pi v s) for v = 0..n-1 of every s (float (m,)), complex (m, n), from 2 sqrt(n)
    exponentials per row (exp(-j pi (a b0 + c) s) = exp(-j pi a b0 s) exp(-j pi c s))."""
    b0 = int(np.ceil(np.sqrt(n)))
    lo = np.exp(-1j * np.pi * np.multiply.outer(s, np.arange(b0)))            # (m, b0)
    hi = np.exp(-1j * np.pi * np.multiply.outer(s, np.arange(-(-n // b0)) * b0))  # (m, n/b0)
    return (hi[:, :, None] * lo[:, None, :]).reshape(len(s), hi.shape[1] * b0)[:, :n]


PeakFinder = Callable[[np.ndarray, int], tuple[np.ndarray, np.ndarray]]
"""A function (x complex (m, n), n_fft) -> (sin(az) float (m,), |peak|^2 float (m,)) of the
strongest angle-spectrum peak of each row: ``tests.oracles.angle.peak_sin_batch`` (the
``n_fft``-point FFT's), :func:`peak_sin_fast`, or the compiled
``host._angle_peaks.peak_sins``."""


Steering = Callable[[np.ndarray, int], np.ndarray]
"""A function (s float (m,), n) -> exp(-j pi v s), complex (m, n): :func:`_steering_rows`
or the compiled ``host._angle_peaks.peak_sins`` / ``host._angle_relax.steering_rows``."""
