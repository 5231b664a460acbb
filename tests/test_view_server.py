"""radar view's web server without a browser: assets, one message in flight per client,
newest frame wins, a stalled client does not hold back another, reconnects, channel choice,
and the command line's refusal of a non-loopback bind."""

from __future__ import annotations

import asyncio
import json

import aiohttp
import numpy as np
import pytest

from host.pointcloud import PointCloud
from model.config import get_preset
from radar.cli import main as radar_main
from radar.commands.view import is_loopback
from radar.view.feed import Feed, ViewFrame
from radar.view.health import LinkHealth
from radar.view.server import ViewServer

CFG = get_preset("paper-fpga")


def _frame(feed: Feed, frame_id: int) -> ViewFrame:
    rng = np.random.default_rng(frame_id)
    shape = (CFG.n_virtual, CFG.n_range, CFG.n_doppler)
    cube = (rng.standard_normal(shape) + 1j * rng.standard_normal(shape)).astype(np.complex64)
    return ViewFrame(seq=feed.next_seq(), frame_id=frame_id, cfg=CFG,
                     cloud=PointCloud.empty(), cube=cube,
                     nci=np.sum(np.abs(cube) ** 2, axis=0), source="test")


async def _recv(ws: aiohttp.ClientWebSocketResponse, timeout: float = 5.0) -> dict:
    msg = await ws.receive(timeout=timeout)
    assert msg.type == aiohttp.WSMsgType.TEXT, msg
    return json.loads(msg.data)


async def _next_frame(ws, timeout: float = 5.0) -> dict:
    """Skip health messages (acking them) until a frame arrives."""
    while True:
        m = await _recv(ws, timeout)
        if m["type"] == "frame":
            return m
        await ws.send_str(json.dumps({"ack": None}))


def test_server_flow_control_and_assets():
    async def run() -> None:
        feed, health = Feed(), LinkHealth()
        server = ViewServer(feed, health, "127.0.0.1", 0)
        await server.start()
        base = f"http://127.0.0.1:{server.port}"
        try:
            async with aiohttp.ClientSession() as http:
                for path, kind in (("/", "text/html"), ("/static/view.js", "javascript"),
                                   ("/static/plotly.min.js", "javascript")):
                    async with http.get(base + path) as r:
                        assert r.status == 200 and kind in r.headers["Content-Type"], path
                        await r.read()
                async with http.get(base + "/static/../server.py") as r:
                    assert r.status in (403, 404)

                feed.publish(_frame(feed, 0))
                fast = await http.ws_connect(base + "/ws")
                stalled = await http.ws_connect(base + "/ws")
                m = await _next_frame(fast)
                assert m["frame_id"] == 0 and m["rd"]["rows"] == CFG.n_range
                assert (await _next_frame(stalled))["frame_id"] == 0
                # `stalled` never acks: it gets nothing more; `fast` is not held back
                for k in range(1, 6):
                    feed.publish(_frame(feed, k))
                    await asyncio.sleep(0.02)
                await fast.send_str(json.dumps({"ack": m["seq"], "draw_fps": 12.5}))
                m = await _next_frame(fast)
                assert m["frame_id"] == 5, "the newest frame, the ones between are dropped"
                with pytest.raises(asyncio.TimeoutError):
                    await stalled.receive(timeout=1.0)
                # channel choice is clamped to the array and answered with a fresh render
                await fast.send_str(json.dumps({"channel": 3, "ack": m["seq"]}))
                m = await _next_frame(fast)
                assert m["channel"] == 3 and m["frame_id"] == 5
                # a health update arrives while no new frame comes
                await fast.send_str(json.dumps({"ack": m["seq"]}))
                h = await _recv(fast, 2.0)
                assert h["type"] == "health" and "packets_lost" in h["health"]
                # garbage from a client is ignored
                await fast.send_str("{not json")
                await fast.send_str(json.dumps([1, 2]))
                await stalled.close()
                # reconnect: a new client gets the newest frame at once
                again = await http.ws_connect(base + "/ws")
                assert (await _next_frame(again))["frame_id"] == 5
                async with http.get(base + "/api/state") as r:
                    state = await r.json()
                assert state["seq"] == 6 and len(state["clients"]) == 2
                assert 12.5 in [c["draw_fps"] for c in state["clients"]]
                await again.close()
                await fast.close()
        finally:
            await server.close()

    asyncio.run(run())


def test_loopback_only_without_flag(capsys):
    assert is_loopback("127.0.0.1") and is_loopback("::1") and is_loopback("localhost")
    assert not is_loopback("0.0.0.0") and not is_loopback("192.168.1.4")
    assert radar_main(["view", "--host", "0.0.0.0", "--scene", "table1"]) == 2
    assert "--allow-remote" in capsys.readouterr().err


def test_bad_replay_file_is_one_line_error(tmp_path, capsys):
    bad = tmp_path / "x.dmacap"
    bad.write_bytes(b"nope")
    assert radar_main(["view", "--replay", str(bad), "--port", "0"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("radar view: error:") and err.count("\n") == 1
