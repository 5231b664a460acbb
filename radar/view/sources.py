"""Where the view's frames come from, each on its own thread.

- :class:`PacketIngest`: DMA packets (UDP datagrams or a replayed capture) -> decoded frames,
  link counters, sender-restart detection. Never raises on bad data.
- :class:`Processor`: newest decoded cube -> host processing (CFAR, angles, point cloud,
  optional GNN) -> :class:`radar.view.feed.ViewFrame`. A cube that arrives while the previous
  one is still being processed replaces the waiting one (counted as "not shown").
- :func:`udp_loop`, :func:`replay_loop`, :func:`scene_loop`: the three producers.

A detection-record stream (on-chip detection) plugs in as another producer that builds
:class:`ViewFrame` objects with ``cloud`` set and ``cube=None`` and calls ``Feed.publish``.
"""

from __future__ import annotations

import random
import socket
import threading
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from host.capture import read_capture
from host.pipeline import DetectionParams, process_cube
from host.stream import Frame, StreamDecoder, geometry_from_packet
from host.udp import UDP_MAX_PAYLOAD, max_packet_words
from model.config import RadarConfig
from model.radar_pipeline import PipelineParams, chain_gain
from radar.view.feed import Feed, ViewFrame
from radar.view.health import LinkHealth

IDLE_RESTART_S = 1.0
"""No datagram for this long: open frames are closed and the next packet starts afresh."""


def channel_power_sum(cube: np.ndarray) -> np.ndarray:
    """sum_v |cube|^2, float (n_range, n_doppler): ``model.reference.range_doppler_power``
    computed on the interleaved I/Q floats (no complex abs), about 3x faster."""
    if cube.dtype != np.complex64 or not cube.flags.c_contiguous:
        return np.sum(np.abs(cube) ** 2, axis=0)
    iq = cube.view(np.float32)  # (n_virtual, n_range, 2 * n_doppler)
    return np.einsum("vrd,vrd->rd", iq, iq).reshape(*cube.shape[1:], 2).sum(axis=-1)


class Processor:
    """Host processing of the newest cube on a worker thread.

    ``gain``: divide cubes by it before processing (the FPGA chain's gain; 1 for model
    cubes). ``detect_objects``: cloud, ego speed -> GNN objects, or None for no GNN.
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
        self._slot: tuple[int, np.ndarray, float, RadarConfig] | None = None
        self._skipped = 0
        self.errors = 0

    def submit(self, frame_id: int, cube: np.ndarray, scale: float = 1.0,
               cfg: RadarConfig | None = None) -> None:
        """Hand over a cube complex (n_virtual, n_range, n_doppler) of configuration ``cfg``
        (default: :attr:`cfg`); ``cube * scale`` is in reference units. The processor owns
        the cube from now on (scaled in place on its own thread, so the ingest thread stays
        free for the link)."""
        with self._cond:
            if self._slot is not None:
                self._skipped += 1
            self._slot = (frame_id, cube, scale, cfg or self.cfg)
            self._cond.notify()

    def run(self, stop: threading.Event) -> None:
        while not stop.is_set():
            if not self.feed.wait_wanted(0.2):
                continue
            with self._cond:
                if self._slot is None:
                    self._cond.wait(0.2)
                if self._slot is None:
                    continue
                (frame_id, cube, scale, cfg), self._slot = self._slot, None
                skipped, self._skipped = self._skipped, 0
            self.feed.taken()
            try:
                if scale != 1.0:
                    cube *= np.float32(scale) if cube.dtype == np.complex64 else scale
                self._process(frame_id, cube, skipped, cfg)
            except Exception as exc:  # noqa: BLE001 - a bad frame must not stop the view
                self.errors += 1
                with self.health.lock:
                    self.health.problems.append(f"frame {frame_id}: processing failed: {exc}")

    def _process(self, frame_id: int, cube: np.ndarray, skipped: int,
                 cfg: RadarConfig | None = None) -> None:
        cfg = cfg or self.cfg
        cloud = process_cube(cube, cfg, self.params, frame=frame_id)
        objects = (self.detect_objects(cloud, ego_speed_mps=self.ego_speed_mps)
                   if self.detect_objects is not None and len(cloud) else [])
        frame = ViewFrame(seq=self.feed.next_seq(), frame_id=frame_id, cfg=cfg,
                          cloud=cloud, cube=cube, nci=channel_power_sum(cube),
                          objects=objects, source=self.source)
        self.health.on_shown(len(cloud), len(objects), skipped)
        self.feed.publish(frame)


class PacketIngest:
    """DMA packets -> frames -> :class:`Processor`, keeping :class:`LinkHealth` current.

    A sender that restarts (frame ids start again) is recognised by a whole frame's worth
    of packets in a row belonging to frames already closed; then, or after
    :data:`IDLE_RESTART_S` without datagrams (:meth:`idle`), a fresh decoder takes over.
    ``gain``: the chain's cube gain (decoded cubes are divided by it).
    ``packet_words``: the stream's PACKET_WORDS, or None to learn it (as ``radar receive``
    does) from the header of the first datagram after each (re)start; the decoder waiting
    for that datagram assumes the most that fit a UDP datagram. ``configs``: the presets the
    stream may be of (default: ``cfg`` only); with more than one, the preset is learnt from
    the headers too (``cfg`` first), and ``gain`` follows the learnt preset.
    """

    def __init__(self, cfg: RadarConfig, packet_words: int | None, health: LinkHealth,
                 processor: Processor, gain: float, use_damaged: bool = True,
                 configs: Sequence[RadarConfig] | None = None) -> None:
        self.cfg = cfg
        self.configs = [cfg] + [c for c in configs or [] if c != cfg]
        self.fixed_packet_words = packet_words
        self.health = health
        self.processor = processor
        self.gain = gain
        self.use_damaged = use_damaged
        self.decoder = self._new_decoder()  # ValueError on a bad geometry
        self._learn = self._learning()
        self._late_run: list[bytes] = []
        self._late_msgs: list[str] = []
        self._last_id: int | None = None
        self._presumed_lost: set[int] = set()
        self._dirty = False

    @property
    def packet_words(self) -> int:
        """PACKET_WORDS the current decoder expects."""
        return self.decoder.packet_words

    def _new_decoder(self, packet_words: int | None = None) -> StreamDecoder:
        pw = packet_words or self.fixed_packet_words or max_packet_words(self.cfg.num_rx)
        return StreamDecoder(self.cfg, pw)

    def _learning(self) -> bool:
        return self.fixed_packet_words is None or len(self.configs) > 1

    def _learn_geometry(self, data: bytes) -> None:
        """Preset and PACKET_WORDS from this datagram's header, when it is a packet of one of
        :attr:`configs`; a datagram that is not stays with the decoder (which counts it as
        malformed)."""
        try:
            cfg, pw = geometry_from_packet(data, self.configs)
        except ValueError:
            return
        self._learn = False
        pw = self.fixed_packet_words or pw
        if cfg != self.cfg:
            self.cfg = cfg
            self.gain = chain_gain(cfg, PipelineParams())
            with self.health.lock:
                self.health.problems.append(f"stream is of preset {cfg.name}")
        if cfg != self.decoder.cfg or pw != self.decoder.packet_words:
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

    def _frame(self, f: Frame) -> None:
        self.health.on_frame(f, self.packet_words, self.decoder.n_packets, self._id_gap(
            f.frame_id))
        if f.complete or self.use_damaged:
            self.processor.submit(f.frame_id, f.cube, scale=1.0 / self.gain, cfg=self.cfg)


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


def load_replay(path: Path, cfg: RadarConfig) -> tuple[int, list[list[bytes]]]:
    """(packet_words, packets grouped by frame) of a capture; ValueError when it does not
    match the preset or is damaged."""
    info, packets = read_capture(path)
    if not info.matches(cfg):
        raise ValueError(f"{path}: capture geometry {info} does not match preset "
                         f"{cfg.name!r} (use --preset)")
    pkts = list(packets)
    n = StreamDecoder(cfg, info.packet_words).n_packets
    frames = [pkts[i:i + n] for i in range(0, len(pkts), n)]
    if not frames:
        raise ValueError(f"{path}: capture holds no packets")
    return info.packet_words, frames


def replay_loop(frames: list[list[bytes]], ingest: PacketIngest, stop: threading.Event,
                fps: float, loop: bool = True, loss: float = 0.0, seed: int = 0) -> None:
    """Feed a capture's packets frame by frame at ``fps`` frames/s (0: as fast as they
    decode); ``loss``: probability of dropping each packet (as ``radar replay --loss``).
    Each pass after the first is a sender restart (frame ids start again)."""
    rng = random.Random(seed)
    t0 = time.monotonic()
    k = 0
    passes = 0
    while not stop.is_set():
        if passes and k % len(frames) == 0:
            ingest.restart()
        for p in frames[k % len(frames)]:
            if loss and rng.random() < loss:
                continue
            ingest.push(p)
        k += 1
        if k % len(frames) == 0:
            passes += 1
            if not loop:
                ingest.restart()
                return
        if fps > 0:
            ahead = t0 + k / fps - time.monotonic()
            if ahead > 0:
                stop.wait(ahead)


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
