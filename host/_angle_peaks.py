"""Private backend of ``host.angle``: the compiled peak search of the angle spectrum.

The angle spectrum of a channel vector x (complex (n,), n <= 128) is its zero-padded
inverse DFT (``model.reference.angle_spectrum`` without the fftshift). The peak search
finds its maximum on the ``n_fft``-point grid without the ``n_fft``-point FFT: a
``COARSE_FFT``-point FFT in single precision picks the lobe (the runner-up lobe too when it
is within ``SECOND_LOBE`` of it) and a parabolic fit a starting fine bin; the spectrum is
then evaluated exactly (double precision) on the 2 ``ZOOM_HALF`` + 1 fine bins around it and
the window moves uphill until its maximum is inside it: the fine-grid maximum of that lobe,
as the ``n_fft``-point FFT finds it unless a third lobe is within the coarse grid's
scalloping of it (at most 0.91 dB at 2x oversampling). The peak's sin(az) is the parabolic
interpolation of the magnitudes around it.

:func:`class_peaks` runs the search on blocks of (row, TDM phasor) pairs: the coarse FFT
vectorised over a block (the pairs innermost), the fine search per pair. The oracle (the
numpy implementation it replaced) is ``tests/oracles/angle_peaks.py``, the ``n_fft``-point
FFT's definition ``tests/oracles/angle.py``. Floating-point sums run in another order than numpy's
(``fastmath`` lets the compiler reorder them): results agree to rounding; a decision that
rests on an exact tie may go the other way.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from host.kernels import njit

COARSE_FFT = 128
"""Length of the coarse angle FFT of the peak search."""
ZOOM_HALF = 2
"""The fine-grid search evaluates 2 ZOOM_HALF + 1 fine bins per step (:func:`_fine_search`
sums a 5-bin window)."""
SECOND_LOBE = 0.8
"""A coarse local maximum at least this fraction of the coarse maximum (amplitude) is
refined as well (two nearly equal lobes: the coarse grid's scalloping could rank them
wrongly)."""


@lru_cache(maxsize=8)
def zoom_tables(n: int, n_fft: int, half: int) -> tuple[np.ndarray, np.ndarray]:
    """(demodulation table complex (n_fft, n): exp(+2 pi j v k / n_fft) per fine bin k,
    offset matrix complex (n, 2 half + 1): exp(+2 pi j v o / n_fft), o = -half..half)."""
    v = np.arange(n)
    demod = np.exp(2j * np.pi * np.outer(np.arange(n_fft), v) / n_fft)
    offs = np.exp(2j * np.pi * np.outer(v, np.arange(-half, half + 1)) / n_fft)
    return demod, offs


_BLOCK = 32
"""(cell, class) pairs per coarse-FFT block: 2 x 128 x 32 float32, 32 KiB, the L1 data cache
of a core (measured on Zen 1: 16 pairs 19 % slower, 64 5 %, 8 29 %; on Zen 4, 64 is 5-8 %
faster, the same outputs bit for bit). Fewer pairs than this take a block of their number
(a column's transform is the same whatever the block's width): RELAX and the split search
a few rows at a time, where a full block's FFT was most of the work."""


@njit(fastmath=True)
def _fine_search(xr: np.ndarray, xi: np.ndarray, ca: float, cb: float, cc: float, kc: int,
                 coarse: int, n_fft: int, dmr: np.ndarray, dmi: np.ndarray, oc: np.ndarray,
                 os_: np.ndarray, mag: np.ndarray) -> tuple[int, float, float, float]:
    """The fine-grid local maximum of |spectrum| of one row x (float64 xr, xi (n,)) uphill
    from coarse bin kc (the module docstring's search), whose
    coarse magnitudes (float32) at kc - 1, kc, kc + 1 are ca, cb, cc: (fine bin,
    |X(k - 1)|, |X(k)|, |X(k + 1)|).
    The window is the 5 fine bins centre - 2 .. centre + 2 (``ZOOM_HALF``);
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


@njit(fastmath=True)
def _interpolated_sin(k0: int, a: float, b: float, c: float, n_fft: int) -> float:
    """sin(az) of a fine-grid peak: unshifted bin k0 with magnitudes a, b, c at k0 - 1,
    k0, k0 + 1, parabolic interpolation, wrapped into [-1, 1)."""
    k = (k0 + n_fft // 2) % n_fft
    den = a - 2.0 * b + c
    delta = 0.5 * (a - c) / den if den < 0 else 0.0
    s = 2.0 * (k + delta - n_fft // 2) / n_fft
    return (s + 1.0) % 2.0 - 1.0


@njit(fastmath=True)
def _block_fft(re: np.ndarray, im: np.ndarray, wr: np.ndarray, wi: np.ndarray) -> None:
    """In-place FFT (kernel exp(+2 pi j n k / N), unscaled) of the columns of a block,
    float32 re, im (N, b), b <= _BLOCK, N a power of two, the columns innermost (vectorised
    over them): radix-4 decimation-in-frequency stages, a radix-2 one last when N is not a power
    of 4; natural order in, digit-reversed order out (:func:`_coarse_tables`). wr, wi:
    float32 (N,) exp(2 pi j k / N)."""
    _fft_stages(re, im, wr, wi, re.shape[0], True)


@njit(fastmath=True)
def _fft_stages(re: np.ndarray, im: np.ndarray, wr: np.ndarray, wi: np.ndarray, size: int,
                radix2: bool) -> None:
    """The stages of :func:`_block_fft` from sub-transform length ``size`` down (``size``
    = N: all of them; N / 4 after :func:`_padded_first_stage`); ``radix2`` False: without
    the final radix-2 stage (N not a power of 4; the caller fuses it with its next pass,
    :func:`_squares_fused`)."""
    n, nb = re.shape
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


@njit(fastmath=True)
def _padded_first_stage(xr: np.ndarray, xi: np.ndarray, re: np.ndarray, im: np.ndarray,
                        wr: np.ndarray, wi: np.ndarray) -> None:
    """The first radix-4 stage of :func:`_block_fft` on columns zero-padded to N: xr, xi
    float64 (N / 2, b) in (rows past the data 0), float32 re, im (N, b) out (the
    inputs N / 2 .. N - 1 are 0, so each butterfly reads two values, rounded to single
    precision as the FFT input)."""
    n, nb = re.shape
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


@njit(fastmath=True)
def _squares_fused(re: np.ndarray, im: np.ndarray, rank: np.ndarray, sq: np.ndarray) -> None:
    """|X|^2 of a block transformed by ``_fft_stages(..., radix2=False)`` into sq (float32
    (b, N), bin k of column j at sq[j, k]): the final radix-2 stage first when N is
    not a power of 4 (rows 2 i, 2 i + 1 are the inputs of one butterfly). re, im float32
    (N * b,) flat; rank int (N,): the bin in each row after the full transform."""
    nb = sq.shape[0]
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


@njit()
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


@njit(fastmath=True)
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
    nb_ = min(_BLOCK, max(m, 1))
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
        # coarse FFT of the block, single precision, the
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
            # the first lobe's 5 bins count as 0 for the runner-up (a
            # shoulder of the first lobe climbs back to it: harmless)
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
        demod, _ = zoom_tables(n, n_fft, half)
        coarse = min(COARSE_FFT, n_fft)
        ang = 2 * np.pi * np.outer(np.arange(1, half + 1), np.arange(n)) / n_fft
        _TABLES[key] = (*_coarse_tables(coarse), *_split(demod), np.cos(ang), np.sin(ang))
    return _TABLES[key]


def class_peaks(x: np.ndarray, cell: np.ndarray, phasors: np.ndarray, n_fft: int
                ) -> tuple[np.ndarray, np.ndarray]:
    """Angle peak of TDM-compensated snapshots: row p is snapshot x[cell[p]] with TX t's
    channels times phasors[p, t] (``host.tdm.tx_phasors``); returns
    the peak of each row's angle spectrum (module docstring): (peak power |X(k)|^2 float
    (m,), sin(az) float (m,)).

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



def peak_sins(x: np.ndarray, n_fft: int) -> tuple[np.ndarray, np.ndarray]:
    """:func:`class_peaks` of the rows of x as they are, complex (m, n): (sin(az) float
    (m,), |peak|^2 float (m,))."""
    x = np.asarray(x)
    m = len(x)
    power, sin = class_peaks(x, np.arange(m), np.ones((m, 1), complex), n_fft)
    return sin, power

