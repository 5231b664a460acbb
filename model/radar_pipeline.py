"""Bit-accurate model of the whole FPGA chain (``rtl/top/radar_pipeline.sv``), composed from
the block models: ADC frame in, DMA packets out, identical to the RTL for loss-free input.

    chirp ping-pong (pass-through when nothing is dropped)
    -> range ``fft_axis`` (Hann window, SCALE_SCH = range_scale_sch)    model.fft_axis
    -> corner turn (chirp order -> Doppler vectors)                      model.corner_turn
    -> Doppler ``fft_axis`` (Hann window, SCALE_SCH = doppler_scale_sch) model.fft_axis
    -> packetizer (header word + PACKET_WORDS payload words, TLAST)      model.axis_packetizer

Scaling: the range FFT keeps the IP's default 1/N (a full-scale ADC tone cannot overflow);
the Doppler FFT divides only every other radix-2 stage (``0x555``: 1/sqrt(N) for even
log2 N). With 1/N in both, thermal noise after the chain is ~0.1 LSB on the ``full`` preset
and weak targets round away to zero; with 0x555 noise sits near 1.6 LSB and the cube keeps
~86 dB of dynamic range. :func:`chain_gain` is the cube's gain over the float reference
(``model.reference.radar_cube``, 1/N per FFT), which the host divides out.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from model.axis_packetizer import check_geometry, cube_to_payload, packetize
from model.config import RadarConfig, hdl_parameters
from model.corner_turn import corner_turn
from model.fft_axis import fft_fixed_planar, fft_fixed_reference, from_planar, to_planar

RANGE_SCALE_SCH = 0xFFF
"""Range FFT scaling schedule: every stage halves (1/N overall, the Xilinx default)."""
DOPPLER_SCALE_SCH = 0x555
"""Doppler FFT scaling schedule: every other stage halves (1/sqrt(N) for even log2 N)."""


@dataclass(frozen=True)
class PipelineParams:
    """HDL parameters of ``radar_pipeline`` beyond the radar configuration.

    ``packet_words``: PACKET_WORDS; ``window``: WINDOW (periodic Hann before both FFTs);
    ``range_scale_sch`` / ``doppler_scale_sch``: the FFTs' SCALE_SCH; ``header``: HEADER.
    """

    packet_words: int = 1024
    window: bool = True
    range_scale_sch: int = RANGE_SCALE_SCH
    doppler_scale_sch: int = DOPPLER_SCALE_SCH
    header: bool = True

    def frame_words(self, cfg: RadarConfig) -> int:
        """Payload words per frame, num_tx * n_range * n_doppler."""
        return cfg.num_tx * cfg.n_range * cfg.n_doppler

    def hdl_parameters(self, cfg: RadarConfig) -> dict[str, int]:
        """All HDL parameters of ``radar_pipeline`` for ``cfg`` with these chain settings
        (:func:`model.config.hdl_parameters` plus PACKET_WORDS, WINDOW, the scaling
        schedules and HEADER)."""
        return hdl_parameters(cfg, PACKET_WORDS=self.packet_words, WINDOW=int(self.window),
                              RANGE_SCALE_SCH=self.range_scale_sch,
                              DOPPLER_SCALE_SCH=self.doppler_scale_sch, HEADER=int(self.header))

    def check(self, cfg: RadarConfig) -> None:
        """ValueError for a combination the RTL refuses at elaboration."""
        check_geometry(self.frame_words(cfg), self.packet_words)


def _stage_gain(n: int, sch: int) -> float:
    """Gain of an FFT with schedule ``sch`` over the 1/N-scaled DFT: 2**(unscaled stages)."""
    stages = n.bit_length() - 1
    return float(2 ** (stages - bin(sch & ((1 << stages) - 1)).count("1")))


def chain_gain(cfg: RadarConfig, params: PipelineParams) -> float:
    """Gain of the fixed-point cube over ``model.reference.radar_cube`` (same windows)."""
    return (_stage_gain(cfg.n_range, params.range_scale_sch)
            * _stage_gain(cfg.n_doppler, params.doppler_scale_sch))


@dataclass(frozen=True)
class ChainOutput:
    """One frame through the chain.

    ``payload``: complex (num_tx, n_range, n_doppler, num_rx) integer-valued, DMA order;
    ``range_overflow`` / ``doppler_overflow``: output beats of each FFT whose computation
    saturated (the RTL's event_overflow pulses).
    """

    payload: np.ndarray
    range_overflow: int
    doppler_overflow: int

    def cube(self) -> np.ndarray:
        """Radar cube complex (n_virtual, n_range, n_doppler), integer-valued."""
        num_tx, n_range, n_doppler, num_rx = self.payload.shape
        return self.payload.transpose(0, 3, 1, 2).reshape(num_tx * num_rx, n_range, n_doppler)


def run_chain(adc: np.ndarray, cfg: RadarConfig, params: PipelineParams | None = None,
              reference: bool = False) -> ChainOutput:
    """ADC frame complex (num_tx * n_doppler, num_rx, n_range) of int16 I/Q -> cube.

    ``reference``: use the stage-by-stage int64 FFT (``fft_fixed_reference``, slow) instead
    of the fast path; the results are identical (checked by tests/test_model_fast.py).
    """
    params = params or PipelineParams()
    cfg.check_adc(adc)
    if reference:
        rng = fft_fixed_reference(np.transpose(adc, (0, 2, 1)), window=params.window,
                                  scale_sch=params.range_scale_sch)
        words = rng.y.reshape(-1, cfg.num_rx)                   # chirp-major input order
        turned = corner_turn(words, cfg.num_tx, cfg.n_range, cfg.n_doppler)
        dop = fft_fixed_reference(turned.reshape(-1, cfg.n_doppler, cfg.num_rx),
                                  window=params.window, scale_sch=params.doppler_scale_sch)
        payload = dop.y.reshape(cfg.num_tx, cfg.n_range, cfg.n_doppler, cfg.num_rx)
        return ChainOutput(payload, int(rng.overflow.sum()), int(dop.overflow.sum()))
    # same steps on planar I/Q (last axis: I, Q); a word of num_rx lanes is num_rx * 2 values
    planar = to_planar(np.asarray(adc)).transpose(0, 2, 1, 3)   # (chirps, n_range, rx, 2)
    rng_p, rng_ov = fft_fixed_planar(planar, window=params.window,
                                     scale_sch=params.range_scale_sch)
    turned = corner_turn(rng_p.reshape(-1, 2 * cfg.num_rx), cfg.num_tx, cfg.n_range,
                         cfg.n_doppler)
    dop_p, dop_ov = fft_fixed_planar(turned.reshape(-1, cfg.n_doppler, cfg.num_rx, 2),
                                     window=params.window, scale_sch=params.doppler_scale_sch)
    payload = from_planar(dop_p).reshape(cfg.num_tx, cfg.n_range, cfg.n_doppler, cfg.num_rx)
    return ChainOutput(payload, int(rng_ov.sum()), int(dop_ov.sum()))


def scaled_cube(adc: np.ndarray, cfg: RadarConfig, params: PipelineParams | None = None
                ) -> np.ndarray:
    """The chain's cube as the host works with it: complex64 (n_virtual, n_range, n_doppler)
    divided by :func:`chain_gain` (units of the float reference), identical to the cube
    decoded from the DMA stream."""
    params = params or PipelineParams()
    return run_chain(adc, cfg, params).cube().astype(np.complex64) / chain_gain(cfg, params)


def dma_packets(adc_frames: list[np.ndarray], cfg: RadarConfig,
                params: PipelineParams | None = None, first_frame_id: int = 0
                ) -> list[np.ndarray]:
    """DMA packets of consecutive frames exactly as ``radar_pipeline`` sends them: uint32
    arrays (words, num_rx), one per TLAST-closed packet, header word first."""
    params = params or PipelineParams()
    params.check(cfg)
    out: list[np.ndarray] = []
    for k, adc in enumerate(adc_frames):
        payload = cube_to_payload(run_chain(adc, cfg, params).payload)
        out.extend(packetize(payload, params.packet_words, first_frame_id + k,
                             header=params.header))
    return out
