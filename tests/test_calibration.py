"""Channel calibration (docs/profiles.md, "Calibration"): `radar calibrate` recovers injected
per-channel gain/phase errors and a range bias from a one-reflector capture, the calibration
file round-trips and is refused for another array, `radar process` applies it (or the TI
.cfg's compRangeBiasAndRxChanPhase) before the angle estimation, and bad input is one line
with exit status 2 and nothing written."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from host.adc_capture import write_npy
from host.calibration import apply_calibration, estimate_calibration, load_calibration
from host.cells import Cells
from host.params import params_for
from host.pipeline import process_frame
from model.config import PRESETS
from model.impairments import Impairments
from model.profile import Calibration, load_profile
from model.reference import radar_cube
from model.scene import Scatterers
from model.simulate import simulate_frame
from radar.cli import main
from tests.test_real_chain import tone_frame

CFG_FILE = Path(__file__).parent / "data" / "openradar" / "openradar_2tx4rx.cfg"
PROFILE = load_profile(CFG_FILE)
CFG = PROFILE.config
RANGE_M, AZ_DEG, BIAS_M = 2.0, 12.0, 0.04
"""The reflector as given, and the range bias the radar adds to it."""


def channel_errors(seed: int = 3) -> np.ndarray:
    """Per virtual channel errors, complex (n_virtual,): +-2 dB, +-15 deg."""
    rng = np.random.default_rng(seed)
    return 10 ** (rng.uniform(-2, 2, CFG.n_virtual) / 20) * np.exp(
        1j * np.radians(rng.uniform(-15, 15, CFG.n_virtual)))


def reflector_frames(n: int = 3, errors: np.ndarray | None = None, amplitude: float = 30.0
                     ) -> list[np.ndarray]:
    """ADC frames of one reflector at RANGE_M + BIAS_M, AZ_DEG through the channel errors."""
    err = channel_errors() if errors is None else errors
    return [tone_frame(CFG, [(RANGE_M + BIAS_M, 0.0, AZ_DEG, amplitude)], 1.0, seed=k,
                       channel_error=err) for k in range(n)]


def test_estimate_recovers_injected_errors():
    err = channel_errors()
    est = estimate_calibration((radar_cube(f, CFG) for f in reflector_frames(errors=err)),
                               CFG, RANGE_M, AZ_DEG)
    corrected = np.array(est.calibration.channel_gain) * err
    corrected /= corrected[0]
    assert np.abs(np.degrees(np.angle(corrected))).max() < 1.0
    assert np.abs(20 * np.log10(np.abs(corrected))).max() < 0.1
    assert est.calibration.range_bias_m == pytest.approx(BIAS_M, abs=0.005)
    assert np.sqrt(np.mean(np.abs(np.array(est.calibration.channel_gain)) ** 2)) == \
        pytest.approx(1.0)
    assert est.frames == 3 and est.snr_db > 40 and est.residual_phase_deg < 1.0


def test_calibration_sharpens_the_angle():
    """The same frame through the errors: uncalibrated its angle is off, calibrated it is
    the reflector's, and the range bias is gone (the cells path applies it:
    ``host.points.points_from_cells``)."""
    err = channel_errors()
    est = estimate_calibration((radar_cube(f, CFG) for f in reflector_frames(errors=err)),
                               CFG, RANGE_M, AZ_DEG)
    frame = tone_frame(CFG, [(3.0 + BIAS_M, 0.5, -25.0, 30.0)], 1.0, seed=9,
                       channel_error=err)
    raw = process_frame(frame, CFG)
    cal = process_frame(frame, CFG, replace(params_for(CFG), calibration=est.calibration))
    assert abs(cal.azimuth_deg[0] + 25.0) < 0.3 < abs(raw.azimuth_deg[0] + 25.0)
    assert abs(cal.range_m[0] - 3.0) < 0.01 and abs(raw.range_m[0] - 3.0 - BIAS_M) < 0.01


def test_apply_calibration_to_cells():
    cells = Cells(np.array([3]), np.array([0]), np.ones(1), np.ones(1), np.zeros((1, 2)),
                  np.ones((1, 2), complex))
    out = apply_calibration(cells, Calibration(0.1, (1j, 2.0)))
    assert np.array_equal(out.snapshot, [[1j, 2.0]]) and out.range_bias_m == 0.1
    assert apply_calibration(cells, None) is cells
    with pytest.raises(ValueError, match="3 channel gains for snapshots of 2 channels"):
        apply_calibration(cells, Calibration(0.0, (1, 1, 1)))


def write_capture(path: Path, frames: list[np.ndarray]) -> Path:
    write_npy(path, frames, len(frames), CFG)
    return path


def calibrate(tmp_path: Path, capture: Path, *extra: str, reflector: str = f"{RANGE_M},{AZ_DEG}"
              ) -> tuple[int, Path]:
    out = tmp_path / "cal.json"
    code = main(["calibrate", "--radar", str(CFG_FILE), "--capture", str(capture),
                 "--reflector", reflector, "--out", str(out), *extra])
    return code, out


def test_calibrate_then_process(tmp_path, capsys):
    code, out = calibrate(tmp_path, write_capture(tmp_path / "ref.npy", reflector_frames()))
    printed = capsys.readouterr().out
    assert code == 0 and "range bias +" in printed and "residual" in printed
    doc = json.loads(out.read_text())
    assert doc["range_bias_m"] == pytest.approx(BIAS_M, abs=0.005)
    assert (doc["format"], doc["num_tx"], doc["num_rx"]) == ("radar-calibration", 2, 4)
    assert doc["virtual_positions_hw"] == CFG.virtual_positions_hw.tolist()
    cal = load_calibration(out, CFG)
    corrected = np.array(cal.channel_gain) * channel_errors()
    assert np.abs(np.degrees(np.angle(corrected / corrected[0]))).max() < 1.0
    scene = write_capture(tmp_path / "scene.npy", [tone_frame(
        CFG, [(3.0 + BIAS_M, 0.5, -25.0, 30.0)], 1.0, channel_error=channel_errors())])
    for extra, name in (([], f"compRangeBiasAndRxChanPhase of {CFG_FILE}"),
                        (["--calibration", str(out)], str(out))):
        pts = tmp_path / "points.json"
        assert main(["process", "--radar", str(CFG_FILE), "--capture", str(scene), "--json",
                     str(pts), *extra]) == 0
        assert f"calibration: {name}" in capsys.readouterr().out
        doc = json.loads(pts.read_text())
        assert doc["calibration"] == name
    assert abs(doc["points"][0]["azimuth_deg"] + 25.0) < 0.3
    assert abs(doc["points"][0]["range_m"] - 3.0) < 0.01


def other_array(tmp_path: Path, cal: Path) -> Path:
    doc = json.loads(cal.read_text())
    doc["num_tx"], doc["profile"] = 1, "paper-fpga"
    path = tmp_path / "other.json"
    path.write_text(json.dumps(doc))
    return path


@pytest.mark.parametrize("case", ["other-array", "malformed", "not-json", "gains",
                                  "far-reflector", "bad-reflector", "other-profile"])
def test_bad_input_one_line_exit_2(tmp_path, capsys, case):
    capture = write_capture(tmp_path / "ref.npy", reflector_frames(1))
    code, cal = calibrate(tmp_path, capture)
    assert code == 0
    capsys.readouterr()
    cal.rename(tmp_path / "good.json")
    good = tmp_path / "good.json"
    if case in ("other-array", "malformed", "not-json", "gains"):
        if case == "other-array":
            bad, want = other_array(tmp_path, good), "calibration of another array (1 TX x 4"
        else:
            doc = json.loads(good.read_text())
            bad = tmp_path / "bad.json"
            if case == "malformed":
                del doc["range_bias_m"]
                want = "range_bias_m: missing"
            elif case == "gains":
                doc["channel_gain"] = doc["channel_gain"][:5]
                want = "channel_gain: must be 8 [re, im] pairs"
            bad.write_text("{not json" if case == "not-json" else json.dumps(doc))
            want = "not a calibration file" if case == "not-json" else want
        pts = tmp_path / "points.json"
        code = main(["process", "--radar", str(CFG_FILE), "--capture", str(capture),
                     "--json", str(pts), "--calibration", str(bad)])
        assert not pts.exists()
    else:
        extra = {"far-reflector": dict(reflector="40"), "bad-reflector": dict(reflector="2,x"),
                 "other-profile": {}}[case]
        if case == "other-profile":
            capture = tmp_path / "other.npy"
            np.save(capture, np.zeros(PRESETS["paper-fpga"].adc_shape, np.complex64))
        code, cal = calibrate(tmp_path, capture, **extra)
        want = {"far-reflector": "--reflector: 40 m is outside radar",
                "bad-reflector": "--reflector: must be RANGE_M",
                "other-profile": "expected shape"}[case]
        assert not cal.exists()
    err = capsys.readouterr().err.strip()
    assert code == 2 and err.count("\n") == 0 and want in err, err


def test_weak_reflector_warned(tmp_path, capsys):
    code, out = calibrate(tmp_path, write_capture(tmp_path / "weak.npy",
                                                  reflector_frames(2, amplitude=0.05)))
    err = capsys.readouterr().err
    assert code == 0 and out.exists() and "warning: the reflector is only" in err


def test_calibrate_a_simulated_capture(tmp_path, capsys):
    """The simulator's per-channel gain / phase errors (``model.impairments``) on the
    OpenRadar profile, one reflector: `radar calibrate` recovers g_tx * g_rx within 1 deg
    and 0.1 dB, and no range bias (the simulator has none); its cubes (complex64,
    ``radar.commands.process.capture_cube``) give the estimate the float reference's cubes
    (``model.reference.radar_cube``) give: the cube is within ``host.cube.SINGLE_RTOL`` (1e-6)
    of the reference's peak, the reflector's cell is that peak, and the eigenvector and the
    normalisation of 8 channels of similar power do not amplify it: gains within 1e-5
    relative, range bias within 1 um."""
    imp = Impairments(seed=1, tx_gain_db=(0.0, 1.5), tx_phase_deg=(0.0, 20.0),
                      rx_gain_db=(0.0, -1.0, 1.0, 0.5), rx_phase_deg=(0.0, 10.0, -12.0, 5.0))
    reflector = Scatterers(np.array([2.0]), np.array([12.0]), np.array([0.0]),
                           np.array([1.0]), np.array([-1]))
    frames = [simulate_frame(CFG, reflector, rng=np.random.default_rng(k),
                             impairments=imp).samples for k in range(3)]
    code, out = calibrate(tmp_path, write_capture(tmp_path / "sim.npy", frames),
                          reflector="2,12")
    assert code == 0, capsys.readouterr().err
    db = np.add.outer(imp.tx_gain_db, imp.rx_gain_db).ravel()
    deg = np.add.outer(imp.tx_phase_deg, imp.rx_phase_deg).ravel()
    cal = load_calibration(out, CFG)
    corrected = np.array(cal.channel_gain) * 10 ** (db / 20) * np.exp(1j * np.radians(deg))
    corrected /= corrected[0]
    assert np.abs(np.degrees(np.angle(corrected))).max() < 1.0
    assert np.abs(20 * np.log10(np.abs(corrected))).max() < 0.1
    assert abs(cal.range_bias_m) < 0.005
    ref = estimate_calibration((radar_cube(f, CFG) for f in frames), CFG, 2.0, 12.0)
    np.testing.assert_allclose(cal.channel_gain, ref.calibration.channel_gain, rtol=1e-5)
    assert cal.range_bias_m == pytest.approx(ref.calibration.range_bias_m, abs=1e-6)
