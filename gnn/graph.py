"""Point cloud -> graph: kNN or radius neighbourhoods (scipy cKDTree) and features.

Node features are, as in RadarGNN, RCS, SNR, the ego-motion compensated radial velocity and
its x/y components and the node degree, plus the line-of-sight direction (see
:data:`NODE_FEATURES`). Absolute positions
enter only through relative positions on the edges. PyG's ``knn_graph`` / ``radius_graph``
need compiled extensions that are not installed, hence cKDTree.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import torch
from scipy.spatial import cKDTree
from torch_geometric.data import Data

from host.pointcloud import PointCloud
from model.scene import check_ego_speed

NODE_FEATURES = ("rcs_dbsm/10", "snr_db/20", "vr_comp/5", "vx_comp/5", "vy_comp/5",
                 "cos_az", "sin_az", "degree/k")
"""Node feature columns (and their scaling). ``cos_az, sin_az`` (the line-of-sight
direction) are our addition to RadarGNN's set: the radar sees only the near side of an
object, so where the centre lies relative to a point depends on the viewing direction."""
EDGE_FEATURES = ("dx/5", "dy/5", "dist/5", "dvr_comp/5")
"""Edge feature columns for edge j -> i: position and velocity of j relative to i."""
POS_SCALE_M = 5.0
VEL_SCALE_MPS = 5.0


@dataclass(frozen=True)
class GraphConfig:
    """How neighbourhoods are built: ``kind`` "knn" (``k`` neighbours, RadarGNN's default
    20) or "radius" (all within ``radius_m``, at most ``k``)."""

    kind: str = "knn"
    k: int = 20
    radius_m: float = 5.0

    def __post_init__(self) -> None:
        if self.kind not in ("knn", "radius"):
            raise ValueError(f"graph kind: must be 'knn' or 'radius', got {self.kind!r}")
        if self.k < 1:
            raise ValueError(f"k: must be >= 1, got {self.k}")
        if not 0 < self.radius_m < math.inf:
            raise ValueError(f"radius_m: must be positive and finite, got {self.radius_m}")


def neighbour_edges(xy: np.ndarray, cfg: GraphConfig) -> np.ndarray:
    """Directed edges j -> i (no self loops), int64 (2, E): row 0 source j, row 1 target i.

    xy: float (n, 2) positions in m. kNN links every node to its ``k`` nearest others;
    radius links every pair closer than ``radius_m`` (each node keeps its ``k`` nearest).
    """
    p = np.asarray(xy, dtype=float).reshape(-1, 2)
    n = len(p)
    if n < 2:
        return np.zeros((2, 0), dtype=np.int64)
    k = min(cfg.k, n - 1)
    ub = cfg.radius_m if cfg.kind == "radius" else np.inf
    dist, idx = cKDTree(p).query(p, k=k + 1, distance_upper_bound=ub)
    dist, idx = dist[:, 1:].reshape(n, k), idx[:, 1:].reshape(n, k)    # drop self
    ok = np.isfinite(dist)
    tgt = np.broadcast_to(np.arange(n)[:, None], idx.shape)
    return np.stack([idx[ok], tgt[ok]]).astype(np.int64)


def compensated_velocity(cloud: PointCloud, ego_speed_mps: float) -> np.ndarray:
    """Radial velocity over ground, m/s (n,): static points -> 0 for ego motion along +x."""
    return cloud.radial_velocity_mps + ego_speed_mps * np.cos(np.radians(cloud.azimuth_deg))


def build_graph(cloud: PointCloud, ego_speed_mps: float = 0.0,
                cfg: GraphConfig | None = None) -> Data:
    """The graph of ``cloud``: ``x`` float32 (n, 8) (:data:`NODE_FEATURES`), ``pos`` float32
    (n, 2) in m, ``edge_index`` int64 (2, E), ``edge_attr`` float32 (E, 4)
    (:data:`EDGE_FEATURES`)."""
    cfg = cfg or GraphConfig()
    check_ego_speed(ego_speed_mps)
    xy = np.stack([cloud.x_m, cloud.y_m], axis=1).astype(float)
    if not np.all(np.isfinite(xy)):
        raise ValueError("cloud: x_m/y_m contain NaN or infinity")
    vr = compensated_velocity(cloud, ego_speed_mps)
    az = np.radians(cloud.azimuth_deg)
    ei = neighbour_edges(xy, cfg)
    degree = np.bincount(ei[1], minlength=len(xy)) / cfg.k
    x = np.stack([np.nan_to_num(cloud.rcs_dbsm) / 10, np.nan_to_num(cloud.snr_db) / 20,
                  vr / VEL_SCALE_MPS, vr * np.cos(az) / VEL_SCALE_MPS,
                  vr * np.sin(az) / VEL_SCALE_MPS, np.cos(az), np.sin(az), degree], axis=1)
    d = xy[ei[0]] - xy[ei[1]]
    edge_attr = np.concatenate([d / POS_SCALE_M, np.hypot(d[:, :1], d[:, 1:]) / POS_SCALE_M,
                                (vr[ei[0]] - vr[ei[1]])[:, None] / VEL_SCALE_MPS], axis=1)
    return Data(x=torch.from_numpy(x.astype(np.float32)),
                pos=torch.from_numpy(xy.astype(np.float32)),
                edge_index=torch.from_numpy(ei),
                edge_attr=torch.from_numpy(edge_attr.astype(np.float32).reshape(-1, 4)),
                num_nodes=len(xy))
