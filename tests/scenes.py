"""Test scenes and detection records shared by the tests and the benchmarks: random
point-target scenes (:func:`random_scene`) and synthetic on-chip detection records
(:func:`synthetic_records`). Test support, not library code: ``benchmarks`` imports it too."""

from __future__ import annotations

import math

import numpy as np

from model.axis_packetizer import pack_iq
from model.config import RadarConfig, get_preset
from model.detect_records import Record
from model.reference import signed_bins
from model.scene import PointTarget, Scene
from tests.oracles.points import tdm_comp

MAX_SCENE_RANGE_M = 150.0
"""Farthest random target, m (full reports up to 435 m, where 5..100 m^2 targets are below
the noise of either path)."""


def random_scene(preset: str, seed: int) -> Scene:
    """1..5 point targets: range uniform in [5 m, min(85 % of the largest reportable range,
    MAX_SCENE_RANGE_M)],
    azimuth +-45 deg, radial velocity within +-90 % of vmax (no aliasing), RCS
    log-uniform 5..100 m^2."""
    cfg = get_preset(preset)
    rng = np.random.default_rng([14, seed])
    targets = tuple(PointTarget(
        range_m=float(rng.uniform(5.0, min(0.85 * cfg.max_detection_range_m,
                                           MAX_SCENE_RANGE_M))),
        azimuth_deg=float(rng.uniform(-45, 45)),
        radial_velocity_mps=float(rng.uniform(-0.9, 0.9) * cfg.max_velocity_mps),
        rcs_m2=float(10 ** rng.uniform(math.log10(5), 2)))
        for _ in range(int(rng.integers(1, 6))))
    return Scene(preset=preset, seed=seed, targets=targets, name=f"random-{seed}")


def synthetic_records(cfg: RadarConfig, n: int, seed: int = 0, varied: bool = False
                      ) -> list[Record]:
    """``n`` records of isolated point targets (worst case for the host: no two in one 3x3
    neighbourhood is not guaranteed, but each is a peak of its own): a TDM-phased plane wave
    at a random angle, 40 dB over unit-variance noise per channel, the CFAR noise estimate
    of that noise, in fixed-point LSB. ``varied``: a mix closer to a real frame: SNR per
    channel uniform in 0..45 dB, velocity aliased by a random alias order (-2..1, the TDM
    test must unfold it), and every 8th record two targets at different angles."""
    rng = np.random.default_rng(seed)
    cells = rng.choice(cfg.n_range * cfg.n_doppler, n, replace=False)
    sigma = 3.0
    out = []
    v = np.arange(cfg.n_virtual)
    for k, c in enumerate(np.sort(cells)):
        r, d = divmod(int(c), cfg.n_doppler)
        s = rng.uniform(-0.9, 0.9)
        amp, fold = 100 * sigma, 0
        if varied:
            amp = sigma * 10 ** (rng.uniform(0, 45) / 20)
            fold = int(rng.integers(-2, 2))
        kk = int(signed_bins(cfg.n_doppler)[d]) + fold * cfg.n_doppler
        tdm = np.conj(tdm_comp(cfg, kk))
        x = amp * np.exp(-1j * np.pi * v * s) * tdm
        if varied and k % 8 == 7:
            x = x + 0.5 * amp * np.exp(-1j * np.pi * v * rng.uniform(-0.9, 0.9)) * tdm
        x = x + rng.normal(0, sigma / math.sqrt(2), (cfg.n_virtual, 2)) @ np.array([1, 1j])
        x = np.clip(np.round(x.real), -32768, 32767) + 1j * np.clip(np.round(x.imag), -32768,
                                                                     32767)
        out.append(Record(range_bin=r, doppler_bin=d, power=int(np.sum(np.abs(x) ** 2)),
                          noise_sum=int(round(100 * cfg.n_virtual * sigma**2)), cells=100,
                          snapshot=pack_iq(x).reshape(cfg.num_tx, cfg.num_rx), index=k))
    return out
