"""Oracle of ``host.angle`` (the implementation the library replaced, kept only to test it
against): per-row RELAX over ``AngleParams.n_fft``-point FFTs (:func:`estimate_angles`,
:func:`peak_sin`: the definition) and its form over all rows in step
(:func:`estimate_angles_rows`). Beside it: ``tests.oracles.angle_peaks``, the numpy fast peak
search whose compiled kernels are ``host._angle_peaks``; ``tests.oracles.angle_screened``,
the batched and screened estimators whose compiled kernels are ``host._angle_relax``, which
also split a first component that sits between two unresolved targets (``host.angle``
module docstring, "Two targets within a beamwidth"); the per-row :func:`estimate_angles`
is RELAX alone.

Virtual channel v at y = v lambda/2 sees exp(-j pi v sin(az)) (``model.simulate``), so the
steering vector is ``steering(n, s)`` and the angle spectrum is the inverse DFT over channels
(``model.reference.angle_spectrum``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from host.angle import AngleArrays, AngleParams
from host.angle import _kept_components as kept_components
from model.reference import angle_spectrum
from tests.oracles.angle_peaks import PeakFinder, Steering, _steering_rows


@dataclass(frozen=True)
class AngleComponent:
    """One target in a cell: sin(az), per-channel complex amplitude (cube units), coherent
    SNR in dB (|a|^2 n / noise_per_channel)."""

    sin_az: float
    amplitude: complex
    snr_db: float

    @property
    def azimuth_deg(self) -> float:
        return float(np.degrees(np.arcsin(np.clip(self.sin_az, -1.0, 1.0))))


def steering(n: int, sin_az: float) -> np.ndarray:
    """Steering vector of an n-channel lambda/2 ULA, complex (n,)."""
    return np.exp(-1j * np.pi * np.arange(n) * sin_az)


def beyond_model_error(power: np.ndarray | float, held: np.ndarray | float,
                       noise: np.ndarray | float, params: AngleParams) -> np.ndarray:
    """The model-order test (``host.angle`` module docstring): a further component of power
    |a|^2 (``power``) is supported where it reaches noise + 10^(array_error_db / 10) times
    ``held``, the power sum_j |a_j|^2 of the components already held (per channel, float
    arrays or scalars); bool of the broadcast shape."""
    return np.asarray(power) >= np.asarray(noise) + 10 ** (params.array_error_db / 10) * \
        np.asarray(held)


def peak_sin(x: np.ndarray, n_fft: int) -> tuple[float, float]:
    """Strongest peak of the angle spectrum of ``x`` (complex (n,)): (sin(az), |peak|^2),
    parabolic interpolation of the magnitude around the zero-padded FFT maximum."""
    spec, _ = angle_spectrum(x, n_fft=n_fft)
    mag = np.abs(spec)
    k = int(np.argmax(mag))
    a, b, c = mag[(k - 1) % n_fft], mag[k], mag[(k + 1) % n_fft]
    den = a - 2 * b + c
    delta = 0.5 * (a - c) / den if den < 0 else 0.0
    s = 2.0 * (k + delta - n_fft // 2) / n_fft
    s = (s + 1.0) % 2.0 - 1.0  # wrap into [-1, 1)
    return float(s), float(b * b)


def peak_power(x: np.ndarray, n_fft: int) -> float:
    """Largest |angle spectrum|^2 of ``x`` (for comparing TDM hypotheses)."""
    spec, _ = angle_spectrum(x, n_fft=n_fft)
    return float(np.max(np.abs(spec) ** 2))


def _spectrum_unshifted(x: np.ndarray, n_fft: int) -> np.ndarray:
    """The angle spectrum of ``model.reference.angle_spectrum`` over the last axis of x,
    complex (..., n_fft), *without* its fftshift (a permutation: bin k here is bin
    (k + n_fft/2) mod n_fft there), which costs as much as the FFT on large batches."""
    return np.fft.ifft(x, n=n_fft, axis=-1) * n_fft


def peak_sin_batch(x: np.ndarray, n_fft: int) -> tuple[np.ndarray, np.ndarray]:
    """:func:`peak_sin` of every row of ``x``, complex (n, n_channels): (sin(az) float (n,),
    |peak|^2 float (n,)), one batched FFT."""
    mag = np.abs(_spectrum_unshifted(x, n_fft))
    k0 = np.argmax(mag, axis=-1)
    rows = np.arange(len(k0))
    a, b, c = mag[rows, (k0 - 1) % n_fft], mag[rows, k0], mag[rows, (k0 + 1) % n_fft]
    k = (k0 + n_fft // 2) % n_fft                  # index in the fftshift order
    den = a - 2 * b + c
    with np.errstate(divide="ignore", invalid="ignore"):
        delta = np.where(den < 0, 0.5 * (a - c) / np.where(den < 0, den, 1.0), 0.0)
    s = 2.0 * (k + delta - n_fft // 2) / n_fft
    return (s + 1.0) % 2.0 - 1.0, b * b


def peak_power_batch(x: np.ndarray, n_fft: int) -> np.ndarray:
    """:func:`peak_power` over the last axis of ``x``, complex (..., n_channels): float (...)."""
    return np.max(np.abs(_spectrum_unshifted(x, n_fft)) ** 2, axis=-1)



def _steer(s: np.ndarray, n: int) -> np.ndarray:
    """:func:`steering` of every s (float (m,)), complex (m, n), the same expression."""
    return np.exp((-1j * np.pi * np.arange(n))[None, :] * s[:, None])


def estimate_angles_rows(x: np.ndarray, noise_per_channel: np.ndarray, params: AngleParams,
                         peaks: PeakFinder | None = None, steer: Steering | None = None
                         ) -> AngleArrays:
    """:func:`estimate_angles` of every row of x, complex (m, n), noise_per_channel float
    (m,), run on all rows in step (the same components: the same peaks, from the batched
    ``n_fft``-point FFT of :func:`peak_sin_batch`, the same gates, refinement passes in
    the same order and the same de-duplication), as flat :class:`AngleArrays`.

    ``peaks``: another peak search (:data:`PeakFinder`; e.g. the compiled
    ``host._angle_peaks.peak_sins``, the same fine-grid maximum as the FFT's unless two
    lobes are within the coarse grid's scalloping, ``tests.oracles.angle_peaks.
    fine_peaks``), with the steering vectors of ``steer`` (default :func:`_steering_rows`;
    equal to rounding).
    Without ``peaks``, :func:`_steer` (the same expression as :func:`steering`)."""
    find = peaks or peak_sin_batch
    steer = _steer if peaks is None else (steer or _steering_rows)
    xs = np.asarray(x, dtype=np.complex128)
    m, n = xs.shape
    noise = np.maximum(np.asarray(noise_per_channel, dtype=float), 1e-30)
    kmax = params.max_targets
    s_c = np.zeros((m, kmax))
    a_c = np.zeros((m, kmax), complex)
    st_c = np.zeros((m, kmax, n), complex)  # steer(s_c): each computed once per estimate
    count = np.zeros(m, np.int64)
    first = np.zeros(m)
    residual = xs.copy()
    live = np.arange(m)                     # rows still adding components, all with t comps
    with np.errstate(divide="ignore", invalid="ignore"):
        for t in range(kmax):
            if not len(live):
                break
            s, _ = find(residual[live], params.n_fft)
            st = steer(s, n)
            a = np.sum(np.conj(st) * residual[live], axis=1) / n
            power = np.abs(a) ** 2
            snr_db = 10 * np.log10(power * n / noise[live])
            stop = np.zeros(len(live), bool)
            if t:
                held = np.sum(np.abs(a_c[live, :t]) ** 2, axis=1)
                stop = (snr_db < params.min_snr_db) | (
                    10 * np.log10(first[live] / power) > params.dynamic_range_db) | \
                    ~beyond_model_error(power, held, noise[live], params)
            keep = ~stop
            live, s, a, power = live[keep], s[keep], a[keep], power[keep]
            s_c[live, t], a_c[live, t], st_c[live, t] = s, a, st[keep]
            count[live] = t + 1
            first[live] = np.where(first[live] != 0, first[live], power)
            if t:
                xl = xs[live]
                stl = st_c[live, :t + 1]            # (live, t + 1, n), kept in step below
                for _ in range(params.refine_iterations):
                    for j in range(t + 1):
                        others = np.zeros((len(live), n), complex)
                        for i in range(t + 1):
                            if i != j:
                                others = others + a_c[live, i][:, None] * stl[:, i]
                        r = xl - others
                        sj, _ = find(r, params.n_fft)
                        s_c[live, j] = sj
                        stl[:, j] = steer(sj, n)
                        a_c[live, j] = np.sum(np.conj(stl[:, j]) * r, axis=1) / n
                st_c[live, :t + 1] = stl
            total = np.zeros((len(live), n), complex)
            for i in range(t + 1):
                total = total + a_c[live, i][:, None] * st_c[live, i]
            residual[live] = xs[live] - total
    return kept_components(s_c, a_c, count, noise, n)


RowsEstimator = Callable[[np.ndarray, np.ndarray, AngleParams], AngleArrays]
"""A function (x complex (m, n), noise_per_channel float (m,), params) -> the
:class:`AngleArrays` of :func:`estimate_angles_rows`: that function with its default peak
search, or the compiled ``host._angle_relax.relax_rows``."""


def estimate_angles(x: np.ndarray, noise_per_channel: float, params: AngleParams
                    ) -> list[AngleComponent]:
    """Components (targets) in one cell's TDM-compensated channel vector x, complex (n,).

    ``noise_per_channel``: noise power per channel in the same units as |x|^2. Components are
    found strongest first; the first is always returned, each further one while its
    coherent SNR reaches ``min_snr_db``, it is within ``dynamic_range_db`` of the first and
    it passes the model-order test (:func:`beyond_model_error`) against those held.
    """
    n = x.shape[0]
    noise = max(noise_per_channel, 1e-30)
    comps: list[tuple[float, complex]] = []
    residual = x.astype(np.complex128)
    first_power = None
    for _ in range(params.max_targets):
        s, _ = peak_sin(residual, params.n_fft)
        a = complex(np.vdot(steering(n, s), residual) / n)
        power = abs(a) ** 2
        snr_db = 10 * np.log10(power * n / noise)
        if comps and snr_db < params.min_snr_db:
            break
        if first_power is not None and 10 * np.log10(first_power / power) > \
                params.dynamic_range_db:
            break
        if comps and not beyond_model_error(power, sum(abs(a_) ** 2 for _, a_ in comps),
                                            noise, params):
            break
        comps.append((s, a))
        first_power = first_power or power
        if len(comps) > 1:
            for _ in range(params.refine_iterations):
                for j in range(len(comps)):
                    others = sum((ai * steering(n, si) for i, (si, ai) in enumerate(comps)
                                  if i != j), np.zeros(n, complex))
                    r = x - others
                    sj, _ = peak_sin(r, params.n_fft)
                    comps[j] = (sj, complex(np.vdot(steering(n, sj), r) / n))
        residual = x - sum((a_ * steering(n, s_) for s_, a_ in comps), np.zeros(n, complex))
    out = [AngleComponent(s, a, float(10 * np.log10(abs(a) ** 2 * n / noise)))
           for s, a in comps]
    # drop components that collapsed onto another during refinement
    unique: list[AngleComponent] = []
    for c in sorted(out, key=lambda c: -abs(c.amplitude)):
        if all(abs(c.sin_az - u.sin_az) > 0.5 / n for u in unique):
            unique.append(c)
    return unique
