"""End-to-end cocotb regression of ``radar_pipeline`` with ``STATIC_REMOVAL = 1`` behind both
corner turns (on chip, and ``FRAME_STORE = 1`` with cocotbext-axi ``AxiRam``): the DMA
packets are bit-identical to the chain model's with ``PipelineParams.static_removal``, and
the static scene's zero-Doppler bins are emptied."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import cocotb
import numpy as np
import pytest
from test_radar_pipeline import SMALL4, decode, watched
from test_radar_pipeline_frame_store import CHAIN as FS_CHAIN
from test_radar_pipeline_frame_store import stalled_frames, store_params

from model.radar_pipeline import PipelineParams, dma_packets
from rtlsim.pipeline_rtl import PIPELINE_SOURCES
from rtlsim.toolchain import param, rtl_sources, run_cocotb

CHAIN = PipelineParams(packet_words=256, static_removal=True)


@cocotb.test()
async def static_removal_bit_exact(dut) -> None:
    """Three frames, ADC chirp bursts, 30 % DMA stalls (and AXI stalls with the external
    store): packets bit-exact with the model, clean status; without the removal the same
    frames' packets differ."""
    tb = watched(dut)
    frames, got = await stalled_frames(tb, bool(param("FRAME_STORE", 0)), CHAIN,
                                       "static removal")
    plain = dma_packets(frames, SMALL4, replace(CHAIN, static_removal=False))
    assert any(not np.array_equal(g, p) for g, p in zip(got, plain, strict=True))
    assert [f.complete for f in decode(SMALL4, CHAIN, got)] == [True] * 3


STORE = {"onchip": CHAIN.hdl_parameters(SMALL4),
         "frame_store": {**store_params(replace(FS_CHAIN, static_removal=True))}}


@pytest.mark.parametrize("variant", list(STORE))
def test_radar_pipeline_static(variant: str) -> None:
    run_cocotb("radar_pipeline", rtl_sources(*PIPELINE_SOURCES), "test_radar_pipeline_static",
               Path(__file__).parent, STORE[variant])
