"""The impairments benchmark's measurement (``benchmarks/bench_impairments.py``) on a small
profile (the OpenRadar 2 TX x 4 RX) and one seed, with every effect but the clutter (its
simulation is the slow part) and large per-channel errors (3 dB / 30 deg rms per TX and RX):
the calibration ``radar calibrate`` estimates takes the azimuth errors back to the clean
case's, keeps every target to one point and adds no angle component in the targets' cells.
A property, not a timing; the benchmark's table and what it leaves (leakage skirts,
I/Q images) are in docs/profiles.md, "Measured: impairments and calibration"."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from benchmarks.bench_impairments import all_impairments, measure
from model.profile import load_profile
from model.scene import PointTarget, Scene

CFG = load_profile(Path(__file__).parent / "data" / "openradar" / "openradar_2tx4rx.cfg").config
TARGETS = tuple(PointTarget(range_m=r, azimuth_deg=az, radial_velocity_mps=v, rcs_m2=1.0)
                for r, az, v in ((2.0, -25.0, 1.5), (3.5, 10.0, -2.0), (4.5, 30.0, 3.0)))


def test_calibration_restores_the_angles() -> None:
    imp = replace(all_impairments(1, CFG.max_range_m, channel_rms=(3.0, 30.0)), walls=(),
                  ground=None)
    t = measure([Scene(seed=1, targets=TARGETS, radar=CFG)], [imp], reflector_m=1.2)
    az = {c: float(np.mean([e[2] for errs in x.errors for e in errs])) for c, x in t.items()}
    assert all(x.missed == 0 for x in t.values())
    assert az["calibrated"] < 2 * az["clean"] + 0.05 and az["impaired"] > 1.0, az
    cal = t["calibrated"]
    assert cal.extra == 0 and all(n == [1] for n in cal.per_target), cal
