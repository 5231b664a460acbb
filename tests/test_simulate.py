"""Scene simulator physics: bins, angles, TDM phase, beamforming gain, noise, ADC."""

from dataclasses import replace

import numpy as np
import pytest

from model.config import C0, PRESETS, RadarConfig, get_preset
from model.reference import (
    angle_spectrum,
    radar_cube,
    range_doppler_power,
    signed_bins,
    tdm_phase_compensation,
)
from model.scene import Scatterers
from model.simulate import (
    chirp_times_s,
    chirp_tx,
    quantize_adc,
    simulate_baseband,
    simulate_frame,
    subarray_factor_power,
    tone_amplitude_lsb,
)


def points(*rows: tuple[float, float, float, float]) -> Scatterers:
    """Scatterers from (range_m, azimuth_deg, radial_velocity_mps, rcs_m2) rows."""
    a = np.array(rows, dtype=float).reshape(-1, 4)
    return Scatterers(a[:, 0], a[:, 1], a[:, 2], a[:, 3], np.full(len(a), -1))


def peak(power: np.ndarray) -> tuple[int, int]:
    r, d = np.unravel_index(np.argmax(power), power.shape)
    return int(r), int(d)


def frame_cube(cfg: RadarConfig, sc: Scatterers, seed: int = 0, **kw) -> np.ndarray:
    f = simulate_frame(cfg, sc, rng=np.random.default_rng(seed), **kw)
    assert f.saturated == 0
    return radar_cube(f.samples, cfg)


CASES = {
    "full": [(12.3, 0.0, 0.0), (40.0, -10.0, -12.5), (150.7, 25.0, 7.3), (300.0, -40.0, -25.0),
             (75.0, 5.0, 20.1)],
    "paper-fpga": [(10.0, 0.0, -3.0), (50.0, 10.0, 12.6), (95.0, -20.0, -20.0)],
}


@pytest.mark.parametrize("preset, case", [(p, c) for p, cs in CASES.items() for c in cs])
def test_target_lands_on_expected_range_and_doppler_bin(preset, case):
    cfg = get_preset(preset)
    rng_m, az, v = case
    rcs = 10.0 * (rng_m / 20.0) ** 4  # keep the SNR comfortable at any range
    power = range_doppler_power(frame_cube(cfg, points((rng_m, az, v, rcs))))
    r, d = peak(power)
    exp_r = cfg.range_bin_of(rng_m, v)
    exp_d = cfg.doppler_bin_of(v)
    assert abs(r - exp_r) <= 0.6, (r, exp_r)
    assert abs(signed_bins(cfg.n_doppler)[d] - exp_d) <= 0.6, (d, exp_d)
    # negative velocities land in the upper half of the natural-order Doppler axis
    if exp_d < -0.6:
        assert d >= cfg.n_doppler // 2


def estimate_azimuth(cfg: RadarConfig, cube: np.ndarray, compensate: bool = True) -> float:
    r, d = peak(range_doppler_power(cube))
    ch = cube[:, r, d]
    if compensate:
        ch = ch * tdm_phase_compensation(cfg, d)
    spec, az = angle_spectrum(ch, n_fft=1024)
    return float(az[np.argmax(np.abs(spec))])


@pytest.mark.parametrize("az, v", [(-45.0, -20.0), (-20.0, 3.1), (-3.3, -26.0), (0.0, 0.0),
                                   (12.7, 24.3), (30.0, -7.7), (50.0, 15.0)])
def test_azimuth_after_tdm_compensated_angle_fft(az, v):
    cfg = get_preset("full")
    cube = frame_cube(cfg, points((60.0, az, v, 200.0)), seed=2)
    assert abs(estimate_azimuth(cfg, cube) - az) <= 0.5


def test_tdm_slot_delay_is_simulated():
    """A fast target's angle is wrong without TDM phase compensation, right with it."""
    cfg = get_preset("full")
    cube = frame_cube(cfg, points((60.0, 10.0, 25.0, 200.0)), seed=3)
    assert abs(estimate_azimuth(cfg, cube, compensate=False) - 10.0) > 0.5
    assert abs(estimate_azimuth(cfg, cube, compensate=True) - 10.0) <= 0.5


def measured_snr_db(cfg: RadarConfig, az: float, beamforming: bool) -> float:
    """Target-cell SNR of the non-coherently integrated map: (cell - noise) / noise."""
    # on bin centres (v = 0, beat frequency an integer number of bins)
    rng_m = 40 * cfg.sample_rate_hz / cfg.n_range * C0 / (2 * cfg.slope_hz_per_s)
    cube = frame_cube(cfg, points((rng_m, az, 0.0, 50.0)), seed=7, beamforming=beamforming)
    power = range_doppler_power(cube)
    noise = np.mean(power[120:250, 60:200])  # far from the target
    return float(10 * np.log10((power[40, 0] - noise) / noise))


def test_tx_beamforming_gain():
    cfg = get_preset("full")
    gain0 = measured_snr_db(cfg, 0.0, True) - measured_snr_db(cfg, 0.0, False)
    assert gain0 == pytest.approx(4.0, abs=0.5)  # paper: 10.87 -> 14.92 dBi
    for az in (30.0, -30.0):
        predicted = (cfg.subarray_gain_dbi - cfg.element_gain_dbi
                     + 10 * np.log10(subarray_factor_power(cfg, az)))
        measured = measured_snr_db(cfg, az, True) - measured_snr_db(cfg, az, False)
        assert predicted < -5.0  # the 3-element array factor has a null near +-41.8 deg
        assert measured == pytest.approx(predicted, abs=0.5)


@pytest.mark.parametrize("preset", sorted(PRESETS))
def test_noise_power_matches_noise_figure(preset):
    cfg = get_preset(preset)
    f = simulate_frame(cfg, points(), rng=np.random.default_rng(11))
    x = f.samples.astype(np.complex128)
    measured = np.mean(np.abs(x) ** 2)
    assert 10 * np.log10(measured / cfg.noise_power_lsb2) == pytest.approx(0.0, abs=1.0)
    assert np.mean(x.real**2) == pytest.approx(np.mean(x.imag**2), rel=0.05)
    # and a lower noise figure gives proportionally less noise
    quiet = replace(cfg, noise_figure_db=cfg.noise_figure_db - 6)
    q = simulate_frame(quiet, points(), rng=np.random.default_rng(11)).samples
    assert 10 * np.log10(measured / np.mean(np.abs(q) ** 2)) == pytest.approx(6.0, abs=0.3)


def test_saturation_is_counted():
    cfg = get_preset("paper-fpga")
    normal = simulate_frame(cfg, points((30.0, 0.0, 1.0, 10.0)))
    assert normal.saturated == 0
    hot = simulate_frame(cfg, points((2.0, 0.0, 1.0, 1000.0)))
    assert hot.saturated > 0
    assert np.abs(hot.samples.real).max() <= 32768 and np.abs(hot.samples.imag).max() <= 32768


def test_adc_output_format():
    cfg = get_preset("full")
    f = simulate_frame(cfg, points((40.0, -10.0, -12.5, 20.0)))
    s = f.samples
    assert s.dtype == np.complex64 and s.shape == (1024, 16, 256)
    assert np.array_equal(s.real, np.round(s.real)) and np.array_equal(s.imag, np.round(s.imag))
    assert s.real.min() >= -32768 and s.real.max() <= 32767


def test_quantize_rounds_half_to_even_and_clips():
    x = np.array([0.5, 1.5, -2.5, 40000.0, -40000.0 + 1j * 2.5])
    q, sat = quantize_adc(x, 16)
    assert list(q.real) == [0.0, 2.0, -2.0, 32767.0, -32768.0]
    assert q.imag[-1] == 2.0 and sat == 2


def test_beyond_if_band_is_dropped():
    cfg = get_preset("full")
    f = simulate_frame(cfg, points((500.0, 0.0, 0.0, 10.0), (50.0, 0.0, 0.0, 10.0)))
    assert f.dropped_scatterers == 1


def test_frames_reproducible_and_independent():
    cfg = get_preset("paper-fpga")
    sc = points((30.0, 5.0, 3.0, 10.0))
    a = simulate_frame(cfg, sc, rng=np.random.default_rng(1)).samples
    b = simulate_frame(cfg, sc, rng=np.random.default_rng(1)).samples
    c = simulate_frame(cfg, sc, rng=np.random.default_rng(2)).samples
    assert np.array_equal(a, b) and not np.array_equal(a, c)


def test_vectorised_simulator_equals_direct_formula():
    """The batched matrix product equals a brute-force evaluation of the documented phase
    2 pi (fc tau + S tau_r t_n - S tau0^2/2) (aperture and v t_n^2 beat terms dropped)."""
    cfg = RadarConfig(name="small", num_tx=2, num_rx=3, n_range=64, n_doppler=16,
                      sample_rate_hz=20e6, chirp_period_s=4e-6, design_max_range_m=100.0)
    sc = points((40.0, -10.0, -12.5, 20.0), (70.0, 25.0, 30.0, 5.0), (10.0, 0.0, 0.0, 1.0))
    got, dropped = simulate_baseband(cfg, sc)
    assert dropped == 0
    amp = tone_amplitude_lsb(cfg, sc, True)
    t_c = chirp_times_s(cfg)[:, None, None, None]
    half = cfg.wavelength_m / 2
    y_tx = half * cfg.tx_positions_hw[chirp_tx(cfg), 0][:, None, None, None]
    y_rx = half * cfg.rx_positions_hw[:, 0][None, :, None, None]
    t_n = (np.arange(cfg.n_range) / cfg.sample_rate_hz)[None, None, :, None]
    r, v, s = sc.range_m, sc.radial_velocity_mps, np.sin(np.radians(sc.azimuth_deg))
    tau = (2 * (r + v * (t_c + t_n)) - (y_tx + y_rx) * s) / C0
    tau_beat = 2 * (r + v * t_c) / C0
    phase = 2 * np.pi * (cfg.fc_hz * tau + cfg.slope_hz_per_s * tau_beat * t_n
                         - cfg.slope_hz_per_s * (2 * r / C0) ** 2 / 2)
    want = (amp * np.exp(1j * phase)).sum(axis=-1)
    assert np.max(np.abs(got - want)) < 1e-3 * np.max(np.abs(want))
