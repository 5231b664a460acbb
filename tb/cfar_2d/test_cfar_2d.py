"""cocotb testbench of ``rtl/detect/cfar_2d.sv`` against ``model/cfar_2d.py``: every output
cell (power, training sum and count, decision, neighbour powers) of every kind built, chosen
at run time, with the local-maximum test off and on."""

from __future__ import annotations

import logging
import os
from pathlib import Path

import cocotb
import numpy as np
import pytest
from cocotb.triggers import with_timeout
from cocotbext.axi import AxiStreamFrame

from model import cfar_2d as cm
from rtlsim.axis import AxisTB, bursty_pause, no_pause, random_pause
from rtlsim.toolchain import param, rtl_sources, run_cocotb
from tb import progress

KIND_NAMES = cm.KINDS
N_CHANNELS = 4  # virtual channels of the test maps (Gamma(4) noise)
PFA = 1e-2      # high on purpose: every frame has noise detections as well as targets


class TB(AxisTB):
    def __init__(self, dut) -> None:
        super().__init__(dut)
        for comp in (self.source, self.sink):
            comp.log.setLevel(logging.WARNING)
        self.cfg = cm.Cfar2dConfig(
            n_range=param("N_RANGE"), n_doppler=param("N_DOPPLER"), pow_w=param("POW_W"),
            guard=(param("GUARD_R"), param("GUARD_D")), train=(param("TRAIN_R"), param("TRAIN_D")),
            kind=KIND_NAMES[param("KIND")], blank_top=param("BLANK_TOP"),
            report=(param("REPORT_LO", 0), param("REPORT_HI", param("N_RANGE"))),
            os=bool(param("OS_BUILD", 0)))
        self.set_kind(self.cfg.kind, False)
        self.in_bytes = (self.cfg.pow_w + 7) // 8
        self.rng = np.random.default_rng(int(os.environ.get("SEED", "1")))
        cells = self.cfg.n_range * self.cfg.n_doppler
        progress.watch(self, conserving=True, latency=progress.cfar_latency(self.cfg),
                       frame=(cells, cells))

    def set_kind(self, kind: str, local_max: bool) -> None:
        """Drive cfg_kind (its code, built or not) and cfg_local_max, and cfg_scale with the
        Pfa-derived table of the kind the RTL then runs (a CA/GO/SO code outside RUN_KINDS
        runs KIND; the local maximum is off unless LOCAL_MAX_BUILD)."""
        code, default = KIND_NAMES.index(kind), param("KIND")
        if code < 3 and not (param("RUN_KINDS", 7) | 1 << default) >> code & 1:
            kind = KIND_NAMES[default]
        self.kind = kind
        self.local_max = local_max and bool(param("LOCAL_MAX_BUILD", 1))
        self.scale = cm.scale_table(self.cfg, PFA, N_CHANNELS, kind=kind)
        self.dut.cfg_kind.value = code
        self.dut.cfg_local_max.value = int(local_max)
        self.dut.cfg_scale.value = cm.pack_scale(self.scale, self.cfg)

    def random_map(self) -> np.ndarray:
        """Gamma(4) noise (mean 4000) with a few strong cells, one at full scale."""
        c = self.cfg
        p = self.rng.gamma(N_CHANNELS, 1000.0, (c.n_range, c.n_doppler))
        n_t = max(2, c.n_range * c.n_doppler // 64)
        idx = self.rng.integers(0, c.n_range * c.n_doppler, n_t)
        p.flat[idx] *= self.rng.uniform(5, 500, n_t)
        p = np.minimum(p.astype(np.int64), (1 << c.pow_w) - 1)
        p.flat[idx[0]] = (1 << c.pow_w) - 1
        return p

    def tie_map(self) -> np.ndarray:
        """Background B with, every fourth row r, the cells (r, d), (r, d+1), (r+1, d-1),
        (r+1, d) and (r+1, d+2) at C(r), the smallest CUT whose OS threshold
        floor((C * inv - 1) / 2^frac) is exactly B (inv the row's OS scale, or the kind's scale
        when OS is not built): every background training cell sits on the OS comparison's
        boundary, and the equal cells are ties for the local maximum along both axes and
        both diagonals."""
        c = self.cfg
        inv = cm.scale_table(c, PFA, N_CHANNELS, kind="os") if c.os_built else self.scale
        b, nd = 5000, c.n_doppler
        p = np.full((c.n_range, nd), b, dtype=np.int64)
        for r in range(0, c.n_range - 1, 4):
            s = int(inv[cm.edge_index(r, c)])
            d = int(self.rng.integers(0, nd))
            cut = ((b << c.scale_frac) + s) // s
            for dr, dd in ((0, 0), (0, 1), (1, -1), (1, 0), (1, 2)):
                p[r + dr, (d + dd) % nd] = cut
        return p

    async def send_map(self, power: np.ndarray) -> None:
        for row in power:
            data = b"".join(int(v).to_bytes(self.in_bytes, "little") for v in row)
            await self.source.send(AxiStreamFrame(data))

    async def recv_maps(self, n: int) -> list[list[tuple]]:
        """n frames of output cells as (r, d, power, sum, count, detect, neighbours) in
        stream order."""
        c = self.cfg
        bd = (c.n_doppler - 1).bit_length()
        frames = []
        # a hang fails after 20x the stall-free row time
        limit = 20 * 10 * (c.n_doppler + 2 * c.pd) * (c.pr + 2)
        for _ in range(n):
            cells = []
            for _r in range(c.n_range):
                f = await with_timeout(self.sink.recv(compact=False), limit, "ns")
                raw = bytes(f.tdata)
                assert len(raw) == c.n_doppler * c.out_bytes, f"row of {len(raw)} bytes"
                for i in range(c.n_doppler):
                    v = int.from_bytes(raw[i * c.out_bytes:(i + 1) * c.out_bytes], "little")
                    tu = f.tuser[i * c.out_bytes]
                    cells.append((tu >> bd, tu & ((1 << bd) - 1), *cm.unpack_cell(v, c)))
            frames.append(cells)
        return frames

    async def run_maps(self, maps: list[np.ndarray]) -> int:
        """Send the maps, receive as many frames and check them (:meth:`check`)."""
        rx = cocotb.start_soon(self.recv_maps(len(maps)))
        for m in maps:
            await self.send_map(m)
        return self.check(await rx, maps)

    def check(self, got: list, sent: list[np.ndarray]) -> int:
        """Compare every cell with the model; returns the number of detections."""
        n_det = 0
        order = cm.output_order(self.cfg)
        for k, (cells, power) in enumerate(zip(got, sent, strict=True)):
            exp = cm.cfar_2d(power, self.cfg, self.scale, self.kind, self.local_max)
            for i, (r, d, pw, s, cnt, det, nb) in enumerate(cells):
                er, ed = order[i]
                want = (int(er), int(ed), int(exp.power[er, ed]), int(exp.train_sum[er, ed]),
                        int(exp.count[er, ed]), bool(exp.detect[er, ed]),
                        tuple(int(v) for v in exp.neighbours[er, ed]))
                assert (r, d, pw, s, cnt, det, nb) == want, f"frame {k} cell {i}: got " \
                    f"{(r, d, pw, s, cnt, det, nb)}, expected {want}"
            n_det += int(exp.detect.sum())
        return n_det


@cocotb.test()
async def test_throughput(dut):
    """Back-to-back frames without stalls; clocks per frame against the pass schedule."""
    tb = TB(dut)
    tb.start_meter()
    await tb.reset()
    c = tb.cfg
    n_det = await tb.run_maps([tb.random_map() for _ in range(3)])
    span = tb.out_last - tb.in_first + 1
    ideal = c.n_range * c.n_doppler + (c.n_range) * 2 * c.pd + (c.pr + 1) * c.n_doppler
    tb.log.info("%d cells/frame, %d detections in 3 frames; %d clocks for 3 frames "
                "(schedule %d per frame, %.3f cells per clock)", c.n_range * c.n_doppler,
                n_det, span, ideal, 3 * c.n_range * c.n_doppler / span)
    assert span <= 3 * ideal + 16, (span, ideal)
    assert n_det > 0
    assert int(dut.detection_count.value) == n_det
    assert int(dut.frame_count.value) == 3 and int(dut.status_framing_error.value) == 0


@cocotb.test()
async def test_random_stalls(dut):
    """Random and long TVALID gaps / TREADY stalls over several frames."""
    tb = TB(dut)
    await tb.reset()
    n = tb.cfg.n_doppler
    tb.set_idle_generator(random_pause(0.3, 1))
    tb.set_backpressure_generator(bursty_pause(2, max_run=2 * n, busy_fraction=0.4))
    maps = [tb.random_map() for _ in range(4)]
    rx = cocotb.start_soon(tb.recv_maps(4))
    for k, m in enumerate(maps):
        if k == 2:
            tb.set_idle_generator(bursty_pause(3, max_run=n))
            tb.set_backpressure_generator(random_pause(0.5, 4))
        await tb.send_map(m)
    got = await rx
    tb.check(got, maps)
    assert int(dut.status_framing_error.value) == 0


@cocotb.test()
async def test_programmed_scale_table(dut):
    """A ``cfg_scale`` table that is not the Pfa-derived one: every edge entry different
    (rows cut below and above by the same count get different scales), so each range-edge
    row must pick its own entry."""
    tb = TB(dut)
    c = tb.cfg
    f = tb.rng.uniform(0.5, 2.0, len(tb.scale))
    tb.scale = np.clip(np.rint(tb.scale * f), 1, (1 << c.scale_w) - 1).astype(np.int64)
    assert len(set(tb.scale.tolist())) == len(tb.scale)
    dut.cfg_scale.value = cm.pack_scale(tb.scale, c)
    await tb.reset()
    tb.set_idle_generator(random_pause(0.2, 1))
    tb.set_backpressure_generator(random_pause(0.2, 2))
    assert await tb.run_maps([tb.random_map() for _ in range(2)]) > 0


@cocotb.test()
async def test_run_time_kind_and_local_max(dut):
    """Every cfg_kind code (a kind not built runs KIND) with the local maximum off and on,
    changed between frames while idle, under random stalls (a random map and a map of ties,
    :meth:`TB.tie_map`, each); the detection count adds up."""
    tb = TB(dut)
    await tb.reset()
    tb.set_idle_generator(random_pause(0.2, 5))
    tb.set_backpressure_generator(random_pause(0.3, 6))
    total = 0
    for kind in KIND_NAMES:
        for lm in (False, True):
            tb.set_kind(kind, lm)
            await tb.cycles(4)
            n_det = await tb.run_maps([tb.random_map(), tb.tie_map()])
            total += n_det
            assert n_det > 0 or tb.cfg.n_range * tb.cfg.n_doppler < 64, (kind, lm)
            await tb.cycles(4)
    assert int(dut.detection_count.value) == total
    assert int(dut.frame_count.value) == 4 * len(KIND_NAMES)


@cocotb.test()
async def test_full_scale(dut):
    """Every sum at its widest: a map of full-scale cells and one with about half its cells
    at full scale, under every cfg_kind code (the vertical, window and training sums and
    the product at their largest values)."""
    tb = TB(dut)
    await tb.reset()
    c = tb.cfg
    top = (1 << c.pow_w) - 1
    full = np.full((c.n_range, c.n_doppler), top, dtype=np.int64)
    half = np.where(tb.rng.random(full.shape) < 0.5, full, tb.random_map())
    for kind in KIND_NAMES:
        tb.set_kind(kind, False)
        await tb.cycles(4)
        await tb.run_maps([full, half])
        await tb.cycles(4)


@cocotb.test()
async def test_framing_error(dut):
    """A misplaced TLAST is flagged (sticky); cells are still placed by count."""
    tb = TB(dut)
    await tb.reset()
    m = tb.random_map()
    b = tb.in_bytes
    rx = cocotb.start_soon(tb.recv_maps(1))
    data = b"".join(int(v).to_bytes(b, "little") for v in m.reshape(-1))
    n = tb.cfg.n_doppler
    await tb.source.send(AxiStreamFrame(data[:(n - 1) * b]))  # TLAST one cell early
    await tb.source.send(AxiStreamFrame(data[(n - 1) * b:2 * n * b]))
    for r in range(2, tb.cfg.n_range):
        await tb.source.send(AxiStreamFrame(data[r * n * b:(r + 1) * n * b]))
    got = await rx
    tb.check(got, [m])
    assert int(dut.status_framing_error.value) == 1


@cocotb.test()
async def test_reset_recovery(dut):
    """Reset in mid-frame (while rows are tested and the output stalls), then clean frames."""
    tb = TB(dut)
    await tb.reset()
    tb.set_backpressure_generator(random_pause(0.5, 8))
    cocotb.start_soon(tb.send_map(tb.random_map()))
    await tb.cycles(tb.cfg.n_range * tb.cfg.n_doppler * 3 // 4)
    tb.source.clear()
    await tb.reset()
    tb.sink.clear()
    assert int(dut.frame_count.value) == 0 and int(dut.detection_count.value) == 0
    assert int(dut.m_axis_tvalid.value) == 0
    tb.set_idle_generator(random_pause(0.2, 9))
    tb.set_backpressure_generator(no_pause())
    tb.set_kind(KIND_NAMES[-1], True)     # OS if built, else the default kind
    await tb.run_maps([tb.random_map() for _ in range(2)])


# ------------------------------------------------------------------------------------------
# pytest: one Verilator build per HDL parameter set
PARAMS = [
    # GO with top range bins blanked, asymmetric window, rows 0, 1, 11, 12 never report
    dict(N_RANGE=16, N_DOPPLER=32, POW_W=34, GUARD_R=1, GUARD_D=2, TRAIN_R=2, TRAIN_D=3, KIND=1,
         BLANK_TOP=3, REPORT_LO=2, REPORT_HI=11),
    # smallest: 4 x 4 map, no guard, one training cell per side, CA (the KIND 0 arm in the
    # default regression: seconds to build and run)
    dict(N_RANGE=4, N_DOPPLER=4, POW_W=24, GUARD_R=0, GUARD_D=0, TRAIN_R=1, TRAIN_D=1, KIND=0,
         BLANK_TOP=1),
    # the same built for CA alone, no local maximum (cfg_kind / cfg_local_max ignored)
    dict(N_RANGE=4, N_DOPPLER=4, POW_W=24, GUARD_R=0, GUARD_D=0, TRAIN_R=1, TRAIN_D=1, KIND=0,
         BLANK_TOP=1, RUN_KINDS=1, LOCAL_MAX_BUILD=0),
    # OS built (KIND 3), no Doppler guard, rows cut at both ends and blanked at the top
    dict(N_RANGE=16, N_DOPPLER=16, POW_W=34, GUARD_R=1, GUARD_D=0, TRAIN_R=2, TRAIN_D=2, KIND=3,
         BLANK_TOP=2, REPORT_LO=1, REPORT_HI=13),
]
LONG_PARAMS = [  # make test-detect-long (DETECT_LONG=1)
    # SO, Doppler window nearly the whole row (wrap on both sides)
    dict(N_RANGE=16, N_DOPPLER=8, POW_W=38, GUARD_R=0, GUARD_D=1, TRAIN_R=3, TRAIN_D=2, KIND=2,
         BLANK_TOP=0),
    # paper-fpga: 64 x 256 map of 1 TX x 4 RX (34-bit power), the host's default window
    dict(N_RANGE=64, N_DOPPLER=256, POW_W=34, GUARD_R=2, GUARD_D=2, TRAIN_R=4, TRAIN_D=8,
         KIND=0, BLANK_TOP=0),
    # the same with OS built beside the default CA
    dict(N_RANGE=64, N_DOPPLER=256, POW_W=34, GUARD_R=2, GUARD_D=2, TRAIN_R=4, TRAIN_D=8,
         KIND=0, BLANK_TOP=0, OS_BUILD=1),
]
if os.environ.get("DETECT_LONG", "0") not in ("", "0"):
    PARAMS += LONG_PARAMS


@pytest.mark.parametrize("parameters", PARAMS, ids=lambda p: "_".join(
    f"{k}{v}" for k, v in p.items()))
def test_cfar_2d(parameters: dict) -> None:
    here = Path(__file__).resolve().parent
    sources = [*rtl_sources("common/*.sv", "buffers/buf_*.sv"), *rtl_sources("detect/cfar_*.sv")]
    run_cocotb("cfar_2d", sources, "test_cfar_2d", here, parameters=parameters)
