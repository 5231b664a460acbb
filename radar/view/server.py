"""The view's web server: aiohttp (HTTP + WebSocket) on its own asyncio loop.

Routes: ``/`` the page, ``/static/*`` its script and style, ``/static/plotly.min.js`` the
plotly.js bundle shipped inside the ``plotly`` Python package (nothing is fetched from the
internet), ``/ws`` the live feed, ``/api/state`` counters as JSON (for scripts and tests).

Flow control per browser: at most one message in flight. The server sends the newest frame
(or, when no new frame came, a health update every :data:`HEALTH_PERIOD_S`) and waits for the
page's ``{"ack": ...}``, which the page sends when it starts drawing that message (so the next
one is prepared while it draws; a message that arrives while one is drawn replaces any other
waiting one). A slow or stalled browser therefore only ever skips frames (newest wins);
nothing queues up on the host or in the page, and other browsers are not held back. A
browser that reconnects is simply a new client.
"""

from __future__ import annotations

import asyncio
import contextlib
import importlib.resources
import json
import threading
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from aiohttp import WSMsgType, web

from radar.view.feed import Feed
from radar.view.health import LinkHealth
from radar.view.render import MessageCache

HEALTH_PERIOD_S = 0.5
"""Health-only update interval while no new frame arrives, s."""

STATIC_DIR = Path(__file__).with_name("static")


def plotly_js_path() -> Path:
    """plotly.min.js as shipped in the ``plotly`` package's package data."""
    path = Path(str(importlib.resources.files("plotly") / "package_data" / "plotly.min.js"))
    if not path.is_file():
        raise FileNotFoundError(f"{path}: plotly.js bundle missing from the plotly package")
    return path


@dataclass(eq=False)
class _Client:
    wake: asyncio.Event = field(default_factory=asyncio.Event)
    credit: asyncio.Event = field(default_factory=asyncio.Event)
    channel: int = 0
    sent_seq: int = -1
    sent_channel: int = -1
    draw_fps: float = 0.0
    acks: int = 0


class ViewServer:
    """Serves ``feed`` and ``health`` on ``host:port`` (port 0: any free port)."""

    def __init__(self, feed: Feed, health: LinkHealth, host: str = "127.0.0.1",
                 port: int = 0, title: str = "radar view") -> None:
        self.feed = feed
        self.health = health
        self.host = host
        self.port = port
        self.title = title
        self.cache = MessageCache()
        self._clients: set[_Client] = set()
        self._loop: asyncio.AbstractEventLoop | None = None
        self._runner: web.AppRunner | None = None
        self._thread: threading.Thread | None = None
        self._plotly = plotly_js_path()

    # ---- app ------------------------------------------------------------------------------
    def _app(self) -> web.Application:
        app = web.Application()
        app.add_routes([web.get("/", self._index), web.get("/ws", self._ws),
                        web.get("/api/state", self._state),
                        web.get("/static/plotly.min.js", self._plotly_js),
                        web.get("/favicon.ico", self._no_icon),
                        web.static("/static", STATIC_DIR)])
        return app

    async def _index(self, request: web.Request) -> web.StreamResponse:
        return web.FileResponse(STATIC_DIR / "index.html",
                                headers={"Cache-Control": "no-cache"})

    async def _no_icon(self, request: web.Request) -> web.Response:
        return web.Response(status=204)  # browsers ask for one; a 404 would log an error

    async def _plotly_js(self, request: web.Request) -> web.StreamResponse:
        return web.FileResponse(self._plotly, headers={"Cache-Control": "max-age=3600"})

    async def _state(self, request: web.Request) -> web.Response:
        return web.json_response(self.state())

    def state(self) -> dict[str, Any]:
        latest = self.feed.latest()
        return {"health": self.health.snapshot(), "seq": latest.seq if latest else None,
                "clients": [{"channel": c.channel, "acks": c.acks, "draw_fps": c.draw_fps}
                            for c in list(self._clients)]}

    async def _ws(self, request: web.Request) -> web.StreamResponse:
        ws = web.WebSocketResponse(heartbeat=10.0, max_msg_size=1 << 16)
        await ws.prepare(request)
        client = _Client()
        client.credit.set()
        client.wake.set()
        self._clients.add(client)
        writer = asyncio.create_task(self._writer(ws, client))
        try:
            async for msg in ws:
                if msg.type == WSMsgType.TEXT:
                    self._on_message(client, msg.data)
        finally:
            self._clients.discard(client)
            writer.cancel()
            with contextlib.suppress(asyncio.CancelledError, ConnectionError):
                await writer
        return ws

    def _on_message(self, client: _Client, text: str) -> None:
        """``{"ack": seq, "draw_fps": f}`` or ``{"channel": n}``; anything else is ignored."""
        try:
            msg = json.loads(text)
        except ValueError:
            return
        if not isinstance(msg, dict):
            return
        if "ack" in msg:
            client.acks += 1
            if isinstance(msg.get("draw_fps"), int | float):
                client.draw_fps = float(msg["draw_fps"])
            client.credit.set()
        if isinstance(msg.get("channel"), int):
            client.channel = msg["channel"]
            client.wake.set()

    async def _writer(self, ws: web.WebSocketResponse, client: _Client) -> None:
        loop = asyncio.get_running_loop()
        while not ws.closed:
            await client.credit.wait()
            self.feed.want()
            with contextlib.suppress(TimeoutError):
                await asyncio.wait_for(client.wake.wait(), HEALTH_PERIOD_S)
            client.wake.clear()
            frame = self.feed.latest()
            health = self.health.snapshot()
            if frame is not None and (frame.seq != client.sent_seq
                                      or client.channel != client.sent_channel):
                channel = client.channel
                text = await loop.run_in_executor(None, self.cache.get, frame, channel, health)
                client.sent_seq, client.sent_channel = frame.seq, channel
            else:
                text = json.dumps({"type": "health", "health": health})
            client.credit.clear()
            try:
                await ws.send_str(text)
            except (ConnectionError, RuntimeError):
                return

    def _wake_all(self) -> None:
        for c in self._clients:
            c.wake.set()

    # ---- running --------------------------------------------------------------------------
    async def start(self) -> None:
        """Bind and serve on the running loop; :attr:`port` is the bound port."""
        self._loop = asyncio.get_running_loop()
        self.feed.demand_driven = True
        self.feed.on_publish = lambda: self._loop.call_soon_threadsafe(  # type: ignore[union-attr]
            self._wake_all)
        self._runner = web.AppRunner(self._app(), access_log=None, handle_signals=False)
        await self._runner.setup()
        site = web.TCPSite(self._runner, self.host, self.port)
        await site.start()
        server = site._server  # noqa: SLF001 - the only way to read an ephemeral port
        if server is not None and server.sockets:
            self.port = int(server.sockets[0].getsockname()[1])

    async def close(self) -> None:
        self.feed.on_publish = None
        self.feed.demand_driven = False
        if self._runner is not None:
            await self._runner.cleanup()

    def start_in_thread(self) -> int:
        """Serve from a daemon thread; returns the bound port."""
        ready = threading.Event()
        errors: list[BaseException] = []

        def run() -> None:
            loop = asyncio.new_event_loop()
            self._loop = loop
            try:
                loop.run_until_complete(self.start())
            except BaseException as exc:  # noqa: BLE001 - reported to the caller
                errors.append(exc)
                ready.set()
                return
            ready.set()
            loop.run_forever()
            loop.run_until_complete(self.close())
            loop.close()

        self._thread = threading.Thread(target=run, name="radar-view-http", daemon=True)
        self._thread.start()
        ready.wait(30)
        if errors:
            raise errors[0]
        return self.port

    def stop(self) -> None:
        """Stop a server started with :meth:`start_in_thread`."""
        if self._loop is not None and self._thread is not None:
            self._loop.call_soon_threadsafe(self._loop.stop)
            self._thread.join(10)
