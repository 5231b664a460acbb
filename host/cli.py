"""The ``radar`` command line.

    radar simulate --scene SCENE.json|table1 --out ADC.npy
    radar detect   --scene SCENE.json|table1 --json OUT.json [--backend model|rtl] [--plots DIR]
    radar demo     [--out DIR] [--preset full|paper-fpga]
    radar capture  --scene ... --out FILE.dmacap      (DMA packets of simulated frames)
    radar replay   --capture FILE.dmacap --port P     (send as the board would, over UDP)
    radar receive  --port P --preset ... --json OUT   (decode UDP packets -> point cloud)

Bad input ends with exit status 2 and a one-line reason on stderr. ``radar <cmd> --help``
explains every option.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np
from tqdm import tqdm

from host.backends import BACKENDS, cube_from_adc
from host.capture import CaptureInfo, read_capture, write_capture
from host.cfar import CfarParams, paper_threshold
from host.evaluate import match_targets, table3
from host.pipeline import DETECTORS, DetectionParams, process_cube
from host.pointcloud import PointCloud
from model.config import PRESETS, RadarConfig, get_preset
from model.packetizer import words_to_bytes
from model.pipeline import PipelineParams, chain_gain, dma_packets
from model.reference import range_doppler_power
from model.scene import EGO_SPEED_KMH, Scene, load_scene, table1_scene
from model.simulate import simulate_scene

RTL_SIM_MAX_FRAME_BITS = 16 * 2**20
"""Largest corner-turn frame the RTL backend simulates (paper-fpga: 2 Mib; full: 128 Mib)."""


class CliError(Exception):
    """Bad input: reported as one line, exit status 2."""


def _progress(iterable, desc: str, total: int | None = None):
    """tqdm progress bar on stderr when it is a terminal (quiet in CI logs)."""
    return tqdm(iterable, desc=desc, total=total, disable=not sys.stderr.isatty(), leave=False)


def _scene(args: argparse.Namespace) -> Scene:
    try:
        return load_scene(args.scene, getattr(args, "preset", None))
    except ValueError as exc:
        raise CliError(str(exc)) from None


def _params(args: argparse.Namespace, scene_bf: bool = True) -> DetectionParams:
    try:
        cfar = CfarParams(pfa=args.pfa, guard=tuple(args.guard), train=tuple(args.train),
                          kind="os" if args.detector == "os" else "ca")
        return DetectionParams(detector=args.detector, cfar=cfar,
                               paper_threshold_db=args.threshold_db, tx_beamforming=scene_bf)
    except ValueError as exc:
        raise CliError(str(exc)) from None


def _out_file(path: str, suffix: str, option: str) -> Path:
    p = Path(path)
    if p.suffix != suffix:
        raise CliError(f"{option}: {p} must end in {suffix}")
    p.parent.mkdir(parents=True, exist_ok=True)
    return p


# ---- simulate -----------------------------------------------------------------------------
def cmd_simulate(args: argparse.Namespace) -> int:
    scene = _scene(args)
    out = _out_file(args.out, ".npy", "--out")
    if args.frame < 0:
        raise CliError("--frame: must be >= 0")
    frame = simulate_scene(scene, frame_index=args.frame)
    np.save(out, frame.samples)
    print(f"wrote {out}: complex64 {frame.samples.shape} (chirps in transmit order, rx, "
          f"samples), preset {scene.config.name}, {len(scene.scatterers())} scatterers, "
          f"{frame.saturated} saturated I/Q values, {frame.dropped_scatterers} scatterers "
          f"beyond the IF band")
    if frame.saturated:
        print(f"warning: {frame.saturated} ADC values clipped at full scale", file=sys.stderr)
    return 0


# ---- detect -------------------------------------------------------------------------------
def _model_frames(scene: Scene, frames: int, params: DetectionParams, backend: str):
    """(frame index, cube, cloud, saturated) for each frame through a model backend."""
    cfg = scene.config
    for k in _progress(range(frames), "frames"):
        adc = simulate_scene(scene, frame_index=k)
        cube = cube_from_adc(adc.samples, cfg, backend)
        yield k, cube, process_cube(cube, cfg, params, frame=k), adc.saturated


def _rtl_frames(scene: Scene, frames: int, params: DetectionParams):
    """The same through the Verilated radar_pipeline (the C++ harness, host.rtlsim.harness):
    simulated ADC frames stream through the RTL back to back; its DMA packets are decoded
    like the board's."""
    from host.rtlsim.harness import run_pipeline
    from host.stream import StreamDecoder

    cfg = scene.config
    frame_bits = cfg.num_tx * cfg.n_range * cfg.n_doppler * cfg.num_rx * 32
    if frame_bits > RTL_SIM_MAX_FRAME_BITS:
        raise CliError(f"--backend rtl: preset {cfg.name!r} needs a "
                       f"{frame_bits / 2**20:.0f} Mib corner turn (external DDR4 on the "
                       f"ZCU106), too large to simulate here; use --preset paper-fpga")
    chain = PipelineParams()
    adcs = [simulate_scene(scene, frame_index=k) for k in range(frames)]
    print(f"building/running the RTL (radar_pipeline, {cfg.name} parameters); the first "
          f"build takes a minute or two", file=sys.stderr)
    try:
        packets, status = run_pipeline([a.samples for a in adcs], cfg, chain)
    except (RuntimeError, FileNotFoundError, ImportError) as exc:
        raise CliError(f"--backend rtl: {exc}") from None
    dec = StreamDecoder(cfg, chain.packet_words)
    decoded = [f for p in packets for f in dec.push_packet(p)] + dec.flush()
    if len(decoded) != frames or not all(f.complete for f in decoded):
        problems = [p for f in decoded for p in f.problems] + dec.stream_problems
        raise CliError(f"--backend rtl: {len(decoded)} frame(s) back, problems: "
                       f"{problems[:3]}, status {status}")
    gain = chain_gain(cfg, chain)
    for k, (f, adc) in enumerate(zip(sorted(decoded, key=lambda f: f.frame_id), adcs,
                                     strict=True)):
        cube = f.cube / gain
        yield k, cube, process_cube(cube, cfg, params, frame=k), adc.saturated


def cmd_detect(args: argparse.Namespace) -> int:
    scene = _scene(args)
    out = _out_file(args.json, ".json", "--json")
    if args.frames < 1:
        raise CliError("--frames: must be >= 1")
    cfg = scene.config
    params = _params(args, scene.tx_beamforming)
    clouds, per_frame, objects = [], [], []
    last_cube = None
    ego = _ego_speed(args, scene)
    t0 = time.perf_counter()
    source = (_rtl_frames(scene, args.frames, params) if args.backend == "rtl"
              else _model_frames(scene, args.frames, params, args.backend))
    for k, cube, cloud, saturated in source:
        clouds.append(cloud)
        per_frame.append({"frame": k, "points": len(cloud), "adc_saturated": saturated})
        if args.gnn:
            objects.extend({"frame": k, **o} for o in _gnn_objects(cloud, ego))
        last_cube = cube
    cloud = PointCloud.concat(clouds)
    doc: dict[str, Any] = cloud.to_json_dict(cfg.name, args.frames)
    doc.update({"backend": args.backend, "detector": args.detector, "scene": scene.name,
                "frame_info": per_frame})
    if args.gnn:
        doc["objects"] = objects
    out.write_text(json.dumps(doc, indent=1))
    print(f"{len(cloud)} points in {args.frames} frame(s) ({time.perf_counter() - t0:.2f} s) "
          f"-> {out}")
    if args.gnn:
        print(f"GNN: {len(objects)} object(s): " + ", ".join(
            f"{o['class']} ({o['score']:.2f}) at x {o['x_m']:.1f} y {o['y_m']:.1f}"
            for o in objects[:8]))
    if args.plots and last_cube is not None:
        last = [o for o in objects if o["frame"] == args.frames - 1]
        _detect_plots(Path(args.plots), cfg, scene, last_cube, clouds[-1], _boxes(last))
    return 0


def _gnn_objects(cloud: PointCloud, ego_speed_mps: float) -> list[dict[str, Any]]:
    """Classified boxes from the shipped GNN checkpoint (imports torch: only when asked)."""
    from gnn.infer import detect_objects

    return detect_objects(cloud, ego_speed_mps=ego_speed_mps)


def _boxes(objects: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """GNN objects -> boxes for host.plots.plot_point_cloud."""
    return [{"x": o["x_m"], "y": o["y_m"], "length": o["length_m"], "width": o["width_m"],
             "heading_deg": o["heading_deg"], "label": f"{o['class']} {o['score']:.2f}"}
            for o in objects]


def _ego_speed(args: argparse.Namespace, scene: Scene) -> float:
    if args.ego_speed is not None:
        return float(args.ego_speed)
    return EGO_SPEED_KMH / 3.6 if scene.name == "table1" else 0.0


def _truth(scene: Scene) -> list[tuple[float, float, str]]:
    return [(t.x_m, t.y_m, f"T{i + 1}") for i, t in enumerate(scene.targets)]


def _detect_plots(folder: Path, cfg: RadarConfig, scene: Scene, cube: np.ndarray,
                  cloud: PointCloud, boxes: list[dict[str, Any]] | None = None) -> None:
    from host.plots import plot_point_cloud, plot_range_doppler

    markers = [(t.range_m, t.radial_velocity_mps, f"T{i + 1}")
               for i, t in enumerate(scene.targets)]
    zoom = 1.5 * max([t.range_m for t in scene.targets] + [10.0])
    paths = [plot_range_doppler(range_doppler_power(cube), cfg, folder / "range_doppler.png",
                                f"{cfg.name}: range-Doppler (all channels)", markers, zoom),
             plot_point_cloud(cloud.x_m, cloud.y_m, cloud.snr_db, folder / "point_cloud.png",
                              f"{cfg.name}: point cloud ({len(cloud)} points)",
                              _truth(scene), boxes)]
    print("figures: " + ", ".join(str(p) for p in paths))


# ---- demo ---------------------------------------------------------------------------------
def cmd_demo(args: argparse.Namespace) -> int:
    from host.angle import range_azimuth_power
    from host.plots import (
        plot_detection_mask,
        plot_point_cloud,
        plot_range_azimuth_pair,
        plot_range_doppler,
    )

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    scene = table1_scene(args.preset)
    cfg = scene.config
    params = DetectionParams()
    t0 = time.perf_counter()
    adc = simulate_scene(scene)
    cube = cube_from_adc(adc.samples, cfg, args.backend)
    t_host = time.perf_counter()
    cloud = process_cube(cube, cfg, params)
    t_host = time.perf_counter() - t_host
    matches, used = match_targets(cloud, scene.targets, cfg)
    print(f"Table I scene, preset {cfg.name} ({cfg.num_tx} TX x {cfg.num_rx} RX, "
          f"{cfg.n_range} x {cfg.n_doppler} FFTs), {args.backend} backend, CA-CFAR Pfa "
          f"{params.cfar.pfa:g}: {len(cloud)} points, {int((~used).sum())} unmatched, host "
          f"processing {t_host * 1e3:.0f} ms")
    print("errors are |estimate - actual|; 'paper' = the paper's hardware error (Table III)")
    print(table3(matches, cloud, cfg))

    # figures: Fig. 6 (channel 0 + thresholded), Fig. 5 (with / without TX beamforming),
    # non-coherent range-Doppler map, point cloud
    zoom = 1.5 * max(t.range_m for t in scene.targets)
    mask, p0 = paper_threshold(cube, params.paper_threshold_db)
    markers = [(t.range_m, t.radial_velocity_mps, f"V{i + 1}")
               for i, t in enumerate(scene.targets)]
    figs = [plot_detection_mask(p0, mask, cfg, out / "fig6_range_doppler_ch0.png",
                                f"{cfg.name}: channel 0 and its threshold "
                                f"({params.paper_threshold_db:g} dB over the median)", zoom),
            plot_range_doppler(range_doppler_power(cube), cfg, out / "range_doppler_nci.png",
                               f"{cfg.name}: range-Doppler, {cfg.n_virtual} channels "
                               f"non-coherent", markers, zoom)]
    no_bf = Scene(preset=scene.preset, seed=scene.seed, tx_beamforming=False,
                  targets=scene.targets, name="table1-no-bf")
    cube_nobf = cube_from_adc(simulate_scene(no_bf).samples, cfg, args.backend)
    ra_bf, az = range_azimuth_power(cube, cfg)
    ra_nobf, _ = range_azimuth_power(cube_nobf, cfg)
    figs.append(plot_range_azimuth_pair(
        [(ra_bf, "TX subarray beamforming (3 elements)"), (ra_nobf, "single TX element")],
        az, cfg, out / "fig5_range_azimuth_bf_vs_nobf.png", zoom))
    objects = _gnn_objects(cloud, EGO_SPEED_KMH / 3.6) if not args.no_gnn else []
    if not args.no_gnn:
        print(f"GNN (synthetic-trained checkpoint; ego {EGO_SPEED_KMH:.0f} km/h is beyond its "
              f"training range): " + (", ".join(
                  f"{o['class']} {o['score']:.2f} at ({o['x_m']:.1f}, {o['y_m']:.1f}) m"
                  for o in objects) or "no objects"))
    figs.append(plot_point_cloud(cloud.x_m, cloud.y_m, cloud.snr_db, out / "point_cloud.png",
                                 f"{cfg.name}: Table I point cloud" + (
                                     " and GNN objects" if objects else ""),
                                 _truth(scene), _boxes(objects)))
    doc = cloud.to_json_dict(cfg.name, 1)
    doc["objects"] = objects
    (out / "table1_points.json").write_text(json.dumps(doc, indent=1))
    print(f"figures in {out}/: " + ", ".join(p.name for p in figs)
          + f" ({time.perf_counter() - t0:.1f} s)")
    return 0


# ---- capture / replay / receive -----------------------------------------------------------
def cmd_capture(args: argparse.Namespace) -> int:
    scene = _scene(args)
    cfg = scene.config
    out = _out_file(args.out, ".dmacap", "--out")
    chain = PipelineParams(packet_words=args.packet_words)
    try:
        chain.check(cfg)
    except ValueError as exc:
        raise CliError(f"--packet-words: {exc}") from None
    if args.frames < 1:
        raise CliError("--frames: must be >= 1")
    packets: list[bytes] = []
    for k in _progress(range(args.frames), "frames"):
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
    out = _out_file(args.json, ".json", "--json")
    gain = chain_gain(cfg, PipelineParams(packet_words=args.packet_words))
    params = _params(args)
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


# ---- parser -------------------------------------------------------------------------------
def _add_detection_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("--detector", choices=DETECTORS, default="ca",
                   help="ca: 2-D CA-CFAR on the non-coherent map (default); os: OS-CFAR "
                        "(slower); paper: the paper's threshold on channel 0")
    p.add_argument("--pfa", type=float, default=1e-6,
                   help="CFAR false-alarm probability per range-Doppler cell (default 1e-6)")
    p.add_argument("--guard", type=int, nargs=2, default=(2, 2), metavar=("RANGE", "DOPPLER"),
                   help="CFAR guard cells per side (default 2 2)")
    p.add_argument("--train", type=int, nargs=2, default=(4, 8), metavar=("RANGE", "DOPPLER"),
                   help="CFAR training cells per side (default 4 8)")
    p.add_argument("--threshold-db", type=float, default=15.0,
                   help="paper detector: threshold over the channel-0 median, dB (default 15)")


def build_parser(with_gnn: bool = False) -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="radar",
        description="Open 77 GHz FMCW TDM-MIMO radar array processor: scene simulator, "
                    "reference of the FPGA chain, host processing and DMA stream tools.")
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")
    presets = sorted(PRESETS)

    s = sub.add_parser(
        "simulate", help="simulate one frame of ADC samples",
        description="Simulate one frame of a scene and write the ADC samples as a complex64 "
                    ".npy array of shape (NUM_TX*N_DOPPLER chirps in transmit order, NUM_RX, "
                    "N_RANGE samples) holding the integer int16 I/Q codes the FPGA receives.")
    s.add_argument("--scene", required=True,
                   help="scene JSON file, or the name of a built-in scene (table1)")
    s.add_argument("--out", required=True, help="output .npy file")
    s.add_argument("--preset", choices=presets, default=None,
                   help="override the scene's radar preset")
    s.add_argument("--frame", type=int, default=0,
                   help="frame index: targets move v*frame*frame_time, fresh noise (default 0)")
    s.set_defaults(func=cmd_simulate)

    d = sub.add_parser(
        "detect", help="scene -> point cloud JSON",
        description="Simulate frames of a scene, run them through the FPGA chain (a model "
                    "of it or the RTL) and the host processing, and write the point cloud "
                    "JSON of DESIGN.md section 4.")
    d.add_argument("--scene", required=True, help="scene JSON file or built-in name (table1)")
    d.add_argument("--json", required=True, help="output point cloud .json")
    d.add_argument("--backend", choices=BACKENDS, default="model",
                   help="model: bit-accurate model of the FPGA chain (default); float: its "
                        "float64 reference (faster); rtl: the Verilated radar_pipeline")
    d.add_argument("--plots", default=None, help="folder for a range-Doppler map and the "
                                                 "x-y point cloud of the last frame")
    d.add_argument("--frames", type=int, default=1, help="frames to process (default 1)")
    d.add_argument("--preset", choices=presets, default=None,
                   help="override the scene's radar preset")
    d.add_argument("--gnn", action="store_true",
                   help="also classify objects with the GNN (shipped checkpoint): adds "
                        "\"objects\" (class, score, rotated box, point indices) to the JSON")
    d.add_argument("--ego-speed", type=float, default=None,
                   help="ego speed along +x for the GNN's velocity compensation, m/s "
                        "(default: 27.78 for table1, else 0)")
    _add_detection_options(d)
    d.set_defaults(func=cmd_detect)

    m = sub.add_parser(
        "demo", help="the paper's Table I scene end to end, with figures",
        description="Simulate the paper's Table I scene, run the FPGA chain (bit-accurate "
                    "model) "
                    "and host processing, print a Table III style comparison (with the "
                    "paper's hardware errors beside ours) and write the figures: channel-0 "
                    "range-Doppler map and its threshold (paper Fig. 6), range-azimuth "
                    "with and without TX beamforming (Fig. 5), the non-coherent "
                    "range-Doppler map and the x-y point cloud.")
    m.add_argument("--out", default="out", help="folder for figures and JSON (default out/)")
    m.add_argument("--preset", choices=presets, default="full",
                   help="radar preset (default full)")
    m.add_argument("--backend", choices=BACKENDS[:2], default="model",
                   help="model: bit-accurate FPGA chain (default, ~20 s on full); float: "
                        "its float64 reference (~3 s)")
    m.add_argument("--no-gnn", action="store_true",
                   help="skip the GNN object classification (saves loading torch)")
    m.set_defaults(func=cmd_demo)

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
    _add_detection_options(v)
    v.set_defaults(func=cmd_receive)

    g = sub.add_parser("gnn", help="GNN object detector: dataset, train, eval, detect "
                                   "(radar gnn --help)")
    if with_gnn:  # imported only for `radar gnn ...`: torch is slow to import
        from gnn.cli import add_subcommands

        add_subcommands(g.add_subparsers(dest="gnn_command", required=True,
                                         metavar="GNN_COMMAND"))
    return p


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    parser = build_parser(with_gnn=bool(argv) and argv[0] == "gnn")
    args = parser.parse_args(argv)
    try:
        return int(args.func(args))
    except CliError as exc:
        print(f"radar {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:
        print(f"radar {args.command}: error: {exc.strerror or exc}: "
              f"{getattr(exc, 'filename', '') or ''}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
