"""Issue 32, nothing lost: every output path is checked before the work starts (one-line
error, exit status 2), an interrupted or failing run writes what it did, port options are
checked."""

from __future__ import annotations

import json
import threading
import time
from pathlib import Path

import pytest

import radar.commands.detect as detect_cmd
from radar.cli import main

UNWRITABLE = "/proc/nothing-lost/x"      # a folder nobody can create files in


def _one_line_error(capsys: pytest.CaptureFixture[str], option: str) -> None:
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "error" in err[0] and option in err[0], err
    assert "Traceback" not in err[0]


@pytest.mark.parametrize(("argv", "option"), [
    (["receive", "--timeout", "30", "--json", UNWRITABLE + ".json"], "--json"),
    (["detect", "--scene", "table1", "--frames", "50", "--json", UNWRITABLE + ".json"],
     "--json"),
    (["detect", "--scene", "table1", "--frames", "50", "--json", "{tmp}/a.json", "--plots",
      UNWRITABLE], "--plots"),
    (["demo", "--out", UNWRITABLE], "--out"),
    (["capture", "--scene", "table1", "--out", UNWRITABLE + ".dmacap"], "--out"),
    (["simulate", "--scene", "table1", "--out", UNWRITABLE + ".npy"], "--out"),
    (["gnn", "eval", "--data", "{tmp}/none.npz", "--json", UNWRITABLE + ".json"], "--json"),
    (["gnn", "detect", "--scene", "table1", "--json", UNWRITABLE + ".json"], "--json"),
    (["gnn", "train", "--data", "{tmp}/none.npz", "--out", UNWRITABLE + ".pt"], "--out"),
    (["gnn", "dataset", "--train", "1", "--test", "0", "--cache-dir", UNWRITABLE],
     "--cache-dir"),
])
def test_output_path_checked_before_the_work(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                             argv: list[str], option: str) -> None:
    argv = [a.replace("{tmp}", str(tmp_path)) for a in argv]
    assert main(argv) == 2
    _one_line_error(capsys, option)


def test_existing_output_file_is_not_changed_by_the_check(tmp_path: Path) -> None:
    from radar.common import out_file
    p = tmp_path / "keep.json"
    p.write_text("old")
    assert out_file(str(p), ".json", "--json") == p and p.read_text() == "old"
    assert out_file(str(tmp_path / "new.json"), ".json", "--json")
    assert not (tmp_path / "new.json").exists()


@pytest.mark.parametrize("n", ["-5", "-1"])
def test_gnn_dataset_counts_are_not_negative(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                             n: str) -> None:
    assert main(["gnn", "dataset", "--train", n, "--cache-dir", str(tmp_path)]) == 2
    _one_line_error(capsys, "--train")


def _stop_at(monkeypatch: pytest.MonkeyPatch, frame: int, exc: BaseException) -> None:
    real = detect_cmd.simulate_scene

    def simulate(scene, frame_index=0):  # noqa: ANN001, ANN202 - as model.simulate
        if frame_index == frame:
            raise exc
        return real(scene, frame_index=frame_index)

    monkeypatch.setattr(detect_cmd, "simulate_scene", simulate)


def test_detect_ctrl_c_keeps_the_frames_processed(tmp_path: Path,
                                                  monkeypatch: pytest.MonkeyPatch,
                                                  capsys: pytest.CaptureFixture[str]) -> None:
    _stop_at(monkeypatch, 3, KeyboardInterrupt())
    out = tmp_path / "pc.json"
    assert main(["detect", "--scene", "table1", "--preset", "paper-fpga", "--backend", "float",
                 "--frames", "50", "--json", str(out)]) == 130
    err = capsys.readouterr().err
    assert "interrupted: wrote the 3 of 50 frame(s) processed" in err and "Traceback" not in err
    doc = json.loads(out.read_text())
    assert doc["interrupted"] is True and doc["frames"] == 3 and doc["frames_requested"] == 50
    assert [f["frame"] for f in doc["frame_info"]] == [0, 1, 2] and doc["points"]


def test_detect_error_mid_run_writes_what_was_done(tmp_path: Path,
                                                   monkeypatch: pytest.MonkeyPatch,
                                                   capsys: pytest.CaptureFixture[str]) -> None:
    _stop_at(monkeypatch, 2, ValueError("disk on fire"))
    out = tmp_path / "pc.json"
    assert main(["detect", "--scene", "table1", "--preset", "paper-fpga", "--backend", "float",
                 "--frames", "5", "--json", str(out)]) == 2
    err = capsys.readouterr().err
    assert "disk on fire (after 2 of 5 frame(s)" in err
    doc = json.loads(out.read_text())
    assert doc["interrupted"] is False and doc["error"] == "disk on fire"
    assert len(doc["frame_info"]) == 2


@pytest.mark.parametrize("argv", [
    ["view", "--port", "70000"], ["view", "--port", "-1"], ["view", "--udp-port", "70000"],
    ["view", "--udp-port", "-1"], ["receive", "--port", "70000", "--json", "{tmp}/r.json"],
    ["receive", "--port", "-1", "--json", "{tmp}/r.json"],
    ["replay", "--capture", "{tmp}/c.dmacap", "--port", "70000"],
    ["replay", "--capture", "{tmp}/c.dmacap", "--port", "0"],
])
def test_port_options_are_one_line_errors(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                          argv: list[str]) -> None:
    argv = [a.replace("{tmp}", str(tmp_path)) for a in argv]
    assert main(argv) == 2
    _one_line_error(capsys, "port")


CLIP = {"preset": "paper-fpga", "targets": [
    {"range_m": 0.8, "azimuth_deg": 0, "radial_velocity_mps": 0, "rcs_m2": 10},
    {"range_m": 30, "azimuth_deg": 0, "radial_velocity_mps": -3, "rcs_m2": 10}]}
CLEAN = {"preset": "paper-fpga", "targets": [CLIP["targets"][1]]}


@pytest.mark.parametrize(("scene", "clips"), [(CLIP, True), (CLEAN, False)])
def test_clipped_frames_and_their_points_are_flagged(tmp_path: Path, scene: dict,
                                                      clips: bool) -> None:
    src, out = tmp_path / "scene.json", tmp_path / "pc.json"
    src.write_text(json.dumps(scene))
    assert main(["detect", "--scene", str(src), "--backend", "float", "--frames", "2",
                 "--json", str(out)]) == 0
    doc = json.loads(out.read_text())
    info = {f["frame"]: f for f in doc["frame_info"]}
    assert all((f["clipped"] > 0) == clips and f["damaged"] is False for f in info.values())
    assert all(f["clipped"] == f["adc_saturated"] for f in info.values())
    assert doc["points"] and all(p.get("clipped", False) == clips for p in doc["points"])


MISFITS = [
    (["capture", "--pfa", "1e-4"], "--pfa"), (["capture", "--detector", "os"], "--detector"),
    (["capture", "--train", "2", "4"], "--train"), (["capture", "--guard", "1", "1"], "--guard"),
    (["capture", "--fpga-cfar", "go"], "--fpga-cfar"),
    (["capture", "--max-detections", "9"], "--max-detections"),
    (["capture", "--detect", "fpga", "--threshold-db", "9"], "--threshold-db"),
    (["capture", "--detect", "fpga", "--max-speed", "9"], "--max-speed"),
    (["detect", "--fpga-cfar", "go"], "--fpga-cfar"),
    (["detect", "--max-detections", "9"], "--max-detections"),
    (["detect", "--threshold-db", "9"], "--threshold-db"),
    (["receive", "--max-detections", "9"], "--max-detections"),
    (["view", "--scene", "table1", "--no-loop"], "--no-loop"),
    (["view", "--frames", "4"], "--frames"), (["view", "--backend", "model"], "--backend"),
    (["view", "--fps", "5"], "--fps"), (["view", "--loss", "0.1"], "--loss"),
    (["view", "--scene", "table1", "--udp-host", "127.0.0.2"], "--udp-host"),
    (["view", "--scene", "table1", "--threshold-db", "9"], "--threshold-db"),
]


@pytest.mark.parametrize(("argv", "option"), MISFITS, ids=[" ".join(a) for a, _ in MISFITS])
def test_options_that_do_not_apply_are_refused(tmp_path: Path,
                                               capsys: pytest.CaptureFixture[str],
                                               argv: list[str], option: str) -> None:
    extra = {"capture": ["--scene", "table1", "--out", str(tmp_path / "c.dmacap")],
             "detect": ["--scene", "table1", "--json", str(tmp_path / "d.json")],
             "receive": ["--timeout", "30", "--json", str(tmp_path / "r.json")],
             "view": ["--port", "0", "--duration", "30"]}[argv[0]]
    assert main([argv[0], *extra, *argv[1:]]) == 2
    _one_line_error(capsys, option)
    assert not (tmp_path / "c.dmacap").exists()


def test_paper_threshold_still_applies_to_the_paper_detector(tmp_path: Path) -> None:
    assert main(["detect", "--scene", "table1", "--preset", "paper-fpga", "--backend", "float",
                 "--detector", "paper", "--threshold-db", "12", "--json",
                 str(tmp_path / "d.json")]) == 0


def test_header_only_capture_is_refused(tmp_path: Path,
                                        capsys: pytest.CaptureFixture[str]) -> None:
    from host.capture import CaptureInfo, write_capture
    cap = tmp_path / "head.dmacap"
    write_capture(cap, CaptureInfo(4, 4093, 3, 512, 128, 0), [])
    assert main(["replay", "--capture", str(cap), "--port", "9"]) == 2
    _one_line_error(capsys, "no packet")


def test_unknown_object_label_is_refused(tmp_path: Path,
                                         capsys: pytest.CaptureFixture[str]) -> None:
    scene = tmp_path / "s.json"
    scene.write_text(json.dumps({"preset": "paper-fpga", "objects": [
        {"x_m": 20, "y_m": 0, "length_m": 4, "width_m": 2, "rcs_m2": 10,
         "label": "spaceship"}]}))
    assert main(["detect", "--scene", str(scene), "--json", str(tmp_path / "d.json")]) == 2
    err = capsys.readouterr().err
    assert "unknown class 'spaceship'" in err and "pedestrian" in err and err.count("\n") == 1


def _capture_and_receive(tmp_path: Path, frames: int
                         ) -> tuple[Path, int, Path, dict, threading.Thread]:
    """A paper-fpga Table I capture of ``frames`` frames and a ``radar receive`` listening
    (in a thread, exit status into the dict) on a free port: (capture, port, JSON, dict,
    thread)."""
    from tests.test_cli_honesty import _free_port

    cap = tmp_path / "c.dmacap"
    assert main(["capture", "--scene", "table1", "--preset", "paper-fpga", "--frames",
                 str(frames), "--out", str(cap)]) == 0
    port, out, rc = _free_port(), tmp_path / "r.json", {}
    t = threading.Thread(target=lambda: rc.update(rc=main([
        "receive", "--port", str(port), "--idle-timeout", "1", "--timeout", "30", "--json",
        str(out)])))
    t.start()
    time.sleep(1.0)
    return cap, port, out, rc, t


def test_garbage_datagrams_are_counted(tmp_path: Path) -> None:
    import socket

    from host.capture import read_capture

    cap, port, out, rc, t = _capture_and_receive(tmp_path, 1)
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        for _ in range(3):                  # before the stream: nothing to learn from
            s.sendto(b"garbage" * 10, ("127.0.0.1", port))
        for i, p in enumerate(read_capture(cap)[1]):
            s.sendto(p, ("127.0.0.1", port))
            if i == 1:                      # inside the stream
                s.sendto(b"xx" * 50, ("127.0.0.1", port))
    t.join(timeout=60)
    doc = json.loads(out.read_text())
    assert rc["rc"] == 0 and doc["stats"]["garbage_packets"] == 4
    assert doc["frame_info"][0]["damaged"] is False


def test_gnn_eval_messages_name_the_way_out(tmp_path: Path,
                                            capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["gnn", "eval", "--cache-dir", str(tmp_path / "fresh")]) == 2
    err = capsys.readouterr().err
    assert "make gnn-dataset" in err and err.count("\n") == 1
    text = tmp_path / "x.txt"
    text.write_text("hello\n")
    assert main(["gnn", "eval", "--data", str(text)]) == 2
    err = capsys.readouterr().err
    assert "not a numpy .npz archive" in err and "allow_pickle" not in err


def test_receive_error_mid_run_writes_the_frames_before(tmp_path: Path,
                                                        monkeypatch: pytest.MonkeyPatch,
                                                        capsys: pytest.CaptureFixture[str]
                                                        ) -> None:
    import radar.commands.link as link

    real, calls = link.frame_cloud, []

    def failing(*a, **k):  # noqa: ANN002, ANN003, ANN202 - as radar.frame_cloud
        calls.append(1)
        if len(calls) == 2:
            raise ValueError("cube: contains NaN or infinite values")
        return real(*a, **k)

    monkeypatch.setattr(link, "frame_cloud", failing)
    cap, port, out, rc, t = _capture_and_receive(tmp_path, 3)
    assert main(["replay", "--capture", str(cap), "--port", str(port)]) == 0
    t.join(timeout=60)
    assert rc["rc"] == 2
    assert "frame 1: cube: contains NaN" in capsys.readouterr().err
    doc = json.loads(out.read_text())
    assert doc["error"].startswith("frame 1") and len(doc["frame_info"]) == 1


@pytest.mark.parametrize(("argv", "option"), [
    (["gnn", "dataset", "--window-s", "1"], "--window-s"),
    (["gnn", "dataset", "--radarscenes", "{tmp}/seq", "--train", "5"], "--train"),
    (["gnn", "train", "--radius", "3"], "--radius"),
    (["gnn", "train", "--graph", "radius", "--k", "5"], "--k"),
    (["gnn", "train", "--epochs", "-5"], "epochs"),
    (["gnn", "train", "--hidden", "-1"], "hidden"),
])
def test_gnn_options_checked_before_the_data(tmp_path: Path,
                                             capsys: pytest.CaptureFixture[str],
                                             argv: list[str], option: str) -> None:
    argv = [a.replace("{tmp}", str(tmp_path)) for a in argv]
    extra = (["--data", str(tmp_path / "none.npz"), "--out", str(tmp_path / "m.pt")]
             if argv[1] == "train" else ["--cache-dir", str(tmp_path / "c")])
    assert main([*argv, *extra]) == 2
    _one_line_error(capsys, option)
