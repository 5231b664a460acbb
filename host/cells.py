"""Detected range-Doppler cells with their channel snapshots: what both the cube path
(``host.pipeline.process_cube``: the host's own CFAR) and the records path
(``host.record_points.process_records``: the FPGA's detector) hand to
``host.points.points_from_cells``, and the peak interpolation both use for it.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

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
    window when N is large)."""
    lo, c, hi = (np.asarray(v, dtype=float) for v in (lo, c, hi))
    if two:
        m_lo, m_c, m_hi = np.sqrt(lo), np.sqrt(c), np.sqrt(hi)
        up = m_hi >= m_lo
        m = np.where(up, m_hi, m_lo)
        den = m_c + m
        with np.errstate(divide="ignore", invalid="ignore"):
            t = np.where(up, 1.0, -1.0) * np.where(den > 0, m / np.where(den > 0, den, 1.0),
                                                   0.0)
        return np.clip(t, -0.5, 0.5)
    den = lo - 2 * c + hi
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.clip(0.5 * (lo - hi) / np.where(den < 0, den, -1.0), -0.5, 0.5)
    return np.where(den < 0, t, 0.0)


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
    t = offset_statistic(lo, c, hi, two_bin(axis))
    tab, off = offset_table(axis)
    return np.sign(t) * np.interp(np.abs(t), tab, off)


def neighbour_offsets(power: np.ndarray, neighbours: np.ndarray, inner: np.ndarray,
                      axes: tuple[FftAxis, FftAxis]) -> np.ndarray:
    """Fractional (range, Doppler) offsets of peaks from their cell centres, float (n, 2)
    in [-0.5, 0.5] bin (:func:`axis_offsets` along each axis); the range offset is 0 where
    ``inner`` is False (a range end). power: float (n,) the cells' non-coherent powers;
    neighbours: float (n, 4) their neighbours' at range - 1, range + 1, Doppler - 1,
    Doppler + 1 (``model.cfar_2d.NEIGHBOURS``); inner: bool (n,); axes: the (range,
    Doppler) axes (``model.reference.fft_axes``)."""
    c = np.asarray(power, dtype=float)
    nb = np.asarray(neighbours, dtype=float).reshape(len(c), 4)
    dr = np.where(inner, axis_offsets(nb[:, 0], c, nb[:, 1], axes[0]), 0.0)
    dd = axis_offsets(nb[:, 2], c, nb[:, 3], axes[1])
    return np.stack([dr, dd], axis=1).reshape(len(c), 2)


def peak_offsets(power: np.ndarray, cells: np.ndarray, axes: tuple[FftAxis, FftAxis]
                 ) -> np.ndarray:
    """:func:`neighbour_offsets` of cells on a map (Doppler circular; 0 at the range ends).
    power: float (n_range, n_doppler) the non-coherent power map; cells: int (n, 2) of
    (range_bin, doppler_bin); axes: the map's (range, Doppler) axes. Returns float (n, 2)
    bins."""
    nr, nd = power.shape
    r, d = cells[:, 0], cells[:, 1]
    rm, rp = np.clip(r - 1, 0, nr - 1), np.clip(r + 1, 0, nr - 1)
    nb = np.stack([power[rm, d], power[rp, d], power[r, (d - 1) % nd],
                   power[r, (d + 1) % nd]], axis=1).reshape(len(cells), 4)
    return neighbour_offsets(power[r, d], nb, (r > 0) & (r < nr - 1), axes)
