"""Evaluate the GNN and the DBSCAN baseline on labelled frames with the same metrics."""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

import numpy as np
from tqdm import tqdm

from gnn.baseline import baseline_detect
from gnn.detection import Detection
from gnn.frame import Frame
from gnn.infer import GnnDetector
from gnn.metrics import DetectionEvaluator
from host.pointcloud import PointCloud

DetectFn = Callable[[PointCloud, float], tuple[list[Detection], np.ndarray]]


def evaluate_detector(detect: DetectFn, frames: list[Frame], progress: bool = True,
                      desc: str = "eval") -> dict[str, Any]:
    """Metrics of ``detect`` over ``frames`` (:class:`gnn.metrics.DetectionEvaluator`) plus
    the mean and 95th-percentile wall time per frame, ms (``latency_ms``,
    ``latency_p95_ms``)."""
    if not frames:
        raise ValueError("eval: no frames")
    ev = DetectionEvaluator()
    times = []
    for f in tqdm(frames, desc=desc, unit="frame", disable=not progress):
        t0 = time.perf_counter()
        dets, point_class = detect(f.cloud, f.ego_speed_mps)
        times.append(time.perf_counter() - t0)
        ev.add(f, dets, point_class)
    res = ev.result()
    res["latency_ms"] = float(np.mean(times) * 1e3)
    res["latency_p95_ms"] = float(np.percentile(times, 95) * 1e3)
    res["frames"] = len(frames)
    return res


def evaluate_all(detector: GnnDetector, frames: list[Frame], progress: bool = True
                 ) -> dict[str, Any]:
    """GNN and baseline metrics: the GNN's keys, ``baseline_*`` copies of the baseline's
    headline numbers and the full ``gnn`` / ``baseline`` result dicts."""
    g = evaluate_detector(detector.detect, frames, progress, "eval gnn")
    b = evaluate_detector(baseline_detect, frames, progress, "eval baseline")
    out: dict[str, Any] = {k: g[k] for k in ("map_point_iou_0_3", "f1", "map_box_iou_0_5",
                                             "latency_ms", "latency_p95_ms", "frames")}
    for k in ("map_point_iou_0_3", "f1", "map_box_iou_0_5", "latency_ms"):
        out[f"baseline_{k}"] = b[k]
    out["gnn"], out["baseline"] = g, b
    return out
