"""cocotb testbench of ``rtl/regs/radar_ctrl.sv`` (with the generated ``radar_regs`` block)
against ``model/radar_ctrl.py``, through the Python access layer ``host.regs`` and
``cocotbext-axi``'s ``AxiLiteMaster`` with random stalls on all five AXI4-Lite channels.

- ``random_traffic``: every register read and written (read-only ones too: the write is
  ignored), byte-strobe writes, legal and refused settings writes, W1C status clears,
  interrupt enables, random event pulses (frame start/done, packet, drop, error) between the
  accesses, resets in mid-test; every read against the model, the cfg_* outputs on every
  clock (they may change only at the edge after frame_start) and irq whenever no access is
  in flight.
- ``shadow_and_refusal``: directed: a setting written in mid-frame shows on cfg_* exactly at
  the edge after the next frame_start pulse, not before; an out-of-range write (reserved CFAR
  kind with a legal max_detections, max_detections above CAPS, packet words 0) changes nothing
  and counts once; sticky flags stay set until written 1, irq follows the enables.
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
from model.radar_ctrl import FLAGS, RadarCtrl
from model.radar_regs_map import REGISTERS
from rtlsim.toolchain import param, rtl_sources, run_cocotb, seed

ACCESS_TIMEOUT_US = 20
"""An access not answered within this (a lost or misrouted response) fails the test."""
EVENTS = ("frame_start", "frame_done", "packet_done", "drop", "error")
CFG = ("cfar_kind", "clutter_removal", "max_detections", "cfar_scale", "packet_words")


def _pauses(rng: random.Random, p: float):
    sub = random.Random(rng.random())
    while True:
        yield sub.random() < p


class TB:
    """Clock, reset, the AXI4-Lite master, the event driver and the model beside the DUT."""

    def __init__(self, dut, stall: float = 0.4) -> None:
        self.dut = dut
        self.rng = random.Random(seed())
        self.model = RadarCtrl(param("MAX_DETECTIONS"), param("PACKET_WORDS"),
                               param("CFAR_KIND"), param("CFAR_SCALE"),
                               bool(param("CLUTTER_REMOVAL")))
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

    async def reset(self, cycles: int = 3) -> None:
        await FallingEdge(self.dut.clk)
        self.dut.rst.value = 1
        for _ in range(cycles):
            await RisingEdge(self.dut.clk)
        await FallingEdge(self.dut.clk)
        self.dut.rst.value = 0
        self.settle = 2

    async def write(self, name: str, word: int, offset: int = 0, nbytes: int = 4) -> None:
        """Write bytes ``offset .. offset+nbytes-1`` of ``word`` to register ``name``."""
        addr = regs.address(name)
        self.busy += 1
        data = word.to_bytes(4, "little")[offset:offset + nbytes]
        await with_timeout(self.axil.write(addr + offset, data), ACCESS_TIMEOUT_US, "us")
        strb = ((1 << nbytes) - 1) << offset
        self.model.write(addr, word, strb)
        self.busy -= 1
        self.settle = 2

    async def read(self, name: str) -> int:
        """Read register ``name``, compare with the model, return the word."""
        self.busy += 1
        resp = await with_timeout(self.axil.read(regs.address(name), 4), ACCESS_TIMEOUT_US,
                                  "us")
        self.busy -= 1
        got = int.from_bytes(resp.data, "little")
        want = self.model.read(regs.address(name))
        assert got == want, f"{name}: read {got:#010x}, model {want:#010x}"
        return got

    async def cycles(self, n: int) -> None:
        for _ in range(n):
            await RisingEdge(self.dut.clk)

    async def pulse_cycle(self, name: str) -> None:
        """Pulse event ``name`` in the next cycle; returns in that cycle (read-only phase,
        before its rising edge)."""
        self.pulse = {name: True}
        await FallingEdge(self.dut.clk)
        await ReadOnly()

    async def frame_start(self) -> None:
        """One frame_start pulse, returning after its edge."""
        await self.pulse_cycle("frame_start")
        await RisingEdge(self.dut.clk)


def _settings(tb: TB, legal: bool) -> int:
    """A random SETTINGS word, in range or (legal=False) with some field out of range."""
    rng, md = tb.rng, tb.model.max_detections
    kind, maxdet = rng.choice((0, 1)), rng.randint(1, md)
    if not legal:
        bad = rng.choice(("kind", "zero", "above"))
        kind = rng.choice((2, 3)) if bad == "kind" else kind
        maxdet = {"zero": 0, "above": rng.randint(md + 1, 0xFFFF) if md < 0xFFFF else 0}.get(
            bad, maxdet)
    return regs.encode("SETTINGS", cfar_kind=kind, clutter_removal=rng.randint(0, 1),
                       max_detections=maxdet)


@cocotb.test()
async def random_traffic(dut) -> None:
    tb = TB(dut)
    await tb.reset()
    m, rng = tb.model, tb.rng
    for name in REGISTERS:                                    # reset values
        await tb.read(name)
    for name in REGISTERS:              # every register written (read-only: ignored), read
        await tb.write(name, rng.getrandbits(32))
        await tb.read(name)
    refused_before = 0
    for step in range(int(os.environ.get("RC_STEPS", "400"))):
        op = rng.random()
        names = list(REGISTERS)
        if op < 0.25:
            name = rng.choice(("SETTINGS", "PACKET"))
            legal = rng.random() < 0.6
            if name == "SETTINGS":
                word = _settings(tb, legal)
            else:
                pw = m.packet_words
                words = rng.randint(1, pw) if legal else rng.choice(
                    (0, pw + 1 if pw < 0xFFFF else 0))
                word = regs.encode("PACKET", words=words)
            if rng.random() < 0.3:                            # one half-word only
                off = rng.choice((0, 2))
                await tb.write(name, word, off, 2)
            else:
                await tb.write(name, word)
        elif op < 0.35:
            await tb.write("CFAR_SCALE", rng.getrandbits(32), rng.choice((0, 1, 2, 3)), 1)
        elif op < 0.45:
            await tb.write("IRQ_ENABLE", rng.getrandbits(4))
        elif op < 0.55:
            await tb.write("STATUS", rng.getrandbits(4))
        elif op < 0.62:                                      # read-only: ignored
            name = rng.choice([n for n in names if REGISTERS[n].fields[0].sw == "r"])
            await tb.write(name, rng.getrandbits(32))
        elif op < 0.85:
            name = rng.choice(names)
            await tb.read(name)
        else:                                                # events, frames
            tb.event_p = {"frame_start": 0.05, "frame_done": 0.05, "packet_done": 0.2,
                          "drop": 0.02, "error": 0.02}
            await tb.cycles(rng.randint(5, 60))
            tb.event_p = dict.fromkeys(EVENTS, 0.0)
        if step in (150, 300):                               # mid-test reset
            refused_before += m.counts["CFG_ERRORS"]
            await tb.reset(rng.randint(1, 4))
            for name in REGISTERS:
                await tb.read(name)
    for name in REGISTERS:
        await tb.read(name)
    assert refused_before + m.counts["CFG_ERRORS"] > 0, "no refused write"
    assert tb.cfg_changes > 0, "no settings change seen on cfg_*"


@cocotb.test()
async def shadow_and_refusal(dut) -> None:
    tb = TB(dut, stall=0.3)
    await tb.reset()
    m = tb.model
    await tb.write("IRQ_ENABLE", regs.encode("IRQ_ENABLE", frame_done=1, cfg_error=1))
    md = m.max_detections
    new = regs.encode("SETTINGS", cfar_kind=1 - m.cfar_kind, clutter_removal=1,
                      max_detections=max(1, md - 1))
    await tb.frame_start()
    await tb.cycles(7)
    old = {n: int(getattr(dut, f"cfg_{n}").value) for n in CFG}
    await tb.write("SETTINGS", new)                          # mid-frame
    await tb.write("PACKET", regs.encode("PACKET", words=max(1, m.packet_words // 2)))
    await tb.cycles(20)
    assert {n: int(getattr(dut, f"cfg_{n}").value) for n in CFG} == old, "applied mid-frame"
    assert regs.decode("SETTINGS", await tb.read("SETTINGS"))["cfar_kind"] == 1 - m.cfar_kind
    await tb.read("ACTIVE_SETTINGS")
    await tb.pulse_cycle("frame_start")                       # the frame_start cycle
    assert {n: int(getattr(dut, f"cfg_{n}").value) for n in CFG} == old
    await RisingEdge(dut.clk)
    await ReadOnly()                                          # the cycle after it
    got = regs.decode("SETTINGS", new)
    assert int(dut.cfg_cfar_kind.value) == got["cfar_kind"]
    assert int(dut.cfg_max_detections.value) == got["max_detections"]
    await tb.read("ACTIVE_SETTINGS")
    await tb.read("ACTIVE_PACKET")
    # refused writes: nothing of them applied, each counted once
    pending = await tb.read("SETTINGS")
    bad = [regs.encode("SETTINGS", cfar_kind=2, max_detections=1),          # reserved kind
           regs.encode("SETTINGS", cfar_kind=0, max_detections=0)]
    if md < 0xFFFF:
        bad.append(regs.encode("SETTINGS", cfar_kind=0, max_detections=md + 1))
    for word in bad:
        await tb.write("SETTINGS", word)
        assert await tb.read("SETTINGS") == pending, "refused write half applied"
    await tb.write("PACKET", regs.encode("PACKET", words=0))
    assert await tb.read("CFG_ERRORS") == len(bad) + 1
    status = regs.decode("STATUS", await tb.read("STATUS"))
    assert status["cfg_error"] == 1
    await tb.cycles(3)
    assert int(dut.irq.value) == 1
    await tb.frame_start()
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
    for name in REGISTERS:
        await tb.read(name)


PARAMS = [
    dict(MAX_DETECTIONS=256, PACKET_WORDS=1024, CFAR_KIND=0, CFAR_SCALE=0x0030_0000,
         CLUTTER_REMOVAL=0),
    dict(MAX_DETECTIONS=5, PACKET_WORDS=65535, CFAR_KIND=1, CFAR_SCALE=0x1234_5678,
         CLUTTER_REMOVAL=1),
]


@pytest.mark.parametrize("parameters", PARAMS, ids=lambda p: f"md{p['MAX_DETECTIONS']}")
def test_radar_ctrl(parameters: dict) -> None:
    here = Path(__file__).resolve().parent
    run_cocotb("radar_ctrl", rtl_sources("regs/*.sv"), "test_radar_ctrl", here,
               parameters=parameters)


@pytest.mark.parametrize("name,value", [("MAX_DETECTIONS", 0), ("MAX_DETECTIONS", 65536),
                                        ("PACKET_WORDS", 0), ("CFAR_KIND", 2)])
def test_bad_parameter_stops_elaboration(name: str, value: int) -> None:
    """An illegal parameter stops elaboration with $fatal naming it."""
    files = [str(p) for p in rtl_sources("regs/*.sv")]
    r = subprocess.run(["verilator", "--lint-only", *files, "--top-module", "radar_ctrl",
                        f"-G{name}={value}"], capture_output=True, text=True)
    assert r.returncode != 0
    assert f"{name}={value}" in r.stdout + r.stderr


def test_model_refuses_bad_parameters() -> None:
    for kw in (dict(max_detections=0), dict(packet_words=70000), dict(cfar_kind=3)):
        with pytest.raises(ValueError):
            RadarCtrl(**kw)
    assert list(itertools.islice(_pauses(random.Random(1), 0.0), 3)) == [False] * 3
