"""cocotb test of the register block inside ``radar_pipeline`` (docs/regs.md), small 4-TX set
with ``STATIC_REMOVAL = 1``: every access through the AXI4-Lite slave ``s_axil_*``
(cocotbext-axi ``AxiLiteMaster``, random stalls on all five channels) with the register names
of ``host.regs``.

ID and version read; every register (every entry of the CFAR_SCALE tables) written with a
random word and read back against ``model.radar_ctrl`` (refused writes counted as there),
then out-of-range writes (packet words 0, below CAPS2 and above CAPS, a CFAR kind not built
in, max_detections 0, a scale entry not built in) refused whole and counted; static-clutter
removal switched off, two frames, switched on between frames, two more: the DMA packets equal
the model's with the removal off for the first two and on from the next frame
(``dma_packets(removal=...)``), ACTIVE_SETTINGS follows; PACKET.words written while frame 4
streams into the packetizer: ACTIVE_PACKET keeps the old length until that frame's last
word, frame 4 is cut with the old length and frame 5 with the new one; a third length set
as by a write accepted in the last cycle before frame 6's first word (the pending register
deposited in the cycle of that word) cuts frame 6 and shows in ACTIVE_PACKET (the model
with ``FrameSettings(packet_words=...)``); the FRAMES / PACKETS counters equal what the DMA
delivered (and the status ports), no drops or errors; irq rises on frame done when enabled
and falls when STATUS.frame_done is written 1.
"""

from __future__ import annotations

import random
from pathlib import Path

import cocotb
import numpy as np
from cocotb.triggers import FallingEdge
from test_radar_pipeline import SMALL4, adc_frames, poll, watched

from host import regs
from model.axis_packetizer import packets_per_frame
from model.radar_ctrl import RadarCtrl
from model.radar_pipeline import FrameSettings, PipelineParams, dma_packets
from model.radar_regs_map import REGISTERS
from rtlsim.axis import chirp_bursts, random_pause
from rtlsim.pipeline import PipelineTB, assert_packets_equal
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
    refused = (await read(tb, "CFG_ERRORS"))["count"]
    await write(tb, "SETTINGS", **fields)
    await tb.cycles(4)
    assert (await read(tb, "ACTIVE_SETTINGS"))["clutter_removal"] == int(on)
    assert (await read(tb, "CFG_ERRORS"))["count"] == refused


async def set_at_first_word(dut, nth: int, words: int) -> None:
    """Set the pending ``PACKET.words`` to ``words`` in the cycle of the ``nth`` frame's first
    word the packetizer takes from now on (its beat with ``pk_mid_q`` low), as a write
    accepted in the cycle before would: that frame is cut with ``words`` and ``ACTIVE_PACKET``
    shows it after that cycle (docs/regs.md, "Packetizer: its input"). The write's timing
    through AXI4-Lite cannot be aimed at one clock, so the pending register of ``u_ctrl``
    is deposited (at the falling edge, where the beat is already decided: the packetizer's
    TREADY does not depend on the length at a frame's first word of at least 2)."""
    seen = 0
    while seen < nth:
        await FallingEdge(dut.clk)
        if int(dut.pk_mid_q.value) == 0 and int(dut.pk_tvalid.value) \
                and int(dut.pk_tready.value):
            seen += 1
    pend = int(dut.u_ctrl.pend_q.value)
    dut.u_ctrl.pend_q.value = (pend & ~0xFFFF) | words   # packet_words: the struct's LSBs


def ctrl_model() -> RadarCtrl:
    """``radar_ctrl`` as the top builds it for CHAIN on SMALL4 (mode 0: no detector)."""
    return RadarCtrl(max_detections=256, packet_words=CHAIN.packet_words, cfar_kind=0,
                     clutter_removal=True, packet_words_min=2, cfar_kinds=0b0001,
                     n_scales=2 * (2 + 4) + 1)


async def every_register(tb: PipelineTB, rng: random.Random) -> None:
    """Every register and table entry written with a random word and read back, against the
    model (the pipeline idle: the removal and packet settings follow at once, the detector's
    never, as in the top without a detector); then out-of-range writes refused and counted;
    the settings restored to their reset values at the end."""
    m = ctrl_model()
    at = [(name, i) for name, reg in REGISTERS.items() for i in range(reg.count)]
    for name, i in at:
        word = rng.getrandbits(32)
        if name == "SETTINGS" and rng.random() < 0.5:   # some legal ones too
            word = regs.encode(name, clutter_removal=rng.randint(0, 1),
                               max_detections=rng.randint(1, 256))
        await tb.write32(regs.address(name, i), word)
        m.write(regs.address(name, i), word)
        await tb.cycles(2)
        m.step(removal_start=True, packet_start=True)
        for rname, ri in (rng.sample(at, 3) + [(name, i), ("CFG_ERRORS", 0)]):
            got = await tb.read32(regs.address(rname, ri))
            assert got == m.read(regs.address(rname, ri)), f"{rname}[{ri}] after {name}[{i}]"
    for name, i in at:
        assert await tb.read32(regs.address(name, i)) == m.read(regs.address(name, i)), name
    refused = m.counts["CFG_ERRORS"]
    bad = [("PACKET", 0, regs.encode("PACKET", words=0)),
           ("PACKET", 0, regs.encode("PACKET", words=1)),                  # below CAPS2
           ("PACKET", 0, regs.encode("PACKET", words=CHAIN.packet_words + 1)),
           ("SETTINGS", 0, regs.encode("SETTINGS", cfar_kind=1, max_detections=1)),
           ("SETTINGS", 0, regs.encode("SETTINGS", max_detections=0)),
           ("CFAR_SCALE", m.n_scales, 5)]
    for name, i, word in bad:
        before = await tb.read32(regs.address(name, i))
        await tb.write32(regs.address(name, i), word)
        assert await tb.read32(regs.address(name, i)) == before, f"{name} half applied"
    assert (await read(tb, "CFG_ERRORS"))["count"] == refused + len(bad)
    await write(tb, "SETTINGS", clutter_removal=1, max_detections=256)
    await write(tb, "PACKET", words=CHAIN.packet_words)
    await write(tb, "IRQ_ENABLE")
    await write(tb, "STATUS", frame_done=1, drop=1, error=1, cfg_error=1)
    assert (await read(tb, "STATUS"))["cfg_error"] == 0


@cocotb.test()
async def registers_through_axi_lite(dut) -> None:
    tb = watched(dut)
    rng = random.Random(seed())
    tb.attach_regs(lambda: random_pause(AXIL_STALL, rng.randrange(1 << 30)))
    tb.set_idle_generator(chirp_bursts(SMALL4.n_range, SMALL4.n_range))
    tb.set_backpressure_generator(random_pause(0.3, 2))
    frames = adc_frames("small4", SMALL4, 4)
    await tb.reset()

    assert await tb.read32(regs.address("ID")) == regs.ID_VALUE
    assert await read(tb, "VERSION") == {"minor": 1, "major": 1}
    await every_register(tb, rng)
    refused = (await read(tb, "CFG_ERRORS"))["count"]
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

    # packet length written while frame 4 streams into the packetizer: from frame 5 on
    more = adc_frames("small4", SMALL4, 7)[4:]
    new_words, last_words = 96, 128
    for adc in more:
        await tb.send_frame(adc)
    fw = SMALL4.num_tx * SMALL4.n_range * SMALL4.n_doppler
    await poll(tb, lambda: int(dut.frames_out.value) == 4 and int(dut.pk_mid_q.value) == 1,
               "frame 4 streaming into the packetizer (frames_out 4, pk_mid_q 1)")
    await tb.cycles(fw // 4)
    assert int(dut.frames_out.value) == 4 and int(dut.pk_mid_q.value) == 1
    await write(tb, "PACKET", words=new_words)
    assert int(dut.frames_out.value) == 4 and int(dut.pk_mid_q.value) == 1, "not mid-frame"
    assert (await read(tb, "ACTIVE_PACKET"))["words"] == CHAIN.packet_words, "applied mid-frame"
    hit = cocotb.start_soon(set_at_first_word(dut, 2, last_words))
    n_pk = (packets_per_frame(fw, CHAIN.packet_words) + packets_per_frame(fw, new_words)
            + packets_per_frame(fw, last_words))
    late = [await tb.recv_packet(2 * tb.frame_timeout_cycles()) for _ in range(n_pk)]
    assert hit.done()
    assert (await read(tb, "ACTIVE_PACKET"))["words"] == last_words
    lengths = [CHAIN.packet_words] * 5 + [new_words, last_words]
    want = dma_packets([*frames, *more], SMALL4, CHAIN, removal=removal + [True] * 3,
                       settings=FrameSettings(packet_words=lengths))
    assert_packets_equal(late, want[len(got):], "packet length written in mid-frame")
    got += late
    assert (await read(tb, "CFG_ERRORS"))["count"] == refused

    st = tb.status()
    assert (await read(tb, "FRAMES"))["count"] == 7 == st["frames_out"]
    assert (await read(tb, "PACKETS"))["count"] == len(got) == st["packets_out"]
    assert (await read(tb, "DROPS"))["count"] == 0
    assert (await read(tb, "ERRORS"))["count"] == 0
    assert (await read(tb, "STATUS")) == {"frame_done": 1, "drop": 0, "error": 0,
                                          "cfg_error": 0}


def test_radar_pipeline_regs() -> None:
    run_cocotb("radar_pipeline", rtl_sources(*PIPELINE_SOURCES), "test_radar_pipeline_regs",
               Path(__file__).parent, CHAIN.hdl_parameters(SMALL4))
