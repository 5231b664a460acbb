"""Benchmark of ``frame_store_axi`` (the corner turn in external DDR4 over AXI4): AXI bytes per
frame, bandwidth as a fraction of the AXI port's peak with an always-ready memory and with
30 % random stalls on all five channels, burst-length histogram, DRAM row hits under the
page model of ``model.frame_store_axi.DramPageModel``, and whether ``full`` is real time at the
radar's 111 frames/s.

Two parts: (1) the model's address trace for the two presets (exact burst lists, no
simulation); (2) the Verilated RTL with cocotbext-axi's AxiRam, payload checked bit-exact
against the model: by default a reduced ``full``-like geometry (4 TX x 16 lanes, 64 x 64,
512-bit port); ``--full`` runs the real ``full`` frame (4 x 16 lanes, 256 x 256: 16 MiB per
frame; slow: tens of minutes on a shared machine).

    tools/venv-run python tb/frame_store_axi/bench_frame_store_axi.py [--full] [--frames N]
"""

from __future__ import annotations

import argparse
import json
import os
import tempfile
from collections import Counter
from pathlib import Path

from model import frame_store_axi as fs
from model.config import get_preset
from model.hdl import FPGA_CLOCK_HZ
from rtlsim.toolchain import rtl_sources, run_cocotb

HERE = Path(__file__).resolve().parent

"""Pipeline (and AXI port) clock: the chain's 100 MHz."""
DRAM_PEAK = 64 / 8 * 2400e6
"""ZCU106 PL DDR4 through MIG: 64-bit bus at 2400 MT/s = 19.2 GB/s (shared by both
directions; MIG's AXI port is 512 bits at 300 MHz)."""

PRESET_STORES = {
    # name: (preset, tile_r, axi_data_w, read_order); "m1": READ_ORDER 1 (on-chip detection,
    # (r, t, d)), whose buffer holds NUM_TX strips per group
    "paper-fpga": ("paper-fpga", 16, 128, 0),
    "paper-fpga/32": ("paper-fpga", 32, 128, 0),
    "full": ("full", 16, 512, 0),
    "full/32": ("full", 32, 512, 0),
    "full-m1/4": ("full", 4, 512, 1),
    "full-m1/8": ("full", 8, 512, 1),
    "full-m1/16": ("full", 16, 512, 1),
}


def geometry(preset: str, tile_r: int, axi_data_w: int, read_order: int = 0
             ) -> fs.StoreGeometry:
    c = get_preset(preset)
    return fs.StoreGeometry(num_tx=c.num_tx, num_rx=c.num_rx, n_range=c.n_range,
                            n_doppler=c.n_doppler, tile_r=tile_r, axi_data_w=axi_data_w,
                            read_order=read_order)


def hist_text(trace: list[tuple[int, int, str]]) -> str:
    h = Counter((k, b) for _, b, k in trace)
    return ", ".join(f"{k}x{b}: {n}" for (k, b), n in sorted(h.items()))


def model_table() -> None:
    pm = fs.DramPageModel()
    print("Model: address layout per preset (steady state, 4 frames; write of k+1 interleaved "
          "with read of k)")
    print(f"{'preset':<13} {'AXI':>4} {'TILE_R':>6} {'frame MiB':>9} {'mem MiB':>7} "
          f"{'AXI MB/frame':>12} {'buffer Mib':>10} {'need GB/s':>9} {'port GB/s':>9} "
          f"{'of port':>7} {'of DDR4':>7} {'row hits':>8}  bursts per frame (dir x beats)")
    for name, (preset, tile_r, axi_w, order) in PRESET_STORES.items():
        g = geometry(preset, tile_r, axi_w, order)
        fps = 1.0 / get_preset(preset).frame_time_s
        trace = fs.interleaved_trace(g, 4)
        hits, total = pm.row_hits(trace, g.axi_bytes)
        one = fs.interleaved_trace(g, 1)
        need = 2 * g.frame_bytes * fps                      # write + read per second
        port = 2 * g.axi_bytes * FPGA_CLOCK_HZ                   # AW/W and AR/R run concurrently
        print(f"{name:<13} {axi_w:>4} {tile_r:>6} {g.frame_bytes / 2**20:>9.2f} "
              f"{g.memory_bytes / 2**20:>7.2f} {2 * g.frame_bytes / 1e6:>12.2f} "
              f"{g.strip_buffer_bits / 2**20:>10.2f} {need / 1e9:>9.2f} {port / 1e9:>9.2f} "
              f"{need / port:>7.1%} {need / DRAM_PEAK:>7.1%} {hits / total:>8.2%}  "
              f"{hist_text(one)}")
    print(f"page model: {pm.page_bytes} B rows, {pm.banks} banks, ROW_BANK_COLUMN map, "
          f"{pm.access_bytes} B accesses (BL8 x 64 bit); DDR4 peak {DRAM_PEAK / 1e9:.1f} GB/s; "
          f"port = {FPGA_CLOCK_HZ / 1e6:.0f} MHz x AXI width, both directions")


def rtl_params(full: bool) -> dict:
    n = 256 if full else 64
    return dict(NUM_TX=4, NUM_RX=16, N_RANGE=n, N_DOPPLER=n, DATA_W=16, TILE_R=16,
                AXI_DATA_W=512, AXI_ADDR_W=32, AXI_ID_W=1, MAX_OUTSTANDING=8, WFIFO_DEPTH=64,
                MEM_BASE=0)


def measure(params: dict, stall: float, frames: int) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "bench.json"
        run_cocotb("frame_store_axi", rtl_sources("common/*.sv", "buffers/*.sv"),
                   "test_frame_store_axi", HERE, params,
                   extra_env={"FS_BENCH_JSON": str(out), "FS_BENCH_STALL": str(stall),
                              "FS_BENCH_FRAMES": str(frames)}, testcase="bench")
        return json.loads(out.read_text())


def rtl_table(full: bool, frames: int) -> None:
    p = rtl_params(full)
    g = fs.StoreGeometry(num_tx=p["NUM_TX"], num_rx=p["NUM_RX"], n_range=p["N_RANGE"],
                         n_doppler=p["N_DOPPLER"], tile_r=p["TILE_R"],
                         axi_data_w=p["AXI_DATA_W"])
    cfg = get_preset("full")
    full_words = cfg.num_tx * cfg.n_range * cfg.n_doppler
    fps_need = 1.0 / cfg.frame_time_s
    beats = g.frame_bytes // g.axi_bytes
    print(f"\nRTL (Verilator + AxiRam), {p['NUM_TX']} TX x {p['NUM_RX']} lanes, "
          f"{p['N_RANGE']} x {p['N_DOPPLER']}, AXI {p['AXI_DATA_W']} bits, {frames} frames, "
          f"payload bit-exact vs model")
    print(f"{'memory':<16} {'period cyc':>10} {'ideal':>7} {'of port':>7} {'latency cyc':>11} "
          f"{'row hits':>8} {'full fps @100MHz':>16} {'real time (111/s)':>17} "
          f"{'sim cyc/s':>9}  bursts")
    pm = fs.DramPageModel()
    for stall in (0.0, 0.3):
        r = measure(p, stall, frames)
        assert r["status"]["mem_error_count"] == 0 and r["status"]["frames_out"] == frames
        period = r["period_cycles"]
        hits, total = pm.row_hits([tuple(t) for t in r["trace"]], g.axi_bytes)
        # full-size frame period scales with the frame's words (the store is streaming)
        full_period = period * full_words / g.frame_words
        fps = FPGA_CLOCK_HZ / full_period
        label = "always ready" if stall == 0 else f"{stall:.0%} random stalls"
        print(f"{label:<16} {period:>10} {beats:>7} {beats / period:>7.1%} "
              f"{r['latency_cycles']:>11} {hits / total:>8.2%} {fps:>16.0f} "
              f"{('yes, x%.1f margin' % (fps / fps_need)) if fps > fps_need else 'NO':>17} "
              f"{r['sim_cycles'] / r['wall_s']:>9.0f}  "
              f"{hist_text([tuple(t) for t in r['trace']])}")
    print("period = clocks between frames leaving in steady state with saturated input and "
          "output; ideal = AXI beats per frame per direction (one beat per clock each way); "
          "of port = ideal / period (both directions move a frame per period).")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--full", action="store_true",
                    help="simulate the real full-preset frame (16 MiB; slow)")
    ap.add_argument("--frames", type=int, default=3, help="frames per RTL run (>= 2)")
    ap.add_argument("--model-only", action="store_true", help="skip the RTL runs")
    a = ap.parse_args()
    if a.frames < 2:
        ap.error("--frames must be at least 2 (the period is measured between frames)")
    os.environ.setdefault("COCOTB_LOG_LEVEL", "WARNING")
    model_table()
    if not a.model_only:
        rtl_table(a.full, a.frames)


if __name__ == "__main__":
    main()
