"""Synthetic radar cubes for the Monte-Carlo curves: exactly the float chain's windowed
range-Doppler cells of targets in white noise, without simulating whole frames.

A periodic Hann window is, in the DFT domain, the 3-tap circular kernel (-1/4, 1/2, -1/4)
(w[n] = 1/2 - cos(2 pi n / N) / 2). So the Hann-windowed 2-D DFT of white noise is white
complex Gaussian cells filtered by that kernel along range and Doppler: the same
correlation between neighbouring cells (power correlation 4/9 at one bin, 1/36 at two,
``model.cfar_stats.HANN_POWER_CORRELATION``) as ``model.reference.radar_cube`` gives for a
frame of white ADC noise. A target at a bin centre is an impulse in the unwindowed DFT;
filtered, it is the window's exact response (the cell and its +-1 neighbours, inside the
CFAR guard). A target off the bin centre (:func:`tone_patch`) gets its windowed DFT values
computed directly. What this leaves out: ADC quantisation and clipping, range migration and
range-Doppler coupling over the frame, and (for detection) scalloping (targets at bin
centres) -- docs/curves.md.
"""

from __future__ import annotations

import numpy as np

from model.reference import hann_periodic

HANN_NOISE_GAIN = 0.375
"""Noise power of a Hann-filtered white cell relative to the white cell (1/4 + 2/16)."""


def complex_normal(rng: np.random.Generator, shape: tuple[int, ...],
                   dtype: type = np.float64) -> np.ndarray:
    """Circular complex Gaussian, unit power, of ``shape`` (complex128, or complex64 for
    ``dtype`` float32)."""
    x = np.empty(shape, np.complex128 if dtype == np.float64 else np.complex64)
    x.real = rng.standard_normal(shape, dtype=dtype)
    x.imag = rng.standard_normal(shape, dtype=dtype)
    return x * dtype(np.sqrt(0.5))


def hann_filter(x: np.ndarray, axis: int) -> np.ndarray:
    """The periodic Hann window applied in the DFT domain along ``axis`` (circular)."""
    return 0.5 * x - 0.25 * (np.roll(x, 1, axis=axis) + np.roll(x, -1, axis=axis))


def target_grid(shape: tuple[int, int], reach: tuple[int, int]) -> np.ndarray:
    """Cells (int (n, 2) of (range, Doppler)) for targets on a map of ``shape``, so that no
    target nor its window response (+-1 cell) is inside another's CFAR window (``reach`` =
    guard + train per side) and no window is cut by the range ends; Doppler is circular."""
    (nr, nd), (pr, pd) = shape, reach
    rows = np.arange(pr, nr - pr, pr + 2)
    cols = np.arange(0, nd - pd - 1, pd + 2)
    return np.stack(np.meshgrid(rows, cols, indexing="ij"), axis=-1).reshape(-1, 2)


def detection_map(rng: np.random.Generator, n_channels: int, shape: tuple[int, int],
                  cells: np.ndarray, cell_snr: float, swerling: int) -> np.ndarray:
    """A Hann-windowed range-Doppler cube, complex64 (n_channels, n_range, n_doppler), noise
    power 1 per channel and cell, with a bin-centred target in each of ``cells`` (int (n, 2))
    of per-channel cell SNR ``cell_snr`` (linear; Swerling 1: the mean, one exponential
    power per target common to all its channels; 0 or no cells: noise only)."""
    white = complex_normal(rng, (n_channels, *shape), np.float32) / np.float32(HANN_NOISE_GAIN)
    if len(cells) and cell_snr > 0.0:
        power = cell_snr * (rng.exponential(size=len(cells)) if swerling else
                            np.ones(len(cells)))
        phase = np.exp(2j * np.pi * rng.random(len(cells)))
        # the filtered impulse is 1/4 of it at the centre (1/2 per axis)
        white[:, cells[:, 0], cells[:, 1]] += (4.0 * np.sqrt(power) * phase).astype(
            np.complex64)
    return hann_filter(hann_filter(white, 1), 2)


def tone_response(offset: np.ndarray, n: int, half: int) -> np.ndarray:
    """Hann-windowed DFT / n of a unit complex tone at ``offset`` bins (float (t,)) from bin
    0, at bins -half..half: complex (t, 2 half + 1)."""
    t = np.arange(n)
    w = hann_periodic(n)
    k = np.arange(-half, half + 1)
    tone = w * np.exp(2j * np.pi * np.outer(offset, t) / n)               # (trials, n)
    return tone @ np.exp(-2j * np.pi * np.outer(t, k) / n) / n


def tone_patch(rng: np.random.Generator, n_range: int, n_doppler: int, n_channels: int,
               snr: float, offsets: np.ndarray, sin_az: np.ndarray, half: int = 2
               ) -> np.ndarray:
    """The float chain's cube around one target per trial: complex (trials, n_channels,
    2 half + 1, 2 half + 1), cells at range/Doppler bins -half..half of the target's bin.

    ``snr``: per-channel, per-ADC-sample SNR (linear; noise power 1 per ADC sample);
    ``offsets``: float (trials, 2) the target's (range, Doppler) position from the centre
    cell, bins; ``sin_az``: float (trials,). Virtual channel v sees exp(-j pi v sin(az))
    (``model.reference``). Windows: periodic Hann on both FFTs, each FFT scaled 1/N."""
    trials = len(offsets)
    r = tone_response(offsets[:, 0], n_range, half)
    d = tone_response(offsets[:, 1], n_doppler, half)
    steer = np.exp(-1j * np.pi * np.outer(sin_az, np.arange(n_channels)))
    amp = np.sqrt(snr) * np.exp(2j * np.pi * rng.random(trials))
    sig = (amp[:, None, None, None] * steer[:, :, None, None] * r[:, None, :, None]
           * d[:, None, None, :])
    p = 2 * half + 1
    white = complex_normal(rng, (trials, n_channels, p + 2, p + 2)) / np.sqrt(
        n_range * n_doppler)
    noise = hann_filter(hann_filter(white, 2), 3)[:, :, 1:-1, 1:-1]
    return sig + noise


def patch_noise_per_channel(n_range: int, n_doppler: int) -> float:
    """Noise power per channel of a :func:`tone_patch` cell (ADC noise power 1)."""
    return HANN_NOISE_GAIN ** 2 / (n_range * n_doppler)
