"""cocotb testbench of ``rtl/buffers/chirp_pingpong.sv`` against ``model/chirp_pingpong.py``."""

from __future__ import annotations

import itertools
from pathlib import Path

import cocotb
import numpy as np
import pytest
from cocotb.triggers import RisingEdge

from model import chirp_pingpong as cp
from rtlsim.axis import AxisTB, bursty_pause, no_pause, random_pause
from rtlsim.toolchain import param, rtl_sources, run_cocotb
from tb import progress, stall_regimes


class TB(AxisTB):
    def __init__(self, dut) -> None:
        super().__init__(dut)
        self.num_rx = param("NUM_RX")
        self.n_range = param("N_RANGE")
        self.backpressure = bool(param("ADC_BACKPRESSURE"))
        assert param("DATA_W") == 16
        # a stopped or endless stream fails at once: the longest pause here is 4 N_RANGE
        # clocks; no beat out that did not come in
        progress.watch(self, stuck=16 * self.n_range + 2000, conserving=True)

    def stream(self, n_chirps: int, chirps_per_frame: int = 16):
        """Random ADC stream of n_chirps good chirps: (words, tlast, sof)."""
        n = n_chirps * self.n_range
        words = self.rng.integers(0, 1 << 32, (n, self.num_rx), dtype=np.uint32)
        idx = np.arange(n)
        tlast = idx % self.n_range == self.n_range - 1
        sof = idx % (chirps_per_frame * self.n_range) == 0
        return words, tlast, sof

    async def start_output_stalled(self) -> bool:
        """Reset, then stall the range FFT for good (the overflow corners while the ADC
        cannot stall): False, and the test skips, when built with ADC_BACKPRESSURE=1."""
        if self.backpressure:
            self.log.info("needs ADC_BACKPRESSURE=0: skipped")
            return False
        await self.reset()
        self.set_backpressure_generator(itertools.repeat(True))    # range FFT stalled
        return True

    async def send(self, words, tlast, sof) -> None:
        """Queue the stream, one AXI frame per TLAST-delimited run."""
        ends = list(np.nonzero(tlast)[0] + 1)
        if not ends or ends[-1] != len(words):
            ends.append(len(words))
        start = 0
        for end in ends:
            await self.send_words(words[start:end], tuser=sof[start:end])
            start = end

    async def send_garbage_idle(self, words, tlast, sof) -> None:
        """Drive the input directly (cocotbext's source, idle, zeroes TLAST between beats)
        with random idle clocks whose TDATA, TLAST and TUSER are random: AXI4-Stream leaves
        them undefined while TVALID is low."""
        d = self.dut
        for word, last, first in zip(words, tlast, sof, strict=True):
            while self.rng.random() < 0.5:
                d.s_axis_tvalid.value = 0
                d.s_axis_tdata.value = int.from_bytes(self.rng.bytes(4 * self.num_rx), "little")
                d.s_axis_tlast.value = int(self.rng.integers(0, 2))
                d.s_axis_tuser.value = int(self.rng.integers(0, 2))
                await RisingEdge(d.clk)
            d.s_axis_tvalid.value = 1
            d.s_axis_tdata.value = sum(int(w) << (32 * k) for k, w in enumerate(word))
            d.s_axis_tlast.value = int(last)
            d.s_axis_tuser.value = int(first)
            await RisingEdge(d.clk)
            while d.s_axis_tready.value != 1:
                await RisingEdge(d.clk)
        d.s_axis_tvalid.value = 0

    async def drain(self, quiet: int = 64) -> list[cp.OutChirp]:
        await self.wait_quiet(quiet)
        out = []
        for w, user in self.drain_words(self.num_rx):
            assert len(w) == self.n_range, f"chirp of {len(w)} samples"
            assert all(u == 0 for u in user[1:]), "TUSER set past the first sample"
            out.append(cp.OutChirp(-1, w, bool(user[0] & 1), bool(user[0] & 2)))
        return out

    def status(self) -> dict[str, int]:
        return self.read_status((
            "status_overflow", "status_framing_error", "drop_count", "chirps_dropped",
            "framing_error_count", "chirps_out"))

    @staticmethod
    def compare(got: list[cp.OutChirp], exp: list[cp.OutChirp]) -> None:
        assert len(got) == len(exp), f"{len(got)} chirps, expected {len(exp)}"
        for i, (g, e) in enumerate(zip(got, exp, strict=True)):
            assert np.array_equal(g.words, e.words), f"chirp {i} (attempt {e.index}) differs"
            assert (g.sof, g.gap) == (e.sof, e.gap), f"chirp {i}: tuser {g} vs {e}"


@cocotb.test()
async def test_throughput(dut):
    """Back-to-back chirps at one sample per clock, never stalled: nothing dropped and one
    word per clock out (ping-pong hand-over without a bubble)."""
    tb = TB(dut)
    tb.start_meter()
    await tb.reset()
    n_chirps = max(8, 4096 // tb.n_range)
    stream = tb.stream(n_chirps)
    await tb.send(*stream)
    got = await tb.drain()
    tb.compare(got, cp.chirp_pingpong(*stream, tb.n_range))
    span = tb.out_last - tb.out_first + 1
    tb.log.info("throughput: %d words out in %d clocks = %.4f words/clock; latency first "
                "sample in -> first sample out %d clocks", tb.out_beats, span,
                tb.out_beats / span, tb.out_first - tb.in_first)
    assert span == tb.out_beats == n_chirps * tb.n_range, (span, tb.out_beats)
    st = tb.status()
    assert st["drop_count"] == 0 and st["chirps_out"] == n_chirps, st


@cocotb.test()
async def test_random_stalls(dut):
    """Random ADC gaps and range-FFT stalls the double buffer can absorb (mode 0), or any
    stalls at all (mode 1): exact chirps, nothing lost."""
    tb = TB(dut)
    await tb.reset()
    n_chirps = max(12, 3072 // tb.n_range)
    if tb.backpressure:
        tb.set_idle_generator(random_pause(0.3, 1))
        tb.set_backpressure_generator(bursty_pause(2, max_run=3 * tb.n_range,
                                                   busy_fraction=0.5))
    else:
        # a real ADC delivers at a constant rate (here half the clock); the range FFT may
        # stall now and then but has a chirp time to drain a chirp
        tb.set_idle_generator(itertools.cycle([False, True]))
        tb.set_backpressure_generator(random_pause(0.1, 4))
    stream = tb.stream(n_chirps)
    await tb.send(*stream)
    got = await tb.drain()
    tb.compare(got, cp.chirp_pingpong(*stream, tb.n_range))
    st = tb.status()
    assert st["drop_count"] == 0 and st["status_overflow"] == 0, st


@cocotb.test()
async def test_garbage_while_idle(dut):
    """Random TDATA, TLAST and TUSER on every idle clock of the ADC stream: exact chirps,
    nothing dropped, no framing error (no decision may read an idle clock's sidebands)."""
    tb = TB(dut)
    await tb.reset()
    stream = tb.stream(8)
    await tb.send_garbage_idle(*stream)
    got = await tb.drain()
    tb.compare(got, cp.chirp_pingpong(*stream, tb.n_range))
    st = tb.status()
    assert st["drop_count"] == 0 and st["framing_error_count"] == 0, st


@cocotb.test()
async def test_overflow(dut):
    """ADC cannot stall, range FFT stalls for long: whole chirps are dropped, counted and
    flagged, the next forwarded chirp carries the gap flag, forwarded chirps are exact."""
    tb = TB(dut)
    if tb.backpressure:
        tb.log.info("overflow test needs ADC_BACKPRESSURE=0: skipped")
        return
    await tb.reset()
    n_chirps = max(24, 6144 // tb.n_range)
    tb.set_idle_generator(random_pause(0.05, 5))
    tb.set_backpressure_generator(bursty_pause(6, max_run=4 * tb.n_range, busy_fraction=0.5))
    stream = tb.stream(n_chirps)
    await tb.send(*stream)
    got = await tb.drain()
    attempts, errors = cp.split_attempts(*stream, tb.n_range)
    assert errors == 0
    # forwarded chirps are a subsequence of the attempts: find which were dropped
    received, k = [], 0
    for g in got:
        while k < len(attempts) and not np.array_equal(attempts[k].words, g.words):
            k += 1
        assert k < len(attempts), "forwarded chirp matches no input chirp (mixed chirps?)"
        received.append(k)
        k += 1
    dropped = sorted(set(range(len(attempts))) - set(received))
    tb.compare(got, cp.pingpong_output(attempts, dropped))
    st = tb.status()
    tb.log.info("overflow: %d of %d chirps dropped, status %s", len(dropped), n_chirps, st)
    assert dropped, "test did not overflow"
    assert st["status_overflow"] == 1 and st["chirps_dropped"] == len(dropped), st
    assert st["drop_count"] == len(dropped) * tb.n_range, st
    assert st["chirps_out"] == len(got) and st["framing_error_count"] == 0, st


@cocotb.test()
async def test_framing(dut):
    """Early and missing TLASTs: the bad chirps are discarded, counted, the stream resyncs."""
    tb = TB(dut)
    await tb.reset()
    tb.set_idle_generator(random_pause(0.2, 7))
    tb.set_backpressure_generator(random_pause(0.2, 8) if tb.backpressure else no_pause())
    n = tb.n_range
    words, tlast, sof = tb.stream(10, chirps_per_frame=5)
    tlast = tlast.copy()
    tlast[2 * n + n // 2] = True             # chirp 2: early TLAST (2 attempts, 1 error)
    tlast[5 * n - 1] = False                 # chirp 4: missing TLAST (skips chirp 5)
    await tb.send(words, tlast, sof)
    got = await tb.drain()
    attempts, errors = cp.split_attempts(words, tlast, sof, n)
    tb.compare(got, cp.pingpong_output(attempts))
    st = tb.status()
    assert errors == 3 and st["framing_error_count"] == errors, (errors, st)
    assert st["status_framing_error"] == 1 and st["drop_count"] == 0, st
    assert st["chirps_out"] == len(got) == 7, st


@cocotb.test()
async def test_overflow_while_resynchronising(dut):
    """A missing TLAST while both banks are full (ADC cannot stall, range FFT stalled): the
    chirp without TLAST is dropped by overflow (its samples counted), the samples skipped up
    to the next TLAST are resynchronisation, not overflow, and are not counted as dropped
    (the corner where ``!skip_q`` guards the drop counter: mutant
    ``chirp_pingpong:dropfirst:7``)."""
    tb = TB(dut)
    if not await tb.start_output_stalled():
        return
    n = tb.n_range
    words, tlast, sof = tb.stream(6, chirps_per_frame=6)
    tlast = tlast.copy()
    tlast[4 * n - 1] = False      # chirp 3 (banks full): missing TLAST, skips chirp 4
    await tb.send(words[:5 * n], tlast[:5 * n], sof[:5 * n])
    await tb.source.wait()        # all sent (the output stays stalled: not quiet)
    await tb.cycles(8)
    st = tb.status()
    # chirps 0, 1 fill the banks; 2 and 3 are dropped by overflow (3 also a framing error)
    assert (st["drop_count"], st["chirps_dropped"]) == (2 * n, 2), st
    assert (st["framing_error_count"], st["status_overflow"]) == (1, 1), st
    tb.set_backpressure_generator(no_pause())
    await tb.wait_quiet()         # both banks out before chirp 5 comes
    await tb.send(words[5 * n:], tlast[5 * n:], sof[5 * n:])
    got = await tb.drain()
    attempts, errors = cp.split_attempts(words, tlast, sof, n)
    assert errors == 1 and len(attempts) == 5
    tb.compare(got, cp.pingpong_output(attempts, dropped=[2]))
    assert tb.status()["drop_count"] == 2 * n


@cocotb.test()
async def test_counters_saturate(dut):
    """The error counters, preloaded inside the DUT to 2^32 - 1, stay there through more
    overflow drops and a framing error instead of wrapping to 0 (a saturation term dropped:
    mutant chirp_pingpong:drop:10)."""
    tb = TB(dut)
    if not await tb.start_output_stalled():
        return
    top = (1 << 32) - 1
    for name in ("drop_cnt_q", "chirp_drop_q", "framing_cnt_q"):
        getattr(dut, name).value = top
    n = tb.n_range
    words, tlast, sof = tb.stream(5, chirps_per_frame=5)
    tlast = tlast.copy()
    tlast[4 * n - 1] = False      # as test_overflow_while_resynchronising: 2 chirps dropped
    await tb.send(words, tlast, sof)
    await tb.source.wait()
    await tb.cycles(8)
    st = tb.status()
    assert (st["drop_count"], st["chirps_dropped"], st["framing_error_count"]) == (top,) * 3, st


@cocotb.test()
async def test_overflow_flag_stays(dut):
    """status_overflow is sticky: a later chirp ended by an early TLAST (a framing error, not
    an overflow) leaves it set (mutant chirp_pingpong:sticky:2 clears it there)."""
    tb = TB(dut)
    if not await tb.start_output_stalled():
        return
    n = tb.n_range
    words, tlast, sof = tb.stream(3, chirps_per_frame=3)     # chirp 2 dropped: banks full
    await tb.send(words, tlast, sof)
    await tb.source.wait()
    await tb.cycles(8)
    assert tb.status()["status_overflow"] == 1, tb.status()
    tb.set_backpressure_generator(no_pause())
    await tb.wait_quiet()
    await tb.send_words(tb.stream(1)[0][:n - 1])              # TLAST on sample N_RANGE-2
    await tb.wait_quiet()
    st = tb.status()
    assert st["status_overflow"] == 1 and st["status_framing_error"] == 1, st


@cocotb.test()
async def test_reset_recovery(dut):
    """Reset in mid-chirp under stalls, then clean chirps."""
    tb = TB(dut)
    await tb.reset()
    tb.set_idle_generator(random_pause(0.2, 9))
    tb.set_backpressure_generator(bursty_pause(10, max_run=2 * tb.n_range))
    await tb.send(*tb.stream(6))
    await tb.cycles(3 * tb.n_range + tb.n_range // 2)
    tb.source.clear()
    await tb.reset()
    tb.sink.clear()
    assert all(v == 0 for v in tb.status().values()), tb.status()
    tb.set_backpressure_generator(random_pause(0.2, 11))
    tb.set_idle_generator(random_pause(0.5, 12))
    stream = tb.stream(6)
    await tb.send(*stream)
    got = await tb.drain()
    tb.compare(got, cp.chirp_pingpong(*stream, tb.n_range))


@cocotb.test()
async def test_stall_cross(dut):
    """Stall regimes crossed (tb/stall_regimes.py: CI subset, all 16 pairs with
    STALL_CROSS=full): exact chirps per pair. Only with ADC_BACKPRESSURE = 1: without it a
    long output stall drops chirps by design (test_overflow checks that path)."""
    tb = TB(dut)
    if not tb.backpressure:
        tb.log.info("stall cross: ADC_BACKPRESSURE = 0 set, skipped (drops by design)")
        return
    await tb.reset()

    async def run(pair, k):
        stream = tb.stream(6)
        await tb.send(*stream)
        got = await tb.drain(quiet=8 * tb.n_range + 64)
        tb.compare(got, cp.chirp_pingpong(*stream, tb.n_range))

    await stall_regimes.run_cross(tb, tb.n_range, run)
    st = tb.status()
    assert st["drop_count"] == 0 and st["status_overflow"] == 0, st


@cocotb.test()
async def test_reset_during_backpressure_and_output(dut):
    """Reset while the output is valid and held (TREADY low), then reset while a chirp
    flows out: counters cleared, the next chirps exact."""
    tb = TB(dut)
    await tb.reset()

    async def start():
        await tb.send(*tb.stream(4))

    for case in ("backpressure", "output"):
        tb.set_idle_generator(random_pause(0.5, 21))
        if case == "backpressure":
            await stall_regimes.reset_while_stalled(tb, start)
        else:
            await stall_regimes.reset_while_sending(tb, start, beats=tb.n_range // 2)
        assert all(v == 0 for v in tb.status().values()), (case, tb.status())
        tb.set_backpressure_generator(random_pause(0.1, 22))
        stream = tb.stream(4)
        await tb.send(*stream)
        got = await tb.drain()
        tb.compare(got, cp.chirp_pingpong(*stream, tb.n_range))
        await tb.reset()


# ------------------------------------------------------------------------------------------
# pytest: one Verilator build per HDL parameter set
PARAMS = [
    dict(NUM_RX=1, N_RANGE=8, ADC_BACKPRESSURE=0),      # smallest, drop path
    dict(NUM_RX=2, N_RANGE=12, ADC_BACKPRESSURE=1),     # non power of two, backpressure
    dict(NUM_RX=4, N_RANGE=64, ADC_BACKPRESSURE=0),     # paper-fpga preset
    dict(NUM_RX=16, N_RANGE=256, ADC_BACKPRESSURE=0),   # full preset (512-bit words)
]


@pytest.mark.parametrize("parameters", PARAMS, ids=lambda p: "_".join(
    f"{k}{v}" for k, v in p.items()))
def test_chirp_pingpong(parameters: dict) -> None:
    here = Path(__file__).resolve().parent
    run_cocotb("chirp_pingpong", rtl_sources("common/*.sv", "buffers/*.sv"),
               "test_chirp_pingpong", here,
               parameters={"DATA_W": 16, **parameters})
