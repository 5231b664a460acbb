"""Bit-exact model of ``rtl/detect/cfar_2d.sv`` (2-D CA/GO/SO/OS-CFAR on the integrated power
map, with the optional 3x3 local-maximum test) and the threshold scales it needs, derived
from a requested Pfa with the host CFAR's statistics (``model/cfar_stats.py``).

Maps are int64 ``(n_range, n_doppler)`` powers (``model/nci.py``), Doppler in natural FFT
order and circular. Window per cell under test (CUT) at (q, d): rows q-PR..q+PR, columns
d-PD..d+PD (mod n_doppler) minus the guard rectangle (rows q-GR..q+GR, columns d-GD..d+GD),
PR = GR + TR, PD = GD + TD.

Range edges: rows outside ``0 .. n_range - blank_top - 1`` do not exist (not training cells,
not tested); the window is cut there and the threshold scale is recomputed for the cells
that remain, the same rule as the host CFAR. The scale of a row depends only on its edge
index ``e`` (0..PR-1: PR-e rows cut below; PR: interior; PR+1..2PR: e-PR rows cut above).
The top ``blank_top`` range bins are the negative beat frequencies of a complex-IF range FFT
(host fix pending): blanked rows never detect and never train. ``report`` = (lo, hi): only
rows lo <= r < hi may detect (``RadarConfig.detection_bins``, the host's reporting rule);
the others still train.

Kinds (run-time ``cfg_kind`` codes 0..3, :data:`KINDS`): ``ca`` sums all training cells;
``go``/``so`` take the greater/smaller of the two Doppler halves (column offsets < 0 and > 0;
the CUT's own column is in neither half); ``os`` (built when ``kind`` is ``os`` or ``os``
is set) takes the k-th smallest training cell of the CA window, k = :func:`os_rank_k`.
Decision (exact integers): ``power * 2^scale_frac > S * scale[e]``, S the kind's training sum;
OS: at least k(e) training cells X with ``X * 2^scale_frac < power * scale[e]``, ``scale``
then the inverse factor 2^scale_frac / alpha (one product per cell on chip, not one per
training cell), which is ``power > alpha' * X_(k)`` with alpha' = 2^scale_frac / scale[e].
OS sends the CA training sum and count (the noise estimate S / count). Local maximum
(``local_max``): a detection stays only if none of its 8 neighbours has a greater power
(``host.cfar.local_peaks``'s rule; Doppler circular, a range neighbour outside the map does
not exist: the host's circular range axis differs only on rows 0 and n_range-1, which
``RadarConfig.detection_bins`` never reports).

Output word of the RTL (one per cell, LSB first): power ``pow_w`` bits, training sum S
``sum_w`` bits, training cell count ``cnt_w`` bits, detect 1 bit, then the powers of the
cell's four neighbours, ``pow_w`` bits each, in the order of :data:`NEIGHBOURS` (range - 1,
range + 1, Doppler - 1, Doppler + 1; Doppler circular, 0 outside the map in range): what the
host's peak interpolation needs, so the records give the cube path's range and
Doppler offsets; tuser ``{r, d}``; order per row: d = PD..n_doppler-1, 0..PD-1
(:func:`output_order`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from model.cfar_stats import ca_factor, effective_cells_mask, go_so_factor, os_factor

KINDS = ("ca", "go", "so", "os")
"""CFAR kinds by their code (``KIND`` parameter, ``cfg_kind`` input, the register map)."""
OS_RANK = 750
"""Default OS rank, per mille of the training cells (the host's ``CfarParams.os_rank``)."""
NEIGHBOURS = ((-1, 0), (1, 0), (0, -1), (0, 1))
"""(range, Doppler) offsets of the four neighbour powers of an output cell, in field order."""


@dataclass(frozen=True)
class Cfar2dConfig:
    """RTL parameters of ``cfar_2d`` (validation mirrors its $fatal checks).

    guard/train: cells per side along (range, Doppler). scale_w/scale_frac: unsigned fixed
    point of the threshold scale.
    """

    n_range: int
    n_doppler: int
    pow_w: int
    guard: tuple[int, int] = (2, 2)
    train: tuple[int, int] = (4, 8)
    kind: str = "ca"
    blank_top: int = 0
    scale_w: int = 32
    scale_frac: int = 20
    report: tuple[int, int] | None = None
    os: bool = False
    os_rank: int = OS_RANK

    def __post_init__(self) -> None:
        if self.report is not None and not 0 <= self.report[0] < self.report[1] <= \
                self.n_range:
            raise ValueError(f"report={self.report}: need 0 <= lo < hi <= n_range")
        for name, n in (("n_range", self.n_range), ("n_doppler", self.n_doppler)):
            if n < 4 or n > 4096 or n & (n - 1):
                raise ValueError(f"{name}={n} must be a power of two in 4..4096")
        if not 8 <= self.pow_w <= 62:
            raise ValueError(f"pow_w={self.pow_w} not in 8..62")
        if any(not 0 <= g <= 15 for g in self.guard) or any(not 1 <= t <= 15
                                                            for t in self.train):
            raise ValueError("guard must be in 0..15 and train in 1..15 cells per side")
        if self.kind not in KINDS:
            raise ValueError(f"kind: must be one of {', '.join(KINDS)}, got {self.kind!r}")
        if self.os_built and self.pd < 2:
            raise ValueError("OS needs guard + train >= 2 Doppler cells per side")
        if not 1 <= self.os_rank <= 999:
            raise ValueError(f"os_rank={self.os_rank} not in 1..999 (per mille)")
        if 2 * self.pd + 1 > self.n_doppler:
            raise ValueError(f"Doppler window {2 * self.pd + 1} wider than n_doppler")
        if self.blank_top < 0 or self.rows < 2 * self.pr + 1:
            raise ValueError(f"blank_top={self.blank_top} leaves {self.rows} rows, need >= "
                             f"{2 * self.pr + 1}")
        if not (2 <= self.scale_w <= 48 and 0 <= self.scale_frac < self.scale_w):
            raise ValueError("scale_w must be 2..48 and 0 <= scale_frac < scale_w")
        if self.sum_w > 63:
            raise ValueError("training sum above 63 bits does not fit the int64 model")

    @property
    def pr(self) -> int:
        return self.guard[0] + self.train[0]

    @property
    def pd(self) -> int:
        return self.guard[1] + self.train[1]

    @property
    def os_built(self) -> bool:
        """The OS test is built (``OS_BUILD``)."""
        return self.os or self.kind == "os"

    def run_kind(self, kind: str | None) -> str:
        """The kind the RTL runs for ``cfg_kind`` = ``kind`` (None: ``self.kind``): a kind
        that is not built (OS) selects ``self.kind``."""
        k = self.kind if kind is None else kind
        if k not in KINDS:
            raise ValueError(f"kind: must be one of {', '.join(KINDS)}, got {k!r}")
        return self.kind if k == "os" and not self.os_built else k

    @property
    def rows(self) -> int:
        """Range rows that exist for the CFAR (tested and training)."""
        return self.n_range - self.blank_top

    @property
    def n_edge(self) -> int:
        """Entries of the scale table (edge indices)."""
        return 2 * self.pr + 1

    @property
    def cnt_w(self) -> int:
        return ((2 * self.pr + 1) * (2 * self.pd + 1) - 1).bit_length()

    @property
    def sum_w(self) -> int:
        return self.pow_w + self.cnt_w

    @property
    def out_bytes(self) -> int:
        return (self.pow_w + self.sum_w + self.cnt_w + 1 + len(NEIGHBOURS) * self.pow_w
                + 7) // 8

    def hdl_parameters(self) -> dict[str, int]:
        """HDL parameters of ``cfar_2d`` for this configuration."""
        rep = ({} if self.report is None
               else dict(REPORT_LO=self.report[0], REPORT_HI=self.report[1]))
        if self.os and self.kind != "os":
            rep["OS_BUILD"] = 1
        if self.os_rank != OS_RANK:
            rep["OS_RANK"] = self.os_rank
        return dict(N_RANGE=self.n_range, N_DOPPLER=self.n_doppler, POW_W=self.pow_w,
                    GUARD_R=self.guard[0], GUARD_D=self.guard[1], TRAIN_R=self.train[0],
                    TRAIN_D=self.train[1], KIND=KINDS.index(self.kind),
                    BLANK_TOP=self.blank_top, SCALE_W=self.scale_w,
                    SCALE_FRAC=self.scale_frac, **rep)


@dataclass
class CfarCells:
    """Per-cell results, each ``(n_range, n_doppler)``: ``power`` and ``train_sum`` int64,
    ``count`` int64 training cells in the sum, ``detect`` bool; ``neighbours`` int64
    ``(n_range, n_doppler, 4)``: the powers of each cell's neighbours (:func:`neighbours`)."""

    power: np.ndarray
    train_sum: np.ndarray
    count: np.ndarray
    detect: np.ndarray
    neighbours: np.ndarray

    def noise(self) -> np.ndarray:
        """Mean training power per cell, float64 ``(n_range, n_doppler)``."""
        return self.train_sum / np.maximum(self.count, 1)


def edge_index(q: int, cfg: Cfar2dConfig) -> int:
    """Scale-table index of range row q (clamped for blanked rows)."""
    lo = max(0, cfg.pr - q)
    hi = min(cfg.pr, max(0, q + cfg.pr - (cfg.rows - 1)))
    return cfg.pr - lo if lo else cfg.pr + hi


def window_rows(q: int, cfg: Cfar2dConfig) -> np.ndarray:
    """bool ``(2PR+1,)``: window row k (range row q-PR+k) exists."""
    rows = q - cfg.pr + np.arange(2 * cfg.pr + 1)
    return (rows >= 0) & (rows < cfg.rows)


def training_mask(cfg: Cfar2dConfig, e: int, half: bool) -> np.ndarray:
    """Training cells for edge index e, float ``(2PR+1, 2PD+1)`` (CUT at the centre);
    ``half``: only the left Doppler half (offsets < 0)."""
    (gr, gd), (pr, pd) = cfg.guard, (cfg.pr, cfg.pd)
    k = np.ones((2 * pr + 1, 2 * pd + 1))
    k[pr - gr:pr + gr + 1, pd - gd:pd + gd + 1] = 0.0
    if half:
        k[:, pd:] = 0.0
    if e < pr:
        k[:pr - e] = 0.0
    elif e > pr:
        k[2 * pr + 1 - (e - pr):] = 0.0
    return k


def os_rank_k(n: int, os_rank: int = OS_RANK) -> int:
    """OS rank k of ``n`` training cells: ``os_rank`` per mille, rounded half to even (the
    host's ``round(os_rank * n)``), clipped to 1..n (the RTL's k table, exact integers)."""
    q, r = divmod(os_rank * n, 1000)
    q += r > 500 or (r == 500 and q % 2 == 1)
    return max(1, min(n, q))


def threshold_factors(cfg: Cfar2dConfig, pfa: float, n_channels: int,
                      windowed: tuple[bool, bool] = (True, True), kind: str | None = None
                      ) -> tuple[np.ndarray, np.ndarray]:
    """Per edge index: (alpha float ``(2PR+1,)``, training cells int ``(2PR+1,)``) such
    that ``CUT > alpha * S / cells`` (OS: ``CUT > alpha * X_(k)``) has false-alarm
    probability ``pfa`` under noise, for ``kind`` (None: ``cfg.kind``).

    Effective cells scale with the cells that remain at range edges (host rule:
    N_eff = cells * N_eff(full window) / cells(full window)); OS takes the cells as
    independent (the host's ``os_factor`` rule).
    """
    kind = cfg.run_kind(kind)
    half = kind in ("go", "so")
    full = training_mask(cfg, cfg.pr, half)
    eff_per_cell = effective_cells_mask(full, windowed) / full.sum()
    alphas, cells = [], []
    for e in range(cfg.n_edge):
        c = int(training_mask(cfg, e, half).sum())
        n_eff = c * eff_per_cell
        if kind == "os":
            a = os_factor(pfa, n_channels, c, os_rank_k(c, cfg.os_rank))
        elif half:
            a = go_so_factor(pfa, n_channels, n_eff, kind)
        else:
            a = float(ca_factor(pfa, n_channels, n_eff))
        alphas.append(a)
        cells.append(c)
    return np.array(alphas), np.array(cells, dtype=np.int64)


def scale_table(cfg: Cfar2dConfig, pfa: float, n_channels: int,
                windowed: tuple[bool, bool] = (True, True), kind: str | None = None
                ) -> np.ndarray:
    """Fixed-point threshold scales int64 ``(2PR+1,)`` for ``kind`` (None: ``cfg.kind``):
    round(alpha / cells * 2^frac), OS round(2^frac / alpha) (the RTL's ``cfg_scale`` input,
    entry e at bits ``e*scale_w``)."""
    alpha, cells = threshold_factors(cfg, pfa, n_channels, windowed, kind)
    value = 1.0 / alpha if cfg.run_kind(kind) == "os" else alpha / cells
    s = np.rint(value * (1 << cfg.scale_frac)).astype(np.int64)
    if (s >= 1 << cfg.scale_w).any() or (s < 1).any():
        raise ValueError(f"threshold scale {value} does not fit {cfg.scale_w} bits "
                         f"with {cfg.scale_frac} fraction bits")
    return s


def pack_scale(scale: np.ndarray, cfg: Cfar2dConfig) -> int:
    """Scale table as the integer value of the RTL's ``cfg_scale`` port."""
    return sum(int(v) << (e * cfg.scale_w) for e, v in enumerate(scale))


def neighbours(power: np.ndarray) -> np.ndarray:
    """Powers of the four neighbours (:data:`NEIGHBOURS`) of every cell of a map (int64
    ``(n_range, n_doppler)``; any dtype), ``(n_range, n_doppler, 4)`` of its dtype:
    Doppler circular; 0 beyond the first and last range rows (blanked rows are real map
    rows here: their power is sent, as the host's map has it)."""
    p = np.asarray(power)
    out = np.zeros((*p.shape, len(NEIGHBOURS)), dtype=p.dtype)
    out[1:, :, 0] = p[:-1]
    out[:-1, :, 1] = p[1:]
    out[:, :, 2] = np.roll(p, 1, axis=1)
    out[:, :, 3] = np.roll(p, -1, axis=1)
    return out


def local_maxima(power: np.ndarray) -> np.ndarray:
    """bool ``(n_range, n_doppler)``: no 8-neighbour of the cell has a greater power (int
    map; Doppler circular, a range neighbour outside the map does not exist)."""
    p = np.asarray(power)
    pad = np.pad(p, ((1, 1), (0, 0)), constant_values=np.iinfo(np.int64).min)
    keep = np.ones(p.shape, dtype=bool)
    for dr in (-1, 0, 1):
        rows = pad[1 + dr:1 + dr + p.shape[0]]
        for dd in (-1, 0, 1):
            if dr or dd:
                keep &= np.roll(rows, -dd, axis=1) <= p
    return keep


def os_detect(power: np.ndarray, cfg: Cfar2dConfig, scale: np.ndarray) -> np.ndarray:
    """OS decisions of every cell (bool ``(n_range, n_doppler)``, before the reporting
    rule): at least k(e) training cells X with ``X * 2^scale_frac < CUT * scale[e]``.
    power: int64 ``(n_range, n_doppler)``; scale: the inverse scales (:func:`scale_table`)."""
    p = np.asarray(power, dtype=np.int64)
    nr, nd = p.shape
    (pr, pd), big = (cfg.pr, cfg.pd), 1 << 62
    sc = np.array([int(scale[edge_index(q, cfg)]) for q in range(nr)], dtype=np.int64)
    # X * 2^frac < CUT * scale  <=>  X <= floor((CUT * scale - 1) / 2^frac) (-1: none);
    # exact in int64 while the product fits, else in Python integers
    if int(p.max()) * int(sc.max()) < big:
        t = (p * sc[:, None] - 1) >> cfg.scale_frac
    else:
        t = np.array([[min((int(c) * int(s) - 1) >> cfg.scale_frac, big) for c in row]
                      for row, s in zip(p, sc, strict=True)], dtype=np.int64)
    # rows that do not exist (cut, blanked) never count: padded above any threshold
    padded = np.full((nr + 2 * pr, nd + 2 * pd), big + 1, dtype=np.int64)
    padded[pr:pr + cfg.rows] = np.pad(p[:cfg.rows], ((0, 0), (pd, pd)), mode="wrap")
    count = np.zeros(p.shape, dtype=np.int64)
    for kr, kd in zip(*np.nonzero(training_mask(cfg, pr, False)), strict=True):
        count += padded[kr:kr + nr, kd:kd + nd] <= t
    k = [os_rank_k(int(training_mask(cfg, edge_index(q, cfg), False).sum()), cfg.os_rank)
         for q in range(nr)]
    return count >= np.array(k)[:, None]


def cfar_2d(power: np.ndarray, cfg: Cfar2dConfig, scale: np.ndarray, kind: str | None = None,
            local_max: bool = False) -> CfarCells:
    """Run the CFAR on one map. power: int ``(n_range, n_doppler)``; scale: int
    ``(2PR+1,)`` from :func:`scale_table` for the kind run; ``kind``: the RTL's
    ``cfg_kind`` (None: ``cfg.kind``; :meth:`Cfar2dConfig.run_kind`); ``local_max``: its
    ``cfg_local_max`` (keep only the detections that are 3x3 local maxima)."""
    kind = cfg.run_kind(kind)
    p = np.asarray(power, dtype=np.int64)
    if p.shape != (cfg.n_range, cfg.n_doppler):
        raise ValueError(f"power: expected {(cfg.n_range, cfg.n_doppler)}, got {p.shape}")
    (gr, gd), pr, pd = cfg.guard, cfg.pr, cfg.pd
    train_sum = np.zeros_like(p)
    count = np.zeros_like(p)
    detect = np.zeros(p.shape, dtype=bool)
    frac = 1 << cfg.scale_frac
    lo, hi = cfg.report or (0, cfg.n_range)
    os_det = os_detect(p, cfg, scale) if kind == "os" else None
    for q in range(cfg.n_range):
        rowv = window_rows(q, cfg)
        rows = q - pr + np.nonzero(rowv)[0]
        inner = rows[np.abs(rows - q) <= gr]
        vo = p[rows].sum(axis=0)
        vi = p[inner].sum(axis=0)
        n_out, n_in = len(rows), len(inner)

        def win(v: np.ndarray, js: range) -> np.ndarray:
            return sum((np.roll(v, -j) for j in js), np.zeros_like(v))

        left = win(vo, range(-pd, 0)) - win(vi, range(-gd, 0))
        right = win(vo, range(1, pd + 1)) - win(vi, range(1, gd + 1))
        if kind in ("ca", "os"):
            s = left + right + vo - vi
            count[q] = n_out * (2 * pd + 1) - n_in * (2 * gd + 1)
        else:
            s = np.maximum(left, right) if kind == "go" else np.minimum(left, right)
            count[q] = n_out * pd - n_in * gd
        train_sum[q] = s
        if q < cfg.rows and lo <= q < hi:
            sc = int(scale[edge_index(q, cfg)])
            if os_det is not None:
                detect[q] = os_det[q]
            else:
                detect[q] = [int(c) * frac > int(t) * sc
                             for c, t in zip(p[q], s, strict=True)]
    if local_max:
        detect &= local_maxima(p)
    return CfarCells(p, train_sum, count, detect, neighbours(p))


def output_order(cfg: Cfar2dConfig) -> np.ndarray:
    """int ``(n_range * n_doppler, 2)``: (r, d) of the RTL's output cells in stream order."""
    d = (np.arange(cfg.n_doppler) + cfg.pd) % cfg.n_doppler
    r = np.repeat(np.arange(cfg.n_range), cfg.n_doppler)
    return np.stack([r, np.tile(d, cfg.n_range)], axis=1)


def pack_cell(cells: CfarCells, r: int, d: int, cfg: Cfar2dConfig) -> int:
    """The RTL's output word of cell (r, d) (module docstring), as an integer."""
    pw, sw, cw = cfg.pow_w, cfg.sum_w, cfg.cnt_w
    v = (int(cells.power[r, d]) | (int(cells.train_sum[r, d]) << pw)
         | (int(cells.count[r, d]) << (pw + sw)) | (int(cells.detect[r, d]) << (pw + sw + cw)))
    base = pw + sw + cw + 1
    for k, nb in enumerate(cells.neighbours[r, d]):
        v |= int(nb) << (base + k * pw)
    return v


def unpack_cell(value: int, cfg: Cfar2dConfig
                ) -> tuple[int, int, int, bool, tuple[int, ...]]:
    """RTL output word -> (power, train_sum, count, detect, neighbour powers (4,))."""
    pw, sw, cw = cfg.pow_w, cfg.sum_w, cfg.cnt_w
    base = pw + sw + cw + 1
    mask = (1 << pw) - 1
    return (value & mask, (value >> pw) & ((1 << sw) - 1),
            (value >> (pw + sw)) & ((1 << cw) - 1), bool((value >> (pw + sw + cw)) & 1),
            tuple((value >> (base + k * pw)) & mask for k in range(len(NEIGHBOURS))))
