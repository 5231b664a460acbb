"""Private backend of ``host.angle``: compiled steering vectors, first angle components with
the screen for a second one, and RELAX on the rows that hold several.

- :func:`first_components`: each row's TDM-compensated vector, the amplitude and power of
  its first component at a given sin(az), and the Cauchy-Schwarz screen: the residual r
  after the first component can hold a second one only if |s^H r / n|^2 <= ||r||^2 / n
  (|s_v| = 1) passes the three gates of ``host.angle.AngleParams`` (SNR, dynamic range,
  model order: ``host.angle`` module docstring); and the split screen: a residual whose
  energy lies mostly in the first component's derivative directions (:data:`SPLIT_STRUCTURE`)
  may be two unresolved targets the first component sits between (:func:`split_rows`).
- :func:`steering_rows`: exp(-j pi v s) per row, from two sines and cosines per row.
- :func:`relax_rows`: RELAX-style sequential estimation (``host.angle`` module docstring),
  every pass's batch of rows through the peak search of ``host._angle_peaks``.
- :func:`split_rows`: two components refined from the first and the residual's peak, kept
  where the refined pair passes the gates and explains the residual (``host.angle``
  module docstring, "Two targets within a beamwidth").

The numpy implementations these replaced are the oracles in ``tests/oracles/angle_screened.py``
(RELAX in step over rows: ``tests/oracles/angle.py``).
"""

from __future__ import annotations

import math

import numpy as np

from host._angle_peaks import COARSE_FFT, SECOND_LOBE, _c128, _class_peaks, _tables
from host.kernels import njit, warm_up

SPLIT_ITERATIONS = 8
"""RELAX passes of :func:`split_rows` (a first component midway between two targets moves
to one of them in a few passes; 2, the default ``refine_iterations``, often stop short)."""
SPLIT_STRUCTURE = 0.5
"""A row may be split only when at least this fraction of its residual's energy lies in
the first component's first two derivative directions (the residual of two targets the
first component sits between; a model error's residue spreads over n - 1 dimensions:
``host.angle`` module docstring), and that part reaches the SNR gate."""
SPLIT_EXPLAINED = 0.75
"""A split is kept only when the pair removes at least this fraction of the first
component's residual energy beyond the noise (``host.angle`` module docstring)."""


@njit(fastmath=True)
def _steer_row(s: float, str_: np.ndarray, sti: np.ndarray, lor: np.ndarray,
               loi: np.ndarray) -> None:
    """exp(-j pi v s) for v = 0..n-1 into str_, sti (float (n,)), as
    v = q b0 + p with b0 = len(lor) = ceil(sqrt(n)), the
    products of powers of exp(-j pi s) and of exp(-j pi b0 s) (two sines and cosines; the
    powers are a few ulp off the exponentials). lor, loi (b0,): scratch."""
    nv = str_.shape[0]
    b0 = lor.shape[0]
    c1 = math.cos(math.pi * s)
    d1 = -math.sin(math.pi * s)
    cb = math.cos(math.pi * b0 * s)
    db = -math.sin(math.pi * b0 * s)
    lor[0] = 1.0
    loi[0] = 0.0
    for p in range(1, b0):
        lor[p] = lor[p - 1] * c1 - loi[p - 1] * d1
        loi[p] = lor[p - 1] * d1 + loi[p - 1] * c1
    hr = 1.0
    hi = 0.0
    for q in range(-(-nv // b0)):
        if q:
            hr, hi = hr * cb - hi * db, hr * db + hi * cb
        for p in range(b0):
            v = q * b0 + p
            if v < nv:
                str_[v] = hr * lor[p] - hi * loi[p]
                sti[v] = hr * loi[p] + hi * lor[p]


@njit(fastmath=True)
def _scratch(n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Scratch of :func:`_steer_row` for n channels: str_, sti float (n,), lor, loi float
    (ceil(sqrt(n)),)."""
    b0 = int(math.ceil(math.sqrt(n)))
    return np.empty(n), np.empty(n), np.empty(b0), np.empty(b0)


@njit(fastmath=True)
def _steering(s: np.ndarray, out: np.ndarray) -> None:
    """:func:`steering_rows` into out (complex128 (m, n))."""
    m, n = out.shape
    str_, sti, lor, loi = _scratch(n)
    for i in range(m):
        _steer_row(s[i], str_, sti, lor, loi)
        for v in range(n):
            out[i, v] = complex(str_[v], sti[v])


def steering_rows(s: np.ndarray, n: int) -> np.ndarray:
    """exp(-j pi v s) for v = 0..n-1 of every s (float (m,)), complex (m, n) (equal to
    the exponentials to rounding)."""
    s = np.ascontiguousarray(s, dtype=float)
    out = np.empty((len(s), n), np.complex128)
    if len(s):
        _steering(s, out)
    return out


@njit(fastmath=True)
def _first_components(x: np.ndarray, ph: np.ndarray, s1: np.ndarray, noise: np.ndarray,
                      snr_lin: float, dyn_lin: float, err_lin: float, screen: bool,
                      out: np.ndarray, a1: np.ndarray, p1: np.ndarray, maybe: np.ndarray,
                      split: np.ndarray) -> None:
    """:func:`first_components` (x, ph, out complex128; snr_lin, dyn_lin, err_lin: the
    gates as power ratios)."""
    n_rows, nv = x.shape
    ntx = ph.shape[1]
    nrx = nv // ntx
    str_, sti, lor, loi = _scratch(nv)
    outr = np.empty(nv)
    outi = np.empty(nv)
    c1 = (nv - 1) / 2.0
    c2 = (nv * nv - 1) / 12.0
    n1 = max(nv * (nv * nv - 1) / 12.0, 1e-300)
    n2 = max(nv * (nv * nv - 1) * (nv * nv - 4) / 180.0, 1e-300)
    for i in range(n_rows):
        for t in range(ntx):
            pr = ph[i, t].real
            pi = ph[i, t].imag
            for r in range(nrx):
                v = t * nrx + r
                xr = x[i, v].real
                xi = x[i, v].imag
                outr[v] = xr * pr - xi * pi
                outi[v] = xr * pi + xi * pr
                out[i, v] = complex(outr[v], outi[v])
        _steer_row(s1[i], str_, sti, lor, loi)
        sr = 0.0
        si = 0.0
        for v in range(nv):     # conj(st) . x, as _project but on the split row (25 % faster)
            sr += str_[v] * outr[v] + sti[v] * outi[v]
            si += str_[v] * outi[v] - sti[v] * outr[v]
        ar = sr / nv
        ai = si / nv
        a1[i] = complex(ar, ai)
        p1[i] = ar * ar + ai * ai
        if screen:
            e = 0.0
            d1r = 0.0               # conj(st) q_k(v) . r, q_k the discrete Legendre
            d1i = 0.0               # polynomials of degree 1, 2 on v = 0..nv-1
            d2r = 0.0
            d2i = 0.0
            for v in range(nv):
                rr = outr[v] - (ar * str_[v] - ai * sti[v])
                ri = outi[v] - (ar * sti[v] + ai * str_[v])
                e += rr * rr + ri * ri
                q1 = v - c1
                q2 = q1 * q1 - c2
                pr = str_[v] * rr + sti[v] * ri
                pi = str_[v] * ri - sti[v] * rr
                d1r += q1 * pr
                d1i += q1 * pi
                d2r += q2 * pr
                d2i += q2 * pi
            bound = e * (1.0 + 1e-9) / nv
            gates = (bound * nv >= snr_lin * noise[i]) and (
                p1[i] <= dyn_lin * max(bound, 1e-300))
            maybe[i] = gates and (bound >= noise[i] + err_lin * p1[i])
            if gates and nv >= 3:
                es = (d1r * d1r + d1i * d1i) / n1 + (d2r * d2r + d2i * d2i) / n2
                split[i] = (es >= SPLIT_STRUCTURE * e) and (es >= snr_lin * noise[i])
                maybe[i] = maybe[i] or split[i]



def first_components(x: np.ndarray, phasors: np.ndarray, first_sin: np.ndarray,
                     noise_per_channel: np.ndarray, min_snr_db: float,
                     dynamic_range_db: float, array_error_db: float, screen: bool = True
                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The first angle component of each TDM-compensated snapshot and the screen for a
    second (module docstring):
    (compensated rows complex128 (n, n_v), amplitude a1 complex (n,), power |a1|^2 float
    (n,), ``maybe`` bool (n,): the row may hold a second component, ``split`` bool (n,):
    it may be two targets the first component sits between (the split screen)).

    x: complex (n, num_tx * num_rx); phasors: complex (n, num_tx) per TX
    (``host.tdm.tx_phasors``); first_sin: float (n,) sin(az) of the row's peak;
    noise_per_channel: float (n,) (clamped to >= 1e-30 as there); min_snr_db,
    dynamic_range_db, array_error_db: the gates of ``host.angle.AngleParams``; ``screen``
    False: no second-component screen (``maybe`` all False)."""
    n = len(x)
    if x.ndim != 2 or phasors.shape[0] != n or x.shape[1] % max(phasors.shape[1], 1):
        raise ValueError(f"first_components: snapshots {x.shape}, phasors {phasors.shape}")
    out = np.empty(x.shape, np.complex128)
    a1, p1, maybe = np.zeros(n, complex), np.zeros(n), np.zeros(n, bool)
    split = np.zeros(n, bool)
    noise = np.maximum(np.asarray(noise_per_channel, dtype=float), 1e-30)
    if n:
        _first_components(_c128(x), _c128(phasors),
                          np.ascontiguousarray(first_sin, dtype=float),
                          noise, 10 ** (min_snr_db / 10), 10 ** (dynamic_range_db / 10),
                          10 ** (array_error_db / 10), screen, out, a1, p1, maybe, split)
    return out, a1, p1, maybe, split



@njit(fastmath=True)
def _project(s: float, row: np.ndarray, str_: np.ndarray, sti: np.ndarray, lor: np.ndarray,
             loi: np.ndarray) -> complex:
    """The amplitude conj(st) . row / n of the component at sin(az) s in row (complex (n,)),
    its steering vector st left in str_, sti (:func:`_steer_row`; lor, loi: scratch)."""
    n = row.shape[0]
    _steer_row(s, str_, sti, lor, loi)
    ar = 0.0
    ai = 0.0
    for v in range(n):
        xr = row[v].real
        xi = row[v].imag
        ar += str_[v] * xr + sti[v] * xi
        ai += str_[v] * xi - sti[v] * xr
    return complex(ar / n, ai / n)


@njit(fastmath=True, error_model="numpy")
def _relax(xs: np.ndarray, noise: np.ndarray, refine: int, min_snr_db: float,
           dyn_db: float, err_lin: float, n_fft: int, second_lobe: float, wr: np.ndarray,
           wi: np.ndarray, rank: np.ndarray, dmr: np.ndarray, dmi: np.ndarray, oc: np.ndarray,
           os_: np.ndarray, s_c: np.ndarray, a_c: np.ndarray, count: np.ndarray) -> None:
    """:func:`relax_rows` into s_c, a_c, count (float, complex (m, k), int (m,); zeros
    in): RELAX's passes, the peak search of each batch of
    live rows by :func:`_class_peaks` (unit phasors), steering by :func:`_steer_row`;
    err_lin: the array-error floor as a power ratio."""
    m, n = xs.shape
    kmax = s_c.shape[1]
    str_, sti, lor, loi = _scratch(n)
    st_c = np.zeros((m, kmax, n), np.complex128)    # steering of s_c, once per estimate
    first = np.zeros(m)
    residual = xs.copy()
    batch = np.empty((m, n), np.complex128)
    rows = np.arange(m)
    ones = np.ones((m, 1), np.complex128)
    out_pow = np.empty(m)
    out_sin = np.empty(m)
    live = np.arange(m)                  # rows still adding components, all with t comps
    nl = m
    for t in range(kmax):
        if nl == 0:
            break
        for p in range(nl):
            batch[p] = residual[live[p]]
        _class_peaks(batch[:nl], rows[:nl], ones[:nl], n_fft, second_lobe, wr, wi, rank,
                     dmr, dmi, oc, os_, out_pow[:nl], out_sin[:nl])
        kept = 0
        for p in range(nl):
            i = live[p]
            s = out_sin[p]
            a = _project(s, residual[i], str_, sti, lor, loi)
            power = a.real * a.real + a.imag * a.imag
            if t:
                snr_db = 10 * np.log10(power * n / noise[i])
                if snr_db < min_snr_db or 10 * np.log10(first[i] / power) > dyn_db:
                    continue
                held = 0.0                  # the model order: beyond noise and array error
                for q in range(t):
                    held += a_c[i, q].real ** 2 + a_c[i, q].imag ** 2
                if power < noise[i] + err_lin * held:
                    continue
            s_c[i, t] = s
            a_c[i, t] = a
            for v in range(n):
                st_c[i, t, v] = complex(str_[v], sti[v])
            count[i] = t + 1
            if first[i] == 0:
                first[i] = power
            live[kept] = i
            kept += 1
        nl = kept
        if t:
            for _ in range(refine):
                for j in range(t + 1):
                    for p in range(nl):      # the row without the other components
                        i = live[p]
                        for v in range(n):
                            o = 0j
                            for q in range(t + 1):
                                if q != j:
                                    o += a_c[i, q] * st_c[i, q, v]
                            batch[p, v] = xs[i, v] - o
                    _class_peaks(batch[:nl], rows[:nl], ones[:nl], n_fft, second_lobe, wr,
                                 wi, rank, dmr, dmi, oc, os_, out_pow[:nl], out_sin[:nl])
                    for p in range(nl):
                        i = live[p]
                        s_c[i, j] = out_sin[p]
                        a_c[i, j] = _project(out_sin[p], batch[p], str_, sti, lor, loi)
                        for v in range(n):
                            st_c[i, j, v] = complex(str_[v], sti[v])
        for p in range(nl):
            i = live[p]
            for v in range(n):
                tot = 0j
                for q in range(t + 1):
                    tot += a_c[i, q] * st_c[i, q, v]
                residual[i, v] = xs[i, v] - tot


def relax_rows(x: np.ndarray, noise: np.ndarray, n_fft: int, max_targets: int,
               refine_iterations: int, min_snr_db: float, dynamic_range_db: float,
               array_error_db: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """RELAX on the rows of x, complex (m, n) (TDM-compensated), noise float (m,) per
    channel (>= 1e-30): components found strongest first, each further one while its
    coherent SNR reaches ``min_snr_db``, it is within ``dynamic_range_db`` of the first and
    its power |a|^2 reaches noise + 10^(array_error_db / 10) sum |a_j|^2 over the components
    held (the model-order test, ``host.angle`` module docstring), every component
    re-estimated ``refine_iterations`` times with the others removed
    (``host.angle.AngleParams``). Returns (sin(az) float (m, max_targets), amplitude complex
    (m, max_targets), count int (m,): the first count slots of each row are valid)."""
    xs = _c128(x)
    m, n = xs.shape
    if noise.shape != (m,):
        raise ValueError(f"relax_rows: {m} rows, noise {noise.shape}")
    if n > min(COARSE_FFT, n_fft):
        raise ValueError(f"relax_rows: {n} channels exceed the coarse FFT "
                         f"({min(COARSE_FFT, n_fft)})")
    s_c = np.zeros((m, max_targets))
    a_c = np.zeros((m, max_targets), np.complex128)
    count = np.zeros(m, np.int64)
    if m:
        wr, wi, rank, dmr, dmi, oc, os_ = _tables(n, n_fft)
        _relax(xs, np.ascontiguousarray(noise, dtype=float), refine_iterations, min_snr_db,
               dynamic_range_db, 10 ** (array_error_db / 10), n_fft, SECOND_LOBE, wr, wi, rank,
               dmr, dmi, oc, os_, s_c, a_c, count)
    return s_c, a_c, count


@njit(fastmath=True, error_model="numpy")
def _split(xs: np.ndarray, noise: np.ndarray, e1: np.ndarray, iters: int, snr_lin: float,
           dyn_lin: float, err_lin: float, n_fft: int, second_lobe: float, wr: np.ndarray,
           wi: np.ndarray, rank: np.ndarray, dmr: np.ndarray, dmi: np.ndarray, oc: np.ndarray,
           os_: np.ndarray, s_c: np.ndarray, a_c: np.ndarray, keep: np.ndarray) -> None:
    """:func:`split_rows` into s_c, a_c (float, complex (m, 2): the starting pair in) and
    keep (bool (m,)); snr_lin, dyn_lin, err_lin: the gates as power ratios."""
    m, n = xs.shape
    str_, sti, lor, loi = _scratch(n)
    st_c = np.zeros((m, 2, n), np.complex128)
    for i in range(m):
        for j in range(2):
            _steer_row(s_c[i, j], str_, sti, lor, loi)
            for v in range(n):
                st_c[i, j, v] = complex(str_[v], sti[v])
    batch = np.empty((m, n), np.complex128)
    rows = np.arange(m)
    ones = np.ones((m, 1), np.complex128)
    out_pow = np.empty(m)
    out_sin = np.empty(m)
    for _ in range(iters):
        for j in range(2):
            for i in range(m):              # the row without the other component
                for v in range(n):
                    batch[i, v] = xs[i, v] - a_c[i, 1 - j] * st_c[i, 1 - j, v]
            _class_peaks(batch, rows, ones, n_fft, second_lobe, wr, wi, rank, dmr, dmi, oc,
                         os_, out_pow, out_sin)
            for i in range(m):
                s_c[i, j] = out_sin[i]
                a_c[i, j] = _project(out_sin[i], batch[i], str_, sti, lor, loi)
                for v in range(n):
                    st_c[i, j, v] = complex(str_[v], sti[v])
    for i in range(m):
        e2 = 0.0
        for v in range(n):
            r = xs[i, v] - a_c[i, 0] * st_c[i, 0, v] - a_c[i, 1] * st_c[i, 1, v]
            e2 += r.real * r.real + r.imag * r.imag
        pa = a_c[i, 0].real ** 2 + a_c[i, 0].imag ** 2
        pb = a_c[i, 1].real ** 2 + a_c[i, 1].imag ** 2
        big = max(pa, pb)
        small = min(pa, pb)
        floor = n * noise[i]
        keep[i] = (small * n >= snr_lin * noise[i]) and (big <= dyn_lin * small) and (
            small >= noise[i] + err_lin * big) and (
            abs(s_c[i, 0] - s_c[i, 1]) > 0.5 / n) and (
            e2 - floor <= (1.0 - SPLIT_EXPLAINED) * (e1[i] - floor))


def split_rows(x: np.ndarray, noise: np.ndarray, s_start: np.ndarray, a_start: np.ndarray,
               n_fft: int, min_snr_db: float, dynamic_range_db: float, array_error_db: float
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Two components of each row of x (complex (m, n), TDM-compensated; noise float (m,)
    per channel, >= 1e-30), refined by :data:`SPLIT_ITERATIONS` RELAX passes from the
    starting pair (sin s_start float (m, 2), amplitude a_start complex (m, 2): the first
    component and the peak of its residual). Kept (``host.angle`` module docstring) where
    the weaker reaches the coherent SNR ``min_snr_db``, is within ``dynamic_range_db`` of
    the stronger, passes the model-order test against it (|a|^2 >= noise +
    10^(array_error_db / 10) |a_strong|^2), the two are more than 0.5 / n apart in sin(az),
    and the pair leaves at most 1 - :data:`SPLIT_EXPLAINED` of the first component's
    residual energy beyond the noise n N. Returns (sin(az) float (m, 2), amplitude
    complex (m, 2), kept bool (m,))."""
    xs = _c128(x)
    m, n = xs.shape
    s_c = np.array(s_start, dtype=float, order="C")
    a_c = np.array(a_start, dtype=np.complex128, order="C")
    if noise.shape != (m,) or s_c.shape != (m, 2) or a_c.shape != (m, 2):
        raise ValueError(f"split_rows: {m} rows, noise {noise.shape}, start {s_c.shape}")
    keep = np.zeros(m, bool)
    if m:
        ns = np.ascontiguousarray(noise, dtype=float)
        e1 = np.sum(np.abs(xs - a_c[:, :1] * steering_rows(s_c[:, 0], n)) ** 2, axis=1)
        wr, wi, rank, dmr, dmi, oc, os_ = _tables(n, n_fft)
        _split(xs, ns, e1, SPLIT_ITERATIONS, 10 ** (min_snr_db / 10),
               10 ** (dynamic_range_db / 10), 10 ** (array_error_db / 10), n_fft, SECOND_LOBE,
               wr, wi, rank, dmr, dmi, oc, os_, s_c, a_c, keep)
    return s_c, a_c, keep


@warm_up
def _warm_up() -> None:
    """RELAX and the steering rows (reached only by cells with several targets) on one row:
    the argument types of ``host.angle`` and its default ``AngleParams``."""
    steering_rows(np.zeros(1), 8)
    relax_rows(np.zeros((1, 8), np.complex128), np.ones(1), 1024, 3, 2, 12.0, 20.0, -10.0)
    split_rows(np.zeros((1, 8), np.complex128), np.ones(1), np.zeros((1, 2)),
               np.zeros((1, 2), np.complex128), 1024, 12.0, 20.0, -10.0)
