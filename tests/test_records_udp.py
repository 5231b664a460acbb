"""The UDP path carries the detection-record stream too: `radar capture --detect fpga`
writes a record capture, `radar replay` sends it, `radar receive --detect fpga` learns the
packet geometry, decodes the records and writes the point cloud; lost packets are
reported; a record stream received as a cube names the flag."""

import json
import socket
import threading
import time

from host.capture import read_capture, write_capture
from model.axis_packetizer import bytes_to_words, seal, words_to_bytes
from model.detect_records import TAG_RECORD, frame_words
from radar.cli import main


def _free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _round_trip(tmp_path, cap, receive_args, replay_args=()):
    port, out, rc = _free_port(), tmp_path / "rx.json", {}
    t = threading.Thread(target=lambda: rc.update(rc=main([
        "receive", "--port", str(port), "--idle-timeout", "1", "--timeout", "30",
        "--json", str(out), *receive_args])))
    t.start()
    time.sleep(0.5)
    assert main(["replay", "--capture", str(cap), "--port", str(port), "--rate-mbps", "0",
                 *replay_args]) == 0
    t.join(timeout=60)
    return rc.get("rc"), out


def test_record_capture_replay_receive(tmp_path, capsys):
    cap = tmp_path / "r.dmacap"
    assert main(["capture", "--scene", "table1", "--preset", "paper-fpga", "--frames", "2",
                 "--packet-words", "64", "--detect", "fpga", "--out", str(cap)]) == 0
    info, packets = read_capture(cap)
    assert info.records and info.max_detections == 256
    # 256 records of 4 header + 1 snapshot words, a 4-word trailer: 1284 words, 21 packets
    assert len(list(packets)) == 2 * -(-frame_words(1, 4, 256) // 64) == 2 * 21
    rc, out = _round_trip(tmp_path, cap, ["--detect", "fpga"])   # geometry learnt
    assert rc == 0
    doc = json.loads(out.read_text())
    assert doc["preset"] == "paper-fpga" and doc["detect"] == "fpga"
    assert doc["packet_words"] == 64
    assert [f["complete"] for f in doc["frame_info"]] == [True, True]
    assert all(f["records"] > 0 and not f["truncated"] for f in doc["frame_info"])
    # paper-fpga sees 3 of the 4 Table I vehicles (vehicle 1 too weak), as from the cube
    assert sum(p["frame"] == 0 for p in doc["points"]) >= 3
    # a lost packet: reported as a damaged frame, not processed, no traceback
    rc, out = _round_trip(tmp_path, cap, ["--detect", "fpga", "--preset", "paper-fpga",
                                          "--packet-words", "64"],
                          ["--loss", "0.3", "--seed", "2"])
    doc = json.loads(out.read_text())
    assert any(not f["complete"] and f["problems"] for f in doc["frame_info"])
    # the record stream received as a cube: a one-line hint at the flag
    capsys.readouterr()
    rc, out = _round_trip(tmp_path, cap, [])
    assert rc == 1
    doc = json.loads(out.read_text())
    assert any("--detect fpga" in u for u in doc["stream_problems"]), doc["stream_problems"]


def test_receive_drops_records_outside_the_map(tmp_path):
    """A record whose bins lie outside the map (corrupt at the source: words that still
    carry the record tag in a packet with a valid CRC) is dropped and named in the frame's
    problems; the other records still become points (process_records refuses such records:
    tests in test_records_fast.py)."""
    cap = tmp_path / "r.dmacap"
    assert main(["capture", "--scene", "table1", "--preset", "paper-fpga", "--frames", "1",
                 "--packet-words", "64", "--detect", "fpga", "--out", str(cap)]) == 0
    info, packets = read_capture(cap)
    packets = list(packets)
    body = bytes_to_words(packets[0], info.num_rx)[:-1].copy()   # without its CRC word
    assert body[1, 0] >> 24 == TAG_RECORD  # the packet header word, then record 0's header
    body[1, 0] |= 0xFFF << 12                                      # range bin 4095
    packets[0] = words_to_bytes(seal(body))
    bad = tmp_path / "bad.dmacap"
    write_capture(bad, info, packets)
    rc, out = _round_trip(tmp_path, bad, ["--detect", "fpga"])
    assert rc == 0
    f0 = json.loads(out.read_text())["frame_info"][0]
    assert f0["complete"] and f0["points"] >= 3
    assert any("1 record(s) outside the 64 x 256 map dropped" in p for p in f0["problems"])


def test_cube_stream_received_as_records_names_the_flag(tmp_path, capsys):
    """A radar-cube stream sent to `receive --detect fpga`: its last packet can fit a
    record stream's geometry too, so such a packet is skipped rather than taken (it was,
    and the frames were then reported as damaged, missing packets); the one-line error
    says it is a cube stream."""
    cap = tmp_path / "c.dmacap"
    assert main(["capture", "--scene", "table1", "--preset", "paper-fpga", "--frames", "2",
                 "--out", str(cap)]) == 0
    capsys.readouterr()
    rc, out = _round_trip(tmp_path, cap, ["--detect", "fpga"])
    assert rc == 1
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert "radar-cube stream packet of paper-fpga (leave out --detect fpga)" in err, err
    doc = json.loads(out.read_text())
    assert doc["frame_info"] == [] and doc["packet_words"] is None
