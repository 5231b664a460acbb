"""Host processing of one frame: radar cube -> detections -> angles -> point cloud.

Steps (docs/design.md section 1, host side):

1. Detection on the range-Doppler map: 2-D CA-CFAR (default) or OS-CFAR on the map
   integrated non-coherently over all virtual channels, or the paper's threshold on channel
   0; optionally only cells ``min_snr_db`` above the noise estimate; peak grouping keeps
   local maxima (of the 3 x 3 neighbourhood, or along Doppler only:
   ``DetectionParams.grouping``); only ``RadarConfig.detection_bins`` are reported (the top
   range bins are negative beat frequencies), and cells within ``sidelobe_margin_db`` of a
   stronger cell's window sidelobes are dropped. After static-clutter removal
   (``DetectionParams.static_removed``) the CFAR leaves out the emptied zero-Doppler bin and
   rescales the bins the removal lowered (:func:`map_cfar`).
2. Range and Doppler refined by interpolation around each peak over the three integrated
   powers along each axis, matched to the axis' window and padding (``host.cells``); with
   ``DetectionParams.refine``, then by maximising the whole frame's periodogram
   (``host.refine``).
3. TDM Doppler phase compensation per TX slot, with velocity unfolding. The measured
   Doppler fixes the velocity only modulo the alias period 2 vmax: the hypotheses are
   v + 2 m vmax for every integer m with |v + 2 m vmax| <= ``max_speed_mps`` (the fastest
   radial speed the application expects, default 100 m/s). With num_tx > 1 the TDM phase
   test separates hypotheses whose m differ modulo num_tx (compensation for the wrong one
   blurs the angle spectrum); hypotheses m and m + num_tx are indistinguishable. A point is
   ``ambiguous`` when more than one hypothesis survives (always with one TX once
   ``max_speed_mps`` > vmax: paper-fpga can never unfold) or when the reported velocity is
   an unfolded one (it rests on the TDM test). The velocity reported is the surviving
   hypothesis of smallest magnitude.
4. Angle: the interpolated peak of the zero-padded angle spectrum, RELAX-style so several
   targets in a cell give several points (``host.angle``). The CFAR already decided that
   the cell holds a target, so its strongest component always gives a point (no second,
   hidden SNR gate: the point cloud's false-alarm rate is the CFAR's Pfa); further
   components must pass
   ``AngleParams.min_snr_db``.
5. Point cloud: range corrected for range-Doppler coupling, x/y, vx/vy, power, coherent
   SNR and an RCS estimate from the radar equation (``host.pointcloud``).

Steps 1 and 2 make the detected cells (``host.cells.Cells``) of a cube here; the FPGA's
detector makes them from its records in ``host.record_points``; steps 3 to 5 are one
function for both, ``host.points.points_from_cells``. Settings: ``host.params``.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import lru_cache

import numpy as np

from host.cells import Cells, peak_offsets
from host.cfar import (
    CfarParams,
    Windows,
    cfar_cells,
    cfar_detect,
    cfar_threshold,
    local_peaks,
    paper_threshold,
    sidelobe_masked,
)
from host.cube import frame_cube, static_noise_gain
from host.kernels import njit, warm_up
from host.params import DetectionParams, params_for
from host.pointcloud import PointCloud
from host.points import points_from_cells
from host.refine import refine_offsets
from model.config import RadarConfig
from model.reference import fft_axes, range_doppler_power

GROUPING_SIZE = {"peak": (3, 3), "doppler": (1, 3)}
"""The (range, Doppler) neighbourhood a detected cell must be the maximum of
(``host.cfar.local_peaks``), by ``DetectionParams.grouping``."""


def _min_snr(cells: np.ndarray, power: np.ndarray, noise: np.ndarray,
             params: DetectionParams) -> np.ndarray:
    """bool (n,): which of the cells (int (n, 2)) have their ``power`` (float (n_range,
    n_doppler) map) ``params.min_snr_db`` above ``noise`` (float (n,), at the cells); all
    when it is None."""
    if params.min_snr_db is None:
        return np.ones(len(cells), bool)
    return power[cells[:, 0], cells[:, 1]] > noise * 10.0 ** (params.min_snr_db / 10.0)


@lru_cache(maxsize=16)
def _static_columns(cfg: RadarConfig, windowed: Windows
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The Doppler bins the CFAR sees after static removal: (gain float (n_doppler,), the
    noise gain of every bin, ``host.cube.static_noise_gain``; keep int (m,), the bins whose
    gain is not 0: all but the emptied zero-Doppler bin; reduced int (n_doppler,), each
    bin's column in the map of the kept bins, -1 for the others). Read-only, once per
    radar and windows."""
    gain = static_noise_gain(cfg, windowed[1].hann)
    keep = np.flatnonzero(gain > 0.0)
    reduced = np.full(len(gain), -1)
    reduced[keep] = np.arange(len(keep))
    for a in (keep, reduced):
        a.flags.writeable = False
    return gain, keep, reduced


def _gain_divided(nci: np.ndarray, keep: np.ndarray, gain: np.ndarray, cf: CfarParams
                  ) -> np.ndarray:
    """The map the CFAR sees after static removal (:func:`map_cfar`): the ``keep`` columns
    of ``nci`` divided by their noise ``gain`` (:func:`_static_columns`), float64; in C
    order for the CA-CFAR, whose training sums read rows and whose threshold is in C order
    (15 us less a frame), in the map's own for the OS-CFAR (its padding gathers either)."""
    return np.divide(nci[:, keep], gain[keep], order="C" if cf.kind == "ca" else "K")


def map_cfar(nci: np.ndarray, cfg: RadarConfig, cf: CfarParams, windowed: Windows,
             static_removed: bool, thresholds: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """``host.cfar.cfar_detect`` of the map ``nci`` (float (n_range_bins, n_doppler)):
    (mask bool, noise float), both of its shape; ``thresholds``: ``host.cfar.
    cfar_threshold``'s (threshold float, noise float) of every cell instead. ``static_removed``:
    the cube's static clutter was removed, so the CFAR runs on the map without its empty
    zero-Doppler bin and with the bins the removal lowered divided by their noise gain
    (``host.cube.static_noise_gain``: plain noise again), threshold and noise estimate scaled
    back; bin 0 is never detected (threshold inf, noise NaN)."""
    run = cfar_threshold if thresholds else cfar_detect
    if not static_removed:
        return run(nci, cfg.n_virtual, cf, windowed)
    gain, keep, _ = _static_columns(cfg, windowed)
    first, noise = run(_gain_divided(nci, keep, gain, cf), cfg.n_virtual, cf, windowed)
    out = np.full(nci.shape, np.inf) if thresholds else np.zeros(nci.shape, bool)
    out[:, keep] = first * gain[keep] if thresholds else first
    noise_map = np.full(nci.shape, np.nan)
    noise_map[:, keep] = noise * gain[keep]
    return out, noise_map


def _static_cfar_cells(nci: np.ndarray, cfg: RadarConfig, cf: CfarParams, windowed: Windows,
                       select: Callable[[np.ndarray, np.ndarray], np.ndarray]
                       ) -> tuple[np.ndarray, np.ndarray]:
    """``host.cfar.cfar_cells`` on the map of :func:`map_cfar` after static removal (the
    emptied zero-Doppler bin left out, the lowered bins divided by their noise gain): the
    cells ``select(mask, nci)`` keeps (int (n, 2), full-map bins) and the noise at them (float
    (n,), scaled back); the same cells and noise as ``map_cfar(..., True)``'s maps give."""
    gain, keep, reduced = _static_columns(cfg, windowed)

    def select_reduced(mask: np.ndarray) -> np.ndarray:
        full = np.zeros(nci.shape, bool)
        full[:, keep] = mask
        cells = select(full, nci)
        return np.column_stack([cells[:, 0], reduced[cells[:, 1]]])

    cells, noise = cfar_cells(_gain_divided(nci, keep, gain, cf), cfg.n_virtual, cf,
                              windowed, select_reduced)
    cells = np.column_stack([cells[:, 0], keep[cells[:, 1]]])
    return cells, noise * gain[cells[:, 1]]


def detect_cells(cube: np.ndarray, cfg: RadarConfig, params: DetectionParams
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Detected range-Doppler cells of a cube.

    cube: complex (n_virtual, n_range_bins, n_doppler). Returns (cells int (n, 2) of
    (range_bin, doppler_bin natural order), noise float (n,) mean noise power per cell of the
    non-coherent map, nci float (n_range_bins, n_doppler) the non-coherent map). The
    detector's mask, then the grouping's peaks in the reported range bins, clear of
    stronger cells' sidelobes, ``min_snr_db`` above their noise: each a test of the cell
    alone, so the noise is needed at the last cells only (the OS-CFAR's is found there,
    ``host.cfar.cfar_cells``).
    """
    nci = range_doppler_power(cube)
    windowed = fft_axes(cfg, params.range_window, params.doppler_window)
    mirrored = windowed[0].real
    size = GROUPING_SIZE[params.grouping]
    lo, hi = cfg.detection_bins             # host.cfar.detection_mask's rows

    def select(mask: np.ndarray, peak_map: np.ndarray) -> np.ndarray:
        cells = local_peaks(peak_map, mask, size, mirrored)
        cells = cells[(cells[:, 0] >= lo) & (cells[:, 0] < hi)]
        if params.sidelobe_margin_db is not None and len(cells):
            cells = cells[~sidelobe_masked(nci, cells, windowed, params.sidelobe_margin_db)]
        return cells

    if params.detector == "paper":
        mask, p0 = paper_threshold(cube, params.paper_threshold_db)
        cells = select(mask, p0)
        noise = np.full(len(cells), np.median(nci))
    else:
        c = params.cfar
        cf = CfarParams(pfa=c.pfa, guard=c.guard, train=c.train, kind=params.detector,
                        os_rank=c.os_rank) if c.kind != params.detector else c
        if params.static_removed:
            cells, noise = _static_cfar_cells(nci, cfg, cf, windowed, select)
        else:
            cells, noise = cfar_cells(nci, cfg.n_virtual, cf, windowed,
                                      lambda mask: select(mask, nci))
    keep = _min_snr(cells, nci, noise, params)
    return cells[keep], noise[keep], nci


def process_cube(cube: np.ndarray, cfg: RadarConfig, params: DetectionParams | None = None,
                 frame: int = 0) -> PointCloud:
    """Point cloud of one radar cube, complex (n_virtual, n_range_bins, n_doppler), in
    float-reference units (``model.reference.radar_cube``)."""
    return process_cube_nci(cube, cfg, params, frame)[0]


def process_cube_nci(cube: np.ndarray, cfg: RadarConfig, params: DetectionParams | None = None,
                     frame: int = 0) -> tuple[PointCloud, np.ndarray]:
    """:func:`process_cube` that also returns the integrated power map it computed, float
    (n_range_bins, n_doppler), in the cube's units squared (a display needs it; computing it
    again costs a cube pass)."""
    params = params or params_for(cfg)
    cfg.check_cube(cube)
    dtype = np.asarray(cube).dtype
    if dtype.kind != "c":
        raise ValueError(f"cube: must be complex (Doppler FFT values), got dtype {dtype}")
    cells, noise, nci = detect_cells(cube, cfg, params)
    if not np.isfinite(nci).all():         # NaN / inf anywhere in the cube reach the map
        raise ValueError("cube: contains NaN or infinite values")
    offsets = peak_offsets(nci, cells, fft_axes(cfg, params.range_window,
                                                params.doppler_window))
    r, d = cells[:, 0], cells[:, 1]
    if params.refine:
        offsets = refine_offsets(cube, r, d, offsets, cfg,
                                 (params.range_window, params.doppler_window),
                                 params.refine_floor)
    found = Cells(r, d, nci[r, d], noise, offsets, cube[:, r, d].T)
    return points_from_cells(found, cfg, params, frame), nci


REAL_ONLY_ASYMMETRY = 0.2
"""Largest :func:`hermitian_asymmetry` of a cube called real-only: complex data gives about
2 (the mirrored cell is independent), real-only data 0 in float and about 0.04 after the
fixed-point chain's rounding."""


def hermitian_asymmetry(cube: np.ndarray) -> float:
    """Energy of ``Y - conj(Y[-r, -d])`` over that of ``Y`` for channel 0 of ``cube``,
    complex (n_virtual, n_range, n_doppler): 0 when the ADC samples were real (their
    spectrum is Hermitian: every target has a mirror at range bin N - k, Doppler -d); nan
    for an all-zero channel."""
    diff, energy = _asymmetry_sums(np.asarray(cube[0]))
    return diff / energy if energy > 0 else float("nan")


@njit()
def _asymmetry_sums(y: np.ndarray) -> tuple[float, float]:
    """(sum |Y[r, d] - conj(Y[-r, -d])|^2, sum |Y|^2) over y, complex (n_range, n_doppler),
    indices modulo the axes, summed in double precision: one pass, no temporaries (numpy's
    flip, roll and differences took twice as long); -r mod n as n - r for r > 0 (an
    integer division per value took a fifth of the pass)."""
    nr, nd = y.shape
    diff = 0.0
    energy = 0.0
    for d in range(nd):                 # range innermost: a cube's contiguous axis
        dm = nd - d if d else 0
        for r in range(nr):
            a = y[r, d]
            b = y[nr - r if r else 0, dm]
            dr = np.float64(a.real) - np.float64(b.real)
            di = np.float64(a.imag) + np.float64(b.imag)
            diff += dr * dr + di * di
            energy += np.float64(a.real) ** 2 + np.float64(a.imag) ** 2
    return diff, energy


@warm_up
def _warm_up() -> None:
    """The real-only check's sums (reached only by cubes) on a tiny channel: complex64
    (``radar process``) and complex128 (the float sources), a cube's strided view and a
    contiguous one."""
    for dtype in (np.complex64, np.complex128):
        y = np.zeros((2, 4), dtype)
        _asymmetry_sums(y)
        _asymmetry_sums(y[:, ::2])


def real_only(cube: np.ndarray) -> bool:
    """Whether ``cube`` (complex (n_virtual, n_range, n_doppler)) looks like real-only
    samples in a complex profile (:data:`REAL_ONLY_ASYMMETRY`)."""
    return bool(hermitian_asymmetry(cube) < REAL_ONLY_ASYMMETRY)


def process_frame(adc: np.ndarray, cfg: RadarConfig, params: DetectionParams | None = None,
                  frame: int = 0) -> PointCloud:
    """ADC frame, complex or real (n_chirps, num_rx, n_samples) -> point cloud, through the float
    reference of the FPGA chain (``model.reference.radar_cube``, computed by its fast
    equivalent ``host.cube.frame_cube``) and :func:`process_cube`."""
    params = params or params_for(cfg)
    cube = frame_cube(adc, cfg, params.range_window, params.doppler_window)
    return process_cube(cube, cfg, params, frame)
