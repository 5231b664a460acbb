"""Detection and estimation curves against theory (``radar curves``, docs/curves.md): the
campaign's tasks, and the JSON built from their results beside the theoretical curves
(``model.detection_theory``).

SNR axes: ``snr_db`` is the per-channel, per-ADC-sample SNR before any processing;
``cell_snr_db`` the per-channel SNR of the target's range-Doppler cell, snr_db plus the two
FFTs' coherent gain with Hann windows (:func:`cell_gain_db`; a target at a bin centre).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from campaign import frames, maps
from campaign import trials as tr
from campaign.runner import CampaignError, Task, merge, run, split
from host.cfar import CfarParams, effective_cells
from host.refine import FIXED_POINT_FLOOR, FLOAT_FLOOR, weights
from model import cfar_2d, cfar_stats
from model import detection_theory as dt
from model.config import PRESETS, RadarConfig
from model.reference import FftAxis, fft_axes

MAP_SHAPE = (64, 128)
"""(range, Doppler) cells of each synthetic detection map."""
COND_MAP_SHAPE = (128, 128)
"""Maps of the conditional Pfa estimate (other maps than the counted ones)."""
CELL_SNR_LIMITS = (-30.0, 40.0)
"""Per-channel cell SNRs (dB) a detection grid may span: beyond, every Pd is 0 or 1."""
SNR_LIMITS = (-90.0, 10.0)
"""Per-sample SNRs (dB) an estimation grid may span."""
CHAINS = ("float", "quantised")
"""Estimation chains: the float chain's cells, and the same cells rounded to the FPGA's
integer output (its LSB at 1.56 LSB RMS noise per cell; the FFT stages' internal rounding is
not modelled)."""


@dataclass(frozen=True)
class Plan:
    """What one ``radar curves`` run measures. Grids: (lo, hi, step) dB; trials: Pd
    targets per point, noise-only cells for the Pfa, estimation and resolution trials per
    point."""

    pfas: tuple[float, ...] = (1e-4, 1e-6)
    cell_snr_sw0: tuple[float, float, float] = (-8.0, 2.0, 1.0)
    cell_snr_sw1: tuple[float, float, float] = (-6.0, 16.0, 1.0)
    pd_trials: int = 2000
    pfa_cells: int = 10_000_000
    snr: tuple[float, float, float] = (-64.0, -20.0, 2.0)
    est_trials: int = 1000
    separations: tuple[float, float, float] = (0.3, 1.5, 0.1)
    res_trials: int = 1000
    res_cell_snr_db: float = 20.0
    azimuth_deg: float = 10.0
    frame_trials: int = 512

    @property
    def pfa_cond_cells(self) -> int:
        """Noise cells of the conditional Pfa estimate (other maps): a fifth of the counted
        ones (its spread is far smaller)."""
        return max(1, self.pfa_cells // 5)

    @staticmethod
    def quick() -> Plan:
        return Plan(cell_snr_sw0=(-8.0, 2.0, 2.0), cell_snr_sw1=(-6.0, 16.0, 2.0),
                    pd_trials=420, pfa_cells=1_200_000, snr=(-64.0, -20.0, 4.0),
                    est_trials=300, separations=(0.3, 1.5, 0.2), res_trials=300,
                    frame_trials=64)

    def check(self) -> None:
        """CampaignError for a plan that cannot run (module limits, Pfa in (0, 1))."""
        for p in self.pfas:
            if not (isinstance(p, float | int) and 1e-12 <= p < 0.5):
                raise CampaignError(f"--pfa: must be in (0, 1) (1e-12 .. 0.5), got {p!r}")
        for name, n in (("--trials", self.pd_trials), ("--trials", self.est_trials),
                        ("--trials", self.res_trials), ("--pfa-cells", self.pfa_cells)):
            if n < 1:
                raise CampaignError(f"{name}: must be at least 1, got {n}")
        if self.frame_trials < 0:
            raise CampaignError(f"--frame-trials: must be 0 or more, got {self.frame_trials}")
        for name, g, (lo, hi) in (("--cell-snr", self.cell_snr_sw0, CELL_SNR_LIMITS),
                                  ("--cell-snr", self.cell_snr_sw1, CELL_SNR_LIMITS),
                                  ("--snr", self.snr, SNR_LIMITS)):
            grid(g, name, lo, hi)


def grid(g: tuple[float, float, float], option: str, lo: float, hi: float) -> list[float]:
    """The points lo..hi step of ``g`` (dB), CampaignError when impossible."""
    a, b, step = g
    if not all(math.isfinite(v) for v in g) or step <= 0 or a > b or a < lo or b > hi \
            or (b - a) / step > 200:
        raise CampaignError(f"{option}: need finite LO <= HI within {lo:g}..{hi:g} dB and "
                            f"0 < STEP with at most 200 points, got {g[0]:g} {g[1]:g} {g[2]:g}")
    return [round(a + i * step, 6) for i in range(int(math.floor((b - a) / step + 1e-9)) + 1)]


def cell_gain_db(cfg: RadarConfig) -> float:
    """cell_snr_db - snr_db: the range and Doppler FFTs' coherent gain over white noise with
    periodic Hann windows, (sum w)^2 / sum w^2 = 2N/3 per FFT, dB."""
    return float(10 * np.log10(cfg.n_range * cfg.n_doppler * (2 / 3) ** 2))


def tasks(plan: Plan) -> dict[str, list[Task]]:
    """The campaign's tasks by curve (``"pfa"``, ``"sw0:<cell snr>"``, ``"sw1:..."``,
    ``"est:<snr>"``, ``"frames:<snr>"`` (one whole frame per task), ``"res:<sep>"``)."""
    cells_per_map = MAP_SHAPE[0] * MAP_SHAPE[1]
    per_map = len(maps.target_grid(MAP_SHAPE, _reach()))
    pfas = list(plan.pfas)
    cond_cells = COND_MAP_SHAPE[0] * COND_MAP_SHAPE[1]
    out: dict[str, list[Task]] = {
        "pfa": split("detection", {"swerling": 0, "cell_snr_db": None, "pfas": pfas,
                                   "shape": list(MAP_SHAPE)},
                     -(-plan.pfa_cells // cells_per_map), 8),
        "pfa_cond": split("detection", {"swerling": 0, "cell_snr_db": None, "pfas": pfas,
                                        "shape": list(COND_MAP_SHAPE)},
                          -(-plan.pfa_cond_cells // cond_cells), 4)}
    for sw, g in ((0, plan.cell_snr_sw0), (1, plan.cell_snr_sw1)):
        for s in grid(g, "--cell-snr", *CELL_SNR_LIMITS):
            out[f"sw{sw}:{s}"] = split("detection", {"swerling": sw, "cell_snr_db": s,
                                                     "pfas": pfas, "shape": list(MAP_SHAPE)},
                                       -(-plan.pd_trials // per_map), 4)
    for s in grid(plan.snr, "--snr", *SNR_LIMITS):
        out[f"est:{s}"] = split("estimation", {"snr_db": s, "azimuth_deg": plan.azimuth_deg,
                                               "chains": list(CHAINS)}, plan.est_trials, 250)
    if plan.frame_trials:
        for s in grid(plan.snr, "--snr", *SNR_LIMITS):
            out[f"frames:{s}"] = split("estimation_frames", {
                "snr_db": s, "chains": list(tr.FRAME_CHAINS)},
                -(-plan.frame_trials // frames.TARGETS), 1)
    for s in grid(plan.separations, "--separations", 0.05, 10.0):
        out[f"res:{s}"] = split("resolution", {"sep_bw": s,
                                               "cell_snr_db": plan.res_cell_snr_db},
                                plan.res_trials, 250)
    return out


def _reach() -> tuple[int, int]:
    return tr.GUARD[0] + tr.TRAIN[0], tr.GUARD[1] + tr.TRAIN[1]


def run_curves(plan: Plan, seed: int, results: Path, workers: int, address: str | None,
               progress: bool | None = None) -> dict[str, Any]:
    """Run (or resume) the campaign of ``plan`` and return the curves' JSON document."""
    plan.check()
    by_curve = tasks(plan)
    flat = [t for ts in by_curve.values() for t in ts]
    got = run(flat, seed, results, workers=workers, address=address, desc="curves",
              progress=progress)
    merged = {name: merge(got[t.key(seed)] for t in ts) for name, ts in by_curve.items()}
    return document(plan, seed, merged)


def _theory(path: str, kind: str, pfa: float, n_ch: int, fpga_lsb: float
            ) -> tuple[float, dt.QuantileFn, int, float, float]:
    """(alpha, noise-estimate quantile, training cells, effective training cells, noise
    power per channel relative to the float noise) of one detector at an interior cell."""
    if path == "host":
        cp = CfarParams(pfa=pfa, guard=tr.GUARD, train=tr.TRAIN, kind=kind)
        pr, pd = _reach()
        n_train = (2 * pr + 1) * (2 * pd + 1) - (2 * tr.GUARD[0] + 1) * (2 * tr.GUARD[1] + 1)
        n_eff = effective_cells(cp)
        if kind == "ca":
            return float(cfar_stats.ca_factor(pfa, n_ch, n_eff)), dt.ca_quantile(
                n_ch, n_eff), n_train, n_eff, 1.0
        k = max(1, min(n_train, round(cp.os_rank * n_train)))
        return cfar_stats.os_factor(pfa, n_ch, n_train, k), dt.os_quantile(
            n_ch, n_train, k), n_train, float(n_train), 1.0
    cfg, scale = tr.fpga_cfar(MAP_SHAPE, kind, pfa, n_ch)
    half = kind != "ca"
    mask = cfar_2d.training_mask(cfg, cfg.pr, half)
    cells = float(mask.sum())
    n_eff = cfar_stats.effective_cells_mask(mask)
    alpha = float(scale[cfg.pr]) * cells / (1 << cfg.scale_frac)   # the fixed-point scale
    # rounding I and Q to integers adds 1/6 LSB^2 per channel to the noise
    noise = (fpga_lsb ** 2 + 1.0 / 6.0) / fpga_lsb ** 2
    q = dt.ca_quantile(n_ch, n_eff) if not half else dt.go_so_quantile(n_ch, n_eff, kind)
    return alpha, q, int(cells * (2 if half else 1)), n_eff * (2 if half else 1), noise


def snr_at(pd: list[float], snr_db: list[float], level: float) -> float | None:
    """The SNR (dB) where a rising Pd curve crosses ``level`` (linear interpolation in dB);
    None when it does not on the grid."""
    for i in range(1, len(pd)):
        if pd[i - 1] < level <= pd[i]:
            f = (level - pd[i - 1]) / (pd[i] - pd[i - 1])
            return round(snr_db[i - 1] + f * (snr_db[i] - snr_db[i - 1]), 3)
    return None


def detection_rows(plan: Plan, merged: dict[str, Any], cfg: RadarConfig) -> list[dict]:
    """The ``detection`` entries (docs/curves.md)."""
    n_ch, gain = cfg.n_virtual, cell_gain_db(cfg)
    lsb = tr.fpga_noise_lsb(cfg)
    npfa = len(plan.pfas)
    rows = []
    guard_cells = (2 * tr.GUARD[0] + 1) * (2 * tr.GUARD[1] + 1) - 1
    for di, (path, kind) in enumerate(tr.DETECTORS):
        for pi, pfa in enumerate(plan.pfas):
            col = di * npfa + pi
            alpha, q, n_train, n_eff, noise = _theory(path, kind, pfa, n_ch, lsb)
            fa, cond = merged["pfa"], merged["pfa_cond"]
            for sw, g in ((0, plan.cell_snr_sw0), (1, plan.cell_snr_sw1)):
                cell = grid(g, "--cell-snr", *CELL_SNR_LIMITS)
                pd = [merged[f"sw{sw}:{s}"]["hits"][col] / merged[f"sw{sw}:{s}"]["cells"]
                      for s in cell]
                theory = [dt.cfar_pd(alpha, q, n_ch, 10 ** (s / 10) / noise, sw) for s in cell]
                at = {}
                for level in (0.5, 0.9):
                    m, t = snr_at(pd, cell, level), snr_at(theory, cell, level)
                    at[str(level)] = {"measured_db": m, "theory_db": t,
                                      "delta_db": None if m is None or t is None
                                      else round(m - t, 3)}
                rows.append({
                    "detector": kind, "path": path, "swerling": sw, "pfa": pfa,
                    "train_cells": n_train, "effective_train_cells": round(n_eff, 2),
                    "guard_cells": guard_cells, "integrated_channels": n_ch,
                    "snr_db": [round(s - gain, 3) for s in cell], "cell_snr_db": cell,
                    "pd": [round(p, 5) for p in pd], "pd_theory": [round(p, 5) for p in theory],
                    "trials": merged[f"sw{sw}:{cell[0]}"]["cells"],
                    "pfa_measured": fa["hits"][col] / fa["cells"], "pfa_cells": fa["cells"],
                    "pfa_false_alarms": fa["hits"][col],
                    "pfa_conditional": float(f"{cond['pfa_sum'][col] / cond['cells']:.4g}"),
                    "pfa_conditional_cells": cond["cells"], "snr_at_pd": at})
    return rows


def _specs(cfg: RadarConfig, sec_az: float) -> dict[str, tuple[str, str, int, int, float]]:
    """quantity -> (unit, result key, aperture, looks, cycles per sample -> unit); sec_az:
    1 / cos(az) of the targets (RMS over them)."""
    nr, nd, nv = cfg.n_range, cfg.n_doppler, cfg.n_virtual
    return {"range": ("m", "se_range_m", nr, nd * nv, nr * cfg.range_bin_m),
            "radial_velocity": ("m/s", "se_velocity_mps", nd, nr * nv,
                                nd * cfg.velocity_bin_mps),
            "azimuth": ("deg", "se_azimuth_deg", nv, nr * nd, 2.0 * sec_az * 180.0 / math.pi)}


def _row(quantity: str, chain: str, snr: list[float], res: list[dict[str, Any]],
         cfg: RadarConfig, sec_az: float, against_crb: bool = False) -> dict[str, Any]:
    """One ``estimation`` entry: RMSE of ``chain`` against the whole data's CRB and against
    the bound of what the estimator is given (the array's for azimuth, the three cells' for
    range and velocity); the threshold against the latter, or (``against_crb``) the CRB."""
    unit, key, n, looks, to_unit = _specs(cfg, sec_az)[quantity]
    gain = cell_gain_db(cfg)
    rmse = [math.sqrt(r[f"{chain}:{key}"] / r["trials"]) for r in res]
    crb = [dt.tone_frequency_crb(10 ** (s / 10), n, looks) * to_unit for s in snr]
    row = {"quantity": quantity, "chain": chain, "unit": unit, "snr_db": snr,
           "cell_snr_db": [round(s + gain, 3) for s in snr],
           "n_elements" if quantity == "azimuth" else "n_samples": n, "looks": looks,
           "rmse": [float(f"{v:.5g}") for v in rmse], "crb": [float(f"{v:.5g}") for v in crb],
           "excess_db": _excess(rmse, crb), "trials": res[0]["trials"]}
    if quantity == "azimuth":      # the array's bound for the one-cell snapshot
        cells = tuple((ax.window(), ax.n_fft) for ax in fft_axes(cfg))
        bound = [dt.cell_snapshot_crb(10 ** (s / 10), n, cells) * to_unit for s in snr]
        row["crb_array"] = [float(f"{v:.5g}") for v in bound]
        row["excess_array_db"] = _excess(rmse, bound)
    else:                          # the bound of the three cells the interpolator reads
        axes = fft_axes(cfg)
        ax = axes if quantity == "range" else axes[::-1]
        bound = [dt.three_cell_crb(10 ** (s / 10), (ax[0].window(), ax[0].n_fft),
                                   (ax[1].window(), ax[1].n_fft), cfg.n_virtual) * to_unit
                 for s in snr]
        row["crb_cells"] = [float(f"{v:.5g}") for v in bound]
        row["excess_cells_db"] = _excess(rmse, bound)
    row.update(_threshold(snr, _excess(rmse, crb if against_crb else bound)))
    return row


def estimation_rows(plan: Plan, merged: dict[str, Any], cfg: RadarConfig) -> list[dict]:
    """The ``estimation`` entries: RMSE and CRB per quantity (docs/curves.md)."""
    snr = grid(plan.snr, "--snr", *SNR_LIMITS)
    res = [merged[f"est:{s}"] for s in snr]
    sec_az = 1.0 / math.cos(math.radians(plan.azimuth_deg))
    return [_row(q, chain, snr, res, cfg, sec_az)
            for q, chain in itertools.product(("range", "radial_velocity", "azimuth"), CHAINS)]


def frame_rows(plan: Plan, merged: dict[str, Any], cfg: RadarConfig) -> list[dict]:
    """The ``estimation_frames`` entries (docs/curves.md, "Whole frames"): as
    ``estimation``'s, per chain of ``campaign.trials.FRAME_CHAINS``; range and velocity for
    every chain (a refined chain's threshold against ``crb``, with ``taper_loss_db`` the
    weighting's derived loss and ``refine_ms_per_cell`` the time in ``host.refine``),
    azimuth for the bit-accurate chain (the refinement leaves the angle as it is)."""
    if not plan.frame_trials:
        return []
    snr = grid(plan.snr, "--snr", *SNR_LIMITS)
    res = [merged[f"frames:{s}"] for s in snr]
    # sin(az) uniform in +-S: the bound's variance averaged over the targets, mean 1/cos^2
    s_max = frames.SIN_AZ_MAX
    sec_az = math.sqrt(math.atanh(s_max) / s_max)
    rows = []
    for chain in tr.FRAME_CHAINS:
        refined = chain.endswith("refined")
        hann = chain != "bit_accurate_rect_refined"
        floor = FLOAT_FLOOR if chain.startswith("float") else FIXED_POINT_FLOOR
        for q in ("range", "radial_velocity", "azimuth"):
            if q == "azimuth" and refined:
                continue
            row = _row(q, chain, snr, res, cfg, sec_az, against_crb=refined)
            if refined:
                axes = fft_axes(cfg, hann, hann)
                ax = axes if q == "range" else axes[::-1]
                row["refine_floor"] = floor
                row["taper_loss_db"] = round(taper_loss_db(ax[0], ax[1], floor), 3)
                row["refine_ms_per_cell"] = round(1e3 * sum(
                    r[f"{chain}:refine_s"] for r in res) / sum(r["trials"] for r in res), 2)
            rows.append(row)
    return rows


def taper_loss_db(axis: FftAxis, other: FftAxis, floor: float) -> float:
    """MSE over the CRB, dB, of the periodogram peak of samples weighted by
    ``host.refine.weights`` (v = w^2 / (w^2 + floor^2) per axis) along ``axis``, to first
    order: sum(v^2 t^2) sum(t^2) / (sum(v t^2))^2 along the axis (t centred) times
    N sum(v^2) / (sum v)^2 across it (the other axis' SNR loss); docs/curves.md."""
    v, t = weights(axis, floor)[1], np.arange(axis.n_samples) - axis.n_samples / 2
    u = weights(other, floor)[1]
    est = np.sum(v ** 2 * t ** 2) * np.sum(t ** 2) / np.sum(v * t ** 2) ** 2
    snr = len(u) * np.sum(u ** 2) / np.sum(u) ** 2
    return float(10 * np.log10(est * snr))


def _excess(rmse: list[float], bound: list[float]) -> list[float]:
    """MSE over the bound's variance, dB (20 log10 of the RMSE ratio)."""
    return [round(20 * math.log10(a / b), 2) for a, b in zip(rmse, bound, strict=True)]


def _threshold(snr: list[float], excess: list[float]) -> dict[str, float | None]:
    """``threshold_snr_db``: the lowest grid SNR from which on every point is within 3 dB
    (MSE) of the bound (the array's for azimuth, the three cells' for range and velocity);
    ``excess_above_threshold_db``: the median excess there."""
    thr = None
    for i in range(len(snr) - 1, -1, -1):
        if excess[i] > 3.0:
            break
        thr = snr[i]
    above = [e for s, e in zip(snr, excess, strict=True) if thr is not None and s >= thr]
    return {"threshold_snr_db": thr, "excess_above_threshold_db":
            round(float(np.median(above)), 2) if above else None}


def document(plan: Plan, seed: int, merged: dict[str, Any]) -> dict[str, Any]:
    """The curves' JSON document (docs/curves.md) from the merged task results."""
    cfg = PRESETS[tr.PRESET]
    seps = grid(plan.separations, "--separations", 0.05, 10.0)
    res = [merged[f"res:{s}"] for s in seps]
    return {
        "preset": cfg.name, "seed": seed, "map_shape": list(MAP_SHAPE),
        "cell_gain_db": round(cell_gain_db(cfg), 3),
        "fpga_noise_lsb": round(tr.fpga_noise_lsb(cfg), 4),
        "detection": detection_rows(plan, merged, cfg),
        "estimation": estimation_rows(plan, merged, cfg),
        "estimation_frames": frame_rows(plan, merged, cfg),
        "resolution": {"cell_snr_db": plan.res_cell_snr_db, "separation_bw": seps,
                       "beamwidth_deg": round(math.degrees(cfg.angle_resolution_rad), 3),
                       "probability": [r["resolved"] / r["trials"] for r in res],
                       "trials": res[0]["trials"]}}
