"""Host processing of the FPGA's detection records (``OUTPUT_MODE = 1``) into the same point
cloud as :func:`host.pipeline.process_cube` makes from a cube.

The FPGA already ran NCI and the 2-D CFAR; a record carries the cell's NCI power, the CFAR's
noise estimate and the NUM_TX x NUM_RX snapshot. The host then does what it does after its
own CFAR (``host.pipeline`` module docstring), on the records alone:

1. keep cells inside ``RadarConfig.detection_bins``;
2. peak grouping: a record is kept when no detected cell of its 3x3 neighbourhood (both
   axes circular) and none of its four direct neighbours (the record's neighbour powers,
   detected or not) is stronger (``host.cfar.local_peaks`` on the map of detected powers,
   and the neighbour powers; the host's own CFAR compares against every neighbour, which
   differs only when an undetected *diagonal* neighbour is stronger than a detected cell);
3. sidelobe masking against stronger *detected* cells in the same row and column
   (``host.cfar.sidelobe_masked``; a cell strong enough to throw sidelobes above the
   threshold is always detected itself);
4. peak offsets: the interpolation over the 3 powers along each axis matched to the
   axis' window and padding, from the four neighbour powers every record carries
   (``host.cells.neighbour_offsets``, the cube path's interpolation on the same values:
   detected or not, the neighbours' powers come from the FPGA's map);
5. TDM compensation, velocity unfolding, angle estimation and the point cloud: the cube
   path's code, ``host.points.points_from_cells``, on the selected records as
   ``host.cells.Cells``.

:func:`process_records` is the public entry (records -> point cloud; the live view, the
CLI). The selection works on the records alone (:func:`select_records`, compiled); its
definition on the whole map (``host.cfar.local_peaks``, ``host.cfar.sidelobe_masked``) is
the oracle in ``tests/oracles/points.py``.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from host.cells import Cells, neighbour_offsets
from host.cfar import sidelobe_envelope
from host.kernels import njit
from host.params import DetectionParams
from host.pointcloud import PointCloud
from host.points import points_from_cells
from host.records import RecordArrays, outside_map
from model.array import slot_channels
from model.config import RadarConfig
from model.reference import fft_axes


def record_offsets(power: np.ndarray, neighbours: np.ndarray, range_bin: np.ndarray,
                   cfg: RadarConfig, params: DetectionParams) -> np.ndarray:
    """Fractional (range, Doppler) peak offsets, float (n, 2) bins, of records (step 4 of
    the module docstring): power float (n,), neighbours float (n, 4)
    (``host.records.RecordArrays``), range_bin int (n,); the cube path's interpolation
    (``host.cells.peak_offsets``) on the same powers, for ``cfg``'s axes with the windows
    of ``params``."""
    r = np.asarray(range_bin)
    return neighbour_offsets(power, neighbours, (r > 0) & (r < cfg.n_range_bins - 1),
                             fft_axes(cfg, params.range_window, params.doppler_window))


@lru_cache(maxsize=16)
def _envelope(n: int, windowed: bool, margin_db: float) -> np.ndarray:
    """``host.cfar.sidelobe_envelope`` times the margin, float (n,), computed once per
    setting (read-only)."""
    env = sidelobe_envelope(n, windowed) * 10 ** (margin_db / 10)
    env.flags.writeable = False
    return env


def select_records(arr: RecordArrays, cfg: RadarConfig, params: DetectionParams
                   ) -> np.ndarray:
    """Indices (int (m,)) of the records that become points (steps 1 to 3), in (range,
    Doppler) order. Works on the records alone (compiled, :func:`select_cells`: a 3x3
    gather per record, pairs of detected cells in a row or column), with the result of
    ``host.cfar.local_peaks`` and ``host.cfar.sidelobe_masked`` on the map."""
    nr, nd = cfg.n_range_bins, cfg.n_doppler
    envelopes = None
    if params.sidelobe_margin_db is not None:
        envelopes = (_envelope(nr, params.range_window, params.sidelobe_margin_db),
                     _envelope(nd, params.doppler_window, params.sidelobe_margin_db))
    nbmax = None if arr.neighbours is None else arr.neighbours.max(axis=1, initial=0.0)
    return select_cells(arr.range_bin, arr.doppler_bin, arr.power, nbmax, (nr, nd),
                        cfg.detection_bins, envelopes)


def _neighbours(arr: RecordArrays) -> np.ndarray:
    """The records' neighbour powers, float (n, 4); ValueError when they are not known."""
    if arr.neighbours is None:
        raise ValueError("records without neighbour powers: the peak offsets need them "
                         "(host.records.record_arrays gives them)")
    return arr.neighbours


def _check_records(arr: RecordArrays, cfg: RadarConfig) -> None:
    """ValueError naming the problem when the records do not fit ``cfg``: their channel
    count, or bins outside its map (``host.records.inside_map`` drops those first)."""
    n = len(np.asarray(arr.range_bin))
    shapes = {"range_bin": (n,), "doppler_bin": (n,), "power": (n,), "noise": (n,),
              "snapshot": (n, cfg.n_virtual)}
    if arr.neighbours is not None:
        shapes["neighbours"] = (n, 4)
    for name, shape in shapes.items():
        value = np.asarray(getattr(arr, name))
        if name == "snapshot" and value.shape[1:] != shape[1:]:
            raise ValueError(f"records carry {value.shape[1:]} channels, {cfg.name} has "
                             f"{cfg.n_virtual} virtual channels")
        if value.shape != shape:
            raise ValueError(f"records: {name} has shape {value.shape}, expected {shape} "
                             f"({n} records)")
        kinds = {"range_bin": "iu", "doppler_bin": "iu", "snapshot": "c"}.get(name, "fiu")
        if value.dtype.kind not in kinds:
            want = {"iu": "integer", "c": "complex"}.get(kinds, "real")
            raise ValueError(f"records: {name} has dtype {value.dtype}, expected {want}")
        if kinds == "fiu" and not (np.isfinite(value).all() and (value >= 0).all()):
            raise ValueError(f"records: {name} must be finite and >= 0 (powers)")
    out = np.flatnonzero(outside_map(arr, cfg))
    if len(out):
        i = out[0]
        raise ValueError(f"{len(out)} record(s) outside {cfg.name}'s {cfg.n_range_bins} x "
                         f"{cfg.n_doppler} map (first: range bin {arr.range_bin[i]}, Doppler "
                         f"bin {arr.doppler_bin[i]}); host.records.inside_map drops them")


def process_records(arr: RecordArrays, cfg: RadarConfig, params: DetectionParams | None = None,
                    frame: int = 0) -> PointCloud:
    """Point cloud of one frame's records (``host.records.record_arrays``, host float units)
    -> the same :class:`host.pointcloud.PointCloud` as ``host.pipeline.process_cube``:
    record selection (steps 1 to 3), peak offsets (step 4), ``host.points.
    points_from_cells``. The public records -> point cloud function (CLI, live view)."""
    params = params or DetectionParams()
    return points_from_cells(record_cells(arr, cfg, params), cfg, params, frame)


def record_cells(arr: RecordArrays, cfg: RadarConfig, params: DetectionParams) -> Cells:
    """The records that become points (steps 1 to 4) as :class:`host.cells.Cells`;
    ValueError naming the problem when the records do not fit ``cfg``."""
    _check_records(arr, cfg)
    idx = select_records(arr, cfg, params)
    r = arr.range_bin[idx]
    offsets = record_offsets(arr.power[idx], _neighbours(arr)[idx], r, cfg, params)
    snapshot = arr.snapshot[idx]
    order = slot_channels(cfg)          # the chain's channels are chirp slots
    return Cells(r, arr.doppler_bin[idx], arr.power[idx], arr.noise[idx], offsets,
                 snapshot if order is None else snapshot[:, order])


@njit()
def _select(r: np.ndarray, d: np.ndarray, power: np.ndarray, nbmax: np.ndarray, nr: int,
            nd: int, lo: int, hi: int, sidelobes: bool, env_r: np.ndarray,
            env_d: np.ndarray) -> np.ndarray:
    """:func:`select_cells` (nbmax: float (n,) the largest neighbour power, 0 when not
    known; env_*: the sidelobe envelopes times the margin)."""
    n = r.shape[0]
    pmap = np.zeros((nr, nd))
    idx1 = np.zeros((nr, nd), np.int64)         # record index + 1 (the last one wins)
    for i in range(n):
        pmap[r[i], d[i]] = power[i]
        idx1[r[i], d[i]] = i + 1
    own = np.zeros(n, np.bool_)                  # the records that are the map's non-zeros
    for i in range(n):
        own[i] = idx1[r[i], d[i]] == i + 1 and pmap[r[i], d[i]] > 0
    cand = np.empty(n, np.int64)
    nc = 0
    for i in range(n):
        if not own[i] or r[i] < lo or r[i] >= hi:
            continue
        p = pmap[r[i], d[i]]
        mx = max(p, nbmax[i])
        for a in range(-1, 2):
            for b in range(-1, 2):
                if a or b:
                    mx = max(mx, pmap[(r[i] + a) % nr, (d[i] + b) % nd])
        if p >= mx:
            cand[nc] = i
            nc += 1
    cand = cand[:nc]
    cand = cand[np.argsort(r[cand] * nd + d[cand], kind="mergesort")]
    if not sidelobes or nc == 0:
        return cand
    # the non-zero cells grouped by column and by row (counting sort)
    col_start = np.zeros(nd + 1, np.int64)
    row_start = np.zeros(nr + 1, np.int64)
    for i in range(n):
        if own[i]:
            col_start[d[i] + 1] += 1
            row_start[r[i] + 1] += 1
    for k in range(nd):
        col_start[k + 1] += col_start[k]
    for k in range(nr):
        row_start[k + 1] += row_start[k]
    col_rows = np.empty(col_start[nd], np.int64)
    row_cols = np.empty(row_start[nr], np.int64)
    col_fill = col_start[:nd].copy()
    row_fill = row_start[:nr].copy()
    for i in range(n):
        if own[i]:
            col_rows[col_fill[d[i]]] = r[i]
            col_fill[d[i]] += 1
            row_cols[row_fill[r[i]]] = d[i]
            row_fill[r[i]] += 1
    keep = np.empty(nc, np.bool_)
    for c in range(nc):
        i = cand[c]
        p = pmap[r[i], d[i]]
        masked = False
        for k in range(col_start[d[i]], col_start[d[i] + 1]):
            rr = col_rows[k]
            if pmap[rr, d[i]] * env_r[(r[i] - rr) % nr] > p:
                masked = True
        for k in range(row_start[r[i]], row_start[r[i] + 1]):
            dd = row_cols[k]
            if pmap[r[i], dd] * env_d[(d[i] - dd) % nd] > p:
                masked = True
        keep[c] = not masked
    return cand[keep]


def select_cells(range_bin: np.ndarray, doppler_bin: np.ndarray, power: np.ndarray,
                 neighbour_max: np.ndarray | None, shape: tuple[int, int],
                 bins: tuple[int, int], envelopes: tuple[np.ndarray, np.ndarray] | None
                 ) -> np.ndarray:
    """The records that become points (:func:`select_records`): indices int
    (m,) in (range, Doppler) order of the records that hold their cell (the last record of a
    cell wins, power > 0), lie in range bins ``bins`` = [lo, hi), are no weaker than any
    of the 8 cells around them on the map of detected powers (both axes circular) nor than
    ``neighbour_max`` (float (n,), their largest neighbour power, detected or not), and,
    with ``envelopes`` (range, Doppler sidelobe envelopes times the margin, float
    (n_range,), (n_doppler,)), are not below the sidelobes of a detected cell in their
    column or row. range_bin, doppler_bin: int (n,); power: float (n,); shape: (n_range,
    n_doppler)."""
    n = len(range_bin)
    nbmax = np.zeros(n) if neighbour_max is None else np.asarray(neighbour_max, dtype=float)
    z = np.zeros(1)
    env_r, env_d = envelopes if envelopes is not None else (z, z)
    return _select(np.ascontiguousarray(range_bin, dtype=np.int64),
                   np.ascontiguousarray(doppler_bin, dtype=np.int64),
                   np.ascontiguousarray(power, dtype=float), np.ascontiguousarray(nbmax),
                   int(shape[0]), int(shape[1]), int(bins[0]), int(bins[1]),
                   envelopes is not None, np.ascontiguousarray(env_r, dtype=float),
                   np.ascontiguousarray(env_d, dtype=float))
