"""Each of OpenRadar's detections on the real frame against this chain, cell by cell: why a
setting of ours misses it (docs/profiles.md "Compared with OpenRadar").

    python -m benchmarks.openradar_cells --peer-python out/openradar-venv/bin/python
        [--out out/openradar_cells]

Runs the peer as ``benchmarks/bench_openradar.py`` does (``openradar_peer.py`` in its own
virtualenv, here also writing its map and its two 1-D CFAR thresholds) and ours at the
benchmark's three settings (:func:`benchmarks.bench_openradar.modes`) on frame 0, and writes
to ``--out``:

- ``cells.md``: one row per detection of the peer's 15 dB setting: its range and Doppler bin,
  its Bartlett azimuth, its margin over its threshold (dB; its SNR over its noise estimate is
  that plus the threshold) and its cell over its range bin's floor (the mean over the Doppler
  bins |d| >= 32, of log powers: 2.5 dB under a mean of powers over noise); ours over the
  same floor (mean power), over our CA-CFAR's and OS-CFAR's noise estimate and thresholds
  (Pfa of ``radar process``: 1e-6, with ``--remove-static``'s correction,
  ``host.pipeline.map_cfar``), the Pfa the CA-CFAR would need to detect it, whether it is the
  largest of its 3 x 3 neighbourhood; then for each setting of ours the point within the
  benchmark's 2 bins, or why there is none (:func:`cause`).
- ``rd_full.png`` / ``rd_zoom.png``: both chains' maps and the margins over the thresholds,
  with both chains' detections (the zoom on the movers).

dB in this module: per channel (a map's cell over a noise estimate of the same kind).
"""

from __future__ import annotations

import argparse
import tempfile
from dataclasses import dataclass
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from scipy import stats  # noqa: E402

from benchmarks.bench_openradar import DATA, Detections, modes, near, run_peer  # noqa: E402
from host.adc_capture import open_capture  # noqa: E402
from host.cfar import CfarParams, effective_cells  # noqa: E402
from host.pipeline import map_cfar  # noqa: E402
from model.reference import fft_axes, range_doppler_power  # noqa: E402
from radar.cli import build_parser  # noqa: E402
from radar.commands.process import (  # noqa: E402
    capture_cube,
    capture_frame_cloud,
    process_params,
    profile_of,
)

FLOOR_DOPPLER = 32
"""A range bin's noise floor: the mean over its Doppler bins |d| >= this (no mover there)."""


@dataclass(frozen=True)
class Ours:
    """Our map of the frame and its CFARs: ``nci`` float (n_range, n_doppler), and per
    kind (``ca``, ``os``) the threshold and noise estimate of every cell, both of that shape;
    ``n_eff`` the CA-CFAR's effective training cells; ``n_virtual`` the map's channels."""

    nci: np.ndarray
    threshold: dict[str, np.ndarray]
    noise: dict[str, np.ndarray]
    n_eff: float
    n_virtual: int

    def snr_db(self, kind: str, r: int, d: int) -> float:
        return float(10 * np.log10(self.nci[r, d] / self.noise[kind][r, d]))

    def margin_db(self, kind: str, r: int, d: int) -> float:
        return float(10 * np.log10(self.nci[r, d] / self.threshold[kind][r, d]))

    def ca_pfa(self, r: int, d: int) -> float:
        """The Pfa at which the CA-CFAR's threshold would be the cell's power."""
        return float(stats.f.sf(self.nci[r, d] / self.noise["ca"][r, d], 2 * self.n_virtual,
                                2 * self.n_virtual * self.n_eff))


def cause(row: dict, mode: str, threshold_db: float) -> str:
    """Why setting ``mode`` of ours has no point within 2 bins of the peer's cell ``row``
    ('' if it has one): under the CFAR's threshold, under ``--min-snr-db``, or detected but
    grouped into a peak more than 2 bins away."""
    if row[mode]:
        return ""
    kind = "os" if "os" in mode else "ca"
    margin, snr = row[f"{kind}_margin"], row[f"{kind}_snr"]
    if margin <= 0:
        need = f", needs Pfa {row['ca_pfa']:.1g}" if kind == "ca" else ""
        return f"{kind.upper()}-CFAR: {margin:+.1f} dB under its threshold{need}"
    if mode != "default" and snr <= threshold_db:
        return f"--min-snr-db {threshold_db:g}: {snr:.1f} dB over the {kind.upper()} noise"
    return "detected, grouped into a peak > 2 bins away"


def table_rows(peer: Detections, peer_map: dict[str, np.ndarray], ours: Ours,
               points: dict[str, Detections], threshold_db: float) -> list[dict]:
    """One dict per peer detection, sorted by range then Doppler bin (see the module
    docstring; ``peer_map``: the runner's ``--map``)."""
    det, n_doppler = peer_map["det"], ours.nci.shape[1]
    unit = 20 * np.log10(2) / ours.n_virtual           # its map's unit, dB per channel
    thr = np.maximum(peer_map["thr_doppler"], peer_map["thr_range"])
    far = np.r_[FLOOR_DOPPLER:n_doppler - FLOOR_DOPPLER + 1]
    floor_peer, floor_ours = det[:, far].mean(axis=1), ours.nci[:, far].mean(axis=1)
    rows = []
    for i in np.lexsort((peer.doppler_bin, peer.range_bin)):
        r, d = int(peer.range_bin[i]), int(peer.doppler_bin[i])
        c = d % n_doppler
        block = ours.nci[np.arange(r - 1, r + 2) % ours.nci.shape[0]][
            :, np.arange(c - 1, c + 2) % n_doppler]
        row = {"r": r, "d": d, "az": float(peer.azimuth_deg[i]),
               "peer_margin": float((det[r, c] - thr[r, c]) * unit),
               "peer_floor": float((det[r, c] - floor_peer[r]) * unit),
               "ours_floor": float(10 * np.log10(ours.nci[r, c] / floor_ours[r])),
               "ca_pfa": ours.ca_pfa(r, c), "peak": bool(block.max() <= ours.nci[r, c])}
        for kind in ("ca", "os"):
            row[f"{kind}_snr"] = ours.snr_db(kind, r, c)
            row[f"{kind}_margin"] = ours.margin_db(kind, r, c)
        one = Detections(np.array([r]), np.array([d]), np.zeros(1), np.zeros(1))
        for mode, o in points.items():
            m = near(o, one, n_doppler)[:, 0]
            j = np.flatnonzero(m)
            k = j[np.argmin(np.abs(o.range_bin[j] - r) + np.abs(o.doppler_bin[j] - d))] \
                if len(j) else None
            row[mode] = "" if k is None else f"({o.range_bin[k]},{o.doppler_bin[k]})"
        rows.append(row)
    return rows


def markdown(rows: list[dict], names: list[str], threshold_db: float) -> str:
    """``cells.md`` (module docstring)."""
    head = ["range bin", "Doppler bin", "its az deg", "its margin dB", "its cell over floor",
            "ours over floor", "CA SNR", "CA margin", "OS SNR", "OS margin", "3x3 peak",
            *names]
    out = [f"# The peer's {len(rows)} detections at {threshold_db:g} dB against ours", "",
           "| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for x in rows:
        cells = [str(x["r"]), str(x["d"]), f"{x['az']:.1f}", f"{x['peer_margin']:+.1f}",
                 f"{x['peer_floor']:.1f}", f"{x['ours_floor']:.1f}", f"{x['ca_snr']:.1f}",
                 f"{x['ca_margin']:+.1f}", f"{x['os_snr']:.1f}", f"{x['os_margin']:+.1f}",
                 "yes" if x["peak"] else "no",
                 *(x[n] or f"**{cause(x, n, threshold_db)}**" for n in names)]
        out.append("| " + " | ".join(cells) + " |")
    out.append("")
    for n in names:
        missed = [x for x in rows if not x[n]]
        out.append(f"- {n}: {len(rows) - len(missed)} of {len(rows)} found" + (
            "; missed: " + "; ".join(f"({x['r']},{x['d']}) {cause(x, n, threshold_db)}"
                                     for x in missed) if missed else ""))
    return "\n".join(out) + "\n"


def plots(out: Path, ours: Ours, peer: Detections, peer_map: dict[str, np.ndarray],
          points: dict[str, Detections], threshold_db: float) -> list[Path]:
    """``rd_full.png`` and ``rd_zoom.png`` (module docstring)."""
    n_doppler = ours.nci.shape[1]
    unit = 20 * np.log10(2) / ours.n_virtual
    det = peer_map["det"]
    with np.errstate(divide="ignore"):
        panels = [
            (10 * np.log10(ours.nci / np.median(ours.nci)), "ours: map, dB over its median",
             (0, 50), "viridis"),
            ((det - np.median(det)) * unit, "OpenRadar: map, dB over its median", (0, 50),
             "viridis"),
            ((det - np.maximum(peer_map["thr_doppler"], peer_map["thr_range"])) * unit,
             f"OpenRadar: margin over its {threshold_db:g} dB (both 1-D CFARs), dB",
             (-20, 20), "RdBu_r"),
            (10 * np.log10(ours.nci / ours.threshold["ca"]),
             "ours: margin over the CA-CFAR's threshold, dB", (-20, 20), "RdBu_r"),
            (10 * np.log10(ours.nci / ours.threshold["os"]),
             "ours: margin over the OS-CFAR's threshold, dB", (-20, 20), "RdBu_r"),
            (10 * np.log10(ours.noise["ca"] / ours.noise["os"]),
             "ours: CA noise estimate over OS noise estimate, dB", (-5, 25), "magma")]
    extent = (-n_doppler // 2 - 0.5, n_doppler // 2 - 0.5, -0.5, ours.nci.shape[0] - 0.5)
    paths = []
    for name, zoom in (("rd_full.png", None), ("rd_zoom.png", (-20, 20, 50, 120))):
        fig, axs = plt.subplots(2, 3, figsize=(20, 11))
        for ax, (img, title, (lo, hi), cmap) in zip(axs.flat, panels, strict=True):
            im = ax.imshow(np.fft.fftshift(img, axes=1), origin="lower", aspect="auto",
                           extent=extent, vmin=lo, vmax=hi, cmap=cmap)
            fig.colorbar(im, ax=ax, label="dB")
            ax.scatter(peer.doppler_bin, peer.range_bin, s=60, facecolors="none",
                       edgecolors="r", label=f"OpenRadar {threshold_db:g} dB")
            for (mode, o), mk, c in zip(points.items(), "x+1", ("w", "orange", "cyan"),
                                        strict=False):
                ax.scatter(o.doppler_bin, o.range_bin, marker=mk, s=40, c=c,
                           label=f"ours {mode}")
            ax.set(title=title, xlabel="Doppler bin (signed)", ylabel="range bin")
            if zoom:
                ax.set(xlim=zoom[:2], ylim=zoom[2:])
            ax.legend(fontsize=6, loc="upper left")
        fig.tight_layout()
        fig.savefig(out / name, dpi=80)
        plt.close(fig)
        paths.append(out / name)
    return paths


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--peer-python", type=Path, required=True)
    ap.add_argument("--radar", default=str(DATA / "openradar_2tx4rx.cfg"))
    ap.add_argument("--capture", type=Path, default=DATA / "doppler_example_1.bin")
    ap.add_argument("--threshold-db", type=float, default=15.0)
    ap.add_argument("--out", type=Path, default=Path("out") / "openradar_cells")
    args = ap.parse_args(argv)
    base = ["process", "--radar", args.radar, "--capture", str(args.capture), "--json", "-",
            "--remove-static"]
    profile = profile_of(args.radar)
    cfg = profile.config
    params = {name: process_params(build_parser().parse_args([*base, *extra]), profile)[0]
              for name, extra in modes(args.threshold_db).items()}
    adc = open_capture(args.capture, profile).frame(0)
    points = {name: Detections.of_cloud(capture_frame_cloud(adc, cfg, p, 0, True).cloud)
              for name, p in params.items()}
    p = params["default"]
    windowed = fft_axes(cfg, p.range_window, p.doppler_window)
    nci = np.asarray(range_doppler_power(capture_cube(adc, cfg, p.range_window,
                                                      p.doppler_window, True)), np.float64)
    thr, noise = {}, {}
    for kind in ("ca", "os"):
        cf = CfarParams(pfa=p.cfar.pfa, guard=p.cfar.guard, train=p.cfar.train, kind=kind)
        thr[kind], noise[kind] = map_cfar(nci, cfg, cf, windowed, True, thresholds=True)
    ours = Ours(nci, thr, noise, effective_cells(p.cfar, windowed), cfg.n_virtual)
    with tempfile.TemporaryDirectory() as tmp:
        doc = run_peer(args.peer_python, args.capture, (cfg.n_chirps, cfg.num_rx,
                       cfg.n_samples, cfg.num_tx), args.threshold_db, 0,
                       map_out=Path(tmp) / "map.npz")
        peer_map = dict(np.load(Path(tmp) / "map.npz"))
    peer = Detections.of_peer(doc["settings"][f"{args.threshold_db:g} dB"]["detections"])
    args.out.mkdir(parents=True, exist_ok=True)
    rows = table_rows(peer, peer_map, ours, points, args.threshold_db)
    text = markdown(rows, list(points), args.threshold_db)
    (args.out / "cells.md").write_text(text)
    paths = plots(args.out, ours, peer, peer_map, points, args.threshold_db)
    print(text.split("\n\n")[-1] if "\n\n" in text else text)
    print("written:", args.out / "cells.md", *paths)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
