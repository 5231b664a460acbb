"""Oracle of ``host.cfar``'s compiled CA-CFAR training sums: the numpy implementation it
replaced (the map padded by the window's half extent, then separable sums of shifted
views), kept only to test the kernel against (``tests/test_cfar_training_sum.py``)."""

from __future__ import annotations

import numpy as np

from host.cfar import CfarParams, _pad


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
    Doppler training cells only, on the map padded by ``host.cfar._pad``."""
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
