"""The training loop learns on a tiny synthetic set; ``radar gnn`` runs end to end."""

import json

import numpy as np
import torch

from gnn.classes import NUM_CLASSES
from gnn.dataset import generate
from gnn.graph import GraphConfig
from gnn.model import ModelConfig
from gnn.train import TrainConfig, frame_to_data, train
from radar.cli import main as radar_main

torch.set_num_threads(1)


def test_tiny_training_learns():
    frames = generate(list(range(40)), "stand-in", workers=1, progress=False)
    gc = GraphConfig(k=10)
    model, hist = train(frames, TrainConfig(epochs=25, batch_size=4, lr=5e-3),
                        ModelConfig(hidden=32, layers=2), gc, progress=False)
    assert hist[-1]["loss"] < 0.7 * hist[0]["loss"]
    # balanced accuracy (mean recall over the classes present) well above chance
    recalls = []
    with torch.no_grad():
        data = [frame_to_data(f, gc) for f in frames]
        y = torch.cat([d.y for d in data])
        pred = torch.cat([model(d.x, d.pos, d.edge_index, d.edge_attr)[0].argmax(1)
                          for d in data])
    for c in range(NUM_CLASSES):
        if (y == c).any():
            recalls.append(float((pred[y == c] == c).float().mean()))
    assert np.mean(recalls) > 1 / NUM_CLASSES + 0.25


def main(argv: list[str]) -> int:
    return radar_main(["gnn", *argv])


def test_cli_end_to_end(tmp_path, capsys):
    cache = str(tmp_path)
    assert main(["dataset", "--cache-dir", cache, "--train", "12", "--test", "6",
                 "--backend", "stand-in", "--workers", "1", "--quiet"]) == 0
    ck = str(tmp_path / "ck.pt")
    assert main(["train", "--cache-dir", cache, "--epochs", "2", "--hidden", "8",
                 "--layers", "1", "--out", ck, "--quiet"]) == 0
    out = tmp_path / "m.json"
    assert main(["eval", "--cache-dir", cache, "--checkpoint", ck, "--json", str(out),
                 "--quiet"]) == 0
    res = json.loads(out.read_text())
    for k in ("map_point_iou_0_3", "f1", "map_box_iou_0_5", "baseline_map_point_iou_0_3",
              "latency_ms"):
        assert k in res
    pts = tmp_path / "p.json"
    pts.write_text(json.dumps({"preset": "full", "frames": 1, "points": [
        {"range_m": 20.0, "azimuth_deg": 3.0, "radial_velocity_mps": -5.0, "x_m": 0, "y_m": 0,
         "power_db": 40.0, "snr_db": 20.0}] * 3}))
    det = tmp_path / "d.json"
    assert main(["detect", "--points", str(pts), "--checkpoint", ck, "--json", str(det)]) == 0
    assert json.loads(det.read_text())["points"] == 3
    assert main(["eval", "--data", str(tmp_path / "missing.npz"), "--quiet"]) == 2
    assert "no such file" in capsys.readouterr().err
