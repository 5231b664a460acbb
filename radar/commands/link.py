"""The link commands: ``radar capture`` (DMA packets of simulated frames to a .dmacap file),
``radar replay`` (send a capture over UDP as the board would) and ``radar receive`` (decode
UDP packets -> point cloud JSON).

With ``--detect fpga`` the stream is the on-chip detector's record stream (``OUTPUT_MODE =
1``) instead of the radar cube: ``capture`` writes it (a record capture, ``host.capture``),
``replay`` sends either kind unchanged, and ``receive --detect fpga`` decodes records and
goes on from them (``radar.frame_cloud``). ``receive`` learns the stream's geometry from the
first datagram that fits (``host.receiver.Receiver``); the kind is chosen by the flag, not
guessed: ``receive`` without it names the record stream in its error when the first datagram
fits a record stream but no cube."""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path
from typing import Any

from host.capture import CaptureInfo, read_capture, write_capture
from host.pointcloud import PointCloud
from host.receiver import CUBE, RECORDS, Receiver
from host.ros.messages import FrameStatus, missing_packets
from model.axis_packetizer import words_to_bytes
from model.config import PRESETS
from model.radar_pipeline import PipelineParams, chain_gain, dma_packets
from model.simulate import simulate_scene
from radar.commands.detect import add_fpga_options, detect_config_of, fpga_config
from radar.common import (
    DETECTION_OPTIONS,
    FPGA_OPTIONS,
    CliError,
    add_command,
    add_detection_options,
    add_radar_option,
    check,
    check_source,
    count,
    detection_params,
    out_file,
    port,
    progress,
    radar_of,
    refuse,
    refuse_detection_misfits,
    scene_of,
    warn,
)
from radar.frame_cloud import frame_cloud
from radar.recording import add_mcap_options, close_recording, open_recording
from radar.sources import get_source

MAX_CAPTURE_FRAMES = 1000
"""Largest --frames of a capture (17 GB on full: more is a mistake)."""
MAX_RECEIVE_FRAMES = 1_000_000
"""Largest --frames of radar receive."""


def cmd_capture(args: argparse.Namespace) -> int:
    from host.udp import max_packet_words

    if args.detect == "host":
        refuse(args, (*DETECTION_OPTIONS, *FPGA_OPTIONS), "to a radar-cube capture (the "
               "host detects after receiving it; use --detect fpga for a record capture)")
    else:
        refuse(args, ("threshold_db", "max_speed"), "to a record capture (host-side "
               "options: give them to radar receive)")
    scene = scene_of(args)
    cfg = scene.config
    if args.radar:
        check_source(get_source("model"), cfg, f"--radar {args.radar}", None)
    out = out_file(args.out, ".dmacap", "--out")
    count(args.frames, "--frames", MAX_CAPTURE_FRAMES)
    fit = max_packet_words(cfg.num_rx)
    pw = fit if args.packet_words is None else args.packet_words
    chain = PipelineParams(packet_words=pw)
    try:
        chain.check(cfg)
    except ValueError as exc:
        raise CliError(f"--packet-words: {exc}") from None
    if pw > fit:
        raise CliError(f"--packet-words: {pw} words + header + CRC = {(pw + 2) * 4 * cfg.num_rx} "
                       f"bytes per packet does not fit a UDP datagram (at most {fit} for "
                       f"{cfg.num_rx} lanes), so radar replay could not send it")
    packets: list[bytes] = []
    adcs = (simulate_scene(scene, frame_index=k).samples
            for k in progress(range(args.frames), "frames"))
    if args.detect == "fpga":
        dcfg = fpga_config(args, cfg, detection_params(args, scene.tx_beamforming, cfg))
        source = get_source("model", chain)
        packets.extend(p if isinstance(p, bytes) else words_to_bytes(p)
                       for p in source.record_packets(adcs, cfg, dcfg))
        max_det = dcfg.max_detections
    else:
        for k, adc in enumerate(adcs):
            packets.extend(words_to_bytes(p) for p in dma_packets([adc], cfg, chain, k))
        max_det = 0
    info = CaptureInfo(cfg.num_rx, pw, cfg.num_tx, cfg.n_range, cfg.n_doppler, max_det)
    n = write_capture(out, info, packets)
    what = (f"detection records, MAX_DETECTIONS {max_det}" if max_det else "radar cube")
    print(f"wrote {out}: {args.frames} frame(s), {n} packets of {pw} payload words "
          f"({'preset' if scene.radar is None else 'radar'} {cfg.name}, {what}; bit-accurate "
          f"model of the FPGA chain, cube gain {chain_gain(cfg, chain):g} over 1/N per FFT)")
    return 0


def cmd_replay(args: argparse.Namespace) -> int:
    from host.udp import Impairments, UdpSender

    check(args.seed, "--seed", 0 <= args.seed < 2**63, "an integer in 0..2**63-1")
    port(args.port, "--port", allow_zero=False)
    rate = args.rate_mbps
    check(rate, "--rate-mbps", rate == 0 or 1e-3 <= rate <= 1e6,
          "0 (unpaced) or a rate in [0.001, 1e6] Mbit/s")
    try:
        info, packets = read_capture(Path(args.capture))
        packets = list(packets)
        if not packets:
            raise ValueError(f"{args.capture}: the capture has a header but no packet: "
                             f"nothing to replay")
        imp = Impairments(loss=args.loss, duplicate=args.duplicate, reorder=args.reorder,
                          seed=args.seed)
        with UdpSender(args.host, args.port, rate * 1e6 if rate else None, imp) as tx:
            log = tx.send(packets)
    except OSError as exc:
        if exc.filename:                # the capture file
            raise CliError(str(exc)) from None
        raise CliError(f"--host {args.host} --port {args.port}: {exc}") from None
    except ValueError as exc:
        raise CliError(str(exc)) from None
    kind = f"records, MAX_DETECTIONS {info.max_detections}" if info.records else "cube"
    # a preset's name, or the geometry of a radar profile's capture (radar capture --radar)
    radar = next((c.name for c in PRESETS.values() if info.matches(c)),
                 f"{info.num_tx} TX x {info.num_rx} RX, {info.n_range} x {info.n_doppler}")
    print(f"sent {log.sent} datagrams ({radar} {kind}, {info.packet_words} payload words "
          f"each) to "
          f"{args.host}:{args.port} ({len(log.dropped)} dropped, {len(log.duplicated)} "
          f"duplicated, {len(log.reordered)} reordered on purpose)")
    return 0


def cmd_receive(args: argparse.Namespace) -> int:
    from host.udp import UdpReceiver, check_seconds

    out = out_file(args.json, ".json", "--json")
    port(args.port, "--port")
    refuse_detection_misfits(args, args.detect == "fpga")
    count(args.frames, "--frames", MAX_RECEIVE_FRAMES)
    count(args.packet_words, "--packet-words", 65535, lo=2)   # before listening
    try:
        check_seconds(args.idle_timeout, "--idle-timeout")
        check_seconds(args.timeout, "--timeout")
    except ValueError as exc:
        raise CliError(str(exc)) from None
    fixed = radar_of(args)
    if args.radar:
        check_source(get_source("model"), fixed, f"--radar {args.radar}", None)
    params = detection_params(args, cfg=fixed)

    records = args.detect == "fpga"
    configs = [fixed] if fixed else list(PRESETS.values())
    # the geometry from the options if given, else learnt from the first datagram that fits
    receiver = Receiver(configs, args.packet_words, RECORDS if records else CUBE,
                        detect_config_of(args))
    try:
        if records:
            for cfg in configs:   # check the detector options before listening
                fpga_config(args, cfg, detection_params(args, cfg=cfg))
        if fixed and args.packet_words:
            # check the geometry before listening
            receiver.decoder_for(fixed, receiver.kind, args.packet_words)
        rx = UdpReceiver(args.host, args.port)
    except ValueError as exc:
        raise CliError(str(exc)) from None
    except OSError as exc:
        raise CliError(f"--host {args.host} --port {args.port}: {exc}") from None
    try:   # frames are stamped from now on (the stream carries no time)
        rec = open_recording(args, fixed.frame_time_s if fixed else None, time.time_ns())
    except CliError:
        rx.close()
        raise
    print(f"listening on {args.host}:{rx.port}", flush=True)
    warn([h for h in (rx.buffer_hint(),) if h], "receive")
    try:
        with rx:
            frames = rx.receive(None, max_frames=args.frames, idle_timeout_s=args.idle_timeout,
                                total_timeout_s=args.timeout, make_decoder=receiver.learn)
    except BaseException:
        close_recording(rec)
        raise
    decoder = rx.decoder
    cfg = receiver.cfg if decoder else fixed
    if decoder and cfg:
        params = detection_params(args, cfg=cfg)  # CFAR window vs the learnt map
    clouds, frames_doc = [], []
    if rec is not None and cfg:
        rec.frame_period_s = cfg.frame_time_s
    error = None                    # a frame the host could not process: the rest is kept
    try:
        for f in frames:
            t_start = time.perf_counter()
            entry: dict[str, Any] = {"frame_id": f.frame_id, "complete": f.complete,
                                     "damaged": not f.complete, "problems": f.problems}
            fc = None
            if decoder and cfg and (f.complete or args.use_damaged):
                fc = frame_cloud(f, cfg, params, f.frame_id, "receive")
                if fc.problems:
                    entry["problems"] = [*f.problems, *fc.problems]
                if records:
                    entry.update({"records": len(f.records), "detections": f.detections,
                                  "truncated": f.truncated})
                clouds.append(fc.cloud)
                entry["points"] = len(fc.cloud)
            frames_doc.append(entry)
            if rec is not None and decoder and cfg:
                rec.write_frame(fc.cloud if fc else None, FrameStatus(
                    f.frame_id, entry.get("points", 0), f.complete,
                    missing_packets(f.valid, decoder.packet_words),
                    entry.get("truncated", False), entry.get("detections", 0),
                    time.perf_counter() - t_start, entry["problems"]))
    except KeyboardInterrupt:
        rx.interrupted = True
    except ValueError as exc:
        error = f"frame {len(frames_doc)}: {exc}"
    finally:
        close_recording(rec)
    cloud = PointCloud.concat(clouds)
    doc = cloud.to_json_dict(cfg or "unknown", len(frames))
    doc.update({"backend": "udp", "detect": args.detect,
                "packet_words": decoder.packet_words if decoder else None,
                "datagrams": rx.datagrams, "interrupted": rx.interrupted,
                "frame_info": frames_doc,
                "stream_problems": (decoder.stream_problems if decoder else []) + rx.unusable,
                "stats": _stats(decoder, rx),
                "link": {"socket_drops": rx.socket_drops, "rate_mbps": rx.rate_bps / 1e6,
                         "rcvbuf_bytes": rx.rcvbuf_granted}})
    if error:
        doc["error"] = error
    out.write_text(json.dumps(doc, indent=1))
    if error:
        raise CliError(f"{error} (the {len(frames_doc)} frame(s) before it are in {out})")
    damaged = sum(not f.complete for f in frames)
    print(f"{len(frames)} frame(s) ({damaged} damaged), {len(cloud)} points -> {out}"
          + (f" (preset {cfg.name}, {decoder.packet_words} payload words per packet learnt "
             f"from the stream)" if decoder and fixed is None else ""))
    for f in frames:
        for p in f.problems[:5]:
            print(f"  {p}")
    warn([h for h in (rx.loss_hint(),) if h], "receive")
    if rx.interrupted:
        warn(["interrupted: wrote what was received"], "receive")
        return 130
    if not clouds:
        why = ("no datagram arrived" if not rx.datagrams else
               "no datagram was a DMA packet of " + (
                   f"radar {fixed.name}" if fixed else
                   "a known preset (another radar's stream: give its --radar)") + (
                   f" ({rx.unusable[0][:300]})" if rx.unusable else "") if not decoder else
               "every frame was damaged (see --use-damaged)")
        print(f"radar receive: error: no usable frame: {why} within {args.timeout:g} s",
              file=sys.stderr)
        return 1
    return 0


def _stats(decoder: Any, rx: Any) -> dict[str, Any]:
    """The decoder's counters (``host.stream.StreamStats``) with the datagrams no decoder
    could be learnt from counted as garbage (they are in ``stream_problems`` too)."""
    stats: dict[str, Any] = dict(vars(decoder.stats)) if decoder else {}
    stats["garbage_packets"] = stats.get("garbage_packets", 0) + len(rx.unusable)
    return stats


def add_parsers(sub: argparse._SubParsersAction, presets: list[str]) -> None:
    c = add_command(
        sub, "capture", "write the DMA packets of simulated frames to a capture file", """
        Simulate frames, run them through the bit-accurate model of the FPGA chain and write its
        DMA packets (header, payload, CRC word, exactly as the packetizer sends them) to a .dmacap
        file for `radar replay`.""")
    c.add_argument("--scene", required=True, help="scene JSON file or built-in name")
    c.add_argument("--out", required=True, help="output .dmacap file")
    c.add_argument("--frames", type=int, default=3,
                   help=f"frames, 1..{MAX_CAPTURE_FRAMES} (default 3)")
    c.add_argument("--packet-words", type=int, default=None,
                   help="payload words per packet, PACKET_WORDS (default: the most that fit "
                        "one UDP datagram of 65507 bytes with the header and CRC words: 1021 for "
                        "the 16 lanes of full, 4092 for the 4 of paper-fpga)")
    c.add_argument("--preset", choices=presets, default=None, help="override the preset")
    add_radar_option(c, "the scene's preset (one the FPGA chain runs)")
    c.add_argument("--detect", choices=("host", "fpga"), default="host",
                   help="host: capture the radar cube stream (default); fpga: the on-chip "
                        "detector's record stream (OUTPUT_MODE = 1), a record capture")
    add_fpga_options(c)
    add_detection_options(c)
    c.set_defaults(func=cmd_capture)

    r = add_command(sub, "replay", "send a capture over UDP as the board would", """
        Send each packet of a .dmacap capture as one UDP datagram, paced to a bit rate,
        optionally with injected loss, duplication and reordering.""")
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

    v = add_command(sub, "receive", "receive DMA packets over UDP and write the point cloud", """
        Receive UDP datagrams (one DMA packet each), reassemble frames, report
        lost/repeated/reordered/corrupt packets, and run host processing on every complete
        frame.""")
    v.add_argument("--preset", choices=presets, default=None,
                   help="radar preset (default: learnt from the first packet's header)")
    add_radar_option(v, "a preset learnt from the stream (one the FPGA chain runs)")
    v.add_argument("--host", default="127.0.0.1", help="address to bind (default 127.0.0.1)")
    v.add_argument("--port", type=int, default=0, help="UDP port (default: any free port, "
                                                       "printed)")
    v.add_argument("--packet-words", type=int, default=None,
                   help="PACKET_WORDS of the stream (default: learnt from the packet headers)")
    v.add_argument("--frames", type=int, default=None, help="stop after this many frames")
    v.add_argument("--idle-timeout", type=float, default=2.0,
                   help="after the first datagram, stop when none arrived for this long, s "
                        "(default 2)")
    v.add_argument("--timeout", type=float, default=300.0,
                   help="stop after this long in all (also the wait for the first datagram), "
                        "s (default 300); exit status 1 if no usable frame arrived, Ctrl-C "
                        "writes what arrived")
    v.add_argument("--use-damaged", action="store_true",
                   help="also process frames with missing packets (zeros where missing)")
    v.add_argument("--json", required=True, help="output point cloud .json")
    v.add_argument("--detect", choices=("host", "fpga"), default="host",
                   help="host: the stream is the radar cube, the host runs the CFAR "
                        "(default); fpga: the stream is the on-chip detector's records "
                        "(radar capture --detect fpga), decoded with the same --max-detections")
    add_fpga_options(v)
    add_detection_options(v)
    add_mcap_options(v)
    v.set_defaults(func=cmd_receive)
