"""Bit-accurate model of the whole FPGA chain (``rtl/top/radar_pipeline.sv``), composed from
the block models: ADC frame in, DMA packets out, identical to the RTL for loss-free input.

    chirp ping-pong (pass-through when nothing is dropped)
    -> range ``fft_axis`` (Hann window, SCALE_SCH = range_scale_sch)    model.fft_axis
    -> corner turn (chirp order -> Doppler vectors)                      model.corner_turn
    -> [static-clutter removal, ``static_removal`` only]                 model.static_removal
    -> Doppler ``fft_axis`` (Hann window, SCALE_SCH = doppler_scale_sch) model.fft_axis
    -> packetizer (header, PACKET_WORDS payload words, CRC word, TLAST)  model.axis_packetizer

Any radar's shape (docs/profiles.md): ``cfg.n_samples`` samples per chirp and ``cfg.n_loops``
loops per frame, each windowed over its own count and zero-filled to the FFT length inside
the FFT (the RTL's N_SAMPLES, N_LOOPS); a real ADC (REAL_ADC) keeps range bins
0..n_range/2-1, ``cfg.n_range_bins``, through the corner turn, the detector and the DMA.

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

from model.array import slot_channels
from model.axis_packetizer import (
    check_geometry,
    cube_to_payload,
    pack_iq,
    packetize,
    unpack_iq,
)
from model.config import RadarConfig
from model.corner_turn import corner_turn
from model.detect_chain import DetectConfig, detect_stream
from model.fft_axis import fft_fixed_planar, from_planar, to_planar
from model.fft_rom import COEF_FRAC, hann_window
from model.frame_store_axi import StoreGeometry, store_frames
from model.hdl import DATA_W, check_hdl, hdl_parameters
from model.static_removal import remove_static_planar

RANGE_SCALE_SCH = 0xFFF
"""Range FFT scaling schedule: every stage halves (1/N overall, the Xilinx default)."""
REAL_RANGE_SCALE_SCH = 0xFFE
"""Range FFT scaling schedule of a real ADC: the first stage unscaled (2/N). A real tone's
amplitude splits between bin k and its mirror N - k, so its bin is half a complex tone's
and the gain of 2 cannot overflow; at 1/N the range FFT's rounding (its noise then well
under 1 LSB) puts Doppler spurs of strong targets above the CFAR threshold (4 false alarms
in 8 simulated frames where the float chain has none, tests/test_real_chain.py)."""
DOPPLER_SCALE_SCH = 0x555
"""Doppler FFT scaling schedule: every other stage halves (1/sqrt(N) for even log2 N)."""

FS_TILE_WORDS = 16
"""Range bins per strip of the external frame store in mode 0 (FS_TILE_R); mode 1 divides it
by num_tx so the on-chip read buffer stays the same size (:meth:`PipelineParams.store_tile_r`)."""


@dataclass(frozen=True)
class PipelineParams:
    """HDL parameters of ``radar_pipeline`` beyond the radar configuration.

    ``packet_words``: PACKET_WORDS; ``window``: WINDOW (periodic Hann before both FFTs);
    ``range_scale_sch`` / ``doppler_scale_sch``: the FFTs' SCALE_SCH (``range_scale_sch``
    None: :meth:`range_schedule` picks it by the ADC); ``header``: HEADER;
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
    range_scale_sch: int | None = None
    doppler_scale_sch: int = DOPPLER_SCALE_SCH
    header: bool = True
    frame_store: bool = False
    axi_data_w: int = 128
    fs_tile_r: int | None = None
    output_mode: int = 0
    detect: DetectConfig | None = None
    static_removal: bool = False

    def range_schedule(self, cfg: RadarConfig) -> int:
        """RANGE_SCALE_SCH: ``range_scale_sch`` if given, else :data:`RANGE_SCALE_SCH`
        (complex ADC) or :data:`REAL_RANGE_SCALE_SCH` (real ADC)."""
        if self.range_scale_sch is not None:
            return self.range_scale_sch
        return REAL_RANGE_SCALE_SCH if cfg.adc == "real" else RANGE_SCALE_SCH

    def detect_config(self, cfg: RadarConfig) -> DetectConfig:
        """The detector of mode 1: ``detect`` (its sizes checked against ``cfg``) or the
        defaults of :class:`model.detect_chain.DetectConfig` sized for ``cfg``, windows as
        ``window``, reporting only ``cfg.detection_bins`` (the host CFAR's rule)."""
        if self.detect is None:
            return DetectConfig(num_tx=cfg.num_tx, num_rx=cfg.num_rx, n_range=cfg.n_range_bins,
                                n_doppler=cfg.n_doppler, windowed=(self.window, self.window),
                                report=cfg.detection_bins)
        d = self.detect
        got = (d.num_tx, d.num_rx, d.n_range, d.n_doppler)
        want = (cfg.num_tx, cfg.num_rx, cfg.n_range_bins, cfg.n_doppler)
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
        return min(cfg.n_range_bins, max(1 << (FS_TILE_WORDS // group).bit_length() - 1,
                                         beat_words))

    def store_geometry(self, cfg: RadarConfig) -> StoreGeometry:
        """The external frame store's geometry (FRAME_STORE = 1); its read order is the
        corner turn's, ``output_mode`` ((t, r, d) for the cube, (r, t, d) for detection)."""
        return StoreGeometry(num_tx=cfg.num_tx, num_rx=cfg.num_rx, n_range=cfg.n_range_bins,
                             n_doppler=cfg.n_doppler, tile_r=self.store_tile_r(cfg),
                             axi_data_w=self.axi_data_w, read_order=self.output_mode)

    def frame_words(self, cfg: RadarConfig) -> int:
        """Payload words per frame: num_tx * n_range_bins * n_doppler (mode 0), the record
        stream's fixed ``DetectConfig.frame_words`` (mode 1)."""
        if self.output_mode == 1:
            return self.detect_config(cfg).frame_words
        return cfg.num_tx * cfg.n_range_bins * cfg.n_doppler

    def hdl_parameters(self, cfg: RadarConfig) -> dict[str, int]:
        """All HDL parameters of ``radar_pipeline`` for ``cfg`` with these chain settings
        (:func:`model.hdl.hdl_parameters` plus PACKET_WORDS, WINDOW, the scaling
        schedules and HEADER; FRAME_STORE, AXI_DATA_W and FS_TILE_R when ``frame_store``;
        OUTPUT_MODE and the detector's parameters when ``output_mode`` is 1: CFAR_KIND the
        kind after reset, CFAR_OS_BUILD / CFAR_OS_RANK, CFAR_LOCAL_MAX the local-maximum
        switch after reset;
        STATIC_REMOVAL when ``static_removal``)."""
        store = ({"FRAME_STORE": 1, "AXI_DATA_W": self.axi_data_w,
                  "FS_TILE_R": self.store_tile_r(cfg)} if self.frame_store else {})
        if self.static_removal:
            store["STATIC_REMOVAL"] = 1
        if self.output_mode == 1:
            dc = self.detect_config(cfg)
            if dc.run_kind not in (None, dc.kind):
                raise ValueError("detect: the top's CFAR kind after reset is CFAR_KIND (run "
                                 "another kind through SETTINGS.cfar_kind, FrameSettings.kinds)")
            d = dc.hdl_parameters()
            store.update(OUTPUT_MODE=1, GUARD_R=d["GUARD_R"], GUARD_D=d["GUARD_D"],
                         TRAIN_R=d["TRAIN_R"], TRAIN_D=d["TRAIN_D"], CFAR_KIND=d["KIND"],
                         BLANK_TOP=d["BLANK_TOP"], SCALE_W=d["SCALE_W"],
                         SCALE_FRAC=d["SCALE_FRAC"], MAX_DETECTIONS=d["MAX_DETECTIONS"],
                         REPORT_LO=d.get("REPORT_LO", 0),
                         REPORT_HI=d.get("REPORT_HI", cfg.n_range_bins))
            store.update({f"CFAR_{k}": d[k] for k in ("OS_BUILD", "OS_RANK") if k in d})
            if dc.local_max:
                store["CFAR_LOCAL_MAX"] = 1
        return hdl_parameters(cfg, PACKET_WORDS=self.packet_words, WINDOW=int(self.window),
                              RANGE_SCALE_SCH=self.range_schedule(cfg),
                              DOPPLER_SCALE_SCH=self.doppler_scale_sch, HEADER=int(self.header),
                              **store)

    def cfar_scales(self, cfg: RadarConfig) -> list[int]:
        """The CFAR_SCALE register table in mode 1: the threshold scale of each range edge
        index for the detector's Pfa (``model.cfar_2d.scale_table``; entry e = register
        CFAR_SCALE entry e)."""
        return [int(v) for v in self.detect_config(cfg).scale()]

    def check(self, cfg: RadarConfig) -> None:
        """ValueError for a radar or a combination the RTL refuses at elaboration."""
        check_hdl(cfg)
        if self.frame_store and cfg.n_loops != cfg.n_doppler:
            raise ValueError(f"radar {cfg.name!r}: {cfg.n_loops} loops of a "
                             f"{cfg.n_doppler}-point Doppler FFT: the external frame store "
                             "(FRAME_STORE = 1) holds whole N_DOPPLER loops only")
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
    return (_stage_gain(cfg.n_range, params.range_schedule(cfg))
            * _stage_gain(cfg.n_doppler, params.doppler_scale_sch))


def range_scale_for_peak(cfg: RadarConfig, peak: float, params: PipelineParams | None = None
                         ) -> int:
    """RANGE_SCALE_SCH for ADC frames whose I and Q codes stay within +-``peak``: the first
    stages of the range FFT halve, as few as keep the worst case (a tone of that peak on I
    and Q, coherent over the frame's samples and chirps, through the windows of ``params``
    and its Doppler schedule) within the DATA_W-bit cube, so no such frame can saturate;
    :data:`RANGE_SCALE_SCH` (every stage, the default) when even that is needed. A capture
    far below full scale (the OpenRadar frame peaks at 265 of 32767) then keeps its noise
    above the rounding instead of a cube of zeros (docs/profiles.md). The worst case sums
    the samples that exist: n_samples of n_range along range and n_loops of n_doppler along
    Doppler (zero fill adds nothing), each weighted by the chain's window over its own count
    (``model.fft_rom.hann_window``) or 1 without windows."""
    params = params or PipelineParams()
    gain = 1.0                  # the worst tone's bin over peak, through the 1/N-scaled FFTs
    for n_in, n_fft in ((cfg.n_samples, cfg.n_range), (cfg.n_loops, cfg.n_doppler)):
        w_sum = hann_window(n_in).sum() / 2**COEF_FRAC if params.window else n_in
        gain *= w_sum / n_fft
    limit = (2 ** (DATA_W - 1) - 1) / (max(float(peak), 1.0) * np.sqrt(2.0) * gain)
    stages = cfg.n_range.bit_length() - 1
    for halved in range(stages):
        sch = (1 << halved) - 1
        if chain_gain(cfg, replace(params, range_scale_sch=sch)) <= limit:
            return sch
    return RANGE_SCALE_SCH


@dataclass(frozen=True)
class ChainOutput:
    """One frame through the chain.

    ``payload``: complex (num_tx, n_range_bins, n_doppler, num_rx) integer-valued, DMA order;
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
        """Radar cube complex (n_virtual, n_range_bins, n_doppler), integer-valued."""
        num_tx, n_range, n_doppler, num_rx = self.payload.shape
        return self.payload.transpose(0, 3, 1, 2).reshape(num_tx * num_rx, n_range, n_doppler)


def run_chain(adc: np.ndarray, cfg: RadarConfig, params: PipelineParams | None = None
              ) -> ChainOutput:
    """ADC frame (num_tx * n_loops, num_rx, n_samples) of int16 I/Q (complex, or real for a
    real ADC) -> cube (and, in
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
    nr = cfg.n_range_bins
    if params.output_mode == 0:
        return ChainOutput(dop.reshape(cfg.num_tx, nr, cfg.n_doppler, cfg.num_rx),
                           rng_ov, dop_ov)
    words = pack_iq(dop)
    payload = dop.reshape(nr, cfg.num_tx, cfg.n_doppler, cfg.num_rx)
    records = detect_stream([words], params.detect_config(cfg))[0]
    return ChainOutput(payload.transpose(1, 0, 2, 3), rng_ov, dop_ov, records)


def _doppler_out(adc: np.ndarray, cfg: RadarConfig, params: PipelineParams
                 ) -> tuple[np.ndarray, int, int]:
    """Doppler-FFT output words, integer-valued complex ``(frame words, num_rx)`` in the
    corner turn's read order (mode 0: (t, r, d); mode 1: (r, t, d)), and the overflow beats
    of the range and Doppler FFTs."""
    check_hdl(cfg)
    cfg.check_adc(adc)
    order, nr = params.output_mode, cfg.n_range_bins
    # same steps on planar I/Q (last axis: I, Q); a word of num_rx lanes is num_rx * 2 values;
    # a real ADC's samples are the I halves (Q zero)
    planar = to_planar(np.asarray(adc)).transpose(0, 2, 1, 3)   # (chirps, n_samples, rx, 2)
    rng_p, rng_ov = fft_fixed_planar(planar, window=params.window,
                                     scale_sch=params.range_schedule(cfg), n_fft=cfg.n_range)
    rng_p, rng_ov = rng_p[:, :nr], rng_ov[:, :nr]         # REAL_ADC: the positive half
    if params.frame_store:     # through the external layout's bursts and strip buffer
        words = from_planar(rng_p).reshape(-1, cfg.num_rx)
        turned = to_planar(turn(words, cfg, params)).astype(rng_p.dtype)
    else:
        turned = corner_turn(rng_p.reshape(-1, 2 * cfg.num_rx), cfg.num_tx, nr,
                             cfg.n_doppler, read_order=order, n_loops=cfg.n_loops)
    vectors = turned.reshape(-1, cfg.n_loops, cfg.num_rx, 2)
    if params.static_removal:
        vectors = remove_static_planar(vectors, window=params.window)[0].astype(vectors.dtype)
    dop_p, dop_ov = fft_fixed_planar(vectors, window=params.window,
                                     scale_sch=params.doppler_scale_sch, n_fft=cfg.n_doppler)
    return from_planar(dop_p).reshape(-1, cfg.num_rx), int(rng_ov.sum()), int(dop_ov.sum())


def turn(words: np.ndarray, cfg: RadarConfig, params: PipelineParams) -> np.ndarray:
    """Range-FFT words complex (num_tx * n_loops * n_range_bins, num_rx), chirp-major input
    order -> Doppler-vector order ((t, r, d) in mode 0, (r, t, d) in mode 1), through the
    on-chip corner turn or, with ``params.frame_store``, through the external store's bursts
    and group buffer in the same read order (the same payload:
    tests/test_frame_store_chain.py)."""
    if params.frame_store:
        return unpack_iq(store_frames([pack_iq(words)], params.store_geometry(cfg))[0])
    return corner_turn(words, cfg.num_tx, cfg.n_range_bins, cfg.n_doppler,
                       read_order=params.output_mode, n_loops=cfg.n_loops)


def scaled_cube(adc: np.ndarray, cfg: RadarConfig, params: PipelineParams | None = None
                ) -> np.ndarray:
    """The chain's cube as the host works with it: complex64 (n_virtual, n_range_bins,
    n_doppler) divided by :func:`chain_gain` (units of the float reference), its channels by
    TX index (``model.array.slot_channels``), identical to the cube decoded from the DMA
    stream."""
    params = params or PipelineParams()
    cube = run_chain(adc, cfg, params).cube()
    order = slot_channels(cfg)
    return (cube if order is None else cube[order]).astype(np.complex64) / chain_gain(cfg,
                                                                                      params)


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
                removal: Sequence[bool] | None = None,
                settings: FrameSettings | None = None) -> list[np.ndarray]:
    """DMA packets of consecutive frames exactly as ``radar_pipeline`` sends them: uint32
    arrays (words, num_rx), one per TLAST-closed packet, header word first. Mode 0: the
    cube; mode 1: the record streams (:func:`record_frames`), same framing. ``removal``,
    ``settings``: as :func:`dma_frames`."""
    return [p for f in dma_frames(adc_frames, cfg, params, first_frame_id, removal, settings)
            for p in f.packets]


@dataclass(frozen=True)
class FrameSettings:
    """Run-time register settings per frame, entry k as frame k ran with them at each
    consumer (the register's active values at that block's frame start, docs/regs.md);
    None: the reset value (the HDL parameter) for every frame.

    ``packet_words``: PACKET.words at the packetizer; ``max_detections``:
    SETTINGS.max_detections at the detector (mode 1); ``scales``: the CFAR_SCALE table at
    the detector (mode 1), int ``(2PR+1,)`` each; ``kinds``: SETTINGS.cfar_kind at the
    detector (mode 1), kind names of ``model.cfar_2d.KINDS``; ``local_max``:
    SETTINGS.local_max at the detector (mode 1)."""

    packet_words: Sequence[int] | None = None
    max_detections: Sequence[int] | None = None
    scales: Sequence[np.ndarray] | None = None
    kinds: Sequence[str] | None = None
    local_max: Sequence[bool] | None = None


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
               removal: Sequence[bool] | None = None,
               settings: FrameSettings | None = None) -> list[FrameDma]:
    """:func:`dma_packets` per frame, with each frame's FFT overflow beats (one model run
    gives both: what a soak compares the RTL's packets and status counters with).
    ``removal``: per frame, the register's static-clutter removal switch as that frame ran
    (ACTIVE_SETTINGS.clutter_removal; True needs ``params.static_removal``); None: every
    frame as ``params.static_removal`` (the reset setting). ``settings``: the other run-time
    settings per frame (:class:`FrameSettings`)."""
    params = params or PipelineParams()
    settings = settings or FrameSettings()
    n = len(adc_frames)
    lengths = settings.packet_words or [params.packet_words] * n
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
                                 first_frame_id=first_frame_id, scales=settings.scales,
                                 limits=settings.max_detections, kinds=settings.kinds,
                                 local_max=settings.local_max)
    else:
        payloads = []
        for adc, fp in zip(adc_frames, per_frame, strict=True):
            out = run_chain(adc, cfg, fp)
            overflow.append((out.range_overflow, out.doppler_overflow))
            payloads.append(cube_to_payload(out.payload))
    return [FrameDma(packetize(payload, lengths[k], first_frame_id + k, header=params.header),
                     *ov)
            for k, (payload, ov) in enumerate(zip(payloads, overflow, strict=True))]
