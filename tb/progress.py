"""Progress watchdog of the block testbenches (issue 33): a design that stops its stream
fails its test within a few thousand clocks, instead of simulating until the 50 ms
simulated-time watchdog of ``rtlsim.toolchain`` (minutes to a quarter of an hour of wall
time per test, where a mutation campaign spends most of its time on hangs).

Imported by cocotb testbenches only (it awaits cocotb triggers).
"""

from __future__ import annotations

import cocotb
from cocotb.triggers import RisingEdge


def watch(tb, stuck: int, conserving: bool = False) -> None:
    """Start the watchdog of ``tb`` (an ``rtlsim.axis.AxisTB``): when no beat has moved on
    either interface for ``stuck`` consecutive clocks out of reset, the test fails (a block
    that stops taking input, or takes it and never answers). ``stuck`` must exceed the
    longest silence a passing test makes: its stall patterns' longest pause (a paused
    source, a stalled sink), its quiet waits at the end. ``conserving``: the block never
    emits more beats than it took (it may drop, never create), so output beyond the input
    fails at once (a block that repeats its output for ever)."""
    cocotb.start_soon(_watch(tb, stuck, conserving))


async def _watch(tb, stuck: int, conserving: bool) -> None:
    d = tb.dut
    s_valid, s_ready, m_valid, m_ready = (
        getattr(d, f"{prefix}_{name}") for prefix, name in (
            (tb._in_prefix, "tvalid"), (tb._in_prefix, "tready"),
            (tb._out_prefix, "tvalid"), (tb._out_prefix, "tready")))
    still = beats_in = beats_out = 0
    while True:
        await RisingEdge(d.clk)
        took = s_valid.value == 1 and s_ready.value == 1
        gave = m_valid.value == 1 and m_ready.value == 1
        beats_in += took
        beats_out += gave
        if conserving and beats_out > beats_in:
            raise AssertionError(f"{beats_out} beats out of {beats_in} in: output created")
        still = 0 if d.rst.value == 1 or took or gave else still + 1
        if still >= stuck:
            raise AssertionError(f"stream stopped: no beat moved for {stuck} clocks")
