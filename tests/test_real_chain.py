"""The float chain on profiles' shapes (docs/profiles.md, "What the chain processes today"):
zero-padded range and Doppler FFTs (200 of 256 samples, 255 of 256 loops), a real ADC (no
mirror images), a TX firing order in the corner turn; the window quantities the host reads
for them (``model.reference.FftAxis``) and the presets left as they were. Frames: tones
synthesised here (:func:`tone_frame`) and the simulator's."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from host.cfar import MAIN_LOBE_BINS, CfarParams, cfar_threshold, sidelobe_envelope
from host.params import default_guard, params_for
from host.pipeline import process_cube, process_frame
from model.array import steering
from model.cfar_stats import HANN_POWER_CORRELATION
from model.config import PRESETS, RadarConfig
from model.hdl import check_hdl
from model.radar_pipeline import PipelineParams, run_chain, scaled_cube
from model.reference import FftAxis, corner_turn, fft_axes, radar_cube, range_doppler_power
from model.scene import Scatterers
from model.simulate import simulate_frame
from radar.frame_cloud import frame_cloud
from tests.oracles.chain import run_chain_reference

BASE = RadarConfig(name="small", num_tx=2, num_rx=4, n_range=256, n_doppler=256,
                   sample_rate_hz=10e6, chirp_period_s=40e-6, design_max_range_m=9.0,
                   sweep_bandwidth_hz=1.5e9)
"""A 2 TX x 4 RX radar, 10 cm range bins, +-24 m/s, ULA (what the chain takes today)."""
TARGETS = [(4.3, 1.1, 10.0, 50.0), (8.0, -2.0, -20.0, 30.0)]
"""(range m, radial velocity m/s, azimuth deg, amplitude LSB) of the test targets."""


def tone_frame(cfg: RadarConfig, targets: list[tuple[float, float, float, float]],
               noise_lsb: float = 1.0, seed: int = 0,
               channel_error: np.ndarray | None = None) -> np.ndarray:
    """One ADC frame of ``cfg`` (n_chirps, num_rx, n_samples) holding point targets as
    tones: beat frequency of range and speed, Doppler over the chirps, each chirp's TX of
    ``cfg.tx_sequence`` at its virtual positions (``model.array.steering``); the real part
    for a real ADC; white noise of ``noise_lsb`` rms; ``channel_error`` complex
    (n_virtual,) multiplies each (TX, RX) lane."""
    rng = np.random.default_rng(seed)
    c = np.arange(cfg.n_chirps)
    tx = np.array(cfg.tx_sequence)[c % cfg.num_tx]
    n = np.arange(cfg.n_samples)
    x = np.zeros(cfg.adc_shape, complex)
    for r, v, az, a in targets:
        sv = steering(cfg.virtual_positions_hw, np.sin(np.radians(az)))
        slow = np.exp(4j * np.pi * v * c * cfg.chirp_period_s / cfg.wavelength_m)
        fast = np.exp(2j * np.pi * cfg.beat_frequency_hz(r, v) * n / cfg.sample_rate_hz)
        x += a * slow[:, None, None] * sv.reshape(cfg.num_tx, cfg.num_rx)[tx][:, :, None] \
            * fast
    if channel_error is not None:
        x = x * channel_error.reshape(cfg.num_tx, cfg.num_rx)[tx][:, :, None]
    if cfg.adc == "real":
        return x.real + noise_lsb * rng.standard_normal(x.shape)
    return x + noise_lsb / np.sqrt(2) * (rng.standard_normal(x.shape)
                                         + 1j * rng.standard_normal(x.shape))


def points_of(cfg: RadarConfig, frame: np.ndarray) -> list[tuple[float, float, float, float]]:
    """(range, velocity, azimuth, RCS) of each point of ``frame`` (default settings)."""
    pc = process_frame(frame, cfg)
    return sorted(zip(pc.range_m, pc.radial_velocity_mps, pc.azimuth_deg, pc.rcs_dbsm,
                      strict=True))


@pytest.mark.parametrize("changes", [dict(loops=255), dict(samples_per_chirp=200),
                                     dict(samples_per_chirp=200, loops=255), dict(adc="real")],
                         ids=["255-loops", "200-samples", "both", "real-adc"])
def test_profile_shapes_process(changes):
    """255 loops of 256, 200 samples of 256 and a real ADC: each target once, at its range,
    speed and angle, with the RCS the unpadded complex profile gives (window gain and
    scalloping of the padded window, half amplitude of a real tone undone)."""
    cfg = replace(BASE, **changes)
    assert cfg.unsupported_features() == []
    want = points_of(BASE, tone_frame(BASE, TARGETS))
    got = points_of(cfg, tone_frame(cfg, TARGETS))
    assert len(got) == len(want) == len(TARGETS)
    for (r, v, az, rcs), (*_, rcs0), (rt, vt, azt, _) in zip(
            got, want, sorted(TARGETS), strict=True):
        assert abs(r - rt) < 0.2 * cfg.range_bin_m and abs(v - vt) < 0.2 * cfg.velocity_bin_mps
        assert abs(az - azt) < 0.3
        assert abs(rcs - rcs0) < 0.2


def test_real_adc_cube_has_no_mirror():
    """A real ADC's cube keeps bins 0..n_range/2-1: no target has a mirror point at bin
    N - k, and its frame is not reported as real-only samples of a complex profile."""
    cfg = replace(BASE, adc="real")
    assert cfg.cube_shape == (8, 128, 256) and cfg.max_range_m == pytest.approx(12.79, 1e-3)
    assert cfg.detection_bins[1] == 124
    frame = tone_frame(cfg, TARGETS)
    assert frame.dtype.kind == "f"
    cube = radar_cube(frame, cfg)
    fc = frame_cloud(cube, cfg, params_for(cfg), 0, "test")
    assert len(fc.cloud) == len(TARGETS) and fc.problems == []
    with pytest.raises(ValueError, match="complex samples"):
        radar_cube(frame.astype(complex), cfg)


def test_tx_order_gives_the_same_cube_channels():
    """Chirps fired in another TX order, put back by the corner turn: channel v = tx *
    num_rx + rx by TX index, whatever slot the TX fired in."""
    cfg = replace(BASE, num_tx=3, n_range=16, design_max_range_m=0.5)
    perm = replace(cfg, tx_order=(2, 0, 1))
    rng = np.random.default_rng(1)
    by_tx = rng.standard_normal((cfg.n_loops, 3, 4, 16)) + 0j     # (loop, TX index, rx, r)
    fired = by_tx[:, list(perm.tx_sequence)]                      # (loop, slot, rx, r)
    a = corner_turn(by_tx.reshape(-1, 4, 16), cfg)
    b = corner_turn(fired.reshape(-1, 4, 16), perm)
    assert np.array_equal(a, b)
    assert not np.array_equal(corner_turn(fired.reshape(-1, 4, 16), cfg), a)


def test_window_quantities_of_padded_axes():
    """FftAxis: the presets' numbers unchanged; a padded axis' main lobe, coherent gain,
    noise correlation and window response as the DFT of the padded window gives them."""
    for cfg in PRESETS.values():
        for ax in fft_axes(cfg):
            assert (ax.main_lobe_bins, ax.coherent_gain) == (MAIN_LOBE_BINS, 0.5)
            assert ax.power_correlation() == HANN_POWER_CORRELATION
        assert default_guard(cfg) == (2, 2)
    ax = FftAxis(256, 200)
    assert ax.main_lobe_bins == 3 and ax.coherent_gain == pytest.approx(0.5 * 200 / 256)
    rho = ax.power_correlation()
    assert rho[1] > HANN_POWER_CORRELATION[1] and len(rho) > 3
    w = np.zeros(256)
    w[:200] = ax.window()
    noise = np.fft.fft(w * np.random.default_rng(0).standard_normal((4000, 256)), axis=1)
    p = np.abs(noise[:, 40:80]) ** 2
    measured = np.corrcoef(p[:, 0], p[:, 1])[0, 1]
    assert measured == pytest.approx(rho[1], abs=0.05)
    off = np.array([0.0, 0.3, -0.5, 1.7])
    resp = np.abs([np.sum(w * np.exp(-2j * np.pi * o * np.arange(256) / 256)) for o in off])
    assert np.allclose(FftAxis(256, 200).response(off), resp / w.sum(), atol=1e-12)
    env = sidelobe_envelope(256, True, 200)
    assert env[:4].max() == 0.0 and 0 < env[4] < 10 ** -2.5
    assert default_guard(replace(BASE, samples_per_chirp=200, loops=255)) == (3, 3)


SCENE = Scatterers(np.array([4.3, 8.0]), np.array([10.0, -20.0]), np.array([1.1, -2.0]),
                   np.array([0.01, 0.1]), np.array([-1, -1]))
"""Two targets (range m, azimuth deg, radial velocity m/s, RCS m^2) for the simulator."""


@pytest.mark.parametrize("changes", [dict(samples_per_chirp=200, loops=255), dict(adc="real"),
                                     dict(samples_per_chirp=200, loops=255, adc="real")],
                         ids=["padded", "real-adc", "padded-real"])
def test_fixed_point_chain_tracks_the_float_chain(changes):
    """The bit-accurate model (the RTL's chain with N_SAMPLES, N_LOOPS, REAL_ADC) on padded
    and real-ADC profiles: on the simulator's frames the same detections as the float chain
    (each target once, same cell, same angle within 0.2 deg; no false alarm the float chain
    has not) -- the zero fill and the real ADC's half spectrum follow the float chain's
    definitions (model.reference)."""
    cfg = replace(BASE, **changes)
    params = PipelineParams()
    params.check(cfg)
    hdl = params.hdl_parameters(cfg)
    assert (hdl["N_SAMPLES"], hdl["N_LOOPS"], hdl["REAL_ADC"]) == (
        cfg.n_samples, cfg.n_loops, int(cfg.adc == "real"))
    extra = 0
    for seed in range(3):
        frame = simulate_frame(cfg, SCENE, rng=np.random.default_rng(seed)).samples
        fixed = process_cube(scaled_cube(frame, cfg, params), cfg)
        ref = process_cube(radar_cube(frame, cfg), cfg)
        near = [np.flatnonzero(np.abs(p.range_m - 4.3) < 0.3) for p in (fixed, ref)]
        far = [np.flatnonzero(np.abs(p.range_m - 8.0) < 0.3) for p in (fixed, ref)]
        for (i, j) in (near, far):
            assert len(i) == len(j) == 1, (seed, fixed.range_m, ref.range_m)
            assert abs(fixed.range_m[i[0]] - ref.range_m[j[0]]) < 0.05 * cfg.range_bin_m
            assert abs(fixed.radial_velocity_mps[i[0]] - ref.radial_velocity_mps[j[0]]) \
                < 0.05 * cfg.velocity_bin_mps
            assert abs(fixed.azimuth_deg[i[0]] - ref.azimuth_deg[j[0]]) < 0.2
        extra += max(0, len(fixed) - len(ref))
    assert extra == 0


def test_fixed_point_chain_matches_its_oracle_on_a_profile():
    """run_chain (planar fast path) = the stage-by-stage int64 oracle on a 200-of-256
    sample, 15-of-32 loop real-ADC profile (tests/oracles/chain.py), in both read orders;
    through the external frame store the same payload (all loops: it refuses fewer)."""
    cfg = replace(BASE, n_doppler=32, samples_per_chirp=200, loops=15, adc="real")
    frame = simulate_frame(cfg, SCENE, rng=np.random.default_rng(0)).samples
    for params in (PipelineParams(), PipelineParams(output_mode=1)):
        a, b = run_chain(frame, cfg, params), run_chain_reference(frame, cfg, params)
        assert a.payload.shape == (2, 128, 32, 4)
        assert np.array_equal(a.payload, b.payload)
        assert (a.range_overflow, a.doppler_overflow) == (b.range_overflow, b.doppler_overflow)
        if params.output_mode:
            assert np.array_equal(a.records, b.records)
    with pytest.raises(ValueError, match="external frame store"):
        PipelineParams(frame_store=True).check(cfg)
    with pytest.raises(ValueError, match="201 samples per chirp .no window ROM"):
        check_hdl(replace(cfg, samples_per_chirp=201))
    whole = replace(cfg, loops=32)          # all loops: the external store takes it too
    frame = simulate_frame(whole, SCENE, rng=np.random.default_rng(1)).samples
    assert np.array_equal(run_chain(frame, whole).payload,
                          run_chain(frame, whole, PipelineParams(frame_store=True)).payload)


def test_padded_noise_keeps_the_configured_pfa():
    """CA-CFAR on noise of a 160-of-256 sample, 160-of-256 loop profile: with the padded
    axes' wider guard and noise correlation the false-alarm rate is the configured one."""
    cfg = replace(BASE, samples_per_chirp=160, loops=160)
    params = CfarParams(pfa=1e-3, guard=default_guard(cfg))
    rng = np.random.default_rng(0)
    alarms = cells = 0
    for _ in range(6):
        noise = rng.standard_normal(cfg.adc_shape) + 1j * rng.standard_normal(cfg.adc_shape)
        nci = range_doppler_power(radar_cube(noise, cfg))
        alarms += int((nci > cfar_threshold(nci, cfg.n_virtual, params, fft_axes(cfg))[0]
                       ).sum())
        cells += nci.size
    assert 0.8e-3 < alarms / cells < 1.2e-3


@pytest.mark.parametrize("changes", [dict(loops=255), dict(adc="real"),
                                     dict(samples_per_chirp=200, loops=255, adc="real")],
                         ids=["255-loops", "real-adc", "padded-real"])
def test_simulated_profiles_process(changes):
    """The simulator's frames of padded and real-ADC profiles (``model.simulate``): each
    target once (no mirror image), at its range, speed and angle, and the radar equation's
    RCS back within 0.3 dB (the padded window's gain, a real tone's half amplitude)."""
    cfg = replace(BASE, **changes)
    sc = Scatterers(np.array([4.3, 8.0]), np.array([10.0, -20.0]), np.array([1.1, -2.0]),
                    np.array([0.01, 0.1]), np.array([-1, -1]))
    frame = simulate_frame(cfg, sc, rng=np.random.default_rng(0)).samples
    assert frame.dtype.kind == ("f" if cfg.adc == "real" else "c")
    pc = process_frame(frame, cfg)
    assert len(pc) == 2
    order = np.argsort(pc.range_m)
    assert np.allclose(pc.range_m[order], sc.range_m, atol=0.2 * cfg.range_bin_m)
    assert np.allclose(pc.radial_velocity_mps[order], sc.radial_velocity_mps,
                       atol=0.25 * cfg.velocity_bin_mps)
    assert np.allclose(pc.azimuth_deg[order], sc.azimuth_deg, atol=0.3)
    assert np.allclose(pc.rcs_dbsm[order], 10 * np.log10(sc.rcs_m2), atol=0.3)
