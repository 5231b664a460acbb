"""`--radar PROFILE` on every command that takes `--preset` (docs/profiles.md, "Any command on
any radar"): a preset name, a TOML profile or a TI .cfg through one helper
(`radar.common.scene_profile` / `radar_of`); never together with `--preset`; a profile the
bit-accurate model and the RTL cannot run refused before any work, naming why and the float
source when it runs the profile; the profile's max_speed_mps reaches detection."""

from __future__ import annotations

import json
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from host.capture import read_capture
from model.profile import load_profile
from radar.cli import build_parser, main
from radar.commands.view import build
from tests.test_records_udp import _round_trip

SMALL = """name = "small"
[waveform]
start_frequency_hz = 77.0e9
slope_hz_per_s     = 30.0e12
sample_rate_hz     = 5.0e6
samples_per_chirp  = 32
chirp_period_s     = 20.0e-6
loops              = 32
[array]
tx = [[0, 0], [4, 0]]
rx = [[0, 0], [1, 0], [2, 0], [3, 0]]
[capture]
format = "npy"
"""
"""2 TX x 4 RX, 32 x 32: a profile every backend runs, fast (0.78 m range bins to 22 m)."""
THREE_TX = SMALL.replace('"small"', '"three"').replace(
    "tx = [[0, 0], [4, 0]]", "tx = [[0, 0], [2, 1], [4, 0]]")
"""3 TX, the middle one raised for elevation (xWR1843): every backend runs it."""
WIDE_ADC = SMALL.replace('"small"', '"wide"').replace("loops              = 32",
                                                      "loops              = 32\nadc_bits = 18")
"""An 18-bit ADC: the float chain processes it, the RTL does not (DATA_W = 16)."""
SCENE = {"preset": "full", "seed": 2,
         "targets": [{"range_m": 10.0, "azimuth_deg": 10.0, "radial_velocity_mps": 1.0,
                      "rcs_m2": 10.0}]}


@pytest.fixture
def files(tmp_path: Path) -> dict[str, str]:
    (tmp_path / "small.toml").write_text(SMALL)
    (tmp_path / "three.toml").write_text(THREE_TX)
    (tmp_path / "wide.toml").write_text(WIDE_ADC)
    (tmp_path / "scene.json").write_text(json.dumps(SCENE))
    return {k: str(tmp_path / f) for k, f in (("small", "small.toml"), ("three", "three.toml"),
                                               ("wide", "wide.toml"), ("scene", "scene.json"))}


def _one_line_error(capsys: pytest.CaptureFixture[str]) -> str:
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    return err


# ---- radar detect ----------------------------------------------------------------------------
@pytest.mark.parametrize("backend", ["float", "model"])
def test_detect_on_a_profile(tmp_path, files, backend):
    out = tmp_path / "p.json"
    assert main(["detect", "--scene", files["scene"], "--radar", files["small"], "--backend",
                 backend, "--json", str(out)]) == 0
    doc = json.loads(out.read_text())
    assert doc["preset"] == "small" and doc["radar"] == files["small"]
    cfg = load_profile(files["small"]).config
    # the profile's max_speed_mps (its unambiguous speed), as radar process has it
    assert doc["max_speed_mps"] == pytest.approx(cfg.max_speed_mps)
    assert cfg.max_speed_mps == pytest.approx(cfg.max_velocity_mps)
    (p,) = doc["points"]
    assert p["range_m"] == pytest.approx(10.0, abs=cfg.range_bin_m)
    assert not p["ambiguous"]
    assert main(["detect", "--scene", files["scene"], "--radar", files["small"], "--backend",
                 backend, "--max-speed", "7", "--json", str(out)]) == 0
    assert json.loads(out.read_text())["max_speed_mps"] == 7.0


def test_detect_radar_preset_name_is_the_preset_path(tmp_path, files):
    """`--radar paper-fpga` gives the points `--preset paper-fpga` gives (float backend)."""
    docs = []
    for option in ("--preset", "--radar"):
        out = tmp_path / f"{option[2:]}.json"
        assert main(["detect", "--scene", files["scene"], option, "paper-fpga", "--backend",
                     "float", "--frames", "2", "--json", str(out)]) == 0
        docs.append(json.loads(out.read_text()))
    by_preset, by_radar = docs
    assert by_radar["preset"] == by_preset["preset"] == "paper-fpga"
    assert by_radar["points"] == by_preset["points"] and len(by_radar["points"]) >= 2
    assert by_radar["max_speed_mps"] == by_preset["max_speed_mps"] == 100.0
    # the built-in scene too (its preset given by --preset otherwise)
    for option in ("--preset", "--radar"):
        assert main(["detect", "--scene", "table1", option, "paper-fpga", "--backend", "float",
                     "--json", str(tmp_path / f"t{option[2:]}.json")]) == 0
    assert json.loads((tmp_path / "tpreset.json").read_text())["points"] == json.loads(
        (tmp_path / "tradar.json").read_text())["points"]


# ---- radar demo, radar simulate ---------------------------------------------------------------
@pytest.mark.parametrize("radar", ["small", "paper-fpga"])
def test_demo_on_a_profile_or_preset(tmp_path, files, capsys, radar):
    spec = files.get(radar, radar)
    assert main(["demo", "--out", str(tmp_path), "--radar", spec, "--backend", "float",
                 "--no-gnn"]) == 0
    text = capsys.readouterr().out
    assert f"Table I scene, radar {radar} " in text
    doc = json.loads((tmp_path / "table1_points.json").read_text())
    assert doc["preset"] == radar and doc["points"]
    assert (tmp_path / "point_cloud.png").read_bytes()[:4] == b"\x89PNG"


@pytest.mark.parametrize("radar", ["small", "paper-fpga"])
def test_simulate_on_a_profile_or_preset(tmp_path, files, radar):
    out = tmp_path / "adc.npy"
    assert main(["simulate", "--scene", files["scene"], "--radar", files.get(radar, radar),
                 "--out", str(out)]) == 0
    assert np.load(out).shape == load_profile(files.get(radar, radar)).config.adc_shape


# ---- radar capture / replay / receive ------------------------------------------------------
@pytest.mark.parametrize("radar", ["small", "paper-fpga"])
def test_capture_replay_receive_on_a_profile_or_preset(tmp_path, files, capsys, radar):
    spec = files.get(radar, radar)
    cap = tmp_path / "c.dmacap"
    assert main(["capture", "--scene", files["scene"], "--radar", spec, "--frames", "2",
                 "--out", str(cap)]) == 0
    assert f"radar {radar}," in capsys.readouterr().out
    info, _ = read_capture(cap)
    cfg = load_profile(spec).config
    assert info.matches(cfg)
    rc, out = _round_trip(tmp_path, cap, ["--radar", spec])
    doc = json.loads(out.read_text())
    assert rc == 0 and doc["preset"] == radar
    assert [f["complete"] for f in doc["frame_info"]] == [True, True]
    assert {p["frame"] for p in doc["points"]} == {0, 1}


# ---- radar view ---------------------------------------------------------------------------
@pytest.mark.parametrize("radar", ["small", "paper-fpga"])
def test_view_of_a_scene_on_a_profile_or_preset(files, radar):
    args = build_parser().parse_args(["view", "--scene", files["scene"], "--radar",
                                      files.get(radar, radar), "--fps", "0", "--frames", "1"])
    stop = threading.Event()
    feed, _, threads, desc = build(args, stop)
    assert desc == "scene custom"
    for t in threads:
        t.start()
    try:
        deadline = time.monotonic() + 60
        while feed.latest() is None and time.monotonic() < deadline:
            time.sleep(0.05)
        frame = feed.latest()
        assert frame is not None and frame.cfg.name == radar and len(frame.cloud) >= 1
    finally:
        stop.set()
        for t in threads:
            t.join(timeout=10)


# ---- refusals -----------------------------------------------------------------------------
@pytest.mark.parametrize("command", [
    ["simulate", "--scene", "table1", "--out", "{tmp}/x.npy"],
    ["detect", "--scene", "table1", "--json", "{tmp}/x.json"],
    ["demo", "--out", "{tmp}/demo"],
    ["capture", "--scene", "table1", "--out", "{tmp}/x.dmacap"],
    ["receive", "--json", "{tmp}/x.json", "--timeout", "1"],
    ["view", "--scene", "table1", "--duration", "0.1", "--port", "0"],
    ["view", "--udp-port", "0", "--duration", "0.1", "--port", "0"],
])
def test_radar_and_preset_together_refused(tmp_path, capsys, command):
    argv = [a.replace("{tmp}", str(tmp_path)) for a in command]
    assert main([*argv, "--radar", "paper-fpga", "--preset", "paper-fpga"]) == 2
    assert "--radar and --preset: give one of them" in _one_line_error(capsys)
    assert not [p for p in tmp_path.rglob("*") if p.is_file()]      # nothing written


@pytest.mark.parametrize("command,named,suggested", [
    (["detect", "--scene", "{scene}", "--json", "{tmp}/x.json"], "--backend model",
     "--backend float"),
    (["detect", "--scene", "{scene}", "--json", "{tmp}/x.json", "--backend", "rtl"],
     "--backend rtl", "--backend float"),
    (["detect", "--scene", "{scene}", "--json", "{tmp}/x.json", "--detect", "fpga"],
     "--backend model", "--detect host --backend float"),
    (["demo", "--out", "{tmp}/demo", "--no-gnn"], "--backend model", "--backend float"),
    (["view", "--scene", "{scene}", "--backend", "model", "--duration", "0.1", "--port", "0"],
     "--backend model", "--backend float"),
    (["view", "--scene", "{scene}", "--detect", "fpga", "--duration", "0.1", "--port", "0"],
     "--backend model", None),
    (["view", "--udp-port", "0", "--duration", "0.1", "--port", "0"], "--radar", None),
    (["capture", "--scene", "{scene}", "--out", "{tmp}/x.dmacap"], "--radar", None),
    (["receive", "--json", "{tmp}/x.json", "--timeout", "1"], "--radar", None),
])
def test_a_profile_the_rtl_cannot_run_is_refused(tmp_path, files, capsys, command, named,
                                                 suggested):
    """Before any work (nothing written, no RTL build): one line naming the option, the
    reason (DATA_W = 16 bits) and the float source where it is an option."""
    out = tmp_path / "out"
    argv = [a.replace("{tmp}", str(out)).replace("{scene}", files["scene"]) for a in command]
    assert main([*argv, "--radar", files["wide"]]) == 2
    err = _one_line_error(capsys)
    assert f"error: {named}" in err and "18-bit ADC" in err and "DATA_W" in err, err
    assert (f"({suggested} runs it)" in err) if suggested else "runs it" not in err, err
    assert not [p for p in out.rglob("*") if p.is_file()]      # nothing written


def test_the_float_backend_runs_that_profile(tmp_path, files):
    out = tmp_path / "p.json"
    assert main(["detect", "--scene", files["scene"], "--radar", files["wide"], "--backend",
                 "float", "--json", str(out)]) == 0
    doc = json.loads(out.read_text())
    assert doc["preset"] == "wide" and len(doc["points"]) == 1


def test_three_tx_through_the_bit_accurate_model(tmp_path, files):
    """3 TX (one raised): the model's cube (--detect host) and its detection records
    (--detect fpga) decode to the float chain's target (the host handles the geometry)."""
    docs = {}
    for name, extra in (("float", ["--backend", "float"]), ("cube", ["--backend", "model"]),
                        ("records", ["--backend", "model", "--detect", "fpga"])):
        out = tmp_path / f"{name}.json"
        assert main(["detect", "--scene", files["scene"], "--radar", files["three"], *extra,
                     "--json", str(out)]) == 0
        docs[name] = json.loads(out.read_text())
    want = docs["float"]["points"]
    assert len(want) == 1
    for name in ("cube", "records"):
        got = docs[name]["points"]
        assert docs[name]["preset"] == "three" and len(got) == 1, (name, got)
        for key, tol in (("range_m", 0.05), ("azimuth_deg", 1.0), ("radial_velocity_mps", 0.1)):
            assert abs(got[0][key] - want[0][key]) <= tol, (name, key, got[0], want[0])


def test_a_bad_profile_is_one_line(tmp_path, capsys):
    for argv in (["detect", "--scene", "table1", "--json", str(tmp_path / "x.json")],
                 ["demo", "--out", str(tmp_path / "d")],
                 ["receive", "--json", str(tmp_path / "x.json")]):
        assert main([*argv, "--radar", str(tmp_path / "nope.toml")]) == 2
        assert "no such file" in _one_line_error(capsys)


def test_a_profile_capture_without_its_radar_says_so(tmp_path, files, capsys):
    cap = tmp_path / "c.dmacap"
    assert main(["capture", "--scene", files["scene"], "--radar", files["small"], "--frames",
                 "1", "--out", str(cap)]) == 0
    capsys.readouterr()
    assert main(["view", "--replay", str(cap), "--duration", "0.1", "--port", "0"]) == 2
    assert "give its --radar" in _one_line_error(capsys)
