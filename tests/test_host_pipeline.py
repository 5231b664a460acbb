"""Host processing acceptance (issue 5): Table I, two close targets, CFAR false alarms,
paper-fpga end to end."""

import numpy as np
import pytest

from host.cells import scallop
from host.cfar import CfarParams, ca_factor, cfar_threshold, effective_cells, os_factor
from host.evaluate import match_targets
from host.pipeline import DetectionParams, detect_cells, process_cube, process_frame
from model.config import get_preset
from model.reference import FftAxis, radar_cube, range_doppler_power
from model.scene import Scatterers, table1_scene
from model.simulate import simulate_frame, simulate_scene


def _points(*rows):
    a = np.array(rows, dtype=float).reshape(-1, 4)
    return Scatterers(a[:, 0], a[:, 1], a[:, 2], a[:, 3], np.full(len(a), -1))


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_table1_full(seed):
    scene = table1_scene("full", seed=seed)
    cfg = scene.config
    cloud = process_frame(simulate_scene(scene).samples, cfg)
    matches, used = match_targets(cloud, scene.targets, cfg)
    for i in (0, 1, 3):  # vehicles 1, 2, 4
        m = matches[i]
        assert m.index >= 0, f"vehicle {i + 1} missed"
        assert abs(m.range_err_m) <= 0.5
        assert abs(m.velocity_err_mps) <= 0.15
        assert abs(m.azimuth_err_deg) <= 0.5
    # vehicle 3 closes at 50 m/s (beyond +-27.78): unfolded, or aliased with the flag
    v3 = matches[2]
    assert v3.index >= 0
    assert cloud.ambiguous[v3.index]
    assert abs(v3.velocity_err_mps) <= 0.15 and abs(v3.range_err_m) <= 0.5
    if not v3.aliased:  # unfolded: the angle is right too
        assert cloud.radial_velocity_mps[v3.index] == pytest.approx(-50.0, abs=0.15)
        assert abs(v3.azimuth_err_deg) <= 0.5
    assert int((~used).sum()) <= 2


def test_table1_rcs_estimates():
    scene = table1_scene("full", seed=4)
    cfg = scene.config
    cloud = process_frame(simulate_scene(scene).samples, cfg)
    matches, _ = match_targets(cloud, scene.targets, cfg)
    for m in matches:
        if m.index >= 0 and cloud.snr_db[m.index] > 30:
            assert cloud.rcs_dbsm[m.index] == pytest.approx(10 * np.log10(m.target.rcs_m2),
                                                            abs=1.5)


@pytest.mark.parametrize("az0, seed", [(0.0, 0), (20.0, 1), (-35.0, 2)])
def test_two_targets_2p5_deg_apart(az0, seed):
    cfg = get_preset("full")
    sc = _points((60.0, az0, -5.0, 10.0), (60.0, az0 + 2.5, -5.0, 10.0))
    cloud = process_frame(simulate_frame(cfg, sc, rng=np.random.default_rng(seed)).samples, cfg)
    assert len(cloud) == 2
    assert sorted(cloud.azimuth_deg) == pytest.approx([az0, az0 + 2.5], abs=0.5)


def _noise_maps(preset, n, seed):
    cfg = get_preset(preset)
    empty = _points()
    return cfg, [range_doppler_power(radar_cube(
        simulate_frame(cfg, empty, rng=np.random.default_rng(seed + k)).samples, cfg))
        for k in range(n)]


@pytest.mark.parametrize("preset, pfa", [("full", 1e-3), ("full", 1e-4), ("paper-fpga", 1e-3)])
def test_ca_cfar_false_alarm_rate(preset, pfa):
    cfg, maps = _noise_maps(preset, 4 if preset == "full" else 16, 100)
    params = CfarParams(pfa=pfa)
    alarms = cells = 0
    for m in maps:
        threshold, _ = cfar_threshold(m, cfg.n_virtual, params)
        alarms += int(np.sum(m > threshold))
        cells += m.size
    assert alarms > 0
    assert 0.5 <= (alarms / cells) / pfa <= 2.0


def test_os_cfar_false_alarm_rate():
    cfg, maps = _noise_maps("paper-fpga", 8, 300)
    params = CfarParams(pfa=1e-3, kind="os")
    alarms = sum(int(np.sum(m > cfar_threshold(m, cfg.n_virtual, params)[0])) for m in maps)
    rate = alarms / (len(maps) * maps[0].size)
    assert 0.5 <= rate / 1e-3 <= 2.0


def test_cfar_factors():
    # single channel, independent cells: the textbook CA factor N (Pfa^(-1/N) - 1)
    assert ca_factor(1e-4, 1, 32) == pytest.approx(32 * (1e-4 ** (-1 / 32) - 1), rel=1e-6)
    # OS with one channel: Pfa = prod_{i<k} (N - i) / (N - i + alpha)
    n, k = 24, 18
    alpha = os_factor(1e-4, 1, n, k)
    assert np.prod([(n - i) / (n - i + alpha) for i in range(k)]) == pytest.approx(1e-4,
                                                                                  rel=1e-3)
    p = CfarParams()
    assert effective_cells(p, (False, False)) == pytest.approx(
        float((2 * 6 + 1) * (2 * 10 + 1) - 5 * 5))
    assert effective_cells(p) < effective_cells(p, (False, False))


def test_bad_cfar_params():
    with pytest.raises(ValueError, match="pfa"):
        CfarParams(pfa=0.0)
    with pytest.raises(ValueError, match="detector"):
        DetectionParams(detector="magic")


def test_bad_grouping_and_min_snr():
    with pytest.raises(ValueError, match="grouping"):
        DetectionParams(grouping="range")
    for bad in (-1.0, 201.0, True):
        with pytest.raises(ValueError, match="min_snr_db"):
            DetectionParams(min_snr_db=bad)


def test_grouping_and_min_snr_on_a_range_extended_return():
    """A return over five range bins at one Doppler (an extended target: its range profile
    peaks in the middle), with a weak point target elsewhere: ``peak`` grouping gives one
    detection for the extended return, ``doppler`` one per range bin over the CFAR, and
    ``min_snr_db`` drops the weak target and the extended return's weak edge bins."""
    cfg = get_preset("paper-fpga")
    rng = np.random.default_rng(5)
    shape = cfg.cube_shape
    cube = (rng.standard_normal(shape) + 1j * rng.standard_normal(shape)) * np.sqrt(0.5)
    for dr, gain in zip(range(-2, 3), (100, 300, 1000, 300, 100), strict=True):
        cube[:, 30 + dr, 20] += gain
    cube[:, 45, 50] += 8.0                                    # 18 dB over the noise
    cells = {g: set(map(tuple, detect_cells(cube, cfg, DetectionParams(grouping=g))[0].tolist()))
             for g in ("peak", "doppler")}
    assert cells["peak"] == {(30, 20), (45, 50)}
    assert {(30 + dr, 20) for dr in range(-2, 3)} | {(45, 50)} == cells["doppler"]
    strong, _, _ = detect_cells(cube, cfg, DetectionParams(grouping="doppler", min_snr_db=30))
    assert set(map(tuple, strong.tolist())) == {(29, 20), (30, 20), (31, 20)}


def test_paper_fpga_end_to_end():
    scene = table1_scene("paper-fpga", seed=1)
    cfg = scene.config
    cloud = process_frame(simulate_scene(scene).samples, cfg)
    matches, used = match_targets(cloud, scene.targets, cfg, gate_azimuth_deg=3.0)
    found = [m for m in matches if m.index >= 0]
    assert len(found) >= 3  # vehicle 1 (100 m, 30 deg) is below the noise with 4 channels
    for m in found:
        v_err = m.alias_velocity_err_mps if m.aliased else m.velocity_err_mps
        assert abs(m.range_err_m) <= 0.5 and abs(v_err) <= 0.15
        assert abs(m.azimuth_err_deg) <= 3.0  # 4 elements: 28.6 deg resolution, coarse angle
    assert matches[2].aliased  # one TX cannot unfold: vehicle 3 shows at +5.56 m/s
    assert cloud.ambiguous[matches[2].index]  # ... and says so
    assert abs(matches[2].velocity_err_mps) > 50  # the error is against the true -50 m/s
    assert int((~used).sum()) <= 2


def test_paper_detector_runs():
    scene = table1_scene("full", seed=1)
    cfg = scene.config
    cube = radar_cube(simulate_scene(scene).samples, cfg)
    cloud = process_cube(cube, cfg, DetectionParams(detector="paper"))
    matches, _ = match_targets(cloud, scene.targets, cfg)
    assert sum(m.index >= 0 for m in matches) >= 3


def test_cube_shape_checked():
    with pytest.raises(ValueError, match="expected shape"):
        process_cube(np.zeros((2, 2, 2), complex), get_preset("full"))


@pytest.mark.parametrize("preset", ["full", "paper-fpga"])
def test_cube_path_is_the_one_it_replaced(preset):
    """Issue 28 (one path from cells to points): the cube path now runs the records path's
    code (``host.points``); on Table I (three noise seeds), random scenes and other settings
    its clouds are those of the numpy path the cube took before
    (``tests.oracles.points.process_cube_reference``): integer and flag fields exactly,
    floats within 1e-9."""
    from tests.oracles.points import assert_same_cloud, process_cube_reference
    from tests.scenes import random_scene
    scenes = [table1_scene(preset, seed=s) for s in (1, 2, 3)]
    scenes += [random_scene(preset, s) for s in range(4 if preset == "full" else 12)]
    settings = (DetectionParams(), DetectionParams(max_speed_mps=30.0, detector="os"),
                DetectionParams(unfold_velocity=False, sidelobe_margin_db=None))
    compared = 0
    for i, scene in enumerate(scenes):
        cube = radar_cube(simulate_scene(scene).samples, scene.config)
        params = settings[i % len(settings)]
        new = process_cube(cube, scene.config, params)
        assert_same_cloud(new, process_cube_reference(cube, scene.config, params))
        compared += len(new)
    assert compared > len(scenes)


@pytest.mark.parametrize("axes", [
    (FftAxis(128, 128), FftAxis(128, 128)),
    (FftAxis(256, 200), FftAxis(64, 48, False)),
    (FftAxis(64, 64, False, True), FftAxis(256, 255)),
])
def test_scallop_is_the_window_response(axes):
    """The compiled window responses of the points path are FftAxis.response's values, bit
    for bit (centres, bin edges, offsets that refinement pushes past them, tiny ones)."""
    rng = np.random.default_rng(5)
    off = np.concatenate([rng.uniform(-0.75, 0.75, (2000, 2)),
                          [[0.0, 0.0], [0.5, -0.5], [1e-13, -1e-13], [-0.75, 0.75]]])
    ref = axes[0].response(off[:, 0]) * axes[1].response(off[:, 1])
    assert np.array_equal(scallop(axes, off), ref)
