"""``radar simulate``: frames of ADC samples of a scene, on a preset or any radar profile,
with the scene's real-world effects, to a ``.npy`` or a DCA1000 ``.bin`` capture."""

from __future__ import annotations

import argparse
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from host.adc_capture import write_npy
from host.dca1000 import write_dca1000
from host.params import default_max_speed_mps
from model.observability import scene_report
from model.simulate import MAX_FRAME_INDEX, check_frame_index, simulate_scene
from radar.common import (
    CliError,
    add_command,
    add_radar_option,
    count,
    out_file,
    scene_profile,
    warn,
)

OUT_SUFFIXES = (".npy", ".bin")
"""What ``--out`` may write: a .npy array or a DCA1000 .bin capture."""


def cmd_simulate(args: argparse.Namespace) -> int:
    scene, profile = scene_profile(args)
    cfg = scene.config
    if Path(args.out).suffix not in OUT_SUFFIXES:
        raise CliError(f"--out: {args.out} must end in {' or '.join(OUT_SUFFIXES)}")
    n = count(args.frames, "--frames", MAX_FRAME_INDEX + 1) or 1
    try:
        check_frame_index(args.frame)
    except ValueError as exc:
        raise CliError(f"--{exc}") from None
    if args.frame + n - 1 > MAX_FRAME_INDEX:
        raise CliError(f"--frames: frames {args.frame}..{args.frame + n - 1} go beyond the "
                       f"last frame index {MAX_FRAME_INDEX}")
    out = out_file(args.out, None, "--out")
    frames = range(args.frame, args.frame + n)
    _, warnings = scene_report(scene, frames, default_max_speed_mps(cfg))
    warn(warnings, "simulate")
    done: list[tuple[int, int, int]] = []     # per frame: saturated, passed, beyond the IF

    def samples() -> Iterator[np.ndarray]:
        for k in frames:
            f = simulate_scene(scene, frame_index=k)
            done.append((f.saturated, f.passed_scatterers, f.beyond_if_scatterers))
            yield f.samples

    try:
        if out.suffix == ".bin":
            write_dca1000(out, samples(), cfg, profile.capture)
        elif args.frames is None:
            np.save(out, next(samples()))
        else:
            write_npy(out, samples(), n, cfg)
    except ValueError as exc:
        raise CliError(f"--out: {exc}") from None
    saturated, passed, beyond = (sum(c) for c in zip(*done, strict=True))
    shape = (n, *cfg.adc_shape) if args.frames is not None or out.suffix == ".bin" \
        else cfg.adc_shape
    what = ("DCA1000 capture " + f"({profile.capture.lanes} lanes, "
            f"{'' if profile.capture.interleaved else 'not '}interleaved) of int16 "
            if out.suffix == ".bin" else
            ("complex64 " if cfg.adc == "complex" else "float32 "))
    print(f"wrote {out}: {what}{shape} ({'frames, ' if len(shape) == 4 else ''}chirps in "
          f"transmit order, rx, samples), {'preset' if scene.radar is None else 'radar'} "
          f"{cfg.name}, {len(scene.scatterers())} scatterers, {saturated} saturated "
          f"{'I/Q' if cfg.adc == 'complex' else 'ADC'} values, "
          f"{passed} scatterers at range <= 0 (passed the radar) and {beyond} beyond the IF "
          f"band not "
          f"simulated" + ("" if n == 1 else " (summed over the frames)"))
    if saturated:
        warn([f"{saturated} ADC values clipped at full scale"], "simulate")
    return 0


def add_parsers(sub: argparse._SubParsersAction, presets: list[str]) -> None:
    s = add_command(sub, "simulate", "simulate frames of ADC samples", """
        Simulate frames of a scene and write the ADC samples. One frame to a .npy: a complex64
        array of shape (NUM_TX*N_DOPPLER chirps in transmit order, NUM_RX, N_RANGE samples)
        holding the integer int16 I/Q codes the FPGA receives (for a profile: chirps, RX and
        samples per chirp of the profile; float32 codes for a real ADC). With --frames N, a
        .npy of shape (N, chirps, rx, samples); to a .bin, a DCA1000 capture in the profile's
        LVDS layout (docs/profiles.md), which `radar process` reads. The scene's
        "impairments" table adds real-world effects (docs/profiles.md).""")
    s.add_argument("--scene", required=True,
                   help="scene JSON file, or the name of a built-in scene (table1)")
    s.add_argument("--out", required=True,
                   help="output .npy (ADC frames) or .bin (DCA1000 capture)")
    s.add_argument("--preset", choices=presets, default=None,
                   help="override the scene's radar preset")
    add_radar_option(s, "the scene's preset")
    s.add_argument("--frame", type=int, default=0,
                   help=f"frame index 0..{MAX_FRAME_INDEX} (the first, with --frames): targets "
                        f"move v*frame*frame_period, fresh noise (default 0)")
    s.add_argument("--frames", type=int, default=None, metavar="N",
                   help="simulate N consecutive frames (default: one, a .npy of one frame's "
                        "shape)")
    s.set_defaults(func=cmd_simulate)
