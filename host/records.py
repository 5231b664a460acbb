"""Decoding of the FPGA's detection-record stream (``OUTPUT_MODE = 1``, docs/detect.md).

The record layout is defined once, in ``model.detect_records`` (docs/detect.md): per frame
``record 0 .. record n-1, trailer, zero words`` up to a fixed ``frame_words``, cut into
packets by the unchanged packetizer. This module reuses both: :class:`RecordDecoder` is the
packet framing of :class:`host.stream.PacketDecoder` (lost, repeated, truncated, reordered
packets reported, never raised) with the layout's decoding on each frame's payload. A frame
with a lost packet is *damaged* (``complete`` False); the records that arrived intact before
the first missing word are still offered (``usable_records``).

The decoder reads a frame's records straight into arrays (:func:`decode_record_fields`, the
same fields as ``model.detect_records.decode_frame``, unpacked by the layout's field table
``model.detect_records.unpack_records``, no per-record Python object);
``DetectionFrame.records`` is a :class:`RecordList` over them that builds a
``model.detect_records.Record`` only when one is looked at. :func:`record_arrays` turns a
frame's records into the arrays the host processing needs (``host.record_points``); on a
:class:`RecordList` (or a slice of one) it does not build any ``Record``.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from typing import overload

import numpy as np

from host.cfar import CfarParams
from host.stream import PacketDecoder
from model.axis_packetizer import unpack_iq
from model.cfar_2d import OS_RANK
from model.config import RadarConfig
from model.detect_chain import DetectConfig
from model.detect_records import (
    RECORD_FIELDS,
    Record,
    Trailer,
    frame_end,
    record_scan,
    record_words,
    records_of,
    unpack_records,
)

DEFAULT_MAX_DETECTIONS = 256
"""MAX_DETECTIONS the host asks the FPGA for unless told otherwise (records per frame)."""


def fpga_detect_config(cfg: RadarConfig, cfar: CfarParams, kind: str = "ca",
                       max_detections: int = DEFAULT_MAX_DETECTIONS,
                       windowed: tuple[bool, bool] = (True, True)) -> DetectConfig:
    """The on-chip detector's settings for ``cfg`` from the host CFAR options: same guard
    and training cells, same Pfa (the scale table is derived from it with the host CFAR's
    statistics), CFAR ``kind`` ca/go/so/os (OS: the host's ``os_rank``, which must be whole
    per mille); only ``RadarConfig.detection_bins`` may report
    (``report``: REPORT_LO/REPORT_HI, the host's rule; the other rows stay training cells,
    as in the host CFAR, and as ``PipelineParams.detect_config``'s default). ValueError on
    settings the detector refuses."""
    rank = round(cfar.os_rank * 1000)
    if kind == "os" and abs(rank - cfar.os_rank * 1000) > 1e-9:
        raise ValueError(f"os_rank {cfar.os_rank}: the on-chip OS rank is in whole per mille")
    return DetectConfig(num_tx=cfg.num_tx, num_rx=cfg.num_rx, n_range=cfg.n_range_bins,
                        n_doppler=cfg.n_doppler, guard=tuple(cfar.guard),
                        train=tuple(cfar.train), kind=kind,
                        max_detections=max_detections, pfa=cfar.pfa, windowed=windowed,
                        report=cfg.detection_bins, os_rank=rank if kind == "os" else OS_RANK)


@dataclass(frozen=True)
class RecordFields:
    """The fields of n records as arrays (``model.detect_records.Record``'s, record k in
    row k; the header fields as ``model.detect_records.unpack_headers`` gives them):
    ``range_bin``, ``doppler_bin``, ``cells``, ``index``, ``frame_id``: int64 (n,);
    ``power``, ``noise_sum``: uint64 (n,) (the 64-bit header fields); ``snapshot``: uint32
    (n, num_tx, num_rx) packed {Q, I}; ``neighbours``: uint64 (n, 4) the neighbour powers
    (range - 1, range + 1, Doppler - 1, Doppler + 1)."""

    range_bin: np.ndarray
    doppler_bin: np.ndarray
    power: np.ndarray
    noise_sum: np.ndarray
    cells: np.ndarray
    index: np.ndarray
    frame_id: np.ndarray
    snapshot: np.ndarray
    neighbours: np.ndarray

    def __len__(self) -> int:
        return int(len(self.range_bin))

    def take(self, sl: slice) -> RecordFields:
        """Rows ``sl`` (views)."""
        return RecordFields(*(getattr(self, f)[sl] for f in self.__dataclass_fields__))

    def header(self) -> dict[str, np.ndarray]:
        """The header fields by name (``model.detect_records.RECORD_FIELDS``)."""
        return {f.name: getattr(self, f.name) for f in RECORD_FIELDS}

    @classmethod
    def of_records(cls, records: Sequence[Record], n_virtual: int) -> RecordFields:
        """The fields of ``Record`` objects (snapshots (num_tx, num_rx) each; no records:
        snapshot (0, 1, n_virtual))."""
        n = len(records)
        fields = {f.name: np.array([getattr(r, f.name) for r in records],
                                   np.uint64 if f.width > 32 else np.int64
                                   ).reshape((n, f.count) if f.count > 1 else n)
                  for f in RECORD_FIELDS}
        snap = (np.stack([np.asarray(r.snapshot, np.uint32) for r in records]) if n
                else np.zeros((0, 1, n_virtual), np.uint32))
        return cls(snapshot=snap, **fields)

    def noise(self) -> np.ndarray:
        """float64 (n,) the CFAR's noise estimates noise_sum / max(cells, 1), each the
        correctly rounded quotient as ``Record.noise`` (Python int / int) gives it."""
        cells = np.maximum(self.cells, 1)
        out = self.noise_sum.astype(np.float64) / cells
        big = np.flatnonzero(self.noise_sum >= np.uint64(1 << 53))   # not exact in float64
        for i in big:
            out[i] = int(self.noise_sum[i]) / int(cells[i])
        return out


class RecordList(Sequence[Record]):
    """The records of :class:`RecordFields` as a read-only sequence of
    ``model.detect_records.Record`` (built on access; a slice is a RecordList again)."""

    def __init__(self, fields: RecordFields) -> None:
        self.fields = fields

    def __len__(self) -> int:
        return len(self.fields)

    @overload
    def __getitem__(self, i: int) -> Record: ...

    @overload
    def __getitem__(self, i: slice) -> RecordList: ...

    def __getitem__(self, i: int | slice) -> Record | RecordList:
        if isinstance(i, slice):
            return RecordList(self.fields.take(i))
        i = range(len(self.fields))[i]         # IndexError, negative indices
        one = self.fields.take(slice(i, i + 1))
        return records_of(one.header(), one.snapshot)[0]

    def __iter__(self) -> Iterator[Record]:
        return (self[i] for i in range(len(self)))

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Sequence) and list(self) == list(other)

    def __repr__(self) -> str:
        return f"RecordList({len(self)} records)"


def decode_record_fields(words: np.ndarray, num_tx: int
                         ) -> tuple[RecordFields, Trailer | None, list[str]]:
    """``model.detect_records.decode_frame`` into arrays: (records, trailer or None,
    errors), the same records, trailer and error messages (tests), without building a
    ``Record`` per detection. words: uint32 (n_words, num_rx), padding allowed; never
    raises on bad data."""
    w, pos, n, hw = record_scan(words, num_tx)
    header, snapshot = unpack_records(w, n, num_tx)
    tr, errors = frame_end(w, pos, n, hw)
    return RecordFields(snapshot=snapshot, **header), tr, errors


@dataclass
class DetectionFrame:
    """One frame of the record stream.

    ``records``: decoded records in CFAR order (``model.detect_records.Record``; snapshot
    uint32 (num_tx, num_rx) packed {Q, I}), a :class:`RecordList` over arrays unless the
    decoder runs with ``reference``; ``trailer``: None when it did not arrive;
    ``problems``: packet and record errors (empty when ``complete``); ``valid``: bool
    (frame_words,) True where the payload word arrived intact; ``usable_records``: how many
    leading records arrived intact (all of them in a complete frame); ``n_virtual``: channels
    of a snapshot (num_tx * num_rx); ``gain``: the chain's gain over the float reference,
    divided out by :meth:`arrays`.
    """

    frame_id: int
    records: Sequence[Record]
    trailer: Trailer | None
    problems: list[str]
    valid: np.ndarray
    usable_records: int
    n_virtual: int
    gain: float = 1.0

    def arrays(self) -> RecordArrays:
        """The intact leading records as :class:`RecordArrays` in float-reference units."""
        return record_arrays(self.records[:self.usable_records], self.n_virtual, self.gain)

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
    ``gain``: the chain's gain over the float reference (``model.radar_pipeline.chain_gain``),
    divided out of the frames' :meth:`DetectionFrame.arrays`.
    """

    def __init__(self, dcfg: DetectConfig, packet_words: int, reorder_window: int = 2,
                 gain: float = 1.0) -> None:
        super().__init__(dcfg.num_rx, dcfg.frame_words, packet_words, reorder_window)
        self.dcfg = dcfg
        self.gain = gain

    def _decode(self, words: np.ndarray
                ) -> tuple[Sequence[Record], Trailer | None, list[str], set[int]]:
        """A frame's payload words -> (records, trailer, decoding errors, the frame ids the
        records carry), the records read straight into arrays (:func:`decode_record_fields`)."""
        fields, trailer, errors = decode_record_fields(words, self.dcfg.num_tx)
        return RecordList(fields), trailer, errors, set(np.unique(fields.frame_id).tolist())

    def _make_frame(self, fid: int, words: np.ndarray, valid: np.ndarray,
                    problems: list[str]) -> DetectionFrame:
        records, trailer, dec_errors, frame_ids = self._decode(words)
        rw = record_words(self.dcfg.num_tx, self.dcfg.num_rx)
        # leading records whose words all arrived (a lost packet zero-fills its words)
        bad = np.flatnonzero(~valid)
        intact = len(records) if not len(bad) else min(len(records), int(bad[0]) // rw)
        errors = list(problems)
        if not errors:  # record errors matter only when the packets were all intact
            errors.extend(f"frame {fid}: {e}" for e in dec_errors)
            tr = trailer
            if tr is not None and tr.frame_id != fid:
                errors.append(f"frame {fid}: trailer carries frame id {tr.frame_id}")
            if tr is not None and tr.max_detections != self.dcfg.max_detections:
                errors.append(f"frame {fid}: trailer says MAX_DETECTIONS "
                              f"{tr.max_detections}, decoder expects "
                              f"{self.dcfg.max_detections}")
            ids = frame_ids - {fid}
            if ids:
                errors.append(f"frame {fid}: records carry frame id(s) {sorted(ids)[:4]}")
        trailer = trailer if valid.all() else None
        return DetectionFrame(frame_id=fid, records=records, trailer=trailer,
                              problems=errors, valid=valid, usable_records=intact,
                              n_virtual=self.dcfg.num_tx * self.dcfg.num_rx, gain=self.gain)


@dataclass(frozen=True)
class RecordArrays:
    """A frame's records as arrays, n records, in the host's float units (the fixed-point
    values divided by the chain gain ``gain``, so they match a cube from
    ``model.radar_pipeline.scaled_cube``).

    ``range_bin``, ``doppler_bin``: int (n,) (natural Doppler order); ``power``: float64 (n,)
    non-coherent power sum_v |x_v|^2; ``noise``: float64 (n,) the CFAR's mean training-cell
    power (same units); ``snapshot``: complex64 (n, num_tx * num_rx), virtual channel
    v = tx * num_rx + rx (the cube's channel order); ``neighbours``: float64 (n, 4) the
    non-coherent powers of the cells at range - 1, range + 1, Doppler - 1, Doppler + 1 (0
    beyond the range ends; None: not known, e.g. records built by hand).
    """

    range_bin: np.ndarray
    doppler_bin: np.ndarray
    power: np.ndarray
    noise: np.ndarray
    snapshot: np.ndarray
    neighbours: np.ndarray | None = None

    def __len__(self) -> int:
        return int(len(self.range_bin))


def outside_map(arr: RecordArrays, cfg: RadarConfig) -> np.ndarray:
    """bool (n,): the records whose (range_bin, doppler_bin) lie outside ``cfg``'s
    n_range x n_doppler map (the header fields are 12 bits wide: corrupt words that still
    look like records, or records of another configuration)."""
    r, d = np.asarray(arr.range_bin), np.asarray(arr.doppler_bin)
    return (r < 0) | (r >= cfg.n_range_bins) | (d < 0) | (d >= cfg.n_doppler)


def inside_map(arr: RecordArrays, cfg: RadarConfig) -> tuple[RecordArrays, int]:
    """(the records inside ``cfg``'s map, how many were dropped) (:func:`outside_map`):
    what the receivers hand to ``host.record_points.process_records``, which refuses
    records outside the map; the count goes into the frame's problems."""
    out = outside_map(arr, cfg)
    if not out.any():
        return arr, 0
    keep = ~out
    return RecordArrays(arr.range_bin[keep], arr.doppler_bin[keep], arr.power[keep],
                        arr.noise[keep], arr.snapshot[keep],
                        None if arr.neighbours is None else arr.neighbours[keep]
                        ), int(out.sum())


def outside_problem(frame_id: int, dropped: int, cfg: RadarConfig) -> str:
    """The frame problem a receiver reports for records :func:`inside_map` dropped."""
    return (f"frame {frame_id}: {dropped} record(s) outside the {cfg.n_range_bins} x "
            f"{cfg.n_doppler} map dropped")


def record_arrays(records: Sequence[Record], n_virtual: int, gain: float = 1.0
                  ) -> RecordArrays:
    """Arrays of ``records`` (see :class:`RecordArrays`); ``gain``: the chain's gain over
    the float reference (``model.radar_pipeline.chain_gain``). On a :class:`RecordList`
    straight from its arrays (same values as from its ``Record`` objects: tests)."""
    if isinstance(records, RecordList):
        return fields_arrays(records.fields, n_virtual, gain)
    return fields_arrays(RecordFields.of_records(records, n_virtual), n_virtual, gain)


def fields_arrays(fields: RecordFields, n_virtual: int, gain: float = 1.0) -> RecordArrays:
    """:func:`record_arrays` of :class:`RecordFields`."""
    n = len(fields)
    if n and fields.snapshot.shape[1] * fields.snapshot.shape[2] != n_virtual:
        raise ValueError(f"records carry {fields.snapshot.shape[1]} x "
                         f"{fields.snapshot.shape[2]} channels, expected {n_virtual}")
    snap = unpack_iq(fields.snapshot).reshape(n, n_virtual)
    g2 = gain * gain
    return RecordArrays(fields.range_bin, fields.doppler_bin,
                        fields.power.astype(np.float64) / g2, fields.noise() / g2,
                        (snap / gain).astype(np.complex64),
                        fields.neighbours.astype(np.float64) / g2)
