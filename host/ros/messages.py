"""Plain data -> ROS 2 messages (dicts in the layout of :mod:`host.ros.msgdefs`, as the
``mcap-ros2-support`` encoder takes them): the point cloud as ``sensor_msgs/msg/PointCloud2``,
the GNN objects as ``visualization_msgs/msg/MarkerArray``, the radar mount as a
``tf2_msgs/msg/TFMessage``, a frame's bookkeeping as ``FrameStatus``. Frames and axes follow
REP 103 (x forward, y left, z up; angles in radians, anticlockwise seen from above), which is
the point cloud's own convention. Field names and units: docs/ros.md."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from host.pointcloud import PointCloud
from host.ros.msgdefs import FRAME_STATUS

TOPICS: dict[str, tuple[str, str]] = {
    "points": ("/radar/points", "sensor_msgs/msg/PointCloud2"),
    "objects": ("/radar/objects", "visualization_msgs/msg/MarkerArray"),
    "status": ("/radar/status", FRAME_STATUS),
    "tf": ("/tf_static", "tf2_msgs/msg/TFMessage"),
}
"""Role -> (topic, ROS 2 type) of the messages of a recording or live channel."""
RADAR_FRAME = "radar"
"""The radar's tf frame: the point cloud, markers and status are stamped in it."""
BASE_FRAME = "base_link"
"""The robot's frame the radar is mounted on (parent of :data:`RADAR_FRAME`)."""

# (ROS field name, little-endian numpy type, sensor_msgs/PointField datatype)
_FLOAT32, _INT32, _UINT8 = 7, 5, 2
POINT_FIELDS: tuple[tuple[str, str, int], ...] = (
    ("x", "<f4", _FLOAT32), ("y", "<f4", _FLOAT32), ("z", "<f4", _FLOAT32),
    ("doppler_velocity", "<f4", _FLOAT32), ("intensity", "<f4", _FLOAT32),
    ("snr", "<f4", _FLOAT32), ("rcs", "<f4", _FLOAT32), ("range", "<f4", _FLOAT32),
    ("azimuth", "<f4", _FLOAT32), ("elevation", "<f4", _FLOAT32),
    ("range_bin", "<i4", _INT32), ("doppler_bin", "<i4", _INT32), ("ambiguous", "u1", _UINT8),
)
"""The PointCloud2 fields in their order in a point; docs/ros.md gives units and sources."""
POINT_STEP = 52
"""Bytes per point: the 49 bytes of :data:`POINT_FIELDS` padded to a multiple of 4."""
POINT_DTYPE = np.dtype({"names": [f[0] for f in POINT_FIELDS],
                        "formats": [f[1] for f in POINT_FIELDS],
                        "offsets": [4 * i for i in range(len(POINT_FIELDS))],
                        "itemsize": POINT_STEP})
"""A point as a numpy structured type (the padding bytes are written as zeros)."""
_POINTFIELD_MSGS = [{"name": name, "offset": POINT_DTYPE.fields[name][1], "datatype": code,
                     "count": 1} for name, _, code in POINT_FIELDS]

OBJECT_HEIGHT_M = 1.5
"""Height of an object's box in the markers (the planar array measures no height)."""
_CLASS_COLOURS = {"car": (0.2, 0.6, 1.0), "pedestrian": (1.0, 0.3, 0.3),
                  "pedestrian_group": (1.0, 0.55, 0.1), "two_wheeler": (1.0, 0.85, 0.1),
                  "large_vehicle": (0.65, 0.4, 1.0)}
"""Marker colour (r, g, b) per class of ``gnn.classes.OBJECT_CLASSES``; others grey."""
_OTHER_COLOUR = (0.7, 0.7, 0.7)
_CUBE, _TEXT, _DELETEALL = 1, 9, 3


@dataclass(frozen=True)
class Mount:
    """Where the radar sits on the robot: position of :data:`RADAR_FRAME` in
    :data:`BASE_FRAME` (m) and its yaw, pitch, roll (deg, applied in that order, REP 103)."""

    x_m: float = 0.0
    y_m: float = 0.0
    z_m: float = 0.0
    yaw_deg: float = 0.0
    pitch_deg: float = 0.0
    roll_deg: float = 0.0

    def quaternion(self) -> tuple[float, float, float, float]:
        """The rotation as a unit quaternion (x, y, z, w)."""
        y, p, r = (math.radians(a) / 2 for a in (self.yaw_deg, self.pitch_deg, self.roll_deg))
        cy, sy, cp, sp, cr, sr = (math.cos(y), math.sin(y), math.cos(p), math.sin(p),
                                  math.cos(r), math.sin(r))
        return (sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy,
                cr * cp * sy - sr * sp * cy, cr * cp * cy + sr * sp * sy)


@dataclass(frozen=True)
class FrameStatus:
    """A frame's bookkeeping. ``frame``: its id (detect: the frame index; receive: the id on
    the link); ``points``: points in its cloud; ``complete``: every packet arrived intact;
    ``missing_packets``: packets of the frame lost or damaged on the link; ``truncated``: the
    on-chip detector found more cells than it may send; ``detections``: cells that passed
    the on-chip CFAR (0 when the host runs the CFAR); ``processing_time_s``: host time from
    the frame to its cloud (and objects), s; ``problems``: what went wrong, one line each."""

    frame: int
    points: int
    complete: bool = True
    missing_packets: int = 0
    truncated: bool = False
    detections: int = 0
    processing_time_s: float = 0.0
    problems: list[str] = field(default_factory=list)


def missing_packets(valid: np.ndarray, packet_words: int) -> int:
    """Packets of a frame with at least one word missing or damaged; ``valid``: bool
    (frame_words,), True where the payload word arrived intact."""
    n = -(-len(valid) // packet_words)
    padded = np.ones(n * packet_words, bool)
    padded[:len(valid)] = valid
    return int((~padded.reshape(n, packet_words).all(axis=1)).sum())


def stamp(t_ns: int) -> dict[str, int]:
    """A ``builtin_interfaces/Time`` from nanoseconds."""
    return {"sec": t_ns // 1_000_000_000, "nanosec": t_ns % 1_000_000_000}


def header(t_ns: int, frame_id: str = RADAR_FRAME) -> dict[str, Any]:
    return {"stamp": stamp(t_ns), "frame_id": frame_id}


def cloud_points(cloud: PointCloud) -> np.ndarray:
    """The cloud's points as :data:`POINT_DTYPE` (n,): float fields as float32, azimuth and
    elevation in rad (z and elevation 0 from an array without vertical extent)."""
    pts = np.zeros(len(cloud), POINT_DTYPE)
    pts["x"], pts["y"], pts["z"] = cloud.x_m, cloud.y_m, cloud.z_m
    pts["elevation"] = np.radians(cloud.elevation_deg)
    pts["doppler_velocity"] = cloud.radial_velocity_mps
    pts["intensity"], pts["snr"], pts["rcs"] = cloud.power_db, cloud.snr_db, cloud.rcs_dbsm
    pts["range"], pts["azimuth"] = cloud.range_m, np.radians(cloud.azimuth_deg)
    pts["range_bin"], pts["doppler_bin"] = cloud.range_bin, cloud.doppler_bin
    pts["ambiguous"] = cloud.ambiguous
    return pts


def point_cloud2(points: np.ndarray, t_ns: int) -> dict[str, Any]:
    """A ``sensor_msgs/msg/PointCloud2`` of ``points`` (:data:`POINT_DTYPE` (n,)): one row,
    little-endian, dense (no NaN points)."""
    n = len(points)
    return {"header": header(t_ns), "height": 1, "width": n, "fields": _POINTFIELD_MSGS,
            "is_bigendian": False, "point_step": POINT_STEP, "row_step": POINT_STEP * n,
            "data": np.ascontiguousarray(points, POINT_DTYPE).tobytes(), "is_dense": True}


def points_of(msg: Any) -> np.ndarray:
    """The points of a decoded PointCloud2 written by :func:`point_cloud2`, as
    :data:`POINT_DTYPE` (n,) (``msg``: an object or dict with ``point_step`` and ``data``);
    ValueError when its layout is another."""
    get = msg.get if isinstance(msg, dict) else lambda k: getattr(msg, k)
    names = [(f["name"] if isinstance(f, dict) else f.name) for f in get("fields")]
    if get("point_step") != POINT_STEP or names != list(POINT_DTYPE.names):
        raise ValueError(f"PointCloud2 layout {names} / {get('point_step')} bytes is not "
                         f"this radar's")
    return np.frombuffer(bytes(get("data")), POINT_DTYPE)


def marker_array(objects: list[dict[str, Any]], t_ns: int) -> dict[str, Any]:
    """A ``visualization_msgs/msg/MarkerArray`` of the GNN objects (dicts with ``class``,
    ``score``, ``x_m``, ``y_m``, ``length_m``, ``width_m``, ``heading_deg``, as
    ``gnn.infer.detect_objects`` gives them): a DELETEALL (the previous frame's objects go),
    then per object a box (ns ``objects``) and a label ``class score`` (ns ``labels``)."""
    hdr = header(t_ns)
    markers: list[dict[str, Any]] = [{"header": hdr, "ns": "objects", "action": _DELETEALL}]
    for i, o in enumerate(objects):
        yaw = math.radians(o["heading_deg"]) / 2
        r, g, b = _CLASS_COLOURS.get(o["class"], _OTHER_COLOUR)
        box = {"header": hdr, "ns": "objects", "id": i, "type": _CUBE, "action": 0,
               "pose": {"position": {"x": o["x_m"], "y": o["y_m"], "z": OBJECT_HEIGHT_M / 2},
                        "orientation": {"x": 0.0, "y": 0.0, "z": math.sin(yaw),
                                        "w": math.cos(yaw)}},
               "scale": {"x": o["length_m"], "y": o["width_m"], "z": OBJECT_HEIGHT_M},
               "color": {"r": r, "g": g, "b": b, "a": 0.5}}
        label = {"header": hdr, "ns": "labels", "id": i, "type": _TEXT, "action": 0,
                 "pose": {"position": {"x": o["x_m"], "y": o["y_m"],
                                       "z": OBJECT_HEIGHT_M + 0.5},
                          "orientation": {"w": 1.0}},
                 "scale": {"z": 0.8}, "color": {"r": r, "g": g, "b": b, "a": 1.0},
                 "text": f"{o['class']} {o['score']:.2f}"}
        markers += [box, label]
    return {"markers": markers}


def tf_message(mount: Mount, t_ns: int) -> dict[str, Any]:
    """A ``tf2_msgs/msg/TFMessage`` with the one transform :data:`BASE_FRAME` ->
    :data:`RADAR_FRAME` of ``mount``."""
    qx, qy, qz, qw = mount.quaternion()
    return {"transforms": [{
        "header": header(t_ns, BASE_FRAME), "child_frame_id": RADAR_FRAME,
        "transform": {"translation": {"x": mount.x_m, "y": mount.y_m, "z": mount.z_m},
                      "rotation": {"x": qx, "y": qy, "z": qz, "w": qw}}}]}


def frame_status(status: FrameStatus, t_ns: int) -> dict[str, Any]:
    """A ``FrameStatus`` message (``host.ros.msgdefs.FRAME_STATUS``) of ``status``."""
    return {"header": header(t_ns), "frame": status.frame, "points": status.points,
            "complete": status.complete, "missing_packets": status.missing_packets,
            "truncated": status.truncated, "detections": status.detections,
            "processing_time_ms": status.processing_time_s * 1e3,
            "problems": list(status.problems)}


def frame_messages(cloud: PointCloud | None, status: FrameStatus,
                   objects: list[dict[str, Any]] | None, t_ns: int
                   ) -> list[tuple[str, dict[str, Any]]]:
    """One frame's messages as (role of :data:`TOPICS`, message), stamped ``t_ns``: its
    cloud (None: a frame that gave no cloud, e.g. a damaged one left out), its objects when
    given (GNN run), its status."""
    out = [] if cloud is None else [("points", point_cloud2(cloud_points(cloud), t_ns))]
    if objects is not None:
        out.append(("objects", marker_array(objects, t_ns)))
    out.append(("status", frame_status(status, t_ns)))
    return out
