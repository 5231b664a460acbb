"""Elevation through `radar detect` (docs/profiles.md, "Angles: the ULA, non-uniform and 2-D
arrays"; the point JSON of docs/design.md 4.4): a 3-TX profile with the middle TX half a
wavelength up (xWR1843) gives every point `elevation_deg` and `z_m` in the JSON, within the
accuracy its one-half-wavelength elevation aperture allows at the point's SNR; a planar
profile's points carry neither field."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from model.config import RadarConfig
from model.detection_theory import cell_snr_gain
from model.profile import load_profile
from model.reference import fft_axes
from model.scene import Scene, load_scene
from model.simulate import snr_per_sample_db
from radar.cli import main
from tests.test_cli_radar_option import SMALL, THREE_TX

TARGETS = [(8.0, 10.0, 1.0, 20.0), (12.0, -15.0, -2.0, -10.0), (16.0, 25.0, 3.0, 0.0),
           (19.0, 0.0, -4.0, 35.0)]
"""(range m, azimuth deg, radial velocity m/s, elevation deg): distinct range and Doppler
cells, elevations above, below and at the horizon."""


def elevation_sigma_deg(cfg: RadarConfig, scene: Scene) -> np.ndarray:
    """The Cramer-Rao bound on each target's elevation, deg, float (n,): the vertical
    direction cosine w = sin(el) enters channel v's phase as pi w h_v (h_v its height in
    half-wavelengths), so var(w) = 1 / (2 pi^2 SNR_ch sum_v (h_v - mean h)^2), SNR_ch the
    per-channel SNR of the target's cell (the simulator's per-sample SNR times both windowed
    FFTs' gain for a tone half a bin off, the worst case). The raised row's horizontal
    centroid is the lower row's, so azimuth does not couple into elevation."""
    h = cfg.virtual_positions_hw[:, 1]
    sc = scene.scatterers()
    gain = np.prod([cell_snr_gain(ax.window(), ax.n_fft, np.array([0.5]))[0]
                    for ax in fft_axes(cfg)])
    snr_ch = 10 ** (snr_per_sample_db(cfg, sc, scene.tx_beamforming) / 10) * gain
    sigma_w = 1.0 / np.sqrt(2 * np.pi**2 * snr_ch * np.sum((h - h.mean()) ** 2))
    return np.degrees(sigma_w / np.cos(np.radians(sc.elevation_deg)))


def _detect(tmp_path: Path, profile: str, backend: str) -> tuple[dict, Scene]:
    """`radar detect` of the TARGETS scene on ``profile``: the JSON and the scene."""
    (tmp_path / "p.toml").write_text(profile)
    (tmp_path / "scene.json").write_text(json.dumps({"preset": "full", "seed": 3, "targets": [
        {"range_m": r, "azimuth_deg": az, "radial_velocity_mps": v, "rcs_m2": 10.0,
         "elevation_deg": el} for r, az, v, el in TARGETS]}))
    out = tmp_path / "p.json"
    assert main(["detect", "--scene", str(tmp_path / "scene.json"), "--radar",
                 str(tmp_path / "p.toml"), "--backend", backend, "--json", str(out)]) == 0
    scene = replace(load_scene(tmp_path / "scene.json"),
                    radar=load_profile(str(tmp_path / "p.toml")).config)
    return json.loads(out.read_text()), scene


@pytest.mark.parametrize("backend", ["float", "model"])
def test_raised_tx_points_carry_elevation(tmp_path, backend):
    doc, scene = _detect(tmp_path, THREE_TX, backend)
    cfg = scene.config
    assert np.ptp(cfg.virtual_positions_hw[:, 1]) == 1.0    # elevation aperture: lambda/2
    tols = 4 * elevation_sigma_deg(cfg, scene)
    assert tols.max() < 2.0, tols             # 2 deg is a test: the targets are strong enough
    assert len(doc["points"]) == len(TARGETS)
    for p in doc["points"]:
        assert {"elevation_deg", "z_m"} <= set(p)
        i = int(np.argmin([abs(t[0] - p["range_m"]) for t in TARGETS]))
        r, _, _, el = TARGETS[i]
        assert p["range_m"] == pytest.approx(r, abs=cfg.range_bin_m / 2)
        assert p["elevation_deg"] == pytest.approx(el, abs=tols[i]), (p, tols[i])
        e = np.radians(p["elevation_deg"])
        # z = R sin(el), x = R cos(el) cos(az) of the written fields; the truth's z within
        # the range and elevation tolerances
        assert p["z_m"] == pytest.approx(p["range_m"] * np.sin(e), abs=2e-3)
        assert p["x_m"] == pytest.approx(p["range_m"] * np.cos(e) * np.cos(np.radians(
            p["azimuth_deg"])), abs=2e-3)
        assert p["z_m"] == pytest.approx(r * np.sin(np.radians(el)), abs=(
            cfg.range_bin_m / 2 + r * np.radians(tols[i])))


def test_planar_points_carry_no_elevation(tmp_path):
    doc, _ = _detect(tmp_path, SMALL, "float")
    assert doc["points"]
    assert not {"elevation_deg", "z_m"} & {k for p in doc["points"] for k in p}
