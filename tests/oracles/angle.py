"""Oracle of ``host.angle`` (the implementation the library replaced, kept only to test it
against): per-row RELAX over ``AngleParams.n_fft``-point FFTs (:func:`estimate_angles`,
:func:`peak_sin`: the definition), its batched forms, and the numpy versions of the fast
peak search and screened estimator whose compiled kernels are ``host._angle_peaks`` and
``host._angle_relax``. The batched forms also split a first component that sits between
two unresolved targets (:func:`split_pairs`, :func:`split_step`: ``host.angle`` module
docstring, "Two targets within a beamwidth"); the per-row :func:`estimate_angles` is RELAX
alone.

Virtual channel v at y = v lambda/2 sees exp(-j pi v sin(az)) (``model.simulate``), so the
steering vector is ``steering(n, s)`` and the angle spectrum is the inverse DFT over channels
(``model.reference.angle_spectrum``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import scipy.fft

from host._angle_peaks import COARSE_FFT, SECOND_LOBE, ZOOM_HALF
from host._angle_peaks import zoom_tables as _zoom_tables
from host._angle_relax import SPLIT_EXPLAINED, SPLIT_ITERATIONS, SPLIT_STRUCTURE
from host.angle import AngleArrays, AngleParams
from host.angle import _kept_components as kept_components
from model.reference import angle_spectrum


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
    k0 - 1, k0, k0 + 1): :func:`peak_sin`'s parabolic interpolation."""
    k = (k0 + n_fft // 2) % n_fft                  # index in the fftshift order
    den = a - 2 * b + c
    with np.errstate(divide="ignore", invalid="ignore"):
        delta = np.where(den < 0, 0.5 * (a - c) / np.where(den < 0, den, 1.0), 0.0)
    s = 2.0 * (k + delta - n_fft // 2) / n_fft
    return (s + 1.0) % 2.0 - 1.0


def peak_sin_fast(x: np.ndarray, n_fft: int) -> tuple[np.ndarray, np.ndarray]:
    """:func:`peak_sin_batch` through :func:`fine_peaks` (same grid maximum, same
    interpolation; differs only where another lobe is within the coarse grid's scalloping
    of the strongest): (sin(az) float (m,), |peak|^2 float (m,))."""
    k0, a, b, c = fine_peaks(x, n_fft)
    return _interpolated_sin(k0, a, b, c, n_fft), b * b


def peak_power_fast(x: np.ndarray, n_fft: int) -> tuple[np.ndarray, np.ndarray]:
    """:func:`peak_power_batch` through :func:`fine_peaks`, x complex (..., n): (peak
    power float (...), and the peak's sin(az) float (...) as :func:`peak_sin_fast`)."""
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
strongest angle-spectrum peak of each row: :func:`peak_sin_batch` (the ``n_fft``-point
FFT's), :func:`peak_sin_fast`, or the compiled ``host._angle_peaks.peak_sins``."""


Steering = Callable[[np.ndarray, int], np.ndarray]
"""A function (s float (m,), n) -> exp(-j pi v s), complex (m, n): :func:`_steering_rows`
or the compiled ``host._angle_peaks.peak_sins`` / ``host._angle_relax.steering_rows``."""


def _components(xs: np.ndarray, noise: np.ndarray, params: AngleParams, s1: np.ndarray,
                a1: np.ndarray, p1: np.ndarray, more: np.ndarray, batched: bool = False,
                peaks: PeakFinder | None = None, steer: Steering | None = None,
                relax: RowsEstimator | None = None) -> AngleArrays:
    """The :class:`AngleArrays` of rows xs (complex (n, n_ch)): the first component (sin
    s1, amplitude a1, power p1, float/complex (n,)) where ``more`` (bool (n,)) is False,
    :func:`estimate_angles` of the row where it is True (``batched``: of all those rows at
    once, :func:`estimate_angles_rows` with ``peaks`` and ``steer``, or ``relax``)."""
    n_rows, n = xs.shape
    snr1 = 10 * np.log10(np.maximum(p1, 1e-300) * n / noise)
    multi = np.flatnonzero(more)
    if not len(multi):
        return AngleArrays(np.arange(n_rows), s1, a1, snr1)
    cell: list = []
    sin_az: list = []
    amp: list = []
    snr: list = []
    if batched:
        got = relax(xs[multi], noise[multi], params) if relax else estimate_angles_rows(
            xs[multi], noise[multi], params, peaks, steer)
        cell, sin_az, amp, snr = multi[got.cell], got.sin_az, got.amplitude, got.snr_db
    else:
        for i in multi:
            for c in estimate_angles(xs[i], float(noise[i]), params):
                cell.append(i)
                sin_az.append(c.sin_az)
                amp.append(c.amplitude)
                snr.append(c.snr_db)
    single = np.flatnonzero(~more)
    cell_a = np.concatenate([single, np.array(cell, np.int64)])
    order = np.argsort(cell_a, kind="stable")
    return AngleArrays(cell_a[order], np.concatenate([s1[single], sin_az])[order],
                       np.concatenate([a1[single], np.array(amp, complex)])[order],
                       np.concatenate([snr1[single], snr])[order])


def _first_peaks(x: np.ndarray, noise_per_channel: np.ndarray, params: AngleParams,
                 first_sin: np.ndarray | None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(rows complex128 (n, n_ch), noise per channel >= 1e-30 float (n,), the rows'
    strongest peak sin(az) float (n,): ``first_sin`` or :func:`peak_sin_fast`)."""
    xs = np.asarray(x, dtype=np.complex128)
    noise = np.maximum(np.asarray(noise_per_channel, dtype=float), 1e-30)
    if not len(xs):
        return xs, noise, np.zeros(0)
    return xs, noise, peak_sin_fast(xs, params.n_fft)[0] if first_sin is None else first_sin


def _no_components() -> AngleArrays:
    z = np.zeros(0)
    return AngleArrays(np.zeros(0, np.int64), z, z.astype(complex), z)


def estimate_angles_fast(x: np.ndarray, noise_per_channel: np.ndarray, params: AngleParams,
                         first_sin: np.ndarray | None = None) -> AngleArrays:
    """:func:`estimate_angles_batch` as flat arrays, the angle peaks by :func:`fine_peaks`
    (no ``n_fft``-point FFT); rows with a second component go through
    :func:`estimate_angles` one by one, as there. ``first_sin``: float (n,) the rows'
    strongest peak (:func:`peak_sin_fast`) when the caller has it already."""
    xs, noise, s1 = _first_peaks(x, noise_per_channel, params, first_sin)
    if not len(xs):
        return _no_components()
    n_rows, n = xs.shape
    st1 = _steering_rows(s1, n)
    a1 = np.sum(np.conj(st1) * xs, axis=1) / n
    p1 = np.abs(a1) ** 2
    more = np.zeros(n_rows, bool)
    pairs = None
    if params.max_targets > 1:
        res = xs - a1[:, None] * st1
        s2, _ = peak_sin_fast(res, params.n_fft)
        st2 = _steering_rows(s2, n)
        a2 = np.sum(np.conj(st2) * res, axis=1) / n
        p2 = np.abs(a2) ** 2
        with np.errstate(divide="ignore"):
            gates = (10 * np.log10(p2 * n / noise) >= params.min_snr_db) & (
                10 * np.log10(p1 / np.maximum(p2, 1e-300)) <= params.dynamic_range_db)
        more = gates & beyond_model_error(p2, p1, noise, params)
        pairs = split_step(xs, noise, params, np.arange(n_rows), s1, a1, s2, a2,
                           gates & split_screen(res, st1, noise, params), more)
    got = _components(xs, noise, params, s1, a1, p1, more)
    return got if pairs is None or not len(pairs[0]) else _with_pairs(got, *pairs, noise, n)


def estimate_angles_screened(x: np.ndarray, noise_per_channel: np.ndarray, params: AngleParams,
                             first_sin: np.ndarray | None = None) -> AngleArrays:
    """:func:`estimate_angles_fast` (same components) with the search for a second
    component screened: the residual r after the first component can hold one only if its
    projection power p2 = |s^H r / n|^2 (|s_v| = 1) passes both gates, and by
    Cauchy-Schwarz p2 <= ||r||^2 / n; rows whose bound fails a gate (a strong single target:
    the residual is noise more than ``dynamic_range_db`` below it; or a weak residual) skip
    the residual's angle search, the others run it as there. Rows with several components
    go through :func:`estimate_angles_rows` (all at once) instead of one by one.

    x: complex (n, n_channels); noise_per_channel: float (n,); first_sin: float (n,) the
    rows' strongest peak (:func:`peak_sin_fast`) when the caller has it already."""
    xs, noise, s1 = _first_peaks(x, noise_per_channel, params, first_sin)
    if not len(xs):
        return _no_components()
    n_rows, n = xs.shape
    a1, p1, maybe, split = first_component_screen(xs, noise, params, s1)
    return screened_components(xs, noise, params, s1, a1, p1, maybe, split)


def split_screen(res: np.ndarray, st1: np.ndarray, noise: np.ndarray, params: AngleParams
                 ) -> np.ndarray:
    """The split screen of residuals res (complex (m, n)) after first components of
    steering st1 (complex (m, n)): the residual's energy in the directions q_k(v) st1_v,
    q_1, q_2 the discrete Legendre polynomials of degree 1 and 2 on v = 0..n-1 (the first
    component's derivatives), is at least ``SPLIT_STRUCTURE`` of its energy and reaches the
    coherent SNR gate; bool (m,) (False for n < 3)."""
    m, n = res.shape
    if n < 3:
        return np.zeros(m, bool)
    q1 = np.arange(n) - (n - 1) / 2
    q2 = q1 ** 2 - (n * n - 1) / 12
    y = np.conj(st1) * res
    es = np.abs(y @ q1) ** 2 / np.sum(q1 ** 2) + np.abs(y @ q2) ** 2 / np.sum(q2 ** 2)
    return (es >= SPLIT_STRUCTURE * np.sum(np.abs(res) ** 2, axis=1)) & (
        es >= 10 ** (params.min_snr_db / 10) * noise)


def first_component_screen(xs: np.ndarray, noise: np.ndarray, params: AngleParams,
                           s1: np.ndarray
                           ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The first half of :func:`estimate_angles_screened`: the first component of rows xs
    (complex128 (n, n_ch)) at sin s1 (float (n,)), amplitude a1 complex (n,) and power p1
    float (n,), and ``maybe`` bool (n,): the Cauchy-Schwarz bound of the residual leaves
    room for a second component (all False when ``params.max_targets`` is 1), and the
    :func:`split_screen` of the rows that pass the SNR and dynamic-range gates (bool (n,);
    those are in ``maybe`` too). noise: float (n,) per channel, >= 1e-30."""
    n = xs.shape[1]
    st1 = _steering_rows(s1, n)
    a1 = np.sum(np.conj(st1) * xs, axis=1) / n
    p1 = np.abs(a1) ** 2
    maybe = np.zeros(len(xs), bool)
    split = np.zeros(len(xs), bool)
    if params.max_targets > 1:
        res = xs - a1[:, None] * st1
        # upper bound of p2 (1e-9: far above the rounding of either side)
        bound = np.einsum("ij,ij->i", res.real, res.real) + np.einsum("ij,ij->i", res.imag,
                                                                       res.imag)
        bound *= (1.0 + 1e-9) / n
        with np.errstate(divide="ignore", invalid="ignore"):
            gates = (10 * np.log10(bound * n / noise) >= params.min_snr_db) & (
                10 * np.log10(p1 / np.maximum(bound, 1e-300)) <= params.dynamic_range_db)
        split = gates & split_screen(res, st1, noise, params)
        maybe = gates & beyond_model_error(bound, p1, noise, params) | split
    return a1, p1, maybe, split


def split_pairs(xs: np.ndarray, noise: np.ndarray, params: AngleParams, s_start: np.ndarray,
                a_start: np.ndarray, peaks: PeakFinder | None = None,
                steer: Steering | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The numpy ``host._angle_relax.split_rows`` (its definition): rows xs (complex
    (m, n)), noise float (m,), the starting pair (sin s_start float (m, 2), amplitude
    a_start complex (m, 2)) refined by ``SPLIT_ITERATIONS`` RELAX passes, kept where the
    weaker passes the SNR, dynamic-range and model-order gates against the stronger, the
    two are more than 0.5 / n apart and the pair removes ``SPLIT_EXPLAINED`` of the first
    component's residual energy beyond the noise. ``peaks``, ``steer``: as
    :func:`screened_components`. Returns (sin float (m, 2), amplitude complex (m, 2), kept
    bool (m,))."""
    find = peaks or peak_sin_fast
    steer_fn = steer or _steering_rows
    m, n = xs.shape
    s_c = np.array(s_start, dtype=float)
    a_c = np.array(a_start, dtype=complex)
    st = [steer_fn(s_c[:, 0], n), steer_fn(s_c[:, 1], n)]
    e1 = np.sum(np.abs(xs - a_c[:, :1] * st[0]) ** 2, axis=1)
    for _ in range(SPLIT_ITERATIONS):
        for j in range(2):
            r = xs - a_c[:, 1 - j, None] * st[1 - j]
            s_c[:, j], _ = find(r, params.n_fft)
            st[j] = steer_fn(s_c[:, j], n)
            a_c[:, j] = np.sum(np.conj(st[j]) * r, axis=1) / n
    e2 = np.sum(np.abs(xs - a_c[:, :1] * st[0] - a_c[:, 1:] * st[1]) ** 2, axis=1)
    pw = np.abs(a_c) ** 2
    big, small = pw.max(axis=1), pw.min(axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        kept = (10 * np.log10(small * n / noise) >= params.min_snr_db) & (
            10 * np.log10(big / small) <= params.dynamic_range_db) & \
            beyond_model_error(small, big, noise, params) & (
            np.abs(s_c[:, 0] - s_c[:, 1]) > 0.5 / n) & (
            e2 - n * noise <= (1.0 - SPLIT_EXPLAINED) * (e1 - n * noise))
    return s_c, a_c, kept


def screened_components(xs: np.ndarray, noise: np.ndarray, params: AngleParams,
                        s1: np.ndarray, a1: np.ndarray, p1: np.ndarray, maybe: np.ndarray,
                        splittable: np.ndarray, peaks: PeakFinder | None = None,
                        steer: Steering | None = None, relax: RowsEstimator | None = None
                        ) -> AngleArrays:
    """The second half of :func:`estimate_angles_screened`: rows xs (complex128 (n, n_ch))
    with their first component (sin s1, amplitude a1, power p1: float/complex (n,)) and the
    screens ``maybe`` and ``splittable`` (bool (n,), :func:`first_component_screen`); the
    rows that may hold a second component search their residual for it, and those that hold
    one go through :func:`estimate_angles_rows`. noise: float (n,) per channel, >= 1e-30.
    ``peaks``: the peak search of the residuals and of :func:`estimate_angles_rows`
    (default: the residual's :func:`peak_sin_fast`, and there the ``n_fft``-point FFT);
    ``steer``: the steering vectors (default :func:`_steering_rows`); ``relax``: the rows
    with several components through this instead (``host._angle_relax.relax_rows``)."""
    n = xs.shape[1]
    more = np.zeros(len(xs), bool)
    rows = np.flatnonzero(maybe)
    if params.max_targets > 1 and len(rows):
        steer_fn = steer or _steering_rows
        st1 = steer_fn(s1[rows], n)
        r = xs[rows] - a1[rows, None] * st1
        s2, _ = (peaks or peak_sin_fast)(r, params.n_fft)
        st2 = steer_fn(s2, n)
        a2 = np.sum(np.conj(st2) * r, axis=1) / n
        p2 = np.abs(a2) ** 2
        with np.errstate(divide="ignore"):
            gates = (10 * np.log10(p2 * n / noise[rows]) >= params.min_snr_db) & (
                10 * np.log10(p1[rows] / np.maximum(p2, 1e-300)) <= params.dynamic_range_db)
        more[rows] = gates & beyond_model_error(p2, p1[rows], noise[rows], params)
        # the first component between two unresolved targets: split it
        got = split_step(xs, noise, params, rows, s1, a1, s2, a2, gates & splittable[rows],
                         more[rows], peaks, steer)
        if len(got[0]):
            return _with_pairs(_components(xs, noise, params, s1, a1, p1, more, batched=True,
                                           peaks=peaks, steer=steer, relax=relax),
                               *got, noise, n)
    return _components(xs, noise, params, s1, a1, p1, more, batched=True, peaks=peaks,
                       steer=steer, relax=relax)


def split_step(xs: np.ndarray, noise: np.ndarray, params: AngleParams, rows: np.ndarray,
               s1: np.ndarray, a1: np.ndarray, s2: np.ndarray, a2: np.ndarray,
               gates: np.ndarray, more: np.ndarray, peaks: PeakFinder | None = None,
               steer: Steering | None = None
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The rows split by :func:`split_pairs` (``host.angle`` module docstring): of rows
    (int (k,)) of xs with first components s1, a1 (float/complex (n,)) and their
    residuals' peaks s2, a2 (float/complex (k,)), those whose peak passes the SNR and
    dynamic-range ``gates`` and the :func:`split_screen` (bool (k,)) but not the
    model-order test (``more``, bool (k,)) and reaches the noise, refined and kept: (rows
    int (j,), sin float (j, 2), amplitude complex (j, 2))."""
    cand = gates & ~more & (np.abs(a2) ** 2 >= noise[rows])
    c = rows[cand]
    if not len(c):
        return c, np.zeros((0, 2)), np.zeros((0, 2), complex)
    s_p, a_p, kept = split_pairs(xs[c], noise[c], params, np.stack([s1[c], s2[cand]], axis=1),
                                 np.stack([a1[c], a2[cand]], axis=1), peaks, steer)
    return c[kept], s_p[kept], a_p[kept]


def _with_pairs(got: AngleArrays, rows: np.ndarray, s_p: np.ndarray, a_p: np.ndarray,
                noise: np.ndarray, n: int) -> AngleArrays:
    """got with the single component of each of rows (int (k,)) replaced by the split pair
    (sin s_p float (k, 2), amplitude a_p complex (k, 2); ``kept_components`` order)."""
    pair = kept_components(s_p, a_p, np.full(len(rows), 2), noise[rows], n)
    keep = ~np.isin(got.cell, rows)
    cell = np.concatenate([got.cell[keep], rows[pair.cell]])
    order = np.argsort(cell, kind="stable")
    return AngleArrays(cell[order], *(np.concatenate([getattr(got, f)[keep],
                                                      getattr(pair, f)])[order]
                                      for f in ("sin_az", "amplitude", "snr_db")))


def estimate_angles_batch(x: np.ndarray, noise_per_channel: np.ndarray, params: AngleParams
                          ) -> list[list[AngleComponent]]:
    """:func:`estimate_angles` of every row of ``x``, complex (n, n_channels), with
    ``noise_per_channel`` float (n,): the first component of all rows and the test for a
    second one in two batched FFTs; only the rows that hold a second component (several
    targets in one cell, rare) go through :func:`estimate_angles` one by one."""
    xs = np.asarray(x, dtype=np.complex128)
    n_rows, n = xs.shape
    noise = np.maximum(np.asarray(noise_per_channel, dtype=float), 1e-30)
    if not n_rows:
        return []
    ch = np.arange(n)
    s1, _ = peak_sin_batch(xs, params.n_fft)
    st1 = np.exp(-1j * np.pi * s1[:, None] * ch[None, :])
    a1 = np.sum(np.conj(st1) * xs, axis=1) / n
    p1 = np.abs(a1) ** 2
    more = np.zeros(n_rows, bool)
    pairs: dict[int, list[AngleComponent]] = {}
    if params.max_targets > 1:
        res = xs - a1[:, None] * st1
        s2, _ = peak_sin_batch(res, params.n_fft)
        st2 = np.exp(-1j * np.pi * s2[:, None] * ch[None, :])
        a2 = np.sum(np.conj(st2) * res, axis=1) / n
        p2 = np.abs(a2) ** 2
        with np.errstate(divide="ignore"):
            gates = (10 * np.log10(p2 * n / noise) >= params.min_snr_db) & (
                10 * np.log10(p1 / np.maximum(p2, 1e-300)) <= params.dynamic_range_db)
        more = gates & beyond_model_error(p2, p1, noise, params)
        rows, s_p, a_p = split_step(xs, noise, params, np.arange(n_rows), s1, a1, s2, a2,
                                    gates & split_screen(res, st1, noise, params), more,
                                    peak_sin_batch, _steer)
        got = kept_components(s_p, a_p, np.full(len(rows), 2), noise[rows], n)
        for c, s_, a_, q in zip(rows[got.cell], got.sin_az, got.amplitude, got.snr_db,
                                strict=True):
            pairs.setdefault(int(c), []).append(AngleComponent(float(s_), complex(a_),
                                                               float(q)))
    snr1 = 10 * np.log10(np.maximum(p1, 1e-300) * n / noise)
    out: list[list[AngleComponent]] = []
    for i in range(n_rows):
        if i in pairs:
            out.append(pairs[i])
        elif more[i]:
            out.append(estimate_angles(xs[i], float(noise[i]), params))
        else:
            out.append([AngleComponent(float(s1[i]), complex(a1[i]), float(snr1[i]))])
    return out


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
    lobes are within the coarse grid's scalloping, :func:`fine_peaks`), with the
    steering vectors of ``steer`` (default :func:`_steering_rows`; equal to rounding).
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
