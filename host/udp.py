"""The paper's Gigabit Ethernet link: DMA packets as UDP datagrams (one packet each).

:class:`UdpSender` replays packets as the board would (optionally paced to a bit rate, with
injected loss, duplication and reordering for testing); :class:`UdpReceiver` feeds arriving
datagrams to a :class:`host.stream.StreamDecoder`. Both are meant for 127.0.0.1 in tests.
"""

from __future__ import annotations

import random
import socket
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field

from host.stream import Frame, StreamDecoder

UDP_MAX_PAYLOAD = 65507
"""Largest UDP payload over IPv4, bytes."""


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


class UdpSender:
    """Sends packets to ``(host, port)``; ``rate_bps`` paces the stream (None: as fast as
    the socket goes)."""

    def __init__(self, host: str, port: int, rate_bps: float | None = None,
                 impairments: Impairments | None = None) -> None:
        if rate_bps is not None and rate_bps <= 0:
            raise ValueError(f"rate_bps: must be positive, got {rate_bps}")
        self.addr = (host, port)
        self.rate_bps = rate_bps
        self.imp = impairments or Impairments()
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)

    def close(self) -> None:
        self.sock.close()

    def __enter__(self) -> UdpSender:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

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


class UdpReceiver:
    """Bound UDP socket (port 0 = an ephemeral port, see :attr:`port`)."""

    def __init__(self, host: str = "127.0.0.1", port: int = 0,
                 rcvbuf_bytes: int = 16 << 20) -> None:
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, rcvbuf_bytes)
        self.sock.bind((host, port))

    @property
    def port(self) -> int:
        return int(self.sock.getsockname()[1])

    def close(self) -> None:
        self.sock.close()

    def __enter__(self) -> UdpReceiver:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def receive(self, decoder: StreamDecoder, max_frames: int | None = None,
                idle_timeout_s: float = 1.0, total_timeout_s: float = 60.0,
                on_frame: Callable[[Frame], None] | None = None) -> list[Frame]:
        """Decode datagrams until ``max_frames`` frames are out, the link has been idle for
        ``idle_timeout_s``, or ``total_timeout_s`` has passed; then close open frames.
        Bounded in time by construction."""
        frames: list[Frame] = []
        deadline = time.monotonic() + total_timeout_s
        self.sock.settimeout(idle_timeout_s)

        def emit(new: list[Frame]) -> None:
            for f in new:
                frames.append(f)
                if on_frame:
                    on_frame(f)

        while time.monotonic() < deadline and (max_frames is None or len(frames) < max_frames):
            try:
                data, _ = self.sock.recvfrom(UDP_MAX_PAYLOAD + 1)
            except TimeoutError:
                break
            emit(decoder.push_packet(data))
        emit(decoder.flush())
        return frames
