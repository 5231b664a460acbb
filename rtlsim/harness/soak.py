"""Soak regression: many ``paper-fpga`` frames through the Verilated ``radar_pipeline`` (C++
harness) with random ADC gaps, DMA stalls and periodic resets; every frame bit-exact
against the bit-accurate model.

    python -m rtlsim.harness.soak [--frames 1000] [--chunk 50] [--reset-every 10] [--seed 1]

Frames are the Table I scene's consecutive frames (independent noise). They go in chunks,
one harness run each, with a timing profile drawn per chunk (ADC rate, chirp gaps, DMA
stall rate; the DMA always faster on average than the ADC, so no frame may be lost) and a
reset every ``--reset-every`` frames (frame ids restart at 0). While the harness runs a
chunk, the model computes the next chunk's expected packets. Prints frames, cycles,
mismatches (must be 0) and wall time; exit status 1 on any mismatch.
"""

from __future__ import annotations

import argparse
import sys
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from model.config import get_preset
from model.radar_pipeline import PipelineParams, dma_packets
from model.scene import table1_scene
from model.simulate import simulate_scene
from rtlsim.harness import HarnessRun, build_harness, run_harness

PROFILES = (
    {"adc_gap": 0.0, "chirp_gap": 64, "dma_stall": 0.3},
    {"adc_gap": 0.3, "chirp_gap": 0, "dma_stall": 0.2},
    {"adc_gap": 0.5, "chirp_gap": 0, "dma_stall": 0.4},
    {"adc_gap": 0.7, "chirp_gap": 0, "dma_stall": 0.6},
    {"adc_gap": 0.2, "chirp_gap": 0, "dma_stall": 0.0},
)
"""Timing profiles (harness options); DMA ready rate above the ADC valid rate in each."""


def expected(frames: list[np.ndarray], reset_every: int, chain: PipelineParams
             ) -> list[list[np.ndarray]]:
    """Model packets of each frame (frame ids restart after every reset)."""
    cfg = get_preset("paper-fpga")
    return [dma_packets([f], cfg, chain, first_frame_id=k % reset_every)
            for k, f in enumerate(frames)]


def count_mismatches(run: HarnessRun, want: list[list[np.ndarray]]) -> int:
    """Frames whose packets differ from the model (missing packets count as mismatches)."""
    bad, i = 0, 0
    for pkts in want:
        got = run.packets[i:i + len(pkts)]
        i += len(pkts)
        if len(got) != len(pkts) or not all(
                g.shape == w.shape and np.array_equal(g, w) for g, w in zip(got, pkts,
                                                                           strict=True)):
            bad += 1
    return bad + (1 if i != len(run.packets) else 0)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--frames", type=int, default=1000)
    ap.add_argument("--chunk", type=int, default=50, help="frames per harness run")
    ap.add_argument("--reset-every", type=int, default=10, help="frames between resets")
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args(argv)
    if args.frames < 1 or args.chunk < 1 or args.reset_every < 1:
        ap.error("--frames, --chunk and --reset-every must be >= 1")
    chunk = max(args.reset_every, args.chunk // args.reset_every * args.reset_every)
    cfg = get_preset("paper-fpga")
    chain = PipelineParams()
    scene = table1_scene("paper-fpga", seed=args.seed)
    rng = np.random.default_rng(args.seed)
    t_build = time.perf_counter()
    build_harness(cfg, chain)
    t0 = time.perf_counter()
    print(f"soak: {args.frames} paper-fpga frames, chunks of {chunk}, reset every "
          f"{args.reset_every} frames (harness built/checked in {t0 - t_build:.1f} s)")
    total_cycles = mismatches = done = 0
    sim_wall = 0.0

    def frames_of(start: int) -> list[np.ndarray]:
        return [simulate_scene(scene, k).samples
                for k in range(start, min(start + chunk, args.frames))]

    with ThreadPoolExecutor(max_workers=1) as pool:
        frames = frames_of(0)
        start = 0
        while frames:
            prof = PROFILES[int(rng.integers(len(PROFILES)))]
            seed = int(rng.integers(1 << 31))
            fut = pool.submit(run_harness, frames, cfg, chain, seed=seed,
                              segment_frames=args.reset_every, **prof)
            want = expected(frames, args.reset_every, chain)    # overlaps the harness run
            nxt = start + len(frames)
            next_frames = frames_of(nxt) if nxt < args.frames else []
            run = fut.result()
            bad = count_mismatches(run, want)
            st_bad = sum(s["status_adc_overflow"] + s["status_fft_overflow"]
                         + s["status_framing_error"] + s["frames_damaged"]
                         for s in run.segments)
            mismatches += bad
            total_cycles += run.cycles
            sim_wall += run.wall_s
            done += len(frames)
            print(f"  frames {start:>5}..{nxt - 1:<5} {prof} seed {seed}: {run.cycles} cycles, "
                  f"{run.cycles / run.wall_s:,.0f} cycles/s, mismatches {bad}"
                  + (f", STATUS FLAGS {run.segments}" if st_bad else ""), flush=True)
            mismatches += 1 if st_bad else 0
            frames, start = next_frames, nxt
    wall = time.perf_counter() - t0
    print(f"frames {done}, cycles {total_cycles}, mismatches {mismatches}, wall {wall:.1f} s "
          f"(RTL {sim_wall:.1f} s, {total_cycles / max(sim_wall, 1e-9):,.0f} cycles/s)")
    return 1 if mismatches else 0


if __name__ == "__main__":
    sys.exit(main())
