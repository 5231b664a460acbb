"""Theoretical detection probability of the CFAR detectors on a non-coherently integrated
(NCI) map, for the thresholds of ``model/cfar_stats.py``, and the Cramer-Rao bound of a tone
in white noise (docs/curves.md).

Units: noise power 1 per channel and cell; ``snr`` the per-channel SNR of the target's cell
(linear). The statistic of the cell under test is X = sum over L channels of |n_v + s_v|^2:

- noise only: X ~ Gamma(L, 1) (a sum of L unit exponentials; 2X is chi-square with 2L
  degrees of freedom);
- Swerling 0 (constant amplitude, |s_v|^2 = snr): 2X is non-central chi-square with 2L
  degrees of freedom and non-centrality 2 L snr (Richards, *Fundamentals of Radar Signal
  Processing*, 2nd ed., section 6.3, non-coherent integration of L samples);
- Swerling 1 with the amplitude common to all channels (one Rayleigh draw per frame): the
  Swerling 0 result averaged over snr' ~ Exponential(mean snr) (Richards section 6.3.4:
  Pd of a fluctuating target = the non-fluctuating Pd averaged over the RCS density).

CFAR (Gandhi & Kassam 1988; Richards section 7.3): the threshold is alpha * Z, Z the noise
estimate from the training cells, independent of X, so
Pd = E_Z[P(X > alpha Z)] = integral over u in (0, 1) of P(X > alpha q_Z(u)) du, q_Z the
quantile function of Z:

- CA: Z = mean of N independent cells ~ Gamma(L N, 1/N); windowed (correlated) cells enter
  with N = N_eff, the effective count of ``model.cfar_stats`` (a moment match);
- GO / SO: Z = max / min of the two half means, each Gamma(L N_h, 1/N_h), independent:
  q_Z(u) = q_Y(sqrt(u)) for GO, q_Y(1 - sqrt(1 - u)) for SO;
- OS: Z = the k-th smallest of n independent Gamma(L, 1) cells: Z = q_G(B), B ~
  Beta(k, n - k + 1).

At snr = 0 every Pd here is the detector's Pfa, which is how ``model/cfar_stats.py`` chose
alpha. ``tests/test_detection_theory.py`` checks each form against a brute-force draw of the
statistic itself (exponential variates, no radar).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy import stats

QuantileFn = Callable[[np.ndarray], np.ndarray]
"""u in (0, 1) -> the noise estimate Z's quantile at u (arrays of the same shape)."""

_GL_NODES, _GL_WEIGHTS = np.polynomial.legendre.leggauss(64)


def cut_sf(x: np.ndarray | float, n_channels: int, snr: float, swerling: int) -> np.ndarray:
    """P(X > x) for the cell under test (module docstring); x float array, any shape."""
    x = np.asarray(x, dtype=float)
    lam = 2.0 * n_channels * snr
    if swerling not in (0, 1):
        raise ValueError(f"swerling: must be 0 or 1, got {swerling}")
    if snr <= 0.0:
        return stats.gamma.sf(x, n_channels)
    if swerling == 0:
        return stats.ncx2.sf(2.0 * x, 2 * n_channels, lam)
    # Swerling 1: average over snr' = -snr log(1 - v), v uniform, by Gauss-Legendre on
    # sub-intervals of v (the exponential's quantile is steep near v = 1)
    edges = np.array([0.0, 0.5, 0.9, 0.99, 0.999, 0.9999, 1.0])
    total = np.zeros_like(x)
    for a, b in zip(edges[:-1], edges[1:], strict=True):
        v = a + (b - a) * (_GL_NODES + 1.0) / 2.0
        w = (b - a) / 2.0 * _GL_WEIGHTS
        lam_v = 2.0 * n_channels * snr * -np.log1p(-v)
        total += np.tensordot(stats.ncx2.sf(2.0 * x[..., None], 2 * n_channels, lam_v), w,
                              axes=([-1], [0]))
    return total


def ca_quantile(n_channels: int, n_eff: float) -> QuantileFn:
    """Quantile function of the CA noise estimate: mean of n_eff cells, Gamma(L N, 1/N)."""
    g = stats.gamma(n_channels * n_eff, scale=1.0 / n_eff)
    return g.ppf


def go_so_quantile(n_channels: int, n_eff_half: float, kind: str) -> QuantileFn:
    """Quantile function of max (``go``) / min (``so``) of two independent half means."""
    y = stats.gamma(n_channels * n_eff_half, scale=1.0 / n_eff_half)
    if kind == "go":
        return lambda u: y.ppf(np.sqrt(u))
    if kind == "so":
        return lambda u: y.ppf(-np.expm1(0.5 * np.log1p(-u)))
    raise ValueError(f"kind: must be 'go' or 'so', got {kind!r}")


def os_quantile(n_channels: int, n_train: int, k: int) -> QuantileFn:
    """Quantile function of the k-th smallest of n_train independent Gamma(L, 1) cells."""
    g = stats.gamma(n_channels)
    order = stats.beta(k, n_train - k + 1)
    return lambda u: g.ppf(order.ppf(u))


_U_EDGES = np.array([0.0, 1e-8, 1e-6, 1e-4, 1e-2, 0.1, 0.5, 0.9, 1 - 1e-2, 1 - 1e-4,
                     1 - 1e-6, 1 - 1e-8, 1.0])
"""Sub-intervals of u for the composite Gauss-Legendre rule of :func:`cfar_pd` (finer
towards both ends, where the quantile functions are steep)."""


def cfar_pd(alpha: float, quantile: QuantileFn, n_channels: int, snr: float,
            swerling: int) -> float:
    """Pd = integral over u of P(X > alpha q_Z(u)) du (module docstring), by composite
    64-point Gauss-Legendre over :data:`_U_EDGES`."""
    a, b = _U_EDGES[:-1, None], _U_EDGES[1:, None]
    u = a + (b - a) * (_GL_NODES + 1.0) / 2.0                 # (intervals, 64)
    w = (b - a) / 2.0 * _GL_WEIGHTS
    val = float(np.sum(cut_sf(alpha * quantile(u), n_channels, snr, swerling) * w))
    return min(max(val, 0.0), 1.0)


def tone_frequency_crb(snr: float, n: int, looks: float = 1.0) -> float:
    """Cramer-Rao bound on the standard deviation of a complex tone's frequency, cycles per
    sample: var >= 6 / ((2 pi)^2 SNR N (N^2 - 1)) (Rife & Boorstyn 1974; Kay, *Fundamentals
    of Statistical Signal Processing: Estimation*, example 3.14, complex form), ``snr``
    the per-sample SNR (linear), ``n`` samples, ``looks`` independent repetitions of the
    same tone (the other dimensions' samples: their SNR adds)."""
    if snr <= 0.0 or n < 2:
        return float("inf")
    return float(np.sqrt(6.0 / ((2.0 * np.pi) ** 2 * snr * looks * n * (n * n - 1.0))))


def three_cell_information(window: np.ndarray, n_fft: int, offset: np.ndarray) -> np.ndarray:
    """Fisher information about a tone's offset from its cell's centre (FFT bins) held by
    the cell and its two neighbours (bins -1, 0, +1) of the DFT of ``window``-weighted
    samples (float (n_samples,), zero-padded to ``n_fft``), the tone's complex amplitude
    unknown: per unit per-sample SNR, bins^-2, float (m,) for offsets float (m,).

    J = 2 Re[d^H C^-1 d] - 2 |s^H C^-1 d|^2 / (s^H C^-1 s), the complex Gaussian Fisher
    information (Kay, *Estimation Theory*, section 15.7) with the amplitude eliminated (its
    Schur complement): s the three bins' response, d = ds/d(offset), C = E E^H their noise
    covariance, E[m, t] = w[t] exp(-j 2 pi m t / n_fft)."""
    t = np.arange(len(window))
    e = window * np.exp(-2j * np.pi * np.outer([-1.0, 0.0, 1.0], t) / n_fft)      # (3, n)
    ci = np.linalg.inv(e @ e.conj().T)
    tone = np.exp(2j * np.pi * np.outer(offset, t) / n_fft)                     # (m, n)
    s = tone @ e.T
    d = (tone * (2j * np.pi * t / n_fft)) @ e.T
    sd = np.einsum("mi,ij,mj->m", s.conj(), ci, d)
    ss = np.einsum("mi,ij,mj->m", s.conj(), ci, s).real
    dd = np.einsum("mi,ij,mj->m", d.conj(), ci, d).real
    return 2.0 * (dd - np.abs(sd) ** 2 / ss)


def cell_snr_gain(window: np.ndarray, n_fft: int, offset: np.ndarray) -> np.ndarray:
    """SNR of one cell of the DFT of ``window``-weighted samples over the per-sample SNR,
    for a tone ``offset`` bins (float (m,)) from the cell's centre: |sum w e^(j 2 pi offset
    t / n_fft)|^2 / sum w^2, float (m,)."""
    t = np.arange(len(window))
    return np.abs(np.exp(2j * np.pi * np.outer(offset, t) / n_fft) @ window) ** 2 / np.sum(
        window ** 2)


_OFFSETS = (np.arange(64) + 0.5) / 128.0
"""Offsets (bins) over which the bounds of one cell are averaged: midpoints of 0..0.5, the
responses symmetric, so a uniform offset in [-0.5, 0.5]."""


def three_cell_crb(snr: float, axis: tuple[np.ndarray, int], other: tuple[np.ndarray, int],
                   looks: float) -> float:
    """Cramer-Rao bound on the standard deviation of a tone's frequency along ``axis``,
    cycles per sample, from what a peak interpolator is given: three cells along ``axis``
    (:func:`three_cell_information`) of the one cell across the ``other`` axis (its SNR
    gain :func:`cell_snr_gain`), in each of ``looks`` channels; RMS over offsets uniform in
    [-0.5, 0.5] bin on both axes (the variances averaged). axis, other: (window float
    (n_samples,), n_fft); ``snr`` per ADC sample (linear)."""
    if snr <= 0.0:
        return float("inf")
    inv_j = np.mean(1.0 / three_cell_information(*axis, _OFFSETS))
    inv_g = np.mean(1.0 / cell_snr_gain(*other, _OFFSETS))
    return float(np.sqrt(inv_j * inv_g / (snr * looks)) / axis[1])


def cell_snapshot_crb(snr: float, n_elements: int, axes: tuple[tuple[np.ndarray, int], ...]
                      ) -> float:
    """Cramer-Rao bound on the standard deviation of a tone's frequency across
    ``n_elements`` elements (cycles per element; the angle's spatial frequency over the
    virtual array), from the snapshot of one cell of the DFT along each of ``axes`` (window
    float (n_samples,), n_fft) of every element's samples: :func:`tone_frequency_crb` at
    the cell's SNR, ``snr`` per ADC sample (linear) times the cell's gain
    :func:`cell_snr_gain` on every axis, the variance averaged over the tone's offsets from
    the cell's centre uniform in [-0.5, 0.5] bin on each axis (scalloping: a tone between
    bins gives its cell less SNR; 0.98 dB of variance on two 256-point Hann axes against a
    tone at the centre)."""
    if snr <= 0.0:
        return float("inf")
    inv_g = np.prod([np.mean(1.0 / cell_snr_gain(*ax, _OFFSETS)) for ax in axes])
    return tone_frequency_crb(snr, n_elements) * float(np.sqrt(inv_g))
