"""Helpers shared by the ``radar`` commands: the one-line error, option groups, input and
output checks."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import TypeVar

from tqdm import tqdm

from host.cfar import CfarParams
from host.pipeline import DETECTORS, DetectionParams
from model.scene import EGO_SPEED_KMH, Scene, load_scene

T = TypeVar("T")


class CliError(Exception):
    """Bad input: reported as one line, exit status 2."""


def progress(iterable: Iterable[T], desc: str, total: int | None = None) -> Iterator[T]:
    """tqdm progress bar on stderr when it is a terminal (quiet in CI logs)."""
    return tqdm(iterable, desc=desc, total=total, disable=not sys.stderr.isatty(), leave=False)


def scene_of(args: argparse.Namespace) -> Scene:
    """The scene of ``--scene`` (file or built-in name) with ``--preset`` if given."""
    try:
        return load_scene(args.scene, getattr(args, "preset", None))
    except ValueError as exc:
        raise CliError(str(exc)) from None


def detection_params(args: argparse.Namespace, scene_bf: bool = True) -> DetectionParams:
    """Host detection settings from the options of :func:`add_detection_options`."""
    try:
        cfar = CfarParams(pfa=args.pfa, guard=tuple(args.guard), train=tuple(args.train),
                          kind="os" if args.detector == "os" else "ca")
        return DetectionParams(detector=args.detector, cfar=cfar,
                               paper_threshold_db=args.threshold_db, tx_beamforming=scene_bf)
    except ValueError as exc:
        raise CliError(str(exc)) from None


def out_file(path: str, suffix: str, option: str) -> Path:
    """``path`` checked to end in ``suffix``, its folder created."""
    p = Path(path)
    if p.suffix != suffix:
        raise CliError(f"{option}: {p} must end in {suffix}")
    p.parent.mkdir(parents=True, exist_ok=True)
    return p


def ego_speed_mps(args: argparse.Namespace, scene: Scene) -> float:
    """``--ego-speed``, else the Table I ego speed for ``table1`` and 0 otherwise."""
    if args.ego_speed is not None:
        return float(args.ego_speed)
    return EGO_SPEED_KMH / 3.6 if scene.name == "table1" else 0.0


def add_detection_options(p: argparse.ArgumentParser) -> None:
    """Detector choice and CFAR settings."""
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
