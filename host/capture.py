"""Recorded DMA streams ("captures"): a file of packets exactly as the board sends them.

File layout (little-endian)::

    bytes 0..7   b"RDMACAP2"
    u32          num_rx (lanes per word)
    u32          packet_words (payload words per packet)
    u32          num_tx, u32 n_range, u32 n_doppler   (frame geometry)
    then per packet: u32 length in bytes, the packet's bytes (header word, payload, CRC word)

A capture of the detection-record stream (``OUTPUT_MODE = 1``, ``host.records``) starts with
b"RDMAREC3" instead and has one more u32 after n_doppler: MAX_DETECTIONS (which fixes the
record frame's length); the packets follow as above. Older captures are refused with a
one-line message naming their version: b"RDMACAP1" / b"RDMAREC2" hold packets without the
CRC word, b"RDMAREC1" the record format before the neighbour powers (8 header lanes).

``radar replay`` sends a capture over UDP one packet per datagram; ``radar receive`` decodes
datagrams with :class:`host.stream.StreamDecoder`.
"""

from __future__ import annotations

import struct
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from model.axis_packetizer import cube_to_payload, packetize, words_to_bytes
from model.config import RadarConfig
from model.reference import cube_to_dma_order

MAGIC = b"RDMACAP2"
MAGIC_RECORDS = b"RDMAREC3"
OLD_VERSIONS = {
    b"RDMACAP1": "cube capture of packets without the CRC word",
    b"RDMAREC2": "record capture of packets without the CRC word",
    b"RDMAREC1": "record capture of 8-lane record headers without the neighbour powers",
}
"""Capture versions no longer read, and why."""
_HEAD = struct.Struct("<8s5I")
_MAX_DET = struct.Struct("<I")


@dataclass(frozen=True)
class CaptureInfo:
    """Geometry stored in a capture's file header."""

    num_rx: int
    packet_words: int
    num_tx: int
    n_range: int
    n_doppler: int
    max_detections: int = 0
    """MAX_DETECTIONS of a record-stream capture; 0 for a radar-cube capture."""

    @property
    def records(self) -> bool:
        """True for a detection-record stream (OUTPUT_MODE = 1)."""
        return self.max_detections > 0

    def matches(self, cfg: RadarConfig) -> bool:
        return (self.num_rx, self.num_tx, self.n_range, self.n_doppler) == (
            cfg.num_rx, cfg.num_tx, cfg.n_range, cfg.n_doppler)

    def config(self, configs: Iterable[RadarConfig]) -> RadarConfig:
        """The configuration among ``configs`` with this capture's geometry (ValueError if
        none): the capture header carries what ``radar receive`` would otherwise need."""
        for cfg in configs:
            if self.matches(cfg):
                return cfg
        raise ValueError(f"capture geometry {self.num_tx} TX x {self.num_rx} RX, "
                         f"{self.n_range} x {self.n_doppler} matches no preset")


def frame_packets(cube: np.ndarray, cfg: RadarConfig, packet_words: int, frame_id: int
                  ) -> list[bytes]:
    """The DMA packets (bytes) of one frame.

    cube: integer-valued complex (n_virtual, n_range, n_doppler) in int16 range.
    """
    words = cube_to_payload(cube_to_dma_order(cube, cfg))
    return [words_to_bytes(p) for p in packetize(words, packet_words, frame_id)]


def write_capture(path: Path, info: CaptureInfo, packets: Iterable[bytes]) -> int:
    """Write packets to ``path``; returns the number written."""
    n = 0
    with open(path, "wb") as f:
        f.write(_HEAD.pack(MAGIC_RECORDS if info.records else MAGIC, info.num_rx,
                           info.packet_words, info.num_tx, info.n_range, info.n_doppler))
        if info.records:
            f.write(_MAX_DET.pack(info.max_detections))
        for p in packets:
            f.write(struct.pack("<I", len(p)))
            f.write(p)
            n += 1
    return n


def read_capture(path: Path) -> tuple[CaptureInfo, Iterator[bytes]]:
    """Header and an iterator over the packets of a capture; ValueError if it is not one
    (bad magic, truncated header) -- a truncated last record is reported by the iterator
    raising ValueError."""
    f = open(path, "rb")  # noqa: SIM115 - closed by the generator
    head = f.read(_HEAD.size)
    if head[:8] in OLD_VERSIONS:
        f.close()
        raise ValueError(f"{path}: capture version {head[:8].decode()} ("
                         f"{OLD_VERSIONS[head[:8]]}) is no longer read; this version reads "
                         f"{MAGIC.decode()} and {MAGIC_RECORDS.decode()}: capture it again")
    if len(head) < _HEAD.size or head[:8] not in (MAGIC, MAGIC_RECORDS):
        f.close()
        raise ValueError(f"{path}: not a DMA capture (missing {MAGIC!r} or {MAGIC_RECORDS!r} "
                         f"header)")
    _, num_rx, packet_words, num_tx, n_range, n_doppler = _HEAD.unpack(head)
    max_det = 0
    if head[:8] == MAGIC_RECORDS:
        more = f.read(_MAX_DET.size)
        if len(more) < _MAX_DET.size or not _MAX_DET.unpack(more)[0]:
            f.close()
            raise ValueError(f"{path}: record capture header truncated or MAX_DETECTIONS 0")
        (max_det,) = _MAX_DET.unpack(more)
    if not 2 <= packet_words <= 65535 or not num_rx or not num_tx:
        f.close()
        raise ValueError(f"{path}: capture header says {packet_words} payload words per "
                         f"packet, {num_rx} lanes, {num_tx} TX (packets carry 2..65535 words, "
                         f"lanes and TX >= 1): not a capture this tool wrote")
    info = CaptureInfo(num_rx, packet_words, num_tx, n_range, n_doppler, max_det)

    def packets() -> Iterator[bytes]:
        with f:
            while True:
                n = f.read(4)
                if not n:
                    return
                if len(n) < 4:
                    raise ValueError(f"{path}: truncated record length")
                (length,) = struct.unpack("<I", n)
                data = f.read(length)
                if len(data) < length:
                    raise ValueError(f"{path}: truncated packet ({len(data)} of {length} "
                                     f"bytes)")
                yield data

    return info, packets()
