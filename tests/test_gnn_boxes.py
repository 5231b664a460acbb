"""Rotated boxes: containment, IoU, NMS, box fitting; per-point labelling."""

import math

import numpy as np
import pytest

from gnn.boxes import box_corners, box_iou, fit_box, points_in_boxes, rotated_nms
from gnn.classes import BACKGROUND, class_index
from gnn.labelling import assign_points


def test_corners_and_containment():
    b = np.array([[10.0, 2.0, 4.0, 2.0, math.pi / 2]])
    c = box_corners(b)[0]
    assert np.allclose(sorted(c[:, 0]), [9, 9, 11, 11])
    assert np.allclose(sorted(c[:, 1]), [0, 0, 4, 4])
    inside = points_in_boxes(np.array([[10, 3.9], [10.9, 2], [11.5, 2]]), b)
    assert inside[:, 0].tolist() == [True, True, False]
    assert points_in_boxes(np.array([[11.5, 2]]), b, margin_m=0.6)[0, 0]


def test_iou_known_values():
    a = np.array([[0.0, 0.0, 2.0, 2.0, 0.0]])
    assert box_iou(a, a)[0, 0] == pytest.approx(1.0)
    assert box_iou(a, a + [[1.0, 0, 0, 0, 0]])[0, 0] == pytest.approx(1 / 3)
    assert box_iou(a, a + [[5.0, 0, 0, 0, 0]])[0, 0] == 0.0
    # a square rotated by 90 degrees is the same square
    assert box_iou(a, a + [[0, 0, 0, 0, math.pi / 2]])[0, 0] == pytest.approx(1.0)
    # 45 degrees: intersection is the regular octagon of area 8 (sqrt2 - 1)
    r = box_iou(a, a + [[0, 0, 0, 0, math.pi / 4]])[0, 0]
    inter = 8 * (math.sqrt(2) - 1)
    assert r == pytest.approx(inter / (8 - inter))


def test_bad_boxes_rejected():
    with pytest.raises(ValueError, match="shape"):
        box_iou(np.zeros((2, 4)), np.zeros((1, 5)))
    with pytest.raises(ValueError, match="positive"):
        box_corners(np.array([[0, 0, -1, 1, 0]]))


def test_nms_keeps_best_and_assigns_owners():
    boxes = np.array([[0, 0, 4, 2, 0], [0.2, 0, 4, 2, 0], [10, 0, 4, 2, 0]], dtype=float)
    keep, owner = rotated_nms(boxes, np.array([0.5, 0.9, 0.7]), 0.3)
    assert keep.tolist() == [1, 2]
    assert owner.tolist() == [1, 1, 2]


def test_fit_box_recovers_rotated_rectangle():
    rng = np.random.default_rng(0)
    h = math.radians(30)
    u = rng.uniform(-2, 2, 200)
    v = rng.uniform(-0.8, 0.8, 200)
    xy = np.stack([5 + u * math.cos(h) - v * math.sin(h), 1 + u * math.sin(h) + v * math.cos(h)],
                  axis=1)
    b = fit_box(xy, n_angles=90)
    assert b[:2] == pytest.approx([5, 1], abs=0.1)
    assert b[2:4] == pytest.approx([4, 1.6], abs=0.15)
    assert math.cos(2 * (b[4] - h)) > 0.99


def test_assign_points_by_enlarged_box():
    boxes = np.array([[10.0, 0.0, 4.0, 2.0, 0.0], [20.0, 0.0, 0.6, 0.6, 0.0]])
    cls_of = np.array([class_index("car"), class_index("pedestrian")])
    xy = np.array([[10, 0.5], [12.5, 0], [20.8, 0], [30, 0]])
    cls, obj = assign_points(xy, boxes, cls_of, margin_m=1.0)
    assert obj.tolist() == [0, 0, 1, -1]
    assert cls.tolist() == [class_index("car"), class_index("car"), class_index("pedestrian"),
                            BACKGROUND]
    cls, obj = assign_points(xy, np.zeros((0, 5)), np.zeros(0, int))
    assert (obj == -1).all() and (cls == BACKGROUND).all()
