"""cocotb testbench of ``rtl/fft/fft_axis.sv`` against the bit-accurate ``model/fft_axis.py``.

Every output sample is compared bit-exact with the model (data, tuser, tlast and the
overflow event of each beat), and the transform is compared with float64 numpy (SQNR, dB,
printed in the log). The pytest function at the bottom builds one Verilator model per HDL
parameter set.
"""

from __future__ import annotations

import json
import logging
import os
from pathlib import Path

import cocotb
import numpy as np
import pytest
from cocotb.triggers import FallingEdge, with_timeout
from cocotbext.axi import AxiStreamFrame

from model import fft_axis as ff
from model.axis_packetizer import bytes_to_words, words_to_bytes
from model.fft_rom import stale_files
from rtlsim.axis import AxisTB, bursty_pause, random_pause
from rtlsim.toolchain import param, rtl_sources, run_cocotb
from tb import progress


class TB(AxisTB):
    """fft_axis testbench: source/sink from :class:`AxisTB`, a per-cycle monitor of the
    handshakes and event pulses, and the model configured from the HDL parameters."""

    def __init__(self, dut) -> None:
        super().__init__(dut, log_level=logging.ERROR)  # the reset test flushes a frame
        self.n = param("N")
        self.n_in = param("N_IN", self.n)      # input samples per vector (zero fill after)
        self.n_out = param("N_OUT", self.n)    # bins out per vector (0..N_OUT-1)
        self.ch = param("NUM_CH")
        self.dw = param("DATA_W", 16)
        self.guard_w = param("GUARD_W", 4)
        self.inverse = bool(param("INVERSE", 0))
        self.window = bool(param("WINDOW", 0))
        self.scale_sch = param("SCALE_SCH", 0xFFF) & ((1 << (self.n.bit_length() - 1)) - 1)
        self.default_scale = self.scale_sch == ff.default_scale_sch(self.n)
        self.clear_monitor()
        cocotb.start_soon(self._monitor())
        progress.watch(self, latency=progress.fft_latency(self.n, self.window),
                       frame=(self.n_in, self.n_out))

    # ------------------------------------------------------------------ monitor
    def clear_monitor(self) -> None:
        self.cycle = 0
        self.in_cycles: list[int] = []
        self.out_cycles: list[int] = []
        self.out_user: list[int] = []
        self.ev_unexp: list[int] = []
        self.ev_miss: list[int] = []
        self.ev_ov: set[int] = set()
        self.tready_low_with_sink_ready = 0

    async def _monitor(self) -> None:
        """Sample everything at the falling edge (stable for the whole cycle)."""
        dut = self.dut
        while True:
            await FallingEdge(dut.clk)
            self.cycle += 1
            c = self.cycle
            if dut.rst.value == 1:
                continue
            s_ready = dut.s_axis_tready.value == 1
            if dut.s_axis_tvalid.value == 1 and s_ready:
                self.in_cycles.append(c)
            if dut.m_axis_tvalid.value == 1 and dut.m_axis_tready.value == 1:
                self.out_cycles.append(c)
                self.out_user.append(int(dut.m_axis_tuser.value))
            if dut.event_tlast_unexpected.value == 1:
                self.ev_unexp.append(c)
            if dut.event_tlast_missing.value == 1:
                self.ev_miss.append(c)
            if dut.event_overflow.value == 1:
                self.ev_ov.add(c)

    # ------------------------------------------------------------------ data helpers
    def to_frame(self, x: np.ndarray) -> AxiStreamFrame:
        """complex (beats, lanes) integer I/Q -> AxiStreamFrame (tlast on the last beat)."""
        dw, mask = self.dw, (1 << self.dw) - 1
        re = np.real(x).astype(np.int64) & mask
        im = np.imag(x).astype(np.int64) & mask
        lane = (im << dw) | re
        if dw == 16:
            return AxiStreamFrame(words_to_bytes(lane))
        nbytes = 2 * dw * self.ch // 8
        out = bytearray()
        for beat in lane:
            word = sum(int(v) << (2 * dw * c) for c, v in enumerate(beat))
            out += word.to_bytes(nbytes, "little")
        return AxiStreamFrame(bytes(out))

    def from_frame(self, frame: AxiStreamFrame) -> tuple[np.ndarray, list[int]]:
        """AxiStreamFrame -> complex (beats, lanes), tuser per beat."""
        dw, ch = self.dw, self.ch
        nbytes = 2 * dw * ch // 8
        raw = bytes(frame.tdata)
        if dw == 16:
            lane = bytes_to_words(raw, ch).astype(np.int64)
        else:
            words = [int.from_bytes(raw[i:i + nbytes], "little")
                     for i in range(0, len(raw), nbytes)]
            lane = np.array([[(w >> (2 * dw * c)) & ((1 << 2 * dw) - 1) for c in range(ch)]
                             for w in words], dtype=np.int64)
        half = 1 << (dw - 1)
        re = ((lane & ((1 << dw) - 1)) ^ half) - half
        im = (((lane >> dw) & ((1 << dw) - 1)) ^ half) - half
        tuser = frame.tuser
        if isinstance(tuser, int):
            tuser = [tuser] * len(raw)
        return re + 1j * im, list(tuser)[:: nbytes]

    def model(self, x: np.ndarray) -> ff.FftFixedResult:
        """The core's output of ``x`` (frames, N_IN, lanes): bins 0..N_OUT-1."""
        r = ff.fft_fixed(x, inverse=self.inverse, window=self.window, scale_sch=self.scale_sch,
                         data_w=self.dw, guard_w=self.guard_w, n_fft=self.n)
        return ff.FftFixedResult(y=r.y[:, :self.n_out], overflow=r.overflow[:, :self.n_out])

    def float_ref(self, x: np.ndarray) -> np.ndarray:
        return ff.fft_float(x, inverse=self.inverse, window=self.window,
                            scale_sch=self.scale_sch, n_fft=self.n)[:, :self.n_out]

    def stimulus(self, frames: int, kinds: list[str] | None = None) -> np.ndarray:
        """complex (frames, N_IN, lanes) integer test vectors, one kind per (frame, lane):
        the first N_IN samples of N-sample shapes."""
        n, rng = self.n, self.rng
        kinds = kinds or ["random", "tone", "tone_between", "impulse", "dc", "extreme",
                          "overflow", "random_small"]
        x = np.zeros((frames, n, self.ch), dtype=np.complex128)
        t = np.arange(n)
        for f in range(frames):
            for c in range(self.ch):
                kind = kinds[(f * self.ch + c) % len(kinds)]
                if kind == "random":
                    v = rng.integers(-32768, 32768, n) + 1j * rng.integers(-32768, 32768, n)
                elif kind == "random_small":
                    v = rng.integers(-300, 300, n) + 1j * rng.integers(-300, 300, n)
                elif kind in ("tone", "tone_between"):
                    k = rng.integers(0, n) + (0.5 if kind == "tone_between" else 0.0)
                    a = rng.uniform(1000, 32000)
                    v = np.round(a * np.exp(2j * np.pi * k * t / n + 1j * rng.uniform(0, 6)))
                elif kind == "impulse":
                    v = np.zeros(n, dtype=np.complex128)
                    v[rng.integers(0, n)] = rng.choice([32767, -32768]) + 1j * rng.choice(
                        [32767, -32768, 0])
                elif kind == "dc":
                    v = np.full(n, rng.integers(-32768, 32768) + 1j * rng.integers(-32768, 32768))
                elif kind == "extreme":
                    pick = rng.integers(0, 3)
                    if pick == 0:
                        v = np.full(n, -32768 - 32768j)
                    elif pick == 1:
                        v = np.where(t % 2 == 0, -32768, 32767) * (1 + 1j)
                    else:
                        v = rng.choice([-32768, 32767], n) + 1j * rng.choice([-32768, 32767], n)
                else:  # "overflow": box corners rotating at bin N/8 -> |bin| > full scale
                    ph = np.exp(2j * np.pi * t / 8)
                    v = np.clip(np.round(46341 * ph.real), -32768, 32767) + 1j * np.clip(
                        np.round(46341 * ph.imag), -32768, 32767)
                x[f, :, c] = v
        x = np.clip(x.real, -32768, 32767) + 1j * np.clip(x.imag, -32768, 32767)
        if self.dw != 16:  # same shapes at the core's full scale
            x = np.floor(x.real * 2.0 ** (self.dw - 16)) + 1j * np.floor(
                x.imag * 2.0 ** (self.dw - 16))
        return x[:, :self.n_in]

    async def run_frames(self, x: np.ndarray, timeout_us: float | None = None) -> np.ndarray:
        """Send frames (frames, N_IN, lanes) back to back, receive and check every output
        beat bit-exact (data, tuser, tlast framing, overflow events). Returns the received
        outputs complex (frames, N_OUT, lanes)."""
        frames = x.shape[0]
        exp = self.model(x)
        first_out = len(self.out_cycles)
        for f in range(frames):
            self.source.send_nowait(self.to_frame(x[f]))
        timeout_us = timeout_us or 20 + frames * self.n * 0.12
        got = np.zeros_like(exp.y)
        for f in range(frames):
            frame = await with_timeout(self.sink.recv(), round(timeout_us * 1000), "ns")
            y, tuser = self.from_frame(frame)
            assert y.shape[0] == self.n_out, f"frame {f}: {y.shape[0]} beats, not {self.n_out}"
            assert tuser == list(range(self.n_out)), f"frame {f}: tuser not 0..N_OUT-1"
            bad = np.argwhere(y != exp.y[f])
            if bad.size:
                k, c = bad[0]
                raise AssertionError(
                    f"frame {f}: {len(bad)} mismatches, first bin {k} lane {c}: got {y[k, c]} "
                    f"expected {exp.y[f, k, c]}")
            got[f] = y
        await self.cycles(3)
        # overflow event = the cycle after the handshake of a flagged beat
        beats = self.out_cycles[first_out:first_out + frames * self.n_out]
        ov_got = np.array([(c + 1) in self.ev_ov for c in beats]).reshape(frames, self.n_out)
        assert np.array_equal(ov_got, exp.overflow), (
            f"overflow events differ: got {int(ov_got.sum())} expected {int(exp.overflow.sum())}")
        return got

    async def start(self) -> None:
        self.set_idle_generator(None)
        self.set_backpressure_generator(None)
        self.clear_monitor()
        await self.reset()
        # no event pulse leaves the reset (a core's status counters would count it)
        assert not (self.ev_ov or self.ev_unexp or self.ev_miss), (
            f"event pulse after reset: overflow {sorted(self.ev_ov)}, tlast unexpected "
            f"{self.ev_unexp}, missing {self.ev_miss}")
        self.clear_monitor()


# ====================================================================== cocotb tests
@cocotb.test()
async def test_mixed_random_stalls(dut) -> None:
    """All stimulus kinds back to back, random TVALID gaps and TREADY stalls: bit-exact."""
    tb = TB(dut)
    await tb.start()
    tb.set_idle_generator(random_pause(0.3, seed=11))
    tb.set_backpressure_generator(random_pause(0.3, seed=12))
    frames = max(6, min(32, 16384 // tb.n))
    x = tb.stimulus(frames)
    await tb.run_frames(x)
    n_ov = len(tb.ev_ov)
    tb.log.info("mixed: %d frames bit-exact, %d overflow events", frames, n_ov)
    assert not tb.ev_unexp and not tb.ev_miss


@cocotb.test()
async def test_input_gaps_never_throttled(dut) -> None:
    """Random TVALID gaps, sink always ready: s_axis_tready never drops (only output
    backpressure may throttle the input) but for the N - N_IN clocks of each vector's zero
    fill."""
    tb = TB(dut)
    await tb.start()
    tb.set_idle_generator(random_pause(0.4, seed=31))
    low = 0

    async def watch() -> None:
        nonlocal low
        while True:
            await FallingEdge(dut.clk)
            low += int(dut.s_axis_tready.value == 0)

    watcher = cocotb.start_soon(watch())
    frames = max(3, min(12, 4096 // tb.n))
    await tb.run_frames(tb.stimulus(frames))
    watcher.cancel()
    fill = frames * (tb.n - tb.n_in)
    assert low == fill, (f"s_axis_tready low for {low} cycles without output backpressure, "
                         f"the zero fill is {fill}")


@cocotb.test()
async def test_long_stalls(dut) -> None:
    """Long bursty stalls on both sides (buffers fill completely): no loss, bit-exact."""
    tb = TB(dut)
    await tb.start()
    tb.set_idle_generator(bursty_pause(seed=21, max_run=3 * tb.n // 2, busy_fraction=0.3))
    tb.set_backpressure_generator(bursty_pause(seed=22, max_run=2 * tb.n, busy_fraction=0.5))
    frames = max(4, min(12, 4096 // tb.n))
    await tb.run_frames(tb.stimulus(frames, ["random", "tone", "impulse", "overflow"]))


@cocotb.test()
async def test_sqnr_random_full_scale(dut) -> None:
    """Random 16-bit full-scale input: SQNR of the RTL output vs float64 DFT/N."""
    tb = TB(dut)
    await tb.start()
    frames = max(2, min(8, 2048 // tb.n))
    x = tb.stimulus(frames, ["random"])
    y = await tb.run_frames(x)
    sq = ff.sqnr_db(y, tb.float_ref(x))
    tb.log.info("SQNR N=%d NUM_CH=%d INVERSE=%d WINDOW=%d SCALE_SCH=0x%X: %.2f dB",
                tb.n, tb.ch, tb.inverse, tb.window, tb.scale_sch, sq)
    if tb.default_scale and not tb.window and tb.dw == 16:
        need = {64: 70.0, 256: 64.0}.get(tb.n, 84.0 - 6.0 * (tb.n.bit_length() - 5))
        assert sq >= need, f"SQNR {sq:.2f} dB < {need} dB"


@cocotb.test()
async def test_throughput_latency(dut) -> None:
    """No stalls: input never throttled (a vector every N clocks, its N_IN samples and the
    zero fill), successive frames' first outputs exactly N cycles apart; measures latency
    (written to $FFT_BENCH_JSON for the benchmark script)."""
    tb = TB(dut)
    await tb.start()
    frames = 4
    await tb.run_frames(tb.stimulus(frames, ["random"]))
    n, n_in, n_out = tb.n, tb.n_in, tb.n_out
    ins, outs = tb.in_cycles, tb.out_cycles
    assert len(ins) == frames * n_in and len(outs) == frames * n_out
    assert ins[-1] - ins[0] == (frames - 1) * n + n_in - 1, "input throttled beyond the fill"
    firsts = [outs[f * n_out] for f in range(frames)]
    periods = [b - a for a, b in zip(firsts, firsts[1:], strict=False)]
    assert all(p == n for p in periods), f"frame periods {periods}, expected {n}"
    assert outs[-1] - outs[0] == (frames - 1) * n + n_out - 1, "output not continuous"
    expected = progress.fft_latency(n, tb.window)
    assert firsts[0] - ins[0] == expected, (
        f"latency {firsts[0] - ins[0]} clocks, docs/fft_axis.md's formula says {expected}")
    res = {
        "N": n, "NUM_CH": tb.ch, "INVERSE": int(tb.inverse), "WINDOW": int(tb.window),
        "period": periods[0],
        "latency_first": firsts[0] - ins[0],
        "latency_last": outs[n_out - 1] - ins[n_in - 1],
        "multipliers_per_lane": ff.multipliers_per_lane(n),
    }
    tb.log.info("throughput/latency: %s", res)
    path = os.environ.get("FFT_BENCH_JSON")
    if path:
        Path(path).write_text(json.dumps(res))


@cocotb.test()
async def test_drain_single_frame(dut) -> None:
    """One frame and nothing after it: the core drains on its own (no flush frames)."""
    tb = TB(dut)
    await tb.start()
    x = tb.stimulus(1, ["tone"])
    await tb.run_frames(x, timeout_us=(4 * tb.n + 200) * 0.01)
    tb.set_idle_generator(random_pause(0.5, seed=3))
    await tb.run_frames(tb.stimulus(1, ["impulse"]), timeout_us=(8 * tb.n + 200) * 0.01)


@cocotb.test()
async def test_tlast_events(dut) -> None:
    """tlast early (unexpected) and late (missing): 1-cycle pulses the cycle after the beat;
    framing keeps counting N samples, so data stays bit-exact against the model."""
    tb = TB(dut)
    await tb.start()
    n = tb.n_in
    x = tb.stimulus(4, ["random", "tone"])
    beats = x.reshape(4 * n, tb.ch)
    # chunks: [N/2 (early tlast), N/2], [2N (missing at N-1, tlast at 2N-1)], [N]
    cuts = [0, n // 2, n, 3 * n, 4 * n]
    exp_unexp, exp_miss = [], []
    for a, b in zip(cuts, cuts[1:], strict=False):
        if (b - 1) % n != n - 1:
            exp_unexp.append(b - 1)
        exp_miss += [i for i in range(a, b - 1) if i % n == n - 1]
        tb.source.send_nowait(tb.to_frame(beats[a:b]))
    exp = tb.model(x)
    outs = []
    for _ in range(4):
        frame = await with_timeout(tb.sink.recv(), round(100e3 + 50 * n * 4), "ns")
        outs.append(tb.from_frame(frame)[0])
    assert np.array_equal(np.stack(outs), exp.y)
    ev_u = [tb.in_cycles.index(c - 1) for c in tb.ev_unexp]
    ev_m = [tb.in_cycles.index(c - 1) for c in tb.ev_miss]
    assert ev_u == exp_unexp, f"tlast_unexpected at beats {ev_u}, expected {exp_unexp}"
    assert ev_m == exp_miss, f"tlast_missing at beats {ev_m}, expected {exp_miss}"
    tb.log.info("tlast events: unexpected at %s, missing at %s", ev_u, ev_m)


async def reset_and_rerun(tb: TB) -> None:
    """Drop the queued input frames (the one on the bus is cut), reset, and check that the
    core comes back clean: nothing stale, then 3 frames bit-exact."""
    tb.source.clear()
    await tb.reset()
    tb.sink.clear()
    await tb.cycles(5)
    tb.clear_monitor()
    assert tb.sink.empty()
    await tb.run_frames(tb.stimulus(3))
    await tb.cycles(2 * tb.n)
    assert tb.sink.empty(), "stale output after the reset"


@cocotb.test()
async def test_reset_mid_frame(dut) -> None:
    """Reset in the middle of a frame (with frames in flight): clean restart, nothing stale."""
    tb = TB(dut)
    await tb.start()
    n = tb.n
    tb.set_backpressure_generator(random_pause(0.2, seed=5))
    for _ in range(3):
        tb.source.send_nowait(tb.to_frame(tb.stimulus(1)[0]))
    while len(tb.in_cycles) < tb.n_in + n // 3:
        await tb.cycles(1)
    await reset_and_rerun(tb)


@cocotb.test()
async def test_reset_mid_output(dut) -> None:
    """Reset while the output reorder reads its second bank (frame 0 out and checked, frame 1
    half out): the reorder's read and write banks must both restart at bank 0, so the next
    frames come out whole, in order and bit-exact (a read bank left out of reset makes
    either frame 0 or the frames after the reset come from the wrong bank)."""
    tb = TB(dut)
    await tb.start()
    n = tb.n
    tb.set_backpressure_generator(random_pause(0.2, seed=6))
    x = tb.stimulus(3)
    exp = tb.model(x)
    for f in range(3):
        tb.source.send_nowait(tb.to_frame(x[f]))
    y, _ = tb.from_frame(await with_timeout(tb.sink.recv(), 20 + 3 * n, "us"))
    assert np.array_equal(y, exp.y[0]), "frame 0 (before the reset) differs from the model"
    while len(tb.out_cycles) < tb.n_out + tb.n_out // 2:
        await tb.cycles(1)
    await reset_and_rerun(tb)


# ====================================================================== pytest
# One Verilator build per HDL parameter set (each costs ~30-60 s of a core): the smallest N
# with 2 lanes, a 12-bit data width, 2 guard bits, the window and a custom schedule
# (overflow-heavy); the paper's 64 x 4 lanes; odd log2 N with the inverse; the full preset's
# 256 (SQNR >= 64 dB); 1024 with the window; 24-bit data with W = 27 (the twiddle's
# four-multiplier form, all others use three, Gauss); no window with stage 0 unscaled, so
# full-scale input reaches the twiddle at full scale (its pre-add re + im needs W+1 bits),
# with the twiddle products split for 18-bit multipliers (MUL_W=18: W = 21 in two partial
# products each, as on the ECP5), two lanes so a twiddle saturates in a lane other than the
# first (each lane has its own overflow register); two lanes with zero fill, also split.
# FFT_AXIS_FULL=1 adds the largest N = 4096 and
# N = 32 (two more builds).
PARAMS = [
    dict(N=16, NUM_CH=2, DATA_W=12, GUARD_W=2, WINDOW=1, SCALE_SCH=0b1010),
    dict(N=64, NUM_CH=4),
    dict(N=128, NUM_CH=4, INVERSE=1),
    dict(N=256, NUM_CH=1),
    dict(N=1024, NUM_CH=1, WINDOW=1),
    dict(N=16, NUM_CH=1, DATA_W=24, GUARD_W=2, INVERSE=1),
    dict(N=16, NUM_CH=2, SCALE_SCH=0b1110, MUL_W=18),
    # zero fill: 15 of 16 samples with their own 15-point window, two lanes; 50 of 64, the
    # positive half only (a real ADC's range FFT)
    dict(N=16, NUM_CH=2, WINDOW=1, N_IN=15, MUL_W=18),
    dict(N=64, NUM_CH=1, WINDOW=1, N_IN=50, N_OUT=32),
]
if os.environ.get("FFT_AXIS_FULL", "0") not in ("", "0"):
    PARAMS += [dict(N=4096, NUM_CH=1, WINDOW=1), dict(N=32, NUM_CH=1, INVERSE=1)]


def run(parameters: dict, testcase: str | None = None,
        extra_env: dict[str, str] | None = None) -> None:
    """Build (once) and run the cocotb tests for one parameter set."""
    # the generated ROM files are never rewritten here (parallel workers, and a stale file
    # must not be hidden from the up-to-date test): a stale one fails, naming `make gen`
    stale = stale_files()
    if stale:
        raise RuntimeError(f"{', '.join(str(p) for p in stale)} stale: run `make gen`")
    here = Path(__file__).resolve().parent
    run_cocotb("fft_axis", rtl_sources("common/*.sv", "fft/*.sv"), "test_fft_axis", here,
               parameters=parameters, testcase=testcase, extra_env=extra_env)


@pytest.mark.parametrize("parameters", PARAMS, ids=lambda p: "_".join(
    f"{k}{v}" for k, v in p.items()))
def test_fft_axis(parameters: dict) -> None:
    run(parameters)
