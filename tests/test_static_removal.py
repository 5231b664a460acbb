"""The static-clutter removal model (model/static_removal.py, rtl/buffers/static_removal.sv):
its reciprocal-multiply mean is the exactly rounded mean for every reachable sum, and the
fixed-point removal follows the float definition (model.reference.remove_static)."""

from __future__ import annotations

import numpy as np
import pytest

from host.pipeline import process_cube
from model.config import RadarConfig
from model.impairments import Ground, Impairments, Wall
from model.radar_pipeline import PipelineParams, dma_packets, scaled_cube
from model.reference import remove_static
from model.scene import PointTarget, Scene
from model.simulate import simulate_frame, simulate_scene
from model.static_removal import (
    divisor,
    mean,
    mean_exact,
    remove_static_planar,
    static_removal,
    weights,
)


@pytest.mark.parametrize("n_loops", [1, 2, 3, 13, 200, 255, 256, 4095, 2 << 15, 256 << 15,
                                     255 << 15])
def test_mean_is_rounded_half_away_for_every_sum(n_loops: int) -> None:
    """Divisors: plain means of n_loops samples and windowed ones (n_loops * 2^15)."""
    lo, hi = -(1 << 15) * n_loops, ((1 << 15) - 1) * n_loops
    if hi - lo < 1 << 22:
        s = np.arange(lo, hi + 1)
    else:   # both ends, around zero and random sums
        rng = np.random.default_rng(n_loops)
        s = np.concatenate([np.arange(lo, lo + (1 << 18)), np.arange(hi - (1 << 18), hi + 1),
                            np.arange(-(1 << 18), 1 << 18), rng.integers(lo, hi + 1, 1 << 20)])
    assert np.array_equal(mean(s, n_loops), mean_exact(s, n_loops))
    assert mean(s, n_loops).min() >= -(1 << 15) and mean(s, n_loops).max() < 1 << 15


@pytest.mark.parametrize("n", [2, 4, 16, 256, 4096, 15, 50, 200, 255])
def test_window_sum_is_the_rtl_divisor(n: int) -> None:
    """The quantised Hann's sum is n * 2^15 (HANN[k] + HANN[k + 2048] = 65536 exactly; the
    generated lengths that are not powers of two too), the constant the RTL divides by."""
    assert int(weights(n).sum()) == divisor(n) == n << 15


@pytest.mark.parametrize("window", [True, False])
def test_follows_the_float_definition(window: bool) -> None:
    rng = np.random.default_rng(0)
    x = rng.integers(-12000, 12000, (5, 32, 4, 2)) + rng.integers(-9000, 9000, (5, 1, 4, 2))
    out, sat = remove_static_planar(x, window=window)
    ref = remove_static((x[..., 0] + 1j * x[..., 1]).transpose(0, 2, 1),
                        window).transpose(0, 2, 1)
    assert sat == 0
    assert np.abs(out[..., 0] - ref.real).max() <= 0.5 + 1e-6 * window
    assert np.abs(out[..., 1] - ref.imag).max() <= 0.5 + 1e-6 * window


def test_windowed_zero_doppler_bin_is_left_empty() -> None:
    """A moving tone less its window-weighted mean: the Hann-windowed DC bin is zero up to the
    mean's rounding, |0.5 + 0.5j| (with the plain mean it keeps the tone's rectangular
    sidelobe)."""
    n = np.arange(64)
    tone = 8000 * np.exp(2j * np.pi * 5.3 * n / 64)
    x = np.stack([np.rint(tone.real), np.rint(tone.imag)], -1)[:, None, :]
    w = weights(64) / divisor(64)
    for window, bound in ((True, 0.5**0.5), (False, None)):
        out = remove_static_planar(x, window=window)[0][:, 0]
        dc = abs(((out[:, 0] + 1j * out[:, 1]) * w).sum())
        assert dc <= bound if bound else dc > 50


def test_zero_fill_saturation_and_bypass() -> None:
    x = np.zeros((1, 8, 1, 2), dtype=np.int64)
    x[0, :5, 0, 0] = [32767, 32767, 32767, 32767, -32767]   # mean 19660.2 -> 19660
    out, sat = remove_static_planar(x, n_loops=5, window=False)
    assert out[0, :, 0, 0].tolist() == [13107] * 4 + [-32768, 0, 0, 0]
    assert sat == 1                                          # -32767 - 19660 saturates
    words = np.arange(16, dtype=np.uint32).reshape(8, 2) * 0x10001
    assert np.array_equal(static_removal(words, 8, enable=False)[0], words)
    removed, _ = static_removal(words, 8)
    assert not np.array_equal(removed, words)


def indoor_scene() -> Scene:
    """paper-fpga in a room: three walls, the floor, eight pieces of furniture (static point
    returns), TX-RX leakage, and three people walking (the movers, m/s radial)."""
    imp = Impairments(
        seed=3, leakage_dbfs=-20.0, leakage_range_m=0.3,
        walls=(Wall(6.0, -6.0, 6.0, 6.0, rcs_m2=50.0, n_scatterers=64),
               Wall(2.0, 3.0, 14.0, 3.5, rcs_m2=30.0, n_scatterers=64),
               Wall(1.0, -4.0, 20.0, -4.5, rcs_m2=30.0, n_scatterers=64)),
        ground=Ground(height_m=1.0, rcs_m2=20.0, min_range_m=1.5, max_range_m=25.0,
                      n_scatterers=128))
    furniture = tuple(PointTarget(r, az, 0.0, 5.0) for r, az in (
        (4.0, -30), (7.5, 25), (11.0, -10), (16.0, 35), (21.0, 0), (27.0, -40), (33.0, 15),
        (40.0, -5)))
    return Scene(preset="paper-fpga", targets=furniture + MOVERS, impairments=imp, seed=5)


MOVERS = (PointTarget(3.5, 10.0, 1.2, 1.0), PointTarget(9.0, -20.0, -2.5, 1.0),
          PointTarget(15.0, 5.0, 4.0, 2.0))


def test_indoor_scene_loses_its_zero_doppler_detections() -> None:
    """The issue-31 goal on the bit-exact chain (the RTL's DMA bytes equal it:
    tb/radar_pipeline/test_radar_pipeline_static.py): with the removal on, at least 90 % of
    the zero-Doppler detections go and every mover is still detected in every frame."""
    scene = indoor_scene()
    cfg = scene.config
    v_bin = 2 * cfg.max_velocity_mps / cfg.n_doppler
    r_bin = cfg.max_range_m / cfg.n_range
    zero, movers = {}, {}
    for on in (False, True):
        zero[on], movers[on] = 0, 0
        for k in range(3):
            pc = process_cube(scaled_cube(simulate_scene(scene, k).samples, cfg,
                                          PipelineParams(static_removal=on)), cfg)
            v, r = np.asarray(pc.radial_velocity_mps), np.asarray(pc.range_m)
            zero[on] += int((np.abs(v) < v_bin / 2).sum())
            movers[on] += sum(bool(((np.abs(v - m.radial_velocity_mps) < 2 * v_bin)
                                    & (np.abs(r - m.range_m) < 2 * r_bin)).any())
                              for m in MOVERS)
    print(f"zero-Doppler detections {zero[False]} -> {zero[True]}, movers found "
          f"{movers[False]} -> {movers[True]} of {3 * len(MOVERS)}")
    assert zero[False] >= 5 and zero[True] <= 0.1 * zero[False]
    assert movers[True] == 3 * len(MOVERS)


@pytest.mark.parametrize("backend", ["float", "model"])
def test_radar_detect_remove_static(tmp_path, backend: str) -> None:
    """`radar detect --remove-static`: the static reflector goes, the mover stays, through the
    float reference and through the bit-accurate chain with STATIC_REMOVAL = 1."""
    import json

    from radar.cli import main

    scene = tmp_path / "scene.json"
    scene.write_text(json.dumps({"preset": "paper-fpga", "seed": 3, "targets": [
        {"range_m": 30.0, "azimuth_deg": 0.0, "radial_velocity_mps": 0.0, "rcs_m2": 10.0},
        {"range_m": 60.0, "azimuth_deg": 0.0, "radial_velocity_mps": 4.0, "rcs_m2": 10.0}]}))
    found = {}
    for remove in (False, True):
        out = tmp_path / f"{remove}.json"
        argv = ["detect", "--scene", str(scene), "--backend", backend, "--json", str(out)]
        assert main(argv + (["--remove-static"] if remove else [])) == 0
        doc = json.loads(out.read_text())
        assert doc["remove_static"] is remove
        found[remove] = [(round(p["range_m"]), abs(p["radial_velocity_mps"]) > 1.0)
                         for p in doc["points"]]
    assert any(r == 30 and not moving for r, moving in found[False])
    assert not any(r in (29, 30, 31) for r, _ in found[True])
    assert any(r in (59, 60, 61) and moving for r, moving in found[True])


def test_dma_frames_removal_per_frame() -> None:
    """``dma_frames(removal=...)``: each frame as a run with its own switch (the register
    SETTINGS.clutter_removal, tb/radar_pipeline/test_radar_pipeline_regs.py); on needs
    STATIC_REMOVAL."""
    cfg = RadarConfig(name="small4", num_tx=4, num_rx=4, n_range=32, n_doppler=32,
                      sample_rate_hz=10e6, chirp_period_s=4e-6, design_max_range_m=50.0)
    sc = Scene(preset="full", targets=(PointTarget(12.0, -20.0, 0.0, 5.0),)).scatterers()
    frames = [simulate_frame(cfg, sc, rng=np.random.default_rng(k), frame_index=k).samples
              for k in range(2)]
    chain = PipelineParams(packet_words=256, static_removal=True)
    mixed = dma_packets(frames, cfg, chain, removal=[False, True])
    half = len(mixed) // 2
    off = dma_packets(frames[:1], cfg, chain, removal=[False])
    on = dma_packets(frames[1:], cfg, chain, first_frame_id=1)
    assert all(np.array_equal(a, b) for a, b in zip(mixed, off + on, strict=True))
    assert not all(np.array_equal(a, b) for a, b in zip(
        mixed[half:], dma_packets(frames[1:], cfg, chain, 1, [False]), strict=True))
    with pytest.raises(ValueError, match="removal"):
        dma_packets(frames, cfg, PipelineParams(packet_words=256), removal=[True, False])
    with pytest.raises(ValueError, match="removal"):
        dma_packets(frames, cfg, chain, removal=[True])
