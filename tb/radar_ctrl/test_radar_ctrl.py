"""cocotb testbench of ``rtl/regs/radar_ctrl.sv`` (with the generated ``radar_regs`` block)
against ``model/radar_ctrl.py``, through the Python access layer ``host.regs`` and
``cocotbext-axi``'s ``AxiLiteMaster`` with random stalls on all five AXI4-Lite channels.

- ``random_traffic``: every register (every entry of the CFAR_SCALE arrays) read and written
  (read-only ones too: the write is ignored), byte-strobe writes, legal and refused settings
  writes, W1C status clears, interrupt enables, random event pulses (the three consumers'
  frame starts, frame done, packet, drop, error) between the accesses, resets in mid-test;
  every read against the model, the cfg_* outputs on every clock (each may change only at
  the edge after its consumer's frame start), and ``pend_packet_words`` (the pending packet
  length) and irq whenever no access is in flight.
- ``shadow_and_refusal``: directed: settings written in mid-frame show on cfg_* exactly at
  the edge after the next frame start of their consumer, not before and not at another
  consumer's; an out-of-range write (a CFAR kind not built in with a legal max_detections,
  max_detections above CAPS, packet words below CAPS2 or 0, a scale wider than SCALE_W, a
  scale entry not built in) changes nothing and counts once; sticky flags stay set until
  written 1, irq follows the enables.
"""

from __future__ import annotations

import itertools
import os
import random
import subprocess
from pathlib import Path

import cocotb
import pytest
from cocotb.clock import Clock
from cocotb.triggers import FallingEdge, ReadOnly, RisingEdge, with_timeout
from cocotbext.axi import AxiLiteBus, AxiLiteMaster

from host import regs
from model.radar_ctrl import FLAGS, GROUPS, RadarCtrl
from model.radar_regs_map import REGISTERS
from rtlsim.toolchain import param, rtl_sources, run_cocotb, seed

ACCESS_TIMEOUT_US = 20
"""An access not answered within this (a lost or misrouted response) fails the test."""
STARTS = tuple(GROUPS)
EVENTS = (*STARTS, "frame_done", "packet_done", "drop", "error")
CFG = ("cfar_kind", "local_max", "clutter_removal", "max_detections", "cfar_scale",
       "packet_words")
CTRL_PARAMS = ("MAX_DETECTIONS", "PACKET_WORDS", "CFAR_KIND", "CFAR_SCALE", "CLUTTER_REMOVAL",
               "PACKET_WORDS_MIN", "CFAR_KINDS", "N_SCALES", "SCALE_W", "LOCAL_MAX")
"""radar_ctrl's parameters, in the order of RadarCtrl's fields."""
ALL = [(name, i) for name, reg in REGISTERS.items() for i in range(reg.count)]
"""Every register and array entry."""


def _pauses(rng: random.Random, p: float):
    sub = random.Random(rng.random())
    while True:
        yield sub.random() < p


class TB:
    """Clock, reset, the AXI4-Lite master, the event driver and the model beside the DUT."""

    def __init__(self, dut, stall: float = 0.4) -> None:
        self.dut = dut
        self.rng = random.Random(seed())
        self.model = RadarCtrl(*(param(n) for n in CTRL_PARAMS))
        cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start())
        self.axil = AxiLiteMaster(AxiLiteBus.from_prefix(dut, "s_axil"), dut.clk, dut.rst)
        for ch in (self.axil.write_if.aw_channel, self.axil.write_if.w_channel,
                   self.axil.write_if.b_channel, self.axil.read_if.ar_channel,
                   self.axil.read_if.r_channel):
            ch.set_pause_generator(_pauses(self.rng, stall))
        self.busy = 0            # accesses in flight: no events, no irq check
        self.settle = 0          # cycles left before irq is compared again
        self.event_p = dict.fromkeys(EVENTS, 0.0)
        self.pulse: dict[str, bool] = {}   # one-shot events for the next edge
        self.cfg_changes = 0
        for name in EVENTS:
            getattr(dut, name).value = 0
        dut.rst.value = 1
        cocotb.start_soon(self._driver())

    async def _driver(self) -> None:
        """Each cycle: events at the falling edge, model step at the rising edge, compare."""
        dut, m = self.dut, self.model
        while True:
            await FallingEdge(dut.clk)
            ev = {n: (not self.busy and self.rng.random() < self.event_p[n])
                  or self.pulse.get(n, False) for n in EVENTS}
            self.pulse = {}
            for n in EVENTS:
                getattr(dut, n).value = int(ev[n])
            await RisingEdge(dut.clk)
            rst = bool(dut.rst.value)
            before = m.active_fields()
            if rst:
                m.reset()
            else:
                m.step(**ev)
            self.cfg_changes += m.active_fields() != before
            await ReadOnly()
            got = {n: int(getattr(dut, f"cfg_{n}").value) for n in CFG}
            assert got == m.active_fields(), f"cfg {got} != model {m.active_fields()}"
            if self.busy or self.settle:
                self.settle = max(self.settle - 1, 0)
            else:
                assert int(dut.irq.value) == m.irq, f"irq {int(dut.irq.value)} != {m.irq}"
                pend = int(dut.pend_packet_words.value)
                assert pend == m.pend_packet_words(), f"pend_packet_words {pend}"

    async def reset(self, cycles: int = 3) -> None:
        await FallingEdge(self.dut.clk)
        self.dut.rst.value = 1
        for _ in range(cycles):
            await RisingEdge(self.dut.clk)
        await FallingEdge(self.dut.clk)
        self.dut.rst.value = 0
        self.settle = 2

    async def write(self, name: str, word: int, offset: int = 0, nbytes: int = 4,
                    index: int = 0) -> None:
        """Write bytes ``offset .. offset+nbytes-1`` of ``word`` to register ``name`` (entry
        ``index`` of an array)."""
        addr = regs.address(name, index)
        self.busy += 1
        data = word.to_bytes(4, "little")[offset:offset + nbytes]
        await with_timeout(self.axil.write(addr + offset, data), ACCESS_TIMEOUT_US, "us")
        strb = ((1 << nbytes) - 1) << offset
        self.model.write(addr, word, strb)
        self.busy -= 1
        self.settle = 2

    async def read(self, name: str, index: int = 0) -> int:
        """Read register ``name`` (entry ``index`` of an array), compare with the model,
        return the word."""
        self.busy += 1
        addr = regs.address(name, index)
        resp = await with_timeout(self.axil.read(addr, 4), ACCESS_TIMEOUT_US, "us")
        self.busy -= 1
        got = int.from_bytes(resp.data, "little")
        want = self.model.read(addr)
        assert got == want, f"{name}[{index}]: read {got:#010x}, model {want:#010x}"
        return got

    def cfg(self) -> dict[str, int]:
        """The cfg_* outputs now."""
        return {n: int(getattr(self.dut, f"cfg_{n}").value) for n in CFG}

    async def cycles(self, n: int) -> None:
        for _ in range(n):
            await RisingEdge(self.dut.clk)

    async def pulse_cycle(self, name: str) -> None:
        """Pulse event ``name`` in the next cycle; returns in that cycle (read-only phase,
        before its rising edge)."""
        self.pulse = {name: True}
        await FallingEdge(self.dut.clk)
        await ReadOnly()

    async def frame_start(self, start: str) -> None:
        """One pulse of frame start ``start``, returning after its edge."""
        await self.pulse_cycle(start)
        await RisingEdge(self.dut.clk)


def _kinds(tb: TB, built: bool) -> list[int]:
    """The CFAR kinds built in (or not) by the model's CFAR_KINDS."""
    return [k for k in range(4) if bool(tb.model.cfar_kinds >> k & 1) == built]


def _settings(tb: TB, legal: bool) -> int:
    """A random SETTINGS word, in range or (legal=False) with some field out of range."""
    rng, md = tb.rng, tb.model.max_detections
    kind, maxdet = rng.choice(_kinds(tb, True)), rng.randint(1, md)
    if not legal:
        bad = rng.choice(("kind", "zero", "above") if _kinds(tb, False) else ("zero", "above"))
        kind = rng.choice(_kinds(tb, False)) if bad == "kind" else kind
        maxdet = {"zero": 0, "above": rng.randint(md + 1, 0xFFFF) if md < 0xFFFF else 0}.get(
            bad, maxdet)
    return regs.encode("SETTINGS", cfar_kind=kind, clutter_removal=rng.randint(0, 1),
                       local_max=rng.randint(0, 1), max_detections=maxdet)


def _packet(tb: TB, legal: bool) -> int:
    """A random PACKET word, in range or (legal=False) out of range."""
    lo, hi = tb.model.packet_words_min, tb.model.packet_words
    bad = [0] + ([lo - 1] if lo > 1 else []) + ([hi + 1] if hi < 0xFFFF else [])
    return regs.encode("PACKET", words=tb.rng.randint(lo, hi) if legal else tb.rng.choice(bad))


def _scale(tb: TB, legal: bool) -> tuple[int, int]:
    """A random (CFAR_SCALE entry, value), in range or (legal=False) out of range."""
    rng, m = tb.rng, tb.model
    if legal:
        return rng.randrange(m.n_scales), rng.getrandbits(m.scale_w)
    bad_entry = m.n_scales < REGISTERS["CFAR_SCALE"].count and (
        m.scale_w == 32 or rng.random() < 0.5)
    if bad_entry:
        return rng.randrange(m.n_scales, REGISTERS["CFAR_SCALE"].count), rng.getrandbits(32)
    return rng.randrange(m.n_scales), rng.randrange(1 << m.scale_w, 1 << 32)


@cocotb.test()
async def random_traffic(dut) -> None:
    tb = TB(dut)
    await tb.reset()
    m, rng = tb.model, tb.rng
    for name, i in ALL:                                      # reset values
        await tb.read(name, i)
    for name, i in ALL:                 # every register written (read-only: ignored), read
        await tb.write(name, rng.getrandbits(32), index=i)
        await tb.read(name, i)
    refused_before = 0
    for step in range(int(os.environ.get("RC_STEPS", "400"))):
        op = rng.random()
        names = list(REGISTERS)
        if op < 0.25:
            name = rng.choice(("SETTINGS", "PACKET"))
            legal = rng.random() < 0.6
            word = _settings(tb, legal) if name == "SETTINGS" else _packet(tb, legal)
            if rng.random() < 0.3:                            # one half-word only
                off = rng.choice((0, 2))
                await tb.write(name, word, off, 2)
            else:
                await tb.write(name, word)
        elif op < 0.35:
            entry, value = _scale(tb, rng.random() < 0.7)
            if rng.random() < 0.5:                            # one byte only
                await tb.write("CFAR_SCALE", value, rng.choice((0, 1, 2, 3)), 1, index=entry)
            else:
                await tb.write("CFAR_SCALE", value, index=entry)
        elif op < 0.45:
            await tb.write("IRQ_ENABLE", rng.getrandbits(4))
        elif op < 0.55:
            await tb.write("STATUS", rng.getrandbits(4))
        elif op < 0.62:                                      # read-only: ignored
            name = rng.choice([n for n in names if REGISTERS[n].fields[0].sw == "r"])
            await tb.write(name, rng.getrandbits(32), index=rng.randrange(REGISTERS[name].count))
        elif op < 0.85:
            name = rng.choice(names)
            await tb.read(name, rng.randrange(REGISTERS[name].count))
        else:                                                # events, frames
            tb.event_p = {**dict.fromkeys(STARTS, 0.05), "frame_done": 0.05,
                          "packet_done": 0.2, "drop": 0.02, "error": 0.02}
            await tb.cycles(rng.randint(5, 60))
            tb.event_p = dict.fromkeys(EVENTS, 0.0)
        if step in (150, 300):                               # mid-test reset
            refused_before += m.counts["CFG_ERRORS"]
            await tb.reset(rng.randint(1, 4))
            for name in REGISTERS:
                await tb.read(name, rng.randrange(REGISTERS[name].count))
    for name, i in ALL:
        await tb.read(name, i)
    assert refused_before + m.counts["CFG_ERRORS"] > 0, "no refused write"
    assert tb.cfg_changes > 0, "no settings change seen on cfg_*"


@cocotb.test()
async def shadow_and_refusal(dut) -> None:
    tb = TB(dut, stall=0.3)
    await tb.reset()
    m = tb.model
    await tb.write("IRQ_ENABLE", regs.encode("IRQ_ENABLE", frame_done=1, cfg_error=1))
    md = m.max_detections
    kind = max(_kinds(tb, True))
    new = regs.encode("SETTINGS", cfar_kind=kind, clutter_removal=1 - m.clutter_removal,
                      local_max=1 - m.local_max, max_detections=max(1, md - 1))
    for start in STARTS:
        await tb.frame_start(start)
    await tb.cycles(7)
    old = tb.cfg()
    await tb.write("SETTINGS", new)                          # mid-frame of every consumer
    await tb.write("PACKET", regs.encode("PACKET", words=max(m.packet_words_min,
                                                                 m.packet_words // 2)))
    await tb.write("CFAR_SCALE", (1 << m.scale_w) - 1, index=m.n_scales - 1)
    await tb.cycles(20)
    assert tb.cfg() == old, "applied mid-frame"
    assert regs.decode("SETTINGS", await tb.read("SETTINGS"))["cfar_kind"] == kind
    await tb.read("ACTIVE_SETTINGS")
    # each consumer's settings change exactly at the edge after its own frame start
    for start, fields in GROUPS.items():
        before = tb.cfg()
        await tb.pulse_cycle(start)                          # the frame-start cycle
        assert tb.cfg() == before
        pend = int(dut.pend_packet_words.value)              # what the packetizer takes
        await RisingEdge(dut.clk)
        await ReadOnly()                                     # the cycle after it
        after = tb.cfg()
        assert after == m.active_fields()
        if start == "packet_start":
            assert after["packet_words"] == pend, "copy != the length taken in the pulse"
        mine = {{"words": "packet_words", "scale": "cfar_scale"}.get(f, f) for _, f in fields}
        assert {n for n in CFG if after[n] != before[n]} <= mine, f"{start} changed others"
        assert after != before or start == "packet_start" and \
            m.packet_words // 2 < m.packet_words_min, f"{start} applied nothing"
        await tb.read("ACTIVE_SETTINGS")
        await tb.read("ACTIVE_PACKET")
        await tb.read("ACTIVE_CFAR_SCALE", m.n_scales - 1)
    # refused writes: nothing of them applied, each counted once
    pending = await tb.read("SETTINGS")
    bad = [regs.encode("SETTINGS", cfar_kind=k, max_detections=1) for k in _kinds(tb, False)]
    bad.append(regs.encode("SETTINGS", cfar_kind=0, max_detections=0))
    if md < 0xFFFF:
        bad.append(regs.encode("SETTINGS", cfar_kind=0, max_detections=md + 1))
    for word in bad:
        await tb.write("SETTINGS", word)
        assert await tb.read("SETTINGS") == pending, "refused write half applied"
    bad_scales = [(m.n_scales, 1)] if m.n_scales < REGISTERS["CFAR_SCALE"].count else []
    if m.scale_w < 32:
        bad_scales.append((0, 1 << m.scale_w))
    for entry, value in bad_scales:
        was = await tb.read("CFAR_SCALE", entry)
        await tb.write("CFAR_SCALE", value, index=entry)
        assert await tb.read("CFAR_SCALE", entry) == was, "refused scale applied"
    await tb.write("PACKET", regs.encode("PACKET", words=0))
    assert await tb.read("CFG_ERRORS") == len(bad) + len(bad_scales) + 1
    status = regs.decode("STATUS", await tb.read("STATUS"))
    assert status["cfg_error"] == 1
    await tb.cycles(3)
    assert int(dut.irq.value) == 1
    for start in STARTS:
        await tb.frame_start(start)
    await tb.cycles(3)
    await tb.read("ACTIVE_SETTINGS")                          # unchanged by the refusals
    # sticky W1C: writing 0 keeps, writing 1 clears, an event sets again
    await tb.write("STATUS", 0)
    assert regs.decode("STATUS", await tb.read("STATUS"))["cfg_error"] == 1
    await tb.write("STATUS", regs.encode("STATUS", **dict.fromkeys(FLAGS, 1)))
    assert await tb.read("STATUS") == 0
    await tb.cycles(3)
    assert int(dut.irq.value) == 0
    await tb.pulse_cycle("frame_done")
    await tb.cycles(4)
    assert int(dut.irq.value) == 1
    assert regs.decode("STATUS", await tb.read("STATUS"))["frame_done"] == 1
    await tb.cycles(50)
    assert regs.decode("STATUS", await tb.read("STATUS"))["frame_done"] == 1, "not sticky"
    for name, i in ALL:
        await tb.read(name, i)


PARAMS = [
    dict(MAX_DETECTIONS=256, PACKET_WORDS=1024, CFAR_KIND=0, CFAR_SCALE=0x0030_0000,
         CLUTTER_REMOVAL=0, PACKET_WORDS_MIN=1, CFAR_KINDS=0b0111, N_SCALES=13, SCALE_W=32,
         LOCAL_MAX=0),
    dict(MAX_DETECTIONS=5, PACKET_WORDS=65535, CFAR_KIND=3, CFAR_SCALE=0x0004_5678,
         CLUTTER_REMOVAL=1, PACKET_WORDS_MIN=40, CFAR_KINDS=0b1001, N_SCALES=61, SCALE_W=20,
         LOCAL_MAX=1),
]


@pytest.mark.parametrize("parameters", PARAMS, ids=lambda p: f"md{p['MAX_DETECTIONS']}")
def test_radar_ctrl(parameters: dict) -> None:
    here = Path(__file__).resolve().parent
    run_cocotb("radar_ctrl", rtl_sources("regs/*.sv"), "test_radar_ctrl", here,
               parameters=parameters)


@pytest.mark.parametrize("name,value", [("MAX_DETECTIONS", 0), ("MAX_DETECTIONS", 65536),
                                        ("PACKET_WORDS", 0), ("CFAR_KIND", 3),
                                        ("PACKET_WORDS_MIN", 2000), ("N_SCALES", 62),
                                        ("SCALE_W", 33), ("CFAR_KINDS", 0)])
def test_bad_parameter_stops_elaboration(name: str, value: int) -> None:
    """An illegal parameter stops elaboration with $fatal naming it."""
    files = [str(p) for p in rtl_sources("regs/*.sv")]
    r = subprocess.run(["verilator", "--lint-only", *files, "--top-module", "radar_ctrl",
                        f"-G{name}={value}"], capture_output=True, text=True)
    assert r.returncode != 0
    assert f"{name}={value}" in r.stdout + r.stderr


def test_model_refuses_bad_parameters() -> None:
    for kw in (dict(max_detections=0), dict(packet_words=70000), dict(cfar_kind=3),
               dict(n_scales=62), dict(scale_w=16, cfar_scale=1 << 16),
               dict(packet_words_min=2000)):
        with pytest.raises(ValueError):
            RadarCtrl(**kw)
    assert list(itertools.islice(_pauses(random.Random(1), 0.0), 3)) == [False] * 3
