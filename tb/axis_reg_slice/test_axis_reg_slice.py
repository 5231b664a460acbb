"""cocotb testbench of ``rtl/common/axis_reg_slice.sv`` against ``model/axis_reg_slice.py``.

``cycle_exact``: a rule-abiding random source (TVALID held until taken, payload stable) and a
random sink, in phases from always-ready to mostly stalled, with resets in mid-stream (also
while both registers are full); TREADY, TVALID and the output payload are compared with the
model on every clock, and full rate is required while the sink is always ready.
``frames``: back-to-back TLAST frames with TUSER through cocotbext-axi with random and bursty
gaps and stalls, received bit-exact; a reset in mid-frame, then clean frames again; a word
offered during the reset is not taken (it would be lost with the reset).
"""

from __future__ import annotations

from pathlib import Path

import cocotb
import numpy as np
import pytest
from cocotb.clock import Clock
from cocotb.triggers import ReadOnly, RisingEdge, with_timeout

from model.axis_reg_slice import LATENCY, AxisRegSlice
from rtlsim.axis import CLK_PERIOD_NS, AxisTB, bursty_pause, random_pause
from rtlsim.toolchain import param, rtl_sources, run_cocotb, seed

TEST_LIMIT_US = 2000


def _bits(rng: np.random.Generator, n: int) -> int:
    """A uniformly random ``n``-bit int (any ``n``)."""
    return int.from_bytes(rng.bytes((n + 7) // 8), "little") & ((1 << n) - 1)


def _word(dut) -> tuple[int, int, int]:
    return (int(dut.m_axis_tdata.value), int(dut.m_axis_tlast.value),
            int(dut.m_axis_tuser.value))


@cocotb.test(timeout_time=TEST_LIMIT_US, timeout_unit="us")
async def cycle_exact(dut) -> None:
    """Every clock: (TREADY, TVALID, payload while valid) equal the model's, across random
    traffic and mid-stream resets; full rate with the sink always ready."""
    data_w, user_w = param("DATA_W"), param("USER_W")
    cocotb.start_soon(Clock(dut.clk, CLK_PERIOD_NS, unit="ns").start())  # ports driven here
    rng = np.random.default_rng(seed())
    model = AxisRegSlice()
    dut.s_axis_tvalid.value = 0
    dut.s_axis_tdata.value = 0
    dut.s_axis_tlast.value = 0
    dut.s_axis_tuser.value = 0
    dut.m_axis_tready.value = 0
    dut.rst.value = 1
    for _ in range(3):
        await RisingEdge(dut.clk)
    dut.rst.value = 0
    # phases: (P(offer a new beat), P(sink ready), clocks)
    phases = [(1.0, 1.0, 60), (0.5, 0.5, 300), (1.0, 0.2, 200), (0.2, 1.0, 100),
              (1.0, 0.0, 10), (0.0, 1.0, 10), (0.9, 0.7, 300)]
    valid, word = False, (0, 0, 0)
    full_rate_in = full_rate_out = 0
    seen = {"skid_full": 0, "skid_drain": 0, "reset_full": 0}
    cycle = 0
    for rep in range(3):
        for p_offer, p_ready, n in phases:
            for k in range(n):
                if not valid and rng.random() < p_offer:
                    valid = True
                    word = (_bits(rng, data_w), int(rng.integers(0, 2)),
                            _bits(rng, user_w))
                ready = bool(rng.random() < p_ready)
                # resets in mid-stream: at fixed points of the later repeats, and once with
                # both registers full
                rst = (rep > 0 and cycle % 211 == 50) or (rep == 2 and model.skid_valid
                                                          and seen["reset_full"] == 0)
                dut.s_axis_tvalid.value = int(valid)
                dut.s_axis_tdata.value, dut.s_axis_tlast.value, dut.s_axis_tuser.value = word
                dut.m_axis_tready.value = int(ready)
                dut.rst.value = int(rst)
                await ReadOnly()
                got_ready = int(dut.s_axis_tready.value)
                want_ready = int(model.s_ready and not rst)
                assert got_ready == want_ready, f"cycle {cycle}: TREADY {got_ready} != {want_ready}"
                assert int(dut.m_axis_tvalid.value) == int(model.m_valid), \
                    f"cycle {cycle}: TVALID {int(dut.m_axis_tvalid.value)} != {int(model.m_valid)}"
                if model.m_valid:
                    assert _word(dut) == model.m_word, \
                        f"cycle {cycle}: payload {_word(dut)} != {model.m_word}"
                taken = valid and bool(got_ready)
                if p_offer == 1.0 and p_ready == 1.0 and k >= 2 * LATENCY + 1 and not rst:
                    full_rate_in += int(taken)
                    full_rate_out += int(model.m_valid)
                seen["skid_full"] += int(model.skid_valid)
                seen["skid_drain"] += int(model.skid_valid and ready)
                seen["reset_full"] += int(rst and model.skid_valid)
                await RisingEdge(dut.clk)
                model.step(valid, word, ready, rst)
                if taken:
                    valid = False
                if rst:
                    valid = False  # the source is reset too: its beat withdrawn
                cycle += 1
    n_full = 3 * (60 - 2 * LATENCY - 1)
    assert full_rate_in == n_full and full_rate_out == n_full, \
        f"always-ready phases: {full_rate_in} in, {full_rate_out} out of {n_full} clocks"
    assert all(seen.values()), seen


def _frames(rng: np.random.Generator, n: int, lanes: int, user_w: int
            ) -> list[tuple[np.ndarray, list[int]]]:
    """``n`` frames of 1..40 beats: (uint32 words (beats, lanes), TUSER per beat)."""
    out = []
    for _ in range(n):
        beats = int(rng.integers(1, 41))
        words = rng.integers(0, 1 << 32, size=(beats, lanes), dtype=np.uint64).astype(np.uint32)
        out.append((words, [int(u) for u in rng.integers(0, 1 << user_w, size=beats)]))
    return out


async def _send_and_check(tb: AxisTB, frames, lanes: int, what: str) -> None:
    for words, user in frames:
        await tb.send_words(words, user)
    limit = 200 * sum(len(w) for w, _ in frames) + 1000
    for i, (words, user) in enumerate(frames):
        got, got_user = await tb.recv_words_user(lanes, timeout_cycles=limit)
        assert np.array_equal(got, words), f"{what}: frame {i} data differs"
        assert got_user == user, f"{what}: frame {i} TUSER differs"


@cocotb.test(timeout_time=TEST_LIMIT_US, timeout_unit="us",
             skip=param("DATA_W", 32) % 32 != 0)
async def frames(dut) -> None:
    """TLAST frames bit-exact through gaps and stalls, a mid-frame reset, a held word."""
    lanes, user_w = param("DATA_W") // 32, param("USER_W")
    tb = AxisTB(dut)
    rng = tb.rng
    await tb.reset()
    regimes = [(None, None), (random_pause(0.3, 1), random_pause(0.3, 2)),
               (random_pause(0.7, 3), None), (None, random_pause(0.8, 4)),
               (bursty_pause(5, 30), bursty_pause(6, 30))]
    for k, (idle, stall) in enumerate(regimes):
        tb.set_idle_generator(idle)
        tb.set_backpressure_generator(stall)
        await _send_and_check(tb, _frames(rng, 6, lanes, user_w), lanes, f"regime {k}")
    # a reset in mid-frame with the sink stalled (both registers full), then clean frames
    tb.set_idle_generator(None)
    tb.set_backpressure_generator(random_pause(0.6, 7))
    long = _frames(rng, 3, lanes, user_w)
    for words, user in long:
        await tb.send_words(words, user)
    await tb.cycles(25)
    tb.source.clear()
    await tb.reset()
    await tb.cycles(4)
    # the frames that left whole before the reset are the first of those sent, in order
    # (the one cut by the reset never reaches the sink: it drops a partial frame)
    left = tb.drain_words(lanes)
    assert len(left) < len(long), "the reset cut no frame"
    for i, ((got, got_user), (words, user)) in enumerate(zip(left, long[:len(left)], strict=True)):
        assert np.array_equal(got, words) and got_user == user, f"before the reset: frame {i}"
    await _send_and_check(tb, _frames(rng, 6, lanes, user_w), lanes, "after the reset")
    # a source outside the reset: its word must wait for the reset's end, then arrive
    tb.set_backpressure_generator(None)
    word = rng.integers(0, 1 << 32, size=lanes, dtype=np.uint64).astype(np.uint32)
    await tb.hold_word_through_reset(word, tlast=True)
    got = await with_timeout(tb.recv_words(lanes), 100 * CLK_PERIOD_NS, "ns")
    assert np.array_equal(got, word[np.newaxis]), "the held word"


PARAMS = [dict(DATA_W=32, USER_W=2), dict(DATA_W=129, USER_W=1), dict(DATA_W=128, USER_W=3)]


@pytest.mark.parametrize("parameters", PARAMS, ids=lambda p: "_".join(
    f"{k}{v}" for k, v in p.items()))
def test_axis_reg_slice(parameters: dict) -> None:
    here = Path(__file__).resolve().parent
    run_cocotb("axis_reg_slice", rtl_sources("common/axis_reg_slice.sv", "common/axis_checker.sv"),
               "test_axis_reg_slice", here, parameters=parameters)
