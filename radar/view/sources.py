"""Where the view's frames come from, each on its own thread.

- :class:`PacketIngest`: DMA packets (UDP datagrams or a replayed capture) -> decoded frames,
  link counters, sender-restart detection. Never raises on bad data. The stream is a radar
  cube (``OUTPUT_MODE = 0``: :class:`CubePayloadDecoder`, the cube decoded lazily) or the
  on-chip detector's records (``OUTPUT_MODE = 1``: ``host.records.RecordDecoder``), given or
  learnt from the packet headers (the frame length, which differs between the two).
- :class:`Processor`: newest decoded frame -> host processing (cube: CFAR, angles, point
  cloud; records: ``host.record_points``; optional GNN) -> :class:`radar.view.feed.ViewFrame`.
  A frame that arrives while the previous one is still being processed replaces the waiting
  one (counted as "not shown").
- :func:`udp_loop`, :func:`replay_loop`, :func:`scene_loop`: the producers (a scene with
  on-chip detection is replayed from its record packets, :func:`scene_record_frames`).
"""

from __future__ import annotations

import random
import socket
import threading
import time
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from host.capture import CaptureInfo, read_capture
from host.pipeline import DetectionParams, process_cube_nci
from host.record_points import process_records
from host.records import (
    DetectionFrame,
    RecordDecoder,
    inside_map,
    outside_problem,
    record_arrays,
)
from host.stream import (
    PacketDecoder,
    cube_frame_words,
    geometry_from_packet,
    payload_words_to_cube,
)
from host.udp import UDP_MAX_PAYLOAD, max_packet_words
from model.axis_packetizer import packets_per_frame, words_to_bytes
from model.config import RadarConfig
from model.detect_chain import DetectConfig
from model.radar_pipeline import PipelineParams, chain_gain, dma_packets
from model.scene import Scene
from model.simulate import simulate_scene
from radar.common import note_compile
from radar.view.feed import Feed, ViewFrame
from radar.view.health import LinkHealth

IDLE_RESTART_S = 1.0
"""No datagram for this long: open frames are closed and the next packet starts afresh."""

CUBE, RECORDS = "cube", "records"
"""Stream kinds: the radar cube (OUTPUT_MODE = 0) and detection records (OUTPUT_MODE = 1)."""

DetectConfigOf = Callable[[RadarConfig], DetectConfig]
"""The on-chip detector's configuration for a preset (fixes a record frame's length)."""


def channel_power_sum(cube: np.ndarray) -> np.ndarray:
    """sum_v |cube|^2, float (n_range, n_doppler): ``model.reference.range_doppler_power``
    computed on the interleaved I/Q floats (no complex abs), about 3x faster."""
    if cube.dtype != np.complex64 or not cube.flags.c_contiguous:
        return np.sum(np.abs(cube) ** 2, axis=0)
    iq = cube.view(np.float32)  # (n_virtual, n_range, 2 * n_doppler)
    return np.einsum("vrd,vrd->rd", iq, iq).reshape(*cube.shape[1:], 2).sum(axis=-1)


@dataclass
class PayloadFrame:
    """A radar-cube frame as it left the decoder: its payload, decoded into the cube only
    when the view shows it (:meth:`cube`), so frames dropped to stay current cost no
    decode. ``words``: uint32 (frame_words, num_rx) in DMA order, zeros where missing;
    ``valid``: bool (frame_words,); ``problems``: as ``host.stream.Frame``."""

    frame_id: int
    words: np.ndarray
    valid: np.ndarray
    problems: list[str]
    cfg: RadarConfig

    @property
    def complete(self) -> bool:
        return bool(self.valid.all()) and not self.problems

    def cube(self) -> np.ndarray:
        """complex64 (n_virtual, n_range, n_doppler), LSB
        (:func:`host.stream.payload_words_to_cube`)."""
        return payload_words_to_cube(self.words, self.cfg)


class CubePayloadDecoder(PacketDecoder[PayloadFrame]):
    """``host.stream.StreamDecoder`` with the cube decode left to the consumer
    (:class:`PayloadFrame`): same framing, counters and problems."""

    def __init__(self, cfg: RadarConfig, packet_words: int, reorder_window: int = 2) -> None:
        super().__init__(cfg.num_rx, cube_frame_words(cfg), packet_words, reorder_window)
        self.cfg = cfg

    def _make_frame(self, fid: int, words: np.ndarray, valid: np.ndarray,
                    problems: list[str]) -> PayloadFrame:
        return PayloadFrame(fid, words, valid, problems, self.cfg)


@dataclass
class _CubeJob:
    frame_id: int
    cube: np.ndarray | PayloadFrame
    scale: float
    cfg: RadarConfig


@dataclass
class _RecordJob:
    frame_id: int
    frame: DetectionFrame
    gain: float
    cfg: RadarConfig


class Processor:
    """Host processing of the newest frame on a worker thread.

    ``detect_objects``: cloud, ego speed -> GNN objects, or None for no GNN.
    """

    def __init__(self, cfg: RadarConfig, feed: Feed, health: LinkHealth,
                 params: DetectionParams | None = None,
                 detect_objects: Callable[..., list[dict[str, Any]]] | None = None,
                 ego_speed_mps: float = 0.0, source: str = "") -> None:
        self.cfg = cfg
        self.feed = feed
        self.health = health
        self.params = params or DetectionParams()
        self.detect_objects = detect_objects
        self.ego_speed_mps = ego_speed_mps
        self.source = source
        self._cond = threading.Condition()
        self._slot: _CubeJob | _RecordJob | None = None
        self._skipped = 0
        self.errors = 0

    def _put(self, job: _CubeJob | _RecordJob) -> None:
        with self._cond:
            if self._slot is not None:
                self._skipped += 1
            self._slot = job
            self._cond.notify()

    def submit(self, frame_id: int, cube: np.ndarray | PayloadFrame, scale: float = 1.0,
               cfg: RadarConfig | None = None) -> None:
        """Hand over a cube complex (n_virtual, n_range, n_doppler) of configuration ``cfg``
        (default: :attr:`cfg`), or a :class:`PayloadFrame` to decode it from; ``cube *
        scale`` is in reference units. The processor owns the cube from now on (decoded and
        scaled in place on its own thread, so the ingest thread stays free for the link)."""
        self._put(_CubeJob(frame_id, cube, scale, cfg or self.cfg))

    def submit_records(self, frame: DetectionFrame, gain: float,
                       cfg: RadarConfig | None = None) -> None:
        """Hand over a record frame (its intact leading records are processed); ``gain``:
        the chain's gain over the float reference (``record_arrays``)."""
        self._put(_RecordJob(frame.frame_id, frame, gain, cfg or self.cfg))

    def run(self, stop: threading.Event) -> None:
        while not stop.is_set():
            if not self.feed.wait_wanted(0.2):
                continue
            with self._cond:
                if self._slot is None:
                    self._cond.wait(0.2)
                if self._slot is None:
                    continue
                job, self._slot = self._slot, None
                skipped, self._skipped = self._skipped, 0
            self.feed.taken()
            try:
                if isinstance(job, _RecordJob):
                    self._process_records(job, skipped)
                else:
                    cube = job.cube.cube() if isinstance(job.cube, PayloadFrame) else job.cube
                    if job.scale != 1.0:
                        cube *= (np.float32(job.scale) if cube.dtype == np.complex64
                                 else job.scale)
                    self._process(job.frame_id, cube, skipped, job.cfg)
            except Exception as exc:  # noqa: BLE001 - a bad frame must not stop the view
                self.errors += 1
                with self.health.lock:
                    self.health.problems.append(f"frame {job.frame_id}: processing failed: "
                                                f"{exc}")

    def _objects(self, cloud: Any) -> list[dict[str, Any]]:
        return (self.detect_objects(cloud, ego_speed_mps=self.ego_speed_mps)
                if self.detect_objects is not None and len(cloud) else [])

    def _process(self, frame_id: int, cube: np.ndarray, skipped: int,
                 cfg: RadarConfig | None = None) -> None:
        cfg = cfg or self.cfg
        cloud, nci = process_cube_nci(cube, cfg, self.params, frame_id)
        objects = self._objects(cloud)
        frame = ViewFrame(seq=self.feed.next_seq(), frame_id=frame_id, cfg=cfg,
                          cloud=cloud, cube=cube, nci=nci, objects=objects,
                          source=self.source)
        self.health.on_shown(len(cloud), len(objects), skipped)
        self.feed.publish(frame)

    def _process_records(self, job: _RecordJob, skipped: int) -> None:
        cfg, f = job.cfg, job.frame
        arr, dropped = inside_map(
            record_arrays(f.records[:f.usable_records], cfg.n_virtual, job.gain), cfg)
        if dropped:                     # corrupt words that still looked like records
            with self.health.lock:
                self.health.problems.append(outside_problem(job.frame_id, dropped, cfg))
        note_compile("view")                # the kernels may compile now (once per checkout)
        cloud = process_records(arr, cfg, self.params, frame=job.frame_id)
        objects = self._objects(cloud)
        frame = ViewFrame(seq=self.feed.next_seq(), frame_id=job.frame_id, cfg=cfg,
                          cloud=cloud, records=arr, objects=objects, source=self.source)
        self.health.on_shown(len(cloud), len(objects), skipped)
        self.feed.publish(frame)


class PacketIngest:
    """DMA packets -> frames -> :class:`Processor`, keeping :class:`LinkHealth` current.

    A sender that restarts (frame ids start again) is recognised by a whole frame's worth
    of packets in a row belonging to frames already closed; then, or after
    :data:`IDLE_RESTART_S` without datagrams (:meth:`idle`), a fresh decoder takes over.
    ``gain``: the chain's cube gain (decoded cubes are divided by it; records likewise).
    ``packet_words``: the stream's PACKET_WORDS, or None to learn it (as ``radar receive``
    does) from the header of the first datagram after each (re)start; the decoder waiting
    for that datagram assumes the most that fit a UDP datagram. ``configs``: the presets the
    stream may be of (default: ``cfg`` only); with more than one, the preset is learnt from
    the headers too (``cfg`` first), and ``gain`` follows the learnt preset.
    ``kind``: :data:`CUBE`, :data:`RECORDS`, or None to learn it from the headers as well
    (a datagram that fits a cube frame of a preset is a cube stream, else one that fits a
    record frame of ``detect_config(preset)``); ``detect_config``: needed for records.
    """

    def __init__(self, cfg: RadarConfig, packet_words: int | None, health: LinkHealth,
                 processor: Processor, gain: float, use_damaged: bool = True,
                 configs: Sequence[RadarConfig] | None = None, kind: str | None = CUBE,
                 detect_config: DetectConfigOf | None = None) -> None:
        if kind not in (CUBE, RECORDS, None):
            raise ValueError(f"stream kind {kind!r}: not {CUBE!r}, {RECORDS!r} or None")
        if kind != CUBE and detect_config is None:
            raise ValueError("a record stream needs the detector's configuration")
        self.cfg = cfg
        self.configs = [cfg] + [c for c in configs or [] if c != cfg]
        self.fixed_packet_words = packet_words
        self.fixed_kind = kind
        self.kind = kind or CUBE
        self.detect_config = detect_config
        self.health = health
        self.processor = processor
        self.gain = gain
        self.use_damaged = use_damaged
        self.decoder = self._new_decoder()  # ValueError on a bad geometry
        if kind is not None:
            self._announce()
        self._learn = self._learning()
        self._unfit_said = False
        self._late_run: list[bytes] = []
        self._late_msgs: list[str] = []
        self._last_id: int | None = None
        self._presumed_lost: set[int] = set()
        self._dirty = False

    @property
    def packet_words(self) -> int:
        """PACKET_WORDS the current decoder expects."""
        return self.decoder.packet_words

    def _frame_words(self, cfg: RadarConfig, kind: str) -> int:
        if kind == RECORDS:
            assert self.detect_config is not None
            return self.detect_config(cfg).frame_words
        return cube_frame_words(cfg)

    def _new_decoder(self, packet_words: int | None = None
                     ) -> CubePayloadDecoder | RecordDecoder:
        pw = packet_words or self.fixed_packet_words or max_packet_words(self.cfg.num_rx)
        self._decoder_key = (self.cfg, self.kind, pw)
        if self.kind == RECORDS:
            assert self.detect_config is not None
            return RecordDecoder(self.detect_config(self.cfg), pw)
        return CubePayloadDecoder(self.cfg, pw)

    def _announce(self) -> None:
        mx = (self.detect_config(self.cfg).max_detections
              if self.kind == RECORDS and self.detect_config else None)
        self.health.on_kind(self.kind, mx)

    def _learning(self) -> bool:
        return (self.fixed_packet_words is None or len(self.configs) > 1
                or self.fixed_kind is None)

    def _fit(self, data: bytes) -> tuple[RadarConfig, int, str] | None:
        """(preset, PACKET_WORDS, kind) this datagram's header fits, or None."""
        kinds = [self.fixed_kind] if self.fixed_kind else [CUBE, RECORDS]
        for kind in kinds:
            def words_of(c: RadarConfig, kind: str = kind) -> int:
                try:
                    return self._frame_words(c, kind)
                except ValueError:  # a detector setting this preset refuses: fits nothing
                    return 0
            try:
                cfg, pw = geometry_from_packet(data, self.configs, words_of)
            except ValueError:
                continue
            return cfg, pw, kind
        return None

    def _learn_geometry(self, data: bytes) -> None:
        """Preset, PACKET_WORDS and stream kind from this datagram's header, when it is a
        packet of one of :attr:`configs`; a datagram that is not stays with the decoder
        (which counts it as malformed)."""
        fit = self._fit(data)
        if fit is None:
            if not self._unfit_said:  # once per (re)start: the first datagrams may be junk
                self._unfit_said = True
                mx = ""
                if self.fixed_kind != CUBE and self.detect_config is not None:
                    try:
                        mx = (f" (a record stream must have the sender's MAX_DETECTIONS, "
                              f"here {self.detect_config(self.cfg).max_detections}: "
                              f"--max-detections)")
                    except ValueError:
                        mx = ""
                with self.health.lock:
                    self.health.problems.append(
                        f"datagram of {len(data)} bytes fits no "
                        f"{self.fixed_kind or 'cube or record'} stream of "
                        f"{', '.join(c.name for c in self.configs)}{mx}")
            return
        self._unfit_said = False
        cfg, pw, kind = fit
        self._learn = False
        pw = self.fixed_packet_words or pw
        if cfg != self.cfg:
            self.cfg = cfg
            self.gain = chain_gain(cfg, PipelineParams())
            with self.health.lock:
                self.health.problems.append(f"stream is of preset {cfg.name}")
        self.kind = kind
        self._announce()
        if (cfg, kind, pw) != self._decoder_key:
            self.health.retire_decoder(self.decoder.stats)
            self.decoder = self._new_decoder(pw)

    def push(self, data: bytes) -> None:
        """One datagram (one DMA packet)."""
        self.health.on_datagram(len(data))
        self._dirty = True
        if self._learn:
            self._learn_geometry(data)
        dec = self.decoder
        late = dec.stats.late_packets
        try:
            frames = dec.push_packet(data)
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
            with self.health.lock:
                self.health.problems.append("sender restarted (frame ids started again)")
            if self._learn:
                self._learn_geometry(replay[0])
            for p in replay:
                frames += self.decoder.push_packet(p)
        for f in frames:
            self._frame(f)
        self._sync()

    def _sync(self) -> None:
        """Hand the decoder's counters and new problem messages to the health record."""
        dec = self.decoder
        self.health.on_decoder(dec.stats, dec.stream_problems)
        dec.stream_problems.clear()  # taken: the decoder's list never reaches its cap

    def restart(self) -> None:
        """Close what is open and start a fresh decoder (sender restarted or idle)."""
        for f in self.decoder.flush():
            self._frame(f)
        self._sync()
        self.health.retire_decoder(self.decoder.stats)
        self.decoder = self._new_decoder(self.decoder.packet_words)
        self._learn = self._learning()
        self._late_run, self._late_msgs = [], []
        self._last_id = None
        self._presumed_lost.clear()
        self._dirty = False

    def idle(self) -> None:
        """The link has been quiet: flush once (no-op while nothing new arrived)."""
        if self._dirty:
            self.restart()

    def _id_gap(self, fid: int) -> int:
        """Frames missing entirely between the newest id seen and ``fid``."""
        if fid in self._presumed_lost:  # arrived after all (reordered): not lost
            self._presumed_lost.discard(fid)
            with self.health.lock:
                self.health.frames_lost -= 1
                self.health.packets_lost -= self.decoder.n_packets
            return 0
        if self._last_id is None:
            self._last_id = fid
            return 0
        m = 1 << self.decoder.id_bits
        d = (fid - self._last_id) % m
        if d == 0 or d >= m // 2:  # repeated or older
            return 0
        gap = d - 1 if d <= 64 else 0  # a jump of more than 64 frames: a new sender
        self._presumed_lost.update((self._last_id + k) % m for k in range(1, gap + 1))
        if len(self._presumed_lost) > 256:
            self._presumed_lost = set(sorted(self._presumed_lost)[-256:])
        self._last_id = fid
        return gap

    def _frame(self, f: PayloadFrame | DetectionFrame) -> None:
        self.health.on_frame(f, self.packet_words, self.decoder.n_packets, self._id_gap(
            f.frame_id))
        if isinstance(f, DetectionFrame):
            tr = f.trailer
            self.health.on_record_frame(len(f.records), f.detections, f.truncated,
                                        bool(tr and tr.truncated_sticky))
            if f.complete or self.use_damaged:
                self.processor.submit_records(f, self.gain, cfg=self.cfg)
        elif f.complete or self.use_damaged:
            self.processor.submit(f.frame_id, f, scale=1.0 / self.gain, cfg=self.cfg)


def udp_loop(sock: socket.socket, ingest: PacketIngest, stop: threading.Event,
             idle_restart_s: float = IDLE_RESTART_S) -> None:
    """Receive datagrams on a bound UDP socket until ``stop``."""
    sock.settimeout(0.1)
    last = time.monotonic()
    while not stop.is_set():
        try:
            data, _ = sock.recvfrom(UDP_MAX_PAYLOAD + 1)
        except TimeoutError:
            if time.monotonic() - last > idle_restart_s:
                ingest.idle()
            continue
        except OSError:
            if stop.is_set():
                return
            time.sleep(0.05)
            continue
        last = time.monotonic()
        ingest.push(data)


def load_replay(path: Path, cfg: RadarConfig, frame_words: int | None = None
                ) -> tuple[int, list[list[bytes]]]:
    """(packet_words, packets grouped by frame) of a capture whose frames are ``frame_words``
    payload words long (default: the cube's); ValueError when it does not match the preset
    or is damaged."""
    info, packets = read_capture(path)
    if not info.matches(cfg):
        raise ValueError(f"{path}: capture geometry {info} does not match preset "
                         f"{cfg.name!r} (use --preset)")
    n = packets_per_frame(frame_words or cube_frame_words(cfg), info.packet_words)
    frames = group_frames(packets, n)
    if not frames:
        raise ValueError(f"{path}: capture holds no packets")
    return info.packet_words, frames


def capture_info(path: Path) -> CaptureInfo:
    """A capture's header (stream kind, geometry); ValueError when it is not a capture."""
    info, packets = read_capture(path)
    close = getattr(packets, "close", None)
    if close:
        close()
    return info


def group_frames(packets: Iterable[bytes], n_packets: int) -> list[list[bytes]]:
    """Consecutive packets, ``n_packets`` per frame."""
    pkts = list(packets)
    return [pkts[i:i + n_packets] for i in range(0, len(pkts), n_packets)]


def scene_record_frames(scene: Scene, chain: PipelineParams, n_frames: int
                        ) -> Iterator[list[bytes]]:
    """The on-chip detector's record stream of frames 0..n_frames-1 of a simulated scene:
    the bit-accurate model of the chain in ``OUTPUT_MODE = 1`` (``chain``: output_mode 1,
    its ``detect`` configuration) and the packetizer framing, as wire bytes grouped by
    frame, one frame at a time (each frame's chain starts from reset: the trailer's
    hardware-sticky truncation flag covers that frame; the view keeps its own sticky flag)."""
    cfg = scene.config
    for k in range(n_frames):
        packets = dma_packets([simulate_scene(scene, frame_index=k).samples], cfg, chain, k)
        yield [words_to_bytes(p) for p in packets]


def replay_loop(frames: Iterable[list[bytes]], ingest: PacketIngest, stop: threading.Event,
                fps: float, loop: bool = True, loss: float = 0.0, seed: int = 0) -> None:
    """Feed a capture's packets frame by frame at ``fps`` frames/s (0: as fast as they
    decode); ``loss``: probability of dropping each packet (as ``radar replay --loss``).
    Each pass after the first is a sender restart (frame ids start again). ``frames``: the
    packets of each frame (a list, or an iterator taken as it produces them on the first
    pass and kept for the next ones)."""

    def schedule() -> Iterator[tuple[bool, list[bytes]]]:
        """(a pass after the first starts here, packets) of each frame to send."""
        kept: list[list[bytes]] = []
        for f in frames:
            kept.append(f)
            yield False, f
        while loop and kept:
            for i, f in enumerate(kept):
                yield i == 0, f

    rng = random.Random(seed)
    t0 = time.monotonic()
    for k, (restart, packets) in enumerate(schedule(), 1):
        if stop.is_set():
            return
        if restart:
            ingest.restart()
        for p in packets:
            if loss and rng.random() < loss:
                continue
            ingest.push(p)
        if fps > 0:
            ahead = t0 + k / fps - time.monotonic()
            if ahead > 0:
                stop.wait(ahead)
    if not stop.is_set():
        ingest.restart()  # the end of a replay that does not loop: close what is open


def scene_loop(make_cube: Callable[[int], np.ndarray], n_frames: int, processor: Processor,
               health: LinkHealth, stop: threading.Event, fps: float) -> None:
    """Simulated frames 0..n_frames-1, repeated; ``make_cube(k)``: frame k's cube in
    reference units."""
    t0 = time.monotonic()
    k = 0
    while not stop.is_set():
        cube = make_cube(k % n_frames)
        health.on_cube_frame()
        with health.lock:
            health.last_frame_id = k
        processor.submit(k, cube)
        k += 1
        if fps > 0:
            ahead = t0 + k / fps - time.monotonic()
            if ahead > 0:
                stop.wait(ahead)
