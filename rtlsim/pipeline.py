"""cocotb-side driver of ``radar_pipeline``: ADC frames in, DMA packets out.

Used by the end-to-end testbenches (``tb/radar_pipeline``) and by the stream test behind
``radar detect --backend rtl`` (:mod:`rtlsim.pipeline_test`), and the register block's
AXI4-Lite slave (:meth:`PipelineTB.attach_regs`; ``host.regs`` names the registers).

The frame flows every ``tb/radar_pipeline`` testbench runs, each compared packet by packet,
word by word, with the bit-accurate model (``model.radar_pipeline.dma_packets``,
:func:`assert_packets_equal`):

- :meth:`PipelineTB.stream_under_stalls`: reset, frames back to back under ADC gaps and DMA
  backpressure, then a clean status (:meth:`PipelineTB.assert_clean`);
- :meth:`PipelineTB.reset_mid_frame`: a reset half way through frame 0 while the ADC keeps
  streaming, the frames after it from frame id 0;
- :meth:`PipelineTB.stall_then_drain`: a :class:`StallSwitch` (the DMA or the external
  memory) stalled for three frame times after frame 0, then everything drained;
- :meth:`PipelineTB.attach_memory`: cocotbext-axi ``AxiRam`` on the external frame store's
  ``m_axi_mem`` with stalls on its five channels.

Imported only inside a cocotb simulation (:func:`assert_packets_equal` also by the harness
tests outside one).
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Coroutine, Iterator, Sequence
from typing import Any, TypeVar

import numpy as np
from cocotb.triggers import SimTimeoutError, with_timeout

from model.axis_packetizer import packets_per_frame
from model.chirp_pingpong import adc_frame_to_stream
from model.config import RadarConfig
from model.detect_records import frame_words as record_frame_words
from model.radar_pipeline import PipelineParams, dma_packets
from model.radar_regs_map import REGISTERS
from rtlsim.axis import CLK_PERIOD_NS, AxisTB, chirp_bursts
from rtlsim.toolchain import param

T = TypeVar("T")
AXIL_ACCESS_CLOCKS = 1000
"""Bound of one register access: the tests' AXI4-Lite stalls (each channel paused with
probability 0.4 a clock) finish one in tens of clocks; a hung handshake fails here."""

STATUS_SIGNALS = ("status_adc_overflow", "status_dma_overflow", "status_fft_overflow",
                  "status_framing_error", "adc_chirps_dropped", "dma_words_dropped",
                  "fft_overflow_count", "framing_error_count", "chirps_in", "frames_damaged",
                  "chirps_filled", "chirps_discarded", "frames_turned", "frames_out",
                  "packets_out", "status_truncated", "detections", "record_frames")
ERROR_FLAGS = ("status_adc_overflow", "status_dma_overflow", "status_fft_overflow",
               "status_framing_error")
"""The sticky flags a clean run leaves at 0."""


def assert_packets_equal(got: Sequence[np.ndarray], want: Sequence[np.ndarray],
                         what: str) -> None:
    """DMA packets (uint32 (words, num_rx) each) equal the model's, packet by packet, word
    by word; the AssertionError names ``what``, the first differing packet, word and lane."""
    assert len(got) == len(want), f"{what}: {len(got)} packets, model {len(want)}"
    for i, (g, w) in enumerate(zip(got, want, strict=True)):
        assert g.shape == w.shape, f"{what}: packet {i} has {g.shape[0]} words, model " \
                                   f"{w.shape[0]}"
        if not np.array_equal(g, w):
            bad = np.argwhere(g != w)[0]
            raise AssertionError(f"{what}: packet {i} word {bad[0]} lane {bad[1]}: "
                                 f"0x{int(g[tuple(bad)]):08x} != model "
                                 f"0x{int(w[tuple(bad)]):08x}")


class StallSwitch:
    """A stall a test turns on and off (``on``): :meth:`pauses` pause while it is on."""

    def __init__(self) -> None:
        self.on = False

    def pauses(self, probability: float = 1.0, seed: int = 0) -> Iterator[bool]:
        """Pause generator: while :attr:`on`, pause each clock with ``probability`` (its own
        random stream, drawn only while on); never while off."""
        rng = np.random.default_rng(seed)
        while True:
            yield self.on and rng.random() < probability


class PipelineTB(AxisTB):
    """:class:`AxisTB` on the ADC input (``s_axis_adc``) and the DMA output (``m_axis_dma``),
    with the pipeline's HDL parameters and frame-level send/receive."""

    def __init__(self, dut) -> None:
        super().__init__(dut, "s_axis_adc", "m_axis_dma")
        self.num_rx = param("NUM_RX")
        self.num_tx = param("NUM_TX")
        self.n_range = param("N_RANGE")
        self.n_doppler = param("N_DOPPLER")
        # range bins out (REAL_ADC keeps 0..N_RANGE/2-1)
        self.n_range_bins = self.n_range // 2 if param("REAL_ADC", 0) else self.n_range
        self.packet_words = param("PACKET_WORDS")
        self.header = bool(param("HEADER", 1))
        self.output_mode = param("OUTPUT_MODE", 0)
        self.max_detections = param("MAX_DETECTIONS", 256)
        self.frame_words = (record_frame_words(self.num_tx, self.num_rx, self.max_detections)
                            if self.output_mode == 1
                            else self.num_tx * self.n_range_bins * self.n_doppler)
        # the register block idle until attach_regs (its reset settings hold: static-clutter
        # removal, when built in with STATIC_REMOVAL = 1, on for every frame)
        for name in ("awvalid", "wvalid", "arvalid"):
            getattr(self.dut, f"s_axil_{name}").value = 0
        self.axil = None
        self.cfar_scales: list[int] = []
        """CFAR_SCALE register table written after every reset (OUTPUT_MODE = 1), e.g.
        ``PipelineParams.cfar_scales(cfg)``; empty: the reset scales (0)."""
        self.packets_per_frame = packets_per_frame(self.frame_words, self.packet_words)

    async def reset(self, cycles: int = 8) -> None:
        """Synchronous active-high reset, then :attr:`cfar_scales` written."""
        await super().reset(cycles)
        await self.write_cfar_scales()

    async def write_cfar_scales(self) -> None:
        """Write :attr:`cfar_scales` to the CFAR_SCALE registers (the detector applies them
        at its next frame start); attaches the AXI4-Lite master if needed."""
        if not self.cfar_scales:
            return
        if self.axil is None:
            self.attach_regs()
        table = REGISTERS["CFAR_SCALE"]
        for e, value in enumerate(self.cfar_scales):
            await self.write32(table.address + e * table.stride, value)

    def attach_regs(self, pauses: Callable[[], Iterator[bool]] | None = None) -> None:
        """Drive the register block's AXI4-Lite slave ``s_axil_*`` with cocotbext-axi's
        ``AxiLiteMaster``; ``pauses`` (if given) makes a pause generator for each of its five
        channels (random AXI4-Lite stalls)."""
        from cocotbext.axi import AxiLiteBus, AxiLiteMaster

        self.axil = AxiLiteMaster(AxiLiteBus.from_prefix(self.dut, "s_axil"), self.dut.clk,
                                  self.dut.rst)
        if pauses is not None:
            for ch in (self.axil.write_if.aw_channel, self.axil.write_if.w_channel,
                       self.axil.write_if.b_channel, self.axil.read_if.ar_channel,
                       self.axil.read_if.r_channel):
                ch.set_pause_generator(pauses())

    async def read32(self, address: int) -> int:
        """One 32-bit register read at byte ``address`` (after :meth:`attach_regs`); with
        ``host.regs.decode`` / ``address`` it reads a register by name. Fails the test when
        no response comes within :data:`AXIL_ACCESS_CLOCKS`."""
        return int(await self._bounded(self.axil.read_dword(address), "read", address))

    async def write32(self, address: int, value: int) -> None:
        """One 32-bit register write at byte ``address`` (after :meth:`attach_regs`); fails
        the test when no response comes within :data:`AXIL_ACCESS_CLOCKS`."""
        await self._bounded(self.axil.write_dword(address, int(value)), "write", address)

    async def _bounded(self, access: Coroutine[Any, Any, T], what: str, address: int) -> T:
        """``access`` (one AXI4-Lite transfer), failed with a message naming the register
        after :data:`AXIL_ACCESS_CLOCKS` clocks instead of waiting for ever."""
        try:
            return await with_timeout(access, AXIL_ACCESS_CLOCKS * CLK_PERIOD_NS, "ns")
        except SimTimeoutError:
            raise AssertionError(
                f"AXI4-Lite {what} at 0x{address:03x}: no response within "
                f"{AXIL_ACCESS_CLOCKS} clocks (the register block or its handshake hangs)"
            ) from None

    def attach_memory(self, size: int, pauses: Callable[[int], Iterator[bool]]):
        """A cocotbext-axi ``AxiRam`` of ``size`` bytes on the external frame store's port
        ``m_axi_mem`` (FRAME_STORE = 1), ``pauses(i)`` the pause generator of its channel i
        (AW, W, B, AR, R); returns the ``AxiRam``."""
        from cocotbext.axi import AxiBus, AxiRam

        ram = AxiRam(AxiBus.from_prefix(self.dut, "m_axi_mem"), self.dut.clk, self.dut.rst,
                     size=size)
        for c in (ram.write_if, ram.read_if):
            c.log.setLevel(logging.WARNING)
        w, r = ram.write_if, ram.read_if
        for i, ch in enumerate([w.aw_channel, w.w_channel, w.b_channel, r.ar_channel,
                                r.r_channel]):
            ch.set_pause_generator(pauses(i))
        return ram

    async def send_frame(self, adc: np.ndarray) -> None:
        """Queue one ADC frame, (n_chirps, num_rx, n_samples) of int16 I/Q (complex, or real:
        I only), one AXI frame per chirp (TLAST on its last sample, TUSER[0] on the frame's
        first sample)."""
        words, _, sof = adc_frame_to_stream(adc)
        per_chirp = adc.shape[2]
        for c in range(adc.shape[0]):
            sl = slice(c * per_chirp, (c + 1) * per_chirp)
            await self.send_words(words[sl], tuser=sof[sl].astype(int))

    async def recv_packet(self, timeout_cycles: int) -> np.ndarray:
        """Next TLAST-closed DMA packet: uint32 (words, num_rx)."""
        return await self.recv_words(self.num_rx, timeout_cycles)

    async def recv_frames(self, n_frames: int, timeout_cycles: int) -> list[np.ndarray]:
        """All packets of ``n_frames`` frames (``timeout_cycles`` per packet)."""
        return [await self.recv_packet(timeout_cycles)
                for _ in range(n_frames * self.packets_per_frame)]

    async def stream(self, frames: Sequence[np.ndarray], cfg: RadarConfig,
                     chain: PipelineParams, what: str, *, timeout_frames: int = 2,
                     first_frame_id: int = 0, sent: Sequence[np.ndarray] | None = None
                     ) -> list[np.ndarray]:
        """Send ``frames`` (complex (n_chirps, num_rx, n_samples) each; ``sent`` instead
        when given: what the ADC drives, e.g. junk on the Q lanes of a real ADC), receive
        their packets (``timeout_frames`` frame timeouts per packet) and compare them with
        the model's (frame ids from ``first_frame_id``); returns the packets."""
        for adc in frames if sent is None else sent:
            await self.send_frame(adc)
        got = await self.recv_frames(len(frames), timeout_frames * self.frame_timeout_cycles())
        assert_packets_equal(got, dma_packets(frames, cfg, chain,
                                              first_frame_id=first_frame_id), what)
        return got

    async def stream_under_stalls(self, frames: Sequence[np.ndarray], cfg: RadarConfig,
                                  chain: PipelineParams, what: str, *,
                                  idle: Iterator[bool], backpressure: Iterator[bool],
                                  timeout_frames: int = 2, clean: bool = True,
                                  sent: Sequence[np.ndarray] | None = None
                                  ) -> list[np.ndarray]:
        """ADC gaps ``idle`` and DMA stalls ``backpressure`` set, reset, then :meth:`stream`;
        with ``clean`` the status is :meth:`assert_clean` after it. Returns the packets."""
        self.set_idle_generator(idle)
        self.set_backpressure_generator(backpressure)
        await self.reset()
        got = await self.stream(frames, cfg, chain, what, timeout_frames=timeout_frames,
                                sent=sent)
        if clean:
            self.assert_clean(len(frames), cfg.n_chirps)
        return got

    def assert_clean(self, n_frames: int, n_chirps: int) -> dict[str, int]:
        """Since the last reset: ``n_frames`` frames out, every one of their ``n_chirps``
        chirps in, no :data:`ERROR_FLAGS` raised; returns the status."""
        st = self.status()
        assert st["frames_out"] == n_frames and st["chirps_in"] == n_frames * n_chirps, st
        for flag in ERROR_FLAGS:
            assert st[flag] == 0, (flag, st)
        return st

    async def reset_mid_frame(self, frames: Sequence[np.ndarray], cfg: RadarConfig,
                              chain: PipelineParams, what: str,
                              backpressure: Iterator[bool] | None = None) -> list[np.ndarray]:
        """Reset, then ``frames`` in ADC chirp bursts (a chirp-long gap after each chirp;
        DMA stalls ``backpressure``), and half way through frame 0 a reset for 8 clocks while
        the source keeps its queue (the ADC keeps streaming: the frames behind the
        interrupted one) and the sink drops what it holds: the packets of the frames after
        it, compared with the model's from frame id 0, are returned (AssertionError with the
        status when nothing comes out)."""
        from cocotb.triggers import ClockCycles, SimTimeoutError

        await self.reset()
        self.set_idle_generator(chirp_bursts(cfg.n_range, cfg.n_range))
        self.set_backpressure_generator(backpressure)
        for adc in frames:
            await self.send_frame(adc)
        await ClockCycles(self.dut.clk, cfg.n_chirps * cfg.n_range)
        self.dut.rst.value = 1
        await ClockCycles(self.dut.clk, 8)
        self.dut.rst.value = 0
        self.sink.clear()
        await self.write_cfar_scales()
        try:
            got = await self.recv_frames(len(frames) - 1, 2 * self.frame_timeout_cycles())
        except SimTimeoutError:
            raise AssertionError(f"no output after reset, status {self.status()}") from None
        assert_packets_equal(got, dma_packets(frames[1:], cfg, chain), what)
        return got

    async def stall_then_drain(self, frames: Sequence[np.ndarray], cfg: RadarConfig,
                               stall: StallSwitch, first_timeout: int) -> list[np.ndarray]:
        """Reset, then ``frames`` in ADC chirp bursts; frame 0's packets leave normally
        (``first_timeout`` clocks per packet), then ``stall`` is on for three frame times
        while the ADC keeps going; returns every packet until the DMA has been quiet for
        1.5 frame times (frames lost in the stall never arrive)."""
        from cocotb.triggers import SimTimeoutError, Timer

        await self.reset()
        self.set_idle_generator(chirp_bursts(cfg.n_range, cfg.n_range))
        for adc in frames:
            await self.send_frame(adc)
        frame_clocks = 2 * cfg.n_chirps * cfg.n_range
        got = [await self.recv_packet(first_timeout) for _ in range(self.packets_per_frame)]
        stall.on = True
        await Timer(3 * frame_clocks * CLK_PERIOD_NS, unit="ns")
        stall.on = False
        while True:
            try:
                got.append(await self.recv_packet(3 * frame_clocks))
            except SimTimeoutError:
                return got

    def status(self) -> dict[str, int]:
        """Current status flags and counters."""
        return self.read_status(STATUS_SIGNALS)

    def frame_timeout_cycles(self) -> int:
        """Generous bound on one frame's latency through the chain, in clocks."""
        return 4 * (self.num_tx * self.n_doppler * self.n_range + 4 * self.n_range
                    + 4 * self.n_doppler + 10_000)
