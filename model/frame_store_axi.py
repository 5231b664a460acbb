"""Bit-accurate model of ``rtl/buffers/frame_store_axi.sv`` (the corner turn in external memory
over AXI4) and of its AXI4 address trace.

The store only moves words, so its payload is the on-chip corner turn's
(:func:`model.corner_turn.corner_turn`); :func:`store_frames` proves it by writing frames
through the real address layout into a byte-addressed memory and reading them back through the
real read bursts. Words are uint32 lane arrays ``(n_words, num_rx)``.

Layout (docs/frame_store.md): two frame areas of :attr:`StoreGeometry.frame_bytes` from
``mem_base``; frame k lives in area ``k % 2``. Inside an area, strip ``(t, s)`` (TX t, range
bins ``s*tile_r .. s*tile_r+tile_r-1``) is a contiguous block of ``n_doppler`` rows of
``tile_r`` words; row d holds chirp d of TX t. The strips follow each other in the order the
output needs them (:meth:`StoreGeometry.strip_index`, the one place for it): ``read_order`` 0
((t, r, d), the cube order) puts strip ``t * strips + s``; ``read_order`` 1 ((r, t, d), all TX
of a range bin together for on-chip detection) puts strip ``s * num_tx + t``. Byte offset of
word (t, d, r)::

    (strip_index(t, r // tile_r) * n_doppler + d) * row_bytes + (r % tile_r) * word_bytes

A *group* is what the on-chip buffer holds at a time: one strip (order 0) or the ``num_tx``
strips of one s (order 1), contiguous either way. Write bursts: one row per (chirp, strip)
in input order. Read bursts: the area linearly, in bursts of :attr:`StoreGeometry.read_burst_bytes`
(the largest power of two dividing the group, at most 4096 bytes); each group leaves as its
Doppler vectors, (r, t, d) inside the group. Any num_tx in 1..16: a count that is not a power
of two only makes the order-1 group (and so the frame area) a non-power-of-two size.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from model.corner_turn import corner_turn

AXI_BOUNDARY = 4096
"""AXI4 bursts never cross a 4 KiB boundary."""
MAX_BURST_BEATS = 256
"""AXI4 INCR bursts hold at most 256 beats."""

WRITE, READ = "W", "R"


def _pow2(n: int) -> bool:
    return n > 0 and (n & (n - 1)) == 0


@dataclass(frozen=True)
class StoreGeometry:
    """HDL parameters of one ``frame_store_axi`` instance (same names, lower case) and every
    size derived from them. Validation mirrors the RTL's elaboration checks."""

    num_tx: int
    num_rx: int
    n_range: int
    n_doppler: int
    data_w: int = 16
    tile_r: int = 16
    axi_data_w: int = 128
    axi_addr_w: int = 32
    mem_base: int = 0
    read_order: int = 0

    def __post_init__(self) -> None:
        checks = [
            (1 <= self.num_tx <= 16, "num_tx", "in 1..16"),
            (_pow2(self.num_rx) and self.num_rx <= 16, "num_rx", "a power of two in 1..16"),
            (_pow2(self.n_range) and 2 <= self.n_range <= 4096, "n_range",
             "a power of two in 2..4096"),
            (_pow2(self.n_doppler) and 2 <= self.n_doppler <= 4096, "n_doppler",
             "a power of two in 2..4096"),
            (self.data_w in (8, 16, 32), "data_w", "8, 16 or 32"),
            (self.axi_data_w in (128, 256, 512), "axi_data_w", "128, 256 or 512"),
            (32 <= self.axi_addr_w <= 40, "axi_addr_w", "in 32..40"),
            (_pow2(self.tile_r) and self.tile_r <= self.n_range, "tile_r",
             "a power of two in 1..n_range"),
            (self.mem_base % AXI_BOUNDARY == 0, "mem_base", "4 KiB aligned"),
            (self.read_order in (0, 1), "read_order", "0 (t, r, d) or 1 (r, t, d)"),
        ]
        for ok, name, what in checks:
            if not ok:
                raise ValueError(f"{name}={getattr(self, name)} must be {what}")
        if not self.axi_bytes <= self.row_bytes <= AXI_BOUNDARY:
            raise ValueError(f"tile_r={self.tile_r} gives {self.row_bytes}-byte rows, need "
                             f"{self.axi_bytes}..{AXI_BOUNDARY}")
        if self.mem_base + self.memory_bytes > 1 << self.axi_addr_w:
            raise ValueError(f"mem_base={self.mem_base:#x} + 2 frames ({self.memory_bytes} "
                             f"bytes) beyond axi_addr_w={self.axi_addr_w}")

    # ---- sizes ----------------------------------------------------------------------------
    @property
    def word_bytes(self) -> int:
        """Bytes of one stream word (num_rx lanes of 2*data_w bits)."""
        return self.num_rx * 2 * self.data_w // 8

    @property
    def axi_bytes(self) -> int:
        """Bytes of one AXI4 beat."""
        return self.axi_data_w // 8

    @property
    def strips(self) -> int:
        """Strips per TX (n_range / tile_r)."""
        return self.n_range // self.tile_r

    @property
    def row_bytes(self) -> int:
        """Bytes of one row = one write burst (tile_r words)."""
        return self.tile_r * self.word_bytes

    @property
    def strip_bytes(self) -> int:
        return self.row_bytes * self.n_doppler

    @property
    def group_strips(self) -> int:
        """Strips per group (the on-chip buffer's unit): 1 (order 0) or num_tx (order 1)."""
        return self.num_tx if self.read_order == 1 else 1

    @property
    def group_bytes(self) -> int:
        return self.strip_bytes * self.group_strips

    @property
    def read_burst_bytes(self) -> int:
        """One read burst: the largest power of two dividing the group, at most 4 KiB (the
        whole group when it is a power of two of at most 4 KiB)."""
        return min(AXI_BOUNDARY, self.group_bytes & -self.group_bytes)

    def strip_index(self, t: np.ndarray | int, s: np.ndarray | int) -> np.ndarray | int:
        """Position of strip (TX t, range strip s) inside a frame area: ``t*strips + s``
        (read_order 0) or ``s*num_tx + t`` (read_order 1). Broadcasts over arrays."""
        if self.read_order == 1:
            return s * self.num_tx + t
        return t * self.strips + s

    @property
    def frame_words(self) -> int:
        return self.num_tx * self.n_range * self.n_doppler

    @property
    def frame_bytes(self) -> int:
        return self.frame_words * self.word_bytes

    @property
    def memory_bytes(self) -> int:
        """External memory used: two frame areas."""
        return 2 * self.frame_bytes

    @property
    def unit_bits(self) -> int:
        """Width of the on-chip buffers: max(word, AXI beat)."""
        return max(self.word_bytes, self.axi_bytes) * 8

    @property
    def strip_buffer_bits(self) -> int:
        """On-chip read buffer: two halves of a group each (two strips in order 0, 2*num_tx
        in order 1), each half rounded up to a power of two of buffer entries."""
        units = self.group_bytes * 8 // self.unit_bits
        return 2 * (1 << (units - 1).bit_length()) * self.unit_bits

    def area_base(self, k: int) -> int:
        """Byte address of frame k's area."""
        return self.mem_base + (k % 2) * self.frame_bytes

    def word_offsets(self) -> np.ndarray:
        """int64 ``(frame_words,)``: byte offset inside an area of input word i
        (input order: chirp c = d*num_tx + t, range bin r)."""
        d, t, r = np.meshgrid(np.arange(self.n_doppler), np.arange(self.num_tx),
                              np.arange(self.n_range), indexing="ij")
        row = self.strip_index(t, r // self.tile_r) * self.n_doppler + d
        return (row * self.row_bytes + (r % self.tile_r) * self.word_bytes).reshape(-1)


# ---- address trace ---------------------------------------------------------------------------
def write_bursts(g: StoreGeometry, k: int) -> np.ndarray:
    """int64 ``(n, 2)``: (byte address, beats) of frame k's write bursts in issue order."""
    d, t, s = np.meshgrid(np.arange(g.n_doppler), np.arange(g.num_tx), np.arange(g.strips),
                          indexing="ij")
    addr = g.area_base(k) + (g.strip_index(t, s) * g.n_doppler + d).reshape(-1) * g.row_bytes
    return np.stack([addr, np.full_like(addr, g.row_bytes // g.axi_bytes)], axis=1)


def read_bursts(g: StoreGeometry, k: int) -> np.ndarray:
    """int64 ``(n, 2)``: (byte address, beats) of frame k's read bursts in issue order."""
    n = g.frame_bytes // g.read_burst_bytes
    addr = g.area_base(k) + np.arange(n, dtype=np.int64) * g.read_burst_bytes
    return np.stack([addr, np.full_like(addr, g.read_burst_bytes // g.axi_bytes)], axis=1)


def check_bursts(g: StoreGeometry, bursts: np.ndarray) -> None:
    """Raise ValueError if a burst breaks an AXI4 rule (length, 4 KiB, alignment, range)."""
    addr, beats = bursts[:, 0], bursts[:, 1]
    if ((beats < 1) | (beats > MAX_BURST_BEATS)).any():
        raise ValueError("burst length outside 1..256 beats")
    if (addr % g.axi_bytes).any():
        raise ValueError("burst address not aligned to the beat size")
    if ((addr % AXI_BOUNDARY) + beats * g.axi_bytes > AXI_BOUNDARY).any():
        raise ValueError("burst crosses a 4 KiB boundary")
    end = addr + beats * g.axi_bytes
    if (addr < g.mem_base).any() or (end > g.mem_base + g.memory_bytes).any():
        raise ValueError("burst outside the two frame areas")


def interleaved_trace(g: StoreGeometry, n_frames: int) -> list[tuple[int, int, str]]:
    """Bursts ``(addr, beats, 'W'|'R')`` of ``n_frames`` frames in steady state: frame k+1's
    writes interleaved with frame k's reads in proportion to bytes (both directions run
    concurrently); the first frame's writes and the last frame's reads stand alone."""
    out: list[tuple[int, int, str]] = []
    for k in range(n_frames + 1):
        w = write_bursts(g, k) if k < n_frames else np.zeros((0, 2), np.int64)
        r = read_bursts(g, k - 1) if k >= 1 else np.zeros((0, 2), np.int64)
        # merge by the byte position each burst starts at, as a fraction of the frame
        wpos = np.arange(len(w)) / max(len(w), 1)
        rpos = np.arange(len(r)) / max(len(r), 1)
        tagged = [(p, 0, int(a), int(b), WRITE) for p, (a, b) in zip(wpos, w, strict=True)]
        tagged += [(p, 1, int(a), int(b), READ) for p, (a, b) in zip(rpos, r, strict=True)]
        out += [(a, b, kind) for _, _, a, b, kind in sorted(tagged)]
    return out


# ---- DRAM page model ---------------------------------------------------------------------------
@dataclass(frozen=True)
class DramPageModel:
    """Open-page DDR4 model: one open row per bank, an access is a row hit if its bank's open
    row is its row. Address map ROW_BANK_COLUMN: ``column = addr % page_bytes``,
    ``bank = (addr // page_bytes) % banks``, ``row = addr // (page_bytes * banks)``.
    Accesses are ``access_bytes`` column bursts (BL8 on a 64-bit bus = 64 bytes).

    Default: the ZCU106 PL DDR4 (64-bit bus of four x16 DDR4 devices: 2 KiB page each,
    8 KiB per row across the bus, 2 bank groups x 4 banks = 8 banks)."""

    page_bytes: int = 8192
    banks: int = 8
    access_bytes: int = 64

    def row_hits(self, trace: list[tuple[int, int, str]], beat_bytes: int) -> tuple[int, int]:
        """(hits, accesses) of a burst trace ``(addr, beats, kind)`` in issue order."""
        open_row: dict[int, int] = {}
        hits = total = 0
        for addr, beats, _ in trace:
            start, end = addr, addr + beats * beat_bytes
            a = start - start % self.access_bytes
            while a < end:
                page = a // self.page_bytes
                bank, row = page % self.banks, page // self.banks
                # accesses of this burst inside this page
                stop = min(end, (page + 1) * self.page_bytes)
                n = -(-(stop - a) // self.access_bytes)
                hit_first = open_row.get(bank) == row
                hits += n - 1 + int(hit_first)
                total += n
                open_row[bank] = row
                a += n * self.access_bytes
        return hits, total


# ---- payload -------------------------------------------------------------------------------------
def store_frames(frames: list[np.ndarray], g: StoreGeometry) -> list[np.ndarray]:
    """Run frames through the external store: write each through its write bursts into a
    byte memory, read it back through its read bursts and the two-group buffer.

    frames: list of ``(frame_words, num_rx)`` uint32 words in input (chirp) order.
    Returns the output frames ``(frame_words, num_rx)`` in Doppler-vector order ((t, r, d)
    for read_order 0, (r, t, d) for 1), which equal :func:`model.corner_turn.corner_turn`
    of each input with the same read_order.
    """
    if g.data_w != 16:
        raise ValueError("store_frames models 32-bit lanes (data_w=16)")
    mem = np.zeros(g.mem_base + g.memory_bytes, dtype=np.uint8)
    row_words = g.tile_r
    out = []
    for k, f in enumerate(frames):
        f = np.ascontiguousarray(np.asarray(f, dtype="<u4"))
        if f.shape != (g.frame_words, g.num_rx):
            raise ValueError(f"frame {k} has shape {f.shape}, expected "
                             f"{(g.frame_words, g.num_rx)}")
        data = f.view(np.uint8).reshape(-1, row_words * g.word_bytes)   # one row per burst
        for (addr, beats), row in zip(write_bursts(g, k), data, strict=True):
            mem[addr:addr + beats * g.axi_bytes] = row
        stream = np.concatenate([mem[a:a + b * g.axi_bytes] for a, b in read_bursts(g, k)])
        gs = g.group_strips
        words = stream.view("<u4").reshape(g.num_tx * g.strips // gs, gs, g.n_doppler,
                                           row_words, g.num_rx)
        # each group leaves as its Doppler vectors: (group, r, t in group, d)
        out.append(np.ascontiguousarray(words.transpose(0, 3, 1, 2, 4)).reshape(-1, g.num_rx))
    return out


def reference(frames: list[np.ndarray], g: StoreGeometry) -> list[np.ndarray]:
    """The on-chip corner turn of each frame (what the store must reproduce)."""
    return [corner_turn(f, g.num_tx, g.n_range, g.n_doppler, read_order=g.read_order)
            for f in frames]
