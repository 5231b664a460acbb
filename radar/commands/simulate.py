"""``radar simulate``: one frame of ADC samples of a scene to a .npy file."""

from __future__ import annotations

import argparse
import sys

import numpy as np

from model.simulate import simulate_scene
from radar.common import CliError, out_file, scene_of


def cmd_simulate(args: argparse.Namespace) -> int:
    scene = scene_of(args)
    out = out_file(args.out, ".npy", "--out")
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


def add_parsers(sub: argparse._SubParsersAction, presets: list[str]) -> None:
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
