"""One link's DMA packets -> decoded frames: the stream's geometry and kind learnt from the
packet headers, the link policy, the chain gain divided out where the stream is decoded.

The stream is a radar cube (``OUTPUT_MODE = 0``: :class:`CubePayloadDecoder`, the cube decoded
lazily, :meth:`PayloadFrame.cube`) or the on-chip detector's records (``OUTPUT_MODE = 1``:
``host.records.RecordDecoder``, :meth:`host.records.DetectionFrame.arrays`), given or learnt
from the packet headers (the frame length, which differs between the two). Both give data in
float-reference units (the chain's gain, ``model.radar_pipeline.chain_gain``, divided out).

:class:`Receiver` is used two ways: ``radar receive`` builds its decoder from the first
datagram that fits (:meth:`Receiver.learn`); ``radar view`` pushes every datagram
(:meth:`Receiver.push`): geometry learnt again after each (re)start, sender restarts
recognised, frames missing by id counted, all reported to a :class:`LinkEvents`.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import NamedTuple, Protocol

import numpy as np

from host.records import DetectionFrame, RecordDecoder
from host.stream import (
    PacketDecoder,
    StreamStats,
    cube_frame_words,
    geometry_from_packet,
    payload_words_to_cube,
)
from host.udp import max_packet_words
from model.axis_packetizer import check_geometry
from model.config import RadarConfig
from model.detect_chain import DetectConfig
from model.radar_pipeline import PipelineParams, chain_gain

CUBE, RECORDS = "cube", "records"
"""Stream kinds: the radar cube (OUTPUT_MODE = 0) and detection records (OUTPUT_MODE = 1)."""

DetectConfigOf = Callable[[RadarConfig], DetectConfig]
"""The on-chip detector's configuration for a preset (fixes a record frame's length);
ValueError when the detector refuses that preset."""

MAX_GAP_FRAMES = 64
"""A frame-id jump larger than this is a new sender, not lost frames."""
MAX_PRESUMED_LOST = 256
"""Frame ids remembered as lost (a reordered one that arrives after all is not lost)."""


@dataclass
class PayloadFrame:
    """A radar-cube frame as it left the decoder: its payload, decoded into the cube only
    when asked (:meth:`cube`), so frames dropped to stay current cost no decode.
    ``words``: uint32 (frame_words, num_rx) in DMA order, zeros where missing; ``valid``:
    bool (frame_words,); ``problems``: as ``host.stream.Frame``; ``gain``: the chain's gain
    over the float reference, divided out by :meth:`cube`."""

    frame_id: int
    words: np.ndarray
    valid: np.ndarray
    problems: list[str]
    cfg: RadarConfig
    gain: float = 1.0

    @property
    def complete(self) -> bool:
        return bool(self.valid.all()) and not self.problems

    def cube(self) -> np.ndarray:
        """complex64 (n_virtual, n_range, n_doppler) in float-reference units
        (:func:`host.stream.payload_words_to_cube` divided by :attr:`gain`)."""
        return payload_words_to_cube(self.words, self.cfg, self.gain)


class CubePayloadDecoder(PacketDecoder[PayloadFrame]):
    """``host.stream.StreamDecoder`` with the cube decode left to the consumer
    (:class:`PayloadFrame`): same framing, counters and problems. ``gain``: the chain's
    gain over the float reference (``model.radar_pipeline.chain_gain``)."""

    def __init__(self, cfg: RadarConfig, packet_words: int, reorder_window: int = 2,
                 gain: float = 1.0) -> None:
        super().__init__(cfg.num_rx, cube_frame_words(cfg), packet_words, reorder_window)
        self.cfg = cfg
        self.gain = gain

    def _make_frame(self, fid: int, words: np.ndarray, valid: np.ndarray,
                    problems: list[str]) -> PayloadFrame:
        return PayloadFrame(fid, words, valid, problems, self.cfg, self.gain)


LinkDecoder = CubePayloadDecoder | RecordDecoder
LinkFrame = PayloadFrame | DetectionFrame


def chain_decoder(cfg: RadarConfig, packet_words: int, chain: PipelineParams,
                  dcfg: DetectConfig | None = None) -> LinkDecoder:
    """The decoder of a chain's DMA stream on ``cfg``: its detection records (``dcfg``, the
    detector's configuration, given) or its radar cube, in float-reference units (the
    chain's gain, ``model.radar_pipeline.chain_gain``, divided out). ValueError on a
    geometry the packetizer refuses."""
    gain = chain_gain(cfg, chain)
    if dcfg is not None:
        return RecordDecoder(dcfg, packet_words, gain=gain)
    return CubePayloadDecoder(cfg, packet_words, gain=gain)


class Geometry(NamedTuple):
    """What a datagram's header says about its stream: preset, PACKET_WORDS, kind."""

    cfg: RadarConfig
    packet_words: int
    kind: str


class LinkEvents(Protocol):
    """What :meth:`Receiver.push` reports as it goes (``radar view``'s link health)."""

    def on_datagram(self, nbytes: int) -> None: ...

    def on_kind(self, kind: str, max_detections: int | None = None) -> None: ...

    def on_problem(self, message: str) -> None: ...

    def on_decoder(self, stats: StreamStats, problems: list[str]) -> None:
        """The current decoder's counters and its new problem messages."""

    def retire_decoder(self, stats: StreamStats) -> None:
        """The decoder with these counters is replaced (restart or a new geometry)."""

    def on_frame(self, frame: LinkFrame, cfg: RadarConfig, packet_words: int,
                 n_packets: int, id_gap: int) -> None:
        """A decoded frame of preset ``cfg``; ``id_gap``: frames missing entirely before it
        (by frame id), -1 when it is one of those counted missing (arrived reordered)."""


class Receiver:
    """DMA packets of one link -> decoded frames in float-reference units.

    ``configs``: the presets the stream may be of (the first is assumed until a header says
    otherwise); ``packet_words``: the stream's PACKET_WORDS, or None to learn it from the
    headers; ``kind``: :data:`CUBE`, :data:`RECORDS`, or None to learn it from the headers
    too (a datagram that fits a cube frame of a preset is a cube stream, else one that fits a
    record frame of ``detect_config(preset)``); ``detect_config``: needed for records (and to
    name a record stream sent as a cube); ``chain``: the sender's chain (its gain is divided
    out; default the board's, ``PipelineParams()``); ``events``: where :meth:`push` reports.

    :meth:`push` (a live link): a sender that restarts (frame ids start again) is
    recognised by a whole frame's worth of packets in a row belonging to frames already
    closed; then, or on :meth:`idle` / :meth:`restart`, a fresh decoder takes over and the
    geometry is learnt again from the next datagram that fits (the decoder waiting for it
    assumes the most PACKET_WORDS that fit a UDP datagram). Never raises on bad data.
    """

    def __init__(self, configs: Sequence[RadarConfig], packet_words: int | None = None,
                 kind: str | None = CUBE, detect_config: DetectConfigOf | None = None,
                 chain: PipelineParams | None = None, events: LinkEvents | None = None
                 ) -> None:
        if kind not in (CUBE, RECORDS, None):
            raise ValueError(f"stream kind {kind!r}: not {CUBE!r}, {RECORDS!r} or None")
        if kind != CUBE and detect_config is None:
            raise ValueError("a record stream needs the detector's configuration")
        if not configs:
            raise ValueError("a receiver needs at least one preset")
        self.configs = [configs[0]] + [c for c in configs[1:] if c != configs[0]]
        self.cfg = self.configs[0]
        self.fixed_packet_words = packet_words
        self.fixed_kind = kind
        self.kind = kind or CUBE
        self.detect_config = detect_config
        self.chain = chain or PipelineParams()
        self.events = events
        self.decoder: LinkDecoder | None = None
        self._learning = self._learns()
        self._unfit_said = False
        self._late_run: list[bytes] = []
        self._late_msgs: list[str] = []
        self._last_id: int | None = None
        self._presumed_lost: set[int] = set()
        self._dirty = False

    # ---- geometry -------------------------------------------------------------------------
    def frame_words(self, cfg: RadarConfig, kind: str) -> int:
        """Payload words of one frame of ``kind`` on ``cfg`` (ValueError: the detector
        refuses the preset)."""
        if kind == RECORDS:
            assert self.detect_config is not None
            return self.detect_config(cfg).frame_words
        return cube_frame_words(cfg)

    def decoder_for(self, cfg: RadarConfig, kind: str, packet_words: int) -> LinkDecoder:
        """A fresh decoder of this geometry, dividing out the chain's gain on ``cfg``
        (ValueError on a geometry the packetizer refuses)."""
        dcfg = None
        if kind == RECORDS:
            assert self.detect_config is not None
            dcfg = self.detect_config(cfg)
        return chain_decoder(cfg, packet_words, self.chain, dcfg)

    def _fits(self, data: bytes, cfg: RadarConfig, kind: str) -> int:
        """PACKET_WORDS of the stream if ``data`` is a packet of a ``kind`` stream of
        ``cfg``; ValueError why not."""
        words = self.frame_words(cfg, kind)
        _, pw = geometry_from_packet(data, [cfg], lambda _: words)
        pw = self.fixed_packet_words or pw
        check_geometry(words, pw)
        return pw

    def _cube_fit(self, data: bytes, check: bool = True) -> Geometry:
        """The cube stream ``data`` is a packet of (``check``: with PACKET_WORDS given, a
        geometry the packetizer takes); ValueError why not."""
        cfg, pw = geometry_from_packet(data, self.configs)
        pw = self.fixed_packet_words or pw
        if check:
            check_geometry(cube_frame_words(cfg), pw)
        return Geometry(cfg, pw, CUBE)

    def _record_fit(self, data: bytes, errors: list[str] | None = None) -> Geometry | None:
        for cfg in self.configs:
            try:
                return Geometry(cfg, self._fits(data, cfg, RECORDS), RECORDS)
            except ValueError as exc:
                if errors is not None:
                    errors.append(f"{cfg.name}: {exc}")
        return None

    def fit(self, data: bytes) -> Geometry:
        """The stream geometry this datagram's header fits, of :attr:`configs` and the
        given (or any) kind; ValueError saying why it fits none (a record stream sent as a
        cube and a cube stream sent as records are named: a cube stream's short last packet
        can fit a record frame too, such a packet is refused)."""
        if self.fixed_kind is None:
            try:
                return self._cube_fit(data)
            except ValueError:
                pass
            fit = self._record_fit(data) if self.detect_config else None
            if fit:
                return fit
            raise ValueError(f"datagram of {len(data)} bytes fits no cube or record stream "
                             f"of {', '.join(c.name for c in self.configs)}"
                             f"{self._max_detections_note()}")
        try:
            cube: Geometry | None = self._cube_fit(data, check=self.fixed_kind == CUBE)
            why = ""
        except ValueError as exc:
            cube, why = None, str(exc)
        if self.fixed_kind == CUBE:
            if cube:
                return cube
            rec = self._record_fit(data) if self.detect_config else None
            if rec:
                raise ValueError(f"{why}; it fits a detection-record stream of "
                                 f"{rec.cfg.name}: use --detect fpga")
            raise ValueError(why)
        errors: list[str] = []
        rec = self._record_fit(data, errors)
        is_cube = (f"it is a radar-cube stream packet of {cube.cfg.name} (leave out --detect "
                   f"fpga)") if cube else ""
        if rec and cube:      # both fit: wait for a packet that says which
            raise ValueError(f"a packet that fits records of {rec.cfg.name} but {is_cube}")
        if rec:
            return rec
        raise ValueError(is_cube or ("not a record-stream packet of " + "; ".join(errors)
                                     + " (check --max-detections)"))

    def _max_detections_note(self) -> str:
        if self.detect_config is None:
            return ""
        try:
            mx = self.detect_config(self.cfg).max_detections
        except ValueError:
            return ""
        return (f" (a record stream must have the sender's MAX_DETECTIONS, here {mx}: "
                f"--max-detections)")

    def learn(self, data: bytes) -> LinkDecoder:
        """The decoder of the stream this datagram belongs to (:meth:`fit`), which becomes
        :attr:`decoder`; ValueError when it fits none (``radar receive``'s first datagram)."""
        cfg, pw, kind = self.fit(data)
        self.decoder = self.decoder_for(cfg, kind, pw)
        self.cfg, self.kind = cfg, kind
        return self.decoder

    # ---- live link ------------------------------------------------------------------------
    @property
    def packet_words(self) -> int:
        """PACKET_WORDS the current decoder expects."""
        return self.open().packet_words

    def open(self) -> LinkDecoder:
        """The current decoder, built on first use for the assumed geometry (ValueError on
        a bad one); a given kind is announced."""
        if self.decoder is None:
            self.decoder = self._new_decoder()
            if self.fixed_kind is not None:
                self._announce()
        return self.decoder

    def _new_decoder(self, packet_words: int | None = None) -> LinkDecoder:
        pw = packet_words or self.fixed_packet_words or max_packet_words(self.cfg.num_rx)
        self._decoder_key = (self.cfg, self.kind, pw)
        return self.decoder_for(self.cfg, self.kind, pw)

    def _announce(self) -> None:
        if self.events is None:
            return
        mx = self.detect_config(self.cfg).max_detections if (
            self.kind == RECORDS and self.detect_config) else None
        self.events.on_kind(self.kind, mx)

    def _problem(self, message: str) -> None:
        if self.events is not None:
            self.events.on_problem(message)

    def _learns(self) -> bool:
        return (self.fixed_packet_words is None or len(self.configs) > 1
                or self.fixed_kind is None)

    def _learn_from(self, data: bytes) -> None:
        """Preset, PACKET_WORDS and kind from this datagram's header, when it fits; one that
        does not stays with the current decoder (which counts it as malformed), and is
        reported once per (re)start (the first datagrams may be junk)."""
        try:
            cfg, pw, kind = self.fit(data)
        except ValueError as exc:
            if not self._unfit_said:
                self._unfit_said = True
                self._problem(str(exc))
            return
        self._unfit_said = False
        self._learning = False
        if cfg != self.cfg:
            self.cfg = cfg
            self._problem(f"stream is of preset {cfg.name}")
        self.kind = kind
        self._announce()
        if (cfg, kind, pw) != self._decoder_key:
            self._retire()
            self.decoder = self._new_decoder(pw)

    def _retire(self) -> None:
        if self.events is not None and self.decoder is not None:
            self.events.retire_decoder(self.decoder.stats)

    def push(self, data: bytes) -> None:
        """One datagram (one DMA packet); its frames go to :attr:`events`."""
        dec = self.open()
        if self.events is not None:
            self.events.on_datagram(len(data))
        self._dirty = True
        if self._learning:
            self._learn_from(data)
            dec = self.open()
        late = dec.stats.late_packets
        frames: list[LinkFrame]
        try:
            frames = list(dec.push_packet(data))
        except Exception as exc:  # noqa: BLE001 - counted and shown, never a crash
            dec.stats.garbage_packets += 1
            frames = []
            dec.stream_problems.append(f"undecodable datagram: {exc}")
        if dec.stats.late_packets > late:
            # held back: if a whole frame of them follows, the sender restarted instead
            self._late_run.append(data)
            self._late_msgs += dec.stream_problems
            dec.stream_problems.clear()
        elif self._late_run:
            dec.stream_problems[:0] = self._late_msgs
            self._late_run, self._late_msgs = [], []
        if len(self._late_run) >= dec.n_packets:
            # a whole frame of packets of closed frames: the sender restarted its frame ids.
            # They were not late after all: a fresh decoder takes them again.
            replay = list(self._late_run)
            dec.stats.late_packets -= len(replay)
            for f in frames:
                self._frame(f)
            frames = []
            self._sync()
            self.restart()
            self._problem("sender restarted (frame ids started again)")
            if self._learning:
                self._learn_from(replay[0])
            for p in replay:
                frames += self.open().push_packet(p)
        for f in frames:
            self._frame(f)
        self._sync()

    def _sync(self) -> None:
        """Hand the decoder's counters and new problem messages to :attr:`events`."""
        dec = self.open()
        if self.events is not None:
            self.events.on_decoder(dec.stats, dec.stream_problems)
        dec.stream_problems.clear()  # taken: the decoder's list never reaches its cap

    def restart(self) -> None:
        """Close what is open and start a fresh decoder (sender restarted or idle)."""
        dec = self.open()
        for f in dec.flush():
            self._frame(f)
        self._sync()
        self._retire()
        self.decoder = self._new_decoder(dec.packet_words)
        self._learning = self._learns()
        self._late_run, self._late_msgs = [], []
        self._last_id = None
        self._presumed_lost.clear()
        self._dirty = False

    def idle(self) -> None:
        """The link has been quiet: flush once (no-op while nothing new arrived)."""
        if self._dirty:
            self.restart()

    def _id_gap(self, fid: int, id_bits: int) -> int:
        """Frames missing entirely between the newest id seen and ``fid`` (-1: ``fid`` was
        counted missing and arrived after all, reordered)."""
        if fid in self._presumed_lost:
            self._presumed_lost.discard(fid)
            return -1
        if self._last_id is None:
            self._last_id = fid
            return 0
        m = 1 << id_bits
        d = (fid - self._last_id) % m
        if d == 0 or d >= m // 2:  # repeated or older
            return 0
        gap = d - 1 if d <= MAX_GAP_FRAMES else 0  # a larger jump: a new sender
        self._presumed_lost.update((self._last_id + k) % m for k in range(1, gap + 1))
        if len(self._presumed_lost) > MAX_PRESUMED_LOST:
            self._presumed_lost = set(sorted(self._presumed_lost)[-MAX_PRESUMED_LOST:])
        self._last_id = fid
        return gap

    def _frame(self, f: LinkFrame) -> None:
        dec = self.open()
        gap = self._id_gap(f.frame_id, dec.id_bits)
        if self.events is not None:
            self.events.on_frame(f, self.cfg, dec.packet_words, dec.n_packets, gap)
