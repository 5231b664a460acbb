"""Baseline detector: DBSCAN on moving points + a rule-based class from extent and speed.

Points whose ego-motion compensated radial velocity exceeds :data:`MOVING_MPS` are clustered
with DBSCAN in (x, y, velocity * :data:`VELOCITY_WEIGHT_S`) space; each cluster becomes one
object with a fitted rotated box and a class from simple rules (:func:`classify_cluster`).
Evaluated with the same metrics as the GNN.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from gnn.boxes import fit_box
from gnn.classes import BACKGROUND, CLASSES, class_index
from gnn.detection import Detection
from gnn.graph import compensated_velocity
from host.pointcloud import PointCloud

# Clustering parameters chosen by a small grid search on 250 *training* frames
# (moving 0.25/0.4, velocity weight 0.1/0.2/0.5, eps 2-6.5 m); see docs/gnn.md.
MOVING_MPS = 0.25
"""A point moves when |compensated radial velocity| exceeds this, m/s."""
VELOCITY_WEIGHT_S = 0.2
"""Velocity axis scale in the clustering space, s (1 m/s counts as 0.2 m)."""
EPS_M = 5.0
"""DBSCAN neighbourhood radius in the (x, y, weighted velocity) space, m."""
MIN_SAMPLES = 1


def dbscan(points: np.ndarray, eps: float, min_samples: int) -> np.ndarray:
    """DBSCAN cluster labels int (n,) (-1 = noise) of float (n, d) ``points``.

    A core point has at least ``min_samples`` neighbours within ``eps`` (itself included);
    clusters grow through core points; border points join the first cluster that reaches
    them.
    """
    p = np.asarray(points, dtype=float)
    if p.ndim != 2:
        raise ValueError(f"dbscan: points must be (n, d), got shape {p.shape}")
    if eps <= 0 or min_samples < 1:
        raise ValueError("dbscan: eps must be positive and min_samples >= 1")
    n = len(p)
    labels = np.full(n, -1)
    if n == 0:
        return labels
    neigh = cKDTree(p).query_ball_point(p, eps)
    core = np.array([len(nb) >= min_samples for nb in neigh])
    cluster = 0
    for i in range(n):
        if labels[i] >= 0 or not core[i]:
            continue
        labels[i] = cluster
        stack = [i]
        while stack:
            j = stack.pop()
            if not core[j]:
                continue
            for k in neigh[j]:
                if labels[k] < 0:
                    labels[k] = cluster
                    stack.append(k)
        cluster += 1
    return labels


def classify_cluster(length_m: float, speed_mps: float, n_points: int) -> int:
    """Rule-based class index from the fitted box length (m), the largest |compensated
    radial velocity| (m/s) and the point count."""
    if length_m > 6.0:
        return class_index("large_vehicle")
    if speed_mps < 2.5:
        return class_index("pedestrian_group" if length_m > 1.2 or n_points > 3
                           else "pedestrian")
    if speed_mps < 8.0 and length_m < 2.5:
        return class_index("two_wheeler")
    return class_index("car")


DEFAULT_SIZE = {"car": (4.5, 1.8), "pedestrian": (0.6, 0.6), "pedestrian_group": (2.0, 2.0),
                "two_wheeler": (1.9, 0.8), "large_vehicle": (10.0, 2.5)}


def baseline_detect(cloud: PointCloud, ego_speed_mps: float = 0.0
                    ) -> tuple[list[Detection], np.ndarray]:
    """Detections and per-point class int (n,) (background outside clusters)."""
    vr = compensated_velocity(cloud, ego_speed_mps)
    moving = np.nonzero(np.abs(vr) > MOVING_MPS)[0]
    point_class = np.full(len(cloud), BACKGROUND)
    feats = np.stack([cloud.x_m[moving], cloud.y_m[moving], vr[moving] * VELOCITY_WEIGHT_S],
                     axis=1)
    labels = dbscan(feats, EPS_M, MIN_SAMPLES)
    dets = []
    for c in range(labels.max(initial=-1) + 1):
        members = moving[labels == c]
        xy = np.stack([cloud.x_m[members], cloud.y_m[members]], axis=1)
        box = fit_box(xy)
        speed = float(np.abs(vr[members]).max())
        cls = classify_cluster(float(box[2]), speed, len(members))
        dl, dw = DEFAULT_SIZE[CLASSES[cls]]
        box[2], box[3] = max(box[2], dl), max(box[3], dw)
        point_class[members] = cls
        dets.append(Detection(cls, float(1 - 1 / (1 + len(members))), box, np.sort(members)))
    return dets, point_class
