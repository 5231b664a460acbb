"""Detection record format of ``rtl/detect/detect_records.sv`` (bit-exact model, shared
with the host decoder: the one place that defines the layout, docs/detect.md).

A *word* is ``num_rx`` 32-bit lanes (uint32 ``(num_rx,)``, lane 0 in the least significant
bits), as in ``model/axis_packetizer.py``. One frame of the record stream is exactly
``frame_words(num_tx, num_rx, max_detections)`` words (it then goes through
``axis_packetizer``: packet header, sequence numbers, loss detection):

    record 0 .. record n-1, trailer, zero words up to the fixed frame length

A header (record header or trailer) is a vector of 16 lanes sent as ``hdr_words(num_rx) =
ceil(16 / num_rx)`` words (lanes past 16 are zero; one word at ``num_rx`` = 16). Record
header lanes::

    0: [31:24] TAG_RECORD 0xD1, [23:12] range bin, [11:0] Doppler bin (natural order)
    1: [31:16] record index within the frame, [15:0] training cells in the noise sum
    2, 3: integrated power (NCI), 64 bits, low lane first
    4, 5: noise sum S (the CFAR's training sum), 64 bits; noise estimate = S / cells
    6: frame id (frames since reset)
    7: 0
    8..15: the integrated powers of the cell's four neighbours, 64 bits each, low lane first,
       in the order range - 1, range + 1, Doppler - 1, Doppler + 1 (``model.cfar_2d.
       NEIGHBOURS``; Doppler circular, 0 beyond the first and last range rows): the host
       interpolates the peak position from them as from the cube's map

followed by ``num_tx`` words: the Doppler-FFT values of the cell for TX 0..num_tx-1, lanes
= RX 0..num_rx-1, ``{Q[31:16], I[15:0]}`` (the snapshot). Trailer lanes::

    0: [31:24] TAG_TRAILER 0xDE, [1] sticky truncated (any frame since reset), [0] truncated
       (this frame had more than max_detections detections)
    1: records in this frame; 2: detections found in this frame (saturates at 2^17-1)
    3: frame id; 4: max_detections; 5..15: 0

Records are in CFAR output order (``model.cfar_2d.output_order``): range row by row, within a
row Doppler bins PD..n_doppler-1, 0..PD-1.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from model.cfar_2d import CfarCells

TAG_RECORD = 0xD1
TAG_TRAILER = 0xDE
HDR_LANES = 16
NEIGHBOUR_LANE = 8
"""First header lane of the four 64-bit neighbour powers."""
MAX_COUNT = (1 << 17) - 1


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


@dataclass
class RecordFrame:
    """A decoded frame: its records, trailer (None if missing) and errors found."""

    records: list[Record]
    trailer: Trailer | None
    errors: list[str]


def _lanes_to_words(lanes: np.ndarray, num_rx: int) -> np.ndarray:
    n = hdr_words(num_rx) * num_rx
    out = np.zeros(n, dtype=np.uint32)
    out[:min(n, len(lanes))] = lanes[:n]
    return out.reshape(-1, num_rx)


def _u64(v: int) -> tuple[int, int]:
    return v & 0xFFFFFFFF, (v >> 32) & 0xFFFFFFFF


def encode_frame(records: Sequence[Record], detections: int, num_tx: int, num_rx: int,
                 max_detections: int, frame_id: int = 0, sticky: bool = False
                 ) -> np.ndarray:
    """Record stream of one frame, uint32 ``(frame_words, num_rx)``, exactly as the RTL
    sends it. ``records``: the first min(len, max_detections) are sent; ``detections``:
    detections found (>= len(records)); ``sticky``: a frame since reset was truncated
    (this frame's own truncation is included automatically)."""
    sent = list(records)[:max_detections]
    truncated = detections > max_detections
    words = []
    for k, rec in enumerate(sent):
        lanes = np.zeros(HDR_LANES, dtype=np.uint32)
        lanes[0] = (TAG_RECORD << 24) | ((rec.range_bin & 0xFFF) << 12) | (rec.doppler_bin & 0xFFF)
        lanes[1] = ((k & 0xFFFF) << 16) | (rec.cells & 0xFFFF)
        lanes[2], lanes[3] = _u64(rec.power)
        lanes[4], lanes[5] = _u64(rec.noise_sum)
        lanes[6] = frame_id & 0xFFFFFFFF
        for j, nb in enumerate(rec.neighbours):
            lanes[NEIGHBOUR_LANE + 2 * j], lanes[NEIGHBOUR_LANE + 2 * j + 1] = _u64(nb)
        words.append(_lanes_to_words(lanes, num_rx))
        words.append(np.asarray(rec.snapshot, dtype=np.uint32).reshape(num_tx, num_rx))
    lanes = np.zeros(HDR_LANES, dtype=np.uint32)
    lanes[0] = (TAG_TRAILER << 24) | (int(sticky or truncated) << 1) | int(truncated)
    lanes[1] = len(sent)
    lanes[2] = min(detections, MAX_COUNT)
    lanes[3] = frame_id & 0xFFFFFFFF
    lanes[4] = max_detections
    words.append(_lanes_to_words(lanes, num_rx))
    out = np.zeros((frame_words(num_tx, num_rx, max_detections), num_rx), dtype=np.uint32)
    body = np.vstack(words)
    out[:len(body)] = body
    return out


def record_scan(words: np.ndarray, num_tx: int) -> tuple[np.ndarray, np.ndarray, int, int]:
    """Where a frame's records are: (w uint32 (n_words, num_rx), the candidate header word
    positions int (n_pos,) at the record stride, the number n of complete records before the
    first position that is not one, header words per record hw). Records are read at
    ``pos[:n]``; ``pos[n]`` (when n < n_pos) is where the frame's end is looked for
    (:func:`frame_end`)."""
    w = np.asarray(words, dtype=np.uint32)
    hw = hdr_words(w.shape[1])
    rw = hw + num_tx
    n_words = len(w)
    # candidate header positions: pos + hw <= n_words
    n_pos = (n_words - hw) // rw + 1 if n_words >= hw else 0
    pos = np.arange(n_pos) * rw
    tags = w[pos, 0] >> 24 if n_pos else np.zeros(0, np.uint32)
    # a record is complete when its snapshot fits too
    stop = (tags != TAG_RECORD) | (pos + rw > n_words)
    n = int(np.argmax(stop)) if stop.any() else n_pos
    return w, pos, n, hw


def trailer_of(lanes: np.ndarray) -> Trailer:
    """The trailer of its header lanes (uint32 (>= 5,))."""
    return Trailer(records=int(lanes[1]), detections=int(lanes[2]),
                   truncated=bool(lanes[0] & 1), truncated_sticky=bool(lanes[0] & 2),
                   frame_id=int(lanes[3]), max_detections=int(lanes[4]))


def frame_end(w: np.ndarray, pos: np.ndarray, n: int, hw: int
              ) -> tuple[Trailer | None, list[str]]:
    """The frame's trailer after its n records (:func:`record_scan`), or None, and the
    errors: a trailer whose count is not n, a bad tag, a record cut short, no trailer."""
    errors: list[str] = []
    if n < len(pos):
        p = int(pos[n])
        tag = int(w[p, 0] >> 24)
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
    at once up to the first word that is not a record header (same output as
    :func:`decode_frame_reference`)."""
    w, pos, n, hw = record_scan(words, num_tx)
    tr, errors = frame_end(w, pos, n, hw)
    return RecordFrame(_records_at(w, pos[:n], hw, num_tx), tr, errors)


def _records_at(w: np.ndarray, pos: np.ndarray, hw: int, num_tx: int) -> list[Record]:
    """Records whose headers start at word indices ``pos`` (int (n,)) of ``w`` (uint32
    (n_words, num_rx)), all fields read in one gather."""
    if not len(pos):
        return []
    num_rx = w.shape[1]
    hdr = w[pos[:, None] + np.arange(hw)[None, :]].reshape(len(pos), -1)[:, :HDR_LANES]
    hdr = hdr.astype(np.int64)
    snaps = w[pos[:, None] + hw + np.arange(num_tx)[None, :]]      # (n, num_tx, num_rx)
    rb = ((hdr[:, 0] >> 12) & 0xFFF).tolist()
    db = (hdr[:, 0] & 0xFFF).tolist()
    power = (hdr[:, 2] | (hdr[:, 3] << 32)).astype(np.uint64).tolist()
    noise = (hdr[:, 4] | (hdr[:, 5] << 32)).astype(np.uint64).tolist()
    cells = (hdr[:, 1] & 0xFFFF).tolist()
    index = (hdr[:, 1] >> 16).tolist()
    fid = hdr[:, 6].tolist()
    nb = neighbour_powers(hdr).tolist()
    return [Record(range_bin=a, doppler_bin=b, power=c, noise_sum=d, cells=e,
                   snapshot=snaps[i].reshape(num_tx, num_rx), index=f, frame_id=g,
                   neighbours=tuple(h))
            for i, (a, b, c, d, e, f, g, h) in enumerate(zip(rb, db, power, noise, cells, index,
                                                             fid, nb, strict=True))]


def neighbour_powers(hdr: np.ndarray) -> np.ndarray:
    """The four neighbour powers of record headers, uint64 ``(n, 4)``, from their lanes
    (int64 ``(n, >= HDR_LANES)``)."""
    lo = hdr[:, NEIGHBOUR_LANE:NEIGHBOUR_LANE + 8:2]
    hi = hdr[:, NEIGHBOUR_LANE + 1:NEIGHBOUR_LANE + 8:2]
    return (lo.astype(np.uint64) | (hi.astype(np.uint64) << np.uint64(32)))


def decode_frame_reference(words: np.ndarray, num_tx: int) -> RecordFrame:
    """The per-record loop :func:`decode_frame` replaced (same output; kept as its
    specification for the tests and the benchmark's old-vs-new timing).

    Never raises on bad data: a bad tag, a missing trailer or a count mismatch is reported
    in ``errors``."""
    w = np.asarray(words, dtype=np.uint32)
    num_rx = w.shape[1]
    hw = hdr_words(num_rx)
    recs: list[Record] = []
    errors: list[str] = []
    pos = 0
    while pos + hw <= len(w):
        lanes = w[pos:pos + hw].reshape(-1)
        tag = int(lanes[0]) >> 24
        if tag == TAG_TRAILER:
            tr = Trailer(records=int(lanes[1]), detections=int(lanes[2]),
                         truncated=bool(lanes[0] & 1), truncated_sticky=bool(lanes[0] & 2),
                         frame_id=int(lanes[3]), max_detections=int(lanes[4]))
            if tr.records != len(recs):
                errors.append(f"trailer counts {tr.records} records, found {len(recs)}")
            return RecordFrame(recs, tr, errors)
        if tag != TAG_RECORD:
            errors.append(f"word {pos}: bad record tag 0x{tag:02x}")
            break
        if pos + hw + num_tx > len(w):
            errors.append(f"word {pos}: record cut short")
            break
        recs.append(Record(
            range_bin=(int(lanes[0]) >> 12) & 0xFFF, doppler_bin=int(lanes[0]) & 0xFFF,
            power=int(lanes[2]) | (int(lanes[3]) << 32),
            noise_sum=int(lanes[4]) | (int(lanes[5]) << 32), cells=int(lanes[1]) & 0xFFFF,
            snapshot=w[pos + hw:pos + hw + num_tx].copy(), index=int(lanes[1]) >> 16,
            frame_id=int(lanes[6]),
            neighbours=tuple(int(lanes[NEIGHBOUR_LANE + 2 * j])  # type: ignore[arg-type]
                             | (int(lanes[NEIGHBOUR_LANE + 2 * j + 1]) << 32)
                             for j in range(4))))
        pos += hw + num_tx
    errors.append("no trailer")
    return RecordFrame(recs, None, errors)
