"""What the view shows of one frame, and the newest-only hand-over to the server.

A :class:`ViewFrame` is source-neutral: a cube stream fills ``cube`` (channel maps) and
``nci`` (integrated map) and the processed ``cloud``; a detection-record stream (on-chip
detection, docs/design.md section 3.4) fills ``cloud`` and ``records`` (no cube, no maps): the
page draws the records in the range-Doppler plane and over range instead. Sources call
:meth:`Feed.publish`; the server's clients read :meth:`Feed.latest`. There is never more
than one frame waiting: a newer one replaces it (frames faster than the browsers draw are
dropped, oldest first).
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from host.pointcloud import PointCloud
from host.records import RecordArrays
from model.config import RadarConfig


@dataclass(frozen=True)
class ViewFrame:
    """One frame as displayed.

    ``seq``: publication counter (increases by one per published frame).
    ``cube``: complex (n_virtual, n_range, n_doppler) in float-reference units (LSB of a
    1/N-per-FFT chain), or None (record stream).
    ``nci``: float (n_range, n_doppler) power summed over channels, LSB^2, or None.
    ``cloud``: the frame's detections. ``objects``: GNN objects (``gnn.infer.detect_objects``
    dicts: class, score, x_m, y_m, length_m, width_m, heading_deg).
    ``records``: a record stream's records (every cell the FPGA's CFAR passed, with its
    integrated power and noise estimate, host float units), or None (cube stream).
    """

    seq: int
    frame_id: int
    cfg: RadarConfig
    cloud: PointCloud
    cube: np.ndarray | None = None
    nci: np.ndarray | None = None
    objects: list[dict[str, Any]] = field(default_factory=list)
    source: str = ""
    records: RecordArrays | None = None


class Feed:
    """Newest-frame slot shared by one producer thread and the server.

    ``on_publish`` (set by the server) is called from the producer thread after each
    publish; it must only schedule work (e.g. ``loop.call_soon_threadsafe``)."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._latest: ViewFrame | None = None
        self._seq = 0
        self.on_publish: Callable[[], None] | None = None
        self.demand_driven = False
        self._wanted = threading.Event()

    def want(self) -> None:
        """A browser is ready for a new frame (any thread)."""
        self._wanted.set()

    def wait_wanted(self, timeout_s: float) -> bool:
        """Whether a new frame should be produced: always, unless ``demand_driven`` (set by
        the server), then only once some browser asked for one since the producer last
        started on a frame. The
        host then processes frames no faster than the browsers draw them, and the CPU it
        saves goes to the browser."""
        return not self.demand_driven or self._wanted.wait(timeout_s)

    def taken(self) -> None:
        """The producer started on a frame: later requests ask for the one after it."""
        self._wanted.clear()

    def next_seq(self) -> int:
        with self._lock:
            self._seq += 1
            return self._seq

    def publish(self, frame: ViewFrame) -> None:
        with self._lock:
            self._latest = frame
        if self.on_publish is not None:
            self.on_publish()

    def latest(self) -> ViewFrame | None:
        with self._lock:
            return self._latest
