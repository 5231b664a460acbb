"""The link commands: ``radar capture`` (DMA packets of simulated frames to a .dmacap file),
``radar replay`` (send a capture over UDP as the board would) and ``radar receive`` (decode
UDP packets -> point cloud JSON)."""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

from host.capture import CaptureInfo, read_capture, write_capture
from host.pipeline import process_cube
from host.pointcloud import PointCloud
from model.axis_packetizer import words_to_bytes
from model.config import get_preset
from model.radar_pipeline import PipelineParams, chain_gain, dma_packets
from model.simulate import simulate_scene
from radar.common import (
    CliError,
    add_detection_options,
    detection_params,
    out_file,
    progress,
    scene_of,
)


def cmd_capture(args: argparse.Namespace) -> int:
    scene = scene_of(args)
    cfg = scene.config
    out = out_file(args.out, ".dmacap", "--out")
    chain = PipelineParams(packet_words=args.packet_words)
    try:
        chain.check(cfg)
    except ValueError as exc:
        raise CliError(f"--packet-words: {exc}") from None
    if args.frames < 1:
        raise CliError("--frames: must be >= 1")
    packets: list[bytes] = []
    for k in progress(range(args.frames), "frames"):
        adc = simulate_scene(scene, frame_index=k).samples
        packets.extend(words_to_bytes(p) for p in dma_packets([adc], cfg, chain, k))
    info = CaptureInfo(cfg.num_rx, args.packet_words, cfg.num_tx, cfg.n_range, cfg.n_doppler)
    n = write_capture(out, info, packets)
    print(f"wrote {out}: {args.frames} frame(s), {n} packets (bit-accurate model of the FPGA "
          f"chain, cube gain {chain_gain(cfg, chain):g} over 1/N per FFT)")
    return 0


def cmd_replay(args: argparse.Namespace) -> int:
    from host.udp import Impairments, UdpSender

    try:
        info, packets = read_capture(Path(args.capture))
        imp = Impairments(loss=args.loss, duplicate=args.duplicate, reorder=args.reorder,
                          seed=args.seed)
        with UdpSender(args.host, args.port, args.rate_mbps * 1e6 if args.rate_mbps else None,
                       imp) as tx:
            log = tx.send(packets)
    except (ValueError, OSError) as exc:
        raise CliError(str(exc)) from None
    print(f"sent {log.sent} datagrams to {args.host}:{args.port} ({len(log.dropped)} dropped, "
          f"{len(log.duplicated)} duplicated, {len(log.reordered)} reordered on purpose)")
    return 0


def cmd_receive(args: argparse.Namespace) -> int:
    from host.stream import StreamDecoder
    from host.udp import UdpReceiver

    cfg = get_preset(args.preset)
    out = out_file(args.json, ".json", "--json")
    gain = chain_gain(cfg, PipelineParams(packet_words=args.packet_words))
    params = detection_params(args)
    try:
        decoder = StreamDecoder(cfg, args.packet_words)
        rx = UdpReceiver(args.host, args.port)
    except (ValueError, OSError) as exc:
        raise CliError(str(exc)) from None
    print(f"listening on {args.host}:{rx.port}", flush=True)
    clouds, frames_doc = [], []
    with rx:
        frames = rx.receive(decoder, max_frames=args.frames, idle_timeout_s=args.idle_timeout,
                            total_timeout_s=args.timeout)
    for f in frames:
        entry: dict[str, Any] = {"frame_id": f.frame_id, "complete": f.complete,
                                 "problems": f.problems}
        if f.complete or args.use_damaged:
            cloud = process_cube(f.cube / gain, cfg, params, frame=f.frame_id)
            clouds.append(cloud)
            entry["points"] = len(cloud)
        frames_doc.append(entry)
    cloud = PointCloud.concat(clouds)
    doc = cloud.to_json_dict(cfg.name, len(frames))
    doc.update({"backend": "udp", "frame_info": frames_doc,
                "stream_problems": decoder.stream_problems,
                "stats": vars(decoder.stats)})
    out.write_text(json.dumps(doc, indent=1))
    damaged = sum(not f.complete for f in frames)
    print(f"{len(frames)} frame(s) ({damaged} damaged), {len(cloud)} points -> {out}")
    for f in frames:
        for p in f.problems[:5]:
            print(f"  {p}")
    return 0


def add_parsers(sub: argparse._SubParsersAction, presets: list[str]) -> None:
    c = sub.add_parser(
        "capture", help="write the DMA packets of simulated frames to a capture file",
        description="Simulate frames, run them through the bit-accurate model of the FPGA "
                    "chain and write its DMA packets (header word + payload, exactly as the "
                    "packetizer sends them) to a .dmacap file for `radar replay`.")
    c.add_argument("--scene", required=True, help="scene JSON file or built-in name")
    c.add_argument("--out", required=True, help="output .dmacap file")
    c.add_argument("--frames", type=int, default=3, help="frames (default 3)")
    c.add_argument("--packet-words", type=int, default=1023,
                   help="payload words per packet, PACKET_WORDS (default 1023: one packet "
                        "fits a UDP datagram for 16 lanes)")
    c.add_argument("--preset", choices=presets, default=None, help="override the preset")
    c.set_defaults(func=cmd_capture)

    r = sub.add_parser(
        "replay", help="send a capture over UDP as the board would",
        description="Send each packet of a .dmacap capture as one UDP datagram, paced to "
                    "a bit rate, optionally with injected loss, duplication and reordering.")
    r.add_argument("--capture", required=True, help=".dmacap file")
    r.add_argument("--host", default="127.0.0.1", help="destination address (default "
                                                       "127.0.0.1)")
    r.add_argument("--port", type=int, required=True, help="destination UDP port")
    r.add_argument("--rate-mbps", type=float, default=766.0,
                   help="pacing in Mbit/s (default 766, the paper's measured link rate; 0 = "
                        "unpaced)")
    r.add_argument("--loss", type=float, default=0.0, help="drop probability per packet")
    r.add_argument("--duplicate", type=float, default=0.0, help="duplicate probability")
    r.add_argument("--reorder", type=float, default=0.0,
                   help="probability of swapping a packet with the next")
    r.add_argument("--seed", type=int, default=0, help="seed of the injected faults")
    r.set_defaults(func=cmd_replay)

    v = sub.add_parser(
        "receive", help="receive DMA packets over UDP and write the point cloud",
        description="Receive UDP datagrams (one DMA packet each), reassemble frames, report "
                    "lost/repeated/reordered/corrupt packets, and run host processing on "
                    "every complete frame.")
    v.add_argument("--preset", choices=presets, default="full", help="radar preset")
    v.add_argument("--host", default="127.0.0.1", help="address to bind (default 127.0.0.1)")
    v.add_argument("--port", type=int, default=0, help="UDP port (default: any free port, "
                                                       "printed)")
    v.add_argument("--packet-words", type=int, default=1023, help="PACKET_WORDS of the stream")
    v.add_argument("--frames", type=int, default=None, help="stop after this many frames")
    v.add_argument("--idle-timeout", type=float, default=2.0,
                   help="stop when no datagram arrived for this long, s (default 2)")
    v.add_argument("--timeout", type=float, default=300.0, help="stop after this long, s")
    v.add_argument("--use-damaged", action="store_true",
                   help="also process frames with missing packets (zeros where missing)")
    v.add_argument("--json", required=True, help="output point cloud .json")
    add_detection_options(v)
    v.set_defaults(func=cmd_receive)
