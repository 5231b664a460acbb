"""End-to-end cocotb regression of ``radar_pipeline`` with ``FRAME_STORE = 1``: the corner
turn in external memory (cocotbext-axi ``AxiRam`` on ``m_axi_mem``, pause generators on all
five channels). The DMA packets must be bit-identical to the chain model's, which are the
same for ``FRAME_STORE`` 0 and 1 (``tests/test_frame_store_chain.py``); a memory slower than
the ADC must end in whole chirps dropped at the ping-pong (flagged, frame marked damaged,
later frames clean), never in a lost sample inside the store.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import replace
from pathlib import Path

import cocotb
import numpy as np
import pytest
from test_radar_pipeline import SMALL4, assert_recovered, decode, watched
from test_radar_pipeline import adc_frames as scene_frames

from model.radar_pipeline import PipelineParams
from rtlsim.axis import chirp_bursts, random_pause
from rtlsim.pipeline import PipelineTB, StallSwitch
from rtlsim.pipeline_rtl import PIPELINE_SOURCES
from rtlsim.toolchain import rtl_sources, run_cocotb

CHAIN = PipelineParams(packet_words=256, frame_store=True, axi_data_w=128, fs_tile_r=8)
MEM_BASE = 0x10000


def store_params(chain: PipelineParams) -> dict[str, int]:
    return {**chain.hdl_parameters(SMALL4), "AXI_ADDR_W": 32, "AXI_ID_W": 1,
            "MEM_BASE": MEM_BASE}


def attach_ram(tb: PipelineTB, pauses: Callable[[int], Iterator[bool]]) -> None:
    """The ``AxiRam`` of CHAIN's store on SMALL4 behind ``MEM_BASE``."""
    tb.attach_memory(MEM_BASE + CHAIN.store_geometry(SMALL4).memory_bytes, pauses)


async def stalled_frames(tb: PipelineTB, external: bool, chain: PipelineParams,
                         what: str) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """Three small4 scene frames in ADC chirp bursts with 30 % DMA stalls and, with the
    ``external`` frame store, an ``AxiRam`` stalling all five channels at random, compared
    with ``chain``'s model packets, clean status: (the ADC frames, the DMA packets)."""
    if external:
        attach_ram(tb, lambda i: random_pause(0.3, 20 + i))
    frames = scene_frames("small4", SMALL4, 3)
    got = await tb.stream_under_stalls(frames, SMALL4, chain, what,
                                       idle=chirp_bursts(SMALL4.n_range, SMALL4.n_range),
                                       backpressure=random_pause(0.3, 2), timeout_frames=4)
    return frames, got


@cocotb.test()
async def external_store_bit_exact_with_axi_stalls(dut) -> None:
    """Three frames, ADC chirp bursts, 30 % DMA stalls, random stalls on all five AXI
    channels: packets bit-exact with the model, clean status, no memory error."""
    tb = watched(dut)
    # the on-chip corner turn's packets: FRAME_STORE changes nothing downstream
    _, got = await stalled_frames(tb, True, replace(CHAIN, frame_store=False), "frame store")
    assert int(dut.status_mem_error.value) == 0 and int(dut.mem_error_count.value) == 0
    assert [f.complete for f in decode(SMALL4, CHAIN, got)] == [True] * 3


@cocotb.test()
async def slow_memory_drops_whole_chirps(dut) -> None:
    """The memory stalls 95 % of the time for three frame times while the ADC keeps going:
    the store back-pressures, the ping-pong drops whole chirps (flagged), frame_align marks
    the frames damaged; after the memory recovers the last frame is clean and bit-exact."""
    tb = watched(dut)
    slow = StallSwitch()
    attach_ram(tb, lambda i: slow.pauses(0.95, 40 + i))
    frames = scene_frames("small4", SMALL4, 6, seed=7)
    got = await tb.stall_then_drain(frames, SMALL4, slow, 2 * tb.frame_timeout_cycles())
    st = tb.status()
    assert int(dut.mem_error_count.value) == 0
    decoded = assert_recovered(SMALL4, CHAIN, frames, got, st)
    tb.dut._log.info("slow memory: %d chirps dropped, %d frames damaged, %d frames out",
                     st["adc_chirps_dropped"], st["frames_damaged"], len(decoded))


@pytest.mark.parametrize("name", ["small4"])
def test_radar_pipeline_frame_store(name: str) -> None:
    run_cocotb("radar_pipeline", rtl_sources(*PIPELINE_SOURCES),
               "test_radar_pipeline_frame_store", Path(__file__).parent,
               store_params(CHAIN))
