"""Where the view's frames come from, each on its own thread: :func:`udp_loop` (datagrams of
a UDP socket), :func:`replay_loop` (a capture's packets, or a scene's record stream from
:func:`scene_record_frames`), both into a ``host.receiver.Receiver``
(:func:`radar.view.ingest.packet_ingest`), and :func:`scene_loop` (simulated cubes straight to
the processor).
"""

from __future__ import annotations

import random
import socket
import threading
import time
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path

import numpy as np

from host.capture import CaptureInfo, read_capture
from host.receiver import Receiver
from host.stream import cube_frame_words
from host.udp import UDP_MAX_PAYLOAD
from model.axis_packetizer import packets_per_frame, words_to_bytes
from model.config import RadarConfig
from model.radar_pipeline import PipelineParams, dma_packets
from model.scene import Scene
from model.simulate import simulate_scene
from radar.view.health import LinkHealth
from radar.view.processor import Processor

IDLE_RESTART_S = 1.0
"""No datagram for this long: open frames are closed and the next packet starts afresh."""


def udp_loop(sock: socket.socket, ingest: Receiver, stop: threading.Event,
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


def replay_loop(frames: Iterable[list[bytes]], ingest: Receiver, stop: threading.Event,
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
