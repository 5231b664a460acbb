"""Private backend of ``host.cfar``: the compiled peak grouping (``host.cfar.local_peaks``)
and sidelobe masking (``host.cfar.sidelobe_masked``) of detected cells, one pass over the
cells each instead of a numpy pass per neighbour (a frame has tens of cells: the passes'
overhead was most of the time). The same decisions on the same values as the numpy code
they replaced: float32 maps compared as float32, their products with the float64 sidelobe
envelopes taken in float64 (``tests/test_sidelobe_cells.py``).
"""

from __future__ import annotations

import numpy as np

from host.kernels import njit, warm_up


@njit()
def local_peak_cells(power: np.ndarray, mask: np.ndarray, size_r: int, size_d: int,
                     mirrored: bool) -> np.ndarray:
    """``host.cfar.local_peaks``: the cells of ``mask`` (bool (n_range, n_doppler)) whose
    ``power`` (float, same shape) is >= every other cell's of their (size_r, size_d)
    neighbourhood (offsets -(s // 2) .. s - s // 2 - 1; Doppler circular, range circular or,
    ``mirrored``, reflected at its ends without repeating the edge cell), int64 (n, 2) of
    (range_bin, doppler_bin) in row-major order."""
    nr, nd = power.shape
    out = np.empty((int(mask.sum()), 2), np.int64)
    n = 0
    for r0 in range(nr):
        for d0 in range(nd):
            if not mask[r0, d0]:
                continue
            p = power[r0, d0]
            keep = True
            for dr in range(-(size_r // 2), size_r - size_r // 2):
                r = r0 + dr
                if mirrored:
                    a = abs(r)
                    r = 2 * (nr - 1) - a if a > nr - 1 else a
                    r = min(max(r, 0), nr - 1)
                else:
                    r %= nr
                for dd in range(-(size_d // 2), size_d - size_d // 2):
                    if (dr or dd) and not power[r, (d0 + dd) % nd] <= p:
                        keep = False
            if keep:
                out[n, 0] = r0
                out[n, 1] = d0
                n += 1
    return out[:n]


@njit()
def _doubled(env: np.ndarray, reverse: bool) -> np.ndarray:
    """env (float64 (f,)) twice over, float64 (2 f,): element j is env[j mod f], or
    (``reverse``) env[-j mod f], so that an index stepping through a circular axis runs
    straight through it."""
    f = env.shape[0]
    out = np.empty(2 * f)
    for j in range(2 * f):
        out[j] = env[(f - j % f) % f] if reverse else env[j % f]
    return out


@njit()
def sidelobe_cells(power: np.ndarray, cells: np.ndarray, env_r: np.ndarray,
                   env_d: np.ndarray, mirrored: bool) -> np.ndarray:
    """``host.cfar.sidelobe_masked`` of cells (int (n, 2)) of ``power`` (float (n_range,
    n_doppler)): bool (n,), whether the largest of power[r', d] env_r[(r - r') mod len] over
    the cell's column (``mirrored``: also with (r + r'), the mirror image's) or of power[r,
    d'] env_d[(d - d') mod len] over its row (float64 products; a NaN among them counts as
    numpy's maximum does: it is the maximum) exceeds the cell's power; env_r, env_d:
    float64 envelopes times the margin, at least as long as the map's axes. The largest
    exceeds p exactly when no product is NaN and one exceeds p: two flags per column and
    row (they vectorise), with the envelopes doubled (:func:`_doubled`) so that their
    circular index runs straight."""
    nr, nd = power.shape
    fr, fd = env_r.shape[0], env_d.shape[0]
    if nr > fr or nd > fd:
        raise ValueError("sidelobe_cells: an envelope shorter than the map's axis")
    er = _doubled(env_r, True)              # er[q - r + fr] = env_r[(r - q) mod fr]
    em = _doubled(env_r, False)             # em[r + q] = env_r[(r + q) mod fr]
    ed = _doubled(env_d, True)
    out = np.zeros(cells.shape[0], np.bool_)
    for i in range(cells.shape[0]):
        r, d = cells[i, 0], cells[i, 1]
        p = np.float64(power[r, d])
        above = False
        nan = False
        col = power[:, d]
        o = fr - r % fr
        for q in range(nr):
            v = np.float64(col[q]) * er[o + q]
            above |= v > p
            nan |= v != v
        if mirrored:
            o = r % fr
            for q in range(nr):
                w = np.float64(col[q]) * em[o + q]
                above |= w > p
                nan |= w != w
        masked = above and not nan
        above = False
        nan = False
        row = power[r]
        o = fd - d % fd
        for q in range(nd):
            v = np.float64(row[q]) * ed[o + q]
            above |= v > p
            nan |= v != v
        out[i] = masked or (above and not nan)
    return out


@warm_up
def _warm_up() -> None:
    """Both kernels (reached only by a cube's detections, not by the FPGA detector's
    records) on a tiny map: float32 in Fortran order (a cube's map) and float64."""
    for power in (np.zeros((4, 4), np.float32, order="F"), np.zeros((4, 4))):
        cells = local_peak_cells(power, np.ones((4, 4), np.bool_), 3, 3, False)
        sidelobe_cells(power, cells, np.zeros(4), np.zeros(4), False)
