"""Frame sources: where a frame's radar cube comes from (``radar detect --backend NAME``).

Every source turns simulated ADC frames (complex (n_chirps, num_rx, n_range) int16 I/Q) into
radar cubes complex (n_virtual, n_range, n_doppler) in the float reference's units (LSB of a
1/N-per-FFT chain), so the host processing is the same for all of them:

- ``model``: bit-accurate model of ``radar_pipeline`` (:func:`model.radar_pipeline.scaled_cube`),
  exactly what the FPGA sends, divided by the chain's gain;
- ``float``: the float64 reference of the chain (:func:`model.reference.radar_cube`, computed
  by its fast equivalent :func:`host.cube.frame_cube`);
- ``rtl``: the Verilated ``radar_pipeline`` (:func:`rtlsim.harness.run_pipeline`, the C++ harness),
  its DMA packets decoded like the board's (``host.receiver.chain_decoder``).

With the on-chip detector (``radar detect --detect fpga``, ``OUTPUT_MODE = 1``) a source
gives the frames' detection records instead (:meth:`FrameSource.dma_frames`): ``model``
runs the bit-accurate chain in mode 1 and ``rtl`` the Verilated top in mode 1; both send
their DMA packets as bytes through :class:`host.records.RecordDecoder`, like the board's.
``radar process`` takes the cube that way too (:meth:`FrameSource.cube_packets` through
:class:`host.receiver.CubePayloadDecoder`), so a capture's model and RTL runs compare byte for
byte.

A new source is one :class:`FrameSource` subclass with a ``name``: it registers itself in
:data:`SOURCES`.
"""

from __future__ import annotations

import sys
from collections.abc import Iterable, Iterator
from dataclasses import replace
from typing import ClassVar

import numpy as np

from host.cube import frame_cube
from host.receiver import LinkFrame, chain_decoder
from model.axis_packetizer import packetize_stream, words_to_bytes
from model.config import RadarConfig
from model.detect_chain import DetectConfig
from model.hdl import FPGA_CLOCK_HZ, FULL_AXI_DATA_W, check_hdl
from model.radar_pipeline import PipelineParams, dma_packets, record_frames, scaled_cube

SOURCES: dict[str, type[FrameSource]] = {}
"""Registered sources by name, in definition order (model, float, rtl)."""

RTL_SIM_MAX_FRAME_BITS = 16 * 2**20
"""Largest corner-turn frame the RTL source keeps on chip (paper-fpga: 2 Mib); a larger one
(full: 128 Mib) runs with FRAME_STORE = 1, the corner turn in external memory, as on the board."""


class SourceError(Exception):
    """The source cannot produce these frames (one-line reason)."""


class FrameSource:
    """ADC frames -> radar cubes. Subclasses set ``name`` and ``help`` and implement
    :meth:`cube` (one frame at a time) or override :meth:`cubes` (a batch)."""

    name: ClassVar[str] = ""
    help: ClassVar[str] = ""
    per_frame: ClassVar[bool] = True
    """True if a single frame is cheap (offered by ``radar demo``)."""
    hdl: ClassVar[bool] = False
    """True if the source runs the RTL's chain, so the HDL's limits apply (:meth:`check`)."""

    def __init__(self, chain: PipelineParams | None = None) -> None:
        self.chain = chain or PipelineParams()

    def __init_subclass__(cls, **kwargs: object) -> None:
        super().__init_subclass__(**kwargs)
        if cls.name:
            SOURCES[cls.name] = cls

    def check(self, cfg: RadarConfig) -> None:
        """SourceError (one line) when this source cannot run the radar ``cfg``: what the
        processing chain does not support (``RadarConfig.check_processable``) and, for the
        sources of the RTL's chain (``hdl``), what the RTL does not elaborate
        (``model.hdl.check_hdl``, ``PipelineParams.check``, the frame store's geometry)."""
        try:
            cfg.check_processable()
            if self.hdl:
                check_hdl(cfg)
                chain = self.chain_for(cfg)
                chain.check(cfg)
                if chain.frame_store:
                    chain.store_geometry(cfg)
        except ValueError as exc:
            raise SourceError(str(exc)) from None

    def chain_for(self, cfg: RadarConfig) -> PipelineParams:
        """The chain settings the source runs ``cfg`` with."""
        return self.chain

    def cube(self, adc: np.ndarray, cfg: RadarConfig) -> np.ndarray:
        """One ADC frame -> its radar cube."""
        raise NotImplementedError

    def cubes(self, adc_frames: Iterable[np.ndarray], cfg: RadarConfig) -> Iterator[np.ndarray]:
        """Consecutive ADC frames -> their cubes, in order (lazily, one frame at a time)."""
        for adc in adc_frames:
            yield self.cube(adc, cfg)

    def record_packets(self, adc_frames: Iterable[np.ndarray], cfg: RadarConfig,
                       dcfg: DetectConfig) -> Iterator[np.ndarray | bytes]:
        """DMA packets of the chain in ``OUTPUT_MODE = 1`` (detection records), uint32
        (words, num_rx) each or their wire bytes, header word first. SourceError when the
        source has none."""
        raise SourceError(f"--backend {self.name} has no on-chip detector (use model or rtl "
                          f"with --detect fpga)")

    def cube_packets(self, adc_frames: Iterable[np.ndarray], cfg: RadarConfig
                     ) -> Iterator[bytes]:
        """DMA packets of the chain in ``OUTPUT_MODE = 0`` (the radar cube) as wire bytes,
        header word first, the frames numbered from 0 as after one reset. SourceError when
        the source has none."""
        raise SourceError(f"--backend {self.name} sends no DMA stream (model and rtl do)")

    def dma_frames(self, adc_frames: Iterable[np.ndarray], cfg: RadarConfig,
                   dcfg: DetectConfig | None = None) -> Iterator[LinkFrame]:
        """Consecutive ADC frames -> their frames as the host decodes the chain's DMA bytes
        (``host.receiver.chain_decoder``), in order: the radar cube's frames
        (:meth:`cube_packets`, ``dcfg`` None) or the on-chip detector's record frames
        (:meth:`record_packets`, ``dcfg`` its configuration), exactly as the board's would
        be decoded."""
        dec = chain_decoder(cfg, self.chain.packet_words, self.chain, dcfg)
        packets = (self.cube_packets(adc_frames, cfg) if dcfg is None
                   else self.record_packets(adc_frames, cfg, dcfg))
        for p in packets:
            yield from dec.push_packet(p if isinstance(p, bytes) else words_to_bytes(p))
        yield from dec.flush()


class ModelSource(FrameSource):
    name = "model"
    help = "bit-accurate model of the FPGA chain (default)"
    hdl = True

    def cube(self, adc: np.ndarray, cfg: RadarConfig) -> np.ndarray:
        # complex64 like the cube decoded from the DMA stream, so both give identical clouds
        return scaled_cube(adc, cfg, self.chain)

    def cube_packets(self, adc_frames: Iterable[np.ndarray], cfg: RadarConfig
                     ) -> Iterator[bytes]:
        # one frame at a time, numbered as one stream after reset (as the RTL's)
        for k, adc in enumerate(adc_frames):
            try:
                packets = dma_packets([adc], cfg, self.chain, first_frame_id=k)
            except ValueError as exc:
                raise SourceError(str(exc)) from None
            yield from (words_to_bytes(p) for p in packets)

    def record_packets(self, adc_frames: Iterable[np.ndarray], cfg: RadarConfig,
                       dcfg: DetectConfig) -> Iterator[np.ndarray | bytes]:
        # the chain in mode 1 (model.radar_pipeline.record_frames: corner turn in (r, t, d)
        # order, detect_chain), frame ids and sticky truncation over the whole stream as
        # after one reset, then the packetizer framing
        chain = replace(self.chain, output_mode=1, detect=dcfg)
        try:
            streams = record_frames(adc_frames, cfg, chain)  # type: ignore[arg-type]
        except ValueError as exc:
            raise SourceError(str(exc)) from None
        yield from packetize_stream(streams, chain.packet_words)


class FloatSource(FrameSource):
    name = "float"
    help = "its float64 reference (faster)"

    def cube(self, adc: np.ndarray, cfg: RadarConfig) -> np.ndarray:
        return frame_cube(adc, cfg, self.chain.window, self.chain.window,
                          remove_static_clutter=self.chain.static_removal)


class RtlSource(FrameSource):
    name = "rtl"
    help = "the Verilated radar_pipeline"
    per_frame = False
    hdl = True

    def chain_for(self, cfg: RadarConfig) -> PipelineParams:
        """The chain with FRAME_STORE = 1 when the frame does not fit on chip."""
        chain = self.chain
        frame_bits = cfg.num_tx * cfg.n_range * cfg.n_doppler * cfg.num_rx * 32
        if frame_bits > RTL_SIM_MAX_FRAME_BITS and not chain.frame_store:
            # too large for on-chip memory: the corner turn goes to DDR4 (FRAME_STORE = 1),
            # here the harness's AXI4 memory model; the payload is the same (docs/design.md 3.3)
            chain = replace(chain, frame_store=True, axi_data_w=FULL_AXI_DATA_W)
        return chain

    def _run(self, adcs: list[np.ndarray], cfg: RadarConfig, chain: PipelineParams
             ) -> tuple[list[np.ndarray], object]:
        """DMA packets and status of the Verilated top for ``adcs`` (SourceError on a
        build or run failure)."""
        from rtlsim.harness import run_pipeline

        adc_gap, chirp_gap = 0.0, 0          # on-chip corner turn: ADC at one sample/clock
        if chain.frame_store:
            # the ADC at its real sample rate against the 100 MHz fabric clock (TVALID gaps)
            # and the idle part of each chirp period, as the board's memory sees it
            adc_gap = max(0.0, 1.0 - cfg.sample_rate_hz / FPGA_CLOCK_HZ)
            chirp_gap = max(0, round((cfg.chirp_period_s - cfg.sampled_chirp_s)
                                     * FPGA_CLOCK_HZ))
        print(f"building/running the RTL (radar_pipeline, {cfg.name} parameters, "
              f"FRAME_STORE={int(chain.frame_store)}); the first build takes a minute or two "
              f"(about ten for the 16-lane full top)", file=sys.stderr)
        try:
            return run_pipeline(adcs, cfg, chain, adc_gap=adc_gap, chirp_gap=chirp_gap,
                                frame_store=chain.frame_store)
        except (RuntimeError, FileNotFoundError, ImportError, TypeError, ValueError) as exc:
            raise SourceError(str(exc)) from None

    def cubes(self, adc_frames: Iterable[np.ndarray], cfg: RadarConfig) -> Iterator[np.ndarray]:
        """All frames stream through the RTL back to back (one simulation); the DMA packets
        are decoded like the board's."""
        adcs = list(adc_frames)
        packets, status = self._run(adcs, cfg, self.chain_for(cfg))
        dec = chain_decoder(cfg, self.chain.packet_words, self.chain)
        decoded = [f for p in packets for f in dec.push_packet(p)] + dec.flush()
        if len(decoded) != len(adcs) or not all(f.complete for f in decoded):
            problems = [p for f in decoded for p in f.problems] + dec.stream_problems
            raise SourceError(f"{len(decoded)} frame(s) back, problems: {problems[:3]}, "
                              f"status {status}")
        for f in sorted(decoded, key=lambda f: f.frame_id):
            yield f.cube()

    def cube_packets(self, adc_frames: Iterable[np.ndarray], cfg: RadarConfig
                     ) -> Iterator[bytes]:
        """All frames through the Verilated top (one simulation)."""
        packets, _ = self._run(list(adc_frames), cfg, self.chain_for(cfg))
        yield from packets

    def record_packets(self, adc_frames: Iterable[np.ndarray], cfg: RadarConfig,
                       dcfg: DetectConfig) -> Iterator[np.ndarray | bytes]:
        """All frames through the Verilated top in OUTPUT_MODE = 1 (one simulation)."""
        chain = replace(self.chain_for(cfg), output_mode=1, detect=dcfg)
        try:
            chain.check(cfg)
        except ValueError as exc:
            raise SourceError(f"OUTPUT_MODE = 1 on {cfg.name}: {exc}") from None
        packets, _ = self._run(list(adc_frames), cfg, chain)
        yield from packets


def get_source(name: str, chain: PipelineParams | None = None) -> FrameSource:
    """The registered source ``name``."""
    try:
        return SOURCES[name](chain)
    except KeyError:
        raise SourceError(f"no frame source {name!r} (have {', '.join(SOURCES)})") from None
