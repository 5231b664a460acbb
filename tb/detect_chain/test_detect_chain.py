"""cocotb testbench of ``rtl/detect/detect_chain.sv`` (nci -> cfar_2d -> detect_records)
against ``model/detect_chain.py``, record stream compared word by word."""

from __future__ import annotations

import logging
import os
from dataclasses import replace
from pathlib import Path

import cocotb
import numpy as np
import pytest
from cocotb.triggers import RisingEdge, with_timeout
from cocotbext.axi import AxiStreamFrame

from model import cfar_2d as cm
from model import detect_chain as dc
from model import detect_records as dr
from model.axis_packetizer import pack_iq, words_to_bytes
from rtlsim.axis import AxisTB, bursty_pause, no_pause, random_pause
from rtlsim.toolchain import param, rtl_sources, run_cocotb
from tb import progress


class TB(AxisTB):
    def __init__(self, dut) -> None:
        super().__init__(dut)
        for comp in (self.source, self.sink):
            comp.log.setLevel(logging.WARNING)
        self.cfg = dc.DetectConfig(
            num_tx=param("NUM_TX"), num_rx=param("NUM_RX"), n_range=param("N_RANGE"),
            n_doppler=param("N_DOPPLER"), guard=(param("GUARD_R"), param("GUARD_D")),
            train=(param("TRAIN_R"), param("TRAIN_D")), kind=cm.KINDS[param("KIND")],
            blank_top=param("BLANK_TOP"), max_detections=param("MAX_DETECTIONS"),
            pfa=float(os.environ["DETECT_PFA"]))
        self.set_local_max(False)
        dut.cfg_max_detections.value = self.cfg.max_detections
        self.rng = np.random.default_rng(int(os.environ.get("SEED", "1")))
        c = self.cfg
        # a frame's last word in to its record frame's last word out: the NCI pipeline, the
        # CFAR's passes over the last rows, the FRAME_WORDS of records, trailer and fill
        progress.watch(self, latency=progress.NCI_LATENCY + progress.cfar_latency(c.cfar)
                       + c.frame_words,
                       frame=(c.num_tx * c.n_range * c.n_doppler, c.frame_words))

    def set_local_max(self, on: bool) -> None:
        """cfg_kind = the default kind (KIND), cfg_local_max = ``on``, the scale table."""
        self.cfg = replace(self.cfg, local_max=on)
        self.scale = self.cfg.scale()
        self.dut.cfg_scale.value = cm.pack_scale(self.scale, self.cfg.cfar)
        self.dut.cfg_kind.value = param("KIND")
        self.dut.cfg_local_max.value = int(on)

    def random_frame(self, n_targets: int) -> np.ndarray:
        """Doppler-FFT words (r, t, d) of Gaussian noise plus ``n_targets`` strong cells
        (random phases per channel, one at int16 full scale)."""
        c = self.cfg
        shape = (c.n_range, c.num_tx, c.n_doppler, c.num_rx)
        x = self.rng.normal(0, 300, shape) + 1j * self.rng.normal(0, 300, shape)
        for k in range(n_targets):
            r, d = self.rng.integers(0, c.n_range), self.rng.integers(0, c.n_doppler)
            amp = 32767 if k == 0 else self.rng.uniform(2000, 20000)
            ph = self.rng.uniform(0, 2 * np.pi, (c.num_tx, c.num_rx))
            x[r, :, d, :] = amp * np.exp(1j * ph)
        x = np.clip(np.rint(x.real), -32768, 32767) + 1j * np.clip(np.rint(x.imag), -32768,
                                                                    32767)
        return pack_iq(x.reshape(-1, c.num_rx))

    def watch_frame_start(self) -> list[int]:
        """The input beats taken (``in_beats``: the meter must run) at each ``frame_start``
        pulse, appended as they come."""
        seen: list[int] = []

        async def monitor() -> None:
            while True:
                await RisingEdge(self.dut.clk)
                if self.dut.frame_start.value == 1:
                    seen.append(self.in_beats)

        cocotb.start_soon(monitor())
        return seen

    def check_frame_starts(self, seen: list[int], n_frames: int) -> None:
        """One ``frame_start`` per frame, each after the input word that completes the NCI of
        the frame's first cell of range row 1 (word (r=1, t=NUM_TX-1, d=0), docs/detect.md):
        the settings may change only then."""
        c = self.cfg
        per_frame = c.num_tx * c.n_range * c.n_doppler
        first = (2 * c.num_tx - 1) * c.n_doppler + 1
        assert len(seen) == n_frames, f"{len(seen)} frame_start pulses for {n_frames} frames"
        for k, beats in enumerate(seen):
            assert beats >= k * per_frame + first, (
                f"frame {k}: frame_start after {beats} input words, before word "
                f"{k * per_frame + first - 1} (range row 1) was taken")

    async def send_frame(self, words: np.ndarray) -> None:
        nd = self.cfg.n_doppler
        for v in range(len(words) // nd):
            await self.source.send(AxiStreamFrame(words_to_bytes(words[v * nd:(v + 1) * nd])))

    async def recv_frames(self, n: int) -> list[np.ndarray]:
        out = []
        for _ in range(n):
            f = await self.sink.recv()
            w = np.frombuffer(bytes(f.tdata), dtype="<u4").reshape(-1, self.cfg.num_rx)
            assert len(w) == self.cfg.frame_words, f"record frame of {len(w)} words"
            out.append(w)
        return out

    def check(self, got: list[np.ndarray], sent: list[np.ndarray],
              first_id: int = 0) -> list[dr.RecordFrame]:
        exp = dc.detect_stream(sent, self.cfg, self.scale)
        decoded = []
        for k, (g, e) in enumerate(zip(got, exp, strict=True)):
            dg, de = dr.decode_frame(g, self.cfg.num_tx), dr.decode_frame(e, self.cfg.num_tx)
            assert not dg.errors, dg.errors
            if not np.array_equal(g, e):
                bad = np.nonzero((g != e).any(axis=1))[0]
                raise AssertionError(
                    f"frame {k}: {len(bad)} words differ, first at {bad[0]}: got "
                    f"{[(x.range_bin, x.doppler_bin) for x in dg.records][:6]} "
                    f"trailer {dg.trailer}, expected "
                    f"{[(x.range_bin, x.doppler_bin) for x in de.records][:6]} "
                    f"trailer {de.trailer}")
            decoded.append(dg)
        return decoded


async def run_frames(tb: TB, frames: list[np.ndarray]) -> list[np.ndarray]:
    """Send and receive; a hang (deadlock) fails after 20x the stall-free frame time."""
    c = tb.cfg
    clocks = (c.num_tx * c.n_range * c.n_doppler + c.n_range * (c.n_doppler + 2 * c.cfar.pd)
              + (c.cfar.pr + 1) * c.n_doppler + c.frame_words)
    rx = cocotb.start_soon(tb.recv_frames(len(frames)))
    for f in frames:
        await tb.send_frame(f)
    return await with_timeout(rx, 20 * 10 * clocks * (len(frames) + 1), "ns")


@cocotb.test()
async def test_frames(dut):
    """Back-to-back frames: noise only, a few targets, more detections than MAX_DETECTIONS
    (truncated, sticky), then a normal frame again."""
    tb = TB(dut)
    tb.start_meter()
    await tb.reset()
    starts = tb.watch_frame_start()
    c = tb.cfg
    frames = [tb.random_frame(0), tb.random_frame(3),
              tb.random_frame(c.max_detections + 4), tb.random_frame(2)]
    got = await run_frames(tb, frames)
    dec = tb.check(got, frames)
    tb.check_frame_starts(starts, len(frames))
    counts = [(len(d.records), d.trailer.detections, d.trailer.truncated) for d in dec]
    tb.log.info("records/detections/truncated per frame: %s; %d input words in %d clocks",
                counts, tb.in_beats, tb.out_last - tb.in_first + 1)
    assert dec[2].trailer.truncated and dec[3].trailer.truncated_sticky
    assert not dec[1].trailer.truncated and not dec[1].trailer.truncated_sticky
    assert int(dut.status_truncated.value) == 1
    assert int(dut.frame_count.value) == 4 and int(dut.status_framing_error.value) == 0


@cocotb.test()
async def test_random_stalls(dut):
    """Random and long TVALID gaps / TREADY stalls."""
    tb = TB(dut)
    await tb.reset()
    nd = tb.cfg.n_doppler
    tb.set_idle_generator(random_pause(0.3, 1))
    tb.set_backpressure_generator(bursty_pause(2, max_run=4 * nd, busy_fraction=0.5))
    frames = [tb.random_frame(k) for k in (1, 5, 2)]
    got = await run_frames(tb, frames)
    tb.check(got, frames)


@cocotb.test()
async def test_local_max(dut):
    """The 3x3 local-maximum test on: only the peaks become records."""
    tb = TB(dut)
    tb.set_local_max(True)
    await tb.reset()
    tb.set_backpressure_generator(random_pause(0.3, 4))
    frames = [tb.random_frame(6), tb.random_frame(2)]
    got = await run_frames(tb, frames)
    tb.check(got, frames)


@cocotb.test()
async def test_reset_recovery(dut):
    """Reset in mid-frame, then clean frames (frame ids and sticky flags restart)."""
    tb = TB(dut)
    await tb.reset()
    tb.set_backpressure_generator(random_pause(0.5, 8))
    c = tb.cfg
    cocotb.start_soon(tb.send_frame(tb.random_frame(c.max_detections + 2)))
    await tb.cycles(c.n_range * c.num_tx * c.n_doppler * 3 // 4)
    tb.source.clear()
    await tb.reset()
    tb.sink.clear()
    assert int(dut.frame_count.value) == 0 and int(dut.status_truncated.value) == 0
    tb.set_idle_generator(random_pause(0.2, 9))
    tb.set_backpressure_generator(no_pause())
    frames = [tb.random_frame(3), tb.random_frame(1)]
    got = await run_frames(tb, frames)
    tb.check(got, frames)


# ------------------------------------------------------------------------------------------
# pytest: one Verilator build per HDL parameter set (PFA reaches cocotb as DETECT_PFA)
PARAMS = [
    # small 4-TX configuration (16 virtual channels, 4-word snapshots), GO
    (dict(NUM_TX=4, NUM_RX=4, N_RANGE=8, N_DOPPLER=16, GUARD_R=0, GUARD_D=1, TRAIN_R=2,
          TRAIN_D=2, KIND=1, BLANK_TOP=0, MAX_DETECTIONS=6), 1e-2),
    # 2 TX x 16 RX (one-word record headers), SO
    (dict(NUM_TX=2, NUM_RX=16, N_RANGE=8, N_DOPPLER=8, GUARD_R=1, GUARD_D=0, TRAIN_R=1,
          TRAIN_D=2, KIND=2, BLANK_TOP=1, MAX_DETECTIONS=5), 1e-2),
]
LONG_PARAMS = [  # make test-detect-long (DETECT_LONG=1)
    # 1 TX x 4 RX, CA, top range bins blanked, small MAX_DETECTIONS, high Pfa
    (dict(NUM_TX=1, NUM_RX=4, N_RANGE=16, N_DOPPLER=32, GUARD_R=1, GUARD_D=1, TRAIN_R=2,
          TRAIN_D=4, KIND=0, BLANK_TOP=2, MAX_DETECTIONS=8), 1e-2),
    # paper-fpga: 1 TX x 4 RX, 64 x 256, the host's default window and Pfa
    (dict(NUM_TX=1, NUM_RX=4, N_RANGE=64, N_DOPPLER=256, GUARD_R=2, GUARD_D=2, TRAIN_R=4,
          TRAIN_D=8, KIND=0, BLANK_TOP=0, MAX_DETECTIONS=64), 1e-6),
]
if os.environ.get("DETECT_LONG", "0") not in ("", "0"):
    PARAMS += LONG_PARAMS


@pytest.mark.parametrize("parameters,pfa", PARAMS, ids=lambda p: "_".join(
    f"{k}{v}" for k, v in p.items()) if isinstance(p, dict) else f"pfa{p:g}")
def test_detect_chain(parameters: dict, pfa: float) -> None:
    here = Path(__file__).resolve().parent
    sources = [*rtl_sources("common/*.sv", "buffers/buf_*.sv"), *rtl_sources("detect/*.sv")]
    run_cocotb("detect_chain", sources, "test_detect_chain", here, parameters=parameters,
               extra_env={"DETECT_PFA": repr(pfa)})
