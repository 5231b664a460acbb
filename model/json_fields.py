"""Checked fields of the simulator's JSON inputs (the scene, its impairments): each bad field
raises a one-line ValueError naming it as ``where.key``."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any


def check_keys(d: Mapping[str, Any], allowed: set[str], where: str) -> None:
    """ValueError unless ``d`` is a JSON object whose keys are all in ``allowed``."""
    if not isinstance(d, Mapping):
        raise ValueError(f"{where}: must be a JSON object, got {type(d).__name__}")
    unknown = set(d) - allowed
    if unknown:
        raise ValueError(f"{where}: unknown field(s) {sorted(unknown)}; allowed: {sorted(allowed)}")


def number(d: Mapping[str, Any], key: str, where: str, default: float | None = None,
           bounds: tuple[float, float] = (-math.inf, math.inf)) -> float:
    """``d[key]`` as a finite float within ``bounds`` (inclusive); ``default`` when absent
    (None: the field is required)."""
    if key not in d:
        if default is None:
            raise ValueError(f"{where}: missing required field {key!r}")
        return default
    value = d[key]
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ValueError(f"{where}.{key}: must be a finite number, got {value!r}")
    try:
        finite = math.isfinite(value)
    except OverflowError:                   # an integer beyond float range
        finite = False
    if not finite:
        raise ValueError(f"{where}.{key}: must be a finite number, got {str(value)[:20]}"
                         f"{'...' if len(str(value)) > 20 else ''}")
    lo, hi = bounds
    if not lo <= value <= hi:
        raise ValueError(f"{where}.{key}: {value!r} is outside what the simulator accepts "
                         f"[{lo:g}, {hi:g}]")
    return float(value)


def integer(d: Mapping[str, Any], key: str, where: str, default: int, lo: int, hi: int) -> int:
    """``d[key]`` as an integer in lo..hi; ``default`` when absent."""
    value = d.get(key, default)
    if isinstance(value, bool) or not isinstance(value, int) or not lo <= value <= hi:
        raise ValueError(f"{where}.{key}: must be an integer in {lo}..{hi}, got {value!r}")
    return value
