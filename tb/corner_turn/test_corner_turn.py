"""cocotb testbench of ``rtl/buffers/corner_turn.sv`` against ``model/corner_turn.py``."""

from __future__ import annotations

from pathlib import Path

import cocotb
import numpy as np
import pytest
from cocotb.triggers import RisingEdge

from model import corner_turn as ct
from rtlsim.axis import AxisTB, bursty_pause, no_pause, random_pause
from rtlsim.toolchain import param, rtl_sources, run_cocotb
from tb import progress, stall_regimes


class TB(AxisTB):
    def __init__(self, dut) -> None:
        super().__init__(dut)
        self.num_tx = param("NUM_TX")
        self.num_rx = param("NUM_RX")
        self.n_range = param("N_RANGE")
        self.n_doppler = param("N_DOPPLER")
        self.n_loops = param("N_LOOPS", self.n_doppler)    # chirps per TX in a frame
        assert param("DATA_W") == 16
        self.read_order = param("READ_ORDER", 0)
        self.frame_words = self.num_tx * self.n_range * self.n_loops
        # a stopped stream fails at once: the longest pause here is max(3 N_DOPPLER,
        # 4 N_RANGE) clocks
        progress.watch(self, stuck=16 * (self.n_range + self.n_doppler) + 2000,
                       conserving=True)

    def random_frame(self) -> np.ndarray:
        return self.rng.integers(0, 1 << 32, (self.frame_words, self.num_rx), dtype=np.uint32)

    async def send_frame(self, words: np.ndarray) -> None:
        """One frame as chirps (TLAST on the last range bin of each chirp)."""
        nr = self.n_range
        for c in range(len(words) // nr):
            await self.send_words(words[c * nr:(c + 1) * nr])

    async def recv_frames(self, n: int) -> list[np.ndarray]:
        """Receive n frames of Doppler vectors, checking TLAST and TUSER (frame start)."""
        frames = []
        for _ in range(n):
            vecs = []
            for v in range(self.num_tx * self.n_range):
                w, sof = await self.recv_words_user(self.num_rx)
                assert len(w) == self.n_loops, f"vector of {len(w)} words"
                assert sof == [int(v == 0 and i == 0) for i in range(len(w))], sof[:4]
                vecs.append(w)
            frames.append(np.vstack(vecs))
        return frames

    def status(self) -> dict[str, int]:
        return self.read_status((
            "status_framing_error", "framing_error_count", "frames_in", "frames_out"))

    def check(self, got: list[np.ndarray], sent: list[np.ndarray]) -> None:
        for k, (g, f) in enumerate(zip(got, sent, strict=True)):
            exp = ct.corner_turn(f, self.num_tx, self.n_range, self.n_doppler, self.read_order,
                                 n_loops=self.n_loops)
            if not np.array_equal(g, exp):
                bad = np.nonzero((g != exp).any(axis=1))[0]
                raise AssertionError(f"frame {k}: {len(bad)} words differ, first at {bad[0]}")


@cocotb.test()
async def test_throughput(dut):
    """Back-to-back frames without stalls: one word per clock in and out."""
    tb = TB(dut)
    tb.start_meter()
    await tb.reset()
    nfr = 2 if tb.frame_words > 4096 else 3
    frames = [tb.random_frame() for _ in range(nfr)]
    rx = cocotb.start_soon(tb.recv_frames(nfr))
    for f in frames:
        await tb.send_frame(f)
    got = await rx
    tb.check(got, frames)
    fw = tb.frame_words
    out_span = tb.out_last - tb.out_first + 1
    total = tb.out_last - tb.in_first + 1
    tb.log.info("throughput: %d words out in %d clocks (%.4f words/clock); %d frames in+out "
                "in %d clocks (ideal %d); latency first in -> first out %d clocks",
                tb.out_beats, out_span, tb.out_beats / out_span, nfr, total, (nfr + 1) * fw,
                tb.out_first - tb.in_first)
    # per frame at most a few clocks of hand-over between writer and reader; with TX banks
    # (order 1, NUM_TX not a power of two) the writer lags by up to about
    # (NUM_TX-1)*|N_DOPPLER-N_RANGE| clocks a frame (docs/buffers.md), bounded here by
    # NUM_TX*max(N_RANGE, N_DOPPLER)
    banked = tb.read_order == 1 and tb.num_tx & (tb.num_tx - 1)
    per_frame = 4 + (tb.num_tx * max(tb.n_range, tb.n_doppler) if banked else 0)
    assert out_span <= nfr * fw + per_frame * nfr, out_span
    assert total <= (nfr + 1) * fw + per_frame * (nfr + 1), total
    st = tb.status()
    assert st == {"status_framing_error": 0, "framing_error_count": 0, "frames_in": nfr,
                  "frames_out": nfr}, st


@cocotb.test()
async def test_random_stalls(dut):
    """Random and long TVALID gaps / TREADY stalls over a full cycle of the address pattern."""
    tb = TB(dut)
    await tb.reset()
    period = ct.frame_period(tb.num_tx, tb.n_range, tb.n_doppler, tb.read_order)
    nfr = 2 if tb.frame_words > 4096 else period + 2
    tb.set_idle_generator(random_pause(0.3, 1))
    tb.set_backpressure_generator(bursty_pause(2, max_run=3 * tb.n_doppler, busy_fraction=0.4))
    frames = [tb.random_frame() for _ in range(nfr)]
    rx = cocotb.start_soon(tb.recv_frames(nfr))
    for k, f in enumerate(frames):
        if k == nfr // 2:
            tb.set_idle_generator(bursty_pause(3, max_run=2 * tb.n_range))
            tb.set_backpressure_generator(random_pause(0.5, 4))
        await tb.send_frame(f)
    got = await rx
    tb.check(got, frames)
    st = tb.status()
    assert st["framing_error_count"] == 0 and st["frames_out"] == nfr, st


@cocotb.test()
async def test_framing_error(dut):
    """A short chirp (early TLAST) is flagged and counted; data still reorders by count."""
    tb = TB(dut)
    await tb.reset()
    tb.set_idle_generator(random_pause(0.2, 5))
    tb.set_backpressure_generator(random_pause(0.2, 6))
    f = tb.random_frame()
    nr = tb.n_range
    rx = cocotb.start_soon(tb.recv_frames(1))
    # chirp 0 split as (nr-1) + 1 words: early TLAST at word nr-2 -> exactly one error
    await tb.send_words(f[:nr - 1])
    await tb.send_words(f[nr - 1:nr])
    for c in range(1, len(f) // nr):
        await tb.send_words(f[c * nr:(c + 1) * nr])
    got = await rx
    tb.check(got, [f])
    st = tb.status()
    assert st["status_framing_error"] == 1 and st["framing_error_count"] == 1, st


@cocotb.test()
async def test_framing_error_on_frame_end(dut):
    """A TLAST missing on a frame's very last word (the beat that also ends the frame) is
    counted like any other (mutation campaign: corner_turn:count:5 skipped the count there)."""
    tb = TB(dut)
    await tb.reset()
    tb.set_idle_generator(random_pause(0.2, 5))
    tb.set_backpressure_generator(random_pause(0.2, 6))
    a, b = tb.random_frame(), tb.random_frame()
    nr = tb.n_range
    rx = cocotb.start_soon(tb.recv_frames(2))
    for c in range(len(a) // nr - 1):
        await tb.send_words(a[c * nr:(c + 1) * nr])
    # a's last chirp and b's first as one packet: no TLAST on a's last word
    await tb.send_words(np.vstack([a[-nr:], b[:nr]]))
    for c in range(1, len(b) // nr):
        await tb.send_words(b[c * nr:(c + 1) * nr])
    got = await rx
    tb.check(got, [a, b])
    st = tb.status()
    assert st["status_framing_error"] == 1 and st["framing_error_count"] == 1, st
    assert st["frames_in"] == 2 and st["frames_out"] == 2, st


@cocotb.test()
async def test_reset_after_framing_error(dut):
    """A reset in the clock after a misplaced TLAST: the error is not counted after it, and
    the next frame turns clean (mutation campaign corner_turn:noreset:17: the registered
    framing event left out of reset counted it once the reset ended)."""
    tb = TB(dut)
    await tb.reset()
    a, b = tb.random_frame(), tb.random_frame()
    await tb.send_words(a[:1])   # a one-word chirp: TLAST on range bin 0, a framing error
    for _ in range(1000):
        await RisingEdge(dut.clk)
        if int(dut.s_axis_tvalid.value) & int(dut.s_axis_tready.value):
            break
    else:
        raise AssertionError("the word was never taken")
    await tb.reset()
    st = tb.status()
    assert st["status_framing_error"] == 0 and st["framing_error_count"] == 0, st
    rx = cocotb.start_soon(tb.recv_frames(1))
    await tb.send_frame(b)
    tb.check(await rx, [b])
    st = tb.status()
    assert st["status_framing_error"] == 0 and st["framing_error_count"] == 0, st


@cocotb.test()
async def test_framing_errors_counted_while_streaming(dut):
    """Frames back to back with TLASTs moved at random (dropped at chirp ends, added inside
    chirps) while earlier frames are read out: the error count equals the number of beats
    whose TLAST is wrong, wherever the reader is (its vector and frame ends, the pending
    frame: mutation campaign, corner_turn:count:1..3), and the data still reorders by count."""
    tb = TB(dut)
    await tb.reset()
    tb.set_idle_generator(random_pause(0.1, 13))
    tb.set_backpressure_generator(random_pause(0.2, 14))
    # 8 frames of the small sets (the reader's frame end meets a wrong TLAST), 3 of large ones
    frames = [tb.random_frame() for _ in range(8 if tb.frame_words <= 1024 else 3)]
    words = np.vstack(frames)
    nr = tb.n_range
    ends = np.zeros(len(words), dtype=bool)          # TLAST per beat as sent
    ends[nr - 1::nr] = True
    # wrong TLASTs: about 60 a frame (at most 30 % of the beats)
    flip = tb.rng.random(len(words)) < min(0.3, 60.0 / tb.frame_words)
    flip[-1] = False                                  # the stream's last beat closes it
    ends ^= flip
    rx = cocotb.start_soon(tb.recv_frames(len(frames)))
    start = 0
    for i in np.nonzero(ends)[0]:
        await tb.send_words(words[start:i + 1])
        start = i + 1
    tb.check(await rx, frames)
    st = tb.status()
    assert st["framing_error_count"] == int(flip.sum()) and st["status_framing_error"] == 1, (
        st, int(flip.sum()))
    # the frame counters, whatever the reader does when a frame's input ends (count:8, 9)
    assert st["frames_in"] == len(frames) and st["frames_out"] == len(frames), st


@cocotb.test()
async def test_reset_recovery(dut):
    """Reset while a frame is read and the next written, then clean frames."""
    tb = TB(dut)
    await tb.reset()
    tb.set_idle_generator(random_pause(0.1, 7))
    tb.set_backpressure_generator(random_pause(0.3, 8))
    for _ in range(1 if tb.frame_words > 4096 else 2):
        await tb.send_frame(tb.random_frame())
    await tb.cycles(tb.frame_words + tb.frame_words // 2)
    tb.source.clear()
    await tb.reset()
    tb.sink.clear()
    st = tb.status()
    assert all(v == 0 for v in st.values()), st
    tb.set_idle_generator(no_pause())
    tb.set_backpressure_generator(random_pause(0.2, 9))
    frames = [tb.random_frame() for _ in range(2)]
    rx = cocotb.start_soon(tb.recv_frames(2))
    for f in frames:
        await tb.send_frame(f)
    got = await rx
    tb.check(got, frames)
    assert tb.status()["frames_out"] == 2


@cocotb.test()
async def test_input_held_through_reset(dut):
    """A source outside the corner turn's reset presents a frame's first word during a reset
    and holds it (TVALID high until TREADY): no word is taken while the corner turn is in
    reset (one taken then is lost with it: mutant corner_turn:dropfirst:0, its TREADY without
    !rst), and the frame comes out whole after the reset."""
    tb = TB(dut)
    await tb.reset()
    frame = tb.random_frame()
    nr = tb.n_range
    await tb.hold_word_through_reset(frame[0], tlast=nr == 1)
    rx = cocotb.start_soon(tb.recv_frames(1))
    if nr > 1:
        await tb.send_words(frame[1:nr])   # the rest of the first chirp
    for c in range(1, len(frame) // nr):
        await tb.send_words(frame[c * nr:(c + 1) * nr])
    tb.check(await rx, [frame])
    st = tb.status()
    assert st["frames_in"] == st["frames_out"] == 1 and st["framing_error_count"] == 0, st


@cocotb.test()
async def test_stall_cross(dut):
    """Stall regimes crossed (tb/stall_regimes.py: CI subset, or all 16 pairs with
    STALL_CROSS=full): per (input, output) pair, frames through the block bit-exact."""
    tb = TB(dut)
    await tb.reset()
    nfr = 1 if tb.frame_words > 4096 else 2
    sent = []

    async def run(pair, k):
        frames = [tb.random_frame() for _ in range(nfr)]
        rx = cocotb.start_soon(tb.recv_frames(nfr))
        for f in frames:
            await tb.send_frame(f)
        tb.check(await rx, frames)
        sent.extend(frames)

    await stall_regimes.run_cross(tb, tb.n_range, run)
    st = tb.status()
    assert st["framing_error_count"] == 0 and st["frames_out"] == len(sent), st


@cocotb.test()
async def test_reset_during_backpressure_and_output(dut):
    """Reset while the output is valid and stalled, then reset while words flow out
    (mid-frame): counters cleared, the next frames bit-exact."""
    tb = TB(dut)
    await tb.reset()

    async def start():  # queues the frames (the source sends them in the background)
        for _ in range(2 if tb.frame_words <= 4096 else 1):
            await tb.send_frame(tb.random_frame())

    for case in ("backpressure", "output"):
        if case == "backpressure":
            await stall_regimes.reset_while_stalled(tb, start)
        else:
            await stall_regimes.reset_while_sending(tb, start, beats=tb.frame_words // 2)
        st = tb.status()
        assert all(v == 0 for v in st.values()), (case, st)
        tb.set_idle_generator(random_pause(0.2, 11))
        tb.set_backpressure_generator(random_pause(0.2, 12))
        frames = [tb.random_frame() for _ in range(2)]
        rx = cocotb.start_soon(tb.recv_frames(2))
        for f in frames:
            await tb.send_frame(f)
        tb.check(await rx, frames)
        assert tb.status()["frames_out"] == 2, case
        tb.set_idle_generator(no_pause())
        await tb.reset()


# ------------------------------------------------------------------------------------------
# pytest: one Verilator build per HDL parameter set
PARAMS = [
    # smallest non-square reorder (B=5, ROT=2: address pattern period 5 frames)
    dict(NUM_TX=1, NUM_RX=1, N_RANGE=4, N_DOPPLER=8),
    # TDM-MIMO interleave, 4 TX, 512-bit words (B=9, ROT=5: period 9 frames); the frame
    # memory in 8 banks of 64 words, chosen after the per-bank output registers (the ECP5
    # timing flow's RAM_BANKS, docs/synth.md note 18)
    dict(NUM_TX=4, NUM_RX=16, N_RANGE=8, N_DOPPLER=16, RAM_BANKS=8),
    # paper-fpga preset: 1 TX x 4 RX, 64 range bins, 256 chirps (16384 x 128-bit words)
    dict(NUM_TX=1, NUM_RX=4, N_RANGE=64, N_DOPPLER=256),
    # on-chip detection order (r, t, d): bit-permutation addresses, period 7 frames
    dict(NUM_TX=4, NUM_RX=2, N_RANGE=4, N_DOPPLER=8, READ_ORDER=1),
    # fewer loops than the Doppler FFT length: 15 of 16 (2 TX), 5 of 8 in the (r, t, d) order
    dict(NUM_TX=2, NUM_RX=2, N_RANGE=4, N_DOPPLER=16, N_LOOPS=15),
    dict(NUM_TX=4, NUM_RX=1, N_RANGE=4, N_DOPPLER=8, N_LOOPS=5, READ_ORDER=1),
    # 3 TX (xWR1843): modular address stepping, stride 12^k mod 95, period 12 frames
    dict(NUM_TX=3, NUM_RX=2, N_RANGE=4, N_DOPPLER=8),
    # 3 TX in order (r, t, d): three TX banks of in-place 8 x 8 transposes, period 2 frames
    dict(NUM_TX=3, NUM_RX=2, N_RANGE=8, N_DOPPLER=8, READ_ORDER=1),
    # TX banks with chirps shorter than the Doppler vectors: the writer waits for its bank
    dict(NUM_TX=3, NUM_RX=1, N_RANGE=2, N_DOPPLER=8, READ_ORDER=1),
    # 3 TX with 5 of 8 loops: the modular read jumps over the skipped words at vector ends;
    # TX banks with 6 of 8 loops (each bank skips its rows' missing words)
    dict(NUM_TX=3, NUM_RX=2, N_RANGE=4, N_DOPPLER=8, N_LOOPS=5),
    dict(NUM_TX=3, NUM_RX=1, N_RANGE=4, N_DOPPLER=8, N_LOOPS=6, READ_ORDER=1),
]


@pytest.mark.parametrize("parameters", PARAMS, ids=lambda p: "_".join(
    f"{k}{v}" for k, v in p.items()))
def test_corner_turn(parameters: dict) -> None:
    here = Path(__file__).resolve().parent
    run_cocotb("corner_turn", rtl_sources("common/*.sv", "buffers/*.sv"), "test_corner_turn", here,
               parameters={"DATA_W": 16, **parameters})


@pytest.mark.parametrize("read_order", [0, 1])
@pytest.mark.parametrize("shape", [(1, 4, 8, 8), (4, 8, 16, 16), (2, 4, 4, 4), (4, 2, 2, 2),
                                   (1, 64, 256, 256), (2, 4, 16, 15), (4, 2, 8, 5),
                                   (1, 16, 256, 255), (3, 4, 8, 8), (3, 16, 64, 64),
                                   (5, 2, 4, 4), (6, 4, 8, 8), (3, 4, 8, 5), (3, 16, 64, 60),
                                   (5, 2, 4, 3), (6, 4, 8, 1)])
def test_in_place_model(shape: tuple[int, int, int, int], read_order: int) -> None:
    """The in-place address scheme (one frame of memory) reproduces the transpose over more
    than a full period of its address pattern, never overwriting an unread slot, also with
    fewer loops than the memory's (the counters skipping the missing words)."""
    nt, nr, nd, nl = shape
    rng = np.random.default_rng(0)
    frames = [rng.integers(0, 1 << 32, (nt * nr * nl, 2), dtype=np.uint32)
              for _ in range(ct.frame_period(nt, nr, nd, read_order) + 2)]
    out = ct.in_place_stream(frames, nt, nr, nd, read_order, n_loops=nl)
    for f, o in zip(frames, out, strict=True):
        assert np.array_equal(o, ct.corner_turn(f, nt, nr, nd, read_order, n_loops=nl))
