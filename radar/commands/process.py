"""``radar process``: a capture of a radar profile -> the point cloud JSON (docs/profiles.md).

The profile (``--radar``: a preset, a TOML profile or a TI ``.cfg``, ``model.profile``) says
how to read the capture (``--capture``: a DCA1000 ``.bin`` or a ``.npy``,
``host.adc_capture.open_capture``); its frames are read one at a time and turned into radar
cubes by the backend: ``float``, the float reference of the chain
(``model.reference.radar_cube``; computed by its fast equivalent ``host.cube.frame_cube``),
or the FPGA chain built with the profile's HDL parameters (``model.hdl``), ``model`` its
bit-accurate model and ``rtl`` the Verilated top (``radar.sources``), whose DMA bytes the host
decodes as the board's (the cube, or with ``--detect fpga`` the on-chip detector's records).
Then the host processing (``radar.frame_cloud``) makes the point clouds, as ``radar detect``
does with simulated frames. The JSON is ``radar detect``'s, each point carrying its frame's
index in the capture.
"""

from __future__ import annotations

import argparse
import json
import time
from collections.abc import Iterator
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
from model.config import RadarConfig
from model.detect_chain import DetectConfig
from model.hdl import DATA_W
from model.profile import Calibration, Profile, load_profile
from model.radar_pipeline import PipelineParams, range_scale_for_peak
from model.simulate import quantize_adc
from radar.commands.detect import add_fpga_options, fpga_config
from radar.common import (
    CliError,
    add_command,
    add_detection_options,
    add_refine_options,
    check_source,
    detection_params,
    out_file,
    out_folder,
    progress,
    refuse_detection_misfits,
    stop_exit,
    stop_fields,
    stopped_before_any,
    warn,
    warn_clipped,
)
from radar.figures import process_plots
from radar.frame_cloud import FrameCloud, dma_frame_info, frame_cloud
from radar.recording import add_mcap_options, close_recording, open_recording
from radar.sources import FrameSource, SourceError, get_source

BACKENDS = ("float", "model", "rtl")
"""Frame sources ``radar process`` runs: the float reference (default), the bit-accurate
model and the Verilated RTL of the FPGA chain (``radar.sources``)."""


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
    ``--min-snr-db``; ``--remove-static``: the CFAR told, ``DetectionParams.static_removed``)
    with the calibration applied before angle estimation (:func:`calibration_of`), and that
    calibration's name for the output; CliError if they do not fit."""
    params = detection_params(args, cfg=profile.config)
    calibration, cal_name = calibration_of(args.calibration, profile)
    try:
        return replace(params, calibration=calibration, grouping=args.grouping,
                       min_snr_db=args.min_snr_db, static_removed=args.remove_static), \
            cal_name
    except ValueError as exc:
        raise CliError(f"--{str(exc).replace('_', '-')}") from None


def hdl_frame(adc: np.ndarray) -> np.ndarray:
    """A capture's ADC frame (chirps, rx, samples) as the RTL takes it: I and Q (or the real
    values) rounded and saturated to ``model.hdl.DATA_W`` bits
    (``model.simulate.quantize_adc``, as the simulated frames of ``radar detect`` are to
    ``adc_bits`` <= DATA_W); a DCA1000 capture's 16-bit codes pass unchanged."""
    return quantize_adc(np.asarray(adc), DATA_W)[0]


def capture_peak(capture: Dca1000Capture | NpyCapture) -> float:
    """The largest |I| or |Q| (real ADC: |value|) of the whole capture, codes (one pass over
    it before the chain is built, so a frame gives the same points whatever ``--frames``
    selects)."""
    peak = 0.0
    for k in progress(range(capture.n_frames), "ADC peak"):
        adc = capture.frame(k)
        peak = max(peak, float(np.abs(adc.real).max()), float(np.abs(adc.imag).max()))
    return peak


def chain_source(args: argparse.Namespace, cfg: RadarConfig) -> FrameSource | None:
    """The FPGA chain's frame source of ``--backend model|rtl`` (static-clutter removal in
    the chain with ``--remove-static``), None for ``--backend float``; CliError (one line,
    before any work) when it cannot run ``cfg`` or ``--detect fpga`` has no chain."""
    if args.backend == "float":
        if args.detect == "fpga":
            raise CliError("--detect fpga: the on-chip detector is the FPGA chain's "
                           "(--backend model or rtl)")
        return None
    source = get_source(args.backend, PipelineParams(static_removal=args.remove_static))
    check_source(source, cfg, alternative="--backend float" if args.detect == "host"
                 else "--detect host --backend float")
    return source


def scaled_for(source: FrameSource, cfg: RadarConfig, peak: float) -> FrameSource:
    """``source`` with the chain's range FFT scaled for ADC codes within +-``peak``
    (``model.radar_pipeline.range_scale_for_peak``: the HDL parameter RANGE_SCALE_SCH)."""
    sch = range_scale_for_peak(cfg, peak, source.chain)
    return get_source(source.name, replace(source.chain, range_scale_sch=sch))


def capture_cube(adc: np.ndarray, cfg: RadarConfig, range_window: bool = True,
                 doppler_window: bool = True, remove_static: bool = False) -> np.ndarray:
    """The one way the commands make a cube of a capture's ADC frame (``radar process``,
    ``radar calibrate``): complex (or real) (chirps in firing order, rx, samples) codes ->
    the float reference's cube (``model.reference.radar_cube``), computed fast by
    ``host.cube.frame_cube`` in single precision: complex64 (n_virtual, n_range_bins,
    n_doppler), within ``host.cube.SINGLE_RTOL`` of it; static clutter removed if asked."""
    return frame_cube(adc, cfg, range_window, doppler_window,
                      remove_static_clutter=remove_static, single=True)


def capture_frame_cloud(adc: np.ndarray, cfg: RadarConfig, params: DetectionParams,
                        frame_id: int, remove_static: bool) -> FrameCloud:
    """One ADC frame of a capture (:func:`capture_cube`) -> its cube and point cloud
    (``radar.frame_cloud``), as ``radar process`` does."""
    cube = capture_cube(adc, cfg, params.range_window, params.doppler_window, remove_static)
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


def frame_clouds(adc_frames: Iterator[np.ndarray], frames: range, cfg: RadarConfig,
                 params: DetectionParams, source: FrameSource | None,
                 dcfg: DetectConfig | None, remove_static: bool
                 ) -> Iterator[tuple[int, FrameCloud, dict[str, Any]]]:
    """The capture's frames ``frames`` (their ADC frames ``adc_frames``, in order) -> per
    frame its index in the capture, its :class:`FrameCloud` and what its ``frame_info``
    entry adds: through the float reference (``source`` None), or the DMA frames
    ``source`` decodes (cubes, or records with ``dcfg``: damage, records, truncation)."""
    if source is None:
        for k, adc in zip(frames, adc_frames, strict=True):
            yield k, capture_frame_cloud(adc, cfg, params, k, remove_static), {}
        return
    # the model and the RTL send every frame, in order, numbered from 0 after reset
    done = 0
    for k, f in zip(frames, source.dma_frames(adc_frames, cfg, dcfg), strict=False):
        fc = frame_cloud(f, cfg, params, k, "process")
        info = dma_frame_info(f, k, "process", dcfg.max_detections if dcfg else 0)
        done += 1
        yield k, fc, {**info, "damaged": not f.complete, "problems": f.problems}
    if done < len(frames):
        raise SourceError(f"{len(frames) - done} of {len(frames)} frame(s) did not come out "
                          f"of the chain")


def cmd_process(args: argparse.Namespace) -> int:
    out = out_file(args.json, ".json", "--json")
    plots = out_folder(args.plots, "--plots") if args.plots else None
    refuse_detection_misfits(args, args.detect == "fpga")
    profile = profile_of(args.radar)
    cfg = profile.config
    source = chain_source(args, cfg)
    params, cal_name = process_params(args, profile)
    dcfg = fpga_config(args, cfg, params) if args.detect == "fpga" else None
    capture, frames = capture_of(args, profile, "process")
    keep_freed_memory()             # frame after frame the same few MB (host.allocator)
    if source is not None:
        source = scaled_for(source, cfg, capture_peak(capture))
    t0 = time.perf_counter()
    clouds, per_frame, clipped = [], [], []
    n_clip: dict[int, int] = {}
    cube = None
    rec = open_recording(args, cfg.frame_time_s)
    stopped: str | None = None      # why the run ended early: what was done is written

    def adc_frames() -> Iterator[np.ndarray]:
        for k in progress(frames, "frames"):
            adc = capture.frame(k)
            n_clip[k] = clipped_samples(adc, cfg.adc_full_scale)
            yield adc if source is None else hdl_frame(adc)

    try:
        t_start = time.perf_counter()
        for k, fc, info in frame_clouds(adc_frames(), frames, cfg, params, source, dcfg,
                                        args.remove_static):
            cube = fc.cube
            clouds.append(fc.cloud)
            problems = info.pop("problems", []) + fc.problems
            per_frame.append({"frame": k, "points": len(fc.cloud), "clipped": n_clip[k],
                              "damaged": False, **info})
            if n_clip[k]:
                clipped.append(k)
            if problems:
                per_frame[-1]["problems"] = problems
            if rec is not None:
                rec.write_frame(fc.cloud, FrameStatus(
                    k, len(fc.cloud), processing_time_s=time.perf_counter() - t_start,
                    problems=problems))
            t_start = time.perf_counter()
    except KeyboardInterrupt:
        stopped = "interrupted"
    except SourceError as exc:
        stopped = f"--backend {args.backend}: {exc}"
    except ValueError as exc:
        stopped = str(exc)
    finally:
        close_recording(rec)
    stopped_before_any(stopped, len(per_frame))
    clipped.sort()
    warn_clipped(clipped, "process")
    done = len(per_frame)
    cloud = PointCloud.concat(clouds)
    doc: dict[str, Any] = cloud.to_json_dict(cfg, done, clipped)
    doc.update({"backend": args.backend, "detector": args.detector, "detect": args.detect,
                "radar": profile.source,
                "capture": str(args.capture), "remove_static": args.remove_static,
                "calibration": cal_name, "grouping": params.grouping,
                "min_snr_db": params.min_snr_db,
                "max_speed_mps": params.max_speed_mps,
                "min_detection_range_m": cfg.min_detection_range_m,
                "frame_info": per_frame})
    if source is not None:
        doc["range_scale_sch"] = source.chain.range_scale_sch
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
        run its frames through the float reference of the chain, or the FPGA chain's
        bit-accurate model or RTL, and the host processing, and write the point cloud JSON
        `radar detect` writes (each point with its frame's index in the capture).""")
    p.add_argument("--radar", required=True, metavar="NAME|FILE",
                   help=f"the radar: preset ({', '.join(presets)}), profile .toml or TI .cfg")
    p.add_argument("--capture", required=True, metavar="FILE",
                   help="ADC capture: DCA1000 .bin (the profile's layout) or .npy")
    p.add_argument("--json", required=True, help="output point cloud .json")
    p.add_argument("--frames", default=None, metavar="A:B",
                   help="frames A..B-1 of the capture (A: or :B open-ended; default all)")
    p.add_argument("--remove-static", action="store_true",
                   help="subtract each range bin's mean over the frame's chirps, per channel, "
                        "before the Doppler FFT (static clutter and TX-RX leakage; model and "
                        "rtl: the chain's static_removal block, STATIC_REMOVAL = 1)")
    p.add_argument("--calibration", default=None, metavar="CAL.json",
                   help="calibration file (`radar calibrate`) applied before the angle "
                        "estimation (default: the TI .cfg's compRangeBiasAndRxChanPhase if "
                        "it has one, else none)")
    p.add_argument("--backend", choices=BACKENDS, default="float",
                   help="float: the float64 reference of the chain (default); model: the "
                        "bit-accurate model of the FPGA chain, rtl: the Verilated top (both "
                        "built with the profile's HDL parameters, their DMA bytes decoded as "
                        "the board's; a profile the RTL takes)")
    p.add_argument("--detect", choices=("host", "fpga"), default="host",
                   help="host: the host runs the CFAR on the cube (default); fpga: the "
                        "chain's on-chip detector (OUTPUT_MODE = 1) and the host goes on "
                        "from its records (--backend model or rtl)")
    add_fpga_options(p)
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
    add_refine_options(p, "a fixed-point cube")
    p.set_defaults(func=cmd_process)
