"""radar view of the on-chip detector's record stream (OUTPUT_MODE = 1) without a browser:
the record ingest (given or learnt from the packet headers), the record frames' health
figures (CFAR detections, records, sticky truncation), record frames through the host
processing to a ViewFrame without a cube, its page message, malformed record datagrams
(counted and shown, never raised), and the command line's stream-kind checks."""

from __future__ import annotations

import threading

import numpy as np
import pytest

from host.capture import CaptureInfo, write_capture
from host.receiver import CUBE, RECORDS, Receiver
from host.records import DetectionFrame
from model.axis_packetizer import seal, words_to_bytes
from model.config import PRESETS, get_preset
from model.detect_records import TAG_RECORD, hdr_words
from model.radar_pipeline import PipelineParams, chain_gain
from model.scene import table1_scene
from radar.cli import main as radar_main
from radar.view.feed import Feed
from radar.view.health import LinkHealth
from radar.view.ingest import packet_ingest
from radar.view.processor import Processor
from radar.view.render import frame_message
from radar.view.sources import replay_loop, scene_record_frames

CFG = get_preset("paper-fpga")
PACKET_WORDS = 256
MAX_DET = {"plenty": 64, "few": 4}


def _chain(max_det: int) -> PipelineParams:
    base = PipelineParams(packet_words=PACKET_WORDS, output_mode=1)
    dcfg = base.detect_config(CFG)
    from dataclasses import replace

    return replace(base, detect=replace(dcfg, max_detections=max_det))


@pytest.fixture(scope="module")
def streams() -> dict[str, list[list[bytes]]]:
    """Record packets (bytes, grouped by frame) of 2 Table I frames through the bit-accurate
    model of the chain in mode 1: with room for every detection, and with MAX_DETECTIONS 4
    (the trailer's truncated flag set)."""
    scene = table1_scene("paper-fpga")
    return {k: list(scene_record_frames(scene, _chain(m), 2)) for k, m in MAX_DET.items()}


class _Keep(Processor):
    """Processor that keeps the record frames it is handed (no processing)."""

    def __init__(self, health: LinkHealth) -> None:
        super().__init__(CFG, Feed(), health)
        self.records: list[tuple[int, int, float, str]] = []
        self.cubes: list[int] = []

    def submit(self, frame_id, frame, cfg=None) -> None:  # noqa: ANN001
        if isinstance(frame, DetectionFrame):
            self.records.append((frame.frame_id, len(frame.records), frame.gain, cfg.name))
        else:
            self.cubes.append(frame_id)


def _ingest(kind: str | None, max_det: int, packet_words: int | None = PACKET_WORDS,
            learn: bool = False) -> tuple[Receiver, LinkHealth, _Keep]:
    health = LinkHealth()
    keep = _Keep(health)
    dcfg = _chain(max_det).detect
    cfg = get_preset("full") if learn else CFG
    ingest = packet_ingest(cfg, packet_words, health, keep,
                           configs=list(PRESETS.values()) if learn else None, kind=kind,
                           detect_config=lambda c: PipelineParams(
                               output_mode=1).detect_config(c) if c != CFG else dcfg)
    return ingest, health, keep


def _push(ingest: Receiver, frames: list[list[bytes]]) -> None:
    for f in frames:
        for p in f:
            ingest.push(p)
    ingest.idle()


def test_record_stream_counts_frames_and_trailer_figures(streams):
    ingest, health, keep = _ingest(RECORDS, MAX_DET["plenty"])
    _push(ingest, streams["plenty"])
    s = health.snapshot()
    assert (s["stream_kind"], s["frames_complete"], s["frames_damaged"], s["malformed"],
            s["packets_lost"], s["max_detections"]) == ("records", 2, 0, 0, 0, 64)
    assert s["cfar_detections"] > 0 and s["records"] == s["cfar_detections"]
    assert not s["truncated"] and s["frames_truncated"] == 0
    assert [(fid, cfg) for fid, _, _, cfg in keep.records] == [(0, "paper-fpga"),
                                                             (1, "paper-fpga")]
    assert keep.records[-1][1] == s["records"] and keep.cubes == []
    gain = chain_gain(CFG, PipelineParams())   # divided out where the records are decoded
    assert all(g == gain for _, _, g, _ in keep.records)


def test_truncated_flag_is_sticky_and_shown(streams):
    """MAX_DETECTIONS 4: every frame is truncated; the flag stays set after a sender restart
    and a clean stream, and a problem line says so."""
    ingest, health, _ = _ingest(RECORDS, MAX_DET["few"])
    _push(ingest, streams["few"])
    s = health.snapshot()
    assert s["truncated"] and s["frames_truncated"] == 2 and s["records"] == 4
    assert s["cfar_detections"] > 4
    assert any("TRUNCATED" in p and "MAX_DETECTIONS 4" in p for p in s["problems"])
    ingest2 = packet_ingest(CFG, PACKET_WORDS, health, _Keep(health), kind=RECORDS,
                            detect_config=lambda c: _chain(64).detect)
    _push(ingest2, streams["plenty"])
    s = health.snapshot()
    assert s["truncated"] and s["frames_truncated"] == 2 and s["frames_complete"] == 4


@pytest.mark.parametrize("packet_words", [None, PACKET_WORDS])
def test_stream_kind_learnt_from_the_headers(streams, packet_words):
    """A UDP stream of unknown kind and preset: record packets are recognised by their
    frame length (records of MAX_DETECTIONS), cube packets as before."""
    from host.capture import frame_packets

    ingest, health, keep = _ingest(None, MAX_DET["plenty"], packet_words, learn=True)
    _push(ingest, streams["plenty"])
    s = health.snapshot()
    assert (s["stream_kind"], s["frames_complete"], s["malformed"]) == ("records", 2, 0)
    assert [r[0] for r in keep.records] == [0, 1] and keep.cubes == []
    # the learnt preset's chain gain (the ingest started on full)
    assert keep.records[0][2] == pytest.approx(chain_gain(CFG, PipelineParams()))
    # the sender switches to the cube (after a pause): learnt again
    rng = np.random.default_rng(0)
    shape = CFG.cube_shape
    cube = (rng.integers(-99, 99, shape) + 1j * rng.integers(-99, 99, shape)).astype(
        np.complex64)
    _push(ingest, [frame_packets(cube, CFG, 1023, 5)])
    s = health.snapshot()
    assert s["stream_kind"] == CUBE and keep.cubes == [5] and s["malformed"] == 0


def test_wrong_max_detections_is_said(streams):
    """A record stream of another MAX_DETECTIONS than --max-detections fits nothing: the
    health panel says why (once), nothing is shown as a frame of the wrong kind."""
    ingest, health, keep = _ingest(None, MAX_DET["plenty"], None, learn=True)
    _push(ingest, streams["few"])
    s = health.snapshot()
    said = [p for p in s["problems"] if "fits no cube or record stream" in p]
    assert len(said) == 1 and "--max-detections" in said[0], s["problems"]
    assert keep.records == []


def _corrupt_record_tag(packet: bytes) -> bytes:
    """The packet with its first record's tag byte destroyed (header word and CRC valid:
    corrupt at the source)."""
    words = np.frombuffer(packet, "<u4").reshape(-1, CFG.num_rx)[:-1].copy()
    assert words[1, 0] >> 24 == TAG_RECORD
    words[1 + hdr_words(CFG.num_rx) + CFG.num_tx, 0] ^= 0x5A000000  # second record's tag
    return words_to_bytes(seal(words))


def _record_off_the_map(packet: bytes) -> bytes:
    """The packet with its first record's range bin set to 4095 (tag and packet intact, CRC
    valid: the frame decodes as complete, the record lies outside the map)."""
    words = np.frombuffer(packet, "<u4").reshape(-1, CFG.num_rx)[:-1].copy()
    words[1, 0] |= 0xFFF << 12
    return words_to_bytes(seal(words))


def test_malformed_record_datagrams_are_counted_never_raised(streams):
    """Garbage, short, odd-length, bad-magic datagrams, a packet of the wrong length, a
    corrupt record inside an intact packet: counted (malformed datagrams, damaged frames),
    reported, and the good frames after them still arrive."""
    ingest, health, keep = _ingest(RECORDS, MAX_DET["plenty"])
    good = streams["plenty"]
    bad_magic = bytearray(good[0][0])
    bad_magic[3] ^= 0xFF  # header magic byte of lane 0
    junk = [b"", b"x", b"not a DMA packet at all", bytes(48), bytes(bad_magic),
            good[0][0][:-5], bytes(np.random.default_rng(1).integers(0, 256, 4096, np.uint8))]
    for j in junk:
        ingest.push(j)
    ingest.restart()  # the cut-short packet fails its CRC: malformed, opens no frame
    s = health.snapshot()
    assert s["malformed"] == len(junk) and s["frames_damaged"] == 0, s
    # a frame whose records are corrupt inside intact packets: damaged, records kept up to it
    corrupt = [_corrupt_record_tag(good[0][0])] + good[0][1:]
    _push(ingest, [corrupt])
    s = health.snapshot()
    assert s["frames_damaged"] == 1, s
    assert any("bad record tag" in p for p in s["problems"]), s["problems"]
    _push(ingest, good)
    s = health.snapshot()
    assert s["frames_complete"] == 2, s
    assert [r[0] for r in keep.records][-2:] == [0, 1]


def test_record_frames_processed_into_a_view_frame(streams):
    """Record frames through the real processor: a ViewFrame without a cube whose points
    are the host's records->cloud (host.record_points), and a page message with the records'
    cells and their profile (no maps); a damaged frame with corrupt records is processed
    without an error."""
    health, feed = LinkHealth(), Feed()
    proc = Processor(CFG, feed, health)
    ingest = packet_ingest(CFG, PACKET_WORDS, health, proc, kind=RECORDS,
                           detect_config=lambda c: _chain(64).detect)
    stop = threading.Event()
    t = threading.Thread(target=proc.run, args=(stop,))
    t.start()
    try:
        _push(ingest, [[_corrupt_record_tag(streams["plenty"][0][0])]
                       + streams["plenty"][0][1:]])
        for _ in range(200):
            if feed.latest() is not None:
                break
            stop.wait(0.05)
        _push(ingest, streams["plenty"][1:])
        for _ in range(200):
            f = feed.latest()
            if f is not None and f.frame_id == 1:
                break
            stop.wait(0.05)
        # a record whose range bin lies off the map (corrupt bits, intact packet) is dropped
        _push(ingest, [[_record_off_the_map(streams["plenty"][0][0])]
                       + streams["plenty"][0][1:]])
        for _ in range(200):
            if any("outside" in p for p in health.snapshot()["problems"]):
                break
            stop.wait(0.05)
        _push(ingest, streams["plenty"][1:])
        for _ in range(200):
            f = feed.latest()
            if f is not None and f.frame_id == 1 and f.seq > 2:
                break
            stop.wait(0.05)
    finally:
        stop.set()
        t.join()
    assert any("1 record(s) outside the 64 x 256 map" in p
               for p in health.snapshot()["problems"]), health.snapshot()["problems"]
    frame = feed.latest()
    assert frame is not None and frame.frame_id == 1 and frame.cube is None
    assert proc.errors == 0, health.snapshot()["problems"]
    assert len(frame.cloud) >= 3 and frame.records is not None
    assert len(frame.records) == health.snapshot()["records"]
    assert health.snapshot()["detections"] == len(frame.cloud)
    msg = frame_message(frame, 0, {})
    assert msg["rd"] is None and msg["nci"] is None
    cells = msg["cells"]
    assert len(cells["range"]) == len(frame.records) == len(cells["v"]) == len(cells["db"])
    assert max(cells["range"]) <= CFG.max_range_m
    assert all(abs(v) <= CFG.max_velocity_mps for v in cells["v"])
    prof = msg["profile"]
    assert prof["kind"] == "records" and len(prof["det_range_m"]) == len(frame.cloud)
    # each point sits on the strongest record of its range bin
    assert all(np.isfinite(prof["det_db"])) and max(prof["det_db"]) == max(cells["db"])


def test_replay_of_a_scene_record_stream_loops(streams):
    ingest, health, keep = _ingest(RECORDS, MAX_DET["plenty"])
    stop = threading.Event()
    replay_loop(iter(streams["plenty"]), ingest, stop, fps=0, loop=False)
    assert [r[0] for r in keep.records] == [0, 1]
    assert health.snapshot()["frames_complete"] == 2


def test_cli_checks_the_capture_kind(tmp_path, capsys, streams):
    path = tmp_path / "rec.dmacap"
    write_capture(path, CaptureInfo(CFG.num_rx, PACKET_WORDS, CFG.num_tx, CFG.n_range,
                                    CFG.n_doppler, MAX_DET["plenty"]),
                  [p for f in streams["plenty"] for p in f])
    assert radar_main(["view", "--replay", str(path), "--detect", "host",
                       "--duration", "0.1", "--port", "0"]) == 2
    err = capsys.readouterr().err.strip()
    assert "detection-record capture" in err and len(err.splitlines()) == 1
    assert radar_main(["view", "--scene", "table1", "--detect", "fpga", "--backend", "float",
                       "--duration", "0.1", "--port", "0"]) == 2
    assert "--backend model" in capsys.readouterr().err
