"""Frame sources: where a frame's radar cube comes from (``radar detect --backend NAME``).

Every source turns simulated ADC frames (complex (n_chirps, num_rx, n_range) int16 I/Q) into
radar cubes complex (n_virtual, n_range, n_doppler) in the float reference's units (LSB of a
1/N-per-FFT chain), so the host processing is the same for all of them:

- ``model``: bit-accurate model of ``radar_pipeline`` (:func:`model.radar_pipeline.scaled_cube`),
  exactly what the FPGA sends, divided by the chain's gain;
- ``float``: the float64 reference of the chain (:func:`model.reference.radar_cube`), fast;
- ``rtl``: the Verilated ``radar_pipeline`` (:func:`rtlsim.harness.run_pipeline`, the C++ harness),
  its DMA packets decoded by :class:`host.stream.StreamDecoder` like the board's.

A new source is one :class:`FrameSource` subclass with a ``name``: it registers itself in
:data:`SOURCES`.
"""

from __future__ import annotations

import sys
from collections.abc import Iterable, Iterator
from dataclasses import replace
from typing import ClassVar

import numpy as np

from model.config import FPGA_CLOCK_HZ, RadarConfig
from model.radar_pipeline import PipelineParams, chain_gain, scaled_cube
from model.reference import radar_cube

SOURCES: dict[str, type[FrameSource]] = {}
"""Registered sources by name, in definition order (model, float, rtl)."""

RTL_SIM_MAX_FRAME_BITS = 16 * 2**20
"""Largest corner-turn frame the RTL source keeps on chip (paper-fpga: 2 Mib); a larger one
(full: 128 Mib) runs with FRAME_STORE = 1, the corner turn in external memory, as on the board."""

FULL_AXI_DATA_W = 512
"""AXI_DATA_W of the external frame store when the RTL source needs it (the ZCU106 PL DDR4
through MIG: 512-bit user interface at the 100 MHz fabric clock, docs/frame_store.md)."""


class SourceError(Exception):
    """The source cannot produce these frames (one-line reason)."""


class FrameSource:
    """ADC frames -> radar cubes. Subclasses set ``name`` and ``help`` and implement
    :meth:`cube` (one frame at a time) or override :meth:`cubes` (a batch)."""

    name: ClassVar[str] = ""
    help: ClassVar[str] = ""
    per_frame: ClassVar[bool] = True
    """True if a single frame is cheap (offered by ``radar demo``)."""

    def __init__(self, chain: PipelineParams | None = None) -> None:
        self.chain = chain or PipelineParams()

    def __init_subclass__(cls, **kwargs: object) -> None:
        super().__init_subclass__(**kwargs)
        if cls.name:
            SOURCES[cls.name] = cls

    def cube(self, adc: np.ndarray, cfg: RadarConfig) -> np.ndarray:
        """One ADC frame -> its radar cube."""
        raise NotImplementedError

    def cubes(self, adc_frames: Iterable[np.ndarray], cfg: RadarConfig) -> Iterator[np.ndarray]:
        """Consecutive ADC frames -> their cubes, in order (lazily, one frame at a time)."""
        for adc in adc_frames:
            yield self.cube(adc, cfg)


class ModelSource(FrameSource):
    name = "model"
    help = "bit-accurate model of the FPGA chain (default)"

    def cube(self, adc: np.ndarray, cfg: RadarConfig) -> np.ndarray:
        # complex64 like the cube decoded from the DMA stream, so both give identical clouds
        return scaled_cube(adc, cfg, self.chain)


class FloatSource(FrameSource):
    name = "float"
    help = "its float64 reference (faster)"

    def cube(self, adc: np.ndarray, cfg: RadarConfig) -> np.ndarray:
        return radar_cube(adc, cfg, self.chain.window, self.chain.window)


class RtlSource(FrameSource):
    name = "rtl"
    help = "the Verilated radar_pipeline"
    per_frame = False

    def cubes(self, adc_frames: Iterable[np.ndarray], cfg: RadarConfig) -> Iterator[np.ndarray]:
        """All frames stream through the RTL back to back (one simulation); the DMA packets
        are decoded like the board's."""
        from host.stream import StreamDecoder
        from rtlsim.harness import run_pipeline

        chain = self.chain
        frame_bits = cfg.num_tx * cfg.n_range * cfg.n_doppler * cfg.num_rx * 32
        if frame_bits > RTL_SIM_MAX_FRAME_BITS and not chain.frame_store:
            # too large for on-chip memory: the corner turn goes to DDR4 (FRAME_STORE = 1),
            # here the harness's AXI4 memory model; the payload is the same (DESIGN.md 3.3)
            chain = replace(chain, frame_store=True, axi_data_w=FULL_AXI_DATA_W)
        adc_gap, chirp_gap = 0.0, 0          # on-chip corner turn: ADC at one sample/clock
        if chain.frame_store:
            # the ADC at its real sample rate against the 100 MHz fabric clock (TVALID gaps)
            # and the idle part of each chirp period, as the board's memory sees it
            adc_gap = max(0.0, 1.0 - cfg.sample_rate_hz / FPGA_CLOCK_HZ)
            chirp_gap = max(0, round((cfg.chirp_period_s - cfg.sampled_chirp_s)
                                     * FPGA_CLOCK_HZ))
        adcs = list(adc_frames)
        print(f"building/running the RTL (radar_pipeline, {cfg.name} parameters, "
              f"FRAME_STORE={int(chain.frame_store)}); the first build takes a minute or two "
              f"(about ten for the 16-lane full top)", file=sys.stderr)
        try:
            packets, status = run_pipeline(adcs, cfg, chain, adc_gap=adc_gap, chirp_gap=chirp_gap,
                                           frame_store=chain.frame_store)
        except (RuntimeError, FileNotFoundError, ImportError) as exc:
            raise SourceError(str(exc)) from None
        dec = StreamDecoder(cfg, self.chain.packet_words)
        decoded = [f for p in packets for f in dec.push_packet(p)] + dec.flush()
        if len(decoded) != len(adcs) or not all(f.complete for f in decoded):
            problems = [p for f in decoded for p in f.problems] + dec.stream_problems
            raise SourceError(f"{len(decoded)} frame(s) back, problems: {problems[:3]}, "
                              f"status {status}")
        gain = chain_gain(cfg, self.chain)
        for f in sorted(decoded, key=lambda f: f.frame_id):
            yield f.cube / gain


def get_source(name: str, chain: PipelineParams | None = None) -> FrameSource:
    """The registered source ``name``."""
    try:
        return SOURCES[name](chain)
    except KeyError:
        raise SourceError(f"no frame source {name!r} (have {', '.join(SOURCES)})") from None
