"""``radar view``: serve the live view (:mod:`radar.view`) of a UDP stream, a replayed
capture or a scene.

    radar view --replay FILE.dmacap [--fps 20] [--loss P]   a capture, looped
    radar view --udp-port P [--preset P | --radar PROFILE]  what `radar replay`/the board sends
    radar view --scene table1 [--preset P | --radar PROFILE] simulated frames
    ... [--host 127.0.0.1] [--port 8050] [--gnn] [--foxglove [PORT]]

The stream is the radar cube or, with on-chip detection (``OUTPUT_MODE = 1``), the
detector's records: a capture says which in its header (``RDMAREC3``), a UDP stream is
recognised by its frame length (records need the sender's ``--max-detections``), a scene
sends records with ``--detect fpga`` (bit-accurate model of the chain).

The page is at http://HOST:PORT/; ``--foxglove`` also serves the frames to Foxglove
(``radar.view.foxglove``) on HOST. Binding to an address other than loopback needs
``--allow-remote`` (neither has authentication).
"""

from __future__ import annotations

import argparse
import asyncio
import ipaddress
import sys
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from host.capture import read_capture
from host.receiver import CUBE, RECORDS
from host.udp import UdpReceiver
from model.config import PRESETS, RadarConfig, get_preset
from model.radar_pipeline import PipelineParams
from model.simulate import simulate_scene
from radar import common
from radar.commands.detect import add_fpga_options, detect_config_of
from radar.common import (
    CliError,
    add_detection_options,
    add_radar_option,
    check,
    check_source,
    count,
    detection_params,
    ego_speed_mps,
    port,
    radar_of,
    refuse,
    scene_of,
)
from radar.sources import get_source
from radar.view.feed import Feed
from radar.view.health import LinkHealth
from radar.view.ingest import packet_ingest
from radar.view.processor import Processor
from radar.view.server import ViewServer
from radar.view.sources import (
    capture_info,
    load_replay,
    replay_loop,
    scene_loop,
    scene_record_frames,
    udp_loop,
)

DEFAULT_PORT = 8050
DEFAULT_FOXGLOVE_PORT = 8765
"""``--foxglove``'s port (Foxglove's own default)."""


def is_loopback(host: str) -> bool:
    """True for 127.0.0.0/8, ::1 and ``localhost``."""
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def preset_of_capture(path: Path) -> RadarConfig:
    """The preset whose geometry matches a capture's header."""
    info, packets = read_capture(path)
    close = getattr(packets, "close", None)
    if close:
        close()
    for name in sorted(PRESETS):
        cfg = get_preset(name)
        if info.matches(cfg):
            return cfg
    raise ValueError(f"{path}: no preset has the capture's geometry {info} (a radar "
                     f"profile's capture: give its --radar)")


def _kind_of_replay(args: argparse.Namespace, path: Path) -> str:
    """The capture's stream kind (its header's magic), checked against ``--detect``."""
    info = capture_info(path)
    kind = RECORDS if info.records else CUBE
    if args.detect == "host" and kind == RECORDS:
        raise CliError(f"--detect host: {path} is a detection-record capture (RDMAREC3, "
                       f"MAX_DETECTIONS {info.max_detections}); leave --detect out")
    if args.detect == "fpga" and kind == CUBE:
        raise CliError(f"--detect fpga: {path} is a radar-cube capture, not records")
    if kind == RECORDS:
        args.max_detections = info.max_detections  # the capture's, not the option's
    return kind


def _refuse_misfits(args: argparse.Namespace) -> None:
    """The options that do not apply to the chosen source: one-line CliError."""
    if not args.replay:
        refuse(args, ("no_loop",), "without --replay")
    if not args.scene:
        refuse(args, ("frames", "backend"), "without --scene")
    if not (args.replay or args.scene):
        refuse(args, ("fps", "loss", "seed"), "to a UDP stream (the sender sets its pace)")
    else:
        refuse(args, ("udp_host", "packet_words"), "without a UDP stream (--udp-port)")
    if args.detector != "paper":
        refuse(args, ("threshold_db",), "to --detector " + args.detector
               + " (it is the paper detector's threshold)")


def _gnn(args: argparse.Namespace) -> Callable[..., list[dict[str, Any]]] | None:
    if not args.gnn:
        return None
    print("radar view: loading the GNN (torch)", file=sys.stderr, flush=True)
    from gnn.infer import detect_objects

    return detect_objects


def build(args: argparse.Namespace, stop: threading.Event
          ) -> tuple[Feed, LinkHealth, list[threading.Thread], str]:
    """Feed, health, the (not yet started) producer threads and a description of the
    source, from parsed ``radar view`` options. Raises CliError on bad input."""
    feed, health = Feed(), LinkHealth()
    port(args.port, "--port")
    port(args.udp_port, "--udp-port")
    _refuse_misfits(args)
    check(args.fps, "--fps", args.fps == 0 or 1e-3 <= args.fps <= 1e4,
          "0 (as fast as possible) or a rate in [0.001, 1e4] frames/s")
    if not 0.0 <= args.loss <= 1.0:
        raise CliError("--loss: probability must be in [0, 1]")
    check(args.seed, "--seed", 0 <= args.seed < 2**63, "an integer in 0..2**63-1")
    if args.duration is not None:
        check(args.duration, "--duration", 0 < args.duration <= 1e7,
              "a number of seconds in (0, 1e7]")
    if args.packet_words is not None:
        count(args.packet_words, "--packet-words", 65535, lo=2)
    kind: str | None = {"host": CUBE, "fpga": RECORDS, None: None}[args.detect]
    detect_config = detect_config_of(args)
    fixed = None if args.scene else radar_of(args)  # a stream's radar, if given
    if args.radar and fixed is not None:            # a stream the FPGA chain sends
        check_source(get_source("model"), fixed, f"--radar {args.radar}", None)
    try:
        if args.replay:
            path = Path(args.replay)
            kind = _kind_of_replay(args, path)
            cfg = fixed or preset_of_capture(path)
            frame_words = detect_config(cfg).frame_words if kind == RECORDS else None
            packet_words, frames = load_replay(path, cfg, frame_words)
            desc = f"replay {path.name}" + (" (records)" if kind == RECORDS else "")
        elif args.scene:
            scene = scene_of(args)
            cfg = scene.config
            desc = f"scene {scene.name}" + (" (on-chip detection)" if kind == RECORDS else "")
            kind = kind or CUBE
            check_source(get_source(args.backend or ("float" if kind == CUBE else "model")),
                         cfg, alternative="--backend float" if kind == CUBE else None)
            if kind == RECORDS:
                detect_config(cfg)  # the detector options fit the preset
        else:
            cfg = fixed or get_preset("full")
            packet_words = args.packet_words
            desc = f"UDP {args.udp_host}:{args.udp_port}"
            if kind == RECORDS:
                for c in [cfg] if fixed else PRESETS.values():
                    detect_config(c)
    except (ValueError, OSError) as exc:
        raise CliError(str(exc)) from None
    # --ego-speed (checked), else the scene's (Table I: 100 km/h); a capture or a link: 0
    ego = ego_speed_mps(args, scene if args.scene else None)
    processor = Processor(cfg, feed, health, detection_params(args, cfg=cfg), _gnn(args), ego,
                          source=desc)
    threads = [threading.Thread(target=processor.run, args=(stop,), name="view-process",
                                daemon=True)]
    if args.frames < 1:
        raise CliError("--frames: must be >= 1")
    if args.scene and kind == CUBE:
        source = get_source(args.backend or "float")

        def make_cube(k: int):  # noqa: ANN202 - complex (n_virtual, n_range, n_doppler)
            return source.cube(simulate_scene(scene, frame_index=k).samples, cfg)

        health.on_kind(CUBE)
        threads.append(threading.Thread(target=scene_loop, name="view-scene", daemon=True,
                                        args=(make_cube, args.frames, processor, health,
                                              stop, args.fps)))
        return feed, health, threads, desc
    if args.scene:
        if (args.backend or "model") != "model":
            raise CliError(f"--backend {args.backend}: on-chip detection (--detect fpga) of a "
                           f"scene runs the bit-accurate model (--backend model)")
        dcfg = detect_config(cfg)
        chain = PipelineParams(output_mode=1, detect=dcfg)
        ingest = packet_ingest(cfg, chain.packet_words, health, processor, kind=RECORDS,
                               detect_config=lambda _: dcfg, chain=chain)
        threads.append(threading.Thread(
            target=replay_loop, name="view-scene", daemon=True,
            args=(scene_record_frames(scene, chain, args.frames), ingest, stop, args.fps,
                  True, args.loss, args.seed)))
        return feed, health, threads, desc
    try:
        # a UDP stream without --preset/--radar: the preset is learnt from the packet headers
        learn = None if args.replay or fixed else list(PRESETS.values())
        ingest = packet_ingest(cfg, packet_words, health, processor, configs=learn,
                               kind=kind, detect_config=detect_config)
    except ValueError as exc:
        raise CliError(f"--packet-words: {exc}") from None
    if args.replay:
        threads.append(threading.Thread(
            target=replay_loop, name="view-replay", daemon=True,
            args=(frames, ingest, stop, args.fps, not args.no_loop, args.loss, args.seed)))
    else:
        try:
            rx = UdpReceiver(args.udp_host, args.udp_port)
        except ValueError as exc:  # port outside 0..65535
            raise CliError(f"--udp-port: {exc}") from None
        except OSError as exc:     # an unknown or foreign --udp-host, a port in use
            raise CliError(f"--udp-host {args.udp_host} --udp-port {args.udp_port}: "
                           f"{exc}") from None
        common.warn([h for h in (rx.buffer_hint(),) if h], "view")
        desc = f"UDP {args.udp_host}:{rx.port}"
        processor.source = desc
        threads.append(threading.Thread(target=udp_loop, name="view-udp", daemon=True,
                                        args=(rx.sock, ingest, stop)))
    return feed, health, threads, desc


async def _serve(args: argparse.Namespace) -> int:
    stop = threading.Event()
    feed, health, threads, desc = build(args, stop)
    server = ViewServer(feed, health, args.host, args.port)
    try:
        await server.start()
    except OSError as exc:
        raise CliError(f"--host/--port: cannot listen on {args.host}:{args.port}: "
                       f"{exc.strerror or exc}") from None
    live = None
    if args.foxglove is not None:
        from radar.view.foxglove import FoxglovePublisher

        try:
            live = FoxglovePublisher(feed, args.host, args.foxglove, gnn=args.gnn)
        except OSError as exc:
            await server.close()
            raise CliError(f"--foxglove: cannot listen on {args.host}:{args.foxglove}: "
                           f"{exc}") from None
        threads.append(threading.Thread(target=live.run, args=(stop,), name="view-foxglove",
                                        daemon=True))
    for t in threads:
        t.start()
    print(f"radar view: http://{args.host}:{server.port}/ showing {desc} (Ctrl-C stops)",
          flush=True)
    if live is not None:
        print(f"radar view: Foxglove WebSocket ws://{args.host}:{live.port} (open it in "
              f"Foxglove: Open connection)", flush=True)
    t_end = time.monotonic() + args.duration if args.duration else None
    try:
        while t_end is None or time.monotonic() < t_end:
            await asyncio.sleep(0.2)
    finally:
        stop.set()
        await server.close()
        if live is not None:
            live.close()
    return 0


def cmd_view(args: argparse.Namespace) -> int:
    if not is_loopback(args.host) and not args.allow_remote:
        raise CliError(f"--host {args.host} is not a loopback address: the page has no "
                       f"authentication; add --allow-remote to serve it anyway")
    try:
        return asyncio.run(_serve(args))
    except KeyboardInterrupt:
        return 0


def add_parsers(sub: argparse._SubParsersAction, presets: list[str]) -> None:
    v = common.add_command(
        sub, "view", "live browser view: range-Doppler maps, point cloud, link health", """
        Serve a live view (like TI's mmWave Demo Visualizer) at http://HOST:PORT/: range-Doppler
        map of one virtual channel and the integrated map, x-y point cloud coloured by velocity
        with GNN boxes, range profile and link health (frames/s, lost packets, damaged frames,
        sticky hardware flags, detections per frame). The source is a UDP stream (default), a
        replayed capture or a simulated scene. Every asset is served from the package: no
        internet needed.""")
    src = v.add_mutually_exclusive_group()
    src.add_argument("--replay", metavar="FILE.dmacap",
                     help="replay a capture (from `radar capture`), looped")
    src.add_argument("--scene", help="simulate a scene (JSON file or built-in name, table1)")
    src.add_argument("--udp-port", type=int, default=0,
                     help="receive DMA packets on this UDP port (default source; 0 = any "
                          "free port, printed)")
    v.add_argument("--preset", choices=presets, default=None,
                   help="radar preset (default: the capture's geometry, the scene's preset, "
                        "or for UDP learnt from the packet headers)")
    add_radar_option(v, "a preset (a capture's or stream's: one the FPGA chain runs)")
    v.add_argument("--packet-words", type=int, default=None,
                   help="PACKET_WORDS of a UDP stream (default: learnt from the packet "
                        "headers, as radar receive does)")
    v.add_argument("--udp-host", default="127.0.0.1",
                   help="address the UDP receiver binds (default 127.0.0.1)")
    v.add_argument("--host", default="127.0.0.1",
                   help="address the web page is served on (default 127.0.0.1)")
    v.add_argument("--port", type=int, default=DEFAULT_PORT,
                   help=f"web page port (default {DEFAULT_PORT}; 0 = any free port)")
    v.add_argument("--allow-remote", action="store_true",
                   help="allow --host to be a non-loopback address (no authentication!)")
    v.add_argument("--fps", type=float, default=20.0,
                   help="replay/scene frame rate, frames/s (default 20; 0 = as fast as "
                        "possible)")
    v.add_argument("--no-loop", action="store_true", help="replay the capture once")
    v.add_argument("--loss", type=float, default=0.0,
                   help="replay: drop each packet with this probability (link test)")
    v.add_argument("--seed", type=int, default=0, help="seed of --loss")
    v.add_argument("--frames", type=int, default=16,
                   help="scene: frames simulated before the scene repeats (default 16)")
    v.add_argument("--backend", choices=("model", "float"), default=None,
                   help="scene: float reference (default, fast) or bit-accurate model (the "
                        "only one with --detect fpga, and its default)")
    v.add_argument("--detect", choices=("host", "fpga"), default=None,
                   help="the stream's kind: host = the radar cube (the host runs the CFAR), "
                        "fpga = the on-chip detector's records (OUTPUT_MODE = 1). Default: "
                        "a capture's header says; a UDP stream is recognised by its frame "
                        "length (records of --max-detections); a scene sends the cube")
    v.add_argument("--gnn", action="store_true",
                   help="classify objects with the GNN (shipped checkpoint), draw boxes")
    v.add_argument("--ego-speed", type=float, default=None,
                   help="ego speed along +x for the GNN's velocity compensation, m/s "
                        "(default: 27.78 for --scene table1, else 0)")
    v.add_argument("--foxglove", type=int, nargs="?", const=DEFAULT_FOXGLOVE_PORT,
                   default=None, metavar="PORT",
                   help="also publish the frames live as ROS 2 messages (the topics of --mcap, "
                        "docs/ros.md) on a Foxglove WebSocket server on --host, port PORT "
                        f"(default {DEFAULT_FOXGLOVE_PORT}; 0 = any free port, printed)")
    v.add_argument("--duration", type=float, default=None,
                   help="stop after this many seconds (default: run until Ctrl-C)")
    add_fpga_options(v)
    add_detection_options(v)
    v.set_defaults(func=cmd_view)
