"""Benchmark: the bit-accurate chain model, fast path against the stage-by-stage reference,
measured in the same run.

    python -m benchmarks.bench_model [--repeat 3]

Prints a table per preset: seconds per frame of ``run_chain`` (reference, fast), the ratio,
``dma_packets`` (fast chain + packing) and the float reference ``radar_cube``; the fast path's
CPU time too, which other jobs on the machine do not inflate. Goal (issue 15):
one ``full`` frame through the bit-accurate model in at most 1 s. Timing is reported, never
asserted in tests.
"""

from __future__ import annotations

import argparse
import os
import time
from collections.abc import Callable

from model.config import get_preset
from model.radar_pipeline import dma_packets, run_chain
from model.reference import radar_cube
from model.scene import table1_scene
from model.simulate import simulate_scene
from tests.oracles.chain import run_chain_reference


def best_of(fn: Callable[[], object], repeat: int, clock=time.perf_counter) -> float:
    """Best time of ``repeat`` calls, s (wall clock, or ``time.process_time`` for CPU)."""
    times = []
    for _ in range(repeat):
        t0 = clock()
        fn()
        times.append(clock() - t0)
    return min(times)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3, help="runs per cell; best is reported")
    args = ap.parse_args()
    print(f"CPU cores: {os.cpu_count()}, load average {os.getloadavg()[0]:.1f}, "
          f"best of {args.repeat} runs (reference: 1 run)")
    print(f"{'preset':<11} {'reference s':>11} {'fast s':>8} {'ratio':>6} {'fast cpu s':>10} "
          f"{'dma_packets s':>13} {'float ref s':>11} {'goal':>8}")
    for preset in ("paper-fpga", "full"):
        cfg = get_preset(preset)
        adc = simulate_scene(table1_scene(preset, seed=1)).samples
        t_ref = best_of(lambda a=adc, c=cfg: run_chain_reference(a, c), 1)
        t_fast = best_of(lambda a=adc, c=cfg: run_chain(a, c), args.repeat)
        cpu_fast = best_of(lambda a=adc, c=cfg: run_chain(a, c), args.repeat,
                           time.process_time)
        t_dma = best_of(lambda a=adc, c=cfg: dma_packets([a], c), args.repeat)
        t_float = best_of(lambda a=adc, c=cfg: radar_cube(a, c), args.repeat)
        goal = ""
        if preset == "full":
            goal = "<= 1 s: wall " + ("met" if t_fast <= 1.0 else "MISSED") + ", CPU " + (
                "met" if cpu_fast <= 1.0 else "MISSED")
        print(f"{preset:<11} {t_ref:>11.3f} {t_fast:>8.3f} {t_ref / t_fast:>6.1f} "
              f"{cpu_fast:>10.3f} {t_dma:>13.3f} {t_float:>11.3f} {goal:>8}")
    print("fast cpu s: CPU time of the fast path (close to its wall time on an idle machine)")


if __name__ == "__main__":
    main()
