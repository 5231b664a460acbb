"""CFAR threshold statistics shared by the host CFAR (``host/cfar.py``) and the FPGA CFAR
model (``model/cfar_2d.py``): one place for the false-alarm arithmetic.

A cell of a map that integrates ``n_channels`` independent channels non-coherently is
Gamma(L, theta) distributed under noise (L = n_channels). For CA-CFAR, CUT / mean(training)
is F(2L, 2NL)-distributed for N independent training cells, so the factor is the F quantile.
Windowed FFTs correlate neighbouring cells (periodic Hann: adjacent-bin power correlation
4/9, next 1/36), which makes the training mean noisier; the factor uses the effective
number of independent cells N_eff = N^2 / sum_ij rho_ij^2 (exact variance of the mean).
GO/SO-CFAR compare the means of two training halves; their factor solves
Pfa = E[P(X > alpha * max/min(Y1, Y2))] numerically with each half mean
Gamma(L * N_eff_half, 1 / N_eff_half) distributed and the halves independent.
OS-CFAR uses the k-th smallest training cell; its factor solves
Pfa = E[P(X > alpha * Y_(k))] numerically.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from scipy import integrate, optimize, special, stats

# Power correlation between bins i apart of a periodic-Hann-windowed DFT of white noise:
# |sum w^2 e^{-j2pi i n/N}|^2 / (sum w^2)^2 -> 1, 4/9, 1/36 for i = 0, 1, 2; 0 beyond.
HANN_POWER_CORRELATION = (1.0, 4.0 / 9.0, 1.0 / 36.0)
RECT_POWER_CORRELATION = (1.0,)


def correlation_sum(mask: np.ndarray, rho_r: tuple[float, ...],
                    rho_d: tuple[float, ...]) -> float:
    """sum over training-cell pairs of their power correlation (separable windows);
    mask: (rows, cols) training-cell mask (1 = training cell, 0 = not).

    Only offsets where rho != 0 contribute, so the pair count per offset (the mask's
    autocorrelation there) is taken by shifting the mask: O(cells), not O(cells^2)."""
    total = 0.0
    nr, nd = mask.shape
    for dr, cr in enumerate(rho_r):
        for dd, cd in enumerate(rho_d):
            if dr >= nr or dd >= nd:
                continue
            pairs = float(np.sum(mask[dr:, dd:] * mask[:nr - dr, :nd - dd]))
            if dd and dr:  # (+dr, +dd) and (+dr, -dd), each counted for both orders
                pairs += float(np.sum(mask[dr:, :nd - dd] * mask[:nr - dr, dd:]))
                total += 2 * cr * cd * pairs
            elif dd or dr:
                total += 2 * cr * cd * pairs
            else:
                total += pairs
    return total


def effective_cells_mask(mask: np.ndarray, windowed: tuple[bool, bool] = (True, True),
                         correlations: tuple[tuple[float, ...], tuple[float, ...]] | None
                         = None) -> float:
    """Number of independent cells with the same averaging power as the cells of ``mask``;
    ``correlations``: the (range, Doppler) power correlations between bins 0, 1, ... apart
    (``model.reference.FftAxis.power_correlation``), else those of ``windowed``'s
    unpadded Hann or rectangular windows."""
    n = float((mask > 0).sum())
    rho_r, rho_d = correlations or tuple(
        HANN_POWER_CORRELATION if w else RECT_POWER_CORRELATION for w in windowed)
    return n * n / correlation_sum(mask, rho_r, rho_d)


def ca_factor(pfa: float, n_channels: int, n_eff: float | np.ndarray) -> np.ndarray:
    """CA-CFAR factor alpha: P(CUT > alpha * mean(train)) = pfa under noise."""
    return np.asarray(stats.f.isf(pfa, 2 * n_channels, 2 * n_channels * np.asarray(n_eff)))


@lru_cache(maxsize=256)
def go_so_factor(pfa: float, n_channels: int, n_eff_half: float, kind: str) -> float:
    """GO (``kind="go"``) or SO (``"so"``) CFAR factor alpha:
    P(CUT > alpha * max/min(mean of half 1, mean of half 2)) = pfa under noise."""
    if kind not in ("go", "so"):
        raise ValueError(f"kind: must be 'go' or 'so', got {kind!r}")
    ky, sy = n_channels * n_eff_half, 1.0 / n_eff_half   # half mean: Gamma(ky, scale sy)
    y = stats.gamma(ky, scale=sy)
    top = float(y.isf(1e-15))
    mid = (float(y.ppf(0.01)), float(y.mean()), float(y.ppf(0.99)))
    log_norm = -special.gammaln(ky) - ky * np.log(sy)

    def pfa_of(alpha: float) -> float:
        # density of max(Y1, Y2) is 2 F f, of min 2 (1 - F) f (independent halves)
        def f(v: float) -> float:
            if v <= 0.0:
                return 0.0
            cdf = special.gammainc(ky, v / sy)
            w = 2 * cdf if kind == "go" else 2 * (1 - cdf)
            pdf = np.exp(log_norm + (ky - 1) * np.log(v) - v / sy)
            return special.gammaincc(n_channels, alpha * v) * w * pdf
        val, _ = integrate.quad(f, 0.0, top, limit=400, points=mid)
        return max(val, 1e-300)

    return float(optimize.brentq(lambda a: np.log(pfa_of(a)) - np.log(pfa), 1e-3, 1e4,
                                 xtol=1e-9))


@lru_cache(maxsize=64)
def os_factor(pfa: float, n_channels: int, n_train: int, k: int) -> float:
    """OS-CFAR factor alpha: P(CUT > alpha * (k-th smallest of n_train)) = pfa, cells
    Gamma(n_channels) distributed (independent cells assumed)."""
    g = stats.gamma(n_channels)
    order = stats.beta(k, n_train - k + 1)  # CDF value of the k-th order statistic

    def pfa_of(alpha: float) -> float:
        # integrate over u = F(y), y = F^-1(u): E_u[ sf(alpha * ppf(u)) ]
        val, _ = integrate.quad(lambda u: g.sf(alpha * g.ppf(u)) * order.pdf(u), 0.0, 1.0,
                                limit=200)
        return max(val, 1e-300)

    return float(optimize.brentq(lambda a: np.log(pfa_of(a)) - np.log(pfa), 1e-3, 1e3,
                                 xtol=1e-6))
