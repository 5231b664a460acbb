"""Checkpoints: a plain dict of the model's state_dict, its configuration and metadata,
loadable with ``torch.load(path, weights_only=True)``."""

from __future__ import annotations

from dataclasses import asdict
from pathlib import Path
from typing import Any

import torch

from gnn.graph import GraphConfig
from gnn.model import ModelConfig, RadarGnn

DEFAULT_CHECKPOINT = Path(__file__).resolve().parent / "checkpoints" / "radargnn_synth.pt"
"""The shipped checkpoint, trained on the synthetic dataset (docs/gnn.md)."""


def save_checkpoint(path: Path, model: RadarGnn, graph_cfg: GraphConfig,
                    meta: dict[str, Any]) -> None:
    """Write ``{"state_dict", "model", "graph", "meta"}`` (tensors, numbers, strings);
    ValueError when a weight is not finite (a diverged training: nothing is written)."""
    bad = _non_finite(model.state_dict())
    if bad:
        raise ValueError(f"checkpoint: {bad} holds NaN or infinite weights (training "
                         f"diverged: lower --lr); nothing written to {path}")
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    torch.save({"state_dict": model.state_dict(), "model": model.cfg.to_dict(),
                "graph": asdict(graph_cfg), "meta": meta}, path)


def load_checkpoint(path: Path | None = None) -> tuple[RadarGnn, GraphConfig, dict[str, Any]]:
    """The model (eval mode), graph configuration and metadata stored at ``path``
    (default :data:`DEFAULT_CHECKPOINT`); ValueError if missing or not a checkpoint."""
    path = Path(path) if path is not None else DEFAULT_CHECKPOINT
    if not path.is_file():
        raise ValueError(f"checkpoint: no such file {str(path)!r}")
    try:
        ck = torch.load(path, weights_only=True, map_location="cpu")
        model = RadarGnn(ModelConfig(**ck["model"]))
        model.load_state_dict(ck["state_dict"])
        graph = GraphConfig(**ck["graph"])
    except Exception as exc:  # noqa: BLE001 - any failure means "not a checkpoint"
        # torch's own message may advise weights_only=False (executing arbitrary pickled
        # code from the file): never pass that on, name only the kind of failure
        raise ValueError(f"checkpoint: {path} is not a readable gnn checkpoint "
                         f"({type(exc).__name__}); use a file written by `radar gnn train` "
                         f"(loaded with weights_only=True only)") from None
    bad = _non_finite(model.state_dict())
    if bad:
        raise ValueError(f"checkpoint: {path}: {bad} holds NaN or infinite weights (a "
                         f"diverged training)")
    model.eval()
    return model, graph, dict(ck.get("meta", {}))


def _non_finite(state: dict[str, torch.Tensor]) -> str | None:
    """The name of the first floating-point tensor of ``state`` with a NaN or infinite
    element, else None."""
    for name, t in state.items():
        if t.is_floating_point() and not bool(torch.isfinite(t).all()):
            return name
    return None
