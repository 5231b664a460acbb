"""Radar scenes: point targets, extended objects (sets of scatterers) and the scene JSON.

Conventions (docs/design.md section 2): x forward (boresight), y left, azimuth positive towards +y
(counter-clockwise), radial velocity positive = receding. Angles in degrees at interfaces.
Kinematics are given at the **centre of the frame** (the middle of the coherent processing
interval), so a target's measured range is its scene range even when it moves metres during
a frame.

Scene JSON (docs/design.md 4.3)::

    {"preset": "full", "seed": 1, "tx_beamforming": true,
     "targets": [{"range_m": 40.0, "azimuth_deg": -10.0, "radial_velocity_mps": -12.5,
                  "rcs_m2": 20.0}],
     "objects": [{"x_m": 30, "y_m": 2, "length_m": 4.5, "width_m": 1.8, "heading_deg": 0,
                  "vx_mps": -5, "vy_mps": 0, "rcs_m2": 10, "n_scatterers": 12,
                  "label": "car"}]}

A target may also give ``elevation_deg`` (default 0); an ``"impairments"`` table adds the
real-world effects of ``model.impairments`` (docs/profiles.md).
``{"scene": "table1", "preset": "full"}`` names the built-in paper scene instead.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from model.config import PRESETS, RadarConfig, get_preset
from model.impairments import NO_IMPAIRMENTS, Impairments
from model.json_fields import check_keys, number

KMH = 1.0 / 3.6
"""m/s per km/h."""

# Limits of what a scene may ask of the simulator (one-line ValueError beyond them).
MAX_RANGE_M = 1.0e5
"""Largest target range or object distance, m (far beyond every preset's IF band)."""
MAX_SPEED_MPS = 1000.0
"""Largest radial velocity or object speed, m/s (Mach 3: covers every road user)."""
MAX_RCS_M2 = 1.0e6
"""Largest RCS, m^2 (a large ship)."""
MAX_SIZE_M = 1000.0
"""Largest object length or width, m."""
MIN_SIZE_M = 0.01
"""Smallest length / width of an extended object, m (a box of edges that can be sampled)."""
MAX_SCATTERERS_PER_OBJECT = 256
"""Scatterers per extended object (memory and time of the simulator grow with it)."""
MAX_SCATTERERS = 2048
"""Scatterers per scene, all targets and objects together."""
MAX_SEED = 2**63 - 1
"""Largest scene seed."""

_BOUNDS = {"range_m": (0.0, MAX_RANGE_M), "elevation_deg": (-90.0, 90.0),
           "radial_velocity_mps": (-MAX_SPEED_MPS, MAX_SPEED_MPS),
           "rcs_m2": (0.0, MAX_RCS_M2), "x_m": (-MAX_RANGE_M, MAX_RANGE_M),
           "y_m": (-MAX_RANGE_M, MAX_RANGE_M), "length_m": (0.0, MAX_SIZE_M),
           "width_m": (0.0, MAX_SIZE_M), "vx_mps": (-MAX_SPEED_MPS, MAX_SPEED_MPS),
           "vy_mps": (-MAX_SPEED_MPS, MAX_SPEED_MPS), "heading_deg": (-3600.0, 3600.0)}


def _number(d: Mapping[str, Any], key: str, where: str, default: float | None = None) -> float:
    return number(d, key, where, default, _BOUNDS.get(key, (-math.inf, math.inf)))


@dataclass(frozen=True)
class Scatterers:
    """A flat set of point scatterers, all arrays of shape (n,).

    ``range_m`` (m), ``azimuth_deg`` (deg), ``radial_velocity_mps`` (m/s, + receding),
    ``rcs_m2`` (m^2), ``object_id`` (int, -1 for free point targets) linking each
    scatterer to the scene object it belongs to (for labelled datasets), and
    ``elevation_deg`` (deg, + up; None: all 0, in the radar's horizontal plane).
    """

    range_m: np.ndarray
    azimuth_deg: np.ndarray
    radial_velocity_mps: np.ndarray
    rcs_m2: np.ndarray
    object_id: np.ndarray
    elevation_deg: np.ndarray = None  # type: ignore[assignment]

    def __post_init__(self) -> None:
        if self.elevation_deg is None:
            object.__setattr__(self, "elevation_deg", np.zeros(np.shape(self.range_m)))

    def __len__(self) -> int:
        return int(self.range_m.shape[0])

    @staticmethod
    def concat(parts: list[Scatterers]) -> Scatterers:
        """All scatterers of ``parts`` in order."""
        if not parts:
            e = np.zeros(0)
            return Scatterers(e, e, e, e, np.zeros(0, dtype=int))
        return Scatterers(*(np.concatenate([getattr(p, f) for p in parts]) for f in (
            "range_m", "azimuth_deg", "radial_velocity_mps", "rcs_m2", "object_id",
            "elevation_deg")))


@dataclass(frozen=True)
class PointTarget:
    """One point scatterer: range (m), azimuth (deg), radial velocity (m/s), RCS (m^2) and
    elevation (deg, + up; optional in the JSON, default 0)."""

    range_m: float
    azimuth_deg: float
    radial_velocity_mps: float
    rcs_m2: float
    elevation_deg: float = 0.0

    FIELDS = ("range_m", "azimuth_deg", "radial_velocity_mps", "rcs_m2")

    def __post_init__(self) -> None:
        if not -90.0 < self.elevation_deg < 90.0:
            raise ValueError(f"elevation_deg: must be inside (-90, 90), got {self.elevation_deg}")
        if self.range_m <= 0:
            raise ValueError(f"range_m: must be positive, got {self.range_m}")
        if not -90.0 < self.azimuth_deg < 90.0:
            raise ValueError(f"azimuth_deg: must be inside (-90, 90), got {self.azimuth_deg}")
        if self.rcs_m2 <= 0:
            raise ValueError(f"rcs_m2: must be positive, got {self.rcs_m2}")

    @classmethod
    def from_dict(cls, d: Mapping[str, Any], where: str = "target") -> PointTarget:
        check_keys(d, {*cls.FIELDS, "elevation_deg"}, where)
        vals = {k: _number(d, k, where) for k in cls.FIELDS}
        vals["elevation_deg"] = _number(d, "elevation_deg", where, 0.0)
        try:
            return cls(**vals)
        except ValueError as exc:
            raise ValueError(f"{where}.{exc}") from None

    def to_dict(self) -> dict[str, float]:
        """The target's JSON (``elevation_deg`` only when not 0)."""
        d = asdict(self)
        if not self.elevation_deg:
            del d["elevation_deg"]
        return d

    @property
    def x_m(self) -> float:
        """Position along the boresight, m (``model.array.cartesian``)."""
        return self.range_m * math.cos(math.radians(self.elevation_deg)) * math.cos(
            math.radians(self.azimuth_deg))

    @property
    def y_m(self) -> float:
        """Position to the left, m."""
        return self.range_m * math.cos(math.radians(self.elevation_deg)) * math.sin(
            math.radians(self.azimuth_deg))


OBJECT_LABELS: tuple[str, ...] = ("car", "pedestrian", "pedestrian_group", "two_wheeler",
                                  "large_vehicle")
"""The labels an object may carry: the GNN's object classes (``gnn.classes``, in its index
order: RadarScenes' road users)."""


@dataclass(frozen=True)
class ExtendedObject:
    """A rigid box-shaped object (vehicle, pedestrian, ...) made of point scatterers.

    Centre ``(x_m, y_m)`` (m), footprint ``length_m`` x ``width_m`` (m) rotated by
    ``heading_deg`` (deg, from +x towards +y), velocity over ground relative to the radar
    ``(vx_mps, vy_mps)`` (m/s), total ``rcs_m2`` (m^2) shared by ``n_scatterers`` points on
    the box outline that face the radar. ``label`` names the class for the GNN datasets.
    """

    x_m: float
    y_m: float
    length_m: float
    width_m: float
    heading_deg: float
    vx_mps: float
    vy_mps: float
    rcs_m2: float
    n_scatterers: int = 12
    label: str = "car"

    NUMBERS = ("x_m", "y_m", "length_m", "width_m", "heading_deg", "vx_mps", "vy_mps", "rcs_m2")

    def __post_init__(self) -> None:
        if self.x_m <= 0:
            raise ValueError(f"x_m: object must be in front of the radar (x > 0), got {self.x_m}")
        if self.length_m < MIN_SIZE_M or self.width_m < MIN_SIZE_M:
            raise ValueError(f"length_m/width_m: must be at least {MIN_SIZE_M:g} m, got "
                             f"{self.length_m!r} x {self.width_m!r}")
        if (self.corners()[:, 0] <= 0).any():
            raise ValueError(f"object at x {self.x_m:g} m, y {self.y_m:g} m: its "
                             f"{self.length_m:g} x {self.width_m:g} m box reaches x <= 0 "
                             f"(beside or behind the radar); the whole box must be in front")
        if self.rcs_m2 <= 0:
            raise ValueError(f"rcs_m2: must be positive, got {self.rcs_m2}")
        if not isinstance(self.n_scatterers, int) or not \
                1 <= self.n_scatterers <= MAX_SCATTERERS_PER_OBJECT:
            raise ValueError(f"n_scatterers: must be an integer in 1..{MAX_SCATTERERS_PER_OBJECT}"
                             f", got {self.n_scatterers}")

    @classmethod
    def from_dict(cls, d: Mapping[str, Any], where: str = "object") -> ExtendedObject:
        check_keys(d, set(cls.NUMBERS) | {"n_scatterers", "label"}, where)
        vals: dict[str, Any] = {k: _number(d, k, where, 0.0 if k in ("heading_deg", "vx_mps",
                                                                  "vy_mps") else None)
                                for k in cls.NUMBERS}
        n = d.get("n_scatterers", 12)
        if isinstance(n, bool) or not isinstance(n, int):
            raise ValueError(f"{where}.n_scatterers: must be an integer, got {n!r}")
        label = d.get("label", "car")
        if not isinstance(label, str):
            raise ValueError(f"{where}.label: must be a string, got {label!r}")
        if label not in OBJECT_LABELS:
            raise ValueError(f"{where}.label: unknown class {label!r}; choose one of "
                             f"{', '.join(OBJECT_LABELS)}")
        try:
            return cls(**vals, n_scatterers=n, label=label)
        except ValueError as exc:
            raise ValueError(f"{where}.{exc}") from None

    def corners(self) -> np.ndarray:
        """Box corners, float (4, 2) as (x, y) in m, counter-clockwise."""
        h = math.radians(self.heading_deg)
        u = np.array([math.cos(h), math.sin(h)])        # along the length
        w = np.array([-math.sin(h), math.cos(h)])       # along the width
        c = np.array([self.x_m, self.y_m])
        hl, hw = self.length_m / 2, self.width_m / 2
        return np.array([c + hl * u - hw * w, c + hl * u + hw * w,
                         c - hl * u + hw * w, c - hl * u - hw * w])

    def scatterers(self, rng: np.random.Generator, object_id: int) -> Scatterers:
        """Scatterers on the radar-facing edges of the box (shape (n_scatterers,) each).

        Points are drawn uniformly along the visible edges (outward normal towards the
        radar); the RCS is split among them with exponential (Swerling-1-like) weights that
        sum to ``rcs_m2``. Radial velocity is the object velocity projected on each point's
        line of sight.
        """
        corners = self.corners()
        edges = [(corners[i], corners[(i + 1) % 4]) for i in range(4)]
        centre = np.array([self.x_m, self.y_m])
        visible = []
        for a, b in edges:
            mid = (a + b) / 2
            normal = mid - centre
            if np.dot(normal, -mid) > 0:  # faces the radar at the origin
                visible.append((a, b))
        lengths = np.array([np.linalg.norm(b - a) for a, b in visible])
        pick = rng.choice(len(visible), size=self.n_scatterers, p=lengths / lengths.sum())
        t = rng.random(self.n_scatterers)
        pts = np.array([visible[k][0] + ti * (visible[k][1] - visible[k][0])
                        for k, ti in zip(pick, t, strict=True)])
        rng_m = np.hypot(pts[:, 0], pts[:, 1])
        az = np.degrees(np.arctan2(pts[:, 1], pts[:, 0]))
        vr = (pts[:, 0] * self.vx_mps + pts[:, 1] * self.vy_mps) / rng_m
        w = rng.exponential(size=self.n_scatterers)
        rcs = self.rcs_m2 * w / w.sum()
        return Scatterers(rng_m, az, vr, rcs, np.full(self.n_scatterers, object_id))


@dataclass(frozen=True)
class Scene:
    """A radar scene: preset name, random seed, TX beamforming switch, targets and objects.

    ``noise=False`` switches thermal noise off (for model tests). Frame k of a scene (see
    ``model.simulate.simulate_scene``) moves each target radially by ``v * k * frame_time``.
    ``impairments``: the real-world effects the simulator adds (``model.impairments``; the
    JSON's ``"impairments"`` table), none by default. ``radar``: the radar when it is not the
    preset (a profile, ``radar simulate --radar``; not part of the JSON), None: the preset's.
    """

    preset: str = "full"
    seed: int = 0
    tx_beamforming: bool = True
    targets: tuple[PointTarget, ...] = ()
    objects: tuple[ExtendedObject, ...] = ()
    noise: bool = True
    name: str = "custom"
    impairments: Impairments = NO_IMPAIRMENTS
    radar: RadarConfig | None = None

    def __post_init__(self) -> None:
        get_preset(self.preset)  # validates the name
        imp = self.impairments
        n = len(self.targets) + sum(o.n_scatterers for o in self.objects) + sum(
            w.n_scatterers for w in imp.walls) + (imp.ground.n_scatterers if imp.ground else 0)
        if n > MAX_SCATTERERS:
            raise ValueError(f"scene: {n} scatterers (targets + objects' and clutter's "
                             f"n_scatterers), at most {MAX_SCATTERERS}")
        if isinstance(self.seed, bool) or not isinstance(self.seed, int) or not \
                0 <= self.seed <= MAX_SEED:
            raise ValueError(f"seed: must be an integer in 0..2**63-1, got {self.seed!r}")
        try:
            imp.check(self.config)
        except ValueError as exc:
            raise ValueError(f"impairments.{exc}") from None

    @property
    def config(self) -> RadarConfig:
        """The scene's radar: ``radar``, else its preset's configuration."""
        return get_preset(self.preset) if self.radar is None else self.radar

    def scatterers(self) -> Scatterers:
        """All scatterers of the scene: point targets (object_id -1) then each object's."""
        rng = np.random.default_rng(self.seed)
        parts = []
        if self.targets:
            t = self.targets
            parts.append(Scatterers(
                np.array([x.range_m for x in t]), np.array([x.azimuth_deg for x in t]),
                np.array([x.radial_velocity_mps for x in t]), np.array([x.rcs_m2 for x in t]),
                np.full(len(t), -1), np.array([x.elevation_deg for x in t])))
        for i, obj in enumerate(self.objects):
            parts.append(obj.scatterers(rng, i))
        return Scatterers.concat(parts)

    # ---- JSON -----------------------------------------------------------------------------
    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> Scene:
        """Parse scene JSON (already decoded); ValueError naming the bad field."""
        if not isinstance(d, Mapping):
            raise ValueError(f"scene: must be a JSON object, got {type(d).__name__}")
        preset = d.get("preset", "full")
        if not isinstance(preset, str) or preset not in PRESETS:
            raise ValueError(f"preset: unknown preset {preset!r}; choose one of "
                             f"{', '.join(PRESETS)}")
        if "scene" in d:
            check_keys(d, {"scene", "preset", "seed", "tx_beamforming", "noise", "impairments"},
                       "scene")
            builtin = d["scene"]
            if not isinstance(builtin, str) or builtin not in BUILTIN_SCENES:
                raise ValueError(f"scene: unknown built-in scene {builtin!r}; choose one of "
                                 f"{', '.join(BUILTIN_SCENES)}")
            base = BUILTIN_SCENES[builtin](preset)
            return Scene(preset=preset, seed=_int(d, "seed", base.seed),
                         tx_beamforming=_bool(d, "tx_beamforming", base.tx_beamforming),
                         targets=base.targets, objects=base.objects,
                         noise=_bool(d, "noise", True), name=builtin,
                         impairments=_impairments(d))
        check_keys(d, {"preset", "seed", "tx_beamforming", "targets", "objects", "noise",
                       "name", "impairments"}, "scene")
        targets = d.get("targets", [])
        objects = d.get("objects", [])
        if not isinstance(targets, list):
            raise ValueError("targets: must be a list")
        if not isinstance(objects, list):
            raise ValueError("objects: must be a list")
        if not targets and not objects:
            raise ValueError("scene: needs at least one entry in 'targets' or 'objects'")
        name = d.get("name", "custom")
        return Scene(
            preset=preset, seed=_int(d, "seed", 0),
            tx_beamforming=_bool(d, "tx_beamforming", True),
            targets=tuple(PointTarget.from_dict(t, f"targets[{i}]")
                          for i, t in enumerate(targets)),
            objects=tuple(ExtendedObject.from_dict(o, f"objects[{i}]")
                          for i, o in enumerate(objects)),
            noise=_bool(d, "noise", True), name=str(name), impairments=_impairments(d))

    def to_dict(self) -> dict[str, Any]:
        """Scene JSON (explicit targets and objects, never a built-in name; the impairments
        table when there are any; not ``radar``)."""
        d = {"preset": self.preset, "seed": self.seed, "tx_beamforming": self.tx_beamforming,
             "noise": self.noise, "name": self.name,
             "targets": [t.to_dict() for t in self.targets],
             "objects": [asdict(o) for o in self.objects]}
        if self.impairments != NO_IMPAIRMENTS:
            d["impairments"] = self.impairments.to_dict()
        return d


def _impairments(d: Mapping[str, Any]) -> Impairments:
    """The scene JSON's impairments table (none: the ideal radar)."""
    return NO_IMPAIRMENTS if d.get("impairments") is None else Impairments.from_dict(
        d["impairments"])


def _int(d: Mapping[str, Any], key: str, default: int) -> int:
    v = d.get(key, default)
    if isinstance(v, bool) or not isinstance(v, int) or not 0 <= v <= MAX_SEED:
        raise ValueError(f"{key}: must be an integer in 0..2**63-1, got {v!r}")
    return v


def _bool(d: Mapping[str, Any], key: str, default: bool) -> bool:
    v = d.get(key, default)
    if not isinstance(v, bool):
        raise ValueError(f"{key}: must be true or false, got {v!r}")
    return v


# ---- the paper's Table I scene -------------------------------------------------------------
EGO_SPEED_KMH = 100.0
"""Ego vehicle speed of the paper's Table I scene, km/h."""

TABLE1_VEHICLES: tuple[tuple[float, float, float, float], ...] = (
    # (RCS m^2, own speed km/h, azimuth deg, range m) -- paper Table I
    (10.0, 50.0, 30.0, 100.0),
    (40.0, 96.0, 10.0, 50.0),
    (20.0, -80.0, -10.0, 40.0),
    (10.0, 25.0, -30.0, 20.0),
)


MAX_EGO_SPEED_MPS = 150.0
"""Largest ego speed accepted for velocity compensation, m/s (540 km/h)."""


def check_ego_speed(ego_speed_mps: float) -> float:
    """ValueError unless ``ego_speed_mps`` is a finite speed within +-MAX_EGO_SPEED_MPS."""
    if isinstance(ego_speed_mps, bool) or not isinstance(ego_speed_mps, int | float) or not \
            -MAX_EGO_SPEED_MPS <= ego_speed_mps <= MAX_EGO_SPEED_MPS:
        raise ValueError(f"ego speed: must be a finite number of m/s within "
                         f"+-{MAX_EGO_SPEED_MPS:g}, got {ego_speed_mps!r}")
    return float(ego_speed_mps)


def default_ego_speed_mps(scene: Scene) -> float:
    """Ego speed along +x a scene implies, m/s: the Table I scene's 100 km/h, else 0 (a
    static radar). ``radar detect --gnn`` and ``radar gnn detect`` both default to it."""
    return EGO_SPEED_KMH * KMH if scene.name == "table1" else 0.0


def table1_scene(preset: str = "full", seed: int = 1, tx_beamforming: bool = True) -> Scene:
    """The paper's Table I scene: ego at 100 km/h, four vehicles.

    Each vehicle closes at (ego speed - own speed): 13.89, 1.11, 50.0 and 20.83 m/s (the
    paper's Table III "actual speed"), so its radial velocity is minus that (approaching).
    Vehicle 3 (-50 m/s) exceeds the +-27.78 m/s unambiguous velocity and aliases to
    +5.56 m/s in every preset: a real limitation of the waveform, reported, not hidden.
    """
    targets = tuple(
        PointTarget(range_m=r, azimuth_deg=az,
                    radial_velocity_mps=-(EGO_SPEED_KMH - own) * KMH, rcs_m2=rcs)
        for rcs, own, az, r in TABLE1_VEHICLES)
    return Scene(preset=preset, seed=seed, tx_beamforming=tx_beamforming, targets=targets,
                 name="table1")


BUILTIN_SCENES = {"table1": table1_scene}


def load_scene(spec: str | Path, preset: str | None = None) -> Scene:
    """A scene from a JSON file path or a built-in name (``table1``).

    ``preset`` overrides the preset of a built-in scene given by name. Raises ValueError
    with a one-line reason on a missing file, invalid JSON or an invalid field.
    """
    spec_s = str(spec)
    if spec_s in BUILTIN_SCENES:
        return Scene.from_dict({"scene": spec_s, "preset": preset or "full"})
    path = Path(spec_s)
    if path.is_dir():
        raise ValueError(f"scene: {spec_s} is a folder, not a scene JSON file")
    if not path.is_file():
        raise ValueError(f"scene: no such file {spec_s!r} and not a built-in scene "
                         f"({', '.join(BUILTIN_SCENES)})")
    try:
        data = json.loads(path.read_text())
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise ValueError(f"scene: {spec_s} is not valid JSON: {exc}") from None
    except RecursionError:
        raise ValueError(f"scene: {spec_s} is not a scene: JSON nested too deeply") from None
    if preset is not None and isinstance(data, dict):
        data = {**data, "preset": preset}
    return Scene.from_dict(data)
