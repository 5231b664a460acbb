"""DMA packet format of ``rtl/buffers/axis_packetizer.sv`` (bit-exact model, shared with the
host decoder).

A *word* is one AXI4-Stream beat of ``num_rx`` 32-bit lanes, lane 0 in the least significant
bits; each lane is a complex sample ``{Q[31:16], I[15:0]}``. In numpy a sequence of words is
a ``uint32`` array of shape ``(n_words, num_rx)``; on the wire (host side) it is the
little-endian bytes of that array (``words_to_bytes``).

Frame payload order (docs/design.md 3.2): for tx, for range bin r, for Doppler bin d: one word =
``num_rx`` lanes of bin ``(tx, r, d)``; ``frame_words = num_tx * n_range * n_doppler``.

Each frame is cut into packets of ``packet_words`` payload words (the last one shorter when
``packet_words`` does not divide ``frame_words``). With ``header=True`` every packet starts
with one header word (layout below, docs/buffers.md) and ends with one CRC word (lane 0: the
CRC-32 of the header and payload wire bytes, ``model.packet_crc``; other lanes zero), and
TLAST closes every packet.

Header lane 0 (always present, meaningful at ``num_rx == 1``)::

    [31:24] MAGIC 0xA5
    [23:16] frame id, low 8 bits (frames since reset)
    [15:4]  packet sequence number within the frame, 0 .. n_packets-1 (at most 4096)
    [3]     FRAMING  sticky framing error (misplaced input TLAST) seen by the packet's end
    [2]     OVERFLOW sticky overflow (any word dropped since reset) by the packet's end
    [1]     DROP     words of this packet were dropped: payload is short, do not use it
    [0]     LAST     this packet ends its frame

Extension lanes (present when ``num_rx`` is large enough; further lanes are zero)::

    lane 1: [31:16] words dropped from this packet, [15:0] payload words that follow
    lane 2: frame id, 32 bits
    lane 3: [31] DAMAGED (the frame was damaged upstream: chirps lost at the ADC side were
            zero-filled), [30:16] packets per frame, [15:0] packet sequence number
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

import numpy as np

from model.packet_crc import packet_crc

MAGIC = 0xA5
FLAG_LAST = 1 << 0
FLAG_DROP = 1 << 1
FLAG_OVERFLOW = 1 << 2
FLAG_FRAMING = 1 << 3
MAX_PACKETS_PER_FRAME = 4096


@dataclass(frozen=True)
class PacketHeader:
    """Decoded header word. Extension fields are ``None`` when ``num_rx`` is too small."""

    frame_id: int  # low 8 bits, or the full 32-bit id when lane 2 is present
    seq: int  # packet number within its frame
    last: bool = False
    drop: bool = False
    overflow: bool = False
    framing: bool = False
    length: int | None = None  # payload words (lane 1)
    dropped: int | None = None  # words dropped from this packet (lane 1)
    n_packets: int | None = None  # packets per frame (lane 3)
    damaged: bool = False  # frame damaged upstream, zero-filled chirps (lane 3 bit 31)

    @property
    def flags(self) -> int:
        return ((FLAG_LAST if self.last else 0) | (FLAG_DROP if self.drop else 0)
                | (FLAG_OVERFLOW if self.overflow else 0) | (FLAG_FRAMING if self.framing else 0))


def packets_per_frame(frame_words: int, packet_words: int) -> int:
    """Number of packets one frame is cut into."""
    return -(-frame_words // packet_words)


def shortest_packet_words(frame_words: int) -> int:
    """The shortest packet length :func:`check_geometry` accepts for a frame of
    ``frame_words`` words: 2, or fewer words would make more than MAX_PACKETS_PER_FRAME
    packets (the top's PACKET_WORDS_MIN)."""
    return max(2, -(-frame_words // MAX_PACKETS_PER_FRAME))


def check_geometry(frame_words: int, packet_words: int) -> None:
    """Raise ValueError for a packet geometry the RTL refuses (same limits as its $fatal)."""
    if not 2 <= packet_words <= 65535:
        raise ValueError(f"packet_words={packet_words} not in 2..65535")
    if not 1 <= frame_words <= 1 << 30:
        raise ValueError(f"frame_words={frame_words} not in 1..2^30")
    if packets_per_frame(frame_words, packet_words) > MAX_PACKETS_PER_FRAME:
        raise ValueError(f"{packets_per_frame(frame_words, packet_words)} packets per frame "
                         f"> {MAX_PACKETS_PER_FRAME}: raise packet_words")


def header_word(hdr: PacketHeader, num_rx: int, n_packets: int, length: int,
                dropped: int = 0) -> np.ndarray:
    """Header word as lanes: uint32 ``(num_rx,)``. ``hdr.frame_id`` is the full frame id."""
    lanes = np.zeros(max(num_rx, 4), dtype=np.uint32)
    lanes[0] = ((MAGIC << 24) | ((hdr.frame_id & 0xFF) << 16) | ((hdr.seq & 0xFFF) << 4)
                | hdr.flags)
    lanes[1] = ((dropped & 0xFFFF) << 16) | (length & 0xFFFF)
    lanes[2] = hdr.frame_id & 0xFFFFFFFF
    lanes[3] = ((int(hdr.damaged) << 31) | ((n_packets & 0x7FFF) << 16)
                | (hdr.seq & 0xFFFF))
    return lanes[:num_rx].copy()


def crc_word(packet: np.ndarray) -> np.ndarray:
    """The CRC word that closes a packet: uint32 lanes ``(num_rx,)``, lane 0 the CRC-32 of
    ``packet`` (uint32 ``(n_words, num_rx)``: header and payload words), other lanes 0."""
    packet = np.asarray(packet, dtype=np.uint32)
    word = np.zeros(packet.shape[1], np.uint32)
    word[0] = packet_crc(words_to_bytes(packet))
    return word


def seal(body: np.ndarray) -> np.ndarray:
    """A packet as sent: ``body`` (uint32 ``(n_words, num_rx)``, header and payload words)
    followed by its CRC word."""
    body = np.asarray(body, dtype=np.uint32)
    return np.vstack([body, crc_word(body)[None, :]])


def crc_error(data: bytes | memoryview, word_bytes: int) -> str | None:
    """Why a packet's wire bytes (header, payload, CRC word; ``word_bytes`` = 4 * num_rx a
    word) fail their CRC, or None when intact. Never raises."""
    view = memoryview(data)
    if len(view) < 2 * word_bytes or len(view) % word_bytes:
        return f"{len(view)} bytes are not a header, payload and CRC word"
    trailer = view[len(view) - word_bytes:]
    if any(trailer[4:]):
        return "CRC word's lanes 1.. are not zero"
    sent = int.from_bytes(trailer[:4], "little")
    got = packet_crc(view[:len(view) - word_bytes])
    return None if got == sent else f"CRC mismatch (sent 0x{sent:08x}, computed 0x{got:08x})"


def parse_header(word: np.ndarray) -> PacketHeader:
    """Decode a header word (uint32 lanes ``(num_rx,)``); ValueError if the magic is wrong."""
    lanes = np.asarray(word, dtype=np.uint32).reshape(-1)
    w0 = int(lanes[0])
    if w0 >> 24 != MAGIC:
        raise ValueError(f"bad packet magic 0x{w0 >> 24:02x} (word 0x{w0:08x})")
    frame_id = (w0 >> 16) & 0xFF
    length = dropped = n_packets = None
    damaged = False
    seq = (w0 >> 4) & 0xFFF
    if lanes.size > 1:
        length, dropped = int(lanes[1]) & 0xFFFF, int(lanes[1]) >> 16
    if lanes.size > 2:
        frame_id = int(lanes[2])
    if lanes.size > 3:
        n_packets, seq = (int(lanes[3]) >> 16) & 0x7FFF, int(lanes[3]) & 0xFFFF
        damaged = bool(int(lanes[3]) >> 31)
    return PacketHeader(frame_id=frame_id, seq=seq, last=bool(w0 & FLAG_LAST),
                        drop=bool(w0 & FLAG_DROP), overflow=bool(w0 & FLAG_OVERFLOW),
                        framing=bool(w0 & FLAG_FRAMING), length=length, dropped=dropped,
                        n_packets=n_packets, damaged=damaged)


def packetize(frame: np.ndarray, packet_words: int, frame_id: int = 0, header: bool = True,
              overflow: bool = False, framing: bool = False, damaged: bool = False
              ) -> list[np.ndarray]:
    """Packets of one loss-free frame, exactly as the RTL sends them.

    frame: uint32 ``(frame_words, num_rx)`` payload words. Returns a list of uint32 arrays
    ``(n_words, num_rx)``, one per TLAST-closed packet: header word, payload, CRC word if
    ``header``, else the payload alone.
    ``overflow``/``framing`` are the sticky flags to stamp in every header of this frame.
    """
    frame = np.asarray(frame, dtype=np.uint32)
    if frame.ndim != 2:
        raise ValueError("frame must be (frame_words, num_rx)")
    frame_words, num_rx = frame.shape
    check_geometry(frame_words, packet_words)
    n_packets = packets_per_frame(frame_words, packet_words)
    out = []
    for seq in range(n_packets):
        payload = frame[seq * packet_words:(seq + 1) * packet_words]
        if header:
            hdr = PacketHeader(frame_id=frame_id, seq=seq, last=seq == n_packets - 1,
                               overflow=overflow, framing=framing, damaged=damaged)
            out.append(seal(np.vstack([header_word(hdr, num_rx, n_packets,
                                                   len(payload))[None, :], payload])))
        else:
            out.append(payload.copy())
    return out


def packetize_stream(frames: Iterable[np.ndarray], packet_words: int | Sequence[int],
                     header: bool = True, first_frame_id: int = 0) -> list[np.ndarray]:
    """Packets of consecutive loss-free frames (frame ids counting from ``first_frame_id``).
    ``packet_words``: one length for every frame, or frame k's length (the RTL's run-time
    ``cfg_packet_words`` as it stood at the frame's first word)."""
    out: list[np.ndarray] = []
    for k, frame in enumerate(frames):
        pw = packet_words if isinstance(packet_words, int) else packet_words[k]
        out.extend(packetize(frame, pw, first_frame_id + k, header))
    return out


@dataclass
class DecodedFrame:
    """One frame reassembled from packets.

    words: uint32 ``(frame_words, num_rx)`` payload (zeros where missing);
    valid: bool ``(frame_words,)`` True where the word arrived in an intact packet.
    """

    frame_id: int
    words: np.ndarray
    valid: np.ndarray
    errors: list[str] = field(default_factory=list)

    @property
    def complete(self) -> bool:
        return bool(self.valid.all()) and not self.errors


def depacketize(packets: Sequence[np.ndarray], frame_words: int, packet_words: int,
                num_rx: int, crc_checked: bool = False) -> list[DecodedFrame]:
    """Reassemble frames from header-carrying packets (uint32 ``(n, num_rx)`` each: header,
    payload, CRC word).

    Detects and reports, never raises on, CRC mismatches and bad magic (the packet is not
    used, so its frame misses it; the message goes to the damaged frame that misses the
    packet its untrusted header names), lost/repeated/reordered packets, packets with dropped
    words (DROP flag), wrong lengths and truncated frames. A packet's payload is placed by
    its sequence number, so intact packets of a damaged frame are still usable.
    ``crc_checked``: the caller has already dropped the packets that fail their CRC
    (``host.stream``), skip the check.
    """
    n_packets = packets_per_frame(frame_words, packet_words)
    frames: list[DecodedFrame] = []
    cur: DecodedFrame | None = None
    seen: set[int] = set()
    expect_seq = 0
    unused: list[tuple[int | None, int | None, str]] = []  # (frame id, seq, why) as named

    def close() -> None:
        if cur is not None:
            if len(seen) != n_packets:
                missing = sorted(set(range(n_packets)) - seen)
                cur.errors.append(f"frame {cur.frame_id}: missing packets {missing[:8]}"
                                  f"{'...' if len(missing) > 8 else ''}")
            if cur.errors:  # the unused packets that explain what this frame misses
                mine = [u for u in unused if u[0] in (None, cur.frame_id)
                        and u[1] not in seen]
                cur.errors[:0] = [m for _, _, m in mine]
                unused[:] = [u for u in unused if u not in mine]
            frames.append(cur)

    for i, pkt in enumerate(packets):
        pkt = np.asarray(pkt, dtype=np.uint32).reshape(-1, num_rx)
        if pkt.shape[0] == 0:
            continue
        bad = None if crc_checked else crc_error(words_to_bytes(pkt), 4 * num_rx)
        try:
            hdr = parse_header(pkt[0])
        except ValueError as exc:
            bad = bad or str(exc)
            hdr = None
        if bad is not None:
            named = (None, None) if hdr is None else (hdr.frame_id, hdr.seq)
            unused.append((*named, f"packet {i}: {bad}, not used"))
            continue
        assert hdr is not None
        fid = hdr.frame_id
        if cur is None or (fid & 0xFF) != (cur.frame_id & 0xFF) or (
                num_rx > 2 and fid != cur.frame_id):
            close()
            cur = DecodedFrame(fid, np.zeros((frame_words, num_rx), np.uint32),
                               np.zeros(frame_words, bool))
            seen = set()
            expect_seq = 0
        payload = pkt[1:-1]
        if hdr.seq != expect_seq:
            cur.errors.append(f"frame {fid}: packet seq {hdr.seq}, expected {expect_seq}")
        expect_seq = hdr.seq + 1
        if hdr.seq >= n_packets:
            cur.errors.append(f"frame {fid}: packet seq {hdr.seq} out of range")
            continue
        if hdr.seq in seen:
            cur.errors.append(f"frame {fid}: packet {hdr.seq} repeated")
            continue
        start = hdr.seq * packet_words
        nominal = min(packet_words, frame_words - start)
        if hdr.damaged and not any("damaged upstream" in e for e in cur.errors):
            cur.errors.append(f"frame {fid}: damaged upstream (chirps lost at the ADC side "
                              f"were zero-filled)")
        if hdr.drop:
            cur.errors.append(f"frame {fid}: packet {hdr.seq} lost "
                              f"{hdr.dropped if hdr.dropped is not None else '?'} words")
            seen.add(hdr.seq)
            continue
        if payload.shape[0] != nominal or (hdr.length is not None and hdr.length != nominal):
            cur.errors.append(f"frame {fid}: packet {hdr.seq} has {payload.shape[0]} words, "
                              f"expected {nominal}")
            seen.add(hdr.seq)
            continue
        cur.words[start:start + nominal] = payload
        cur.valid[start:start + nominal] = True
        seen.add(hdr.seq)
    close()
    return frames


def words_to_bytes(words: np.ndarray) -> bytes:
    """Host wire format: little-endian 32-bit lanes, lane 0 first, word after word."""
    return np.ascontiguousarray(words, dtype="<u4").tobytes()


def bytes_to_words(data: bytes, num_rx: int) -> np.ndarray:
    """Inverse of :func:`words_to_bytes`: uint32 ``(n_words, num_rx)``."""
    return np.frombuffer(data, dtype="<u4").reshape(-1, num_rx).astype(np.uint32)


def pack_iq(samples: np.ndarray) -> np.ndarray:
    """Integer-valued complex samples -> uint32 ``{Q[31:16], I[15:0]}`` (same shape)."""
    s = np.asarray(samples)
    i = np.real(s).astype(np.int64) & 0xFFFF
    q = np.imag(s).astype(np.int64) & 0xFFFF
    return ((q << 16) | i).astype(np.uint32)


def unpack_iq(words: np.ndarray) -> np.ndarray:
    """uint32 ``{Q, I}`` -> complex64 with the int16 I/Q values (same shape)."""
    w = np.asarray(words, dtype=np.uint32)
    i = (w & 0xFFFF).astype(np.uint16).view(np.int16).astype(np.float32)
    q = (w >> 16).astype(np.uint16).view(np.int16).astype(np.float32)
    return (i + 1j * q).astype(np.complex64)


def cube_to_payload(cube: np.ndarray) -> np.ndarray:
    """Doppler-FFT cube -> frame payload words.

    cube: integer-valued complex ``(num_tx, n_range, n_doppler, num_rx)``.
    Returns uint32 ``(num_tx * n_range * n_doppler, num_rx)`` in DMA payload order.
    """
    cube = np.asarray(cube)
    return pack_iq(cube.reshape(-1, cube.shape[-1]))


def payload_to_cube(words: np.ndarray, num_tx: int, n_range: int,
                    n_doppler: int) -> np.ndarray:
    """Inverse of :func:`cube_to_payload`: complex64 ``(num_tx, n_range, n_doppler, num_rx)``."""
    w = np.asarray(words, dtype=np.uint32)
    return unpack_iq(w).reshape(num_tx, n_range, n_doppler, w.shape[-1])
