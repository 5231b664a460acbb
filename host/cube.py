"""ADC frame -> radar cube on the host, fast: the same cube as the float reference
``model.reference.radar_cube`` (equal to float64 rounding), in fewer passes.

The reference takes the steps of the FPGA chain one by one (cast, range window, range FFT
scaled 1/n_range, corner turn, optional static-clutter removal, Doppler window, Doppler FFT
scaled 1/n_doppler), each a pass over the cube. Both windows and both scales are linear
per axis, so here they are one precomputed (n_loops, n_samples) weight, applied while the
frame is cast (a single pass, in the frame's own order); then one 2-D FFT over the loops and
the samples (a real ADC: a real FFT along range, which gives bins 0..n_range/2 directly), and
the cube is that array with its axes reordered, a view (no corner-turn copy: numpy reads it
as any array, in memory order where it can). The weighted cast (compiled, :func:`_weighted`)
writes the frame channel by channel, (tx, rx, loops, samples): each channel's FFT then
works on a block of its own (128 KB for 128 x 128 complex64) whose rows are one chirp
apart, not all channels' chirps (a power-of-two stride that mapped a Doppler column onto a
few cache sets); the same transforms in the same order, every value the same. Static-clutter
removal (``model.reference.remove_static``: each slow-time vector less its Doppler-window weighted
mean c = sum(w x) / sum(w)) is linear too, and done after the FFT: the Doppler FFT of
w (x - c) is Y[k] - c W[k] / n_doppler with W the DFT of the window (zero-padded to
n_doppler), and Y[0] = c W[0] / n_doppler, so it is Y[k] - Y[0] W[k] / W[0]
(:func:`_static_response`): a few bins touched instead of two passes over the samples (all
of them for an unwindowed zero-padded axis, whose W is dense). ``radar process`` and ``radar
calibrate`` build their cubes here in single precision (``radar.commands.process.
capture_cube``), as do
``host.pipeline.process_frame`` and the float frame source (``radar.sources``) in double;
the tests hold it to the reference.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
import scipy.fft

from host.kernels import njit, warm_up
from model.array import tx_slots
from model.config import RadarConfig
from model.reference import check_frame, fft_axes

SINGLE_RTOL = 1e-6
"""``frame_cube(single=True)``'s cube differs from the reference's by at most about this
times the cube's largest magnitude (float32 rounding through the weights and the FFTs, whose
error grows with log2 of their length; the ADC's 16-bit codes are exact in float32): 120 dB
below the strongest return, far below the noise of a 16-bit ADC."""
RESPONSE_FLOOR = 1e-13
"""W[k] / W[0] below this (the DFT's rounding around the window's exact zeros) is taken
as 0 in :func:`_static_response`: such bins are left as they are."""


@lru_cache(maxsize=16)
def _weights(cfg: RadarConfig, range_window: bool, doppler_window: bool, single: bool
             ) -> np.ndarray:
    """Both windows (``model.reference.fft_axes``) and both FFT scales,
    w_d[l] w_r[s] / (n_range n_doppler), float64 (n_loops, n_samples) (``single``:
    float32), to broadcast over a frame's (tx, rx, loops, samples)."""
    ax_r, ax_d = fft_axes(cfg, range_window, doppler_window)
    w = np.outer(ax_d.window() / (cfg.n_range * cfg.n_doppler), ax_r.window())
    w = w.astype(np.float32 if single else np.float64)
    w.flags.writeable = False
    return w


@lru_cache(maxsize=16)
def _static_response(cfg: RadarConfig, doppler_window: bool) -> tuple[np.ndarray, np.ndarray]:
    """(bins int (m,), W[bins] / W[0] complex (m,)): the Doppler bins k >= 1 a slow-time
    constant reaches through the Doppler window (the window's DFT W, zero-padded to
    n_doppler; :data:`RESPONSE_FLOOR`) and its response there relative to bin 0. A
    periodic Hann over an unpadded axis: bins 1 and n_doppler - 1, ratio -1/2."""
    w = fft_axes(cfg, True, doppler_window)[1].window()
    ratio = np.fft.fft(w, cfg.n_doppler) / w.sum()
    bins = np.flatnonzero(np.abs(ratio) > RESPONSE_FLOOR)
    bins = bins[bins > 0]
    out = (bins, ratio[bins])
    for a in out:
        a.flags.writeable = False
    return out


@lru_cache(maxsize=16)
def static_noise_gain(cfg: RadarConfig, doppler_window: bool) -> np.ndarray:
    """float (n_doppler,): the noise power of each Doppler bin after static-clutter removal
    (``frame_cube(remove_static_clutter=True)``) over its power without, for white noise:
    0 at bin 0, 1 - 2 Re(r* V[k]) / V[0] + |r|^2 at the bins :func:`_static_response`
    touches (r = W[k] / W[0], V the DFT of the squared window; 7/12 for a periodic Hann's
    bins 1 and n_doppler - 1), 1 elsewhere. A CFAR on such a cube must not take the touched
    bins for plain noise (``host.pipeline.detect_cells``)."""
    w = fft_axes(cfg, True, doppler_window)[1].window()
    v = np.fft.fft(w * w, cfg.n_doppler)
    bins, ratio = _static_response(cfg, doppler_window)
    gain = np.ones(cfg.n_doppler)
    gain[0] = 0.0
    gain[bins] = 1.0 - 2.0 * np.real(np.conj(ratio) * v[bins]) / v[0].real + np.abs(ratio) ** 2
    gain.flags.writeable = False
    return gain


@njit()
def _weighted(x: np.ndarray, w: np.ndarray, out: np.ndarray) -> None:
    """out[t, r, l, s] = x[l, t, r, s] w[l, s] for a complex frame x (loops, tx, rx,
    samples), real weights w (loops, samples), into complex out (tx, rx, loops, samples):
    numpy's complex product with w + 0j, (a c - b 0) + (a 0 + b c) j in the wider of the
    two precisions, then out's (the same values as ``np.multiply``, signed zeros too), in
    one pass (numpy's broadcast over the transposed output took 2.5 times as long)."""
    nl, nt, nr, ns = x.shape
    zero = w.dtype.type(0.0)
    for t in range(nt):
        for r in range(nr):
            for m in range(nl):
                for s in range(ns):
                    v = x[m, t, r, s]
                    c = w[m, s]
                    out[t, r, m, s] = complex(v.real * c - v.imag * zero,
                                              v.real * zero + v.imag * c)


@warm_up
def _warm_up() -> None:
    """The weighting of complex frames, complex64 and complex128, in single and double
    precision (``radar process``: complex64 in single; the float sources: double)."""
    for x in (np.zeros((1, 1, 1, 2), np.complex64), np.zeros((1, 1, 1, 2), np.complex128)):
        for w, kind in ((np.zeros((1, 2), np.float32), np.complex64),
                        (np.zeros((1, 2)), np.complex128)):
            _weighted(x, w, np.empty((1, 1, 1, 2), kind))


def frame_cube(adc: np.ndarray, cfg: RadarConfig, range_window: bool = True,
               doppler_window: bool = True, remove_static_clutter: bool = False,
               single: bool = False) -> np.ndarray:
    """``model.reference.radar_cube`` computed in fewer passes (module docstring).

    adc: complex, or real for a real ADC, (n_chirps, num_rx, n_samples) -> complex128
    (n_virtual, n_range_bins, n_doppler), equal to the reference's to float64 rounding
    (with ``remove_static_clutter`` the zero-Doppler bin is exactly 0); not C-contiguous
    (per channel, its Doppler bins' rows of range bins in memory). ``single``: computed in
    single precision, complex64 (:data:`SINGLE_RTOL`).
    """
    check_frame(adc, cfg)
    w = _weights(cfg, range_window, doppler_window, single)
    x = np.asarray(adc).reshape(cfg.n_loops, cfg.num_tx, cfg.num_rx, cfg.n_samples)
    if cfg.tx_sequence != tuple(range(cfg.num_tx)):
        x = x[:, tx_slots(cfg)]                 # slot of each TX index
    real = cfg.adc == "real"
    y = np.empty((cfg.num_tx, cfg.num_rx, cfg.n_loops, cfg.n_samples),
                 (np.float32 if real else np.complex64) if single else
                 (np.float64 if real else np.complex128))
    if x.dtype in (np.complex64, np.complex128):
        _weighted(x, w, y)                          # (tx, rx, loops, samples)
    else:                                           # real samples (a real ADC's)
        np.multiply(x.transpose(1, 2, 0, 3), w, out=y)
    if real:
        y = scipy.fft.rfft(y, n=cfg.n_range, axis=3)[..., :cfg.n_range_bins]
        y = scipy.fft.fft(y, n=cfg.n_doppler, axis=2, overwrite_x=True)
    else:
        y = scipy.fft.fft2(y, s=(cfg.n_doppler, cfg.n_range), axes=(2, 3), overwrite_x=True)
    if remove_static_clutter:
        bins, ratio = _static_response(cfg, doppler_window)
        y[:, :, bins] -= y[:, :, :1] * ratio.astype(y.dtype)[:, None]
        y[:, :, 0] = 0.0
    # (tx, rx, Doppler, range) -> the cube's axes, a view: no corner-turn copy
    return y.transpose(0, 1, 3, 2).reshape(cfg.cube_shape)
