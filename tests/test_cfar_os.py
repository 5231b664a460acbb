"""``host._cfar_os``'s compiled OS-CFAR against the numpy implementation it replaced
(``tests/oracles/cfar.py``): the same thresholds and noise estimates bit for bit
(``host.cfar.cfar_threshold``), and the same detections with the same noise at them
(``host.cfar.cfar_detect``, which counts instead of selecting), on circular and mirrored
(real ADC) range axes, windows that reach the map's edges, several ranks, maps full of
ties (integer powers, constant regions), and maps with negative values (the key-based
searches' fallback)."""

from __future__ import annotations

import numpy as np
import pytest

from host._cfar_os import NEAR_RANKS, _kth_keyed, _kth_near, _select
from host.cfar import CfarParams, cfar_detect, cfar_threshold
from model.reference import FftAxis
from tests.oracles.cfar import os_threshold_reference

WINDOWS = [((2, 2), (4, 8)), ((0, 1), (1, 1)), ((3, 0), (5, 2)), ((1, 1), (2, 2))]


def _map(rng: np.random.Generator, shape: tuple[int, int], ties: bool) -> np.ndarray:
    """Gamma(4) noise with targets 3-300x and a few very strong ones; ``ties``: small
    integer powers (many equal values) and a constant block, float64 (shape)."""
    p = rng.gamma(4, 1.0, shape)
    idx = rng.integers(0, p.size, max(1, p.size // 50))
    p.flat[idx] *= rng.uniform(3, 300, len(idx))
    p.flat[idx[:3]] *= 1e6
    if ties:
        p = np.floor(p)
        p[: shape[0] // 3, : shape[1] // 3] = 5.0
    return p


def _axes(shape: tuple[int, int], real: bool) -> tuple[FftAxis, FftAxis]:
    """A map's axes: a real ADC's mirrored range axis, or a complex one."""
    return (FftAxis(2 * shape[0], 2 * shape[0], True, True) if real else
            FftAxis(shape[0], shape[0]), FftAxis(shape[1], shape[1]))


@pytest.mark.parametrize("shape", [(64, 32), (33, 128), (24, 40)])
@pytest.mark.parametrize("guard,train", WINDOWS)
@pytest.mark.parametrize("real", [False, True])
@pytest.mark.parametrize("ties", [False, True])
def test_os_cfar_is_the_oracles(shape, guard, train, real, ties):
    rng = np.random.default_rng(sum(shape) + sum(guard) + 3 * sum(train) + real + 7 * ties)
    power = _map(rng, shape, ties)
    axes = _axes(shape, real)
    for rank in (0.75, 0.5, 0.01, 0.99):
        params = CfarParams(pfa=1e-3, guard=guard, train=train, kind="os", os_rank=rank)
        threshold, noise = cfar_threshold(power, 4, params, axes)
        want_t, want_n = os_threshold_reference(power, 4, params, real)
        np.testing.assert_array_equal(threshold, want_t)
        np.testing.assert_array_equal(noise, want_n)
        for p in (power, power.astype(np.float32)):      # the chain's maps are float32
            want_t, want_n = os_threshold_reference(p, 4, params, real)
            mask, at = cfar_detect(p, 4, params, axes)
            np.testing.assert_array_equal(mask, p > want_t)
            np.testing.assert_array_equal(at[mask], want_n[mask])
            assert np.isnan(at[~mask]).all()


def test_detections_at_the_threshold():
    """Cells whose power equals alpha x_(k) exactly (not detected: power > threshold) and
    one ulp above it (detected): the count decides as the comparison with the threshold."""
    rng = np.random.default_rng(11)
    params = CfarParams(pfa=1e-2, guard=(1, 1), train=(2, 3), kind="os")
    power = np.floor(rng.gamma(4, 3.0, (32, 48)))
    threshold, _ = os_threshold_reference(power, 4, params)
    cells = rng.integers(0, power.size, 60)
    power.flat[cells[:30]] = threshold.flat[cells[:30]]
    power.flat[cells[30:]] = np.nextafter(threshold.flat[cells[30:]], np.inf)
    want, _ = os_threshold_reference(power, 4, params)
    mask, _ = cfar_detect(power, 4, params)
    np.testing.assert_array_equal(mask, power > want)
    assert mask.any() and not mask.all()


def test_select_with_any_first_pivot():
    """The k-th smallest whatever the first pivot (none, inside, outside, equal to an
    element), on data with and without ties."""
    rng = np.random.default_rng(2)
    for n in (1, 2, 7, 248):
        for data in (rng.normal(size=n), np.floor(rng.uniform(0, 3, n))):
            for k in {0, n // 2, n - 1}:
                want = np.sort(data)[k]
                for pivot in (np.nan, -1e9, 1e9, data[0], 0.5):
                    assert _select(data.copy(), n, k, pivot) == want


def test_kth_near_with_any_guess():
    """The k-th smallest from any guess: none, far below or above, an element, between
    elements, up to NEAR_RANKS ranks from the answer (the branch-free search) and further
    (the quickselect)."""
    assert NEAR_RANKS < 248 // 4
    rng = np.random.default_rng(4)
    for n in (1, 5, 248):
        for data in (rng.normal(size=n), np.floor(rng.uniform(0, 4, n))):
            s = np.sort(data)
            for k in {0, n // 4, n // 2, n - 1}:
                for guess in (np.nan, -1e9, 1e9, *s[::max(1, n // 9)], s[k] + 1e-3,
                              s[k] - 1e-3):
                    assert _kth_near(data.copy(), n, k, guess, np.empty(n)) == s[k]


def test_os_cfar_with_negative_values():
    """A map with negative values (not a power map: the 16-bit keys' selection falls back to
    the search from a guess) detects and estimates as the oracle."""
    rng = np.random.default_rng(5)
    power = _map(rng, (40, 48), False) - 3.0
    axes = _axes((40, 48), False)
    params = CfarParams(pfa=1e-3, guard=(1, 2), train=(3, 4), kind="os")
    want_t, want_n = os_threshold_reference(power, 4, params)
    mask, at = cfar_detect(power, 4, params, axes)
    np.testing.assert_array_equal(mask, power > want_t)
    assert mask.any()
    np.testing.assert_array_equal(at[mask], want_n[mask])


def test_kth_keyed():
    """The k-th smallest by 16-bit keys: values over 60 decades, integer ties, values equal
    in float32 but not in float64 (one key), infinities; NaN, buffer untouched, for data
    with a NaN, a negative value or -0.0."""
    rng = np.random.default_rng(3)
    for trial in range(400):
        n = int(rng.integers(1, 300))
        x = rng.gamma(4, 1.0, n) * 10.0 ** rng.uniform(-30, 30)
        if trial % 4 == 1:
            x = np.floor(rng.uniform(0, 4, n))
        elif trial % 4 == 2:
            x = 7.0 * (1.0 + 1e-12 * rng.integers(0, 3, n))
        elif trial % 4 == 3:
            x[rng.integers(0, n, 3)] = np.inf
        k = int(rng.integers(0, n))
        got = _kth_keyed(x.copy(), n, k, np.empty(n, np.float32), np.empty(n, np.int16))
        assert got == np.sort(x)[k]
    for bad in (np.nan, -1.0, -0.0):
        x = np.array([3.0, bad, 1.0, 2.0])
        buf = x.copy()
        assert np.isnan(_kth_keyed(buf, 4, 1, np.empty(4, np.float32), np.empty(4, np.int16)))
        np.testing.assert_array_equal(buf, x)
