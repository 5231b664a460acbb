"""MCAP recordings of ROS 2 messages (host.ros): the message definitions are ROS 2 Jazzy's,
a recording reads back through `rosbags` (as ROS 2 tooling reads it) and through `mcap`'s
reader with the same points in the same fields, and a recording cut short or stopped by a
full disk keeps what was written readable."""

import errno
import io
import math
from pathlib import Path

import numpy as np
import pytest
from rosbags.highlevel import AnyReader
from rosbags.typesys import Stores, get_typestore
from rosbags.typesys.msg import get_types_from_msg

from host.pointcloud import PointCloud
from host.ros.messages import (
    POINT_DTYPE,
    TOPICS,
    FrameStatus,
    Mount,
    cloud_points,
    missing_packets,
)
from host.ros.msgdefs import FRAME_STATUS, schema_text
from host.ros.recording import Recorder, RecordingError
from host.ros.summary import read_points, summarize

PERIOD_S = 0.00897024
OBJECTS = [{"class": "car", "score": 0.91, "x_m": 20.0, "y_m": -1.5, "length_m": 4.5,
            "width_m": 1.9, "heading_deg": 30.0, "points": [0, 1]},
           {"class": "pedestrian", "score": 0.6, "x_m": 8.0, "y_m": 2.0, "length_m": 0.6,
            "width_m": 0.6, "heading_deg": 0.0, "points": [2]}]


def _cloud(frame: int, n: int, seed: int = 0) -> PointCloud:
    rng = np.random.default_rng(seed + frame)
    return PointCloud.from_polar(
        rng.uniform(1, 150, n), rng.uniform(-70, 70, n), rng.normal(0, 8, n),
        rng.normal(50, 6, n), rng.normal(18, 4, n), rng.normal(5, 10, n),
        rng.integers(0, 256, n), rng.integers(-100, 100, n), rng.random(n) < 0.2,
        frame=frame)


def _record(out, clouds, objects=True) -> None:
    with Recorder(out, PERIOD_S, start_ns=1_700_000_000_000_000_000,
                  mount=Mount(1.2, 0.0, 0.5, yaw_deg=90.0)) as rec:
        for k, c in enumerate(clouds):
            rec.write_frame(c, FrameStatus(k, len(c), processing_time_s=0.002,
                                           problems=["p"] if k == 1 else []),
                            OBJECTS if objects else None)


@pytest.mark.parametrize("typename", ["sensor_msgs/msg/PointCloud2", "tf2_msgs/msg/TFMessage",
                                      "visualization_msgs/msg/MarkerArray"])
def test_definitions_are_ros2_jazzys(typename):
    ours = get_typestore(Stores.EMPTY)
    ours.register(get_types_from_msg(schema_text(typename), typename))
    assert ours.hash_rihs01(typename) == get_typestore(Stores.ROS2_JAZZY).hash_rihs01(typename)


def test_recording_reads_back_with_rosbags(tmp_path):
    clouds = [_cloud(k, 50 + k) for k in range(4)] + [PointCloud.empty()]
    out = tmp_path / "r.mcap"
    _record(out, clouds)
    got: dict[str, list] = {}
    with AnyReader([out]) as reader:
        assert {c.topic: c.msgtype for c in reader.connections} == dict(TOPICS.values())
        for conn, t, raw in reader.messages():
            got.setdefault(conn.topic, []).append((t, reader.deserialize(raw, conn.msgtype)))
    clouds_msgs = got["/radar/points"]
    assert len(clouds_msgs) == len(clouds)
    for k, ((t, msg), cloud) in enumerate(zip(clouds_msgs, clouds, strict=True)):
        t_expect = 1_700_000_000_000_000_000 + round(k * PERIOD_S * 1e9)
        assert t == t_expect
        assert msg.header.stamp.sec * 10**9 + msg.header.stamp.nanosec == t_expect
        assert msg.header.frame_id == "radar" and msg.width == len(cloud)
        assert [(f.name, f.offset, f.datatype, f.count) for f in msg.fields] == [
            (n, POINT_DTYPE.fields[n][1], d, 1) for n, d in
            zip(POINT_DTYPE.names, (7,) * 10 + (5, 5, 2), strict=True)]
        pts = np.frombuffer(msg.data.tobytes(), POINT_DTYPE)
        f32 = np.float32
        for ros, ours in (("x", cloud.x_m), ("y", cloud.y_m),
                          ("doppler_velocity", cloud.radial_velocity_mps),
                          ("intensity", cloud.power_db), ("snr", cloud.snr_db),
                          ("rcs", cloud.rcs_dbsm), ("range", cloud.range_m),
                          ("azimuth", np.radians(cloud.azimuth_deg))):
            np.testing.assert_array_equal(pts[ros], ours.astype(f32), err_msg=ros)
        assert not pts["z"].any() and not pts["elevation"].any()
        np.testing.assert_array_equal(pts["range_bin"], cloud.range_bin)
        np.testing.assert_array_equal(pts["doppler_bin"], cloud.doppler_bin)
        np.testing.assert_array_equal(pts["ambiguous"].astype(bool), cloud.ambiguous)
    status = [m for _, m in got["/radar/status"]]
    assert [s.frame for s in status] == list(range(len(clouds)))
    assert [s.points for s in status] == [len(c) for c in clouds]
    assert status[1].problems == ["p"] and status[0].complete and not status[0].truncated
    assert status[0].processing_time_ms == pytest.approx(2.0)
    markers = got["/radar/objects"][0][1].markers
    assert markers[0].action == 3                     # DELETEALL, then box + label each
    assert [m.text for m in markers[2::2]] == ["car 0.91", "pedestrian 0.60"]
    assert markers[1].pose.orientation.z == pytest.approx(math.sin(math.radians(15)))
    (t_tf, tf), = got["/tf_static"]
    tr = tf.transforms[0]
    assert (tr.header.frame_id, tr.child_frame_id) == ("base_link", "radar")
    assert tr.transform.translation.x == 1.2 and tr.transform.translation.z == 0.5
    assert tr.transform.rotation.z == pytest.approx(math.sqrt(0.5))


def test_recording_reads_back_with_mcap_reader(tmp_path):
    clouds = [_cloud(k, 30) for k in range(3)]
    out = tmp_path / "r.mcap"
    _record(out, clouds, objects=False)
    back = read_points(out)
    assert [t for t, _ in back] == [1_700_000_000_000_000_000 + round(k * PERIOD_S * 1e9)
                                    for k in range(3)]
    for (_, pts), cloud in zip(back, clouds, strict=True):
        np.testing.assert_array_equal(pts, cloud_points(cloud))
    s = summarize(out)
    assert s.cut_short is None and s.frames == 3
    assert {t.topic: t.messages for t in s.topics} == {"/radar/points": 3, "/radar/status": 3,
                                                      "/tf_static": 1}


def test_recording_cut_short_is_read_up_to_the_cut(tmp_path):
    out = tmp_path / "r.mcap"
    _record(out, [_cloud(k, 2000) for k in range(40)])      # ~4 MB: several chunks
    data = out.read_bytes()
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(data[:len(data) // 2])
    s = summarize(cut)
    assert s.cut_short and "no footer" in s.cut_short
    assert 0 < s.frames < 40


class _FullDisk(io.RawIOBase):
    """A file that takes ``limit`` bytes, then fails as a full disk does."""

    def __init__(self, limit: int) -> None:
        self.limit, self.data = limit, bytearray()

    def writable(self) -> bool:
        return True

    def tell(self) -> int:
        return len(self.data)

    def write(self, b) -> int:
        if len(self.data) + len(b) > self.limit:
            raise OSError(errno.ENOSPC, "No space left on device")
        self.data += b
        return len(b)


def test_full_disk_stops_with_one_error_and_keeps_what_was_written(tmp_path):
    sink = _FullDisk(2_500_000)
    rec = Recorder(sink, PERIOD_S)
    with pytest.raises(RecordingError, match="No space left on device after [0-9]+ frame"):
        with rec:
            for k in range(100):
                rec.write_frame(_cloud(k, 2000), FrameStatus(k, 2000))
    kept = tmp_path / "kept.mcap"
    kept.write_bytes(bytes(sink.data))
    s = summarize(kept)
    assert s.cut_short and 0 < s.frames <= rec.frames


def test_missing_packets_counts_packets_with_a_missing_word():
    valid = np.ones(10, bool)
    assert missing_packets(valid, 4) == 0
    valid[[1, 2, 9]] = False               # packets of 4 words: 0 twice, then the last (short)
    assert missing_packets(valid, 4) == 2


def test_unwritable_path_fails_at_once():
    with pytest.raises(OSError):
        Recorder(Path("/proc/no/such/dir/r.mcap"), PERIOD_S)


def test_status_schema_is_named_for_the_project():
    assert FRAME_STATUS.startswith("radar_array_processor_msgs/msg/")
