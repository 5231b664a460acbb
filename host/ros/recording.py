"""MCAP recordings with ROS 2 (CDR) messages: per frame the point cloud, the GNN objects and
a status, and once the radar mount (topics in :data:`TOPICS`; docs/ros.md).

A recording is opened before the work starts (an unwritable path fails at once), written
frame by frame, and closed by :meth:`Recorder.close` or the ``with`` block, also when the work
stops on an error or Ctrl-C: what was written so far is then a complete, readable file. When
the disk fills, the file is cut short at its last complete chunk (``radar mcap info`` says
so and summarises what is there)."""

from __future__ import annotations

from contextlib import suppress
from pathlib import Path
from types import TracebackType
from typing import Any, BinaryIO

from mcap.well_known import MessageEncoding, SchemaEncoding
from mcap.writer import CompressionType, Writer

from host.pointcloud import PointCloud
from host.ros.cdr import encoder
from host.ros.messages import TOPICS, FrameStatus, Mount, frame_messages, tf_message
from host.ros.msgdefs import schema_text

CHUNK_BYTES = 1 << 20
"""Uncompressed bytes per MCAP chunk (zstd): what a cut-short recording loses at most."""


class RecordingError(Exception):
    """Writing the recording failed (a full disk): the message says after how many frames."""


class Recorder:
    """Writes one MCAP recording. ``out``: a path (created or replaced; OSError when it
    cannot be) or a binary file object (left open); ``frame_period_s``: the radar's frame
    period (``model.config.RadarConfig.frame_time_s``), s, which a caller that learns the
    radar from its stream sets later (before the first frame); a frame ``k`` frames after the
    first is stamped ``start_ns + k * frame_period_s`` (ns since the Unix epoch);
    ``mount``: the radar's pose on the robot, written once to ``/tf_static``."""

    def __init__(self, out: str | Path | BinaryIO, frame_period_s: float | None = None,
                 start_ns: int = 0, mount: Mount | None = None) -> None:
        self._own = isinstance(out, str | Path)
        self.name = str(out) if self._own else getattr(out, "name", "the recording")
        self._file: BinaryIO = open(out, "wb") if self._own else out  # noqa: SIM115
        self.frame_period_s = frame_period_s
        self.start_ns = int(start_ns)
        self.frames = 0
        self._first_id: int | None = None
        self._last_index = -1
        self._closed = False
        self._channels: dict[str, int] = {}
        try:
            self._writer = Writer(self._file, chunk_size=CHUNK_BYTES,
                                  compression=CompressionType.ZSTD)
            self._writer.start(profile="ros2", library="radar-array-processor host.ros")
            self._write("tf", tf_message(mount or Mount(), self.start_ns), self.start_ns)
        except BaseException:
            with suppress(OSError):
                self._close_file()
            raise

    def _write(self, role: str, msg: dict[str, Any], t_ns: int) -> None:
        topic, typename = TOPICS[role]
        if role not in self._channels:        # a channel appears with its first message
            schema = self._writer.register_schema(typename, SchemaEncoding.ROS2,
                                                  schema_text(typename).encode())
            self._channels[role] = self._writer.register_channel(topic, MessageEncoding.CDR,
                                                                 schema)
        self._writer.add_message(self._channels[role], log_time=t_ns,
                                 data=encoder(typename)(msg), publish_time=t_ns,
                                 sequence=self.frames)

    def time_ns(self, frame_id: int) -> int:
        """The stamp of frame ``frame_id``: ids count frames from the first one written; an
        id before the first (a restarted sender) follows the latest frame."""
        if self._first_id is None:
            self._first_id = frame_id
        index = frame_id - self._first_id
        if index < 0:
            index = self._last_index + 1
        self._last_index = max(self._last_index, index)
        if not self.frame_period_s or self.frame_period_s <= 0:
            raise ValueError(f"frame period must be > 0 s, got {self.frame_period_s!r}")
        return self.start_ns + round(index * self.frame_period_s * 1e9)

    def write_frame(self, cloud: PointCloud | None, status: FrameStatus,
                    objects: list[dict[str, Any]] | None = None) -> None:
        """Record one frame, stamped by ``status.frame``: its cloud on ``/radar/points``
        (None: a frame that gave no cloud, e.g. a damaged one left out), ``status`` on
        ``/radar/status`` and, when given (GNN run), ``objects`` on ``/radar/objects``
        (dicts as ``gnn.infer.detect_objects`` gives them). RecordingError when the write
        fails."""
        t = self.time_ns(status.frame)
        try:
            for role, msg in frame_messages(cloud, status, objects, t):
                self._write(role, msg, t)
        except OSError as exc:
            raise self._failed(exc) from exc
        self.frames += 1

    def _failed(self, exc: OSError) -> RecordingError:
        return RecordingError(f"{self.name}: {exc.strerror or exc} after {self.frames} "
                              f"frame(s): the recording is cut short there")

    def close(self) -> None:
        """Write the MCAP summary and footer, then close the file (a path's). A failing
        write (full disk) still closes the file, then raises RecordingError."""
        if self._closed:
            return
        self._closed = True
        failed = None
        try:
            self._writer.finish()
        except OSError as exc:
            failed = exc
        try:
            self._close_file()
        except OSError as exc:     # the buffered rest did not fit either
            failed = failed or exc
        if failed is not None:
            raise self._failed(failed) from failed

    def _close_file(self) -> None:
        if self._own:
            self._file.close()

    def __enter__(self) -> Recorder:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        if exc_type is None:
            self.close()
            return
        try:       # the error that stopped the work is the one to report
            self.close()
        except RecordingError:
            pass
