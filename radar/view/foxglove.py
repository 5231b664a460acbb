"""``radar view --foxglove``: the view's frames as ROS 2 messages (the topics and CDR bytes of
an ``--mcap`` recording, ``host.ros``) on a Foxglove WebSocket server (``foxglove-sdk``), so
Foxglove shows the radar live beside a robot's other sensors.

:class:`FoxglovePublisher` reads the newest frame of the view's :class:`radar.view.feed.Feed`
and logs it on its own thread; like a browser it asks the producer for the next frame
(:meth:`Feed.want`) once it has sent one, so it sustains the source's rate and never queues
old frames (a frame that arrives while one is sent replaces the waiting one). Messages are
stamped with the wall clock at sending (live data); ``/tf_static`` goes with every frame, so
a client that connects late still gets the mount. The status carries the frame id and its
points (the page's link health has the rest)."""

from __future__ import annotations

import threading
import time
from typing import Any

import foxglove
from foxglove import Channel, Schema

from host.ros.cdr import encoder
from host.ros.messages import TOPICS, FrameStatus, Mount, frame_messages, tf_message
from host.ros.msgdefs import schema_text
from radar.view.feed import Feed, ViewFrame

POLL_S = 0.002
"""How often the publisher looks for a new frame, s (well under a frame at 111 frames/s)."""


class FoxglovePublisher:
    """Foxglove WebSocket server on ``host:port`` (0: any free port, :attr:`port`) publishing
    ``feed``'s frames; ``gnn``: the view runs the GNN (``/radar/objects`` is published).
    OSError when the port cannot be bound (in use)."""

    def __init__(self, feed: Feed, host: str, port: int, gnn: bool = False,
                 mount: Mount | None = None) -> None:
        self.feed, self.gnn, self.mount = feed, gnn, mount or Mount()
        self.sent = 0
        self._context = foxglove.Context()
        self._channels = {role: Channel(topic, schema=Schema(
            name=typename, encoding="ros2msg", data=schema_text(typename).encode()),
            message_encoding="cdr", context=self._context)
            for role, (topic, typename) in TOPICS.items()}
        try:
            self._server = foxglove.start_server(name="radar-array-processor", host=host,
                                                 port=port, context=self._context)
        except RuntimeError as exc:      # FoxgloveError: Failed to bind port: ...
            raise OSError(str(exc).removeprefix("FoxgloveError: ")) from None
        self.port: int = self._server.port

    def publish(self, frame: ViewFrame) -> None:
        """Log one frame's messages (and the mount), stamped now."""
        t = time.time_ns()
        msgs: list[tuple[str, dict[str, Any]]] = [("tf", tf_message(self.mount, t))]
        msgs += frame_messages(frame.cloud, FrameStatus(frame.frame_id, len(frame.cloud)),
                               frame.objects if self.gnn else None, t)
        for role, msg in msgs:
            self._channels[role].log(encoder(TOPICS[role][1])(msg), log_time=t)
        self.sent += 1

    def run(self, stop: threading.Event) -> None:
        """Publish each new frame of the feed until ``stop`` is set."""
        last_seq = -1
        self.feed.want()
        while not stop.is_set():
            frame = self.feed.latest()
            if frame is None or frame.seq == last_seq:
                time.sleep(POLL_S)
                continue
            last_seq = frame.seq
            self.publish(frame)
            self.feed.want()

    def close(self) -> None:
        self._server.stop()
