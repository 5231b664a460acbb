"""Oracles of ``host.points`` / ``host.record_points`` / ``host.tdm``: the implementations
the library replaced, kept only to test it against (as scipy keeps its mpmath references in
its tests).

- :func:`points_from_cells_reference`: the definition of detected cells -> points: every
  cell's and TDM alias class's ``n_fft``-point angle FFT, the per-cell Python unfolding
  decision :func:`choose_fold`, per-row RELAX (``tests.oracles.angle``).
- :func:`points_from_cells_numpy`: the vectorised numpy path the cube took before the host
  core had one path (coarse FFT + fine-grid peaks of every alias class, unscreened second-
  component search).
- :func:`select_records_reference`: the record selection on the whole map.
- :func:`process_records_reference`, :func:`process_cube_reference`: records / a cube ->
  points through those.
"""

from __future__ import annotations

from dataclasses import fields

import numpy as np

from host.cells import peak_offsets
from host.cfar import detection_mask, local_peaks, sidelobe_masked
from host.params import DetectionParams
from host.pipeline import detect_cells
from host.pointcloud import PointCloud
from host.points import cell_snr_db, cloud
from host.record_points import _check_records, _neighbours, record_offsets
from host.records import RecordArrays
from host.tdm import choose_folds, tx_phasors
from model.config import RadarConfig
from model.reference import fft_axes, signed_bins, tdm_phase_compensation
from tests.oracles.angle import peak_power_batch
from tests.oracles.angle_peaks import peak_power_fast
from tests.oracles.angle_screened import estimate_angles_batch, estimate_angles_fast


def tdm_comp(cfg: RadarConfig, k: np.ndarray | int) -> np.ndarray:
    """TDM compensation phasors, complex (..., n_virtual), for the *unfolded* signed Doppler
    bins ``k`` (any integers, int or int (...)). ``tdm_phase_compensation`` takes
    natural-order bins and maps k >= n_doppler/2 back to k - n_doppler, which would undo an
    unfolding by +1; its phase has period num_tx * n_doppler in k, so k is shifted by that
    period instead."""
    k = np.asarray(k)
    k = np.where(k >= cfg.n_doppler // 2, k - cfg.num_tx * cfg.n_doppler, k)
    return tdm_phase_compensation(cfg, k)


def velocity_hypotheses(cfg: RadarConfig, velocity_mps: float, max_speed_mps: float
                        ) -> list[int]:
    """Alias orders m with |velocity + 2 m vmax| <= max_speed (m = 0 when none is)."""
    period = 2.0 * cfg.max_velocity_mps
    lo = int(np.ceil((-max_speed_mps - velocity_mps) / period))
    hi = int(np.floor((max_speed_mps - velocity_mps) / period))
    return list(range(lo, hi + 1)) or [0]


def choose_fold(power: dict[int, float], cfg: RadarConfig, velocity_mps: float,
                 snr_db: float, params: DetectionParams) -> tuple[int, bool]:
    """Alias order m of a cell's velocity and whether it is ambiguous (module docstring,
    step 3). ``power``: peak angle-spectrum power of the cell's channel vector compensated
    for each alias class c = m mod num_tx (:func:`class_powers`; empty when the TDM test does
    not run); ``velocity_mps``: measured (aliased)."""
    hyps = velocity_hypotheses(cfg, velocity_mps, params.max_speed_mps)
    if cfg.num_tx > 1 and params.unfold_velocity and len(hyps) > 1:
        classes = sorted({m % cfg.num_tx for m in hyps})
        best = max(classes, key=power.__getitem__)
        margin = 10 ** (params.unfold_margin_db / 10)
        others = [power[c] for c in classes if c != best]
        beats_all = not others or power[best] >= margin * max(others)
        if best != 0 and not (beats_all and snr_db >= params.unfold_min_snr_db):
            best = 0 if 0 in classes else best
            beats_all = not others or power[best] >= margin * max(
                power[c] for c in classes if c != best)
        if beats_all:
            hyps = [m for m in hyps if m % cfg.num_tx == best] or hyps
    m = min(hyps, key=lambda h: abs(velocity_mps + 2.0 * h * cfg.max_velocity_mps))
    return m, len(hyps) > 1 or m != 0


def class_powers(x: np.ndarray, cfg: RadarConfig, k: np.ndarray, n_fft: int) -> np.ndarray:
    """Peak angle-spectrum power of each cell compensated for alias class c, float
    (n, num_tx): x complex (n, n_virtual), k int (n,) signed Doppler bins (one batched FFT
    of all cells and classes)."""
    c = np.arange(cfg.num_tx)
    comp = tdm_comp(cfg, k[:, None] + c[None, :] * cfg.n_doppler)      # (n, num_tx, n_v)
    return peak_power_batch(x[:, None, :] * comp, n_fft)


def _cell_values(cells: np.ndarray, snapshots: np.ndarray, power: np.ndarray,
                 noise: np.ndarray, offsets: np.ndarray, cfg: RadarConfig
                 ) -> tuple[np.ndarray, ...]:
    """(range bins int (n,), snapshots, noise float (n,), signed Doppler bins int (n,), cell
    SNR dB float (n,), measured (aliased) velocity m/s float (n,)) of detected cells."""
    sb = signed_bins(cfg.n_doppler)[np.asarray(cells[:, 1])].astype(np.int64)
    noise = np.asarray(noise, dtype=float)
    return (np.asarray(cells[:, 0]), np.asarray(snapshots), noise, sb,
            cell_snr_db(power, noise, cfg.n_virtual),
            (sb + offsets[:, 1]) * cfg.velocity_bin_mps)


def points_from_cells_reference(cells: np.ndarray, snapshots: np.ndarray, power: np.ndarray,
                                noise: np.ndarray, offsets: np.ndarray, cfg: RadarConfig,
                                params: DetectionParams, frame: int = 0) -> PointCloud:
    """The implementation :func:`points_from_cells` replaced (1024-point angle FFTs of
    every cell and TDM hypothesis, per-cell Python unfolding decision); kept for the
    benchmark's old-vs-new timing and the tests. Point cloud of detected cells (steps 3 to
    5 of the module docstring), whether they come from a cube (:func:`process_cube`) or
    from the FPGA's records (``host.record_points``). Vectorised over the cells: the angle
    FFTs of all cells and TDM hypotheses run as batches.

    cells: int (n, 2) of (range_bin, doppler_bin natural order); snapshots: complex
    (n, n_virtual) the cells' Doppler-FFT values per virtual channel (cube units, LSB);
    power: float (n,) non-coherent power sum_v |x_v|^2; noise: float (n,) mean noise power
    per cell of the non-coherent map; offsets: float (n, 2) fractional (range, Doppler)
    offsets of the peak from the cell centre, bins.
    """
    n = len(cells)
    if not n:
        return PointCloud.empty()
    nd, nv = cfg.n_doppler, cfg.n_virtual
    r, x, noise, sb, snr_db, measured = _cell_values(cells, snapshots, power, noise, offsets,
                                                     cfg)
    # step 3: TDM hypothesis powers of every cell and class in one batch, then the decision
    class_power = (class_powers(x, cfg, sb, params.angle.n_fft)
                   if cfg.num_tx > 1 and params.unfold_velocity else np.zeros((n, 0)))
    fold = np.zeros(n, np.int64)
    ambiguous = np.zeros(n, bool)
    for i in range(n):
        powers = {c: float(p) for c, p in enumerate(class_power[i])}
        fold[i], ambiguous[i] = choose_fold(powers, cfg, float(measured[i]),
                                             float(snr_db[i]), params)
    k = sb + fold * nd
    # step 4: angles of the TDM-compensated channel vectors
    comps = estimate_angles_batch(x * tdm_comp(cfg, k), noise / nv, params.angle)
    # step 5: one point per angle component
    cell = np.array([i for i, cs in enumerate(comps) for _ in cs], dtype=np.int64)
    flat = [c for cs in comps for c in cs]
    return cloud(cfg, params, r, offsets, k, ambiguous, cell,
                  np.array([c.azimuth_deg for c in flat]),
                  np.array([c.amplitude for c in flat], dtype=complex),
                  np.array([c.snr_db for c in flat]), frame)


def tdm_compensate(cfg: RadarConfig, x: np.ndarray, k: np.ndarray) -> np.ndarray:
    """x complex (n, n_virtual) times :func:`_tdm_comp` of k (int (n,) or (n, h)) without
    forming the per-channel phasors: complex (n, n_virtual) or (n, h, n_virtual)."""
    ph = tx_phasors(cfg, k)                                   # (n, [h,] num_tx)
    n = len(x)
    xt = x.reshape(n, *([1] * (ph.ndim - 2)), cfg.num_tx, cfg.num_rx)
    return (xt * ph[..., None]).reshape(*ph.shape[:-1], cfg.n_virtual)


def points_from_cells_numpy(cells: np.ndarray, snapshots: np.ndarray, power: np.ndarray,
                            noise: np.ndarray, offsets: np.ndarray, cfg: RadarConfig,
                            params: DetectionParams, frame: int = 0) -> PointCloud:
    """The cube path's points before ``host.points.points_from_cells`` (steps 3 to 5 of
    ``host.pipeline``'s docstring). Vectorised over the cells: the TDM hypotheses' phasors,
    their angle peaks (coarse FFT + fine-grid search, ``tests.oracles.angle_peaks.fine_peaks``, the
    same peaks as ``AngleParams.n_fft``-point FFTs), the unfolding decision
    (:func:`choose_folds`) and the angles run on all cells at once. Arguments as
    :func:`points_from_cells_reference`."""
    n = len(cells)
    if not n:
        return PointCloud.empty()
    nd, nv = cfg.n_doppler, cfg.n_virtual
    r, x, noise, sb, snr_db, measured = _cell_values(cells, snapshots, power, noise, offsets,
                                                     cfg)
    # step 3: TDM hypothesis powers of every cell and class in one batch, then the decision
    if cfg.num_tx > 1 and params.unfold_velocity:
        c = np.arange(cfg.num_tx)
        xc = tdm_compensate(cfg, x, sb[:, None] + c[None, :] * nd)    # (n, num_tx, n_v)
        class_power, class_sin = peak_power_fast(xc, params.angle.n_fft)
    else:
        class_power = np.zeros((n, 0))
    fold, ambiguous = choose_folds(class_power, cfg, measured, snr_db, params)
    k = sb + fold * nd
    # step 4: angles of the TDM-compensated channel vectors (the phasors of k are those of
    # its class k mod num_tx n_doppler: the class's vector and peak serve)
    if class_power.shape[1]:
        rows, cls = np.arange(n), fold % cfg.num_tx
        ang = estimate_angles_fast(xc[rows, cls], noise / nv, params.angle,
                                   first_sin=class_sin[rows, cls])
    else:
        ang = estimate_angles_fast(tdm_compensate(cfg, x, k), noise / nv, params.angle)
    return cloud(cfg, params, r, offsets, k, ambiguous, ang.cell, ang.azimuth_deg,
                 ang.amplitude, ang.snr_db, frame)


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


def process_records_reference(arr: RecordArrays, cfg: RadarConfig,
                              params: DetectionParams | None = None, frame: int = 0
                              ) -> PointCloud:
    """Records -> points as before the host core had one path: the selection on the map
    (:func:`select_records_reference`), :func:`points_from_cells_numpy`."""
    params = params or DetectionParams()
    _check_records(arr, cfg)
    idx = select_records_reference(arr, cfg, params)[0]
    cells = np.stack([arr.range_bin[idx], arr.doppler_bin[idx]], axis=1)
    offsets = record_offsets(arr.power[idx], _neighbours(arr)[idx], cells[:, 0], cfg, params)
    return points_from_cells_numpy(cells, arr.snapshot[idx], arr.power[idx],
                                   arr.noise[idx], offsets, cfg, params, frame)


def process_cube_reference(cube: np.ndarray, cfg: RadarConfig,
                           params: DetectionParams | None = None, frame: int = 0
                           ) -> PointCloud:
    """The cube path as before the host core had one path: the host CFAR's cells
    (``host.pipeline.detect_cells``) through :func:`points_from_cells_numpy`."""
    params = params or DetectionParams()
    cells, noise, nci = detect_cells(cube, cfg, params)
    offsets = peak_offsets(nci, cells, fft_axes(cfg, params.range_window,
                                                params.doppler_window))
    r, d = cells[:, 0], cells[:, 1]
    return points_from_cells_numpy(cells, cube[:, r, d].T, nci[r, d], noise, offsets, cfg,
                                   params, frame)


def assert_same_cloud(a: PointCloud, b: PointCloud) -> None:
    """The tests' "same cloud": as many points, integer and flag fields equal, float fields
    within 1e-9 (relative and absolute; the library evaluates the same sums, partly in
    another order)."""
    assert len(a) == len(b)
    for f in fields(a):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if x.dtype.kind in "fc":
            np.testing.assert_allclose(x, y, rtol=1e-9, atol=1e-9, err_msg=f.name)
        else:
            np.testing.assert_array_equal(x, y, err_msg=f.name)
