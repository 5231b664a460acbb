"""Channel calibration (docs/profiles.md, "Calibration"): per virtual channel complex gains
and a range bias, estimated from a capture of one reflector, stored as a calibration file
and applied to detected cells before the angle estimation.

- :func:`apply_calibration`: the one place a calibration (``model.profile.Calibration``: a
  calibration file's, or a TI ``.cfg``'s ``compRangeBiasAndRxChanPhase``) is applied:
  each cell's snapshot times the channel gains (channel v = tx * num_rx + rx by TX index),
  the points' range less the bias (``host.cells.Cells.range_bias_m``).
  ``host.points.points_from_cells`` calls it, so the cube and the records paths share it.
- :func:`estimate_calibration`: the reflector's cell near the given range at zero Doppler,
  its channel snapshots averaged over the frames (the principal eigenvector of their sum of
  outer products, so a phase common to all channels that drifts between frames does not
  cancel), divided by the steering vector of the reflector's direction
  (``model.array.steering``) and inverted: gains with channel 0's phase 0 and an rms
  magnitude of 1 (the noise power per channel is kept on average).
- :func:`save_calibration` / :func:`load_calibration`: the calibration file, JSON: the
  gains as [re, im] pairs, the range bias, and the array it belongs to (num_tx, num_rx,
  virtual positions; the profile's name for information): a file of another array is
  refused.
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterable
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from host.cells import Cells, axis_offsets
from model.array import direction_cosines, steering
from model.config import RadarConfig
from model.profile import Calibration
from model.reference import fft_axes

FORMAT = "radar-calibration"
"""The ``format`` of a calibration file."""
VERSION = 1
"""Its ``version``."""
WEAK_REFLECTOR_DB = 25.0
"""A reflector less than this over the zero-Doppler median leaves noisy gains (``radar
calibrate`` warns): at 25 dB over 8 channels the phase error is a few degrees."""
SEARCH_M = 0.3
"""The reflector is searched within this distance of the given range (and at least the
range window's main lobe), m."""


@dataclass(frozen=True)
class Estimate:
    """A calibration estimated from a reflector (:func:`estimate_calibration`).

    ``calibration``: the gains (complex (n_virtual,) as a tuple) and range bias;
    ``measured_range_m``: the reflector's interpolated range; ``snr_db``: its cell's power
    over the median of the frame-summed map at zero Doppler, dB; ``errors``: complex
    (n_virtual,) the channel errors found (1 / gains); ``residual_phase_deg`` /
    ``residual_gain_db``: rms over frames and channels of each frame's calibrated snapshot
    against the steering vector (after its common phase and gain), deg / dB; ``frames``:
    frames averaged."""

    calibration: Calibration
    measured_range_m: float
    snr_db: float
    errors: np.ndarray
    residual_phase_deg: float
    residual_gain_db: float
    frames: int


def check_calibration(cal: Calibration, cfg: RadarConfig, what: str = "calibration") -> None:
    """ValueError (one line) unless ``cal`` has one finite, non-zero gain per virtual
    channel of ``cfg`` and a finite range bias."""
    g = np.asarray(cal.channel_gain, dtype=complex)
    if g.shape != (cfg.n_virtual,):
        raise ValueError(f"{what}: {g.size} channel gains, radar {cfg.name!r} has "
                         f"{cfg.n_virtual} virtual channels")
    if not (np.isfinite(g).all() and (g != 0).all() and math.isfinite(cal.range_bias_m)):
        raise ValueError(f"{what}: channel gains and range bias must be finite, gains "
                         f"non-zero")


def apply_calibration(cells: Cells, cal: Calibration | None) -> Cells:
    """``cells`` with each snapshot (complex (n, n_virtual)) multiplied by the channel
    gains of ``cal`` and its range bias set (subtracted from the points' range); ``cells``
    itself when ``cal`` is None. ValueError when the gains do not fit the snapshots."""
    if cal is None:
        return cells
    g = np.asarray(cal.channel_gain, dtype=np.complex128)
    x = np.asarray(cells.snapshot)
    if x.ndim != 2 or x.shape[1] != g.size:
        raise ValueError(f"calibration: {g.size} channel gains for snapshots of "
                         f"{x.shape[-1] if x.ndim else 0} channels")
    return replace(cells, snapshot=x * g, range_bias_m=cal.range_bias_m)


def reflector_range_error(range_m: float, cfg: RadarConfig) -> str | None:
    """Why a reflector at ``range_m`` cannot calibrate ``cfg`` (outside the ranges a
    detection can report), or None."""
    lo, hi = cfg.min_detection_range_m, cfg.max_detection_range_m
    if not lo <= range_m < hi:
        return (f"{range_m:g} m is outside radar {cfg.name!r}'s detection ranges "
                f"{lo:.3g}..{hi:.4g} m")
    return None


def estimate_calibration(cubes: Iterable[np.ndarray], cfg: RadarConfig, range_m: float,
                         azimuth_deg: float = 0.0, elevation_deg: float = 0.0) -> Estimate:
    """The calibration of ``cfg``'s array from radar cubes (complex (n_virtual,
    n_range_bins, n_doppler), ``model.reference.radar_cube`` or its fast equivalent
    ``host.cube.frame_cube``, complex64 as ``radar calibrate`` makes them; both windows on,
    no static-clutter removal) of one reflector at ``range_m`` and (azimuth, elevation) in
    deg (module docstring). ValueError (one line) when the range is outside the profile's or
    no frame is given."""
    why = reflector_range_error(range_m, cfg)
    if why:
        raise ValueError(f"reflector: {why}")
    zero = []                                    # each frame's zero-Doppler (n_v, n_rb)
    for cube in cubes:
        cfg.check_cube(cube)
        zero.append(np.array(cube[:, :, 0], dtype=np.complex128))
    if not zero:
        raise ValueError("capture: no frames to calibrate from")
    power = sum(np.sum(np.abs(z) ** 2, axis=0) for z in zero)
    r = _reflector_bin(power, cfg, range_m)
    snaps = np.stack([z[:, r] for z in zero])                           # (frames, n_v)
    offset = float(axis_offsets(power[r - 1], power[r], power[r + 1], fft_axes(cfg)[0]))
    measured = (r + offset) * cfg.range_bin_m
    u, w = direction_cosines(math.radians(azimuth_deg), math.radians(elevation_deg))
    a = steering(cfg.virtual_positions_hw, u, w)                          # (n_v,)
    _, vecs = np.linalg.eigh(snaps.T @ snaps.conj())                      # sum x x^H
    gains = a / vecs[:, -1]                       # the principal eigenvector ~ the snapshot
    gains = gains * np.exp(-1j * np.angle(gains[0])) / np.sqrt(np.mean(np.abs(gains) ** 2))
    res = snaps * gains / a                       # each frame's calibrated, steering removed
    res = res / np.mean(res, axis=1, keepdims=True)                      # common part out
    snr = 10 * math.log10(max(power[r], 1e-300) / max(float(np.median(power)), 1e-300))
    return Estimate(Calibration(measured - range_m, tuple(complex(g) for g in gains)),
                    measured, snr, 1.0 / gains,
                    float(np.degrees(np.sqrt(np.mean(np.angle(res) ** 2)))),
                    float(np.sqrt(np.mean((20 * np.log10(np.abs(res))) ** 2))),
                    len(zero))


def _reflector_bin(power: np.ndarray, cfg: RadarConfig, range_m: float) -> int:
    """The strongest range bin of ``power`` (float (n_range_bins,), zero Doppler) within
    :data:`SEARCH_M` (at least the main lobe) of ``range_m``, inside the detection bins and
    away from the map's ends."""
    span = max(SEARCH_M / cfg.range_bin_m, fft_axes(cfg)[0].main_lobe_bins)
    lo_det, hi_det = cfg.detection_bins
    centre = range_m / cfg.range_bin_m
    lo = max(lo_det, 1, math.floor(centre - span))
    hi = min(hi_det, cfg.n_range_bins - 1, math.ceil(centre + span) + 1)
    return lo + int(np.argmax(power[lo:hi]))


# ---- the calibration file -------------------------------------------------------------------
def calibration_document(est: Estimate, cfg: RadarConfig, reflector: tuple[float, float, float]
                         ) -> dict[str, object]:
    """The calibration file's JSON document of ``est`` for radar ``cfg`` (module
    docstring); ``reflector``: the given (range m, azimuth deg, elevation deg)."""
    cal = est.calibration
    return {
        "format": FORMAT, "version": VERSION, "profile": cfg.name,
        "num_tx": cfg.num_tx, "num_rx": cfg.num_rx,
        "virtual_positions_hw": cfg.virtual_positions_hw.tolist(),
        "range_bias_m": cal.range_bias_m,
        "channel_gain": [[g.real, g.imag] for g in cal.channel_gain],
        "reflector": {"range_m": reflector[0], "azimuth_deg": reflector[1],
                      "elevation_deg": reflector[2], "measured_range_m": est.measured_range_m,
                      "snr_db": est.snr_db, "frames": est.frames},
        "errors": {"phase_deg": np.degrees(np.angle(est.errors)).tolist(),
                   "gain_db": (20 * np.log10(np.abs(est.errors))).tolist()},
        "residual": {"phase_rms_deg": est.residual_phase_deg,
                     "gain_rms_db": est.residual_gain_db},
    }


def save_calibration(path: str | Path, doc: dict[str, object]) -> None:
    """Write the calibration document ``doc`` (:func:`calibration_document`) to ``path``
    whole (a temporary file renamed: never half written)."""
    p = Path(path)
    tmp = p.with_name(p.name + ".tmp")
    tmp.write_text(json.dumps(doc, indent=1) + "\n")
    tmp.replace(p)


def load_calibration(path: str | Path, cfg: RadarConfig) -> Calibration:
    """The calibration in file ``path`` for radar ``cfg``; ValueError (one line, naming the
    file) when it is missing, malformed or of another array."""
    p = Path(path)
    try:
        doc = json.loads(p.read_text())
    except FileNotFoundError:
        raise ValueError(f"{p}: no such calibration file") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ValueError(f"{p}: not a calibration file ({exc})") from None
    try:
        return _calibration_of(doc, cfg)
    except ValueError as exc:
        raise ValueError(f"{p}: {exc}") from None


def _calibration_of(doc: object, cfg: RadarConfig) -> Calibration:
    """The calibration of a parsed calibration file (module docstring); ValueError."""
    if not isinstance(doc, dict) or doc.get("format") != FORMAT:
        raise ValueError(f"not a calibration file (no \"format\": \"{FORMAT}\")")
    if doc.get("version") != VERSION:
        raise ValueError(f"version {doc.get('version')!r}, this reader takes {VERSION}")
    for key in ("num_tx", "num_rx", "virtual_positions_hw", "range_bias_m", "channel_gain"):
        if key not in doc:
            raise ValueError(f"{key}: missing")
    try:
        pos = np.array(doc["virtual_positions_hw"], dtype=float)
        gains = np.array(doc["channel_gain"], dtype=float)
        bias = float(doc["range_bias_m"])
    except (TypeError, ValueError):
        raise ValueError("virtual_positions_hw, channel_gain, range_bias_m: must be numbers "
                         "([h, v] and [re, im] pairs)") from None
    here = cfg.virtual_positions_hw
    if (doc["num_tx"], doc["num_rx"]) != (cfg.num_tx, cfg.num_rx) or pos.shape != here.shape \
            or not np.allclose(pos, here):
        raise ValueError(f"calibration of another array ({doc['num_tx']} TX x "
                         f"{doc['num_rx']} RX of profile {doc.get('profile')!r}; radar "
                         f"{cfg.name!r} has {cfg.num_tx} TX x {cfg.num_rx} RX"
                         + (")" if (doc["num_tx"], doc["num_rx"]) != (cfg.num_tx, cfg.num_rx)
                            else ", at other virtual positions)"))
    if gains.shape != (cfg.n_virtual, 2):
        raise ValueError(f"channel_gain: must be {cfg.n_virtual} [re, im] pairs, got shape "
                         f"{gains.shape}")
    cal = Calibration(bias, tuple(complex(re, im) for re, im in gains))
    check_calibration(cal, cfg)
    return cal
