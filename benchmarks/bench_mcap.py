"""MCAP recording speed (issue 34): ``host.ros.recording.Recorder`` writing a 1,000-frame
recording of 1,000 points per frame (the ``full`` preset's frame period and bins; random
points, which compress worst), on one core, then reading it back (``host.ros.summary.
read_points``) and checking every point is the one written. The radar makes 111 frames/s;
the recorder must keep up with it.

Prints one row per variant (point cloud + status; and with 20 GNN objects as markers):
frames/s and MB per frame writing, frames/s reading back, and whether the read-back is
identical:

    python -m benchmarks.bench_mcap [--frames 1000] [--points 1000]

Reported, never asserted in tests.
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

from host.pointcloud import PointCloud
from host.ros.messages import FrameStatus, cloud_points
from host.ros.recording import Recorder
from host.ros.summary import read_points
from model.config import RadarConfig, get_preset

RADAR_FPS = 111


def clouds(cfg: RadarConfig, frames: int, points: int, seed: int = 0) -> list[PointCloud]:
    """``frames`` random clouds of ``points`` points within ``cfg``'s map."""
    rng = np.random.default_rng(seed)
    out = []
    for k in range(frames):
        rb = rng.integers(1, cfg.n_range, points)
        out.append(PointCloud.from_polar(
            rb * cfg.range_bin_m, rng.uniform(-60, 60, points), rng.normal(0, 10, points),
            rng.normal(60, 8, points), rng.normal(20, 5, points), rng.normal(5, 10, points),
            rb, rng.integers(-cfg.n_doppler, cfg.n_doppler, points), rng.random(points) < 0.1,
            frame=k))
    return out


def objects(n: int, seed: int = 1) -> list[dict[str, Any]]:
    """``n`` GNN-like objects (the dicts of ``gnn.infer.detect_objects``)."""
    rng = np.random.default_rng(seed)
    return [{"class": "car", "score": float(rng.random()), "x_m": float(rng.uniform(5, 100)),
             "y_m": float(rng.uniform(-20, 20)), "length_m": 4.5, "width_m": 1.9,
             "heading_deg": float(rng.uniform(-180, 180)), "points": []} for _ in range(n)]


def run(cfg: RadarConfig, data: list[PointCloud], objs: list[dict[str, Any]] | None,
        path: Path) -> tuple[float, float, float, bool]:
    """Write ``data`` to ``path``, read it back: (write frames/s, MB per frame, read
    frames/s, read-back identical)."""
    t0 = time.perf_counter()
    with Recorder(path, cfg.frame_time_s) as rec:
        for k, cloud in enumerate(data):
            rec.write_frame(cloud, FrameStatus(k, len(cloud), processing_time_s=1e-3), objs)
    t_write = time.perf_counter() - t0
    t0 = time.perf_counter()
    back = read_points(path)
    t_read = time.perf_counter() - t0
    same = len(back) == len(data) and all(
        np.array_equal(pts, cloud_points(c)) and t == round(k * cfg.frame_time_s * 1e9)
        for k, ((t, pts), c) in enumerate(zip(back, data, strict=True)))
    n = len(data)
    return n / t_write, path.stat().st_size / 1e6 / n, n / t_read, same


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--frames", type=int, default=1000)
    ap.add_argument("--points", type=int, default=1000, help="points per frame")
    args = ap.parse_args(argv)
    if hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, {min(os.sched_getaffinity(0))})     # one core
    cfg = get_preset("full")
    data = clouds(cfg, args.frames, args.points)
    print(f"MCAP recording, {args.frames} frames x {args.points} points, preset {cfg.name} "
          f"({1 / cfg.frame_time_s:.1f} frames/s), zstd chunks, one core")
    print(f"{'variant':<26} {'write frames/s':>14} {'MB/frame':>9} {'read frames/s':>14} "
          f"{'identical':>9}")
    with tempfile.TemporaryDirectory() as tmp:
        for name, objs in (("points + status", None), ("+ 20 objects (markers)", objects(20))):
            w, mb, r, same = run(cfg, data, objs, Path(tmp) / "bench.mcap")
            print(f"{name:<26} {w:>14.0f} {mb:>9.4f} {r:>14.0f} {'yes' if same else 'NO':>9}")
    print(f"goal: >= {RADAR_FPS} frames/s writing")


if __name__ == "__main__":
    main()
