"""Radar point cloud: one detection per row, the fields of docs/design.md 4.4 and more.

A :class:`PointCloud` holds parallel numpy arrays of shape (n,), one entry per point:

- ``range_m`` (m), ``azimuth_deg`` (deg, + towards +y), ``radial_velocity_mps`` (m/s,
  + receding), ``x_m``/``y_m`` (m; x forward, y left)
- ``vx_mps``/``vy_mps``: the radial velocity projected on the line of sight (m/s)
- ``elevation_deg`` (deg, + up), ``z_m`` (m, up): 0 for an array without vertical extent
  (x, y, z: ``model.array.cartesian``)
- ``power_db``: cell power after angle FFT, dB re 1 LSB^2; ``snr_db``: over the local noise
- ``rcs_dbsm``: RCS estimate from the radar equation, dB re 1 m^2
- ``range_bin``, ``doppler_bin`` (signed, unfolded), ``ambiguous`` (bool: another velocity
  within the assumed maximum speed explains the measurement, or the velocity was unfolded by
  the TDM test; ``host.pipeline`` step 3)
- in the JSON only: ``clipped`` (true, present on the points of a frame whose ADC samples
  clipped; absent = false)

JSON (``to_json_dict``, read back by ``from_json_dict``) follows docs/design.md 4.4:
``{"preset", "frames", "points": [...]}`` with the required fields range_m, azimuth_deg,
radial_velocity_mps, x_m, y_m, power_db, snr_db plus the extra ones, and z_m and
elevation_deg when the radar's array has vertical extent (every writer passes its
``RadarConfig``, so the rule is applied here only).
"""

from __future__ import annotations

from collections.abc import Collection
from dataclasses import dataclass, fields
from typing import Any

import numpy as np

from model.array import cartesian, has_vertical_extent
from model.config import RadarConfig

FLOAT_FIELDS = ("range_m", "azimuth_deg", "radial_velocity_mps", "x_m", "y_m", "vx_mps",
                "vy_mps", "power_db", "snr_db", "rcs_dbsm")
INT_FIELDS = ("range_bin", "doppler_bin", "frame")
BOOL_FIELDS = ("ambiguous",)
ELEVATION_FIELDS = ("z_m", "elevation_deg")
"""Float fields in the JSON of an array with vertical extent only."""


@dataclass(frozen=True)
class PointCloud:
    """Detections of one or more frames; every field is an array of shape (n,)
    (``z_m``, ``elevation_deg``: None gives zeros)."""

    range_m: np.ndarray
    azimuth_deg: np.ndarray
    radial_velocity_mps: np.ndarray
    x_m: np.ndarray
    y_m: np.ndarray
    vx_mps: np.ndarray
    vy_mps: np.ndarray
    power_db: np.ndarray
    snr_db: np.ndarray
    rcs_dbsm: np.ndarray
    range_bin: np.ndarray
    doppler_bin: np.ndarray
    frame: np.ndarray
    ambiguous: np.ndarray
    z_m: np.ndarray | None = None
    elevation_deg: np.ndarray | None = None

    def __post_init__(self) -> None:
        n = len(self.range_m)
        for name in ELEVATION_FIELDS:
            if getattr(self, name) is None:
                object.__setattr__(self, name, np.zeros(n))
        for name in _FIELD_NAMES:
            if len(getattr(self, name)) != n:
                raise ValueError(f"PointCloud.{name}: length {len(getattr(self, name))} "
                                 f"!= {n}")

    def __len__(self) -> int:
        return int(len(self.range_m))

    @classmethod
    def from_polar(cls, range_m: np.ndarray, azimuth_deg: np.ndarray,
                   radial_velocity_mps: np.ndarray, power_db: np.ndarray, snr_db: np.ndarray,
                   rcs_dbsm: np.ndarray, range_bin: np.ndarray, doppler_bin: np.ndarray,
                   ambiguous: np.ndarray, frame: int | np.ndarray = 0,
                   elevation_deg: np.ndarray | float = 0.0) -> PointCloud:
        """Build a cloud from polar measurements; x, y, z, vx, vy are derived."""
        r = np.asarray(range_m, dtype=float)
        az = np.radians(np.asarray(azimuth_deg, dtype=float))
        el = np.radians(np.broadcast_to(np.asarray(elevation_deg, dtype=float), r.shape))
        vr = np.asarray(radial_velocity_mps, dtype=float)
        n = r.shape[0]
        # positions and velocities in one call (the angles' sines and cosines once)
        (x, vx), (y, vy), (z, _) = cartesian(np.stack([r, vr]), az, el)
        return cls(
            range_m=r, azimuth_deg=np.degrees(az), radial_velocity_mps=vr,
            x_m=x, y_m=y, vx_mps=vx, vy_mps=vy, z_m=z, elevation_deg=np.degrees(el),
            power_db=np.asarray(power_db, dtype=float),
            snr_db=np.asarray(snr_db, dtype=float), rcs_dbsm=np.asarray(rcs_dbsm, dtype=float),
            range_bin=np.asarray(range_bin, dtype=int), doppler_bin=np.asarray(doppler_bin,
                                                                               dtype=int),
            frame=np.full(n, frame, dtype=int) if np.ndim(frame) == 0 else
            np.broadcast_to(np.asarray(frame, dtype=int), (n,)).copy(),
            ambiguous=np.asarray(ambiguous, dtype=bool))

    @classmethod
    def empty(cls) -> PointCloud:
        z = np.zeros(0)
        return cls.from_polar(z, z, z, z, z, z, z.astype(int), z.astype(int),
                              z.astype(bool))

    @staticmethod
    def concat(clouds: list[PointCloud]) -> PointCloud:
        """All points of ``clouds`` in order."""
        if not clouds:
            return PointCloud.empty()
        return PointCloud(**{f.name: np.concatenate([getattr(c, f.name) for c in clouds])
                             for f in fields(PointCloud)})

    def select(self, mask: np.ndarray) -> PointCloud:
        """The points where ``mask`` (bool (n,) or index array) selects."""
        return PointCloud(**{f.name: getattr(self, f.name)[mask] for f in fields(self)})

    def records(self, clipped_frames: Collection[int] = (), elevation: bool = False
                ) -> list[dict[str, Any]]:
        """One JSON-ready dict per point (floats rounded to 4 decimals); a point of a frame
        in ``clipped_frames`` (the ADC clipped) also gets ``"clipped": true``; ``elevation``
        (the array has vertical extent): z_m and elevation_deg too."""
        out = []
        clipped = set(clipped_frames)
        floats = FLOAT_FIELDS + ELEVATION_FIELDS if elevation else FLOAT_FIELDS
        for i in range(len(self)):
            rec: dict[str, Any] = {k: round(float(getattr(self, k)[i]), 4) for k in floats}
            rec.update({k: int(getattr(self, k)[i]) for k in INT_FIELDS})
            rec["ambiguous"] = bool(self.ambiguous[i])
            if rec["frame"] in clipped:
                rec["clipped"] = True
            out.append(rec)
        return out

    def to_json_dict(self, radar: RadarConfig | str, frames: int,
                     clipped_frames: Collection[int] = ()) -> dict[str, Any]:
        """The point cloud JSON object of the points of ``radar``: the configuration they
        came from (its name is the JSON's "preset"; when its virtual array has vertical
        extent, ``model.array.has_vertical_extent``, every point carries z_m and
        elevation_deg), or only a radar's name (no configuration known: planar points).
        Points of ``clipped_frames`` carry ``"clipped": true`` (harmonics of a clipped echo
        can be false points)."""
        if isinstance(radar, str):
            name, elevation = radar, False
        else:
            name, elevation = radar.name, has_vertical_extent(radar.virtual_positions_hw)
        return {"preset": name, "frames": int(frames),
                "points": self.records(clipped_frames, elevation)}

    @classmethod
    def from_json_dict(cls, doc: dict[str, Any]) -> PointCloud:
        """A cloud from the docs/design.md 4.4 JSON object (``{"points": [...]}``, as
        written by :meth:`to_json_dict`). Each point needs range_m, azimuth_deg,
        radial_velocity_mps, power_db and snr_db; rcs_dbsm, range_bin, doppler_bin, frame
        and ambiguous default to 0/false, elevation_deg to 0; x, y, z, vx, vy are derived
        from the polar fields. Raises ValueError naming the problem."""
        try:
            pts = doc["points"]
            get = {k: [float(p[k]) for p in pts] for k in
                   ("range_m", "azimuth_deg", "radial_velocity_mps", "power_db", "snr_db")}
            rcs = [float(p.get("rcs_dbsm", 0.0)) for p in pts]
            rb = [int(p.get("range_bin", 0)) for p in pts]
            db = [int(p.get("doppler_bin", 0)) for p in pts]
            frame = np.array([int(p.get("frame", 0)) for p in pts], dtype=int)
            amb = [bool(p.get("ambiguous", False)) for p in pts]
            el = [float(p.get("elevation_deg", 0.0)) for p in pts]
        except (KeyError, TypeError, ValueError, OverflowError) as exc:
            raise ValueError(f"not a point cloud JSON object ({exc!r})") from None
        for key, values in (*get.items(), ("rcs_dbsm", rcs), ("elevation_deg", el)):
            bad = [i for i, v in enumerate(values) if not np.isfinite(v)]
            if bad:
                raise ValueError(f"point {bad[0]}: {key} is {values[bad[0]]!r}, not a finite "
                                 f"number")
        bad = [i for i, (r, az, e) in enumerate(zip(get["range_m"], get["azimuth_deg"], el,
                                                    strict=True))
               if r < 0 or abs(az) > 90 or abs(e) > 90]
        if bad:
            raise ValueError(f"point {bad[0]}: range_m {get['range_m'][bad[0]]!r}, azimuth_deg "
                             f"{get['azimuth_deg'][bad[0]]!r}, elevation_deg {el[bad[0]]!r}: "
                             f"a point needs range >= 0 and |azimuth|, |elevation| <= 90 deg")
        return cls.from_polar(rcs_dbsm=rcs, range_bin=rb, doppler_bin=db, ambiguous=amb,
                              frame=frame, elevation_deg=np.array(el, dtype=float), **get)


_FIELD_NAMES = tuple(f.name for f in fields(PointCloud))
"""The fields of :class:`PointCloud`, in order (checked on every cloud made)."""
