"""Detected range-Doppler cells with their channel snapshots: what both the cube path
(``host.pipeline.process_cube``: the host's own CFAR) and the records path
(``host.record_points.process_records``: the FPGA's detector) hand to
``host.points.points_from_cells``, and the peak interpolation both use for it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from host.kernels import njit, warm_up
from model.reference import FftAxis


@dataclass(frozen=True)
class Cells:
    """n detected cells, one row each, in float-reference units (``model.reference``).

    ``range_bin``: int (n,); ``doppler_bin``: int (n,) natural FFT order (0..n_doppler - 1);
    ``power``: float (n,) non-coherent power sum_v |x_v|^2 of the cell; ``noise``: float
    (n,) the detector's mean noise power per cell of the non-coherent map; ``offsets``:
    float (n, 2) fractional (range, Doppler) offsets of the peak from the cell centre, bins
    in (-0.5, 0.5) (:func:`neighbour_offsets`; up to 0.75 bin further after
    ``host.refine``); ``snapshot``: complex (n, n_virtual) the
    cell's Doppler-FFT values per virtual channel v = tx * num_rx + rx; ``range_bias_m``:
    subtracted from the points' range (a calibration's, ``host.calibration``)."""

    range_bin: np.ndarray
    doppler_bin: np.ndarray
    power: np.ndarray
    noise: np.ndarray
    offsets: np.ndarray
    snapshot: np.ndarray
    range_bias_m: float = 0.0

    def __len__(self) -> int:
        return len(self.range_bin)


TABLE_POINTS = 1025
"""Offsets 0..0.5 bin of the tables that invert the interpolation statistic
(:func:`offset_table`; linear interpolation between them is exact to about 1e-7 bin)."""
TWO_BIN_PADDING = 1.125
"""A rectangular (unwindowed) axis padded by less than this (n_fft / n_samples) is
interpolated from two bins (:func:`offset_statistic`): its neighbours sit near the
response's nulls, where the three-power parabola loses the offset's sign (docs/curves.md)."""


def two_bin(axis: FftAxis) -> bool:
    """Whether ``axis`` takes the two-bin statistic (:data:`TWO_BIN_PADDING`)."""
    return not axis.hann and axis.n_fft < TWO_BIN_PADDING * axis.n_samples


def offset_statistic(lo: np.ndarray, c: np.ndarray, hi: np.ndarray, two: bool
                     ) -> np.ndarray:
    """The statistic t in [-0.5, 0.5] the offset is read from (:func:`offset_table`), from
    the powers (float, any one shape) of a peak cell ``c`` and its neighbours at -1 and +1
    bin; 0 where it is undefined (the samples do not curve down, all zero).

    Three bins (``two`` False): the vertex of the parabola through the three *powers*,
    t = (lo - hi) / (2 (lo - 2 c + hi)). Additive noise power cancels from it, and on a
    Hann-windowed peak its variance is within 0.12 dB (mean over the offsets) of the bound
    of the three cells (docs/curves.md). Two bins (``two`` True, a rectangular unpadded
    axis): t = +-m / (m_c + m) with m the larger neighbour's magnitude sqrt(power), sign
    toward it (Rife and Vincent's ratio; exact, t = offset, for an unpadded rectangular
    window when N is large). Compiled (:func:`_statistic`, one value at a time)."""
    lo, c, hi = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (lo, c, hi)))
    out = np.empty(c.shape)
    _statistics(lo.ravel(), c.ravel(), hi.ravel(), bool(two), out.reshape(-1))
    return out


@njit()
def _statistic(lo: float, c: float, hi: float, two: bool) -> float:
    """:func:`offset_statistic` of one cell (float64 powers)."""
    if two:
        m_lo, m_c, m_hi = np.sqrt(lo), np.sqrt(c), np.sqrt(hi)
        up = m_hi >= m_lo
        m = m_hi if up else m_lo
        den = m_c + m
        t = (1.0 if up else -1.0) * (m / den if den > 0 else 0.0)
    else:
        den = lo - 2 * c + hi
        if not den < 0:
            return 0.0
        t = 0.5 * (lo - hi) / den
    if t < -0.5:                # np.clip's, NaN kept
        return -0.5
    return 0.5 if t > 0.5 else t


@njit()
def _statistics(lo: np.ndarray, c: np.ndarray, hi: np.ndarray, two: bool,
                out: np.ndarray) -> None:
    """:func:`_statistic` of every cell of the float64 (m,) powers into out (m,)."""
    for i in range(c.shape[0]):
        out[i] = _statistic(lo[i], c[i], hi[i], two)


def tone_power(axis: FftAxis, offset: np.ndarray) -> np.ndarray:
    """|W(x)|^2 of a unit tone ``offset`` bins (float (m,)) of ``axis``' FFT from a bin
    centre: W(x) = sum_t w[t] exp(-j 2 pi x t / n_fft) over the axis' window w
    (``model.reference.FftAxis.window``, n_samples samples; its closed form
    ``FftAxis.response`` times W(0) = sum(w)), float (m,)."""
    return (axis.response(offset) * axis.window().sum()) ** 2


@lru_cache(maxsize=32)
def offset_table(axis: FftAxis) -> tuple[np.ndarray, np.ndarray]:
    """(t, offset): the statistic of :func:`offset_statistic` of a noise-free tone, float
    (:data:`TABLE_POINTS`,) rising from 0 to 0.5, at offsets 0..0.5 bin (float, same
    shape) of ``axis`` (its window, zero padding): the exact response, whatever the FFT
    length, window and padding. Read-only, computed once per axis. The statistic is odd in
    the offset (the response is symmetric)."""
    off = np.linspace(0.0, 0.5, TABLE_POINTS)
    p = tone_power(axis, (off[:, None] - np.array([-1.0, 0.0, 1.0])).ravel()).reshape(-1, 3)
    t = offset_statistic(p[:, 0], p[:, 1], p[:, 2], two_bin(axis))
    t[0], t[-1] = 0.0, 0.5                          # exact by symmetry
    if not np.all(np.diff(t) > 0):
        raise ValueError(f"peak interpolation: the statistic is not monotonic on {axis}")
    for a in (t, off):
        a.flags.writeable = False
    return t, off


def axis_offsets(lo: np.ndarray, c: np.ndarray, hi: np.ndarray, axis: FftAxis
                 ) -> np.ndarray:
    """Offsets in [-0.5, 0.5] bin of peaks from their cells' centres along ``axis``, float
    like ``c``: :func:`offset_statistic` of the powers lo, c, hi (non-coherent sums over
    channels keep each channel's tone shape) inverted through :func:`offset_table`. Unbiased
    for a noise-free tone (to about 1e-7 bin) at any offset, window and padding."""
    lo, c, hi = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (lo, c, hi)))
    out = np.empty(c.shape)
    _axis_offsets(lo.ravel(), c.ravel(), hi.ravel(), _inversion(axis), out.reshape(-1))
    return out[()]


def _inversion(axis: FftAxis) -> tuple[bool, np.ndarray, np.ndarray]:
    """What the kernels need of ``axis`` to turn three powers into an offset: (whether it
    takes the two-bin statistic, :func:`offset_table`'s t and offsets)."""
    return (two_bin(axis), *offset_table(axis))


@njit()
def _interp(x: float, xp: np.ndarray, fp: np.ndarray) -> float:
    """``np.interp(x, xp, fp)`` of one value (xp rising), the same arithmetic: the segment
    xp[j] <= x < xp[j + 1] by bisection, fp[j] at a sample, the slope formula between,
    the end values outside, NaN for NaN."""
    n = xp.shape[0]
    if x != x:
        return x
    if x < xp[0]:
        return fp[0]
    if x > xp[n - 1]:
        return fp[n - 1]
    lo, hi = 0, n - 1                   # xp[lo] <= x, and x < xp[hi] unless x == xp[-1]
    if x >= xp[hi]:
        return fp[hi]
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if x >= xp[mid]:
            lo = mid
        else:
            hi = mid
    if xp[lo] == x:
        return fp[lo]
    slope = (fp[lo + 1] - fp[lo]) / (xp[lo + 1] - xp[lo])
    y = slope * (x - xp[lo]) + fp[lo]
    if y != y:
        y = slope * (x - xp[lo + 1]) + fp[lo + 1]
        if y != y and fp[lo] == fp[lo + 1]:
            y = fp[lo]
    return y


@njit()
def _offset(lo: float, c: float, hi: float, inv: tuple[bool, np.ndarray, np.ndarray]
            ) -> float:
    """:func:`axis_offsets` of one cell: sign(t) |offset| at |t| (np.sign's 0 at 0)."""
    t = _statistic(lo, c, hi, inv[0])
    sign = 1.0 if t > 0 else (-1.0 if t < 0 else (0.0 if t == 0 else t))
    return sign * _interp(abs(t), inv[1], inv[2])


@njit()
def _axis_offsets(lo: np.ndarray, c: np.ndarray, hi: np.ndarray,
                  inv: tuple[bool, np.ndarray, np.ndarray], out: np.ndarray) -> None:
    """:func:`_offset` of every cell of the float64 (m,) powers into out (m,)."""
    for i in range(c.shape[0]):
        out[i] = _offset(lo[i], c[i], hi[i], inv)


def neighbour_offsets(power: np.ndarray, neighbours: np.ndarray, inner: np.ndarray,
                      axes: tuple[FftAxis, FftAxis]) -> np.ndarray:
    """Fractional (range, Doppler) offsets of peaks from their cell centres, float (n, 2)
    in [-0.5, 0.5] bin (:func:`axis_offsets` along each axis); the range offset is 0 where
    ``inner`` is False (a range end). power: float (n,) the cells' non-coherent powers;
    neighbours: float (n, 4) their neighbours' at range - 1, range + 1, Doppler - 1,
    Doppler + 1 (``model.cfar_2d.NEIGHBOURS``); inner: bool (n,); axes: the (range,
    Doppler) axes (``model.reference.fft_axes``)."""
    c = np.ascontiguousarray(power, dtype=float).reshape(-1)
    nb = np.ascontiguousarray(neighbours, dtype=float).reshape(len(c), 4)
    out = np.empty((len(c), 2))
    _neighbour_offsets(c, nb, np.ascontiguousarray(np.broadcast_to(inner, c.shape)),
                       _inversion(axes[0]), _inversion(axes[1]), out)
    return out


@njit()
def _neighbour_offsets(c: np.ndarray, nb: np.ndarray, inner: np.ndarray,
                       inv_r: tuple[bool, np.ndarray, np.ndarray],
                       inv_d: tuple[bool, np.ndarray, np.ndarray], out: np.ndarray) -> None:
    """:func:`neighbour_offsets` into out (float64 (n, 2))."""
    for i in range(c.shape[0]):
        out[i, 0] = _offset(nb[i, 0], c[i], nb[i, 1], inv_r) if inner[i] else 0.0
        out[i, 1] = _offset(nb[i, 2], c[i], nb[i, 3], inv_d)


def peak_offsets(power: np.ndarray, cells: np.ndarray, axes: tuple[FftAxis, FftAxis]
                 ) -> np.ndarray:
    """:func:`neighbour_offsets` of cells on a map (Doppler circular; 0 at the range ends).
    power: float (n_range, n_doppler) the non-coherent power map; cells: int (n, 2) of
    (range_bin, doppler_bin); axes: the map's (range, Doppler) axes. Returns float (n, 2)
    bins; the neighbours are read off the map in the kernel (:func:`_map_offsets`)."""
    cells = np.asarray(cells).reshape(-1, 2)
    out = np.empty((len(cells), 2))
    if len(cells):
        _map_offsets(power, cells, _inversion(axes[0]), _inversion(axes[1]), out)
    return out


@njit()
def _map_offsets(power: np.ndarray, cells: np.ndarray,
                 inv_r: tuple[bool, np.ndarray, np.ndarray],
                 inv_d: tuple[bool, np.ndarray, np.ndarray], out: np.ndarray) -> None:
    """:func:`peak_offsets` into out (float64 (n, 2)); power: any float map, read as
    float64."""
    nr, nd = power.shape
    for i in range(cells.shape[0]):
        r, d = cells[i, 0], cells[i, 1]
        c = np.float64(power[r, d])
        out[i, 0] = _offset(np.float64(power[r - 1, d]), c, np.float64(power[r + 1, d]),
                            inv_r) if 0 < r < nr - 1 else 0.0
        out[i, 1] = _offset(np.float64(power[r, (d + nd - 1) % nd]), c,
                            np.float64(power[r, (d + 1) % nd]), inv_d)


def scallop(axes: tuple[FftAxis, FftAxis], offsets: np.ndarray) -> np.ndarray:
    """The window response at each cell's peak, float (n,): ``FftAxis.response`` of the
    range axis at offsets[:, 0] times the Doppler axis' at offsets[:, 1] (offsets float
    (n, 2) bins; axes the (range, Doppler) axes), in one compiled pass: the same
    operations in the same order as ``model.reference.FftAxis.response`` (sines and the
    hypotenuse from the C library, as numpy's), so the same values bit for bit
    (``tests/test_host_pipeline.py``)."""
    off = np.ascontiguousarray(offsets, dtype=float).reshape(-1, 2)
    out = np.empty(len(off))
    _scallop(off, _response_constants(axes[0]), _response_constants(axes[1]), out)
    return out


@lru_cache(maxsize=32)
def _response_constants(axis: FftAxis) -> tuple[float, int, bool, float, float, float]:
    """What :func:`_response` needs of ``axis``, computed as ``FftAxis.response`` computes
    it: (n_samples / n_fft, n_samples, hann, 0.25 cos(phi), 0.25 sin(phi), n_samples / 2),
    phi = pi (n - 1) / n."""
    n = axis.n_samples
    phi = np.pi * (n - 1) / n
    return (axis.n_samples / axis.n_fft, n, axis.hann, float(0.25 * np.cos(phi)),
            float(0.25 * np.sin(phi)), n / 2)


@njit()
def _dirichlet(y: float, n: int, sin_pi_y: float) -> float:
    """``model.reference._dirichlet_ratio`` of one value."""
    den = math.sin(math.pi * y / n)
    return float(n) if abs(den) < 1e-12 else sin_pi_y / den


@njit()
def _response(offset: float, k: tuple[float, int, bool, float, float, float]) -> float:
    """``FftAxis.response`` of one offset, the axis given by :func:`_response_constants`."""
    ratio, n, hann, c, sn, half = k
    x = offset * ratio
    s = math.sin(math.pi * x)
    r0 = _dirichlet(x, n, s)
    if not hann:
        return abs(r0) / n
    rm = _dirichlet(x - 1, n, -s)
    rp = _dirichlet(x + 1, n, -s)
    return math.hypot(0.5 * r0 - c * (rm + rp), sn * (rp - rm)) / half


@njit()
def _scallop(off: np.ndarray, kr: tuple[float, int, bool, float, float, float],
             kd: tuple[float, int, bool, float, float, float], out: np.ndarray) -> None:
    """:func:`scallop` into out (float64 (n,))."""
    for i in range(off.shape[0]):
        out[i] = _response(off[i, 0], kr) * _response(off[i, 1], kd)


@warm_up
def _warm_up() -> None:
    """The offsets off a map (a cube's, float32 in Fortran order, and float64), of
    neighbours (the records') and along one axis (a calibration's), and the window
    responses (the points of any cells): each path reaches only some of them."""
    inv = _inversion(FftAxis(8, 8))
    cells = np.ones((1, 2), np.int64)
    for power in (np.ones((4, 4), np.float32, order="F"), np.ones((4, 4))):
        _map_offsets(power, cells, inv, inv, np.empty((1, 2)))
    one = np.ones(1)
    _neighbour_offsets(one, np.ones((1, 4)), np.ones(1, np.bool_), inv, inv, np.empty((1, 2)))
    _axis_offsets(one, one, one, inv, np.empty(1))
    scallop((FftAxis(8, 8), FftAxis(8, 8, False)), np.zeros((1, 2)))
