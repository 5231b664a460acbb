"""Detected cells -> point cloud: the one path both the cube (``host.pipeline``) and the
FPGA's records (``host.record_points``) take (``host.pipeline`` module docstring, steps 3 to
5), vectorised over the cells.

1. TDM velocity unfolding (``host.tdm``): the angle-spectrum peak of each cell compensated
   for each alias class that holds one of its velocity hypotheses (``host.angle.
   peak_powers``), then the decision of every cell (``host.tdm.choose_folds``).
2. Angles (``host.angle.estimate_angles``) of each cell's vector compensated for its chosen
   alias order; the chosen class's peak is the first component's. The contiguous lambda/2
   ULA (``RadarConfig.uniform_linear_array``) takes the angle FFT's fast path, any other
   virtual array the steering vectors of its positions (azimuth, and elevation where it
   has vertical extent).
3. One point per angle component (:func:`cloud`): range corrected for range-Doppler
   coupling, x/y/z, velocity, power, coherent SNR and an RCS estimate from the radar equation
   with the window's scalloping and coherent gain undone.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from host.angle import estimate_angles, peak_powers
from host.calibration import apply_calibration
from host.cells import Cells, scallop
from host.params import DetectionParams
from host.pointcloud import PointCloud
from host.tdm import choose_folds, hypothesis_classes, tx_phasors
from model.config import RadarConfig, dbm_to_w
from model.reference import fft_axes, signed_bins
from model.simulate import rx_gain, tx_gain


def points_from_cells(cells: Cells, cfg: RadarConfig, params: DetectionParams,
                      frame: int = 0) -> PointCloud:
    """Point cloud of detected cells (module docstring); ``frame`` is the points' frame
    index. ValueError when the snapshots do not have ``cfg``'s virtual channels. The
    calibration of ``params`` is applied first (``host.calibration.apply_calibration``)."""
    cells = apply_calibration(cells, params.calibration)
    n = len(cells)
    if not n:
        return PointCloud.empty()
    nd, nv, ntx = cfg.n_doppler, cfg.n_virtual, cfg.num_tx
    x = np.ascontiguousarray(cells.snapshot, dtype=np.complex128)
    if x.shape != (n, nv):
        raise ValueError(f"cells: snapshots {x.shape}, expected ({n}, {nv}) for {cfg.name}")
    noise = np.asarray(cells.noise, dtype=float)
    sb = _signed_bins(nd)[np.asarray(cells.doppler_bin)]
    snr_db = cell_snr_db(np.asarray(cells.power, dtype=float), noise, nv)
    measured = (sb + cells.offsets[:, 1]) * cfg.velocity_bin_mps
    positions = _positions(cfg)
    first_sin = None
    if ntx > 1 and params.unfold_velocity:
        # (cell, class) pairs of the classes that hold a hypothesis: only these enter the
        # decision; the others' power stays 0 (choose_folds masks them)
        ci, cc = np.nonzero(hypothesis_classes(cfg, measured, params.max_speed_mps))
        pw, sn = peak_powers(x, params.angle.n_fft, tx_phasors(cfg, sb[ci] + cc * nd), ci,
                             positions)
        class_power = np.zeros((n, ntx))
        class_power[ci, cc] = pw
        pair = np.full((n, ntx), -1, np.int64)
        pair[ci, cc] = np.arange(len(ci))
        fold, ambiguous = choose_folds(class_power, cfg, measured, snr_db, params)
        # the fold's class always holds a hypothesis: its peak was computed (the ULA's
        # sin(az) is the first component's)
        if positions is None:
            first_sin = sn[pair[np.arange(n), fold % ntx]]
    else:
        fold, ambiguous = choose_folds(np.zeros((n, 0)), cfg, measured, snr_db, params)
    k = sb + fold * nd
    ang = estimate_angles(x, noise / nv, params.angle, tx_phasors(cfg, k), first_sin,
                          positions)
    return cloud(cfg, params, np.asarray(cells.range_bin), cells.offsets, k, ambiguous,
                 ang.cell, ang.azimuth_deg, ang.amplitude, ang.snr_db, frame,
                 ang.elevation_deg, cells.range_bias_m)


@lru_cache(maxsize=16)
def _signed_bins(n: int) -> np.ndarray:
    """``model.reference.signed_bins(n)`` as int64, read-only, computed once per length."""
    sb = signed_bins(n).astype(np.int64)
    sb.flags.writeable = False
    return sb


@lru_cache(maxsize=16)
def _positions(cfg: RadarConfig) -> np.ndarray | None:
    """The virtual array the angle estimator is given: None for the contiguous lambda/2 ULA
    (its FFT path), else ``cfg.virtual_positions_hw`` (read-only); once per radar."""
    if cfg.uniform_linear_array:
        return None
    p = cfg.virtual_positions_hw
    p.flags.writeable = False
    return p


def cell_snr_db(power: np.ndarray, noise: np.ndarray, n_virtual: int) -> np.ndarray:
    """SNR of detected cells over the coherent sum of their channels, dB, float (n,):
    (power - noise) / noise of the non-coherent map (power, noise float (n,)) plus the
    coherent gain 10 log10(n_virtual); a zero noise estimate (noiseless input: every
    training cell 0) counts as 1e-30, as the angle estimator's noise floor."""
    noise = np.maximum(noise, 1e-30)
    return 10 * np.log10(np.maximum(power - noise, 1e-30) / noise) + 10 * np.log10(n_virtual)


def cloud(cfg: RadarConfig, params: DetectionParams, r: np.ndarray, offsets: np.ndarray,
          k: np.ndarray, ambiguous: np.ndarray, cell: np.ndarray, az: np.ndarray,
          amplitude: np.ndarray, snr_db: np.ndarray, frame: int,
          elevation_deg: np.ndarray | float = 0.0, range_bias_m: float = 0.0
          ) -> PointCloud:
    """Step 3 of the module docstring, one point per angle component: range (Doppler
    coupling removed), velocity of the unfolded bin ``k``, power and RCS (window
    scalloping and coherent gain undone).

    Per cell (n,): r range bin, k unfolded signed Doppler bin, ambiguous flag; offsets
    float (n, 2) bins. Per component (m,): ``cell`` its cell index, ``az`` deg,
    ``amplitude`` complex (LSB), ``snr_db``, ``elevation_deg`` (or a scalar);
    ``range_bias_m`` is subtracted from the range (calibration)."""
    nr = cfg.n_range
    dr, dd = offsets[:, 0], offsets[:, 1]
    velocity = (k + dd) * cfg.velocity_bin_mps
    # the beat frequency includes the Doppler shift 2v/lambda: remove it from the range
    coupling = 2 * velocity / cfg.wavelength_m / cfg.sample_rate_hz * nr
    range_m = (r + dr - coupling) * cfg.range_bin_m - range_bias_m
    ax_r, ax_d = fft_axes(cfg, params.range_window, params.doppler_window)
    cg = ax_r.coherent_gain * ax_d.coherent_gain
    amp = np.abs(amplitude)
    amp_adc = amp / (cg * scallop((ax_r, ax_d), offsets)[cell])
    rcs = rcs_estimate_dbsm(cfg, amp_adc, range_m[cell], az, params.tx_beamforming)
    return PointCloud.from_polar(
        range_m[cell], az, velocity[cell], 20 * np.log10(np.maximum(amp, 1e-30)), snr_db,
        rcs, r[cell].astype(int), k[cell].astype(int), ambiguous[cell], frame=frame,
        elevation_deg=elevation_deg)


def rcs_estimate_dbsm(cfg: RadarConfig, amplitude_adc: np.ndarray, range_m: np.ndarray,
                      azimuth_deg: np.ndarray, beamforming: bool) -> np.ndarray:
    """Radar-equation inverse: RCS (dBsm) from the ADC-referred tone amplitude (LSB)."""
    pr = (np.asarray(amplitude_adc) / cfg.adc_full_scale) ** 2 * dbm_to_w(cfg.adc_full_scale_dbm)
    lam = cfg.wavelength_m
    g = dbm_to_w(cfg.tx_power_dbm) * tx_gain(cfg, azimuth_deg, beamforming) \
        * rx_gain(cfg, azimuth_deg) * lam**2
    loss = 10 ** (cfg.system_loss_db / 10)
    with np.errstate(divide="ignore"):
        sigma = pr * (4 * np.pi) ** 3 * np.asarray(range_m) ** 4 * loss / np.maximum(g, 1e-30)
        return 10 * np.log10(np.maximum(sigma, 1e-30))
