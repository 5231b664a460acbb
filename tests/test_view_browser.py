"""radar view in a real browser (headless Debian chromium driven by Playwright).

A `radar view` process listens for UDP on loopback; this test sends it the DMA packets of a
short Table I capture (paper-fpga) over UDP, as the board would, and checks on the page that
the plots are drawn with data, the counters move, an injected loss and malformed datagrams
show up, a page reload reconnects, a sender pause and restart is survived, and the page loads
nothing from outside the server; and the same for the on-chip detector's record stream (records
and points drawn, the sticky TRUNCATED flag shown). About 30 s + 20 s on a quiet machine (2 min
at load 15); the waits allow three times that, since the regression runs beside Verilator
builds on two cores (they guard liveness, not speed).
"""

from __future__ import annotations

import threading
import time
from pathlib import Path

import numpy as np
import pytest

from host.capture import read_capture
from host.udp import Impairments, UdpSender
from radar.cli import main as radar_main
from radar.view.browser import chromium_missing_reason, launch, start_view

_REASON = chromium_missing_reason()
pytestmark = pytest.mark.skipif(_REASON is not None, reason=_REASON or "")


class Sender(threading.Thread):
    """Sends the capture's packets over UDP, pass after pass (frame ids start again each
    pass), paced to ``rate_bps`` (the default: about 10 cube frames/s). ``mode``: "clean",
    "loss" (one pass with 25 % loss and two malformed datagrams, then clean again), "pause"
    (nothing)."""

    def __init__(self, packets: list[bytes], port: int, rate_bps: float = 25e6) -> None:
        super().__init__(daemon=True)
        self.packets = packets
        self.port = port
        self.rate_bps = rate_bps
        self.mode = "clean"
        self.passes = 0
        self.stop = threading.Event()

    def run(self) -> None:
        while not self.stop.is_set():
            mode = self.mode
            if mode == "pause":
                time.sleep(0.05)
                continue
            imp = Impairments(loss=0.25, seed=self.passes) if mode == "loss" else None
            with UdpSender("127.0.0.1", self.port, self.rate_bps, imp) as tx:
                if mode == "loss":
                    tx.sock.sendto(b"not a DMA packet", tx.addr)
                    tx.sock.sendto(bytes(48), tx.addr)
                    self.mode = "clean"
                tx.send(self.packets)
            self.passes += 1


@pytest.fixture(scope="module")
def capture(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("view") / "table1.dmacap"
    assert radar_main(["capture", "--scene", "table1", "--preset", "paper-fpga",
                       "--frames", "3", "--out", str(path)]) == 0
    return path


def _wait(page, condition: str, timeout_ms: int, errors: list[str]) -> None:
    """Wait for a JS condition, polled in 1 s slices: fails at once when the page logged an
    error (a broken page fails in seconds, not at the timeout), and on timeout says what the
    page counted."""
    from playwright.sync_api import TimeoutError as PwTimeout

    deadline = time.monotonic() + timeout_ms / 1e3
    while True:
        assert not errors, f"the page logged errors while waiting for {condition!r}: {errors[:3]}"
        try:
            page.wait_for_function(condition, timeout=1_000)
            return
        except PwTimeout:
            if time.monotonic() > deadline:
                break
    state = page.evaluate("JSON.stringify({frames: window.radarView.frames, "
                          "draws: window.radarView.draws, health: window.radarView.lastHealth})")
    pytest.fail(f"page never met {condition!r} in {timeout_ms / 1e3:.0f} s; page state "
                f"{state[:600]}")


def _counter(page, key: str) -> str:
    return page.locator(f"#h-{key}").inner_text()


def test_view_in_browser(capture, tmp_path):
    from playwright.sync_api import sync_playwright

    _, it = read_capture(capture)
    packets = list(it)
    view = start_view(["--udp-port", "0"])  # preset and PACKET_WORDS learnt from the headers
    sender = Sender(packets, view.udp_port)
    requests: list[str] = []
    errors: list[str] = []
    try:
        sender.start()
        with sync_playwright() as pw:
            ctx = launch(pw, tmp_path / "profile")
            page = ctx.new_page()
            page.on("request", lambda r: requests.append(r.url))
            page.on("pageerror", lambda e: errors.append(f"page error: {e}"))
            page.on("console", lambda m: errors.append(f"console: {m.text}")
                    if m.type == "error" else None)
            page.goto(view.url)
            _wait(page, "window.radarView.frames >= 3", 90_000, errors)

            # plots drawn with data: 64 x 128 maps (canvas cells with a spread of colours
            # under plotly's axes and colour bar), a point cloud, a 64-bin profile
            drawn = page.evaluate("""() => {
                const heat = id => {
                    const h = document.getElementById(id).heat;
                    const px = h.canvas.getContext('2d')
                        .getImageData(0, 0, h.canvas.width, h.canvas.height).data;
                    const colours = new Set();
                    for (let i = 0; i < px.length; i += 4) {
                        colours.add(px[i] << 16 | px[i + 1] << 8 | px[i + 2]);
                    }
                    const box = h.canvas.getBoundingClientRect();
                    return {cells: [h.canvas.height, h.canvas.width], colours: colours.size,
                            shown: !h.canvas.hidden && box.width > 100 && box.height > 100,
                            colourbar: document.getElementById(id)
                                .querySelectorAll('.colorbar').length};
                };
                const d = id => document.getElementById(id).data;
                return {rd: heat('plot-rd'), nci: heat('plot-nci'),
                        points: d('plot-cloud')[0].x.length,
                        profile: d('plot-profile')[0].y.length};
            }""")
            for m in (drawn["rd"], drawn["nci"]):
                assert m["cells"] == [64, 128] and m["shown"] and m["colourbar"] == 1, m
                assert m["colours"] > 20, m
            assert drawn["points"] > 0 and drawn["profile"] == 64
            assert page.locator("#link").inner_text() == "live"

            # counters move
            before = int(_counter(page, "frames_complete"))
            _wait(page, f"+document.getElementById('h-frames_complete').textContent > {before + 3}",
                  45_000, errors)
            assert _counter(page, "packets_lost") == "0"
            assert _counter(page, "malformed") == "0"

            # injected loss and malformed datagrams show up
            sender.mode = "loss"
            # (a frame is called damaged when it ends, after the loss itself was counted)
            _wait(page, "+document.getElementById('h-packets_lost').textContent > 0 && "
                  "+document.getElementById('h-malformed').textContent >= 2 && "
                  "+document.getElementById('h-frames_damaged').textContent > 0", 45_000, errors)
            assert "alarm" in (page.locator("#h-packets_lost").get_attribute("class") or "")

            # the browser reconnects after a reload and keeps drawing
            page.reload()
            _wait(page, "window.radarView.frames >= 2", 45_000, errors)

            # the sender stops (link idle) and starts again: the view follows
            restarts = int(_counter(page, "stream_restarts"))
            sender.mode = "pause"
            _wait(page, f"+document.getElementById('h-stream_restarts').textContent > {restarts}",
                  30_000, errors)
            frames = page.evaluate("window.radarView.frames")
            sender.mode = "clean"
            _wait(page, f"window.radarView.frames > {frames + 2}", 45_000, errors)
            page.screenshot(path=str(tmp_path / "radar_view.png"))
            ctx.close()
        assert view.proc.poll() is None, "the view process survived everything"
    finally:
        sender.stop.set()
        view.stop()
    base = view.url.rstrip("/").removeprefix("http://")
    outside = [u for u in requests if base not in u]
    assert not outside, f"page loaded from outside the server: {outside[:3]}"
    assert not errors, f"the page logged errors: {errors[:3]}"


def test_record_frames_in_browser(tmp_path):
    """A detection-record stream's frame (points only, no cube, no map) renders: the
    detections in range-Doppler, the point cloud with a GNN box, SNR over range; and a cube
    frame after it brings the heat maps back."""
    from playwright.sync_api import sync_playwright

    from host.pointcloud import PointCloud
    from model.config import get_preset
    from radar.view.feed import Feed, ViewFrame
    from radar.view.health import LinkHealth
    from radar.view.server import ViewServer

    cfg = get_preset("paper-fpga")
    n = 5
    cloud = PointCloud.from_polar(
        np.linspace(10, 80, n), np.linspace(-20, 20, n), np.linspace(-15, 15, n),
        np.full(n, 50.0), np.linspace(12, 30, n), np.zeros(n), np.arange(n) + 5,
        np.arange(n) + 60, np.zeros(n, bool))
    obj = {"class": "car", "score": 0.9, "x_m": 30.0, "y_m": 2.0, "length_m": 4.5,
           "width_m": 1.8, "heading_deg": 10.0}
    feed, health = Feed(), LinkHealth()
    server = ViewServer(feed, health)
    port = server.start_in_thread()
    errors: list[str] = []
    stop = threading.Event()

    def publish(cube: bool) -> None:
        rng = np.random.default_rng(0)
        shape = (cfg.n_virtual, cfg.n_range, cfg.n_doppler)
        c = (rng.standard_normal(shape) + 1j * rng.standard_normal(shape)).astype(
            np.complex64) if cube else None
        while not stop.is_set():
            feed.publish(ViewFrame(seq=feed.next_seq(), frame_id=feed.next_seq(), cfg=cfg,
                                   cloud=cloud, objects=[obj], cube=c,
                                   nci=None if c is None else np.sum(np.abs(c) ** 2, axis=0),
                                   source="records"))
            stop.wait(0.1)

    producer = threading.Thread(target=publish, args=(False,), daemon=True)
    try:
        producer.start()
        with sync_playwright() as pw:
            ctx = launch(pw, tmp_path / "profile")
            page = ctx.new_page()
            page.on("pageerror", lambda e: errors.append(f"page error: {e}"))
            page.on("console", lambda m: errors.append(f"console: {m.text}")
                    if m.type == "error" else None)
            page.goto(f"http://127.0.0.1:{port}/")
            _wait(page, "window.radarView.frames >= 3", 60_000, errors)
            drawn = page.evaluate("""() => {
                const el = id => document.getElementById(id);
                const heat = el('plot-nci').heat;
                return {detections: el('plot-nci').data[0].y.length,
                        cloud: el('plot-cloud').data.map(t => t.x.length),
                        snr: el('plot-profile').data[0].y.length,
                        note: el('plot-rd').textContent.includes('no per-channel map'),
                        canvas: heat ? !heat.canvas.hidden : false};
            }""")
            assert drawn == {"detections": n, "cloud": [n, 5, 1], "snr": n, "note": True,
                             "canvas": False}, drawn
            # the stream turns into a cube stream: the heat maps come back
            stop.set()
            producer.join(5)
            stop.clear()
            producer = threading.Thread(target=publish, args=(True,), daemon=True)
            producer.start()
            frames = page.evaluate("window.radarView.frames")
            _wait(page, f"window.radarView.frames > {frames + 2}", 60_000, errors)
            shown = page.evaluate("""() => ['plot-rd', 'plot-nci'].map(id => {
                const h = document.getElementById(id).heat;
                return [h.canvas.width, h.canvas.height, !h.canvas.hidden];
            })""")
            assert shown == [[128, 64, True], [128, 64, True]], shown
            ctx.close()
    finally:
        stop.set()
        server.stop()
    assert not errors, f"the page logged errors: {errors[:3]}"


@pytest.fixture(scope="module")
def record_capture(tmp_path_factory) -> Path:
    """The on-chip detector's records of 2 Table I frames, MAX_DETECTIONS 8 (fewer than the
    CFAR passes: every frame's trailer says truncated)."""
    path = tmp_path_factory.mktemp("view") / "table1_records.dmacap"
    assert radar_main(["capture", "--scene", "table1", "--preset", "paper-fpga",
                       "--detect", "fpga", "--max-detections", "8", "--frames", "2",
                       "--out", str(path)]) == 0
    return path


def test_record_stream_in_browser(record_capture, tmp_path):
    """A detection-record stream over UDP (kind and preset learnt from the headers, the
    sender's --max-detections given): the records and points render, the counters move,
    the record rows of the health panel show the on-chip detections and the sticky
    TRUNCATED flag, malformed datagrams are counted."""
    from playwright.sync_api import sync_playwright

    _, it = read_capture(record_capture)
    packets = list(it)
    view = start_view(["--udp-port", "0", "--max-detections", "8"])
    # about 20 frames/s: faster would only fill the socket buffer (the kernel drops, unseen)
    sender = Sender(packets, view.udp_port, rate_bps=20 * 8 * len(packets[0]))
    errors: list[str] = []
    try:
        sender.start()
        with sync_playwright() as pw:
            ctx = launch(pw, tmp_path / "profile")
            page = ctx.new_page()
            page.on("pageerror", lambda e: errors.append(f"page error: {e}"))
            page.on("console", lambda m: errors.append(f"console: {m.text}")
                    if m.type == "error" else None)
            page.goto(view.url)
            _wait(page, "window.radarView.frames >= 3", 90_000, errors)
            drawn = page.evaluate("""() => {
                const el = id => document.getElementById(id);
                const rows = [...document.querySelectorAll('tr.rec')];
                return {records: el('plot-nci').data[0].x.length,
                        ringed: el('plot-nci').data[1].x.length,
                        cloud: el('plot-cloud').data[0].x.length,
                        profile: el('plot-profile').data[0].y.length,
                        note: el('plot-rd').textContent.includes('records stream: no cube'),
                        rowsShown: rows.length > 0 && rows.every(r => !r.hidden)};
            }""")
            assert drawn["records"] == 8 and drawn["profile"] == 8, drawn
            assert drawn["cloud"] > 0 and drawn["ringed"] == drawn["cloud"], drawn
            assert drawn["note"] and drawn["rowsShown"], drawn
            assert _counter(page, "stream_kind") == "records"
            assert _counter(page, "records") == "8" and _counter(page, "max_detections") == "8"
            assert int(_counter(page, "cfar_detections")) > 8
            assert _counter(page, "truncated") == "SET"
            assert "alarm" in (page.locator("#h-truncated").get_attribute("class") or "")
            assert page.locator("#h-truncated").is_visible()
            before = int(_counter(page, "frames_complete"))
            _wait(page, f"+document.getElementById('h-frames_complete').textContent > {before + 3}",
                  45_000, errors)
            sender.mode = "loss"  # 25 % loss and two malformed datagrams
            _wait(page, "+document.getElementById('h-malformed').textContent >= 2", 45_000,
                  errors)
            page.screenshot(path=str(tmp_path / "radar_view_records.png"))
            ctx.close()
        assert view.proc.poll() is None, "the view process survived everything"
    finally:
        sender.stop.set()
        view.stop()
    assert not errors, f"the page logged errors: {errors[:3]}"
