"""Fine range and Doppler estimation from the whole frame (``--refine``, docs/curves.md,
"The refinement").

The peak interpolation of ``host.cells`` reads three Hann-windowed cells per axis: 7.1 dB
(MSE) above the Cramer-Rao bound of the whole data on ``full``, by what those cells hold.
This stage goes back to all the frame's samples. The radar cube is the windowed 2-D DFT of
the ADC samples per virtual channel, so its inverse DFT gives them back, each multiplied by
its windows' weights: y[v, t, c] = w_r[t] w_d[c] x[v, t, c] (:func:`frame_samples`). For one
tone with an unknown complex amplitude per channel in white noise, the maximum-likelihood
frequency maximises the channel-summed periodogram of the unwindowed samples,
J(f_r, f_d) = sum_v |sum_{t,c} x[v, t, c] exp(-j 2 pi (f_r t / N_r + f_d c / N_d))|^2
(Rife and Boorstyn 1974; Kay, *Estimation Theory*, section 7.10, per channel amplitude
eliminated). Dividing by the windows is exact in float but amplifies what was added after
them (the fixed-point chain's rounding) where they are near zero, so the samples are
weighted instead by g = w / (w^2 + floor^2): the unwindowed x where w >> floor, a taper
w^2 / floor^2 where w << floor (the weighted least-squares weight for rounding noise
floor^2 below the ADC noise). ``floor`` trades the taper's estimation loss against the
rounding's amplification (docs/curves.md gives both).

:func:`refine_offsets` starts from the interpolated peak of each detected cell and maximises
J by coordinate-wise Newton steps, range with the Doppler frequency fixed and the reverse,
:data:`ROUNDS` times; each 1-D step works on the projection of the samples on the other
axis' tone (a matrix product over the whole frame). With several cells each is then refined
on the samples less the other cells' fitted tones, :data:`RELAX_PASSES` times (RELAX: Li
and Stoica, "Efficient mixed-spectrum estimation with applications to target feature
extraction", IEEE Trans. SP 44(2), 1996), so a strong neighbour's nearly unwindowed
sidelobes do not pull a weak cell. The steps stay within :data:`MAX_SHIFT_BINS` of the
interpolated peak; a cell whose periodogram would be lower after a pass than before it keeps
the frequencies it had.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from model.config import RadarConfig
from model.reference import FftAxis, fft_axes

ROUNDS = 1
"""Range-then-Doppler rounds of Newton steps per pass (the cross-derivative of J vanishes
at the peak on centred samples: a second round moves the estimate by far less than its
error)."""
NEWTON_STEPS = 4
"""Newton steps per axis and round."""
RELAX_PASSES = 3
"""Passes against the other cells' fitted tones (none for a single cell)."""
MAX_STEP_BINS = 0.25
"""Largest single Newton step, bins."""
MAX_SHIFT_BINS = 0.75
"""Largest move from the interpolated peak, bins (the steps are clipped to it)."""
FLOAT_FLOOR = 0.001
"""Weighting floor for a float cube (module docstring): its taper costs 0.22 dB of
estimation (range or Doppler) and 0.07 dB of the other axis' SNR on a 256-sample Hann
axis."""
FIXED_POINT_FLOOR = 0.3
"""Weighting floor for the fixed-point chain's cube (``model.radar_pipeline``): its
rounding after the windows equals the ADC noise in the projections at a floor of 0.1 and
is 9 dB below it at 0.3; docs/curves.md, "The refinement"."""


def weights(axis: FftAxis, floor: float) -> tuple[np.ndarray, np.ndarray]:
    """(g, v) float (n_samples,): the weight applied to the windowed samples,
    g = w / (w^2 + floor^2), and the resulting weight of the unwindowed ones, v = g w
    (1 without a window)."""
    w = axis.window()
    if not axis.hann:
        return np.ones_like(w), np.ones_like(w)
    g = w / (w * w + floor * floor)
    return g, g * w


def frame_samples(cube: np.ndarray, cfg: RadarConfig, windows: tuple[bool, bool],
                  floor: float) -> np.ndarray:
    """The frame's samples weighted by :func:`weights` (v_r[t] v_d[c] x[v, t, c]), complex64
    (n_virtual, n_samples, n_loops), from the cube complex (n_virtual, n_range, n_doppler)
    of a complex-ADC radar (scaled as ``model.reference.radar_cube``: 1/N per FFT)."""
    if cfg.adc != "complex":
        raise ValueError("refine: needs a complex-ADC radar (a real ADC's cube keeps half "
                         "the range spectrum)")
    ax_r, ax_d = fft_axes(cfg, *windows)
    y = np.fft.ifft(cube, axis=2)[:, :, :ax_d.n_samples] * ax_d.n_fft
    y = np.fft.ifft(y, axis=1)[:, :ax_r.n_samples, :] * ax_r.n_fft
    g_r, g_d = weights(ax_r, floor)[0], weights(ax_d, floor)[0]
    return (y * (g_r[:, None] * g_d[None, :])).astype(np.complex64)


def _tones(freq: np.ndarray, n: int, n_fft: int) -> np.ndarray:
    """exp(-j 2 pi f (t - n/2) / n_fft), complex64 (len(freq), n): the tones of ``freq``
    (bins) over samples centred on the window's centre."""
    return np.exp(-2j * np.pi * np.outer(freq, np.arange(n) - n / 2) / n_fft).astype(
        np.complex64)


def _periodogram(u: np.ndarray, f: np.ndarray, n_fft: int) -> tuple[np.ndarray, np.ndarray]:
    """(J float (P,), channel sums complex (P, V)) of u complex (P, V, n) at ``f`` (P,)
    bins: a[p, v] = sum_t u[p, v, t] exp(-j 2 pi f t' / n_fft), J = sum_v |a|^2."""
    a = np.einsum("pvt,pt->pv", u, _tones(f, u.shape[2], n_fft))
    return np.sum(np.abs(a) ** 2, axis=1), a


def _newton(u: np.ndarray, f: np.ndarray, start: np.ndarray, n_fft: int) -> np.ndarray:
    """Newton steps on J(f) = sum_v |sum_t u[p, v, t] exp(-j theta t')|^2 per row p, theta
    = 2 pi f / n_fft, t' centred (:func:`_tones`): u complex (P, V, n), f and start float
    (P,) bins; steps within :data:`MAX_STEP_BINS`, f within :data:`MAX_SHIFT_BINS` of
    ``start``; a row whose J is not concave moves by a fixed step uphill."""
    n = u.shape[2]
    t = (np.arange(n) - n / 2).astype(np.float32)
    for _ in range(NEWTON_STEPS):
        e = _tones(f, n, n_fft)
        a = np.einsum("pvt,pt->pv", u, e)
        a1 = np.einsum("pvt,pt->pv", u, e * (-1j * t))
        a2 = np.einsum("pvt,pt->pv", u, e * (-t * t))
        grad = 2 * np.sum((a.conj() * a1).real, axis=1, dtype=float)
        hess = 2 * np.sum(np.abs(a1) ** 2 + (a.conj() * a2).real, axis=1, dtype=float)
        safe = np.where(hess < 0, hess, -1.0)
        step = np.where(hess < 0, -grad / safe, np.sign(grad) * np.pi / n)
        step = np.clip(step * n_fft / (2 * np.pi), -MAX_STEP_BINS, MAX_STEP_BINS)
        f = np.clip(f + step, start - MAX_SHIFT_BINS, start + MAX_SHIFT_BINS)
    return f


class _Samples:
    """The weighted samples x complex64 (V, T, C) in the two layouts the projections need."""

    def __init__(self, x: np.ndarray) -> None:
        self.shape = x.shape
        self.by_doppler = x.reshape(-1, x.shape[2])                           # (V T, C)
        self.by_range = np.ascontiguousarray(x.transpose(1, 0, 2)).reshape(x.shape[1], -1)

    def on_doppler(self, ed: np.ndarray) -> np.ndarray:
        """Projections on Doppler tones ed (P, C): complex (P, V, T)."""
        v, t, _ = self.shape
        return (self.by_doppler @ ed.T).reshape(v, t, -1).transpose(2, 0, 1)

    def on_range(self, er: np.ndarray) -> np.ndarray:
        """Projections on range tones er (P, T): complex (P, V, C)."""
        v, _, c = self.shape
        return (er @ self.by_range).reshape(-1, v, c)


@dataclass
class _Pass:
    """A refinement pass' result per row (P,): frequencies (bins), J where it started and
    where it ended, and the channel sums at the end complex (P, V)."""

    fr: np.ndarray
    fd: np.ndarray
    j_from: np.ndarray
    j_to: np.ndarray
    amp: np.ndarray


def _fit(x: _Samples, fr: np.ndarray, fd: np.ndarray, start: np.ndarray,
         ax: tuple[FftAxis, FftAxis], own: _Own | None) -> _Pass:
    """One pass of :data:`ROUNDS` coordinate Newton rounds from (fr, fd) float (P,) bins
    for the samples ``x``, ``start`` float (P, 2) the interpolated peaks; with ``own`` (x
    then the residual of every row's fitted tone), each row's own tone is added back to its
    projections."""
    j_from = None
    for _ in range(ROUNDS):
        ed = _tones(fd, ax[1].n_samples, ax[1].n_fft)
        u = x.on_doppler(ed)                                                 # (P, V, T)
        if own is not None:
            u = u + own.back_range(ed)
        if j_from is None:
            j_from = _periodogram(u, fr, ax[0].n_fft)[0]
        fr = _newton(u, fr, start[:, 0], ax[0].n_fft)
        er = _tones(fr, ax[0].n_samples, ax[0].n_fft)
        z = x.on_range(er)                                                   # (P, V, C)
        if own is not None:
            z = z + own.back_doppler(er)
        fd = _newton(z, fd, start[:, 1], ax[1].n_fft)
    j_to, amp = _periodogram(z, fd, ax[1].n_fft)
    return _Pass(fr, fd, j_from, j_to, amp)


class _Own:
    """The fitted tones of the cells: per row, amplitude complex (V,) times the weighted
    tone v_r[t] v_d[c] exp(j 2 pi (fr t' / N_r + fd c' / N_d)) at its (fr, fd)."""

    def __init__(self, amp: np.ndarray, fr: np.ndarray, fd: np.ndarray, vr: np.ndarray,
                 vd: np.ndarray, ax: tuple[FftAxis, FftAxis]) -> None:
        self.amp = amp.astype(np.complex64)
        self.sr = vr.astype(np.float32) * _tones(fr, len(vr), ax[0].n_fft).conj()   # (P, T)
        self.sd = vd.astype(np.float32) * _tones(fd, len(vd), ax[1].n_fft).conj()   # (P, C)

    def model(self) -> np.ndarray:
        """Sum of the tones, complex64 (V, T, C)."""
        outer = self.sr[:, :, None] * self.sd[:, None, :]               # (P, T, C)
        p = len(self.amp)
        return (self.amp.T @ outer.reshape(p, -1)).reshape(self.amp.shape[1], *outer.shape[1:])

    def back_range(self, ed: np.ndarray) -> np.ndarray:
        """Each row's tone projected on its Doppler tones ``ed`` (P, C): (P, V, T)."""
        k = np.sum(self.sd * ed, axis=1)                                # (P,)
        return (self.amp * k[:, None])[:, :, None] * self.sr[:, None, :]

    def back_doppler(self, er: np.ndarray) -> np.ndarray:
        """Each row's tone projected on its range tones ``er`` (P, T): (P, V, C)."""
        k = np.sum(self.sr * er, axis=1)
        return (self.amp * k[:, None])[:, :, None] * self.sd[:, None, :]


def refine_offsets(cube: np.ndarray, range_bin: np.ndarray, doppler_bin: np.ndarray,
                   offsets: np.ndarray, cfg: RadarConfig, windows: tuple[bool, bool],
                   floor: float = FLOAT_FLOOR) -> np.ndarray:
    """Refined (range, Doppler) offsets float (n, 2) bins of the detected cells (int (n,)
    ``range_bin``, natural-order ``doppler_bin``) from their interpolated ``offsets`` float
    (n, 2), by maximising the channel-summed periodogram of the whole frame's samples
    (module docstring); cube complex (n_virtual, n_range, n_doppler), float-reference
    units; ``windows``: (range, Doppler) Hann on. A row whose periodogram at the refined
    frequencies is below that at the interpolated ones keeps the interpolated offsets (a
    RELAX pass' move likewise, on its residual)."""
    offsets = np.asarray(offsets, dtype=float)
    if len(offsets) == 0:
        return offsets.copy()
    ax = fft_axes(cfg, *windows)
    raw = frame_samples(cube, cfg, windows, floor)
    x = _Samples(raw)
    start = np.stack([range_bin + offsets[:, 0], doppler_bin + offsets[:, 1]], axis=1)
    first = _fit(x, start[:, 0].copy(), start[:, 1].copy(), start, ax, None)
    ok = first.j_to >= first.j_from
    fr = np.where(ok, first.fr, start[:, 0])
    fd = np.where(ok, first.fd, start[:, 1])
    last = first
    vr, vd = weights(ax[0], floor)[1], weights(ax[1], floor)[1]
    norm = np.sum(vr) * np.sum(vd)            # a tone of amplitude A projects to A norm
    for _ in range(RELAX_PASSES if len(offsets) > 1 else 0):
        # each row against the residual of every row's fitted tone, its own added back
        own = _Own(last.amp / norm, last.fr, last.fd, vr, vd, ax)
        last = _fit(_Samples(raw - own.model()), last.fr, last.fd, start, ax, own)
        ok &= last.j_to >= last.j_from
        fr, fd = np.where(ok, last.fr, fr), np.where(ok, last.fd, fd)
    return np.stack([fr - range_bin, fd - doppler_bin], axis=1)
