"""``radar detect``: frames of a scene through a frame source (model, float, rtl) and the
host processing to the point cloud JSON of docs/design.md 4.4, optionally GNN objects and
figures.

``--detect host`` (default): the source gives radar cubes, the host runs the CFAR
(``host.pipeline.process_cube``). ``--detect fpga``: the chain runs its on-chip detector
(``OUTPUT_MODE = 1``), the source gives decoded detection records
(``host.records.RecordDecoder``) and the host goes on from them
(``host.record_points.process_records``): the same point cloud JSON."""

from __future__ import annotations

import argparse
import json
import time
from collections.abc import Iterator
from dataclasses import replace
from typing import Any

import numpy as np

from host.pipeline import DetectionParams
from host.pointcloud import PointCloud
from host.receiver import DetectConfigOf
from host.records import DEFAULT_MAX_DETECTIONS, fpga_detect_config
from host.ros.messages import FrameStatus
from model.cfar_2d import KINDS
from model.config import RadarConfig
from model.detect_chain import DetectConfig
from model.observability import scene_report
from model.radar_pipeline import PipelineParams
from model.simulate import simulate_scene
from radar.common import (
    CliError,
    add_command,
    add_detection_options,
    add_radar_option,
    add_refine_options,
    check_source,
    count,
    detection_params,
    ego_speed_mps,
    out_file,
    out_folder,
    progress,
    refuse_detection_misfits,
    scene_profile,
    stop_exit,
    stop_fields,
    stopped_before_any,
    warn,
    warn_clipped,
)
from radar.figures import detect_plots
from radar.frame_cloud import dma_frame_info, frame_cloud
from radar.objects import describe, gnn_objects, object_boxes
from radar.recording import add_mcap_options, close_recording, open_recording
from radar.sources import SOURCES, SourceError, get_source

MAX_DETECT_FRAMES = 10_000
"""Largest --frames (90 s of radar time; the command keeps every cloud in memory)."""
MAX_FPGA_DETECTIONS = 65535
"""Largest --max-detections (the record index is 16 bits)."""


def fpga_config(args: argparse.Namespace, cfg: RadarConfig, params: DetectionParams
                ) -> DetectConfig:
    """The on-chip detector's settings from the options (CliError on a bad combination)."""
    if args.detector == "paper":
        raise CliError("--detect fpga: the FPGA runs a CFAR (--fpga-cfar ca/go/so, or "
                       "--detector os), not --detector paper")
    if args.detector == "os" and args.fpga_cfar != "ca":
        raise CliError(f"--fpga-cfar {args.fpga_cfar}: --detector os runs the OS-CFAR on chip; "
                       f"--fpga-cfar chooses among the others with --detector ca")
    kind = "os" if args.detector == "os" else args.fpga_cfar
    if getattr(args, "plots", None):
        raise CliError("--plots: needs the radar cube, which --detect fpga does not send "
                       "(use --detect host)")
    count(args.max_detections, "--max-detections", MAX_FPGA_DETECTIONS)
    try:
        return fpga_detect_config(cfg, params.cfar, kind, args.max_detections,
                                  (params.range_window, params.doppler_window))
    except ValueError as exc:
        raise CliError(f"--detect fpga: {exc}") from None


def detect_config_of(args: argparse.Namespace) -> DetectConfigOf:
    """The on-chip detector's configuration for a preset from the options (``--fpga-cfar``,
    ``--max-detections``, the CFAR options); ValueError when they do not fit the preset."""
    def of(cfg: RadarConfig) -> DetectConfig:
        try:
            return fpga_config(args, cfg, detection_params(args, cfg=cfg))
        except CliError as exc:
            raise ValueError(str(exc)) from None

    return of


def cmd_detect(args: argparse.Namespace) -> int:
    refuse_detection_misfits(args, args.detect == "fpga")
    if args.refine and args.detect == "fpga":
        raise CliError("--refine: needs the radar cube, which --detect fpga does not send "
                       "(use --detect host)")
    scene, profile = scene_profile(args)
    cfg = scene.config
    source = get_source(args.backend, PipelineParams(static_removal=args.remove_static))
    check_source(source, cfg, alternative="--backend float" if args.detect == "host"
                 else "--detect host --backend float")
    out = out_file(args.json, ".json", "--json")
    count(args.frames, "--frames", MAX_DETECT_FRAMES)
    plots = out_folder(args.plots, "--plots") if args.plots else None
    params = replace(detection_params(args, scene.tx_beamforming, cfg),
                     static_removed=args.remove_static)
    clouds, per_frame, objects = [], [], []
    last_cube = None
    ego = ego_speed_mps(args, scene)
    report, warnings = scene_report(scene, range(args.frames), params.max_speed_mps)
    warn(warnings, "detect")
    t0 = time.perf_counter()
    saturated: list[int] = []

    def adc_frames() -> Iterator[np.ndarray]:
        for k in progress(range(args.frames), "frames"):
            adc = simulate_scene(scene, frame_index=k)
            saturated.append(adc.saturated)
            yield adc.samples

    def finish_frame(k: int, cloud: PointCloud, t_start: float, **status: Any) -> None:
        """The objects (--gnn) and the recording (--mcap) of frame k."""
        objs = gnn_objects(cloud, ego) if args.gnn else None
        if objs is not None:
            objects.extend({"frame": k, **o} for o in objs)
        if rec is not None:
            rec.write_frame(cloud, FrameStatus(k, len(cloud), processing_time_s=(
                time.perf_counter() - t_start), **status), objs)

    dcfg = fpga_config(args, cfg, params) if args.detect == "fpga" else None
    rec = open_recording(args, cfg.frame_time_s)
    stopped: str | None = None      # why the run ended early: what was done is written
    try:
        if dcfg is not None:
            frames = source.dma_frames(adc_frames(), cfg, dcfg)
            for f in frames:
                t_start = time.perf_counter()
                k = f.frame_id          # a damaged frame closes late: ids, not arrival
                fc = frame_cloud(f, cfg, params, k, "detect")
                cloud = fc.cloud
                clouds.append(cloud)
                n_clip = saturated[k] if k < len(saturated) else 0
                per_frame.append({"frame": k, "points": len(cloud), "adc_saturated": n_clip,
                                  **dma_frame_info(f, k, "detect", dcfg.max_detections),
                                  "problems": f.problems + fc.problems,
                                  "clipped": n_clip, "damaged": not f.complete})
                finish_frame(k, cloud, t_start, complete=f.complete, truncated=f.truncated,
                             detections=f.detections, problems=f.problems + fc.problems)
        else:
            for k, cube in enumerate(source.cubes(adc_frames(), cfg)):
                t_start = time.perf_counter()
                fc = frame_cloud(cube, cfg, params, k, "detect")
                cloud = fc.cloud
                clouds.append(cloud)
                per_frame.append({"frame": k, "points": len(cloud),
                                  "adc_saturated": saturated[k], "clipped": saturated[k],
                                  "damaged": False})
                if fc.problems:
                    per_frame[-1]["problems"] = fc.problems
                finish_frame(k, cloud, t_start, problems=fc.problems)
                last_cube = cube
    except KeyboardInterrupt:
        stopped = "interrupted"
    except SourceError as exc:
        stopped = f"--backend {args.backend}: {exc}"
    except ValueError as exc:  # a checkpoint that does not load, a bad ego speed
        stopped = str(exc)
    finally:
        close_recording(rec)
    stopped_before_any(stopped, len(per_frame))
    clipped = [k for k, n in enumerate(saturated) if n]
    warn_clipped(clipped, "detect")
    cloud = PointCloud.concat(clouds)
    done = len(per_frame) if stopped else args.frames
    doc: dict[str, Any] = cloud.to_json_dict(cfg, done, clipped)
    doc.update({"backend": args.backend, "detector": args.detector, "detect": args.detect,
                "remove_static": args.remove_static,
                "scene": scene.name, **({"radar": profile.source} if args.radar else {}),
                "ego_speed_mps": ego, "max_speed_mps": params.max_speed_mps,
                "frame_info": per_frame, **report})
    if args.gnn:
        doc["objects"] = objects
    doc.update(stop_fields(stopped, args.frames))
    out.write_text(json.dumps(doc, indent=1))
    print(f"{len(cloud)} points in {done} frame(s) ({time.perf_counter() - t0:.2f} s) "
          f"-> {out}")
    if args.gnn:
        print(f"GNN: {len(objects)} object(s): " + describe(objects))
    code = stop_exit(stopped, done, args.frames, out, "detect")
    if code is not None:
        return code
    if plots and last_cube is not None:
        last = [o for o in objects if o["frame"] == args.frames - 1]
        detect_plots(plots, cfg, scene, last_cube, clouds[-1], object_boxes(last))
    return 0


def add_fpga_options(p: argparse.ArgumentParser) -> None:
    """Options of the on-chip detector (``--detect fpga``)."""
    p.add_argument("--fpga-cfar", choices=KINDS[:3], default="ca",
                   help="--detect fpga: the on-chip CFAR kind, cell averaging or greatest/"
                        "smallest of the two Doppler halves (default ca; --detector os "
                        "runs the on-chip OS-CFAR)")
    p.add_argument("--max-detections", type=int, default=DEFAULT_MAX_DETECTIONS,
                   help=f"--detect fpga: MAX_DETECTIONS, records per frame, 1.."
                        f"{MAX_FPGA_DETECTIONS} (default {DEFAULT_MAX_DETECTIONS}; more "
                        f"detections set the trailer's truncated flag)")


def add_parsers(sub: argparse._SubParsersAction, presets: list[str]) -> None:
    d = add_command(sub, "detect", "scene -> point cloud JSON", """
        Simulate frames of a scene, run them through the FPGA chain (a model of it or the RTL) and
        the host processing, and write the point cloud JSON of docs/design.md 4.4.""")
    d.add_argument("--scene", required=True, help="scene JSON file or built-in name (table1)")
    d.add_argument("--json", required=True, help="output point cloud .json")
    d.add_argument("--backend", choices=list(SOURCES), default="model",
                   help="; ".join(f"{name}: {src.help}" for name, src in SOURCES.items()))
    d.add_argument("--plots", default=None, help="folder for a range-Doppler map and the "
                                                 "x-y point cloud of the last frame")
    d.add_argument("--frames", type=int, default=1,
                   help=f"frames to process, 1..{MAX_DETECT_FRAMES} (default 1)")
    d.add_argument("--preset", choices=presets, default=None,
                   help="override the scene's radar preset")
    add_radar_option(d, "the scene's preset")
    d.add_argument("--gnn", action="store_true",
                   help="also classify objects with the GNN (shipped checkpoint): adds "
                        "\"objects\" (class, score, rotated box, point indices) to the JSON")
    d.add_argument("--ego-speed", type=float, default=None,
                   help="ego speed along +x for the GNN's velocity compensation, m/s "
                        "(default: 27.78 for table1, else 0; written to the JSON, where "
                        "`radar gnn detect --points` picks it up)")
    d.add_argument("--detect", choices=("host", "fpga"), default="host",
                   help="host: the FPGA sends the radar cube and the host runs the CFAR "
                        "(default); fpga: the chain detects on chip (OUTPUT_MODE = 1: NCI, "
                        "2-D CFAR, snapshot records) and the host goes on from the records "
                        "(--backend model or rtl)")
    add_fpga_options(d)
    add_detection_options(d)
    add_refine_options(d, "--backend model and rtl")
    d.add_argument("--remove-static", action="store_true",
                   help="static-clutter removal: each range bin's mean over the frame's "
                        "chirps, per channel, subtracted before the Doppler FFT (float: "
                        "model.reference.remove_static; model and rtl: the static_removal "
                        "block, STATIC_REMOVAL = 1)")
    add_mcap_options(d)
    d.set_defaults(func=cmd_detect)
