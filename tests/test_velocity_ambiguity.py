"""Issue 12 item 3: every point whose velocity could be an alias says so.

Rule (host.pipeline, step 3): hypotheses v + 2 m vmax within +-max_speed_mps; one TX cannot
separate them (paper-fpga: every point ambiguous once max_speed > vmax); with TDM the phase
test separates hypotheses that differ modulo num_tx. Whatever the preset, a point whose
reported velocity is not the true one must carry ``ambiguous``.
"""

import numpy as np
import pytest

from host.evaluate import match_targets, table3
from host.pipeline import DetectionParams, process_frame
from model.config import get_preset
from model.scene import Scene, table1_scene
from model.simulate import simulate_scene
from tests.oracles.points import velocity_hypotheses


def _cloud(preset, targets, params=None, seed=2):
    scene = Scene.from_dict({"preset": preset, "seed": seed, "targets": [
        {"range_m": r, "azimuth_deg": az, "radial_velocity_mps": v, "rcs_m2": 20.0}
        for r, az, v in targets]})
    return scene, process_frame(simulate_scene(scene).samples, scene.config, params)


def _check_honest(scene, cloud, params):
    """Each target is found; a point reporting a wrong velocity is flagged."""
    cfg = scene.config
    matches, _ = match_targets(cloud, scene.targets, cfg, gate_azimuth_deg=4.0)
    for m in matches:
        assert m.index >= 0, f"target {m.target} missed"
    for i in range(len(cloud)):
        t = min(scene.targets, key=lambda t: abs(t.range_m - cloud.range_m[i]))
        if abs(cloud.radial_velocity_mps[i] - t.radial_velocity_mps) > 0.5:
            assert cloud.ambiguous[i], (f"point at {cloud.range_m[i]:.1f} m reports "
                                        f"{cloud.radial_velocity_mps[i]:.2f} m/s for true "
                                        f"{t.radial_velocity_mps} without the flag")
    return matches


def test_paper_fpga_one_tx_flags_everything():
    targets = [(15, 0, -50.0), (25, 10, -30.0), (35, -10, -10.0), (45, 5, 0.7),
               (55, 0, 20.0), (65, -5, 45.0)]
    scene, cloud = _cloud("paper-fpga", targets)
    _check_honest(scene, cloud, DetectionParams())
    assert len(cloud) >= len(targets) and cloud.ambiguous.all()


def test_full_tdm_unfolds_or_flags():
    targets = [(20, 0, -90.0), (30, 15, -50.0), (40, -15, -30.0), (50, 5, -10.0),
               (60, -5, 5.0), (70, 20, 20.0), (80, -20, 40.0), (90, 10, 70.0)]
    scene, cloud = _cloud("full", targets)
    matches = _check_honest(scene, cloud, DetectionParams())
    # strong, in-span targets are unfolded correctly
    for m in matches:
        assert abs(m.velocity_err_mps) < 0.3
    # slow targets well inside +-vmax are not flagged: TDM excludes the other hypotheses
    slow = [m.index for m in matches if abs(m.target.radial_velocity_mps) < 15]
    assert not cloud.ambiguous[slow].any()


def test_beyond_tdm_span_flagged_when_max_speed_covers_it():
    """200 m/s on full aliases to -22.2 m/s by 2 * num_tx * vmax: the data cannot tell;
    with max_speed 250 the point says so (with the default 100 m/s the scene check warns,
    see test_observability)."""
    params = DetectionParams(max_speed_mps=250.0)
    scene, cloud = _cloud("full", [(40, 0, 200.0)], params)
    assert len(cloud) == 1 and cloud.ambiguous[0]
    assert cloud.radial_velocity_mps[0] == pytest.approx(200.0 - 8 * 27.78, abs=0.5)


def test_max_speed_below_vmax_makes_one_tx_unambiguous():
    params = DetectionParams(max_speed_mps=20.0)
    scene, cloud = _cloud("paper-fpga", [(30, 0, -10.0)], params)
    assert len(cloud) == 1 and not cloud.ambiguous[0]


def test_hypotheses():
    cfg = get_preset("full")  # vmax 27.78, alias period 55.56
    assert velocity_hypotheses(cfg, -3.0, 100.0) == [-1, 0, 1]
    assert velocity_hypotheses(cfg, -3.0, 20.0) == [0]
    assert velocity_hypotheses(cfg, 5.53, 60.0) == [-1, 0]
    assert velocity_hypotheses(cfg, 25.0, 10.0) == [0]


def test_table3_never_measures_error_against_the_alias():
    scene = table1_scene("paper-fpga", seed=1)
    cfg = scene.config
    cloud = process_frame(simulate_scene(scene).samples, cfg)
    matches, _ = match_targets(cloud, scene.targets, cfg, gate_azimuth_deg=3.0)
    v3 = matches[2]
    assert v3.aliased and abs(v3.velocity_err_mps) > 50 and abs(v3.alias_velocity_err_mps) < 0.2
    row = table3(matches, cloud, cfg).splitlines()[2 + 2]
    assert "ALIASED" in row and "*" in row
    err = float(row.split("|")[2].split()[2])
    assert err > 50, row
    assert np.all(cloud.ambiguous)
