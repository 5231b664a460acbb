"""``host._grouping.sidelobe_cells`` (``host.cfar.sidelobe_masked``'s kernel) against numpy:
the largest product of the column and row with the circular envelopes (numpy's maximum: a
NaN is the maximum) over the cell's power, on float32 and float64 maps in either memory
order, circular and mirrored range axes, envelopes as long as the axes and longer (a real
ADC's range axis is half its FFT), and maps with NaN and infinite values."""

from __future__ import annotations

import numpy as np
import pytest

from host._grouping import sidelobe_cells


def _reference(power: np.ndarray, cells: np.ndarray, env_r: np.ndarray, env_d: np.ndarray,
               mirrored: bool) -> np.ndarray:
    """bool (n,): the kernel's decision, one numpy expression per cell (inf x 0 is NaN, as
    in the kernel)."""
    q_r, q_d = np.arange(power.shape[0]), np.arange(power.shape[1])
    out = []
    with np.errstate(invalid="ignore"):
        for r, d in cells:
            col = power[:, d].astype(np.float64) * env_r[(r - q_r) % len(env_r)]
            if mirrored:
                col = np.maximum(col, power[:, d].astype(np.float64)
                                 * env_r[(r + q_r) % len(env_r)])
            row = power[r].astype(np.float64) * env_d[(d - q_d) % len(env_d)]
            p = np.float64(power[r, d])
            out.append(bool(np.max(col) > p or np.max(row) > p))
    return np.array(out, bool)


@pytest.mark.parametrize("dtype,order", [(np.float32, "F"), (np.float64, "C"),
                                         (np.float32, "C")])
@pytest.mark.parametrize("mirrored", [False, True])
def test_sidelobe_cells_is_numpys(dtype, order, mirrored):
    rng = np.random.default_rng(9 + mirrored)
    for trial in range(12):
        nr, nd = int(rng.integers(4, 40)), int(rng.integers(4, 40))
        power = rng.gamma(2, 1.0, (nr, nd)) * 10.0 ** rng.uniform(0, 6, (nr, nd))
        if trial % 4 == 1:
            power[rng.integers(0, nr), rng.integers(0, nd)] = np.nan
        elif trial % 4 == 2:
            power[rng.integers(0, nr), rng.integers(0, nd)] = np.inf
        power = np.asarray(power, dtype=dtype, order=order)
        fr = nr * (2 if trial % 3 == 0 else 1)
        env_r = rng.uniform(0, 1e-2, fr) * (rng.uniform(size=fr) < 0.7)
        env_d = rng.uniform(0, 1e-2, nd)
        cells = np.argwhere(rng.uniform(size=(nr, nd)) < 0.2).astype(np.int64)
        got = sidelobe_cells(power, cells, env_r, env_d, mirrored)
        np.testing.assert_array_equal(got, _reference(power, cells, env_r, env_d, mirrored))


def test_sidelobe_cells_refuses_a_short_envelope():
    with pytest.raises(ValueError, match="envelope"):
        sidelobe_cells(np.ones((8, 8)), np.zeros((1, 2), np.int64), np.ones(4), np.ones(8),
                       False)
