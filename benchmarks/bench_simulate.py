"""Benchmark: wall time to simulate one frame (and to run the float reference chain).

    python -m benchmarks.bench_simulate [--repeat 5]

Prints a table; the goal (issue 2) is one ``full``-preset frame with 200 scatterers in at
most 2 s on a 2-core machine. Timing is reported, never asserted in tests.
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

from model.config import get_preset
from model.reference import radar_cube
from model.scene import Scatterers
from model.simulate import simulate_frame


def random_scatterers(n: int, max_range_m: float, rng: np.random.Generator) -> Scatterers:
    """``n`` scatterers uniform in range (2 m .. 0.9 max range), azimuth +-60 deg,
    velocity +-27 m/s, RCS 1..20 m^2."""
    return Scatterers(rng.uniform(2.0, 0.9 * max_range_m, n), rng.uniform(-60, 60, n),
                      rng.uniform(-27, 27, n), rng.uniform(1, 20, n), np.full(n, -1))


def best_of(fn, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5, help="runs per row; best is reported")
    args = ap.parse_args()
    rng = np.random.default_rng(0)
    print(f"CPU cores: {os.cpu_count()}, best of {args.repeat} runs")
    print(f"{'preset':<11} {'scatterers':>10} {'samples':>10} {'simulate s':>11} "
          f"{'chain s':>8} {'goal':>8}")
    for preset, n in (("paper-fpga", 4), ("paper-fpga", 200), ("full", 4), ("full", 200),
                      ("full", 1000)):
        cfg = get_preset(preset)
        sc = random_scatterers(n, cfg.max_range_m, rng)
        frame = simulate_frame(cfg, sc, rng=rng)
        t_sim = best_of(lambda cfg=cfg, sc=sc: simulate_frame(cfg, sc, rng=rng), args.repeat)
        t_chain = best_of(lambda cfg=cfg, f=frame: radar_cube(f.samples, cfg), args.repeat)
        goal = "<= 2 s" if (preset, n) == ("full", 200) else ""
        ok = ("" if not goal else (" met" if t_sim <= 2.0 else " MISSED"))
        print(f"{preset:<11} {n:>10} {frame.samples.size:>10} {t_sim:>11.3f} {t_chain:>8.3f} "
              f"{goal:>8}{ok}")


if __name__ == "__main__":
    main()
