"""Metrics (AP, point IoU, F1), the DBSCAN baseline and the decoder on hand-made frames."""

import numpy as np
import pytest

from gnn.baseline import baseline_detect, classify_cluster, dbscan
from gnn.classes import BACKGROUND, NUM_CLASSES, class_index
from gnn.detection import Detection, decode
from gnn.frame import Frame
from gnn.metrics import DetectionEvaluator, average_precision
from host.pointcloud import PointCloud

CAR, PED = class_index("car"), class_index("pedestrian")


def xy_cloud(xy: np.ndarray, vr: np.ndarray) -> PointCloud:
    r = np.hypot(xy[:, 0], xy[:, 1])
    n = len(r)
    return PointCloud.from_polar(r, np.degrees(np.arctan2(xy[:, 1], xy[:, 0])), vr,
                                 np.full(n, 40.0), np.full(n, 20.0), np.zeros(n),
                                 np.zeros(n, int), np.zeros(n, int), np.zeros(n, bool))


def two_object_frame() -> Frame:
    """A car (points 0-3), a pedestrian (point 4) and static clutter (points 5-7)."""
    xy = np.array([[20, 0], [21, 0.5], [22, -0.5], [21.5, 0], [30, 5], [40, -10], [41, -10],
                   [15, 8]], dtype=float)
    vr = np.array([-8, -8, -8.2, -8.1, 1.5, 0, 0, 0], dtype=float)
    boxes = np.array([[21.0, 0.0, 4.5, 1.8, 0.0], [30.0, 5.0, 0.6, 0.6, 0.0]])
    return Frame(xy_cloud(xy, vr), 0.0, np.array([CAR] * 4 + [PED] + [BACKGROUND] * 3),
                 np.array([0, 0, 0, 0, 1, -1, -1, -1]), boxes, np.array([CAR, PED]))


def test_average_precision():
    assert average_precision(np.array([0.9, 0.8]), np.array([True, True]), 2) == 1.0
    assert average_precision(np.array([0.9]), np.array([True]), 2) == pytest.approx(51 / 101)
    assert average_precision(np.array([0.9, 0.8]), np.array([False, True]), 1) == \
        pytest.approx(0.5)
    assert np.isnan(average_precision(np.zeros(0), np.zeros(0, bool), 0))


def test_perfect_detections_score_one():
    f = two_object_frame()
    ev = DetectionEvaluator()
    dets = [Detection(CAR, 0.9, f.boxes[0], np.arange(4)), Detection(PED, 0.8, f.boxes[1],
                                                                      np.array([4]))]
    ev.add(f, dets, f.point_class)
    r = ev.result()
    assert r["map_point_iou_0_3"] == 1.0 and r["map_box_iou_0_5"] == 1.0 and r["f1"] == 1.0


def test_point_iou_threshold_and_wrong_class():
    f = two_object_frame()
    ev = DetectionEvaluator()
    # car detection holding 1 of 4 car points + 3 clutter points: IoU 1/7 < 0.3 -> FP;
    # pedestrian detected as a car: FP for car, miss for pedestrian
    dets = [Detection(CAR, 0.9, f.boxes[0], np.array([0, 5, 6, 7])),
            Detection(CAR, 0.5, f.boxes[1], np.array([4]))]
    pc = f.point_class.copy()
    pc[4] = CAR
    ev.add(f, dets, pc)
    r = ev.result()
    assert r["ap_point"]["car"] == 0.0 and r["ap_point"]["pedestrian"] == 0.0
    assert r["f1_class"]["pedestrian"] == 0.0 and 0 < r["f1"] < 1


def test_dbscan_clusters_and_noise():
    pts = np.array([[0, 0], [0.5, 0], [1.0, 0], [10, 10], [10.4, 10], [50, 50]], dtype=float)
    lab = dbscan(pts, eps=0.6, min_samples=2)
    assert lab[:3].tolist() == [0, 0, 0] and lab[3:5].tolist() == [1, 1] and lab[5] == -1
    with pytest.raises(ValueError, match="eps"):
        dbscan(pts, eps=0, min_samples=1)


def test_rules():
    assert classify_cluster(10.0, 10.0, 8) == class_index("large_vehicle")
    assert classify_cluster(0.6, 1.2, 1) == PED
    assert classify_cluster(2.0, 1.2, 5) == class_index("pedestrian_group")
    assert classify_cluster(1.8, 5.0, 2) == class_index("two_wheeler")
    assert classify_cluster(4.2, 12.0, 4) == CAR


def test_baseline_finds_moving_objects():
    f = two_object_frame()
    dets, pc = baseline_detect(f.cloud, 0.0)
    assert sorted(d.points.tolist() for d in dets) == [[0, 1, 2, 3], [4]]
    assert (pc[5:] == BACKGROUND).all()
    ev = DetectionEvaluator()
    ev.add(f, dets, pc)
    assert ev.result()["map_point_iou_0_3"] > 0.4


def test_decode_merges_consistent_proposals():
    f = two_object_frame()
    n = len(f.cloud)
    prob = np.full((n, NUM_CLASSES), 0.01)
    prob[np.arange(n), f.point_class] = 0.95
    box = np.zeros((n, 5))
    box[:, 0] = np.where(f.point_object >= 0, f.boxes[np.maximum(f.point_object, 0), 0]
                         - f.cloud.x_m, 0)
    box[:, 1] = np.where(f.point_object >= 0, f.boxes[np.maximum(f.point_object, 0), 1]
                         - f.cloud.y_m, 0)
    box[:, 2] = np.log(np.where(f.point_class == CAR, 4.5, 0.6))
    box[:, 3] = np.log(np.where(f.point_class == CAR, 1.8, 0.6))
    dets, pc = decode(f.cloud, prob, box)
    assert [(d.class_index, d.points.tolist()) for d in dets] == [(CAR, [0, 1, 2, 3]),
                                                                  (PED, [4])]
    assert (pc == f.point_class).all()
    with pytest.raises(ValueError, match="decode"):
        decode(f.cloud, prob[:, :3], box)


def test_mean_box_averages_heading_modulo_pi():
    from gnn.detection import mean_box

    h = np.radians([89.0, -89.0])
    b = mean_box(np.array([[0, 0, 4, 2, h[0]], [2, 2, 6, 2, h[1]]]))
    assert b[:4] == pytest.approx([1, 1, 5, 2])
    assert abs(np.cos(2 * b[4]) - np.cos(np.pi)) < 1e-6            # 90 deg, not 0
