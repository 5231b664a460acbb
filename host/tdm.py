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

from host.kernels import njit
from model.array import tx_slots
from model.config import RadarConfig
from model.reference import signed_bin


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
    k = np.asarray(k)
    k = np.where(k >= cfg.n_doppler // 2, k - cfg.num_tx * cfg.n_doppler, k)
    k = signed_bin(k, cfg.n_doppler)
    n = cfg.n_doppler * cfg.num_tx
    m = np.multiply.outer(k, _slots(cfg))
    return _unit_circle(n)[m & (n - 1) if n & (n - 1) == 0 else m % n]   # & : mod 2^b


def alias_orders(cfg: RadarConfig, velocity_mps: np.ndarray, max_speed_mps: float
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The velocity hypotheses of every cell: alias orders m with |v + 2 m max_velocity| <=
    max_speed_mps, as (lo, hi) int (n,), the range lo..hi of each cell (empty when lo > hi:
    the cell then takes m = 0), and ms int (h,), every order any cell may take, and 0.
    velocity_mps: float (n,) measured (aliased)."""
    v = np.asarray(velocity_mps, dtype=float)
    period = 2.0 * cfg.max_velocity_mps
    lo = np.ceil((-max_speed_mps - v) / period).astype(np.int64)
    hi = np.floor((max_speed_mps - v) / period).astype(np.int64)
    ms = np.arange(int(min(lo.min(initial=0), 0)), int(max(hi.max(initial=0), 0)) + 1)
    return lo, hi, ms


def hypothesis_classes(cfg: RadarConfig, velocity_mps: np.ndarray, max_speed_mps: float
                       ) -> np.ndarray:
    """Alias classes c = m mod num_tx that hold a velocity hypothesis m of each cell
    (:func:`alias_orders`; m = 0 when none is), bool (n, num_tx); velocity_mps: float (n,)
    measured (aliased). Only these classes' powers enter :func:`choose_folds`."""
    lo, hi, _ = alias_orders(cfg, velocity_mps, max_speed_mps)
    count = hi - lo + 1                        # consecutive orders lo..hi (none: m = 0)
    first = np.where(count > 0, lo, 0)
    count = np.maximum(count, 1)
    c = np.arange(cfg.num_tx)
    # class c holds an order of lo..hi when the first one at or after lo is within it
    return (c[None, :] - first[:, None]) % cfg.num_tx < count[:, None]


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
