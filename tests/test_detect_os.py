"""The on-chip detector's OS-CFAR and 3x3 local-maximum test (model/cfar_2d.py, the bit-exact
model of rtl/detect/cfar_2d.sv) against the host CFAR (host/cfar.py) and the configured Pfa
(docs/detect.md)."""

from __future__ import annotations

import numpy as np
import pytest

from host.cfar import CfarParams, cfar_threshold, local_peaks
from model import cfar_2d as cm

L = 4  # channels of the test maps (Gamma(4) noise)


def _noise(rng: np.random.Generator, shape: tuple[int, int]) -> np.ndarray:
    """Independent Gamma(L) cells, int64 (mean 1000 L)."""
    return rng.gamma(L, 1000.0, shape).astype(np.int64)


def test_os_rank_is_the_hosts() -> None:
    """k of the RTL's integer table = the host's round(os_rank * n) (half to even)."""
    for n in range(1, 3000):
        assert cm.os_rank_k(n) == max(1, min(n, round(0.75 * n))), n
    assert cm.os_rank_k(10, 250) == 2 and cm.os_rank_k(14, 250) == 4   # 2.5 -> 2, 3.5 -> 4
    assert cm.os_rank_k(3, 1) == 1


@pytest.mark.parametrize("guard,train", [((2, 2), (4, 8)), ((1, 0), (2, 3))])
def test_os_model_matches_host_os(guard: tuple[int, int], train: tuple[int, int]) -> None:
    """Same detections as host.cfar's OS-CFAR (same window, rank 0.75, Pfa) on every row
    whose window does not reach a range edge (the host wraps the range axis)."""
    rng = np.random.default_rng(3)
    p = _noise(rng, (64, 256))
    idx = rng.integers(0, p.size, 40)
    p.flat[idx] *= rng.uniform(3, 300, 40).astype(np.int64)
    cfg = cm.Cfar2dConfig(n_range=64, n_doppler=256, pow_w=34, guard=guard, train=train,
                          kind="os")
    pfa = 1e-3
    res = cm.cfar_2d(p, cfg, cm.scale_table(cfg, pfa, L))
    thr, _ = cfar_threshold(p.astype(float), L, CfarParams(pfa=pfa, guard=guard, train=train,
                                                           kind="os"))
    inner = slice(cfg.pr, cfg.n_range - cfg.pr)
    host = (p > thr)[inner]
    assert host.sum() >= 20
    assert np.array_equal(res.detect[inner], host)
    ca = cm.cfar_2d(p, cfg, cm.scale_table(cfg, pfa, L, kind="ca"), kind="ca")
    assert np.array_equal(res.train_sum, ca.train_sum) and np.array_equal(res.count, ca.count)


@pytest.mark.parametrize("pfa", [1e-2, 1e-3, 1e-4, 1e-5])
def test_os_false_alarm_rate(pfa: float) -> None:
    """Noise maps through the model: the measured false-alarm rate of the on-chip OS-CFAR
    (every row, the range ends with their own k and factor) is within 2x of the configured
    one (about 30 expected false alarms per Pfa)."""
    rng = np.random.default_rng(int(-np.log10(pfa)))
    cfg = cm.Cfar2dConfig(n_range=1024, n_doppler=512, pow_w=34, kind="os")
    scale = cm.scale_table(cfg, pfa, L)
    n_maps = max(1, int(np.ceil(30 / pfa / (cfg.n_range * cfg.n_doppler))))
    hits = sum(int(cm.os_detect(_noise(rng, (cfg.n_range, cfg.n_doppler)), cfg, scale).sum())
               for _ in range(n_maps))      # cfar_2d's decisions (no reporting rule here)
    measured = hits / (n_maps * cfg.n_range * cfg.n_doppler)
    print(f"Pfa {pfa:g}: measured {measured:.3g} ({hits} in {n_maps} maps)")
    assert 0.5 < measured / pfa < 2.0, (measured, pfa)


def test_run_time_kind_and_local_max() -> None:
    """cfg_kind picks the kind among those built (OS without OS_BUILD runs the default
    kind); the local maximum keeps exactly host.cfar.local_peaks' cells of the detections
    (rows 0 and n-1 aside: the host's range axis is circular, detection_bins never reports
    them)."""
    rng = np.random.default_rng(5)
    p = _noise(rng, (32, 64))
    p[rng.integers(0, 32, 30), rng.integers(0, 64, 30)] *= 50
    p[10, 10] = p[10, 11] = 900_000          # a tie: both are local maxima
    go = cm.Cfar2dConfig(n_range=32, n_doppler=64, pow_w=34, guard=(1, 1), train=(2, 4),
                         kind="go")
    assert go.run_kind("os") == "go" and go.run_kind(None) == "go"
    both = cm.Cfar2dConfig(n_range=32, n_doppler=64, pow_w=34, guard=(1, 1), train=(2, 4),
                           os=True)
    assert both.run_kind("os") == "os" and both.hdl_parameters()["OS_BUILD"] == 1
    for kind in cm.KINDS:
        scale = cm.scale_table(both, 1e-2, L, kind=kind)
        plain = cm.cfar_2d(p, both, scale, kind)
        grouped = cm.cfar_2d(p, both, scale, kind, local_max=True)
        want = np.zeros_like(plain.detect)
        cells = local_peaks(p.astype(float), plain.detect)
        want[cells[:, 0], cells[:, 1]] = True
        assert np.array_equal(grouped.detect[1:-1], want[1:-1]), kind
        assert grouped.detect.sum() < plain.detect.sum()
        assert grouped.detect[10, 10] == plain.detect[10, 10] and grouped.detect[10, 10]
