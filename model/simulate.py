"""FMCW TDM-MIMO baseband simulator: scatterers -> ADC samples of one frame, for any radar
profile (docs/profiles.md).

Signal model (per scatterer s, chirp c, RX r, fast-time sample n). The IF signal is the
transmitted chirp times the conjugate of the echo, so the beat frequency is positive and
grows with range, and a receding target has a positive Doppler frequency. The array follows
``model.array``: chirp c is fired by TX ``cfg.tx_sequence[c % num_tx]`` at p_tx(c), RX r sits at
p_rx(r) (half-wavelengths, ``cfg.tx_positions_hw`` / ``rx_positions_hw``), and a scatterer at
azimuth az, elevation el has the direction cosines u = sin(az) cos(el), w = sin(el). With
round-trip delay

    tau = [2 (R + v (t_c + t_n)) - (lambda / 2) (p_tx(c) + p_rx(r)) . (u, w)] / c0

the phase is 2 pi (fc tau + S tau t_n - S tau0^2 / 2). Kept exactly: range, Doppler over
slow time, the Doppler shift inside the chirp (range-Doppler coupling), range migration over
the frame (the beat frequency changes chirp to chirp), the time of each chirp slot (whatever
TX fires it), the virtual-array phase (2-D, non-uniform arrays) and the residual video phase.
Neglected (documented): the array aperture's effect on the beat frequency (< 0.04 cycles over
the 64-element array) and the v t_n^2 term (< 1e-4 cycles). Times t_c are measured from the
centre of the frame, so scene kinematics are those at the frame centre; frame k starts
k frame periods (``cfg.frame_period_s``, else back to back) after frame 0.
Fast time runs over the ``cfg.n_samples`` ADC samples of a chirp, slow time over the
``cfg.n_chirps`` chirps of ``cfg.n_loops`` loops (the FFT lengths ``n_range`` / ``n_doppler``
only matter to the processing, which zero-pads).

Amplitude: radar equation Pr = Pt Gt(az) Gr(az) lambda^2 sigma / ((4 pi)^3 R^4 L); the ADC
code amplitude of the tone is full_scale * sqrt(Pr / P_fullscale). The antenna patterns are
azimuth-only (a scatterer's elevation changes its phase, not its gain). Thermal noise
k T0 F fs (complex, circular). The sum is quantised to ``adc_bits`` with saturation, counted.

Complex ADC (``cfg.adc == "complex"``): I and Q are the real and imaginary parts of that
complex IF, beat frequencies [0, fs) map to range bins 0..n_range-1.
Real ADC (``cfg.adc == "real"``): the IF is real-valued, the I channel of the same
complex IF: a tone of complex amplitude A becomes A cos(phase), i.e. two tones of amplitude
A/2 at +f and -f (a target's echo also appears at the mirror frequency, range bin n_range - k,
in the range FFT); thermal noise is real Gaussian of variance ``noise_power_lsb2 / 2`` (the I
noise of the complex ADC: the same per-sample SNR; after the FFT the image band's noise costs
3 dB). Beat frequencies must stay below fs / 2. Frames are float32 arrays of integer codes.

Real-world effects (``model.impairments``: channel gain/phase errors, TX-RX leakage, DC
offset, static clutter, I/Q imbalance, phase noise) are added by :func:`simulate_frame`
when asked for; all off, the output is that of the ideal radar.

Vectorised as a batched matrix product: for each chirp, (rx x scatterers) @ (scatterers x
samples), in chunks of chirps to bound memory; complex64 arithmetic (errors ~1e-3 LSB,
far below the ADC's 0.29 LSB quantisation noise).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from model.array import direction_cosines, steering
from model.config import C0, RadarConfig, db_to_lin, dbm_to_w
from model.impairments import NO_IMPAIRMENTS, Impairments, apply_iq_imbalance, phase_noise_rad
from model.scene import Scatterers, Scene

MAX_FRAME_INDEX = 1_000_000
"""Largest frame index (2.5 h of the full preset's frames; the phase of t_c stays exact)."""


def check_frame_index(frame_index: int) -> int:
    """ValueError unless ``frame_index`` is an integer in 0..MAX_FRAME_INDEX."""
    if isinstance(frame_index, bool) or not isinstance(frame_index, int | np.integer) or \
            not 0 <= frame_index <= MAX_FRAME_INDEX:
        raise ValueError(f"frame: must be an integer in 0..{MAX_FRAME_INDEX}, got "
                         f"{frame_index!r}")
    return int(frame_index)


CLUTTER_ID = -2
"""``object_id`` of the static clutter's scatterers (``model.impairments``)."""
CHIRP_CHUNK = 64
"""Chirps per batched matrix product (bounds the (chunk, scatterers, samples) temporary)."""
FAST_SPLIT = 16
"""Fast-time phasors are built as ceil(n_samples/16) x 16 outer products."""


# ---- antennas -------------------------------------------------------------------------------
def element_power_pattern(cfg: RadarConfig, azimuth_deg: np.ndarray) -> np.ndarray:
    """Cosine element power pattern cos(az)**(2 m), relative to broadside; shape of input."""
    c = np.cos(np.radians(np.asarray(azimuth_deg, dtype=float)))
    return np.clip(c, 0.0, None) ** (2.0 * cfg.element_cos_power)


def subarray_factor_power(cfg: RadarConfig, azimuth_deg: np.ndarray) -> np.ndarray:
    """|AF(az)|^2 / M^2 of the M-element lambda/2 TX subarray steered to broadside (1 at 0)."""
    m = cfg.subarray_elements
    s = np.sin(np.radians(np.asarray(azimuth_deg, dtype=float)))
    k = np.arange(m) - (m - 1) / 2.0
    # the element positions are symmetric about the centre: AF = sum_k cos(pi s k), real
    af = np.cos(np.pi * np.multiply.outer(s, k)).sum(axis=-1)
    return af**2 / m**2


def tx_gain(cfg: RadarConfig, azimuth_deg: np.ndarray, beamforming: bool) -> np.ndarray:
    """Linear TX gain towards ``azimuth_deg``: subarray (beamforming) or single element."""
    elem = element_power_pattern(cfg, azimuth_deg)
    if beamforming:
        return db_to_lin(cfg.subarray_gain_dbi) * elem * subarray_factor_power(cfg, azimuth_deg)
    return db_to_lin(cfg.element_gain_dbi) * elem


def rx_gain(cfg: RadarConfig, azimuth_deg: np.ndarray) -> np.ndarray:
    """Linear RX element gain towards ``azimuth_deg``."""
    return db_to_lin(cfg.rx_gain_dbi) * element_power_pattern(cfg, azimuth_deg)


def received_power_w(cfg: RadarConfig, sc: Scatterers, beamforming: bool) -> np.ndarray:
    """Echo power at one RX antenna port per scatterer, W, shape (n,) (radar equation)."""
    lam = cfg.wavelength_m
    return (dbm_to_w(cfg.tx_power_dbm) * tx_gain(cfg, sc.azimuth_deg, beamforming)
            * rx_gain(cfg, sc.azimuth_deg) * lam**2 * sc.rcs_m2
            / ((4.0 * np.pi) ** 3 * sc.range_m**4 * db_to_lin(cfg.system_loss_db)))


def tone_amplitude_lsb(cfg: RadarConfig, sc: Scatterers, beamforming: bool) -> np.ndarray:
    """Complex-tone amplitude of each scatterer in ADC codes (LSB), shape (n,)."""
    return cfg.adc_full_scale * np.sqrt(
        received_power_w(cfg, sc, beamforming) / dbm_to_w(cfg.adc_full_scale_dbm))


def snr_per_sample_db(cfg: RadarConfig, sc: Scatterers, beamforming: bool) -> np.ndarray:
    """Per-ADC-sample SNR of each scatterer, dB, shape (n,) (before any FFT gain)."""
    return 10.0 * np.log10(received_power_w(cfg, sc, beamforming) / cfg.noise_power_w)


# ---- geometry and timing -------------------------------------------------------------------
def chirp_tx(cfg: RadarConfig) -> np.ndarray:
    """TX index firing each chirp of a frame, int (n_chirps,): ``cfg.tx_sequence[c % num_tx]``
    (``model.array``)."""
    return np.array(cfg.tx_sequence)[np.arange(cfg.n_chirps) % cfg.num_tx]


def frame_period_s(cfg: RadarConfig) -> float:
    """Time from one frame's start to the next, s: ``cfg.frame_period_s``, else the frame's
    chirps back to back (``frame_time_s``)."""
    return cfg.frame_time_s if cfg.frame_period_s is None else cfg.frame_period_s


def chirp_times_s(cfg: RadarConfig, frame_index: int = 0) -> np.ndarray:
    """Start time of each chirp of frame ``frame_index`` relative to the centre of frame 0, s,
    shape (n_chirps,), firing order (chirp c = slot c % num_tx of loop c // num_tx)."""
    c = np.arange(cfg.n_chirps)
    if cfg.frame_period_s is None:      # back to back: one exact product per chirp
        return (c + frame_index * cfg.n_chirps) * cfg.chirp_period_s - cfg.frame_time_s / 2.0
    return c * cfg.chirp_period_s + (frame_index * cfg.frame_period_s - cfg.frame_time_s / 2.0)


# ---- the simulator --------------------------------------------------------------------------
@dataclass(frozen=True)
class AdcFrame:
    """One frame of ADC samples and what happened while producing it.

    ``samples``: shape ``cfg.adc_shape`` = (n_chirps in firing order, num_rx, n_samples);
    complex64 with integer-valued I and Q in [-2**(b-1), 2**(b-1)-1] (the codes the FPGA
    receives) for a complex ADC, float32 of integer codes for a real one.
    ``saturated``: number of I or Q (or real) values clipped by the ADC.
    ``dropped_scatterers``: scatterers (clutter included) not simulated, all reasons:
    ``passed_scatterers``
    (range <= 0 at some chirp of the frame: the scatterer is at or behind the radar, and
    its beat frequency would be negative) plus those beyond the IF bandwidth (beat >= fs, or
    fs / 2 for a real ADC, at the frame centre), removed by the anti-alias filter.
    """

    samples: np.ndarray
    saturated: int
    dropped_scatterers: int
    config: RadarConfig
    passed_scatterers: int = 0

    @property
    def beyond_if_scatterers(self) -> int:
        """Scatterers removed by the anti-alias filter (beat >= the IF bandwidth)."""
        return self.dropped_scatterers - self.passed_scatterers


def frame_centre_range_m(cfg: RadarConfig, sc: Scatterers, frame_index: int = 0) -> np.ndarray:
    """Range of each scatterer at the centre of frame ``frame_index``, m, shape (n,): scene
    ranges hold at the centre of frame 0 and targets move radially at constant speed."""
    return sc.range_m + sc.radial_velocity_mps * frame_index * frame_period_s(cfg)


def passed_radar(cfg: RadarConfig, sc: Scatterers, frame_index: int = 0) -> np.ndarray:
    """bool (n,): the scatterer is at range <= 0 at some chirp of the frame (it has driven
    past the radar; its echo would have a negative beat frequency)."""
    r = frame_centre_range_m(cfg, sc, frame_index)
    return r - np.abs(sc.radial_velocity_mps) * cfg.frame_time_s / 2.0 <= 0.0


def simulate_baseband(cfg: RadarConfig, sc: Scatterers, *, beamforming: bool = True,
                      frame_index: int = 0) -> tuple[np.ndarray, int]:
    """Noise-free, unquantised complex baseband of all scatterers, in ADC codes.

    Returns (complex128 ``cfg.adc_shape`` = (n_chirps, num_rx, n_samples), scatterers not
    simulated: at or behind the radar (see :func:`passed_radar`) or beyond the IF band at
    the frame centre). A real ADC samples the real part (see the module docstring).
    """
    beat = cfg.beat_frequency_hz(frame_centre_range_m(cfg, sc, frame_index),
                                 sc.radial_velocity_mps)
    keep = (beat >= 0) & (beat < cfg.if_bandwidth_hz) & ~passed_radar(cfg, sc, frame_index)
    dropped = int((~keep).sum())
    r = sc.range_m[keep]
    v = sc.radial_velocity_mps[keep]
    u, w = direction_cosines(np.radians(sc.azimuth_deg[keep]), np.radians(sc.elevation_deg[keep]))
    r_centre = frame_centre_range_m(cfg, sc, frame_index)[keep]
    amp = tone_amplitude_lsb(cfg, Scatterers(r_centre, sc.azimuth_deg[keep], v,
                                             sc.rcs_m2[keep], sc.object_id[keep]), beamforming)
    lam, slope = cfg.wavelength_m, cfg.slope_hz_per_s
    n_samples = cfg.n_samples
    out = np.zeros(cfg.adc_shape, dtype=np.complex128)
    if r.size == 0:
        return out, dropped

    t_c = chirp_times_s(cfg, frame_index)                                       # (C,)
    tau0 = 2.0 * r / C0
    # per scatterer constant: amplitude, carrier phase 2R/lambda, residual video phase
    const = amp * np.exp(2j * np.pi * (2.0 * r / lam - 0.5 * slope * tau0**2))   # (S,)
    # slow time x TX: Doppler 2 v t_c / lambda and the firing TX's share of the array phase
    tx = steering(cfg.tx_positions_hw, u, w)[:, chirp_tx(cfg)].T                 # (C, S)
    slow = np.exp(2j * np.pi * np.outer(t_c, 2.0 * v / lam)) * tx * const        # (C, S)
    rx = steering(cfg.rx_positions_hw, u, w).T                                   # (R, S)
    # fast-time frequency per chirp: beat of R(t_c) (range migration) + in-chirp Doppler
    f_fast = (slope * 2.0 * (r[None, :] + v[None, :] * t_c[:, None]) / C0
              + 2.0 * v[None, :] / lam)                                         # (C, S)
    cyc = (f_fast / cfg.sample_rate_hz) % 1.0                                   # cycles/sample
    # exp(j 2 pi cyc n) with n = SPLIT*a + b as an outer product of two small tables computed
    # in float64: accurate to ~1e-7 rad and ~10x faster than evaluating every phase.
    a = np.arange(-(-n_samples // FAST_SPLIT)) * FAST_SPLIT
    b = np.arange(FAST_SPLIT)
    left_all = (rx[None, :, :] * slow[:, None, :]).astype(np.complex64)        # (C, R, S)
    for start in range(0, cfg.n_chirps, CHIRP_CHUNK):
        sl = slice(start, min(start + CHIRP_CHUNK, cfg.n_chirps))
        coarse = np.exp(2j * np.pi * cyc[sl, :, None] * a).astype(np.complex64)  # (c, S, A)
        fine = np.exp(2j * np.pi * cyc[sl, :, None] * b).astype(np.complex64)    # (c, S, 16)
        fast = (coarse[..., :, None] * fine[..., None, :]).reshape(
            coarse.shape[0], coarse.shape[1], a.size * FAST_SPLIT)               # (c, S, 16 A)
        if fast.shape[-1] != n_samples:
            fast = fast[..., :n_samples]
        out[sl] = np.matmul(left_all[sl], fast)
    return out, dropped


def quantize_adc(x: np.ndarray, bits: int) -> tuple[np.ndarray, int]:
    """Round to integers (half to even) and clip to ``bits`` two's complement: I and Q of a
    complex ``x``, the values of a real one.

    Returns (complex64, or float32 for real ``x``, of the same shape with integer values,
    count of clipped values).
    """
    lo, hi = -(2 ** (bits - 1)), 2 ** (bits - 1) - 1
    if not np.iscomplexobj(x):
        q = np.rint(x)
        saturated = int(np.count_nonzero((q < lo) | (q > hi)))
        return np.clip(q, lo, hi).astype(np.float32), saturated
    re = np.rint(x.real)
    im = np.rint(x.imag)
    saturated = int(np.count_nonzero((re < lo) | (re > hi)) + np.count_nonzero((im < lo)
                                                                                | (im > hi)))
    out = np.empty(x.shape, dtype=np.complex64)
    out.real = np.clip(re, lo, hi)
    out.imag = np.clip(im, lo, hi)
    return out, saturated


def thermal_noise(cfg: RadarConfig, shape: tuple[int, ...], rng: np.random.Generator
                  ) -> np.ndarray:
    """Thermal noise of the ADC's kind: circular complex white Gaussian of power
    ``cfg.noise_power_lsb2`` (complex128), or for a real ADC real white Gaussian of variance
    ``noise_power_lsb2 / 2`` (float64)."""
    sigma = math.sqrt(cfg.noise_power_lsb2 / 2.0)
    if cfg.adc == "real":
        return sigma * rng.standard_normal(shape)
    return sigma * (rng.standard_normal(shape) + 1j * rng.standard_normal(shape))


def simulate_frame(cfg: RadarConfig, sc: Scatterers, *, beamforming: bool = True,
                   noise: bool = True, rng: np.random.Generator | None = None,
                   frame_index: int = 0, impairments: Impairments = NO_IMPAIRMENTS
                   ) -> AdcFrame:
    """One frame of quantised ADC samples (see :class:`AdcFrame`) for ``sc``, with the
    real-world effects of ``impairments`` (``model.impairments``, in its order; the phase
    noise is drawn from ``rng`` after the thermal noise). ValueError naming an impairment
    field that does not fit ``cfg``."""
    check_frame_index(frame_index)
    imp = impairments
    imp.check(cfg)
    rng = rng if rng is not None else np.random.default_rng(0)
    every = sc
    if imp.clutter:
        r, az, el, rcs = imp.clutter_points()
        every = Scatterers.concat([sc, Scatterers(r, az, np.zeros_like(r), rcs,
                                                  np.full(r.shape, CLUTTER_ID), el)])
    x, dropped = simulate_baseband(cfg, every, beamforming=beamforming, frame_index=frame_index)
    tx = chirp_tx(cfg)
    if imp.leakage_dbfs is not None:
        tone = np.exp(2j * np.pi * cfg.beat_frequency_hz(imp.leakage_range_m)
                      / cfg.sample_rate_hz * np.arange(cfg.n_samples))
        x += imp.leakage_amplitudes(cfg)[tx][:, :, None] * tone
    if imp.channel_errors:
        g_tx, g_rx = imp.channel_gains(cfg)
        x *= g_tx[tx][:, None, None] * g_rx[None, :, None]
    thermal = thermal_noise(cfg, x.shape, rng) if noise else None
    if imp.phase_noise_rms_deg:
        x *= np.exp(1j * phase_noise_rad(imp, cfg, rng))[:, None, :]
    if cfg.adc == "real":
        x = x.real.copy()
    if thermal is not None:
        x += thermal
    if imp.iq_imbalance:
        x = apply_iq_imbalance(x, imp.iq_gain_db, imp.iq_phase_deg)
    if imp.dc_offset_dbfs is not None:
        x += imp.dc_offsets(cfg)[None, :, None]
    samples, saturated = quantize_adc(x, cfg.adc_bits)
    return AdcFrame(samples=samples, saturated=saturated, dropped_scatterers=dropped,
                    config=cfg, passed_scatterers=int(passed_radar(cfg, sc, frame_index).sum()))


def simulate_scene(scene: Scene, frame_index: int = 0) -> AdcFrame:
    """One frame of ``scene`` (its radar, seed, beamforming and noise switches, impairments).

    Noise for frame k uses the seed sequence (scene.seed, k), so frames are reproducible
    and independent.
    """
    check_frame_index(frame_index)
    rng = np.random.default_rng([scene.seed, frame_index])
    return simulate_frame(scene.config, scene.scatterers(), beamforming=scene.tx_beamforming,
                          noise=scene.noise, rng=rng, frame_index=frame_index,
                          impairments=scene.impairments)
