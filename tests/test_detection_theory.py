"""model.detection_theory against a brute-force draw of the statistics themselves (complex
Gaussian channels, exponential training cells; no radar), and the CRB formula."""

from __future__ import annotations

import numpy as np
import pytest

from model import detection_theory as dt
from model.cfar_stats import ca_factor, go_so_factor, os_factor
from model.reference import hann_periodic

L, N, PFA, DRAWS = 4, 16, 1e-2, 60_000


def brute_pd(kind: str, snr: float, swerling: int, alpha: float, rng: np.random.Generator
             ) -> float:
    """Pd by drawing X (L channels, target common amplitude) and the training cells."""
    noise = (rng.standard_normal((DRAWS, L)) + 1j * rng.standard_normal((DRAWS, L))) / np.sqrt(2)
    amp = np.sqrt(snr * (rng.exponential(size=(DRAWS, 1)) if swerling else np.ones((DRAWS, 1))))
    phase = np.exp(2j * np.pi * rng.random((DRAWS, 1)))
    x = np.sum(np.abs(noise + amp * phase) ** 2, axis=1)
    cells = rng.gamma(L, size=(DRAWS, N))                # independent cells, mean L
    if kind == "ca":
        z = cells.mean(axis=1)
    elif kind in ("go", "so"):
        h1, h2 = cells[:, :N // 2].mean(axis=1), cells[:, N // 2:].mean(axis=1)
        z = np.maximum(h1, h2) if kind == "go" else np.minimum(h1, h2)
    else:
        z = np.sort(cells, axis=1)[:, 12 - 1]
    return float(np.mean(x > alpha * z))


def theory(kind: str) -> tuple[float, dt.QuantileFn]:
    """(alpha for PFA, the noise estimate's quantile function) of each detector."""
    if kind == "ca":
        return float(ca_factor(PFA, L, N)), dt.ca_quantile(L, N)
    if kind in ("go", "so"):
        return go_so_factor(PFA, L, N / 2, kind), dt.go_so_quantile(L, N / 2, kind)
    return os_factor(PFA, L, N, 12), dt.os_quantile(L, N, 12)


@pytest.mark.parametrize("kind", ["ca", "go", "so", "os"])
@pytest.mark.parametrize("swerling", [0, 1])
def test_cfar_pd_matches_brute_force(kind: str, swerling: int) -> None:
    rng = np.random.default_rng([7, swerling, len(kind), ord(kind[0])])
    alpha, q = theory(kind)
    for snr_db in (-30.0, 0.0, 3.0, 6.0):
        snr = 10 ** (snr_db / 10)
        want = dt.cfar_pd(alpha, q, L, snr, swerling)
        got = brute_pd(kind, snr, swerling, alpha, rng)
        sigma = np.sqrt(max(want * (1 - want), 1e-4) / DRAWS)
        assert abs(got - want) < 5 * sigma + 1e-3, (kind, swerling, snr_db, got, want)


@pytest.mark.parametrize("kind", ["ca", "go", "so", "os"])
def test_pd_at_zero_snr_is_the_pfa(kind: str) -> None:
    alpha, q = theory(kind)
    for swerling in (0, 1):
        assert dt.cfar_pd(alpha, q, L, 0.0, swerling) == pytest.approx(PFA, rel=1e-3)
    alpha = float(ca_factor(1e-6, 64, 150.0))
    assert dt.cfar_pd(alpha, dt.ca_quantile(64, 150.0), 64, 0.0, 1) == pytest.approx(
        1e-6, rel=1e-3)


def test_cut_sf_swerling1_closed_form_single_channel() -> None:
    """L = 1 Swerling 1 with a fixed threshold: Pd = Pfa^(1 / (1 + snr)) (Richards 6.3)."""
    t = -np.log(1e-4)
    for snr in (0.5, 3.0, 30.0):
        assert float(dt.cut_sf(t, 1, snr, 1)) == pytest.approx(1e-4 ** (1 / (1 + snr)),
                                                                rel=1e-5)


def test_tone_crb_against_least_squares_estimates() -> None:
    """Periodogram-peak (ML) frequency estimates of a tone at high SNR reach the bound."""
    rng = np.random.default_rng(3)
    n, snr, trials = 32, 10.0, 4000
    f0 = 0.1234
    t = np.arange(n)
    x = np.exp(2j * np.pi * f0 * t) + (rng.standard_normal((trials, n)) + 1j *
                                      rng.standard_normal((trials, n))) / np.sqrt(2 * snr)
    grid = f0 + np.linspace(-0.02, 0.02, 2001)
    spec = np.abs(x @ np.exp(-2j * np.pi * np.outer(t, grid))) ** 2
    est = grid[np.argmax(spec, axis=1)]
    rmse = np.sqrt(np.mean((est - f0) ** 2))
    assert rmse == pytest.approx(dt.tone_frequency_crb(snr, n), rel=0.08)
    assert dt.tone_frequency_crb(snr, n, looks=4) == pytest.approx(
        dt.tone_frequency_crb(snr, n) / 2)


def test_three_cell_bound_against_least_squares_estimates() -> None:
    """ML (least-squares) offsets from the three Hann-windowed DFT cells of a tone reach
    :func:`three_cell_information`'s bound at high SNR; the cell gain at the centre is
    (sum w)^2 / sum w^2 = 2N/3; :func:`three_cell_crb` lies above the whole data's bound."""
    rng = np.random.default_rng(4)
    n, snr, trials, off = 32, 10.0, 3000, 0.2
    w = hann_periodic(n)
    t = np.arange(n)
    e = w * np.exp(-2j * np.pi * np.outer([-1.0, 0.0, 1.0], t) / n)          # (3, n)
    x = np.exp(2j * np.pi * off * t / n) + (rng.standard_normal((trials, n)) + 1j *
                                           rng.standard_normal((trials, n))) / np.sqrt(2 * snr)
    y = x @ e.T                                                          # (trials, 3)
    ci = np.linalg.inv(e @ e.conj().T)
    grid = off + np.linspace(-0.1, 0.1, 1001)
    s = np.exp(2j * np.pi * np.outer(grid, t) / n) @ e.T                 # (grid, 3)
    fit = np.abs(y.conj() @ ci @ s.T) ** 2 / np.einsum("gi,ij,gj->g", s.conj(), ci, s).real
    rmse = np.sqrt(np.mean((grid[np.argmax(fit, axis=1)] - off) ** 2))
    bound = 1 / np.sqrt(snr * dt.three_cell_information(w, n, np.array([off]))[0])
    assert rmse == pytest.approx(bound, rel=0.08)
    assert dt.cell_snr_gain(w, n, np.zeros(1))[0] == pytest.approx(2 * n / 3)
    hann = (hann_periodic(256), 256)
    assert dt.three_cell_crb(1.0, hann, hann, 64) > dt.tone_frequency_crb(1.0, 256, 256 * 64)


def test_cell_snapshot_bound_against_ml_estimates_between_bins() -> None:
    """The ML (periodogram-peak) frequency across 16 elements of one cell of a 32 x 32
    Hann-windowed 2-D DFT, the tone at offsets uniform in +-0.5 bin on both axes, reaches
    :func:`cell_snapshot_crb`; the bound of a tone at the cell's centre is 11 % (0.98 dB of
    variance) lower, which the estimate does not reach."""
    rng = np.random.default_rng(5)
    n, m, snr, trials, f0 = 16, 32, 0.2, 4000, 0.1
    w, t, v = hann_periodic(m), np.arange(m), np.arange(n)
    off = rng.uniform(-0.5, 0.5, (trials, 2))
    cell = np.prod(np.exp(2j * np.pi * off[:, :, None] * t / m) @ w, axis=1)   # (trials,)
    noise = np.sqrt(np.sum(w ** 2) ** 2 / 2)
    x = (np.sqrt(snr) * cell * np.exp(2j * np.pi * rng.random(trials)))[:, None] \
        * np.exp(2j * np.pi * f0 * v) + noise * (rng.standard_normal((trials, n)) + 1j
                                                * rng.standard_normal((trials, n)))
    grid = f0 + np.linspace(-0.01, 0.01, 2001)
    est = grid[np.argmax(np.abs(x @ np.exp(-2j * np.pi * np.outer(v, grid))), axis=1)]
    rmse = np.sqrt(np.mean((est - f0) ** 2))
    bound = dt.cell_snapshot_crb(snr, n, ((w, m), (w, m)))
    assert rmse == pytest.approx(bound, rel=0.04)
    centre = dt.tone_frequency_crb(snr * (2 * m / 3) ** 2, n)
    assert bound / centre == pytest.approx(1.12, abs=0.01)
    assert dt.cell_snapshot_crb(0.0, n, ((w, m),)) == float("inf")
