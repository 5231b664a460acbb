"""The fast bit-accurate model (planar float path) against the stage-by-stage int64
reference: identical outputs and overflow flags, bit for bit, over every FFT option, through
saturation, and through the whole chain."""

from __future__ import annotations

import numpy as np
import pytest

from model import fft_axis as ff
from model.config import RadarConfig
from model.radar_pipeline import PipelineParams, run_chain
from model.scene import table1_scene
from model.simulate import simulate_scene
from tests.oracles.chain import run_chain_reference


def _assert_same(x: np.ndarray, **kw) -> ff.FftFixedResult:
    want = ff.fft_fixed_reference(x, **kw)
    got = ff.fft_fixed(x, **kw)
    assert np.array_equal(got.y, want.y), kw
    assert np.array_equal(got.overflow, want.overflow), kw
    return want


@pytest.mark.parametrize("n", [16, 32, 64, 256, 4096])
@pytest.mark.parametrize("inverse", [False, True])
@pytest.mark.parametrize("window", [False, True])
def test_fast_fft_equals_reference(n: int, inverse: bool, window: bool) -> None:
    rng = np.random.default_rng(n + 2 * inverse + window)
    frames = max(2, 1024 // n)
    for sch in (None, 0, 0x555, 0xAAA, int(rng.integers(0, 1 << 12))):
        for amp in (32768, 2000, 3):
            x = (rng.integers(-amp, amp, (frames, n, 3))
                 + 1j * rng.integers(-amp, amp, (frames, n, 3)))
            _assert_same(x, inverse=inverse, window=window, scale_sch=sch)


def test_fast_fft_saturation_flags() -> None:
    """Full-scale input with no scaling saturates in butterflies, twiddles and the output
    rounding: the per-beat flags must agree, not just the values."""
    rng = np.random.default_rng(7)
    x = rng.integers(-32768, 32768, (6, 64, 2)) + 1j * rng.integers(-32768, 32768, (6, 64, 2))
    x[0] = -32768 - 32768j
    x[1, ::2] = 32767 + 32767j
    want = _assert_same(x, scale_sch=0)
    assert want.overflow.any() and not want.overflow.all()
    _assert_same(x, scale_sch=0x3, window=True)


@pytest.mark.parametrize(("data_w", "guard_w"), [(16, 4), (18, 5), (24, 2), (12, 0)])
def test_fast_fft_widths(data_w: int, guard_w: int) -> None:
    """float32 path (internal width + carry <= 24 bits) and float64 path (wider)."""
    rng = np.random.default_rng(data_w)
    lim = 1 << (data_w - 1)
    x = rng.integers(-lim, lim, (8, 128, 2)) + 1j * rng.integers(-lim, lim, (8, 128, 2))
    for sch in (0, 0x2A, None):
        _assert_same(x, data_w=data_w, guard_w=guard_w, scale_sch=sch, window=True)


SMALL4 = RadarConfig(name="small4", num_tx=4, num_rx=4, n_range=32, n_doppler=32,
                     sample_rate_hz=10e6, chirp_period_s=4e-6, design_max_range_m=50.0)


@pytest.mark.parametrize("params", [PipelineParams(), PipelineParams(
    window=False, range_scale_sch=0x0F0, doppler_scale_sch=0)])
def test_fast_chain_equals_reference(params: PipelineParams) -> None:
    scene = table1_scene("paper-fpga", seed=3)
    adc = simulate_scene(scene).samples
    for cfg, frame in ((scene.config, adc), (SMALL4, _small4_frame())):
        want = run_chain_reference(frame, cfg, params)
        got = run_chain(frame, cfg, params)
        assert np.array_equal(got.payload, want.payload)
        assert (got.range_overflow, got.doppler_overflow) == (want.range_overflow,
                                                              want.doppler_overflow)


def _small4_frame() -> np.ndarray:
    rng = np.random.default_rng(5)
    shape = (SMALL4.n_chirps, SMALL4.num_rx, SMALL4.n_range)
    return (rng.integers(-32768, 32768, shape) + 1j * rng.integers(-32768, 32768, shape)
            ).astype(np.complex64)


def test_fast_planar_input_checks() -> None:
    with pytest.raises(ValueError, match="planar"):
        ff.fft_fixed_planar(np.zeros((2, 16, 2)))
    with pytest.raises(ValueError, match="16-bit"):
        ff.fft_fixed_planar(np.full((1, 16, 1, 2), 40000.0))
