"""The static-clutter removal model (model/static_removal.py, rtl/buffers/static_removal.sv):
its reciprocal-multiply mean is the exactly rounded mean for every reachable sum, and the
fixed-point removal follows the float definition (model.reference.remove_static)."""

from __future__ import annotations

import numpy as np
import pytest

from model.reference import remove_static
from model.static_removal import mean, mean_exact, remove_static_planar, static_removal


@pytest.mark.parametrize("n_loops", [1, 2, 3, 13, 200, 255, 256, 4095])
def test_mean_is_rounded_half_away_for_every_sum(n_loops: int) -> None:
    lo, hi = -(1 << 15) * n_loops, ((1 << 15) - 1) * n_loops
    if hi - lo < 1 << 22:
        s = np.arange(lo, hi + 1)
    else:   # both ends, around zero and random sums
        rng = np.random.default_rng(n_loops)
        s = np.concatenate([np.arange(lo, lo + (1 << 18)), np.arange(hi - (1 << 18), hi + 1),
                            np.arange(-(1 << 18), 1 << 18), rng.integers(lo, hi + 1, 1 << 20)])
    assert np.array_equal(mean(s, n_loops), mean_exact(s, n_loops))
    assert mean(s, n_loops).min() >= -(1 << 15) and mean(s, n_loops).max() < 1 << 15


def test_follows_the_float_definition() -> None:
    rng = np.random.default_rng(0)
    x = rng.integers(-12000, 12000, (5, 32, 4, 2)) + rng.integers(-9000, 9000, (5, 1, 4, 2))
    out, sat = remove_static_planar(x)
    ref = remove_static((x[..., 0] + 1j * x[..., 1]).transpose(0, 2, 1)).transpose(0, 2, 1)
    assert sat == 0
    assert np.abs(out[..., 0] - ref.real).max() <= 0.5
    assert np.abs(out[..., 1] - ref.imag).max() <= 0.5


def test_zero_fill_saturation_and_bypass() -> None:
    x = np.zeros((1, 8, 1, 2), dtype=np.int64)
    x[0, :5, 0, 0] = [32767, 32767, 32767, 32767, -32767]   # mean 19660.2 -> 19660
    out, sat = remove_static_planar(x, n_loops=5)
    assert out[0, :, 0, 0].tolist() == [13107] * 4 + [-32768, 0, 0, 0]
    assert sat == 1                                          # -32767 - 19660 saturates
    words = np.arange(16, dtype=np.uint32).reshape(8, 2) * 0x10001
    assert np.array_equal(static_removal(words, 8, enable=False)[0], words)
    removed, _ = static_removal(words, 8)
    assert not np.array_equal(removed, words)
