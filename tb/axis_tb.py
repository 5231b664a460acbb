"""Shared cocotb-side testbench helpers: clock, reset, AXI4-Stream source/sink, idle and
backpressure generators. Every block's ``TB`` class builds on :class:`AxisTB`.
"""

from __future__ import annotations

import itertools
import logging
import random
from collections.abc import Iterator

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import RisingEdge
from cocotbext.axi import AxiStreamBus, AxiStreamSink, AxiStreamSource

CLK_PERIOD_NS = 10  # 100 MHz, the paper's FPGA clock


def no_pause() -> Iterator[bool]:
    """Never pause (full throughput)."""
    return itertools.repeat(False)


def random_pause(probability: float, seed: int) -> Iterator[bool]:
    """Pause each cycle independently with ``probability`` (random TVALID gaps / TREADY stalls)."""
    rng = random.Random(seed)
    while True:
        yield rng.random() < probability


def bursty_pause(seed: int, max_run: int = 200, busy_fraction: float = 0.3) -> Iterator[bool]:
    """Long stalls: alternating runs of up to ``max_run`` cycles, paused ``busy_fraction`` of
    the time on average (exercises buffers filling completely)."""
    rng = random.Random(seed)
    while True:
        paused = rng.random() < busy_fraction
        for _ in range(rng.randint(1, max_run)):
            yield paused


class AxisTB:
    """Clock, synchronous active-high reset, and one AXI4-Stream source and sink.

    ``source_prefix`` / ``sink_prefix`` name the DUT's port prefixes (``s_axis``/``m_axis``).
    """

    def __init__(self, dut, source_prefix: str = "s_axis", sink_prefix: str = "m_axis") -> None:
        self.dut = dut
        self.log = logging.getLogger(f"cocotb.tb.{dut._name}")
        self.log.setLevel(logging.INFO)
        cocotb.start_soon(Clock(dut.clk, CLK_PERIOD_NS, unit="ns").start())
        self.source = AxiStreamSource(AxiStreamBus.from_prefix(dut, source_prefix), dut.clk,
                                      dut.rst)
        self.sink = AxiStreamSink(AxiStreamBus.from_prefix(dut, sink_prefix), dut.clk, dut.rst)
        self._in_prefix, self._out_prefix = source_prefix, sink_prefix
        self.cycle = 0
        self.reset_meter()

    # ---- throughput meter (costs simulation time: start it only where it is measured) -----
    def start_meter(self) -> None:
        """Count handshakes on both interfaces every clock: ``in_beats``, ``out_beats``,
        ``in_first`` (clock of the first input handshake), ``out_first``/``out_last``."""
        cocotb.start_soon(self._meter())

    def reset_meter(self) -> None:
        self.in_beats = self.out_beats = 0
        self.in_first = self.out_first = self.out_last = None

    async def _meter(self) -> None:
        d = self.dut
        s_valid, s_ready = (getattr(d, f"{self._in_prefix}_{n}") for n in ("tvalid", "tready"))
        m_valid, m_ready = (getattr(d, f"{self._out_prefix}_{n}") for n in ("tvalid", "tready"))
        while True:
            await RisingEdge(d.clk)
            self.cycle += 1
            if s_valid.value == 1 and s_ready.value == 1:
                self.in_beats += 1
                if self.in_first is None:
                    self.in_first = self.cycle
            if m_valid.value == 1 and m_ready.value == 1:
                self.out_beats += 1
                if self.out_first is None:
                    self.out_first = self.cycle
                self.out_last = self.cycle

    def set_idle_generator(self, generator: Iterator[bool] | None) -> None:
        """TVALID gaps on the source (None = back to back)."""
        self.source.set_pause_generator(generator)

    def set_backpressure_generator(self, generator: Iterator[bool] | None) -> None:
        """TREADY stalls on the sink (None = always ready)."""
        self.sink.set_pause_generator(generator)

    async def wait_quiet(self, quiet: int = 64) -> None:
        """Wait until the source has sent everything and neither interface has had TVALID
        high for ``quiet`` consecutive clocks."""
        await self.source.wait()
        s_valid = getattr(self.dut, f"{self._in_prefix}_tvalid")
        m_valid = getattr(self.dut, f"{self._out_prefix}_tvalid")
        idle = 0
        while idle < quiet:
            await RisingEdge(self.dut.clk)
            idle = 0 if (m_valid.value == 1 or s_valid.value == 1) else idle + 1

    async def cycles(self, n: int) -> None:
        for _ in range(n):
            await RisingEdge(self.dut.clk)

    async def reset(self, cycles: int = 4) -> None:
        """Hold ``rst`` high for ``cycles`` clocks (synchronous, active high)."""
        self.dut.rst.value = 1
        await self.cycles(cycles)
        self.dut.rst.value = 0
        await self.cycles(2)
