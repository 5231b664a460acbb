"""The simulator on any radar profile (docs/profiles.md): zero padding, loops, TX firing
order, 2-D / non-uniform arrays, elevation, frame period, real ADC; the presets unchanged."""

import hashlib
import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from host.adc_capture import open_capture
from model.array import direction_cosines, steering
from model.config import C0, RadarConfig
from model.profile import load_profile
from model.scene import ExtendedObject, PointTarget, Scatterers, Scene, table1_scene
from model.simulate import (
    chirp_times_s,
    chirp_tx,
    frame_period_s,
    simulate_baseband,
    simulate_frame,
    simulate_scene,
    tone_amplitude_lsb,
)
from radar.cli import main

PROFILE = RadarConfig(
    name="odd", num_tx=3, num_rx=4, n_range=64, n_doppler=16, sample_rate_hz=20e6,
    chirp_period_s=4e-6, design_max_range_m=60.0, samples_per_chirp=50, loops=13,
    tx_order=(2, 0, 1), tx_positions=((0, 0), (2, 1), (4, 0)),
    rx_positions=((0, 0), (1, 0), (2.5, 0), (3, 0.5)), frame_period_s=1e-3)
"""Every profile field away from the presets' (complex ADC; the real one: ``REAL``)."""
REAL = replace(PROFILE, name="odd-real", adc="real", design_max_range_m=30.0)


def points(*rows: tuple[float, ...]) -> Scatterers:
    """Scatterers from (range_m, azimuth_deg, radial_velocity_mps, rcs_m2, elevation_deg)."""
    a = np.array(rows, dtype=float).reshape(-1, 5)
    return Scatterers(a[:, 0], a[:, 1], a[:, 2], a[:, 3], np.full(len(a), -1), a[:, 4])


def digest(a: np.ndarray) -> str:
    return hashlib.sha256(np.ascontiguousarray(a).tobytes()).hexdigest()[:16]


def test_presets_bit_identical_to_before_profiles():
    """All profile fields at their defaults: the frames of the simulator before profiles and
    impairments existed (sha256 of the samples, pinned on this code's numpy)."""
    assert digest(simulate_scene(table1_scene("paper-fpga", seed=1), 0).samples) == \
        "77aee7fac94e13e6"
    sc = Scene(preset="paper-fpga", seed=3, targets=(PointTarget(12.0, 20.0, 3.0, 5.0),),
               objects=(ExtendedObject(30, 2, 4.5, 1.8, 20, -5, 1, 10, 20),))
    assert digest(simulate_scene(sc, 7).samples) == "20e4254c88a9eff1"


def test_any_profile_equals_direct_formula():
    """The batched product equals a brute-force evaluation of the documented phase with the
    TX of each chirp slot, 2-D positions (model.array.steering), elevation, n_samples and
    n_loops, and the frame period."""
    cfg = PROFILE
    sc = points((30.0, -10.0, -4.0, 20.0, 5.0), (50.0, 25.0, 6.0, 5.0, -12.0),
                (10.0, 0.0, 0.0, 1.0, 30.0))
    k = 2
    got, dropped = simulate_baseband(cfg, sc, frame_index=k)
    assert dropped == 0 and got.shape == cfg.adc_shape == (39, 4, 50)
    r_centre = sc.range_m + sc.radial_velocity_mps * k * cfg.frame_period_s
    amp = tone_amplitude_lsb(cfg, replace(sc, range_m=r_centre), True)
    r = sc.range_m                      # t_c is measured from the centre of frame 0
    t_c = chirp_times_s(cfg, k)[:, None, None, None]
    assert np.isclose(t_c[1, 0, 0, 0] - t_c[0, 0, 0, 0], cfg.chirp_period_s)
    assert np.isclose(chirp_times_s(cfg, 1)[0] - chirp_times_s(cfg, 0)[0], 1e-3)
    u, w = direction_cosines(np.radians(sc.azimuth_deg), np.radians(sc.elevation_deg))
    pos = (cfg.tx_positions_hw[chirp_tx(cfg)][:, None, :] + cfg.rx_positions_hw[None, :, :])
    path = (cfg.wavelength_m / 2) * (pos[..., 0, None] * u + pos[..., 1, None] * w)
    path = path[:, :, None, :]                                           # (C, R, 1, S)
    t_n = (np.arange(cfg.n_samples) / cfg.sample_rate_hz)[None, None, :, None]
    v, slope = sc.radial_velocity_mps, cfg.slope_hz_per_s
    tau = (2 * (r + v * (t_c + t_n)) - path) / C0
    tau_beat = 2 * (r + v * t_c) / C0
    phase = 2 * np.pi * (cfg.fc_hz * tau + slope * tau_beat * t_n - slope * (2 * r / C0) ** 2 / 2)
    want = (amp * np.exp(1j * phase)).sum(axis=-1)
    assert np.max(np.abs(got - want)) < 1e-3 * np.max(np.abs(want))


def test_channel_phases_follow_tx_order_and_elevation():
    """A static target's range-FFT peak, channel by channel (chirp c fired by
    tx_sequence[c % num_tx], RX r), has the phases of model.array.steering."""
    cfg = replace(PROFILE, samples_per_chirp=64)
    bin_m = cfg.range_bin_m
    az, el = 20.0, -15.0
    frame = simulate_frame(cfg, points((20 * bin_m, az, 0.0, 5e4, el)), noise=False)
    peak = np.fft.fft(frame.samples, axis=-1)[:, :, 20]                 # (C, R)
    u, w = direction_cosines(np.radians(az), np.radians(el))
    want = (steering(cfg.tx_positions_hw, u, w)[chirp_tx(cfg)][:, None]
            * steering(cfg.rx_positions_hw, u, w)[None, :])
    ratio = peak / want
    assert np.max(np.abs(np.angle(ratio / ratio[0, 0]))) < np.radians(0.5)
    assert chirp_tx(cfg)[:6].tolist() == [2, 0, 1, 2, 0, 1]


def test_zero_padded_profile_shapes_and_target_bin():
    cfg = PROFILE
    frame = simulate_frame(cfg, points((20.0, 0.0, 0.0, 20.0, 0.0)))
    assert frame.samples.shape == (3 * 13, 4, 50) and frame.samples.dtype == np.complex64
    spec = np.abs(np.fft.fft(frame.samples, n=cfg.n_range, axis=-1)).sum(axis=(0, 1))
    assert abs(int(np.argmax(spec)) - cfg.range_bin_of(20.0)) <= 0.5
    assert np.isclose(frame_period_s(cfg), 1e-3)
    assert np.isclose(frame_period_s(replace(cfg, frame_period_s=None)), cfg.frame_time_s)


def test_real_adc_is_the_i_channel_of_the_complex_if():
    """A real ADC's noise-free frame is the real part of the complex ADC's (same codes), real
    float32 integers; its range spectrum is Hermitian: the target at bin k and its mirror at
    n - k with equal magnitude; its noise has variance noise_power_lsb2 / 2."""
    sc = points((12.0, 10.0, 1.0, 20.0, 0.0))
    real = simulate_frame(REAL, sc, noise=False).samples
    cplx = simulate_frame(replace(REAL, adc="complex"), sc, noise=False).samples
    assert real.dtype == np.float32 and real.shape == REAL.adc_shape
    assert np.array_equal(real, np.rint(real)) and np.array_equal(real, cplx.real)
    spec = np.fft.fft(real[0, 0], n=REAL.n_range)
    assert np.allclose(spec[1:], np.conj(spec[1:][::-1]), atol=1e-3)
    k = int(np.argmax(np.abs(spec[: REAL.n_range // 2])))
    assert abs(k - REAL.range_bin_of(12.0, 1.0)) <= 0.5
    assert np.isclose(np.abs(spec[REAL.n_range - k]), np.abs(spec[k]))
    noise = simulate_frame(REAL, points(), rng=np.random.default_rng(4)).samples
    assert np.var(noise) == pytest.approx(REAL.noise_power_lsb2 / 2, rel=0.03)


def test_real_adc_drops_beats_beyond_half_the_sample_rate():
    beyond = 0.75 * REAL.n_range * REAL.range_bin_m          # beat 0.75 fs: < fs, > fs / 2
    assert simulate_frame(REAL, points((beyond, 0.0, 0.0, 1.0, 0.0))).beyond_if_scatterers == 1
    assert simulate_frame(replace(REAL, adc="complex"),
                          points((beyond, 0.0, 0.0, 1.0, 0.0))).beyond_if_scatterers == 0


def test_scene_elevation_json():
    d = {"preset": "paper-fpga", "targets": [{"range_m": 20, "azimuth_deg": 5,
                                              "radial_velocity_mps": 0, "rcs_m2": 1,
                                              "elevation_deg": 10}]}
    s = Scene.from_dict(d)
    assert s.targets[0].elevation_deg == 10 and s.scatterers().elevation_deg.tolist() == [10]
    assert Scene.from_dict(s.to_dict()) == s
    flat = Scene.from_dict({**d, "targets": [{**d["targets"][0], "elevation_deg": 0}]})
    assert "elevation_deg" not in flat.to_dict()["targets"][0]
    with pytest.raises(ValueError, match=r"targets\[0\]\.elevation_deg"):
        Scene.from_dict({**d, "targets": [{**d["targets"][0], "elevation_deg": 95}]})


# ---- radar simulate --radar / --frames / .bin ------------------------------------------------
DATA = Path(__file__).parent / "data" / "openradar"
SMALL_TOML = """
name = "small-real"
[waveform]
start_frequency_hz = 77.0e9
slope_hz_per_s     = 60.0e12
sample_rate_hz     = 5.0e6
samples_per_chirp  = 61
idle_time_s        = 10.0e-6
ramp_end_time_s    = 20.0e-6
loops              = 9
tx_order           = [1, 0, 2]
adc                = "real"
[array]
tx = [[0, 0], [2, 1], [4, 0]]
rx = [[0, 0], [1, 0], [2, 0], [3, 0]]
[capture]
format      = "dca1000"
lanes       = 4
interleaved = true
"""
"""A 3-TX real-ADC profile (xWR1843-like raised TX, 61 samples, 9 loops, 4-lane capture)."""
ROOM = {"preset": "paper-fpga", "seed": 3,
        "targets": [{"range_m": 3.0, "azimuth_deg": 10, "radial_velocity_mps": 0.6,
                     "rcs_m2": 0.5, "elevation_deg": 5}],
        "impairments": {"seed": 1, "rx_phase_rms_deg": 5, "leakage_dbfs": -30,
                        "dc_offset_dbfs": -60, "phase_noise_rms_deg": 0.5,
                        "walls": [{"x1_m": 4.5, "y1_m": -2, "x2_m": 4.5, "y2_m": 2,
                                   "rcs_m2": 1}]}}


@pytest.fixture
def room(tmp_path: Path) -> Path:
    p = tmp_path / "room.json"
    p.write_text(json.dumps(ROOM))
    return p


@pytest.mark.parametrize("profile_text, suffix", [(None, ".bin"), (None, ".npy"),
                                                  (SMALL_TOML, ".bin"), (SMALL_TOML, ".npy")])
def test_simulate_writes_a_capture_of_any_profile(tmp_path, room, capsys, profile_text, suffix):
    if profile_text is None:
        spec = str(DATA / "openradar_2tx4rx.cfg")
    else:
        spec = str(tmp_path / "small.toml")
        Path(spec).write_text(profile_text)
    out = tmp_path / f"cap{suffix}"
    assert main(["simulate", "--scene", str(room), "--radar", spec, "--frames", "2",
                 "--frame", "4", "--out", str(out)]) == 0
    assert "radar " in capsys.readouterr().out
    profile = load_profile(spec)
    scene = replace(Scene.from_dict(ROOM), radar=profile.config)
    cap = open_capture(out, profile)
    got = list(cap.frames())
    assert len(got) == 2
    for k, frame in enumerate(got):
        assert np.array_equal(frame, simulate_scene(scene, 4 + k).samples)


def test_simulated_capture_processes(tmp_path, room):
    """The round trip a user makes: an impaired capture of the OpenRadar profile, then
    `radar process` on it."""
    cfg = str(DATA / "openradar_2tx4rx.cfg")
    cap = tmp_path / "room.bin"
    assert main(["simulate", "--scene", str(room), "--radar", cfg, "--out", str(cap)]) == 0
    assert main(["process", "--radar", cfg, "--capture", str(cap), "--json",
                 str(tmp_path / "pts.json"), "--remove-static"]) == 0
    assert json.loads((tmp_path / "pts.json").read_text())["points"]


def test_one_frame_npy_is_unchanged(tmp_path):
    out = tmp_path / "adc.npy"
    assert main(["simulate", "--scene", "table1", "--preset", "paper-fpga", "--out",
                 str(out)]) == 0
    assert np.array_equal(np.load(out), simulate_scene(table1_scene("paper-fpga", 1)).samples)


@pytest.mark.parametrize("extra, message", [
    (["--radar", "nope.toml"], "nope.toml"),
    (["--radar", "full", "--preset", "full"], "--radar and --preset"),
    (["--frames", "0"], "--frames"),
    (["--frame", "999999", "--frames", "5"], "--frames"),
    (["--out-txt"], "must end in .npy or .bin"),
])
def test_simulate_bad_input_one_line_exit_2(tmp_path, room, capsys, extra, message):
    out = ["--out", str(tmp_path / ("x.txt" if extra == ["--out-txt"] else "x.npy"))]
    args = ["simulate", "--scene", str(room), *out, *[a for a in extra if a != "--out-txt"]]
    assert main(args) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and message in err
    assert not (tmp_path / "x.npy").exists()


def test_simulate_refuses_impairments_the_radar_cannot_have(tmp_path, capsys):
    scene = tmp_path / "iq.json"
    scene.write_text(json.dumps({**ROOM, "impairments": {"iq_gain_db": 0.5}}))
    toml = tmp_path / "small.toml"
    toml.write_text(SMALL_TOML)
    assert main(["simulate", "--scene", str(scene), "--radar", str(toml), "--out",
                 str(tmp_path / "x.bin")]) == 2
    assert "impairments.iq_gain_db" in capsys.readouterr().err
    assert not (tmp_path / "x.bin").exists()


def test_process_plots_side_view_for_an_array_with_elevation(tmp_path, room, capsys):
    """`radar process --plots` on a capture of the raised-TX profile: its points carry z_m and
    elevation_deg and the figures include the x-z side view (planar arrays have none)."""
    spec = tmp_path / "small.toml"
    spec.write_text(SMALL_TOML)
    cap = tmp_path / "cap.npy"
    assert main(["simulate", "--scene", str(room), "--radar", str(spec), "--frames", "1",
                 "--out", str(cap)]) == 0
    out, figs = tmp_path / "points.json", tmp_path / "figs"
    assert main(["process", "--radar", str(spec), "--capture", str(cap), "--json", str(out),
                 "--remove-static", "--plots", str(figs), "--train", "4", "3"]) == 0
    doc = json.loads(out.read_text())
    assert doc["points"] and all("z_m" in p and "elevation_deg" in p for p in doc["points"])
    assert (figs / "side_view.png").read_bytes()[:4] == b"\x89PNG"
    assert "side_view.png" in capsys.readouterr().out
