"""Figures (matplotlib, Agg backend, PNG files)."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from model.config import RadarConfig  # noqa: E402
from model.reference import signed_bins  # noqa: E402


def _save(fig: plt.Figure, path: Path, tight: bool = True) -> Path:
    """Write ``fig`` to ``path`` (creating folders) and release it."""
    if tight:
        fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path)
    plt.close(fig)
    return path


POWER_LABEL = "power (dB re 1 LSB², LSB = one ADC code)"
"""Colour-bar label of every power map: the float reference keeps the ADC's scale."""
VELOCITY_LABEL = "radial velocity (m/s, + receding)"


def _range_axis(ax: plt.Axes, cfg: RadarConfig, max_range_m: float | None) -> None:
    """Range on the y axis, cropped to ``max_range_m`` when given, the label saying so."""
    if max_range_m is not None and max_range_m < cfg.max_range_m:
        ax.set_ylim(0, max_range_m)
        ax.set_ylabel(f"range (m; 0-{max_range_m:.0f} of {cfg.max_range_m:.0f} m shown)")
    else:
        ax.set_ylabel("range (m)")


def _aliased(v: float, cfg: RadarConfig) -> tuple[float, bool]:
    """Where velocity ``v`` (m/s) shows on the +-vmax axis, and whether it aliased."""
    vmax = cfg.max_velocity_mps
    if -vmax <= v < vmax:
        return v, False
    return (v + vmax) % (2 * vmax) - vmax, True


def _rd_grid(cfg: RadarConfig) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(Doppler column order for a signed axis, velocity (m/s) per column, range (m) per
    row) of a natural-order (n_range, n_doppler) map."""
    order = np.argsort(signed_bins(cfg.n_doppler))
    vel = signed_bins(cfg.n_doppler)[order] * cfg.velocity_bin_mps
    return order, vel, np.arange(cfg.n_range_bins) * cfg.range_bin_m


def plot_range_doppler(power: np.ndarray, cfg: RadarConfig, path: Path, title: str,
                       markers: list[tuple[float, float, str]] | None = None,
                       max_range_m: float | None = None) -> Path:
    """Range-Doppler map in dB. power: float (n_range, n_doppler) natural Doppler order.

    ``markers``: (range_m, radial_velocity_mps, label) drawn as circles (the scene truth);
    velocities outside +-vmax are drawn where they alias to. ``max_range_m`` crops the plot.
    """
    order, vel, rng = _rd_grid(cfg)
    pdb = 10.0 * np.log10(np.maximum(power[:, order], 1e-12))
    fig, ax = plt.subplots(figsize=(7, 5), dpi=110)
    floor = np.median(pdb)
    im = ax.pcolormesh(vel, rng, pdb, shading="nearest", vmin=floor - 3, vmax=pdb.max(),
                       cmap="viridis")
    fig.colorbar(im, ax=ax, label=POWER_LABEL)
    for r, v, label in markers or []:
        v, aliased = _aliased(v, cfg)
        ax.plot(v, r, "o", mfc="none", mec="r", ms=12)
        ax.annotate(label + (" (aliased)" if aliased else ""), (v, r), xytext=(6, 6),
                    textcoords="offset points", color="r")
    ax.set_xlabel(VELOCITY_LABEL)
    _range_axis(ax, cfg, max_range_m)
    ax.set_title(title)
    return _save(fig, path)


def plot_detection_mask(power: np.ndarray, mask: np.ndarray, cfg: RadarConfig, path: Path,
                        title: str, max_range_m: float | None = None,
                        markers: list[tuple[float, float, str]] | None = None) -> Path:
    """The paper's Fig. 6: channel-0 range-Doppler map (left) and its thresholded image
    (right: black = over the threshold). power: float (n_range, n_doppler), mask: bool
    (n_range, n_doppler), natural Doppler order. ``markers``: (range_m, radial_velocity_mps,
    label) of the scene's targets, circled on both panels; those with no cell over the
    threshold within one bin are named in a note under the panels."""
    order, vel, rng = _rd_grid(cfg)
    pdb = 10.0 * np.log10(np.maximum(power[:, order], 1e-12))
    shown = mask[:, order]
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.8), dpi=110, sharey=True)
    im = axes[0].pcolormesh(vel, rng, pdb, shading="nearest", cmap="viridis",
                            vmin=np.median(pdb) - 3, vmax=pdb.max())
    fig.colorbar(im, ax=axes[0], label=POWER_LABEL)
    axes[1].pcolormesh(vel, rng, shown.astype(float), shading="nearest", cmap="gray_r",
                       vmin=0, vmax=1)
    axes[0].set_title("range-speed response, channel 0")
    axes[1].set_title("thresholded (black: over the threshold)")
    below = []
    for r, v, label in markers or []:
        v, aliased = _aliased(v, cfg)
        rb, db = int(round(r / cfg.range_bin_m)), int(np.argmin(np.abs(vel - v)))
        hit = shown[max(rb - 1, 0):rb + 2, max(db - 1, 0):db + 2].any()
        for ax in axes:
            ax.plot(v, r, "o", mfc="none", mec="r", ms=12)
            ax.annotate(label + (" (aliased)" if aliased else ""), (v, r), xytext=(6, 6),
                        textcoords="offset points", color="r")
        if not hit:
            below.append(f"{label} ({r:.0f} m)")
    for ax in axes:
        ax.set_xlabel(VELOCITY_LABEL)
        _range_axis(ax, cfg, max_range_m)
    fig.suptitle(title)
    if below:
        fig.text(0.01, 0.01, f"not over the threshold in channel 0: {', '.join(below)} (one "
                 f"channel lacks the integration gain of all {cfg.n_virtual}; the CFAR on the "
                 f"integrated map detects it)", fontsize=8, va="bottom")
        fig.tight_layout(rect=(0, 0.05, 1, 1))
        return _save(fig, path, tight=False)
    return _save(fig, path)


def plot_range_azimuth_pair(maps: list[tuple[np.ndarray, str]], az: np.ndarray,
                            cfg: RadarConfig, path: Path, max_range_m: float | None = None,
                            note: str | None = None, title: str | None = None) -> Path:
    """Range-azimuth maps side by side on one colour scale (the paper's Fig. 5 with and
    without TX beamforming). maps: (float (n_range, n_fft) power, title). ``note``: text
    under the maps (e.g. why an aliased target is smeared in azimuth); ``title``: over
    them."""
    rng = np.arange(cfg.n_range_bins) * cfg.range_bin_m
    ok = np.isfinite(az)
    dbs = [10 * np.log10(np.maximum(m[:, ok], 1e-12)) for m, _ in maps]
    vmax = max(d.max() for d in dbs)
    vmin = min(np.median(d) for d in dbs)
    fig, axes = plt.subplots(1, len(maps), figsize=(5.5 * len(maps), 4.8), dpi=110,
                             sharey=True, squeeze=False)
    # the colour bar right beside the last map (no gap), the note under the maps
    fig.subplots_adjust(left=0.07, right=0.9, wspace=0.08, top=0.85,
                        bottom=0.2 if note else 0.12)
    for ax, d, (_, map_title) in zip(axes[0], dbs, maps, strict=True):
        im = ax.pcolormesh(az[ok], rng, d, shading="nearest", cmap="viridis", vmin=vmin,
                           vmax=vmax)
        ax.set_title(map_title)
        ax.set_xlabel("azimuth (deg, + left)")
    _range_axis(axes[0][0], cfg, max_range_m)
    cax = fig.add_axes((0.91, axes[0][0].get_position().y0, 0.015,
                        axes[0][0].get_position().height))
    fig.colorbar(im, cax=cax, label=POWER_LABEL)
    if title:
        fig.suptitle(title)
    if note:
        fig.text(0.01, 0.01, note, fontsize=7, va="bottom", wrap=True)
    return _save(fig, path, tight=False)


def plot_point_cloud(x: np.ndarray, y: np.ndarray, snr_db: np.ndarray, path: Path, title: str,
                     truth: list[tuple[float, float, str]] | None = None,
                     boxes: list[dict] | None = None, missed: list[str] | None = None,
                     note: str | None = None) -> Path:
    """Bird's-eye view of a point cloud (x forward up, y left to the left: the axes of the
    live view), coloured by SNR. x, y, snr_db: float (n,) in m, m, dB.

    truth: (x_m, y_m, label) ground-truth markers (targets and object centres); ``missed``:
    labels of truth targets no point matched (drawn as red crosses, "missed" in the legend);
    boxes: dicts with x, y, length, width, heading_deg, label (detected objects) drawn as
    rotated rectangles, their labels above left (truth labels below right, so they do not
    overlap). A legend names truth, radar points, GNN boxes and missed targets; axis limits
    include every marker and label (nothing clipped). ``note``: text under the plot.
    """
    from mpl_toolkits.axes_grid1 import make_axes_locatable

    fig, ax = plt.subplots(figsize=(6.5, 7), dpi=110)
    handles = []
    sc = ax.scatter(y, x, c=snr_db, cmap="plasma", s=28, zorder=3, label="radar points")
    handles.append(sc)
    cax = make_axes_locatable(ax).append_axes("right", size="4%", pad=0.1)
    fig.colorbar(sc, cax=cax, label="point SNR (dB)")
    missed = set(missed or [])
    hs, vs = [0.0, *np.asarray(y, float)], [0.0, *np.asarray(x, float)]
    for tx, ty, label in truth or []:
        if label in missed:
            h, = ax.plot(ty, tx, "x", color="r", ms=14, mew=2.5, zorder=4,
                         label="truth, missed")
            ax.annotate(f"{label} missed", (ty, tx), xytext=(8, -12),
                        textcoords="offset points", color="r", annotation_clip=False)
        else:
            h, = ax.plot(ty, tx, "s", mfc="none", mec="g", ms=14, zorder=2, label="truth")
            ax.annotate(label, (ty, tx), xytext=(8, -12), textcoords="offset points",
                        color="g", annotation_clip=False)
        if h.get_label() not in [k.get_label() for k in handles]:
            handles.append(h)
        hs.append(ty)
        vs.append(tx)
    for b in boxes or []:
        h = np.radians(b["heading_deg"])
        u = np.array([np.cos(h), np.sin(h)]) * b["length"] / 2
        w = np.array([-np.sin(h), np.cos(h)]) * b["width"] / 2
        c = np.array([b["x"], b["y"]])
        pts = np.array([c + u + w, c + u - w, c - u - w, c - u + w, c + u + w])
        line, = ax.plot(pts[:, 1], pts[:, 0], "-", color="tab:blue", label="GNN boxes")
        if "GNN boxes" not in [k.get_label() for k in handles]:
            handles.append(line)
        ax.annotate(b.get("label", ""), (b["y"], b["x"]), xytext=(-8, 8), ha="right",
                    textcoords="offset points", color="tab:blue", annotation_clip=False)
        hs.extend(pts[:, 1])
        vs.extend(pts[:, 0])
    radar, = ax.plot(0, 0, "k^", ms=10, label="radar")
    handles.append(radar)
    # limits with room for the labels (about 20 % of the span on each side, 12 % on top);
    # y grows to the left
    h0, h1, v0, v1 = min(hs), max(hs), min(vs), max(vs)
    span = max(h1 - h0, v1 - v0, 10.0)
    ax.set_xlim(h1 + 0.2 * span, h0 - 0.2 * span)
    ax.set_ylim(v0 - 0.08 * span, v1 + 0.12 * span)
    ax.set_xlabel("y (m, left +)")
    ax.set_ylabel("x (m, forward)")
    ax.set_aspect("equal", adjustable="box")
    ax.grid(alpha=0.3)
    ax.legend(handles=handles, loc="lower right", fontsize=8, framealpha=0.9)
    ax.set_title(title)
    if note:
        fig.text(0.01, 0.005, note, fontsize=7, va="bottom", wrap=True)
    return _save(fig, path)


def plot_side_view(x: np.ndarray, z: np.ndarray, snr_db: np.ndarray, path: Path, title: str
                   ) -> Path:
    """Side view (x-z) of a point cloud from an array with vertical extent: x forward to the
    right, z up, coloured by SNR. x, z, snr_db: float (n,) in m, m, dB."""
    fig, ax = plt.subplots(figsize=(7, 4), dpi=110)
    sc = ax.scatter(x, z, c=snr_db, cmap="plasma", s=28, zorder=3, label="radar points")
    fig.colorbar(sc, ax=ax, label="point SNR (dB)")
    radar, = ax.plot(0, 0, "k>", ms=10, label="radar")
    top = max(float(np.max(np.abs(z), initial=0.0)), 1.0)
    ax.set_xlim(0.0, max(float(np.max(x, initial=0.0)) * 1.1, 5.0))
    ax.set_ylim(-1.2 * top, 1.2 * top)
    ax.set_xlabel("x (m, forward)")
    ax.set_ylabel("z (m, up)")
    ax.grid(alpha=0.3)
    ax.legend(handles=[sc, radar], loc="lower right", fontsize=8, framealpha=0.9)
    ax.set_title(title)
    return _save(fig, path)
