"""Progress watchdog of the block testbenches (issue 33): a design that stops its stream
fails its test within a few thousand clocks, instead of simulating until the 50 ms
simulated-time watchdog of ``rtlsim.toolchain`` (minutes to a quarter of an hour of wall
time per test, where a mutation campaign spends most of its time on hangs).

Three kinds of rule (docs/verification.md, "Watchdogs that fail fast"):

- ``stuck``: no beat on either interface for that many clocks, whatever the testbench does
  (it must exceed the longest pause the tests make);
- ``latency``: the block's documented latency, in clocks; the limit is :data:`MARGIN` times
  it, counted only over the clocks the block alone is to blame for (its sink is not holding
  an offered beat), so the testbench's stall patterns never add to it. The input port fails
  when TVALID waits without TREADY and nothing moves; with ``frame``, the output port fails
  when a whole input frame has been taken and the block gives no beat of its answer;
- ``frame`` / ``most`` (beats per frame in and out): the output port fails at once when it
  gives more beats than the input frames begun allow (a block that repeats its output for
  ever, which moves beats and so passes the other limits).

For a block that drops frames by design while it is held up (``radar_pipeline``: its ADC
input never waits, the chirp ping-pong drops), ``start``, ``stalls`` and ``lossy`` adapt the
output rules: frames counted from a frame start, other ports' stalls are the testbench's too,
and frames owed when the output was last held up are forgiven.

Imported by cocotb testbenches only (it awaits cocotb triggers).
"""

from __future__ import annotations

from collections.abc import Sequence

import cocotb
from cocotb.triggers import RisingEdge

from model.fft_axis import multipliers_per_lane

MARGIN = 4
"""A ``latency`` limit is this many times the block's documented latency: a block that works
is silent at most one latency (a frame's tail, its pipeline), one that stopped for good fails
within seconds of wall time."""


def watch(tb, stuck: int | None = None, conserving: bool = False, *,
          latency: int | None = None, frame: tuple[int, int] | None = None,
          most: tuple[int, int] | None = None, start: bool = False,
          stalls: Sequence[str] = (), lossy: bool = False) -> None:
    """Start the watchdog of ``tb`` (an ``rtlsim.axis.AxisTB``); every rule is off unless
    its argument is given, and every count restarts in reset.

    ``stuck``: the test fails when no beat has moved on either interface for ``stuck``
    consecutive clocks (a block that stops taking input, or takes it and never answers);
    ``stuck`` must exceed the longest silence a passing test makes (its stall patterns'
    longest pause, its quiet waits at the end).

    ``latency`` (clocks, the block's documented latency): the input port fails when, for
    ``MARGIN * latency`` consecutive clocks, its TVALID is high without TREADY, no beat
    moves and the sink is not holding an offered beat (TVALID without TREADY on the output
    is the testbench's stall, not the block's). With ``frame = (beats in, beats out)`` of one
    frame, the output port fails when the block owes an answer (more input frames taken
    whole than output frames given) and gives no output beat for ``MARGIN * latency``
    consecutive clocks in which its sink is not holding an offered beat.

    ``frame``, or ``most = (beats in, most beats out)`` of one frame where the output per
    frame varies (words dropped, run-time packet lengths): the test fails at once when the
    output exceeds that many beats per input frame begun.

    ``conserving``: the block never emits more beats than it took (it may drop, never
    create), so output beyond the input fails at once (a block that repeats its output for
    ever).

    ``start``: input beats count only from the first beat with TUSER[0] (frame start) after
    reset on (a source that keeps streaming through a reset enters mid-frame, and the block
    discards up to the next frame start). ``stalls``: handshake prefixes of other ports
    whose sink is the testbench (``m_axi_mem_aw`` for ``m_axi_mem_awvalid`` /
    ``awready``): their VALID without READY holds the block up as the output's sink does.
    ``lossy``: the block drops frames by design while it is held up, so every such clock
    forgives the frames owed so far (the owed rule counts frames taken from then on against
    the beats given from then on)."""
    cocotb.start_soon(_watch(tb, stuck, conserving, latency, frame, most or frame, start,
                             stalls, lossy))


async def _watch(tb, stuck: int | None, conserving: bool, latency: int | None,
                 frame: tuple[int, int] | None, most: tuple[int, int] | None, start: bool,
                 stalls: Sequence[str], lossy: bool) -> None:
    d = tb.dut
    inp, out = tb._in_prefix, tb._out_prefix
    s_valid, s_ready, m_valid, m_ready = (
        getattr(d, f"{prefix}_{name}") for prefix, name in (
            (inp, "tvalid"), (inp, "tready"), (out, "tvalid"), (out, "tready")))
    sof = getattr(d, f"{inp}_tuser") if start else None
    others = [(getattr(d, f"{p}valid"), getattr(d, f"{p}ready")) for p in stalls]
    limit = MARGIN * latency if latency is not None else None
    why = f"{MARGIN} x the block's latency of {latency} clocks"
    still = waiting = owing = beats_in = beats_out = forgiven_in = forgiven_out = 0
    aligned = not start
    while True:
        await RisingEdge(d.clk)
        if d.rst.value == 1:
            still = waiting = owing = beats_in = beats_out = forgiven_in = forgiven_out = 0
            aligned = not start
            continue
        offered = s_valid.value == 1
        took = offered and s_ready.value == 1
        held = (m_valid.value == 1 and m_ready.value == 0) or any(
            v.value == 1 and r.value == 0 for v, r in others)
        gave = m_valid.value == 1 and m_ready.value == 1
        aligned = aligned or (took and int(sof.value) & 1 == 1)
        beats_in += took and aligned
        beats_out += gave
        if conserving and beats_out > beats_in:
            raise AssertionError(f"{beats_out} beats out of {beats_in} in: output created")
        if most is not None and beats_out > -(-beats_in // most[0]) * most[1]:
            raise AssertionError(
                f"{out} runs away: {beats_out} beats out of {beats_in} in, more than "
                f"{most[1]} per {most[0]} taken")
        still = 0 if took or gave else still + 1
        if stuck is not None and still >= stuck:
            raise AssertionError(f"stream stopped: no beat moved for {stuck} clocks")
        if limit is None:
            continue
        waiting = waiting + 1 if offered and not took and not gave and not held else 0
        if waiting >= limit:
            raise AssertionError(
                f"{inp} stalled: TVALID high without TREADY for {limit} clocks, no beat "
                f"moved and {out} not held by its sink ({why})")
        if frame is None:
            continue
        if lossy and held:
            forgiven_in, forgiven_out = beats_in // frame[0], beats_out
        taken = beats_in // frame[0] - forgiven_in
        answered = (beats_out - forgiven_out) // frame[1]
        owing = owing + 1 if taken > answered and not gave and not held else 0
        if owing >= limit:
            raise AssertionError(
                f"{out} stalled: no output beat for {limit} clocks with its sink not holding "
                f"one, while {taken} input frames were taken and {answered} answered"
                f"{' (those owed when it was last held up forgiven)' if lossy else ''} "
                f"({why})")


# ---- documented latencies of the blocks whose testbenches share them -------------------------
NCI_LATENCY = 4
"""Clocks from an input word to its cell's sum (docs/detect.md, nci: "Pipeline (4 clocks)")."""

CFAR_PIPELINE = 10
"""Clocks from a column read to the decision (docs/detect.md, cfar_2d)."""


def packetizer_latency(packet_words: int) -> int:
    """Clocks from a packet's first payload word into ``axis_packetizer`` to its header out
    (docs/buffers.md 3): the packet is held whole, PACKET_WORDS + 2."""
    return packet_words + 2


def cfar_latency(c) -> int:
    """Clocks from a frame's last cell into ``cfar_2d`` (``c`` a ``model.cfar_2d.Cfar2dConfig``)
    to its last cell out (docs/detect.md, cfar_2d's streaming schedule): the PR+1 passes
    without input that test the frame's last rows, N_DOPPLER + 2 PD steps each (the Doppler
    wrap), then :data:`CFAR_PIPELINE`."""
    return (c.pr + 1) * (c.n_doppler + 2 * c.pd) + CFAR_PIPELINE


def fft_latency(n: int, window: bool) -> int:
    """Clocks from the first sample of an ``n``-point ``fft_axis`` frame in to its first bin
    out (docs/fft_axis.md, "Latency and throughput"): 2N + 2L + 5M + 3, +3 with the window,
    L = log2 N butterfly stages, M the twiddle multipliers of one lane
    (``model.fft_axis.multipliers_per_lane``); the 3 includes the input buffer's clock."""
    stages = n.bit_length() - 1
    return 2 * n + 2 * stages + 5 * multipliers_per_lane(n) + 3 + 3 * int(window)
