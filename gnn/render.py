"""Scene -> radar point cloud: the one place where the dataset meets the radar.

``render_points`` runs ``model.simulate`` and the host detection chain
(``host.pipeline.process_frame``, ``full`` preset), so the network sees exactly what our radar
produces (the shipped dataset and checkpoint use it). :func:`stand_in_points`
(``backend="stand-in"``) maps scatterers to points through the model's radar equation and
resolution cells instead, about 500x faster: the unit tests use it.
"""

from __future__ import annotations

import numpy as np

from host.pointcloud import PointCloud
from model.config import RadarConfig
from model.reference import signed_bin
from model.scene import Scatterers, Scene
from model.simulate import simulate_scene, snr_per_sample_db

BACKENDS = ("auto", "pipeline", "stand-in")

STAND_IN_THRESHOLD_DB = 15.0
"""Stand-in detection threshold on the integrated SNR of a resolution cell, dB."""
STAND_IN_WINDOW_LOSS_DB = 3.5
"""Stand-in processing loss of the two Hann windows (range and Doppler), dB."""


def resolve_backend(backend: str) -> str:
    """``auto`` -> ``pipeline`` (the host chain); the others as given."""
    if backend not in BACKENDS:
        raise ValueError(f"backend: unknown backend {backend!r}; choose one of "
                         f"{', '.join(BACKENDS)}")
    if backend == "auto":
        return "pipeline"
    return backend


def render_points(scene: Scene, backend: str = "auto", frame_index: int = 0) -> PointCloud:
    """Point cloud of ``scene`` as our radar sees it (see the module docstring)."""
    if resolve_backend(backend) == "pipeline":
        from host.pipeline import process_frame

        adc = simulate_scene(scene, frame_index).samples
        return process_frame(adc, scene.config)
    return stand_in_points(scene.config, scene.scatterers(), scene.tx_beamforming,
                           np.random.default_rng([scene.seed, frame_index, 99]))


def stand_in_points(cfg: RadarConfig, sc: Scatterers, beamforming: bool,
                    rng: np.random.Generator) -> PointCloud:
    """Stand-in for simulate + host chain: one point per occupied resolution cell.

    Scatterers are binned into (range bin, signed Doppler bin, angle cell of width
    2/n_virtual in sin(az)) cells; their complex amplitudes add with random phase. A cell is
    detected when its integrated SNR (per-sample SNR from the radar equation + coherent gain
    of n_range * n_doppler * n_virtual samples - window loss) exceeds
    :data:`STAND_IN_THRESHOLD_DB`. The point sits at the cell's range (plus interpolation
    error), the power-weighted sine of azimuth (plus 0.3 deg noise) and the cell's velocity.
    A few false alarms are added.
    """
    gain_db = 10 * np.log10(cfg.n_range * cfg.n_doppler * cfg.n_virtual) - \
        STAND_IN_WINDOW_LOSS_DB
    snr_lin = 10 ** ((snr_per_sample_db(cfg, sc, beamforming) + gain_db) / 10)
    rbin = np.rint([cfg.range_bin_of(r, v) for r, v in
                    zip(sc.range_m, sc.radial_velocity_mps, strict=True)]).astype(int)
    half = cfg.n_doppler // 2
    dbin = signed_bin(np.rint(sc.radial_velocity_mps / cfg.velocity_bin_mps).astype(int)
                      % cfg.n_doppler, cfg.n_doppler)
    sin_az = np.sin(np.radians(sc.azimuth_deg))
    abin = np.rint(sin_az * cfg.n_virtual / 2).astype(int)
    ok = (rbin >= 0) & (rbin < cfg.n_range)
    keys = np.stack([rbin, dbin, abin], axis=1)[ok]
    amp = np.sqrt(snr_lin[ok]) * np.exp(2j * np.pi * rng.random(ok.sum()))
    cells, inv = np.unique(keys, axis=0, return_inverse=True)
    inv = inv.reshape(-1)
    snr_cell = np.abs(np.bincount(inv, amp.real, len(cells))
                      + 1j * np.bincount(inv, amp.imag, len(cells))) ** 2
    w = np.abs(amp) ** 2
    s_cell = np.bincount(inv, w * sin_az[ok], len(cells)) / np.bincount(inv, w, len(cells))
    rcs_cell = np.bincount(inv, sc.rcs_m2[ok], len(cells))
    det = 10 * np.log10(np.maximum(snr_cell, 1e-12)) > STAND_IN_THRESHOLD_DB
    cells, snr_db = cells[det], 10 * np.log10(snr_cell[det])
    s, rcs = s_cell[det], rcs_cell[det]
    n_fa = int(rng.poisson(3.0))                                     # false alarms
    cells = np.concatenate([cells, np.stack([
        rng.integers(2, cfg.n_range // 4, n_fa), rng.integers(-half, half, n_fa),
        rng.integers(-cfg.n_virtual // 3, cfg.n_virtual // 3, n_fa)], axis=1)])
    snr_db = np.concatenate([snr_db, rng.uniform(STAND_IN_THRESHOLD_DB,
                                                 STAND_IN_THRESHOLD_DB + 3, n_fa)])
    s = np.concatenate([s, cells[len(s):, 2] * 2 / cfg.n_virtual])
    rcs = np.concatenate([rcs, rng.uniform(0.05, 0.5, n_fa)])
    n = len(cells)
    rng_m = (cells[:, 0] + rng.uniform(-0.3, 0.3, n)) * cfg.range_bin_m
    az = np.degrees(np.arcsin(np.clip(s, -0.99, 0.99))) + rng.normal(0, 0.3, n)
    vr = cells[:, 1] * cfg.velocity_bin_mps
    return PointCloud.from_polar(
        range_m=rng_m, azimuth_deg=az, radial_velocity_mps=vr, power_db=snr_db + 36.0,
        snr_db=snr_db, rcs_dbsm=10 * np.log10(rcs) + rng.normal(0, 2.0, n),
        range_bin=cells[:, 0], doppler_bin=cells[:, 1] % cfg.n_doppler,
        ambiguous=np.abs(cells[:, 1]) >= half - 1)
