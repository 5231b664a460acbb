"""TDM-MIMO Doppler: the per-TX phase compensation of a cell's channel vector and the
velocity-unfolding decision (``host.pipeline`` module docstring, step 3).

With num_tx chirp slots per loop, TX t transmits in slot q_t (``model.array.tx_slots``:
the firing order ``cfg.tx_sequence``), q_t slots after the loop's first chirp, so a target
of signed Doppler bin k (cycles per n_doppler same-TX chirps) has advanced k q_t /
(n_doppler num_tx) turns on TX t's channels: :func:`tx_phasors` undoes that. The measured
Doppler fixes the velocity only modulo the alias period 2 vmax; the hypotheses are the alias
orders m with |v + 2 m vmax| <= max_speed (:func:`alias_orders`). Compensation for the
wrong order blurs the angle spectrum unless the orders differ by a multiple of num_tx: the
alias *classes* c = m mod num_tx are told apart by the angle spectrum's peak power
(:func:`choose_folds`).
"""

from __future__ import annotations

from functools import lru_cache
from typing import Protocol

import numpy as np

from host.kernels import njit, warm_up
from model.array import tx_slots
from model.config import RadarConfig


class UnfoldSettings(Protocol):
    """The settings :func:`choose_folds` reads (``host.params.DetectionParams``)."""

    unfold_velocity: bool
    unfold_min_snr_db: float
    unfold_margin_db: float
    max_speed_mps: float


@lru_cache(maxsize=8)
def _unit_circle(n: int) -> np.ndarray:
    """exp(-2 pi j m / n) for m = 0..n-1, complex (n,), read-only."""
    w = np.exp(-2j * np.pi * np.arange(n) / n)
    w.flags.writeable = False
    return w


@lru_cache(maxsize=16)
def _slots(cfg: RadarConfig) -> np.ndarray:
    """``model.array.tx_slots(cfg)``, read-only, once per radar."""
    q = tx_slots(cfg)
    q.flags.writeable = False
    return q


def tx_phasors(cfg: RadarConfig, k: np.ndarray) -> np.ndarray:
    """TDM compensation phasors per TX, complex (..., num_tx), for the *unfolded* signed
    Doppler bins k (any integers, int (...)): TX t's channels are multiplied by
    exp(-2 pi j k q_t / (n_doppler num_tx)), q_t its slot in the loop
    (``model.reference.tdm_phase_compensation``'s phase, one value per TX, looked up on the
    unit circle). The phase has period num_tx n_doppler in k; k >= n_doppler / 2 is
    shifted by that period, not by n_doppler (which would undo an unfolding by +1)."""
    k = np.asarray(k, dtype=np.int64)
    out = np.empty((k.size, cfg.num_tx), np.complex128)
    _phasors(k.reshape(-1), cfg.n_doppler, _slots(cfg),
             _unit_circle(cfg.n_doppler * cfg.num_tx), out)
    return out.reshape(*k.shape, cfg.num_tx)


@njit()
def _phasors(k: np.ndarray, nd: int, slots: np.ndarray, circle: np.ndarray,
             out: np.ndarray) -> None:
    """:func:`tx_phasors` of the bins k (int64 (m,)) into out (complex128 (m, num_tx)):
    circle[k q_t mod n] with n = len(circle) = n_doppler num_tx (a mask when n is a power of
    two), slots q_t int64 (num_tx,)."""
    n = circle.shape[0]
    mask = n - 1 if n & (n - 1) == 0 else -1
    shift = n                               # num_tx n_doppler
    for i in range(k.shape[0]):
        kk = k[i]
        if kk >= nd // 2:
            kk -= shift
        if kk >= nd // 2:                   # model.reference.signed_bin
            kk -= nd
        for t in range(slots.shape[0]):
            m = kk * slots[t]
            out[i, t] = circle[m & mask if mask >= 0 else m % n]


def alias_orders(cfg: RadarConfig, velocity_mps: np.ndarray, max_speed_mps: float
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The velocity hypotheses of every cell: alias orders m with |v + 2 m max_velocity| <=
    max_speed_mps, as (lo, hi) int (n,), the range lo..hi of each cell (empty when lo > hi:
    the cell then takes m = 0), and ms int (h,), every order any cell may take, and 0.
    velocity_mps: float (n,) measured (aliased)."""
    v = np.asarray(velocity_mps, dtype=float)
    lo, hi = np.empty(v.shape, np.int64), np.empty(v.shape, np.int64)
    m_lo, m_hi = _alias_bounds(v.reshape(-1), 2.0 * cfg.max_velocity_mps, float(max_speed_mps),
                               lo.reshape(-1), hi.reshape(-1))
    return lo, hi, np.arange(m_lo, m_hi + 1)


@njit()
def _alias_bounds(v: np.ndarray, period: float, max_speed: float, lo: np.ndarray,
                  hi: np.ndarray) -> tuple[int, int]:
    """:func:`alias_orders`' lo = ceil((-max_speed - v) / period) and hi = floor((max_speed
    - v) / period) of every v (float64 (n,)) into lo, hi (int64 (n,)); returns (min(lo, 0),
    max(hi, 0))."""
    m_lo, m_hi = 0, 0
    for i in range(v.shape[0]):
        lo[i] = np.int64(np.ceil((-max_speed - v[i]) / period))
        hi[i] = np.int64(np.floor((max_speed - v[i]) / period))
        m_lo = min(m_lo, lo[i])
        m_hi = max(m_hi, hi[i])
    return m_lo, m_hi


def hypothesis_classes(cfg: RadarConfig, velocity_mps: np.ndarray, max_speed_mps: float
                       ) -> np.ndarray:
    """Alias classes c = m mod num_tx that hold a velocity hypothesis m of each cell
    (:func:`alias_orders`; m = 0 when none is), bool (n, num_tx); velocity_mps: float (n,)
    measured (aliased). Only these classes' powers enter :func:`choose_folds`."""
    lo, hi, _ = alias_orders(cfg, velocity_mps, max_speed_mps)
    out = np.empty((len(lo), cfg.num_tx), bool)
    _classes(lo, hi, out)
    return out


@njit()
def _classes(lo: np.ndarray, hi: np.ndarray, out: np.ndarray) -> None:
    """:func:`hypothesis_classes` of the orders lo..hi (int64 (n,)) into out (bool (n,
    num_tx)): class c holds an order of lo..hi (none: m = 0) when the first one at or after
    lo (0) is within them."""
    ntx = out.shape[1]
    for i in range(lo.shape[0]):
        count = hi[i] - lo[i] + 1              # consecutive orders lo..hi
        first = lo[i] if count > 0 else 0
        count = max(count, 1)
        for c in range(ntx):
            out[i, c] = (c - first) % ntx < count


def choose_folds(class_power: np.ndarray, cfg: RadarConfig, velocity_mps: np.ndarray,
                 snr_db: np.ndarray, params: UnfoldSettings) -> tuple[np.ndarray, np.ndarray]:
    """The alias order of every cell's velocity and whether it is ambiguous: (m int (n,),
    ambiguous bool (n,)). Hypotheses: :func:`alias_orders`. With num_tx > 1,
    ``unfold_velocity`` and more than one hypothesis, the TDM test keeps those of the alias
    class whose peak power in class_power (float (n, num_tx), :func:`hypothesis_classes`'
    entries; (n, 0) when the test does not run) beats every other hypothesis class's by
    ``unfold_margin_db``; a class other than 0 wins only in cells of at least
    ``unfold_min_snr_db`` (snr_db float (n,)), else class 0 (when it holds a hypothesis)
    must win by the margin. The surviving order nearest zero velocity is reported; a cell
    is ambiguous when more than one order survives or the reported one is not 0.
    velocity_mps: float (n,) measured (aliased)."""
    v = np.asarray(velocity_mps, dtype=float)
    n = len(v)
    lo, hi, ms = alias_orders(cfg, v, params.max_speed_mps)
    test = cfg.num_tx > 1 and params.unfold_velocity and class_power.shape[1] == cfg.num_tx
    fold = np.zeros(n, np.int64)
    ambiguous = np.zeros(n, bool)
    if n:
        cp = class_power if test else np.zeros((n, cfg.num_tx))
        _fold_decisions(np.ascontiguousarray(cp, dtype=float), v,
                        np.ascontiguousarray(snr_db, dtype=float), lo, hi, ms,
                        float(cfg.max_velocity_mps), bool(test),
                        float(10 ** (params.unfold_margin_db / 10)),
                        float(params.unfold_min_snr_db), fold, ambiguous)
    return fold, ambiguous


@njit()
def _beats(p: np.ndarray, best: int, margin: float) -> bool:
    """Class ``best``'s power beats every other present class's by ``margin`` (absent
    classes: -inf; none other present: True)."""
    mo = -np.inf
    for c in range(p.shape[0]):
        if c != best and p[c] > mo:
            mo = p[c]
    return mo == -np.inf or p[best] >= margin * mo


@njit()
def _fold_decisions(cp: np.ndarray, v: np.ndarray, snr: np.ndarray, lo: np.ndarray,
                    hi: np.ndarray, ms: np.ndarray, vmax: float, test: bool, margin: float,
                    min_snr: float, fold: np.ndarray, ambiguous: np.ndarray) -> None:
    """:func:`choose_folds` into fold, ambiguous (int64, bool (n,)); margin: a power
    ratio; ms sorted, 0 among them."""
    ntx = cp.shape[1]
    h = ms.shape[0]
    hyp = np.empty(h, np.bool_)
    p = np.empty(ntx)
    present = np.empty(ntx, np.bool_)
    for i in range(v.shape[0]):
        count = 0
        for k in range(h):
            hyp[k] = lo[i] <= ms[k] <= hi[i]
            count += hyp[k]
        if count == 0:                     # no order within max_speed: m = 0
            for k in range(h):
                hyp[k] = ms[k] == 0
            count = 1
        if test and count > 1:
            for c in range(ntx):
                present[c] = False
            for k in range(h):
                if hyp[k]:
                    present[ms[k] % ntx] = True
            for c in range(ntx):
                p[c] = cp[i, c] if present[c] else -np.inf
            best = 0
            for c in range(1, ntx):
                if p[c] > p[best]:
                    best = c
            beats_all = _beats(p, best, margin)
            if best != 0 and not (beats_all and snr[i] >= min_snr):
                if present[0]:             # back to the unshifted class when it holds one
                    best = 0
                beats_all = _beats(p, best, margin)
            if beats_all:
                count = 0
                for k in range(h):
                    hyp[k] = hyp[k] and ms[k] % ntx == best
                    count += hyp[k]
        kbest = -1
        dbest = np.inf
        for k in range(h):                 # the hypothesis nearest zero velocity
            if hyp[k]:
                d = abs(v[i] + 2.0 * ms[k] * vmax)
                if d < dbest:
                    dbest = d
                    kbest = k
        fold[i] = ms[kbest]
        ambiguous[i] = count > 1 or ms[kbest] != 0


@warm_up
def _warm_up() -> None:
    """The alias classes (reached only by radars of several TX) on one cell."""
    _classes(np.zeros(1, np.int64), np.zeros(1, np.int64), np.empty((1, 2), np.bool_))
