"""cocotb testbench of ``rtl/buffers/frame_store_axi.sv`` against ``model/frame_store_axi.py``:
cocotbext-axi ``AxiRam`` on ``m_axi_mem`` with pause generators on all five AXI channels, the
AR/AW address trace checked burst by burst against the model, payload word by word against
the on-chip corner turn in the same read order (READ_ORDER 0: (t, r, d), the cube; 1:
(r, t, d), on-chip detection), SLVERR answers counted, mid-stream reset."""

from __future__ import annotations

import logging
import os
from collections.abc import Awaitable
from pathlib import Path
from typing import TypeVar

import cocotb
import numpy as np
import pytest
from cocotb.triggers import RisingEdge, with_timeout
from cocotbext.axi import AxiBus, AxiStreamFrame
from cocotbext.axi.axi_ram import AxiRamRead, AxiRamWrite
from cocotbext.axi.memory import Memory

from model import frame_store_axi as fs
from model.axis_packetizer import words_to_bytes
from rtlsim.axis import CLK_PERIOD_NS, AxisTB, bursty_pause, no_pause, random_pause
from rtlsim.toolchain import param, rtl_sources, run_cocotb

T = TypeVar("T")


class FaultRamWrite(AxiRamWrite):
    """AxiRamWrite answering SLVERR (and dropping the data) for writes touching ``bad``."""

    bad: tuple[int, int] | None = None

    async def _write(self, address: int, data: bytes) -> None:
        if self.bad and address < self.bad[1] and address + len(data) > self.bad[0]:
            raise OSError("injected write error")
        self.write(address % self.size, data)


class FaultRamRead(AxiRamRead):
    """AxiRamRead answering SLVERR (data zero) for beats touching ``bad``."""

    bad: tuple[int, int] | None = None

    async def _read(self, address: int, length: int) -> bytes:
        if self.bad and address < self.bad[1] and address + length > self.bad[0]:
            raise OSError("injected read error")
        return self.read(address % self.size, length)


class FaultAxiRam(Memory):
    """``AxiRam`` with an optional byte range [lo, hi) that answers SLVERR."""

    def __init__(self, bus: AxiBus, clock, reset, size: int) -> None:
        super().__init__(size)
        self.write_if = FaultRamWrite(bus.write, clock, reset, mem=self.mem)
        self.read_if = FaultRamRead(bus.read, clock, reset, mem=self.mem)
        for c in (self.write_if, self.read_if):
            c.log.setLevel(logging.WARNING)

    def set_bad(self, bad: tuple[int, int] | None) -> None:
        self.write_if.bad = self.read_if.bad = bad

    def channels(self) -> list:
        """AW, W, B, AR, R."""
        w, r = self.write_if, self.read_if
        return [w.aw_channel, w.w_channel, w.b_channel, r.ar_channel, r.r_channel]

    def set_pause(self, gens: list | None) -> None:
        """One pause generator per channel (AW, W, B, AR, R); None: never pause."""
        for ch, g in zip(self.channels(), gens or [None] * 5, strict=True):
            ch.set_pause_generator(g)


class TB(AxisTB):
    def __init__(self, dut) -> None:
        super().__init__(dut)
        self.g = fs.StoreGeometry(
            num_tx=param("NUM_TX"), num_rx=param("NUM_RX"), n_range=param("N_RANGE"),
            n_doppler=param("N_DOPPLER"), data_w=param("DATA_W"), tile_r=param("TILE_R"),
            axi_data_w=param("AXI_DATA_W"), axi_addr_w=param("AXI_ADDR_W"),
            mem_base=param("MEM_BASE"), read_order=param("READ_ORDER", 0))
        self.ram = FaultAxiRam(AxiBus.from_prefix(dut, "m_axi_mem"), dut.clk, dut.rst,
                               size=self.g.mem_base + self.g.memory_bytes)
        self.aw: list[tuple[int, int]] = []
        self.ar: list[tuple[int, int]] = []
        self.events: list[tuple[int, int, int, str]] = []   # (clock, addr, beats, W|R)
        self.s_stalls = 0
        self.count_stalls = False
        cocotb.start_soon(self._axi_monitor())

    async def _axi_monitor(self) -> None:
        """Record every AW/AR (address, beats); count input stalls when ``count_stalls``;
        check that at most MAX_OUTSTANDING write bursts (AW in, B not yet) and read bursts
        (AR in, last R beat not yet) are open (a limit off on the tie, ``<=`` for ``<``, lets
        one more through: mutant ``frame_store_axi:tie:1``)."""
        d = self.dut
        beat_size = self.g.axi_bytes.bit_length() - 1
        limit = param("MAX_OUTSTANDING")
        cyc = open_w = open_r = 0
        while True:
            await RisingEdge(d.clk)
            cyc += 1
            if d.rst.value == 1:
                open_w = open_r = 0
                continue
            open_w += int(d.m_axi_mem_awvalid.value == 1 and d.m_axi_mem_awready.value == 1)
            open_w -= int(d.m_axi_mem_bvalid.value == 1 and d.m_axi_mem_bready.value == 1)
            open_r += int(d.m_axi_mem_arvalid.value == 1 and d.m_axi_mem_arready.value == 1)
            open_r -= int(d.m_axi_mem_rvalid.value == 1 and d.m_axi_mem_rready.value == 1
                          and d.m_axi_mem_rlast.value == 1)
            open_w, open_r = max(open_w, 0), max(open_r, 0)
            assert open_w <= limit and open_r <= limit, (cyc, open_w, open_r, limit)
            if d.m_axi_mem_awvalid.value == 1 and d.m_axi_mem_awready.value == 1:
                assert int(d.m_axi_mem_awsize.value) == beat_size
                assert int(d.m_axi_mem_awburst.value) == 1
                self.aw.append((int(d.m_axi_mem_awaddr.value), int(d.m_axi_mem_awlen.value) + 1))
                self.events.append((cyc, *self.aw[-1], fs.WRITE))
            if d.m_axi_mem_arvalid.value == 1 and d.m_axi_mem_arready.value == 1:
                assert int(d.m_axi_mem_arsize.value) == beat_size
                assert int(d.m_axi_mem_arburst.value) == 1
                self.ar.append((int(d.m_axi_mem_araddr.value), int(d.m_axi_mem_arlen.value) + 1))
                self.events.append((cyc, *self.ar[-1], fs.READ))
            if self.count_stalls and d.s_axis_tvalid.value == 1 and d.s_axis_tready.value == 0:
                self.s_stalls += 1

    @property
    def w_beats(self) -> int:
        return sum(n for _, n in self.aw)

    @property
    def r_beats(self) -> int:
        return sum(n for _, n in self.ar)

    def clear_trace(self) -> None:
        self.aw.clear()
        self.ar.clear()
        self.events.clear()

    def random_frame(self) -> np.ndarray:
        g = self.g
        return self.rng.integers(0, 1 << 32, (g.frame_words, g.num_rx), dtype=np.uint32)

    async def send_frame(self, words: np.ndarray) -> None:
        nr = self.g.n_range
        for c in range(len(words) // nr):
            await self.source.send(AxiStreamFrame(words_to_bytes(words[c * nr:(c + 1) * nr])))

    async def recv_frames(self, n: int) -> list[np.ndarray]:
        """n frames of Doppler vectors; TLAST closes each vector, TUSER marks frame starts."""
        g = self.g
        frames = []
        for _ in range(n):
            vecs = []
            for v in range(g.num_tx * g.n_range):
                f = await self.sink.recv(compact=False)
                w = np.frombuffer(bytes(f.tdata), dtype="<u4").reshape(-1, g.num_rx)
                assert len(w) == g.n_doppler, f"vector of {len(w)} words"
                lanes = g.num_rx * 4
                sof = [f.tuser[i * lanes] for i in range(len(w))]
                assert sof == [int(v == 0 and i == 0) for i in range(len(w))], sof[:4]
                vecs.append(w)
            frames.append(np.vstack(vecs))
        return frames

    async def within_budget(self, n_frames: int, wait: Awaitable[T]) -> T:
        """Await ``wait`` (a coroutine or task) within a generous budget for ``n_frames``
        frames (10,000 clocks + 200 per word, far above what the stall patterns here cost):
        a stream that stops fails the test (``SimTimeoutError``) instead of hanging it."""
        budget = (10_000 + 200 * n_frames * self.g.frame_words) * CLK_PERIOD_NS
        return await with_timeout(wait, budget, "ns")

    async def run_frames(self, frames: list[np.ndarray]) -> list[np.ndarray]:
        """Send the frames and receive as many, within :meth:`within_budget`."""

        async def both() -> list[np.ndarray]:
            rx = cocotb.start_soon(self.recv_frames(len(frames)))
            for f in frames:
                await self.send_frame(f)
            return await rx

        return await self.within_budget(len(frames), both())

    def status(self) -> dict[str, int]:
        d = self.dut
        return {k: int(getattr(d, k).value) for k in (
            "status_framing_error", "framing_error_count", "status_mem_error",
            "mem_error_count", "frames_in", "frames_out")}

    def check_payload(self, got: list[np.ndarray], sent: list[np.ndarray]) -> None:
        for k, (o, e) in enumerate(zip(got, fs.store_frames(sent, self.g), strict=True)):
            if not np.array_equal(o, e):
                bad = np.nonzero((o != e).any(axis=1))[0]
                raise AssertionError(f"frame {k}: {len(bad)} words differ, first at {bad[0]}")

    def check_trace(self, first: int, n: int) -> None:
        """AW and AR bursts of frames first..first+n-1 against the model, in order."""
        g = self.g
        for name, got, gen in (("AW", self.aw, fs.write_bursts), ("AR", self.ar, fs.read_bursts)):
            exp = np.concatenate([gen(g, k) for k in range(first, first + n)])
            fs.check_bursts(g, np.asarray(got, dtype=np.int64).reshape(-1, 2))
            assert len(got) == len(exp), f"{name}: {len(got)} bursts, model {len(exp)}"
            for i, (a, e) in enumerate(zip(got, exp.tolist(), strict=True)):
                assert a == tuple(e), f"{name} burst {i}: {a[0]:#x}+{a[1]} vs model " \
                                      f"{e[0]:#x}+{e[1]}"


def stalls(seed: int, p: float = 0.3) -> list:
    return [random_pause(p, seed + i) for i in range(5)]


def long_stalls(seed: int, run: int) -> list:
    return [bursty_pause(seed + i, max_run=run, busy_fraction=0.4) for i in range(5)]


@cocotb.test()
async def test_throughput(dut):
    """Back-to-back frames, always-ready memory: output rate and the address trace."""
    tb = TB(dut)
    tb.start_meter()
    await tb.reset()
    nfr = 3
    frames = [tb.random_frame() for _ in range(nfr)]
    got = await tb.run_frames(frames)
    tb.check_payload(got, frames)
    tb.check_trace(0, nfr)
    fw = tb.g.frame_words
    span = tb.out_last - tb.out_first + 1
    tb.log.info("throughput: %d words out in %d clocks (%.3f words/clock); first in -> first "
                "out %d clocks; %d W beats, %d R beats", tb.out_beats, span,
                tb.out_beats / span, tb.out_first - tb.in_first, tb.w_beats, tb.r_beats)
    assert tb.w_beats * tb.g.axi_bytes == nfr * tb.g.frame_bytes
    assert tb.r_beats * tb.g.axi_bytes == nfr * tb.g.frame_bytes
    # output of frames 1..n-1 follows at (nearly) the port's rate: one word per clock, or one
    # beat per clock when a word needs several beats
    clocks_per_word = max(1, tb.g.word_bytes // tb.g.axi_bytes)
    assert span <= (nfr * fw + fw // 2) * clocks_per_word + 64, span
    st = tb.status()
    assert st == {"status_framing_error": 0, "framing_error_count": 0, "status_mem_error": 0,
                  "mem_error_count": 0, "frames_in": nfr, "frames_out": nfr}, st


@cocotb.test()
async def test_axi_stalls(dut):
    """Random then long stalls on all five AXI channels and on both streams."""
    tb = TB(dut)
    await tb.reset()
    nfr = 4
    tb.ram.set_pause(stalls(10))
    tb.set_idle_generator(random_pause(0.2, 1))
    tb.set_backpressure_generator(random_pause(0.3, 2))
    frames = [tb.random_frame() for _ in range(nfr)]
    rx = cocotb.start_soon(tb.recv_frames(nfr))
    for k, f in enumerate(frames):
        if k == nfr // 2:
            tb.ram.set_pause(long_stalls(20, 4 * tb.g.n_doppler))
            tb.set_backpressure_generator(bursty_pause(3, max_run=2 * tb.g.n_doppler))
        await tb.send_frame(f)
    got = await tb.within_budget(nfr, rx)
    tb.check_payload(got, frames)
    tb.check_trace(0, nfr)
    st = tb.status()
    assert st["frames_out"] == nfr and st["mem_error_count"] == 0, st


@cocotb.test()
async def test_slow_memory(dut):
    """A memory slower than the input: s_axis_tready drops (the back-pressure the chirp
    ping-pong turns into whole dropped chirps), not one word is lost here."""
    tb = TB(dut)
    await tb.reset()
    tb.count_stalls = True
    # at most 0.4 words per clock through the port whatever the beat / word ratio
    words_per_beat = max(1, tb.g.axi_bytes // tb.g.word_bytes)
    p = max(0.6, 1 - 0.4 / words_per_beat)
    tb.ram.set_pause([random_pause(p, 30 + i) for i in range(5)])
    frames = [tb.random_frame() for _ in range(2)]
    got = await tb.run_frames(frames)
    tb.check_payload(got, frames)
    tb.log.info("input stalled %d clocks by the slow memory", tb.s_stalls)
    assert tb.s_stalls > tb.g.frame_words, tb.s_stalls
    assert tb.status()["mem_error_count"] == 0


@cocotb.test()
async def test_read_waits_for_bresp(dut):
    """Writes slow (W and B stall 90 %), reads fast: a frame is read only after every BRESP
    of it is in, never from memory its writes have not reached yet."""
    tb = TB(dut)
    await tb.reset()
    tb.ram.set_pause([None, random_pause(0.9, 60), random_pause(0.9, 61), None, None])
    frames = [tb.random_frame() for _ in range(3)]
    got = await tb.run_frames(frames)
    tb.check_payload(got, frames)


@cocotb.test()
async def test_slverr(dut):
    """One AXI beat of area 0 answers SLVERR: flagged and counted (one per bad write burst,
    one per bad read beat), frames keep flowing, only the words of that beat are lost."""
    tb = TB(dut)
    await tb.reset()
    g = tb.g
    tb.ram.set_pause(stalls(40, 0.2))
    off = (g.frame_bytes // 3) // g.axi_bytes * g.axi_bytes
    lo = g.mem_base + off
    tb.ram.set_bad((lo, lo + g.axi_bytes))
    nfr = 4
    frames = [tb.random_frame() for _ in range(nfr)]
    got = await tb.run_frames(frames)
    # lanes whose bytes fall in the bad beat read back as zero in area-0 frames (0, 2)
    woff = g.word_offsets()
    lane = woff[:, None] + 4 * np.arange(g.num_rx)[None, :]
    lost = (lane >= off) & (lane < off + g.axi_bytes)
    assert lost.sum() == g.axi_bytes // 4
    exp_in = [f.copy() for f in frames]
    for k in (0, 2):
        exp_in[k][lost] = 0
    tb.check_payload(got, exp_in)
    st = tb.status()
    assert st["status_mem_error"] == 1 and st["mem_error_count"] == 4, st
    assert st["frames_out"] == nfr and st["frames_in"] == nfr, st
    tb.ram.set_bad(None)


@cocotb.test()
async def test_slverr_read_only(dut):
    """Only a read beat answers SLVERR (its write succeeded): the sticky flag and the count
    must come from the R channel alone."""
    tb = TB(dut)
    await tb.reset()
    g = tb.g
    off = (g.frame_bytes // 3) // g.axi_bytes * g.axi_bytes
    lo = g.mem_base + off
    tb.ram.read_if.bad = (lo, lo + g.axi_bytes)
    frames = [tb.random_frame() for _ in range(2)]
    got = await tb.run_frames(frames)
    woff = g.word_offsets()
    lane = woff[:, None] + 4 * np.arange(g.num_rx)[None, :]
    exp_in = [f.copy() for f in frames]
    exp_in[0][(lane >= off) & (lane < off + g.axi_bytes)] = 0
    tb.check_payload(got, exp_in)
    st = tb.status()
    assert st["status_mem_error"] == 1 and st["mem_error_count"] == 1, st
    tb.ram.set_bad(None)


@cocotb.test()
async def test_framing_error(dut):
    """An early TLAST is flagged and counted; data still placed by count."""
    tb = TB(dut)
    await tb.reset()
    f = tb.random_frame()
    nr = tb.g.n_range
    rx = cocotb.start_soon(tb.recv_frames(1))
    await tb.source.send(AxiStreamFrame(words_to_bytes(f[:nr - 1])))
    await tb.source.send(AxiStreamFrame(words_to_bytes(f[nr - 1:nr])))
    for c in range(1, len(f) // nr):
        await tb.source.send(AxiStreamFrame(words_to_bytes(f[c * nr:(c + 1) * nr])))
    got = await tb.within_budget(1, rx)
    tb.check_payload(got, [f])
    st = tb.status()
    assert st["status_framing_error"] == 1 and st["framing_error_count"] == 1, st


@cocotb.test()
async def test_reset_recovery(dut):
    """Reset (store and memory) while one frame is read and the next written, then clean
    frames with the address trace starting again at area 0."""
    tb = TB(dut)
    await tb.reset()
    tb.ram.set_pause(stalls(50))
    tb.set_backpressure_generator(random_pause(0.3, 8))
    for _ in range(2):
        await tb.send_frame(tb.random_frame())
    await tb.cycles(tb.g.frame_words + tb.g.frame_words // 2)
    tb.source.clear()
    await tb.reset()
    tb.sink.clear()
    tb.clear_trace()
    st = tb.status()
    assert all(v == 0 for v in st.values()), st
    tb.set_backpressure_generator(no_pause())
    frames = [tb.random_frame() for _ in range(3)]
    got = await tb.run_frames(frames)
    tb.check_payload(got, frames)
    tb.check_trace(0, 3)
    assert tb.status()["frames_out"] == 3


@cocotb.test()
async def test_input_held_through_reset(dut):
    """A source outside the store's reset presents a frame's first word during a reset and
    holds it (TVALID high until TREADY): no word is taken while the store is in reset (one
    taken then is lost, the reset empties the write FIFO: mutant frame_store_fifo:dropfirst:0,
    its TREADY without !rst, seen where the write gearbox passes words straight through,
    WORD_W >= AXI_DATA_W), and the frame comes out whole after the reset."""
    tb = TB(dut)
    await tb.reset()
    frame = tb.random_frame()
    await tb.hold_word_through_reset(frame[0], tlast=tb.g.n_range == 1)
    nr = tb.g.n_range
    rx = cocotb.start_soon(tb.recv_frames(1))
    if nr > 1:
        await tb.source.send(AxiStreamFrame(words_to_bytes(frame[1:nr])))
    for c in range(1, len(frame) // nr):
        await tb.source.send(AxiStreamFrame(words_to_bytes(frame[c * nr:(c + 1) * nr])))
    tb.check_payload(await tb.within_budget(1, rx), [frame])
    st = tb.status()
    assert st["frames_in"] == st["frames_out"] == 1 and st["framing_error_count"] == 0, st


# ------------------------------------------------------------------------------------------
# pytest: one Verilator build per HDL parameter set
PARAMS = [
    # 1 TX, one 32-bit lane in 128-bit beats (4 words per beat), 1-beat write bursts
    dict(NUM_TX=1, NUM_RX=1, N_RANGE=8, N_DOPPLER=8, TILE_R=4, AXI_DATA_W=128,
         MAX_OUTSTANDING=4, WFIFO_DEPTH=4, MEM_BASE=0x1000),
    # 4 TX x 16 lanes (512-bit words) over a 128-bit port: 4 beats per word, 256-beat reads
    dict(NUM_TX=4, NUM_RX=16, N_RANGE=8, N_DOPPLER=8, TILE_R=8, AXI_DATA_W=128,
         MAX_OUTSTANDING=8, WFIFO_DEPTH=16, MEM_BASE=0x0),
    # the full preset's word and port width (512 bits), 2 TX, 2 outstanding, a base that is
    # not a multiple of the frame size
    dict(NUM_TX=2, NUM_RX=16, N_RANGE=16, N_DOPPLER=16, TILE_R=8, AXI_DATA_W=512,
         MAX_OUTSTANDING=2, WFIFO_DEPTH=16, MEM_BASE=0x3000),
    # READ_ORDER 1 (r, t, d), on-chip detection: 4 TX, a group (4 strips) of 8 KiB read in
    # two 4 KiB bursts, 4-beat write rows
    dict(NUM_TX=4, NUM_RX=4, N_RANGE=8, N_DOPPLER=32, TILE_R=4, AXI_DATA_W=128,
         MAX_OUTSTANDING=4, WFIFO_DEPTH=16, MEM_BASE=0x2000, READ_ORDER=1),
    # READ_ORDER 1 with 4 words per beat (one 32-bit lane) and 2 TX: 256-byte groups
    dict(NUM_TX=2, NUM_RX=1, N_RANGE=8, N_DOPPLER=8, TILE_R=4, AXI_DATA_W=128,
         MAX_OUTSTANDING=2, WFIFO_DEPTH=4, MEM_BASE=0x0, READ_ORDER=1),
    # 3 TX (xWR1843), cube order: 12 KiB frame areas, 4-beat rows
    dict(NUM_TX=3, NUM_RX=4, N_RANGE=16, N_DOPPLER=16, TILE_R=4, AXI_DATA_W=128,
         MAX_OUTSTANDING=4, WFIFO_DEPTH=16, MEM_BASE=0x1000),
    # 3 TX, READ_ORDER 1: 384-byte groups read in 128-byte bursts into 32-entry halves,
    # 768-byte frame areas (the second one not 4 KiB aligned)
    dict(NUM_TX=3, NUM_RX=1, N_RANGE=8, N_DOPPLER=8, TILE_R=4, AXI_DATA_W=128,
         MAX_OUTSTANDING=2, WFIFO_DEPTH=4, MEM_BASE=0x0, READ_ORDER=1),
]


@pytest.mark.parametrize("parameters", PARAMS, ids=lambda p: "_".join(
    f"{k}{v}" for k, v in p.items() if k not in ("MEM_BASE",)))
def test_frame_store_axi(parameters: dict) -> None:
    here = Path(__file__).resolve().parent
    run_cocotb("frame_store_axi", rtl_sources("common/*.sv", "buffers/*.sv"),
               "test_frame_store_axi", here,
               parameters={"DATA_W": 16, "AXI_ADDR_W": 32, "AXI_ID_W": 1, **parameters})


MODEL_GEOMETRIES = [
    dict(num_tx=1, num_rx=1, n_range=8, n_doppler=8, tile_r=4),
    dict(num_tx=4, num_rx=16, n_range=8, n_doppler=8, tile_r=8),
    dict(num_tx=1, num_rx=4, n_range=64, n_doppler=256, tile_r=16),            # paper-fpga
    dict(num_tx=4, num_rx=16, n_range=256, n_doppler=256, tile_r=16,           # full
         axi_data_w=512, mem_base=0x8000_0000),
    dict(num_tx=4, num_rx=4, n_range=16, n_doppler=32, tile_r=4, read_order=1),
    dict(num_tx=2, num_rx=1, n_range=8, n_doppler=8, tile_r=4, read_order=1),
    dict(num_tx=4, num_rx=16, n_range=256, n_doppler=256, tile_r=4,            # full, mode 1
         axi_data_w=512, read_order=1),
    dict(num_tx=3, num_rx=4, n_range=16, n_doppler=16, tile_r=4),              # 3 TX
    dict(num_tx=3, num_rx=1, n_range=8, n_doppler=8, tile_r=4, read_order=1),
    dict(num_tx=3, num_rx=4, n_range=8, n_doppler=64, tile_r=4, read_order=1),  # 12 KiB groups
    dict(num_tx=3, num_rx=4, n_range=256, n_doppler=128, tile_r=4,             # xWR1843, mode 1
         axi_data_w=512, read_order=1),
]


@pytest.mark.parametrize("geom", MODEL_GEOMETRIES, ids=lambda g: "_".join(map(str, g.values())))
def test_model_payload_and_trace(geom: dict) -> None:
    """The store through its address layout gives the on-chip corner turn's output; every
    burst obeys the AXI4 rules; each frame's writes and reads cover its area exactly once."""
    g = fs.StoreGeometry(**geom)
    rng = np.random.default_rng(0)
    frames = [rng.integers(0, 1 << 32, (g.frame_words, g.num_rx), dtype=np.uint32)
              for _ in range(3)]
    for o, e in zip(fs.store_frames(frames, g), fs.reference(frames, g), strict=True):
        assert np.array_equal(o, e)
    for k in range(3):
        for b in (fs.write_bursts(g, k), fs.read_bursts(g, k)):
            fs.check_bursts(g, b)
            covered = np.concatenate([np.arange(a, a + n * g.axi_bytes, g.axi_bytes)
                                      for a, n in b])
            assert np.array_equal(np.sort(covered), g.area_base(k)
                                  + np.arange(0, g.frame_bytes, g.axi_bytes))


def test_model_rejects_bad_geometry() -> None:
    with pytest.raises(ValueError, match="mem_base"):
        fs.StoreGeometry(num_tx=1, num_rx=4, n_range=64, n_doppler=256, mem_base=0x800)
    with pytest.raises(ValueError, match="tile_r"):
        fs.StoreGeometry(num_tx=1, num_rx=1, n_range=64, n_doppler=256, tile_r=2)
    with pytest.raises(ValueError, match="read_order"):
        fs.StoreGeometry(num_tx=4, num_rx=4, n_range=64, n_doppler=64, read_order=2)
    with pytest.raises(ValueError, match="axi_addr_w"):
        fs.StoreGeometry(num_tx=4, num_rx=16, n_range=256, n_doppler=256,
                         mem_base=0xFF00_0000)


def test_page_model() -> None:
    """Row hits: a linear stream hits except once per row; alternating rows of one bank miss."""
    pm = fs.DramPageModel(page_bytes=8192, banks=8, access_bytes=64)
    lin = [(a, 64, fs.READ) for a in range(0, 65536, 4096)]
    assert pm.row_hits(lin, 64) == (1024 - 8, 1024)
    thrash = [(0, 1, fs.READ), (65536, 1, fs.READ)] * 4
    assert pm.row_hits(thrash, 64) == (0, 8)


# ------------------------------------------------------------------------------------------
# benchmark (run by bench_frame_store_axi.py only: needs FS_BENCH_JSON)
@cocotb.test(skip=os.environ.get("FS_BENCH_JSON") is None)
async def bench(dut):
    """Saturated input and output, memory always ready or stalling FS_BENCH_STALL of the
    cycles on every channel: beats per clock in each direction, frame period, latency, the
    AW/AR trace in issue order (for the DRAM page model), payload checked bit-exact."""
    import json
    import time

    tb = TB(dut)
    g = tb.g
    stall = float(os.environ.get("FS_BENCH_STALL", "0"))
    nfr = int(os.environ.get("FS_BENCH_FRAMES", "3"))
    done_at: list[int] = []

    async def watch() -> None:
        cyc = 0
        last_out = 0
        while True:
            await RisingEdge(tb.dut.clk)
            cyc += 1
            fo = int(tb.dut.frames_out.value)
            if fo != last_out:
                done_at.append(cyc)
                last_out = fo

    await tb.reset()
    tb.start_meter()
    cocotb.start_soon(watch())
    if stall > 0:
        tb.ram.set_pause(stalls(70, stall))
    frames = [tb.random_frame() for _ in range(nfr)]
    t0 = time.perf_counter()
    got = await tb.run_frames(frames)
    wall = time.perf_counter() - t0
    tb.check_payload(got, frames)
    tb.check_trace(0, nfr)
    periods = np.diff(done_at)
    result = {
        "frames": nfr, "stall": stall, "frame_words": g.frame_words,
        "w_beats": tb.w_beats, "r_beats": tb.r_beats,
        "period_cycles": int(periods.max()) if len(periods) else None,
        "latency_cycles": tb.out_first - tb.in_first,
        "out_span": tb.out_last - tb.out_first + 1,
        "sim_cycles": tb.cycle, "wall_s": wall,
        "trace": [(a, b, k) for _, a, b, k in tb.events],
        "status": tb.status(),
    }
    Path(os.environ["FS_BENCH_JSON"]).write_text(json.dumps(result))
