"""The ``radar`` command line.

    radar simulate --scene SCENE.json|table1 --out ADC.npy
    radar demo [--out DIR]

Bad input ends with exit status 2 and a one-line reason on stderr.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

from model.config import PRESETS
from model.reference import radar_cube, range_doppler_power
from model.scene import load_scene, table1_scene
from model.simulate import simulate_scene


class CliError(Exception):
    """Bad input: reported as one line, exit status 2."""


def _scene_arg(args: argparse.Namespace):
    try:
        return load_scene(args.scene, getattr(args, "preset", None))
    except ValueError as exc:
        raise CliError(str(exc)) from None


def cmd_simulate(args: argparse.Namespace) -> int:
    scene = _scene_arg(args)
    frame = simulate_scene(scene, frame_index=args.frame)
    out = Path(args.out)
    if out.suffix != ".npy":
        raise CliError(f"--out: {out} must end in .npy")
    out.parent.mkdir(parents=True, exist_ok=True)
    np.save(out, frame.samples)
    cfg = scene.config
    print(f"wrote {out}: complex64 {frame.samples.shape} (chirps in transmit order, rx, "
          f"samples), preset {cfg.name}, {len(scene.scatterers())} scatterers, "
          f"{frame.saturated} saturated I/Q values, {frame.dropped_scatterers} scatterers "
          f"beyond the IF band")
    if frame.saturated:
        print(f"warning: {frame.saturated} ADC values clipped at full scale", file=sys.stderr)
    return 0


def cmd_demo(args: argparse.Namespace) -> int:
    from host.plots import plot_range_doppler

    out = Path(args.out)
    scene = table1_scene(args.preset)
    cfg = scene.config
    t0 = time.perf_counter()
    frame = simulate_scene(scene)
    cube = radar_cube(frame.samples, cfg)
    elapsed = time.perf_counter() - t0
    markers = []
    print(f"Table I scene, preset {cfg.name}: simulated and processed one frame in "
          f"{elapsed:.2f} s ({frame.saturated} saturated values)")
    print(f"{'vehicle':>7} {'range m':>8} {'v_r m/s':>8} {'az deg':>7} {'range bin':>9} "
          f"{'Doppler bin':>11}  note")
    for i, t in enumerate(scene.targets, start=1):
        db = cfg.doppler_bin_of(t.radial_velocity_mps)
        note = ""
        if abs(t.radial_velocity_mps) >= cfg.max_velocity_mps:
            aliased = (t.radial_velocity_mps + cfg.max_velocity_mps) % (
                2 * cfg.max_velocity_mps) - cfg.max_velocity_mps
            note = f"aliases to {aliased:+.2f} m/s (|v| > {cfg.max_velocity_mps:.2f})"
        print(f"{i:>7} {t.range_m:>8.1f} {t.radial_velocity_mps:>8.2f} {t.azimuth_deg:>7.1f} "
              f"{cfg.range_bin_of(t.range_m, t.radial_velocity_mps):>9.2f} {db:>11.2f}  {note}")
        markers.append((t.range_m, t.radial_velocity_mps, f"V{i}"))
    zoom = 1.5 * max(t.range_m for t in scene.targets)
    p0 = plot_range_doppler(np.abs(cube[0]) ** 2, cfg, out / "range_doppler_ch0.png",
                            f"{cfg.name}: range-Doppler, virtual channel 0", markers,
                            max_range_m=zoom)
    p1 = plot_range_doppler(range_doppler_power(cube), cfg, out / "range_doppler_nci.png",
                            f"{cfg.name}: range-Doppler, all {cfg.n_virtual} channels "
                            f"(non-coherent)", markers, max_range_m=zoom)
    print(f"wrote {p0} and {p1}")
    (out / "preset.json").write_text(json.dumps(cfg.summary(), indent=2))
    return 0


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="radar",
        description="Open 77 GHz FMCW TDM-MIMO radar array processor: scene simulator, "
                    "float reference of the FPGA chain and host processing.")
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")

    s = sub.add_parser(
        "simulate", help="simulate one frame of ADC samples",
        description="Simulate one frame of a scene and write the ADC samples as a complex64 "
                    ".npy array of shape (NUM_TX*N_DOPPLER chirps in transmit order, NUM_RX, "
                    "N_RANGE samples) holding the integer int16 I/Q codes the FPGA receives.")
    s.add_argument("--scene", required=True,
                   help="scene JSON file, or the name of a built-in scene (table1)")
    s.add_argument("--out", required=True, help="output .npy file")
    s.add_argument("--preset", choices=sorted(PRESETS), default=None,
                   help="override the scene's radar preset")
    s.add_argument("--frame", type=int, default=0,
                   help="frame index: targets move v*frame*frame_time, fresh noise (default 0)")
    s.set_defaults(func=cmd_simulate)

    d = sub.add_parser(
        "demo", help="the paper's Table I scene end to end, with figures",
        description="Simulate the paper's Table I scene, run the float reference of the FPGA "
                    "chain, print where each vehicle lands and write range-Doppler PNGs.")
    d.add_argument("--out", default="out", help="folder for figures (default out/)")
    d.add_argument("--preset", choices=sorted(PRESETS), default="full",
                   help="radar preset (default full)")
    d.set_defaults(func=cmd_demo)
    return p


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args))
    except CliError as exc:
        print(f"radar {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:
        print(f"radar {args.command}: error: {exc.strerror or exc}: "
              f"{getattr(exc, 'filename', '')}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
