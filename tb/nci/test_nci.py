"""cocotb testbench of ``rtl/detect/nci.sv`` against ``model/nci.py``."""

from __future__ import annotations

import logging
import os
from pathlib import Path

import cocotb
import numpy as np
import pytest
from cocotb.triggers import with_timeout
from cocotbext.axi import AxiStreamFrame

from model import nci as nci_model
from model.axis_packetizer import words_to_bytes
from rtlsim.axis import AxisTB, bursty_pause, no_pause, random_pause
from rtlsim.toolchain import param, rtl_sources, run_cocotb
from tb import progress


class TB(AxisTB):
    def __init__(self, dut) -> None:
        super().__init__(dut)
        for comp in (self.source, self.sink):
            comp.log.setLevel(logging.WARNING)
        self.num_tx = param("NUM_TX")
        self.num_rx = param("NUM_RX")
        self.n_range = param("N_RANGE")
        self.n_doppler = param("N_DOPPLER")
        assert param("DATA_W") == 16
        self.pow_w = nci_model.power_width(self.num_tx, self.num_rx)
        self.out_bytes = (self.pow_w + 7) // 8
        self.frame_words = self.num_tx * self.n_range * self.n_doppler
        self.rng = np.random.default_rng(int(os.environ.get("SEED", "1")))
        # a frame: NUM_TX x N_RANGE x N_DOPPLER words in, N_RANGE x N_DOPPLER cells out
        progress.watch(self, latency=progress.NCI_LATENCY,
                       frame=(self.frame_words, self.n_range * self.n_doppler))

    def random_frame(self) -> np.ndarray:
        """Random lanes, a quarter of them at the extremes (-32768 squares to 2^30)."""
        w = self.rng.integers(0, 1 << 32, (self.frame_words, self.num_rx), dtype=np.uint32)
        extreme = self.rng.random(w.shape) < 0.25
        w[extreme] = self.rng.choice(np.array([0x80008000, 0x7FFF8000, 0x80007FFF],
                                              dtype=np.uint32), size=int(extreme.sum()))
        return w

    async def send_frame(self, words: np.ndarray) -> None:
        """One frame as Doppler vectors (TLAST on the last Doppler bin of each)."""
        nd = self.n_doppler
        for v in range(len(words) // nd):
            await self.source.send(AxiStreamFrame(words_to_bytes(words[v * nd:(v + 1) * nd])))

    async def recv_frames(self, n: int) -> list[np.ndarray]:
        """Receive n power maps (one TLAST-closed row per range bin), checking TUSER = {r, d}."""
        bd = (self.n_doppler - 1).bit_length()
        maps = []
        for _ in range(n):
            rows = []
            for r in range(self.n_range):
                # a hang fails after 40x the stall-free row time
                f = await with_timeout(self.sink.recv(compact=False),
                                       40 * 10 * self.num_tx * self.n_doppler, "ns")
                raw = np.frombuffer(bytes(f.tdata), dtype=np.uint8).reshape(-1, self.out_bytes)
                assert len(raw) == self.n_doppler, f"row of {len(raw)} cells"
                vals = [int.from_bytes(bytes(c), "little") for c in raw]
                tuser = [f.tuser[i * self.out_bytes] for i in range(len(raw))]
                assert tuser == [(r << bd) | d for d in range(self.n_doppler)], (r, tuser[:4])
                rows.append(vals)
            maps.append(np.array(rows, dtype=np.int64))
        return maps

    async def run_frames(self, frames: list[np.ndarray]) -> None:
        """Send the frames while receiving as many power maps, then :meth:`check` them."""
        rx = cocotb.start_soon(self.recv_frames(len(frames)))
        for f in frames:
            await self.send_frame(f)
        self.check(await rx, frames)

    def check(self, got: list[np.ndarray], sent: list[np.ndarray]) -> None:
        for k, (g, f) in enumerate(zip(got, sent, strict=True)):
            exp = nci_model.nci(f, self.num_tx, self.n_range, self.n_doppler)
            if not np.array_equal(g, exp):
                bad = np.argwhere(g != exp)
                raise AssertionError(f"frame {k}: {len(bad)} cells differ, first at "
                                     f"{tuple(bad[0])}: {g[tuple(bad[0])]} != {exp[tuple(bad[0])]}")


@cocotb.test()
async def test_throughput(dut):
    """Back-to-back frames without stalls: one input word per clock."""
    tb = TB(dut)
    tb.start_meter()
    await tb.reset()
    await tb.run_frames([tb.random_frame() for _ in range(3)])
    span = tb.cycle - tb.in_first
    tb.log.info("%d input words in %d clocks", tb.in_beats, span)
    assert tb.in_beats == 3 * tb.frame_words
    assert int(dut.frame_count.value) == 3 and int(dut.status_framing_error.value) == 0


@cocotb.test()
async def test_random_stalls(dut):
    """Random and long TVALID gaps / TREADY stalls over several frames."""
    tb = TB(dut)
    await tb.reset()
    tb.set_idle_generator(random_pause(0.3, 1))
    tb.set_backpressure_generator(bursty_pause(2, max_run=2 * tb.n_doppler, busy_fraction=0.4))
    frames = [tb.random_frame() for _ in range(4)]
    rx = cocotb.start_soon(tb.recv_frames(4))
    for k, f in enumerate(frames):
        if k == 2:
            tb.set_idle_generator(bursty_pause(3, max_run=tb.n_doppler))
            tb.set_backpressure_generator(random_pause(0.5, 4))
        await tb.send_frame(f)
    got = await rx
    tb.check(got, frames)
    assert int(dut.status_framing_error.value) == 0


@cocotb.test()
async def test_framing_error(dut):
    """A misplaced TLAST is flagged (sticky, cleared by reset); data still integrates by
    count."""
    tb = TB(dut)
    await tb.reset()
    f = tb.random_frame()
    nd = tb.n_doppler
    rx = cocotb.start_soon(tb.recv_frames(1))
    await tb.source.send(AxiStreamFrame(words_to_bytes(f[:nd + 1])))  # TLAST one word late
    await tb.source.send(AxiStreamFrame(words_to_bytes(f[nd + 1:2 * nd])))
    for v in range(2, len(f) // nd):
        await tb.source.send(AxiStreamFrame(words_to_bytes(f[v * nd:(v + 1) * nd])))
    got = await rx
    tb.check(got, [f])
    assert int(dut.status_framing_error.value) == 1
    await tb.cycles(20)
    assert int(dut.status_framing_error.value) == 1, "framing flag not sticky"
    await tb.reset()
    assert int(dut.status_framing_error.value) == 0, "framing flag not cleared by reset"


@cocotb.test()
async def test_reset_recovery(dut):
    """Reset in mid-frame (input and output busy), then clean frames."""
    tb = TB(dut)
    await tb.reset()
    tb.set_backpressure_generator(random_pause(0.5, 8))
    f = tb.random_frame()
    cocotb.start_soon(tb.send_frame(f))
    await tb.cycles(tb.frame_words // 2 + 3)
    tb.source.clear()
    await tb.reset()
    tb.sink.clear()
    assert int(dut.frame_count.value) == 0 and int(dut.m_axis_tvalid.value) == 0
    tb.set_idle_generator(random_pause(0.2, 9))
    tb.set_backpressure_generator(no_pause())
    await tb.run_frames([tb.random_frame() for _ in range(2)])


# ------------------------------------------------------------------------------------------
# pytest: one Verilator build per HDL parameter set
PARAMS = [
    # TX count not a power of two (accumulator RAM, t wrap at 3); an odd RX count (the
    # adder tree's last lane pair holds one lane)
    dict(NUM_TX=3, NUM_RX=3, N_RANGE=4, N_DOPPLER=4),
]
LONG_PARAMS = [  # make test-detect-long (DETECT_LONG=1)
    # smallest: one channel, 2 x 2 map
    dict(NUM_TX=1, NUM_RX=1, N_RANGE=2, N_DOPPLER=2),
    # 4 TX x 16 RX (the full preset's virtual array, 38-bit power), small map
    dict(NUM_TX=4, NUM_RX=16, N_RANGE=4, N_DOPPLER=16),
    # paper-fpga: 1 TX x 4 RX, 64 x 256
    dict(NUM_TX=1, NUM_RX=4, N_RANGE=64, N_DOPPLER=256),
]
if os.environ.get("DETECT_LONG", "0") not in ("", "0"):
    PARAMS += LONG_PARAMS


@pytest.mark.parametrize("parameters", PARAMS, ids=lambda p: "_".join(
    f"{k}{v}" for k, v in p.items()))
def test_nci(parameters: dict) -> None:
    here = Path(__file__).resolve().parent
    sources = [*rtl_sources("common/*.sv", "buffers/buf_*.sv"), *rtl_sources("detect/nci.sv")]
    run_cocotb("nci", sources, "test_nci", here, parameters={"DATA_W": 16, **parameters})
