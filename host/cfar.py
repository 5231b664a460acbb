"""Detection on range-Doppler maps: the paper's threshold, 2-D CA-CFAR and OS-CFAR, peak
grouping.

Maps are float (n_range, n_doppler) powers with the Doppler axis in natural FFT order. The
Doppler axis is circular (wraps around); the range axis is not: near its ends the training
window is cut off and the threshold factor is recomputed for the cells that remain.

Thresholds for a configured false-alarm probability are derived, not tuned (the statistics
live in ``model/cfar_stats.py``, shared with the FPGA CFAR model). A cell of a
map that integrates ``n_channels`` independent channels non-coherently is Gamma(L, theta)
distributed under noise (L = n_channels). For CA-CFAR, CUT / mean(training) is then
F(2L, 2NL)-distributed for N independent training cells, so the factor is the F quantile.
Windowed FFTs correlate neighbouring cells (periodic Hann: adjacent-bin power correlation
4/9, next 1/36), which makes the training mean noisier; the factor uses the effective
number of independent cells N_eff = N^2 / sum_ij rho_ij^2 (exact variance of the mean) so
the configured Pfa holds with windows on. OS-CFAR uses the k-th smallest training cell;
its factor solves Pfa = E[P(X > alpha * Y_(k))] numerically.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import stats
from scipy.ndimage import maximum_filter
from scipy.signal import fftconvolve

from model.cfar_stats import (  # noqa: F401 - re-exported: host code imports them from here
    HANN_POWER_CORRELATION,
    RECT_POWER_CORRELATION,
    ca_factor,
    effective_cells_mask,
    os_factor,
)


@dataclass(frozen=True)
class CfarParams:
    """2-D CFAR window, in cells: ``guard`` and ``train`` per side along (range, Doppler).

    ``pfa``: configured false-alarm probability per cell. ``kind``: ``"ca"`` (cell
    averaging) or ``"os"`` (ordered statistic, ``os_rank`` = fraction of training cells
    below the chosen one, 0.75 by default).
    """

    pfa: float = 1e-6
    guard: tuple[int, int] = (2, 2)
    train: tuple[int, int] = (4, 8)
    kind: str = "ca"
    os_rank: float = 0.75

    def __post_init__(self) -> None:
        if not 0.0 < self.pfa < 0.5:
            raise ValueError(f"pfa: must be in (0, 0.5), got {self.pfa}")
        if self.kind not in ("ca", "os"):
            raise ValueError(f"kind: must be 'ca' or 'os', got {self.kind!r}")
        if any(g < 0 for g in self.guard) or any(t < 1 for t in self.train):
            raise ValueError("guard must be >= 0 and train >= 1 cells per side")
        if not 0.0 < self.os_rank < 1.0:
            raise ValueError(f"os_rank: must be in (0, 1), got {self.os_rank}")


def _kernel(params: CfarParams) -> np.ndarray:
    """Training-cell mask, float (2(g_r+t_r)+1, 2(g_d+t_d)+1), CUT at the centre."""
    (gr, gd), (tr, td) = params.guard, params.train
    k = np.ones((2 * (gr + tr) + 1, 2 * (gd + td) + 1))
    k[tr:tr + 2 * gr + 1, td:td + 2 * gd + 1] = 0.0
    return k


def effective_cells(params: CfarParams, windowed: tuple[bool, bool] = (True, True)) -> float:
    """Number of independent cells with the same averaging power as the training set."""
    return effective_cells_mask(_kernel(params), windowed)


def _pad(power: np.ndarray, params: CfarParams) -> tuple[np.ndarray, np.ndarray]:
    """Map padded with wrap in Doppler and zeros in range, and the matching validity mask."""
    (gr, gd), (tr, td) = params.guard, params.train
    pr, pd = gr + tr, gd + td
    valid = np.ones_like(power)
    padded = np.pad(np.pad(power, ((0, 0), (pd, pd)), mode="wrap"), ((pr, pr), (0, 0)))
    vpad = np.pad(np.pad(valid, ((0, 0), (pd, pd)), mode="wrap"), ((pr, pr), (0, 0)))
    return padded, vpad


def cfar_threshold(power: np.ndarray, n_channels: int, params: CfarParams,
                   windowed: tuple[bool, bool] = (True, True)) -> tuple[np.ndarray, np.ndarray]:
    """Per-cell detection threshold and noise estimate (mean power per cell).

    power: float (n_range, n_doppler). Returns (threshold, noise), both float of that shape.
    """
    if power.ndim != 2:
        raise ValueError(f"power: expected a 2-D (range, Doppler) map, got shape {power.shape}")
    kernel = _kernel(params)
    padded, vpad = _pad(power.astype(np.float64), params)
    count = np.rint(fftconvolve(vpad, kernel, mode="valid"))
    # effective cells scale with the count of training cells that remain near range edges
    n_eff = count * effective_cells(params, windowed) / kernel.sum()
    if params.kind == "ca":
        total = fftconvolve(padded, kernel, mode="valid")
        noise = np.maximum(total, 0.0) / np.maximum(count, 1.0)
        alpha = np.empty_like(noise)
        for c in np.unique(count):
            alpha[count == c] = ca_factor(params.pfa, n_channels, n_eff[count == c][0])
        return alpha * noise, noise
    # ordered statistic over the training cells (range edges: zero padding excluded)
    win = np.lib.stride_tricks.sliding_window_view(padded, kernel.shape)
    vwin = np.lib.stride_tricks.sliding_window_view(vpad, kernel.shape)
    sel = kernel.ravel() > 0
    cells = win.reshape(*win.shape[:2], -1)[..., sel]
    ok = vwin.reshape(*vwin.shape[:2], -1)[..., sel] > 0
    cells = np.where(ok, cells, np.inf)
    threshold = np.empty(power.shape)
    noise = np.empty(power.shape)
    for c in np.unique(count).astype(int):
        m = count == c
        k = max(1, min(c, int(round(params.os_rank * c))))
        kth = np.partition(cells[m], k - 1, axis=-1)[:, k - 1]
        alpha = os_factor(params.pfa, n_channels, c, k)
        threshold[m] = alpha * kth
        # E[k-th of c] ~ theta * ppf(k / (c + 1)); mean noise power per cell = L * theta
        noise[m] = kth * n_channels / stats.gamma(n_channels).ppf(k / (c + 1))
    return threshold, noise


def local_peaks(power: np.ndarray, mask: np.ndarray, size: tuple[int, int] = (3, 3)
                ) -> np.ndarray:
    """Peak grouping: cells of ``mask`` that are the maximum of their (range, Doppler)
    neighbourhood (Doppler circular). Returns int (n, 2) of (range_bin, doppler_bin)."""
    mx = maximum_filter(power, size=size, mode=("nearest", "wrap"))
    return np.argwhere(mask & (power >= mx))


def paper_threshold(cube: np.ndarray, threshold_db: float) -> tuple[np.ndarray, np.ndarray]:
    """The paper's detector: threshold the first channel's range-Doppler map.

    cube: complex (n_virtual, n_range, n_doppler). The threshold is ``threshold_db`` above
    the map's median power (a robust noise-floor estimate). Returns (mask bool
    (n_range, n_doppler), channel-0 power float (n_range, n_doppler)).
    """
    p0 = np.abs(cube[0]) ** 2
    floor = np.median(p0)
    return p0 > floor * 10.0 ** (threshold_db / 10.0), p0
