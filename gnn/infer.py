"""Inference: point cloud -> objects with the trained GNN (``detect_objects``)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import torch

from gnn.checkpoint import load_checkpoint
from gnn.detection import Detection, decode
from gnn.graph import GraphConfig, build_graph
from gnn.model import RadarGnn
from host.pointcloud import PointCloud
from model.scene import check_ego_speed


class GnnDetector:
    """A trained :class:`gnn.model.RadarGnn` with its graph settings and the decoder."""

    def __init__(self, model: RadarGnn, graph_cfg: GraphConfig) -> None:
        self.model = model.eval()
        self.graph_cfg = graph_cfg

    @classmethod
    def from_checkpoint(cls, path: Path | None = None) -> GnnDetector:
        """Load ``path`` (default: the shipped checkpoint)."""
        model, graph_cfg, _ = load_checkpoint(path)
        return cls(model, graph_cfg)

    def predict(self, cloud: PointCloud, ego_speed_mps: float = 0.0
                ) -> tuple[np.ndarray, np.ndarray]:
        """Class probabilities float (n, C) and box outputs float (n, 5) per point."""
        if len(cloud) == 0:
            return np.zeros((0, 6)), np.zeros((0, 5))
        g = build_graph(cloud, ego_speed_mps, self.graph_cfg)
        with torch.inference_mode():
            logits, box = self.model(g.x, g.pos, g.edge_index, g.edge_attr)
        return torch.softmax(logits, 1).numpy().astype(float), box.numpy().astype(float)

    def detect(self, cloud: PointCloud, ego_speed_mps: float = 0.0
               ) -> tuple[list[Detection], np.ndarray]:
        """Detections and per-point class int (n,)."""
        prob, box = self.predict(cloud, ego_speed_mps)
        return decode(cloud, prob, box)


_DEFAULT: GnnDetector | None = None


def detect_objects(cloud: PointCloud, ego_speed_mps: float = 0.0,
                   checkpoint: Path | None = None) -> list[dict[str, Any]]:
    """Objects in ``cloud``, best score first, each a dict ``{"class", "score", "x_m",
    "y_m", "length_m", "width_m", "heading_deg", "points"}`` (m, deg; ``points`` are
    indices into the cloud). ``ego_speed_mps``: ego speed along +x (m/s, 0 for a static
    radar). Uses the shipped checkpoint unless ``checkpoint`` names another."""
    global _DEFAULT
    check_ego_speed(ego_speed_mps)  # before loading torch weights: fail fast
    if checkpoint is not None:
        det = GnnDetector.from_checkpoint(checkpoint)
    else:
        if _DEFAULT is None:
            _DEFAULT = GnnDetector.from_checkpoint()
        det = _DEFAULT
    dets, _ = det.detect(cloud, ego_speed_mps)
    return [d.to_dict() for d in dets]
