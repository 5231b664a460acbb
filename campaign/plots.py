"""Figures of the curves document (``campaign.curves.document``): ``pd_swerling0.png``,
``pd_swerling1.png`` (Pd against cell SNR, measured and theory, one panel per detector),
``crb_range.png``, ``crb_radial_velocity.png``, ``crb_azimuth.png`` (RMSE against the
Cramer-Rao bound) and ``crb_resolution.png`` (two-target resolution probability)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402 - after the backend choice


def detection_figures(doc: dict[str, Any], folder: Path) -> list[Path]:
    """One figure per Swerling case; returns the files written."""
    out = []
    rows = doc["detection"]
    for sw in (0, 1):
        mine = [r for r in rows if r["swerling"] == sw]
        panels = sorted({(r["path"], r["detector"]) for r in mine},
                        key=lambda p: (p[0] != "host", p[1]))
        fig, axes = plt.subplots(1, len(panels), figsize=(3.2 * len(panels), 3.4),
                                 sharey=True, squeeze=False)
        for ax, (path, kind) in zip(axes[0], panels, strict=True):
            for r, colour in zip([r for r in mine if (r["path"], r["detector"]) == (path, kind)],
                                 ("C0", "C3", "C2", "C1"), strict=False):
                ax.plot(r["cell_snr_db"], r["pd"], "o", ms=3, color=colour,
                        label=f"Pfa {r['pfa']:g} (meas. {r['pfa_conditional']:.2g})")
                ax.plot(r["cell_snr_db"], r["pd_theory"], "-", lw=1, color=colour)
            ax.set_title(f"{path} {kind.upper()}-CFAR", fontsize=9)
            ax.set_xlabel("per-channel cell SNR, dB")
            ax.grid(alpha=0.3)
            ax.legend(fontsize=6, loc="lower right")
        axes[0][0].set_ylabel("Pd (dots: measured, lines: theory)")
        fig.suptitle(f"Swerling {sw}, NCI of {mine[0]['integrated_channels']} channels, "
                     f"{mine[0]['train_cells']} training cells", fontsize=10)
        fig.tight_layout()
        p = folder / f"pd_swerling{sw}.png"
        fig.savefig(p, dpi=110)
        plt.close(fig)
        out.append(p)
    return out


def estimation_figures(doc: dict[str, Any], folder: Path) -> list[Path]:
    """RMSE against the CRB per quantity (the cells' chains, then the whole frames'), and
    the resolution probability."""
    out = []
    every = doc["estimation"] + doc.get("estimation_frames", [])
    for quantity in dict.fromkeys(r["quantity"] for r in doc["estimation"]):
        rows = [r for r in every if r["quantity"] == quantity]
        r = rows[0]
        fig, ax = plt.subplots(figsize=(4.6, 3.4))
        for row, style in zip(rows, ("o-", "s--", "^-", "v-", "d--", "x-"), strict=False):
            ax.semilogy(row["snr_db"], row["rmse"], style, ms=3,
                        label=f"RMSE, {row['chain']} chain")
        ax.semilogy(r["snr_db"], r["crb"], "k--", lw=1, label="Cramer-Rao bound")
        if "crb_array" in r:
            ax.semilogy(r["snr_db"], r["crb_array"], "k:", lw=1,
                        label="array CRB of the cell snapshot")
        if "crb_cells" in r:
            ax.semilogy(r["snr_db"], r["crb_cells"], "k:", lw=1,
                        label="CRB of the three cells interpolated")
        if r["threshold_snr_db"] is not None:
            ax.axvline(r["threshold_snr_db"], color="grey", lw=0.8, ls=":",
                       label="threshold (within 3 dB from here)")
        ax.set_xlabel("per-channel, per-sample SNR, dB")
        ax.set_ylabel(f"{quantity.replace('_', ' ')}, {r['unit']}")
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=6, loc="upper right")
        fig.tight_layout()
        p = folder / f"crb_{quantity}.png"
        fig.savefig(p, dpi=110)
        plt.close(fig)
        out.append(p)
    res = doc["resolution"]
    fig, ax = plt.subplots(figsize=(4.6, 3.4))
    ax.plot(res["separation_bw"], res["probability"], "o-", ms=3)
    ax.axhline(0.9, color="grey", lw=0.8, ls=":")
    ax.set_xlabel(f"separation, beamwidths ({res['beamwidth_deg']} deg)")
    ax.set_ylabel("P(resolved)")
    ax.set_title(f"two equal targets, {res['cell_snr_db']:g} dB cell SNR per channel",
                 fontsize=9)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    p = folder / "crb_resolution.png"
    fig.savefig(p, dpi=110)
    plt.close(fig)
    out.append(p)
    return out
