"""Issue 12 item 4: targets the radar cannot see are named, with a reason."""

import pytest

from host.pipeline import process_frame
from model.observability import beyond_max_speed, summarize, unobservable_targets
from model.scene import Scene
from model.simulate import simulate_scene


def _scene(preset, targets, objects=(), bf=True):
    return Scene.from_dict({"preset": preset, "seed": 1, "tx_beamforming": bf,
                            "targets": [{"range_m": r, "azimuth_deg": az,
                                         "radial_velocity_mps": v, "rcs_m2": rcs}
                                        for r, az, v, rcs in targets],
                            "objects": list(objects)})


@pytest.mark.parametrize("preset", ["full", "paper-fpga"])
def test_reasons(preset):
    cfg = Scene(preset=preset).config
    far = cfg.max_detection_range_m + 5
    scene = _scene(preset, [(30, 0, -3, 10), (far, 0, 0, 1e4), (30, 41.81, 0, 10),
                            (cfg.max_range_m * 0.5, 0, 0, 1e-4), (0.5, 0, 0, 0.01)])
    got = {u.target: u.reason for u in unobservable_targets(scene)}
    assert got == {"targets[1]": "beyond_max_range", "targets[2]": "tx_null",
                   "targets[3]": "too_weak", "targets[4]": "too_close"}
    # and they really are not seen: only the first target gives points
    cloud = process_frame(simulate_scene(scene).samples, cfg)
    assert len(cloud) >= 1 and abs(cloud.range_m - 30).max() < 3
    doc = summarize(unobservable_targets(scene))
    assert doc["unobservable_targets"] == 4


def test_tx_null_only_with_beamforming():
    scene = _scene("full", [(30, 41.81, 0, 10)], bf=False)
    assert unobservable_targets(scene) == []


def test_object_entirely_beyond_range():
    obj = {"x_m": 600, "y_m": 0, "length_m": 4.5, "width_m": 1.8, "rcs_m2": 10}
    scene = _scene("full", [(30, 0, 0, 10)], [obj])
    assert [(u.target, u.reason) for u in unobservable_targets(scene)] == [
        ("objects[0]", "beyond_max_range")]


def test_passing_target_counted_once_over_frames():
    scene = _scene("paper-fpga", [(1.9, 0, -25, 10)])
    items = [u for k in range(0, 12, 3) for u in unobservable_targets(scene, k)]
    doc = summarize(items)
    assert doc["unobservable_targets"] == 1
    assert {e["reason"] for e in doc["unobservable"]} <= {"passed", "too_close"}


def test_fast_target_warned():
    scene = _scene("full", [(40, 0, 200, 10), (50, 0, -20, 10)])
    warn = beyond_max_speed(scene, 100.0)
    assert len(warn) == 1 and warn[0].startswith("targets[0]")
