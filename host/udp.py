"""The paper's Gigabit Ethernet link: DMA packets as UDP datagrams (one packet each).

:class:`UdpSender` replays packets as the board would (optionally paced to a bit rate, with
injected loss, duplication and reordering for testing); :class:`UdpReceiver` feeds arriving
datagrams to a :class:`host.stream.PacketDecoder` (a cube ``StreamDecoder`` or a detection
record ``host.records.RecordDecoder``). Both are meant for 127.0.0.1 in tests.
"""

from __future__ import annotations

import random
import socket
import struct
import sys
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import Any, Self

from host.stream import PacketDecoder

UDP_MAX_PAYLOAD = 65507
"""Largest UDP payload over IPv4, bytes."""


def max_packet_words(num_rx: int) -> int:
    """Largest PACKET_WORDS whose packet (header word + payload + CRC word, 4 * num_rx bytes
    a word) fits one UDP datagram: 1021 for 16 lanes, 4092 for 4 (capped at the header's
    65535)."""
    return min(UDP_MAX_PAYLOAD // (4 * num_rx) - 2, 65535)


def check_port(port: int, allow_zero: bool = True) -> int:
    """ValueError unless ``port`` is a UDP port number (0 = any free port, if allowed)."""
    lo = 0 if allow_zero else 1
    if isinstance(port, bool) or not isinstance(port, int) or not lo <= port <= 65535:
        raise ValueError(f"port: must be an integer in {lo}..65535, got {port!r}")
    return port


def check_seconds(value: float | None, name: str, allow_none: bool = False) -> None:
    """ValueError unless ``value`` is a finite positive number of seconds (<= 1 day)."""
    if value is None and allow_none:
        return
    if isinstance(value, bool) or not isinstance(value, int | float) or not \
            0.0 < value <= 86400.0:
        raise ValueError(f"{name}: must be a number of seconds in (0, 86400], got {value!r}")


@dataclass(frozen=True)
class Impairments:
    """Link faults injected by the sender: per-packet probabilities and a seed."""

    loss: float = 0.0
    duplicate: float = 0.0
    reorder: float = 0.0
    seed: int = 0

    def __post_init__(self) -> None:
        for name in ("loss", "duplicate", "reorder"):
            if not 0.0 <= getattr(self, name) <= 1.0:
                raise ValueError(f"{name}: probability must be in [0, 1]")


@dataclass
class SendLog:
    """What the sender did: indices (into the input packets) dropped / duplicated /
    swapped with their successor, and the number of datagrams sent."""

    sent: int = 0
    dropped: list[int] = field(default_factory=list)
    duplicated: list[int] = field(default_factory=list)
    reordered: list[int] = field(default_factory=list)


class _UdpSocket:
    """A UDP socket (``self.sock``) closed by :meth:`close` or at the end of a ``with``."""

    sock: socket.socket

    def close(self) -> None:
        self.sock.close()

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class UdpSender(_UdpSocket):
    """Sends packets to ``(host, port)``; ``rate_bps`` paces the stream (None: as fast as
    the socket goes)."""

    def __init__(self, host: str, port: int, rate_bps: float | None = None,
                 impairments: Impairments | None = None) -> None:
        if rate_bps is not None and not 0 < rate_bps <= 1e12:
            raise ValueError(f"rate: must be positive and at most 1e6 Mbit/s, got "
                             f"{rate_bps / 1e6:g} Mbit/s")
        check_port(port, allow_zero=False)
        self.addr = (host, port)
        self.rate_bps = rate_bps
        self.imp = impairments or Impairments()
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)

    def send(self, packets: Iterable[bytes]) -> SendLog:
        rng = random.Random(self.imp.seed)
        pkts = list(packets)
        for i, p in enumerate(pkts):
            if len(p) > UDP_MAX_PAYLOAD:
                raise ValueError(f"packet {i} has {len(p)} bytes, more than a UDP datagram "
                                 f"carries ({UDP_MAX_PAYLOAD}): use fewer PACKET_WORDS")
        log = SendLog()
        order = list(range(len(pkts)))
        i = 0
        while i < len(order) - 1:
            if rng.random() < self.imp.reorder:
                order[i], order[i + 1] = order[i + 1], order[i]
                log.reordered.append(order[i + 1])
                i += 2
            else:
                i += 1
        t0 = time.perf_counter()
        sent_bits = 0
        for idx in order:
            if rng.random() < self.imp.loss:
                log.dropped.append(idx)
                continue
            copies = 2 if rng.random() < self.imp.duplicate else 1
            if copies == 2:
                log.duplicated.append(idx)
            for _ in range(copies):
                self.sock.sendto(pkts[idx], self.addr)
                log.sent += 1
                sent_bits += 8 * len(pkts[idx])
                if self.rate_bps:
                    ahead = sent_bits / self.rate_bps - (time.perf_counter() - t0)
                    if ahead > 0.001:
                        time.sleep(ahead)
        return log


RCVBUF_BYTES = 64 << 20
"""Socket receive buffer asked for, bytes: more than three frames of ``full`` (17 MB each),
so a receiver that pauses (another process on the core) for a second at 766 Mbit/s loses
nothing. Linux grants at most ``net.core.rmem_max`` (privileged processes may go beyond
it: SO_RCVBUFFORCE)."""
_SO_RCVBUFFORCE = getattr(socket, "SO_RCVBUFFORCE", 33 if sys.platform == "linux" else None)
_SO_RXQ_OVFL = getattr(socket, "SO_RXQ_OVFL", 40 if sys.platform == "linux" else None)
"""Linux: each datagram carries the socket's count of datagrams dropped for want of buffer."""


def set_receive_buffer(sock: socket.socket, asked: int) -> int:
    """Raise ``sock``'s receive buffer towards ``asked`` bytes as far as the OS allows and
    return what it granted, bytes (Linux reports twice the usable size: halved here)."""
    for opt in (_SO_RCVBUFFORCE, socket.SO_RCVBUF):
        if opt is None:
            continue
        try:
            sock.setsockopt(socket.SOL_SOCKET, opt, asked)
            break
        except OSError:                 # SO_RCVBUFFORCE needs CAP_NET_ADMIN
            continue
    got = sock.getsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF)
    return got // 2 if sys.platform == "linux" else got


class UdpReceiver(_UdpSocket):
    """Bound UDP socket (port 0 = an ephemeral port, see :attr:`port`) with its receive
    buffer raised towards ``rcvbuf_bytes`` (:attr:`rcvbuf_granted`: what the OS gave).
    :meth:`receive` measures the link: :attr:`socket_drops` (datagrams the kernel dropped
    because the buffer was full: the receiver fell behind; Linux only, else 0) and
    :attr:`rate_bps` (the arrival rate)."""

    def __init__(self, host: str = "127.0.0.1", port: int = 0,
                 rcvbuf_bytes: int = RCVBUF_BYTES) -> None:
        check_port(port)
        self.interrupted = False
        self.decoder: PacketDecoder[Any] | None = None
        self.datagrams = 0
        self.bytes = 0
        self.socket_drops = 0
        self.rate_bps = 0.0
        self.unusable: list[str] = []  # datagrams no decoder could be built from
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.rcvbuf_asked = rcvbuf_bytes
        self.rcvbuf_granted = set_receive_buffer(self.sock, rcvbuf_bytes)
        self._ovfl = False
        if _SO_RXQ_OVFL is not None:
            try:
                self.sock.setsockopt(socket.SOL_SOCKET, _SO_RXQ_OVFL, 1)
                self._ovfl = True
            except OSError:
                pass
        self.sock.bind((host, port))

    def buffer_hint(self) -> str | None:
        """A hint when the OS granted a smaller receive buffer than asked, else None."""
        if self.rcvbuf_granted >= self.rcvbuf_asked:
            return None
        return (f"socket receive buffer {self.rcvbuf_granted / 2**20:.1f} MiB, asked "
                f"{self.rcvbuf_asked / 2**20:.0f} MiB (the OS limit; Linux: sysctl -w "
                f"net.core.rmem_max={self.rcvbuf_asked}): a fast stream may be dropped")

    def loss_hint(self) -> str | None:
        """A hint with the measured loss when the receiver fell behind, else None."""
        if not self.socket_drops:
            return None
        total = self.datagrams + self.socket_drops
        return (f"fell behind: the kernel dropped {self.socket_drops} of {total} datagrams "
                f"({100 * self.socket_drops / total:.1f} %) because the socket receive "
                f"buffer ({self.rcvbuf_granted / 2**20:.1f} MiB) was full at "
                f"{self.rate_bps / 1e6:.0f} Mbit/s; lower the sender's rate (radar replay "
                f"--rate-mbps) or raise the buffer (Linux: net.core.rmem_max)")

    def _recv(self) -> bytes:
        """One datagram; the kernel's drop count from its ancillary data (Linux)."""
        if not self._ovfl:
            return self.sock.recvfrom(UDP_MAX_PAYLOAD + 1)[0]
        data, anc, _, _ = self.sock.recvmsg(UDP_MAX_PAYLOAD + 1, socket.CMSG_SPACE(4))
        for level, kind, value in anc:
            if level == socket.SOL_SOCKET and kind == _SO_RXQ_OVFL and len(value) >= 4:
                self.socket_drops = struct.unpack("=I", value[:4])[0]
        return data

    @property
    def port(self) -> int:
        return int(self.sock.getsockname()[1])

    def receive(self, decoder: PacketDecoder[Any] | None, max_frames: int | None = None,
                idle_timeout_s: float = 1.0, total_timeout_s: float = 60.0,
                on_frame: Callable[[Any], None] | None = None,
                make_decoder: Callable[[bytes], PacketDecoder[Any]] | None = None
                ) -> list[Any]:
        """Decode datagrams until ``max_frames`` frames are out, the link has been idle for
        ``idle_timeout_s`` *after the first datagram*, or ``total_timeout_s`` has passed
        (which also bounds the wait for the first one); then close open frames. Ctrl-C
        (KeyboardInterrupt) stops the same way and sets :attr:`interrupted`, so what was
        received is returned, not lost. ``decoder`` None: ``make_decoder(first datagram)``
        builds it (geometry learnt from the stream); it is kept in :attr:`decoder`."""
        check_seconds(idle_timeout_s, "idle timeout")
        check_seconds(total_timeout_s, "timeout")
        if max_frames is not None and (isinstance(max_frames, bool) or max_frames < 1):
            raise ValueError(f"frames: must be >= 1, got {max_frames!r}")
        if decoder is None and make_decoder is None:
            raise ValueError("receive: needs a decoder or make_decoder")
        self.decoder = decoder
        frames: list[Any] = []
        deadline = time.monotonic() + total_timeout_s
        t_first = 0.0

        def emit(new: list[Any]) -> None:
            for f in new:
                frames.append(f)
                if on_frame:
                    on_frame(f)

        try:
            while max_frames is None or len(frames) < max_frames:
                left = deadline - time.monotonic()
                if left <= 0:
                    break
                self.sock.settimeout(min(left, idle_timeout_s) if self.datagrams else left)
                try:
                    data = self._recv()
                except TimeoutError:
                    if self.datagrams:
                        break
                    continue
                now = time.monotonic()
                if not self.datagrams:
                    t_first = now
                self.datagrams += 1
                self.bytes += len(data)
                if now > t_first:
                    self.rate_bps = 8 * self.bytes / (now - t_first)
                if self.decoder is None:
                    assert make_decoder is not None
                    try:
                        self.decoder = make_decoder(data)
                    except ValueError as exc:  # not a packet of any known geometry
                        self.unusable.append(str(exc))
                        continue
                emit(self.decoder.push_packet(data))
        except KeyboardInterrupt:
            self.interrupted = True
        if self.decoder is not None:
            emit(self.decoder.flush())
        return frames
