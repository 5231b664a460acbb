"""Random labelled road scenes for the synthetic GNN dataset, built from ``model.scene``.

A scene holds moving road users of the five RadarScenes classes, static clutter (guard rails,
poles, parked cars) and ego motion along +x. Each road user is one
:class:`model.scene.ExtendedObject` (the body: scatterers on its radar-facing edges) plus
:class:`model.scene.PointTarget` s for its micro-Doppler parts (wheels of cars, bikes and
trucks; swinging arms and legs of pedestrians) whose radial velocities are perturbed around
the body's. Everything static moves at minus the ego velocity relative to the radar.

Kinematics follow the model's convention: velocities relative to the radar, at the centre of
the frame. Sizes, speeds and RCS are plausible RadarScenes-like values (:data:`CLASS_SPECS`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gnn.classes import CLASSES, class_index
from model.scene import ExtendedObject, PointTarget, Scene


@dataclass(frozen=True)
class ClassSpec:
    """Size (m), speed over ground (m/s), total RCS (m^2, log-uniform) and body scatterers."""

    length_m: tuple[float, float]
    width_m: tuple[float, float]
    speed_mps: tuple[float, float]
    rcs_m2: tuple[float, float]
    n_body: tuple[int, int]
    n_micro: tuple[int, int]
    """Extra micro-Doppler scatterers (wheels, limbs)."""
    micro_spread: float
    """Micro-Doppler velocity spread as a fraction of the speed over ground."""


CLASS_SPECS: dict[str, ClassSpec] = {
    "car": ClassSpec((3.8, 5.0), (1.7, 2.0), (3.0, 18.0), (5.0, 30.0), (8, 14), (2, 4), 0.6),
    "pedestrian": ClassSpec((0.4, 0.7), (0.4, 0.7), (0.6, 2.2), (0.3, 1.2), (2, 3), (2, 4),
                            1.0),
    "pedestrian_group": ClassSpec((1.2, 3.0), (1.2, 3.0), (0.6, 1.8), (1.0, 4.0), (5, 9),
                                  (4, 8), 1.0),
    "two_wheeler": ClassSpec((1.6, 2.2), (0.6, 0.9), (3.0, 12.0), (1.0, 5.0), (3, 5), (2, 4),
                             0.8),
    "large_vehicle": ClassSpec((7.0, 14.0), (2.4, 2.6), (3.0, 15.0), (30.0, 150.0),
                               (16, 26), (4, 8), 0.5),
}
"""Plausible parameter ranges (uniform unless stated) of each object class."""

MAX_RELATIVE_SPEED_MPS = 25.0
"""Road users are drawn so their speed relative to the radar stays below this (the
waveform's unambiguous velocity is 27.78 m/s)."""


@dataclass(frozen=True)
class LabelledScene:
    """A model scene with its ground truth.

    ``boxes``: float (m, 5) ``[x, y, length, width, heading_rad]`` of the moving road users;
    ``box_class``: int (m,) class indices (:data:`gnn.classes.CLASSES`); ``ego_speed_mps``:
    ego speed along +x (m/s, over ground). Static objects carry no box (background).
    """

    scene: Scene
    boxes: np.ndarray
    box_class: np.ndarray
    ego_speed_mps: float


def _micro_doppler(rng: np.random.Generator, box: np.ndarray, vrel: np.ndarray,
                   v_ground: np.ndarray, spec: ClassSpec, rcs_total: float) -> list[PointTarget]:
    """Micro-Doppler scatterers inside ``box``: velocity = vrel + perturbation along the
    object's motion (wheels and limbs move between 0 and ~2x the body speed)."""
    n = int(rng.integers(spec.n_micro[0], spec.n_micro[1] + 1))
    x, y, length, width, h = box
    out = []
    for _ in range(n):
        a, c = rng.uniform(-0.45, 0.45, size=2)
        px = x + a * length * math.cos(h) - c * width * math.sin(h)
        py = y + a * length * math.sin(h) + c * width * math.cos(h)
        if px <= 0.5:
            continue
        pert = v_ground * (spec.micro_spread * rng.uniform(-1.0, 1.0))
        v = vrel + pert
        r = math.hypot(px, py)
        out.append(PointTarget(range_m=r, azimuth_deg=math.degrees(math.atan2(py, px)),
                               radial_velocity_mps=float((px * v[0] + py * v[1]) / r),
                               rcs_m2=rcs_total * float(rng.uniform(0.03, 0.15))))
    return out


def _free_spot(rng: np.random.Generator, taken: list[np.ndarray], radius: float,
               max_range: float, max_az_deg: float) -> np.ndarray | None:
    """A centre (x, y) inside the field of view at least ``radius`` + each taken radius away."""
    for _ in range(50):
        r = rng.uniform(max(4.0, radius + 2.0), max_range)
        az = math.radians(rng.uniform(-max_az_deg, max_az_deg))
        p = np.array([r * math.cos(az), r * math.sin(az)])
        if all(np.hypot(*(p - t[:2])) > radius + t[2] for t in taken):
            return p
    return None


def random_scene(seed: int, preset: str = "full", max_range_m: float = 70.0,
                 max_azimuth_deg: float = 40.0, n_objects: tuple[int, int] = (2, 8)
                 ) -> LabelledScene:
    """A random labelled scene, fully determined by ``seed``.

    Objects lie within ``max_range_m`` (m) and +-``max_azimuth_deg`` (deg) of boresight;
    between ``n_objects`` moving road users (classes equally likely), 0-2 guard rails,
    0-6 poles and 0-3 parked cars.
    """
    if seed < 0:
        raise ValueError(f"seed: must be non-negative, got {seed}")
    rng = np.random.default_rng([7, seed])
    ego = float(rng.uniform(0.0, 12.0))
    v_static = np.array([-ego, 0.0])
    taken: list[np.ndarray] = []          # (x, y, radius) of placed things
    objects: list[ExtendedObject] = []
    targets: list[PointTarget] = []
    boxes, box_class = [], []

    for _ in range(int(rng.integers(n_objects[0], n_objects[1] + 1))):
        name = CLASSES[int(rng.integers(0, 5))]
        spec = CLASS_SPECS[name]
        length = rng.uniform(*spec.length_m)
        width = min(rng.uniform(*spec.width_m), length)
        radius = math.hypot(length, width) / 2 + 1.0
        p = _free_spot(rng, taken, radius, max_range_m, max_azimuth_deg)
        if p is None:
            continue
        for _ in range(20):
            heading = rng.uniform(-math.pi, math.pi)
            speed = rng.uniform(*spec.speed_mps)
            v_ground = speed * np.array([math.cos(heading), math.sin(heading)])
            vrel = v_ground + v_static
            if np.hypot(*vrel) < MAX_RELATIVE_SPEED_MPS:
                break
        taken.append(np.array([p[0], p[1], radius]))
        rcs = math.exp(rng.uniform(math.log(spec.rcs_m2[0]), math.log(spec.rcs_m2[1])))
        box = np.array([p[0], p[1], length, width, heading])
        objects.append(ExtendedObject(
            x_m=float(p[0]), y_m=float(p[1]), length_m=float(length), width_m=float(width),
            heading_deg=math.degrees(heading), vx_mps=float(vrel[0]), vy_mps=float(vrel[1]),
            rcs_m2=rcs, n_scatterers=int(rng.integers(spec.n_body[0], spec.n_body[1] + 1)),
            label=name))
        targets.extend(_micro_doppler(rng, box, vrel, v_ground, spec, rcs))
        boxes.append(box)
        box_class.append(class_index(name))

    targets.extend(_static_clutter(rng, taken, v_static, max_range_m, max_azimuth_deg))
    for _ in range(int(rng.integers(0, 4))):          # parked cars: static, background
        p = _free_spot(rng, taken, 3.5, max_range_m, max_azimuth_deg)
        if p is None:
            continue
        taken.append(np.array([p[0], p[1], 3.5]))
        objects.append(ExtendedObject(
            x_m=float(p[0]), y_m=float(p[1]), length_m=float(rng.uniform(3.8, 5.0)),
            width_m=1.8, heading_deg=float(rng.choice([0.0, 90.0]) + rng.normal(0, 5)),
            vx_mps=-ego, vy_mps=0.0, rcs_m2=float(rng.uniform(5, 20)),
            n_scatterers=int(rng.integers(6, 12)), label="static"))
    scene = Scene(preset=preset, seed=seed, targets=tuple(targets), objects=tuple(objects),
                  name=f"gnn-synth-{seed}")
    return LabelledScene(scene=scene, boxes=np.array(boxes, dtype=float).reshape(-1, 5),
                         box_class=np.array(box_class, dtype=int), ego_speed_mps=ego)


def _static_clutter(rng: np.random.Generator, taken: list[np.ndarray], v_static: np.ndarray,
                    max_range_m: float, max_az_deg: float) -> list[PointTarget]:
    """Guard rails (posts every 2-4 m along a line y = const) and isolated poles, kept 1.5 m
    clear of the road users so geometric labelling stays unambiguous."""
    pts: list[tuple[float, float, float]] = []
    for _ in range(int(rng.integers(0, 3))):
        y = float(rng.choice([-1.0, 1.0]) * rng.uniform(3.0, 9.0))
        x = float(rng.uniform(3.0, 8.0))
        step = float(rng.uniform(2.0, 4.0))
        while x < max_range_m:
            pts.append((x, y + rng.normal(0, 0.1), float(rng.uniform(0.1, 1.0))))
            x += step
    for _ in range(int(rng.integers(0, 7))):
        r = rng.uniform(4.0, max_range_m)
        az = math.radians(rng.uniform(-max_az_deg, max_az_deg))
        pts.append((r * math.cos(az), r * math.sin(az), float(rng.uniform(0.5, 5.0))))
    out = []
    for x, y, rcs in pts:
        az_deg = math.degrees(math.atan2(y, x))
        if abs(az_deg) >= 60 or any(math.hypot(x - t[0], y - t[1]) < t[2] + 0.5 for t in taken):
            continue
        r = math.hypot(x, y)
        out.append(PointTarget(range_m=r, azimuth_deg=az_deg,
                               radial_velocity_mps=float((x * v_static[0] + y * v_static[1]) / r),
                               rcs_m2=rcs))
    return out
