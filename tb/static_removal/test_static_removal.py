"""cocotb testbench of ``rtl/buffers/static_removal.sv`` against ``model/static_removal.py``:
back-to-back frames at one word per clock, random TVALID gaps and TREADY stalls, the enable
switched in mid-frame (taking effect at the next frame), a reset in mid-stream, a misplaced
TLAST; every output word compared with the model."""

from __future__ import annotations

from pathlib import Path

import cocotb
import numpy as np
import pytest
from cocotb.triggers import RisingEdge

from model.static_removal import static_removal
from rtlsim.axis import AxisTB, bursty_pause, no_pause, random_pause
from rtlsim.toolchain import param, rtl_sources, run_cocotb
from tb import progress

VECTORS = 6
"""Slow-time vectors per test frame (TX slots x range bins of a frame, as the block sees it)."""


class TB(AxisTB):
    def __init__(self, dut) -> None:
        super().__init__(dut)
        self.num_rx = param("NUM_RX")
        self.n_doppler = param("N_DOPPLER")
        self.n_loops = param("N_LOOPS")
        self.window = bool(param("WINDOW"))
        assert param("DATA_W") == 16
        self.frame_words = VECTORS * self.n_doppler
        self.schedule: list[bool] = []      # enable of frame k (set by drive_enable)
        dut.enable.value = 0
        # a stopped or endless stream fails at once: the longest pause here is 2 N_DOPPLER
        # clocks; no beat out that did not come in
        progress.watch(self, stuck=16 * self.n_doppler + 2000, conserving=True)

    def random_frame(self) -> np.ndarray:
        """uint32 (frame_words, num_rx): per-vector DC offsets (the static part) plus noise, a
        tenth of the values at the extremes (saturating differences)."""
        shape = (VECTORS, self.n_doppler, self.num_rx, 2)
        dc = self.rng.integers(-20000, 20000, (VECTORS, 1, self.num_rx, 2))
        v = np.clip(dc + self.rng.integers(-9000, 9000, shape), -32768, 32767)
        extreme = self.rng.random(shape) < 0.1
        v[extreme] = self.rng.choice([-32768, 32767], size=int(extreme.sum()))
        w = (v[..., 0] & 0xFFFF) | ((v[..., 1] & 0xFFFF) << 16)
        return w.reshape(self.frame_words, self.num_rx).astype(np.uint32)

    async def send_frame(self, words: np.ndarray) -> None:
        nd = self.n_doppler
        for v in range(VECTORS):
            user = [1 if v == 0 else 0] + [0] * (nd - 1)
            await self.send_words(words[v * nd:(v + 1) * nd], tuser=user)

    async def drive_enable(self, schedule: list[bool]) -> None:
        """Frame k is sent with enable = schedule[k]: the switch is set before the first
        frame and changed in the middle of frame k-1 (it must not act before frame k)."""
        self.schedule = schedule
        self.dut.enable.value = int(schedule[0])
        beats = 0
        while True:
            await RisingEdge(self.dut.clk)
            if self.dut.s_axis_tvalid.value == 1 and self.dut.s_axis_tready.value == 1:
                beats += 1
                k, pos = divmod(beats, self.frame_words)
                if pos == self.frame_words // 2 + 1 and k + 1 < len(schedule):
                    self.dut.enable.value = int(schedule[k + 1])

    async def recv_frame(self) -> np.ndarray:
        """One frame's vectors, checking TLAST per vector (recv) and TUSER on word 0 only."""
        out = []
        for v in range(VECTORS):
            w, user = await self.recv_words_user(self.num_rx, 40 * self.frame_words)
            assert len(w) == self.n_doppler, f"vector of {len(w)} words"
            assert user == [int(v == 0)] + [0] * (self.n_doppler - 1), user[:4]
            out.append(w)
        return np.concatenate(out)

    def check(self, got: list[np.ndarray], sent: list[np.ndarray], enables: list[bool]) -> int:
        """Compare every frame with the model; returns the model's saturated words."""
        saturated = 0
        for k, (g, f, en) in enumerate(zip(got, sent, enables, strict=True)):
            exp, sat = static_removal(f, self.n_doppler, self.n_loops, enable=en,
                                      window=self.window)
            saturated += sat
            if not np.array_equal(g, exp):
                bad = np.argwhere(g != exp)
                raise AssertionError(f"frame {k} (enable {en}): {len(bad)} lanes differ, first "
                                     f"at {tuple(bad[0])}: {g[tuple(bad[0])]:#x} != "
                                     f"{exp[tuple(bad[0])]:#x}")
        return saturated

    async def run_frames(self, frames: list[np.ndarray], enables: list[bool]) -> None:
        cocotb.start_soon(self.drive_enable(enables))
        rx = cocotb.start_soon(self._recv_all(len(frames)))
        for f in frames:
            await self.send_frame(f)
        got = await rx
        sat = self.check(got, frames, enables)
        assert int(self.dut.status_saturated.value) == int(sat > 0)
        assert int(self.dut.status_framing_error.value) == 0

    async def _recv_all(self, n: int) -> list[np.ndarray]:
        return [await self.recv_frame() for _ in range(n)]


@cocotb.test()
async def test_throughput(dut):
    """Back-to-back frames without stalls: one word per clock in, the mean removed."""
    tb = TB(dut)
    tb.start_meter()
    await tb.reset()
    frames = [tb.random_frame() for _ in range(3)]
    await tb.run_frames(frames, [True] * 3)
    span = tb.out_last - tb.in_first + 1
    tb.log.info("%d words in %d clocks", tb.in_beats, span)
    assert tb.in_beats == 3 * tb.frame_words
    # one vector plus a few clocks of latency, no bubble per vector
    assert span <= tb.in_beats + tb.n_doppler + 6, span


@cocotb.test()
async def test_stalls_and_enable(dut):
    """Random and long gaps and stalls; the enable toggled between frames (set mid-frame)."""
    tb = TB(dut)
    await tb.reset()
    tb.set_idle_generator(random_pause(0.3, 1))
    tb.set_backpressure_generator(bursty_pause(2, max_run=2 * tb.n_doppler, busy_fraction=0.4))
    frames = [tb.random_frame() for _ in range(5)]
    await tb.run_frames(frames, [True, False, True, True, False])


@cocotb.test()
async def test_reset_recovery(dut):
    """Reset in mid-stream (input and output busy), then clean frames."""
    tb = TB(dut)
    await tb.reset()
    dut.enable.value = 1
    tb.set_backpressure_generator(random_pause(0.5, 8))
    cocotb.start_soon(tb.send_frame(tb.random_frame()))
    await tb.cycles(tb.frame_words // 2 + 3)
    tb.source.clear()
    await tb.reset()
    tb.sink.clear()
    assert int(dut.m_axis_tvalid.value) == 0 and int(dut.status_saturated.value) == 0
    tb.set_idle_generator(random_pause(0.2, 9))
    tb.set_backpressure_generator(no_pause())
    frames = [tb.random_frame() for _ in range(2)]
    await tb.run_frames(frames, [True, True])


@cocotb.test()
async def test_framing_error(dut):
    """A TLAST one word early is flagged (sticky); the data still go by position."""
    tb = TB(dut)
    await tb.reset()
    dut.enable.value = 1
    f = tb.random_frame()
    nd = tb.n_doppler
    rx = cocotb.start_soon(tb.sink.recv(compact=False))
    await tb.send_words(f[:nd - 1], tuser=[1] + [0] * (nd - 2))
    await tb.send_words(f[nd - 1:nd])
    await rx
    await tb.cycles(10)
    assert int(dut.status_framing_error.value) == 1
    await tb.cycles(10)
    assert int(dut.status_framing_error.value) == 1, "framing flag not sticky"


# ------------------------------------------------------------------------------------------
# pytest: one Verilator build per HDL parameter set
PARAMS = [
    # Hann-weighted mean (shift-and-add division by N_LOOPS 2^15), 2 lanes
    dict(NUM_RX=2, N_DOPPLER=8, N_LOOPS=8, WINDOW=1),
    # Hann-weighted over 8 loops of 16 (zero fill passes unchanged), 1 lane
    dict(NUM_RX=1, N_DOPPLER=16, N_LOOPS=8, WINDOW=1),
    # plain mean of 13 loops of 16 (reciprocal multiply, zero fill passes unchanged), 1 lane
    dict(NUM_RX=1, N_DOPPLER=16, N_LOOPS=13, WINDOW=0),
    # the pipeline's 15 loops (zero-filled to 16 by the Doppler FFT behind): 15-word vectors,
    # weighted by the generated 15-point window (reciprocal multiply), 2 lanes
    dict(NUM_RX=2, N_DOPPLER=15, N_LOOPS=15, WINDOW=1),
]


@pytest.mark.parametrize("parameters", PARAMS, ids=lambda p: "_".join(
    f"{k}{v}" for k, v in p.items()))
def test_static_removal(parameters: dict) -> None:
    here = Path(__file__).resolve().parent
    sources = [*rtl_sources("fft/fft_rom_pkg.sv", "fft/fft_hann_rom.sv", "fft/fft_win_rom.sv",
                            "common/*.sv", "buffers/buf_*.sv"),
               *rtl_sources("buffers/static_removal.sv")]
    run_cocotb("static_removal", sources, "test_static_removal", here,
               parameters={"DATA_W": 16, **parameters})
