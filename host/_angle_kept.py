"""Private backend of ``host.angle``: which of the components found per row are kept, in
one compiled pass over the rows (``host.angle._kept_components``, whose numpy form, a
stable argsort and a collapse loop over the slots, cost more in call overhead than in work
on a frame's few dozen rows)."""

from __future__ import annotations

import numpy as np

from host.kernels import njit, warm_up


@njit()
def _kept(mag: np.ndarray, count: np.ndarray, s: np.ndarray, w: np.ndarray, tol_u: float,
          tol_w: float, rows: np.ndarray, comp: np.ndarray) -> int:
    """:func:`kept_slots` into rows, comp (int (m k,)); returns how many are kept."""
    m, kmax = mag.shape
    order = np.empty(kmax, np.int64)
    key = np.empty(kmax)
    kept = np.empty(kmax, np.bool_)
    out = 0
    for i in range(m):
        for q in range(kmax):           # np.argsort(where(valid, -mag, inf), stable)
            key[q] = -mag[i, q] if q < count[i] else np.inf
            p = q
            while p > 0 and key[order[p - 1]] > key[q]:
                order[p] = order[p - 1]
                p -= 1
            order[p] = q
        for p in range(kmax):
            kept[p] = order[p] < count[i]
            for u in range(p):
                apart = abs(s[i, order[p]] - s[i, order[u]]) > tol_u or \
                    abs(w[i, order[p]] - w[i, order[u]]) > tol_w
                kept[p] = kept[p] and (not kept[u] or apart)
        for p in range(kmax):
            if kept[p]:
                rows[out] = i
                comp[out] = order[p]
                out += 1
    return out


def kept_slots(mag: np.ndarray, count: np.ndarray, s: np.ndarray, w: np.ndarray | None,
               tol_u: float, tol_w: float) -> tuple[np.ndarray, np.ndarray]:
    """The kept components of every row, strongest first within a row (a stable order),
    rows in order: (row int (p,), slot int (p,)). mag float (m, k) the components'
    magnitudes |a|, the first count int (m,) slots of each row valid; s, w float (m, k) their
    direction cosines (w None: 0); a component is dropped when it is within tol_u in s and
    tol_w in w of a stronger kept one (it collapsed onto it during refinement)."""
    m, k = mag.shape
    w = np.zeros((m, k)) if w is None else np.ascontiguousarray(w, dtype=float)
    rows = np.empty(m * k, np.int64)
    comp = np.empty(m * k, np.int64)
    got = _kept(np.ascontiguousarray(mag, dtype=float), np.ascontiguousarray(count,
                dtype=np.int64), np.ascontiguousarray(s, dtype=float), w, float(tol_u),
                float(tol_w), rows, comp)
    return rows[:got], comp[:got]


@warm_up
def _warm_up() -> None:
    """The kernel (reached only by rows with several components on the ULA) on one row."""
    kept_slots(np.ones((1, 2)), np.array([2]), np.zeros((1, 2)), None, 0.1, np.inf)
