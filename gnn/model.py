"""RadarGNN-style detector: node/edge embeddings, max-aggregation message passing, heads.

Per node the network outputs class logits (:data:`gnn.classes.CLASSES`) and a box
``[dx, dy, log length, log width, heading]``: the offset from the point to the object centre
(m), the log of the footprint (log m) and the heading (rad, modulo pi).

Message passing (Point-GNN, Shi & Rajkumar 2020, as used by RadarGNN, Fent et al. 2023):
``h_i' = h_i + g( max_j f([h_j, e_ij, p_j - p_i + Δp_i]) )`` where ``Δp_i = a(h_i)`` is the
optional auto-registration offset and the residual ``h_i +`` is optional too.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import torch
from torch import Tensor, nn
from torch_geometric.nn import MessagePassing

from gnn.classes import NUM_CLASSES
from gnn.graph import EDGE_FEATURES, NODE_FEATURES, POS_SCALE_M

BOX_DIM = 5


def mlp(dims: list[int], last_activation: bool = True) -> nn.Sequential:
    """Linear + ReLU stack through ``dims`` (len(dims) - 1 layers)."""
    layers: list[nn.Module] = []
    for i in range(len(dims) - 1):
        layers.append(nn.Linear(dims[i], dims[i + 1]))
        if i < len(dims) - 2 or last_activation:
            layers.append(nn.ReLU())
    return nn.Sequential(*layers)


@dataclass(frozen=True)
class ModelConfig:
    """Network size: ``hidden`` width, ``layers`` message-passing layers, ``auto_offset``
    (Point-GNN auto-registration) and ``residual`` updates."""

    hidden: int = 64
    layers: int = 3
    auto_offset: bool = True
    residual: bool = True

    def __post_init__(self) -> None:
        if self.hidden < 4 or self.layers < 1:
            raise ValueError(f"model: hidden must be >= 4 and layers >= 1, got "
                             f"{self.hidden}, {self.layers}")

    def to_dict(self) -> dict[str, int | bool]:
        return asdict(self)


class PointGnnLayer(MessagePassing):
    """One message-passing layer with max aggregation (see the module docstring)."""

    def __init__(self, hidden: int, auto_offset: bool, residual: bool) -> None:
        super().__init__(aggr="max")
        self.auto_offset = auto_offset
        self.residual = residual
        self.offset = mlp([hidden, hidden // 2, 2], last_activation=False) if auto_offset \
            else None
        self.message_mlp = mlp([2 * hidden + 2, hidden, hidden])
        self.update_mlp = mlp([hidden, hidden, hidden], last_activation=not residual)

    def forward(self, h: Tensor, pos: Tensor, edge_index: Tensor, e: Tensor) -> Tensor:
        """h: (n, hidden); pos: (n, 2) m; edge_index: (2, E); e: (E, hidden)."""
        delta = self.offset(h) if self.offset is not None else torch.zeros_like(pos)
        agg = self.propagate(edge_index, h=h, pos=pos / POS_SCALE_M, delta=delta, e=e)
        out = self.update_mlp(agg)
        return torch.relu(h + out) if self.residual else out

    def message(self, h_j: Tensor, pos_j: Tensor, pos_i: Tensor, delta_i: Tensor,
                e: Tensor) -> Tensor:
        return self.message_mlp(torch.cat([h_j, e, pos_j - pos_i + delta_i], dim=1))


class RadarGnn(nn.Module):
    """Node embedding (4-layer MLP), edge embedding (3-layer MLP), message passing, heads."""

    def __init__(self, cfg: ModelConfig | None = None) -> None:
        super().__init__()
        self.cfg = cfg or ModelConfig()
        h = self.cfg.hidden
        self.node_embed = mlp([len(NODE_FEATURES), h, h, h, h])
        self.edge_embed = mlp([len(EDGE_FEATURES), h, h, h])
        self.layers = nn.ModuleList(PointGnnLayer(h, self.cfg.auto_offset, self.cfg.residual)
                                    for _ in range(self.cfg.layers))
        self.class_head = mlp([h, h, NUM_CLASSES], last_activation=False)
        self.box_head = mlp([h, h, BOX_DIM], last_activation=False)

    def forward(self, x: Tensor, pos: Tensor, edge_index: Tensor, edge_attr: Tensor
                ) -> tuple[Tensor, Tensor]:
        """x: (n, 6) node features; pos: (n, 2) m; edge_index: (2, E); edge_attr: (E, 4).
        Returns (class logits (n, NUM_CLASSES), box (n, 5))."""
        h = self.node_embed(x)
        e = self.edge_embed(edge_attr)
        for layer in self.layers:
            h = layer(h, pos, edge_index, e)
        return self.class_head(h), self.box_head(h)
