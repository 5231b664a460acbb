"""RadarScenes loader on a tiny sequence written here in the data set's schema."""

import json

import h5py
import numpy as np
import pytest

from gnn.classes import BACKGROUND, class_index
from gnn.frame import IGNORE
from gnn.radarscenes import load_sequence, map_labels

RADAR_DTYPE = np.dtype([
    ("timestamp", "<u8"), ("sensor_id", "u1"), ("range_sc", "<f4"), ("azimuth_sc", "<f4"),
    ("rcs", "<f4"), ("vr", "<f4"), ("vr_compensated", "<f4"), ("x_cc", "<f4"), ("y_cc", "<f4"),
    ("x_seq", "<f4"), ("y_seq", "<f4"), ("uuid", "S32"), ("track_id", "S32"), ("label_id", "u1")])
ODOM_DTYPE = np.dtype([("timestamp", "<u8"), ("x_seq", "<f4"), ("y_seq", "<f4"),
                       ("yaw_seq", "<f4"), ("vx", "<f4"), ("yaw_rate", "<f4")])


def write_sequence(folder, with_odometry=True):
    """3 scans (sensors 1, 2, 1) within 0.3 s, then 1 scan 0.6 s later. Ego at x_seq = 100,
    yaw 90 deg, so car x = y_seq - y0 and car y = -(x_seq - 100)."""
    rows = []
    def add(ts, sensor, x, y, label, track):
        xs, ys = 100 - y, 50 + x                      # car -> sequence coordinates
        rows.append((ts, sensor, np.hypot(x, y), np.arctan2(y, x), 5.0, -3.0, 2.0, x, y, xs, ys,
                     b"u", track, label))
    t0 = 1_000_000
    for k, (ts, sensor) in enumerate([(t0, 1), (t0 + 100_000, 2), (t0 + 250_000, 1)]):
        add(ts, sensor, 20 + 0.5 * k, 1.0, 0, b"car-a")          # a car
        add(ts, sensor, 30.0, -5.0 + 0.2 * k, 7, b"ped-b")     # a pedestrian
        add(ts, sensor, 40.0, 8.0, 11, b"")                     # static
        add(ts, sensor, 45.0, 8.0, 9, b"animal")                # animal -> ignored
    add(t0 + 600_000, 1, 25.0, 2.0, 2, b"truck-c")              # truck -> large vehicle
    radar = np.array(rows, dtype=RADAR_DTYPE)
    odom = np.array([(t0, 100.0, 50.0, np.pi / 2, 5.0, 0.0)], dtype=ODOM_DTYPE)
    with h5py.File(folder / "radar_data.h5", "w") as f:
        f.create_dataset("radar_data", data=radar)
        if with_odometry:
            f.create_dataset("odometry", data=odom)
    scenes = {}
    for i, ts in enumerate([t0, t0 + 100_000, t0 + 250_000, t0 + 600_000]):
        scenes[str(ts)] = {"sensor_id": [1, 2, 1, 1][i], "odometry_index": 0,
                           "odometry_timestamp": t0, "image_name": "x.jpg",
                           "radar_indices": [4 * i, 4 * i + (4 if i < 3 else 1)]}
    (folder / "scenes.json").write_text(json.dumps({
        "sequence_name": "sequence_test", "category": "train", "first_timestamp": t0,
        "last_timestamp": t0 + 600_000, "scenes": scenes}))


def test_label_mapping_follows_radarscenes():
    got = map_labels(np.arange(12)).tolist()
    assert got == [class_index(c) for c in (
        "car", "large_vehicle", "large_vehicle", "large_vehicle", "large_vehicle",
        "two_wheeler", "two_wheeler", "pedestrian", "pedestrian_group")] + [
        IGNORE, IGNORE, BACKGROUND]
    with pytest.raises(ValueError, match="label_id"):
        map_labels(np.array([12]))


@pytest.mark.parametrize("odometry", [True, False])
def test_accumulates_windows_and_labels(tmp_path, odometry):
    write_sequence(tmp_path, odometry)
    frames = load_sequence(tmp_path, window_s=0.5)
    assert [len(f.cloud) for f in frames] == [12, 1]
    f = frames[0]
    assert f.point_class.tolist().count(IGNORE) == 3
    assert (f.point_class == BACKGROUND).sum() == 3
    assert sorted(f.box_class.tolist()) == [class_index("car"), class_index("pedestrian")]
    car = f.point_object[0]
    assert (f.point_object == car).sum() == 3
    assert np.allclose(f.cloud.x_m[f.point_object == car], [20, 20.5, 21], atol=1e-4)
    assert np.allclose(f.cloud.y_m[0], 1.0, atol=1e-4)
    assert f.cloud.radial_velocity_mps[0] == pytest.approx(2.0)        # compensated
    assert frames[1].box_class.tolist() == [class_index("large_vehicle")]


def test_missing_files_are_reported(tmp_path):
    with pytest.raises(ValueError, match="missing"):
        load_sequence(tmp_path)
