"""Monte Carlo of the TDM velocity-unfolding test (issue 14: why the host keeps the angle-peak
test although it is most of the records -> point cloud time).

``host.tdm.choose_folds`` compares, per detected cell, the peak of the angle spectrum of
the channel vector compensated for each TDM alias class (``host.angle.peak_powers``: a
128-point FFT and the exact 1024-grid peak, for ~3.4 classes per cell on ``full``). A
cheaper test needs no angle FFT per class: estimate the angle on the 16-element TX
sub-arrays (where the TDM phase does not enter), beamform each sub-array there, and take the
power of each class as the 4-point DFT over TX of those beams (the TX progression left after
the angle's own progression is removed). For one target it separates the classes far better
(the wrong ones fall to the noise instead of 0.9 dB below); this benchmark shows what it
does to cells with two targets, where the sub-array angle lies between them.

Prints, per case, the fraction of cells whose velocity is reported correctly without the
``ambiguous`` flag, flagged ambiguous, and **wrong without the flag** (the failure that
matters), for the peak test and two variants of the cheap one (sub-array angle from the lag-1
phase, or from the peak of the non-coherent sub-array spectrum), and the CPU time of each
statistic for 1000 cells (all classes):

    python -m benchmarks.bench_unfold [--cells 4000]

Reported, never asserted in tests. ``full`` preset, default ``DetectionParams``.
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable

import numpy as np
import scipy.fft

from host.angle import peak_powers
from host.params import DetectionParams
from host.tdm import choose_folds, tx_phasors
from model.config import RadarConfig, get_preset
from tests.oracles.points import tdm_compensate

Stat = Callable[[np.ndarray, np.ndarray], np.ndarray]


def peak_test(cfg: RadarConfig, n_fft: int) -> Stat:
    """The pipeline's statistic: angle-spectrum peak power per class, float (n, num_tx)."""
    def stat(x: np.ndarray, sb: np.ndarray) -> np.ndarray:
        rows = np.arange(len(x))
        return np.stack([peak_powers(x, n_fft, tx_phasors(cfg, sb + c * cfg.n_doppler), rows)[0]
                         for c in range(cfg.num_tx)], axis=1)
    return stat


def tx_coherent_test(cfg: RadarConfig, angle: str) -> Stat:
    """The cheap statistic: |sum_t phasor_c,t z_t|^2 per class c, z_t the TX sub-array t
    beamformed at the sub-array angle (``angle``: ``lag`` the phase of the lag-1
    correlation inside the sub-arrays; ``nc`` the peak of their non-coherent spectrum,
    64-point FFT, parabolic)."""
    ntx, nrx = cfg.num_tx, cfg.num_rx

    def stat(x: np.ndarray, sb: np.ndarray) -> np.ndarray:
        n = len(x)
        xb = x.reshape(n, ntx, nrx)
        if angle == "lag":
            ps = -np.angle(np.einsum("ntr,ntr->n", xb[:, :, 1:], np.conj(xb[:, :, :-1])))
        else:
            spec = np.abs(scipy.fft.ifft(xb, n=64, axis=-1)) ** 2
            nc = spec.sum(axis=1)
            k = np.argmax(nc, axis=1)
            rows = np.arange(n)
            a, b, c = nc[rows, (k - 1) % 64], nc[rows, k], nc[rows, (k + 1) % 64]
            den = a - 2 * b + c
            d = np.where(den < 0, 0.5 * (a - c) / np.where(den < 0, den, 1.0), 0.0)
            f = ((k + d) / 64 + 0.5) % 1.0 - 0.5          # cycles per element
            ps = 2 * np.pi * f
        ph = np.exp(1j * ps[:, None] * np.arange(ntx * nrx)[None, :]).reshape(n, ntx, nrx)
        z = (xb * ph).sum(axis=2)                                         # (n, num_tx)
        p0 = tx_phasors(cfg, sb[:, None] + np.arange(ntx)[None, :] * cfg.n_doppler)
        return np.abs(np.einsum("nct,nt->nc", p0, z)) ** 2
    return stat


def outcome(stats: dict[str, Stat], cfg: RadarConfig, params: DetectionParams, n: int,
            snr_db: float, rng: np.random.Generator,
            second: tuple[float, float] | None = None) -> dict[str, tuple[float, float, float]]:
    """(correct and unflagged, flagged ambiguous, wrong and unflagged) fractions of ``n``
    cells per statistic: one target (sin(az) uniform in +-0.8, radial velocity uniform
    within +-0.95 max_speed, ``snr_db`` per channel over unit noise), with ``second`` =
    (sin(az) separation, dB below) a second target of the same velocity in the cell."""
    nv, nd = cfg.n_virtual, cfg.n_doppler
    v = np.arange(nv)
    s = rng.uniform(-0.8, 0.8, n)
    k = np.round(rng.uniform(-0.95, 0.95, n) * params.max_speed_mps
                 / cfg.velocity_bin_mps).astype(np.int64)            # unfolded signed bin
    sb = (k + nd // 2) % nd - nd // 2
    m_true = (k - sb) // nd
    amp = 10 ** (snr_db / 20)
    x = amp * np.exp(-1j * np.pi * np.outer(s, v))
    if second is not None:
        sep, below = second
        x = x + amp * 10 ** (-below / 20) * np.exp(
            -1j * np.pi * np.outer(s + sep, v) + 1j * rng.uniform(0, 2 * np.pi, (n, 1)))
    x = x * np.conj(tdm_compensate(cfg, np.ones((n, nv)), k))      # the TDM phase of k
    x = x + (rng.normal(size=(n, nv)) + 1j * rng.normal(size=(n, nv))) / np.sqrt(2)
    power = np.sum(np.abs(x) ** 2, axis=1)
    noise = np.full(n, float(nv))
    snr = 10 * np.log10(np.maximum(power - noise, 1e-30) / noise) + 10 * np.log10(nv)
    out = {}
    for name, stat in stats.items():
        fold, amb = choose_folds(stat(x, sb), cfg, sb * cfg.velocity_bin_mps, snr, params)
        ok = fold == m_true
        out[name] = (float(np.mean(ok & ~amb)), float(np.mean(amb)),
                     float(np.mean(~ok & ~amb)))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cells", type=int, default=4000, help="cells per case")
    args = ap.parse_args()
    cfg = get_preset("full")
    params = DetectionParams()
    stats = {"angle peak (pipeline)": peak_test(cfg, params.angle.n_fft),
             "TX-coherent, lag-1 angle": tx_coherent_test(cfg, "lag"),
             "TX-coherent, NC-peak angle": tx_coherent_test(cfg, "nc")}
    rng = np.random.default_rng(14)
    print(f"## Velocity unfolding on full, {args.cells} cells per case: correct unflagged / "
          f"flagged ambiguous / **wrong unflagged**")
    print("| case | " + " | ".join(stats) + " |")
    print("|---|" + "---|" * len(stats))
    cases: list[tuple[str, float, tuple[float, float] | None]] = [
        (f"one target, {snr} dB per channel", snr, None) for snr in (0, 5, 10, 20, 30)]
    cases += [(f"two targets {sep:g} apart in sin(az), second {below} dB below, 20 dB",
               20.0, (sep, below)) for sep in (0.02, 0.04, 0.0625, 0.1, 0.2)
              for below in (0, 6)]
    for name, snr, second in cases:
        got = outcome(stats, cfg, params, args.cells, snr, rng, second)
        print(f"| {name} | " + " | ".join(f"{a:.3f} / {b:.3f} / **{c:.4f}**"
                                          for a, b, c in got.values()) + " |")
    x = (rng.normal(size=(1000, cfg.n_virtual)) + 1j * rng.normal(size=(1000, cfg.n_virtual)))
    sb = rng.integers(-cfg.n_doppler // 2, cfg.n_doppler // 2, 1000)
    print("| CPU ms per 1000 cells, all 4 classes (best of 5) | " + " | ".join(
        f"{cpu_ms(lambda f=f: f(x, sb)):.2f}" for f in stats.values()) + " |")


def cpu_ms(fn: Callable[[], object], repeat: int = 5) -> float:
    """Best CPU time of ``fn`` in ms."""
    best = float("inf")
    for _ in range(repeat):
        t = time.process_time()
        fn()
        best = min(best, time.process_time() - t)
    return best * 1e3


if __name__ == "__main__":
    main()
