"""Scene JSON parsing, built-in Table I scene, extended objects."""

import json

import numpy as np
import pytest

from model.scene import ExtendedObject, Scene, load_scene, table1_scene

DESIGN_EXAMPLE = {"preset": "full", "seed": 1, "tx_beamforming": True,
                  "targets": [{"range_m": 40.0, "azimuth_deg": -10.0,
                               "radial_velocity_mps": -12.5, "rcs_m2": 20.0}]}


def test_design_example_parses():
    s = Scene.from_dict(DESIGN_EXAMPLE)
    assert s.preset == "full" and s.seed == 1 and s.tx_beamforming
    assert s.targets[0].radial_velocity_mps == -12.5
    assert Scene.from_dict(s.to_dict()) == s


def test_builtin_by_name_and_by_json(tmp_path):
    a = load_scene("table1")
    p = tmp_path / "s.json"
    p.write_text(json.dumps({"scene": "table1", "preset": "paper-fpga"}))
    b = load_scene(p)
    assert a.preset == "full" and b.preset == "paper-fpga"
    assert a.targets == b.targets


def test_table1_speeds():
    closing = [-t.radial_velocity_mps for t in table1_scene().targets]
    assert closing == pytest.approx([13.89, 1.11, 50.0, 20.83], abs=0.01)


@pytest.mark.parametrize("bad, msg", [
    ({"preset": "huge", "targets": DESIGN_EXAMPLE["targets"]}, "preset"),
    ({"preset": "full", "targets": [{"range_m": 10, "azimuth_deg": 0, "rcs_m2": 1}]},
     "radial_velocity_mps"),
    ({"preset": "full", "targets": [{**DESIGN_EXAMPLE["targets"][0], "range_m": -3}]},
     "range_m"),
    ({"preset": "full", "targets": [{**DESIGN_EXAMPLE["targets"][0], "azimuth_deg": 95}]},
     "azimuth_deg"),
    ({"preset": "full", "targets": [{**DESIGN_EXAMPLE["targets"][0], "speed": 1}]}, "speed"),
    ({"preset": "full", "targets": []}, "at least one"),
    ({"preset": "full", "targets": DESIGN_EXAMPLE["targets"], "seed": "x"}, "seed"),
    ({"scene": "table2"}, "table2"),
    ([1, 2], "JSON object"),
])
def test_bad_scene_names_the_problem(bad, msg):
    with pytest.raises(ValueError, match=msg):
        Scene.from_dict(bad)


def test_bad_files(tmp_path):
    with pytest.raises(ValueError, match="no such file"):
        load_scene(tmp_path / "missing.json")
    p = tmp_path / "broken.json"
    p.write_text("{not json")
    with pytest.raises(ValueError, match="not valid JSON"):
        load_scene(p)


def test_extended_object_scatterers():
    obj = ExtendedObject(x_m=30.0, y_m=5.0, length_m=4.5, width_m=1.8, heading_deg=20.0,
                         vx_mps=-8.0, vy_mps=1.0, rcs_m2=10.0, n_scatterers=40)
    sc = obj.scatterers(np.random.default_rng(3), object_id=7)
    assert len(sc) == 40 and np.all(sc.object_id == 7)
    assert sc.rcs_m2.sum() == pytest.approx(10.0)
    x = sc.range_m * np.cos(np.radians(sc.azimuth_deg))
    y = sc.range_m * np.sin(np.radians(sc.azimuth_deg))
    # every point lies on the box outline, on the half facing the radar
    h = np.radians(20.0)
    u = (x - 30.0) * np.cos(h) + (y - 5.0) * np.sin(h)
    w = -(x - 30.0) * np.sin(h) + (y - 5.0) * np.cos(h)
    # the radar (origin) is at u = -29.9, w = +5.6 in the box frame: only the rear edge
    # (u = -L/2) and the +w side (w = +W/2) face it
    assert np.all(np.isclose(u, -2.25) | np.isclose(w, 0.9))
    assert np.any(np.isclose(u, -2.25)) and np.any(np.isclose(w, 0.9))
    # radial velocity is the velocity projected on each line of sight
    assert sc.radial_velocity_mps == pytest.approx((x * -8.0 + y * 1.0) / sc.range_m)


def test_scene_scatterers_reproducible():
    d = {"preset": "full", "seed": 5, "objects": [
        {"x_m": 20, "y_m": -3, "length_m": 4, "width_m": 2, "heading_deg": 10, "vx_mps": 2,
         "vy_mps": 0, "rcs_m2": 5, "n_scatterers": 8, "label": "car"}]}
    a, b = Scene.from_dict(d).scatterers(), Scene.from_dict(d).scatterers()
    assert np.array_equal(a.range_m, b.range_m)
