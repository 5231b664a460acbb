"""Benchmark of the Monte-Carlo layer (``campaign.runner``): the same campaign with 1 and
with 2 tasks in flight on one local Ray of 2 CPUs, in the same run, and the speed-up (goal:
2 workers >= 1.8x one). The tasks are the detection curves' noise-only maps (64 x 128
cells, 64 channels, every detector at two Pfa), each a fraction of a second of numpy work;
BLAS / OpenMP pools get one thread per worker (Ray's default for a 1-CPU task). Prints the
1-minute load average before and after: on a shared machine other processes take CPU time
from the workers, and the speed-up says so.

    python -m benchmarks.bench_ray [--tasks 16] [--maps 2]
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

from campaign.runner import RaySession, run, split


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--tasks", type=int, default=16, help="tasks per run (default 16)")
    ap.add_argument("--maps", type=int, default=2, help="maps per task (default 2)")
    args = ap.parse_args()
    tasks = split("detection", {"swerling": 0, "cell_snr_db": None, "pfas": [1e-4, 1e-6],
                                "shape": [64, 128]}, args.tasks * args.maps, args.maps)
    load0 = os.getloadavg()[0]
    session = RaySession(workers=2)
    t0 = time.perf_counter()
    session.open()
    startup = time.perf_counter() - t0
    try:
        with tempfile.TemporaryDirectory() as tmp:
            run(tasks[:2], 0, Path(tmp) / "warm.jsonl", workers=2)    # workers import once
            times = {}
            results = {}
            for workers in (1, 2):
                t0 = time.perf_counter()
                results[workers] = run(tasks, 1, Path(tmp) / f"w{workers}.jsonl",
                                       workers=workers)
                times[workers] = time.perf_counter() - t0
    finally:
        session.close()
    load1 = os.getloadavg()[0]
    print(f"local Ray start-up: {startup:.1f} s; {len(tasks)} tasks of {args.maps} maps")
    print("| tasks in flight | wall s | tasks/s |")
    print("|---|---|---|")
    for w, t in times.items():
        print(f"| {w} | {t:.2f} | {len(tasks) / t:.2f} |")
    print(f"speed-up 2 vs 1: {times[1] / times[2]:.2f}x (goal >= 1.8x); results identical: "
          f"{results[1] == results[2]}; 1-min load average {load0:.2f} before, "
          f"{load1:.2f} after, on {os.cpu_count()} CPUs")


if __name__ == "__main__":
    main()
