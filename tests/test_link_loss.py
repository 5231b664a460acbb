"""Issue 32, loopback loss: the receiver asks for a large socket buffer and reports what
the OS granted; datagrams the kernel drops because the receiver fell behind are counted
(SO_RXQ_OVFL) and named in a hint with the measured loss."""

from __future__ import annotations

import socket
import sys

import pytest

from host.stream import StreamDecoder
from host.udp import RCVBUF_BYTES, UdpReceiver
from model.config import get_preset


def test_receive_buffer_is_raised_and_read_back() -> None:
    with UdpReceiver() as rx:
        assert rx.rcvbuf_asked == RCVBUF_BYTES
        granted = rx.sock.getsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF)
        assert rx.rcvbuf_granted == (granted // 2 if sys.platform == "linux" else granted)
        assert rx.rcvbuf_granted > 212992          # more than Linux's default
        assert (rx.buffer_hint() is None) == (rx.rcvbuf_granted >= rx.rcvbuf_asked)
        rx.rcvbuf_asked = 10 * rx.rcvbuf_granted       # as when the OS caps the buffer
        assert "net.core.rmem_max" in rx.buffer_hint()


@pytest.mark.skipif(sys.platform != "linux", reason="SO_RXQ_OVFL is Linux's")
def test_a_receiver_that_falls_behind_says_how_much_was_lost() -> None:
    cfg = get_preset("paper-fpga")
    with UdpReceiver(rcvbuf_bytes=1 << 16) as rx, \
            socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as tx:
        for _ in range(40):                      # 40 x 32 KiB into a 64 KiB buffer, unread
            tx.sendto(bytes(32768), ("127.0.0.1", rx.port))
        tx.sendto(bytes(100), ("127.0.0.1", rx.port))
        rx.receive(StreamDecoder(cfg, 4093), idle_timeout_s=0.3, total_timeout_s=5)
        assert rx.socket_drops > 0 and rx.datagrams + rx.socket_drops == 41
        hint = rx.loss_hint()
        assert hint is not None and f"dropped {rx.socket_drops} of 41 datagrams" in hint
        assert "--rate-mbps" in hint and "Mbit/s" in hint
    with UdpReceiver() as rx:
        assert rx.loss_hint() is None
