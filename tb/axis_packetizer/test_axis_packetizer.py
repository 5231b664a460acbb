"""cocotb testbench of ``rtl/buffers/axis_packetizer.sv`` against ``model/axis_packetizer.py``.

``cfg_packet_words`` is PACKET_WORDS, or (``test_runtime_length``, with input backpressure)
changed at random clocks, in mid-frame too, to any legal length (the shortest ones make the
input wait for the packet count): each frame must be cut with the length it had at its
first word.
"""

from __future__ import annotations

import itertools
from pathlib import Path

import cocotb
import numpy as np
import pytest
from cocotb.triggers import FallingEdge, RisingEdge

from model import axis_packetizer as pk
from rtlsim.axis import AxisTB, bursty_pause, no_pause, random_pause
from rtlsim.toolchain import param, rtl_sources, run_cocotb
from tb import progress, stall_regimes


class TB(AxisTB):
    def __init__(self, dut) -> None:
        super().__init__(dut)
        self.num_rx = param("NUM_RX")
        self.packet_words = param("PACKET_WORDS")
        self.frame_words = param("FRAME_WORDS")
        self.header = bool(param("HEADER"))
        self.backpressure = bool(param("INPUT_BACKPRESSURE"))
        self.tlast_period = param("TLAST_PERIOD")
        self.n_packets = pk.packets_per_frame(self.frame_words, self.packet_words)
        self.lengths: list[int] = []      # cfg_packet_words at each frame's first word
        dut.cfg_packet_words.value = self.packet_words
        cocotb.start_soon(self._watch_lengths())
        # latency: a packet's first payload word in to its header out (docs/buffers.md);
        # no owed-frame rule: without input backpressure words are dropped by design and
        # run-time lengths change the words per frame, so only their most: the payload and
        # a header and CRC word per packet of the shortest length change_lengths sets
        shortest = self.shortest_length() if self.header else self.frame_words
        progress.watch(self, latency=progress.packetizer_latency(self.packet_words),
                       most=(self.frame_words,
                             self.frame_words
                             + 2 * pk.packets_per_frame(self.frame_words, shortest)))

    async def _watch_lengths(self) -> None:
        """Record cfg_packet_words at every frame's first input word."""
        d, n = self.dut, 0
        while True:
            await RisingEdge(d.clk)
            if d.rst.value == 1:
                n = 0
                self.lengths = []
            elif d.s_axis_tvalid.value == 1 and d.s_axis_tready.value == 1:
                if n % self.frame_words == 0:
                    self.lengths.append(int(d.cfg_packet_words.value))
                n += 1

    def shortest_length(self) -> int:
        """The shortest legal cfg_packet_words (at most MAX_PACKETS_PER_FRAME packets)."""
        return pk.shortest_packet_words(self.frame_words)

    async def change_lengths(self, seed: int) -> None:
        """cfg_packet_words to a random legal length every few to few hundred clocks."""
        rng = np.random.default_rng(seed)
        lo = self.shortest_length()
        while True:
            await self.cycles(int(rng.integers(3, 300)))
            await FallingEdge(self.dut.clk)
            self.dut.cfg_packet_words.value = int(rng.integers(lo, self.packet_words + 1))

    def random_frame(self) -> np.ndarray:
        return self.rng.integers(0, 1 << 32, (self.frame_words, self.num_rx), dtype=np.uint32)

    async def send_frame(self, words: np.ndarray) -> None:
        """Queue one frame, cut at the expected input TLAST positions."""
        chunk = self.tlast_period or len(words)
        for start in range(0, len(words), chunk):
            await self.send_words(words[start:start + chunk])

    async def drain(self, quiet: int = 64) -> list[np.ndarray]:
        """Wait for the source to finish and the output to go quiet; return received packets."""
        await self.wait_quiet(quiet)
        return [w for w, _ in self.drain_words(self.num_rx)]

    def status(self) -> dict[str, int]:
        d = self.dut
        return {k: int(getattr(d, k).value) for k in (
            "status_overflow", "status_framing_error", "drop_count", "framing_error_count",
            "frame_count", "packet_count")}

    def expected(self, frames: list[np.ndarray], first_id: int = 0, **flags) -> list[np.ndarray]:
        out = []
        for k, f in enumerate(frames):
            out.extend(pk.packetize(f, self.packet_words, first_id + k, self.header, **flags))
        return out

    def check_crc(self, got: list[np.ndarray]) -> None:
        """Every packet's CRC word (RTL) is the model's CRC of the header and payload the RTL
        sent (``model.packet_crc``), lanes 1.. zero."""
        if not self.header:
            return
        for i, g in enumerate(got):
            want = pk.crc_word(g[:-1])
            assert np.array_equal(g[-1], want), (
                f"packet {i}: CRC word {[hex(v) for v in g[-1]]}, model {hex(int(want[0]))}")

    def compare(self, got: list[np.ndarray], exp: list[np.ndarray]) -> None:
        """Packets bit-exact against the model's (header, payload and CRC word)."""
        self.check_crc(got)
        assert len(got) == len(exp), f"{len(got)} packets, expected {len(exp)}"
        for i, (g, e) in enumerate(zip(got, exp, strict=True)):
            if not np.array_equal(g, e):
                bad = [j for j in range(min(len(g), len(e))) if not np.array_equal(g[j], e[j])]
                raise AssertionError(f"packet {i}: {len(g)} words vs {len(e)}, first mismatch "
                                     f"word {bad[:1]}: {g[bad[0]] if bad else ''} vs "
                                     f"{e[bad[0]] if bad else ''}")


@cocotb.test()
async def test_throughput(dut):
    """Back-to-back frames, no stalls: the DMA side moves one word per clock."""
    tb = TB(dut)
    tb.start_meter()
    await tb.reset()
    nfr = 2 if tb.frame_words > 4096 else 3
    frames = [tb.random_frame() for _ in range(nfr)]
    # The header and CRC words cost two output clocks per packet; without input backpressure
    # the producer must leave two idle clocks per packet, exactly their share.
    if tb.header and not tb.backpressure:
        p = tb.packet_words
        tb.set_idle_generator(itertools.cycle([False] * p + [True, True]))
    else:
        tb.set_idle_generator(no_pause())
    tb.set_backpressure_generator(no_pause())
    tb.reset_meter()
    for f in frames:
        await tb.send_frame(f)
    got = await tb.drain()
    tb.compare(got, tb.expected(frames))
    st = tb.status()
    assert st["drop_count"] == 0 and st["status_overflow"] == 0, st
    assert st["frame_count"] == nfr and st["packet_count"] == nfr * tb.n_packets, st
    span = tb.out_last - tb.out_first + 1
    words = tb.out_beats
    tb.log.info("throughput: %d output words in %d clocks = %.4f words/clock (input %d words); "
                "latency first word in -> first word out %d clocks", words, span,
                words / span, nfr * tb.frame_words, tb.out_first - tb.in_first)
    assert words == sum(len(p) for p in got)
    assert span <= words + 2, f"output not one word per clock: {words} words in {span} clocks"


@cocotb.test()
async def test_random_stalls(dut):
    """Random TVALID gaps and TREADY stalls (short and long): exact packets, nothing lost."""
    tb = TB(dut)
    await tb.reset()
    nfr = 1 if tb.frame_words > 4096 else 5
    for seed, (idle, bp) in enumerate([
            (random_pause(0.3, 1), random_pause(0.3, 2)),
            (random_pause(0.1, 3), bursty_pause(4, max_run=300, busy_fraction=0.5))]):
        if not tb.backpressure:
            # no input backpressure: keep the sink fast enough that nothing overflows
            idle, bp = random_pause(0.6, 10 + seed), random_pause(0.2, 20 + seed)
        tb.set_idle_generator(idle)
        tb.set_backpressure_generator(bp)
        frames = [tb.random_frame() for _ in range(nfr)]
        first = seed * nfr
        for f in frames:
            await tb.send_frame(f)
        got = await tb.drain()
        tb.compare(got, tb.expected(frames, first_id=first))
        st = tb.status()
        assert st["drop_count"] == 0 and st["frame_count"] == first + nfr, st


@cocotb.test()
async def test_overflow(dut):
    """No input backpressure and a stalling DMA: dropped words are flagged and counted, intact
    packets are exact, and every lost word is accounted for."""
    tb = TB(dut)
    if tb.backpressure or not tb.header:
        tb.log.info("overflow test needs INPUT_BACKPRESSURE=0 and HEADER=1: skipped")
        return
    await tb.reset()
    nfr = 6
    frames = [tb.random_frame() for _ in range(nfr)]
    tb.set_idle_generator(random_pause(0.1, 5))
    tb.set_backpressure_generator(bursty_pause(6, max_run=4 * tb.packet_words,
                                               busy_fraction=0.5))
    for f in frames:
        await tb.send_frame(f)
    got = await tb.drain()
    tb.check_crc(got)   # DROP packets too: CRC over their short payload
    st = tb.status()
    exp = {(k, s): p for k in range(nfr)
           for s, p in enumerate(pk.packetize(frames[k], tb.packet_words, k, True))}
    lost, seen, prev, ovf_seen = 0, set(), (-1, -1), False
    for pkt in got:
        h = pk.parse_header(pkt[0])
        key = (h.frame_id, h.seq)  # 8-bit frame id is enough here (< 256 frames)
        assert key > prev, f"packet order {key} after {prev}"
        prev = key
        seen.add(key)
        e = exp[key]
        nominal = len(e) - 2   # header and CRC word
        assert h.last == (h.seq == tb.n_packets - 1)
        assert h.overflow >= ovf_seen, "sticky overflow flag cleared"
        ovf_seen = h.overflow
        if h.drop:
            assert h.overflow
            payload = [tuple(w) for w in pkt[1:-1]]
            ref = [tuple(w) for w in e[1:-1]]
            it = iter(ref)
            assert all(w in it for w in payload), "payload of a DROP packet is not a subsequence"
            dropped = nominal - len(payload)
            assert dropped > 0
            if h.dropped is not None:
                assert h.dropped == dropped and h.length == len(payload)
            lost += dropped
        else:
            assert np.array_equal(pkt[1:-1], e[1:-1]), f"intact packet {key} differs"
            if h.length is not None:
                assert h.length == nominal and h.dropped == 0
    for key, e in exp.items():
        if key not in seen:
            lost += len(e) - 2
    tb.log.info("overflow: %d packets received of %d, %d words dropped (drop_count %d)",
                len(got), len(exp), lost, st["drop_count"])
    assert st["drop_count"] == lost and lost > 0, (lost, st)
    assert st["status_overflow"] == 1 and st["frame_count"] == nfr
    # the decoder (host side) sees the damage and keeps intact packets
    dec = pk.depacketize(got, tb.frame_words, tb.packet_words, tb.num_rx)
    assert any(not f.complete for f in dec)


@cocotb.test()
async def test_framing_error(dut):
    """A misplaced input TLAST raises the sticky framing flag, is counted, and is stamped in
    the headers that follow; the stream itself continues by word count."""
    tb = TB(dut)
    if not tb.tlast_period or not tb.header:
        tb.log.info("framing test needs TLAST_PERIOD>0 and HEADER=1: skipped")
        return
    await tb.reset()
    tb.set_idle_generator(random_pause(0.2, 7))
    tb.set_backpressure_generator(random_pause(0.2, 8) if tb.backpressure else no_pause())
    frames = [tb.random_frame() for _ in range(2)]
    await tb.send_frame(frames[0])
    # frame 1 with one TLAST a word early (on word t-2): exactly one framing error
    t = tb.tlast_period
    await tb.send_words(frames[1][:t - 1])
    await tb.send_words(frames[1][t - 1:t])
    for start in range(t, len(frames[1]), t):
        await tb.send_words(frames[1][start:start + t])
    got = await tb.drain()
    st = tb.status()
    assert st["status_framing_error"] == 1 and st["framing_error_count"] == 1, st
    tb.check_crc(got)
    hdrs = [pk.parse_header(p[0]) for p in got]
    payload = np.vstack([p[1:-1] for p in got])
    assert np.array_equal(payload, np.vstack(frames)), "payload must continue by word count"
    assert not any(h.framing for h in hdrs[:tb.n_packets])
    assert hdrs[-1].framing and hdrs[-1].frame_id == 1


@cocotb.test()
async def test_framing_error_on_packet_closing_word(dut):
    """The TLAST error falls on the word that closes packet 0 (an early TLAST there, or a
    missing one when that word is a TLAST position): packet 0's own header already carries
    the framing flag (kills the mutant that stamps only the registered flag)."""
    tb = TB(dut)
    if not tb.tlast_period or not tb.header:
        tb.log.info("framing test needs TLAST_PERIOD>0 and HEADER=1: skipped")
        return
    await tb.reset()
    tb.set_idle_generator(random_pause(0.2, 27))
    tb.set_backpressure_generator(random_pause(0.2, 28) if tb.backpressure else no_pause())
    frame = tb.random_frame()
    t, cut = tb.tlast_period, tb.packet_words          # error on word cut - 1
    bounds = set(range(t, len(frame), t)) ^ {cut}      # add an early TLAST or drop one
    edges = [0, *sorted(b for b in bounds if 0 < b < len(frame)), len(frame)]
    for a, b in zip(edges[:-1], edges[1:], strict=True):
        await tb.send_words(frame[a:b])
    got = await tb.drain()
    st = tb.status()
    assert st["status_framing_error"] == 1 and st["framing_error_count"] == 1, st
    tb.check_crc(got)
    hdrs = [pk.parse_header(p[0]) for p in got]
    assert np.array_equal(np.vstack([p[1:-1] for p in got]), frame)
    assert all(h.framing for h in hdrs), [h.framing for h in hdrs]


@cocotb.test()
async def test_reset_recovery(dut):
    """Reset in mid-frame under stalls, then clean frames from frame id 0."""
    tb = TB(dut)
    await tb.reset()
    tb.set_idle_generator(random_pause(0.2, 11))
    tb.set_backpressure_generator(bursty_pause(12, max_run=50))
    await tb.send_frame(tb.random_frame())
    await tb.cycles(tb.frame_words // 2)
    tb.source.clear()
    await tb.reset()
    tb.sink.clear()
    st = tb.status()
    assert all(v == 0 for v in st.values()), st
    tb.set_backpressure_generator(random_pause(0.3, 13))
    frames = [tb.random_frame() for _ in range(1 if tb.frame_words > 4096 else 2)]
    if not tb.backpressure:
        tb.set_idle_generator(random_pause(0.6, 14))
        tb.set_backpressure_generator(random_pause(0.2, 15))
    for f in frames:
        await tb.send_frame(f)
    got = await tb.drain()
    tb.compare(got, tb.expected(frames))
    assert tb.status()["drop_count"] == 0


@cocotb.test()
async def test_runtime_length(dut):
    """cfg_packet_words changed at random clocks with random stalls: every frame cut with
    the length it had at its first word, header packet counts included."""
    tb = TB(dut)
    if not tb.backpressure:
        tb.log.info("run-time length needs INPUT_BACKPRESSURE=1: skipped")
        return
    await tb.reset()
    tb.set_idle_generator(random_pause(0.2, 31))
    tb.set_backpressure_generator(random_pause(0.3, 32))
    task = cocotb.start_soon(tb.change_lengths(seed=33))
    frames = [tb.random_frame() for _ in range(2 if tb.frame_words > 4096 else 8)]
    for f in frames:
        await tb.send_frame(f)
    got = await tb.drain(quiet=8 * tb.packet_words + 64)
    task.cancel()
    exp = pk.packetize_stream(frames, tb.lengths, tb.header)
    tb.compare(got, exp)
    assert len(set(tb.lengths)) > 1, f"the length never changed between frames: {tb.lengths}"


@cocotb.test()
async def test_stall_cross(dut):
    """Stall regimes crossed (tb/stall_regimes.py: CI subset, all 16 pairs with
    STALL_CROSS=full): per pair, frames packetized bit-exact, frame ids continuing. Only
    with INPUT_BACKPRESSURE = 1: without it a long output stall drops words by design
    (test_overflow checks the drop path)."""
    tb = TB(dut)
    if not tb.backpressure:
        tb.log.info("stall cross: INPUT_BACKPRESSURE = 0 set, skipped (drops by design)")
        return
    await tb.reset()
    nfr = 1 if tb.frame_words > 4096 else 2
    sent = 0

    async def run(pair, k):
        nonlocal sent
        frames = [tb.random_frame() for _ in range(nfr)]
        for f in frames:
            await tb.send_frame(f)
        got = await tb.drain(quiet=8 * tb.packet_words + 64)
        tb.compare(got, tb.expected(frames, first_id=sent))
        sent += nfr

    await stall_regimes.run_cross(tb, tb.packet_words, run)
    st = tb.status()
    assert st["drop_count"] == 0 and st["frame_count"] == sent, st


@cocotb.test()
async def test_reset_during_backpressure_and_output(dut):
    """Reset while the output is valid and held (TREADY low), then reset while packets flow
    out: counters cleared, the next frames from frame id 0 bit-exact."""
    tb = TB(dut)
    await tb.reset()

    async def start():
        await tb.send_frame(tb.random_frame())

    for case in ("backpressure", "output"):
        if case == "backpressure":
            await stall_regimes.reset_while_stalled(tb, start)
        else:
            await stall_regimes.reset_while_sending(tb, start, beats=tb.packet_words // 2)
        st = tb.status()
        assert all(v == 0 for v in st.values()), (case, st)
        frames = [tb.random_frame() for _ in range(1 if tb.frame_words > 4096 else 2)]
        tb.set_backpressure_generator(random_pause(0.1, 16))
        if not tb.backpressure:  # input at most as fast as the output drains (no drops)
            tb.set_idle_generator(random_pause(0.6, 17))
        for f in frames:
            await tb.send_frame(f)
        got = await tb.drain()
        assert tb.status()["drop_count"] == 0, case
        tb.compare(got, tb.expected(frames))
        tb.set_idle_generator(None)
        await tb.reset()


# ------------------------------------------------------------------------------------------
# pytest: one Verilator build per HDL parameter set
PARAMS = [
    # tiny, odd frame (last packet short), header, no input backpressure (drop path)
    dict(NUM_RX=1, PACKET_WORDS=8, FRAME_WORDS=52, NUM_BANKS=4, HEADER=1,
         INPUT_BACKPRESSURE=0, TLAST_PERIOD=13),
    # no header, input backpressure, 2 lanes
    dict(NUM_RX=2, PACKET_WORDS=16, FRAME_WORDS=64, NUM_BANKS=2, HEADER=0,
         INPUT_BACKPRESSURE=1, TLAST_PERIOD=0),
    # paper-fpga: 4 lanes (128-bit DMA), frame 1 x 64 x 256 words, 256-word packets
    dict(NUM_RX=4, PACKET_WORDS=256, FRAME_WORDS=16384, NUM_BANKS=2, HEADER=1,
         INPUT_BACKPRESSURE=1, TLAST_PERIOD=256),
]


@pytest.mark.parametrize("parameters", PARAMS, ids=lambda p: "_".join(
    f"{k}{v}" for k, v in p.items()))
def test_axis_packetizer(parameters: dict) -> None:
    here = Path(__file__).resolve().parent
    run_cocotb("axis_packetizer", rtl_sources("common/*.sv", "buffers/*.sv"),
               "test_axis_packetizer", here,
               parameters={"DATA_W": 16, **parameters})


@pytest.mark.parametrize("num_rx", [1, 2, 4, 16])
def test_packet_model(num_rx: int) -> None:
    """Model round trip: packetize -> bytes -> depacketize, and loss/damage detection."""
    rng = np.random.default_rng(num_rx)
    fw, pw = 100, 16
    frames = [rng.integers(0, 1 << 32, (fw, num_rx), dtype=np.uint32) for _ in range(3)]
    pkts = pk.packetize_stream(frames, pw)
    wire = [pk.bytes_to_words(pk.words_to_bytes(p), num_rx) for p in pkts]
    dec = pk.depacketize(wire, fw, pw, num_rx)
    assert [d.complete for d in dec] == [True] * 3
    for d, f in zip(dec, frames, strict=True):
        assert np.array_equal(d.words, f)
    hdr = pk.parse_header(pkts[6][0])
    assert hdr.seq == 6 and hdr.last and (hdr.frame_id & 0xFF) == 0
    # lose packet 2 of frame 1, truncate packet 3, corrupt a magic
    bad = [p.copy() for p in pkts]
    n = pk.packets_per_frame(fw, pw)
    del bad[n + 2]
    bad[n + 2] = bad[n + 2][:-1]
    bad[2 * n - 2][0, 0] ^= 0xFF000000  # last packet of frame 1 (after the deletion)
    dec = pk.depacketize(bad, fw, pw, num_rx)
    assert dec[0].complete and dec[2].complete and not dec[1].complete
    assert not dec[1].valid[2 * pw:4 * pw].any() and dec[1].valid[:2 * pw].all()
    assert len(dec[1].errors) >= 3
    with pytest.raises(ValueError):
        pk.parse_header(np.zeros(num_rx, np.uint32))
