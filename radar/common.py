"""Helpers shared by the ``radar`` commands: the one-line error, option groups, input and
output checks."""

from __future__ import annotations

import argparse
import sys
import tempfile
from collections.abc import Iterable, Iterator
from dataclasses import replace
from pathlib import Path
from typing import TypeVar

from tqdm import tqdm

from host.angle import AngleParams
from host.cfar import CfarParams
from host.params import (
    DETECTORS,
    MAX_RADIAL_SPEED_MPS,
    DetectionParams,
    default_guard,
    default_max_speed_mps,
)
from host.refine import FIXED_POINT_FLOOR, FLOAT_FLOOR
from model.config import RadarConfig, get_preset
from model.profile import Profile, load_profile, preset_profile
from model.scene import Scene, check_ego_speed, default_ego_speed_mps, load_scene
from radar.sources import FrameSource, SourceError, get_source

T = TypeVar("T")


class CliError(Exception):
    """Bad input: reported as one line, exit status 2."""


def progress(iterable: Iterable[T], desc: str, total: int | None = None) -> Iterator[T]:
    """tqdm progress bar on stderr when it is a terminal (quiet in CI logs)."""
    return tqdm(iterable, desc=desc, total=total, disable=not sys.stderr.isatty(), leave=False)


def add_radar_option(p: argparse.ArgumentParser, instead: str) -> None:
    """``--radar PROFILE``: the radar ``instead`` of the preset (a preset name, a TOML
    profile or a TI .cfg; :func:`radar_profile`)."""
    p.add_argument("--radar", default=None, metavar="PROFILE",
                   help=f"the radar instead of {instead}: a preset name, a TOML profile or a "
                        f"TI .cfg (docs/profiles.md); not with --preset")


def radar_profile(args: argparse.Namespace) -> Profile | None:
    """The profile of ``--radar`` (``model.profile.load_profile``), None without it;
    CliError (one line) for a bad profile or when ``--preset`` is given too."""
    spec = getattr(args, "radar", None)
    if spec is None:
        return None
    if getattr(args, "preset", None) is not None:
        raise CliError("--radar and --preset: give one of them")
    try:
        return load_profile(spec)
    except ValueError as exc:
        raise CliError(str(exc)) from None


def radar_of(args: argparse.Namespace) -> RadarConfig | None:
    """The radar of ``--radar`` or ``--preset`` (None: neither given)."""
    profile = radar_profile(args)
    if profile is not None:
        return profile.config
    return get_preset(args.preset) if args.preset else None


def on_radar(scene: Scene, profile: Profile | None) -> Scene:
    """``scene`` on the radar of ``profile`` (``Scene.radar``; None: the scene's preset);
    CliError (one line) for impairments that radar cannot have."""
    if profile is None:
        return scene
    try:
        return replace(scene, radar=profile.config)
    except ValueError as exc:
        raise CliError(str(exc)) from None


def scene_profile(args: argparse.Namespace) -> tuple[Scene, Profile]:
    """The scene of ``--scene`` (file or built-in name) on the radar of ``--radar`` or
    ``--preset`` (:func:`radar_profile`), and that radar's profile (without ``--radar``:
    the scene's preset's, ``model.profile.preset_profile``)."""
    profile = radar_profile(args)
    try:
        scene = load_scene(args.scene, getattr(args, "preset", None))
    except ValueError as exc:
        raise CliError(str(exc)) from None
    return on_radar(scene, profile), profile or preset_profile(scene.preset)


def scene_of(args: argparse.Namespace) -> Scene:
    """The scene of ``--scene`` on the radar of ``--radar`` or ``--preset``
    (:func:`scene_profile`)."""
    return scene_profile(args)[0]


def check_source(source: FrameSource, cfg: RadarConfig, what: str | None = None,
                 alternative: str | None = "--backend float") -> None:
    """One-line CliError, before any work, when ``source`` cannot run the radar ``cfg``
    (``FrameSource.check``: the bit-accurate model and the RTL run what the HDL supports):
    ``what`` (default ``--backend NAME``), why, and ``alternative`` when the float source
    runs ``cfg``."""
    try:
        source.check(cfg)
    except SourceError as exc:
        line = f"{what or '--backend ' + source.name}: {exc}"
        if alternative and source.name != "float":
            try:
                get_source("float").check(cfg)
                line += f" ({alternative} runs it)"
            except SourceError:
                pass
        raise CliError(line) from None


def detection_params(args: argparse.Namespace, scene_bf: bool = True,
                     cfg: RadarConfig | None = None) -> DetectionParams:
    """Host detection settings from the options of :func:`add_detection_options`, checked
    against ``cfg`` when given (CFAR window larger than the map); without ``--max-speed``
    the radar's (``host.params.default_max_speed_mps``: a profile's ``max_speed_mps``,
    100 m/s for the presets and without ``cfg``); without ``--guard`` the guard is
    ``cfg``'s main lobe (``host.params.default_guard``)."""
    speed = args.max_speed if args.max_speed is not None else (
        MAX_RADIAL_SPEED_MPS if cfg is None else default_max_speed_mps(cfg))
    guard = tuple(args.guard) if cfg is None or given(args, "guard") else default_guard(cfg)
    try:
        cfar = CfarParams(pfa=args.pfa, guard=guard, train=tuple(args.train),
                          kind="os" if args.detector == "os" else "ca")
        params = DetectionParams(detector=args.detector, cfar=cfar,
                                 paper_threshold_db=args.threshold_db, tx_beamforming=scene_bf,
                                 max_speed_mps=speed,
                                 angle=AngleParams(array_error_db=args.array_error_db),
                                 **refine_settings(args))
        if cfg is not None:
            params.check(cfg)
        return params
    except ValueError as exc:
        raise CliError(str(exc)) from None


def check(value: T, option: str, ok: bool, what: str) -> T:
    """``value`` of ``option`` if ``ok``, else a one-line CliError saying what it must be."""
    if not ok:
        raise CliError(f"{option}: must be {what}, got {value!r}")
    return value


def count(value: int | None, option: str, hi: int, lo: int = 1) -> int | None:
    """An integer option in lo..hi (None passes: option not given)."""
    if value is None:
        return None
    return check(value, option, lo <= value <= hi, f"an integer in {lo}..{hi}")


def warn(lines: Iterable[str], command: str) -> None:
    """One ``radar <command>: warning: ...`` line on stderr per entry."""
    for line in lines:
        print(f"radar {command}: warning: {line}", file=sys.stderr)


_compile_noted = False


def note_compile(command: str) -> None:
    """Once per process, right before the first records -> point cloud call: one
    ``radar <command>: ...`` line on stderr when the host's compiled kernels
    (``host.kernels``) are not cached yet (that call then takes 20-30 s longer, once
    per checkout); the kernels only some data reaches are compiled right then, so the
    note does not come back."""
    global _compile_noted
    if _compile_noted:
        return
    _compile_noted = True
    from host import kernels  # numba: only where records are
    if kernels.uncompiled_kernels():
        print(f"radar {command}: compiling the host kernels (numba; "
              "first run in this checkout, 20-30 s)", file=sys.stderr)
        kernels.compile_data_dependent()    # then the next run finds every kernel cached


def out_file(path: str, suffix: str | None, option: str) -> Path:
    """``path`` checked, before any work, to end in ``suffix`` (None: any name) and to be a
    file this process can write (its folder created; an existing file is not changed)."""
    p = Path(path)
    if suffix is not None and p.suffix != suffix:
        raise CliError(f"{option}: {p} must end in {suffix}")
    if p.is_dir():
        raise CliError(f"{option}: {p} is a folder, not a file")
    _make_folder(p.parent, option)
    try:
        if p.exists():
            with open(p, "ab"):          # writable? (append mode: the content stays)
                pass
        else:
            with open(p, "xb"):
                pass
            p.unlink()
    except OSError as exc:
        raise CliError(f"{option}: cannot write {p}: {exc.strerror or exc}") from None
    return p


def out_folder(path: str, option: str) -> Path:
    """``path`` checked, before any work, to be a folder this process can write in (created
    if missing)."""
    p = Path(path)
    if p.exists() and not p.is_dir():
        raise CliError(f"{option}: {p} is a file, not a folder")
    _make_folder(p, option)
    try:
        with tempfile.NamedTemporaryFile(dir=p, prefix=".write-test-"):
            pass
    except OSError as exc:
        raise CliError(f"{option}: cannot write in {p}: {exc.strerror or exc}") from None
    return p


def _make_folder(p: Path, option: str) -> None:
    """``p`` created with its parents (CliError naming ``option`` when it cannot be)."""
    try:
        p.mkdir(parents=True, exist_ok=True)
    except FileExistsError:
        raise CliError(f"{option}: {p} is a file, not a folder") from None
    except OSError as exc:
        raise CliError(f"{option}: cannot make the folder {p}: {exc.strerror or exc}") from None


def port(value: int, option: str, allow_zero: bool = True) -> int:
    """A port option checked to be in 0..65535 (1..65535 without ``allow_zero``)."""
    lo = 0 if allow_zero else 1
    return check(value, option, lo <= value <= 65535, f"a port number in {lo}..65535")


def ego_speed_mps(args: argparse.Namespace, scene: Scene | None) -> float:
    """``--ego-speed`` (checked), else the scene's (``model.scene.default_ego_speed_mps``:
    the Table I 100 km/h for ``table1``, 0 otherwise; 0 without a scene). ``radar detect
    --gnn`` and ``radar gnn detect`` both use it."""
    try:
        if args.ego_speed is not None:
            return check_ego_speed(args.ego_speed)
    except ValueError as exc:
        raise CliError(f"--{exc}") from None
    return default_ego_speed_mps(scene) if scene is not None else 0.0


def add_detection_options(p: argparse.ArgumentParser) -> None:
    """Detector choice and CFAR settings (:func:`detection_params`)."""
    p.add_argument("--detector", choices=DETECTORS, default="ca",
                   help="ca: 2-D CA-CFAR on the non-coherent map (default); os: OS-CFAR "
                        "(slower); paper: the paper's threshold on channel 0")
    p.add_argument("--pfa", type=float, default=1e-6,
                   help="CFAR false-alarm probability per range-Doppler cell (default 1e-6)")
    p.add_argument("--guard", type=int, nargs=2, default=(2, 2), metavar=("RANGE", "DOPPLER"),
                   help="CFAR guard cells per side (default 2 2, the Hann main lobe; "
                        "wider for a zero-padded profile)")
    p.add_argument("--train", type=int, nargs=2, default=(4, 8), metavar=("RANGE", "DOPPLER"),
                   help="CFAR training cells per side (default 4 8)")
    p.add_argument("--threshold-db", type=float, default=15.0,
                   help="paper detector: threshold over the channel-0 median, dB (default 15)")
    p.add_argument("--max-speed", type=float, default=None,
                   help="fastest radial speed to expect, m/s: velocities are unfolded within "
                        "it and a point is flagged ambiguous when another velocity within it "
                        "explains the measurement (default: the radar profile's max_speed_mps, "
                        "its unambiguous speed unless it states one; "
                        f"{MAX_RADIAL_SPEED_MPS:g} for the presets)")
    p.add_argument("--array-error-db", type=float, default=AngleParams.array_error_db,
                   help="the array's model error (calibration residue) relative to a "
                        "target, dB: a second angle component in a cell is kept only beyond "
                        "what it and the noise explain (default "
                        f"{AngleParams.array_error_db:g}, an uncalibrated array; about -25 "
                        "after `radar calibrate`; docs/profiles.md \"Angles\")")


def add_refine_options(p: argparse.ArgumentParser, fixed_point: str) -> None:
    """``--refine`` and ``--refine-floor`` (:func:`refine_settings`); ``fixed_point``: the
    sources whose cube is the fixed-point chain's (they get its floor by default)."""
    p.add_argument("--refine", action="store_true",
                   help="re-estimate each detected cell's range and Doppler from the whole "
                        "frame (the channel-summed periodogram's peak, host.refine; 7 dB "
                        "lower MSE on a float cube, about 30 ms per cell; complex ADC only; "
                        "docs/curves.md)")
    p.add_argument("--refine-floor", type=float, default=None, metavar="F",
                   help="--refine: weighting floor against the rounding after the windows "
                        f"(default {FLOAT_FLOOR:g} for a float cube, {FIXED_POINT_FLOOR:g} "
                        f"for {fixed_point})")


def refine_settings(args: argparse.Namespace) -> dict[str, object]:
    """``refine`` / ``refine_floor`` of :class:`DetectionParams` from the options of
    :func:`add_refine_options` (none for a command without them): the floor of the
    fixed-point chain when ``args.backend`` is ``model`` or ``rtl``."""
    if not getattr(args, "refine", False):
        if getattr(args, "refine_floor", None) is not None:
            raise CliError("--refine-floor: only with --refine")
        return {}
    floor = args.refine_floor
    if floor is None:
        floor = FIXED_POINT_FLOOR if getattr(args, "backend", "float") in ("model", "rtl") \
            else FLOAT_FLOOR
    return {"refine": True, "refine_floor": floor}


def add_command(sub: argparse._SubParsersAction, name: str, summary: str,
                description: str) -> argparse.ArgumentParser:
    """A ``radar`` subcommand's parser: ``summary`` in ``radar --help``, ``description`` (one
    paragraph; its line breaks and indentation are re-wrapped) on the command's own page.
    The parsed options keep the parser (``args.parser``) for :func:`refuse`."""
    p = sub.add_parser(name, help=summary, description=" ".join(description.split()))
    p.set_defaults(parser=p)
    return p


def given(args: argparse.Namespace, dest: str) -> bool:
    """Whether option ``dest`` has a value other than its default (the user gave it)."""
    parser: argparse.ArgumentParser | None = getattr(args, "parser", None)
    default = parser.get_default(dest) if parser is not None else None
    value = getattr(args, dest)
    return (list(value) if isinstance(value, list | tuple) else value) != (
        list(default) if isinstance(default, list | tuple) else default)


DETECTION_OPTIONS = ("detector", "pfa", "guard", "train", "threshold_db", "max_speed")
"""Destinations of :func:`add_detection_options`."""
FPGA_OPTIONS = ("fpga_cfar", "max_detections")
"""Destinations of the on-chip detector's options (``radar.commands.detect``)."""


def refuse(args: argparse.Namespace, dests: Iterable[str], why: str) -> None:
    """One-line CliError when any option of ``dests`` was given: it does not apply (``why``
    says to what)."""
    for dest in dests:
        if given(args, dest):
            raise CliError(f"--{dest.replace('_', '-')}: does not apply {why}")


def refuse_detection_misfits(args: argparse.Namespace, fpga: bool) -> None:
    """The detection options that do not apply: ``--fpga-cfar``/``--max-detections``
    without ``--detect fpga``, ``--threshold-db`` without ``--detector paper``."""
    if not fpga:
        refuse(args, FPGA_OPTIONS, "without --detect fpga (the host runs the CFAR)")
    if args.detector != "paper":
        refuse(args, ("threshold_db",), "to --detector " + args.detector
               + " (it is the paper detector's threshold)")


def stopped_before_any(stopped: str | None, done: int) -> None:
    """A run that stopped (``stopped``: "interrupted" or the error) before its first frame
    has nothing to write: Ctrl-C goes on as KeyboardInterrupt, an error as a CliError."""
    if stopped and not done:
        if stopped == "interrupted":
            raise KeyboardInterrupt
        raise CliError(stopped)


def warn_clipped(clipped: list[int], command: str) -> None:
    """The one-line warning of the frames (indices, sorted) whose ADC values clipped."""
    if clipped:
        warn([f"ADC clipped in {len(clipped)} frame(s) ({clipped[0]}..{clipped[-1]}): "
              f"harmonics of the clipped echo can appear as false points (flagged "
              f"\"clipped\" in the JSON)"], command)


def stop_fields(stopped: str | None, requested: int) -> dict[str, object]:
    """The JSON fields of a run that stopped early (none when it completed)."""
    if not stopped:
        return {}
    return {"interrupted": stopped == "interrupted", "error": stopped,
            "frames_requested": requested}


def stop_exit(stopped: str | None, done: int, requested: int, out: Path, command: str
              ) -> int | None:
    """After the JSON of a stopped run is written: Ctrl-C warns and gives exit status 130,
    an error is a CliError naming what was kept; None when the run completed."""
    if stopped == "interrupted":
        warn([f"interrupted: wrote the {done} of {requested} frame(s) processed"], command)
        return 130
    if stopped:
        raise CliError(f"{stopped} (after {done} of {requested} frame(s): those are in "
                       f"{out})")
    return None
