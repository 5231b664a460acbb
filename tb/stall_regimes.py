"""Stall regimes crossed with each block's testbench (issue 16 item 4, after taxi's
``cycle_pause`` x parameter-set cross): one place that names the regimes, builds their
TVALID-gap / TREADY-backpressure generators, chooses which (input, output) pairs run, and
drives the two reset cases every streaming block must survive.

Regimes (one ``Iterator[bool]`` each, True = pause this clock):

- ``none``:   never pause (full rate);
- ``random``: each clock paused with probability 0.3 (short, frequent stalls);
- ``bursty``: alternating runs of 1..``scale`` clocks, paused 40 % of the runs;
- ``long``:   paused for ``scale``..4 x ``scale`` clocks, then 1..``scale`` clocks free
  (buffers fill completely; ``scale`` is a frame-sized number of the block, e.g. a chirp).

Which pairs run: ``STALL_CROSS=full`` (``make test-stall``) runs all 16 (input, output)
pairs; otherwise (``make test``) the fixed subset :data:`CI_PAIRS` (4 pairs: every regime
once on each side). The parameter corners are the testbench's own ``PARAMS`` (pytest
builds each), so the cross is regimes x pairs x corners.

Imported by cocotb testbenches only (the reset helpers await cocotb triggers).
"""

from __future__ import annotations

import itertools
import os
import random
from collections.abc import Awaitable, Callable, Iterator

REGIMES = ("none", "random", "bursty", "long")
CI_PAIRS = (("none", "none"), ("random", "bursty"), ("bursty", "long"), ("long", "random"))
"""(input regime, output regime) pairs of the default regression: each regime once per side."""


def pause(regime: str, seed: int, scale: int) -> Iterator[bool]:
    """Pause generator of ``regime`` (see the module docstring); ``scale`` in clocks (>= 1)."""
    rng = random.Random(seed)
    scale = max(1, int(scale))
    if regime == "none":
        return itertools.repeat(False)
    if regime == "random":
        return (rng.random() < 0.3 for _ in itertools.count())
    if regime == "bursty":
        def bursty() -> Iterator[bool]:
            while True:
                paused = rng.random() < 0.4
                yield from [paused] * rng.randint(1, scale)
        return bursty()
    if regime == "long":
        def long() -> Iterator[bool]:
            while True:
                yield from [True] * rng.randint(scale, 4 * scale)
                yield from [False] * rng.randint(1, scale)
        return long()
    raise ValueError(f"unknown stall regime {regime!r}, expected one of {REGIMES}")


def full_cross() -> bool:
    """True when ``STALL_CROSS=full`` asks for every (input, output) pair."""
    return os.environ.get("STALL_CROSS", "") == "full"


def pairs() -> list[tuple[str, str]]:
    """(input regime, output regime) pairs to run: all 16 or :data:`CI_PAIRS`."""
    if full_cross():
        return list(itertools.product(REGIMES, REGIMES))
    return list(CI_PAIRS)


def apply(tb, pair: tuple[str, str], seed: int, scale: int) -> None:
    """Set ``tb``'s (an ``rtlsim.axis.AxisTB``) idle and backpressure generators."""
    tb.set_idle_generator(pause(pair[0], 2 * seed, scale))
    tb.set_backpressure_generator(pause(pair[1], 2 * seed + 1, scale))


async def run_cross(tb, scale: int, run: Callable[[tuple[str, str], int], Awaitable[None]]
                    ) -> None:
    """For each pair of :func:`pairs`: set the generators and await ``run(pair, k)`` (which
    sends and checks its frames against the model); logs the pairs run."""
    done = []
    for k, pair in enumerate(pairs()):
        apply(tb, pair, seed=100 + k, scale=scale)
        await run(pair, k)
        done.append("/".join(pair))
    tb.log.info("stall cross (%s): %d pairs bit-exact: %s",
                "full" if full_cross() else "CI subset", len(done), ", ".join(done))


async def _flush_source(tb) -> None:
    """After the reset under test: the source's frame in flight (clear() drops only the
    queued ones) is let finish into the block, then a second reset removes that testbench
    artefact (a register the reset misses is still missed: both resets are the same)."""
    if not tb.source.idle():
        await tb.source.wait()
        await tb.reset()


async def reset_while_stalled(tb, start: Callable[[], Awaitable[None]], min_stall: int = 8
                              ) -> None:
    """Reset during backpressure: hold TREADY low, ``start()`` traffic, wait until the
    block's output has been valid and stalled for ``min_stall`` clocks, then reset (input
    queue and sink cleared). Raises AssertionError when the output never became valid."""
    from cocotb.triggers import RisingEdge

    tb.set_backpressure_generator(itertools.repeat(True))
    await start()
    stalled = 0
    for _ in range(200_000):
        await RisingEdge(tb.dut.clk)
        stalled = stalled + 1 if int(tb.dut.m_axis_tvalid.value) else 0
        if stalled >= min_stall:
            break
    assert stalled >= min_stall, "output never valid under backpressure"
    tb.source.clear()
    await tb.reset()
    tb.set_backpressure_generator(itertools.repeat(False))
    await _flush_source(tb)
    tb.sink.clear()


async def reset_while_sending(tb, start: Callable[[], Awaitable[None]], beats: int) -> None:
    """Reset during output: ``start()`` traffic with the output free, count ``beats`` output
    handshakes (mid-stream), reset on the next clock (input queue and sink cleared)."""
    from cocotb.triggers import RisingEdge

    await start()
    seen = 0
    for _ in range(200_000):
        await RisingEdge(tb.dut.clk)
        seen += int(tb.dut.m_axis_tvalid.value) & int(tb.dut.m_axis_tready.value)
        if seen >= beats:
            break
    assert seen >= beats, f"only {seen} output beats before the reset"
    tb.source.clear()
    await tb.reset()
    await _flush_source(tb)
    tb.sink.clear()
