"""Float (float64) reference of the FPGA chain and of the plain host angle FFT.

FPGA chain (docs/design.md section 1): optional periodic-Hann window -> range FFT -> corner turn
-> optional window -> Doppler FFT. Each FFT is scaled by 1/N like the FPGA core's default
schedule (``fft_axis``: output = DFT(x)/N), so reference and RTL outputs share units (LSB).

Axis conventions:

- ADC frame: complex, or real for a real ADC, (n_chirps = num_tx * n_loops in transmit
  order, num_rx, n_samples); chirp c is slot c mod num_tx of loop c // num_tx and was sent
  by TX ``cfg.tx_sequence[c % num_tx]`` (``model.array``).
- Radar cube: complex (n_virtual, n_range_bins, n_doppler), virtual channel v = tx * num_rx
  + rx by TX index (whatever the firing order), range bin r in 0..n_range_bins-1 (natural
  order; a real ADC keeps 0..n_range/2-1, the other half mirrors it), Doppler bin d in
  0..n_doppler-1 in natural FFT order (bins >= n_doppler/2 are negative velocities; see
  :func:`signed_bins`).
- Zero padding (a profile's samples_per_chirp < n_range, loops < n_doppler): the samples
  are windowed by a periodic Hann of their own count, then zero-padded to the FFT length,
  so the window's main lobe spans ``2 n_fft / n_samples`` bins (:class:`FftAxis`, which
  the host's CFAR, sidelobe masking and amplitude corrections read).
- DMA payload order (docs/design.md 3.2): (num_tx, n_range, n_doppler, num_rx) -- for tx, for
  range bin, for Doppler bin, one word of num_rx lanes; see :func:`cube_to_dma_order`.

Angle (host side): virtual channel v at y = v lambda/2 sees phase exp(-j pi v sin(az)) (see
``model.simulate``), so the angle spectrum is the *inverse* DFT over channels: bin k of an
``n_fft``-point spectrum (after fftshift) is sin(az) = 2 (k - n_fft/2) / n_fft.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from model.array import tx_slots
from model.cfar_stats import HANN_POWER_CORRELATION, RECT_POWER_CORRELATION
from model.config import RadarConfig

HANN_MAIN_LOBE_BINS = 2
"""Half width of the periodic Hann window's main lobe, bins of an FFT as long as the window:
a tone spreads over +-2 bins (+-2 n_fft / n_samples when zero-padded, :class:`FftAxis`;
host CFAR guard and sidelobe masking; a profile's near-range guard covers the leakage's
main lobe, ``model.profile.default_min_range_m``)."""
POWER_CORRELATION_FLOOR = 1e-4
"""Power correlations between noise bins below this are taken as 0 (:class:`FftAxis`)."""


def hann_periodic(n: int) -> np.ndarray:
    """Periodic Hann window w[i] = 0.5 - 0.5 cos(2 pi i / n), float64 (n,) (w[0] = 0)."""
    return 0.5 - 0.5 * np.cos(2.0 * np.pi * np.arange(n) / n)


def _dirichlet_ratio(y: np.ndarray, n: int, sin_pi_y: np.ndarray) -> np.ndarray:
    """The real factor of the Dirichlet kernel D(y) = sum_{t<n} exp(-j 2 pi y t / n) =
    exp(-j pi y (n - 1) / n) sin(pi y) / sin(pi y / n), float like y (|y| < n; n at y = 0);
    sin_pi_y: sin(pi y), given (callers share it)."""
    den = np.sin(np.pi * y / n)
    small = np.abs(den) < 1e-12
    return np.where(small, n, sin_pi_y / np.where(small, 1.0, den))


@dataclass(frozen=True)
class FftAxis:
    """One FFT axis of the chain: ``n_samples`` inputs, periodic-Hann windowed over their own
    count (``hann``) or not, zero-padded to ``n_fft``; ``real``: the inputs were real, so
    the map keeps bins 0..n_fft/2-1 (the rest mirror them). What a detector needs of it:
    main lobe, coherent gain, noise correlation between bins (:func:`fft_axes`)."""

    n_fft: int
    n_samples: int
    hann: bool = True
    real: bool = False

    @property
    def n_bins(self) -> int:
        """Bins of the map along this axis: n_fft, or n_fft / 2 for real inputs."""
        return self.n_fft // 2 if self.real else self.n_fft

    @property
    def main_lobe_bins(self) -> int:
        """Half width of the Hann main lobe in whole bins, ceil(2 n_fft / n_samples): 2
        without padding (also used unwindowed, as the presets' masking always has)."""
        return math.ceil(HANN_MAIN_LOBE_BINS * self.n_fft / self.n_samples - 1e-9)

    def window(self) -> np.ndarray:
        """The window over the samples, float64 (n_samples,)."""
        return hann_periodic(self.n_samples) if self.hann else np.ones(self.n_samples)

    def response(self, offset: np.ndarray | float) -> np.ndarray:
        """|W(offset)| / |W(0)|: amplitude of a tone ``offset`` bins (float (m,) or scalar)
        off a bin centre of this axis' FFT, float like ``offset``. Zero-padded: the
        n_samples-point response at offset * n_samples / n_fft. W is the DFT of the periodic
        Hann window (0.5 D(x) - 0.25 D(x - 1) - 0.25 D(x + 1) with the Dirichlet kernel D)
        or of the rectangular one (D). The three kernels share their phase up to
        exp(+-j phi), phi = pi (n - 1) / n, and sin(pi (x +- 1)) = -sin(pi x): |W| is
        |0.5 R(x) - 0.25 e^{j phi} R(x - 1) - 0.25 e^{-j phi} R(x + 1)| with the real factors
        R of :func:`_dirichlet_ratio` (four sines, no complex exponential). Compiled, for the
        points of a frame's cells: ``host.cells.scallop`` (the same operations)."""
        x = np.asarray(offset, dtype=float) * (self.n_samples / self.n_fft)
        n = self.n_samples
        s = np.sin(np.pi * x)
        r0 = _dirichlet_ratio(x, n, s)
        if not self.hann:
            return np.abs(r0) / n
        rm = _dirichlet_ratio(x - 1, n, -s)
        rp = _dirichlet_ratio(x + 1, n, -s)
        phi = np.pi * (n - 1) / n
        re = 0.5 * r0 - 0.25 * np.cos(phi) * (rm + rp)
        im = 0.25 * np.sin(phi) * (rp - rm)
        return np.hypot(re, im) / (n / 2)

    @property
    def coherent_gain(self) -> float:
        """Bin amplitude over the input tone's amplitude at a bin centre: sum(window) / n_fft
        (0.5 with Hann, 1 without, times n_samples / n_fft when padded), halved for real
        inputs (a real tone's amplitude splits between its bin and the mirror)."""
        gain = (0.5 if self.hann else 1.0) * (self.n_samples / self.n_fft)
        return gain * 0.5 if self.real else gain

    def power_correlation(self) -> tuple[float, ...]:
        """Power correlation of white noise between bins i = 0, 1, ... apart,
        |sum w^2 e^{-j 2 pi i t / n_fft}|^2 / (sum w^2)^2, while above
        :data:`POWER_CORRELATION_FLOOR` (``model.cfar_stats``' constants unpadded)."""
        if self.n_samples == self.n_fft:
            return HANN_POWER_CORRELATION if self.hann else RECT_POWER_CORRELATION
        w2 = self.window() ** 2
        rho = np.abs(np.fft.fft(w2, self.n_fft)[: self.n_fft // 2]) ** 2 / w2.sum() ** 2
        n = int(np.flatnonzero(rho >= POWER_CORRELATION_FLOOR).max()) + 1
        return tuple(float(r) for r in rho[:n])


def fft_axes(cfg: RadarConfig, range_window: bool = True, doppler_window: bool = True
             ) -> tuple[FftAxis, FftAxis]:
    """The (range, Doppler) axes of ``cfg``'s cube with these windows."""
    return (FftAxis(cfg.n_range, cfg.n_samples, range_window, cfg.adc == "real"),
            FftAxis(cfg.n_doppler, cfg.n_loops, doppler_window))


def signed_bin(k: np.ndarray | int, n: int) -> np.ndarray:
    """Signed index of natural-order FFT bin ``k`` (0..n-1 -> 0..n/2-1, -n/2..-1), int, the
    shape of ``k``. Values below n/2 pass unchanged and larger ones lose ``n`` (so an
    already signed bin stays as it is)."""
    k = np.asarray(k)
    return np.where(k < n // 2, k, k - n)


def signed_bins(n: int) -> np.ndarray:
    """Signed bin index of each natural-order FFT bin: 0..n/2-1, -n/2..-1, int (n,)."""
    return signed_bin(np.arange(n), n)


def check_frame(adc: np.ndarray, cfg: RadarConfig) -> None:
    """ValueError unless ``adc`` is one ADC frame of ``cfg`` (``RadarConfig.check_adc``),
    real for a real ADC."""
    cfg.check_adc(adc)
    if cfg.adc == "real" and np.iscomplexobj(adc):
        raise ValueError(f"adc: complex samples for radar {cfg.name!r}, which has a real ADC")


def range_fft(adc: np.ndarray, cfg: RadarConfig, window: bool = True) -> np.ndarray:
    """Range FFT of every chirp, scaled 1/n_range: each chirp's n_samples (windowed by a
    periodic Hann of n_samples) zero-padded to n_range; a real ADC keeps bins
    0..n_range/2-1.

    adc: complex, or real for a real ADC, (n_chirps, num_rx, n_samples) -> complex128
    (n_chirps, num_rx, n_range_bins).
    """
    check_frame(adc, cfg)
    x = adc.astype(np.complex128)
    if window:
        x = x * hann_periodic(cfg.n_samples)
    out = np.fft.fft(x, n=cfg.n_range, axis=-1) / cfg.n_range
    return out if cfg.adc == "complex" else out[..., :cfg.n_range_bins]


def corner_turn(range_out: np.ndarray, cfg: RadarConfig) -> np.ndarray:
    """Reorder range-FFT output into Doppler vectors, by TX index.

    range_out: (n_chirps, num_rx, n_range_bins) in transmit order ->
    (num_tx, num_rx, n_range_bins, n_loops): for each TX (index, not firing slot), RX and
    range bin the slow-time vector of that TX's chirps in order.
    """
    x = range_out.reshape(cfg.n_loops, cfg.num_tx, cfg.num_rx, cfg.n_range_bins)
    if cfg.tx_sequence != tuple(range(cfg.num_tx)):
        x = x[:, tx_slots(cfg)]                 # slot of each TX index
    return np.transpose(x, (1, 2, 3, 0))


def doppler_fft(turned: np.ndarray, cfg: RadarConfig, window: bool = True) -> np.ndarray:
    """Doppler FFT along the last axis (n_loops slow-time samples, windowed by a periodic
    Hann of n_loops, zero-padded to n_doppler), scaled 1/n_doppler, natural bin order:
    (..., n_loops) -> complex128 (..., n_doppler)."""
    x = turned
    if window:
        x = x * hann_periodic(cfg.n_loops)
    return np.fft.fft(x, n=cfg.n_doppler, axis=-1) / cfg.n_doppler


def remove_static(turned: np.ndarray, window: bool = True) -> np.ndarray:
    """Static-clutter removal: each slow-time vector less its mean over the frame's chirps,
    per channel (TX slot and RX) and range bin (docs/profiles.md, "Processing a capture"),
    the mean weighted by the Doppler window when it is on: ``c = sum(w x) / sum(w)`` with
    ``w`` the periodic Hann of n_loops (:func:`doppler_fft`'s), so a constant is removed
    exactly and the windowed zero-Doppler bin of any vector is left exactly zero (no residue
    of a moving target's rectangular-window sidelobes); the plain mean with the window off.
    turned: complex (..., n_loops) -> the same shape; returns a new array."""
    if not window:
        return turned - turned.mean(axis=-1, keepdims=True)
    w = hann_periodic(turned.shape[-1])
    return turned - (turned @ w)[..., None] / w.sum()


def radar_cube(adc: np.ndarray, cfg: RadarConfig, range_window: bool = True,
               doppler_window: bool = True, remove_static_clutter: bool = False
               ) -> np.ndarray:
    """The FPGA chain in float: ADC frame -> radar cube; ``remove_static_clutter``: apply
    :func:`remove_static` before the Doppler FFT (the FPGA chain's optional
    ``static_removal`` block in fixed point: ``model.static_removal``).

    adc: complex, or real for a real ADC, (n_chirps, num_rx, n_samples) -> complex128
    (n_virtual, n_range_bins, n_doppler).
    """
    turned = corner_turn(range_fft(adc, cfg, range_window), cfg)
    if remove_static_clutter:
        turned = remove_static(turned, doppler_window)
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
    """Non-coherently integrated power sum_v |cube|^2, float64 (n_range, n_doppler): summed
    channel by channel in order (what ``np.sum(np.abs(cube) ** 2, axis=0)`` computes, without
    its two cube-sized temporaries; one map-sized buffer, reused)."""
    cube = np.asarray(cube)
    power = np.abs(cube[0])
    power *= power                      # ** 2 is a square: the same product
    square = np.empty_like(power)
    for channel in cube[1:]:
        np.abs(channel, out=square)
        square *= square
        power += square
    return power


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
