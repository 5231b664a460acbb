"""cocotb regression of ``radar_pipeline`` with NUM_TX = 3 (a TI xWR1843-style board: 3 TX x
4 RX, one TX raised for elevation, which only the host's angle step sees), 16 x 16: the
corner turn's non-power-of-two address schemes (docs/buffers.md) and the external store's
3-strip groups (docs/frame_store.md) in both output modes, bit-exact against
``model.radar_pipeline.dma_packets``.

Parameter sets (one Verilator build each, ``RP_TX3_SET``): ``cube`` (OUTPUT_MODE 0),
``records`` (OUTPUT_MODE 1), ``cube-store`` and ``records-store`` (FRAME_STORE = 1, an
``AxiRam`` stalling all five channels at random). Each runs frames back to back with random
ADC gaps and DMA stalls, then a reset in the middle of a frame while the ADC keeps streaming.
"""

from __future__ import annotations

import os
from dataclasses import replace
from pathlib import Path

import cocotb
import numpy as np
import pytest
from test_radar_pipeline import decode, watched

from model.axis_packetizer import depacketize
from model.config import RadarConfig
from model.detect_chain import DetectConfig
from model.detect_records import decode_frame
from model.radar_pipeline import PipelineParams, run_chain
from model.scene import PointTarget, Scene
from model.simulate import simulate_frame
from rtlsim.axis import random_pause
from rtlsim.pipeline import PipelineTB
from rtlsim.pipeline_rtl import PIPELINE_SOURCES
from rtlsim.toolchain import rtl_sources, run_cocotb

TX3 = RadarConfig(name="tx3", num_tx=3, num_rx=4, n_range=16, n_doppler=16,
                  sample_rate_hz=10e6, chirp_period_s=8e-6, design_max_range_m=25.0,
                  tx_positions=((0, 0), (2, 1), (4, 0)))
TARGETS = (PointTarget(8.0, -20.0, -3.0, 5.0), PointTarget(15.0, 15.0, 4.0, 20.0))
DETECT = DetectConfig(num_tx=3, num_rx=4, n_range=16, n_doppler=16, guard=(1, 1), train=(2, 3),
                      max_detections=16,
                      report=TX3.detection_bins)
MEM_BASE = 0x10000
CUBE = PipelineParams(packet_words=128)
RECORDS = PipelineParams(packet_words=64, output_mode=1, detect=DETECT)
SETS: dict[str, PipelineParams] = {
    "cube": CUBE, "records": RECORDS,
    "cube-store": replace(CUBE, frame_store=True, axi_data_w=128),
    "records-store": replace(RECORDS, frame_store=True, axi_data_w=128),
}


def adc_frames(n: int, seed: int) -> list[np.ndarray]:
    sc = Scene(preset="full", targets=TARGETS).scatterers()
    return [simulate_frame(TX3, sc, rng=np.random.default_rng([seed, k]), frame_index=k)
            .samples for k in range(n)]


def setup(dut) -> tuple[PipelineTB, PipelineParams]:
    """The testbench of the set ``RP_TX3_SET``; with the external store an ``AxiRam`` whose
    five channels stall 30 % of the time."""
    tb = watched(dut)
    chain = SETS[os.environ["RP_TX3_SET"]]
    assert (tb.num_tx, tb.frame_words) == (3, chain.frame_words(TX3))
    if chain.output_mode == 1:
        tb.cfar_scales = chain.cfar_scales(TX3)
    if chain.frame_store:
        tb.attach_memory(MEM_BASE + chain.store_geometry(TX3).memory_bytes,
                         lambda i: random_pause(0.3, 30 + i))
    return tb, chain


def check_decoded(chain: PipelineParams, frames: list[np.ndarray],
                  got: list[np.ndarray]) -> None:
    """The host's decoders take the 3-TX stream: the cube (mode 0) equals the model chain's,
    the record frames (mode 1) decode without errors and hold the scene's detections."""
    if chain.output_mode == 0:
        decoded = decode(TX3, chain, got)
        assert [f.complete for f in decoded] == [True] * len(frames)
        for f, adc in zip(decoded, frames, strict=True):
            assert np.array_equal(f.cube, run_chain(adc, TX3, chain).cube())
        return
    for f in depacketize(got, chain.frame_words(TX3), chain.packet_words, TX3.num_rx):
        assert f.complete, f.errors
        rf = decode_frame(f.words, TX3.num_tx)
        assert not rf.errors and rf.trailer.records >= 2, (rf.errors, rf.trailer)


@cocotb.test()
async def frames_bit_exact_with_stalls(dut) -> None:
    """Three frames back to back, random ADC gaps, 30 % DMA stalls (and AXI stalls with the
    external store): packets bit-exact, clean status, the host decodes them."""
    tb, chain = setup(dut)
    frames = adc_frames(3, seed=1)
    got = await tb.stream_under_stalls(frames, TX3, chain, os.environ["RP_TX3_SET"],
                                       idle=random_pause(0.3, 3),
                                       backpressure=random_pause(0.3, 4), timeout_frames=4)
    check_decoded(chain, frames, got)


@cocotb.test()
async def reset_mid_stream(dut) -> None:
    """A reset half way through frame 0 while the ADC keeps streaming: frames 1 and 2 come
    out bit-exact with frame ids from 0."""
    tb, chain = setup(dut)
    frames = adc_frames(3, seed=11)
    got = await tb.reset_mid_frame(frames, TX3, chain, "after reset", random_pause(0.2, 5))
    check_decoded(chain, frames[1:], got)


# ---- pytest: one Verilator build per parameter set -----------------------------------------
@pytest.mark.parametrize("name", list(SETS))
def test_radar_pipeline_tx3(name: str) -> None:
    chain = SETS[name]
    params = chain.hdl_parameters(TX3)
    if chain.frame_store:
        params = {**params, "AXI_ADDR_W": 32, "AXI_ID_W": 1, "MEM_BASE": MEM_BASE}
    run_cocotb("radar_pipeline", rtl_sources(*PIPELINE_SOURCES), "test_radar_pipeline_tx3",
               Path(__file__).parent, params, extra_env={"RP_TX3_SET": name})
