"""Oracles of ``host.cfar``'s compiled kernels: the numpy implementations they replaced,
kept only to test the kernels against: the CA-CFAR training sums (the map padded by the
window's half extent, then separable sums of shifted views; ``tests/test_cfar_training_sum.py``)
and the OS-CFAR (``host._cfar_os``; ``tests/test_cfar_os.py``)."""

from __future__ import annotations

import numpy as np
from scipy import stats

from host.cfar import CfarParams, _kernel, os_factor


def _pad(power: np.ndarray, params: CfarParams, mirrored: bool = False) -> np.ndarray:
    """``power`` (float (n_range, n_doppler)) padded by the CFAR window's half extent,
    circularly on both axes (``mirrored``: the range axis reflected at both ends, a real
    ADC's), by ``np.pad`` (what ``host._cfar_os.os_pad`` gathers)."""
    (gr, gd), (tr, td) = params.guard, params.train
    out = np.pad(power, ((gr + tr, gr + tr), (0, 0)), mode="reflect" if mirrored else "wrap")
    return np.pad(out, ((0, 0), (gd + td, gd + td)), mode="wrap")


def _shifted_sum(x: np.ndarray, offsets: range | list[int], axis: int, pad: int,
                 n: int) -> np.ndarray:
    """Sum over ``offsets`` (cells from the centre, |offset| <= ``pad``) of ``x`` shifted
    along ``axis``, whose ``pad`` cells each side pad ``n`` centre cells: that axis comes
    out n long (float (.., n, ..))."""
    def view(o: int) -> np.ndarray:
        sl = [slice(None)] * x.ndim
        sl[axis] = slice(pad + o, pad + o + n)
        return x[tuple(sl)]

    out = view(offsets[0]).copy()
    for o in offsets[1:]:
        out += view(o)
    return out


def training_sum_reference(power: np.ndarray, params: CfarParams, mirrored: bool = False
                           ) -> np.ndarray:
    """Sum over each cell's CFAR training cells of ``power`` (float (n_range, n_doppler)),
    float64 of that shape: training rows of the full Doppler extent plus guard rows of the
    Doppler training cells only, on the map padded by :func:`_pad`."""
    padded = _pad(np.asarray(power, np.float64), params, mirrored)
    (gr, gd), (tr, td) = params.guard, params.train
    pr, pd = gr + tr, gd + td
    nr, nd = padded.shape[0] - 2 * pr, padded.shape[1] - 2 * pd
    outer_d = [*range(-pd, -gd), *range(gd + 1, pd + 1)]
    side = _shifted_sum(padded, outer_d, 1, pd, nd)                 # Doppler training cells
    full = side + _shifted_sum(padded, range(-gd, gd + 1), 1, pd, nd)
    outer_r = [*range(-pr, -gr), *range(gr + 1, pr + 1)]
    return _shifted_sum(full, outer_r, 0, pr, nr) + _shifted_sum(side, range(-gr, gr + 1),
                                                                  0, pr, nr)


def os_threshold_reference(power: np.ndarray, n_channels: int, params: CfarParams,
                           mirrored: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """``host.cfar.cfar_threshold``'s OS-CFAR (threshold, noise), float64 (n_range,
    n_doppler) each, as numpy computed it before ``host._cfar_os``: every cell's training
    cells as a strided view of the padded map, ``np.partition`` for the k-th smallest."""
    kernel = _kernel(params)
    n_train = int(kernel.sum())
    padded = _pad(power.astype(np.float64), params, mirrored)
    # ordered statistic over the training cells
    win = np.lib.stride_tricks.sliding_window_view(padded, kernel.shape)
    cells = win.reshape(*win.shape[:2], -1)[..., kernel.ravel() > 0]
    k = max(1, min(n_train, int(round(params.os_rank * n_train))))
    kth = np.partition(cells, k - 1, axis=-1)[..., k - 1]
    alpha = os_factor(params.pfa, n_channels, n_train, k)
    # E[k-th of c] ~ theta * ppf(k / (c + 1)); mean noise power per cell = L * theta
    return alpha * kth, kth * n_channels / stats.gamma(n_channels).ppf(k / (n_train + 1))
