"""Command line of the GNN detector: ``dataset``, ``train``, ``eval``, ``detect``.

Mounted by the ``radar`` command as ``radar gnn ...`` through :func:`add_subcommands`; also
runnable on its own as ``python -m gnn.cli ...``. Bad input exits non-zero with a one-line
reason.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from host.pointcloud import PointCloud

DEFAULT_CACHE = Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache")) / "radar-gnn"
"""Default dataset cache folder (``$XDG_CACHE_HOME/radar-gnn``)."""


def _cmd_dataset(args: argparse.Namespace) -> int:
    from gnn.dataset import build_split, save_frames

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


def _cmd_train(args: argparse.Namespace) -> int:
    import torch

    from gnn.checkpoint import save_checkpoint
    from gnn.dataset import load_frames
    from gnn.graph import GraphConfig
    from gnn.model import ModelConfig
    from gnn.train import TrainConfig, train

    torch.set_num_threads(args.threads)
    paths = [Path(d) for d in args.data] if args.data else [_data_path(args, "train")]
    frames, meta = [], {}
    for path in paths:
        more, meta = load_frames(path)
        frames.extend(more)
    gc = GraphConfig(kind=args.graph, k=args.k, radius_m=args.radius)
    mc = ModelConfig(hidden=args.hidden, layers=args.layers, auto_offset=not args.no_offset,
                     residual=not args.no_residual)
    tc = TrainConfig(epochs=args.epochs, batch_size=args.batch_size, lr=args.lr,
                     box_weight=args.box_weight, seed=args.seed)
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


def _cmd_eval(args: argparse.Namespace) -> int:
    import torch

    from gnn.dataset import load_frames
    from gnn.evaluate import evaluate_all
    from gnn.infer import GnnDetector

    torch.set_num_threads(args.threads)
    frames, _ = load_frames(_data_path(args, "test"))
    res = evaluate_all(GnnDetector.from_checkpoint(args.checkpoint), frames,
                       progress=not args.quiet)
    print(f"{'metric':<22}{'GNN':>10}{'baseline':>10}")
    for k in ("map_point_iou_0_3", "f1", "map_box_iou_0_5", "latency_ms"):
        print(f"{k:<22}{res[k]:>10.3f}{res['baseline_' + k]:>10.3f}")
    if args.json is not None:
        Path(args.json).write_text(json.dumps(_jsonable(res), indent=1) + "\n")
    return 0


def _cmd_detect(args: argparse.Namespace) -> int:
    from gnn.infer import detect_objects

    if args.points is not None:
        cloud = _read_points(Path(args.points))
    else:
        from gnn.render import render_points
        from model.scene import load_scene

        cloud = render_points(load_scene(args.scene), "pipeline")
    objs = detect_objects(cloud, args.ego_speed, args.checkpoint)
    text = json.dumps({"points": len(cloud), "objects": objs}, indent=1)
    if args.json is not None:
        Path(args.json).write_text(text + "\n")
    for o in objs:
        print(f"{o['class']:<17}{o['score']:6.2f}  x {o['x_m']:7.2f} m  y {o['y_m']:7.2f} m  "
              f"{o['length_m']:5.2f} x {o['width_m']:4.2f} m  {o['heading_deg']:7.1f} deg  "
              f"{len(o['points'])} points")
    return 0


def _read_points(path: Path) -> PointCloud:
    """A point cloud from the DESIGN.md section 4 JSON (``{"points": [...]}``)."""
    from host.pointcloud import PointCloud

    if not path.is_file():
        raise ValueError(f"points: no such file {str(path)!r}")
    try:
        pts = json.loads(path.read_text())["points"]
        get = {k: [float(p[k]) for p in pts] for k in
               ("range_m", "azimuth_deg", "radial_velocity_mps", "power_db", "snr_db")}
        rcs = [float(p.get("rcs_dbsm", 0.0)) for p in pts]
        rb = [int(p.get("range_bin", 0)) for p in pts]
        db = [int(p.get("doppler_bin", 0)) for p in pts]
        amb = [bool(p.get("ambiguous", False)) for p in pts]
    except (json.JSONDecodeError, KeyError, TypeError, ValueError) as exc:
        raise ValueError(f"points: {path} is not a point cloud JSON ({exc!r})") from None
    return PointCloud.from_polar(rcs_dbsm=rcs, range_bin=rb, doppler_bin=db, ambiguous=amb,
                                 **get)


def _data_path(args: argparse.Namespace, split: str) -> Path:
    if args.data is not None:
        return Path(args.data)
    from gnn.dataset import split_path

    return split_path(Path(args.cache_dir), split)


def _jsonable(x: Any) -> Any:
    if isinstance(x, dict):
        return {k: _jsonable(v) for k, v in x.items()}
    if isinstance(x, list | tuple):
        return [_jsonable(v) for v in x]
    if hasattr(x, "item"):
        return x.item()
    return x


def _guarded(cmd: Callable[[argparse.Namespace], int]) -> Callable[[argparse.Namespace], int]:
    """``cmd`` that turns a ValueError (bad input) into ``error: <reason>`` on stderr and
    exit status 2, so callers (``radar gnn``) need no knowledge of our exceptions."""
    def run(args: argparse.Namespace) -> int:
        try:
            return int(cmd(args))
        except ValueError as exc:
            print(f"gnn: error: {exc}", file=sys.stderr)
            return 2
    return run


def add_subcommands(subparsers: argparse._SubParsersAction) -> None:
    """Add ``dataset``, ``train``, ``eval`` and ``detect`` to ``subparsers``; each sets
    ``func(args) -> int`` (0 on success, 2 with a one-line reason on bad input)."""
    from gnn.checkpoint import DEFAULT_CHECKPOINT

    def common(p: argparse.ArgumentParser) -> None:
        p.add_argument("--cache-dir", default=str(DEFAULT_CACHE),
                       help=f"dataset cache folder (default {DEFAULT_CACHE})")
        p.add_argument("--quiet", action="store_true", help="no progress bars")

    p = subparsers.add_parser("dataset", help="generate the synthetic labelled dataset",
                              description="Render random labelled scenes through "
                              "model.simulate and the host chain; cache one .npz per split.")
    common(p)
    p.add_argument("--train", type=int, default=700, help="training frames (default 700)")
    p.add_argument("--val", type=int, default=0, help="validation frames (default 0)")
    p.add_argument("--test", type=int, default=200, help="held-out test frames (default 200)")
    p.add_argument("--backend", default="auto", choices=("auto", "pipeline", "stand-in"),
                   help="scene -> points: host chain (pipeline) or the model stand-in; "
                   "auto = pipeline when host.pipeline exists")
    p.add_argument("--workers", type=int, default=2, help="worker processes (default 2)")
    p.add_argument("--radarscenes", default=None, metavar="SEQ_DIR",
                   help="instead: convert one RadarScenes sequence folder (radar_data.h5 + "
                   "scenes.json) into CACHE_DIR/radarscenes-<name>.npz")
    p.add_argument("--window-s", type=float, default=0.5,
                   help="RadarScenes accumulation window, s (default 0.5, as RadarGNN)")
    p.set_defaults(func=_guarded(_cmd_dataset))

    p = subparsers.add_parser("train", help="train the GNN, write a checkpoint",
                              description="Adam on weighted cross-entropy + Huber box loss.")
    common(p)
    p.add_argument("--data", default=None, nargs="+", metavar="NPZ",
                   help="training .npz file(s) (default CACHE_DIR/train.npz)")
    p.add_argument("--out", default=str(DEFAULT_CHECKPOINT), help="checkpoint to write")
    p.add_argument("--epochs", type=int, default=40, help="epochs (default 40)")
    p.add_argument("--batch-size", type=int, default=16, help="graphs per batch (default 16)")
    p.add_argument("--lr", type=float, default=2e-3, help="Adam learning rate (default 2e-3)")
    p.add_argument("--box-weight", type=float, default=1.0, help="box loss weight")
    p.add_argument("--hidden", type=int, default=64, help="feature width (default 64)")
    p.add_argument("--layers", type=int, default=3, help="message-passing layers (default 3)")
    p.add_argument("--graph", default="knn", choices=("knn", "radius"), help="graph kind")
    p.add_argument("--k", type=int, default=20, help="neighbours per node (default 20)")
    p.add_argument("--radius", type=float, default=5.0, help="radius graph radius, m")
    p.add_argument("--no-offset", action="store_true", help="no auto-registration offsets")
    p.add_argument("--no-residual", action="store_true", help="no residual updates")
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    p.add_argument("--threads", type=int, default=1, help="torch CPU threads (default 1)")
    p.set_defaults(func=_guarded(_cmd_train))

    p = subparsers.add_parser("eval", help="GNN vs DBSCAN baseline metrics",
                              description="mAP at point IoU 0.3 and box IoU 0.5, per-point "
                              "F1, latency; GNN and baseline on the same frames.")
    common(p)
    p.add_argument("--data", default=None, help="test .npz (default CACHE_DIR/test.npz)")
    p.add_argument("--checkpoint", default=None, help="checkpoint (default: shipped one)")
    p.add_argument("--json", default=None, metavar="OUT.json", help="write all metrics here")
    p.add_argument("--threads", type=int, default=1, help="torch CPU threads (default 1)")
    p.set_defaults(func=_guarded(_cmd_eval))

    p = subparsers.add_parser("detect", help="detect objects in one point cloud or scene")
    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--points", default=None, help="point cloud JSON (DESIGN.md section 4)")
    src.add_argument("--scene", default=None,
                     help="scene JSON or built-in name, simulated through the host chain")
    p.add_argument("--ego-speed", type=float, default=0.0, help="ego speed along +x, m/s")
    p.add_argument("--checkpoint", default=None, help="checkpoint (default: shipped one)")
    p.add_argument("--json", default=None, metavar="OUT.json", help="write the objects here")
    p.set_defaults(func=_guarded(_cmd_detect))


def build_parser() -> argparse.ArgumentParser:
    """``python -m gnn.cli`` parser."""
    parser = argparse.ArgumentParser(prog="python -m gnn.cli",
                                     description="RadarGNN-style detector for the radar's "
                                     "point clouds.")
    add_subcommands(parser.add_subparsers(dest="command", required=True))
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run one subcommand; on bad input print ``gnn: error: <reason>`` and return 2."""
    args = build_parser().parse_args(argv)
    return int(args.func(args))


if __name__ == "__main__":
    sys.exit(main())
