"""`radar detect --detect fpga`: the chain's on-chip detector (OUTPUT_MODE = 1, bit-accurate
model) -> record bytes -> host decoder -> point cloud, on the Table I scene (full)."""

import json
import os
from dataclasses import replace

import pytest

from host.cfar import CfarParams
from host.evaluate import match_targets
from host.params import DetectionParams
from host.pointcloud import PointCloud
from host.records import fpga_detect_config
from model.config import get_preset
from model.radar_pipeline import PipelineParams
from model.scene import table1_scene
from model.simulate import simulate_scene
from radar.cli import main
from radar.frame_cloud import frame_cloud
from radar.sources import get_source

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
                       (["--detector", "paper"], "not --detector paper"),
                       (["--detector", "os", "--fpga-cfar", "go"], "--fpga-cfar go"),
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


def test_table1_os_on_chip(tmp_path):
    """--detector os --detect fpga: the on-chip OS-CFAR finds every Table I vehicle."""
    out = tmp_path / "os.json"
    assert main(["detect", "--scene", "table1", "--json", str(out), "--detect", "fpga",
                 "--detector", "os", "--backend", "model"]) == 0
    doc = json.loads(out.read_text())
    matches, _ = match_targets(PointCloud.from_json_dict(doc), table1_scene("full").targets,
                               get_preset("full"))
    assert all(m.index >= 0 for m in matches), [m.target for m in matches if m.index < 0]


@pytest.mark.parametrize("kind", ["ca", "os"])
def test_on_chip_local_max_same_points(kind: str):
    """With the on-chip 3x3 local maximum on, the records are fewer and the host's
    regrouping of them gives the same points as from all detections (paper-fpga, Table I)."""
    scene = table1_scene("paper-fpga")
    cfg = scene.config
    params = DetectionParams(detector=kind, cfar=CfarParams(kind=kind))
    dcfg = fpga_detect_config(cfg, params.cfar, kind)
    source = get_source("model", PipelineParams())
    adc = simulate_scene(scene, frame_index=0).samples
    clouds, records = [], []
    for d in (dcfg, replace(dcfg, local_max=True)):
        (frame,) = list(source.dma_frames([adc], cfg, d))
        fc = frame_cloud(frame, cfg, params, 0, "detect")
        clouds.append(fc.cloud.records())
        records.append(len(fc.records.range_bin))
    assert records[1] < records[0] and len(clouds[0]) >= 3
    assert clouds[1] == clouds[0]
