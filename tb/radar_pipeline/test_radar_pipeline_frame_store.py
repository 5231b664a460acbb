"""End-to-end cocotb regression of ``radar_pipeline`` with ``FRAME_STORE = 1``: the corner
turn in external memory (cocotbext-axi ``AxiRam`` on ``m_axi_mem``, pause generators on all
five channels). The DMA packets must be bit-identical to the chain model's, which are the
same for ``FRAME_STORE`` 0 and 1 (``tests/test_frame_store_chain.py``); a memory slower than
the ADC must end in whole chirps dropped at the ping-pong (flagged, frame marked damaged,
later frames clean), never in a lost sample inside the store.
"""

from __future__ import annotations

import logging
from dataclasses import replace
from pathlib import Path

import cocotb
import numpy as np
import pytest
from cocotb.triggers import SimTimeoutError, Timer
from cocotbext.axi import AxiBus, AxiRam
from test_radar_pipeline import SMALL4, assert_packets_equal, chirp_bursts, decode
from test_radar_pipeline import adc_frames as scene_frames

from model.axis_packetizer import parse_header
from model.frame_store_axi import StoreGeometry
from model.radar_pipeline import PipelineParams, dma_packets, run_chain
from rtlsim.axis import random_pause
from rtlsim.pipeline import PipelineTB
from rtlsim.pipeline_rtl import PIPELINE_SOURCES
from rtlsim.toolchain import rtl_sources, run_cocotb

CHAIN = PipelineParams(packet_words=256, frame_store=True, axi_data_w=128, fs_tile_r=8)
MEM_BASE = 0x10000


def store_params(chain: PipelineParams) -> dict[str, int]:
    return {**chain.hdl_parameters(SMALL4), "AXI_ADDR_W": 32, "AXI_ID_W": 1,
            "MEM_BASE": MEM_BASE}


def attach_ram(tb: PipelineTB) -> AxiRam:
    g: StoreGeometry = CHAIN.store_geometry(SMALL4)
    ram = AxiRam(AxiBus.from_prefix(tb.dut, "m_axi_mem"), tb.dut.clk, tb.dut.rst,
                 size=MEM_BASE + g.memory_bytes)
    for c in (ram.write_if, ram.read_if):
        c.log.setLevel(logging.WARNING)
    return ram


def channels(ram: AxiRam) -> list:
    w, r = ram.write_if, ram.read_if
    return [w.aw_channel, w.w_channel, w.b_channel, r.ar_channel, r.r_channel]


async def stalled_frames(tb: PipelineTB, external: bool) -> tuple[list[np.ndarray],
                                                                  list[np.ndarray]]:
    """Three small4 scene frames in ADC chirp bursts with 30 % DMA stalls and, with the
    ``external`` frame store, an ``AxiRam`` stalling all five channels at random: (the ADC
    frames, the DMA packets received)."""
    if external:
        for i, ch in enumerate(channels(attach_ram(tb))):
            ch.set_pause_generator(random_pause(0.3, 20 + i))
    frames = scene_frames("small4", SMALL4, 3)
    tb.set_idle_generator(chirp_bursts(SMALL4.n_range, SMALL4.n_range))
    tb.set_backpressure_generator(random_pause(0.3, 2))
    await tb.reset()
    for adc in frames:
        await tb.send_frame(adc)
    return frames, await tb.recv_frames(3, 4 * tb.frame_timeout_cycles())


@cocotb.test()
async def external_store_bit_exact_with_axi_stalls(dut) -> None:
    """Three frames, ADC chirp bursts, 30 % DMA stalls, random stalls on all five AXI
    channels: packets bit-exact with the model, clean status, no memory error."""
    tb = PipelineTB(dut)
    frames, got = await stalled_frames(tb, external=True)
    # the on-chip corner turn's packets: FRAME_STORE changes nothing downstream
    want = dma_packets(frames, SMALL4, replace(CHAIN, frame_store=False))
    assert_packets_equal(got, want, "frame store")
    st = tb.status()
    assert st["frames_out"] == 3 and st["status_adc_overflow"] == 0, st
    assert int(dut.status_mem_error.value) == 0 and int(dut.mem_error_count.value) == 0
    assert [f.complete for f in decode(SMALL4, CHAIN, got)] == [True] * 3


@cocotb.test()
async def slow_memory_drops_whole_chirps(dut) -> None:
    """The memory stalls 95 % of the time for three frame times while the ADC keeps going:
    the store back-pressures, the ping-pong drops whole chirps (flagged), frame_align marks
    the frames damaged; after the memory recovers the last frame is clean and bit-exact."""
    tb = PipelineTB(dut)
    ram = attach_ram(tb)
    slow = {"on": False}
    rngs = [np.random.default_rng(40 + i) for i in range(5)]
    for ch, rng in zip(channels(ram), rngs, strict=True):
        ch.set_pause_generator(iter(lambda r=rng: slow["on"] and r.random() < 0.95, None))
    n_frames = 6
    frames = scene_frames("small4", SMALL4, n_frames, seed=7)
    await tb.reset()
    tb.set_idle_generator(chirp_bursts(SMALL4.n_range, SMALL4.n_range))
    for adc in frames:
        await tb.send_frame(adc)
    frame_clocks = 2 * SMALL4.n_chirps * SMALL4.n_range
    got = [await tb.recv_packet(2 * tb.frame_timeout_cycles())
           for _ in range(tb.packets_per_frame)]          # frame 0 leaves normally
    slow["on"] = True
    await Timer(3 * frame_clocks * 10, unit="ns")
    slow["on"] = False
    while True:
        try:
            got.append(await tb.recv_packet(3 * frame_clocks))
        except SimTimeoutError:
            break
    st = tb.status()
    assert st["status_adc_overflow"] == 1 and st["adc_chirps_dropped"] > 0, st
    assert st["frames_damaged"] >= 1, st
    assert int(dut.mem_error_count.value) == 0
    decoded = decode(SMALL4, CHAIN, got)
    assert decoded[0].complete and decoded[-1].complete, decoded[-1].problems
    assert np.array_equal(decoded[-1].cube, run_chain(frames[-1], SMALL4, CHAIN).cube())
    hdr = parse_header(got[-1][0])
    assert not hdr.damaged and not hdr.drop
    tb.dut._log.info("slow memory: %d chirps dropped, %d frames damaged, %d frames out",
                     st["adc_chirps_dropped"], st["frames_damaged"], len(decoded))


@pytest.mark.parametrize("name", ["small4"])
def test_radar_pipeline_frame_store(name: str) -> None:
    run_cocotb("radar_pipeline", rtl_sources(*PIPELINE_SOURCES),
               "test_radar_pipeline_frame_store", Path(__file__).parent,
               store_params(CHAIN))
