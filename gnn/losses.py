"""Training targets and losses: weighted cross-entropy + Huber box regression."""

from __future__ import annotations

import math

import numpy as np
import torch
from torch import Tensor
from torch.nn import functional as F  # noqa: N812

from gnn.classes import NUM_CLASSES
from gnn.frame import IGNORE, Frame


def wrap_half_turn(a: Tensor | np.ndarray) -> Tensor | np.ndarray:
    """Angle (rad) wrapped into [-pi/2, pi/2): box headings are defined modulo pi."""
    return (a + math.pi / 2) % math.pi - math.pi / 2


def box_targets(frame: Frame) -> tuple[np.ndarray, np.ndarray]:
    """Per-point box target float32 (n, 5) ``[dx, dy, log l, log w, heading]`` (m, log m,
    rad in [-pi/2, pi/2)) and bool (n,) mask of points that belong to an object."""
    n = len(frame.cloud)
    t = np.zeros((n, 5), dtype=np.float32)
    mask = frame.point_object >= 0
    b = frame.boxes[frame.point_object[mask]]
    t[mask, 0] = b[:, 0] - frame.cloud.x_m[mask]
    t[mask, 1] = b[:, 1] - frame.cloud.y_m[mask]
    t[mask, 2] = np.log(b[:, 2])
    t[mask, 3] = np.log(b[:, 3])
    t[mask, 4] = wrap_half_turn(b[:, 4])
    return t, mask


def class_weights(frames: list[Frame], power: float = 0.5) -> Tensor:
    """Class weights proportional to frequency**-power, mean 1, float32 (NUM_CLASSES,);
    classes absent from ``frames`` get weight 1."""
    labels = np.concatenate([f.point_class for f in frames] or [np.zeros(0, int)])
    counts = np.bincount(labels[labels != IGNORE], minlength=NUM_CLASSES).astype(float)
    w = np.where(counts > 0, np.maximum(counts, 1) ** -power, 0.0)
    w = w / w[counts > 0].mean() if (counts > 0).any() else np.ones(NUM_CLASSES)
    w[counts == 0] = 1.0
    return torch.tensor(w, dtype=torch.float32)


def detection_loss(logits: Tensor, box: Tensor, y: Tensor, box_t: Tensor, box_mask: Tensor,
                   weights: Tensor, box_weight: float = 1.0) -> tuple[Tensor, Tensor, Tensor]:
    """Weighted cross-entropy over labelled points + Huber (delta 1) box loss over object
    points, heading error wrapped modulo pi. Shapes: logits (n, C), box (n, 5), y (n,) with
    :data:`IGNORE` = -1 skipped, box_t (n, 5), box_mask bool (n,).
    Returns (total, classification, box) losses."""
    cls = F.cross_entropy(logits, y, weight=weights, ignore_index=IGNORE)
    if bool(box_mask.any()):
        p, t = box[box_mask], box_t[box_mask]
        diff = torch.cat([p[:, :4] - t[:, :4], wrap_half_turn(p[:, 4:] - t[:, 4:])], dim=1)
        reg = F.huber_loss(diff, torch.zeros_like(diff), delta=1.0)
    else:
        reg = box.sum() * 0.0
    return cls + box_weight * reg, cls, reg
