"""Bit-accurate model of the whole FPGA chain (``rtl/top/radar_pipeline.sv``), composed from
the block models: ADC frame in, DMA packets out, identical to the RTL for loss-free input.

    chirp ping-pong (pass-through when nothing is dropped)
    -> range ``fft_axis`` (Hann window, SCALE_SCH = range_scale_sch)    model.fft_axis
    -> corner turn (chirp order -> Doppler vectors)                      model.corner_turn
    -> [static-clutter removal, ``static_removal`` only]                 model.static_removal
    -> Doppler ``fft_axis`` (Hann window, SCALE_SCH = doppler_scale_sch) model.fft_axis
    -> packetizer (header, PACKET_WORDS payload words, CRC word, TLAST)  model.axis_packetizer

``output_mode = 1`` (on-chip detection, docs/design.md 3.4, docs/detect.md): the corner turn reads
(r, t, d) (``read_order = 1``), the Doppler FFT output goes through the detector
(``model.detect_chain``: NCI, 2-D CFAR, records) and the record stream, a fixed
``DetectConfig.frame_words`` per frame, through the same packetizer framing.

Scaling: the range FFT keeps the IP's default 1/N (a full-scale ADC tone cannot overflow);
the Doppler FFT divides only every other radix-2 stage (``0x555``: 1/sqrt(N) for even
log2 N). With 1/N in both, thermal noise after the chain is ~0.1 LSB on the ``full`` preset
and weak targets round away to zero; with 0x555 noise sits near 1.6 LSB and the cube keeps
~86 dB of dynamic range. :func:`chain_gain` is the cube's gain over the float reference
(``model.reference.radar_cube``, 1/N per FFT), which the host divides out.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from model.axis_packetizer import (
    check_geometry,
    cube_to_payload,
    pack_iq,
    packetize,
    unpack_iq,
)
from model.cfar_2d import pack_scale
from model.config import RadarConfig
from model.corner_turn import corner_turn
from model.detect_chain import DetectConfig, detect_stream
from model.fft_axis import fft_fixed_planar, from_planar, to_planar
from model.frame_store_axi import StoreGeometry, store_frames
from model.hdl import hdl_parameters
from model.profile_fields import check_preset_chain
from model.static_removal import remove_static_planar

RANGE_SCALE_SCH = 0xFFF
"""Range FFT scaling schedule: every stage halves (1/N overall, the Xilinx default)."""
DOPPLER_SCALE_SCH = 0x555
"""Doppler FFT scaling schedule: every other stage halves (1/sqrt(N) for even log2 N)."""

FS_TILE_WORDS = 16
"""Range bins per strip of the external frame store in mode 0 (FS_TILE_R); mode 1 divides it
by num_tx so the on-chip read buffer stays the same size (:meth:`PipelineParams.store_tile_r`)."""


@dataclass(frozen=True)
class PipelineParams:
    """HDL parameters of ``radar_pipeline`` beyond the radar configuration.

    ``packet_words``: PACKET_WORDS; ``window``: WINDOW (periodic Hann before both FFTs);
    ``range_scale_sch`` / ``doppler_scale_sch``: the FFTs' SCALE_SCH; ``header``: HEADER;
    ``frame_store``: FRAME_STORE (corner turn in external memory over AXI4, same payload),
    ``axi_data_w`` / ``fs_tile_r``: its AXI_DATA_W and FS_TILE_R (None:
    :meth:`store_tile_r` picks it); ``output_mode``:
    OUTPUT_MODE (0: radar cube, 1: detection records); ``detect``: the detector settings in
    mode 1 (None: :meth:`detect_config` derives them from the RadarConfig);
    ``static_removal``: STATIC_REMOVAL (static-clutter removal before the Doppler FFT; the
    register SETTINGS.clutter_removal switches it per frame and is on after reset, so
    without register writes every frame has it; :func:`dma_frames`' ``removal`` follows
    the switch).
    """

    packet_words: int = 1024
    window: bool = True
    range_scale_sch: int = RANGE_SCALE_SCH
    doppler_scale_sch: int = DOPPLER_SCALE_SCH
    header: bool = True
    frame_store: bool = False
    axi_data_w: int = 128
    fs_tile_r: int | None = None
    output_mode: int = 0
    detect: DetectConfig | None = None
    static_removal: bool = False

    def detect_config(self, cfg: RadarConfig) -> DetectConfig:
        """The detector of mode 1: ``detect`` (its sizes checked against ``cfg``) or the
        defaults of :class:`model.detect_chain.DetectConfig` sized for ``cfg``, windows as
        ``window``, reporting only ``cfg.detection_bins`` (the host CFAR's rule)."""
        if self.detect is None:
            return DetectConfig(num_tx=cfg.num_tx, num_rx=cfg.num_rx, n_range=cfg.n_range,
                                n_doppler=cfg.n_doppler, windowed=(self.window, self.window),
                                report=cfg.detection_bins)
        d = self.detect
        got = (d.num_tx, d.num_rx, d.n_range, d.n_doppler)
        want = (cfg.num_tx, cfg.num_rx, cfg.n_range, cfg.n_doppler)
        if got != want:
            raise ValueError(f"detect: sizes (num_tx, num_rx, n_range, n_doppler) {got} do not "
                             f"match the radar configuration's {want}")
        return d

    def store_tile_r(self, cfg: RadarConfig) -> int:
        """FS_TILE_R: ``fs_tile_r`` if given, else the largest tile whose on-chip read buffer
        is at most the mode-0 store's with 16-bin strips (2 x 16 x n_doppler words): 16 in
        mode 0, the power of two at most 16 // num_tx in mode 1 (whose buffer holds the
        num_tx strips of one range strip, docs/frame_store.md), and at least one AXI beat
        per row."""
        if self.fs_tile_r is not None:
            return self.fs_tile_r
        group = cfg.num_tx if self.output_mode == 1 else 1
        beat_words = max(1, self.axi_data_w // (cfg.num_rx * 32))
        return min(cfg.n_range, max(1 << (FS_TILE_WORDS // group).bit_length() - 1,
                                    beat_words))

    def store_geometry(self, cfg: RadarConfig) -> StoreGeometry:
        """The external frame store's geometry (FRAME_STORE = 1); its read order is the
        corner turn's, ``output_mode`` ((t, r, d) for the cube, (r, t, d) for detection)."""
        return StoreGeometry(num_tx=cfg.num_tx, num_rx=cfg.num_rx, n_range=cfg.n_range,
                             n_doppler=cfg.n_doppler, tile_r=self.store_tile_r(cfg),
                             axi_data_w=self.axi_data_w, read_order=self.output_mode)

    def frame_words(self, cfg: RadarConfig) -> int:
        """Payload words per frame: num_tx * n_range * n_doppler (mode 0), the record
        stream's fixed ``DetectConfig.frame_words`` (mode 1)."""
        if self.output_mode == 1:
            return self.detect_config(cfg).frame_words
        return cfg.num_tx * cfg.n_range * cfg.n_doppler

    def hdl_parameters(self, cfg: RadarConfig) -> dict[str, int]:
        """All HDL parameters of ``radar_pipeline`` for ``cfg`` with these chain settings
        (:func:`model.hdl.hdl_parameters` plus PACKET_WORDS, WINDOW, the scaling
        schedules and HEADER; FRAME_STORE, AXI_DATA_W and FS_TILE_R when ``frame_store``;
        OUTPUT_MODE and the detector's parameters when ``output_mode`` is 1;
        STATIC_REMOVAL when ``static_removal``)."""
        store = ({"FRAME_STORE": 1, "AXI_DATA_W": self.axi_data_w,
                  "FS_TILE_R": self.store_tile_r(cfg)} if self.frame_store else {})
        if self.static_removal:
            store["STATIC_REMOVAL"] = 1
        if self.output_mode == 1:
            d = self.detect_config(cfg).hdl_parameters()
            store.update(OUTPUT_MODE=1, GUARD_R=d["GUARD_R"], GUARD_D=d["GUARD_D"],
                         TRAIN_R=d["TRAIN_R"], TRAIN_D=d["TRAIN_D"], CFAR_KIND=d["KIND"],
                         BLANK_TOP=d["BLANK_TOP"], SCALE_W=d["SCALE_W"],
                         SCALE_FRAC=d["SCALE_FRAC"], MAX_DETECTIONS=d["MAX_DETECTIONS"],
                         REPORT_LO=d.get("REPORT_LO", 0),
                         REPORT_HI=d.get("REPORT_HI", cfg.n_range))
        return hdl_parameters(cfg, PACKET_WORDS=self.packet_words, WINDOW=int(self.window),
                              RANGE_SCALE_SCH=self.range_scale_sch,
                              DOPPLER_SCALE_SCH=self.doppler_scale_sch, HEADER=int(self.header),
                              **store)

    def cfar_scale(self, cfg: RadarConfig) -> int:
        """Value of the top's quasi-static ``cfg_cfar_scale`` input in mode 1 (the threshold
        scale table for the detector's Pfa, ``model.cfar_2d.pack_scale``)."""
        d = self.detect_config(cfg)
        return pack_scale(d.scale(), d.cfar)

    def check(self, cfg: RadarConfig) -> None:
        """ValueError for a radar or a combination the RTL refuses at elaboration."""
        check_preset_chain(cfg)
        self.check_mode(cfg)
        check_geometry(self.frame_words(cfg), self.packet_words)

    def check_mode(self, cfg: RadarConfig) -> None:
        """ValueError for an OUTPUT_MODE / detector setting the RTL refuses."""
        if self.output_mode not in (0, 1):
            raise ValueError(f"output_mode={self.output_mode} not 0 or 1")
        if self.output_mode == 1:
            self.detect_config(cfg)


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
    saturated (the RTL's event_overflow pulses); ``records`` (mode 1 only, else None): the
    detector's record stream of this frame as the first frame after reset, uint32
    ``(DetectConfig.frame_words, num_rx)``.
    """

    payload: np.ndarray
    range_overflow: int
    doppler_overflow: int
    records: np.ndarray | None = None

    def cube(self) -> np.ndarray:
        """Radar cube complex (n_virtual, n_range, n_doppler), integer-valued."""
        num_tx, n_range, n_doppler, num_rx = self.payload.shape
        return self.payload.transpose(0, 3, 1, 2).reshape(num_tx * num_rx, n_range, n_doppler)


def run_chain(adc: np.ndarray, cfg: RadarConfig, params: PipelineParams | None = None
              ) -> ChainOutput:
    """ADC frame complex (num_tx * n_doppler, num_rx, n_range) of int16 I/Q -> cube (and, in
    mode 1, the record stream of the frame as the first after reset). The FFTs run on planar
    I/Q (``model.fft_axis.fft_fixed_planar``); the stage-by-stage int64 FFT gives the same
    words (the oracle chain of tests/oracles/chain.py, tests/test_model_fast.py)."""
    params = params or PipelineParams()
    params.check_mode(cfg)
    return chain_output(*_doppler_out(adc, cfg, params), cfg, params)


def chain_output(dop: np.ndarray, rng_ov: int, dop_ov: int, cfg: RadarConfig,
                 params: PipelineParams) -> ChainOutput:
    """The :class:`ChainOutput` of the Doppler-FFT output words ``dop`` (integer-valued
    complex (frame words, num_rx) in the corner turn's read order) and the FFTs' overflow
    beats: the cube, and in mode 1 the frame's detection records."""
    if params.output_mode == 0:
        return ChainOutput(dop.reshape(cfg.num_tx, cfg.n_range, cfg.n_doppler, cfg.num_rx),
                           rng_ov, dop_ov)
    words = pack_iq(dop)
    payload = dop.reshape(cfg.n_range, cfg.num_tx, cfg.n_doppler, cfg.num_rx)
    records = detect_stream([words], params.detect_config(cfg))[0]
    return ChainOutput(payload.transpose(1, 0, 2, 3), rng_ov, dop_ov, records)


def _doppler_out(adc: np.ndarray, cfg: RadarConfig, params: PipelineParams
                 ) -> tuple[np.ndarray, int, int]:
    """Doppler-FFT output words, integer-valued complex ``(frame words, num_rx)`` in the
    corner turn's read order (mode 0: (t, r, d); mode 1: (r, t, d)), and the overflow beats
    of the range and Doppler FFTs."""
    check_preset_chain(cfg)
    cfg.check_adc(adc)
    order = params.output_mode
    # same steps on planar I/Q (last axis: I, Q); a word of num_rx lanes is num_rx * 2 values
    planar = to_planar(np.asarray(adc)).transpose(0, 2, 1, 3)   # (chirps, n_range, rx, 2)
    rng_p, rng_ov = fft_fixed_planar(planar, window=params.window,
                                     scale_sch=params.range_scale_sch)
    if params.frame_store:     # through the external layout's bursts and strip buffer
        words = from_planar(rng_p).reshape(-1, cfg.num_rx)
        turned = to_planar(turn(words, cfg, params)).astype(rng_p.dtype)
    else:
        turned = corner_turn(rng_p.reshape(-1, 2 * cfg.num_rx), cfg.num_tx, cfg.n_range,
                             cfg.n_doppler, read_order=order)
    vectors = turned.reshape(-1, cfg.n_doppler, cfg.num_rx, 2)
    if params.static_removal:
        vectors = remove_static_planar(vectors, window=params.window)[0].astype(vectors.dtype)
    dop_p, dop_ov = fft_fixed_planar(vectors, window=params.window,
                                     scale_sch=params.doppler_scale_sch)
    return from_planar(dop_p).reshape(-1, cfg.num_rx), int(rng_ov.sum()), int(dop_ov.sum())


def turn(words: np.ndarray, cfg: RadarConfig, params: PipelineParams) -> np.ndarray:
    """Range-FFT words complex (num_tx * n_doppler * n_range, num_rx), chirp-major input
    order -> Doppler-vector order ((t, r, d) in mode 0, (r, t, d) in mode 1), through the
    on-chip corner turn or, with ``params.frame_store``, through the external store's bursts
    and group buffer in the same read order (the same payload:
    tests/test_frame_store_chain.py)."""
    if params.frame_store:
        return unpack_iq(store_frames([pack_iq(words)], params.store_geometry(cfg))[0])
    return corner_turn(words, cfg.num_tx, cfg.n_range, cfg.n_doppler,
                       read_order=params.output_mode)


def scaled_cube(adc: np.ndarray, cfg: RadarConfig, params: PipelineParams | None = None
                ) -> np.ndarray:
    """The chain's cube as the host works with it: complex64 (n_virtual, n_range, n_doppler)
    divided by :func:`chain_gain` (units of the float reference), identical to the cube
    decoded from the DMA stream."""
    params = params or PipelineParams()
    return run_chain(adc, cfg, params).cube().astype(np.complex64) / chain_gain(cfg, params)


def record_frames(adc_frames: list[np.ndarray], cfg: RadarConfig,
                  params: PipelineParams | None = None, first_frame_id: int = 0
                  ) -> list[np.ndarray]:
    """Mode 1: the detector's record streams of consecutive frames after reset (frame ids
    from ``first_frame_id``, sticky truncation across them), uint32
    ``(DetectConfig.frame_words, num_rx)`` each (``model.detect_chain.detect_stream``)."""
    params = params or PipelineParams(output_mode=1)
    if params.output_mode != 1:
        raise ValueError("record_frames needs output_mode=1")
    params.check(cfg)
    words = (pack_iq(_doppler_out(adc, cfg, params)[0]) for adc in adc_frames)
    return detect_stream(words, params.detect_config(cfg), first_frame_id=first_frame_id)


def dma_packets(adc_frames: list[np.ndarray], cfg: RadarConfig,
                params: PipelineParams | None = None, first_frame_id: int = 0,
                removal: Sequence[bool] | None = None) -> list[np.ndarray]:
    """DMA packets of consecutive frames exactly as ``radar_pipeline`` sends them: uint32
    arrays (words, num_rx), one per TLAST-closed packet, header word first. Mode 0: the
    cube; mode 1: the record streams (:func:`record_frames`), same framing. ``removal``: as
    :func:`dma_frames`."""
    return [p for f in dma_frames(adc_frames, cfg, params, first_frame_id, removal)
            for p in f.packets]


@dataclass(frozen=True)
class FrameDma:
    """One frame as ``radar_pipeline`` sends it, and the FFT saturation behind it.

    ``packets``: uint32 arrays (words, num_rx), header word first (as :func:`dma_packets`);
    ``range_overflow`` / ``doppler_overflow``: output beats of the range / Doppler FFT whose
    computation saturated (the RTL's per-FFT ``event_overflow`` pulses, as
    :class:`ChainOutput`).
    """

    packets: list[np.ndarray]
    range_overflow: int
    doppler_overflow: int


def dma_frames(adc_frames: list[np.ndarray], cfg: RadarConfig,
               params: PipelineParams | None = None, first_frame_id: int = 0,
               removal: Sequence[bool] | None = None) -> list[FrameDma]:
    """:func:`dma_packets` per frame, with each frame's FFT overflow beats (one model run
    gives both: what a soak compares the RTL's packets and status counters with).
    ``removal``: per frame, the register's static-clutter removal switch as that frame ran
    (ACTIVE_SETTINGS.clutter_removal; True needs ``params.static_removal``); None: every
    frame as ``params.static_removal`` (the reset setting)."""
    params = params or PipelineParams()
    params.check(cfg)
    if removal is None:
        removal = [params.static_removal] * len(adc_frames)
    if len(removal) != len(adc_frames) or (any(removal) and not params.static_removal):
        raise ValueError("removal: one switch per frame, on only with static_removal "
                         "(STATIC_REMOVAL = 1)")
    per_frame = [replace(params, static_removal=bool(on)) for on in removal]
    overflow: list[tuple[int, int]] = []
    if params.output_mode == 1:
        def words():                    # one frame's Doppler output at a time
            for adc, fp in zip(adc_frames, per_frame, strict=True):
                dop, rng_ov, dop_ov = _doppler_out(adc, cfg, fp)
                overflow.append((rng_ov, dop_ov))
                yield pack_iq(dop)
        payloads = detect_stream(words(), params.detect_config(cfg),
                                 first_frame_id=first_frame_id)
    else:
        payloads = []
        for adc, fp in zip(adc_frames, per_frame, strict=True):
            out = run_chain(adc, cfg, fp)
            overflow.append((out.range_overflow, out.doppler_overflow))
            payloads.append(cube_to_payload(out.payload))
    return [FrameDma(packetize(payload, params.packet_words, first_frame_id + k,
                               header=params.header), *ov)
            for k, (payload, ov) in enumerate(zip(payloads, overflow, strict=True))]
