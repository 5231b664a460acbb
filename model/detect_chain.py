"""Bit-exact model of ``rtl/detect/detect_chain.sv``: Doppler-FFT words (mode-1 order) ->
non-coherent integration -> 2-D CFAR -> detection records (``OUTPUT_MODE = 1``,
docs/design.md 3.4). The record stream then goes through ``axis_packetizer``
(``model/axis_packetizer.py``) like the cube does in mode 0.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, replace

import numpy as np

from model import cfar_2d, detect_records, nci

KIND_CODES = {k: i for i, k in enumerate(cfar_2d.KINDS)}


@dataclass(frozen=True)
class DetectConfig:
    """Detector settings (RTL parameters of ``detect_chain`` plus the Pfa the scale table
    is derived from). guard/train: cells per side along (range, Doppler); ``windowed``:
    Hann windows before the (range, Doppler) FFTs (cell correlation in the Pfa arithmetic);
    ``blank_top``: top range bins blanked (negative beat frequencies); ``report``: (lo, hi),
    only range bins lo <= r < hi may detect (``RadarConfig.detection_bins``; None: all).
    ``kind``: KIND (the default kind; ``os`` builds the OS test), ``os``: OS_BUILD with
    another default kind, ``os_rank``: OS_RANK (per mille); the run-time inputs:
    ``run_kind`` (``cfg_kind``; None: ``kind``) and ``local_max`` (``cfg_local_max``)."""

    num_tx: int
    num_rx: int
    n_range: int
    n_doppler: int
    guard: tuple[int, int] = (2, 2)
    train: tuple[int, int] = (4, 8)
    kind: str = "ca"
    blank_top: int = 0
    max_detections: int = 256
    pfa: float = 1e-6
    windowed: tuple[bool, bool] = (True, True)
    scale_w: int = 32
    scale_frac: int = 20
    report: tuple[int, int] | None = None
    os: bool = False
    os_rank: int = cfar_2d.OS_RANK
    run_kind: str | None = None
    local_max: bool = False

    def __post_init__(self) -> None:
        if not 1 <= self.num_tx <= 16:
            raise ValueError(f"num_tx={self.num_tx} not in 1..16")
        if not 1 <= self.num_rx <= 64:
            raise ValueError(f"num_rx={self.num_rx} not in 1..64")
        if not 1 <= self.max_detections <= 65535:
            raise ValueError(f"max_detections={self.max_detections} not in 1..65535")
        self.cfar.run_kind(self.run_kind)  # validates the CFAR geometry and the kind

    @property
    def pow_w(self) -> int:
        return nci.power_width(self.num_tx, self.num_rx)

    @property
    def cfar(self) -> cfar_2d.Cfar2dConfig:
        return cfar_2d.Cfar2dConfig(
            n_range=self.n_range, n_doppler=self.n_doppler, pow_w=self.pow_w, guard=self.guard,
            train=self.train, kind=self.kind, blank_top=self.blank_top, scale_w=self.scale_w,
            scale_frac=self.scale_frac, report=self.report, os=self.os, os_rank=self.os_rank)

    @property
    def frame_words(self) -> int:
        return detect_records.frame_words(self.num_tx, self.num_rx, self.max_detections)

    def scale(self) -> np.ndarray:
        """Threshold scale table int64 ``(2PR+1,)`` for the configured Pfa and the kind run."""
        return cfar_2d.scale_table(self.cfar, self.pfa, self.num_tx * self.num_rx,
                                   self.windowed, self.run_kind)

    def hdl_parameters(self) -> dict[str, int]:
        """HDL parameters of ``detect_chain`` (OS_BUILD and OS_RANK when not the default)."""
        extra = {k: v for k, v in self.cfar.hdl_parameters().items()
                 if k in ("OS_BUILD", "OS_RANK")}
        return dict(**extra, NUM_TX=self.num_tx, NUM_RX=self.num_rx, N_RANGE=self.n_range,
                    N_DOPPLER=self.n_doppler, GUARD_R=self.guard[0], GUARD_D=self.guard[1],
                    TRAIN_R=self.train[0], TRAIN_D=self.train[1], KIND=KIND_CODES[self.kind],
                    BLANK_TOP=self.blank_top, SCALE_W=self.scale_w, SCALE_FRAC=self.scale_frac,
                    MAX_DETECTIONS=self.max_detections,
                    **({} if self.report is None
                       else dict(REPORT_LO=self.report[0], REPORT_HI=self.report[1])))


def detections(words: np.ndarray, cfg: DetectConfig, scale: np.ndarray
               ) -> tuple[list[detect_records.Record], cfar_2d.CfarCells]:
    """All detections of one frame in output order (not truncated) and the CFAR cells.

    words: uint32 ``(n_range * num_tx * n_doppler, num_rx)`` packed {Q, I}, (r, t, d) order.
    """
    w = np.asarray(words, dtype=np.uint32)
    power = nci.nci(w, cfg.num_tx, cfg.n_range, cfg.n_doppler)
    cells = cfar_2d.cfar_2d(power, cfg.cfar, scale, cfg.run_kind, cfg.local_max)
    snap = w.reshape(cfg.n_range, cfg.num_tx, cfg.n_doppler, cfg.num_rx)
    recs = []
    for r, d in cfar_2d.output_order(cfg.cfar):
        if cells.detect[r, d]:
            recs.append(detect_records.Record.of_cell(cells, r, d, snap[r, :, d, :].copy()))
    return recs, cells


def detect_stream(frames: Iterable[np.ndarray], cfg: DetectConfig,
                  scale: np.ndarray | None = None, first_frame_id: int = 0,
                  scales: Sequence[np.ndarray] | None = None,
                  limits: Sequence[int] | None = None,
                  kinds: Sequence[str] | None = None,
                  local_max: Sequence[bool] | None = None) -> list[np.ndarray]:
    """Record streams of consecutive frames after reset: list of uint32
    ``(frame_words, num_rx)``, one per frame (frame ids from ``first_frame_id``, sticky
    truncation from the first frame on). Run-time settings per frame k, as the registers
    applied them at that frame's start (docs/regs.md): ``scales[k]`` (int64 ``(2PR+1,)``;
    None: ``scale`` for every frame, by default ``cfg.scale()``), ``limits[k]`` (records
    at most, 1..cfg.max_detections; None: cfg.max_detections), ``kinds[k]`` (the CFAR kind
    run, ``cfg_kind``; None: ``cfg.run_kind``) and ``local_max[k]`` (``cfg_local_max``;
    None: ``cfg.local_max``)."""
    sc = cfg.scale() if scale is None else scale
    out = []
    sticky = False
    for k, f in enumerate(frames):
        run = cfg if kinds is None and local_max is None else replace(
            cfg, run_kind=cfg.run_kind if kinds is None else kinds[k],
            local_max=cfg.local_max if local_max is None else bool(local_max[k]))
        recs, _ = detections(f, run, sc if scales is None else scales[k])
        limit = cfg.max_detections if limits is None else limits[k]
        out.append(detect_records.encode_frame(recs, len(recs), cfg.num_tx, cfg.num_rx,
                                               cfg.max_detections, frame_id=first_frame_id + k,
                                               sticky=sticky, limit=limit))
        sticky = sticky or len(recs) > limit
    return out
