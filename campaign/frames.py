"""Whole ADC frames of many single-tone targets for the estimation curves that need the
whole data: the refinement (``host.refine``) on the float chain, and the bit-accurate chain
(``model.radar_pipeline``) with and without it (docs/curves.md, "Whole frames").

A frame holds :data:`TARGETS` targets, target p in range cell 4 p + 2 and Doppler cell
4 (27 p mod 64) + 2 (natural order), each at a random sub-bin offset in +-0.5 bin on both
axes and a random azimuth: every pair is at least 4 bins apart on both axes (no two share a
row or a column of the map; 27 is prime to 64), so the Hann responses (sidelobes -31 dB at
4 bins, falling 18 dB per octave) barely touch. Target p's samples are
a_p exp(j 2 pi (f_r n / N_r + f_d l / N_d)) exp(-j pi v sin(az_p)) on sample n of loop l
and virtual channel v = tx num_rx + rx, a_p of random phase: a tone per loop, the same for
every TX slot of the loop (no Doppler phase between the slots: the channels' phases are the
array's alone, as in the cells of ``campaign.maps``). Noise: circular complex Gaussian,
power ``noise_power`` per sample. The bit-accurate chain gets the frame at the ADC's noise
level (``RadarConfig.noise_power_lsb2``), I and Q rounded to integers.
"""

from __future__ import annotations

import numpy as np

from campaign.maps import complex_normal
from model.array import tx_slots
from model.config import RadarConfig

TARGETS = 64
"""Targets per frame."""
PITCH = 4
"""Bins between neighbouring targets' cells on both axes (at least)."""
STRIDE = 27
"""Doppler stride of the layout (prime to the 64 columns)."""
SIN_AZ_MAX = 0.3
"""The targets' sin(az) is uniform in +-this."""


def target_cells(cfg: RadarConfig) -> np.ndarray:
    """The targets' cells int (TARGETS, 2) of (range, Doppler natural order)."""
    p = np.arange(TARGETS)
    cols = cfg.n_doppler // PITCH
    return np.stack([PITCH * p + PITCH // 2, PITCH * ((STRIDE * p) % cols) + PITCH // 2],
                    axis=1)


def tone_frame(rng: np.random.Generator, cfg: RadarConfig, snr: float, noise_power: float,
               offsets: np.ndarray, sin_az: np.ndarray) -> np.ndarray:
    """A complex ADC frame (n_chirps, num_rx, n_samples) of the targets of
    :func:`target_cells` at ``offsets`` float (TARGETS, 2) bins (range, Doppler) from their
    cells' centres and ``sin_az`` float (TARGETS,), per-sample SNR ``snr`` (linear) over
    white noise of power ``noise_power`` per sample."""
    cells = target_cells(cfg)
    f = cells + offsets
    n = np.arange(cfg.n_samples)
    loops = np.arange(cfg.n_loops)
    amp = np.sqrt(snr * noise_power) * np.exp(2j * np.pi * rng.random(TARGETS))
    rng_tone = np.exp(2j * np.pi * np.outer(f[:, 0], n) / cfg.n_range)          # (P, n)
    dop_tone = np.exp(2j * np.pi * np.outer(f[:, 1], loops) / cfg.n_doppler)    # (P, L)
    steer = np.exp(-1j * np.pi * np.outer(sin_az, np.arange(cfg.n_virtual)))    # (P, V)
    outer = (dop_tone[:, :, None] * rng_tone[:, None, :]).reshape(TARGETS, -1)
    sig = ((steer * amp[:, None]).T @ outer).reshape(cfg.num_tx, cfg.num_rx, cfg.n_loops,
                                                     cfg.n_samples)
    adc = np.empty((cfg.n_loops, cfg.num_tx, cfg.num_rx, cfg.n_samples), np.complex128)
    adc[:, tx_slots(cfg)] = sig.transpose(2, 0, 1, 3)        # TX t fires in slot tx_slots[t]
    adc += complex_normal(rng, adc.shape) * np.sqrt(noise_power)
    return adc.reshape(cfg.n_chirps, cfg.num_rx, cfg.n_samples)
