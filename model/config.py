"""Radar configuration: the two presets of docs/design.md section 2 and every derived quantity.

A :class:`RadarConfig` is a frozen dataclass; all validation happens in ``__post_init__`` and
raises :class:`ValueError` naming the offending field. Derived values are properties, so a
configuration can never hold inconsistent numbers.

Where the paper's numbers disagree (docs/design.md section 2):

- The paper quotes 300 m maximum range, 3.5 m range resolution, 19.33 MSPS and 256 range
  samples; 256 samples at 19.33 MSPS with an 86.77 MHz sampled sweep give a 1.7275 m bin but a
  13.2 us ramp that does not fit the 8.76 us chirp slot that 4 TX x 256 chirps x 100 km/h need.
  The ``full`` preset keeps the 1.7275 m bin and 256 samples but samples at 32.5 MSPS
  (7.877 us sampled ramp): **a deliberate deviation from the paper's 19.33 MSPS**, needed to
  reach >= 300 m at 1.7275 m bins inside an 8.76 us chirp.
- ``paper-fpga`` is the paper's hardware prototype: 1 TX x 4 RX, 64-point range FFT at
  19.33 MSPS (the paper's "~17.4 MHz maximum beat frequency" is the beat of 100 m here).
- The paper's "3.5 m" and "1.6 km/h" resolutions are the Hann main lobe (2 bins) of the
  1.7275 m and 0.78 km/h (0.217 m/s) bins.

The presets sample complex (I/Q), so a beat frequency in [0, fs) maps to range bins 0..N-1
and the maximum range is ``n_range * range_bin_m``. A real ADC (a profile's ``adc = "real"``)
samples beats in [0, fs/2): the range FFT of real samples is Hermitian (bin N-k mirrors bin
k), so the cube keeps bins 0..N/2-1 (:attr:`RadarConfig.n_range_bins`, the cube's range
length) and the maximum range is half.

Range bins and the range edge: the range FFT of a complex IF signal is circular. Bin N-k is
the beat frequency -k fs/N just as much as (N-k) fs/N: a target at range <= 0 (one that has
driven past the radar), and the window sidelobes of a strong near target, land in the top
bins. The detectors therefore treat the range axis as circular (CFAR windows wrap, they are
not cut; a real ADC's half axis is mirrored at both ends instead) and never report the
``NEGATIVE_BEAT_GUARD_BINS`` top bins (with a real ADC: the bins next to fs/2, the
anti-alias filter's edge, where a tone and its mirror image meet) nor the
``DC_GUARD_BINS`` lowest ones (DC offset / TX leakage; a profile's ``min_range_m`` guards
more); :meth:`RadarConfig.detection_bins` is
that one rule, for the host CFAR and the FPGA detector alike, and
:attr:`RadarConfig.max_detection_range_m` the largest range a detection can report.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np

from model.profile_fields import PROFILE_FIELDS, check_profile_fields, unsupported_features

C0 = 299_792_458.0
"""Speed of light in vacuum, m/s."""
BOLTZMANN = 1.380649e-23
"""Boltzmann constant, J/K."""

FFT_MIN, FFT_MAX = 16, 4096
"""Transform lengths the open FFT core supports (docs/design.md 3.1)."""

DC_GUARD_BINS = 1
"""Range bins 0..DC_GUARD_BINS-1 are never detections (DC offset, TX-RX leakage)."""
NEGATIVE_BEAT_GUARD_BINS = 4
"""Top range bins N-4..N-1 are never detections: with complex sampling they hold negative
beat frequencies (range < 0), i.e. only the wrapped window sidelobes of near targets
(periodic Hann main lobe +-2 bins, first sidelobes at +-2.5 bins) and targets that have
passed the radar. A real ADC's top bins of its n_range / 2 sit next to fs / 2 (the
anti-alias filter's edge, where a tone meets its mirror image): guarded the same."""


def db_to_lin(db: float) -> float:
    """Power ratio from decibels."""
    return 10.0 ** (db / 10.0)


def dbm_to_w(dbm: float) -> float:
    """Watts from dBm."""
    return 10.0 ** ((dbm - 30.0) / 10.0)


def _is_pow2(n: int) -> bool:
    return n > 0 and (n & (n - 1)) == 0


@dataclass(frozen=True)
class RadarConfig:
    """One FMCW TDM-MIMO radar configuration (waveform, array, front end, ADC).

    Array geometry (docs/design.md section 2): ``num_rx`` RX elements at lambda/2 along +y, and
    ``num_tx`` TX subarrays whose phase centres are ``num_rx * lambda/2`` apart, so virtual
    channel ``v = tx * num_rx + rx`` sits at ``v * lambda/2``: a contiguous ULA.

    Radar profiles (docs/profiles.md, ``model.profile``) describe other radars through the
    fields after ``adc_full_scale_dbm``: samples per chirp and loops below the FFT lengths
    (zero padding), the TX firing order, a real ADC, 2-D / non-uniform array positions, the
    frame period and the fastest expected speed. Their defaults are the presets' behaviour;
    :meth:`unsupported_features` lists what of a profile the processing chain cannot handle
    yet, and :meth:`check_adc` / :meth:`check_cube` refuse such a profile.

    RF front-end values (defaults documented in the README, "Radar equation"): TX power per
    subarray, element / subarray / RX gains at broadside (the paper's 10.87 dBi element and
    14.92 dBi 3-element subarray), cosine element field pattern ``cos(az)**element_cos_power``
    (MATLAB's ``phased.CosineAntennaElement`` default 1.5), receiver noise figure, lumped
    system losses and the ADC full-scale level referred to the RX antenna port.
    """

    name: str
    num_tx: int
    """TDM transmit slots (TX subarrays) per frame; chirp c is sent by TX c mod num_tx."""
    num_rx: int
    """Receive lanes (RX elements), one ADC lane each."""
    n_range: int
    """Range FFT length (power of two, 16..4096); the ADC samples of a chirp
    (``n_samples``) are zero-padded to it."""
    n_doppler: int
    """Doppler FFT length (power of two, 16..4096); the chirp loops of a frame (``n_loops``,
    chirps per TX) are zero-padded to it."""
    sample_rate_hz: float
    """ADC sample rate (complex I/Q pairs, or real samples for a real ADC), Hz."""
    chirp_period_s: float
    """Chirp repetition interval Tc between consecutive chirps (any TX), s."""
    design_max_range_m: float
    """Range the preset must cover; its beat frequency must stay below the sample rate, m."""
    fc_hz: float = 77e9
    """Carrier (start) frequency, Hz."""
    sweep_bandwidth_hz: float = 86.77e6
    """Bandwidth swept during the sampled part of the ramp (``n_samples`` samples), Hz."""
    adc_bits: int = 16
    """ADC resolution per I and per Q, bits (two's complement)."""
    tx_power_dbm: float = 13.0
    """Transmit power per TX slot (whole subarray), dBm (AWR2243-class transmitter)."""
    element_gain_dbi: float = 10.87
    """Single series-fed TX/RX element gain at broadside, dBi (paper, TI reference design)."""
    subarray_gain_dbi: float = 14.92
    """3-element TX subarray gain at broadside with analog beamforming, dBi (paper Fig. 4)."""
    subarray_elements: int = 3
    """Elements per TX subarray, lambda/2 apart, fixed broadside phase."""
    rx_gain_dbi: float = 10.87
    """RX element gain at broadside, dBi."""
    element_cos_power: float = 1.5
    """Exponent m of the cosine element field pattern cos(az)**m (power: cos**2m)."""
    noise_figure_db: float = 12.0
    """Receiver noise figure, dB (AWR-class 77 GHz receiver)."""
    system_loss_db: float = 2.0
    """Lumped losses (radome, feed lines, processing), dB."""
    temperature_k: float = 290.0
    """Reference noise temperature T0, K."""
    adc_full_scale_dbm: float = -33.0
    """Received power at the RX antenna port of a tone that just reaches ADC full scale, dBm.
    Sets the receive gain; at -33 dBm thermal noise sits near -54 dBFS (about 60 LSB rms),
    well above the quantisation floor and far from clipping."""
    # ---- profile fields (docs/profiles.md); the defaults are the presets' behaviour ----------
    samples_per_chirp: int | None = None
    """ADC samples per chirp, 8..n_range (None: n_range, no zero padding)."""
    loops: int | None = None
    """Chirp loops per frame, 1..n_doppler; one loop fires every TX once (None: n_doppler)."""
    tx_order: tuple[int, ...] | None = None
    """TX index fired in each chirp slot of a loop, a permutation of 0..num_tx-1
    (None: 0, 1, ..., num_tx-1)."""
    adc: str = "complex"
    """ADC kind: ``complex`` (I/Q) or ``real``."""
    tx_positions: tuple[tuple[float, float], ...] | None = None
    """(horizontal, vertical) phase centre of each TX in half-wavelengths at fc_hz
    (None: TX k at (k * num_rx, 0), the contiguous virtual ULA of docs/design.md section 2)."""
    rx_positions: tuple[tuple[float, float], ...] | None = None
    """(horizontal, vertical) position of each RX in half-wavelengths (None: RX r at (r, 0))."""
    frame_period_s: float | None = None
    """Frame repetition period, s (None: frames back to back, ``frame_time_s``)."""
    max_speed_mps: float | None = None
    """Fastest radial speed the profile expects, m/s (None: the host's default)."""
    min_range_m: float | None = None
    """Near-range guard: range bins below min_range_m are never detections (TX-RX leakage),
    m (None: only the ``DC_GUARD_BINS``; ``model.profile.default_min_range_m``)."""

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if f.name in PROFILE_FIELDS:
                continue
            if f.name == "name":
                if not isinstance(value, str) or not value:
                    raise ValueError("name: must be a non-empty string")
                continue
            if isinstance(value, bool) or not isinstance(value, int | float):
                raise ValueError(f"{f.name}: must be a number, got {value!r}")
            if not math.isfinite(value):
                raise ValueError(f"{f.name}: must be finite, got {value!r}")
        for name in ("num_tx", "num_rx", "n_range", "n_doppler", "adc_bits", "subarray_elements"):
            value = getattr(self, name)
            if not isinstance(value, int):
                raise ValueError(f"{name}: must be an integer, got {value!r}")
            if value < 1:
                raise ValueError(f"{name}: must be at least 1, got {value}")
        for name in ("n_range", "n_doppler"):
            value = getattr(self, name)
            if not _is_pow2(value) or not FFT_MIN <= value <= FFT_MAX:
                raise ValueError(
                    f"{name}: FFT length must be a power of two in {FFT_MIN}..{FFT_MAX}, "
                    f"got {value}")
        if not 2 <= self.adc_bits <= 24:
            raise ValueError(f"adc_bits: must be in 2..24, got {self.adc_bits}")
        for name in ("sample_rate_hz", "chirp_period_s", "fc_hz", "sweep_bandwidth_hz",
                     "design_max_range_m", "temperature_k", "element_cos_power"):
            if getattr(self, name) <= 0:
                raise ValueError(f"{name}: must be positive, got {getattr(self, name)}")
        if self.noise_figure_db < 0:
            raise ValueError(f"noise_figure_db: must be >= 0 dB, got {self.noise_figure_db}")
        check_profile_fields(self)
        if self.chirp_period_s < self.sampled_chirp_s:
            raise ValueError(
                f"chirp_period_s: {self.chirp_period_s * 1e6:.3f} us is shorter than the sampled "
                f"ramp n_samples/sample_rate_hz = {self.sampled_chirp_s * 1e6:.3f} us")
        beat = self.beat_frequency_hz(self.design_max_range_m)
        if beat >= self.if_bandwidth_hz:
            raise ValueError(
                f"design_max_range_m: beat frequency {beat / 1e6:.2f} MHz of "
                f"{self.design_max_range_m} m is at or above "
                + (f"sample_rate_hz {self.sample_rate_hz / 1e6:.2f} MHz (complex sampling)"
                   if self.adc == "complex" else
                   f"half of sample_rate_hz, {self.if_bandwidth_hz / 1e6:.2f} MHz (real "
                   f"sampling)") + "; raise the sample rate or lower the range")

    # ---- waveform -------------------------------------------------------------------------
    @property
    def wavelength_m(self) -> float:
        """Carrier wavelength lambda = c / fc, m."""
        return C0 / self.fc_hz

    @property
    def n_samples(self) -> int:
        """ADC samples per chirp (``samples_per_chirp``, else n_range)."""
        return self.n_range if self.samples_per_chirp is None else self.samples_per_chirp

    @property
    def n_loops(self) -> int:
        """Chirp loops per frame = chirps per TX (``loops``, else n_doppler)."""
        return self.n_doppler if self.loops is None else self.loops

    @property
    def tx_sequence(self) -> tuple[int, ...]:
        """TX index fired in each chirp slot of a loop (``tx_order``, else 0..num_tx-1)."""
        return tuple(range(self.num_tx)) if self.tx_order is None else self.tx_order

    @property
    def if_bandwidth_hz(self) -> float:
        """Largest beat frequency the ADC samples unambiguously: fs (complex), fs / 2 (real)."""
        return self.sample_rate_hz if self.adc == "complex" else self.sample_rate_hz / 2.0

    @property
    def sampled_chirp_s(self) -> float:
        """Duration of the sampled part of the ramp, n_samples / fs, s."""
        return self.n_samples / self.sample_rate_hz

    @property
    def slope_hz_per_s(self) -> float:
        """Chirp slope S = sweep bandwidth / sampled duration, Hz/s."""
        return self.sweep_bandwidth_hz / self.sampled_chirp_s

    @property
    def tx_repetition_s(self) -> float:
        """Time between two chirps of the same TX, num_tx * Tc, s (slow-time sample period)."""
        return self.num_tx * self.chirp_period_s

    @property
    def frame_time_s(self) -> float:
        """Duration of one frame's chirps (coherent processing interval), num_tx * n_loops *
        Tc, s."""
        return self.num_tx * self.n_loops * self.chirp_period_s

    @property
    def n_chirps(self) -> int:
        """Chirps per frame in transmit order, num_tx * n_loops."""
        return self.num_tx * self.n_loops

    # ---- range ----------------------------------------------------------------------------
    @property
    def range_bin_m(self) -> float:
        """Range-FFT bin c / (2 B) * n_samples / n_range, m (1.7275 m for both presets; the
        range resolution c / (2 B) when there is no zero padding)."""
        return C0 / (2.0 * self.sweep_bandwidth_hz) * (self.n_samples / self.n_range)

    @property
    def n_range_bins(self) -> int:
        """Range bins of the cube: n_range (complex ADC), n_range / 2 (real ADC: bins
        0..n_range/2-1, the rest are their mirror images)."""
        return self.n_range if self.adc == "complex" else self.n_range // 2

    @property
    def max_range_m(self) -> float:
        """Largest unambiguous range, n_range_bins * range_bin, m (beat frequency fs for a
        complex ADC, fs / 2 for a real one)."""
        return self.n_range_bins * self.range_bin_m

    @property
    def detection_bins(self) -> tuple[int, int]:
        """Range bins a detector may report: ``lo <= bin < hi`` (see the module docstring:
        DC guard, or the ``min_range_m`` near-range guard, below; negative-beat guard at the
        top of the circular range axis)."""
        lo = DC_GUARD_BINS if self.min_range_m is None else max(
            DC_GUARD_BINS, math.ceil(self.min_range_m / self.range_bin_m - 1e-9))
        return lo, self.n_range_bins - NEGATIVE_BEAT_GUARD_BINS

    @property
    def max_detection_range_m(self) -> float:
        """Largest range a detection can report, the start of the top guard band, m."""
        return self.detection_bins[1] * self.range_bin_m

    @property
    def min_detection_range_m(self) -> float:
        """Smallest range a detection can report (end of the DC guard), m."""
        return self.detection_bins[0] * self.range_bin_m

    def beat_frequency_hz(self, range_m: float, radial_velocity_mps: float = 0.0) -> float:
        """Beat frequency of a target, S * 2R / c plus its Doppler shift 2v / lambda, Hz."""
        return (self.slope_hz_per_s * 2.0 * range_m / C0
                + 2.0 * radial_velocity_mps / self.wavelength_m)

    def range_bin_of(self, range_m: float, radial_velocity_mps: float = 0.0) -> float:
        """Fractional range-FFT bin of a target (includes range-Doppler coupling)."""
        return self.beat_frequency_hz(range_m, radial_velocity_mps) / self.sample_rate_hz \
            * self.n_range

    # ---- velocity -------------------------------------------------------------------------
    @property
    def velocity_bin_mps(self) -> float:
        """Doppler-FFT bin lambda / (2 * n_doppler * num_tx * Tc), m/s."""
        return self.wavelength_m / (2.0 * self.n_doppler * self.tx_repetition_s)

    @property
    def max_velocity_mps(self) -> float:
        """Unambiguous radial velocity +-lambda / (4 * num_tx * Tc), m/s."""
        return self.wavelength_m / (4.0 * self.tx_repetition_s)

    def doppler_bin_of(self, radial_velocity_mps: float) -> float:
        """Signed fractional Doppler bin of a radial velocity (not wrapped)."""
        return radial_velocity_mps / self.velocity_bin_mps

    # ---- angle ----------------------------------------------------------------------------
    @property
    def n_virtual(self) -> int:
        """Virtual channels num_tx * num_rx; channel v = tx * num_rx + rx."""
        return self.num_tx * self.num_rx

    @property
    def tx_positions_hw(self) -> np.ndarray:
        """TX phase centres (horizontal, vertical) in half-wavelengths, float (num_tx, 2)."""
        if self.tx_positions is None:
            return np.stack([np.arange(self.num_tx) * float(self.num_rx),
                             np.zeros(self.num_tx)], axis=1)
        return np.array(self.tx_positions, dtype=float).reshape(self.num_tx, 2)

    @property
    def rx_positions_hw(self) -> np.ndarray:
        """RX positions (horizontal, vertical) in half-wavelengths, float (num_rx, 2)."""
        if self.rx_positions is None:
            return np.stack([np.arange(self.num_rx, dtype=float), np.zeros(self.num_rx)],
                            axis=1)
        return np.array(self.rx_positions, dtype=float).reshape(self.num_rx, 2)

    @property
    def virtual_positions_hw(self) -> np.ndarray:
        """Virtual element (tx, rx) at tx + rx, half-wavelengths, float (n_virtual, 2),
        row v = tx * num_rx + rx."""
        return (self.tx_positions_hw[:, None, :] + self.rx_positions_hw[None, :, :]).reshape(
            self.n_virtual, 2)

    @property
    def uniform_linear_array(self) -> bool:
        """True when the virtual array is the contiguous horizontal lambda/2 ULA 0..n_virtual-1
        in channel order (the array the angle estimators assume)."""
        v = self.virtual_positions_hw
        return bool(np.array_equal(v[:, 0], np.arange(self.n_virtual)) and not v[:, 1].any())

    @property
    def angle_resolution_rad(self) -> float:
        """Boresight azimuth resolution 2 / (horizontal aperture + 1) with the aperture in
        half-wavelengths (2 / n_virtual for the lambda/2 ULA), rad."""
        h = self.virtual_positions_hw[:, 0]
        return 2.0 / float(h.max() - h.min() + 1.0)

    @property
    def angle_resolution_deg(self) -> float:
        """Boresight angle resolution, degrees."""
        return math.degrees(self.angle_resolution_rad)

    # ---- data path ------------------------------------------------------------------------
    @property
    def data_rate_per_lane_bps(self) -> float:
        """ADC burst data rate of one RX lane, fs * 2 * adc_bits (complex) or fs * adc_bits
        (real), bit/s."""
        return self.sample_rate_hz * (2 if self.adc == "complex" else 1) * self.adc_bits

    @property
    def adc_full_scale(self) -> int:
        """Largest positive ADC code, 2**(adc_bits-1) - 1."""
        return 2 ** (self.adc_bits - 1) - 1

    # ---- array shapes ---------------------------------------------------------------------
    @property
    def adc_shape(self) -> tuple[int, int, int]:
        """Shape of one ADC frame: (n_chirps in transmit order, num_rx, n_samples)."""
        return (self.n_chirps, self.num_rx, self.n_samples)

    @property
    def cube_shape(self) -> tuple[int, int, int]:
        """Shape of one radar cube: (n_virtual, n_range_bins, n_doppler)."""
        return (self.n_virtual, self.n_range_bins, self.n_doppler)

    def check_adc(self, adc: np.ndarray, what: str = "adc") -> None:
        """ValueError naming the expected and actual shape unless ``adc`` is one ADC frame
        of this configuration, (n_chirps, num_rx, n_samples), and the chain can process it
        (:meth:`check_processable`)."""
        self.check_processable()
        if np.shape(adc) != self.adc_shape:
            raise ValueError(f"{what}: expected shape {self.adc_shape} (chirps, rx, samples) "
                             f"for preset {self.name!r}, got {np.shape(adc)}")

    def check_cube(self, cube: np.ndarray, what: str = "cube") -> None:
        """ValueError naming the expected and actual shape unless ``cube`` is one radar cube
        of this configuration, (n_virtual, n_range_bins, n_doppler), and the chain can
        process it (:meth:`check_processable`)."""
        self.check_processable()
        if np.shape(cube) != self.cube_shape:
            raise ValueError(f"{what}: expected shape {self.cube_shape} for preset "
                             f"{self.name!r}, got {np.shape(cube)}")

    def unsupported_features(self) -> list[str]:
        """What of this configuration the processing chain cannot handle yet, one phrase each
        (empty for the presets; ``model.profile_fields.unsupported_features``)."""
        return unsupported_features(self)

    def check_processable(self) -> None:
        """ValueError naming what the processing chain does not support yet, if anything."""
        missing = self.unsupported_features()
        if missing:
            raise ValueError(f"radar {self.name!r}: the processing chain does not support "
                             f"{'; '.join(missing)} yet")

    # ---- front end ------------------------------------------------------------------------
    @property
    def noise_power_w(self) -> float:
        """Thermal noise power in the complex sampling bandwidth, k T0 F fs, W."""
        return (BOLTZMANN * self.temperature_k * db_to_lin(self.noise_figure_db)
                * self.sample_rate_hz)

    @property
    def noise_power_lsb2(self) -> float:
        """Expected complex noise power per ADC sample E|n|^2 in LSB^2 (I and Q half each)."""
        return self.adc_full_scale ** 2 * self.noise_power_w / dbm_to_w(self.adc_full_scale_dbm)

    def summary(self) -> dict[str, float | int | str]:
        """The configuration and its derived quantities, for tables and JSON."""
        return {
            "preset": self.name,
            "num_tx": self.num_tx,
            "num_rx": self.num_rx,
            "n_virtual": self.n_virtual,
            "n_range": self.n_range,
            "n_doppler": self.n_doppler,
            "sample_rate_msps": self.sample_rate_hz / 1e6,
            "sampled_chirp_us": self.sampled_chirp_s * 1e6,
            "chirp_period_us": self.chirp_period_s * 1e6,
            "tx_repetition_us": self.tx_repetition_s * 1e6,
            "slope_mhz_per_us": self.slope_hz_per_s / 1e12,
            "wavelength_mm": self.wavelength_m * 1e3,
            "range_bin_m": self.range_bin_m,
            "max_range_m": self.max_range_m,
            "velocity_bin_mps": self.velocity_bin_mps,
            "max_velocity_mps": self.max_velocity_mps,
            "angle_resolution_deg": self.angle_resolution_deg,
            "data_rate_per_lane_mbps": self.data_rate_per_lane_bps / 1e6,
            "frame_time_ms": self.frame_time_s * 1e3,
        }


PRESETS: dict[str, RadarConfig] = {
    # The paper's hardware prototype: the "first four virtual elements" on the ZCU106.
    "paper-fpga": RadarConfig(
        name="paper-fpga", num_tx=1, num_rx=4, n_range=64, n_doppler=256,
        sample_rate_hz=19.33e6, chirp_period_s=35.04e-6, design_max_range_m=100.0),
    # The paper's specification (4 TX subarrays x 16 RX). Samples at 32.5 MSPS, NOT the
    # paper's 19.33 MSPS: >= 300 m at 1.7275 m bins inside an 8.76 us chirp needs it.
    "full": RadarConfig(
        name="full", num_tx=4, num_rx=16, n_range=256, n_doppler=256,
        sample_rate_hz=32.5e6, chirp_period_s=8.76e-6, design_max_range_m=300.0),
}


def get_preset(name: str) -> RadarConfig:
    """The preset called ``name`` (``paper-fpga`` or ``full``); ValueError otherwise."""
    try:
        return PRESETS[name]
    except KeyError:
        raise ValueError(
            f"preset: unknown preset {name!r}; choose one of {', '.join(PRESETS)}") from None
