"""Smoke tests of the detection benchmark's host-time tables (``benchmarks.bench_detect``): each
runs on a small frame and gives consistent numbers (the timings themselves are reported by
the benchmark, never asserted)."""

from __future__ import annotations

from benchmarks.bench_detect import (
    NESTED,
    STAGES,
    host_time_rows,
    link_rows,
    spread_ms,
    stage_rows,
)
from host import angle, points


def test_host_time_rows_times_each_step() -> None:
    dec, cloud, both, points = host_time_rows("full", 10, repeat=1)
    assert points == 10
    for cpu, wall in (dec, cloud, both):
        assert cpu > 0 and wall > 0


def test_stage_rows_add_up_to_at_most_the_total() -> None:
    rows = stage_rows("full", 10, repeat=1, varied=True)
    assert set(rows) <= {*STAGES, "total"} and "peak_powers" in rows
    parts = sum(v for k, v in rows.items() if k not in ("total", *NESTED))
    assert 0 < parts <= rows["total"]
    assert points.peak_powers is angle.peak_powers   # the timers are removed


def test_spread_is_ordered() -> None:
    best, median, p90 = spread_ms("full", 10, runs=5, varied=False, unfold=True)
    assert 0 < best <= median <= p90


def test_link_rows_grow_with_the_detections() -> None:
    rows = link_rows("full", (10, 100))
    assert rows[0][0].startswith("radar cube")
    sizes = [b for _, b, _ in rows[1:]]
    assert sizes == sorted(sizes) and len(sizes) == 2
