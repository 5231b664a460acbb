"""``radar simulate``: one frame of ADC samples of a scene to a .npy file."""

from __future__ import annotations

import argparse

import numpy as np

from host.params import MAX_RADIAL_SPEED_MPS
from model.observability import scene_report
from model.simulate import MAX_FRAME_INDEX, check_frame_index, simulate_scene
from radar.common import CliError, add_command, out_file, scene_of, warn


def cmd_simulate(args: argparse.Namespace) -> int:
    scene = scene_of(args)
    out = out_file(args.out, ".npy", "--out")
    try:
        check_frame_index(args.frame)
    except ValueError as exc:
        raise CliError(f"--{exc}") from None
    _, warnings = scene_report(scene, [args.frame], MAX_RADIAL_SPEED_MPS)
    warn(warnings, "simulate")
    frame = simulate_scene(scene, frame_index=args.frame)
    np.save(out, frame.samples)
    print(f"wrote {out}: complex64 {frame.samples.shape} (chirps in transmit order, rx, "
          f"samples), preset {scene.config.name}, {len(scene.scatterers())} scatterers, "
          f"{frame.saturated} saturated I/Q values, {frame.passed_scatterers} scatterers "
          f"at range <= 0 (passed the radar) and {frame.beyond_if_scatterers} beyond the IF "
          f"band not simulated")
    if frame.saturated:
        warn([f"{frame.saturated} ADC values clipped at full scale"], "simulate")
    return 0


def add_parsers(sub: argparse._SubParsersAction, presets: list[str]) -> None:
    s = add_command(sub, "simulate", "simulate one frame of ADC samples", """
        Simulate one frame of a scene and write the ADC samples as a complex64 .npy array of shape
        (NUM_TX*N_DOPPLER chirps in transmit order, NUM_RX, N_RANGE samples) holding the integer
        int16 I/Q codes the FPGA receives.""")
    s.add_argument("--scene", required=True,
                   help="scene JSON file, or the name of a built-in scene (table1)")
    s.add_argument("--out", required=True, help="output .npy file")
    s.add_argument("--preset", choices=presets, default=None,
                   help="override the scene's radar preset")
    s.add_argument("--frame", type=int, default=0,
                   help=f"frame index 0..{MAX_FRAME_INDEX}: targets move v*frame*frame_time, "
                        f"fresh noise (default 0)")
    s.set_defaults(func=cmd_simulate)
