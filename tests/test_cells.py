"""The peak interpolation of ``host.cells`` (both the cube and the records path): unbiased
on noise-free tones for every window and padding, blind to added noise power, and as
efficient as the three cells it reads allow (``model.detection_theory``)."""

from __future__ import annotations

import numpy as np
import pytest

from host.cells import axis_offsets, neighbour_offsets, offset_table, peak_offsets, two_bin
from model import detection_theory as dt
from model.reference import FftAxis

AXES = [FftAxis(256, 256), FftAxis(256, 256, hann=False), FftAxis(256, 200),
        FftAxis(256, 160, hann=False), FftAxis(16, 16), FftAxis(16, 16, hann=False),
        FftAxis(64, 24), FftAxis(512, 400, real=True)]


def bin_powers(axis: FftAxis, offsets: np.ndarray, amplitude: np.ndarray | None = None
               ) -> np.ndarray:
    """|FFT|^2 at bins -1, 0, +1 of tones ``offsets`` bins (float (m,)) from bin 0: the
    axis' window over its samples, zero-padded to its FFT; summed over channels of complex
    ``amplitude`` (default one channel of 1). float (m, 3)."""
    amplitude = np.ones(1) if amplitude is None else amplitude
    t = np.arange(axis.n_samples)
    x = axis.window() * np.exp(2j * np.pi * np.outer(offsets, t) / axis.n_fft)
    spec = np.fft.fft(x, axis.n_fft, axis=-1)[:, [-1, 0, 1]]
    return np.abs(spec) ** 2 * np.sum(np.abs(amplitude) ** 2)


@pytest.mark.parametrize("axis", AXES, ids=str)
def test_unbiased_on_noise_free_tones(axis: FftAxis) -> None:
    """Offsets -0.5..0.5 bin come back exactly (bias < 1e-5 bin), Hann or rectangular,
    padded or not; the range ends give 0 in range."""
    off = np.linspace(-0.5, 0.5, 81)
    p = bin_powers(axis, off)
    assert np.abs(axis_offsets(p[:, 0], p[:, 1], p[:, 2], axis) - off).max() < 1e-5
    got = neighbour_offsets(p[:, 1], np.stack([p[:, 0], p[:, 2], p[:, 0], p[:, 2]], axis=1),
                            np.arange(81) % 2 == 0, (axis, axis))
    np.testing.assert_array_equal(got[:, 1], axis_offsets(p[:, 0], p[:, 1], p[:, 2], axis))
    assert np.all(got[1::2, 0] == 0.0)
    assert two_bin(axis) == (not axis.hann and axis.n_fft == axis.n_samples)


def test_noise_power_and_channels_cancel() -> None:
    """The three-power parabola does not see a constant added to the powers (the noise
    power's mean) nor how the tone's power splits over channels."""
    axis = FftAxis(256, 256)
    off = np.linspace(-0.45, 0.45, 19)
    amp = np.array([1.0, 0.3j, -2.0 + 1j])
    p = bin_powers(axis, off, amp) + 7.5
    np.testing.assert_allclose(axis_offsets(p[:, 0], p[:, 1], p[:, 2], axis), off, atol=1e-6)


def test_undefined_inputs_give_zero() -> None:
    """All-zero powers, or samples that do not peak at the cell, give offset 0; a cell
    weaker than a neighbour gives at most 0.5."""
    for axis in (FftAxis(64, 64), FftAxis(64, 64, hann=False)):
        assert axis_offsets(0.0, 0.0, 0.0, axis) == 0.0
        assert abs(axis_offsets(1.0, 0.5, 2.0, axis)) <= 0.5
    assert axis_offsets(1.0, 0.5, 1.0, FftAxis(64, 64)) == 0.0


def test_peak_offsets_on_a_map() -> None:
    """:func:`peak_offsets` reads the four neighbours off the map (Doppler circular)."""
    axes = (FftAxis(32, 32), FftAxis(16, 16))
    pr = bin_powers(axes[0], np.array([0.3]))[0]
    pd = bin_powers(axes[1], np.array([-0.2]))[0]
    pmap = np.full((32, 16), 1e-9)
    for i in range(3):
        for j in range(3):
            pmap[10 + i - 1, (j - 1) % 16] = pr[i] * pd[j]
    got = peak_offsets(pmap, np.array([[10, 0], [0, 5]]), axes)
    assert got[0] == pytest.approx([0.3, -0.2], abs=1e-5)
    assert got[1, 0] == 0.0


def test_table_is_monotonic_and_odd() -> None:
    """The inversion table rises from (0, 0) to (0.5, 0.5)."""
    for axis in AXES:
        t, off = offset_table(axis)
        assert t[0] == 0.0 and t[-1] == 0.5 and off[-1] == 0.5 and np.all(np.diff(t) > 0)


@pytest.mark.parametrize("offset, excess_db", [(0.05, 0.4), (0.25, 0.5)])
def test_efficient_against_the_three_cell_bound(offset: float, excess_db: float) -> None:
    """Hann, 64 channels of random phase, white noise through the window, cell SNR 23 dB
    per channel: the MSE of the offsets is within ``excess_db`` of the bound of the three
    cells (``model.detection_theory.three_cell_information``; 0.2 and 0.3 dB expected from
    the first-order variance) and not below it. At lower SNR per channel the noise x noise
    part of the powers adds to it (docs/curves.md)."""
    axis, channels, trials, snr = FftAxis(64, 64), 64, 4000, 5.0
    rng = np.random.default_rng(5)
    t = np.arange(64)
    amp = np.sqrt(snr) * np.exp(2j * np.pi * rng.random((trials, channels, 1)))
    x = amp * np.exp(2j * np.pi * offset * t / 64) + (
        rng.standard_normal((trials, channels, 64))
        + 1j * rng.standard_normal((trials, channels, 64))) / np.sqrt(2)
    spec = np.fft.fft(x * axis.window(), axis=-1)[..., [-1, 0, 1]]
    p = np.sum(np.abs(spec) ** 2, axis=1)
    err = axis_offsets(p[:, 0], p[:, 1], p[:, 2], axis) - offset
    bound = 1 / (snr * channels * dt.three_cell_information(axis.window(), 64,
                                                             np.array([offset]))[0])
    excess = 10 * np.log10(np.mean(err ** 2) / bound)
    assert -0.2 < excess < excess_db
