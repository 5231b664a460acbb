"""Object detections (GNN or baseline) and the per-point GNN output decoder."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from gnn.boxes import rotated_nms
from gnn.classes import BACKGROUND, CLASSES
from host.pointcloud import PointCloud

SCORE_THRESHOLD = 0.3
"""Points whose best object-class probability is below this propose no box."""
NMS_IOU = 0.1
"""Rotated-box NMS IoU threshold."""
NMS_CENTRE_MARGIN_M = 1.0
"""NMS also merges a proposal whose centre lies in a kept box grown by this much, m."""


@dataclass(frozen=True)
class Detection:
    """One detected object: class index, score in [0, 1], box float (5,)
    ``[x, y, length, width, heading_rad]`` and the indices (int (k,)) of its points."""

    class_index: int
    score: float
    box: np.ndarray
    points: np.ndarray

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict: class, score, x_m, y_m, length_m, width_m, heading_deg, points."""
        x, y, length, width, h = (float(v) for v in self.box)
        return {"class": CLASSES[self.class_index], "score": round(self.score, 4),
                "x_m": round(x, 3), "y_m": round(y, 3), "length_m": round(length, 3),
                "width_m": round(width, 3), "heading_deg": round(math.degrees(h), 2),
                "points": [int(i) for i in self.points]}


def mean_box(boxes: np.ndarray) -> np.ndarray:
    """Average of boxes (k, 5) -> (5,): mean centre and size, heading as the circular mean
    modulo pi (mean of the doubled angle)."""
    h = boxes[:, 4]
    heading = 0.5 * np.arctan2(np.sin(2 * h).mean(), np.cos(2 * h).mean())
    return np.array([*boxes[:, :4].mean(axis=0), heading])


def decode(cloud: PointCloud, prob: np.ndarray, box: np.ndarray,
           score_threshold: float = SCORE_THRESHOLD, nms_iou: float = NMS_IOU
           ) -> tuple[list[Detection], np.ndarray]:
    """Per-point network output -> objects.

    prob: float (n, C) class probabilities; box: float (n, 5) ``[dx, dy, log l, log w,
    heading]``. Every point whose best class is an object class with probability >=
    ``score_threshold`` proposes the box (x + dx, y + dy, l, w, heading); rotated NMS per
    class keeps the best box, and the points whose proposals it suppressed become its
    points; the object's box is the mean of their proposals (:func:`mean_box`) and its score
    their mean class probability times k / (k + 1) for k points, so single-point fragments
    rank below well-supported objects. Returns (detections, per-point class
    int (n,) for the segmentation metrics).
    """
    n = len(cloud)
    if prob.shape != (n, len(CLASSES)) or box.shape != (n, 5):
        raise ValueError(f"decode: expected prob ({n}, {len(CLASSES)}) and box ({n}, 5), got "
                         f"{prob.shape} and {box.shape}")
    point_class = prob.argmax(axis=1)
    obj_prob = prob[np.arange(n), point_class]
    boxes = np.stack([cloud.x_m + box[:, 0], cloud.y_m + box[:, 1],
                      np.exp(np.clip(box[:, 2], -3, 4)), np.exp(np.clip(box[:, 3], -3, 4)),
                      box[:, 4]], axis=1)
    dets: list[Detection] = []
    for c in range(len(CLASSES)):
        if c == BACKGROUND:
            continue
        idx = np.nonzero((point_class == c) & (obj_prob >= score_threshold))[0]
        if not len(idx):
            continue
        keep, owner = rotated_nms(boxes[idx], obj_prob[idx], nms_iou, NMS_CENTRE_MARGIN_M)
        for k in keep:
            members = idx[owner == k]
            score = obj_prob[members].mean() * len(members) / (len(members) + 1)
            dets.append(Detection(c, float(score), mean_box(boxes[members]),
                                  np.sort(members)))
    dets.sort(key=lambda d: -d.score)
    low = (point_class != BACKGROUND) & (obj_prob < score_threshold)
    point_class = np.where(low, BACKGROUND, point_class)
    return dets, point_class
