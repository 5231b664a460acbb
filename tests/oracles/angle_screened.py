"""Oracle of ``host._angle_relax`` and of ``host.angle.estimate_angles``' batched path:
the numpy batched and screened estimators its compiled kernels replaced
(:func:`estimate_angles_batch`, :func:`estimate_angles_fast`,
:func:`estimate_angles_screened` = :func:`first_component_screen` +
:func:`screened_components`) and the split of a first component that sits between two
unresolved targets (:func:`split_screen`, :func:`split_pairs`, :func:`split_step`:
``host.angle`` module docstring, "Two targets within a beamwidth"). Each gives the
components of ``tests.oracles.angle``'s per-row RELAX, with that split."""

from __future__ import annotations

import numpy as np

from host._angle_relax import SPLIT_EXPLAINED, SPLIT_ITERATIONS, SPLIT_STRUCTURE
from host.angle import AngleArrays, AngleParams
from host.angle import _kept_components as kept_components
from tests.oracles.angle import (
    AngleComponent,
    RowsEstimator,
    _steer,
    beyond_model_error,
    estimate_angles,
    estimate_angles_rows,
    peak_sin_batch,
)
from tests.oracles.angle_peaks import PeakFinder, Steering, _steering_rows, peak_sin_fast


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


def _residual_peak(xs: np.ndarray, a1: np.ndarray, st1: np.ndarray, noise: np.ndarray,
                   params: AngleParams, find: PeakFinder, steer: Steering
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The residual's strongest peak after the first component (amplitude a1 complex (n,),
    steering st1 complex (n, n_ch)) of rows xs (complex (n, n_ch)), found by ``find`` with
    steering vectors of ``steer``: (residual complex (n, n_ch), its peak's sin s2 float (n,)
    and amplitude a2 complex (n,), the SNR and dynamic-range ``gates`` bool (n,), and
    ``more`` bool (n,): the gates and the model-order test passed)."""
    n = xs.shape[1]
    p1 = np.abs(a1) ** 2
    res = xs - a1[:, None] * st1
    s2, _ = find(res, params.n_fft)
    st2 = steer(s2, n)
    a2 = np.sum(np.conj(st2) * res, axis=1) / n
    p2 = np.abs(a2) ** 2
    with np.errstate(divide="ignore"):
        gates = (10 * np.log10(p2 * n / noise) >= params.min_snr_db) & (
            10 * np.log10(p1 / np.maximum(p2, 1e-300)) <= params.dynamic_range_db)
    return res, s2, a2, gates, gates & beyond_model_error(p2, p1, noise, params)


def estimate_angles_fast(x: np.ndarray, noise_per_channel: np.ndarray, params: AngleParams,
                         first_sin: np.ndarray | None = None) -> AngleArrays:
    """:func:`estimate_angles_batch` as flat arrays, the angle peaks by
    ``tests.oracles.angle_peaks.fine_peaks`` (no ``n_fft``-point FFT); rows with a second
    component go through :func:`estimate_angles` one by one, as there. ``first_sin``: float
    (n,) the rows' strongest peak (:func:`peak_sin_fast`) when the caller has it already."""
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
        res, s2, a2, gates, more = _residual_peak(xs, a1, st1, noise, params, peak_sin_fast,
                                                  _steering_rows)
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


def _plane_waves(s: np.ndarray, n: int) -> np.ndarray:
    """exp(-j pi v s) for v = 0..n-1 of every s (float (m,)), complex (m, n), evaluated as
    :func:`estimate_angles_batch` always has (``_steer``'s values to rounding)."""
    return np.exp(-1j * np.pi * s[:, None] * np.arange(n)[None, :])


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
    s1, _ = peak_sin_batch(xs, params.n_fft)
    st1 = _plane_waves(s1, n)
    a1 = np.sum(np.conj(st1) * xs, axis=1) / n
    p1 = np.abs(a1) ** 2
    more = np.zeros(n_rows, bool)
    pairs: dict[int, list[AngleComponent]] = {}
    if params.max_targets > 1:
        res, s2, a2, gates, more = _residual_peak(xs, a1, st1, noise, params, peak_sin_batch,
                                                  _plane_waves)
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
