"""RadarScenes loader (Schumann et al. 2021): ``radar_data.h5`` + ``scenes.json`` -> frames.

Schema of one sequence folder (as published):

- ``radar_data.h5``, dataset ``radar_data``: one compound record per detection with
  ``timestamp`` (us), ``sensor_id`` (1-4), ``range_sc`` (m), ``azimuth_sc`` (rad),
  ``rcs`` (dBsm), ``vr`` / ``vr_compensated`` (m/s), ``x_cc``/``y_cc`` (m, car frame),
  ``x_seq``/``y_seq`` (m, sequence frame), ``uuid``, ``track_id`` (bytes, empty for static),
  ``label_id`` (0-11). Optional dataset ``odometry`` with ``timestamp``, ``x_seq``, ``y_seq``,
  ``yaw_seq`` (rad), ``vx``, ``yaw_rate``.
- ``scenes.json``: ``{"sequence_name", "first_timestamp", "last_timestamp", "scenes":
  {"<timestamp>": {"sensor_id", "radar_indices": [start, end), "odometry_index", ...}}}``.

Like RadarGNN, measurements are accumulated over a time window (default 500 ms, all four
sensors) into one frame, expressed in the car frame of the window's last measurement (through
the odometry's sequence pose when present, else the per-scan ``x_cc``/``y_cc``). Label ids
map to the five classes + background as RadarScenes' ``ClassificationLabel`` does (animal
and other -> :data:`gnn.frame.IGNORE`). Each labelled track becomes one object whose true box
is the smallest rotated box around its points. Radial velocities are the ego-motion
compensated ones, so frames carry ``ego_speed_mps = 0``; ``snr_db`` is not in the data set
and is set to 0.
"""

from __future__ import annotations

import json
from pathlib import Path

import h5py
import numpy as np

from gnn.boxes import fit_box
from gnn.classes import BACKGROUND, class_index
from gnn.frame import IGNORE, Frame
from host.pointcloud import PointCloud

LABEL_NAMES = ("CAR", "LARGE_VEHICLE", "TRUCK", "BUS", "TRAIN", "BICYCLE",
               "MOTORIZED_TWO_WHEELER", "PEDESTRIAN", "PEDESTRIAN_GROUP", "ANIMAL", "OTHER",
               "STATIC")
"""RadarScenes label ids 0-11."""
LABEL_TO_CLASS = np.array([
    class_index("car"), class_index("large_vehicle"), class_index("large_vehicle"),
    class_index("large_vehicle"), class_index("large_vehicle"), class_index("two_wheeler"),
    class_index("two_wheeler"), class_index("pedestrian"), class_index("pedestrian_group"),
    IGNORE, IGNORE, BACKGROUND])
"""Our class index of each RadarScenes label id (RadarScenes' ClassificationLabel)."""
RADAR_FIELDS = ("timestamp", "sensor_id", "range_sc", "azimuth_sc", "rcs", "vr",
                "vr_compensated", "x_cc", "y_cc", "x_seq", "y_seq", "uuid", "track_id",
                "label_id")


def map_labels(label_id: np.ndarray) -> np.ndarray:
    """Class index int (n,) of RadarScenes label ids (0-11); ValueError on others."""
    lab = np.asarray(label_id, dtype=int)
    if lab.size and (lab.min() < 0 or lab.max() >= len(LABEL_TO_CLASS)):
        raise ValueError(f"label_id: must be 0-11, got values {sorted(set(lab.tolist()))}")
    return LABEL_TO_CLASS[lab]


def _read(seq_dir: Path) -> tuple[dict, np.ndarray, np.ndarray | None]:
    scenes_path, h5_path = seq_dir / "scenes.json", seq_dir / "radar_data.h5"
    for p in (scenes_path, h5_path):
        if not p.is_file():
            raise ValueError(f"radarscenes: missing {p}")
    try:
        meta = json.loads(scenes_path.read_text())
        scenes = meta["scenes"]
    except (json.JSONDecodeError, KeyError, TypeError) as exc:
        raise ValueError(f"radarscenes: {scenes_path} is not a scenes.json ({exc!r})") from None
    with h5py.File(h5_path, "r") as f:
        if "radar_data" not in f:
            raise ValueError(f"radarscenes: {h5_path} has no 'radar_data' dataset")
        radar = f["radar_data"][:]
        odom = f["odometry"][:] if "odometry" in f else None
    missing = [k for k in RADAR_FIELDS if k not in (radar.dtype.names or ())]
    if missing:
        raise ValueError(f"radarscenes: radar_data lacks field(s) {missing}")
    return scenes, radar, odom


def load_sequence(seq_dir: str | Path, window_s: float = 0.5) -> list[Frame]:
    """Frames of one sequence folder, one per ``window_s`` (s) of measurements."""
    if window_s <= 0:
        raise ValueError(f"window_s: must be positive, got {window_s}")
    scenes, radar, odom = _read(Path(seq_dir))
    ts = sorted(int(t) for t in scenes)
    if not ts:
        return []
    window = ((np.array(ts) - ts[0]) // int(window_s * 1e6)).astype(int)
    frames = []
    for w in np.unique(window):
        members = [ts[i] for i in np.nonzero(window == w)[0]]
        frames.append(_frame(members, scenes, radar, odom))
    return frames


def _frame(timestamps: list[int], scenes: dict, radar: np.ndarray, odom: np.ndarray | None
           ) -> Frame:
    """One accumulated frame in the car frame of the last of ``timestamps``."""
    parts, scan = [], []
    for k, t in enumerate(timestamps):
        a, b = scenes[str(t)]["radar_indices"]
        parts.append(radar[a:b])
        scan.append(np.full(b - a, k))
    d = np.concatenate(parts)
    last = scenes[str(timestamps[-1])]
    if odom is not None and "odometry_index" in last:
        pose = odom[int(last["odometry_index"])]
        c, s = np.cos(pose["yaw_seq"]), np.sin(pose["yaw_seq"])
        dx, dy = d["x_seq"] - pose["x_seq"], d["y_seq"] - pose["y_seq"]
        x, y = c * dx + s * dy, -s * dx + c * dy
    else:
        x, y = d["x_cc"].astype(float), d["y_cc"].astype(float)
    az = np.arctan2(y, x)
    vr = d["vr_compensated"].astype(float)
    n = len(d)
    cloud = PointCloud(
        range_m=np.hypot(x, y), azimuth_deg=np.degrees(az), radial_velocity_mps=vr,
        x_m=x, y_m=y, vx_mps=vr * np.cos(az), vy_mps=vr * np.sin(az),
        power_db=d["rcs"].astype(float), snr_db=np.zeros(n), rcs_dbsm=d["rcs"].astype(float),
        range_bin=np.zeros(n, dtype=int), doppler_bin=np.zeros(n, dtype=int),
        frame=np.concatenate(scan), ambiguous=np.zeros(n, dtype=bool))
    cls = map_labels(d["label_id"])
    obj = np.full(n, -1)
    boxes, box_class = [], []
    tracks = np.array([bytes(t) for t in d["track_id"]], dtype=object)
    dynamic = (cls != BACKGROUND) & (cls != IGNORE) & (tracks != b"")
    for tid in dict.fromkeys(tracks[dynamic]):
        m = dynamic & (tracks == tid)
        obj[m] = len(boxes)
        boxes.append(fit_box(np.stack([x[m], y[m]], axis=1)))
        box_class.append(int(np.bincount(cls[m]).argmax()))
    return Frame(cloud=cloud, ego_speed_mps=0.0, point_class=cls, point_object=obj,
                 boxes=np.array(boxes).reshape(-1, 5), box_class=np.array(box_class, dtype=int))
