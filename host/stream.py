"""Incremental decoding of the FPGA's DMA stream into radar cubes.

The packet format (header word layout, payload order) is defined once, in
``model.axis_packetizer`` (mirrored by ``rtl/buffers/axis_packetizer.sv``); this module groups
arriving packets into frames and hands each frame to ``model.axis_packetizer.depacketize``, which
places every intact packet by its sequence number and reports what is wrong.

Input comes either as packets (one UDP datagram = one TLAST-closed DMA packet, the paper's
Ethernet link) via :meth:`StreamDecoder.push_packet`, or as a raw byte stream without packet
boundaries (a DMA dump) via :meth:`StreamDecoder.push_bytes`, which splits packets by their
header and resynchronises on the header magic after garbage.

Every packet's CRC word is checked before its payload is used
(``model.axis_packetizer.crc_error``): a packet that fails is counted
(``StreamStats.crc_errors``) and never used, so its frame misses it and is damaged (with the
CRC failure among its problems); an intact copy of the same packet (a duplicated datagram)
still completes the frame.

Nothing here raises on bad data: every problem ends up in a frame's ``problems`` (frame
damaged: lost, repeated, truncated, reordered or corrupt packets) or in the decoder's
``stream_problems`` (bytes that belong to no frame, late packets, hardware sticky flags).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import Generic, Protocol, TypeVar

import numpy as np

from model.array import tx_slots
from model.axis_packetizer import (
    MAGIC,
    PacketHeader,
    check_geometry,
    crc_error,
    depacketize,
    packets_per_frame,
    parse_header,
)
from model.config import RadarConfig

MAX_STREAM_PROBLEMS = 1000
"""Stream-level problem messages kept (counters keep counting past it)."""


def cube_frame_words(cfg: RadarConfig) -> int:
    """Payload words of one radar-cube frame, num_tx * n_range_bins * n_doppler (a real
    ADC's frame keeps range bins 0..n_range/2-1)."""
    return cfg.num_tx * cfg.n_range_bins * cfg.n_doppler


def geometry_from_packet(data: bytes, configs: Iterable[RadarConfig],
                         frame_words_of: Callable[[RadarConfig], int] = cube_frame_words
                         ) -> tuple[RadarConfig, int]:
    """The radar configuration and PACKET_WORDS a DMA packet belongs to, from its header
    alone (its CRC checked at each candidate word width): the datagram length and header
    lane 1 (payload words) give the word width, hence num_rx; lane 3 gives the packets per
    frame, which with the payload length fixes PACKET_WORDS for a preset's frame size
    (``frame_words_of(cfg)``: the cube's by default, a record stream's for ``host.records``).
    ValueError when no configuration fits."""
    tried = []
    for cfg in configs:
        wb = 4 * cfg.num_rx
        if len(data) < wb or len(data) % wb or cfg.num_rx < 4:
            tried.append(cfg.name)
            continue
        words = np.frombuffer(data, dtype="<u4").reshape(-1, cfg.num_rx)
        try:
            hdr = parse_header(words[0])
        except ValueError:
            tried.append(cfg.name)
            continue
        frame_words = frame_words_of(cfg)
        if (hdr.length != len(words) - 2 or not hdr.n_packets
                or crc_error(data, wb) is not None):
            tried.append(cfg.name)
            continue
        n = hdr.n_packets
        if hdr.seq < n - 1:
            pw = hdr.length
        elif n > 1 and (frame_words - hdr.length) % (n - 1) == 0:
            pw = (frame_words - hdr.length) // (n - 1)
        elif n == 1:
            pw = max(hdr.length, 2)
        else:
            tried.append(cfg.name)
            continue
        if pw >= 2 and packets_per_frame(frame_words, pw) == n:
            return cfg, pw
        tried.append(cfg.name)
    raise ValueError(f"packet of {len(data)} bytes fits none of the configurations "
                     f"{', '.join(tried)} (word width, payload length and packets per frame "
                     f"from its header)")


def payload_words_to_cube(words: np.ndarray, cfg: RadarConfig, gain: float = 1.0
                          ) -> np.ndarray:
    """Frame payload, uint32 (frame_words, num_rx) in DMA order -> radar cube complex64
    (n_virtual, n_range_bins, n_doppler), divided by ``gain`` (the chain's gain over the float
    reference, ``model.radar_pipeline.chain_gain``: float-reference units; 1.0: LSB). Same
    result as ``model.reference.dma_order_to_cube(model.axis_packetizer.payload_to_cube(
    ...)) / gain``, several times faster on a ``full`` frame: the 32-bit {Q, I} words are
    transposed to channel order while still words (one strided copy), then widened
    contiguously. The payload's TX blocks are chirp slots; the cube's channels count TXs by
    index (``model.array.slot_channels``)."""
    w = np.ascontiguousarray(words, dtype="<u4").reshape(
        cfg.num_tx, cfg.n_range_bins, cfg.n_doppler, cfg.num_rx)
    if cfg.tx_sequence != tuple(range(cfg.num_tx)):
        w = w[tx_slots(cfg)]                    # slot of each TX index
    t = np.empty((cfg.num_tx, cfg.num_rx, cfg.n_range_bins, cfg.n_doppler), np.uint32)
    t[...] = w.transpose(0, 3, 1, 2)
    iq = np.empty(t.shape + (2,), np.float32)
    iq[...] = t.view("<i2").reshape(t.shape + (2,))  # I: low half of the word, Q: high
    if gain != 1.0:
        iq /= np.float32(gain)
    return iq.view(np.complex64).reshape(cfg.cube_shape)


@dataclass
class Frame:
    """One decoded frame.

    ``cube``: complex64 (n_virtual, n_range_bins, n_doppler) in the payload's LSB, zeros
    where words are missing.
    ``valid``: bool (num_tx, n_range_bins, n_doppler): True where the word arrived intact.
    ``problems``: what is wrong with the frame (empty when ``complete``).
    """

    frame_id: int
    cube: np.ndarray
    valid: np.ndarray
    problems: list[str]

    @property
    def complete(self) -> bool:
        return bool(self.valid.all()) and not self.problems


class DecodedFrameLike(Protocol):
    """What every decoded frame offers (a cube :class:`Frame` or a record frame)."""

    frame_id: int
    problems: list[str]

    @property
    def complete(self) -> bool: ...


FrameT = TypeVar("FrameT", bound=DecodedFrameLike)


@dataclass
class StreamStats:
    """Counters of a decoder's lifetime."""

    packets: int = 0
    bytes: int = 0
    garbage_packets: int = 0
    garbage_bytes: int = 0
    late_packets: int = 0
    frames_complete: int = 0
    frames_damaged: int = 0
    reordered_packets: int = 0
    duplicate_packets: int = 0
    crc_errors: int = 0
    """Packets whose CRC word did not match (corrupt on the way: not used)."""
    hw_overflow_seen: bool = False
    hw_framing_seen: bool = False


@dataclass
class _Open:
    packets: list[np.ndarray] = field(default_factory=list)
    seqs: set[int] = field(default_factory=set)
    full_id: int = 0
    # (seq, message) of the packets that failed their CRC naming this frame
    corrupt: list[tuple[int, str]] = field(default_factory=list)


class PacketDecoder(Generic[FrameT]):
    """Groups DMA packets into frames of ``frame_words`` payload words of ``num_rx`` lanes
    (loss, repeat, reorder and truncation detection); subclasses turn a frame's words into
    their frame type (:meth:`_make_frame`): the radar cube (:class:`StreamDecoder`) or
    detection records (``host.records.RecordDecoder``).

    ``packet_words``: payload words per packet (the packetizer's PACKET_WORDS).
    ``reorder_window``: a frame stays open until a packet of a frame this many ids later
    arrives, so packets reordered across a frame boundary are still placed; a frame that has
    all its packets closes at once.
    """

    def __init__(self, num_rx: int, frame_words: int, packet_words: int,
                 reorder_window: int = 2) -> None:
        self.num_rx = num_rx
        self.word_bytes = 4 * num_rx
        self.frame_words = frame_words
        check_geometry(self.frame_words, packet_words)
        self.packet_words = packet_words
        self.n_packets = packets_per_frame(self.frame_words, packet_words)
        self.reorder_window = max(1, reorder_window)
        # frame id width on the wire: 32 bits when header lane 2 exists, else 8 bits
        self.id_bits = 32 if num_rx > 2 else 8
        self.stats = StreamStats()
        self.stream_problems: list[str] = []
        self._open: dict[int, _Open] = {}
        self._closed: list[int] = []  # recently closed ids, to recognise late packets
        # CRC failures naming a frame not open yet (its first packets were the corrupt ones)
        self._corrupt_pending: dict[int, list[tuple[int, str]]] = {}
        self._buf = bytearray()

    def _make_frame(self, fid: int, words: np.ndarray, valid: np.ndarray,
                    problems: list[str]) -> FrameT:
        """A decoded frame from its payload, uint32 (frame_words, num_rx) (zeros where
        missing), ``valid`` bool (frame_words,) and the packet problems found."""
        raise NotImplementedError

    # ---- helpers --------------------------------------------------------------------------
    def _problem(self, msg: str) -> None:
        if len(self.stream_problems) < MAX_STREAM_PROBLEMS:
            self.stream_problems.append(msg)

    def _newer(self, a: int, b: int) -> int:
        """Serial-number distance a - b in the wire id width (positive: a is newer)."""
        m = 1 << self.id_bits
        d = (a - b) % m
        return d - m if d >= m // 2 else d

    def _nominal_words(self, seq: int) -> int:
        start = seq * self.packet_words
        return max(0, min(self.packet_words, self.frame_words - start))

    # ---- packet input ---------------------------------------------------------------------
    def push_packet(self, data: bytes) -> list[FrameT]:
        """One DMA packet (header word, payload, CRC word; little-endian lanes). Returns the
        frames this packet completed or pushed out of the reorder window."""
        self.stats.packets += 1
        self.stats.bytes += len(data)
        if len(data) < self.word_bytes:
            self.stats.garbage_packets += 1
            self._problem(f"packet of {len(data)} bytes is shorter than one "
                          f"{self.word_bytes}-byte word")
            return []
        if len(data) % self.word_bytes:
            self._problem(f"packet of {len(data)} bytes is not a whole number of "
                          f"{self.word_bytes}-byte words (truncated)")
            data = data[:len(data) - len(data) % self.word_bytes]
        words = np.frombuffer(data, dtype="<u4").reshape(-1, self.num_rx).astype(np.uint32)
        try:
            hdr = parse_header(words[0])
        except ValueError as exc:
            self.stats.garbage_packets += 1
            self._problem(f"packet dropped: {exc}")
            return []
        bad = crc_error(data, self.word_bytes)
        if bad is not None:
            self._corrupt(hdr, bad)
            return []
        if hdr.overflow and not self.stats.hw_overflow_seen:
            self.stats.hw_overflow_seen = True
            self._problem(f"hardware OVERFLOW flag set (sticky) from frame {hdr.frame_id}")
        if hdr.framing and not self.stats.hw_framing_seen:
            self.stats.hw_framing_seen = True
            self._problem(f"hardware FRAMING flag set (sticky) from frame {hdr.frame_id}")
        fid = hdr.frame_id
        if fid in self._closed:
            self.stats.late_packets += 1
            self._problem(f"late or repeated packet {hdr.seq} of already closed frame {fid}")
            return []
        out: list[FrameT] = []
        # frames too old for the reorder window close now, incomplete
        for old in sorted(self._open, key=lambda k: self._newer(k, fid)):
            if self._newer(fid, old) >= self.reorder_window:
                out.append(self._close(old))
        if fid not in self._open:
            self._open[fid] = _Open(full_id=fid, corrupt=self._corrupt_pending.pop(fid, []))
        entry = self._open[fid]
        entry.packets.append(words)
        if hdr.seq < self.n_packets:
            entry.seqs.add(hdr.seq)
        if len(entry.seqs) == self.n_packets and len(entry.packets) >= self.n_packets:
            out.append(self._close(fid))
        return out

    def _corrupt(self, hdr: PacketHeader, why: str) -> None:
        """A packet that failed its CRC: counted, never used. Its frame is damaged by the
        packet's absence; the frame its (untrusted) header names gets the CRC message when
        it closes without an intact packet of that number (so a corrupt header never
        damages another frame, and an intact duplicate still completes the frame)."""
        self.stats.crc_errors += 1
        msg = f"frame {hdr.frame_id}: packet {hdr.seq} failed its CRC ({why}), not used"
        entry = self._open.get(hdr.frame_id)
        if entry is not None:
            entry.corrupt.append((hdr.seq, msg))
        elif hdr.frame_id not in self._closed:
            self._corrupt_pending.setdefault(hdr.frame_id, []).append((hdr.seq, msg))
            while len(self._corrupt_pending) > 4 * self.reorder_window:
                del self._corrupt_pending[next(iter(self._corrupt_pending))]
        self._problem(f"packet {hdr.seq} of frame {hdr.frame_id} dropped: {why}")

    def _close(self, fid: int) -> FrameT:
        entry = self._open.pop(fid)
        self._closed.append(fid)
        del self._closed[:-4 * self.reorder_window]
        packets = self._in_order(entry.packets)
        # depacketize reports what is still wrong: gaps, conflicting repeats, bad lengths
        # (every packet here passed its CRC in push_packet)
        decoded = depacketize(packets, self.frame_words, self.packet_words, self.num_rx,
                              crc_checked=True)
        if len(decoded) != 1:  # cannot happen: all packets carry the same frame id
            problems = [f"frame {fid}: packets split into {len(decoded)} groups"]
            words = np.zeros((self.frame_words, self.num_rx), np.uint32)
            valid = np.zeros(self.frame_words, bool)
        else:
            problems, words, valid = decoded[0].errors, decoded[0].words, decoded[0].valid
        if problems:  # CRC failures that explain packets this frame misses
            problems = [m for seq, m in entry.corrupt if seq not in entry.seqs] + problems
        frame = self._make_frame(fid, words, valid, list(problems))
        if frame.complete:
            self.stats.frames_complete += 1
        else:
            self.stats.frames_damaged += 1
            if not frame.problems:
                frame.problems.append(f"frame {fid}: {int((~valid).sum())} words missing")
        return frame

    def _in_order(self, packets: list[np.ndarray]) -> list[np.ndarray]:
        """A frame's packets sorted by sequence number with exact duplicates removed: a
        link that only reordered or duplicated packets loses nothing (counted in
        ``stats``). Differing packets with the same number stay, for depacketize to report."""
        seqs = [parse_header(p[0]).seq for p in packets]
        order = sorted(range(len(packets)), key=lambda i: (seqs[i], i))
        if order != sorted(order):
            self.stats.reordered_packets += sum(
                1 for a, b in zip(seqs, seqs[1:], strict=False) if b < a)
        out: list[np.ndarray] = []
        last_seq = None
        for i in order:
            if seqs[i] == last_seq and np.array_equal(packets[i], out[-1]):
                self.stats.duplicate_packets += 1
                continue
            out.append(packets[i])
            last_seq = seqs[i]
        return out

    def flush(self) -> list[FrameT]:
        """Close every open frame (end of stream), oldest first."""
        ids = sorted(self._open, key=lambda k: self._newer(k, next(iter(self._open))))
        return [self._close(k) for k in ids]

    # ---- raw byte stream input ------------------------------------------------------------
    def push_bytes(self, data: bytes) -> list[FrameT]:
        """Raw stream bytes (no packet boundaries): packets are cut by their header's
        payload length (lane 1, or the nominal length for num_rx < 2) plus the CRC word.
        After garbage, and after a packet that fails its CRC (its length may be what was
        corrupted), the decoder resynchronises byte by byte on a plausible header (magic,
        sequence number and length consistent with the frame geometry); skipped bytes are
        counted."""
        self._buf.extend(data)
        out: list[FrameT] = []
        wb = self.word_bytes
        while len(self._buf) >= wb:
            length = self._header_length(bytes(self._buf[:wb]))
            if length is None:
                self._resync()
                continue
            need = (2 + length) * wb
            if len(self._buf) < need:
                break
            packet = bytes(self._buf[:need])
            corrupt = self.stats.crc_errors
            out.extend(self.push_packet(packet))
            # a corrupt packet: resynchronise from its second word, else take it whole
            del self._buf[:wb if self.stats.crc_errors > corrupt else need]
        return out

    def _header_length(self, word: bytes) -> int | None:
        """Payload words announced by a plausible header word, else None."""
        lanes = np.frombuffer(word, dtype="<u4")
        w0 = int(lanes[0])
        if w0 >> 24 != MAGIC:
            return None
        seq = (w0 >> 4) & 0xFFF if lanes.size < 4 else int(lanes[3]) & 0xFFFF
        if seq >= self.n_packets:
            return None
        if lanes.size > 3 and (int(lanes[3]) >> 16) & 0x7FFF != self.n_packets:
            return None
        nominal = self._nominal_words(seq)
        if lanes.size > 1:
            length = int(lanes[1]) & 0xFFFF
            return length if length <= nominal else None
        return nominal

    def _resync(self) -> None:
        """Drop bytes up to the next byte that could be the magic of a header's lane 0."""
        idx = self._buf.find(bytes([MAGIC]), 4)
        n = idx - 3 if idx >= 0 else max(1, len(self._buf) - 3)
        if not self.stream_problems or not self.stream_problems[-1].startswith("skipped"):
            self._problem("skipped bytes without a packet header (resynchronising)")
        self.stats.garbage_bytes += n
        del self._buf[:n]

    def finish(self) -> list[FrameT]:
        """End of a raw stream: leftover bytes are reported, open frames closed."""
        if self._buf:
            self._problem(f"{len(self._buf)} trailing bytes do not form a whole packet "
                          f"(truncated)")
            self.stats.garbage_bytes += len(self._buf)
            self._buf.clear()
        return self.flush()


class StreamDecoder(PacketDecoder[Frame]):
    """Groups DMA packets into frames and decodes them into radar cubes.

    ``cfg``: radar configuration (cube shape, lanes). ``packet_words``: payload words per
    packet (the packetizer's PACKET_WORDS). ``reorder_window``: see :class:`PacketDecoder`.
    """

    def __init__(self, cfg: RadarConfig, packet_words: int, reorder_window: int = 2) -> None:
        super().__init__(cfg.num_rx, cube_frame_words(cfg), packet_words, reorder_window)
        self.cfg = cfg

    def _make_frame(self, fid: int, words: np.ndarray, valid: np.ndarray,
                    problems: list[str]) -> Frame:
        cfg = self.cfg
        return Frame(frame_id=fid, cube=payload_words_to_cube(words, cfg),
                     valid=valid.reshape(cfg.num_tx, cfg.n_range_bins, cfg.n_doppler),
                     problems=problems)
