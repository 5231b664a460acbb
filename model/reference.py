"""Float (float64) reference of the FPGA chain and of the plain host angle FFT.

FPGA chain (docs/design.md section 1): optional periodic-Hann window -> range FFT -> corner turn
-> optional window -> Doppler FFT. Each FFT is scaled by 1/N like the FPGA core's default
schedule (``fft_axis``: output = DFT(x)/N), so reference and RTL outputs share units (LSB).

Axis conventions:

- ADC frame: complex (n_chirps = num_tx * n_doppler in transmit order, num_rx, n_range);
  chirp c was sent by TX c mod num_tx.
- Radar cube: complex (n_virtual, n_range, n_doppler), virtual channel v = tx * num_rx + rx,
  range bin r in 0..n_range-1 (natural order), Doppler bin d in 0..n_doppler-1 in natural FFT
  order (bins >= n_doppler/2 are negative velocities; see :func:`signed_bins`).
- DMA payload order (docs/design.md 3.2): (num_tx, n_range, n_doppler, num_rx) -- for tx, for
  range bin, for Doppler bin, one word of num_rx lanes; see :func:`cube_to_dma_order`.

Angle (host side): virtual channel v at y = v lambda/2 sees phase exp(-j pi v sin(az)) (see
``model.simulate``), so the angle spectrum is the *inverse* DFT over channels: bin k of an
``n_fft``-point spectrum (after fftshift) is sin(az) = 2 (k - n_fft/2) / n_fft.
"""

from __future__ import annotations

import numpy as np

from model.array import tx_slots
from model.config import RadarConfig

HANN_MAIN_LOBE_BINS = 2
"""Half width of the periodic Hann window's main lobe, bins: a tone spreads over +-2 bins of
its FFT (host CFAR sidelobe masking starts beyond it; a profile's near-range guard covers the
leakage's main lobe, ``model.profile.default_min_range_m``)."""


def hann_periodic(n: int) -> np.ndarray:
    """Periodic Hann window w[i] = 0.5 - 0.5 cos(2 pi i / n), float64 (n,) (w[0] = 0)."""
    return 0.5 - 0.5 * np.cos(2.0 * np.pi * np.arange(n) / n)


def signed_bin(k: np.ndarray | int, n: int) -> np.ndarray:
    """Signed index of natural-order FFT bin ``k`` (0..n-1 -> 0..n/2-1, -n/2..-1), int, the
    shape of ``k``. Values below n/2 pass unchanged and larger ones lose ``n`` (so an
    already signed bin stays as it is)."""
    k = np.asarray(k)
    return np.where(k < n // 2, k, k - n)


def signed_bins(n: int) -> np.ndarray:
    """Signed bin index of each natural-order FFT bin: 0..n/2-1, -n/2..-1, int (n,)."""
    return signed_bin(np.arange(n), n)


def range_fft(adc: np.ndarray, cfg: RadarConfig, window: bool = True) -> np.ndarray:
    """Range FFT of every chirp, scaled 1/n_range.

    adc: complex (n_chirps, num_rx, n_range) -> complex128 (n_chirps, num_rx, n_range).
    """
    cfg.check_adc(adc)
    x = adc.astype(np.complex128)
    if window:
        x = x * hann_periodic(cfg.n_range)
    return np.fft.fft(x, axis=-1) / cfg.n_range


def corner_turn(range_out: np.ndarray, cfg: RadarConfig) -> np.ndarray:
    """Reorder range-FFT output into Doppler vectors.

    range_out: (n_chirps, num_rx, n_range) in transmit order ->
    (num_tx, num_rx, n_range, n_doppler): for each TX, RX and range bin the slow-time vector
    of that TX's chirps in order.
    """
    x = range_out.reshape(cfg.n_doppler, cfg.num_tx, cfg.num_rx, cfg.n_range)
    return np.transpose(x, (1, 2, 3, 0))


def doppler_fft(turned: np.ndarray, cfg: RadarConfig, window: bool = True) -> np.ndarray:
    """Doppler FFT along the last axis, scaled 1/n_doppler, natural bin order."""
    x = turned
    if window:
        x = x * hann_periodic(cfg.n_doppler)
    return np.fft.fft(x, axis=-1) / cfg.n_doppler


def remove_static(turned: np.ndarray) -> np.ndarray:
    """Static-clutter removal: each slow-time vector less its mean over the frame's chirps,
    i.e. per channel (TX slot and RX) and range bin (docs/profiles.md, "Processing a
    capture"). turned: complex (..., n_doppler) -> the same shape; returns a new array."""
    return turned - turned.mean(axis=-1, keepdims=True)


def radar_cube(adc: np.ndarray, cfg: RadarConfig, range_window: bool = True,
               doppler_window: bool = True, remove_static_clutter: bool = False
               ) -> np.ndarray:
    """The FPGA chain in float: ADC frame -> radar cube; ``remove_static_clutter``: apply
    :func:`remove_static` before the Doppler FFT (not a step of the FPGA chain).

    adc: complex (n_chirps, num_rx, n_range) -> complex128 (n_virtual, n_range, n_doppler).
    """
    turned = corner_turn(range_fft(adc, cfg, range_window), cfg)
    if remove_static_clutter:
        turned = remove_static(turned)
    cube = doppler_fft(turned, cfg, doppler_window)
    return cube.reshape(cfg.cube_shape)


def cube_to_dma_order(cube: np.ndarray, cfg: RadarConfig) -> np.ndarray:
    """Radar cube (n_virtual, n_range, n_doppler) -> DMA payload order
    (num_tx, n_range, n_doppler, num_rx)."""
    return cube.reshape(cfg.num_tx, cfg.num_rx, cfg.n_range, cfg.n_doppler).transpose(0, 2, 3, 1)


def dma_order_to_cube(words: np.ndarray, cfg: RadarConfig) -> np.ndarray:
    """Inverse of :func:`cube_to_dma_order`: (num_tx, n_range, n_doppler, num_rx) ->
    (n_virtual, n_range, n_doppler)."""
    return words.transpose(0, 3, 1, 2).reshape(cfg.cube_shape)


def range_doppler_power(cube: np.ndarray) -> np.ndarray:
    """Non-coherently integrated power sum_v |cube|^2, float64 (n_range, n_doppler)."""
    return np.sum(np.abs(cube) ** 2, axis=0)


def tdm_phase_compensation(cfg: RadarConfig, doppler_bin: np.ndarray | int) -> np.ndarray:
    """Phasors that undo the TDM slot delay, complex (..., n_virtual).

    TX t fires in slot q = ``model.array.tx_slots(cfg)[t]`` of its loop, q * Tc after the
    loop's first chirp, so a target in signed Doppler bin k picks up
    exp(j 2 pi k q / (n_doppler * num_tx)) on TX t's channels; multiply by the returned
    conjugate phasor. ``doppler_bin`` is the natural-order bin (converted to signed).
    """
    k = signed_bin(doppler_bin, cfg.n_doppler)
    slot_of_v = tx_slots(cfg)[np.arange(cfg.n_virtual) // cfg.num_rx]
    return np.exp(-2j * np.pi * np.multiply.outer(k, slot_of_v) / (cfg.n_doppler * cfg.num_tx))


def angle_spectrum(channels: np.ndarray, n_fft: int = 256, window: bool = False
                   ) -> tuple[np.ndarray, np.ndarray]:
    """Angle spectrum over the last axis (virtual channels), zero-padded to ``n_fft``.

    channels: complex (..., n_virtual), TDM-compensated.
    Returns (complex (..., n_fft) spectrum in fftshift order, float (n_fft,) azimuth in deg of
    each bin; bins with |sin(az)| >= 1 get NaN).
    """
    x = channels
    if window:
        x = x * np.hanning(x.shape[-1] + 2)[1:-1]
    spec = np.fft.fftshift(np.fft.ifft(x, n=n_fft, axis=-1) * n_fft, axes=-1)
    s = 2.0 * (np.arange(n_fft) - n_fft // 2) / n_fft
    with np.errstate(invalid="ignore"):
        az = np.degrees(np.arcsin(np.where(np.abs(s) < 1.0, s, np.nan)))
    return spec, az
