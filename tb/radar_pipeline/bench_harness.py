"""Benchmark: the Verilator-native C++ harness against the cocotb path, same RTL, same run.

    tools/venv-run python tb/radar_pipeline/bench_harness.py [--frames 3] [--full]

Rows (``paper-fpga`` top, frames back to back at one sample per clock, DMA always ready):
clocks simulated, the simulation loop's cycles per second and the end-to-end wall time per
frame (build excluded, process start, file I/O and the Python side included) of

- cocotb: ``run_pipeline_rtl`` (cocotb + cocotbext-axi driving every clock from Python);
- harness: ``run_pipeline`` (C++ main, ``rtlsim/harness/main.cpp``);

and their ratio (goal: >= 100x cycles/s). ``--full`` adds one ``full``-preset frame through
the harness (16 lanes, 128 Mib corner turn; goal <= 20 s; the first build takes minutes).
Timing is reported, never asserted in tests.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

os.environ.setdefault("COCOTB_LOG_LEVEL", "WARNING")
HERE = Path(__file__).resolve().parent
sys.path[:0] = [str(HERE.parent), str(HERE)]

from bench_radar_pipeline import measure  # noqa: E402

from model.config import get_preset  # noqa: E402
from model.radar_pipeline import PipelineParams, dma_packets  # noqa: E402
from model.scene import table1_scene  # noqa: E402
from model.simulate import simulate_scene  # noqa: E402
from rtlsim.harness import build_harness, run_harness  # noqa: E402
from rtlsim.pipeline_rtl import run_pipeline_rtl  # noqa: E402
from rtlsim.toolchain import SIM_BUILD  # noqa: E402


def cocotb_loop_speed() -> tuple[float, float]:
    """Cycles per wall second and per CPU second of the cocotb simulation loop alone (the
    ``throughput_latency`` test of tb/radar_pipeline, 3 paper-fpga frames, via its benchmark
    script)."""
    r = measure("paper-fpga")
    return r["sim_cycles"] / r["wall_s"], r["sim_cycles"] / r["cpu_s"]


def frames_of(preset: str, n: int):
    scene = table1_scene(preset, seed=1)
    return [simulate_scene(scene, k).samples for k in range(n)]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--frames", type=int, default=3)
    ap.add_argument("--full", action="store_true", help="also one full-preset frame")
    args = ap.parse_args()
    cfg, chain = get_preset("paper-fpga"), PipelineParams()
    frames = frames_of("paper-fpga", args.frames)
    want = [p.tobytes() for p in dma_packets(frames, cfg, chain)]
    build_harness(cfg, chain)
    t0 = time.perf_counter()
    run = run_harness(frames, cfg, chain)
    t_h = time.perf_counter() - t0
    assert run.packet_bytes() == want, "harness output differs from the model"
    h_speed = run.cycles / run.wall_s
    # the cocotb path: time a run once built (a warm-up run builds it)
    run_pipeline_rtl(frames[:1], cfg, chain)
    t0 = time.perf_counter()
    pk, _ = run_pipeline_rtl(frames, cfg, chain)
    t_c = time.perf_counter() - t0
    assert list(pk) == want, "cocotb output differs from the model"
    h_cpu = run.cycles / run.cpu_s
    c_e2e = run.cycles / t_c      # same clocks (same stimulus, no gaps)
    c_loop, c_cpu = cocotb_loop_speed()
    print(f"CPU cores: {os.cpu_count()}, load average {os.getloadavg()[0]:.1f}; "
          f"{args.frames} paper-fpga frames, {run.cycles} clocks, no gaps or stalls")
    print(f"{'path':<9} {'loop cyc/s':>10} {'cyc/CPU-s':>10} {'e2e cyc/s':>10} {'s/frame':>8} "
          f"{'loop ratio':>10} {'CPU ratio':>9} {'e2e ratio':>9}")
    print(f"{'cocotb':<9} {c_loop:>10,.0f} {c_cpu:>10,.0f} {c_e2e:>10,.0f} "
          f"{t_c / args.frames:>8.2f} {1.0:>10.1f} {1.0:>9.1f} {1.0:>9.1f}")
    print(f"{'harness':<9} {h_speed:>10,.0f} {h_cpu:>10,.0f} {run.cycles / t_h:>10,.0f} "
          f"{t_h / args.frames:>8.3f} {h_speed / c_loop:>10.1f} {h_cpu / c_cpu:>9.1f} "
          f"{t_c / t_h:>9.1f}")
    print("loop: the simulation loop alone, per wall second (goal: harness >= 100x cocotb); "
          "CPU: the same loop per CPU second of its process (what holds when other jobs share "
          "the cores); e2e: the whole call (process start, files, Python side; build "
          "excluded)")
    if args.full:
        full = get_preset("full")
        t0 = time.perf_counter()
        build_harness(full, chain)
        t_b = time.perf_counter() - t0
        ff = frames_of("full", 1)
        t0 = time.perf_counter()
        fr = run_harness(ff, full, chain)
        t_f = time.perf_counter() - t0
        ok = fr.packet_bytes() == [p.tobytes() for p in dma_packets(ff, full, chain)]
        print(f"{'full':<9} {fr.cycles / fr.wall_s:>10,.0f} {t_f:>8.2f} {'':>6}  one full "
              f"frame ({fr.cycles} clocks, bit-exact {ok}, goal <= 20 s; build/check "
              f"{t_b:.0f} s, {SIM_BUILD.name}/)")


if __name__ == "__main__":
    main()
