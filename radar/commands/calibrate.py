"""``radar calibrate``: a capture of one reflector -> the array's calibration file
(docs/profiles.md, "Calibration"; ``host.calibration``), which ``radar process
--calibration`` applies (``radar.commands.process.calibration_of``)."""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from host.calibration import (
    WEAK_REFLECTOR_DB,
    calibration_document,
    estimate_calibration,
    reflector_range_error,
    save_calibration,
)
from radar.commands.process import capture_cube, capture_of, profile_of
from radar.common import CliError, add_command, out_file, progress, warn


def reflector_of(text: str) -> tuple[float, float, float]:
    """(range m, azimuth deg, elevation deg) of ``--reflector RANGE[,AZ[,EL]]``; CliError."""
    parts = text.split(",")
    try:
        values = [float(p) for p in parts]
    except ValueError:
        values = []
    if not 1 <= len(values) <= 3 or len(values) != len(parts) or not all(
            math.isfinite(v) for v in values):
        raise CliError(f"--reflector: must be RANGE_M[,AZ_DEG[,EL_DEG]] (numbers), got "
                       f"{text!r}")
    rng, az, el = (values + [0.0, 0.0])[:3]
    if not (abs(az) < 90 and abs(el) < 90):
        raise CliError(f"--reflector: azimuth and elevation must be within +-90 deg, got "
                       f"{az:g}, {el:g}")
    return rng, az, el


def cmd_calibrate(args: argparse.Namespace) -> int:
    out = out_file(args.out, ".json", "--out")
    profile = profile_of(args.radar)
    cfg = profile.config
    reflector = reflector_of(args.reflector)
    why = reflector_range_error(reflector[0], cfg)
    if why:
        raise CliError(f"--reflector: {why}")
    capture, frames = capture_of(args, profile, "calibrate")
    t0 = time.perf_counter()
    try:
        est = estimate_calibration((capture_cube(capture.frame(k), cfg) for k in
                                    progress(frames, "frames")), cfg, *reflector)
    except ValueError as exc:
        raise CliError(str(exc)) from None
    if est.snr_db < WEAK_REFLECTOR_DB:
        warn([f"the reflector is only {est.snr_db:.1f} dB over the zero-Doppler median "
              f"(a clear one gives {WEAK_REFLECTOR_DB:g} dB or more): the gains are noisy; "
              f"is it at {reflector[0]:g} m?"], "calibrate")
    save_calibration(out, calibration_document(est, cfg, reflector))
    phase = np.degrees(np.angle(est.errors))
    gain = 20 * np.log10(np.abs(est.errors))
    print(f"reflector at {est.measured_range_m:.4g} m (given {reflector[0]:g} m: range bias "
          f"{est.calibration.range_bias_m * 100:+.2f} cm), {est.snr_db:.1f} dB over the "
          f"zero-Doppler median, {est.frames} frame(s) ({time.perf_counter() - t0:.2f} s)")
    print(f"channel errors found: phase {phase.min():+.1f}..{phase.max():+.1f} deg, gain "
          f"{gain.min():+.2f}..{gain.max():+.2f} dB; residual over the frames "
          f"{est.residual_phase_deg:.2f} deg rms, {est.residual_gain_db:.3f} dB rms -> {out}")
    return 0


def add_parsers(sub: argparse._SubParsersAction, presets: list[str]) -> None:
    p = add_command(sub, "calibrate", "one-reflector capture -> array calibration file", """
        Estimate the array's calibration from a capture of one reflector (a corner reflector
        at a known range and direction, nothing else near it): per virtual channel complex
        gains and the range bias, written as a calibration file that `radar process
        --calibration` applies (docs/profiles.md, "Calibration").""")
    p.add_argument("--radar", required=True, metavar="NAME|FILE",
                   help=f"the radar: preset ({', '.join(presets)}), profile .toml or TI .cfg")
    p.add_argument("--capture", required=True, metavar="FILE",
                   help="ADC capture of the reflector: DCA1000 .bin or .npy")
    p.add_argument("--reflector", required=True, metavar="RANGE_M[,AZ_DEG[,EL_DEG]]",
                   help="the reflector's range (m) and direction (deg, default 0,0)")
    p.add_argument("--out", required=True, metavar="CAL.json", help="calibration file")
    p.add_argument("--frames", default=None, metavar="A:B",
                   help="frames A..B-1 of the capture (A: or :B open-ended; default all)")
    p.set_defaults(func=cmd_calibrate)
