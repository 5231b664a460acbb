"""Training loop: Adam on weighted cross-entropy + Huber box loss over batches of graphs."""

from __future__ import annotations

import math
import random
from dataclasses import dataclass

import numpy as np
import torch
from torch_geometric.data import Data
from torch_geometric.loader import DataLoader
from tqdm import tqdm

from gnn.frame import IGNORE, Frame
from gnn.graph import GraphConfig, build_graph
from gnn.losses import box_targets, class_weights, detection_loss
from gnn.model import ModelConfig, RadarGnn


@dataclass(frozen=True)
class TrainConfig:
    """Optimiser settings: epochs, batch size (graphs), learning rate, weight of the box
    loss, random seed."""

    epochs: int = 40
    batch_size: int = 16
    lr: float = 2e-3
    box_weight: float = 1.0
    seed: int = 0

    def __post_init__(self) -> None:
        if self.epochs < 1 or self.batch_size < 1 or not 0 < self.lr < math.inf:
            raise ValueError("train: epochs and batch_size must be >= 1 and lr finite > 0")
        if not 0 <= self.box_weight < math.inf:
            raise ValueError(f"train: box_weight must be finite and >= 0, got "
                             f"{self.box_weight!r}")


def seed_everything(seed: int) -> None:
    """Seed Python, numpy and torch."""
    random.seed(seed)
    np.random.seed(seed)  # noqa: NPY002  (legacy global seed for third-party code)
    torch.manual_seed(seed)


def frame_to_data(frame: Frame, graph_cfg: GraphConfig) -> Data:
    """Graph of ``frame`` with training targets ``y`` (n,), ``box_t`` (n, 5), ``box_mask``."""
    data = build_graph(frame.cloud, frame.ego_speed_mps, graph_cfg)
    t, mask = box_targets(frame)
    data.y = torch.from_numpy(frame.point_class.astype(np.int64))
    data.box_t = torch.from_numpy(t)
    data.box_mask = torch.from_numpy(mask)
    return data


def train(frames: list[Frame], train_cfg: TrainConfig | None = None,
          model_cfg: ModelConfig | None = None, graph_cfg: GraphConfig | None = None,
          progress: bool = True) -> tuple[RadarGnn, list[dict[str, float]]]:
    """Train a fresh model on ``frames``; returns it (eval mode) and per-epoch history
    (``loss``, ``cls_loss``, ``box_loss``, ``accuracy`` over labelled training points)."""
    tc, gc = train_cfg or TrainConfig(), graph_cfg or GraphConfig()
    if not frames:
        raise ValueError("train: no training frames")
    seed_everything(tc.seed)
    data = [frame_to_data(f, gc) for f in frames if len(f.cloud)]
    weights = class_weights(frames)
    model = RadarGnn(model_cfg)
    opt = torch.optim.Adam(model.parameters(), lr=tc.lr)
    sched = torch.optim.lr_scheduler.CosineAnnealingLR(opt, T_max=tc.epochs)
    gen = torch.Generator().manual_seed(tc.seed)
    loader = DataLoader(data, batch_size=tc.batch_size, shuffle=True, generator=gen)
    history: list[dict[str, float]] = []
    bar = tqdm(range(tc.epochs), desc="train", unit="epoch", disable=not progress)
    for epoch in bar:
        model.train()
        tot = np.zeros(3)
        correct = labelled = 0
        for b in loader:
            logits, box = model(b.x, b.pos, b.edge_index, b.edge_attr)
            loss, lc, lb = detection_loss(logits, box, b.y, b.box_t, b.box_mask, weights,
                                          tc.box_weight)
            opt.zero_grad()
            loss.backward()
            opt.step()
            tot += [loss.item(), lc.item(), lb.item()]
            keep = b.y != IGNORE
            correct += int((logits.argmax(1)[keep] == b.y[keep]).sum())
            labelled += int(keep.sum())
        sched.step()
        nb = max(len(loader), 1)
        history.append({"epoch": epoch, "loss": float(tot[0] / nb),
                        "cls_loss": float(tot[1] / nb), "box_loss": float(tot[2] / nb),
                        "accuracy": correct / max(labelled, 1)})
        bar.set_postfix(loss=f"{tot[0] / nb:.3f}", acc=f"{correct / max(labelled, 1):.3f}")
    model.eval()
    return model, history
