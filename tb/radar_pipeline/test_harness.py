"""The Verilator-native harness (``rtlsim.harness``, C++ main) against the bit-accurate
model and against the cocotb path, on the small 4-TX parameter set of
``test_radar_pipeline.py`` (one harness build, seconds to run).

- Same frames through the harness and through the cocotb stream test behind
  ``run_pipeline_rtl``: identical DMA bytes and counters.
- Under the cocotb testbench's own stall settings (chirp bursts + 30 % DMA stalls; 80 % ADC
  gaps + 50 % DMA stalls) and reset segments: bit-exact packets against the model, as the
  cocotb testbench checks for the same frames and settings.
- Same seed, same cycle count; DMA overload: the status counters report the dropped chirps.
"""

from __future__ import annotations

import os
import sys
from dataclasses import replace

import numpy as np
import pytest
from test_radar_pipeline import CONFIGS, adc_frames

from model.radar_pipeline import dma_frames, dma_packets
from rtlsim.harness import run_harness, run_pipeline
from rtlsim.harness.soak import expected_status, payload_mismatches, status_mismatches
from rtlsim.pipeline import assert_packets_equal
from rtlsim.pipeline_rtl import run_pipeline_rtl
from rtlsim.toolchain import RTL

NAME = "small4"
CFG, CHAIN = CONFIGS[NAME]


def test_harness_equals_cocotb_stream() -> None:
    frames = adc_frames(NAME, CFG, 2, seed=21)
    got, status = run_pipeline(frames, CFG, CHAIN, seed=4)
    want, want_status = run_pipeline_rtl(frames, CFG, CHAIN)
    assert got == want
    assert {k: status[k] for k in want_status} == want_status
    assert_packets_equal([np.frombuffer(p, "<u4").reshape(-1, CFG.num_rx) for p in got],
                         dma_packets(frames, CFG, CHAIN), "harness vs model")


@pytest.mark.parametrize(("kw", "seed"), [
    ({"chirp_gap": CONFIGS[NAME][0].n_range, "dma_stall": 0.3}, 2),
    ({"adc_gap": 0.8, "dma_stall": 0.5}, 5),
])
def test_harness_bit_exact_under_stalls(kw: dict, seed: int) -> None:
    frames = adc_frames(NAME, CFG, 3, seed=seed)
    run = run_harness(frames, CFG, CHAIN, seed=seed, **kw)
    assert_packets_equal(run.packets, dma_packets(frames, CFG, CHAIN), f"harness {kw}")
    st = run.status
    assert st["frames_out"] == 3 and st["chirps_in"] == 3 * CFG.n_chirps, st
    for flag in ("status_adc_overflow", "status_dma_overflow", "status_fft_overflow",
                 "status_framing_error"):
        assert st[flag] == 0, (flag, st)


def test_harness_reset_segments_and_determinism() -> None:
    """Five frames in segments of two (reset between): frame ids restart after each reset;
    the same seed gives the same cycle count, another seed a different one."""
    frames = adc_frames(NAME, CFG, 5, seed=9)
    kw = {"adc_gap": 0.4, "dma_stall": 0.3, "segment_frames": 2}
    run = run_harness(frames, CFG, CHAIN, seed=1, **kw)
    want = [p for k in range(0, 5, 2) for p in dma_packets(frames[k:k + 2], CFG, CHAIN)]
    assert_packets_equal(run.packets, want, "segments")
    assert [s["frames_out"] for s in run.segments] == [2, 2, 1]
    again = run_harness(frames, CFG, CHAIN, seed=1, **kw)
    other = run_harness(frames, CFG, CHAIN, seed=2, **kw)
    assert again.cycles == run.cycles != other.cycles


def test_harness_reports_dma_overload() -> None:
    """DMA ready one clock in ten while the ADC runs at full rate: the ping-pong drops
    chirps, frame_align zero-fills and discards; the status says so, and what came out
    differs from the model (run until the DMA is quiet: lost frames never arrive)."""
    frames = adc_frames(NAME, CFG, 4, seed=13)
    frame_clocks = CFG.n_chirps * CFG.n_range
    run = run_harness(frames, CFG, CHAIN, seed=3, dma_stall=0.9, quiet=20 * frame_clocks)
    st = run.status
    assert st["status_adc_overflow"] == 1 and st["adc_chirps_dropped"] > 0, st
    assert st["frames_damaged"] >= 1 and 1 <= st["frames_out"] < 4, st
    want = dma_packets(frames, CFG, CHAIN)
    assert 0 < len(run.packets) < len(want)
    assert any(not np.array_equal(g, w) for g, w in zip(run.packets, want, strict=False))


def test_harness_bad_input() -> None:
    with pytest.raises(ValueError, match="expected shape"):
        run_harness([np.zeros((3, 4, 64), complex)], CFG, CHAIN)


def saturating_frame() -> np.ndarray:
    """Full-scale DC on every lane (32767 + 32767j): the Doppler FFT saturates (4 beats on
    small4, model.radar_pipeline.dma_frames), the range FFT does not."""
    return np.full((CFG.n_chirps, CFG.num_rx, CFG.n_range), 32767 + 32767j)


@pytest.mark.parametrize("frame_store", [False, True])
def test_harness_status_as_model_predicts(frame_store: bool) -> None:
    """The soak's check (rtlsim.harness.soak): per reset segment every status counter as
    the model predicts, including the FFT overflow flag and count of frames that saturate
    (segments [scene, DC], [scene, scene], [DC]) and, FRAME_STORE = 1, the memory beats; a
    prediction without the overflow (or with a frame too few) is caught."""
    if frame_store and "FRAME_STORE" not in (RTL / "top" / "radar_pipeline.sv").read_text():
        pytest.skip("radar_pipeline has no FRAME_STORE parameter in this tree")
    scene = adc_frames(NAME, CFG, 3, seed=17)
    frames = [scene[0], saturating_frame(), scene[1], scene[2], saturating_frame()]
    kw = {"mem_latency": 30, "mem_stall": 0.3} if frame_store else {}
    run = run_harness(frames, CFG, CHAIN, seed=6, adc_gap=0.5, dma_stall=0.3,
                      segment_frames=2, frame_store=frame_store, **kw)
    model_chain = replace(CHAIN, frame_store=frame_store)   # the store's geometry: defaults
    want = [dma_frames(frames[k:k + 2], CFG, model_chain) for k in range(0, 5, 2)]
    assert payload_mismatches(run, [f for seg in want for f in seg]) == 0
    assert [s["fft_overflow_count"] for s in run.segments] == [4, 0, 4], run.segments
    for seg, w in zip(run.segments, want, strict=True):
        assert status_mismatches(seg, expected_status(w, CFG, model_chain)) == [], seg
    clean = dma_frames(scene[:2], CFG, model_chain)         # no overflow predicted
    assert any("fft_overflow_count" in m for m in
               status_mismatches(run.segments[0], expected_status(clean, CFG, model_chain)))
    assert status_mismatches(run.segments[1], expected_status(want[1][:1], CFG, model_chain))


def test_dma_frames_is_dma_packets() -> None:
    """``dma_frames`` (packets and overflow per frame) gives ``dma_packets``' packets."""
    frames = [*adc_frames(NAME, CFG, 2, seed=8), saturating_frame()]
    per_frame = dma_frames(frames, CFG, CHAIN, first_frame_id=3)
    flat = [p for f in per_frame for p in f.packets]
    assert_packets_equal(flat, dma_packets(frames, CFG, CHAIN, first_frame_id=3), "dma_frames")
    assert [(f.range_overflow, f.doppler_overflow) for f in per_frame] == [(0, 0), (0, 0),
                                                                           (0, 4)]


@pytest.mark.parametrize(("mem_latency", "mem_stall"), [(20, 0.0), (40, 0.3)])
def test_harness_frame_store(mem_latency: int, mem_stall: float) -> None:
    """FRAME_STORE = 1 top (corner turn in external memory over m_axi_mem): the harness's
    AXI4 memory model with latency and random stalls; packets bit-exact against the model,
    every frame written and read back, no AXI protocol error. Runs once radar_pipeline has
    the FRAME_STORE parameter (the external frame store's branch)."""
    if "FRAME_STORE" not in (RTL / "top" / "radar_pipeline.sv").read_text():
        pytest.skip("radar_pipeline has no FRAME_STORE parameter in this tree")
    frames = adc_frames(NAME, CFG, 3, seed=2)
    run = run_harness(frames, CFG, CHAIN, seed=3, frame_store=True, mem_latency=mem_latency,
                      mem_stall=mem_stall, dma_stall=0.2, chirp_gap=CFG.n_range)
    assert_packets_equal(run.packets, dma_packets(frames, CFG, CHAIN), "frame store")
    st = run.status
    words = 3 * CFG.num_tx * CFG.n_range * CFG.n_doppler
    assert st["mem_protocol_errors"] == 0, st
    assert st["mem_writes"] > 0 and st["mem_writes"] == st["mem_reads"], st
    assert st["frames_out"] == 3 and words % st["mem_writes"] == 0, st


def test_harness_mode1_paper_fpga_records() -> None:
    """OUTPUT_MODE = 1 (on-chip detection) on paper-fpga through ``run_pipeline`` (the RTL
    source of ``radar detect --detect fpga --backend rtl``): the record-stream packets are
    byte-identical to the model's, with DMA stalls; the detector's counters are reported.
    The ADC has idle clocks between chirps, as at its real rate: with NUM_TX = 1 the CFAR
    needs 19 456 clocks per 16 384-cell frame (docs/detect.md), so an ADC at one sample every
    clock without pause overflows the chirp ping-pong (flagged, chirps dropped)."""
    from test_radar_pipeline_detect import SETS

    cfg, chain = SETS["paper-fpga"]
    frames = adc_frames("paper-fpga", cfg, 2, seed=3)
    got, status = run_pipeline(frames, cfg, chain, seed=7, dma_stall=0.3,
                               chirp_gap=cfg.n_range // 2)
    assert status["status_adc_overflow"] == 0, status
    want = dma_packets(frames, cfg, chain)
    assert got == [np.ascontiguousarray(p, "<u4").tobytes() for p in want]
    assert status["record_frames"] == 2 and status["detections"] > 0, status
    assert status["status_truncated"] == 0, status


@pytest.mark.skipif(os.environ.get("FULL_FRAME", "0") in ("", "0"),
                    reason="one full-size frame through the 16-lane FRAME_STORE = 1 top: "
                           "`make test-full` (about 2 minutes with the build)")
def test_harness_full_frame_store() -> None:
    """The paper's full system, one `full` frame (4 TX x 16 RX, 256 x 256) through the
    FRAME_STORE = 1 top (512-bit AXI4 to the harness's memory with latency and 30 % stalls),
    the ADC at its real 32.5 MSPS against the 100 MHz clock: every DMA byte equals the
    model's, nothing flagged."""
    from model.config import get_preset
    from model.hdl import FPGA_CLOCK_HZ, FULL_AXI_DATA_W
    from model.radar_pipeline import PipelineParams

    cfg = get_preset("full")
    chain = PipelineParams(frame_store=True, axi_data_w=FULL_AXI_DATA_W)
    frames = adc_frames("full", cfg, 1, seed=5)
    adc_gap = 1.0 - cfg.sample_rate_hz / FPGA_CLOCK_HZ
    chirp_gap = round((cfg.chirp_period_s - cfg.sampled_chirp_s) * FPGA_CLOCK_HZ)
    run = run_harness(frames, cfg, chain, seed=9, frame_store=True, mem_latency=40,
                      mem_stall=0.3, adc_gap=adc_gap, chirp_gap=chirp_gap)
    assert_packets_equal(run.packets, dma_packets(frames, cfg, chain), "full frame store")
    st = run.status
    assert st["mem_protocol_errors"] == 0 and st["frames_out"] == 1, st
    print(f"full frame: {run.cycles} clocks in {run.wall_s:.1f} s", file=sys.stderr)


def test_harness_mode1_frame_store_small4() -> None:
    """OUTPUT_MODE = 1 with FRAME_STORE = 1 on the 4-TX set (frame_store_axi READ_ORDER = 1:
    the store reads (r, t, d), so the detector sees all TX of a cell together): record
    packets bit-exact against the model through AXI4 memory latency and 30 % stalls, DMA
    stalls, and a reset after two frames (segments)."""
    from dataclasses import replace

    from test_radar_pipeline_detect import SETS

    cfg, chain = SETS["small4"]
    chain = replace(chain, frame_store=True)
    frames = adc_frames("small4", cfg, 3, seed=4)
    run = run_harness(frames, cfg, chain, seed=6, frame_store=True, mem_latency=40,
                      mem_stall=0.3, dma_stall=0.2, chirp_gap=cfg.n_range, segment_frames=2)
    want = [p for k in range(0, 3, 2) for p in dma_packets(frames[k:k + 2], cfg, chain)]
    assert_packets_equal(run.packets, want, "mode 1, frame store")
    assert [s["record_frames"] for s in run.segments] == [2, 1], run.segments
    for st in run.segments:
        assert st["mem_protocol_errors"] == 0, st
        assert st["detections"] > 0 and st["status_adc_overflow"] == 0, st
        assert st["mem_writes"] > 0 and st["mem_writes"] == st["mem_reads"], st


@pytest.mark.skipif(os.environ.get("FULL_DETECT", "0") in ("", "0"),
                    reason="one full-size Table I frame through the OUTPUT_MODE = 1, "
                           "FRAME_STORE = 1 top: FULL_DETECT=1 (a 10-minute build)")
def test_harness_full_frame_store_detect() -> None:
    """`full` in mode 1 through the external store (READ_ORDER = 1, FS_TILE_R 4), the ADC at
    its real rate, 512-bit AXI4 memory with latency and 30 % stalls, the Table I scene: the
    record packets equal the model's byte for byte, nothing flagged or truncated."""
    from model.config import get_preset
    from model.hdl import FPGA_CLOCK_HZ, FULL_AXI_DATA_W
    from model.radar_pipeline import PipelineParams
    from model.scene import table1_scene
    from model.simulate import simulate_scene

    cfg = get_preset("full")
    chain = PipelineParams(frame_store=True, axi_data_w=FULL_AXI_DATA_W, output_mode=1)
    frames = [simulate_scene(table1_scene("full", seed=1), 0).samples]
    adc_gap = 1.0 - cfg.sample_rate_hz / FPGA_CLOCK_HZ
    chirp_gap = round((cfg.chirp_period_s - cfg.sampled_chirp_s) * FPGA_CLOCK_HZ)
    run = run_harness(frames, cfg, chain, seed=9, frame_store=True, mem_latency=40,
                      mem_stall=0.3, adc_gap=adc_gap, chirp_gap=chirp_gap)
    want = dma_packets(frames, cfg, chain)
    assert_packets_equal(run.packets, want, "full, mode 1, frame store")
    st = run.status
    assert st["mem_protocol_errors"] == 0 and st["record_frames"] == 1, st
    assert st["status_truncated"] == 0 and st["detections"] >= 4, st
    print(f"full mode-1 frame: {st['detections']} detections, {run.cycles} clocks in "
          f"{run.wall_s:.1f} s", file=sys.stderr)
