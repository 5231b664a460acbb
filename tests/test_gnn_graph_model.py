"""Graph construction, the network, checkpoints and inference on hand-made clouds."""

from dataclasses import replace

import numpy as np
import pytest
import torch

from gnn.checkpoint import load_checkpoint, save_checkpoint
from gnn.classes import NUM_CLASSES
from gnn.graph import GraphConfig, build_graph, neighbour_edges
from gnn.infer import GnnDetector, detect_objects
from gnn.model import ModelConfig, RadarGnn
from host.pointcloud import PointCloud

torch.set_num_threads(1)


def cloud(n: int = 30, seed: int = 0) -> PointCloud:
    rng = np.random.default_rng(seed)
    return PointCloud.from_polar(
        range_m=rng.uniform(5, 60, n), azimuth_deg=rng.uniform(-40, 40, n),
        radial_velocity_mps=rng.uniform(-10, 10, n), power_db=rng.uniform(30, 60, n),
        snr_db=rng.uniform(10, 40, n), rcs_dbsm=rng.uniform(-10, 20, n),
        range_bin=rng.integers(0, 256, n), doppler_bin=rng.integers(0, 256, n),
        ambiguous=np.zeros(n, bool))


def shifted(c: PointCloud, dx: float, dy: float) -> PointCloud:
    return replace(c, x_m=c.x_m + dx, y_m=c.y_m + dy)


def test_knn_edges():
    xy = np.random.default_rng(1).normal(size=(50, 2))
    ei = neighbour_edges(xy, GraphConfig(k=20))
    assert ei.shape == (2, 50 * 20)
    assert not np.any(ei[0] == ei[1])
    assert np.all(np.bincount(ei[1], minlength=50) == 20)
    assert neighbour_edges(xy[:5], GraphConfig(k=20)).shape == (2, 20)   # n - 1 each
    assert neighbour_edges(xy[:1], GraphConfig()).shape == (2, 0)


def test_radius_edges_respect_radius():
    xy = np.array([[0, 0], [1, 0], [5, 0]], dtype=float)
    ei = neighbour_edges(xy, GraphConfig(kind="radius", radius_m=2.0))
    assert sorted(map(tuple, ei.T.tolist())) == [(0, 1), (1, 0)]
    with pytest.raises(ValueError, match="kind"):
        GraphConfig(kind="delaunay")


def test_edge_features_are_translation_invariant():
    c = cloud()
    a, b = build_graph(c), build_graph(shifted(c, 7.0, -3.0))
    assert torch.equal(a.x, b.x)       # node features come from the polar fields
    assert torch.equal(a.edge_index, b.edge_index)
    assert torch.allclose(a.edge_attr, b.edge_attr, atol=1e-5)
    assert a.x.shape == (30, 8) and a.edge_attr.shape == (600, 4)


def test_network_shapes_and_permutation_equivariance():
    torch.manual_seed(0)
    c = cloud()
    g = build_graph(c)
    model = RadarGnn(ModelConfig(hidden=16, layers=2)).eval()
    logits, box = model(g.x, g.pos, g.edge_index, g.edge_attr)
    assert logits.shape == (30, NUM_CLASSES) and box.shape == (30, 5)
    perm = np.random.default_rng(3).permutation(30)
    gp = build_graph(c.select(perm))
    lp, _ = model(gp.x, gp.pos, gp.edge_index, gp.edge_attr)
    assert torch.allclose(lp, logits[perm], atol=1e-5)


@pytest.mark.parametrize("offset,residual", [(True, True), (False, False)])
def test_checkpoint_roundtrip_weights_only(tmp_path, offset, residual):
    model = RadarGnn(ModelConfig(hidden=8, layers=1, auto_offset=offset, residual=residual))
    path = tmp_path / "ck.pt"
    save_checkpoint(path, model, GraphConfig(k=7), {"note": "test"})
    raw = torch.load(path, weights_only=True)
    assert set(raw) == {"state_dict", "model", "graph", "meta"}
    m2, gc, meta = load_checkpoint(path)
    assert gc.k == 7 and meta["note"] == "test"
    for k, v in model.state_dict().items():
        assert torch.equal(v, m2.state_dict()[k])
    with pytest.raises(ValueError, match="no such file"):
        load_checkpoint(tmp_path / "missing.pt")


def test_detect_objects_contract(tmp_path):
    path = tmp_path / "ck.pt"
    save_checkpoint(path, RadarGnn(ModelConfig(hidden=8, layers=1)), GraphConfig(), {})
    objs = detect_objects(cloud(), 3.0, checkpoint=path)
    for o in objs:
        assert set(o) == {"class", "score", "x_m", "y_m", "length_m", "width_m",
                          "heading_deg", "points"}
    assert GnnDetector.from_checkpoint(path).detect(PointCloud.empty())[0] == []


def test_shipped_checkpoint_is_small_and_loads():
    from gnn.checkpoint import DEFAULT_CHECKPOINT

    assert DEFAULT_CHECKPOINT.stat().st_size <= 5 * 2**20
    objs = detect_objects(cloud())
    assert isinstance(objs, list)
