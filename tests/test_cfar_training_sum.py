"""``host.cfar``'s compiled CA-CFAR training sums against the numpy oracle they replaced
(``tests/oracles/cfar.py``): the same sums, bit for bit (the same additions in the same
order), on circular and mirrored (real ADC) range axes, for several windows and map
shapes, and the CA threshold built on them."""

from __future__ import annotations

import numpy as np
import pytest

from host.cfar import CfarParams, _ca_alpha, _kernel, _training_sum, cfar_threshold
from model.reference import FftAxis
from tests.oracles.cfar import training_sum_reference


@pytest.mark.parametrize("shape", [(64, 32), (33, 128), (128, 24)])
@pytest.mark.parametrize("guard,train", [((2, 2), (4, 8)), ((0, 1), (1, 1)), ((3, 0), (5, 2))])
@pytest.mark.parametrize("mirrored", [False, True])
def test_training_sum_is_the_oracles(shape, guard, train, mirrored):
    params = CfarParams(guard=guard, train=train)
    rng = np.random.default_rng(sum(shape) + sum(guard) + sum(train))
    power = rng.exponential(1.0, shape) * 10.0 ** rng.uniform(-3, 6, shape)
    got = _training_sum(power, *guard, *train, mirrored)
    assert np.array_equal(got, training_sum_reference(power, params, mirrored))


@pytest.mark.parametrize("real", [False, True])
def test_ca_threshold_on_the_sums(real):
    """The CA threshold is the factor times the training mean (float32 maps taken too)."""
    params = CfarParams()
    axes = (FftAxis(128, 128, True, real), FftAxis(64, 64))
    power = np.random.default_rng(1).exponential(1.0, (64 if real else 128, 64))
    threshold, noise = cfar_threshold(power.astype(np.float32), 8, params, axes)
    mean = training_sum_reference(power.astype(np.float32), params, real) / _kernel(params).sum()
    np.testing.assert_array_equal(noise, mean)
    np.testing.assert_array_equal(threshold, _ca_alpha(params.pfa, 8, params, axes) * mean)
