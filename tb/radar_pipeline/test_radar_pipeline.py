"""End-to-end cocotb regression of ``rtl/top/radar_pipeline.sv`` against ``model.radar_pipeline``.

ADC frames from ``model.simulate`` go through the RTL; the DMA stream is decoded by the host
decoder (``host.stream``) and compared packet by packet, bit for bit, with the model;
detections from the decoded cubes equal the model backend's. Parameter sets: the paper's
FPGA prototype (Table I scene, 1 TX x 4 RX, 64 x 256) and a small 4-TX set (4 RX, 32 x 32)
so TDM ordering, DMA overload and a mid-stream reset run in seconds.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import cocotb
import numpy as np
import pytest
from cocotb.triggers import RisingEdge

from host.pipeline import process_cube
from host.stream import StreamDecoder
from model.axis_packetizer import (
    packets_per_frame,
    parse_header,
    shortest_packet_words,
    words_to_bytes,
)
from model.axis_reg_slice import LATENCY as SLICE_LATENCY
from model.config import RadarConfig, get_preset
from model.detect_chain import DetectConfig
from model.radar_pipeline import (
    PipelineParams,
    chain_gain,
    dma_packets,
    run_chain,
    scaled_cube,
)
from model.scene import PointTarget, Scene, table1_scene
from model.simulate import simulate_frame, simulate_scene
from rtlsim.axis import chirp_bursts, random_pause
from rtlsim.pipeline import PipelineTB, StallSwitch, assert_packets_equal
from rtlsim.pipeline_rtl import PIPELINE_SOURCES
from rtlsim.toolchain import param, rtl_sources, run_cocotb
from tb import progress

SMALL4 = RadarConfig(name="small4", num_tx=4, num_rx=4, n_range=32, n_doppler=32,
                     sample_rate_hz=10e6, chirp_period_s=4e-6, design_max_range_m=50.0)
SMALL4_TARGETS = (PointTarget(12.0, -20.0, -8.0, 5.0), PointTarget(30.0, 15.0, 11.0, 20.0))
CONFIGS = {"paper-fpga": (get_preset("paper-fpga"), PipelineParams(packet_words=1024)),
           "small4": (SMALL4, PipelineParams(packet_words=256))}


MEM_STALLS = ("m_axi_mem_aw", "m_axi_mem_w", "m_axi_mem_ar")
"""The external frame store's request channels (FRAME_STORE = 1): the testbench's ``AxiRam``
refusing one holds the top up as a stalled DMA does (idle, never refused, on chip)."""


def pipeline_latency(tb: PipelineTB) -> int:
    """Clocks from a frame's last ADC sample to its first DMA word: the documented latencies of
    the blocks on the way, added. The ping-pong's chirp, N_SAMPLES + 2, frame_align's register
    and the register slice behind it (docs/buffers.md 1, 4, 9); the range FFT
    (``progress.fft_latency``, docs/fft_axis.md) and the register slice behind it; the corner
    turn, 3 clocks after a frame's last word on chip (docs/buffers.md 2), about a frame plus a
    strip in external memory (docs/frame_store.md: 2 F here, F the cube's words); static
    removal, a vector + 5 (docs/buffers.md 6); the Doppler FFT; in mode 1 the whole frame
    through the detector first (F words at one a clock, the CFAR's Doppler wrap N_RBINS 2 PD,
    the NCI, the CFAR's passes over the last rows, the record frame's FRAME_WORDS:
    docs/detect.md); then the register slice in front of the packetizer and the packetizer, a
    packet's first payload word to its header (``progress.packetizer_latency``)."""
    window = bool(param("WINDOW", 1))
    cells = tb.num_tx * tb.n_range_bins * tb.n_doppler
    clocks = (param("N_SAMPLES", tb.n_range) + 2 + 1 + SLICE_LATENCY
              + progress.fft_latency(tb.n_range, window) + SLICE_LATENCY
              + (2 * cells if param("FRAME_STORE", 0) else 3)
              + (tb.n_doppler + 5 if param("STATIC_REMOVAL", 0) else 0)
              + progress.fft_latency(tb.n_doppler, window)
              + SLICE_LATENCY + progress.packetizer_latency(tb.packet_words))
    if tb.output_mode == 1:
        cfar = DetectConfig(num_tx=tb.num_tx, num_rx=tb.num_rx, n_range=tb.n_range_bins,
                            n_doppler=tb.n_doppler, guard=(param("GUARD_R"), param("GUARD_D")),
                            train=(param("TRAIN_R"), param("TRAIN_D"))).cfar
        clocks += (cells + tb.n_range_bins * 2 * cfar.pd + progress.NCI_LATENCY
                   + progress.cfar_latency(cfar) + tb.frame_words)
    return clocks


def frame_beats(tb: PipelineTB) -> int:
    """ADC beats of one frame: NUM_TX N_LOOPS chirps of N_SAMPLES."""
    return tb.num_tx * param("N_LOOPS", tb.n_doppler) * param("N_SAMPLES", tb.n_range)


async def poll(tb: PipelineTB, ready: Callable[[], bool], what: str) -> None:
    """Wait clock by clock until ``ready()`` (a condition on the top's internal state), at
    most ``progress.MARGIN`` x (two frames' ADC beats + :func:`pipeline_latency`) clocks: the
    frame a test polls for enters at half rate or faster (chirp bursts, 20 % gaps) and then
    crosses the pipeline. Else AssertionError naming ``what``."""
    limit = progress.MARGIN * (2 * frame_beats(tb) + pipeline_latency(tb))
    for _ in range(limit):
        if ready():
            return
        await tb.cycles(1)
    raise AssertionError(f"waited {limit} clocks for {what}")


def watched(dut) -> PipelineTB:
    """A :class:`PipelineTB` on ``dut`` with ``tb/progress.py``'s port watchdog beside the
    test (docs/verification.md, "Watchdogs that fail fast"). The ADC input never waits, so
    only the output rules apply: once a whole ADC frame (NUM_TX N_LOOPS N_SAMPLES beats,
    counted from a frame start: after a mid-frame reset the top discards up to the next)
    is in and fewer frames' DMA words have left, the DMA port must give a beat within
    4 x :func:`pipeline_latency` clocks in which neither it nor the memory (:data:`MEM_STALLS`)
    is held by its sink; frames owed when the top was last held up are forgiven (it drops
    chirps by design then); more DMA words than the ADC frames begun allow fails at once.
    A frame's DMA words: the payload and, with HEADER, a header and CRC word per packet, of
    PACKET_WORDS for the owed rule (run-time lengths are shorter, never longer) and of the
    shortest legal length (the top's PACKET_WORDS_MIN) for the bound."""
    tb = PipelineTB(dut)
    fw = tb.frame_words
    frame_in = frame_beats(tb)

    def words(packet: int) -> int:
        return fw + 2 * packets_per_frame(fw, packet) * tb.header

    progress.watch(tb, latency=pipeline_latency(tb), frame=(frame_in, words(tb.packet_words)),
                   most=(frame_in, words(shortest_packet_words(fw))), start=True,
                   stalls=MEM_STALLS, lossy=True)
    return tb


def config_of(tb: PipelineTB) -> tuple[str, RadarConfig, PipelineParams]:
    for name, (cfg, chain) in CONFIGS.items():
        if (cfg.num_tx, cfg.num_rx, cfg.n_range, cfg.n_doppler, chain.packet_words) == (
                tb.num_tx, tb.num_rx, tb.n_range, tb.n_doppler, tb.packet_words):
            return name, cfg, chain
    raise AssertionError("unknown parameter set")


def adc_frames(name: str, cfg: RadarConfig, n: int, seed: int = 1) -> list[np.ndarray]:
    """n consecutive frames of the set's scene (Table I for paper-fpga)."""
    if name == "paper-fpga":
        scene = table1_scene("paper-fpga", seed=seed)
        return [simulate_scene(scene, k).samples for k in range(n)]
    sc = Scene(preset="full", targets=SMALL4_TARGETS).scatterers()
    return [simulate_frame(cfg, sc, rng=np.random.default_rng([seed, k]), frame_index=k)
            .samples for k in range(n)]


def decode(cfg: RadarConfig, chain: PipelineParams, packets: list[np.ndarray]):
    """The host's decoding of DMA packets (``host.stream``): frames by frame id."""
    dec = StreamDecoder(cfg, chain.packet_words)
    frames = [f for p in packets for f in dec.push_packet(words_to_bytes(p))] + dec.flush()
    return sorted(frames, key=lambda f: f.frame_id)


def assert_model_detections(cube: np.ndarray, adc: np.ndarray, cfg: RadarConfig,
                             chain: PipelineParams, min_points: int) -> int:
    """The host's detections (``host.pipeline.process_cube``) on a decoded RTL ``cube``
    (scaled back by the chain gain) equal those on the model's cube of ``adc``, field by
    field, and number at least ``min_points``; returns how many."""
    rtl_cloud = process_cube(cube / chain_gain(cfg, chain), cfg)
    model_cloud = process_cube(scaled_cube(adc, cfg, chain), cfg)
    assert len(rtl_cloud) == len(model_cloud) >= min_points
    for field in ("range_m", "azimuth_deg", "radial_velocity_mps", "snr_db"):
        assert np.array_equal(getattr(rtl_cloud, field), getattr(model_cloud, field))
    return len(rtl_cloud)


def assert_recovered(cfg: RadarConfig, chain: PipelineParams, frames: list[np.ndarray],
                     got: list[np.ndarray], status: dict[str, int]) -> list:
    """After an overload (:meth:`PipelineTB.stall_then_drain`): chirps dropped at the ADC
    ping-pong (flagged), frames marked damaged, frame 0 and the last frame complete, the last
    one bit-exact with the model and its header clean; returns the decoded frames."""
    assert status["status_adc_overflow"] == 1 and status["adc_chirps_dropped"] > 0, status
    assert status["frames_damaged"] >= 1, status
    decoded = decode(cfg, chain, got)
    assert decoded[0].complete and decoded[-1].complete, decoded[-1].problems
    assert np.array_equal(decoded[-1].cube, run_chain(frames[-1], cfg, chain).cube())
    hdr = parse_header(got[-1][0])
    assert not hdr.damaged and not hdr.drop
    return decoded


@cocotb.test()
async def frames_back_to_back_with_dma_stalls(dut) -> None:
    """Three frames back to back, each chirp at one ADC sample per clock with a chirp-long
    gap between chirps, random DMA stalls (30 %): bit-exact packets, clean status, host
    decode and detections identical to the model backend."""
    tb = watched(dut)
    name, cfg, chain = config_of(tb)
    frames = adc_frames(name, cfg, 3)
    got = await tb.stream_under_stalls(frames, cfg, chain, name,
                                       idle=chirp_bursts(cfg.n_range, cfg.n_range),
                                       backpressure=random_pause(0.3, 2))
    status = tb.status()
    decoded = decode(cfg, chain, got)
    assert [f.complete for f in decoded] == [True] * 3
    points = [assert_model_detections(f.cube, adc, cfg, chain,
                                      3 if name == "paper-fpga" else 2)
              for f, adc in zip(decoded, frames, strict=True)]
    tb.dut._log.info("%s: 3 frames bit-exact, %d points in frame 0, status %s", name,
                     points[0], status)


@cocotb.test()
async def adc_gaps_at_the_real_sample_rate(dut) -> None:
    """ADC valid about one clock in five (19.33 MSPS at 100 MHz) and DMA stalls."""
    tb = watched(dut)
    name, cfg, chain = config_of(tb)
    if name != "small4":
        return
    await tb.stream_under_stalls(adc_frames(name, cfg, 2, seed=5), cfg, chain, "adc gaps",
                                 idle=random_pause(0.8, 3), backpressure=random_pause(0.5, 4),
                                 timeout_frames=6)


@cocotb.test()
async def dma_overload_then_recovery(dut) -> None:
    """The DMA stalls for three frame times while the ADC keeps going: the corner turn's
    frame store fills, the ADC ping-pong drops chirps, frame_align zero-fills the damaged
    frames; flags and counters say so, the host reports those frames as damaged, and the
    frames after the stall come out clean and bit-exact."""
    tb = watched(dut)
    name, cfg, chain = config_of(tb)
    if name != "small4":
        return
    frames = adc_frames(name, cfg, 6, seed=7)
    stall = StallSwitch()
    tb.set_backpressure_generator(stall.pauses())
    got = await tb.stall_then_drain(frames, cfg, stall, tb.frame_timeout_cycles())
    status = tb.status()
    decoded = assert_recovered(cfg, chain, frames, got, status)
    assert status["chirps_filled"] > 0, status
    assert status["status_dma_overflow"] == 0, status  # the DMA side never drops
    damaged = [f for f in decoded if any("damaged upstream" in p for p in f.problems)]
    assert len(damaged) == status["frames_damaged"]
    tb.dut._log.info("overload: %d chirps dropped, %d filled, %d discarded, %d frames "
                     "damaged, %d frames out; last frame clean", status["adc_chirps_dropped"],
                     status["chirps_filled"], status["chirps_discarded"],
                     status["frames_damaged"], len(decoded))


@cocotb.test()
async def reset_mid_stream(dut) -> None:
    """A reset in the middle of frame 0 while the ADC keeps streaming (a real ADC does not
    stop): frame_align discards the rest of frame 0 up to the next frame start, and frames 1
    and 2 come out clean, bit-exact, with frame ids from 0."""
    tb = watched(dut)
    name, cfg, chain = config_of(tb)
    if name != "small4":
        return
    await tb.reset_mid_frame(adc_frames(name, cfg, 3, seed=11), cfg, chain, "after reset")
    status = tb.status()
    assert status["frames_out"] == 2 and status["frames_damaged"] == 0, status
    assert status["chirps_discarded"] > 0, status  # the rest of frame 0


# FFT event registers of the top's two FFTs (fft_axis ev_*_q: one-cycle pulses)
FFT_EVENTS = {"rf_unexp": ("u_range_fft", "ev_unexp_q"), "rf_miss": ("u_range_fft", "ev_miss_q"),
              "df_unexp": ("u_doppler_fft", "ev_unexp_q"),
              "df_miss": ("u_doppler_fft", "ev_miss_q"),
              "rf_ovf": ("u_range_fft", "ev_ov_q"), "df_ovf": ("u_doppler_fft", "ev_ov_q")}


async def inject_fft_events(tb: PipelineTB, cycles: list[tuple[str, ...]]) -> None:
    """Fault injection: for each entry, raise those FFT event registers for one clock (a
    deposit after the falling edge; the register's own next-state logic clears it at the
    following rising edge), with an idle clock between entries."""
    from cocotb.triggers import FallingEdge

    for names in cycles:
        await FallingEdge(tb.dut.clk)
        for name in names:
            inst, reg = FFT_EVENTS[name]
            getattr(getattr(tb.dut, inst), reg).value = 1
        await RisingEdge(tb.dut.clk)
        await RisingEdge(tb.dut.clk)


@cocotb.test()
async def fft_overflow_and_framing_counters(dut) -> None:
    """The top's own error path (fft overflow / FFT framing flags and counters).

    Overflow, end to end: three frames, the first all full-scale, the second the normal
    scene, the third with full-scale samples on half the chirps and two RX lanes: the
    Doppler FFT saturates; the packets equal the model bit for bit (saturation included) and
    ``fft_overflow_count`` equals the model's saturated output beats (4 + 0 + 2).

    Framing: frame_align regenerates every chirp's TLAST, so no input at the top's ports
    misplaces a TLAST inside an FFT (the FFT testbench drives those cases on the block); the
    top's counting of them is checked by injecting one-clock event pulses into the FFTs'
    event registers: ``fft_framing`` counts clocks with any TLAST event of either FFT,
    ``fft_overflow_count`` clocks with any overflow event; the flags stay set (sticky)
    through a clean frame, ``framing_error_count`` is the sum of the blocks' counters, and a
    reset clears all of them."""
    tb = watched(dut)
    name, cfg, chain = config_of(tb)
    if name != "small4":
        return
    frames = adc_frames(name, cfg, 3, seed=13)
    full = complex(32767, -32768)
    frames[0][:] = full
    frames[2][::2, :2, :] = full
    want_ovf = [run_chain(f, cfg, chain) for f in frames]
    assert [(w.range_overflow, w.doppler_overflow) for w in want_ovf] == [(0, 4), (0, 0),
                                                                          (0, 2)]
    await tb.stream_under_stalls(frames, cfg, chain, "saturating frames",
                                 idle=chirp_bursts(cfg.n_range, cfg.n_range // 2),
                                 backpressure=random_pause(0.3, 9), clean=False)
    st = tb.status()
    assert st["status_fft_overflow"] == 1 and st["fft_overflow_count"] == 6, st
    assert st["status_framing_error"] == 0 and st["framing_error_count"] == 0, st
    await tb.cycles(50)   # the chain is idle: no real event below

    await inject_fft_events(tb, [("rf_unexp",), ("rf_miss",), ("df_unexp",), ("df_miss",),
                                 ("rf_unexp", "df_miss"), ("rf_ovf",), ("df_ovf",),
                                 ("rf_ovf", "df_ovf", "df_unexp")])
    await tb.cycles(2)
    st = tb.status()
    assert st["status_framing_error"] == 1 and st["framing_error_count"] == 6, st
    assert st["status_fft_overflow"] == 1 and st["fft_overflow_count"] == 9, st

    # sticky through a clean frame (and the clean frame is unharmed)
    await tb.stream(adc_frames(name, cfg, 1, seed=14), cfg, chain, "clean frame after events",
                    first_frame_id=3)
    st = tb.status()
    assert (st["status_framing_error"], st["framing_error_count"]) == (1, 6), st
    assert (st["status_fft_overflow"], st["fft_overflow_count"]) == (1, 9), st

    # overflow flag alone (framing untouched) and framing alone from a fresh reset
    await tb.reset()
    st = tb.status()
    assert (st["status_fft_overflow"], st["fft_overflow_count"], st["status_framing_error"],
            st["framing_error_count"]) == (0, 0, 0, 0), st
    await inject_fft_events(tb, [("df_ovf",)])
    await tb.cycles(2)
    st = tb.status()
    assert (st["status_fft_overflow"], st["fft_overflow_count"], st["status_framing_error"],
            st["framing_error_count"]) == (1, 1, 0, 0), st
    await inject_fft_events(tb, [("df_miss",)])
    await tb.cycles(2)
    st = tb.status()
    assert (st["status_fft_overflow"], st["fft_overflow_count"], st["status_framing_error"],
            st["framing_error_count"]) == (1, 1, 1, 1), st
    # on-chip corner turn (FRAME_STORE = 0): the external memory port is idle and says so
    idle = {n: int(getattr(dut, f"m_axi_mem_{n}").value) for n in (
        "awvalid", "wvalid", "wlast", "bready", "arvalid", "rready", "awlock", "arlock")}
    assert idle == dict.fromkeys(idle, 0) and int(dut.status_mem_error.value) == 0, idle
    tb.dut._log.info("fft events: overflow beats counted as the model's, injected framing "
                     "and overflow pulses counted per clock, sticky, cleared by reset")


# Sticky framing flag and counter of each block the top merges (instance path, flag, counter)
BLOCK_FRAMING = {"pingpong": ("u_pingpong", "framing_q", "framing_cnt_q"),
                 "corner_turn": ("g_ct_onchip.u_corner_turn", "framing_q", "framing_cnt_q"),
                 "packetizer": ("u_packetizer", "framing_q", "framing_cnt_q")}


@cocotb.test()
async def block_framing_flags_reach_the_top(dut) -> None:
    """Each block's sticky framing flag alone raises the top's ``status_framing_error`` (an OR
    of the blocks' flags) and its counter alone reaches ``framing_error_count`` (their sum).
    frame_align regenerates every TLAST, so no input at the ports sets these flags: they are
    set by deposit (fault injection), one block per reset; a flag dropped from the top's merge
    (mutants ``radar_pipeline:merge:4..6``) leaves the status at 0."""
    from cocotb.triggers import FallingEdge

    tb = watched(dut)
    name, _, _ = config_of(tb)
    if name != "small4":
        return
    for block, (path, flag, count) in BLOCK_FRAMING.items():
        await tb.reset()
        inst = tb.dut
        for part in path.split("."):
            inst = getattr(inst, part)
        await FallingEdge(tb.dut.clk)
        getattr(inst, flag).value = 1
        getattr(inst, count).value = 3
        await tb.cycles(2)
        st = tb.status()
        assert (st["status_framing_error"], st["framing_error_count"]) == (1, 3), (block, st)
    await tb.reset()
    st = tb.status()
    assert (st["status_framing_error"], st["framing_error_count"]) == (0, 0), st


@cocotb.test()
async def throughput_latency(dut) -> None:
    """ADC at one sample per clock with no gaps, DMA always ready: the steady-state frame
    period is the frame's DMA words (payload + a header and a CRC word per packet), i.e. the
    chain moves one sample per clock per lane; measures latency and simulation speed
    (RP_BENCH_JSON)."""
    import time

    tb = watched(dut)
    name, cfg, chain = config_of(tb)
    n = 3
    frames = adc_frames(name, cfg, n, seed=3)
    await tb.reset()
    d = tb.dut
    marks = {"in_last": [], "out_last": []}
    frame_samples = cfg.n_chirps * cfg.n_range

    async def monitor() -> None:
        cycle = in_beats = out_pkts = 0
        while True:
            await RisingEdge(d.clk)
            cycle += 1
            if d.s_axis_adc_tvalid.value == 1 and d.s_axis_adc_tready.value == 1:
                in_beats += 1
                if in_beats % frame_samples == 0:
                    marks["in_last"].append(cycle)
            if d.m_axis_dma_tvalid.value == 1 and d.m_axis_dma_tready.value == 1 and \
                    d.m_axis_dma_tlast.value == 1:
                out_pkts += 1
                if out_pkts % tb.packets_per_frame == 0:
                    marks["out_last"].append(cycle)

    cocotb.start_soon(monitor())
    t0, cpu0 = time.perf_counter(), time.process_time()
    for adc in frames:
        await tb.send_frame(adc)
    got = await tb.recv_frames(n, tb.frame_timeout_cycles())
    wall, cpu = time.perf_counter() - t0, time.process_time() - cpu0
    await RisingEdge(d.clk)
    assert_packets_equal(got, dma_packets(frames, cfg, chain), f"{name} full rate")
    period = marks["out_last"][2] - marks["out_last"][1]
    dma_words = chain.frame_words(cfg) + (2 * tb.packets_per_frame if chain.header else 0)
    latency = [o - i for i, o in zip(marks["in_last"], marks["out_last"], strict=True)]
    assert period <= dma_words + 8, (period, dma_words)
    result = {"name": name, "frame_samples": frame_samples, "dma_words": dma_words,
              "period_cycles": period, "latency_cycles": latency[-1],
              "sim_cycles": marks["out_last"][-1], "wall_s": wall, "cpu_s": cpu,
              "status": tb.status()}
    tb.dut._log.info("throughput: %s", result)
    if os.environ.get("RP_BENCH_JSON"):
        Path(os.environ["RP_BENCH_JSON"]).write_text(json.dumps(result))


# ---- pytest: one Verilator build per parameter set -----------------------------------------
@pytest.mark.parametrize("name", list(CONFIGS))
def test_radar_pipeline(name: str, tmp_path: Path) -> None:
    cfg, chain = CONFIGS[name]
    run_cocotb("radar_pipeline", rtl_sources(*PIPELINE_SOURCES), "test_radar_pipeline",
               Path(__file__).parent, chain.hdl_parameters(cfg),
               extra_env={"SEED": os.environ.get("SEED", "1")})
    if name == "paper-fpga":
        # `radar detect --backend rtl` (same build folder, so run here, after the build)
        # gives the same point cloud JSON as the bit-accurate model backend; run as a
        # command, as a user does (the testbenches do not import the application)
        assert chain == PipelineParams()  # the CLI's chain settings
        docs = {}
        for backend in ("rtl", "model"):
            out = tmp_path / f"{backend}.json"
            subprocess.run([sys.executable, "-m", "radar.cli", "detect", "--scene", "table1",
                            "--preset", "paper-fpga", "--frames", "2", "--backend", backend,
                            "--json", str(out)], check=True)
            docs[backend] = json.loads(out.read_text())
            docs[backend].pop("backend")
        assert docs["rtl"] == docs["model"]
        assert len(docs["rtl"]["points"]) >= 6
