"""Issue 12 item 5: the Ethernet path works with its defaults (library level; the CLI
round trip is in the CLI tests).

Packets fit UDP; the receiver learns the geometry from the packets, waits for the first
datagram before its idle timeout runs, keeps what arrived on Ctrl-C."""

import os
import signal
import threading
import time

import numpy as np
import pytest

from host.capture import CaptureInfo, frame_packets
from host.stream import StreamDecoder, geometry_from_packet
from host.udp import UDP_MAX_PAYLOAD, UdpReceiver, UdpSender, max_packet_words
from model.config import PRESETS, get_preset


def _cube(cfg, seed=0):
    rng = np.random.default_rng(seed)
    shape = (cfg.n_virtual, cfg.n_range, cfg.n_doppler)
    return rng.integers(-3000, 3000, shape) + 1j * rng.integers(-3000, 3000, shape)


@pytest.mark.parametrize("preset", sorted(PRESETS))
def test_default_packets_fit_udp_and_geometry_is_learnt(preset):
    cfg = get_preset(preset)
    pw = max_packet_words(cfg.num_rx)
    assert (pw + 2) * 4 * cfg.num_rx <= UDP_MAX_PAYLOAD < (pw + 3) * 4 * cfg.num_rx
    pk = frame_packets(_cube(cfg), cfg, pw, 7)
    assert max(len(p) for p in pk) <= UDP_MAX_PAYLOAD
    for p in (pk[0], pk[len(pk) // 2], pk[-1]):  # any packet, the last (short) one too
        got_cfg, got_pw = geometry_from_packet(p, PRESETS.values())
        assert got_cfg.name == preset and got_pw == pw
    assert CaptureInfo(cfg.num_rx, pw, cfg.num_tx, cfg.n_range, cfg.n_doppler).config(
        PRESETS.values()).name == preset


def test_geometry_from_garbage_is_a_value_error():
    with pytest.raises(ValueError, match="fits none"):
        geometry_from_packet(b"\x00" * 64, PRESETS.values())
    with pytest.raises(ValueError, match="matches no preset"):
        CaptureInfo(3, 100, 1, 16, 16).config(PRESETS.values())


def _send_later(packets, port, delay_s):
    def run():
        time.sleep(delay_s)
        with UdpSender("127.0.0.1", port, rate_bps=None) as tx:
            tx.send(packets)
    t = threading.Thread(target=run)
    t.start()
    return t


def test_idle_timeout_starts_after_the_first_datagram():
    """Receive first (idle timeout 0.3 s), the sender starts 1 s later: frames arrive."""
    cfg = get_preset("paper-fpga")
    pw = max_packet_words(cfg.num_rx)
    cube = _cube(cfg)
    pk = frame_packets(cube, cfg, pw, 0) + frame_packets(cube, cfg, pw, 1)
    with UdpReceiver() as rx:
        t = _send_later(pk, rx.port, 1.0)
        frames = rx.receive(None, idle_timeout_s=0.3, total_timeout_s=20.0,
                            make_decoder=lambda d: StreamDecoder(
                                *geometry_from_packet(d, PRESETS.values())))
        t.join()
    assert [f.frame_id for f in frames] == [0, 1] and all(f.complete for f in frames)
    assert np.array_equal(frames[0].cube, cube)
    assert rx.decoder is not None and rx.decoder.cfg.name == "paper-fpga"


def test_nothing_arrives_returns_no_frames_within_the_total_timeout():
    with UdpReceiver() as rx:
        t0 = time.monotonic()
        frames = rx.receive(StreamDecoder(get_preset("paper-fpga"), 4092),
                            idle_timeout_s=0.1, total_timeout_s=0.6)
    assert frames == [] and rx.datagrams == 0 and 0.5 < time.monotonic() - t0 < 3.0


def test_ctrl_c_keeps_what_was_received(sigint_raises):
    cfg = get_preset("paper-fpga")
    pw = max_packet_words(cfg.num_rx)
    pk = frame_packets(_cube(cfg), cfg, pw, 0)
    main = threading.main_thread().ident
    assert threading.get_ident() == main
    with UdpReceiver() as rx:
        t = _send_later(pk, rx.port, 0.2)
        timer = threading.Timer(1.5, lambda: os.kill(os.getpid(), signal.SIGINT))
        timer.start()
        frames = rx.receive(StreamDecoder(cfg, pw), idle_timeout_s=30.0, total_timeout_s=30.0)
        t.join()
    assert rx.interrupted and len(frames) == 1 and frames[0].complete


@pytest.mark.parametrize("kw", [{"idle_timeout_s": -1.0}, {"idle_timeout_s": float("nan")},
                                {"total_timeout_s": 0.0}, {"max_frames": 0}])
def test_receive_bad_arguments(kw):
    with UdpReceiver() as rx, pytest.raises(ValueError):
        rx.receive(StreamDecoder(get_preset("paper-fpga"), 4092), **kw)


@pytest.mark.parametrize("port", [-1, 65536, 10**9])
def test_bad_ports(port):
    with pytest.raises(ValueError, match="port"):
        UdpReceiver(port=port)
    with pytest.raises(ValueError, match="port"):
        UdpSender("127.0.0.1", port)
