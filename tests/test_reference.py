"""Float reference chain: scaling, axis order, corner turn, DMA order."""

import numpy as np
import pytest

from model.config import C0, RadarConfig, get_preset
from model.reference import (
    corner_turn,
    cube_to_dma_order,
    dma_order_to_cube,
    hann_periodic,
    radar_cube,
    range_fft,
    signed_bins,
)
from model.scene import Scatterers
from model.simulate import simulate_baseband, tone_amplitude_lsb

SMALL = RadarConfig(name="small", num_tx=2, num_rx=3, n_range=16, n_doppler=32,
                    sample_rate_hz=2e6, chirp_period_s=10e-6, design_max_range_m=20.0)


def test_tone_amplitude_survives_the_chain_exactly():
    """1/N scaling per FFT: a tone on bin centres comes out with its ADC amplitude."""
    cfg = get_preset("full")
    rng_m = 40 * cfg.sample_rate_hz / cfg.n_range * C0 / (2 * cfg.slope_hz_per_s)
    sc = Scatterers(np.array([rng_m]), np.array([0.0]), np.array([0.0]), np.array([30.0]),
                    np.array([-1]))
    x, _ = simulate_baseband(cfg, sc)
    amp = tone_amplitude_lsb(cfg, sc, True)[0]
    plain = radar_cube(x, cfg, range_window=False, doppler_window=False)
    assert np.abs(plain[:, 40, 0]) == pytest.approx(np.full(cfg.n_virtual, amp), rel=1e-4)
    windowed = radar_cube(x, cfg)
    # periodic Hann coherent gain is exactly 1/2 per dimension
    assert np.abs(windowed[:, 40, 0]) == pytest.approx(np.full(cfg.n_virtual, amp / 4), rel=1e-4)


def test_corner_turn_order():
    rng = np.random.default_rng(0)
    x = rng.standard_normal((SMALL.n_chirps, SMALL.num_rx, SMALL.n_range))
    t = corner_turn(x, SMALL)
    assert t.shape == (SMALL.num_tx, SMALL.num_rx, SMALL.n_range, SMALL.n_doppler)
    for tx in range(SMALL.num_tx):
        for d in range(SMALL.n_doppler):
            chirp = d * SMALL.num_tx + tx  # chirp c is sent by TX c mod num_tx
            assert np.array_equal(t[tx, :, :, d], x[chirp])


def test_dma_order_round_trip_and_layout():
    rng = np.random.default_rng(1)
    cube = rng.standard_normal((SMALL.n_virtual, SMALL.n_range, SMALL.n_doppler))
    words = cube_to_dma_order(cube, SMALL)
    assert words.shape == (SMALL.num_tx, SMALL.n_range, SMALL.n_doppler, SMALL.num_rx)
    assert words[1, 5, 7, 2] == cube[1 * SMALL.num_rx + 2, 5, 7]
    assert np.array_equal(dma_order_to_cube(words, SMALL), cube)


def test_window_and_bins():
    w = hann_periodic(8)
    assert w[0] == 0 and w[4] == 1 and w.sum() == pytest.approx(4.0)
    assert list(signed_bins(8)) == [0, 1, 2, 3, -4, -3, -2, -1]


def test_shape_check():
    with pytest.raises(ValueError, match="expected shape"):
        range_fft(np.zeros((3, 3, 3)), SMALL)
