"""Compare a point cloud with the scene truth (Table III style).

Targets are matched to points within gates in range (m), radial velocity (m/s, on the
unfolded velocity or, for an aliased target, on the velocity it aliases to) and azimuth
(deg); the strongest point in the gate wins. Errors are always measured against the true
velocity: a point that reports the alias of a target's velocity has an error of about
2 vmax, and the table says so (the error against the alias is shown beside it, labelled).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from host.pointcloud import PointCloud
from model.config import RadarConfig
from model.scene import PointTarget

PAPER_HW_ERRORS = (  # paper Table III: |HW output - actual| per vehicle (range m, speed m/s)
    (14.29, 3.69), (7.14, 1.11), (2.85, 0.93), (8.57, 0.46))


def alias_velocity(v: float, cfg: RadarConfig) -> float:
    """The velocity ``v`` appears at after Doppler aliasing into [-vmax, vmax)."""
    vmax = cfg.max_velocity_mps
    return (v + vmax) % (2 * vmax) - vmax


@dataclass(frozen=True)
class Match:
    """A target and the point that matched it (index -1: missed)."""

    target: PointTarget
    index: int
    range_err_m: float
    velocity_err_mps: float  # estimate - true velocity (never against the alias)
    azimuth_err_deg: float
    aliased: bool  # matched at the aliased velocity (not unfolded)
    alias_velocity_err_mps: float = float("nan")  # estimate - alias (aliased matches only)


def match_targets(cloud: PointCloud, targets: tuple[PointTarget, ...], cfg: RadarConfig,
                  gate_range_m: float = 3.0, gate_velocity_mps: float = 1.0,
                  gate_azimuth_deg: float = 5.0) -> tuple[list[Match], np.ndarray]:
    """Match every target to a point. Returns (matches, bool (n,) True for points that
    matched a target)."""
    used = np.zeros(len(cloud), bool)
    out = []
    for t in targets:
        best, best_p, aliased = -1, -np.inf, False
        for want_v, is_alias in ((t.radial_velocity_mps, False),
                                 (alias_velocity(t.radial_velocity_mps, cfg), True)):
            ok = ((np.abs(cloud.range_m - t.range_m) <= gate_range_m)
                  & (np.abs(cloud.radial_velocity_mps - want_v) <= gate_velocity_mps)
                  & (np.abs(cloud.azimuth_deg - t.azimuth_deg) <= gate_azimuth_deg) & ~used)
            for i in np.flatnonzero(ok):
                if cloud.power_db[i] > best_p:
                    best, best_p, aliased = int(i), cloud.power_db[i], is_alias
            if best >= 0:
                break
        if best < 0:
            out.append(Match(t, -1, np.nan, np.nan, np.nan, False))
            continue
        used[best] = True
        v = float(cloud.radial_velocity_mps[best])
        alias_err = v - alias_velocity(t.radial_velocity_mps, cfg) if aliased else float("nan")
        out.append(Match(t, best, float(cloud.range_m[best] - t.range_m),
                         v - t.radial_velocity_mps,
                         float(cloud.azimuth_deg[best] - t.azimuth_deg), aliased, alias_err))
    # other points of a matched target's cell (same range/Doppler bins) are not false alarms
    for m in out:
        if m.index >= 0:
            used |= ((cloud.range_bin == cloud.range_bin[m.index])
                     & (cloud.doppler_bin == cloud.doppler_bin[m.index])
                     & (np.abs(cloud.azimuth_deg - cloud.azimuth_deg[m.index]) < 2.0))
    return out, used


def table3(matches: list[Match], cloud: PointCloud, cfg: RadarConfig,
           with_paper: bool = True) -> str:
    """The paper's Table III (actual vs estimated range and closing speed, plus azimuth)
    with our absolute errors and, beside them, the paper's hardware errors. An aliased
    speed is marked ``*`` and its error is against the true speed (flags give the error
    against the alias)."""
    paper_col = f" {'paper':>6}" if with_paper else ""
    head = (f"{'veh':>3} | {'range m':>7} {'est':>7} {'err':>6}{paper_col} | "
            f"{'speed m/s':>9} {'est':>7} {'err':>6}{paper_col} | "
            f"{'az deg':>6} {'est':>7} {'err':>6} | flags")
    lines = [head, "-" * len(head)]
    for i, m in enumerate(matches):
        t = m.target
        paper = PAPER_HW_ERRORS[i] if i < len(PAPER_HW_ERRORS) else (np.nan, np.nan)
        pr = f" {paper[0]:>6.2f}" if with_paper else ""
        pv = f" {paper[1]:>6.2f}" if with_paper else ""
        closing = -t.radial_velocity_mps
        if m.index < 0:
            lines.append(f"{i + 1:>3} | {t.range_m:>7.2f} {'--':>7} {'':>6}{pr} | "
                         f"{closing:>9.2f} {'--':>7} {'':>6}{pv} | "
                         f"{t.azimuth_deg:>6.1f} {'--':>7} {'':>6} | MISSED")
            continue
        j = m.index
        flags = []
        mark = " "
        if m.aliased:
            mark = "*"
            flags.append(f"ALIASED: speed {-cloud.radial_velocity_mps[j]:.2f} is the alias of "
                         f"{closing:.2f} (beyond +-{cfg.max_velocity_mps:.2f}); error vs "
                         f"the alias {abs(m.alias_velocity_err_mps):.2f}")
        elif abs(t.radial_velocity_mps) > cfg.max_velocity_mps:
            flags.append("unfolded by TDM phase test")
        if cloud.ambiguous[j]:
            flags.append("ambiguous flag")
        lines.append(
            f"{i + 1:>3} | {t.range_m:>7.2f} {cloud.range_m[j]:>7.2f} "
            f"{abs(m.range_err_m):>6.2f}{pr} | {closing:>9.2f} "
            f"{-cloud.radial_velocity_mps[j]:>6.2f}{mark} {abs(m.velocity_err_mps):>6.2f}{pv} | "
            f"{t.azimuth_deg:>6.1f} {cloud.azimuth_deg[j]:>7.2f} {abs(m.azimuth_err_deg):>6.2f}"
            f" | {', '.join(flags)}")
    return "\n".join(lines)


def alias_note(targets: tuple[PointTarget, ...], cfg: RadarConfig, prefix: str = "V"
               ) -> str | None:
    """A sentence for figures explaining the targets whose velocity is beyond +-vmax
    (labels ``prefix`` + 1-based index), or None when there are none."""
    vmax = cfg.max_velocity_mps
    fast = [(i, t) for i, t in enumerate(targets) if not -vmax <= t.radial_velocity_mps < vmax]
    if not fast:
        return None
    names = ", ".join(f"{prefix}{i + 1} ({t.radial_velocity_mps:+.1f} m/s, shows at "
                      f"{alias_velocity(t.radial_velocity_mps, cfg):+.2f})" for i, t in fast)
    if cfg.num_tx > 1:
        return (f"{names}: beyond the unambiguous +-{vmax:.2f} m/s. This map compensates the "
                f"TDM slot delay with the aliased Doppler, which mis-phases the {cfg.num_tx} "
                f"TX slots and smears the target across azimuth; the point cloud tests the "
                f"unfolded hypotheses and places it correctly.")
    return (f"{names}: beyond the unambiguous +-{vmax:.2f} m/s. With one TX there is no TDM "
            f"phase to correct (azimuth is right) and nothing to unfold with: its velocity "
            f"is reported aliased and flagged ambiguous.")
