"""Soak regression: many ``paper-fpga`` frames through the Verilated ``radar_pipeline`` (C++
harness) with random ADC gaps, DMA stalls, external-memory latency and stalls, and periodic
resets; every frame bit-exact against the bit-accurate model, every status counter as the
model predicts.

    python -m rtlsim.harness.soak [--frames 1000] [--chunk 50] [--reset-every 10]
                                  [--store both|0|1] [--seed 1]

Frames are the Table I scene's consecutive frames (independent noise). They go in chunks,
one harness run each. With ``--store both`` (default) the chunks alternate between the top
with the on-chip corner turn (FRAME_STORE = 0) and the top with the external frame store
(FRAME_STORE = 1, the harness's AXI4 memory: per chunk a random latency and random stalls on
all five channels). Each chunk takes the next timing profile of its variant in turn (ADC
rate, chirp gaps, DMA and memory stall rates; the DMA and the memory always faster on
average than the ADC, so no frame may be lost) with a random seed (and memory latency), and
resets the top every ``--reset-every`` frames (frame ids restart at 0). While the harness
runs a chunk, the model computes the next chunk's expected packets and FFT overflow beats
(``model.radar_pipeline.dma_frames``).

Checks per frame: its DMA packets equal the model's. Checks per reset segment: every status
counter the harness reads equals :func:`expected_status` (the FFT overflow flag and count
from the model's overflow beats, the frame/chirp/packet counts, every loss and error counter
zero, the memory beats of the store's bursts). Prints a table of frames, cycles, payload and
status mismatches and wall time per variant; exit status 1 on any mismatch.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

from model.config import RadarConfig, get_preset
from model.frame_store_axi import read_bursts, write_bursts
from model.radar_pipeline import FrameDma, PipelineParams, dma_frames
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
"""Timing profiles of the on-chip corner turn (harness options); DMA ready rate above the
ADC valid rate in each."""

STORE_PROFILES = (
    {"adc_gap": 0.0, "chirp_gap": 192, "dma_stall": 0.3, "mem_stall": 0.3},
    {"adc_gap": 0.5, "chirp_gap": 0, "dma_stall": 0.3, "mem_stall": 0.2},
    {"adc_gap": 0.7, "chirp_gap": 0, "dma_stall": 0.5, "mem_stall": 0.5},
    {"adc_gap": 0.4, "chirp_gap": 0, "dma_stall": 0.0, "mem_stall": 0.1},
)
"""Timing profiles of the external frame store: the memory's ready rate (each burst also
waits ``mem_latency``, drawn per chunk from :data:`MEM_LATENCY`) above the ADC valid rate."""
MEM_LATENCY = (4, 100)
"""Range of the memory model's read/write-response latency in clocks, drawn per chunk."""

STATUS_ZERO = ("status_adc_overflow", "status_dma_overflow", "status_framing_error",
               "adc_chirps_dropped", "dma_words_dropped", "framing_error_count",
               "frames_damaged", "chirps_filled", "chirps_discarded", "status_truncated",
               "detections", "record_frames", "status_mem_error", "mem_error_count")
"""Status counters of the radar-cube top that stay zero for loss-free, well-framed input."""


def expected_status(frames: Sequence[FrameDma], cfg: RadarConfig, chain: PipelineParams
                    ) -> dict[str, tuple[int, int]]:
    """The status a loss-free reset segment of ``frames`` (model results, first frame right
    after the reset) leaves in a radar-cube top (``output_mode`` 0): per status name the
    allowed range ``(lo, hi)``, ``lo == hi`` for all but one.

    ``fft_overflow_count`` counts the clocks with a pulse of either FFT's ``event_overflow``
    (rtl/top/radar_pipeline.sv): the sum of the model's range and Doppler overflow beats when
    only one FFT saturated in the segment; when both did, a range FFT beat of frame k+1 may
    share its clock with a Doppler FFT beat of frame k (timing dependent), so the count lies
    between the larger sum and the total. ``mem_*``: the harness's memory model (FRAME_STORE
    = 1): the beats of the store's write and read bursts (``model.frame_store_axi``).
    """
    if chain.output_mode != 0:
        raise ValueError("expected_status: radar-cube top (output_mode 0) only")
    n = len(frames)
    rng_ov = sum(f.range_overflow for f in frames)
    dop_ov = sum(f.doppler_overflow for f in frames)
    want = {name: (0, 0) for name in STATUS_ZERO}
    exact = {"frames": n, "chirps_in": n * cfg.n_chirps, "frames_turned": n, "frames_out": n,
             "packets_out": sum(len(f.packets) for f in frames),
             "status_fft_overflow": int(rng_ov + dop_ov > 0)}
    want.update({k: (v, v) for k, v in exact.items()})
    want["fft_overflow_count"] = ((max(rng_ov, dop_ov) if rng_ov and dop_ov else rng_ov + dop_ov),
                                  rng_ov + dop_ov)
    if chain.frame_store:
        g = chain.store_geometry(cfg)
        beats_w = sum(int(write_bursts(g, k)[:, 1].sum()) for k in range(n))
        beats_r = sum(int(read_bursts(g, k)[:, 1].sum()) for k in range(n))
        want.update(mem_writes=(beats_w, beats_w), mem_reads=(beats_r, beats_r),
                    mem_protocol_errors=(0, 0))
    return want


def status_mismatches(got: dict[str, int], want: dict[str, tuple[int, int]]) -> list[str]:
    """``name got (want lo..hi)`` for every expected status outside its range (missing
    ones included)."""
    bad = []
    for name, (lo, hi) in want.items():
        v = got.get(name)
        if v is None or not lo <= v <= hi:
            bad.append(f"{name} {v} (model {lo}" + (f"..{hi})" if hi != lo else ")"))
    return bad


def payload_mismatches(run: HarnessRun, want: Sequence[FrameDma]) -> int:
    """Frames whose packets differ from the model (missing packets count as mismatches,
    extra packets as one more)."""
    bad, i = 0, 0
    for frame in want:
        got = run.packets[i:i + len(frame.packets)]
        i += len(frame.packets)
        if len(got) != len(frame.packets) or not all(
                g.shape == w.shape and np.array_equal(g, w)
                for g, w in zip(got, frame.packets, strict=True)):
            bad += 1
    return bad + (1 if i != len(run.packets) else 0)


@dataclass
class Tally:
    """Totals of one soak variant (one row of the table)."""

    frames: int = 0
    cycles: int = 0
    payload_bad: int = 0
    status_bad: int = 0
    wall_s: float = 0.0
    cpu_s: float = 0.0

    def add(self, t: Tally) -> None:
        self.frames += t.frames
        self.cycles += t.cycles
        self.payload_bad += t.payload_bad
        self.status_bad += t.status_bad
        self.wall_s += t.wall_s
        self.cpu_s += t.cpu_s


@dataclass(frozen=True)
class Chunk:
    """One harness run: its first frame, ADC frames, top variant and harness options."""

    start: int
    frames: list[np.ndarray]
    store: bool
    options: dict


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--frames", type=int, default=1000, help="paper-fpga frames in all")
    ap.add_argument("--chunk", type=int, default=50,
                    help="frames per harness run (rounded to whole reset segments)")
    ap.add_argument("--reset-every", type=int, default=10, help="frames between resets")
    ap.add_argument("--store", choices=("both", "0", "1"), default="both",
                    help="FRAME_STORE of the top: both (alternate chunks, default), 0 (on-chip "
                         "corner turn) or 1 (external frame store, AXI4 memory model)")
    ap.add_argument("--seed", type=int, default=1, help="scene noise and timing seed")
    args = ap.parse_args(argv)
    if args.frames < 1 or args.chunk < 1 or args.reset_every < 1:
        ap.error("--frames, --chunk and --reset-every must be >= 1")
    chunk = max(args.reset_every, args.chunk // args.reset_every * args.reset_every)
    stores = {"both": (False, True), "0": (False,), "1": (True,)}[args.store]
    cfg = get_preset("paper-fpga")
    chains = {False: PipelineParams(), True: PipelineParams(frame_store=True)}
    scene = table1_scene("paper-fpga", seed=args.seed)
    rng = np.random.default_rng(args.seed)
    t_build = time.perf_counter()
    for store in stores:
        build_harness(cfg, chains[store])
    t0, cpu0 = time.perf_counter(), time.process_time() + cpu_children()
    print(f"soak: {args.frames} paper-fpga frames, chunks of {chunk}, reset every "
          f"{args.reset_every} frames, FRAME_STORE {'/'.join(str(int(s)) for s in stores)} "
          f"(harnesses built/checked in {t0 - t_build:.1f} s)")

    def chunk_at(start: int) -> Chunk | None:
        if start >= args.frames:
            return None
        k, n_var = start // chunk, len(stores)
        store = stores[k % n_var]
        if store:       # profiles in turn (each one runs), seeds and latency drawn
            opts = dict(STORE_PROFILES[k // n_var % len(STORE_PROFILES)])
            opts["mem_latency"] = int(rng.integers(MEM_LATENCY[0], MEM_LATENCY[1] + 1))
        else:
            opts = dict(PROFILES[k // n_var % len(PROFILES)])
        opts["seed"] = int(rng.integers(1 << 31))
        frames = [simulate_scene(scene, k).samples
                  for k in range(start, min(start + chunk, args.frames))]
        return Chunk(start, frames, store, opts)

    def model_of(c: Chunk) -> list[list[FrameDma]]:
        r = args.reset_every
        return [dma_frames(c.frames[s:s + r], cfg, chains[c.store])
                for s in range(0, len(c.frames), r)]

    tallies = {store: Tally() for store in stores}
    with ThreadPoolExecutor(max_workers=1) as pool:
        cur = chunk_at(0)
        while cur is not None:
            fut = pool.submit(run_harness, cur.frames, cfg, chains[cur.store],
                              segment_frames=args.reset_every, **cur.options)
            want = model_of(cur)                     # overlaps the harness run
            nxt = chunk_at(cur.start + len(cur.frames))
            run = fut.result()
            bad = payload_mismatches(run, [f for seg in want for f in seg])
            st_bad = [m for seg, w in zip(run.segments, want, strict=True)
                      for m in status_mismatches(seg, expected_status(w, cfg,
                                                                      chains[cur.store]))]
            if len(run.segments) != len(want):
                st_bad.append(f"{len(run.segments)} segments, expected {len(want)}")
            tallies[cur.store].add(Tally(len(cur.frames), run.cycles, bad, len(st_bad),
                                         run.wall_s, run.cpu_s))
            ovf = sum(s["fft_overflow_count"] for s in run.segments)
            print(f"  frames {cur.start:>4}..{cur.start + len(cur.frames) - 1:<4} "
                  f"FRAME_STORE {int(cur.store)} {cur.options}: {run.cycles} cycles, "
                  f"{run.cycles / run.wall_s:,.0f} cycles/s, FFT overflow beats {ovf}, "
                  f"payload mismatches {bad}, status mismatches {len(st_bad)}"
                  + (f": {'; '.join(st_bad[:6])}" if st_bad else ""), flush=True)
            cur = nxt
    wall = time.perf_counter() - t0
    return report(tallies, wall, time.process_time() + cpu_children() - cpu0)


def cpu_children() -> float:
    """CPU seconds of the finished harness processes."""
    import resource

    ru = resource.getrusage(resource.RUSAGE_CHILDREN)
    return ru.ru_utime + ru.ru_stime


def report(tallies: dict[bool, Tally], wall: float, cpu: float) -> int:
    """Print the table (``wall`` / ``cpu``: seconds of the whole soak, builds excluded);
    1 if any frame or status mismatched, else 0."""
    total = Tally()
    print(f"{'top':<20} {'frames':>6} {'cycles':>11} {'payload':>8} {'status':>8} "
          f"{'RTL wall':>8} {'RTL CPU':>8} {'cyc/CPU-s':>9}")
    print(f"{'':<20} {'':>6} {'':>11} {'mismatch':>8} {'mismatch':>8} {'s':>8} {'s':>8}")

    def row(name: str, t: Tally) -> None:
        print(f"{name:<20} {t.frames:>6} {t.cycles:>11,} {t.payload_bad:>8} {t.status_bad:>8} "
              f"{t.wall_s:>8.1f} {t.cpu_s:>8.1f} {t.cycles / max(t.cpu_s, 1e-9):>9,.0f}")

    for store, t in tallies.items():
        total.add(t)
        row("FRAME_STORE 1 (AXI4)" if store else "FRAME_STORE 0", t)
    row("total", total)
    print(f"wall time {wall:.1f} s, CPU {cpu:.1f} s (harness runs overlapped with the model "
          f"and the scene simulation; on a loaded machine the CPU time is the stable figure)")
    return 1 if total.payload_bad or total.status_bad else 0


if __name__ == "__main__":
    sys.exit(main())
