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
4. peak offsets: Gaussian interpolation over the 3 log powers along each axis, from the
   four neighbour powers every record carries (``host.pipeline.neighbour_offsets``, the
   cube path's interpolation on the same values: detected or not, the neighbours' powers
   come from the FPGA's map);
5. TDM compensation, velocity unfolding, angle estimation and the point cloud: the same
   points as :func:`host.pipeline.points_from_cells` (the cube path's code), computed by
   :func:`points_from_snapshots` with less work: the TDM test runs only the alias classes
   that hold a velocity hypothesis of the cell (what ``host.pipeline.choose_folds`` looks
   at), and the search for a second angle component only where a Cauchy-Schwarz bound
   leaves room for one (``host.angle.estimate_angles_screened``).

:func:`process_records` is the public entry (records -> point cloud; the live view, the
CLI); :func:`process_records_reference` is the path it replaced (benchmark, tests).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from host.angle import estimate_angles_screened, peak_power_lean, screened_components
from host.cell_kernels import (
    class_peaks,
    first_components,
    peak_sins,
    relax_rows,
    select_cells,
    steering_rows,
)
from host.cfar import detection_mask, local_peaks, sidelobe_envelope, sidelobe_masked
from host.pipeline import (
    DetectionParams,
    _cloud,
    _tdm_compensate,
    _tdm_tx_phasors,
    alias_orders,
    cell_snr_db,
    choose_folds,
    neighbour_offsets,
    points_from_cells,
)
from host.pointcloud import PointCloud
from host.records import RecordArrays, outside_map
from model.config import RadarConfig
from model.reference import signed_bins


def record_offsets(power: np.ndarray, neighbours: np.ndarray, range_bin: np.ndarray,
                   n_range: int) -> np.ndarray:
    """Fractional (range, Doppler) peak offsets, float (n, 2) bins, of records (step 4 of
    the module docstring): power float (n,), neighbours float (n, 4)
    (``host.records.RecordArrays``), range_bin int (n,); the cube path's interpolation
    (``host.pipeline.peak_offsets``) on the same powers."""
    logc = np.log(np.maximum(power, 1e-30))
    lognb = np.log(np.maximum(neighbours, 1e-30))
    r = np.asarray(range_bin)
    return neighbour_offsets(logc, lognb, (r > 0) & (r < n_range - 1))


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
    Doppler) order. Works on the records
    alone (compiled, ``host.cell_kernels.select_cells``: a 3x3 gather per record, pairs
    of detected cells in a row or column), with the result of ``host.cfar.local_peaks`` and
    ``host.cfar.sidelobe_masked`` on the map (:func:`select_records_reference`)."""
    nr, nd = cfg.n_range, cfg.n_doppler
    envelopes = None
    if params.sidelobe_margin_db is not None:
        envelopes = (_envelope(nr, params.range_window, params.sidelobe_margin_db),
                     _envelope(nd, params.doppler_window, params.sidelobe_margin_db))
    nbmax = None if arr.neighbours is None else arr.neighbours.max(axis=1, initial=0.0)
    return select_cells(arr.range_bin, arr.doppler_bin, arr.power, nbmax, (nr, nd),
                        cfg.detection_bins, envelopes)


def select_records_reference(arr: RecordArrays, cfg: RadarConfig, params: DetectionParams
                             ) -> tuple[np.ndarray, np.ndarray]:
    """:func:`select_records` on the whole map (``host.cfar.local_peaks``,
    ``host.cfar.sidelobe_masked``): the specification, and the benchmark's old path; also
    returns that map of detected powers, float (n_range, n_doppler)."""
    nr, nd = cfg.n_range, cfg.n_doppler
    pmap = np.zeros((nr, nd))
    index = np.full((nr, nd), -1, np.int64)
    pmap[arr.range_bin, arr.doppler_bin] = arr.power
    index[arr.range_bin, arr.doppler_bin] = np.arange(len(arr))
    mask = (pmap > 0) & detection_mask(nr, nd, cfg.detection_bins)
    if arr.neighbours is not None:           # a direct neighbour, detected or not, is stronger
        nbmax = np.zeros((nr, nd))
        nbmax[arr.range_bin, arr.doppler_bin] = arr.neighbours.max(axis=1, initial=0.0)
        mask &= pmap >= nbmax
    cells = local_peaks(pmap, mask)
    windowed = (params.range_window, params.doppler_window)
    if params.sidelobe_margin_db is not None and len(cells):
        cells = cells[~sidelobe_masked(pmap, cells, windowed, params.sidelobe_margin_db)]
    return index[cells[:, 0], cells[:, 1]], pmap


def hypothesis_classes(cfg: RadarConfig, velocity_mps: np.ndarray, params: DetectionParams
                       ) -> np.ndarray:
    """Alias classes c = m mod num_tx that hold a velocity hypothesis m of each cell (the
    hypotheses of ``host.pipeline.choose_folds``: |v + 2 m vmax| <= max_speed, m = 0 when
    none is), bool (n, num_tx); velocity_mps: float (n,) measured (aliased). Only these
    classes' powers enter the unfolding decision."""
    lo, hi, _ = alias_orders(cfg, velocity_mps, params)
    count = hi - lo + 1                        # consecutive orders lo..hi (none: m = 0)
    first = np.where(count > 0, lo, 0)
    count = np.maximum(count, 1)
    c = np.arange(cfg.num_tx)
    # class c holds an order of lo..hi when the first one at or after lo is within it
    return (c[None, :] - first[:, None]) % cfg.num_tx < count[:, None]


def points_from_snapshots(cells: np.ndarray, snapshots: np.ndarray, power: np.ndarray,
                          noise: np.ndarray, offsets: np.ndarray, cfg: RadarConfig,
                          params: DetectionParams, frame: int = 0, compiled: bool = True
                          ) -> PointCloud:
    """``host.pipeline.points_from_cells`` (steps 3 to 5 there; same arguments, same
    points) with less work: angle peaks (``host.angle.fine_peaks``) only of the TDM alias
    classes in :func:`hypothesis_classes` (the others do not enter ``choose_folds``), and
    the second-component search screened (``host.angle.estimate_angles_screened``).
    ``compiled``: the class peaks, first angle components, steering vectors and RELAX peak
    searches by the compiled kernels of ``host.cell_kernels`` (default); False: by numpy
    (the same values to rounding).

    cells: int (n, 2) (range_bin, doppler_bin natural order); snapshots: complex
    (n, n_virtual); power, noise: float (n,); offsets: float (n, 2) bins."""
    n = len(cells)
    if not n:
        return PointCloud.empty()
    nd, nv, ntx = cfg.n_doppler, cfg.n_virtual, cfg.num_tx
    r, d = np.asarray(cells[:, 0]), np.asarray(cells[:, 1])
    x = np.ascontiguousarray(snapshots, dtype=np.complex128)   # once for every kernel
    noise = np.asarray(noise, dtype=float)
    sb = signed_bins(nd)[d].astype(np.int64)
    snr_db = cell_snr_db(power, noise, nv)
    measured = (sb + offsets[:, 1]) * cfg.velocity_bin_mps
    fold = np.zeros(n, np.int64)
    sn_sel = None
    if ntx > 1 and params.unfold_velocity:
        ci, cc = np.nonzero(hypothesis_classes(cfg, measured, params))   # (cell, class) pairs
        if compiled:
            pw, sn = class_peaks(x, ci, _tdm_tx_phasors(cfg, sb[ci] + cc * nd),
                                 params.angle.n_fft)
        else:
            xc = _tdm_compensate(cfg, x[ci], sb[ci] + cc * nd)
            pw, sn = peak_power_lean(xc, params.angle.n_fft)
        class_power = np.zeros((n, ntx))         # absent classes: masked by choose_folds
        class_power[ci, cc] = pw
        pair = np.full((n, ntx), -1, np.int64)
        pair[ci, cc] = np.arange(len(ci))
        fold, ambiguous = choose_folds(class_power, cfg, measured, snr_db, params)
        # the fold's class always holds a hypothesis: its peak was computed
        sel = pair[np.arange(n), fold % ntx]
        sn_sel = sn[sel]
        if not compiled:
            ang = estimate_angles_screened(xc[sel], noise / nv, params.angle, first_sin=sn_sel)
    else:
        fold, ambiguous = choose_folds(np.zeros((n, 0)), cfg, measured, snr_db, params)
        if not compiled:
            ang = estimate_angles_screened(_tdm_compensate(cfg, x, sb + fold * nd), noise / nv,
                                           params.angle)
    if compiled:
        ph = _tdm_tx_phasors(cfg, sb + fold * nd)
        if sn_sel is None:                       # no TDM test: the peaks of the fold's class
            sn_sel = class_peaks(x, np.arange(n), ph, params.angle.n_fft)[1]
        a = params.angle
        xs, a1, p1, maybe = first_components(x, ph, sn_sel, noise / nv, a.min_snr_db,
                                             a.dynamic_range_db, a.max_targets > 1)
        ang = screened_components(xs, np.maximum(noise / nv, 1e-30), a, sn_sel, a1, p1, maybe,
                                  peaks=peak_sins, steer=steering_rows, relax=relax_rows)
    return _cloud(cfg, params, r, offsets, sb + fold * nd, ambiguous, ang.cell,
                  ang.azimuth_deg, ang.amplitude, ang.snr_db, frame)


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
        raise ValueError(f"{len(out)} record(s) outside {cfg.name}'s {cfg.n_range} x "
                         f"{cfg.n_doppler} map (first: range bin {arr.range_bin[i]}, Doppler "
                         f"bin {arr.doppler_bin[i]}); host.records.inside_map drops them")


def process_records(arr: RecordArrays, cfg: RadarConfig, params: DetectionParams | None = None,
                    frame: int = 0, reference: bool = False, compiled: bool = True
                    ) -> PointCloud:
    """Point cloud of one frame's records (``host.records.record_arrays``, host float units)
    -> the same :class:`host.pointcloud.PointCloud` as ``host.pipeline.process_cube``:
    record selection (steps 1 to 3), peak offsets (step 4), :func:`points_from_snapshots`.
    The public records -> point cloud function (CLI, live view). ``reference``: run the
    replaced implementation (:func:`process_records_reference`; benchmark, tests);
    ``compiled`` False: the angle work of :func:`points_from_snapshots` in numpy (benchmark)."""
    params = params or DetectionParams()
    _check_records(arr, cfg)
    if reference:
        return process_records_reference(arr, cfg, params, frame)
    idx = select_records(arr, cfg, params)
    cells = np.stack([arr.range_bin[idx], arr.doppler_bin[idx]], axis=1)
    offsets = record_offsets(arr.power[idx], _neighbours(arr)[idx], cells[:, 0], cfg.n_range)
    return points_from_snapshots(cells, arr.snapshot[idx], arr.power[idx], arr.noise[idx],
                                 offsets, cfg, params, frame, compiled)


def process_records_reference(arr: RecordArrays, cfg: RadarConfig,
                              params: DetectionParams | None = None, frame: int = 0
                              ) -> PointCloud:
    """The implementation :func:`process_records` replaced (``host.pipeline.
    points_from_cells``: every TDM alias class's angle peaks, every cell's second-component
    search); same points (tests). The map-based selection and 1024-point FFTs before it are
    ``select_records_reference`` and ``host.pipeline.points_from_cells_reference``."""
    params = params or DetectionParams()
    _check_records(arr, cfg)
    idx = select_records(arr, cfg, params)
    cells = np.stack([arr.range_bin[idx], arr.doppler_bin[idx]], axis=1)
    offsets = record_offsets(arr.power[idx], _neighbours(arr)[idx], cells[:, 0], cfg.n_range)
    return points_from_cells(cells, arr.snapshot[idx], arr.power[idx], arr.noise[idx],
                             offsets, cfg, params, frame)
