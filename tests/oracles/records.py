"""Test oracles of the detection-record path: the implementations the current ones replaced
(issue 14), each written straight from the layout in docs/detect.md, independent of the
field table of ``model.detect_records`` (tests/test_records_fast.py checks the library
against them)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from host.records import RecordArrays, RecordDecoder
from model.axis_packetizer import unpack_iq
from model.detect_records import (
    TAG_RECORD,
    TAG_TRAILER,
    Record,
    RecordFrame,
    Trailer,
    decode_frame,
    hdr_words,
)

NEIGHBOUR_LANE = 8
"""First header lane of the four 64-bit neighbour powers (docs/detect.md)."""


def decode_frame_reference(words: np.ndarray, num_tx: int) -> RecordFrame:
    """``model.detect_records.decode_frame`` as a per-record loop (same output).

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
                         frame_id=int(lanes[3]), max_detections=int(lanes[4]),
                         limit=int(lanes[5]))
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


def record_arrays_reference(records: Sequence[Record], n_virtual: int, gain: float = 1.0
                            ) -> RecordArrays:
    """``host.records.record_arrays`` straight from ``Record`` objects (same output)."""
    n = len(records)
    rb = np.fromiter((r.range_bin for r in records), dtype=np.int64, count=n)
    db = np.fromiter((r.doppler_bin for r in records), dtype=np.int64, count=n)
    power = np.fromiter((r.power for r in records), dtype=np.float64, count=n)
    noise = np.fromiter((r.noise for r in records), dtype=np.float64, count=n)
    nb = np.array([r.neighbours for r in records], dtype=np.float64).reshape(n, 4)
    if n:
        snap = unpack_iq(np.stack([r.snapshot for r in records])).reshape(n, n_virtual)
    else:
        snap = np.zeros((0, n_virtual), np.complex64)
    g2 = gain * gain
    return RecordArrays(rb, db, power / g2, noise / g2, (snap / gain).astype(np.complex64),
                        nb / g2)


class RecordDecoderReference(RecordDecoder):
    """``host.records.RecordDecoder`` decoding each frame into ``Record`` objects
    (``model.detect_records.decode_frame``: the path ``decode_record_fields`` replaced)."""

    def _decode(self, words: np.ndarray
                ) -> tuple[Sequence[Record], Trailer | None, list[str], set[int]]:
        dec = decode_frame(words, self.dcfg.num_tx)
        return dec.records, dec.trailer, dec.errors, {r.frame_id for r in dec.records}
