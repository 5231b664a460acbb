"""Reading recordings of :mod:`host.ros.recording` back: a summary (topics, message counts,
frames, time span), also of a recording cut short (no footer: read up to the cut), and the
point clouds as written."""

from __future__ import annotations

import struct
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from mcap.exceptions import McapError
from mcap.reader import make_reader
from mcap.records import Channel, Message, Schema
from mcap.stream_reader import StreamReader
from mcap_ros2.decoder import DecoderFactory

from host.ros.messages import TOPICS, points_of

MCAP_MAGIC = b"\x89MCAP0\r\n"
_READ_ERRORS = (McapError, struct.error, ValueError, EOFError, KeyError)


@dataclass(frozen=True)
class TopicSummary:
    """One topic: its ROS 2 type and how many messages it has."""

    topic: str
    schema: str
    messages: int


@dataclass(frozen=True)
class RecordingSummary:
    """What a recording holds. ``frames``: point cloud messages; ``start_ns``/``end_ns``:
    first and last message time, ns (0 when empty); ``cut_short``: None for a complete
    recording, else why it ends early (the counts are then of what could be read)."""

    topics: list[TopicSummary]
    frames: int
    start_ns: int
    end_ns: int
    size_bytes: int
    cut_short: str | None = None


def summarize(path: str | Path) -> RecordingSummary:
    """Summary of the recording at ``path``: from its summary section when it has one, else
    by reading its records up to where it is cut short. ValueError when it is not MCAP."""
    path = Path(path)
    size = path.stat().st_size
    with open(path, "rb") as f:
        if f.read(8) != MCAP_MAGIC:
            raise ValueError(f"{path}: not an MCAP recording (no MCAP magic at the start)")
        f.seek(0)
        try:
            summary = make_reader(f).get_summary()
        except _READ_ERRORS:
            summary = None
        if summary is not None and summary.statistics is not None:
            stats = summary.statistics
            counts = {summary.channels[c].topic: (summary.schemas[
                summary.channels[c].schema_id].name, n)
                for c, n in stats.channel_message_counts.items()}
            return _summary(counts, stats.message_start_time if stats.message_count else 0,
                            stats.message_end_time if stats.message_count else 0, size, None)
        f.seek(0)
        return _scan(f, size)


def _scan(f: object, size: int) -> RecordingSummary:
    """Summary by reading records in order until the end or the cut."""
    schemas: dict[int, str] = {}
    channels: dict[int, tuple[str, str]] = {}
    counts: dict[str, tuple[str, int]] = {}
    start = end = None
    cut = None
    try:
        for rec in StreamReader(f, validate_crcs=True).records:  # type: ignore[arg-type]
            if isinstance(rec, Schema):
                schemas[rec.id] = rec.name
            elif isinstance(rec, Channel):
                channels[rec.id] = (rec.topic, schemas.get(rec.schema_id, "?"))
            elif isinstance(rec, Message):
                topic, schema = channels.get(rec.channel_id, (f"channel {rec.channel_id}", "?"))
                counts[topic] = (schema, counts.get(topic, (schema, 0))[1] + 1)
                start = rec.log_time if start is None else min(start, rec.log_time)
                end = rec.log_time if end is None else max(end, rec.log_time)
    except _READ_ERRORS as exc:
        cut = f"no footer: reading stopped on {type(exc).__name__}" + (f" {exc}" if str(exc)
                                                                       else "")
    return _summary(counts, start or 0, end or 0, size, cut)


def _summary(counts: dict[str, tuple[str, int]], start: int, end: int, size: int,
             cut: str | None) -> RecordingSummary:
    topics = [TopicSummary(t, s, n) for t, (s, n) in sorted(counts.items())]
    frames = counts.get(TOPICS["points"][0], ("", 0))[1]
    return RecordingSummary(topics, frames, start, end, size, cut)


def read_points(path: str | Path) -> list[tuple[int, np.ndarray]]:
    """Every point cloud of a complete recording in time order: (stamp ns, points as
    ``host.ros.messages.POINT_DTYPE`` (n,))."""
    out = []
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        for _, _, _, msg in reader.iter_decoded_messages(topics=[TOPICS["points"][0]],
                                                        log_time_order=True):
            stamp = msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec
            out.append((stamp, points_of(msg)))
    return out
