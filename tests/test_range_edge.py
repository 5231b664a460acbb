"""Issue 12 item 1: no phantom targets at the top range bins (negative beat frequencies).

The complex-IF range FFT is circular: a near target's window sidelobes wrap into the top
bins, and a target that has passed the radar would land there. Near targets at several
ranges on both presets give exactly one point; a target driving past the radar never shows
up far away; the simulator drops (and counts) scatterers at range <= 0.
"""

import numpy as np
import pytest

from host.cfar import CfarParams, cfar_threshold, detection_mask, local_peaks
from host.pipeline import process_frame
from model.config import NEGATIVE_BEAT_GUARD_BINS, get_preset
from model.observability import unobservable_targets
from model.scene import Scatterers, Scene
from model.simulate import simulate_frame, simulate_scene


def _scene(preset, r, v=-3.0, az=0.0, rcs=10.0):
    return Scene.from_dict({"preset": preset, "seed": 3, "targets": [
        {"range_m": r, "azimuth_deg": az, "radial_velocity_mps": v, "rcs_m2": rcs}]})


@pytest.mark.parametrize("preset", ["full", "paper-fpga"])
@pytest.mark.parametrize("r", [2.5, 5.0, 9.0, 16.0])
def test_near_target_gives_one_point(preset, r):
    scene = _scene(preset, r)
    cfg = scene.config
    cloud = process_frame(simulate_scene(scene).samples, cfg)
    assert len(cloud) == 1, (f"{len(cloud)} points: ranges {np.round(cloud.range_m, 1)}, "
                             f"bins {cloud.range_bin}")
    assert cloud.range_m[0] == pytest.approx(r, abs=0.5)


@pytest.mark.parametrize("preset", ["full", "paper-fpga"])
def test_strong_near_target_at_an_angle(preset):
    """100 m^2 at 3 m, 20 deg: sidelobes 80 dB above the noise, still one point."""
    scene = _scene(preset, 3.0, v=4.0, az=20.0, rcs=100.0)
    cloud = process_frame(simulate_scene(scene).samples, scene.config)
    assert len(cloud) == 1
    assert cloud.range_m.max() < 10


@pytest.mark.parametrize("preset, frames", [("paper-fpga", range(0, 40)),
                                            ("full", (0, 12, 20, 22, 26, 27, 30))])
def test_passing_target_never_appears_far_away(preset, frames):
    """6 m closing at 25 m/s passes the radar after ~27 frames (8.97 ms each)."""
    scene = _scene(preset, 6.0, v=-25.0)
    cfg = scene.config
    seen_after_pass = 0
    for k in frames:
        adc = simulate_scene(scene, frame_index=k)
        if adc.saturated:  # within ~0.9 m the echo clips the ADC: harmonics, reported
            continue
        cloud = process_frame(adc.samples, cfg, frame=k)
        assert np.all(cloud.range_m < 10.0), f"frame {k}: points at {cloud.range_m}"
        r_centre = 6.0 - 25.0 * k * cfg.frame_time_s
        if r_centre < -0.5:
            assert adc.passed_scatterers == 1 and adc.dropped_scatterers == 1
            seen_after_pass += len(cloud)
            reasons = [u.reason for u in unobservable_targets(scene, k)]
            assert reasons == ["passed"]
        elif r_centre > 3.0:
            assert adc.passed_scatterers == 0
            assert len(cloud) == 1
    assert seen_after_pass == 0


def test_simulator_drops_targets_behind_the_radar():
    cfg = get_preset("paper-fpga")
    sc = Scatterers(np.array([-5.0, 0.1, 20.0]), np.zeros(3), np.array([0.0, -30.0, 0.0]),
                    np.full(3, 10.0), np.full(3, -1))
    frame = simulate_frame(cfg, sc, noise=False)
    # -5 m: behind; 0.1 m closing at 30 m/s crosses zero inside the frame; 20 m: kept
    assert frame.passed_scatterers == 2 and frame.dropped_scatterers == 2
    assert frame.beyond_if_scatterers == 0
    w = np.hanning(cfg.n_range + 1)[:-1]
    spec = np.abs(np.fft.fft(frame.samples[:, 0, :] * w, axis=-1)).sum(axis=0)
    assert spec[-NEGATIVE_BEAT_GUARD_BINS:].max() < 1e-2 * spec.max()  # only the 20 m tone


@pytest.mark.parametrize("preset", ["full", "paper-fpga"])
def test_very_strong_near_target_sidelobes_are_masked(preset):
    """1.1 m: ~95 dB above the noise, Hann sidelobes above the noise 30 bins away."""
    scene = _scene(preset, 1.07, v=-25.0)
    adc = simulate_scene(scene)
    assert adc.saturated == 0
    cloud = process_frame(adc.samples, scene.config)
    assert len(cloud) == 1 and cloud.range_m[0] < 2.0


@pytest.mark.parametrize("preset", ["full", "paper-fpga"])
def test_nothing_reported_from_the_top_guard_bins(preset):
    """A strong target whose peak falls in the negative-beat guard band gives no point (the
    bins cannot tell it from a near target's wrapped sidelobes) and is named unobservable."""
    cfg = get_preset(preset)
    r = (cfg.n_range - 1.6) * cfg.range_bin_m
    scene = _scene(preset, r, v=0.0, rcs=1e5)
    cloud = process_frame(simulate_scene(scene).samples, cfg)
    assert len(cloud) == 0, cloud.range_m
    assert [u.reason for u in unobservable_targets(scene)] == ["beyond_max_range"]


def test_cfar_window_wraps_in_range():
    """A strong cell at bin 1: the cells at the top of the range axis see it in their
    training window (circular), so its sidelobe there is not detected."""
    rng = np.random.default_rng(0)
    p = rng.exponential(size=(64, 64))
    p[1, 10] = 1e6
    p[63, 10] = 1e3  # its wrapped sidelobe, 30 dB down
    thr, _ = cfar_threshold(p, 1, CfarParams(pfa=1e-3, guard=(1, 1), train=(2, 2)))
    assert not p[63, 10] > thr[63, 10]
    # peak grouping wraps too: bin 0 next to a stronger bin 63 is not a peak
    q = np.ones((16, 16))
    q[15, 3], q[0, 3] = 10.0, 5.0
    peaks = local_peaks(q, q > 2)
    assert [tuple(x) for x in peaks] == [(15, 3)]


def test_one_rule_for_reportable_bins():
    for cfg in (get_preset("full"), get_preset("paper-fpga")):
        lo, hi = cfg.detection_bins
        assert hi == cfg.n_range - NEGATIVE_BEAT_GUARD_BINS and lo >= 1
        m = detection_mask(cfg.n_range, 8, cfg.detection_bins)
        assert not m[:lo].any() and not m[hi:].any() and m[lo:hi].all()
        assert cfg.max_detection_range_m == pytest.approx(hi * cfg.range_bin_m)
