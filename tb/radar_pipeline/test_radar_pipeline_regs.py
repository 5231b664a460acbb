"""cocotb test of the register block inside ``radar_pipeline`` (docs/regs.md), small 4-TX set
with ``STATIC_REMOVAL = 1``: every access through the AXI4-Lite slave ``s_axil_*``
(cocotbext-axi ``AxiLiteMaster``, random stalls on all five channels) with the register names
of ``host.regs``.

ID and version read; static-clutter removal switched off, two frames, switched on between
frames, two more: the DMA packets equal the model's with the removal off for the first two
and on from the next frame (``dma_packets(removal=...)``), ACTIVE_SETTINGS follows; the
FRAMES / PACKETS counters equal what the DMA delivered (and the status ports), no drops or
errors; irq rises on frame done when enabled and falls when STATUS.frame_done is written 1.
"""

from __future__ import annotations

import random
from pathlib import Path

import cocotb
import numpy as np
from test_radar_pipeline import SMALL4, adc_frames, assert_packets_equal, chirp_bursts

from host import regs
from model.radar_pipeline import PipelineParams, dma_packets
from rtlsim.axis import random_pause
from rtlsim.pipeline import PipelineTB
from rtlsim.pipeline_rtl import PIPELINE_SOURCES
from rtlsim.toolchain import rtl_sources, run_cocotb, seed

CHAIN = PipelineParams(packet_words=256, static_removal=True)
AXIL_STALL = 0.4
"""Probability of a pause per cycle on each AXI4-Lite channel."""


async def read(tb: PipelineTB, name: str) -> dict[str, int]:
    return regs.decode(name, await tb.read32(regs.address(name)))


async def write(tb: PipelineTB, name: str, **fields: int) -> None:
    await tb.write32(regs.address(name), regs.encode(name, **fields))


async def set_removal(tb: PipelineTB, on: bool) -> None:
    """SETTINGS.clutter_removal by read-modify-write, then wait until it is active (the
    corner turn's output is between frames: the active set follows at once)."""
    fields = await read(tb, "SETTINGS")
    fields["clutter_removal"] = int(on)
    await write(tb, "SETTINGS", **fields)
    await tb.cycles(4)
    assert (await read(tb, "ACTIVE_SETTINGS"))["clutter_removal"] == int(on)
    assert (await read(tb, "CFG_ERRORS"))["count"] == 0


@cocotb.test()
async def registers_through_axi_lite(dut) -> None:
    tb = PipelineTB(dut)
    rng = random.Random(seed())
    tb.attach_regs(lambda: random_pause(AXIL_STALL, rng.randrange(1 << 30)))
    tb.set_idle_generator(chirp_bursts(SMALL4.n_range, SMALL4.n_range))
    tb.set_backpressure_generator(random_pause(0.3, 2))
    frames = adc_frames("small4", SMALL4, 4)
    await tb.reset()

    assert await tb.read32(regs.address("ID")) == regs.ID_VALUE
    assert (await read(tb, "VERSION"))["major"] == 1
    # reset: removal on (STATIC_REMOVAL = 1), nothing counted, no flag, irq low
    assert (await read(tb, "ACTIVE_SETTINGS"))["clutter_removal"] == 1
    await write(tb, "IRQ_ENABLE", frame_done=1)
    await tb.cycles(2)
    assert int(dut.irq.value) == 0

    removal = [False, False, True, True]
    got: list[np.ndarray] = []
    for k in (0, 2):
        await set_removal(tb, removal[k])
        for adc in frames[k:k + 2]:
            await tb.send_frame(adc)
        got += await tb.recv_frames(2, 2 * tb.frame_timeout_cycles())
        await tb.cycles(4)
        assert int(dut.irq.value) == 1, "frame done, enabled: irq"
        assert (await read(tb, "STATUS"))["frame_done"] == 1
        await write(tb, "STATUS", frame_done=1)          # W1C
        await tb.cycles(2)
        assert (await read(tb, "STATUS"))["frame_done"] == 0
        assert int(dut.irq.value) == 0, "flag cleared: irq low"

    assert_packets_equal(got, dma_packets(frames, SMALL4, CHAIN, removal=removal),
                         "removal switched by the register")
    plain = dma_packets(frames[2:], SMALL4, CHAIN, first_frame_id=2, removal=[False] * 2)
    assert any(not np.array_equal(g, p) for g, p in zip(got[-len(plain):], plain, strict=True))

    st = tb.status()
    assert (await read(tb, "FRAMES"))["count"] == 4 == st["frames_out"]
    assert (await read(tb, "PACKETS"))["count"] == len(got) == st["packets_out"]
    assert (await read(tb, "DROPS"))["count"] == 0
    assert (await read(tb, "ERRORS"))["count"] == 0
    assert (await read(tb, "STATUS")) == dict.fromkeys(("frame_done", "drop", "error",
                                                        "cfg_error"), 0)


def test_radar_pipeline_regs() -> None:
    run_cocotb("radar_pipeline", rtl_sources(*PIPELINE_SOURCES), "test_radar_pipeline_regs",
               Path(__file__).parent, CHAIN.hdl_parameters(SMALL4))
