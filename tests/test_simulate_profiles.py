"""The simulator on any radar profile (docs/profiles.md): zero padding, loops, TX firing
order, 2-D / non-uniform arrays, elevation, frame period, real ADC; the presets unchanged."""

import hashlib
from dataclasses import replace

import numpy as np
import pytest

from model.array import direction_cosines, steering
from model.config import C0, RadarConfig
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
