"""Detection record format of ``rtl/detect/detect_records.sv`` (bit-exact model, shared
with the host decoder ``host.records``: the one place that defines the layout; described in
docs/detect.md).

A *word* is ``num_rx`` 32-bit lanes (uint32 ``(num_rx,)``, lane 0 in the least significant
bits), as in ``model/axis_packetizer.py``. One frame of the record stream is exactly
``frame_words(num_tx, num_rx, max_detections)`` words (it then goes through
``axis_packetizer``: packet header, sequence numbers, loss detection):

    record 0 .. record n-1, trailer, zero words up to the fixed frame length

A header (record header or trailer) is a vector of ``HDR_LANES`` = 16 lanes sent as
``hdr_words(num_rx) = ceil(16 / num_rx)`` words (lanes past 16 are zero; one word at
``num_rx`` = 16). Its fields are one table, :data:`TAG` plus :data:`RECORD_FIELDS` or
:data:`TRAILER_FIELDS` (:class:`Field`: lane, bit offset, width), from which the encoder
packs (:func:`pack_headers`) and the decoders unpack (:func:`unpack_headers`, n headers at
once; :func:`unpack_header`, one). A record header is followed by ``num_tx`` words: the
Doppler-FFT values of the cell for TX 0..num_tx-1, lanes = RX 0..num_rx-1,
``{Q[31:16], I[15:0]}`` (the snapshot).

Records are in CFAR output order (``model.cfar_2d.output_order``): range row by row, within a
row Doppler bins PD..n_doppler-1, 0..PD-1.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from dataclasses import fields as dataclass_fields
from typing import Any

import numpy as np

from model.cfar_2d import CfarCells

TAG_RECORD = 0xD1
TAG_TRAILER = 0xDE
MAX_COUNT = (1 << 17) - 1
"""The trailer's detection count saturates here (the RTL's 17-bit counter)."""


@dataclass(frozen=True)
class Field:
    """One field of a header: ``count`` values of ``width`` bits, value j starting at bit
    ``lsb`` of 32-bit lane ``lane + j * span``; a value wider than 32 bits spans several
    lanes, low lane first. A 1-bit field is a flag (``bool`` in :class:`Trailer`)."""

    name: str
    lane: int
    lsb: int
    width: int
    count: int = 1

    @property
    def span(self) -> int:
        """Lanes one value occupies."""
        return -(-(self.lsb + self.width) // 32)

    @property
    def end(self) -> int:
        """One past the field's last lane."""
        return self.lane + self.count * self.span


TAG = Field("tag", 0, 24, 8)
"""Lane 0 [31:24] of every header: TAG_RECORD or TAG_TRAILER."""
RECORD_FIELDS: tuple[Field, ...] = (
    Field("range_bin", 0, 12, 12),
    Field("doppler_bin", 0, 0, 12),
    Field("index", 1, 16, 16),          # record index within the frame
    Field("cells", 1, 0, 16),           # training cells in the noise sum
    Field("power", 2, 0, 64),           # integrated power (NCI)
    Field("noise_sum", 4, 0, 64),       # the CFAR's training sum
    Field("frame_id", 6, 0, 32),        # frames since reset
    Field("neighbours", 8, 0, 64, count=4),
)
"""The record header's fields (besides :data:`TAG`), named as :class:`Record`'s; lane 7 is
0. ``neighbours``: the integrated powers of the cells at range - 1, range + 1, Doppler - 1,
Doppler + 1 (``model.cfar_2d.NEIGHBOURS``; Doppler circular, 0 beyond the first and last
range rows): the host interpolates the peak position from them as from the cube's map."""
TRAILER_FIELDS: tuple[Field, ...] = (
    Field("truncated", 0, 0, 1),            # this frame had more than max_detections
    Field("truncated_sticky", 0, 1, 1),     # any frame since reset was truncated
    Field("records", 1, 0, 32),
    Field("detections", 2, 0, 32),          # found, saturating at MAX_COUNT
    Field("frame_id", 3, 0, 32),
    Field("max_detections", 4, 0, 32),    # MAX_DETECTIONS: fixes the frame length
    Field("limit", 5, 0, 32),             # this frame's run-time record limit
)
"""The trailer's fields (besides :data:`TAG`), named as :class:`Trailer`'s."""
HDR_LANES = max(f.end for f in (TAG, *RECORD_FIELDS, *TRAILER_FIELDS))
"""Lanes of a header (16)."""


def pack_headers(tag: int, table: Sequence[Field], values: Mapping[str, Any]) -> np.ndarray:
    """The lanes of n headers, uint32 ``(n, HDR_LANES)``: ``tag`` and ``values`` by field
    name of ``table`` (non-negative ints below 2^64: ``(n,)``, or ``(n, count)`` for a
    field of several values), each cut to its width."""
    n = len(values[table[0].name])
    lanes = np.zeros((n, HDR_LANES), np.uint64)
    for f in (TAG, *table):
        v = np.full(n, tag) if f is TAG else values[f.name]
        bits = (np.array(v, np.uint64).reshape(n, f.count) & ((1 << f.width) - 1)) << f.lsb
        for k in range(f.span):                 # lane k of each value: (n, count)
            lanes[:, f.lane + k:f.end:f.span] |= (bits >> 32 * k) & 0xFFFFFFFF
    return lanes.astype(np.uint32)


def unpack_headers(lanes: np.ndarray, table: Sequence[Field] = RECORD_FIELDS
                   ) -> dict[str, np.ndarray]:
    """The fields of ``table`` of n headers, lanes uint32 ``(n, >= HDR_LANES)``, by name:
    int64 ``(n,)`` for fields up to 32 bits, uint64 ``(n,)`` for wider ones, ``(n, count)``
    for a field of several values."""
    wide = np.asarray(lanes)[:, :HDR_LANES].astype(np.uint64)
    out = {}
    for f in table:
        def at(k: int, f: Field = f) -> np.ndarray:
            """Lane k of each value: (n,) or (n, count)."""
            return wide[:, f.lane + k] if f.count == 1 else wide[:, f.lane + k:f.end:f.span]
        v = at(0)
        for k in range(1, f.span):
            v = v | (at(k) << 32 * k)
        if f.lsb:
            v = v >> f.lsb
        if f.lsb + f.width < 32 * f.span:
            v = v & ((1 << f.width) - 1)
        out[f.name] = v.view(np.int64) if f.width <= 32 else v     # values below 2^32
    return out


def unpack_header(lanes: np.ndarray, table: Sequence[Field]) -> dict[str, Any]:
    """The fields of ``table`` of one header, lanes uint32 ``(>= the table's lanes,)``, by
    name: Python ints (a tuple of ``count`` ints for a field of several values)."""
    ln = np.asarray(lanes).tolist()
    out: dict[str, Any] = {}
    for f in table:
        vals = []
        for first in range(f.lane, f.end, f.span):
            v = ln[first]
            for k in range(1, f.span):
                v |= ln[first + k] << 32 * k
            vals.append((v >> f.lsb) & ((1 << f.width) - 1))
        out[f.name] = tuple(vals) if f.count > 1 else vals[0]
    return out


def tag_of(w: np.ndarray, pos: np.ndarray | int) -> np.ndarray:
    """The header tags of the headers starting at word(s) ``pos`` of ``w`` (uint32
    ``(n_words, num_rx)``; the tag lies in a header's first word)."""
    return (w[pos, TAG.lane] >> TAG.lsb) & ((1 << TAG.width) - 1)


def hdr_words(num_rx: int) -> int:
    """Words per record header or trailer."""
    return -(-HDR_LANES // num_rx)


def record_words(num_tx: int, num_rx: int) -> int:
    """Words per record (header + num_tx snapshot words)."""
    return hdr_words(num_rx) + num_tx


def frame_words(num_tx: int, num_rx: int, max_detections: int) -> int:
    """Fixed words per frame of the record stream."""
    return max_detections * record_words(num_tx, num_rx) + hdr_words(num_rx)


def snap_rows(guard_r: int, train_r: int) -> int:
    """Snapshot ring rows: the power of two >= PR + 3 (PR + 2 rows needed, one of slack)."""
    need = guard_r + train_r + 3
    return 1 << (need - 1).bit_length()


@dataclass(frozen=True)
class Record:
    """One detection. ``snapshot``: uint32 ``(num_tx, num_rx)`` packed {Q, I} lanes;
    ``neighbours``: the integrated powers of the cells at range - 1, range + 1, Doppler - 1,
    Doppler + 1 (``model.cfar_2d.NEIGHBOURS``)."""

    range_bin: int
    doppler_bin: int
    power: int
    noise_sum: int
    cells: int
    snapshot: np.ndarray
    index: int = 0
    frame_id: int = 0
    neighbours: tuple[int, int, int, int] = (0, 0, 0, 0)

    @classmethod
    def of_cell(cls, cells: CfarCells, r: int, d: int, snapshot: np.ndarray) -> Record:
        """The record the RTL sends for CFAR output cell (r, d) with its snapshot (uint32
        ``(num_tx, num_rx)``)."""
        return cls(range_bin=int(r), doppler_bin=int(d), power=int(cells.power[r, d]),
                   noise_sum=int(cells.train_sum[r, d]), cells=int(cells.count[r, d]),
                   snapshot=snapshot,
                   neighbours=tuple(int(v) for v in cells.neighbours[r, d]))  # type: ignore[arg-type]

    @property
    def noise(self) -> float:
        """Mean training-cell power (the CFAR's noise estimate)."""
        return self.noise_sum / max(self.cells, 1)


@dataclass(frozen=True)
class Trailer:
    """End of a frame's records."""

    records: int
    detections: int
    truncated: bool
    truncated_sticky: bool
    frame_id: int
    max_detections: int
    limit: int
    """Records per frame at most in this frame (the run-time setting, <= max_detections)."""


@dataclass
class RecordFrame:
    """A decoded frame: its records, trailer (None if missing) and errors found."""

    records: list[Record]
    trailer: Trailer | None
    errors: list[str]


def encode_frame(records: Sequence[Record], detections: int, num_tx: int, num_rx: int,
                 max_detections: int, frame_id: int = 0, sticky: bool = False,
                 limit: int | None = None) -> np.ndarray:
    """Record stream of one frame, uint32 ``(frame_words, num_rx)``, exactly as the RTL
    sends it. ``max_detections``: the RTL's MAX_DETECTIONS (the frame length); ``limit``:
    the frame's run-time record limit, 1..max_detections (None: max_detections);
    ``records``: the first min(len, limit) are sent (each with its position as ``index``
    and ``frame_id``); ``detections``: detections found (>= len(records)); ``sticky``: a
    frame since reset was truncated (this frame's own truncation is included
    automatically)."""
    limit = max_detections if limit is None else limit
    if not 1 <= limit <= max_detections:
        raise ValueError(f"limit {limit} not in 1..{max_detections}")
    sent = list(records)[:limit]
    n, hw = len(sent), hdr_words(num_rx)
    values = {f.name: [getattr(r, f.name) for r in sent] for f in RECORD_FIELDS}
    values.update(index=range(n), frame_id=[frame_id] * n)
    rec = np.zeros((n, hw * num_rx + num_tx * num_rx), np.uint32)    # header, snapshot
    rec[:, :HDR_LANES] = pack_headers(TAG_RECORD, RECORD_FIELDS, values)
    if n:
        rec[:, hw * num_rx:] = np.stack([np.asarray(r.snapshot, dtype=np.uint32).reshape(-1)
                                         for r in sent])
    truncated = detections > limit
    trailer = Trailer(records=n, detections=min(detections, MAX_COUNT), truncated=truncated,
                      truncated_sticky=sticky or truncated, frame_id=frame_id,
                      max_detections=max_detections, limit=limit)
    out = np.zeros((frame_words(num_tx, num_rx, max_detections), num_rx), dtype=np.uint32)
    lanes = out.reshape(-1)                                          # a view of out
    lanes[:rec.size] = rec.reshape(-1)
    lanes[rec.size:rec.size + HDR_LANES] = pack_headers(
        TAG_TRAILER, TRAILER_FIELDS, {k: [v] for k, v in vars(trailer).items()})[0]
    return out


def record_scan(words: np.ndarray, num_tx: int) -> tuple[np.ndarray, np.ndarray, int, int]:
    """Where a frame's records are: (w uint32 (n_words, num_rx), the candidate header word
    positions int (n_pos,) at the record stride, the number n of complete records before the
    first position that is not one, header words per record hw). Records are read at
    ``pos[:n]`` (:func:`unpack_records`); ``pos[n]`` (when n < n_pos) is where the frame's
    end is looked for (:func:`frame_end`)."""
    w = np.asarray(words, dtype=np.uint32)
    hw = hdr_words(w.shape[1])
    rw = hw + num_tx
    n_words = len(w)
    # candidate header positions: pos + hw <= n_words
    n_pos = (n_words - hw) // rw + 1 if n_words >= hw else 0
    pos = np.arange(n_pos) * rw
    tags = tag_of(w, pos) if n_pos else np.zeros(0, np.uint32)
    # a record is complete when its snapshot fits too
    stop = (tags != TAG_RECORD) | (pos + rw > n_words)
    n = int(np.argmax(stop)) if stop.any() else n_pos
    return w, pos, n, hw


def unpack_records(w: np.ndarray, n: int, num_tx: int
                   ) -> tuple[dict[str, np.ndarray], np.ndarray]:
    """The first n records of ``w`` (uint32 (n_words, num_rx), records from word 0 on, as
    :func:`record_scan` finds them): (their header fields, :func:`unpack_headers`; their
    snapshots uint32 (n, num_tx, num_rx), a view of ``w``)."""
    num_rx = w.shape[1]
    hw = hdr_words(num_rx)
    block = w[:n * (hw + num_tx)].reshape(n, hw + num_tx, num_rx)
    return unpack_headers(block[:, :hw].reshape(n, hw * num_rx)), block[:, hw:]


def records_of(fields: Mapping[str, np.ndarray], snapshots: np.ndarray) -> list[Record]:
    """:class:`Record` objects of n records' header fields (:func:`unpack_headers`) and
    snapshots (uint32 (n, num_tx, num_rx); record k's snapshot is ``snapshots[k]``)."""
    cols = {f.name: [tuple(v) for v in fields[f.name].tolist()] if f.count > 1
            else fields[f.name].tolist() for f in RECORD_FIELDS}
    cols["snapshot"] = list(snapshots)
    return [Record(*row)
            for row in zip(*(cols[f.name] for f in dataclass_fields(Record)), strict=True)]


def trailer_of(lanes: np.ndarray) -> Trailer:
    """The trailer of its header lanes (uint32 (>= 5,))."""
    v = unpack_header(lanes, TRAILER_FIELDS)
    return Trailer(**{f.name: bool(v[f.name]) if f.width == 1 else v[f.name]
                      for f in TRAILER_FIELDS})


def frame_end(w: np.ndarray, pos: np.ndarray, n: int, hw: int
              ) -> tuple[Trailer | None, list[str]]:
    """The frame's trailer after its n records (:func:`record_scan`), or None, and the
    errors: a trailer whose count is not n, a bad tag, a record cut short, no trailer."""
    errors: list[str] = []
    if n < len(pos):
        p = int(pos[n])
        tag = int(tag_of(w, p))
        if tag == TAG_TRAILER:
            tr = trailer_of(w[p:p + hw].reshape(-1))
            if tr.records != n:
                errors.append(f"trailer counts {tr.records} records, found {n}")
            return tr, errors
        if tag != TAG_RECORD:
            errors.append(f"word {p}: bad record tag 0x{tag:02x}")
        else:
            errors.append(f"word {p}: record cut short")
    errors.append("no trailer")
    return None, errors


def decode_frame(words: np.ndarray, num_tx: int) -> RecordFrame:
    """Records of one frame's record stream (uint32 ``(n, num_rx)``, padding allowed).

    Never raises on bad data: a bad tag, a missing trailer or a count mismatch is reported
    in ``errors``. Vectorised: the headers sit at a fixed stride, so all of them are read
    at once up to the first word that is not a record header. The snapshots are copies
    (not views of ``words``)."""
    w, pos, n, hw = record_scan(words, num_tx)
    tr, errors = frame_end(w, pos, n, hw)
    fields, snaps = unpack_records(w, n, num_tx)
    return RecordFrame(records_of(fields, snaps.copy()), tr, errors)
