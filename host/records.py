"""Decoding of the FPGA's detection-record stream (``OUTPUT_MODE = 1``, DESIGN 3.4).

The record layout is defined once, in ``model.detect_records`` (docs/detect.md): per frame
``record 0 .. record n-1, trailer, zero words`` up to a fixed ``frame_words``, cut into
packets by the unchanged packetizer. This module reuses both: :class:`RecordDecoder` is the
packet framing of :class:`host.stream.PacketDecoder` (lost, repeated, truncated, reordered
packets reported, never raised) with ``model.detect_records.decode_frame`` on each frame's
payload. A frame with a lost packet is *damaged* (``complete`` False); the records that
arrived intact before the first missing word are still offered (``usable_records``).

:func:`record_arrays` turns a frame's records into the arrays the host processing needs
(``host.record_points``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from host.cfar import CfarParams
from host.stream import PacketDecoder
from model.axis_packetizer import unpack_iq
from model.config import RadarConfig
from model.detect_chain import DetectConfig
from model.detect_records import (
    Record,
    Trailer,
    decode_frame,
    decode_frame_reference,
    record_words,
)

DEFAULT_MAX_DETECTIONS = 256
"""MAX_DETECTIONS the host asks the FPGA for unless told otherwise (records per frame)."""


def fpga_detect_config(cfg: RadarConfig, cfar: CfarParams, kind: str = "ca",
                       max_detections: int = DEFAULT_MAX_DETECTIONS,
                       windowed: tuple[bool, bool] = (True, True)) -> DetectConfig:
    """The on-chip detector's settings for ``cfg`` from the host CFAR options: same guard
    and training cells, same Pfa (the scale table is derived from it with the host CFAR's
    statistics), CFAR ``kind`` ca/go/so; only ``RadarConfig.detection_bins`` may report
    (``report``: REPORT_LO/REPORT_HI, the host's rule; the other rows stay training cells,
    as in the host CFAR, and as ``PipelineParams.detect_config``'s default). ValueError on
    settings the detector refuses."""
    return DetectConfig(num_tx=cfg.num_tx, num_rx=cfg.num_rx, n_range=cfg.n_range,
                        n_doppler=cfg.n_doppler, guard=tuple(cfar.guard),
                        train=tuple(cfar.train), kind=kind,
                        max_detections=max_detections, pfa=cfar.pfa, windowed=windowed,
                        report=cfg.detection_bins)


@dataclass
class DetectionFrame:
    """One frame of the record stream.

    ``records``: decoded records in CFAR order (``model.detect_records.Record``; snapshot
    uint32 (num_tx, num_rx) packed {Q, I}); ``trailer``: None when it did not arrive;
    ``problems``: packet and record errors (empty when ``complete``); ``valid``: bool
    (frame_words,) True where the payload word arrived intact; ``usable_records``: how many
    leading records arrived intact (all of them in a complete frame).
    """

    frame_id: int
    records: list[Record]
    trailer: Trailer | None
    problems: list[str]
    valid: np.ndarray
    usable_records: int

    @property
    def complete(self) -> bool:
        return self.trailer is not None and not self.problems and bool(self.valid.all())

    @property
    def truncated(self) -> bool:
        """More cells passed the CFAR than MAX_DETECTIONS: records are the first ones."""
        return bool(self.trailer and self.trailer.truncated)

    @property
    def detections(self) -> int:
        """Cells that passed the CFAR (from the trailer; records sent when it is lost)."""
        return self.trailer.detections if self.trailer else len(self.records)


class RecordDecoder(PacketDecoder[DetectionFrame]):
    """DMA packets of the record stream -> :class:`DetectionFrame` per frame.

    ``dcfg``: the detector's configuration (lanes, TX, MAX_DETECTIONS fix the frame length);
    ``packet_words``: PACKET_WORDS; ``reorder_window``: see ``host.stream.PacketDecoder``;
    ``reference``: decode with the per-record loop (``decode_frame_reference``; benchmark).
    """

    def __init__(self, dcfg: DetectConfig, packet_words: int, reorder_window: int = 2,
                 reference: bool = False) -> None:
        super().__init__(dcfg.num_rx, dcfg.frame_words, packet_words, reorder_window)
        self.dcfg = dcfg
        self._decode = decode_frame_reference if reference else decode_frame

    def _make_frame(self, fid: int, words: np.ndarray, valid: np.ndarray,
                    problems: list[str]) -> DetectionFrame:
        dec = self._decode(words, self.dcfg.num_tx)
        rw = record_words(self.dcfg.num_tx, self.dcfg.num_rx)
        # leading records whose words all arrived (a lost packet zero-fills its words)
        bad = np.flatnonzero(~valid)
        intact = len(dec.records) if not len(bad) else min(len(dec.records), int(bad[0]) // rw)
        errors = list(problems)
        if not errors:  # record errors matter only when the packets were all intact
            errors.extend(f"frame {fid}: {e}" for e in dec.errors)
            tr = dec.trailer
            if tr is not None and tr.frame_id != fid:
                errors.append(f"frame {fid}: trailer carries frame id {tr.frame_id}")
            if tr is not None and tr.max_detections != self.dcfg.max_detections:
                errors.append(f"frame {fid}: trailer says MAX_DETECTIONS "
                              f"{tr.max_detections}, decoder expects "
                              f"{self.dcfg.max_detections}")
            ids = {r.frame_id for r in dec.records} - {fid}
            if ids:
                errors.append(f"frame {fid}: records carry frame id(s) {sorted(ids)[:4]}")
        trailer = dec.trailer if valid.all() else None
        return DetectionFrame(frame_id=fid, records=dec.records, trailer=trailer,
                              problems=errors, valid=valid, usable_records=intact)


@dataclass(frozen=True)
class RecordArrays:
    """A frame's records as arrays, n records, in the host's float units (the fixed-point
    values divided by the chain gain ``gain``, so they match a cube from
    ``model.radar_pipeline.scaled_cube``).

    ``range_bin``, ``doppler_bin``: int (n,) (natural Doppler order); ``power``: float64 (n,)
    non-coherent power sum_v |x_v|^2; ``noise``: float64 (n,) the CFAR's mean training-cell
    power (same units); ``snapshot``: complex64 (n, num_tx * num_rx), virtual channel
    v = tx * num_rx + rx (the cube's channel order).
    """

    range_bin: np.ndarray
    doppler_bin: np.ndarray
    power: np.ndarray
    noise: np.ndarray
    snapshot: np.ndarray

    def __len__(self) -> int:
        return int(len(self.range_bin))


def record_arrays(records: list[Record], n_virtual: int, gain: float = 1.0) -> RecordArrays:
    """Arrays of ``records`` (see :class:`RecordArrays`); ``gain``: the chain's gain over
    the float reference (``model.radar_pipeline.chain_gain``)."""
    n = len(records)
    rb = np.fromiter((r.range_bin for r in records), dtype=np.int64, count=n)
    db = np.fromiter((r.doppler_bin for r in records), dtype=np.int64, count=n)
    power = np.fromiter((r.power for r in records), dtype=np.float64, count=n)
    noise = np.fromiter((r.noise for r in records), dtype=np.float64, count=n)
    if n:
        snap = unpack_iq(np.stack([r.snapshot for r in records])).reshape(n, n_virtual)
    else:
        snap = np.zeros((0, n_virtual), np.complex64)
    g2 = gain * gain
    return RecordArrays(rb, db, power / g2, noise / g2, (snap / gain).astype(np.complex64))
