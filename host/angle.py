"""Angle of arrival over the virtual array: the strongest peak of the angle spectrum,
interpolated, and RELAX-style sequential estimation so that several targets in one
range-Doppler cell each give a point and the sidelobes of a strong target do not.

The contiguous lambda/2 ULA (``RadarConfig.uniform_linear_array``, the presets): virtual
channel v at y = v lambda/2 sees exp(-j pi v sin(az)) (``model.array``), so the steering
vector is exp(-j pi v s) and the angle spectrum is the zero-padded inverse DFT over channels
(``model.reference.angle_spectrum``), searched by compiled kernels. Any other array (gaps,
another channel order, elements at several heights) is given by its virtual positions
(``positions``, ``RadarConfig.virtual_positions_hw``): the Bartlett spectrum |s^H x|^2 over
its steering vectors ``model.array.steering`` on a grid of directions, refined locally
(``host._angle_array``), with the same RELAX and gates; where the array has vertical extent
the components carry an elevation too. The entry points:

- :func:`peak_powers`: the strongest peak (power, sin(az)) of each row's spectrum, the rows
  optionally TDM-compensated per TX (the velocity-unfolding test of ``host.tdm`` compares
  these peaks between alias classes).
- :func:`estimate_angles`: the components (targets) of each row: the first at the
  spectrum's peak, always kept (the detector decided the cell holds a target); a second one
  is searched only where a Cauchy-Schwarz bound on the residual leaves room for one that
  passes the gates of :class:`AngleParams` or the residual has a second target's shape;
  the rows that hold one go through RELAX (every component re-estimated with the others
  removed), those whose first component sits between two unresolved targets are split
  (below).
- :func:`range_azimuth_power`: a range-azimuth map for figures.

Model order (how many components a row holds). A further component k + 1 is kept only when
its coherent SNR reaches ``min_snr_db``, it is within ``dynamic_range_db`` of the first, and
the energy it removes from the residual is more than the residual the components already
held explain without it. An n-channel row holding targets of per-channel amplitudes a_j on
an array whose channels deviate from the model by complex relative errors e_v (gain and
phase; E|e_v|^2 = eps^2 = 10^(``array_error_db`` / 10)) is

    x_v = sum_j a_j s_j,v (1 + e_v) + noise_v,

and after removing the components its residual holds the noise, n N on average (N per
channel), and the part of each component the model cannot represent, n |a_j|^2 eps^2 on
average (less the part the fit absorbs): E ||r||^2 <= n N + n eps^2 sum_j |a_j|^2. A
further component at steering vector s (|s_v| = 1) removes n |a|^2 = |s^H r|^2 / n <=
||r||^2 (Cauchy-Schwarz) from it, so when the held components explain the row, a further
one removes at most the residual they leave: the test keeps it only where

    n |a_{k+1}|^2 >= n N + n eps^2 sum_{j <= k} |a_j|^2,

i.e. the new component alone carries more than the whole residual expected of the others:
model error and noise reach that only where the residual exceeds its expected energy, and
even then only in part (a single target's error residue spreads over n - 1 dimensions, its
best single direction takes a fraction of it). The floor is the array's error power per
channel: 2 dB rms gain with 10 deg rms phase is -11 dB, an uncalibrated TI board's +-2 dB
and up to 12 deg about -15 dB (the residue of the OpenRadar frame's strong cells). With the
default, -10 dB, an uncalibrated array gives one component per single target in over 99 %
of cells (``tests/test_angle_model_order.py``), and a second target must be within about
10 dB of the first; a calibrated array can lower ``array_error_db`` (e.g. -25 dB) to
resolve weaker neighbours, and -inf disables the test.

Two targets within a beamwidth. Two targets closer than the beamwidth (2 / n in sin(az))
make one lobe: the first component sits between them and takes most of their energy, and
when they are nearly in phase its residual is a small two-lobe (difference) pattern that
fails the model-order test above, which measures energy only. Its shape tells the two apart:
two targets at s1 -+ d leave, to second order in d, a residual in the span of the first
component's derivatives d/ds and d^2/ds^2 of its steering vector, i.e. of q_k(v) exp(-j pi v
s1) with q_1, q_2 the discrete Legendre polynomials of degree 1 and 2 over the channels,
while a model error's residue spreads over n - 1 dimensions (2 / (n - 1) of it in that span
on average). So a row whose residual holds at least ``SPLIT_STRUCTURE`` (half) of its energy
in that span, that part reaching the SNR gate, and whose residual peak passes the SNR and
dynamic-range gates but not the model-order test, is split: the first component and the
residual's peak are refined together by ``SPLIT_ITERATIONS`` (8) RELAX passes (the first
moves to one target, the second to the other), and the pair is kept when the weaker passes
all three gates against the stronger (n |a_2|^2 >= n N + n eps^2 |a_1|^2 with the refined
amplitudes), the two are more than 0.5 / n apart, and together they leave at most a quarter
of the first component's residual energy beyond the noise (``SPLIT_EXPLAINED``). Such a row
gives exactly two components (``host._angle_relax.split_rows``). At 20 dB per channel on the
64-channel array, two equal targets 0.7 beamwidths apart are resolved in 96 % of the trials
instead of 67 % (``docs/curves.md``), and an uncalibrated array still gives one component
per single target (``tests/test_angle_model_order.py``). The general-array path
(``positions``) does not split.

The work runs in compiled kernels (``host._angle_peaks``, ``host._angle_relax``; numba,
or the same code uncompiled where numba is missing: ``host.kernels``). The definition they
are tested against (per-row Python RELAX over ``AngleParams.n_fft``-point FFTs) is the
oracle in ``tests/oracles/angle.py``; the peaks agree with the ``n_fft``-point FFT's unless
two lobes are within the coarse grid's scalloping of each other (``host._angle_peaks``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from host._angle_array import (
    ArrayGrid,
    array_grid,
    bartlett_peaks,
    level_gates,
    model_order,
    relax_general,
)
from host._angle_kept import kept_slots
from host._angle_peaks import COARSE_FFT, class_peaks, peak_sins
from host._angle_relax import (
    first_components,
    relax_rows,
    split_rows,
    steering_rows,
)
from model.array import steering
from model.config import RadarConfig
from model.reference import angle_spectrum, tdm_phase_compensation


@dataclass(frozen=True)
class AngleParams:
    """Angle estimator settings.

    ``n_fft``: zero-padded angle FFT length (the grid of the peak search). ``max_targets``:
    components per cell. ``min_snr_db``: the coherent SNR (angle-domain peak over noise) a
    second or further component must reach; the first component of a detected cell is
    always kept (the detector decided the cell, so a second gate here would lower the
    false-alarm rate below the configured Pfa and hide weak targets the CFAR found).
    ``dynamic_range_db``: further components at most this far below the strongest (model
    errors of a strong target leave residue below that). ``array_error_db``: the array's
    per-channel model error (gain and phase, E|e_v|^2) relative to a component's power, the
    floor of the model-order test (module docstring). ``refine_iterations``: RELAX passes
    re-estimating each component with the others removed.
    """

    n_fft: int = 1024
    max_targets: int = 3
    min_snr_db: float = 12.0
    dynamic_range_db: float = 20.0
    array_error_db: float = -10.0
    refine_iterations: int = 2

    def __post_init__(self) -> None:
        if self.n_fft < 16 or self.n_fft & (self.n_fft - 1):
            raise ValueError(f"n_fft: must be a power of two >= 16, got {self.n_fft}")
        if self.max_targets < 1:
            raise ValueError(f"max_targets: must be >= 1, got {self.max_targets}")
        if math.isnan(self.array_error_db) or self.array_error_db >= 0.0:
            raise ValueError(f"array_error_db: must be a number of dB below 0 (the array's "
                             f"model error relative to a target; -inf: no model-order test), "
                             f"got {self.array_error_db}")


@dataclass(frozen=True)
class AngleArrays:
    """Angle components of many rows as flat arrays (one entry per component, rows in
    order, strongest first within a row): ``cell`` int (p,) row of the input; ``sin_az``,
    ``snr_db`` float (p,) (coherent SNR |a|^2 n / noise per channel, dB); ``amplitude``
    complex (p,) per-channel amplitude in the input's units; ``sin_el`` float (p,) sin of
    the elevation (None: 0, an array without vertical extent)."""

    cell: np.ndarray
    sin_az: np.ndarray
    amplitude: np.ndarray
    snr_db: np.ndarray
    sin_el: np.ndarray | None = None

    @property
    def azimuth_deg(self) -> np.ndarray:
        return np.degrees(np.arcsin(np.clip(self.sin_az, -1.0, 1.0)))

    @property
    def elevation_deg(self) -> np.ndarray:
        if self.sin_el is None:
            return np.zeros(len(self.cell))
        return np.degrees(np.arcsin(np.clip(self.sin_el, -1.0, 1.0)))


MAX_CHANNELS = COARSE_FFT
"""The most virtual channels the estimator takes (the coarse FFT's length)."""


def _vectors(x: np.ndarray) -> np.ndarray:
    """x as complex128 (n, n_ch); ValueError when it is not a 2-D array of at most
    :data:`MAX_CHANNELS` channels."""
    xs = np.ascontiguousarray(x, dtype=np.complex128)
    if xs.ndim != 2:
        raise ValueError(f"angles: channel vectors must be (n, n_channels), got {xs.shape}")
    if xs.shape[1] > MAX_CHANNELS:
        raise ValueError(f"angles: {xs.shape[1]} channels, at most {MAX_CHANNELS}")
    return xs


def _rows_and_phasors(x: np.ndarray, tx_phasors: np.ndarray | None
                      ) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_vectors` of x, and the per-TX phasors complex (n, num_tx) (ones (n, 1) when
    None); ValueError naming a shape that does not fit."""
    xs = _vectors(x)
    ph = np.ones((len(xs), 1)) if tx_phasors is None else np.asarray(tx_phasors)
    _check_phasors(ph, xs)
    return xs, ph


def _check_phasors(ph: np.ndarray, x: np.ndarray) -> None:
    """ValueError unless ph (complex (m, num_tx)) holds TX phasors of the rows x (complex
    (m, n), n a multiple of num_tx)."""
    if ph.ndim != 2 or len(ph) != len(x) or ph.shape[1] < 1 or x.shape[1] % ph.shape[1]:
        raise ValueError(f"angles: TX phasors {ph.shape} do not fit channel vectors "
                         f"{x.shape}")


def peak_powers(x: np.ndarray, n_fft: int, tx_phasors: np.ndarray | None = None,
                rows: np.ndarray | None = None, positions: np.ndarray | None = None
                ) -> tuple[np.ndarray, np.ndarray]:
    """The strongest peak of the angle spectrum of each vector: (|X(k)|^2 at the
    ``n_fft``-grid maximum, float (m,); its interpolated sin(az), float (m,)).

    x: complex (n, n_channels), channel v = tx * num_rx + rx; rows: int (m,) which row of x
    each vector is (default: every row once); tx_phasors: complex (m, num_tx), TX t's
    channels multiplied by tx_phasors[:, t] first (TDM compensation, ``host.tdm``);
    positions: float (n_channels, 2) the virtual array (``RadarConfig.
    virtual_positions_hw``) when it is not the contiguous lambda/2 ULA: then the peak of
    the Bartlett spectrum |s^H x|^2 over its steering vectors (``host._angle_array``) and
    its direction cosine u (sin(az) cos(el)) instead."""
    xs = _vectors(x)
    rows = np.arange(len(xs)) if rows is None else np.asarray(rows)
    ph = np.ones((len(rows), 1)) if tx_phasors is None else np.asarray(tx_phasors)
    if positions is None:
        return class_peaks(xs, rows, ph, n_fft)
    _check_phasors(ph, xs[rows])
    u, _, power = bartlett_peaks(_compensated(xs[rows], ph), _grid_of(positions, xs))
    return power, u


def _compensated(x: np.ndarray, ph: np.ndarray) -> np.ndarray:
    """Rows x (complex (m, n)) with TX t's channels times ph[:, t] (ph complex (m, num_tx),
    :func:`_check_phasors`)."""
    return x * np.repeat(ph, x.shape[1] // ph.shape[1], axis=1)


def _grid_of(positions: np.ndarray, x: np.ndarray) -> ArrayGrid:
    """``host._angle_array.array_grid`` of positions (float (n, 2)); ValueError unless
    they are one per channel of x (complex (m, n))."""
    p = np.asarray(positions, dtype=float)
    if p.shape != (x.shape[1], 2):
        raise ValueError(f"angles: array positions {p.shape} for {x.shape[1]} channels")
    return array_grid(p)


def estimate_angles(x: np.ndarray, noise_per_channel: np.ndarray, params: AngleParams,
                    tx_phasors: np.ndarray | None = None, first_sin: np.ndarray | None = None,
                    positions: np.ndarray | None = None) -> AngleArrays:
    """The angle components of every row (module docstring).

    x: complex (n, n_channels) channel vectors (cube units); noise_per_channel: float (n,)
    noise power per channel in the units of |x|^2 (0 counts as 1e-30); tx_phasors:
    complex (n, num_tx), TX t's channels of row i multiplied by tx_phasors[i, t] first
    (TDM compensation; None: the rows as they are); first_sin: float (n,) the
    (compensated) rows' :func:`peak_powers` sin(az) when the caller has it already (the
    ULA only); positions: float (n_channels, 2) the virtual array when it is not the
    contiguous lambda/2 ULA (``RadarConfig.virtual_positions_hw``): RELAX over its
    steering vectors (``host._angle_array``), elevation too where it has vertical extent."""
    xs, ph = _rows_and_phasors(x, tx_phasors)
    n_rows, n = xs.shape
    noise = np.maximum(np.asarray(noise_per_channel, dtype=float), 1e-30)
    if noise.shape != (n_rows,):
        raise ValueError(f"angles: noise {noise.shape} for {n_rows} rows")
    if positions is not None and first_sin is not None:
        raise ValueError("angles: first_sin is the ULA's peak; not with array positions")
    if not n_rows:
        z = np.zeros(0)
        return AngleArrays(np.zeros(0, np.int64), z, z.astype(complex), z,
                           None if positions is None else z)
    if positions is not None:
        return _general(xs, ph, noise, params, positions)
    s1 = class_peaks(xs, np.arange(n_rows), ph, params.n_fft)[1] if first_sin is None \
        else np.asarray(first_sin, dtype=float)
    xc, a1, p1, maybe, splittable = first_components(
        xs, ph, s1, noise, params.min_snr_db, params.dynamic_range_db, params.array_error_db,
        params.max_targets > 1)
    more = np.zeros(n_rows, bool)
    split = np.zeros(n_rows, bool)
    rows = np.flatnonzero(maybe)
    if len(rows):                       # the residual's strongest peak passes the gates?
        r = xc[rows] - a1[rows, None] * steering_rows(s1[rows], n)
        s2, _ = peak_sins(r, params.n_fft)
        a2 = np.sum(np.conj(steering_rows(s2, n)) * r, axis=1) / n
        p2 = np.abs(a2) ** 2
        p1r, nr_ = p1[rows], noise[rows]
        gates = level_gates(p2, p1r, nr_, n, params)      # shared by both tests below
        more[rows] = gates & model_order(p2, p1r, nr_, params)
        cand = splittable[rows] & ~more[rows] & gates & model_order(p2, 0.0 * p1r, nr_,
                                                                    params)
        if cand.any():                  # two unresolved targets the first one sits between?
            c = rows[cand]
            s_p, a_p, kept = split_rows(xc[c], noise[c], np.stack([s1[c], s2[cand]], axis=1),
                                        np.stack([a1[c], a2[cand]], axis=1), params.n_fft,
                                        params.min_snr_db, params.dynamic_range_db,
                                        params.array_error_db)
            split[c[kept]] = True
            pair = _kept_components(s_p[kept], a_p[kept], np.full(int(kept.sum()), 2),
                                    noise[c[kept]], n)
    snr1 = 10 * np.log10(np.maximum(p1, 1e-300) * n / noise)
    single = ~more & ~split
    parts = [AngleArrays(np.flatnonzero(single), s1[single], a1[single], snr1[single])]
    multi = np.flatnonzero(more)
    if len(multi):
        got = _relax(xc[multi], noise[multi], params)
        parts.append(AngleArrays(multi[got.cell], got.sin_az, got.amplitude, got.snr_db))
    if split.any():
        parts.append(AngleArrays(np.flatnonzero(split)[pair.cell], pair.sin_az,
                                 pair.amplitude, pair.snr_db))
    if len(parts) == 1:
        return parts[0]
    cell = np.concatenate([p.cell for p in parts])
    order = np.argsort(cell, kind="stable")
    return AngleArrays(cell[order], *(np.concatenate([getattr(p, f) for p in parts])[order]
                                      for f in ("sin_az", "amplitude", "snr_db")))


def _general(xs: np.ndarray, ph: np.ndarray, noise: np.ndarray, params: AngleParams,
             positions: np.ndarray) -> AngleArrays:
    """:func:`estimate_angles` over the steering vectors of an array at ``positions`` (float
    (n, 2)): ``host._angle_array.relax_general`` of the compensated rows xs (complex (m, n))
    and :func:`_kept_components`, sin(az) = u / cos(el)."""
    grid = _grid_of(positions, xs)
    u, w, a, count = relax_general(_compensated(xs, ph), noise, grid, params)
    got = _kept_components(u, a, count, noise, xs.shape[1], w, grid.span)
    sin_el = got.sin_el if not grid.planar else np.zeros(len(got.cell))
    sin_az = got.sin_az / np.sqrt(np.maximum(1.0 - sin_el ** 2, 1e-30))
    return AngleArrays(got.cell, np.clip(sin_az, -1.0, 1.0), got.amplitude, got.snr_db,
                       sin_el)


def _relax(xs: np.ndarray, noise: np.ndarray, params: AngleParams) -> AngleArrays:
    """RELAX (``host._angle_relax.relax_rows``) of rows xs, complex (m, n), noise float (m,)
    per channel, as :func:`_kept_components`."""
    s_c, a_c, count = relax_rows(xs, noise, params.n_fft, params.max_targets,
                                 params.refine_iterations, params.min_snr_db,
                                 params.dynamic_range_db, params.array_error_db)
    return _kept_components(s_c, a_c, count, noise, xs.shape[1])


def _kept_components(s_c: np.ndarray, a_c: np.ndarray, count: np.ndarray, noise: np.ndarray,
                     n: int, w_c: np.ndarray | None = None,
                     span: tuple[float, float] | None = None) -> AngleArrays:
    """The components found per row (sin s_c float (m, k), amplitude a_c complex (m, k), the
    first count int (m,) slots of each row valid; noise float (m,) per channel, n channels)
    strongest first (a stable sort), without those that collapsed onto a stronger one during
    refinement (within 0.5 / n in sin(az); ``host._angle_kept.kept_slots``), as flat
    :class:`AngleArrays`. A general array:
    s_c holds the direction cosines u, w_c float (m, k) the w, span (H + 1, V + 1) its
    apertures (``host._angle_array.ArrayGrid``): collapsed within 0.5 / (H + 1) in u and
    0.5 / (V + 1) in w, the w kept as ``sin_el``."""
    mag = np.abs(a_c)
    with np.errstate(divide="ignore"):
        snr_c = 10 * np.log10(mag ** 2 * n / noise[:, None])   # 0 in unused slots
    tol_u, tol_w = (0.5 / n, np.inf) if span is None else (0.5 / span[0], 0.5 / span[1])
    rows, comp = kept_slots(mag, count, s_c, w_c, tol_u, tol_w)
    return AngleArrays(rows.astype(np.int64), s_c[rows, comp], a_c[rows, comp],
                       snr_c[rows, comp], None if w_c is None else w_c[rows, comp])


def range_azimuth_power(cube: np.ndarray, cfg: RadarConfig, n_fft: int = 256
                        ) -> tuple[np.ndarray, np.ndarray]:
    """Range-azimuth map: TDM-compensated, Hann-tapered angle FFT of every cell, power
    summed over Doppler (for figures; detection uses :func:`estimate_angles`).

    cube: complex (n_virtual, n_range, n_doppler). Returns (float (n_range, n_fft) power,
    float (n_fft,) azimuth of each column in deg, NaN outside the visible region). A
    virtual array other than the contiguous lambda/2 ULA: the Bartlett spectrum over its
    steering vectors at elevation 0 (untapered) on the same sin(az) grid.
    """
    comp = tdm_phase_compensation(cfg, np.arange(cfg.n_doppler))             # (n_d, n_v)
    x = np.moveaxis(cube, 0, -1) * comp[None, :, :]                           # (r, d, n_v)
    if cfg.uniform_linear_array:
        spec, az = angle_spectrum(x, n_fft=n_fft, window=True)                # (r, d, n_fft)
    else:                   # the azimuths of the same grid, from one (empty) vector
        _, az = angle_spectrum(np.zeros(cfg.n_virtual), n_fft=n_fft)
        s = 2.0 * (np.arange(n_fft) - n_fft // 2) / n_fft
        spec = x @ np.conj(steering(cfg.virtual_positions_hw, s)).T
    return np.sum(np.abs(spec) ** 2, axis=1), az
