"""``radar process``: a capture of a radar profile -> the point cloud JSON (docs/profiles.md).

The profile (``--radar``: a preset, a TOML profile or a TI ``.cfg``, ``model.profile``) says
how to read the capture (``--capture``: a DCA1000 ``.bin`` or a ``.npy``,
``host.adc_capture.open_capture``); its frames are read one at a time, turned into radar cubes
as the float reference of the chain gives them (``model.reference.radar_cube``; computed by
its fast equivalent ``host.cube.frame_cube``) and into point clouds by
the host processing (``radar.frame_cloud``), as ``radar detect`` does with simulated frames.
The JSON is ``radar detect``'s, each point carrying its frame's index in the capture.
"""

from __future__ import annotations

import argparse
import json
import time
from dataclasses import replace
from typing import Any

import numpy as np

from host.adc_capture import NpyCapture, open_capture
from host.allocator import keep_freed_memory
from host.calibration import check_calibration, load_calibration
from host.cube import frame_cube
from host.dca1000 import Dca1000Capture
from host.params import GROUPINGS, DetectionParams
from host.pointcloud import PointCloud
from host.ros.messages import FrameStatus
from model.array import has_vertical_extent
from model.config import RadarConfig
from model.profile import Calibration, Profile, load_profile
from radar.common import (
    CliError,
    add_command,
    add_detection_options,
    detection_params,
    out_file,
    out_folder,
    progress,
    stop_exit,
    stop_fields,
    stopped_before_any,
    warn,
    warn_clipped,
)
from radar.figures import process_plots
from radar.frame_cloud import FrameCloud, frame_cloud
from radar.recording import add_mcap_options, close_recording, open_recording

BACKENDS = ("float",)
"""Frame sources ``radar process`` runs: the float reference only (the bit-accurate model
and the RTL process the presets' frames, ``radar detect``; profiles are later work)."""


def frame_range(text: str | None, n_frames: int) -> range:
    """The frames of ``--frames A:B`` (A..B-1; A defaults to 0 and B to the capture's end;
    a single number A is frame A alone) in a capture of ``n_frames``; CliError unless
    0 <= A < B <= n_frames."""
    if text is None:
        return range(n_frames)
    a, colon, b = text.partition(":")
    try:
        start = int(a) if a.strip() else 0
        stop = (int(b) if b.strip() else n_frames) if colon else start + 1
    except ValueError:
        raise CliError(f"--frames: must be A:B (frame numbers), got {text!r}") from None
    if not 0 <= start < stop <= n_frames:
        raise CliError(f"--frames: {text} selects no frames of the capture's 0..{n_frames - 1}"
                       if start >= stop or start >= n_frames else
                       f"--frames: {text} is outside the capture's frames 0..{n_frames - 1}")
    return range(start, stop)


def profile_of(spec: str) -> Profile:
    """The profile of ``--radar``, one the chain can process; CliError (one line) if not."""
    try:
        profile = load_profile(spec)
        profile.config.check_processable()
    except ValueError as exc:
        raise CliError(str(exc)) from None
    return profile


PROFILE_CALIBRATION = "compRangeBiasAndRxChanPhase"
"""What the output calls a TI ``.cfg``'s calibration."""


def calibration_of(path: str | None, profile: Profile, use_profile: bool = True
                   ) -> tuple[Calibration | None, str]:
    """The calibration ``radar process`` applies and its name for the output: the file
    ``path`` (``--calibration``), else the profile's own (a TI ``.cfg``'s
    ``compRangeBiasAndRxChanPhase``) when ``use_profile``, else none. CliError (one line)
    for a file that is missing, malformed or of another array."""
    cfg = profile.config
    try:
        if path is not None:
            return load_calibration(path, cfg), path
        if use_profile and profile.calibration is not None:
            check_calibration(profile.calibration, cfg, f"{profile.source}: "
                                                       f"{PROFILE_CALIBRATION}")
            return profile.calibration, f"{PROFILE_CALIBRATION} of {profile.source}"
    except ValueError as exc:
        raise CliError(str(exc)) from None
    return None, "none"


def capture_of(args: argparse.Namespace, profile: Profile, command: str
               ) -> tuple[Dca1000Capture | NpyCapture, range]:
    """The capture of ``--capture`` in ``profile``'s format and its frames of ``--frames``;
    a truncated capture warned about (``radar <command>``); CliError (one line) for a file
    that does not fit the profile or frames outside it."""
    try:
        capture = open_capture(args.capture, profile)
    except ValueError as exc:
        raise CliError(str(exc)) from None
    if capture.dropped_bytes:
        warn([capture.report()], command)
    return capture, frame_range(args.frames, capture.n_frames)


def process_params(args: argparse.Namespace, profile: Profile) -> tuple[DetectionParams, str]:
    """``radar process``'s detection settings from its options (``radar.common.
    detection_params``: the profile's maximum speed and guard by default; ``--grouping``,
    ``--min-snr-db``) with the calibration applied before angle estimation
    (:func:`calibration_of`), and that calibration's name for the output; CliError if they
    do not fit."""
    params = detection_params(args, cfg=profile.config)
    calibration, cal_name = calibration_of(args.calibration, profile)
    try:
        return replace(params, calibration=calibration, grouping=args.grouping,
                       min_snr_db=args.min_snr_db), cal_name
    except ValueError as exc:
        raise CliError(f"--{str(exc).replace('_', '-')}") from None


def capture_frame_cloud(adc: np.ndarray, cfg: RadarConfig, params: DetectionParams,
                        frame_id: int, remove_static: bool) -> FrameCloud:
    """One ADC frame of a capture, complex (or real) (chirps in firing order, rx, samples)
    codes, -> its cube (the float reference's, ``model.reference.radar_cube``, computed fast
    by ``host.cube.frame_cube`` in single precision: complex64, within ``host.cube.
    SINGLE_RTOL`` of it; static clutter removed if asked) and point cloud
    (``radar.frame_cloud``), as ``radar process`` does."""
    cube = frame_cube(adc, cfg, params.range_window, params.doppler_window,
                      remove_static_clutter=remove_static, single=True)
    return frame_cloud(cube, cfg, params, frame_id, "process")


def clipped_samples(frame: np.ndarray, full_scale: int) -> int:
    """ADC values (I and Q counted apart) of a frame, complex or real integer codes, at or
    beyond full scale (+full_scale or -full_scale - 1): clipped, so the echo's harmonics
    can be false points."""
    lim = full_scale
    if np.iscomplexobj(frame):
        return int(np.count_nonzero(np.abs(frame.real) >= lim) +
                   np.count_nonzero(np.abs(frame.imag) >= lim))
    return int(np.count_nonzero(np.abs(frame) >= lim))


def cmd_process(args: argparse.Namespace) -> int:
    out = out_file(args.json, ".json", "--json")
    plots = out_folder(args.plots, "--plots") if args.plots else None
    if args.backend not in BACKENDS:
        raise CliError(f"--backend {args.backend}: radar process runs only "
                       f"{', '.join(BACKENDS)} for now")
    profile = profile_of(args.radar)
    cfg = profile.config
    params, cal_name = process_params(args, profile)
    capture, frames = capture_of(args, profile, "process")
    keep_freed_memory()             # frame after frame the same few MB (host.allocator)
    t0 = time.perf_counter()
    clouds, per_frame, clipped = [], [], []
    cube = None
    rec = open_recording(args, cfg.frame_time_s)
    stopped: str | None = None      # why the run ended early: what was done is written
    try:
        for k in progress(frames, "frames"):
            t_start = time.perf_counter()
            adc = capture.frame(k)
            n_clip = clipped_samples(adc, cfg.adc_full_scale)
            fc = capture_frame_cloud(adc, cfg, params, k, args.remove_static)
            cube = fc.cube
            clouds.append(fc.cloud)
            per_frame.append({"frame": k, "points": len(fc.cloud), "clipped": n_clip,
                              "damaged": False})
            if n_clip:
                clipped.append(k)
            if fc.problems:
                per_frame[-1]["problems"] = fc.problems
            if rec is not None:
                rec.write_frame(fc.cloud, FrameStatus(
                    k, len(fc.cloud), processing_time_s=time.perf_counter() - t_start,
                    problems=fc.problems))
    except KeyboardInterrupt:
        stopped = "interrupted"
    except ValueError as exc:
        stopped = str(exc)
    finally:
        close_recording(rec)
    stopped_before_any(stopped, len(per_frame))
    warn_clipped(clipped, "process")
    done = len(per_frame)
    cloud = PointCloud.concat(clouds)
    doc: dict[str, Any] = cloud.to_json_dict(cfg.name, done, clipped,
                                             has_vertical_extent(cfg.virtual_positions_hw))
    doc.update({"backend": args.backend, "detector": args.detector, "radar": profile.source,
                "capture": str(args.capture), "remove_static": args.remove_static,
                "calibration": cal_name, "grouping": params.grouping,
                "min_snr_db": params.min_snr_db,
                "max_speed_mps": params.max_speed_mps,
                "min_detection_range_m": cfg.min_detection_range_m,
                "frame_info": per_frame})
    doc.update(stop_fields(stopped, len(frames)))
    out.write_text(json.dumps(doc, indent=1))
    print(f"{len(cloud)} points in {done} frame(s) of {args.capture} "
          f"({time.perf_counter() - t0:.2f} s, calibration: {cal_name}) -> {out}")
    code = stop_exit(stopped, done, len(frames), out, "process")
    if code is not None:
        return code
    if plots and cube is not None:
        process_plots(plots, cfg, cube, clouds[-1], frames[-1])
    return 0


def add_parsers(sub: argparse._SubParsersAction, presets: list[str]) -> None:
    p = add_command(sub, "process", "radar capture -> point cloud JSON", """
        Read an ADC capture of a radar profile (a DCA1000 .bin or a .npy, docs/profiles.md),
        run its frames through the float reference of the chain and the host processing, and
        write the point cloud JSON `radar detect` writes (each point with its frame's index
        in the capture).""")
    p.add_argument("--radar", required=True, metavar="NAME|FILE",
                   help=f"the radar: preset ({', '.join(presets)}), profile .toml or TI .cfg")
    p.add_argument("--capture", required=True, metavar="FILE",
                   help="ADC capture: DCA1000 .bin (the profile's layout) or .npy")
    p.add_argument("--json", required=True, help="output point cloud .json")
    p.add_argument("--frames", default=None, metavar="A:B",
                   help="frames A..B-1 of the capture (A: or :B open-ended; default all)")
    p.add_argument("--remove-static", action="store_true",
                   help="subtract each range bin's mean over the frame's chirps, per channel, "
                        "before the Doppler FFT (static clutter and TX-RX leakage)")
    p.add_argument("--calibration", default=None, metavar="CAL.json",
                   help="calibration file (`radar calibrate`) applied before the angle "
                        "estimation (default: the TI .cfg's compRangeBiasAndRxChanPhase if "
                        "it has one, else none)")
    p.add_argument("--backend", default="float",
                   help="frame source: float, the float64 reference of the chain (the only "
                        "one for now: model and rtl process presets in `radar detect`)")
    p.add_argument("--plots", default=None,
                   help="folder for the last frame's range-Doppler map with its detections, "
                        "range-azimuth map and x-y point cloud")
    p.add_argument("--grouping", choices=GROUPINGS, default="peak",
                   help="peak: one detection per peak of the range-Doppler map (default); "
                        "doppler: one per range bin of a return that spans several (a "
                        "person, a car's body), the peaks along Doppler only")
    p.add_argument("--min-snr-db", type=float, default=None, metavar="DB",
                   help="detected cells must also be this far above their noise estimate "
                        "(mean SNR per channel; default: the CFAR's Pfa alone decides)")
    add_mcap_options(p)
    add_detection_options(p)
    p.set_defaults(func=cmd_process)
