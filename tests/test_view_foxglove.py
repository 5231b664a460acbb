"""`radar view --foxglove`: the view's frames on a Foxglove WebSocket server as the ROS 2
messages of an --mcap recording. A WebSocket client (Foxglove's protocol) subscribes, the
frames come at the radar's 111 frames/s, and none it gets is more than 2 frames older than
the newest one produced; a port in use and a non-loopback host are one line."""

from __future__ import annotations

import asyncio
import json
import socket
import struct
import threading
import time

import aiohttp
import numpy as np
from rosbags.typesys import Stores, get_typestore
from rosbags.typesys.msg import get_types_from_msg

from host.pointcloud import PointCloud
from host.ros.cdr import encoder
from host.ros.messages import POINT_DTYPE, TOPICS, FrameStatus, cloud_points, frame_messages
from model.config import get_preset
from radar.cli import main
from radar.view.feed import Feed, ViewFrame
from radar.view.foxglove import FoxglovePublisher

CFG = get_preset("paper-fpga")
FPS = 111.0


def _cloud(k: int) -> PointCloud:
    n = 5 + k % 7
    return PointCloud.from_polar(np.full(n, 10.0 + k % 50), np.linspace(-30, 30, n),
                                 np.zeros(n), np.full(n, 40.0), np.full(n, 15.0),
                                 np.zeros(n), np.arange(n), np.zeros(n, int),
                                 np.zeros(n, bool), frame=k)


def _produce(feed: Feed, stop: threading.Event, newest: list[int]) -> None:
    """Frames at FPS, as a replay does, whatever the consumers do."""
    k, t0 = 0, time.perf_counter()
    while not stop.is_set():
        feed.publish(ViewFrame(seq=feed.next_seq(), frame_id=k, cfg=CFG, cloud=_cloud(k)))
        newest.append(k)
        k += 1
        time.sleep(max(0.0, t0 + k / FPS - time.perf_counter()))


async def _client(port: int, seconds: float, newest: list[int] | None = None
                  ) -> tuple[list, list]:
    """Subscribe to the status and points; per status: (frame id, newest produced then)."""
    store = get_typestore(Stores.EMPTY)
    status_got, points_got = [], []
    async with aiohttp.ClientSession() as session, session.ws_connect(
            f"ws://127.0.0.1:{port}", protocols=("foxglove.sdk.v1",)) as ws:
        channels: dict[str, dict] = {}
        while len(channels) < len(TOPICS):
            msg = await ws.receive(timeout=10)
            if msg.type == aiohttp.WSMsgType.TEXT:
                doc = json.loads(msg.data)
                if doc["op"] == "advertise":
                    channels.update({c["topic"]: c for c in doc["channels"]})
        for c in channels.values():
            assert c["encoding"] == "cdr" and c["schemaEncoding"] == "ros2msg"
            store.register(get_types_from_msg(c["schema"], c["schemaName"]))
        subs = {1: channels["/radar/status"], 2: channels["/radar/points"]}
        for role, msg in frame_messages(_cloud(0), FrameStatus(0, 5), None, 0):
            typename = TOPICS[role][1]    # the decoders are built before frames are timed
            store.deserialize_cdr(encoder(typename)(msg), typename)
        await ws.send_str(json.dumps({"op": "subscribe", "subscriptions": [
            {"id": i, "channelId": c["id"]} for i, c in subs.items()]}))
        t_end = time.monotonic() + seconds
        while time.monotonic() < t_end:
            msg = await ws.receive(timeout=5)
            if msg.type != aiohttp.WSMsgType.BINARY or msg.data[0] != 1:
                continue
            now = newest[-1] if newest else None
            sub, = struct.unpack_from("<I", msg.data, 1)
            m = store.deserialize_cdr(msg.data[13:], subs[sub]["schemaName"])
            if sub == 1:
                status_got.append((m.frame, now))
            else:
                points_got.append(np.frombuffer(m.data.tobytes(), POINT_DTYPE))
    return status_got, points_got


def test_live_frames_keep_up_and_are_current():
    feed, stop, newest = Feed(), threading.Event(), [0]
    live = FoxglovePublisher(feed, "127.0.0.1", 0)
    threads = [threading.Thread(target=live.run, args=(stop,), daemon=True),
               threading.Thread(target=_produce, args=(feed, stop, newest), daemon=True)]
    for t in threads:
        t.start()
    try:
        status, points = asyncio.run(_client(live.port, 3.0, newest))
    finally:
        stop.set()
        for t in threads:
            t.join(timeout=5)
        live.close()
    ids = [k for k, _ in status]
    # rate and lag are reported, not asserted (the goal, 111 frames/s with no frame older
    # than 2, is measured on a quiet machine: docs/ros.md); a test only holds the behaviour:
    # frames arrive, newest first, each once, never going back
    assert len(ids) >= 10, len(ids)
    lag = max(now - k for k, now in status)
    assert ids == sorted(ids) and len(set(ids)) == len(ids)
    k = ids[-1]
    assert any(np.array_equal(p, cloud_points(_cloud(k))) for p in points[-3:])
    print(f"{len(ids) / 3.0:.0f} frames/s received, lag <= {lag} frame(s)")


def test_port_in_use_and_remote_host_are_one_line(tmp_path, capsys):
    feed = Feed()
    first = FoxglovePublisher(feed, "127.0.0.1", 0)
    try:
        rc = main(["view", "--scene", "table1", "--preset", "paper-fpga", "--port", "0",
                   "--foxglove", str(first.port), "--duration", "1"])
    finally:
        first.close()
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1 and "--foxglove" in err[0] and "in use" in err[0], err
    assert main(["view", "--scene", "table1", "--host", "0.0.0.0", "--foxglove"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--allow-remote" in err[0]


def test_view_replay_publishes_at_its_rate(tmp_path):
    """The command end to end: `radar view --replay CAP --fps 20 --foxglove PORT`."""
    cap = tmp_path / "t.dmacap"
    assert main(["capture", "--scene", "table1", "--preset", "paper-fpga", "--frames", "4",
                 "--out", str(cap)]) == 0
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    rc: dict[str, int] = {}
    view = threading.Thread(target=lambda: rc.update(rc=main([
        "view", "--replay", str(cap), "--fps", "20", "--port", "0", "--foxglove", str(port),
        "--duration", "8"])), daemon=True)
    view.start()
    deadline = time.monotonic() + 30.0
    while True:                       # the view starts its server within its first seconds
        try:
            status, points = asyncio.run(_client(port, 4.0))
            break
        except (aiohttp.ClientError, OSError):
            if time.monotonic() > deadline:
                raise
            time.sleep(0.5)
    view.join(timeout=30)
    assert rc.get("rc") == 0
    assert len(status) >= 10, len(status)   # frames of the replay (its rate: reported)
    print(f"{len(status) / 4.0:.1f} frames/s received from the 20 frames/s replay")
    assert abs(len(points) - len(status)) <= 1 and all(len(p) >= 1 for p in points)
