"""Benchmark of ``radar_pipeline``: frame period, latency and frames per second at 100 MHz,
against the ideal (one sample per clock per lane), the paper (3.79 frames/s, 766 Mbit/s over
Gigabit Ethernet) and the ADC rate each preset needs. Also Verilator's simulation speed.

Runs the cocotb test ``throughput_latency`` of ``test_radar_pipeline.py`` (builds shared with
the regression under ``sim_build/``). The ``full`` preset's row is computed from the
measured per-sample throughput: its 128 Mib corner turn is too large to simulate here (and
needs external DDR4 on the ZCU106, see docs/buffers.md).

    tools/venv-run python tb/radar_pipeline/bench_radar_pipeline.py
"""

from __future__ import annotations

import json
import os
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path[:0] = [str(HERE.parents[1]), str(HERE)]

from test_radar_pipeline import CONFIGS  # noqa: E402

from model.axis_packetizer import packets_per_frame  # noqa: E402
from model.config import get_preset  # noqa: E402
from model.hdl import FPGA_CLOCK_HZ  # noqa: E402
from model.radar_pipeline import PipelineParams  # noqa: E402
from rtlsim.pipeline_rtl import PIPELINE_SOURCES  # noqa: E402
from rtlsim.toolchain import rtl_sources, run_cocotb  # noqa: E402

PAPER_FPS = 3.79
PAPER_LINK_BPS = 766e6


def measure(name: str) -> dict:
    cfg, chain = CONFIGS[name]
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "bench.json"
        run_cocotb("radar_pipeline", rtl_sources(*PIPELINE_SOURCES), "test_radar_pipeline",
                   HERE, chain.hdl_parameters(cfg),
                   extra_env={"RP_BENCH_JSON": str(out)}, testcase="throughput_latency")
        return json.loads(out.read_text())


def main() -> None:
    os.environ.setdefault("COCOTB_LOG_LEVEL", "WARNING")
    rows = []
    for name in CONFIGS:
        r = measure(name)
        cfg, chain = CONFIGS[name]
        rows.append((name, cfg, r["period_cycles"], r["latency_cycles"],
                     r["sim_cycles"] / r["wall_s"], "simulated"))
    full = get_preset("full")
    chain = PipelineParams(packet_words=1023)
    words = full.num_tx * full.n_range * full.n_doppler
    # structure: the corner turn releases a frame once it is complete, then the Doppler FFT
    # (about 2 N) and the packetizer's store-and-forward (one packet) follow
    rows.append(("full", full, words + packets_per_frame(words, chain.packet_words),
                 words + 2 * full.n_doppler + chain.packet_words, float("nan"),
                 "computed, not simulated"))
    print(f"{'set':<11} {'lanes':>5} {'frame samples':>13} {'period cyc':>10} "
          f"{'ideal':>7} {'latency cyc':>11} {'fps @100MHz':>11} {'radar fps':>9} "
          f"{'DMA Mbit/s':>10} {'sim cyc/s':>9}  note")
    for name, cfg, period, latency, speed, note in rows:
        samples = cfg.n_chirps * cfg.n_range
        fps = FPGA_CLOCK_HZ / period
        radar_fps = 1.0 / cfg.frame_time_s if name != "small4" else float("nan")
        words = cfg.num_tx * cfg.n_range * cfg.n_doppler
        dma_mbps = (words * 32 * cfg.num_rx * radar_fps / 1e6) if name != "small4" else \
            float("nan")
        print(f"{name:<11} {cfg.num_rx:>5} {samples:>13} {period:>10} {samples:>7} "
              f"{latency:>11} {fps:>11.1f} {radar_fps:>9.1f} {dma_mbps:>10.0f} "
              f"{speed:>9.0f}  {note}")
    print(f"paper: {PAPER_FPS} frames/s over a {PAPER_LINK_BPS / 1e6:.0f} Mbit/s Ethernet link "
          f"(Xilinx FFT IP: 231/837 cycles per 64/256-point transform)")
    print("radar fps = frames the radar produces per second (1 / frame time); the chain is "
          "real-time when fps @100MHz exceeds it. DMA Mbit/s = output rate at the radar's "
          "frame rate.")


if __name__ == "__main__":
    main()
