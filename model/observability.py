"""Which scene targets the radar cannot see in a frame, and why.

A target (point target or extended object) is *unobservable* in a frame when no detection
can come from it, whatever the detector settings:

- ``passed``: its range is <= 0 during the frame (it has driven past the radar); the
  simulator drops it (``model.simulate.passed_radar``);
- ``too_close``: its peak falls in the DC guard bins (``RadarConfig.detection_bins``);
- ``beyond_max_range``: its peak falls in the top guard bins, i.e. beyond about
  ``RadarConfig.max_detection_range_m`` (the negative-beat guard band; beyond
  ``max_range_m`` the anti-alias filter removes it);
- ``tx_null``: the echo is too weak to detect because the TX subarray pattern has a null
  there (3 elements at lambda/2: nulls at +-41.8 deg);
- ``too_weak``: the expected SNR after full coherent integration (range, Doppler and all
  virtual channels, Hann losses included) is below ``MIN_DETECTABLE_SNR_DB``.

An extended object is unobservable when all its scatterers are (its reason is the most
common one among them). The checks use the scene truth; they are for warnings and counts
next to a simulated point cloud, not part of detection.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from model.config import RadarConfig
from model.scene import Scatterers, Scene
from model.simulate import (
    frame_centre_range_m,
    passed_radar,
    snr_per_sample_db,
    subarray_factor_power,
)

MIN_DETECTABLE_SNR_DB = 10.0
"""Expected integrated SNR below which a target counts as too weak to detect, dB (a CFAR
at Pfa 1e-6 needs about 13 dB for a 50 % detection probability)."""
HANN_LOSS_DB = 1.76
"""SNR loss of a periodic Hann window per FFT dimension, dB (1.5x noise bandwidth)."""
TX_NULL_DB = -10.0
"""A too-weak target counts as in the TX null when the subarray factor costs more than
this, dB."""
REASONS = ("passed", "too_close", "beyond_max_range", "tx_null", "too_weak")


@dataclass(frozen=True)
class Unobservable:
    """One target the radar cannot see in a frame: ``target`` is ``targets[i]`` or
    ``objects[j]``, ``reason`` one of :data:`REASONS`, ``detail`` a readable sentence."""

    target: str
    frame: int
    reason: str
    detail: str


def integrated_snr_db(cfg: RadarConfig, sc: Scatterers, beamforming: bool,
                      frame_index: int = 0) -> np.ndarray:
    """Expected SNR of each scatterer after coherent integration over range, Doppler and
    virtual channels with Hann windows (the ADC samples and loops: zero padding adds no
    gain), dB, shape (n,)."""
    moved = Scatterers(np.maximum(frame_centre_range_m(cfg, sc, frame_index), 1e-3),
                       sc.azimuth_deg, sc.radial_velocity_mps, sc.rcs_m2, sc.object_id)
    with np.errstate(divide="ignore"):
        per_sample = snr_per_sample_db(cfg, moved, beamforming)
    gain = 10 * np.log10(cfg.n_samples * cfg.n_loops * cfg.n_virtual) - 2 * HANN_LOSS_DB
    return per_sample + gain


def scatterer_reasons(cfg: RadarConfig, sc: Scatterers, beamforming: bool,
                      frame_index: int = 0) -> list[tuple[str, str] | None]:
    """Per scatterer: None when observable, else (reason, detail)."""
    r = frame_centre_range_m(cfg, sc, frame_index)
    passed = passed_radar(cfg, sc, frame_index)
    # the peak lands in the nearest bin: reportable when that bin is in detection_bins
    rbin = np.array([cfg.range_bin_of(x, v) for x, v in zip(r, sc.radial_velocity_mps,
                                                             strict=True)])
    lo, hi = cfg.detection_bins
    snr = integrated_snr_db(cfg, sc, beamforming, frame_index)
    with np.errstate(divide="ignore"):
        af_db = 10 * np.log10(subarray_factor_power(cfg, sc.azimuth_deg)) if beamforming \
            else np.zeros(len(sc))
    out: list[tuple[str, str] | None] = []
    for i in range(len(sc)):
        if passed[i]:
            out.append(("passed", f"range {r[i]:.2f} m <= 0 during the frame (passed the "
                                  f"radar)"))
        elif rbin[i] < lo - 0.5:
            out.append(("too_close", f"range {r[i]:.2f} m inside the DC guard "
                                     f"(< {(lo - 0.5) * cfg.range_bin_m:.2f} m)"))
        elif rbin[i] >= hi - 0.5:
            out.append(("beyond_max_range", f"range {r[i]:.1f} m beyond the "
                                            f"{cfg.max_detection_range_m:.1f} m maximum "
                                            f"detection range of {cfg.name}"))
        elif snr[i] < MIN_DETECTABLE_SNR_DB:
            if af_db[i] < TX_NULL_DB:
                out.append(("tx_null", f"azimuth {sc.azimuth_deg[i]:.1f} deg in the TX "
                                       f"subarray null ({af_db[i]:.0f} dB), expected SNR "
                                       f"{snr[i]:.0f} dB"))
            else:
                out.append(("too_weak", f"expected SNR {snr[i]:.1f} dB < "
                                        f"{MIN_DETECTABLE_SNR_DB:g} dB"))
        else:
            out.append(None)
    return out


def unobservable_targets(scene: Scene, frame_index: int = 0) -> list[Unobservable]:
    """Targets and objects of ``scene`` the radar cannot see in frame ``frame_index``."""
    cfg = scene.config
    sc = scene.scatterers()
    reasons = scatterer_reasons(cfg, sc, scene.tx_beamforming, frame_index)
    out: list[Unobservable] = []
    n_targets = len(scene.targets)
    for i in range(n_targets):
        if reasons[i] is not None:
            out.append(Unobservable(f"targets[{i}]", frame_index, *reasons[i]))
    for j in range(len(scene.objects)):
        idx = np.flatnonzero(sc.object_id == j)  # point targets have object_id -1
        rs = [reasons[k] for k in idx]
        if rs and all(x is not None for x in rs):
            reason, _ = Counter(x[0] for x in rs).most_common(1)[0]  # type: ignore[index]
            detail = next(x[1] for x in rs if x[0] == reason)  # type: ignore[index]
            out.append(Unobservable(f"objects[{j}]", frame_index, reason,
                                    f"all {len(rs)} scatterers unobservable, e.g. {detail}"))
    return out


def summarize(items: list[Unobservable]) -> dict[str, object]:
    """JSON summary: ``unobservable_targets`` (distinct targets unobservable in at least
    one frame) and one entry per (target, reason) with its frames."""
    groups: dict[tuple[str, str], list[Unobservable]] = {}
    for u in items:
        groups.setdefault((u.target, u.reason), []).append(u)
    entries = [{"target": t, "reason": r, "frames": [u.frame for u in g],
                "detail": g[0].detail} for (t, r), g in groups.items()]
    return {"unobservable_targets": len({u.target for u in items}), "unobservable": entries}


def beyond_max_speed(scene: Scene, max_speed_mps: float) -> list[str]:
    """Targets / objects of ``scene`` whose radial speed exceeds ``max_speed_mps``: the host
    unfolds velocities only within that speed, so theirs will be reported as an alias,
    possibly without the ``ambiguous`` flag. One sentence each."""
    sc = scene.scatterers()
    out = []
    for i, t in enumerate(scene.targets):
        if abs(t.radial_velocity_mps) > max_speed_mps:
            out.append(f"targets[{i}]: radial velocity {t.radial_velocity_mps:g} m/s beyond "
                       f"the assumed maximum speed {max_speed_mps:g} m/s")
    for j in range(len(scene.objects)):
        v = np.abs(sc.radial_velocity_mps[sc.object_id == j])
        if v.size and v.max() > max_speed_mps:
            out.append(f"objects[{j}]: radial velocity up to {v.max():.1f} m/s beyond the "
                       f"assumed maximum speed {max_speed_mps:g} m/s")
    return out


def scene_report(scene: Scene, frames: Iterable[int], max_speed_mps: float
                 ) -> tuple[dict[str, object], list[str]]:
    """What a command that simulates ``frames`` of ``scene`` should tell its user: the JSON
    fields (``unobservable_targets``, ``unobservable``, ``velocity_beyond_max_speed``) and
    one warning line per unobservable (target, reason) and per too-fast target."""
    items = [u for k in frames for u in unobservable_targets(scene, k)]
    doc = summarize(items)
    fast = beyond_max_speed(scene, max_speed_mps)
    doc["velocity_beyond_max_speed"] = fast
    lines = []
    for e in doc["unobservable"]:  # type: ignore[union-attr]
        fr = e["frames"]
        when = f"frame {fr[0]}" if len(fr) == 1 else f"{len(fr)} frames ({fr[0]}..{fr[-1]})"
        lines.append(f"{e['target']} not observable in {when}: {e['detail']}")
    lines += [f"{f}: its velocity will be reported as an alias" for f in fast]
    return doc, lines
