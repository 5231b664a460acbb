"""Angles of non-uniform and 2-D virtual arrays (``host._angle_array``: Bartlett over
``model.array.steering`` vectors, RELAX over it), the TX firing order in the TDM phase
compensation (``model.array.tx_slots``), and the point cloud's z / elevation. Snapshots and
cubes synthesised here from ``model.array`` (TX-index channel rows, each TX delayed by its
slot)."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from host.angle import AngleParams, estimate_angles, peak_powers, range_azimuth_power
from host.params import DetectionParams
from host.pipeline import process_cube
from host.pointcloud import PointCloud
from host.ros.messages import cloud_points
from host.tdm import tx_phasors
from model.array import direction_cosines, has_vertical_extent, steering, tx_slots
from model.config import RadarConfig
from model.profile import load_profile
from model.reference import doppler_fft, tdm_phase_compensation

OPENRADAR = load_profile(Path(__file__).parent / "data" / "openradar" / "openradar_2tx4rx.cfg")
XWR1843_TX = ((0.0, 0.0), (2.0, 1.0), (4.0, 0.0))
"""TI xWR1843BOOST: TX1 half a wavelength above TX0 and TX2."""


def xwr1843(tx_order: tuple[int, ...] | None = None) -> RadarConfig:
    """The OpenRadar profile with the xWR1843's 3 TX x 4 RX array (12 virtual channels)."""
    return replace(OPENRADAR.config, num_tx=3, tx_positions=XWR1843_TX, tx_order=tx_order)


def noisy(rng: np.random.Generator, x: np.ndarray, noise: float) -> np.ndarray:
    return x + np.sqrt(noise / 2) * (rng.standard_normal(x.shape)
                                     + 1j * rng.standard_normal(x.shape))


@pytest.mark.parametrize("tx, vertical", [(((0.0, 0.0), (6.0, 0.0)), False),
                                          (XWR1843_TX, True)])
def test_single_target_azimuth_and_elevation(tx: tuple, vertical: bool) -> None:
    """One target per row (40 dB coherent SNR) on a non-uniform planar array (a gap of two
    elements) and on the xWR1843's 2-D array: one component each, azimuth within 0.5 deg,
    elevation (2-D array) within 3 deg, 0 on the planar one."""
    cfg = replace(OPENRADAR.config, num_tx=len(tx), tx_positions=tx)
    assert not cfg.uniform_linear_array and has_vertical_extent(cfg.virtual_positions_hw) \
        == vertical
    rng = np.random.default_rng(5)
    m, n = 300, cfg.n_virtual
    az = np.radians(rng.uniform(-50, 50, m))
    el = np.radians(rng.uniform(-30, 30, m)) if vertical else np.zeros(m)
    noise = n * 1e-4
    x = noisy(rng, steering(cfg.virtual_positions_hw, *direction_cosines(az, el)), noise)
    got = estimate_angles(x, np.full(m, noise), AngleParams(),
                          positions=cfg.virtual_positions_hw)
    assert np.array_equal(got.cell, np.arange(m))
    assert np.abs(got.azimuth_deg - np.degrees(az)).max() < 0.5
    assert np.abs(got.elevation_deg - np.degrees(el)).max() < (3.0 if vertical else 1e-12)


def test_general_path_on_the_ula_is_the_fast_path() -> None:
    """The steering-vector path given the contiguous ULA's positions finds the components
    the angle FFT's fast path finds (one or two targets per row), and the same peaks."""
    rng = np.random.default_rng(8)
    m, n = 200, 8
    pos = np.stack([np.arange(n, dtype=float), np.zeros(n)], axis=1)
    u1 = rng.uniform(-0.6, 0.45, m)
    two = rng.random(m) < 0.5
    x = steering(pos, u1) + np.where(two, 0.8, 0.0)[:, None] * steering(pos, u1 + 0.45)
    x = noisy(rng, x, 1e-3)
    fast = estimate_angles(x, np.full(m, 1e-3), AngleParams())
    general = estimate_angles(x, np.full(m, 1e-3), AngleParams(), positions=pos)
    assert np.array_equal(fast.cell, general.cell)
    assert np.abs(fast.sin_az - general.sin_az).max() < 2e-3
    np.testing.assert_allclose(np.abs(general.amplitude), np.abs(fast.amplitude), rtol=1e-2)
    assert not general.elevation_deg.any()
    p_fast, s_fast = peak_powers(x, 1024)
    p_gen, u_gen = peak_powers(x, 1024, positions=pos)
    np.testing.assert_allclose(p_gen, p_fast, rtol=1e-3)
    assert np.abs(u_gen - s_fast).max() < 2e-3


def test_two_targets_on_the_2d_array() -> None:
    """Two targets of equal power at one elevation, 30 deg apart in azimuth (more than a
    beamwidth of the 8-element horizontal aperture): two points in >= 95 % of the rows."""
    cfg = xwr1843()
    rng = np.random.default_rng(11)
    m = 200
    az = np.radians(rng.uniform(-30, 0, m))
    el = np.radians(rng.uniform(-10, 10, m))
    pos = cfg.virtual_positions_hw
    x = steering(pos, *direction_cosines(az, el)) + np.exp(2j * np.pi * rng.random((m, 1))) \
        * steering(pos, *direction_cosines(az + np.radians(30), el))
    x = noisy(rng, x, 1e-2)
    got = estimate_angles(x, np.full(m, 1e-2), AngleParams(), positions=pos)
    assert np.mean(np.bincount(got.cell, minlength=m) == 2) >= 0.95


def test_tdm_compensation_uses_the_slot() -> None:
    """TX t's channels are compensated for its slot tx_slots[t], not for t: the phasors of
    ``model.reference`` and ``host.tdm`` agree and undo a permuted order's slot delays."""
    cfg = xwr1843((2, 0, 1))
    assert tx_slots(cfg).tolist() == [1, 2, 0]
    k = np.array([-7, 0, 5, 20])
    ref = tdm_phase_compensation(cfg, k % cfg.n_doppler)
    np.testing.assert_allclose(ref, np.repeat(tx_phasors(cfg, k), cfg.num_rx, axis=1),
                               atol=1e-12)
    delay = np.exp(2j * np.pi * np.multiply.outer(k, tx_slots(cfg))
                   / (cfg.n_doppler * cfg.num_tx))
    np.testing.assert_allclose(np.repeat(delay, cfg.num_rx, axis=1) * ref, 1.0, atol=1e-12)


def synth_cube(cfg: RadarConfig, targets: list[tuple[int, float, float, float]],
               rng: np.random.Generator, amplitude: float = 300.0) -> np.ndarray:
    """A radar cube (n_virtual, n_range, n_doppler), rows by TX index, of point targets
    (range bin, signed Doppler bin, azimuth deg, elevation deg) on range-bin centres: TX
    t's chirp of loop l fired at slot tx_slots[t] (l num_tx + slot chirp periods), the
    Hann-windowed range FFT's 0.5, -0.25 on the bin and its neighbours, the Doppler FFT of
    ``model.reference``; plus unit complex noise per cell."""
    nd, ntx, nrx = cfg.n_doppler, cfg.num_tx, cfg.num_rx
    slot = np.repeat(tx_slots(cfg), nrx)                                       # (n_v,)
    turned = np.zeros((cfg.n_virtual, cfg.n_range, nd), complex)
    loops = np.arange(nd)
    for rb, k, az, el in targets:
        a = steering(cfg.virtual_positions_hw, *direction_cosines(np.radians(az),
                                                                  np.radians(el)))
        slow = np.exp(2j * np.pi * k * (loops[None, :] * ntx + slot[:, None]) / (nd * ntx))
        for dr, w in ((-1, -0.25), (0, 0.5), (1, -0.25)):
            turned[:, rb + dr] += amplitude * w * a[:, None] * slow
    cube = doppler_fft(turned, cfg)
    return noisy(rng, cube, 1.0 / nd)


SCENE = [(40, 9.0, -20.0, 15.0), (70, -14.0, 25.0, -10.0), (90, 3.0, 5.0, 0.0)]


@pytest.mark.parametrize("order", [(2, 0, 1), (1, 2, 0)])
def test_permuted_firing_order_gives_the_same_points(order: tuple[int, ...]) -> None:
    """The same physical scene fired in the identity order and in a permuted one: the
    same strongest point per target (azimuth, elevation within 1 deg, velocity within a
    tenth of a bin); processed as if fired in order, the permuted cube's angles are off."""
    params = DetectionParams(max_speed_mps=OPENRADAR.config.max_speed_mps)
    clouds = {}
    for o in ((0, 1, 2), order):
        cfg = xwr1843(o)
        assert not cfg.unsupported_features()
        clouds[o] = process_cube(synth_cube(cfg, SCENE, np.random.default_rng(1)), cfg,
                                 params)
    for rb, k, az, el in SCENE:
        for o, cloud in clouds.items():
            at = np.flatnonzero(cloud.range_bin == rb)
            best = at[np.argmax(cloud.snr_db[at])]
            assert abs(cloud.azimuth_deg[best] - az) < 1.0, (o, rb)
            assert abs(cloud.elevation_deg[best] - el) < 1.0, (o, rb)
            v = k * xwr1843().velocity_bin_mps
            assert abs(cloud.radial_velocity_mps[best] - v) < 0.1 * xwr1843().velocity_bin_mps
            assert cloud.z_m[best] == pytest.approx(
                cloud.range_m[best] * np.sin(np.radians(cloud.elevation_deg[best])))
    wrong = process_cube(synth_cube(xwr1843(order), SCENE, np.random.default_rng(1)),
                         xwr1843(), params)
    at = np.flatnonzero(wrong.range_bin == 70)
    best = at[np.argmax(wrong.snr_db[at])]
    assert abs(wrong.azimuth_deg[best] - 25.0) + abs(wrong.elevation_deg[best] + 10.0) > 2.0


def test_elevation_in_json_ros_and_figures() -> None:
    """z_m and elevation_deg in the JSON only for an array with vertical extent,
    read back; the ROS point's z and elevation; the range-azimuth map of a 2-D array."""
    cfg = xwr1843()
    cloud = process_cube(synth_cube(cfg, SCENE, np.random.default_rng(2)), cfg,
                         DetectionParams(max_speed_mps=cfg.max_speed_mps))
    planar = cloud.to_json_dict("x", 1)["points"]
    assert "z_m" not in planar[0] and "elevation_deg" not in planar[0]
    doc = json.loads(json.dumps(cloud.to_json_dict(cfg, 1)))
    assert {"z_m", "elevation_deg"} <= set(doc["points"][0])
    back = PointCloud.from_json_dict(doc)
    np.testing.assert_allclose(back.elevation_deg, cloud.elevation_deg, atol=1e-4)
    np.testing.assert_allclose(back.z_m, cloud.z_m, atol=1e-3)
    assert np.abs(cloud.elevation_deg).max() > 5
    pts = cloud_points(cloud)
    np.testing.assert_allclose(pts["z"], cloud.z_m, rtol=1e-6, atol=1e-6)
    np.testing.assert_allclose(pts["elevation"], np.radians(cloud.elevation_deg), atol=1e-6)
    with pytest.raises(ValueError, match="elevation_deg"):
        PointCloud.from_json_dict({"points": [dict(doc["points"][0], elevation_deg=91.0)]})
    power, az = range_azimuth_power(synth_cube(cfg, SCENE, np.random.default_rng(3)), cfg)
    assert power.shape == (cfg.n_range, 256)
    assert abs(az[np.argmax(power[90])] - 5.0) < 2.0


@pytest.mark.parametrize("order", [(0, 1, 2), (2, 0, 1)])
def test_velocity_unfolding_on_the_2d_array(order: tuple[int, ...]) -> None:
    """A target beyond the unambiguous speed (Doppler bin 84 of 128: measured at -44): the
    TDM test over the 2-D array's Bartlett peaks unfolds it, in either firing order."""
    cfg = xwr1843(order)
    cube = synth_cube(cfg, [(60, 84.0, 12.0, -8.0)], np.random.default_rng(4))
    cloud = process_cube(cube, cfg, DetectionParams(max_speed_mps=3 * cfg.max_velocity_mps))
    best = np.argmax(cloud.snr_db)
    assert cloud.doppler_bin[best] == 84 and cloud.ambiguous[best]
    assert abs(cloud.azimuth_deg[best] - 12.0) < 1.0
    assert abs(cloud.elevation_deg[best] + 8.0) < 1.0
