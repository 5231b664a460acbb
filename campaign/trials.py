"""Trial functions of the campaigns (``campaign.runner``): each takes (params, trial
indices, campaign seed, group) and returns counts and sums that add up across tasks.
Trial ``i`` draws from ``numpy.random.default_rng([seed, group, i])``.

- ``detection``: one synthetic range-Doppler map per trial (``campaign.maps``), every
  detector of :data:`DETECTORS` at every Pfa of ``params["pfas"]``; counts of detections at
  the target cells (Pd) or, for a noise-only map (``cell_snr_db`` None), over all cells
  (Pfa).
- ``estimation``: one target per trial in the float chain's cells around it (and those cells
  rounded to the FPGA's integer LSB); squared errors of range, radial velocity and azimuth
  from the host's estimators.
- ``estimation_frames``: whole frames of 64 targets (``campaign.frames``) through the float
  chain with the refinement (``host.refine``) and the bit-accurate chain
  (``model.radar_pipeline``) with and without it: squared errors as for ``estimation``.
- ``resolution``: two equal targets in one cell, ``sep_bw`` beamwidths apart; how often the
  host's angle estimator resolves them.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from functools import lru_cache
from typing import Any

import numpy as np
from scipy import stats

from campaign import frames, maps
from host.angle import AngleParams, estimate_angles
from host.cells import neighbour_offsets
from host.cfar import CfarParams, cfar_threshold
from host.refine import FIXED_POINT_FLOOR, FLOAT_FLOOR, refine_offsets
from model import cfar_2d
from model.config import PRESETS, RadarConfig
from model.detect_chain import DetectConfig
from model.radar_pipeline import PipelineParams, chain_gain, scaled_cube
from model.reference import FftAxis, fft_axes, radar_cube

DETECTORS = (("host", "ca"), ("host", "os"), ("fpga", "ca"), ("fpga", "go"), ("fpga", "so"))
"""(path, kind) of every detector the detection curves run: the host CFAR
(``host.cfar``: CA and OS) and the FPGA detector's bit-accurate model (``model.cfar_2d``:
CA, GO, SO)."""
GUARD, TRAIN = (2, 2), (4, 8)
"""The CFAR window of the curves: the host's and the FPGA's default, cells per side."""
PRESET = "full"
"""The radar whose FFT sizes, channel count and FPGA noise level the curves use."""

TrialFn = Callable[[dict[str, Any], range, int, int], dict[str, Any]]


def rng_of(seed: int, group: int, trial: int) -> np.random.Generator:
    """The random generator of one trial."""
    return np.random.default_rng([seed, group, trial])


def fpga_noise_lsb(cfg: RadarConfig) -> float:
    """RMS noise per channel of a Hann-windowed cell at the FPGA detector's input, LSB:
    the ADC noise through both 1/N-scaled windowed FFTs (3/8 of the power per axis, over
    N) and the fixed-point chain's gain (``model.radar_pipeline.chain_gain``)."""
    power = (cfg.noise_power_lsb2 * maps.HANN_NOISE_GAIN ** 2 / (cfg.n_range * cfg.n_doppler)
             * chain_gain(cfg, PipelineParams()) ** 2)
    return float(np.sqrt(power))


@lru_cache(maxsize=64)
def fpga_cfar(shape: tuple[int, int], kind: str, pfa: float, n_channels: int
          ) -> tuple[cfar_2d.Cfar2dConfig, np.ndarray]:
    """The FPGA CFAR configuration and scale table for a map of ``shape``."""
    num_tx = 4 if n_channels % 4 == 0 else 1
    d = DetectConfig(num_tx=num_tx, num_rx=n_channels // num_tx, n_range=shape[0],
                     n_doppler=shape[1], guard=GUARD, train=TRAIN, kind=kind, pfa=pfa)
    return d.cfar, d.scale()


def detect_all(cube: np.ndarray, pfas: list[float], fpga_lsb: float
               ) -> list[tuple[np.ndarray, np.ndarray]]:
    """(detections bool, threshold float) maps (n_range, n_doppler) of every (detector, Pfa),
    detector-major (:data:`DETECTORS`, then ``pfas``), for a cube complex (L, n_range,
    n_doppler) with unit noise per channel and cell. The FPGA model gets the cube in LSB
    (noise ``fpga_lsb`` RMS per channel), I and Q rounded to integers, integrated exactly;
    its threshold (in LSB^2: the cell detects when its power exceeds it) is the training sum
    times the row's scale over 2^scale_frac (every row may detect here)."""
    n_channels, shape = cube.shape[0], cube.shape[1:]
    nci = np.sum(cube.real ** 2 + cube.imag ** 2, axis=0)
    q = cube * fpga_lsb
    power = np.sum(np.rint(q.real).astype(np.int64) ** 2 + np.rint(q.imag).astype(np.int64)
                   ** 2, axis=0)
    out = []
    for path, kind in DETECTORS:
        for pfa in pfas:
            if path == "host":
                thr, _ = cfar_threshold(nci, n_channels, CfarParams(
                    pfa=pfa, guard=GUARD, train=TRAIN, kind=kind), (True, True))
                out.append((nci > thr, thr))
            else:
                cfg, scale = fpga_cfar(tuple(shape), kind, pfa, n_channels)
                cells = cfar_2d.cfar_2d(power, cfg, scale)
                row_scale = np.array([scale[cfar_2d.edge_index(r, cfg)]
                                      for r in range(shape[0])], float)
                thr = cells.train_sum * row_scale[:, None] / (1 << cfg.scale_frac)
                out.append((cells.detect, thr))
    return out


def detection(params: dict[str, Any], trials: range, seed: int, group: int
              ) -> dict[str, Any]:
    """params: ``swerling`` 0/1, ``cell_snr_db`` (None: noise only), ``pfas`` list,
    ``shape`` [n_range, n_doppler] of the maps. Returns ``cells`` (tested cells) and
    ``hits`` (detections per (detector, Pfa), :func:`detect_all` order); for noise-only maps
    also ``pfa_sum``: the sum over the cells of P(X > the cell's threshold) for X the cell
    under test's noise-only statistic, independent of its training cells (conditional Monte
    Carlo: its mean is the Pfa, with far less spread than counting false alarms). X is
    Gamma(L, 1) for the host; for the FPGA, Gamma(L, noise) with noise = fpga_lsb^2 + 1/6
    LSB^2 per channel (the rounding's mean; an approximation of the rounded values' sum)."""
    cfg = PRESETS[PRESET]
    shape = tuple(params["shape"])
    snr_db = params["cell_snr_db"]
    targets = maps.target_grid(shape, (GUARD[0] + TRAIN[0], GUARD[1] + TRAIN[1]))
    hits = np.zeros(len(DETECTORS) * len(params["pfas"]), np.int64)
    pfa_sum = np.zeros(len(hits))
    cells = 0
    lsb = fpga_noise_lsb(cfg)
    for t in trials:
        rng = rng_of(seed, group, t)
        snr = 0.0 if snr_db is None else 10 ** (snr_db / 10)
        cube = maps.detection_map(rng, cfg.n_virtual, shape, targets, snr, params["swerling"])
        dets = detect_all(cube, params["pfas"], lsb)
        if snr_db is None:
            hits += [int(d.sum()) for d, _ in dets]
            cells += shape[0] * shape[1]
            paths = [path for path, _ in DETECTORS for _ in params["pfas"]]
            for i, ((_, thr), path) in enumerate(zip(dets, paths, strict=True)):
                theta = 1.0 if path == "host" else lsb ** 2 + 1 / 6
                pfa_sum[i] += float(np.sum(stats.gamma.sf(thr, cfg.n_virtual, scale=theta)))
        else:
            hits += [int(d[targets[:, 0], targets[:, 1]].sum()) for d, _ in dets]
            cells += len(targets)
    out = {"cells": cells, "hits": hits.tolist()}
    if snr_db is None:
        out["pfa_sum"] = pfa_sum.tolist()
    return out


def estimate(cube: np.ndarray, noise: float, half: int, cfg: RadarConfig,
             axes: tuple[FftAxis, FftAxis] | None = None
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(range bins, Doppler bins, sin(az)) estimated from cells complex (n, L, 2 half + 1,
    2 half + 1) around each target (noise power ``noise`` per channel and cell): the cell of
    the integrated map's maximum among the 3 x 3 around the centre, the host's peak
    interpolation (``host.cells``, for ``axes``: default the Hann axes of ``cfg``) and angle
    estimator (``host.angle``, strongest component); bins relative to the centre cell."""
    n = len(cube)
    nci = np.sum(cube.real ** 2 + cube.imag ** 2, axis=1)
    centre = nci[:, half - 1:half + 2, half - 1:half + 2].reshape(n, 9).argmax(axis=1)
    pr, pd = centre // 3 + half - 1, centre % 3 + half - 1
    idx = np.arange(n)
    nb = np.stack([nci[idx, pr - 1, pd], nci[idx, pr + 1, pd], nci[idx, pr, pd - 1],
                   nci[idx, pr, pd + 1]], axis=1)
    off = neighbour_offsets(nci[idx, pr, pd], nb, np.ones(n, bool), axes or fft_axes(cfg))
    got = estimate_angles(cube[idx, :, pr, pd], np.full(n, noise), AngleParams())
    first = np.searchsorted(got.cell, idx)                 # strongest component of each row
    return pr - half + off[:, 0], pd - half + off[:, 1], got.sin_az[first]


def estimation(params: dict[str, Any], trials: range, seed: int, group: int
               ) -> dict[str, Any]:
    """params: ``snr_db`` per-channel per-sample SNR, ``azimuth_deg``, ``chains`` (a list
    of ``float``, ``quantised``). One target per trial at a random sub-bin position (and
    azimuth within half a beamwidth of ``azimuth_deg``), estimated by :func:`estimate` from
    the float chain's cells and, for ``quantised``, from the same cells in the FPGA's LSB
    (:func:`fpga_noise_lsb`) with I and Q rounded to integers. Returns ``trials`` and per
    chain the sums of squared errors ``<chain>:se_range_m``, ``<chain>:se_velocity_mps``,
    ``<chain>:se_azimuth_deg``."""
    cfg = PRESETS[PRESET]
    n = len(trials)
    rngs = [rng_of(seed, group, t) for t in trials]
    draws = np.array([r.random(4) for r in rngs])                       # (n, 4)
    offsets = draws[:, :2] - 0.5
    bw = cfg.angle_resolution_rad
    sin_az = np.sin(np.radians(params["azimuth_deg"]) + (draws[:, 2] - 0.5) * bw)
    half = 2
    cube = np.concatenate([maps.tone_patch(r, cfg.n_range, cfg.n_doppler, cfg.n_virtual,
                                           10 ** (params["snr_db"] / 10), offsets[i:i + 1],
                                           sin_az[i:i + 1], half)
                           for i, r in enumerate(rngs)])               # (n, L, 5, 5)
    noise = maps.patch_noise_per_channel(cfg.n_range, cfg.n_doppler)
    out: dict[str, Any] = {"trials": n}
    for chain in params["chains"]:
        if chain == "float":
            est = estimate(cube, noise, half, cfg)
        else:
            lsb = fpga_noise_lsb(cfg)
            q = cube * (lsb / np.sqrt(noise))
            est = estimate(np.rint(q.real) + 1j * np.rint(q.imag), lsb ** 2 + 1 / 6, half,
                            cfg)
        az = np.degrees(np.arcsin(np.clip(est[2], -1.0, 1.0)))
        out[f"{chain}:se_range_m"] = float(np.sum(((est[0] - offsets[:, 0])
                                                   * cfg.range_bin_m) ** 2))
        out[f"{chain}:se_velocity_mps"] = float(np.sum(((est[1] - offsets[:, 1])
                                                        * cfg.velocity_bin_mps) ** 2))
        out[f"{chain}:se_azimuth_deg"] = float(np.sum((az - np.degrees(np.arcsin(sin_az)))
                                                      ** 2))
    return out


FRAME_CHAINS = ("float_refined", "bit_accurate", "bit_accurate_refined",
                "bit_accurate_rect_refined")
"""Chains of :func:`estimation_frames`: the float chain with the refinement
(``host.refine``); the bit-accurate chain (``model.radar_pipeline``, Hann windows) with the
host's interpolation, and with the refinement; the bit-accurate chain with its windows off
(``PipelineParams(window=False)``) and the refinement."""


def _frame_errors(cube: np.ndarray, cfg: RadarConfig, truth: np.ndarray, noise: float,
                  windows: tuple[bool, bool], floor: float | None
                  ) -> tuple[np.ndarray, np.ndarray, float]:
    """(errors float (P, 2) of (range, Doppler) bins, sin(az) float (P,), seconds in
    ``host.refine``) of the targets of ``campaign.frames`` in ``cube`` (n_virtual, n_range,
    n_doppler; noise power ``noise`` per channel and cell): :func:`estimate` on the 5 x 5
    cells around each target's cell, then (``floor`` not None) ``host.refine`` from there;
    ``truth`` float (P, 2) the targets' (range, Doppler) bins."""
    cells = frames.target_cells(cfg)
    k = np.arange(-2, 3)
    rows = (cells[:, 0, None] + k) % cube.shape[1]              # both axes circular
    cols = (cells[:, 1, None] + k) % cube.shape[2]
    patch = cube[:, rows[:, :, None], cols[:, None, :]]
    axes = fft_axes(cfg, *windows)
    est_r, est_d, sin_est = estimate(np.moveaxis(patch, 0, 1), noise, 2, cfg, axes)
    got = np.stack([est_r, est_d], axis=1) + cells
    start = time.perf_counter()
    if floor is not None:
        cell = np.rint(got).astype(int)
        off = refine_offsets(cube, cell[:, 0] % cube.shape[1], cell[:, 1] % cube.shape[2],
                             got - cell, cfg, windows, floor)
        got = cell + off
    return got - truth, sin_est, time.perf_counter() - start


def estimation_frames(params: dict[str, Any], trials: range, seed: int, group: int
                      ) -> dict[str, Any]:
    """params: ``snr_db`` per-channel per-sample SNR, ``chains`` (of :data:`FRAME_CHAINS`).
    One whole frame per trial (``campaign.frames``: 64 targets at random sub-bin positions,
    sin(az) uniform in +-``SIN_AZ_MAX``) through the float chain (``model.reference``) and
    the bit-accurate one (``model.radar_pipeline``, the ADC at its noise level, I and Q
    rounded); estimates by :func:`_frame_errors`. Returns ``trials`` (targets) and per chain
    ``<chain>:se_range_m``, ``<chain>:se_velocity_mps``, ``<chain>:se_azimuth_deg``, and
    ``<chain>:refine_s`` (seconds in ``host.refine``) for the refined chains."""
    cfg = PRESETS[PRESET]
    snr = 10 ** (params["snr_db"] / 10)
    noise_adc = cfg.noise_power_lsb2
    cell_noise = noise_adc * maps.patch_noise_per_channel(cfg.n_range, cfg.n_doppler)
    out: dict[str, Any] = {"trials": 0}
    for t in trials:
        rng = rng_of(seed, group, t)
        off = rng.random((frames.TARGETS, 2)) - 0.5
        sin_az = rng.uniform(-frames.SIN_AZ_MAX, frames.SIN_AZ_MAX, frames.TARGETS)
        adc = frames.tone_frame(rng, cfg, snr, noise_adc, off, sin_az)
        truth = frames.target_cells(cfg) + off
        codes = np.rint(adc.real) + 1j * np.rint(adc.imag)
        cubes = {}
        for chain in params["chains"]:
            if chain == "float_refined":
                cube, windows, floor = radar_cube(adc, cfg), (True, True), FLOAT_FLOOR
            elif chain == "bit_accurate_rect_refined":
                cube = scaled_cube(codes, cfg, PipelineParams(window=False))
                windows, floor = (False, False), FIXED_POINT_FLOOR
            else:
                if "hann" not in cubes:
                    cubes["hann"] = scaled_cube(codes, cfg)
                cube, windows = cubes["hann"], (True, True)
                floor = FIXED_POINT_FLOOR if chain.endswith("refined") else None
            # noise per channel and cell of the cube (rect windows: 1 / 0.375^2 more)
            noise = cell_noise / (1.0 if windows[0] else maps.HANN_NOISE_GAIN ** 2)
            err, sin_est, seconds = _frame_errors(cube, cfg, truth, noise, windows, floor)
            if floor is not None:
                out[f"{chain}:refine_s"] = out.get(f"{chain}:refine_s", 0.0) + seconds
            az = np.degrees(np.arcsin(np.clip(sin_est, -1.0, 1.0)))
            for name, e in ((":se_range_m", err[:, 0] * cfg.range_bin_m),
                            (":se_velocity_mps", err[:, 1] * cfg.velocity_bin_mps),
                            (":se_azimuth_deg", az - np.degrees(np.arcsin(sin_az)))):
                out[chain + name] = out.get(chain + name, 0.0) + float(np.sum(e ** 2))
        out["trials"] += frames.TARGETS
    return out


def resolution(params: dict[str, Any], trials: range, seed: int, group: int
               ) -> dict[str, Any]:
    """params: ``sep_bw`` separation in beamwidths (2 / n_channels in sin(az)),
    ``cell_snr_db`` per-channel SNR of each target in the cell. Resolved: the estimator
    returns two or more components and the two strongest are each within half the
    separation of a different target. Returns ``trials`` and ``resolved``."""
    n_ch = PRESETS[PRESET].n_virtual
    sep = params["sep_bw"] * 2.0 / n_ch
    amp = np.sqrt(10 ** (params["cell_snr_db"] / 10))
    v = np.arange(n_ch)
    rows, truth = [], []
    for t in trials:
        rng = rng_of(seed, group, t)
        s0 = rng.uniform(-0.3, 0.3)
        s = np.array([s0 - sep / 2, s0 + sep / 2])
        ph = np.exp(2j * np.pi * rng.random(2))
        x = (amp * ph[:, None] * np.exp(-1j * np.pi * np.outer(s, v))).sum(axis=0)
        rows.append(x + maps.complex_normal(rng, (n_ch,)))
        truth.append(s)
    got = estimate_angles(np.array(rows), np.ones(len(rows)), AngleParams())
    resolved = 0
    for i, s in enumerate(truth):
        est = got.sin_az[got.cell == i][:2]
        if len(est) == 2:
            est = np.sort(est)
            resolved += int(np.all(np.abs(est - s) < sep / 2))
    return {"trials": len(truth), "resolved": resolved}


TRIALS: dict[str, TrialFn] = {"detection": detection, "estimation": estimation,
                              "estimation_frames": estimation_frames,
                              "resolution": resolution}
"""Trial functions by the name a :class:`campaign.runner.Task` gives."""
