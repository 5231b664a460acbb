"""Packet integrity end to end: random single-bit and burst flips injected into the DMA packet
byte streams of radar cubes and detection records, as datagrams (the live link), as a raw
byte stream (a DMA dump) and as ``.dmacap`` captures. Every flip must leave its frame damaged
(the packet's CRC word fails, ``StreamStats.crc_errors``), no corrupt frame is ever complete,
the frames around it are untouched, and the decoders never raise on corrupted bytes.

The false-accept rate (corrupt frames reported complete) is printed; it must be zero.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from host.capture import CaptureInfo, frame_packets, read_capture, write_capture
from host.receiver import RECORDS, Receiver
from host.records import RecordDecoder
from host.stream import PacketDecoder, StreamDecoder
from model.axis_packetizer import (
    bytes_to_words,
    crc_error,
    depacketize,
    packetize_stream,
    words_to_bytes,
)
from model.config import get_preset
from model.detect_chain import detect_stream
from model.radar_pipeline import PipelineParams
from tests.test_host_stream import PW as CUBE_PW
from tests.test_host_stream import SMALL as CUBE_CFG
from tests.test_host_stream import cubes, stream
from tests.test_records import DCFG, _frames, _packets
from tests.test_records import PW as REC_PW

FLIPS_PER_CASE = 1250              # x 2 kinds x 2 flip shapes x 2 input paths = 10 000
N_FRAMES = 3                       # flips go into the middle frame (id 1)
STREAMS = {"cube": stream(CUBE_CFG, cubes(CUBE_CFG, N_FRAMES)),   # 8 packets a frame
           "records": _packets(_frames(N_FRAMES, seed=1, targets=4))}


def _decoder(kind: str) -> PacketDecoder:
    return StreamDecoder(CUBE_CFG, CUBE_PW) if kind == "cube" else RecordDecoder(DCFG, REC_PW)


def _payload(frame) -> np.ndarray:  # noqa: ANN001 - a cube Frame or a DetectionFrame
    return frame.cube if hasattr(frame, "cube") else np.asarray(
        [(r.range_bin, r.doppler_bin, r.power) for r in frame.records])


def _flip(data: bytes, rng: np.random.Generator, burst: bool, lo: int = 0) -> bytes:
    """``data`` with one bit flipped, or a burst of 2..256 bits (first and last flipped,
    the bits between at random), at a random place at or after byte ``lo``."""
    bits = 8 * (len(data) - lo)
    n = int(rng.integers(2, 257)) if burst else 1
    n = min(n, bits)
    start = 8 * lo + int(rng.integers(0, bits - n + 1))
    pattern = rng.integers(0, 2, n).astype(bool)
    pattern[0] = pattern[-1] = True
    out = bytearray(data)
    for i in np.flatnonzero(pattern):
        b = start + int(i)
        out[b // 8] ^= 1 << (b % 8)
    return bytes(out)


def _decode(kind: str, packets: list[bytes], raw: bool) -> tuple[list, PacketDecoder]:
    dec = _decoder(kind)
    if raw:
        out = dec.push_bytes(b"".join(packets)) + dec.finish()
    else:
        out = [f for p in packets for f in dec.push_packet(p)] + dec.flush()
    return out, dec


def _check_trial(kind: str, clean: dict[int, np.ndarray], frames: list) -> bool:
    """True when the corrupt frame (id 1) was accepted as complete (a false accept); the
    other frames must come out complete and exact whatever happened to frame 1, and every
    complete frame must be exactly the sent one."""
    by_id = {f.frame_id: f for f in frames}
    for fid in (0, 2):
        assert by_id[fid].complete, (kind, fid, by_id[fid].problems)
    for f in frames:
        if f.complete:
            assert f.frame_id in clean and np.array_equal(_payload(f), clean[f.frame_id])
    return 1 in by_id and by_id[1].complete


@pytest.mark.parametrize("raw", [False, True], ids=["datagrams", "byte-stream"])
@pytest.mark.parametrize("burst", [False, True], ids=["single-bit", "burst"])
@pytest.mark.parametrize("kind", ["cube", "records"])
def test_every_flip_is_detected(kind: str, burst: bool, raw: bool) -> None:
    packets = STREAMS[kind]
    ref, _ = _decode(kind, packets, raw)
    assert all(f.complete for f in ref) and len(ref) == N_FRAMES
    clean = {f.frame_id: _payload(f) for f in ref}
    per_frame = len(packets) // N_FRAMES
    rng = np.random.default_rng([kind == "cube", burst, raw])   # the same flips every run
    false_accepts = crc_caught = 0
    for _ in range(FLIPS_PER_CASE):
        i = per_frame + int(rng.integers(0, per_frame))     # a packet of frame 1
        bad = list(packets)
        bad[i] = _flip(packets[i], rng, burst)
        frames, dec = _decode(kind, bad, raw)
        false_accepts += _check_trial(kind, clean, frames)
        crc_caught += dec.stats.crc_errors > 0
    print(f"\n{kind} {'burst' if burst else 'single-bit'} flips, "
          f"{'byte stream' if raw else 'datagrams'}: {FLIPS_PER_CASE} injected, "
          f"{FLIPS_PER_CASE - false_accepts} detected ({crc_caught} by the CRC, the rest by "
          f"the header checks), false accepts {false_accepts} "
          f"({false_accepts / FLIPS_PER_CASE:.2%})")
    assert false_accepts == 0


@pytest.mark.parametrize("kind", ["cube", "records"])
def test_flips_in_captures_are_detected(kind: str, tmp_path: Path) -> None:
    """Flips anywhere in a capture's packet records (length prefixes included): the reader
    says it is truncated, or the decoder marks frame 1 damaged; never a corrupt frame used."""
    packets = STREAMS[kind]
    info = (CaptureInfo(CUBE_CFG.num_rx, CUBE_PW, CUBE_CFG.num_tx, CUBE_CFG.n_range,
                        CUBE_CFG.n_doppler) if kind == "cube" else
            CaptureInfo(DCFG.num_rx, REC_PW, DCFG.num_tx, DCFG.n_range, DCFG.n_doppler,
                        DCFG.max_detections))
    path = tmp_path / "x.dmacap"
    write_capture(path, info, packets)
    image = path.read_bytes()
    per_frame = len(packets) // N_FRAMES
    # frame 1's records: from its first length prefix to the end of its last packet
    offsets = np.cumsum([0] + [4 + len(p) for p in packets])
    head = len(image) - int(offsets[-1])
    lo, hi = head + int(offsets[per_frame]), head + int(offsets[2 * per_frame])
    ref, _ = _decode(kind, packets, raw=False)
    clean = {f.frame_id: _payload(f) for f in ref}
    rng = np.random.default_rng(7)
    trials, false_accepts, refused = 400, 0, 0
    for t in range(trials):
        bad = image[:lo] + _flip(image[lo:hi], rng, burst=bool(t % 2)) + image[hi:]
        path.write_bytes(bad)
        dec = _decoder(kind)
        frames: list = []
        _, it = read_capture(path)
        try:
            for p in it:
                frames += dec.push_packet(p)
        except ValueError:
            refused += 1        # the reader: a length prefix now runs past the file's end
        frames += dec.flush()
        by_id = {f.frame_id: f for f in frames}
        false_accepts += 1 in by_id and by_id[1].complete
        for f in frames:
            if f.complete:
                assert np.array_equal(_payload(f), clean[f.frame_id])
    print(f"\n{kind} capture: {trials} flips, {refused} refused by the reader, "
          f"false accepts {false_accepts}")
    assert false_accepts == 0


@pytest.mark.parametrize("kind", ["cube", "records"])
def test_live_link_counts_and_marks_corrupt_packets(kind: str) -> None:
    """The live link (host.receiver.Receiver, as ``radar receive`` / ``radar view`` use it):
    a corrupt datagram is counted in the decoder's crc_errors and its frame is damaged."""
    cfg = get_preset("paper-fpga")
    rng = np.random.default_rng(3)
    if kind == "cube":
        cube = (rng.integers(-200, 200, cfg.cube_shape)
                + 1j * rng.integers(-200, 200, cfg.cube_shape)).astype(np.complex64)
        packets = [p for k in range(N_FRAMES) for p in frame_packets(cube, cfg, 1024, k)]
    else:
        dcfg = PipelineParams(output_mode=1).detect_config(cfg)
        words = [np.zeros((dcfg.n_range * dcfg.num_tx * dcfg.n_doppler, dcfg.num_rx),
                          np.uint32)] * N_FRAMES
        packets = [words_to_bytes(p) for p in packetize_stream(detect_stream(words, dcfg),
                                                               256)]
    rx = Receiver([cfg], None, kind, lambda c: PipelineParams(output_mode=1).detect_config(c))
    dec = rx.learn(packets[0])
    assert (kind == RECORDS) == isinstance(dec, RecordDecoder)
    per_frame = len(packets) // N_FRAMES
    bad = list(packets)
    bad[per_frame + 1] = _flip(bad[per_frame + 1], rng, burst=False, lo=4 * cfg.num_rx)
    frames = [f for p in bad for f in dec.push_packet(p)] + dec.flush()
    assert [f.complete for f in sorted(frames, key=lambda f: f.frame_id)] == [True, False, True]
    assert dec.stats.crc_errors == 1 and dec.stats.frames_damaged == 1
    assert any("failed its CRC" in p for f in frames for p in f.problems)


def test_model_depacketize_drops_corrupt_packets() -> None:
    """The model's decoder (``model.axis_packetizer.depacketize``, used by the testbenches)
    applies the same check: a flipped packet is not used, its frame is damaged (and names
    the CRC failure unless the flip hit the header it would be named by), the other frames
    are complete."""
    packets = [bytes_to_words(p, CUBE_CFG.num_rx) for p in STREAMS["cube"]]
    per_frame = len(packets) // N_FRAMES
    fw = CUBE_CFG.num_tx * CUBE_CFG.n_range * CUBE_CFG.n_doppler
    rng = np.random.default_rng(11)
    for t in range(300):
        i = per_frame + int(rng.integers(0, per_frame))
        bad = list(packets)
        bad[i] = bytes_to_words(_flip(words_to_bytes(packets[i]), rng, burst=bool(t % 2)),
                                CUBE_CFG.num_rx)
        frames = depacketize(bad, fw, CUBE_PW, CUBE_CFG.num_rx)
        assert [f.complete for f in frames] == [True, False, True], [f.errors for f in frames]
        assert any("missing packets" in e for e in frames[1].errors)
        flipped_header = not np.array_equal(bad[i][0], packets[i][0])
        assert flipped_header or any("not used" in e for e in frames[1].errors)


def test_crc_error_names_what_is_wrong() -> None:
    """The check itself: intact, a flipped bit, a non-zero upper lane, a short packet."""
    p = STREAMS["cube"][0]
    assert crc_error(p, 16) is None
    assert "CRC mismatch" in crc_error(p[:20] + bytes([p[20] ^ 1]) + p[21:], 16)
    assert "lanes 1.. are not zero" in crc_error(p[:-1] + b"\x01", 16)
    assert "not a header, payload and CRC word" in crc_error(p[:16], 16)


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(kind=st.sampled_from(["cube", "records"]), raw=st.booleans(),
       edits=st.lists(st.tuples(st.integers(0, 10**9), st.integers(0, 255),
                                st.sampled_from(["xor", "cut", "dup", "insert"])),
                      min_size=1, max_size=6))
def test_decoders_never_raise_on_corrupted_bytes(kind: str, raw: bool,
                                                 edits: list[tuple[int, int, str]]) -> None:
    """Arbitrary byte corruption (flips, cuts, duplicated and inserted bytes) in packets of
    either stream, as datagrams or a raw byte stream: the decoder never raises, and every
    frame it calls complete is one that was sent, exactly."""
    packets = list(STREAMS[kind])
    ref, _ = _decode(kind, packets, raw=False)
    clean = {f.frame_id: _payload(f) for f in ref}
    for where, value, op in edits:
        i = where % len(packets)
        buf = packets[i]
        at = (where // len(packets)) % max(1, len(buf))
        if op == "xor" and buf:
            buf = buf[:at] + bytes([buf[at] ^ (value or 1)]) + buf[at + 1:]
        elif op in ("cut", "xor"):
            buf = buf[:at]
        elif op == "dup":
            buf = buf[:at] + buf[at:at + value % 64] * 2 + buf[at + value % 64:]
        else:
            buf = buf[:at] + bytes([value]) * (1 + value % 7) + buf[at:]
        packets[i] = buf
    frames, dec = _decode(kind, packets, raw)
    for f in frames:
        if f.complete:
            assert np.array_equal(_payload(f), clean[f.frame_id])
    assert dec.stats.frames_complete + dec.stats.frames_damaged == len(frames)


def test_corrupted_capture_replayed_and_received(tmp_path: Path) -> None:
    """The reported case: 200 bytes inverted inside frame 1 of a 3-frame capture, then
    ``radar replay`` -> ``radar receive``: frame 1 is damaged and gives no points, its packet
    is counted in the JSON's stats.crc_errors, frames 0 and 2 are intact."""
    import json
    import socket
    import threading
    import time

    from radar.cli import main

    cap = tmp_path / "t.dmacap"
    assert main(["capture", "--scene", "table1", "--preset", "paper-fpga", "--frames", "3",
                 "--out", str(cap)]) == 0
    info, it = read_capture(cap)
    sizes = [len(p) for p in it]
    per_frame = len(sizes) // 3
    image = bytearray(cap.read_bytes())
    head = len(image) - sum(4 + n for n in sizes)
    at = head + sum(4 + n for n in sizes[:per_frame + 1]) - 1000   # inside frame 1
    image[at:at + 200] = bytes(b ^ 0xFF for b in image[at:at + 200])
    cap.write_bytes(bytes(image))
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    out, rc = tmp_path / "rx.json", {}
    t = threading.Thread(target=lambda: rc.update(rc=main([
        "receive", "--port", str(port), "--idle-timeout", "1", "--timeout", "60",
        "--json", str(out)])))
    t.start()
    time.sleep(0.5)
    assert main(["replay", "--capture", str(cap), "--port", str(port)]) == 0
    t.join(timeout=90)
    assert rc["rc"] == 0 and info.packet_words == 4092
    doc = json.loads(out.read_text())
    info_by_id = sorted(doc["frame_info"], key=lambda f: f["frame_id"])  # damaged: late
    assert [f["complete"] for f in info_by_id] == [True, False, True]
    assert doc["stats"]["crc_errors"] == 1
    assert any("failed its CRC" in p for p in info_by_id[1]["problems"])
    assert "points" not in info_by_id[1] and not any(
        p["frame"] == 1 for p in doc["points"])
