"""Rotated 2-D boxes: corners, point containment, IoU and non-maximum suppression.

A box array is float (m, 5) with columns ``[x_m, y_m, length_m, width_m, heading_rad]``:
centre (m), footprint along / across the heading (m) and heading (rad, from +x towards +y).
"""

from __future__ import annotations

import numpy as np

BOX_COLUMNS = ("x_m", "y_m", "length_m", "width_m", "heading_rad")


def check_boxes(boxes: np.ndarray, what: str = "boxes") -> np.ndarray:
    """``boxes`` as float64 (m, 5); ValueError naming ``what`` on a bad shape or size."""
    b = np.asarray(boxes, dtype=float)
    if b.ndim != 2 or b.shape[1] != 5:
        raise ValueError(f"{what}: expected shape (m, 5), got {b.shape}")
    if b.size and (np.any(b[:, 2] <= 0) or np.any(b[:, 3] <= 0)):
        raise ValueError(f"{what}: length and width must be positive")
    return b


def box_corners(boxes: np.ndarray) -> np.ndarray:
    """Corners of each box, float (m, 4, 2) as (x, y) in m, counter-clockwise."""
    b = check_boxes(boxes)
    c, s = np.cos(b[:, 4]), np.sin(b[:, 4])
    u = np.stack([c, s], axis=1) * (b[:, 2:3] / 2)        # half length along heading
    w = np.stack([-s, c], axis=1) * (b[:, 3:4] / 2)       # half width across
    ctr = b[:, :2]
    return np.stack([ctr + u - w, ctr + u + w, ctr - u + w, ctr - u - w], axis=1)


def points_in_boxes(xy: np.ndarray, boxes: np.ndarray, margin_m: float = 0.0) -> np.ndarray:
    """Which points lie inside which box grown by ``margin_m`` on every side.

    xy: float (n, 2) in m; boxes: (m, 5). Returns bool (n, m).
    """
    b = check_boxes(boxes)
    p = np.asarray(xy, dtype=float).reshape(-1, 2)
    d = p[:, None, :] - b[None, :, :2]                     # (n, m, 2)
    c, s = np.cos(b[:, 4]), np.sin(b[:, 4])
    along = d[..., 0] * c + d[..., 1] * s
    across = -d[..., 0] * s + d[..., 1] * c
    return ((np.abs(along) <= b[:, 2] / 2 + margin_m)
            & (np.abs(across) <= b[:, 3] / 2 + margin_m))


def _clip(poly: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Part of convex polygon ``poly`` (k, 2) left of the directed edge a->b."""
    if len(poly) == 0:
        return poly
    e = b - a
    side = e[0] * (poly[:, 1] - a[1]) - e[1] * (poly[:, 0] - a[0])   # >= 0: inside
    out = []
    for i in range(len(poly)):
        p, q = poly[i], poly[(i + 1) % len(poly)]
        sp, sq = side[i], side[(i + 1) % len(poly)]
        if sp >= 0:
            out.append(p)
        if (sp >= 0) != (sq >= 0):
            out.append(p + (q - p) * (sp / (sp - sq)))
    return np.array(out).reshape(-1, 2)


def _area(poly: np.ndarray) -> float:
    if len(poly) < 3:
        return 0.0
    x, y = poly[:, 0], poly[:, 1]
    return 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))


def box_iou(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Rotated-box IoU of every pair, float (m, k) in [0, 1]; a: (m, 5), b: (k, 5)."""
    a, b = check_boxes(a, "a"), check_boxes(b, "b")
    out = np.zeros((len(a), len(b)))
    if not len(a) or not len(b):
        return out
    ca, cb = box_corners(a), box_corners(b)
    area_a, area_b = a[:, 2] * a[:, 3], b[:, 2] * b[:, 3]
    # cheap reject by circumscribed circles
    ra, rb = np.hypot(a[:, 2], a[:, 3]) / 2, np.hypot(b[:, 2], b[:, 3]) / 2
    dist = np.linalg.norm(a[:, None, :2] - b[None, :, :2], axis=2)
    for i, j in zip(*np.nonzero(dist < ra[:, None] + rb[None, :]), strict=True):
        poly = ca[i]
        for k in range(4):
            poly = _clip(poly, cb[j, k], cb[j, (k + 1) % 4])
        inter = _area(poly)
        out[i, j] = inter / (area_a[i] + area_b[j] - inter)
    return out


def rotated_nms(boxes: np.ndarray, scores: np.ndarray, iou_threshold: float,
                centre_margin_m: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Greedy rotated-box non-maximum suppression.

    boxes: (m, 5); scores: float (m,). A box is suppressed by a higher-scoring kept box when
    their IoU exceeds ``iou_threshold`` or its centre lies inside the kept box grown by
    ``centre_margin_m`` (m). Returns (indices of kept boxes, best score first, int (k,);
    ``owner``: int (m,), the kept box that suppressed each box, or itself if kept).
    """
    b = check_boxes(boxes)
    s = np.asarray(scores, dtype=float)
    if s.shape != (len(b),):
        raise ValueError(f"scores: expected shape ({len(b)},), got {s.shape}")
    order = np.argsort(-s, kind="stable")
    owner = np.full(len(b), -1)
    keep: list[int] = []
    inside = points_in_boxes(b[:, :2], b, centre_margin_m)   # (m, m): centre i in box j
    for i in order:
        if owner[i] >= 0:
            continue
        owner[i] = i
        keep.append(int(i))
        sup = (owner < 0) & inside[:, i]
        rest = np.nonzero((owner < 0) & ~sup)[0]
        if len(rest):
            sup[rest[box_iou(b[i:i + 1], b[rest])[0] > iou_threshold]] = True
        owner[sup] = i
    return np.array(keep, dtype=int), owner


def fit_box(xy: np.ndarray, min_length_m: float = 0.5, min_width_m: float = 0.5,
            n_angles: int = 36) -> np.ndarray:
    """Smallest-area rotated box around points ``xy`` (float (k, 2), m, k >= 1), searched over
    ``n_angles`` headings in [0, pi/2); sides at least the given minima (m). Returns (5,)."""
    p = np.asarray(xy, dtype=float).reshape(-1, 2)
    if len(p) == 0:
        raise ValueError("fit_box: needs at least one point")
    ang = np.arange(n_angles) * (np.pi / 2 / n_angles)
    c, s = np.cos(ang), np.sin(ang)
    u = p[:, :1] * c + p[:, 1:] * s                   # (k, a) along
    v = -p[:, :1] * s + p[:, 1:] * c                  # (k, a) across
    du, dv = u.max(0) - u.min(0), v.max(0) - v.min(0)
    a = int(np.argmin(du * dv))
    cu, cv = (u[:, a].max() + u[:, a].min()) / 2, (v[:, a].max() + v[:, a].min()) / 2
    length, width, heading = du[a], dv[a], ang[a]
    if width > length:
        length, width, heading = width, length, heading + np.pi / 2
    centre = np.array([cu * c[a] - cv * s[a], cu * s[a] + cv * c[a]])
    return np.array([centre[0], centre[1], max(length, min_length_m), max(width, min_width_m),
                     heading])
