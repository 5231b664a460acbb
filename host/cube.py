"""ADC frame -> radar cube on the host, fast: the same cube as the float reference
``model.reference.radar_cube`` (equal to float64 rounding), in fewer passes.

The reference takes the steps of the FPGA chain one by one (cast, range window, range FFT
scaled 1/n_range, corner turn, optional static-clutter removal, Doppler window, Doppler FFT
scaled 1/n_doppler), each a pass over the cube. Both windows and both scales are linear
per axis, so here they are one precomputed (n_samples, n_loops) weight, applied while the
frame is cast to float64 and turned into cube order (a single pass); static-clutter removal
(each slow-time vector less its Doppler-window weighted mean) commutes with the range FFT and
its window, so it is done on the samples, before the weight; then one 2-D FFT (a real ADC: a
real FFT along range, which gives bins 0..n_range/2 directly). ``radar process`` builds its cubes
here (``radar.commands.process.capture_frame_cloud``); the tests hold it to the reference.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
import scipy.fft

from model.array import tx_slots
from model.config import RadarConfig
from model.reference import check_frame, fft_axes, remove_static


@lru_cache(maxsize=16)
def _weights(cfg: RadarConfig, range_window: bool, doppler_window: bool) -> np.ndarray:
    """Both windows (``model.reference.fft_axes``) and both FFT scales,
    w_r[s] w_d[l] / (n_range n_doppler), float64 (n_samples, n_loops)."""
    ax_r, ax_d = fft_axes(cfg, range_window, doppler_window)
    w = np.outer(ax_r.window(), ax_d.window() / (cfg.n_range * cfg.n_doppler))
    w.flags.writeable = False
    return w


def frame_cube(adc: np.ndarray, cfg: RadarConfig, range_window: bool = True,
               doppler_window: bool = True, remove_static_clutter: bool = False) -> np.ndarray:
    """``model.reference.radar_cube`` computed in fewer passes (module docstring).

    adc: complex, or real for a real ADC, (n_chirps, num_rx, n_samples) -> complex128
    (n_virtual, n_range_bins, n_doppler), equal to the reference's to float64 rounding.
    """
    check_frame(adc, cfg)
    w = _weights(cfg, range_window, doppler_window)
    x = np.asarray(adc).reshape(cfg.n_loops, cfg.num_tx, cfg.num_rx, cfg.n_samples)
    if cfg.tx_sequence != tuple(range(cfg.num_tx)):
        x = x[:, tx_slots(cfg)]                 # slot of each TX index
    x = x.transpose(1, 2, 3, 0)                 # (tx, rx, samples, loops)
    real = cfg.adc == "real"
    y = np.empty(x.shape, np.float64 if real else np.complex128)
    # less the (Doppler-window weighted) slow-time mean when asked, then both weights
    np.multiply(remove_static(x, doppler_window) if remove_static_clutter else x, w, out=y)
    if real:
        y = scipy.fft.rfft(y, n=cfg.n_range, axis=2)[:, :, :cfg.n_range_bins]
        y = scipy.fft.fft(y, n=cfg.n_doppler, axis=3, overwrite_x=True)
    else:
        y = scipy.fft.fft2(y, s=(cfg.n_range, cfg.n_doppler), axes=(2, 3), overwrite_x=True)
    return y.reshape(cfg.cube_shape)
