"""Link and health counters of a live stream, as the view shows them.

One :class:`LinkHealth` lives as long as the view. The ingest thread updates it (datagrams,
frames, losses); the server reads :meth:`LinkHealth.snapshot` from another thread, so every
update and the snapshot hold :attr:`LinkHealth.lock`.
"""

from __future__ import annotations

import threading
import time
from collections import deque
from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np

from host.stream import StreamStats

RATE_WINDOW_S = 2.0
"""Frames/s and datagrams/s are averaged over this window, s."""


class LinkFrame(Protocol):
    """What the counters read of a decoded frame (a cube frame or a record frame)."""

    frame_id: int
    problems: list[str]
    valid: np.ndarray

    @property
    def complete(self) -> bool: ...


def missing_packets(frame: LinkFrame, packet_words: int) -> int:
    """Packets of ``frame`` with at least one word missing (lost or corrupt).

    ``frame.valid``: bool, any shape that flattens to DMA word order (a cube frame's
    (num_tx, n_range, n_doppler), a record frame's (frame_words,)); packet k carries words
    [k * packet_words, (k + 1) * packet_words)."""
    valid = frame.valid.reshape(-1)
    starts = np.arange(0, valid.size, packet_words)
    return int((np.minimum.reduceat(valid.astype(np.uint8), starts) == 0).sum())


@dataclass
class LinkHealth:
    """Counters since the view started (across sender restarts)."""

    datagrams: int = 0
    bytes: int = 0
    malformed: int = 0
    """Datagrams that are no DMA packet or fail their CRC."""
    late_packets: int = 0
    packets_lost: int = 0
    frames_complete: int = 0
    frames_damaged: int = 0
    frames_lost: int = 0
    frames_not_shown: int = 0
    stream_restarts: int = 0
    hw_overflow: bool = False
    hw_framing: bool = False
    last_frame_id: int | None = None
    detections: int = 0
    objects: int = 0
    stream_kind: str = ""
    """"cube", "records" (the on-chip detector's record stream) or "" (nothing learnt yet)."""
    cfar_detections: int | None = None
    """Record stream: cells the FPGA's CFAR passed in the newest frame (its trailer)."""
    records: int | None = None
    """Record stream: records the newest frame carried (at most MAX_DETECTIONS)."""
    max_detections: int | None = None
    truncated: bool = False
    """Sticky: some frame had more detections than MAX_DETECTIONS (trailer flag, this frame's
    or the hardware's sticky one)."""
    frames_truncated: int = 0
    problems: deque[str] = field(default_factory=lambda: deque(maxlen=8))
    lock: threading.Lock = field(default_factory=threading.Lock, repr=False)
    _frame_times: deque[float] = field(default_factory=lambda: deque(maxlen=4096), repr=False)
    _last_datagram: float = 0.0
    _base: StreamStats = field(default_factory=StreamStats, repr=False)

    # ---- updates (ingest thread) ----------------------------------------------------------
    def on_datagram(self, nbytes: int) -> None:
        with self.lock:
            self.datagrams += 1
            self.bytes += nbytes
            self._last_datagram = time.monotonic()

    def on_decoder(self, stats: StreamStats, problems: list[str]) -> None:
        """Take the decoder's counters (``stats``: the current decoder's, added to those of
        decoders retired by a restart) and its newest problem messages."""
        with self.lock:
            b = self._base
            self.malformed = (b.garbage_packets + stats.garbage_packets + b.crc_errors
                              + stats.crc_errors)
            self.late_packets = b.late_packets + stats.late_packets
            self.hw_overflow |= stats.hw_overflow_seen
            self.hw_framing |= stats.hw_framing_seen
            for p in problems:
                self.problems.append(p)

    def retire_decoder(self, stats: StreamStats) -> None:
        """A decoder is replaced (sender restarted): keep its counters."""
        with self.lock:
            self._base.garbage_packets += stats.garbage_packets
            self._base.crc_errors += stats.crc_errors
            self._base.late_packets += stats.late_packets
            self.stream_restarts += 1

    def on_frame(self, frame: LinkFrame, packet_words: int, n_packets: int,
                 id_gap: int) -> None:
        """A decoded frame; ``id_gap``: frames missing entirely before it (by frame id),
        -1 when it is one of those counted missing, arrived after all (reordered)."""
        lost = missing_packets(frame, packet_words)
        with self.lock:
            self._frame_times.append(time.monotonic())
            if frame.complete:
                self.frames_complete += 1
            else:
                self.frames_damaged += 1
                for p in frame.problems[:2]:
                    self.problems.append(p)
            self.frames_lost += id_gap
            self.packets_lost += lost + id_gap * n_packets
            self.last_frame_id = frame.frame_id

    def on_kind(self, kind: str, max_detections: int | None = None) -> None:
        """The stream is a radar cube ("cube") or the detector's records ("records",
        ``max_detections`` records per frame at most)."""
        with self.lock:
            self.stream_kind = kind
            self.max_detections = max_detections if kind == "records" else None

    def on_record_frame(self, records: int, detections: int, truncated: bool,
                        truncated_sticky: bool) -> None:
        """A record frame's trailer figures (``records`` sent, ``detections`` the CFAR
        passed, its ``truncated`` flag and the hardware's sticky one)."""
        with self.lock:
            self.records = records
            self.cfar_detections = detections
            self.frames_truncated += int(truncated)
            if (truncated or truncated_sticky) and not self.truncated:
                self.problems.append(f"TRUNCATED: more than MAX_DETECTIONS "
                                     f"{self.max_detections} cells passed the CFAR "
                                     f"({detections} in one frame)")
            self.truncated |= truncated or truncated_sticky

    def on_cube_frame(self) -> None:
        """A frame that arrived without packets (simulated scene)."""
        with self.lock:
            self._frame_times.append(time.monotonic())
            self.frames_complete += 1

    def on_shown(self, detections: int, objects: int, skipped: int) -> None:
        with self.lock:
            self.detections = detections
            self.objects = objects
            self.frames_not_shown += skipped

    # ---- reading (any thread) -------------------------------------------------------------
    def frames_per_s(self, now: float | None = None) -> float:
        now = time.monotonic() if now is None else now
        with self.lock:
            recent = [t for t in self._frame_times if now - t <= RATE_WINDOW_S]
        if len(recent) < 2:
            return 0.0
        span = max(now - recent[0], 1e-3)
        return (len(recent) - 1) / span if span < RATE_WINDOW_S else len(recent) / span

    def snapshot(self) -> dict[str, Any]:
        """Plain-JSON view of every counter (what the page and the benchmark read)."""
        fps = self.frames_per_s()
        with self.lock:
            idle = (time.monotonic() - self._last_datagram) if self._last_datagram else None
            return {
                "frames_per_s": round(fps, 2),
                "datagrams": self.datagrams, "bytes": self.bytes,
                "malformed": self.malformed, "late_packets": self.late_packets,
                "packets_lost": self.packets_lost,
                "frames_complete": self.frames_complete,
                "frames_damaged": self.frames_damaged, "frames_lost": self.frames_lost,
                "frames_not_shown": self.frames_not_shown,
                "stream_restarts": self.stream_restarts,
                "hw_overflow": self.hw_overflow, "hw_framing": self.hw_framing,
                "last_frame_id": self.last_frame_id,
                "detections": self.detections, "objects": self.objects,
                "stream_kind": self.stream_kind, "cfar_detections": self.cfar_detections,
                "records": self.records, "max_detections": self.max_detections,
                "truncated": self.truncated, "frames_truncated": self.frames_truncated,
                "link_idle_s": None if idle is None else round(idle, 1),
                "problems": list(self.problems),
            }
