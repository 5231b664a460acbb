"""The GNN detector's tasks behind ``radar gnn``: ``dataset``, ``train``, ``eval``,
``detect``. Each takes the parsed options and returns the exit status; bad input raises
ValueError (reported by :mod:`radar.commands.gnn`)."""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

from host.pointcloud import PointCloud
from radar.common import out_file, out_folder, refuse


def cmd_dataset(args: argparse.Namespace) -> int:
    from gnn.dataset import build_split, save_frames

    if args.radarscenes is None:
        refuse(args, ("window_s",), "without --radarscenes")
    else:
        refuse(args, ("train", "val", "test", "backend", "workers"), "to --radarscenes "
               "(it converts one recorded sequence)")
    for option in ("--train", "--val", "--test"):
        n = getattr(args, option[2:])
        if n < 0:
            raise ValueError(f"{option}: must be a number of frames >= 0, got {n}")
    out_folder(args.cache_dir, "--cache-dir")    # before rendering, not after

    if args.radarscenes is not None:
        from gnn.radarscenes import load_sequence

        frames = load_sequence(args.radarscenes, window_s=args.window_s)
        out = Path(args.cache_dir) / f"radarscenes-{Path(args.radarscenes).name}.npz"
        save_frames(out, frames, {"source": "radarscenes", "frames": len(frames)})
        print(f"{out}: {len(frames)} frames")
        return 0
    for split, n in (("train", args.train), ("val", args.val), ("test", args.test)):
        if n > 0:
            path = build_split(Path(args.cache_dir), split, n, args.backend, args.workers,
                               progress=not args.quiet)
            print(f"{split}: {path} ({n} frames)")
    return 0


def cmd_train(args: argparse.Namespace) -> int:
    import torch

    from gnn.checkpoint import save_checkpoint
    from gnn.dataset import load_frames
    from gnn.graph import GraphConfig
    from gnn.model import ModelConfig
    from gnn.train import TrainConfig, train

    _threads(torch, args.threads)
    out_file(args.out, None, "--out")   # before training, not after
    refuse(args, ("radius",) if args.graph == "knn" else ("k",),
           f"to --graph {args.graph}")
    gc = GraphConfig(kind=args.graph, k=args.k, radius_m=args.radius)   # checked first
    mc = ModelConfig(hidden=args.hidden, layers=args.layers, auto_offset=not args.no_offset,
                     residual=not args.no_residual)
    tc = TrainConfig(epochs=args.epochs, batch_size=args.batch_size, lr=args.lr,
                     box_weight=args.box_weight, seed=args.seed)
    paths = [Path(d) for d in args.data] if args.data else [_data_path(args, "train")]
    frames, meta = [], {}
    for path in paths:
        more, meta = load_frames(path)
        frames.extend(more)
    model, history = train(frames, tc, mc, gc, progress=not args.quiet)
    save_checkpoint(args.out, model, gc, {
        "train_frames": len(frames), "dataset_backend": meta.get("backend", "?"),
        "datasets": " ".join(p.name for p in paths),
        "epochs": tc.epochs, "seed": tc.seed, "final_loss": history[-1]["loss"],
        "final_accuracy": history[-1]["accuracy"]})
    last = history[-1]
    print(f"{args.out}: loss {history[0]['loss']:.3f} -> {last['loss']:.3f}, "
          f"point accuracy {last['accuracy']:.3f}")
    return 0


def _threads(torch: Any, threads: int) -> None:
    """``--threads`` checked, then torch's intra-op pool set to it."""
    if threads < 1:
        raise ValueError(f"--threads: must be >= 1, got {threads}")
    torch.set_num_threads(threads)


def cmd_eval(args: argparse.Namespace) -> int:
    import torch

    from gnn.dataset import load_frames
    from gnn.evaluate import evaluate_all
    from gnn.infer import GnnDetector

    _threads(torch, args.threads)
    if args.json is not None:
        out_file(args.json, None, "--json")     # before the evaluation, not after
    frames, _ = load_frames(_data_path(args, "test"))
    res = evaluate_all(GnnDetector.from_checkpoint(args.checkpoint), frames,
                       progress=not args.quiet)
    print(f"{'metric':<22}{'GNN':>10}{'baseline':>10}")
    for k in ("map_point_iou_0_3", "f1", "map_box_iou_0_5", "latency_ms"):
        print(f"{k:<22}{res[k]:>10.3f}{res['baseline_' + k]:>10.3f}")
    if args.json is not None:
        Path(args.json).write_text(json.dumps(_jsonable(res), indent=1) + "\n")
    return 0


def cmd_detect(args: argparse.Namespace) -> int:
    from gnn.infer import detect_objects
    from model.scene import check_ego_speed, default_ego_speed_mps

    if args.json is not None:
        out_file(args.json, None, "--json")     # before the work, not after
    # the ego speed defaults as in `radar detect --gnn`: the scene's (100 km/h for table1,
    # else 0), and for a point cloud JSON the ego_speed_mps that `radar detect` wrote in it
    if args.points is not None:
        cloud = read_points(Path(args.points))
        ego = args.ego_speed if args.ego_speed is not None else _json_ego(Path(args.points))
    else:
        from gnn.render import render_points
        from model.scene import load_scene

        scene = load_scene(args.scene)
        cloud = render_points(scene, "pipeline")
        ego = args.ego_speed if args.ego_speed is not None else default_ego_speed_mps(scene)
    objs = detect_objects(cloud, check_ego_speed(ego), args.checkpoint)
    text = json.dumps({"points": len(cloud), "objects": objs}, indent=1)
    if args.json is not None:
        Path(args.json).write_text(text + "\n")
    for o in objs:
        print(f"{o['class']:<17}{o['score']:6.2f}  x {o['x_m']:7.2f} m  y {o['y_m']:7.2f} m  "
              f"{o['length_m']:5.2f} x {o['width_m']:4.2f} m  {o['heading_deg']:7.1f} deg  "
              f"{len(o['points'])} points")
    return 0


def _json_ego(path: Path) -> float:
    """``ego_speed_mps`` recorded in a point cloud JSON by ``radar detect`` (0 if absent)."""
    value = json.loads(path.read_text()).get("ego_speed_mps", 0.0)
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ValueError(f"points: {path}: ego_speed_mps must be a number, got {value!r}")
    return float(value)


def read_points(path: Path) -> PointCloud:
    """A point cloud from the docs/design.md 4.4 JSON file ``path``."""
    if not path.is_file():
        raise ValueError(f"points: no such file {str(path)!r}")
    try:
        doc = json.loads(path.read_text())
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise ValueError(f"points: {path} is not a point cloud JSON ({exc})") from None
    except RecursionError:
        raise ValueError(f"points: {path} is not a point cloud JSON (nested too "
                         f"deeply)") from None
    try:
        return PointCloud.from_json_dict(doc)
    except (ValueError, OverflowError) as exc:
        raise ValueError(f"points: {path}: {exc}") from None


def _data_path(args: argparse.Namespace, split: str) -> Path:
    if args.data is not None:
        return Path(args.data)
    from gnn.dataset import split_path

    path = split_path(Path(args.cache_dir), split)
    if not path.is_file():
        raise ValueError(f"dataset: no {split} set at {path}: generate it first with "
                         f"`make gnn-dataset` (or `radar gnn dataset --cache-dir "
                         f"{args.cache_dir}`)")
    return path


def _jsonable(x: Any) -> Any:
    if isinstance(x, dict):
        return {k: _jsonable(v) for k, v in x.items()}
    if isinstance(x, list | tuple):
        return [_jsonable(v) for v in x]
    if hasattr(x, "item"):
        return x.item()
    return x
