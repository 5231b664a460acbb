"""cocotb testbench of ``rtl/detect/detect_records.sv`` against ``model/detect_records.py``.

The snapshot port is driven word by word while ``snap_room`` allows it; the CFAR cells come
from ``model/cfar_2d.py`` on a random map, sent only after their snapshot row was written
(as in the chain). A slow cell source lets the writer run into the ``snap_room`` interlock.
The run-time record limit ``cfg_max_detections`` is MAX_DETECTIONS, or (``test_runtime_limit``)
changed at random clocks, in mid-frame too: each frame must use the value it had at the
frame's first cell.
"""

from __future__ import annotations

import logging
import os
import random
from pathlib import Path

import cocotb
import numpy as np
import pytest
from cocotb.triggers import FallingEdge, RisingEdge, with_timeout
from cocotbext.axi import AxiStreamFrame

from model import cfar_2d as cm
from model import detect_records as dr
from rtlsim.axis import AxisTB, bursty_pause, no_pause, random_pause
from rtlsim.toolchain import param, rtl_sources, run_cocotb
from tb import progress

GUARD, TRAIN = (1, 1), (1, 2)


class TB(AxisTB):
    def __init__(self, dut) -> None:
        super().__init__(dut)
        for comp in (self.source, self.sink):
            comp.log.setLevel(logging.WARNING)
        self.num_tx, self.num_rx = param("NUM_TX"), param("NUM_RX")
        self.n_range, self.n_doppler = param("N_RANGE"), param("N_DOPPLER")
        self.max_det = param("MAX_DETECTIONS")
        self.cfg = cm.Cfar2dConfig(n_range=self.n_range, n_doppler=self.n_doppler,
                                   pow_w=param("POW_W"), guard=GUARD, train=TRAIN)
        assert (param("SUM_W"), param("CNT_W")) == (self.cfg.sum_w, self.cfg.cnt_w)
        self.frame_words = dr.frame_words(self.num_tx, self.num_rx, self.max_det)
        self.rng = np.random.default_rng(int(os.environ.get("SEED", "1")))
        self.rows_written = 0
        self.writer_gap = 0.0
        self.tasks: list = []
        self.limits: list[int] = []       # the limit at each frame's first cell
        dut.snap_wr.value = 0
        dut.snap_data.value = 0
        dut.cfg_max_detections.value = self.max_det
        cocotb.start_soon(self._watch_limits())
        # latency: a frame's records, trailer and zero fill are FRAME_WORDS words
        # (docs/detect.md, the record format), so a working block owes no answer for longer
        progress.watch(self, latency=self.frame_words,
                       frame=(self.n_range * self.n_doppler, self.frame_words))

    async def _watch_limits(self) -> None:
        """Record cfg_max_detections at every frame's first cell beat."""
        d, cells, n = self.dut, self.n_range * self.n_doppler, 0
        while True:
            await RisingEdge(d.clk)
            if d.rst.value == 1:
                n = 0
                self.limits = []
            elif d.s_axis_tvalid.value == 1 and d.s_axis_tready.value == 1:
                if n % cells == 0:
                    self.limits.append(int(d.cfg_max_detections.value))
                n += 1

    async def change_limits(self, seed: int) -> None:
        """cfg_max_detections to a random legal value every few to few tens of clocks."""
        rng = random.Random(seed)
        while True:
            await self.cycles(rng.randint(3, 60))
            await FallingEdge(self.dut.clk)
            self.dut.cfg_max_detections.value = rng.randint(1, self.max_det)

    def random_frame(self, n_targets: int) -> tuple[np.ndarray, np.ndarray]:
        """(snapshot words uint32 (r, t, d, rx) flattened, power map int64 (r, d))."""
        snap = self.rng.integers(0, 1 << 32, (self.n_range * self.num_tx * self.n_doppler,
                                              self.num_rx), dtype=np.uint32)
        p = self.rng.gamma(4, 1000.0, (self.n_range, self.n_doppler)).astype(np.int64)
        idx = self.rng.integers(0, p.size, n_targets)
        p.flat[idx] *= 200
        return snap, p

    async def write_snapshots(self, frames: list[np.ndarray], seed: int) -> None:
        """Snapshot words of all frames, one per clock at most, only while snap_room."""
        rng = random.Random(seed)
        d = self.dut
        row_words = self.num_tx * self.n_doppler
        for f in frames:
            for i, w in enumerate(f):
                while True:
                    await FallingEdge(d.clk)
                    if d.snap_room.value == 1 and rng.random() >= self.writer_gap:
                        break
                    d.snap_wr.value = 0
                d.snap_wr.value = 1
                d.snap_data.value = int.from_bytes(w.astype("<u4").tobytes(), "little")
                if (i + 1) % row_words == 0:
                    self.rows_written += 1
        await FallingEdge(d.clk)
        d.snap_wr.value = 0

    async def send_cells(self, maps: list[np.ndarray], scale: np.ndarray) -> None:
        """CFAR cells of every map in output order, row q after its snapshot row."""
        c = self.cfg
        bd = (c.n_doppler - 1).bit_length()
        order = cm.output_order(c)
        for k, p in enumerate(maps):
            res = cm.cfar_2d(p, c, scale)
            for q in range(c.n_range):
                while self.rows_written <= k * c.n_range + q:
                    await FallingEdge(self.dut.clk)
                data, tuser = b"", []
                for r, d in order[q * c.n_doppler:(q + 1) * c.n_doppler]:
                    v = cm.pack_cell(res, int(r), int(d), c)
                    data += v.to_bytes(c.out_bytes, "little")
                    tuser += [(int(r) << bd) | int(d)] * c.out_bytes
                await self.source.send(AxiStreamFrame(data, tuser=tuser))

    def expected(self, snaps: list[np.ndarray], maps: list[np.ndarray],
                 scale: np.ndarray) -> list[np.ndarray]:
        out, sticky = [], False
        c = self.cfg
        for k, (s, p) in enumerate(zip(snaps, maps, strict=True)):
            res = cm.cfar_2d(p, c, scale)
            sv = s.reshape(c.n_range, self.num_tx, c.n_doppler, self.num_rx)
            recs = [dr.Record.of_cell(res, r, d, sv[r, :, d, :])
                    for r, d in cm.output_order(c) if res.detect[r, d]]
            limit = self.limits[k]
            out.append(dr.encode_frame(recs, len(recs), self.num_tx, self.num_rx,
                                       self.max_det, frame_id=k, sticky=sticky, limit=limit))
            sticky = sticky or len(recs) > limit
        return out

    async def run(self, n_frames: int, targets: list[int], seed: int) -> None:
        scale = cm.scale_table(self.cfg, 1e-2, 4)
        frames = [self.random_frame(t) for t in targets[:n_frames]]
        snaps, maps = [f[0] for f in frames], [f[1] for f in frames]
        self.rows_written = 0
        self.tasks = [cocotb.start_soon(self.write_snapshots(snaps, seed)),
                      cocotb.start_soon(self.send_cells(maps, scale))]
        # a hang (deadlock) fails after 20x the stall-free frame time
        limit = 20 * 10 * (self.num_tx * self.n_range * self.n_doppler + self.frame_words)
        got = [await with_timeout(self.sink.recv(), limit, "ns") for _ in range(n_frames)]
        exp = self.expected(snaps, maps, scale)
        for k, (f, e) in enumerate(zip(got, exp, strict=True)):
            g = np.frombuffer(bytes(f.tdata), dtype="<u4").reshape(-1, self.num_rx)
            assert len(g) == self.frame_words, f"frame {k}: {len(g)} words"
            if not np.array_equal(g, e):
                bad = np.nonzero((g != e).any(axis=1))[0]
                raise AssertionError(f"frame {k}: {len(bad)} words differ, first at {bad[0]}: "
                                     f"{dr.decode_frame(g, self.num_tx).trailer} vs "
                                     f"{dr.decode_frame(e, self.num_tx).trailer}")


@cocotb.test()
async def test_frames(dut):
    """Back-to-back frames: few detections, more than MAX_DETECTIONS, few again."""
    tb = TB(dut)
    await tb.reset()
    await tb.run(3, [2, 3 * tb.max_det, 1], seed=1)
    assert int(dut.status_truncated.value) == 1 and int(dut.frame_count.value) == 3


@cocotb.test()
async def test_slow_cells_and_stalls(dut):
    """Slow, bursty cell source (the writer runs into snap_room) and output stalls."""
    tb = TB(dut)
    await tb.reset()
    tb.set_idle_generator(bursty_pause(1, max_run=3 * tb.n_doppler, busy_fraction=0.6))
    tb.set_backpressure_generator(random_pause(0.4, 2))
    await tb.run(3, [4, 2, 5], seed=2)


@cocotb.test()
async def test_reset_recovery(dut):
    """Reset while records are sent, then clean frames."""
    tb = TB(dut)
    await tb.reset()
    tb.set_backpressure_generator(random_pause(0.7, 3))
    task = cocotb.start_soon(tb.run(1, [3 * tb.max_det], seed=3))
    await tb.cycles(tb.n_range * tb.n_doppler)
    for t in [task, *tb.tasks]:
        t.cancel()
    dut.snap_wr.value = 0
    tb.source.clear()
    await tb.reset()
    tb.sink.clear()
    assert int(dut.frame_count.value) == 0 and int(dut.status_truncated.value) == 0
    tb.writer_gap = 0.3
    tb.set_backpressure_generator(no_pause())
    tb.set_idle_generator(random_pause(0.2, 4))
    await tb.run(2, [2, 1], seed=4)


@cocotb.test()
async def test_runtime_limit(dut):
    """cfg_max_detections changed at random clocks (mid-frame too), output stalls: each
    frame keeps the limit it had at its first cell; the frame length stays fixed."""
    tb = TB(dut)
    await tb.reset()
    tb.set_backpressure_generator(random_pause(0.3, 2))
    task = cocotb.start_soon(tb.change_limits(seed=5))
    await tb.run(8, [3 * tb.max_det, 2 * tb.max_det, 1, 3 * tb.max_det, 2, 4 * tb.max_det,
                     tb.max_det, 3 * tb.max_det], seed=5)
    task.cancel()
    assert len(set(tb.limits)) > 1, f"the limit never changed between frames: {tb.limits}"


# ------------------------------------------------------------------------------------------
def _params(num_tx: int, num_rx: int, n_range: int, n_doppler: int, max_det: int) -> dict:
    cfg = cm.Cfar2dConfig(n_range=n_range, n_doppler=n_doppler, pow_w=34, guard=GUARD,
                          train=TRAIN)
    return dict(NUM_TX=num_tx, NUM_RX=num_rx, N_RANGE=n_range, N_DOPPLER=n_doppler,
                POW_W=34, SUM_W=cfg.sum_w, CNT_W=cfg.cnt_w,
                SNAP_ROWS=dr.snap_rows(GUARD[0], TRAIN[0]), MAX_DETECTIONS=max_det)


PARAMS = [
    _params(1, 1, 8, 8, 3),     # 8-word headers, 1-word snapshots
    # one-word headers (the full preset's 16 lanes): the only geometry where the last record
    # of a truncated frame leaves out_q on the frame's last word while cells still come in
    # (mutant detect_records:count:0 miscounts the detections past MAX_DETECTIONS there)
    _params(4, 16, 8, 16, 4),   # one-word headers, 4-word snapshots
    _params(3, 2, 8, 8, 3),     # 3 TX (xWR1843): 3-word snapshots, TX wrap at 2
]


@pytest.mark.parametrize("parameters", PARAMS, ids=lambda p: "_".join(
    f"{k}{v}" for k, v in p.items()))
def test_detect_records(parameters: dict) -> None:
    here = Path(__file__).resolve().parent
    sources = rtl_sources("common/*.sv", "buffers/buf_*.sv", "detect/detect_records.sv")
    run_cocotb("detect_records", sources, "test_detect_records", here, parameters=parameters)
