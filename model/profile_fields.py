"""Checks of the profile fields of :class:`model.config.RadarConfig` (the fields a radar
profile adds to the presets' numbers, docs/profiles.md), and what of a configuration the
processing chain does not support yet."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from model.config import RadarConfig

PROFILE_FIELDS = frozenset({"samples_per_chirp", "loops", "tx_order", "adc", "tx_positions",
                            "rx_positions", "frame_period_s", "max_speed_mps",
                            "min_range_m"})
"""RadarConfig fields that may be None or not numbers (checked by check_profile_fields)."""


def _positions(value: object, name: str, count: int) -> None:
    """ValueError unless ``value`` is ``count`` pairs of finite numbers."""
    if not isinstance(value, tuple | list) or len(value) != count:
        raise ValueError(f"{name}: must be {count} (horizontal, vertical) positions, one per "
                         f"{name[:2].upper()}, got {value!r}")
    for i, pos in enumerate(value):
        if not isinstance(pos, tuple | list) or len(pos) != 2 or any(
                isinstance(x, bool) or not isinstance(x, int | float) or not math.isfinite(x)
                for x in pos):
            raise ValueError(f"{name}[{i}]: must be two numbers (horizontal, vertical) in "
                             f"half-wavelengths, got {pos!r}")


def check_profile_fields(cfg: RadarConfig) -> None:
    """ValueError naming the first bad profile field of ``cfg`` (see the field docs)."""
    for name, hi in (("samples_per_chirp", cfg.n_range), ("loops", cfg.n_doppler)):
        value = getattr(cfg, name)
        if value is not None and (isinstance(value, bool) or not isinstance(value, int)
                                  or not min(8 if name == "samples_per_chirp" else 1, hi)
                                  <= value <= hi):
            raise ValueError(f"{name}: must be an integer in "
                             f"{8 if name == 'samples_per_chirp' else 1}..{hi} (the FFT "
                             f"length), got {value!r}")
    if cfg.tx_order is not None:
        order = cfg.tx_order
        if not isinstance(order, tuple | list) or any(
                isinstance(t, bool) or not isinstance(t, int) for t in order):
            raise ValueError(f"tx_order: must be a list of TX indices, got {order!r}")
        bad = [t for t in order if not 0 <= t < cfg.num_tx]
        if bad:
            raise ValueError(f"tx_order: TX index {bad[0]} out of range 0..{cfg.num_tx - 1}")
        if sorted(order) != list(range(cfg.num_tx)):
            raise ValueError(f"tx_order: every TX 0..{cfg.num_tx - 1} must fire exactly once "
                             f"per loop, got {list(order)}")
    if cfg.adc not in ("complex", "real"):
        raise ValueError(f"adc: must be 'complex' or 'real', got {cfg.adc!r}")
    if cfg.tx_positions is not None:
        _positions(cfg.tx_positions, "tx_positions", cfg.num_tx)
    if cfg.rx_positions is not None:
        _positions(cfg.rx_positions, "rx_positions", cfg.num_rx)
    for name in ("frame_period_s", "max_speed_mps", "min_range_m"):
        value = getattr(cfg, name)
        if value is not None and (isinstance(value, bool) or not isinstance(value, int | float)
                                  or not math.isfinite(value) or value <= 0):
            raise ValueError(f"{name}: must be a positive number, got {value!r}")
    lo, hi = cfg.detection_bins
    if lo >= hi:
        raise ValueError(f"min_range_m: {cfg.min_range_m} m leaves no range bin to detect in "
                         f"(the top {cfg.n_range_bins - hi} are guarded too)")
    if cfg.frame_period_s is not None and cfg.frame_period_s < cfg.frame_time_s:
        raise ValueError(f"frame_period_s: {cfg.frame_period_s * 1e3:.3f} ms is shorter than "
                         f"the frame's chirps, {cfg.frame_time_s * 1e3:.3f} ms")


def unsupported_features(cfg: RadarConfig) -> list[str]:
    """What of ``cfg`` the float processing chain cannot handle yet, one phrase each: nothing
    today (zero padding, a real ADC, any firing order, non-uniform and 2-D virtual arrays
    are processed); ``RadarConfig.check_processable`` and ``radar profile show`` read it."""
    return []


def preset_chain_features(cfg: RadarConfig) -> list[str]:
    """What of ``cfg`` the presets' fixed-point chain (the bit-accurate model, the RTL) does
    not run, one phrase each (empty for the presets): zero padding, a firing order other
    than 0..num_tx-1, a real ADC. The array's geometry is the host's (host.points): the
    chain moves the NUM_TX x NUM_RX channels whatever their positions."""
    out = []
    if cfg.n_samples != cfg.n_range:
        out.append(f"{cfg.n_samples} samples per chirp zero-padded to a {cfg.n_range}-point "
                   "range FFT")
    if cfg.n_loops != cfg.n_doppler:
        out.append(f"{cfg.n_loops} loops zero-padded to a {cfg.n_doppler}-point Doppler FFT")
    if cfg.tx_sequence != tuple(range(cfg.num_tx)):
        out.append(f"TX firing order {list(cfg.tx_sequence)}")
    if cfg.adc != "complex":
        out.append("real-valued ADC")
    return out


def check_preset_chain(cfg: RadarConfig) -> None:
    """ValueError (one line) naming what of ``cfg`` the bit-accurate model and the RTL (the
    presets' chain) do not handle (:func:`preset_chain_features`); the float chain
    processes profiles."""
    missing = preset_chain_features(cfg)
    if missing:
        raise ValueError(f"radar {cfg.name!r}: the bit-accurate model and the RTL do not "
                         f"handle {'; '.join(missing)} yet (the float chain does)")
