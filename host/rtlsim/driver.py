"""cocotb-side driver of ``radar_pipeline``: ADC frames in, DMA packets out.

Used by the end-to-end testbench (``tb/radar_pipeline``) and by the stream test behind
``radar detect --backend rtl`` (:mod:`host.rtlsim.pipeline_test`). Imported only inside a
cocotb simulation.
"""

from __future__ import annotations

import logging
from collections.abc import Iterator

import cocotb
import numpy as np
from cocotb.clock import Clock
from cocotb.triggers import RisingEdge, with_timeout
from cocotbext.axi import AxiStreamBus, AxiStreamFrame, AxiStreamSink, AxiStreamSource

from host.rtlsim.toolchain import param
from model.chirp_pingpong import adc_frame_to_stream
from model.packetizer import packets_per_frame

CLK_PERIOD_NS = 10  # 100 MHz, the paper's FPGA clock

STATUS_SIGNALS = ("status_adc_overflow", "status_dma_overflow", "status_fft_overflow",
                  "status_framing_error", "adc_chirps_dropped", "dma_words_dropped",
                  "fft_overflow_count", "framing_error_count", "chirps_in", "frames_damaged",
                  "chirps_filled", "chirps_discarded", "frames_turned", "frames_out",
                  "packets_out")


class PipelineTB:
    """Clock, reset, ADC source (``s_axis_adc``) and DMA sink (``m_axis_dma``)."""

    def __init__(self, dut) -> None:
        self.dut = dut
        self.num_rx = param("NUM_RX")
        self.num_tx = param("NUM_TX")
        self.n_range = param("N_RANGE")
        self.n_doppler = param("N_DOPPLER")
        self.packet_words = param("PACKET_WORDS")
        self.header = bool(param("HEADER", 1))
        self.frame_words = self.num_tx * self.n_range * self.n_doppler
        self.packets_per_frame = packets_per_frame(self.frame_words, self.packet_words)
        self.word_bytes = 4 * self.num_rx
        cocotb.start_soon(Clock(dut.clk, CLK_PERIOD_NS, unit="ns").start())
        self.source = AxiStreamSource(AxiStreamBus.from_prefix(dut, "s_axis_adc"), dut.clk,
                                      dut.rst)
        self.sink = AxiStreamSink(AxiStreamBus.from_prefix(dut, "m_axis_dma"), dut.clk,
                                  dut.rst)
        for comp in (self.source, self.sink):
            comp.log.setLevel(logging.WARNING)

    async def reset(self, cycles: int = 8) -> None:
        """Synchronous active-high reset."""
        self.dut.rst.value = 1
        for _ in range(cycles):
            await RisingEdge(self.dut.clk)
        self.dut.rst.value = 0
        for _ in range(2):
            await RisingEdge(self.dut.clk)

    def set_adc_gaps(self, generator: Iterator[bool] | None) -> None:
        """ADC sample gaps (TVALID low), e.g. the ADC rate below the clock."""
        self.source.set_pause_generator(generator)

    def set_dma_stalls(self, generator: Iterator[bool] | None) -> None:
        """DMA backpressure (TREADY low)."""
        self.sink.set_pause_generator(generator)

    async def send_frame(self, adc: np.ndarray) -> None:
        """Queue one ADC frame, complex (n_chirps, num_rx, n_range) of int16 I/Q, one AXI
        frame per chirp (TLAST on its last sample, TUSER[0] on the frame's first sample)."""
        words, _, sof = adc_frame_to_stream(adc)
        per_chirp = self.n_range
        data = np.ascontiguousarray(words, dtype="<u4")
        for c in range(adc.shape[0]):
            sl = slice(c * per_chirp, (c + 1) * per_chirp)
            user = np.repeat(sof[sl].astype(int), self.word_bytes).tolist()
            await self.source.send(AxiStreamFrame(data[sl].tobytes(), tuser=user))

    async def recv_packet(self, timeout_cycles: int) -> np.ndarray:
        """Next TLAST-closed DMA packet: uint32 (words, num_rx)."""
        frame = await with_timeout(self.sink.recv(), timeout_cycles * CLK_PERIOD_NS, "ns")
        return np.frombuffer(bytes(frame.tdata), dtype="<u4").reshape(-1, self.num_rx).copy()

    async def recv_frames(self, n_frames: int, timeout_cycles: int) -> list[np.ndarray]:
        """All packets of ``n_frames`` frames (``timeout_cycles`` per packet)."""
        return [await self.recv_packet(timeout_cycles)
                for _ in range(n_frames * self.packets_per_frame)]

    def status(self) -> dict[str, int]:
        """Current status flags and counters."""
        return {name: int(getattr(self.dut, name).value) for name in STATUS_SIGNALS}

    def frame_timeout_cycles(self) -> int:
        """Generous bound on one frame's latency through the chain, in clocks."""
        return 4 * (self.num_tx * self.n_doppler * self.n_range + 4 * self.n_range
                    + 4 * self.n_doppler + 10_000)
