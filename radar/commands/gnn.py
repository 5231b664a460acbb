"""``radar gnn``: the GNN object detector's commands ``dataset``, ``train``, ``eval`` and
``detect`` (the tasks themselves are :mod:`radar.commands.gnn_tasks`). Bad input exits with
status 2 and a one-line reason.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable

from radar.commands import gnn_tasks as tasks
from radar.common import CliError


def _guarded(cmd: Callable[[argparse.Namespace], int]) -> Callable[[argparse.Namespace], int]:
    """``cmd`` that turns a ValueError or CliError (bad input) into ``error: <reason>`` on
    stderr and exit status 2, so callers (``radar gnn``) need no knowledge of our
    exceptions."""
    def run(args: argparse.Namespace) -> int:
        try:
            return int(cmd(args))
        except (ValueError, CliError) as exc:
            print(f"radar gnn: error: {exc}", file=sys.stderr)
            return 2
    return run


def add_subcommands(subparsers: argparse._SubParsersAction) -> None:
    """Add ``dataset``, ``train``, ``eval`` and ``detect`` to ``subparsers``; each sets
    ``func(args) -> int`` (0 on success, 2 with a one-line reason on bad input)."""
    from gnn.checkpoint import DEFAULT_CHECKPOINT
    from gnn.dataset import DEFAULT_CACHE

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
                   "auto = pipeline")
    p.add_argument("--workers", type=int, default=2, help="worker processes (default 2)")
    p.add_argument("--radarscenes", default=None, metavar="SEQ_DIR",
                   help="instead: convert one RadarScenes sequence folder (radar_data.h5 + "
                   "scenes.json) into CACHE_DIR/radarscenes-<name>.npz")
    p.add_argument("--window-s", type=float, default=0.5,
                   help="RadarScenes accumulation window, s (default 0.5, as RadarGNN)")
    p.set_defaults(func=_guarded(tasks.cmd_dataset), parser=p)

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
    p.set_defaults(func=_guarded(tasks.cmd_train), parser=p)

    p = subparsers.add_parser("eval", help="GNN vs DBSCAN baseline metrics",
                              description="mAP at point IoU 0.3 and box IoU 0.5, per-point "
                              "F1, latency; GNN and baseline on the same frames.")
    common(p)
    p.add_argument("--data", default=None, help="test .npz (default CACHE_DIR/test.npz)")
    p.add_argument("--checkpoint", default=None, help="checkpoint (default: shipped one)")
    p.add_argument("--json", default=None, metavar="OUT.json", help="write all metrics here")
    p.add_argument("--threads", type=int, default=1, help="torch CPU threads (default 1)")
    p.set_defaults(func=_guarded(tasks.cmd_eval))

    p = subparsers.add_parser("detect", help="detect objects in one point cloud or scene")
    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--points", default=None, help="point cloud JSON (docs/design.md 4.4)")
    src.add_argument("--scene", default=None,
                     help="scene JSON or built-in name, simulated through the host chain")
    p.add_argument("--ego-speed", type=float, default=None,
                   help="ego speed along +x, m/s (default as `radar detect --gnn`: the "
                        "scene's, 27.78 for table1, else 0; with --points the ego_speed_mps "
                        "recorded in the JSON, else 0)")
    p.add_argument("--checkpoint", default=None, help="checkpoint (default: shipped one)")
    p.add_argument("--json", default=None, metavar="OUT.json", help="write the objects here")
    p.set_defaults(func=_guarded(tasks.cmd_detect))


def add_parsers(sub: argparse._SubParsersAction, presets: list[str],
                with_subcommands: bool = False) -> None:
    """The ``gnn`` command; its subcommands only when ``with_subcommands`` (building them
    imports the checkpoint module: only for ``radar gnn ...``)."""
    g = sub.add_parser("gnn", help="GNN object detector: dataset, train, eval, detect "
                                   "(radar gnn --help)")
    if with_subcommands:
        add_subcommands(g.add_subparsers(dest="gnn_command", required=True,
                                         metavar="GNN_COMMAND"))
