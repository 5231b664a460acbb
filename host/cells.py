"""Detected range-Doppler cells with their channel snapshots: what both the cube path
(``host.pipeline.process_cube``: the host's own CFAR) and the records path
(``host.record_points.process_records``: the FPGA's detector) hand to
``host.points.points_from_cells``, and the peak interpolation both use for it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Cells:
    """n detected cells, one row each, in float-reference units (``model.reference``).

    ``range_bin``: int (n,); ``doppler_bin``: int (n,) natural FFT order (0..n_doppler - 1);
    ``power``: float (n,) non-coherent power sum_v |x_v|^2 of the cell; ``noise``: float
    (n,) the detector's mean noise power per cell of the non-coherent map; ``offsets``:
    float (n, 2) fractional (range, Doppler) offsets of the peak from the cell centre, bins
    in (-0.5, 0.5) (:func:`neighbour_offsets`); ``snapshot``: complex (n, n_virtual) the
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


def gaussian_offset(lm: np.ndarray | float, c: np.ndarray | float, lp: np.ndarray | float
                    ) -> np.ndarray:
    """Offset in (-0.5, 0.5) of a peak from 3 log-power samples (Gaussian interpolation: a
    parabola through them, whatever the main lobe's width, so a zero-padded axis' wider
    lobe needs nothing else); element-wise over arrays, 0 where the samples do not curve
    down."""
    lm, c, lp = (np.asarray(v, dtype=float) for v in (lm, c, lp))
    den = lm - 2 * c + lp
    with np.errstate(divide="ignore", invalid="ignore"):
        off = np.clip(0.5 * (lm - lp) / np.where(den < 0, den, -1.0), -0.5, 0.5)
    return np.where(den < 0, off, 0.0)


def neighbour_offsets(logc: np.ndarray, lognb: np.ndarray, inner: np.ndarray) -> np.ndarray:
    """Fractional (range, Doppler) offsets of peaks from their cell centres, float (n, 2)
    in (-0.5, 0.5), by Gaussian interpolation over the 3 log-power samples along each axis;
    the range offset is 0 where ``inner`` is False (a range end). logc: float (n,) the
    cells' log powers; lognb: float (n, 4) their neighbours' at range - 1, range + 1,
    Doppler - 1, Doppler + 1 (``model.cfar_2d.NEIGHBOURS``); inner: bool (n,)."""
    dr = np.where(inner, gaussian_offset(lognb[:, 0], logc, lognb[:, 1]), 0.0)
    dd = gaussian_offset(lognb[:, 2], logc, lognb[:, 3])
    return np.stack([dr, dd], axis=1).reshape(len(logc), 2)


def peak_offsets(logp: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """:func:`neighbour_offsets` of cells on a map (Doppler circular; 0 at the range ends).
    logp: float (n_range, n_doppler) log power; cells: int (n, 2) of (range_bin,
    doppler_bin). Returns float (n, 2) bins."""
    nr, nd = logp.shape
    r, d = cells[:, 0], cells[:, 1]
    rm, rp = np.clip(r - 1, 0, nr - 1), np.clip(r + 1, 0, nr - 1)
    lognb = np.stack([logp[rm, d], logp[rp, d], logp[r, (d - 1) % nd],
                      logp[r, (d + 1) % nd]], axis=1).reshape(len(cells), 4)
    return neighbour_offsets(logp[r, d], lognb, (r > 0) & (r < nr - 1))
