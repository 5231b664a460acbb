"""Issue 12 through the `radar` command line: one point per near target, warnings and counts
for targets the radar cannot see, the Ethernet path with its defaults, one-line errors with
exit status 2 for every bad option value."""

import json
import socket
import threading
import time

import pytest

from radar.cli import main

NEAR = {"targets": [{"range_m": 5, "azimuth_deg": 0, "radial_velocity_mps": -3, "rcs_m2": 10}]}


def _scene(tmp_path, doc, name="scene.json"):
    p = tmp_path / name
    p.write_text(json.dumps(doc))
    return str(p)


@pytest.mark.parametrize("preset", ["full", "paper-fpga"])
def test_detect_single_near_target_one_point(tmp_path, preset):
    out = tmp_path / "pc.json"
    scene = _scene(tmp_path, {"preset": preset, **NEAR})
    assert main(["detect", "--scene", scene, "--backend", "float", "--json", str(out)]) == 0
    doc = json.loads(out.read_text())
    assert len(doc["points"]) == 1 and abs(doc["points"][0]["range_m"] - 5) < 0.5
    assert doc["unobservable_targets"] == 0


def test_detect_warns_and_counts_unobservable_targets(tmp_path, capsys):
    scene = _scene(tmp_path, {"preset": "paper-fpga", "targets": [
        {"range_m": 30, "azimuth_deg": 0, "radial_velocity_mps": -3, "rcs_m2": 10},
        {"range_m": 300, "azimuth_deg": 0, "radial_velocity_mps": 0, "rcs_m2": 1000},
        {"range_m": 30, "azimuth_deg": -41.8, "radial_velocity_mps": 0, "rcs_m2": 10},
        {"range_m": 40, "azimuth_deg": 0, "radial_velocity_mps": 200, "rcs_m2": 10}]})
    out = tmp_path / "pc.json"
    assert main(["detect", "--scene", scene, "--backend", "float", "--json", str(out)]) == 0
    err = capsys.readouterr().err
    assert "targets[1] not observable" in err and "targets[2] not observable" in err
    assert "targets[3]" in err and "alias" in err
    doc = json.loads(out.read_text())
    assert doc["unobservable_targets"] == 2
    assert {e["reason"] for e in doc["unobservable"]} == {"beyond_max_range", "tx_null"}
    assert len(doc["velocity_beyond_max_speed"]) == 1


def test_simulate_reports_targets_behind_the_radar(tmp_path, capsys):
    scene = _scene(tmp_path, {"preset": "paper-fpga", "targets": [
        {"range_m": 2, "azimuth_deg": 0, "radial_velocity_mps": -25, "rcs_m2": 1}]})
    assert main(["simulate", "--scene", scene, "--frame", "30", "--out",
                 str(tmp_path / "a.npy")]) == 0
    cap = capsys.readouterr()
    assert "1 scatterers at range <= 0" in cap.out and "passed the radar" in cap.err


def _free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _receive(args, rc):
    t = threading.Thread(target=lambda: rc.update(rc=main(["receive", *args])))
    t.start()
    return t


@pytest.mark.parametrize("faults", [[], ["--reorder", "0.3", "--duplicate", "0.3", "--seed",
                                         "3"]])
def test_capture_replay_receive_with_defaults(tmp_path, faults):
    """No --preset / --packet-words anywhere; receive starts first with a short idle
    timeout; reordered and duplicated packets still give complete frames."""
    cap = tmp_path / "t.dmacap"
    assert main(["capture", "--scene", "table1", "--preset", "paper-fpga", "--frames", "2",
                 "--out", str(cap)]) == 0
    port, out, rc = _free_port(), tmp_path / "rx.json", {}
    t = _receive(["--port", str(port), "--idle-timeout", "0.5", "--timeout", "30",
                  "--json", str(out)], rc)
    time.sleep(1.5)  # longer than the idle timeout: it must not have started yet
    assert main(["replay", "--capture", str(cap), "--port", str(port), *faults]) == 0
    t.join(timeout=60)
    assert rc["rc"] == 0
    doc = json.loads(out.read_text())
    assert doc["preset"] == "paper-fpga" and doc["packet_words"] == 4092
    assert [f["complete"] for f in doc["frame_info"]] == [True, True]
    assert sum(p["frame"] == 0 for p in doc["points"]) >= 3


def test_receive_ctrl_c_writes_json_no_traceback(tmp_path, capsys, sigint_raises):
    import os
    import signal

    out = tmp_path / "rx.json"
    timer = threading.Timer(1.0, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    assert main(["receive", "--port", str(_free_port()), "--timeout", "30", "--json",
                 str(out)]) == 130
    err = capsys.readouterr().err
    assert "Traceback" not in err and "interrupted" in err
    assert json.loads(out.read_text())["interrupted"] is True


def test_receive_nothing_exits_1_and_writes_json(tmp_path, capsys):
    out = tmp_path / "rx.json"
    assert main(["receive", "--port", str(_free_port()), "--timeout", "0.5", "--json",
                 str(out)]) == 1
    assert "no usable frame" in capsys.readouterr().err
    assert json.loads(out.read_text())["datagrams"] == 0


BAD = [
    ["detect", "--train", "100", "300"], ["detect", "--guard", "200", "2"],
    ["detect", "--pfa", "nan"], ["detect", "--pfa", "0"], ["detect", "--pfa", "1e-20"],
    ["detect", "--detector", "paper", "--threshold-db", "nan"],
    ["detect", "--ego-speed", "nan"], ["detect", "--ego-speed", "1e6"],
    ["detect", "--frames", "0"], ["detect", "--frames", "1000000000"],
    ["detect", "--max-speed", "nan"], ["detect", "--max-speed", "-5"],
    ["detect", "--array-error-db", "3"], ["detect", "--array-error-db", "nan"],
    ["simulate", "--frame", "1000000000000"], ["simulate", "--frame", "-1"],
    ["receive", "--port", "70000"], ["receive", "--port", "-1"],
    ["receive", "--idle-timeout", "-1"], ["receive", "--timeout", "nan"],
    ["receive", "--frames", "0"], ["receive", "--packet-words", "1", "--preset", "full"],
    ["receive", "--train", "100", "300", "--preset", "paper-fpga"],
    ["replay", "--port", "0"], ["replay", "--port", "70000"], ["replay", "--rate-mbps", "-1"],
    ["replay", "--rate-mbps", "nan"], ["replay", "--loss", "2"], ["replay", "--seed", "-1"],
    ["capture", "--packet-words", "5000"], ["capture", "--packet-words", "1"],
    ["capture", "--frames", "0"], ["capture", "--frames", "100000"],
    ["replay", "--rate-mbps", "1e-9"], ["replay", "--rate-mbps", "1e-300"],
    ["receive", "--packet-words", "-3"], ["receive", "--packet-words", "0"],
    ["view", "--fps", "nan"], ["view", "--fps", "1e-300"], ["view", "--duration", "0"],
    ["view", "--duration", "nan"], ["view", "--duration", "-1"], ["view", "--seed", "-1"],
    ["view", "--ego-speed", "nan"], ["view", "--packet-words", "0"],
]


@pytest.mark.parametrize("argv", BAD, ids=[" ".join(a) for a in BAD])
def test_bad_option_values_one_line_exit_2(tmp_path, capsys, argv):
    cmd, rest = argv[0], argv[1:]
    scene = _scene(tmp_path, {"preset": "full", **NEAR})
    extra = {"detect": ["--scene", scene, "--backend", "float", "--json",
                        str(tmp_path / "o.json")],
             "simulate": ["--scene", scene, "--out", str(tmp_path / "o.npy")],
             "receive": ["--json", str(tmp_path / "o.json"), "--timeout", "0.2"],
             "replay": ["--capture", str(tmp_path / "missing.dmacap")],
             "capture": ["--scene", scene, "--out", str(tmp_path / "o.dmacap")],
             "view": ["--scene", scene, "--port", "0", "--duration", "0.1"]}[cmd]
    if cmd == "replay" and "--port" not in rest:
        extra += ["--port", "9"]
    t0 = time.monotonic()
    assert main([cmd, *extra, *rest]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and err.startswith(f"radar {cmd}: error:"), err
    assert "Traceback" not in err and time.monotonic() - t0 < 20


@pytest.mark.parametrize("n", [1_000_000, 1e6])
def test_scene_with_huge_scatterer_count(tmp_path, capsys, n):
    scene = _scene(tmp_path, {"preset": "full", "objects": [
        {"x_m": 20, "y_m": 0, "length_m": 4, "width_m": 2, "rcs_m2": 10, "n_scatterers": n}]})
    assert main(["simulate", "--scene", scene, "--out", str(tmp_path / "a.npy")]) == 2
    assert "n_scatterers" in capsys.readouterr().err


def test_gnn_detect_and_detect_gnn_agree(tmp_path, capsys):
    """Same scene, same ego speed default, same objects (issue 12 item 7)."""
    pc = tmp_path / "pc.json"
    assert main(["detect", "--scene", "table1", "--backend", "float", "--gnn", "--json",
                 str(pc)]) == 0
    doc = json.loads(pc.read_text())
    assert doc["ego_speed_mps"] == pytest.approx(100 / 3.6)
    objs = tmp_path / "objs.json"
    assert main(["gnn", "detect", "--points", str(pc), "--json", str(objs)]) == 0
    got = json.loads(objs.read_text())["objects"]
    assert [(o["class"], round(o["score"], 3)) for o in got] == [
        (o["class"], round(o["score"], 3)) for o in doc["objects"]]
    bad = tmp_path / "bad.pt"
    bad.write_bytes(b"\x80\x04garbage")
    capsys.readouterr()
    assert main(["gnn", "detect", "--points", str(pc), "--checkpoint", str(bad)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "weights_only=False" not in err
    assert main(["gnn", "detect", "--points", str(pc), "--ego-speed", "nan"]) == 2


def test_demo_paper_fpga_says_aliased(tmp_path, capsys):
    assert main(["demo", "--preset", "paper-fpga", "--backend", "float", "--no-gnn", "--out",
                 str(tmp_path)]) == 0
    out = capsys.readouterr().out
    row = [line for line in out.splitlines() if line.strip().startswith("3 |")][0]
    assert "ALIASED" in row and "*" in row
    assert (tmp_path / "point_cloud.png").stat().st_size > 10_000


def _bad_files(tmp_path):
    """(argv, what the one-line error must say) of bad files given to the CLI, and
    addresses this machine cannot bind."""
    deep = tmp_path / "deep.json"
    deep.write_text("[" * 100_000 + "]" * 100_000)
    pts = {"range_m": 10.0, "azimuth_deg": 0.0, "radial_velocity_mps": 0.0, "power_db": 1.0,
           "snr_db": 20.0}

    def points(name, **bad):
        p = tmp_path / name
        p.write_text(json.dumps({"points": [{**pts, **bad}]}))
        return str(p)

    cap = tmp_path / "c.dmacap"
    assert main(["capture", "--scene", "table1", "--preset", "paper-fpga", "--frames", "1",
                 "--out", str(cap)]) == 0
    raw = bytearray(cap.read_bytes())
    raw[12:16] = (0).to_bytes(4, "little")          # header: payload words per packet 0
    pw0 = tmp_path / "pw0.dmacap"
    pw0.write_bytes(bytes(raw))
    empty = tmp_path / "empty.npz"
    empty.write_bytes(b"")
    (tmp_path / "adir.json").mkdir()
    return [
        (["simulate", "--scene", str(deep), "--out", str(tmp_path / "o.npy")], "nested"),
        (["gnn", "detect", "--points", str(deep)], "nested"),
        (["gnn", "detect", "--points", points("inf.json", frame=float("inf"))], "infinity"),
        (["gnn", "detect", "--points", points("neg.json", range_m=-42.0)], "range >= 0"),
        (["gnn", "detect", "--points", points("az.json", azimuth_deg=1000.0)], "azimuth"),
        (["gnn", "detect", "--points", points("nan.json", snr_db=float("nan"))], "snr_db"),
        (["replay", "--capture", str(pw0), "--port", "9"], "0 payload words"),
        (["view", "--replay", str(pw0), "--port", "0", "--duration", "0.1"],
         "0 payload words"),
        (["gnn", "eval", "--data", str(empty)], "not a gnn dataset"),
        (["gnn", "train", "--data", str(empty), "--threads", "0"], "--threads"),
        (["gnn", "train", "--data", str(empty), "--out", "/proc/x.pt"], "--out"),
        (["receive", "--json", str(tmp_path / "adir.json"), "--timeout", "0.2"], "folder"),
        (["detect", "--scene", "table1", "--preset", "paper-fpga", "--backend", "float",
          "--plots", str(empty), "--json", str(tmp_path / "d.json")], "not a folder"),
        (["simulate", "--scene", "table1", "--out", str(empty / "x.npy")], "not a folder"),
        (["receive", "--json", str(tmp_path / "r.json"), "--host", "8.8.8.8", "--timeout",
          "0.2"], "--host 8.8.8.8"),
        (["view", "--udp-host", "8.8.8.8", "--port", "0", "--duration", "0.1"],
         "--udp-host 8.8.8.8"),
    ]


def test_bad_files_one_line_exit_2(tmp_path, capsys):
    """Files that are not what the option needs (nested too deeply, non-finite or impossible
    points, a capture header with 0 words per packet, an empty dataset, an unwritable or
    folder output): exit 2 with one line naming the problem, before any long work."""
    for argv, word in _bad_files(tmp_path):
        capsys.readouterr()
        assert main(argv) == 2, argv
        err = capsys.readouterr().err.strip()
        assert err.count("\n") == 0 and err.startswith(f"radar {argv[0]}: error:"), err
        assert word.lower() in err.lower() and "Traceback" not in err, (argv, err)
