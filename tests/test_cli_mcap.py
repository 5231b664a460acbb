"""`radar detect|receive --mcap` record what the command computes as ROS 2 messages (the
same points as the JSON), `radar mcap info` summarises a recording; bad input: an unwritable
path fails before the work, Ctrl-C and a full disk leave a readable recording and one line."""

import json
import os
import resource
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from rosbags.highlevel import AnyReader

from host.ros.messages import POINT_DTYPE
from host.ros.summary import summarize
from radar.cli import main
from tests.test_records_udp import _round_trip

DETECT = ["detect", "--scene", "table1", "--preset", "paper-fpga", "--backend", "float"]


def _points(path: Path) -> list[np.ndarray]:
    with AnyReader([path]) as reader:
        conns = [c for c in reader.connections if c.topic == "/radar/points"]
        return [np.frombuffer(reader.deserialize(raw, c.msgtype).data.tobytes(), POINT_DTYPE)
                for c, _, raw in reader.messages(connections=conns)]


def _same_as_json(points: list[np.ndarray], doc: dict, frames: list[int] | None = None
                  ) -> None:
    """The recording's points are the JSON's, frame by frame (``frames``: the ids of the
    frames with a cloud, default 0..frames-1; the JSON rounds to 4 decimals)."""
    frames = list(range(doc["frames"])) if frames is None else frames
    assert len(points) == len(frames)
    for k, pts in zip(frames, points, strict=True):
        js = [p for p in doc["points"] if p["frame"] == k]
        assert len(pts) == len(js)
        for ros, key in (("x", "x_m"), ("y", "y_m"), ("range", "range_m"),
                         ("doppler_velocity", "radial_velocity_mps"), ("snr", "snr_db"),
                         ("intensity", "power_db"), ("rcs", "rcs_dbsm")):
            np.testing.assert_allclose(pts[ros], [p[key] for p in js], atol=2e-4, err_msg=ros)
        np.testing.assert_allclose(np.degrees(pts["azimuth"]), [p["azimuth_deg"] for p in js],
                                   atol=2e-3)
        assert pts["range_bin"].tolist() == [p["range_bin"] for p in js]
        assert pts["doppler_bin"].tolist() == [p["doppler_bin"] for p in js]
        assert pts["ambiguous"].astype(bool).tolist() == [p["ambiguous"] for p in js]


def test_detect_records_the_json_points(tmp_path, capsys):
    out, rec = tmp_path / "pc.json", tmp_path / "sub" / "pc.mcap"
    assert main([*DETECT, "--frames", "2", "--gnn", "--json", str(out), "--mcap", str(rec),
                 "--mount", "1", "0", "0.5", "0"]) == 0
    doc = json.loads(out.read_text())
    _same_as_json(_points(rec), doc)
    with AnyReader([rec]) as reader:
        conns = [c for c in reader.connections if c.topic == "/radar/objects"]
        labels = [[m.text for m in reader.deserialize(raw, c.msgtype).markers if m.text]
                  for c, _, raw in reader.messages(connections=conns)]
    assert labels == [[f"{o['class']} {o['score']:.2f}" for o in doc["objects"]
                       if o["frame"] == k] for k in range(2)]
    assert any(labels)
    capsys.readouterr()
    assert main(["mcap", "info", str(rec)]) == 0
    text = capsys.readouterr()
    assert "2 frame(s)" in text.out and "/radar/status" in text.out and not text.err
    assert "sensor_msgs/msg/PointCloud2" in text.out


def test_detect_without_mcap_is_unchanged(tmp_path):
    out = tmp_path / "pc.json"
    assert main([*DETECT, "--json", str(out)]) == 0
    assert not list(tmp_path.glob("*.mcap"))


@pytest.mark.parametrize("path,why", [("/proc/nope/r.mcap", "cannot make the folder /proc/nope"),
                                      ("r.bag", "must end in .mcap")])
def test_unwritable_mcap_fails_before_the_work(tmp_path, capsys, path, why):
    t0 = time.perf_counter()
    assert main([*DETECT, "--frames", "10000", "--json", str(tmp_path / "pc.json"),
                 "--mcap", path]) == 2
    err = [e for e in capsys.readouterr().err.splitlines() if "warning" not in e]
    assert len(err) == 1 and "--mcap" in err[0] and why in err[0], err
    assert time.perf_counter() - t0 < 30 and not (tmp_path / "pc.json").exists()


def test_ctrl_c_leaves_a_complete_recording(tmp_path, monkeypatch, capsys):
    import radar.commands.detect as detect

    real, calls = detect.frame_cloud, []

    def interrupted(*args, **kwargs):
        calls.append(1)
        if len(calls) == 3:
            raise KeyboardInterrupt
        return real(*args, **kwargs)

    monkeypatch.setattr(detect, "frame_cloud", interrupted)
    rec = tmp_path / "pc.mcap"
    assert main([*DETECT, "--frames", "5", "--json", str(tmp_path / "pc.json"),
                 "--mcap", str(rec)]) == 130
    s = summarize(rec)
    assert s.cut_short is None and s.frames == 2


def test_mcap_info_cut_short_and_not_mcap(tmp_path, capsys):
    rec = tmp_path / "pc.mcap"
    assert main([*DETECT, "--frames", "2", "--json", str(tmp_path / "pc.json"),
                 "--mcap", str(rec)]) == 0
    data = rec.read_bytes()
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(data[:len(data) - 200])           # the summary and footer lost
    capsys.readouterr()
    assert main(["mcap", "info", str(cut)]) == 0
    text = capsys.readouterr()
    assert text.err.count("\n") == 1 and "cut short" in text.err
    assert "frame(s)" in text.out
    assert main(["mcap", "info", str(tmp_path / "pc.json")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "not an MCAP recording" in err


def _fsize_limit(limit: int):
    def apply() -> None:
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)   # writes past it fail with EFBIG
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
    return apply


def test_full_disk_is_one_line_and_the_recording_so_far_reads(tmp_path):
    # the same run without the limit first: the host kernels are then compiled and cached
    # (a fresh checkout would otherwise write numba's cache files under the size limit)
    assert main([*DETECT, "--frames", "1", "--json", str(tmp_path / "warm.json")]) == 0
    rec = tmp_path / "pc.mcap"
    args = [*DETECT, "--frames", "3", "--json", str(tmp_path / "pc.json"), "--mcap", str(rec)]
    run = subprocess.run([sys.executable, "-c", "import sys; from radar.cli import main; "
                          f"sys.exit(main({args!r}))"], capture_output=True, text=True,
                         preexec_fn=_fsize_limit(3000), env=os.environ, timeout=300)
    assert run.returncode == 2, run.stderr
    lines = [e for e in run.stderr.splitlines() if "warning" not in e]
    assert len(lines) == 1 and "--mcap" in lines[0] and "File too large" in lines[0], lines
    print(lines[0])
    assert summarize(rec).cut_short


def test_receive_records_the_frames_it_processes(tmp_path):
    cap, rec = tmp_path / "t.dmacap", tmp_path / "rx.mcap"
    assert main(["capture", "--scene", "table1", "--preset", "paper-fpga", "--frames", "2",
                 "--packet-words", "1024", "--out", str(cap)]) == 0
    rc, out = _round_trip(tmp_path, cap, ["--mcap", str(rec)])
    assert rc == 0
    doc = json.loads(out.read_text())
    processed = [f["frame_id"] for f in doc["frame_info"] if "points" in f]
    _same_as_json(_points(rec), doc, processed)
    with AnyReader([rec]) as reader:
        conns = [c for c in reader.connections if c.topic == "/radar/status"]
        status = [reader.deserialize(raw, c.msgtype) for c, _, raw in
                  reader.messages(connections=conns)]
    assert [(s.frame, s.complete) for s in status] == [
        (f["frame_id"], f["complete"]) for f in doc["frame_info"]]
    assert all(s.missing_packets == 0 for s in status if s.complete)
