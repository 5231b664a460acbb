"""Detection metrics as RadarGNN reports them.

- COCO-style mean average precision (101-point interpolated precision/recall curve per
  class, averaged over the classes present in the ground truth) with **point-based IoU**
  (IoU of the point sets of a detection and a true object) at 0.3, and with rotated
  **box IoU** at 0.5.
- Per-point **F1** of the semantic segmentation (each point's class), macro-averaged over
  the six classes including background (RadarScenes' convention), plus per-class F1.

True objects without any labelled point cannot be detected from the point cloud and are
left out of both mAPs. Points labelled :data:`gnn.frame.IGNORE` are left out of F1 and
removed from point sets.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from gnn.boxes import box_iou
from gnn.classes import BACKGROUND, CLASSES, NUM_CLASSES
from gnn.detection import Detection
from gnn.frame import IGNORE, Frame


def average_precision(scores: np.ndarray, tp: np.ndarray, n_gt: int) -> float:
    """COCO 101-point interpolated AP of detections (scores (d,), tp bool (d,)) against
    ``n_gt`` true objects; NaN when ``n_gt`` is 0."""
    if n_gt == 0:
        return float("nan")
    order = np.argsort(-np.asarray(scores), kind="stable")
    tp = np.asarray(tp, dtype=bool)[order]
    ctp, cfp = np.cumsum(tp), np.cumsum(~tp)
    recall = ctp / n_gt
    precision = ctp / np.maximum(ctp + cfp, 1)
    precision = np.maximum.accumulate(precision[::-1])[::-1] if len(precision) else precision
    ap = 0.0
    for r in np.linspace(0, 1, 101):
        above = np.nonzero(recall >= r)[0]
        ap += precision[above[0]] if len(above) else 0.0
    return ap / 101


def point_iou_matrix(dets: list[Detection], gt_points: list[np.ndarray]) -> np.ndarray:
    """Point-set IoU float (d, g) between detections and true objects' point indices."""
    out = np.zeros((len(dets), len(gt_points)))
    for i, d in enumerate(dets):
        for j, g in enumerate(gt_points):
            inter = len(np.intersect1d(d.points, g, assume_unique=True))
            if inter:
                out[i, j] = inter / len(np.union1d(d.points, g))
    return out


def _match(iou: np.ndarray, scores: np.ndarray, threshold: float) -> np.ndarray:
    """Greedy matching, best score first; bool (d,) true positives."""
    tp = np.zeros(len(scores), dtype=bool)
    used = np.zeros(iou.shape[1], dtype=bool)
    for i in np.argsort(-scores, kind="stable"):
        if not iou.shape[1]:
            break
        cand = np.where(used, -1.0, iou[i])
        j = int(np.argmax(cand))
        if cand[j] >= threshold:
            tp[i], used[j] = True, True
    return tp


class DetectionEvaluator:
    """Accumulates frames, then :meth:`result` gives every metric."""

    def __init__(self, point_iou_threshold: float = 0.3, box_iou_threshold: float = 0.5):
        self.point_thr, self.box_thr = point_iou_threshold, box_iou_threshold
        self._scores: dict[int, list[float]] = {c: [] for c in range(NUM_CLASSES)}
        self._tp_point: dict[int, list[bool]] = {c: [] for c in range(NUM_CLASSES)}
        self._tp_box: dict[int, list[bool]] = {c: [] for c in range(NUM_CLASSES)}
        self._n_gt = np.zeros(NUM_CLASSES, dtype=int)
        self._confusion = np.zeros((NUM_CLASSES, NUM_CLASSES), dtype=int)

    def add(self, frame: Frame, dets: list[Detection], point_class: np.ndarray) -> None:
        """One frame: its truth, the detections and the predicted class int (n,) per point."""
        valid = frame.point_class != IGNORE
        np.add.at(self._confusion, (frame.point_class[valid], point_class[valid]), 1)
        ignored = np.nonzero(~valid)[0]
        for c in range(NUM_CLASSES):
            if c == BACKGROUND:
                continue
            gt = [j for j in np.nonzero(frame.box_class == c)[0]
                  if np.any(frame.point_object == j)]
            self._n_gt[c] += len(gt)
            dc = [d for d in dets if d.class_index == c]
            if not dc:
                continue
            dc = [Detection(d.class_index, d.score, d.box, np.setdiff1d(d.points, ignored))
                  for d in dc]
            scores = np.array([d.score for d in dc])
            gpts = [np.nonzero(frame.point_object == j)[0] for j in gt]
            tp_p = _match(point_iou_matrix(dc, gpts), scores, self.point_thr)
            tp_b = _match(box_iou(np.array([d.box for d in dc]), frame.boxes[gt].reshape(-1, 5)),
                          scores, self.box_thr)
            self._scores[c].extend(scores.tolist())
            self._tp_point[c].extend(tp_p.tolist())
            self._tp_box[c].extend(tp_b.tolist())

    def result(self) -> dict[str, Any]:
        """``map_point_iou_0_3``, ``map_box_iou_0_5``, ``f1`` (macro) and per-class values
        (``ap_point``, ``ap_box``, ``f1_class``: dicts by class name), ``n_objects``."""
        ap_p, ap_b = {}, {}
        for c in range(NUM_CLASSES):
            if c == BACKGROUND:
                continue
            s = np.array(self._scores[c])
            ap_p[CLASSES[c]] = average_precision(s, np.array(self._tp_point[c]), self._n_gt[c])
            ap_b[CLASSES[c]] = average_precision(s, np.array(self._tp_box[c]), self._n_gt[c])
        cm = self._confusion
        tp = np.diag(cm).astype(float)
        denom = cm.sum(0) + cm.sum(1)
        f1 = np.where(denom > 0, 2 * tp / np.maximum(denom, 1), np.nan)
        present = cm.sum(1) > 0
        return {
            "map_point_iou_0_3": _nanmean(list(ap_p.values())),
            "map_box_iou_0_5": _nanmean(list(ap_b.values())),
            "f1": float(np.mean(f1[present])) if present.any() else float("nan"),
            "ap_point": ap_p, "ap_box": ap_b,
            "f1_class": {CLASSES[c]: float(f1[c]) for c in range(NUM_CLASSES)},
            "n_objects": {CLASSES[c]: int(self._n_gt[c]) for c in range(NUM_CLASSES)
                          if c != BACKGROUND},
        }


def _nanmean(values: list[float]) -> float:
    v = np.array(values, dtype=float)
    return float(np.nanmean(v)) if np.isfinite(v).any() else float("nan")
