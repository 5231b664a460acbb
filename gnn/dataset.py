"""Synthetic labelled dataset: random scenes -> radar point clouds -> labelled frames, cached.

Frame ``i`` of a split is :func:`gnn.synth_scenes.random_scene` with seed
``SPLIT_SEED_BASE[split] + i`` rendered by :func:`gnn.render.render_points`, so every frame is
reproducible on its own and the splits never share a scene. A split is cached as one ``.npz``
(points of all frames concatenated, with offsets); generation runs over worker processes with
a progress bar.
"""

from __future__ import annotations

import multiprocessing as mp
import os
from dataclasses import MISSING, fields
from pathlib import Path

import numpy as np
from tqdm import tqdm

from gnn.frame import Frame
from gnn.labelling import assign_points
from gnn.render import render_points, resolve_backend
from gnn.synth_scenes import random_scene
from host.pointcloud import PointCloud

DEFAULT_CACHE = Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache")) / "radar-gnn"
"""Default dataset cache folder (``$XDG_CACHE_HOME/radar-gnn``)."""
SPLIT_SEED_BASE = {"train": 0, "val": 500_000, "test": 1_000_000}
"""First scene seed of each split."""
FORMAT_VERSION = 1


def make_frame(seed: int, backend: str = "auto", preset: str = "full") -> Frame:
    """One labelled frame of scene ``seed`` (see the module docstring)."""
    ls = random_scene(seed, preset=preset)
    cloud = render_points(ls.scene, backend)
    cls, obj = assign_points(np.stack([cloud.x_m, cloud.y_m], axis=1), ls.boxes, ls.box_class)
    return Frame(cloud=cloud, ego_speed_mps=ls.ego_speed_mps, point_class=cls,
                 point_object=obj, boxes=ls.boxes, box_class=ls.box_class)


def _make_frame_args(args: tuple[int, str, str]) -> Frame:
    return make_frame(*args)


def generate(seeds: list[int], backend: str = "auto", workers: int = 2,
             progress: bool = True, preset: str = "full") -> list[Frame]:
    """Frames of ``seeds`` in order, over ``workers`` processes (1: in this process)."""
    if workers < 1:
        raise ValueError(f"workers: must be >= 1, got {workers}")
    backend = resolve_backend(backend)
    jobs = [(s, backend, preset) for s in seeds]
    bar = tqdm(total=len(jobs), desc=f"frames ({backend})", unit="frame", disable=not progress)
    out: list[Frame] = []
    if workers == 1:
        for j in jobs:
            out.append(_make_frame_args(j))
            bar.update()
    else:
        with mp.get_context("fork").Pool(workers) as pool:
            for f in pool.imap(_make_frame_args, jobs, chunksize=4):
                out.append(f)
                bar.update()
    bar.close()
    return out


def save_frames(path: Path, frames: list[Frame], meta: dict[str, str | int]) -> None:
    """Write ``frames`` to one compressed ``.npz`` with string/int ``meta``."""
    counts = np.array([len(f.cloud) for f in frames])
    nbox = np.array([len(f.boxes) for f in frames])
    arrays: dict[str, np.ndarray] = {
        f"pc_{fl.name}": np.concatenate([getattr(f.cloud, fl.name) for f in frames])
        if frames else np.zeros(0) for fl in fields(PointCloud)}
    arrays.update(
        point_offsets=np.concatenate([[0], np.cumsum(counts)]),
        box_offsets=np.concatenate([[0], np.cumsum(nbox)]),
        point_class=np.concatenate([f.point_class for f in frames] or [np.zeros(0, int)]),
        point_object=np.concatenate([f.point_object for f in frames] or [np.zeros(0, int)]),
        boxes=np.concatenate([f.boxes for f in frames] or [np.zeros((0, 5))]),
        box_class=np.concatenate([f.box_class for f in frames] or [np.zeros(0, int)]),
        ego_speed=np.array([f.ego_speed_mps for f in frames]),
        meta_keys=np.array(list(meta)), meta_values=np.array([str(v) for v in meta.values()]))
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".tmp.npz")
    np.savez_compressed(tmp, **arrays)
    tmp.replace(path)


def load_frames(path: Path) -> tuple[list[Frame], dict[str, str]]:
    """Frames and meta saved by :func:`save_frames`; ValueError if the file is not one."""
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"dataset: no such file {str(path)!r}")
    try:
        z = np.load(path)
        po, bo = z["point_offsets"], z["box_offsets"]
        meta = dict(zip(z["meta_keys"].tolist(), z["meta_values"].tolist(), strict=True))
        pc = {fl.name: z[f"pc_{fl.name}"] for fl in fields(PointCloud)
              if fl.default is MISSING or f"pc_{fl.name}" in z.files}  # older files: no z
        pcls, pobj, boxes, bcls, ego = (z[k] for k in ("point_class", "point_object", "boxes",
                                                       "box_class", "ego_speed"))
    except (KeyError, OSError, ValueError, EOFError) as exc:
        # numpy's own advice for a non-archive (load it unsafely with allow_pickle) is not
        # one to give about a dataset file
        why = "not a numpy .npz archive" if "allow_pickle" in str(exc) else str(exc)
        raise ValueError(f"dataset: {path} is not a gnn dataset file ({why})") from None
    frames = []
    for i in range(len(ego)):
        p, b = slice(po[i], po[i + 1]), slice(bo[i], bo[i + 1])
        frames.append(Frame(cloud=PointCloud(**{k: v[p] for k, v in pc.items()}),
                            ego_speed_mps=float(ego[i]), point_class=pcls[p],
                            point_object=pobj[p], boxes=boxes[b], box_class=bcls[b]))
    return frames, meta


def read_meta(path: Path) -> dict[str, str] | None:
    """The meta of a dataset file without loading its points; None if unreadable."""
    try:
        with np.load(path) as z:
            return dict(zip(z["meta_keys"].tolist(), z["meta_values"].tolist(), strict=True))
    except (KeyError, OSError, ValueError):
        return None


def split_path(cache_dir: Path, split: str) -> Path:
    """Cache file of ``split`` inside ``cache_dir``."""
    if split not in SPLIT_SEED_BASE:
        raise ValueError(f"split: unknown split {split!r}; choose one of "
                         f"{', '.join(SPLIT_SEED_BASE)}")
    return Path(cache_dir) / f"{split}.npz"


def build_split(cache_dir: Path, split: str, n_frames: int, backend: str = "auto",
                workers: int = 2, progress: bool = True) -> Path:
    """Generate (or reuse from the cache) ``n_frames`` frames of ``split``; returns the file.

    The cache is reused when its meta (format, split, frame count, backend) matches.
    """
    if n_frames < 1:
        raise ValueError(f"frames: must be >= 1, got {n_frames}")
    path = split_path(cache_dir, split)
    backend = resolve_backend(backend)
    meta: dict[str, str | int] = {"format": FORMAT_VERSION, "split": split,
                                  "frames": n_frames, "backend": backend,
                                  "first_seed": SPLIT_SEED_BASE[split]}
    if path.is_file() and read_meta(path) == {k: str(v) for k, v in meta.items()}:
        return path
    base = SPLIT_SEED_BASE[split]
    frames = generate(list(range(base, base + n_frames)), backend, workers, progress)
    save_frames(path, frames, meta)
    return path
