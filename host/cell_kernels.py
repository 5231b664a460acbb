"""Compiled (numba) kernels of the per-cell work of the records -> point cloud path
(``host.record_points.points_from_snapshots``): the same results as the numpy functions
named below, without numpy's per-call overhead and temporaries, one pass per cell.

- :func:`class_peaks`: the TDM alias classes' angle peaks, ``host.angle.peak_power_lean``
  of ``host.pipeline._tdm_compensate``'d snapshots. The coarse angle FFT (single
  precision, as there) runs on blocks of (cell, class) pairs at once, the pairs in the
  innermost loop (vectorised over the block); the fine-grid search (double precision)
  runs per pair.
- :func:`first_components`: the TDM-compensated vector of each cell's chosen class, its
  first angle component's amplitude and power, and the Cauchy-Schwarz screen for a second
  one (the first half of ``host.angle.estimate_angles_screened``).
- :func:`peak_sins`, :func:`steering_rows`: the peak search and steering vectors of RELAX
  (``host.angle.estimate_angles_rows``) and of the residual search.
- :func:`relax_rows`: RELAX itself (``host.angle.estimate_angles_rows`` with those two),
  every pass's batch of rows through the :func:`class_peaks` machinery.
- :func:`fold_decisions`: the velocity-unfolding decision of every cell
  (``host.pipeline.choose_folds``, the per-cell ``_choose_fold``; both paths use it).

Floating-point sums run in a different order than numpy's (and ``fastmath`` lets the
compiler reorder them): results agree to rounding; a decision that rests on an exact tie
(two equal spectrum values) may go the other way. The first call compiles the kernels
(20-30 s; cached in ``__pycache__`` for the next process, which loads them in 0.5 s).
"""

from __future__ import annotations

import math
import os

import numba
import numpy as np

from host.angle import (
    COARSE_FFT,
    SECOND_LOBE,
    ZOOM_HALF,
    AngleArrays,
    AngleParams,
    _zoom_tables,
    kept_components,
)

if ZOOM_HALF != 2:
    raise ImportError("host.cell_kernels: _fine_search sums a 5-bin window (ZOOM_HALF = 2)")

_BLOCK = 32
"""(cell, class) pairs per coarse-FFT block: 2 x 128 x 32 float32, 32 KiB, the L1 data cache
of a core (measured on Zen 1: 16 pairs 19 % slower, 64 5 %, 8 29 %; on Zen 4, 64 is 5-8 %
faster, the same outputs bit for bit)."""


@numba.njit(cache=True, fastmath=True)
def _fine_search(xr: np.ndarray, xi: np.ndarray, ca: float, cb: float, cc: float, kc: int,
                 coarse: int, n_fft: int, dmr: np.ndarray, dmi: np.ndarray, oc: np.ndarray,
                 os_: np.ndarray, mag: np.ndarray) -> tuple[int, float, float, float]:
    """``host.angle._refine`` of one row x (float64 xr, xi (n,)) from coarse bin kc, whose
    coarse magnitudes (float32) at kc - 1, kc, kc + 1 are ca, cb, cc: (fine bin,
    |X(k - 1)|, |X(k)|, |X(k + 1)|).
    The window is the 5 fine bins centre - 2 .. centre + 2 (``host.angle.ZOOM_HALF``);
    with y = x demodulated by the centre (dm*: exp(2 pi j v k / n_fft) per fine bin k),
    bins centre +- o are A_o +- j B_o with A_o, B_o the sums of y_v cos and y_v sin(2 pi v o
    / n_fft) (oc, os_: float (2, n)): half the multiplications of a complex product per
    bin, all ten sums in one pass over the channels. mag (5,): scratch."""
    n = xr.shape[0]
    half = ZOOM_HALF
    w = 2 * half + 1
    step = n_fft // coarse
    den = ca - np.float32(2.0) * cb + cc
    delta = np.float32(0.0)
    if den < 0:
        delta = np.float32(0.5) * (ca - cc) / den
    delta = min(max(delta, np.float32(-0.5)), np.float32(0.5))
    centre = (kc * step + int(np.rint(delta * np.float32(step)))) % n_fft
    max_it = n_fft // half + 2
    j = 0
    for it in range(max_it):
        zr = 0.0
        zi = 0.0
        a1r = 0.0
        a1i = 0.0
        b1r = 0.0
        b1i = 0.0
        a2r = 0.0
        a2i = 0.0
        b2r = 0.0
        b2i = 0.0
        for v in range(n):
            dr = dmr[centre, v]
            di = dmi[centre, v]
            yr = xr[v] * dr - xi[v] * di
            yi = xr[v] * di + xi[v] * dr
            zr += yr
            zi += yi
            c1 = oc[0, v]
            s1 = os_[0, v]
            c2 = oc[1, v]
            s2 = os_[1, v]
            a1r += yr * c1
            a1i += yi * c1
            b1r += yr * s1
            b1i += yi * s1
            a2r += yr * c2
            a2i += yi * c2
            b2r += yr * s2
            b2i += yi * s2
        # X(centre + o) = A_o + j B_o, X(centre - o) = A_o - j B_o
        mag[0] = math.sqrt((a2r + b2i) ** 2 + (a2i - b2r) ** 2)
        mag[1] = math.sqrt((a1r + b1i) ** 2 + (a1i - b1r) ** 2)
        mag[2] = math.sqrt(zr * zr + zi * zi)
        mag[3] = math.sqrt((a1r - b1i) ** 2 + (a1i + b1r) ** 2)
        mag[4] = math.sqrt((a2r - b2i) ** 2 + (a2i + b2r) ** 2)
        j = 0
        for o in range(1, w):
            if mag[o] > mag[j]:
                j = o
        # uphill only when the edge is strictly higher (ties stop here)
        edge = (j == 0 and mag[0] > mag[1]) or j == w - 1
        if not edge or it == max_it - 1:
            break
        centre = (centre + j - half) % n_fft
    k = (centre + j - half) % n_fft
    return k, mag[max(j - 1, 0)], mag[j], mag[min(j + 1, w - 1)]


@numba.njit(cache=True, fastmath=True)
def _interpolated_sin(k0: int, a: float, b: float, c: float, n_fft: int) -> float:
    """``host.angle._interpolated_sin`` of one peak."""
    k = (k0 + n_fft // 2) % n_fft
    den = a - 2.0 * b + c
    delta = 0.5 * (a - c) / den if den < 0 else 0.0
    s = 2.0 * (k + delta - n_fft // 2) / n_fft
    return (s + 1.0) % 2.0 - 1.0


@numba.njit(cache=True, fastmath=True)
def _block_fft(re: np.ndarray, im: np.ndarray, wr: np.ndarray, wi: np.ndarray) -> None:
    """In-place FFT (kernel exp(+2 pi j n k / N), unscaled) of the columns of a block,
    float32 re, im (N, _BLOCK), N a power of two, the columns innermost (vectorised over
    them): radix-4 decimation-in-frequency stages, a radix-2 one last when N is not a power
    of 4; natural order in, digit-reversed order out (:func:`_coarse_tables`). wr, wi:
    float32 (N,) exp(2 pi j k / N)."""
    _fft_stages(re, im, wr, wi, re.shape[0], True)


@numba.njit(cache=True, fastmath=True)
def _fft_stages(re: np.ndarray, im: np.ndarray, wr: np.ndarray, wi: np.ndarray, size: int,
                radix2: bool) -> None:
    """The stages of :func:`_block_fft` from sub-transform length ``size`` down (``size``
    = N: all of them; N / 4 after :func:`_padded_first_stage`); ``radix2`` False: without
    the final radix-2 stage (N not a power of 4; the caller fuses it with its next pass,
    :func:`_squares_fused`)."""
    n = re.shape[0]
    nb = _BLOCK                     # a compile-time trip count: the loops vectorise
    while size >= 4:
        q = size // 4
        stride = n // size
        for start in range(0, n, size):
            for k in range(q):
                w1r = wr[k * stride]
                w1i = wi[k * stride]
                w2r = wr[2 * k * stride]
                w2i = wi[2 * k * stride]
                w3r = wr[3 * k * stride]
                w3i = wi[3 * k * stride]
                i0 = start + k
                i1 = i0 + q
                i2 = i1 + q
                i3 = i2 + q
                for j in range(nb):
                    t0r = re[i0, j] + re[i2, j]
                    t0i = im[i0, j] + im[i2, j]
                    t1r = re[i0, j] - re[i2, j]
                    t1i = im[i0, j] - im[i2, j]
                    t2r = re[i1, j] + re[i3, j]
                    t2i = im[i1, j] + im[i3, j]
                    t3r = re[i1, j] - re[i3, j]
                    t3i = im[i1, j] - im[i3, j]
                    re[i0, j] = t0r + t2r
                    im[i0, j] = t0i + t2i
                    ur = t1r - t3i                 # t1 + j t3
                    ui = t1i + t3r
                    re[i1, j] = ur * w1r - ui * w1i
                    im[i1, j] = ur * w1i + ui * w1r
                    ur = t0r - t2r
                    ui = t0i - t2i
                    re[i2, j] = ur * w2r - ui * w2i
                    im[i2, j] = ur * w2i + ui * w2r
                    ur = t1r + t3i                 # t1 - j t3
                    ui = t1i - t3r
                    re[i3, j] = ur * w3r - ui * w3i
                    im[i3, j] = ur * w3i + ui * w3r
        size = q
    if size == 2 and radix2:
        for start in range(0, n, 2):
            for j in range(nb):
                ur = re[start, j]
                ui = im[start, j]
                vr = re[start + 1, j]
                vi = im[start + 1, j]
                re[start, j] = ur + vr
                im[start, j] = ui + vi
                re[start + 1, j] = ur - vr
                im[start + 1, j] = ui - vi


@numba.njit(cache=True, fastmath=True)
def _padded_first_stage(xr: np.ndarray, xi: np.ndarray, re: np.ndarray, im: np.ndarray,
                        wr: np.ndarray, wi: np.ndarray) -> None:
    """The first radix-4 stage of :func:`_block_fft` on columns zero-padded to N: xr, xi
    float64 (N / 2, _BLOCK) in (rows past the data 0), float32 re, im (N, _BLOCK) out (the
    inputs N / 2 .. N - 1 are 0, so each butterfly reads two values, rounded to single
    precision as the FFT input)."""
    n = re.shape[0]
    nb = _BLOCK
    q = n // 4
    for k in range(q):
        w1r = wr[k]
        w1i = wi[k]
        w2r = wr[2 * k]
        w2i = wi[2 * k]
        w3r = wr[3 * k]
        w3i = wi[3 * k]
        for j in range(nb):
            ar = np.float32(xr[k, j])
            ai = np.float32(xi[k, j])
            br = np.float32(xr[k + q, j])
            bi = np.float32(xi[k + q, j])
            re[k, j] = ar + br
            im[k, j] = ai + bi
            ur = ar - bi                       # a + j b
            ui = ai + br
            re[k + q, j] = ur * w1r - ui * w1i
            im[k + q, j] = ur * w1i + ui * w1r
            ur = ar - br
            ui = ai - bi
            re[k + 2 * q, j] = ur * w2r - ui * w2i
            im[k + 2 * q, j] = ur * w2i + ui * w2r
            ur = ar + bi                       # a - j b
            ui = ai - br
            re[k + 3 * q, j] = ur * w3r - ui * w3i
            im[k + 3 * q, j] = ur * w3i + ui * w3r


@numba.njit(cache=True, fastmath=True)
def _squares_fused(re: np.ndarray, im: np.ndarray, rank: np.ndarray, sq: np.ndarray) -> None:
    """|X|^2 of a block transformed by ``_fft_stages(..., radix2=False)`` into sq (float32
    (_BLOCK, N), bin k of column j at sq[j, k]): the final radix-2 stage first when N is
    not a power of 4 (rows 2 i, 2 i + 1 are the inputs of one butterfly). re, im float32
    (N * _BLOCK,) flat; rank int (N,): the bin in each row after the full transform."""
    nb = _BLOCK
    n = rank.shape[0]
    if n & 0x55555555:                          # a power of 4: no radix-2 stage
        for q in range(n):
            k = rank[q]
            for j in range(nb):
                sq[j, k] = re[q * nb + j] * re[q * nb + j] + im[q * nb + j] * im[q * nb + j]
        return
    for start in range(0, n, 2):
        k0 = rank[start]
        k1 = rank[start + 1]
        q = start * nb
        for j in range(nb):
            sr = re[q + j] + re[q + nb + j]
            si = im[q + j] + im[q + nb + j]
            dr = re[q + j] - re[q + nb + j]
            di = im[q + j] - im[q + nb + j]
            sq[j, k0] = sr * sr + si * si
            sq[j, k1] = dr * dr + di * di


@numba.njit(cache=True)
def _argmax_bits(bits: np.ndarray) -> int:
    """np.argmax of a row of non-negative float32 values given as their int32 bit patterns
    (bits (n,); ordered as the values): two integer reductions (they vectorise; a float
    maximum with an index does not)."""
    n = bits.shape[0]
    mx = np.int32(-1)
    for k in range(n):
        v = bits[k]
        mx = v if v > mx else mx
    n32 = np.int32(n)                   # 32-bit indices: twice as many per vector
    first = n32
    for k in range(n):
        k32 = np.int32(k)
        first = min(first, k32 if bits[k] == mx else n32)
    return int(first)


@numba.njit(cache=True, fastmath=True)
def _class_peaks(x: np.ndarray, cell: np.ndarray, ph: np.ndarray, n_fft: int,
                 second_lobe: float, wr: np.ndarray, wi: np.ndarray, rank: np.ndarray,
                 dmr: np.ndarray, dmi: np.ndarray, oc: np.ndarray, os_: np.ndarray,
                 out_pow: np.ndarray, out_sin: np.ndarray) -> None:
    """:func:`class_peaks` (x, ph complex128); wr, wi float32 (coarse,) the
    coarse FFT's twiddles, rank int (coarse,) the bin :func:`_block_fft` leaves in each row; dm*,
    oc, os_: see :func:`_fine_search`."""
    m = cell.shape[0]
    nv = x.shape[1]
    ntx = ph.shape[1]
    nrx = nv // ntx
    coarse = rank.shape[0]
    nb_ = _BLOCK
    re2 = np.zeros((coarse, nb_), np.float32)
    im2 = np.zeros((coarse, nb_), np.float32)
    re = re2.ravel()                   # the same block, flat: (bin, column) at bin * nb_ + column
    im = im2.ravel()
    # the block's compensated rows as columns, double; rows nv.. stay 0 (the FFT's padding)
    xcr = np.zeros((max(nv, coarse // 2), nb_))
    xci = np.zeros((max(nv, coarse // 2), nb_))
    sq = np.empty((nb_, coarse), np.float32)   # squared magnitudes, a row per column
    sqb = sq.view(np.int32)
    rowr = np.empty(nv)
    rowi = np.empty(nv)
    mag = np.empty(2 * ZOOM_HALF + 1)
    lobe = np.float32(second_lobe)
    cmask = coarse - 1                        # coarse: a power of two
    for b0 in range(0, m, nb_):
        nb = min(nb_, m - b0)
        for t in range(ntx):                # TDM compensation
            for j in range(nb):
                pr = ph[b0 + j, t].real
                pi = ph[b0 + j, t].imag
                c = cell[b0 + j]
                for r in range(nrx):
                    v = t * nrx + r
                    xr = x[c, v].real
                    xi = x[c, v].imag
                    xcr[v, j] = xr * pr - xi * pi
                    xci[v, j] = xr * pi + xi * pr
        # coarse FFT of the block, single precision (as host.angle.fine_peaks), the
        # zero-padded rows as columns
        if 2 * nv <= coarse:
            _padded_first_stage(xcr, xci, re2, im2, wr, wi)
            _fft_stages(re2, im2, wr, wi, coarse // 4, False)
        else:
            for v in range(nv):
                for j in range(nb_):
                    re[v * nb_ + j] = np.float32(xcr[v, j])
                    im[v * nb_ + j] = np.float32(xci[v, j])
            re[nv * nb_:] = 0.0
            im[nv * nb_:] = 0.0
            _fft_stages(re2, im2, wr, wi, coarse, False)
        # squared magnitudes, natural bin order, one row per column (the maxima are the
        # same; a square root only where a magnitude is used)
        _squares_fused(re, im, rank, sq)
        for j in range(nb):
            row = sq[j]
            kc = _argmax_bits(sqb[j])
            ca = np.sqrt(row[(kc - 1) & cmask])
            first = np.sqrt(row[kc])
            cc = np.sqrt(row[(kc + 1) & cmask])
            # the first lobe's 5 bins count as 0 for the runner-up (host.angle.
            # _peaks_from_coarse sets them so)
            for o in range(-2, 3):
                row[(kc + o) & cmask] = 0.0
            k2c = _argmax_bits(sqb[j])
            for v in range(nv):
                rowr[v] = xcr[v, j]
                rowi[v] = xci[v, j]
            k0, a, b, c = _fine_search(rowr, rowi, ca, first, cc, kc, coarse,
                                       n_fft, dmr, dmi, oc, os_, mag)
            if np.sqrt(row[k2c]) >= lobe * first:
                k2, a2, b2, c2 = _fine_search(
                    rowr, rowi, np.sqrt(row[(k2c - 1) & cmask]),
                    np.sqrt(row[k2c]), np.sqrt(row[(k2c + 1) & cmask]),
                    k2c, coarse, n_fft, dmr, dmi, oc, os_, mag)
                if b2 > b:
                    k0, a, b, c = k2, a2, b2, c2
            out_pow[b0 + j] = b * b
            out_sin[b0 + j] = _interpolated_sin(k0, a, b, c, n_fft)


@numba.njit(cache=True, fastmath=True)
def _steer_row(s: float, str_: np.ndarray, sti: np.ndarray, lor: np.ndarray,
               loi: np.ndarray) -> None:
    """exp(-j pi v s) for v = 0..n-1 into str_, sti (float (n,)), as
    ``host.angle._steering_rows``: v = q b0 + p with b0 = len(lor) = ceil(sqrt(n)), the
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


@numba.njit(cache=True, fastmath=True)
def _steering(s: np.ndarray, out: np.ndarray) -> None:
    """:func:`steering_rows` into out (complex128 (m, n))."""
    m, n = out.shape
    b0 = int(math.ceil(math.sqrt(n)))
    lor = np.empty(b0)
    loi = np.empty(b0)
    str_ = np.empty(n)
    sti = np.empty(n)
    for i in range(m):
        _steer_row(s[i], str_, sti, lor, loi)
        for v in range(n):
            out[i, v] = complex(str_[v], sti[v])


def steering_rows(s: np.ndarray, n: int) -> np.ndarray:
    """``host.angle._steering_rows``: exp(-j pi v s) for v = 0..n-1 of every s (float
    (m,)), complex (m, n); equal to rounding."""
    s = np.ascontiguousarray(s, dtype=float)
    out = np.empty((len(s), n), np.complex128)
    if len(s):
        _steering(s, out)
    return out


@numba.njit(cache=True, fastmath=True)
def _first_components(x: np.ndarray, ph: np.ndarray, s1: np.ndarray, noise: np.ndarray,
                      snr_lin: float, dyn_lin: float, screen: bool, out: np.ndarray,
                      a1: np.ndarray, p1: np.ndarray, maybe: np.ndarray) -> None:
    """:func:`first_components` (x, ph, out complex128; snr_lin, dyn_lin: the gates as
    power ratios)."""
    n_rows, nv = x.shape
    ntx = ph.shape[1]
    nrx = nv // ntx
    b0 = int(math.ceil(math.sqrt(nv)))
    lor = np.empty(b0)
    loi = np.empty(b0)
    str_ = np.empty(nv)
    sti = np.empty(nv)
    outr = np.empty(nv)
    outi = np.empty(nv)
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
            for v in range(nv):
                rr = outr[v] - (ar * str_[v] - ai * sti[v])
                ri = outi[v] - (ar * sti[v] + ai * str_[v])
                e += rr * rr + ri * ri
            bound = e * (1.0 + 1e-9) / nv
            maybe[i] = (bound * nv >= snr_lin * noise[i]) and (
                p1[i] <= dyn_lin * max(bound, 1e-300))


def _c128(x: np.ndarray) -> np.ndarray:
    """x as a C-contiguous complex128 array (no copy when it is one)."""
    return np.ascontiguousarray(x, dtype=np.complex128)


def _split(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(real, imaginary) float64 C-contiguous copies of complex x."""
    return np.ascontiguousarray(x.real, dtype=np.float64), np.ascontiguousarray(
        x.imag, dtype=np.float64)


def _coarse_tables(coarse: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(twiddles float32 re, im (coarse,): exp(+2 pi j k / coarse); rank int (coarse,): the
    bin :func:`_block_fft` leaves in each row, found by transforming a delta at n = 1,
    whose bin k is exp(2 pi j k / coarse))."""
    w = np.exp(2j * np.pi * np.arange(coarse) / coarse)
    wr, wi = w.real.astype(np.float32), w.imag.astype(np.float32)
    re = np.zeros((coarse, _BLOCK), np.float32)
    im = np.zeros((coarse, _BLOCK), np.float32)
    re[1, 0] = 1.0
    _block_fft(re, im, wr, wi)
    k = np.round(np.angle(re[:, 0] + 1j * im[:, 0]) * coarse / (2 * np.pi)).astype(np.int64)
    rank = k % coarse
    if sorted(rank) != list(range(coarse)):
        raise AssertionError("_block_fft: output order is not a permutation")
    return wr, wi, rank


_TABLES: dict[tuple[int, int], tuple[np.ndarray, ...]] = {}


def _tables(n: int, n_fft: int) -> tuple[np.ndarray, ...]:
    """The kernels' constant tables for n channels, computed once per setting."""
    key = (n, n_fft)
    half = ZOOM_HALF
    if key not in _TABLES:
        demod, _ = _zoom_tables(n, n_fft, half)
        coarse = min(COARSE_FFT, n_fft)
        ang = 2 * np.pi * np.outer(np.arange(1, half + 1), np.arange(n)) / n_fft
        _TABLES[key] = (*_coarse_tables(coarse), *_split(demod), np.cos(ang), np.sin(ang))
    return _TABLES[key]


def class_peaks(x: np.ndarray, cell: np.ndarray, phasors: np.ndarray, n_fft: int
                ) -> tuple[np.ndarray, np.ndarray]:
    """Angle peak of TDM-compensated snapshots: row p is snapshot x[cell[p]] with TX t's
    channels times phasors[p, t] (``host.pipeline._tdm_tx_phasors``); returns
    ``host.angle.peak_power_lean`` of those rows, (peak power float (m,), sin(az) float
    (m,)).

    x: complex (n, num_tx * num_rx), virtual channel tx * num_rx + rx; cell: int (m,);
    phasors: complex (m, num_tx)."""
    m = len(cell)
    if x.ndim != 2 or phasors.shape != (m, phasors.shape[1]) or phasors.shape[1] < 1 or \
            x.shape[1] % phasors.shape[1]:
        raise ValueError(f"class_peaks: snapshots {x.shape}, phasors {phasors.shape} for "
                         f"{m} pairs")
    if x.shape[1] > min(COARSE_FFT, n_fft):
        raise ValueError(f"class_peaks: {x.shape[1]} channels exceed the coarse FFT "
                         f"({min(COARSE_FFT, n_fft)})")
    out_pow, out_sin = np.zeros(m), np.zeros(m)
    if m:
        wr, wi, rank, dmr, dmi, oc, os_ = _tables(x.shape[1], n_fft)
        _class_peaks(_c128(x), np.ascontiguousarray(cell, dtype=np.int64), _c128(phasors),
                     n_fft, SECOND_LOBE, wr, wi, rank, dmr, dmi, oc, os_, out_pow, out_sin)
    return out_pow, out_sin


def first_components(x: np.ndarray, phasors: np.ndarray, first_sin: np.ndarray,
                     noise_per_channel: np.ndarray, min_snr_db: float,
                     dynamic_range_db: float, screen: bool = True
                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The first angle component of each TDM-compensated snapshot and the screen for a
    second (``host.angle.estimate_angles_screened`` up to its residual search):
    (compensated rows complex128 (n, n_v), amplitude a1 complex (n,), power |a1|^2 float
    (n,), ``maybe`` bool (n,): the row may hold a second component).

    x: complex (n, num_tx * num_rx); phasors: complex (n, num_tx) per TX
    (``host.pipeline._tdm_tx_phasors``); first_sin: float (n,) sin(az) of the row's peak;
    noise_per_channel: float (n,) (clamped to >= 1e-30 as there); ``screen`` False: no
    second-component screen (``maybe`` all False)."""
    n = len(x)
    if x.ndim != 2 or phasors.shape[0] != n or x.shape[1] % max(phasors.shape[1], 1):
        raise ValueError(f"first_components: snapshots {x.shape}, phasors {phasors.shape}")
    out = np.empty(x.shape, np.complex128)
    a1, p1, maybe = np.zeros(n, complex), np.zeros(n), np.zeros(n, bool)
    noise = np.maximum(np.asarray(noise_per_channel, dtype=float), 1e-30)
    if n:
        _first_components(_c128(x), _c128(phasors),
                          np.ascontiguousarray(first_sin, dtype=float),
                          noise, 10 ** (min_snr_db / 10), 10 ** (dynamic_range_db / 10),
                          screen, out, a1, p1, maybe)
    return out, a1, p1, maybe


def peak_sins(x: np.ndarray, n_fft: int) -> tuple[np.ndarray, np.ndarray]:
    """``host.angle.peak_sin_fast`` of the rows of x, complex (m, n): (sin(az) float (m,),
    |peak|^2 float (m,)); a ``host.angle.PeakFinder``."""
    x = np.asarray(x)
    m = len(x)
    power, sin = class_peaks(x, np.arange(m), np.ones((m, 1), complex), n_fft)
    return sin, power


@numba.njit(cache=True, fastmath=True)
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


@numba.njit(cache=True, fastmath=True, error_model="numpy")
def _relax(xs: np.ndarray, noise: np.ndarray, refine: int, min_snr_db: float,
           dyn_db: float, n_fft: int, second_lobe: float, wr: np.ndarray, wi: np.ndarray,
           rank: np.ndarray, dmr: np.ndarray, dmi: np.ndarray, oc: np.ndarray,
           os_: np.ndarray, s_c: np.ndarray, a_c: np.ndarray, count: np.ndarray) -> None:
    """:func:`relax_rows` into s_c, a_c, count (float, complex (m, k), int (m,); zeros
    in): ``host.angle.estimate_angles_rows``'s passes, the peak search of each batch of
    live rows by :func:`_class_peaks` (unit phasors), steering by :func:`_steer_row`."""
    m, n = xs.shape
    kmax = s_c.shape[1]
    b0 = int(math.ceil(math.sqrt(n)))
    lor = np.empty(b0)
    loi = np.empty(b0)
    str_ = np.empty(n)
    sti = np.empty(n)
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


def relax_rows(x: np.ndarray, noise_per_channel: np.ndarray, params: AngleParams
               ) -> AngleArrays:
    """``host.angle.estimate_angles_rows(x, noise_per_channel, params, peak_sins,
    steering_rows)`` compiled (the same components to rounding): x complex (m, n),
    noise_per_channel float (m,); a ``host.angle.RowsEstimator``."""
    xs = _c128(x)
    m, n = xs.shape
    noise = np.maximum(np.asarray(noise_per_channel, dtype=float), 1e-30)
    if noise.shape != (m,):
        raise ValueError(f"relax_rows: {m} rows, noise {noise.shape}")
    if n > min(COARSE_FFT, params.n_fft):
        raise ValueError(f"relax_rows: {n} channels exceed the coarse FFT "
                         f"({min(COARSE_FFT, params.n_fft)})")
    s_c = np.zeros((m, params.max_targets))
    a_c = np.zeros((m, params.max_targets), np.complex128)
    count = np.zeros(m, np.int64)
    if m:
        wr, wi, rank, dmr, dmi, oc, os_ = _tables(n, params.n_fft)
        _relax(xs, noise, params.refine_iterations, params.min_snr_db,
               params.dynamic_range_db, params.n_fft, SECOND_LOBE, wr, wi, rank, dmr, dmi,
               oc, os_, s_c, a_c, count)
    return kept_components(s_c, a_c, count, noise, n)


@numba.njit(cache=True)
def _beats(p: np.ndarray, best: int, margin: float) -> bool:
    """Class ``best``'s power beats every other present class's by ``margin`` (absent
    classes: -inf; none other present: True)."""
    mo = -np.inf
    for c in range(p.shape[0]):
        if c != best and p[c] > mo:
            mo = p[c]
    return mo == -np.inf or p[best] >= margin * mo


@numba.njit(cache=True)
def _fold_decisions(cp: np.ndarray, v: np.ndarray, snr: np.ndarray, lo: np.ndarray,
                    hi: np.ndarray, ms: np.ndarray, vmax: float, test: bool, margin: float,
                    min_snr: float, fold: np.ndarray, ambiguous: np.ndarray) -> None:
    """:func:`fold_decisions` into fold, ambiguous (int64, bool (n,))."""
    ntx = cp.shape[1]
    h = ms.shape[0]
    hyp = np.empty(h, np.bool_)
    p = np.empty(ntx)
    present = np.empty(ntx, np.bool_)
    for i in range(v.shape[0]):
        count = 0
        for k in range(h):
            hyp[k] = lo[i] <= ms[k] <= hi[i]
            count += hyp[k]
        if count == 0:                     # no order within max_speed: m = 0
            for k in range(h):
                hyp[k] = ms[k] == 0
            count = 1
        if test and count > 1:
            for c in range(ntx):
                present[c] = False
            for k in range(h):
                if hyp[k]:
                    present[ms[k] % ntx] = True
            for c in range(ntx):
                p[c] = cp[i, c] if present[c] else -np.inf
            best = 0
            for c in range(1, ntx):
                if p[c] > p[best]:
                    best = c
            beats_all = _beats(p, best, margin)
            if best != 0 and not (beats_all and snr[i] >= min_snr):
                if present[0]:             # back to the unshifted class when it holds one
                    best = 0
                beats_all = _beats(p, best, margin)
            if beats_all:
                count = 0
                for k in range(h):
                    hyp[k] = hyp[k] and ms[k] % ntx == best
                    count += hyp[k]
        kbest = -1
        dbest = np.inf
        for k in range(h):                 # the hypothesis nearest zero velocity
            if hyp[k]:
                d = abs(v[i] + 2.0 * ms[k] * vmax)
                if d < dbest:
                    dbest = d
                    kbest = k
        fold[i] = ms[kbest]
        ambiguous[i] = count > 1 or ms[kbest] != 0


def fold_decisions(class_power: np.ndarray, velocity_mps: np.ndarray, snr_db: np.ndarray,
                   lo: np.ndarray, hi: np.ndarray, orders: np.ndarray,
                   max_velocity_mps: float, test: bool, margin: float, min_snr_db: float
                   ) -> tuple[np.ndarray, np.ndarray]:
    """The velocity-unfolding decision of ``host.pipeline._choose_fold`` for every cell:
    (alias order int (n,), ambiguous bool (n,)). Hypotheses: the alias orders m in
    ``orders`` (int (h,), sorted, 0 among them) within lo..hi (int (n,) each, the cell's
    orders from ``host.pipeline.alias_orders``; m = 0 when the range is empty). With
    ``test`` and more than one hypothesis the TDM test keeps those of the alias class
    (m mod num_tx) whose power in class_power (float (n, num_tx)) beats every other present
    class's by ``margin`` (a power ratio), falling back to class 0 below min_snr_db (snr_db
    float (n,)); the order nearest zero velocity (|v + 2 m max_velocity_mps|) wins.
    velocity_mps: float (n,) measured (aliased)."""
    n = len(velocity_mps)
    fold = np.zeros(n, np.int64)
    ambiguous = np.zeros(n, bool)
    if n:
        _fold_decisions(np.ascontiguousarray(class_power, dtype=float),
                        np.ascontiguousarray(velocity_mps, dtype=float),
                        np.ascontiguousarray(snr_db, dtype=float),
                        np.ascontiguousarray(lo, dtype=np.int64),
                        np.ascontiguousarray(hi, dtype=np.int64),
                        np.ascontiguousarray(orders, dtype=np.int64), float(max_velocity_mps),
                        bool(test), float(margin), float(min_snr_db), fold, ambiguous)
    return fold, ambiguous


@numba.njit(cache=True)
def _select(r: np.ndarray, d: np.ndarray, power: np.ndarray, nbmax: np.ndarray, nr: int,
            nd: int, lo: int, hi: int, sidelobes: bool, env_r: np.ndarray,
            env_d: np.ndarray) -> np.ndarray:
    """:func:`select_cells` (nbmax: float (n,) the largest neighbour power, 0 when not
    known; env_*: the sidelobe envelopes times the margin)."""
    n = r.shape[0]
    pmap = np.zeros((nr, nd))
    idx1 = np.zeros((nr, nd), np.int64)         # record index + 1 (the last one wins)
    for i in range(n):
        pmap[r[i], d[i]] = power[i]
        idx1[r[i], d[i]] = i + 1
    own = np.zeros(n, np.bool_)                  # the records that are the map's non-zeros
    for i in range(n):
        own[i] = idx1[r[i], d[i]] == i + 1 and pmap[r[i], d[i]] > 0
    cand = np.empty(n, np.int64)
    nc = 0
    for i in range(n):
        if not own[i] or r[i] < lo or r[i] >= hi:
            continue
        p = pmap[r[i], d[i]]
        mx = max(p, nbmax[i])
        for a in range(-1, 2):
            for b in range(-1, 2):
                if a or b:
                    mx = max(mx, pmap[(r[i] + a) % nr, (d[i] + b) % nd])
        if p >= mx:
            cand[nc] = i
            nc += 1
    cand = cand[:nc]
    cand = cand[np.argsort(r[cand] * nd + d[cand], kind="mergesort")]
    if not sidelobes or nc == 0:
        return cand
    # the non-zero cells grouped by column and by row (counting sort)
    col_start = np.zeros(nd + 1, np.int64)
    row_start = np.zeros(nr + 1, np.int64)
    for i in range(n):
        if own[i]:
            col_start[d[i] + 1] += 1
            row_start[r[i] + 1] += 1
    for k in range(nd):
        col_start[k + 1] += col_start[k]
    for k in range(nr):
        row_start[k + 1] += row_start[k]
    col_rows = np.empty(col_start[nd], np.int64)
    row_cols = np.empty(row_start[nr], np.int64)
    col_fill = col_start[:nd].copy()
    row_fill = row_start[:nr].copy()
    for i in range(n):
        if own[i]:
            col_rows[col_fill[d[i]]] = r[i]
            col_fill[d[i]] += 1
            row_cols[row_fill[r[i]]] = d[i]
            row_fill[r[i]] += 1
    keep = np.empty(nc, np.bool_)
    for c in range(nc):
        i = cand[c]
        p = pmap[r[i], d[i]]
        masked = False
        for k in range(col_start[d[i]], col_start[d[i] + 1]):
            rr = col_rows[k]
            if pmap[rr, d[i]] * env_r[(r[i] - rr) % nr] > p:
                masked = True
        for k in range(row_start[r[i]], row_start[r[i] + 1]):
            dd = row_cols[k]
            if pmap[r[i], dd] * env_d[(d[i] - dd) % nd] > p:
                masked = True
        keep[c] = not masked
    return cand[keep]


def select_cells(range_bin: np.ndarray, doppler_bin: np.ndarray, power: np.ndarray,
                 neighbour_max: np.ndarray | None, shape: tuple[int, int],
                 bins: tuple[int, int], envelopes: tuple[np.ndarray, np.ndarray] | None
                 ) -> np.ndarray:
    """The records that become points (``host.record_points.select_records``): indices int
    (m,) in (range, Doppler) order of the records that hold their cell (the last record of a
    cell wins, power > 0), lie in range bins ``bins`` = [lo, hi), are no weaker than any
    of the 8 cells around them on the map of detected powers (both axes circular) nor than
    ``neighbour_max`` (float (n,), their largest neighbour power, detected or not), and,
    with ``envelopes`` (range, Doppler sidelobe envelopes times the margin, float
    (n_range,), (n_doppler,)), are not below the sidelobes of a detected cell in their
    column or row. range_bin, doppler_bin: int (n,); power: float (n,); shape: (n_range,
    n_doppler)."""
    n = len(range_bin)
    nbmax = np.zeros(n) if neighbour_max is None else np.asarray(neighbour_max, dtype=float)
    z = np.zeros(1)
    env_r, env_d = envelopes if envelopes is not None else (z, z)
    return _select(np.ascontiguousarray(range_bin, dtype=np.int64),
                   np.ascontiguousarray(doppler_bin, dtype=np.int64),
                   np.ascontiguousarray(power, dtype=float), np.ascontiguousarray(nbmax),
                   int(shape[0]), int(shape[1]), int(bins[0]), int(bins[1]),
                   envelopes is not None, np.ascontiguousarray(env_r, dtype=float),
                   np.ascontiguousarray(env_d, dtype=float))


def uncompiled_kernels() -> list[str]:
    """The kernels of this module without a compiled cache on disk (numba's index file in
    ``__pycache__``): their next call compiles them (a fresh checkout's first call, 20-30 s
    in all). [] when every kernel has one, or when numba's cache layout is not the expected
    one (then nothing is known)."""
    missing = []
    for name, obj in sorted(globals().items()):
        cache_file = getattr(getattr(obj, "_cache", None), "_cache_file", None)
        index = getattr(cache_file, "_index_path", None)
        if isinstance(obj, numba.core.dispatcher.Dispatcher) and isinstance(index, str) \
                and not os.path.exists(index):
            missing.append(name)
    return missing
