"""The angle estimator end to end on simulated frames (``model.simulate`` with profiles and
``model.impairments``): elevation from the xWR1843's 2-D array, and one point per target
from an uncalibrated array (the model-order test)."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from host.angle import AngleParams
from host.params import DetectionParams
from host.pipeline import process_frame
from model.impairments import Impairments
from model.profile import load_profile
from model.scene import Scatterers
from model.simulate import simulate_frame

OPENRADAR = load_profile(Path(__file__).parent / "data" / "openradar" / "openradar_2tx4rx.cfg")


def scatterers(*rows: tuple[float, float, float, float, float]) -> Scatterers:
    """Scatterers from (range_m, azimuth_deg, radial_velocity_mps, rcs_m2, elevation_deg)."""
    a = np.array(rows, dtype=float).reshape(-1, 5)
    return Scatterers(a[:, 0], a[:, 1], a[:, 2], a[:, 3], np.full(len(a), -1), a[:, 4])


TARGETS = ((2.0, -25.0, 1.5, 1.0, 12.0), (3.5, 10.0, -2.0, 1.0, -15.0),
           (4.5, 30.0, 3.0, 1.0, 0.0))


def strongest_near(cloud, range_m: float, velocity_mps: float) -> int:  # noqa: ANN001
    """Index of the strongest point within 0.15 m and 0.3 m/s of a target."""
    near = np.flatnonzero((np.abs(cloud.range_m - range_m) < 0.15)
                          & (np.abs(cloud.radial_velocity_mps - velocity_mps) < 0.3))
    assert len(near), (range_m, velocity_mps)
    return int(near[np.argmax(cloud.snr_db[near])])


@pytest.mark.parametrize("order", [None, (2, 0, 1), (1, 2, 0)])
def test_simulated_2d_array_measures_elevation(order: tuple[int, ...] | None) -> None:
    """A simulated frame of the xWR1843's 3 TX x 4 RX array (TX1 half a wavelength up),
    fired in order or permuted (the corner turn sorts the chirps by TX, the TDM
    compensation uses each TX's slot): each target's strongest point within 1.5 deg in
    azimuth and 3 deg in elevation, z from the elevation."""
    cfg = replace(OPENRADAR.config, num_tx=3, tx_positions=((0, 0), (2, 1), (4, 0)),
                  tx_order=order)
    frame = simulate_frame(cfg, scatterers(*TARGETS), rng=np.random.default_rng(1))
    cloud = process_frame(frame.samples, cfg, DetectionParams(max_speed_mps=cfg.max_speed_mps))
    for r, az, v, _, el in TARGETS:
        i = strongest_near(cloud, r, v)
        assert abs(cloud.azimuth_deg[i] - az) < 1.5, (r, cloud.azimuth_deg[i])
        assert abs(cloud.elevation_deg[i] - el) < 3.0, (r, cloud.elevation_deg[i])
        assert abs(cloud.z_m[i] - cloud.range_m[i] * np.sin(np.radians(
            cloud.elevation_deg[i]))) < 1e-9


def test_uncalibrated_simulated_array_one_point_per_target() -> None:
    """The OpenRadar profile with per-channel gain (1.5 dB rms per TX and RX) and phase
    (8 deg rms) errors, eight seeds (arrays): every target cell gives one point with the
    model-order test; without it (array_error_db -inf) cells spray extra points."""
    cfg = OPENRADAR.config
    params = DetectionParams(max_speed_mps=cfg.max_speed_mps)
    counts, sprayed = [], []
    for seed in range(8):
        imp = Impairments(seed=seed, tx_gain_rms_db=1.5, rx_gain_rms_db=1.5,
                          tx_phase_rms_deg=8.0, rx_phase_rms_deg=8.0)
        frame = simulate_frame(cfg, scatterers(*TARGETS), rng=np.random.default_rng(seed),
                               impairments=imp)
        for floor, out in ((AngleParams().array_error_db, counts), (-np.inf, sprayed)):
            cloud = process_frame(frame.samples, cfg,
                                  replace(params, angle=AngleParams(array_error_db=floor)))
            for r, _, v, _, _ in TARGETS:
                i = strongest_near(cloud, r, v)
                same = (cloud.range_bin == cloud.range_bin[i]) & (
                    cloud.doppler_bin == cloud.doppler_bin[i])
                out.append(int(same.sum()))
    assert np.mean(np.array(counts) == 1) >= 0.95, counts
    assert np.mean(np.array(sprayed) == 1) < 0.5, sprayed
