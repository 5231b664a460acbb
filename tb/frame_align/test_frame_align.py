"""cocotb testbench of ``rtl/buffers/frame_align.sv`` against ``model/frame_align.py``.

Chirp sequences: clean back-to-back frames, chirps lost inside a frame (next chirp marked as
a gap), a lost frame-start chirp, an early frame start, chirps without frame start after
reset; random TVALID gaps and TREADY stalls; a reset in mid-stream. Every output chirp, the
per-frame damaged marks and the counters are compared with the model.

Watchdogs (a design that stops the stream fails within seconds, not after the 50 ms default
of ``rtlsim.toolchain``, a quarter of an hour of wall time here): every wait for output or
for the input to drain is bounded by :meth:`TB.chirp_clocks`, and every test by
:data:`TEST_LIMIT_US` of simulated time.
"""

from __future__ import annotations

from pathlib import Path

import cocotb
import numpy as np
import pytest
from cocotb.triggers import RisingEdge, with_timeout

from model.frame_align import frame_align
from rtlsim.axis import CLK_PERIOD_NS, AxisTB, bursty_pause, random_pause
from rtlsim.toolchain import param, rtl_sources, run_cocotb
from tb import stall_regimes


def _test_limit_us() -> float | None:
    """Simulated-time limit of each test, us: 10 us (1,000 clocks) per sample of a frame. The
    longest test, ``stall_cross_with_losses``, simulates about 0.6 us per frame sample with the
    CI stall pairs (12 us at N_RANGE 4 x 6 chirps, 76 us at 16 x 8) and 4x that with all 16
    pairs (``STALL_CROSS=full``). None outside a simulation (pytest collecting the module)."""
    samples = param("N_RANGE", 0) * param("FRAME_CHIRPS", 0)
    return 10.0 * samples if samples else None


TEST_LIMIT_US = _test_limit_us()
ONE_CHIRP_FRAMES = param("FRAME_CHIRPS", 0) == 1
"""Every chirp starts its own frame (FRAME_CHIRPS = 1): a lost chirp is a lost frame and the
next one a clean frame start, so no frame is ever damaged; the two tests that need damaged
frames are skipped there."""


class TB(AxisTB):
    def __init__(self, dut) -> None:
        super().__init__(dut)
        self.num_rx = param("NUM_RX")
        self.n_range = param("N_RANGE")
        self.frame_chirps = param("FRAME_CHIRPS")
        self.done: list[bool] = []
        cocotb.start_soon(self._watch_frames())

    async def _watch_frames(self) -> None:
        """Every clock: record each frame's damaged mark, and check the clock-level rules
        the proof (formal/frame_align.sby) states and the model cannot see: in PASS (state
        read inside the DUT) beats move 1:1, an input beat only with an output beat (a
        chirp to discard is taken in DISCARD, not in the clock that decides it: mutant
        frame_align:drop:9); the clock after a damaged frame's last beat, a frame start
        held at the input is forwarded at once (no bubble: frame_align:drop:16)."""
        d = self.dut
        fill_ended = False
        pass_code = None   # state_q's value in PASS: its reset value (whatever the encoding)
        while True:
            await RisingEdge(d.clk)
            if d.rst.value == 1:
                fill_ended = False
                pass_code = int(d.state_q.value)
                continue
            s_valid, m_valid = d.s_axis_tvalid.value == 1, d.m_axis_tvalid.value == 1
            in_beat = s_valid and d.s_axis_tready.value == 1
            out_beat = m_valid and d.m_axis_tready.value == 1
            if int(d.state_q.value) == pass_code:
                assert in_beat == out_beat, "PASS: an input beat without an output beat"
            if fill_ended and s_valid and int(d.s_axis_tuser.value) & 1:
                assert m_valid, "a frame start waiting after a fill is not forwarded at once"
            fill_ended = d.frame_done.value == 1 and d.frame_done_damaged.value == 1
            if d.frame_done.value == 1:
                self.done.append(bool(d.frame_done_damaged.value))

    @property
    def chirp_clocks(self) -> int:
        """Clocks within which the next output chirp must arrive (or the input drain): twice
        the worst case of the stall patterns here, where before an output chirp up to
        FRAME_CHIRPS + 1 input chirps are discarded or forwarded, and every beat in or out is
        held at most 4 N_RANGE + 64 clocks (the longest pause runs of ``stall_regimes`` and
        ``bursty_pause(.., 60)``)."""
        return 2 * (self.frame_chirps + 2) * self.n_range * (4 * self.n_range + 64)

    async def wait_quiet(self, quiet: int = 64) -> None:
        """:meth:`AxisTB.wait_quiet` within :attr:`chirp_clocks` (``SimTimeoutError``)."""
        await with_timeout(super().wait_quiet(quiet), self.chirp_clocks * CLK_PERIOD_NS, "ns")

    def chirp(self) -> np.ndarray:
        return self.rng.integers(1, 1 << 32, (self.n_range, self.num_rx), dtype=np.uint32)

    def sequence(self, n_frames: int, faults: bool) -> tuple[list, list, list]:
        """ADC-order chirps after the ping-pong: frames of FRAME_CHIRPS chirps, with random
        losses (a lost run of chirps marks the next one as a gap) when ``faults``; drawn
        again until it has one (few chirps per frame: FRAME_CHIRPS = 1)."""
        while True:
            chirps, sof, gap = [], [], []
            lost = False
            for _ in range(n_frames):
                for c in range(self.frame_chirps):
                    if faults and self.rng.random() < 0.12:
                        lost = True  # this chirp is dropped by the ping-pong
                        continue
                    chirps.append(self.chirp())
                    sof.append(c == 0)
                    gap.append(lost)
                    lost = False
            if not faults or any(gap):
                return chirps, sof, gap

    async def send(self, chirps, sof, gap) -> None:
        for ch, s, g in zip(chirps, sof, gap, strict=True):
            await self.send_words(ch, tuser=[int(s) | (int(g) << 1)] + [0] * (len(ch) - 1))

    async def send_garbage_idle(self, chirps, sof, gap) -> None:
        """Drive the input directly (cocotbext's source, idle, holds its last TDATA/TUSER)
        with random idle clocks whose TDATA, TLAST and TUSER are random: AXI4-Stream leaves
        them undefined while TVALID is low, so no decision may look at them then."""
        d = self.dut
        for ch, s, g in zip(chirps, sof, gap, strict=True):
            for i, word in enumerate(ch):
                while self.rng.random() < 0.4:
                    d.s_axis_tvalid.value = 0
                    d.s_axis_tdata.value = int.from_bytes(self.rng.bytes(4 * self.num_rx),
                                                          "little")
                    d.s_axis_tlast.value = int(self.rng.integers(0, 2))
                    d.s_axis_tuser.value = int(self.rng.integers(0, 4))
                    await RisingEdge(d.clk)
                d.s_axis_tvalid.value = 1
                d.s_axis_tdata.value = sum(int(w) << (32 * k) for k, w in enumerate(word))
                d.s_axis_tlast.value = int(i == len(ch) - 1)
                d.s_axis_tuser.value = (int(s) | int(g) << 1) if i == 0 else 0
                await RisingEdge(d.clk)
                while d.s_axis_tready.value != 1:
                    await RisingEdge(d.clk)
        d.s_axis_tvalid.value = 0

    async def collect(self, n_chirps: int) -> list[np.ndarray]:
        out = []
        for _ in range(n_chirps):
            out.append(await self.recv_words(self.num_rx, timeout_cycles=self.chirp_clocks))
        return out

    def counters(self) -> tuple[int, int, int]:
        d = self.dut
        return (int(d.frames_damaged.value), int(d.chirps_filled.value),
                int(d.chirps_discarded.value))

    async def check(self, chirps, sof, gap, what: str) -> None:
        want = frame_align(chirps, sof, gap, self.frame_chirps)
        got = await self.collect(len(want.chirps))
        for i, (g, w) in enumerate(zip(got, want.chirps, strict=True)):
            assert g.shape == w.shape and np.array_equal(g, w), f"{what}: chirp {i} differs"
        await self.wait_quiet(4 * self.n_range)
        assert self.sink.empty(), f"{what}: more output than the model"
        assert self.done == want.frames_damaged, (what, self.done, want.frames_damaged)
        assert self.counters() == (sum(want.frames_damaged), want.chirps_filled,
                                   want.chirps_discarded), (what, self.counters())
        self.dut._log.info("%s: %d chirps out, %d frames (%d damaged), %d filled, "
                           "%d discarded", what, len(got), len(self.done),
                           sum(self.done), want.chirps_filled, want.chirps_discarded)


@cocotb.test(timeout_time=TEST_LIMIT_US, timeout_unit="us")
async def clean_frames_back_to_back(dut) -> None:
    """Whole frames pass through unchanged at one sample per clock."""
    tb = TB(dut)
    await tb.reset()
    seq = tb.sequence(4, faults=False)
    tb.start_meter()
    await tb.send(*seq)
    await tb.check(*seq, "clean")
    assert tb.out_last - tb.out_first + 1 == tb.out_beats  # no bubble in the output
    assert not any(tb.done)


@cocotb.test(timeout_time=TEST_LIMIT_US, timeout_unit="us", skip=ONE_CHIRP_FRAMES)
async def lost_chirps_with_gaps_and_stalls(dut) -> None:
    """Random chirp losses, random TVALID gaps and TREADY stalls (long ones too)."""
    tb = TB(dut)
    for seed, (idle, stall) in enumerate([(random_pause(0.3, 1), random_pause(0.3, 2)),
                                          (bursty_pause(3, 60), bursty_pause(4, 60))]):
        tb.rng = np.random.default_rng(100 + seed)
        tb.set_idle_generator(idle)
        tb.set_backpressure_generator(stall)
        await tb.reset()
        tb.done.clear()
        seq = tb.sequence(8, faults=True)
        assert any(seq[2]), "the seed must produce losses"
        await tb.send(*seq)
        await tb.check(*seq, f"losses, seed {seed}")
        assert any(tb.done), "some frame must be damaged"


@cocotb.test(timeout_time=TEST_LIMIT_US, timeout_unit="us")
async def start_lost_early_start_and_midframe_entry(dut) -> None:
    """The frame-start chirp lost; a frame start arriving early; entry in mid-frame."""
    tb = TB(dut)
    await tb.reset()
    f = tb.frame_chirps
    chirps = [tb.chirp() for _ in range(4 * f)]
    sof = [False] * (4 * f)
    gap = [False] * (4 * f)
    # chirps 0..1: mid-frame entry (no sof); then a clean frame
    sof[2] = True
    # next frame starts early (after f-2 chirps of the previous one)
    sof[2 + f] = True
    sof[2 + 2 * f - 2] = True
    # the following frame's start chirp is lost: first chirp seen carries the gap flag
    gap[2 + 3 * f - 2] = True
    await tb.send(chirps, sof, gap)
    await tb.check(chirps, sof, gap, "edge cases")


@cocotb.test(timeout_time=TEST_LIMIT_US, timeout_unit="us")
async def garbage_while_idle(dut) -> None:
    """Random TDATA, TLAST and TUSER (frame start, gap) on every idle clock of the input,
    with chirp losses: output, frame marks and counters as the model says (a decision taken
    on an idle clock's TUSER, e.g. at_first without TVALID, fills or discards at random:
    mutant frame_align:dropfirst:0)."""
    tb = TB(dut)
    tb.rng = np.random.default_rng(500)
    await tb.reset()
    seq = tb.sequence(6, faults=True)
    assert any(seq[2]), "the seed must produce losses"
    driver = cocotb.start_soon(tb.send_garbage_idle(*seq))
    await tb.check(*seq, "garbage while idle")
    await driver


@cocotb.test(timeout_time=TEST_LIMIT_US, timeout_unit="us", skip=ONE_CHIRP_FRAMES)
async def counters_saturate(dut) -> None:
    """Each status counter, preloaded inside the DUT to 2^32 - 2, sees two or more events
    and stops at 2^32 - 1 instead of wrapping to 0 (its saturation term dropped: mutants
    frame_align:drop:18, drop:21)."""
    tb = TB(dut)
    await tb.reset()
    f = tb.frame_chirps
    chirps = [tb.chirp() for _ in range(3 + 3 * f)]
    sof, gap = [False] * len(chirps), [False] * len(chirps)
    sof[2] = sof[2 + f - 1] = True           # 2 chirps discarded, then an early frame start
    gap[2 + 2 * f - 1] = True                # the next frame's start chirp lost
    sof[2 + 2 * f] = True
    want = frame_align(chirps, sof, gap, f)
    assert min(sum(want.frames_damaged), want.chirps_filled, want.chirps_discarded) >= 2, want
    top = (1 << 32) - 1
    for name in ("dmg_cnt_q", "fill_cnt_q", "disc_cnt_q"):
        getattr(dut, name).value = top - 1
    await tb.send(chirps, sof, gap)
    got = await tb.collect(len(want.chirps))
    assert all(np.array_equal(g, w) for g, w in zip(got, want.chirps, strict=True))
    await tb.wait_quiet(4 * tb.n_range)
    assert tb.counters() == (top, top, top), tb.counters()


async def clean_frames_after_reset(tb: TB) -> None:
    """After a reset: let the flushed source finish its chirp, then 2 fault-free frames must
    pass exactly as the model says, undamaged, with frames_damaged and chirps_filled still 0
    (chirps_discarded may count the interrupted chirp's tail, which has no frame start)."""
    await tb.wait_quiet(2 * tb.n_range)  # the flushed source finishes its chirp
    tb.sink.clear()
    tb.done.clear()
    base = tb.counters()
    seq = tb.sequence(2, faults=False)
    await tb.send(*seq)
    want = frame_align(*seq, tb.frame_chirps)
    got = await tb.collect(len(want.chirps))
    assert all(np.array_equal(g, w) for g, w in zip(got, want.chirps, strict=True))
    await tb.wait_quiet(4 * tb.n_range)
    assert tb.done == want.frames_damaged == [False, False]
    assert tb.counters()[:2] == base[:2] == (0, 0)


@cocotb.test(timeout_time=TEST_LIMIT_US, timeout_unit="us")
async def reset_mid_stream(dut) -> None:
    """A reset in the middle of a frame, then clean frames: nothing of the old stream leaks."""
    tb = TB(dut)
    await tb.reset()
    tb.set_backpressure_generator(random_pause(0.2, 9))
    seq = tb.sequence(3, faults=False)
    await tb.send(*seq)
    await tb.cycles(tb.frame_chirps * tb.n_range + tb.n_range // 2)
    # the queue cleared before the reset: after it the source starts no chirp of the old
    # stream (a frame-start chirp would begin a frame the clean frames then fill up)
    tb.source.clear()
    await tb.reset()
    tb.sink.clear()
    tb.done.clear()
    # the interrupted chirp (if the reset did not flush it) has no frame start: discarded
    await clean_frames_after_reset(tb)


@cocotb.test(timeout_time=TEST_LIMIT_US, timeout_unit="us")
async def reset_mid_chirp_then_midframe_entry(dut) -> None:
    """A reset lands after the first samples of an input chirp, and the ADC then resumes with
    a chirp that has no frame start: the reset makes the next sample a chirp's first, so that
    chirp is discarded (counted) and the frames after it pass (mutant frame_align:noreset:5,
    in_first_q left out of reset, forwarded it)."""
    tb = TB(dut)
    await tb.reset()
    d = tb.dut
    taken = 0
    while taken < max(1, tb.n_range // 2):  # the first half of a frame-start chirp, no TLAST
        d.s_axis_tvalid.value = 1
        d.s_axis_tdata.value = taken + 1
        d.s_axis_tlast.value = 0
        d.s_axis_tuser.value = 1 if taken == 0 else 0
        await RisingEdge(d.clk)
        taken += int(d.s_axis_tready.value)
    d.s_axis_tvalid.value = 0
    await tb.reset()
    tb.sink.clear()
    tb.done.clear()
    chirps, sof, gap = tb.sequence(2, faults=False)
    seq = ([tb.chirp(), *chirps], [False, *sof], [False, *gap])
    await tb.send(*seq)
    await tb.check(*seq, "entry after a reset mid-chirp")
    assert tb.counters() == (0, 0, 1), tb.counters()


@cocotb.test(timeout_time=TEST_LIMIT_US, timeout_unit="us")
async def stall_cross_with_losses(dut) -> None:
    """Stall regimes crossed (tb/stall_regimes.py: CI subset, all 16 pairs with
    STALL_CROSS=full), each pair from reset with random chirp losses: output chirps, frame
    marks and counters equal the model."""
    tb = TB(dut)

    async def run(pair, k) -> None:
        tb.rng = np.random.default_rng(300 + k)
        await tb.reset()
        tb.done.clear()
        seq = tb.sequence(3, faults=True)
        await tb.send(*seq)
        await tb.check(*seq, "stall pair " + "/".join(pair))

    await stall_regimes.run_cross(tb, tb.n_range, run)


@cocotb.test(timeout_time=TEST_LIMIT_US, timeout_unit="us")
async def reset_during_backpressure(dut) -> None:
    """Reset while the output is valid and held by TREADY low: counters cleared, nothing of
    the old stream leaks, the next frames pass unchanged and undamaged."""
    tb = TB(dut)
    await tb.reset()

    async def start() -> None:
        await tb.send(*tb.sequence(2, faults=False))

    await stall_regimes.reset_while_stalled(tb, start)
    assert tb.counters() == (0, 0, 0), tb.counters()
    await clean_frames_after_reset(tb)



PARAMS = [dict(NUM_RX=2, DATA_W=16, N_RANGE=4, FRAME_CHIRPS=6),
          dict(NUM_RX=4, DATA_W=16, N_RANGE=16, FRAME_CHIRPS=8),
          # neither count a power of two: the sample and chirp counters must wrap by compare,
          # not by overflow (mutant frame_align:last:7)
          dict(NUM_RX=1, DATA_W=16, N_RANGE=6, FRAME_CHIRPS=5),
          # the smallest sizes: every chirp a frame, two samples each (the frame-end flag is
          # constant: mutant chirp_last_q without its FRAME_CHIRPS == 1 term)
          dict(NUM_RX=1, DATA_W=16, N_RANGE=2, FRAME_CHIRPS=1)]


@pytest.mark.parametrize("parameters", PARAMS, ids=lambda p: f"rx{p['NUM_RX']}_n{p['N_RANGE']}")
def test_frame_align(parameters: dict) -> None:
    run_cocotb("frame_align", rtl_sources("common/*.sv", "buffers/frame_align.sv"),
               "test_frame_align",
               Path(__file__).parent, parameters)
