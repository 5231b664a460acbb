"""``radar profile show NAME|FILE``: a radar profile's derived numbers (docs/profiles.md)."""

from __future__ import annotations

import argparse

import numpy as np

from model.hdl import hdl_unsupported
from model.profile import LVDS_LAYOUTS, Profile, load_profile
from radar.common import CliError, add_command


def array_picture(virtual_hw: np.ndarray) -> list[str]:
    """The virtual array as text: one row per vertical position (top row highest), one column
    per half-wavelength, each element shown by its channel number (``*`` where channels
    coincide). ``virtual_hw``: float (n_virtual, 2) in half-wavelengths."""
    h = np.round(virtual_hw[:, 0] - virtual_hw[:, 0].min()).astype(int)
    v = np.round(virtual_hw[:, 1] - virtual_hw[:, 1].min()).astype(int)
    if h.max() > 200 or v.max() > 20 or not np.allclose(
            virtual_hw - virtual_hw.min(axis=0), np.stack([h, v], axis=1)):
        return ["(not on a half-wavelength grid within 200 x 20: see the positions)"]
    width = len(str(len(h) - 1)) + 1
    grid = [["." .rjust(width)] * (h.max() + 1) for _ in range(v.max() + 1)]
    for ch, (x, y) in enumerate(zip(h, v, strict=True)):
        grid[y][x] = str(ch).rjust(width) if grid[y][x].strip() == "." else "*".rjust(width)
    return ["".join(row) for row in reversed(grid)]


def describe(profile: Profile) -> list[str]:
    """The lines ``radar profile show`` prints for ``profile``."""
    c, cap = profile.config, profile.capture
    v = c.virtual_positions_hw
    pad = lambda n, fft: f"{n}" + (f" (zero-padded to {fft})" if n != fft else "")  # noqa: E731
    rows = [
        ("radar", f"{c.name} ({profile.source})"),
        ("array", f"{c.num_tx} TX x {c.num_rx} RX = {c.n_virtual} virtual channels"),
        ("TX positions", _pos(c.tx_positions_hw)), ("RX positions", _pos(c.rx_positions_hw)),
        ("TX order", f"{list(c.tx_sequence)} per loop"),
        ("ADC", f"{c.adc}, {c.adc_bits} bit, {c.sample_rate_hz / 1e6:g} MSPS"),
        ("samples per chirp", pad(c.n_samples, c.n_range)),
        ("loops per frame", pad(c.n_loops, c.n_doppler)),
        ("carrier", f"{c.fc_hz / 1e9:.4f} GHz (wavelength {c.wavelength_m * 1e3:.3f} mm)"),
        ("slope", f"{c.slope_hz_per_s / 1e12:.4g} MHz/us, sampled bandwidth "
                  f"{c.sweep_bandwidth_hz / 1e6:.6g} MHz"),
        ("range bin", f"{c.range_bin_m:.5g} m (resolution "
                      f"{c.range_bin_m * c.n_range / c.n_samples:.5g} m)"),
        ("max range", f"{c.max_range_m:.5g} m (detections {c.min_detection_range_m:.4g} .. "
                      f"{c.max_detection_range_m:.5g} m; covers {c.design_max_range_m:.5g} m)"),
        ("velocity bin", f"{c.velocity_bin_mps:.4g} m/s"),
        ("unambiguous speed", f"+-{c.max_velocity_mps:.4g} m/s"),
        ("max speed", "host default" if c.max_speed_mps is None
         else f"{c.max_speed_mps:.4g} m/s"),
        ("azimuth resolution", f"{c.angle_resolution_deg:.3g} deg at boresight"),
    ]
    if np.ptp(v[:, 1]) > 0:
        rows.append(("elevation resolution",
                     f"{np.degrees(2.0 / (np.ptp(v[:, 1]) + 1.0)):.3g} deg at boresight"))
    rows += [
        ("chirp", f"{c.chirp_period_s * 1e6:.4g} us period, {c.sampled_chirp_s * 1e6:.4g} us "
                  f"sampled"),
        ("loop", f"{c.tx_repetition_s * 1e6:.4g} us ({c.num_tx} chirps)"),
        ("frame", f"{c.frame_time_s * 1e3:.4g} ms of chirps ({c.n_chirps} chirps)"
         + ("" if c.frame_period_s is None else
            f", period {c.frame_period_s * 1e3:.4g} ms ({1 / c.frame_period_s:.4g} frames/s)")),
        ("data rate", f"{c.data_rate_per_lane_bps / 1e6:.5g} Mbit/s per RX"),
        ("capture", cap.format + (f", {cap.lanes} LVDS lanes, "
                                  f"{'' if cap.interleaved else 'non-'}interleaved "
                                  f"({LVDS_LAYOUTS[(cap.lanes, cap.interleaved)]})"
                                  if cap.format == "dca1000" else "")),
    ]
    if profile.calibration is not None:
        g = np.array(profile.calibration.channel_gain)
        rows.append(("calibration", f"range bias {profile.calibration.range_bias_m:g} m, "
                                    f"channel gains {np.abs(g).min():.3g}..{np.abs(g).max():.3g}"
                                    f", phases {np.degrees(np.angle(g)).min():.1f}.."
                                    f"{np.degrees(np.angle(g)).max():.1f} deg"))
    missing = c.unsupported_features()
    rows.append(("processing", "supported by the chain" if not missing else
                 "not yet: " + "; ".join(missing)))
    fixed = hdl_unsupported(c)
    rows.append(("model / RTL", "run it" if not fixed else "not yet: " + "; ".join(fixed)))
    width = max(len(k) for k, _ in rows)
    lines = [f"{k.ljust(width)}  {val}" for k, val in rows]
    lines.append("virtual array (channel numbers, half-wavelength grid, up is vertical):")
    return lines + ["  " + row for row in array_picture(v)]


def _pos(p: np.ndarray) -> str:
    """Positions in half-wavelengths, the first 8 and the last if there are more."""
    text = [f"({h:g},{v:g})" for h, v in p]
    return " ".join(text if len(text) <= 9 else text[:8] + ["...", text[-1]]) \
        + " half-wavelengths"


def cmd_profile_show(args: argparse.Namespace) -> int:
    try:
        profile = load_profile(args.radar)
    except ValueError as exc:
        raise CliError(str(exc)) from None
    print("\n".join(describe(profile)))
    return 0


def add_parsers(sub: argparse._SubParsersAction, presets: list[str]) -> None:
    p = add_command(sub, "profile", "show a radar profile's derived numbers", """
        Radar profiles (docs/profiles.md): a preset name, a TOML profile or a TI mmWave SDK
        .cfg file. `radar profile show` prints the derived numbers: range and velocity bins,
        maximum range and unambiguous speed, angle resolution, the virtual array, chirp and
        frame timing, and what of the profile the processing chain does not support yet.""")
    psub = p.add_subparsers(dest="action", required=True, metavar="ACTION")
    s = psub.add_parser("show", help="print a profile's derived numbers",
                        description="Print the derived numbers of a radar profile.")
    s.add_argument("radar", metavar="NAME|FILE",
                   help=f"preset ({', '.join(presets)}), profile .toml or TI .cfg")
    s.set_defaults(func=cmd_profile_show)
