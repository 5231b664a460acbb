"""``host.cube.frame_cube``, the fast cube of ``radar process``, ``host.pipeline.
process_frame`` and the float frame source, against the float reference
``model.reference.radar_cube``: the same cube to float64 rounding (complex and real ADC,
windows on and off, zero padding, static-clutter removal, TX firing order), within
``SINGLE_RTOL`` in single precision, and the same point cloud on the real TI frame
(tests/data/openradar) and on simulated frames: to float64 rounding, and in single
precision (``radar process``'s) the same points with every value within
:data:`SINGLE_CLOUD_TOL`."""

from __future__ import annotations

from dataclasses import fields, replace

import numpy as np
import pytest

import host.cube
import model.reference
from host.adc_capture import open_capture
from host.cube import SINGLE_RTOL, frame_cube
from host.params import DetectionParams, params_for
from host.pipeline import process_frame
from host.pointcloud import PointCloud
from model.config import PRESETS
from model.profile import load_profile
from model.radar_pipeline import PipelineParams
from model.reference import corner_turn, doppler_fft, radar_cube, range_fft, remove_static
from model.simulate import simulate_scene
from radar.commands.process import capture_frame_cloud
from radar.frame_cloud import frame_cloud
from radar.sources import SOURCES
from tests.scenes import random_scene
from tests.test_process import BIN_FILE, CFG_FILE
from tests.test_real_chain import BASE, TARGETS, tone_frame

OPENRADAR = load_profile(CFG_FILE)


SINGLE_CLOUD_TOL = 1e-4
"""A single-precision cube's cloud: the same points (bins, flags, frame equal), each value
within this times max(|reference value|, 1) (measured: 2e-5 at most, the RCS in dBsm; angles
within 2e-6 deg)."""


def assert_same_cube(adc: np.ndarray, cfg: object, **kw: bool) -> None:
    ref = radar_cube(adc, cfg, **kw)
    fast = frame_cube(adc, cfg, **kw)
    assert fast.shape == ref.shape and fast.dtype == np.complex128
    np.testing.assert_allclose(fast, ref, rtol=0, atol=1e-12 * np.abs(ref).max())
    single = frame_cube(adc, cfg, **kw, single=True)
    assert single.shape == ref.shape and single.dtype == np.complex64
    np.testing.assert_allclose(single, ref, rtol=0, atol=SINGLE_RTOL * np.abs(ref).max())


def assert_same_cloud(a: PointCloud, b: PointCloud, tol: float = 1e-9) -> None:
    assert len(a) == len(b) > 0
    for f in fields(PointCloud):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if x.dtype.kind in "fc":
            np.testing.assert_array_less(np.abs(x - y), tol * np.maximum(np.abs(y), 1.0)
                                         + 1e-300, err_msg=f.name)
        else:
            assert np.array_equal(x, y), f.name


@pytest.mark.parametrize("remove", [False, True])
@pytest.mark.parametrize("windows", [(True, True), (False, True), (True, False)])
def test_real_frame_cube(remove, windows):
    adc = open_capture(BIN_FILE, OPENRADAR).frame(0)
    assert_same_cube(adc, OPENRADAR.config, range_window=windows[0],
                     doppler_window=windows[1], remove_static_clutter=remove)


@pytest.mark.parametrize("changes", [{}, {"adc": "real"}, {"samples_per_chirp": 200},
                                     {"samples_per_chirp": 160, "loops": 160},
                                     {"adc": "real", "samples_per_chirp": 200, "loops": 255}])
@pytest.mark.parametrize("remove", [False, True])
def test_profile_shapes_cube(changes, remove):
    cfg = replace(BASE, **changes)
    adc = tone_frame(cfg, TARGETS)
    assert_same_cube(adc, cfg, remove_static_clutter=remove)
    if cfg.adc == "real":
        with pytest.raises(ValueError, match="real ADC"):
            frame_cube(adc + 0j, cfg)
    with pytest.raises(ValueError, match="expected shape"):
        frame_cube(adc[1:], cfg)


def test_tx_firing_order(monkeypatch):
    """Chirps in another TX order: the corner turn's reordering, done in the same pass (the
    processability check left out: the chain does not take a firing order yet)."""
    cfg = replace(BASE, num_tx=3, n_range=16, design_max_range_m=0.5, tx_order=(2, 0, 1))
    for mod in (host.cube, model.reference):
        monkeypatch.setattr(mod, "check_frame", lambda adc, cfg: None)
    rng = np.random.default_rng(2)
    adc = rng.standard_normal(cfg.adc_shape) + 1j * rng.standard_normal(cfg.adc_shape)
    ref = doppler_fft(remove_static(corner_turn(range_fft(adc, cfg), cfg)), cfg)
    fast = frame_cube(adc, cfg, remove_static_clutter=True)
    np.testing.assert_allclose(fast, ref.reshape(cfg.cube_shape), rtol=0, atol=1e-13)


@pytest.mark.parametrize("remove", [False, True])
def test_real_frame_cloud(remove):
    """The capture path's cloud on the real TI frame is the float reference's."""
    cfg = OPENRADAR.config
    params = DetectionParams(max_speed_mps=cfg.max_speed_mps)
    adc = open_capture(BIN_FILE, OPENRADAR).frame(0)
    fast = capture_frame_cloud(adc, cfg, params, 0, remove)
    ref = frame_cloud(radar_cube(adc, cfg, remove_static_clutter=remove), cfg, params, 0,
                      "process")
    assert fast.cube.dtype == np.complex64
    assert_same_cloud(fast.cloud, ref.cloud, SINGLE_CLOUD_TOL)
    # the map's rounding is relative to its largest cell (that of the cube's FFTs)
    np.testing.assert_allclose(fast.nci, ref.nci, rtol=0, atol=SINGLE_RTOL * ref.nci.max())
    double = frame_cloud(frame_cube(adc, cfg, remove_static_clutter=remove), cfg, params, 0,
                         "process")
    assert_same_cloud(double.cloud, ref.cloud)


@pytest.mark.parametrize("preset,seed", [(name, seed) for name in PRESETS for seed in (0, 3)])
def test_simulated_frame_cloud(preset, seed):
    """The capture path's cloud on simulated frames of each preset is the reference's."""
    cfg = PRESETS[preset]
    adc = simulate_scene(random_scene(preset, seed)).samples
    params = params_for(cfg)
    fast = capture_frame_cloud(adc, cfg, params, 0, False)
    ref = frame_cloud(radar_cube(adc, cfg), cfg, params, 0, "detect")
    assert_same_cloud(fast.cloud, ref.cloud, SINGLE_CLOUD_TOL)
    assert_same_cloud(process_frame(adc, cfg, params), ref.cloud)
    ref_cube = radar_cube(adc, cfg, remove_static_clutter=seed > 0)
    source = SOURCES["float"](PipelineParams(static_removal=seed > 0))
    np.testing.assert_allclose(source.cube(adc, cfg), ref_cube, rtol=0,
                               atol=1e-12 * np.abs(ref_cube).max())
