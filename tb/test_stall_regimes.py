"""Unit test of tb/stall_regimes.py (plain pytest, no simulator): the CI pairs, the full
cross and the shape of each regime's pause pattern."""
from __future__ import annotations

import pytest

from tb import stall_regimes as sr


def test_stall_regimes(monkeypatch: pytest.MonkeyPatch) -> None:
    """The CI pairs use every regime once per side, STALL_CROSS=full gives all 16, and each
    generator has its regime's shape."""
    monkeypatch.delenv("STALL_CROSS", raising=False)
    ci = sr.pairs()
    assert sorted(a for a, _ in ci) == sorted(sr.REGIMES) == sorted(b for _, b in ci)
    monkeypatch.setenv("STALL_CROSS", "full")
    assert len(set(sr.pairs())) == 16
    take = {r: [next(g) for _ in range(4000)] for r in sr.REGIMES
            for g in [sr.pause(r, seed=1, scale=10)]}
    assert not any(take["none"])
    assert 0.2 < sum(take["random"]) / 4000 < 0.4
    runs, k = [], 0          # paused runs of "long" are scale..4 x scale clocks
    for i, p in enumerate(take["long"] + [False]):
        if not p and k:
            runs.append(k)
        k = k + 1 if p else 0
        if i > 3900:
            break
    assert runs and min(runs[:-1]) >= 10 and max(runs) <= 40
    with pytest.raises(ValueError, match="unknown stall regime"):
        sr.pause("sometimes", 1, 1)
