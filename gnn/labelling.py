"""Per-point ground truth by geometry: a detection belongs to the object whose slightly
enlarged true box contains it (the nearest centre wins when boxes overlap)."""

from __future__ import annotations

import numpy as np

from gnn.boxes import check_boxes, points_in_boxes
from gnn.classes import BACKGROUND

LABEL_MARGIN_M = 1.0
"""Growth of every true box on each side before testing containment, m. About half a
``full``-preset range bin (1.73 m) plus the angle error at typical ranges."""


def assign_points(xy: np.ndarray, boxes: np.ndarray, box_class: np.ndarray,
                  margin_m: float = LABEL_MARGIN_M) -> tuple[np.ndarray, np.ndarray]:
    """Label points by the enlarged boxes that contain them.

    xy: float (n, 2) point positions, m; boxes: (m, 5); box_class: int (m,).
    Returns (class: int (n,), background where no box contains the point;
    object: int (n,), box index or -1).
    """
    b = check_boxes(boxes)
    p = np.asarray(xy, dtype=float).reshape(-1, 2)
    obj = np.full(len(p), -1)
    if len(b) and len(p):
        inside = points_in_boxes(p, b, margin_m)                        # (n, m)
        dist = np.linalg.norm(p[:, None, :] - b[None, :, :2], axis=2)
        nearest = np.argmin(np.where(inside, dist, np.inf), axis=1)
        obj = np.where(inside.any(axis=1), nearest, -1)
    cls = np.full(len(p), BACKGROUND)
    cls[obj >= 0] = np.asarray(box_class, dtype=int)[obj[obj >= 0]]
    return cls, obj
