"""radar view without a browser: link counters, sender restarts, malformed datagrams,
drop-to-newest processing, heat-map reduction and the page's assets."""

from __future__ import annotations

import base64
import re
import threading

import numpy as np
import pytest

from host.capture import frame_packets
from host.cube import frame_cube
from host.pointcloud import PointCloud
from host.receiver import Receiver
from host.stream import StreamDecoder
from model.axis_packetizer import cube_to_payload, packetize, words_to_bytes
from model.config import get_preset
from model.profile import profile_from_toml
from model.reference import cube_to_dma_order, range_doppler_power
from model.scene import Scatterers
from model.simulate import simulate_frame
from radar.view.feed import Feed, ViewFrame
from radar.view.health import LinkHealth, missing_packets
from radar.view.ingest import packet_ingest
from radar.view.processor import Job, Processor, channel_power_sum
from radar.view.render import MAX_AXIS, box_outline, frame_message, heatmap, pool_max
from radar.view.server import STATIC_DIR, plotly_js_path
from radar.view.sources import replay_loop
from tests.test_cli_radar_option import THREE_TX

CFG = get_preset("paper-fpga")
PACKET_WORDS = 1023


def _cube(seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    shape = (CFG.n_virtual, CFG.n_range, CFG.n_doppler)
    return (rng.integers(-200, 200, shape) + 1j * rng.integers(-200, 200, shape)).astype(
        np.complex64)


@pytest.fixture(scope="module")
def frames() -> list[list[bytes]]:
    """Packets of 4 frames (ids 0..3) of random cubes."""
    return [frame_packets(_cube(k), CFG, PACKET_WORDS, k) for k in range(4)]


class _Recorder(Processor):
    """Processor that records what it is handed instead of processing it."""

    def __init__(self, health: LinkHealth) -> None:
        super().__init__(CFG, Feed(), health)
        self.got: list[int] = []

    def submit(self, frame_id: int, frame: object, cfg: object = None) -> None:
        self.got.append(frame_id)


def _ingest() -> tuple[Receiver, LinkHealth, _Recorder]:
    health = LinkHealth()
    rec = _Recorder(health)
    return packet_ingest(CFG, PACKET_WORDS, health, rec), health, rec


def test_clean_stream_counts_frames(frames):
    ingest, health, rec = _ingest()
    for f in frames:
        for p in f:
            ingest.push(p)
    ingest.idle()
    s = health.snapshot()
    assert rec.got == [0, 1, 2, 3]
    assert (s["frames_complete"], s["frames_damaged"], s["packets_lost"], s["malformed"]) == (
        4, 0, 0, 0)
    assert s["datagrams"] == sum(len(f) for f in frames)


def test_loss_and_whole_frame_loss_and_malformed(frames):
    ingest, health, rec = _ingest()
    n = len(frames[0])
    for p in frames[0]:
        ingest.push(p)
    for i, p in enumerate(frames[1]):
        if i != 2:  # one packet of frame 1 lost
            ingest.push(p)
    ingest.push(b"\x01\x02")  # shorter than a word
    ingest.push(bytes(64))  # whole words, no header magic
    # frame 2 lost entirely
    for p in frames[3]:
        ingest.push(p)
    ingest.idle()
    s = health.snapshot()
    assert s["frames_damaged"] == 1 and s["frames_complete"] == 2
    assert s["frames_lost"] == 1
    assert s["packets_lost"] == 1 + n
    assert s["malformed"] == 2
    assert s["problems"], "problems are reported for the page"
    assert rec.got == [0, 1, 3]  # damaged frames are still shown (zeros where missing)


def test_sender_restart_without_pause(frames):
    """Frame ids start again with no idle gap: a fresh decoder takes over after one frame's
    worth of late packets; the restarted frames decode."""
    ingest, health, rec = _ingest()
    for _ in range(3):
        for f in frames:
            for p in f:
                ingest.push(p)
    ingest.idle()
    s = health.snapshot()
    assert s["stream_restarts"] >= 2
    assert rec.got[-3:] == [1, 2, 3]
    assert s["frames_complete"] >= 10


@pytest.mark.parametrize("packet_words", [1023, 4093, 500])
def test_packet_words_learnt_from_the_header(packet_words):
    """No --packet-words: the stream's PACKET_WORDS comes from the first packet's header
    (``radar capture`` writes the most that fit a datagram, 4093 on paper-fpga); a sender that
    restarts with another PACKET_WORDS is learnt again."""
    health = LinkHealth()
    rec = _Recorder(health)
    ingest = packet_ingest(CFG, None, health, rec)
    for k in range(3):
        for p in frame_packets(_cube(k), CFG, packet_words, k):
            ingest.push(p)
    assert ingest.packet_words == packet_words
    ingest.idle()
    for k in range(2):
        for p in frame_packets(_cube(k), CFG, 1023, k):
            ingest.push(p)
    ingest.idle()
    s = health.snapshot()
    assert ingest.packet_words == 1023
    assert rec.got == [0, 1, 2, 0, 1]
    assert (s["frames_complete"], s["frames_damaged"], s["packets_lost"], s["malformed"],
            s["late_packets"]) == (5, 0, 0, 0, 0)


def test_preset_learnt_from_the_header():
    """A UDP stream without --preset: the view starts on ``full`` and learns paper-fpga
    (and its PACKET_WORDS) from the first packet; cubes reach the processor with that
    preset's shape and chain gain (divided out where the cube is decoded)."""
    from model.config import PRESETS
    from model.radar_pipeline import PipelineParams, chain_gain

    full = get_preset("full")
    health = LinkHealth()
    got: list[tuple[int, tuple[int, ...], float, str]] = []

    class Rec(Processor):
        def submit(self, frame_id, frame, cfg=None) -> None:
            got.append((frame_id, frame.cube().shape, frame.gain, cfg.name))  # decoded here

    ingest = packet_ingest(full, None, health, Rec(full, Feed(), health),
                           configs=list(PRESETS.values()))
    for k in range(2):
        for p in frame_packets(_cube(k), CFG, 4093, k):
            ingest.push(p)
    ingest.idle()
    gain = chain_gain(CFG, PipelineParams())
    assert got == [(k, CFG.cube_shape, pytest.approx(gain), "paper-fpga") for k in (0, 1)]
    s = health.snapshot()
    assert (s["frames_complete"], s["malformed"], s["packets_lost"]) == (2, 0, 0)


def test_reordered_frame_is_not_lost(frames):
    ingest, health, _ = _ingest()
    for k in (0, 2, 1, 3):  # whole frame 1 arrives after frame 2
        for p in frames[k]:
            ingest.push(p)
    ingest.idle()
    assert health.snapshot()["frames_lost"] == 0


def test_sticky_hardware_flags_stay_set(frames):
    """The packetizer's OVERFLOW flag in one frame's headers stays shown afterwards, also
    across a sender restart."""
    ingest, health, _ = _ingest()
    words = cube_to_payload(cube_to_dma_order(_cube(9), CFG))
    flagged = [words_to_bytes(p) for p in packetize(words, PACKET_WORDS, 0, overflow=True)]
    for p in flagged + frames[1]:
        ingest.push(p)
    ingest.restart()
    for p in frames[0]:
        ingest.push(p)
    s = health.snapshot()
    assert s["hw_overflow"] and not s["hw_framing"]
    assert any("OVERFLOW" in p for p in s["problems"])


def test_missing_packets_counts_per_packet(frames):
    dec = StreamDecoder(CFG, PACKET_WORDS)
    out = [f for i, p in enumerate(frames[0]) if i not in (0, 5) for f in dec.push_packet(p)]
    out += dec.flush()
    assert missing_packets(out[0], PACKET_WORDS) == 2


def test_replay_loop_with_loss_stops(frames):
    ingest, health, rec = _ingest()
    stop = threading.Event()
    replay_loop(frames, ingest, stop, fps=0, loop=False, loss=0.2, seed=1)
    s = health.snapshot()
    assert s["packets_lost"] > 0 and s["frames_damaged"] > 0
    assert s["frames_complete"] + s["frames_damaged"] + s["frames_lost"] == 4


def test_processor_drops_to_newest():
    health, feed = LinkHealth(), Feed()
    proc = Processor(CFG, feed, health)
    cubes = [_cube(k) / 64 for k in range(3)]
    for k, c in enumerate(cubes):
        proc.submit(k, c)
    stop = threading.Event()
    t = threading.Thread(target=proc.run, args=(stop,))
    t.start()
    for _ in range(200):
        if feed.latest() is not None:
            break
        threading.Event().wait(0.05)
    stop.set()
    t.join()
    latest = feed.latest()
    assert latest is not None and latest.frame_id == 2 and latest.seq == 1
    assert health.snapshot()["frames_not_shown"] == 2


def test_processing_follows_browser_demand():
    """With a server (demand_driven), a cube is processed only once a browser asks."""
    health, feed = LinkHealth(), Feed()
    feed.demand_driven = True
    proc = Processor(CFG, feed, health)
    stop = threading.Event()
    t = threading.Thread(target=proc.run, args=(stop,))
    t.start()
    try:
        proc.submit(0, _cube(0) / 64)
        threading.Event().wait(0.6)
        assert feed.latest() is None
        feed.want()
        for _ in range(200):
            if feed.latest() is not None:
                break
            threading.Event().wait(0.05)
        assert feed.latest() is not None and feed.latest().frame_id == 0
    finally:
        stop.set()
        t.join()


def test_bad_cube_is_reported_not_raised():
    health, feed = LinkHealth(), Feed()
    proc = Processor(CFG, feed, health)
    proc.submit(7, np.zeros((1, 2, 3), np.complex64))
    stop = threading.Event()
    t = threading.Thread(target=proc.run, args=(stop,))
    t.start()
    threading.Event().wait(0.5)
    stop.set()
    t.join()
    assert proc.errors == 1 and feed.latest() is None
    assert "frame 7" in health.snapshot()["problems"][-1]


def test_channel_power_sum_is_the_reference():
    cube = _cube(3)
    np.testing.assert_allclose(channel_power_sum(cube), range_doppler_power(cube), rtol=1e-5)


def test_pool_max_keeps_single_cell_peak():
    full = get_preset("full")
    p = np.ones((full.n_range, full.n_doppler))
    p[101, 37] = 1e6
    pooled = pool_max(p)
    assert pooled.shape == (MAX_AXIS, MAX_AXIS)
    assert pooled[50, 18] == 1e6 and pooled.max() == 1e6


def test_heatmap_quantisation_round_trip():
    p = np.full((CFG.n_range, CFG.n_doppler), 100.0)
    p[10, 1] = 1e7  # Doppler bin 1 -> shifted column n/2 + 1 -> pooled column n/4
    m = heatmap(p, CFG)
    q = np.frombuffer(base64.b64decode(m["q"]), np.uint8).reshape(m["rows"], m["cols"])
    assert (m["rows"], m["cols"]) == (CFG.n_range, MAX_AXIS)
    assert q.max() == 255 and q[10, MAX_AXIS // 2] == 255, "a one-cell peak survives"
    assert m["hi"] == pytest.approx(70.0) and m["lo"] == pytest.approx(15.0)
    assert m["velocity_mps"][0] < 0 < m["velocity_mps"][-1]


def test_box_outline_is_rotated_rectangle():
    xs, ys = box_outline({"x_m": 10.0, "y_m": 2.0, "length_m": 4.0, "width_m": 2.0,
                         "heading_deg": 90.0})
    assert (xs[0], ys[0]) == (xs[-1], ys[-1])
    assert min(ys) == pytest.approx(0.0) and max(ys) == pytest.approx(4.0)
    assert min(xs) == pytest.approx(9.0) and max(xs) == pytest.approx(11.0)


def test_frame_message_without_cube_for_record_streams():
    """A detection-record stream (no cube) still gives points; the maps are absent."""
    cloud = PointCloud.from_polar(np.array([20.0]), np.array([10.0]), np.array([3.0]),
                                  np.array([50.0]), np.array([20.0]), np.array([5.0]),
                                  np.array([11]), np.array([14]), np.array([False]))
    obj = {"class": "car", "score": 0.9, "x_m": 19.7, "y_m": 3.5, "length_m": 4.5,
           "width_m": 1.8, "heading_deg": 0.0}
    msg = frame_message(ViewFrame(seq=1, frame_id=5, cfg=CFG, cloud=cloud, objects=[obj]),
                        channel=99, health={})
    assert msg["rd"] is None and msg["nci"] is None and msg["channel"] == CFG.n_virtual - 1
    assert msg["points"]["x"] == [pytest.approx(19.696, abs=1e-3)]
    assert msg["boxes"][0]["label"] == "car 0.90"


def test_page_assets_reference_no_external_url():
    """Everything the page loads comes from the package (works with no internet)."""
    for name in ("index.html", "view.js", "view.css"):
        text = (STATIC_DIR / name).read_text()
        assert not re.search(r"(https?:)?//[a-z0-9.-]+\.[a-z]{2,}", text, re.I), name
    html = (STATIC_DIR / "index.html").read_text()
    refs = re.findall(r'(?:src|href)="([^"]+)"', html)
    assert refs and all(r.startswith("/static/") for r in refs), refs
    for r in refs:
        name = r.removeprefix("/static/")
        assert (STATIC_DIR / name).is_file() or name == "plotly.min.js"
    assert plotly_js_path().stat().st_size > 1_000_000



def test_frame_message_carries_elevation_of_a_2d_array():
    """A 3-TX profile with the middle TX raised (xWR1843, ``tests.test_cli_radar_option.
    THREE_TX``) through the view's processor: the browser's points carry z and elevation,
    the values the point JSON writes (``PointCloud.to_json_dict``); a planar preset's carry
    neither."""
    cfg = profile_from_toml(THREE_TX).config
    sc = Scatterers(np.array([10.0]), np.array([10.0]), np.array([1.0]), np.array([10.0]),
                    np.array([-1]), np.array([20.0]))
    adc = simulate_frame(cfg, sc, rng=np.random.default_rng(1)).samples
    feed = Feed()
    Processor(cfg, feed, LinkHealth()).process(Job(0, frame_cube(adc, cfg), cfg))
    frame = feed.latest()
    assert frame is not None and len(frame.cloud) >= 1
    msg = frame_message(frame, channel=0, health={})
    points = frame.cloud.to_json_dict(cfg, 1)["points"]
    assert msg["points"]["z"] == pytest.approx([p["z_m"] for p in points], abs=1e-3)
    assert msg["points"]["el"] == pytest.approx([p["elevation_deg"] for p in points], abs=0.01)
    strongest = int(np.argmax(frame.cloud.snr_db))
    assert msg["points"]["el"][strongest] == pytest.approx(20.0, abs=3.0)
    planar = frame_message(ViewFrame(seq=1, frame_id=0, cfg=CFG, cloud=frame.cloud),
                           channel=0, health={})
    assert "z" not in planar["points"] and "el" not in planar["points"]
