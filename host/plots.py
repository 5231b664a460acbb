"""Figures (matplotlib, Agg backend, PNG files)."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from model.config import RadarConfig  # noqa: E402
from model.reference import signed_bins  # noqa: E402


def plot_range_doppler(power: np.ndarray, cfg: RadarConfig, path: Path, title: str,
                       markers: list[tuple[float, float, str]] | None = None,
                       max_range_m: float | None = None) -> Path:
    """Range-Doppler map in dB. power: float (n_range, n_doppler) natural Doppler order.

    ``markers``: (range_m, radial_velocity_mps, label) drawn as circles (the scene truth);
    velocities outside +-vmax are drawn where they alias to. ``max_range_m`` crops the plot.
    """
    order = np.argsort(signed_bins(cfg.n_doppler))
    pdb = 10.0 * np.log10(np.maximum(power[:, order], 1e-12))
    vel = signed_bins(cfg.n_doppler)[order] * cfg.velocity_bin_mps
    rng = np.arange(cfg.n_range) * cfg.range_bin_m
    fig, ax = plt.subplots(figsize=(7, 5), dpi=110)
    floor = np.median(pdb)
    im = ax.pcolormesh(vel, rng, pdb, shading="nearest", vmin=floor - 3, vmax=pdb.max(),
                       cmap="viridis")
    fig.colorbar(im, ax=ax, label="power (dB, LSB^2)")
    vmax = cfg.max_velocity_mps
    for r, v, label in markers or []:
        if not -vmax <= v < vmax:
            v = (v + vmax) % (2 * vmax) - vmax
            label += " (aliased)"
        ax.plot(v, r, "o", mfc="none", mec="r", ms=12)
        ax.annotate(label, (v, r), xytext=(6, 6), textcoords="offset points", color="r")
    ax.set_xlabel("radial velocity (m/s, + receding)")
    ax.set_ylabel("range (m)")
    if max_range_m is not None:
        ax.set_ylim(0, min(max_range_m, cfg.max_range_m))
    ax.set_title(title)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path)
    plt.close(fig)
    return path
