"""CPU inference latency per frame of the shipped GNN (graph + network + decoding), and of
the DBSCAN baseline, on held-out synthetic frames. Prints a table.

Usage: ``python -m benchmarks.bench_infer [--data TEST.npz] [--checkpoint CK.pt] [--threads 1]``
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
import torch

from gnn.baseline import baseline_detect
from gnn.dataset import DEFAULT_CACHE, generate, load_frames, split_path
from gnn.frame import Frame
from gnn.infer import GnnDetector


def _stage_times(det: GnnDetector, frames: list[Frame]) -> dict[str, np.ndarray]:
    """Per-frame wall times (s) of graph building, network and decoding."""
    from gnn.detection import decode
    from gnn.graph import build_graph

    out: dict[str, list[float]] = {"graph": [], "network": [], "decode": [], "total": []}
    for f in frames:
        t0 = time.perf_counter()
        g = build_graph(f.cloud, f.ego_speed_mps, det.graph_cfg)
        t1 = time.perf_counter()
        with torch.inference_mode():
            logits, box = det.model(g.x, g.pos, g.edge_index, g.edge_attr)
        t2 = time.perf_counter()
        decode(f.cloud, torch.softmax(logits, 1).numpy().astype(float),
               box.numpy().astype(float))
        t3 = time.perf_counter()
        for k, v in zip(out, (t1 - t0, t2 - t1, t3 - t2, t3 - t0), strict=True):
            out[k].append(v)
    return {k: np.array(v) for k, v in out.items()}


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--data", default=str(split_path(DEFAULT_CACHE, "test")),
                   help="frames to run on (default: the cached test split; generated with "
                   "the stand-in backend when missing)")
    p.add_argument("--checkpoint", default=None, help="checkpoint (default: shipped one)")
    p.add_argument("--threads", type=int, default=1, help="torch CPU threads (default 1)")
    p.add_argument("--frames", type=int, default=200, help="frames to time (default 200)")
    args = p.parse_args(argv)
    torch.set_num_threads(args.threads)
    if Path(args.data).is_file():
        frames = load_frames(Path(args.data))[0][: args.frames]
    else:
        frames = generate(list(range(args.frames)), "stand-in", workers=1, progress=False)
    det = GnnDetector.from_checkpoint(args.checkpoint)
    _stage_times(det, frames[:10])                                    # warm-up
    t = _stage_times(det, frames)
    t_base = []
    for f in frames:
        t0 = time.perf_counter()
        baseline_detect(f.cloud, f.ego_speed_mps)
        t_base.append(time.perf_counter() - t0)
    t["baseline"] = np.array(t_base)
    pts = np.mean([len(f.cloud) for f in frames])
    print(f"{len(frames)} frames, {pts:.1f} points/frame, {args.threads} thread(s)")
    print(f"{'stage':<10}{'mean ms':>10}{'p50 ms':>10}{'p95 ms':>10}{'max ms':>10}")
    for k, v in t.items():
        ms = v * 1e3
        print(f"{k:<10}{ms.mean():>10.2f}{np.median(ms):>10.2f}{np.percentile(ms, 95):>10.2f}"
              f"{ms.max():>10.2f}")
    print(f"GNN total mean {t['total'].mean() * 1e3:.2f} ms/frame (goal <= 20 ms)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
