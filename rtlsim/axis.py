"""Shared cocotb-side testbench base: clock, reset, AXI4-Stream source/sink with words in and
out, status reads, idle and backpressure generators. Every block's ``TB`` class (and
:class:`rtlsim.pipeline.PipelineTB`) builds on :class:`AxisTB`. Imported only inside a cocotb
simulation.
"""

from __future__ import annotations

import itertools
import logging
import random
from collections.abc import Iterable, Iterator, Sequence

import cocotb
import numpy as np
from cocotb.clock import Clock
from cocotb.triggers import RisingEdge, with_timeout
from cocotbext.axi import AxiStreamBus, AxiStreamFrame, AxiStreamSink, AxiStreamSource

from model.axis_packetizer import bytes_to_words, words_to_bytes
from rtlsim.toolchain import seed

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


def chirp_bursts(active: int, idle: int) -> Iterator[bool]:
    """ADC timing: chirps at one sample per clock (``active`` clocks), then ``idle`` clocks
    between chirps (the real chirp repetition leaves the ADC idle most of the time)."""
    while True:
        yield from [False] * active
        yield from [True] * idle


def unpack_frame(frame: AxiStreamFrame, lanes: int) -> tuple[np.ndarray, list[int]]:
    """A received AXI-Stream frame -> (uint32 words (beats, lanes), TUSER of each beat)."""
    words = bytes_to_words(bytes(frame.tdata), lanes)
    n, tuser = len(words), frame.tuser
    if not tuser:  # no TUSER port (None or empty)
        return words, [0] * n
    if isinstance(tuser, int):
        return words, [tuser] * n
    stride = len(tuser) // max(n, 1)  # one entry per byte (or per beat)
    return words, [int(tuser[i * stride]) for i in range(n)]


class AxisTB:
    """Clock, synchronous active-high reset, and one AXI4-Stream source and sink.

    ``source_prefix`` / ``sink_prefix`` name the DUT's port prefixes (``s_axis``/``m_axis``);
    the cocotbext-axi components log at ``log_level`` (warnings by default: a testbench that
    flushes a frame on purpose passes ``logging.ERROR``). ``rng`` is seeded from ``SEED``.
    """

    def __init__(self, dut, source_prefix: str = "s_axis", sink_prefix: str = "m_axis",
                 log_level: int = logging.WARNING) -> None:
        self.dut = dut
        self.log = logging.getLogger(f"cocotb.tb.{dut._name}")
        self.log.setLevel(logging.INFO)
        self.rng = np.random.default_rng(seed())
        cocotb.start_soon(Clock(dut.clk, CLK_PERIOD_NS, unit="ns").start())
        self.source = AxiStreamSource(AxiStreamBus.from_prefix(dut, source_prefix), dut.clk,
                                      dut.rst)
        self.sink = AxiStreamSink(AxiStreamBus.from_prefix(dut, sink_prefix), dut.clk, dut.rst)
        for comp in (self.source, self.sink):
            comp.log.setLevel(log_level)
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
        """TVALID gaps on the source (None = back to back: cocotbext keeps the last pause
        value when its generator is removed, so it is cleared here)."""
        self.source.set_pause_generator(generator)
        if generator is None:
            self.source.pause = False

    def set_backpressure_generator(self, generator: Iterator[bool] | None) -> None:
        """TREADY stalls on the sink (None = always ready, the last pause value cleared)."""
        self.sink.set_pause_generator(generator)
        if generator is None:
            self.sink.pause = False

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

    # ---- words in and out ------------------------------------------------------------------
    async def send_words(self, words: np.ndarray, tuser: Sequence[int] | None = None) -> None:
        """Queue one AXI-Stream frame (TLAST on its last beat): ``words`` uint32 (beats,
        lanes), lane 0 in the low 32 bits; ``tuser`` one value per beat (None: no TUSER)."""
        words = np.asarray(words)
        if words.ndim == 1:
            words = words[:, None]
        user = None
        if tuser is not None:
            user = np.repeat(np.asarray(tuser, dtype=int), 4 * words.shape[1]).tolist()
        await self.source.send(AxiStreamFrame(words_to_bytes(words), tuser=user))

    async def recv_words_user(self, lanes: int, timeout_cycles: int | None = None
                              ) -> tuple[np.ndarray, list[int]]:
        """Next TLAST-closed frame from the sink: (uint32 words (beats, lanes), TUSER of each
        beat). ``timeout_cycles`` bounds the wait (raises ``SimTimeoutError``)."""
        recv = self.sink.recv(compact=False)
        if timeout_cycles is not None:
            frame = await with_timeout(recv, timeout_cycles * CLK_PERIOD_NS, "ns")
        else:
            frame = await recv
        return unpack_frame(frame, lanes)

    async def recv_words(self, lanes: int, timeout_cycles: int | None = None) -> np.ndarray:
        """Next TLAST-closed frame from the sink: uint32 words (beats, lanes)."""
        words, _ = await self.recv_words_user(lanes, timeout_cycles)
        return words

    def drain_words(self, lanes: int) -> list[tuple[np.ndarray, list[int]]]:
        """Every frame already in the sink's queue, as (words, TUSER per beat)."""
        out = []
        while not self.sink.empty():
            out.append(unpack_frame(self.sink.recv_nowait(compact=False), lanes))
        return out

    def read_status(self, names: Iterable[str]) -> dict[str, int]:
        """Current values of the DUT's status/counter ports ``names``."""
        return {name: int(getattr(self.dut, name).value) for name in names}

    async def cycles(self, n: int) -> None:
        for _ in range(n):
            await RisingEdge(self.dut.clk)

    async def hold_word_through_reset(self, word: np.ndarray, tlast: bool,
                                      cycles: int = 4) -> None:
        """A source outside the DUT's reset: assert ``rst``, then present one input word
        (``word``: one value per 32-bit lane, ``s_axis_tdata`` as ``words_to_bytes`` packs
        it) with TVALID high and hold it until TREADY, releasing ``rst`` after ``cycles``
        clocks. Fails if the word is taken while ``rst`` is high (it would be lost with the
        reset) or not within 64 clocks; leaves TVALID low once it is taken."""
        d = self.dut
        d.rst.value = 1
        await RisingEdge(d.clk)   # the testbench's own source has seen the reset (TVALID low)
        d.s_axis_tdata.value = int.from_bytes(words_to_bytes(word[np.newaxis]), "little")
        d.s_axis_tlast.value = int(tlast)
        d.s_axis_tvalid.value = 1
        for cyc in range(64):
            if cyc == cycles:
                d.rst.value = 0
            await RisingEdge(d.clk)
            if d.s_axis_tready.value == 1:
                taken_in_reset = d.rst.value == 1
                break
        else:
            raise AssertionError("the word held through the reset was never taken")
        d.s_axis_tvalid.value = 0
        assert not taken_in_reset, "a word was taken during the reset (and lost with it)"

    async def reset(self, cycles: int = 4) -> None:
        """Hold ``rst`` high for ``cycles`` clocks (synchronous, active high)."""
        self.dut.rst.value = 1
        await self.cycles(cycles)
        self.dut.rst.value = 0
        await self.cycles(2)
