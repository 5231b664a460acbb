"""cocotb-side driver of ``radar_pipeline``: ADC frames in, DMA packets out.

Used by the end-to-end testbench (``tb/radar_pipeline``) and by the stream test behind
``radar detect --backend rtl`` (:mod:`rtlsim.pipeline_test`), and the register block's
AXI4-Lite slave (:meth:`PipelineTB.attach_regs`; ``host.regs`` names the registers). Imported
only inside a cocotb simulation.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator

import numpy as np

from model.axis_packetizer import packets_per_frame
from model.chirp_pingpong import adc_frame_to_stream
from model.detect_records import frame_words as record_frame_words
from model.radar_regs_map import REGISTERS
from rtlsim.axis import AxisTB
from rtlsim.toolchain import param

STATUS_SIGNALS = ("status_adc_overflow", "status_dma_overflow", "status_fft_overflow",
                  "status_framing_error", "adc_chirps_dropped", "dma_words_dropped",
                  "fft_overflow_count", "framing_error_count", "chirps_in", "frames_damaged",
                  "chirps_filled", "chirps_discarded", "frames_turned", "frames_out",
                  "packets_out", "status_truncated", "detections", "record_frames")


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
        ``host.regs.decode`` / ``address`` it reads a register by name."""
        return int(await self.axil.read_dword(address))

    async def write32(self, address: int, value: int) -> None:
        """One 32-bit register write at byte ``address`` (after :meth:`attach_regs`)."""
        await self.axil.write_dword(address, int(value))

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

    async def reset_then_recv(self, after_cycles: int, n_frames: int) -> list[np.ndarray]:
        """Mid-stream reset: ``after_cycles`` clocks from now, reset for 8 clocks while the
        source keeps its queue (the frames behind the interrupted one), drop what the sink
        holds, then return the packets of the next ``n_frames`` frames (AssertionError with
        the status when nothing comes out)."""
        from cocotb.triggers import ClockCycles, SimTimeoutError

        await ClockCycles(self.dut.clk, after_cycles)
        self.dut.rst.value = 1
        await ClockCycles(self.dut.clk, 8)
        self.dut.rst.value = 0
        self.sink.clear()
        await self.write_cfar_scales()
        try:
            return await self.recv_frames(n_frames, 2 * self.frame_timeout_cycles())
        except SimTimeoutError:
            raise AssertionError(f"no output after reset, status {self.status()}") from None

    def status(self) -> dict[str, int]:
        """Current status flags and counters."""
        return self.read_status(STATUS_SIGNALS)

    def frame_timeout_cycles(self) -> int:
        """Generous bound on one frame's latency through the chain, in clocks."""
        return 4 * (self.num_tx * self.n_doppler * self.n_range + 4 * self.n_range
                    + 4 * self.n_doppler + 10_000)
