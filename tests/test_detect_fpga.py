"""`radar detect --detect fpga`: the chain's on-chip detector (OUTPUT_MODE = 1, bit-accurate
model) -> record bytes -> host decoder -> point cloud, on the Table I scene (full)."""

import json
import os

import pytest

from host.evaluate import match_targets
from host.pointcloud import PointCloud
from model.config import get_preset
from model.scene import table1_scene
from radar.cli import main

REQUIRED = {"range_m", "azimuth_deg", "radial_velocity_mps", "x_m", "y_m", "power_db", "snr_db"}


def test_table1_every_vehicle_found(tmp_path, capsys):
    out = tmp_path / "pts.json"
    assert main(["detect", "--scene", "table1", "--json", str(out), "--detect", "fpga",
                 "--backend", "model"]) == 0
    doc = json.loads(out.read_text())
    assert doc["preset"] == "full" and doc["frames"] == 1 and doc["detect"] == "fpga"
    assert doc["points"] and all(REQUIRED <= set(p) for p in doc["points"])
    info = doc["frame_info"][0]
    assert info["complete"] and not info["truncated"] and info["records"] >= len(doc["points"])
    cloud = PointCloud.from_json_dict(doc)
    scene = table1_scene("full")
    matches, _ = match_targets(cloud, scene.targets, get_preset("full"))
    assert all(m.index >= 0 for m in matches), [m.target for m in matches if m.index < 0]
    assert all(abs(m.range_err_m) < 1.0 for m in matches)


def test_bad_input_one_line(tmp_path, capsys):
    base = ["detect", "--scene", "table1", "--json", str(tmp_path / "x.json"), "--detect",
            "fpga"]
    for extra, why in ((["--backend", "float"], "no on-chip detector"),
                       (["--detector", "os"], "not --detector os"),
                       (["--max-detections", "0"], "--max-detections"),
                       (["--plots", str(tmp_path)], "--plots")):
        assert main(base + extra) == 2
        err = capsys.readouterr().err.strip()
        assert err.count("\n") == 0 and why in err, err
    assert not (tmp_path / "x.json").exists()


@pytest.mark.skipif(not os.environ.get("DETECT_LONG"),
                    reason="builds the mode-1 top (minutes): make test-detect-long")
def test_rtl_backend_same_points_as_model_paper_fpga(tmp_path):
    docs = []
    for backend in ("rtl", "model"):
        out = tmp_path / f"{backend}.json"
        assert main(["detect", "--scene", "table1", "--preset", "paper-fpga", "--detect",
                     "fpga", "--backend", backend, "--json", str(out)]) == 0
        docs.append(json.loads(out.read_text()))
    assert docs[0]["points"] == docs[1]["points"] and len(docs[0]["points"]) >= 3
    assert docs[0]["frame_info"][0]["complete"]
