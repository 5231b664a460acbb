"""The `radar` command line: simulate writes the DESIGN.md array; bad input exits 2."""

import json
import subprocess
import sys

import numpy as np

from host.cli import main


def test_simulate_builtin(tmp_path, capsys):
    out = tmp_path / "adc.npy"
    assert main(["simulate", "--scene", "table1", "--out", str(out)]) == 0
    x = np.load(out)
    assert x.dtype == np.complex64 and x.shape == (4 * 256, 16, 256)
    assert np.array_equal(x.real, np.round(x.real))
    assert "saturated" in capsys.readouterr().out


def test_simulate_scene_file(tmp_path):
    scene = tmp_path / "scene.json"
    scene.write_text(json.dumps({"preset": "paper-fpga", "seed": 1, "tx_beamforming": True,
                                 "targets": [{"range_m": 40.0, "azimuth_deg": -10.0,
                                              "radial_velocity_mps": -12.5, "rcs_m2": 20.0}]}))
    out = tmp_path / "adc.npy"
    assert main(["simulate", "--scene", str(scene), "--out", str(out)]) == 0
    assert np.load(out).shape == (256, 4, 64)


def test_bad_input_one_line_exit_2(tmp_path, capsys):
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"preset": "full", "targets": [{"range_m": "far"}]}))
    assert main(["simulate", "--scene", str(bad), "--out", str(tmp_path / "x.npy")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "targets[0].range_m" in err
    assert main(["simulate", "--scene", "table1", "--out", str(tmp_path / "x.txt")]) == 2


def test_entry_point_installed():
    r = subprocess.run([sys.executable, "-m", "host.cli", "simulate", "--help"],
                       capture_output=True, text=True, check=True)
    assert "--scene" in r.stdout and "N_RANGE" in r.stdout


def test_demo_writes_figures(tmp_path, capsys):
    assert main(["demo", "--out", str(tmp_path)]) == 0
    text = capsys.readouterr().out
    assert "aliases to +5.56 m/s" in text  # vehicle 3 reported honestly
    for name in ("range_doppler_ch0.png", "range_doppler_nci.png"):
        assert (tmp_path / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
