"""Detection on range-Doppler maps: the paper's threshold, 2-D CA-CFAR and OS-CFAR, peak
grouping.

Maps are float (n_range, n_doppler) powers with the Doppler axis in natural FFT order. Both
axes are circular: the Doppler FFT's, and the range FFT's too because the IF is sampled
complex (bin N-k is the negative beat frequency -k fs/N, ``model.config``). CFAR windows and
peak grouping therefore wrap around at the range edges instead of being cut: a strong near
target's window sidelobes that wrap into the top bins meet a training window that holds the
target itself, exactly as its sidelobes on the other side do. Which bins may be *reported*
is a separate rule, ``RadarConfig.detection_bins`` (applied by :func:`detection_mask`).
A real ADC's range axis (bins 0..N/2-1, ``model.reference.FftAxis.real``) is not circular
but mirrored at both ends (bin -k is bin k's image): windows and peak grouping reflect there.
Zero-padded axes widen the main lobe and correlate the noise of more neighbouring bins:
the ``windowed`` arguments take the map's ``model.reference.FftAxis`` pair
(``fft_axes``) for that, or plain booleans (unpadded, complex).

Thresholds for a configured false-alarm probability are derived, not tuned (the statistics
live in ``model/cfar_stats.py``, shared with the FPGA CFAR model). A cell of a
map that integrates ``n_channels`` independent channels non-coherently is Gamma(L, theta)
distributed under noise (L = n_channels). For CA-CFAR, CUT / mean(training) is then
F(2L, 2NL)-distributed for N independent training cells, so the factor is the F quantile.
Windowed FFTs correlate neighbouring cells (periodic Hann: adjacent-bin power correlation
4/9, next 1/36), which makes the training mean noisier; the factor uses the effective
number of independent cells N_eff = N^2 / sum_ij rho_ij^2 (exact variance of the mean) so
the configured Pfa holds with windows on. OS-CFAR uses the k-th smallest training cell;
its factor solves Pfa = E[P(X > alpha * Y_(k))] numerically; it is computed by the compiled
backend ``host._cfar_os`` (:func:`cfar_detect` finds the k-th at the detected cells only).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy import stats

from host._cfar_os import os_detect, os_kth, os_kth_at, os_pad
from host._grouping import local_peak_cells, sidelobe_cells
from host.kernels import njit, warm_up
from model.cfar_stats import (  # noqa: F401 - re-exported: host code imports them from here
    HANN_POWER_CORRELATION,
    RECT_POWER_CORRELATION,
    ca_factor,
    effective_cells_mask,
    os_factor,
)
from model.reference import HANN_MAIN_LOBE_BINS, FftAxis

Windows = tuple[bool | FftAxis, bool | FftAxis]
"""The (range, Doppler) windows of a map: booleans (Hann or not, no padding, complex) or
the chain's axes (``model.reference.fft_axes``)."""

OS_MAX_ELEMENTS = 2 * 10**8
"""Bound on an OS-CFAR's work, (cells x training cells) values selected from (``host.
_cfar_os``): about a second at the bound."""
MAX_WINDOW_CELLS = 2048
"""Largest guard or training extent per side (half the largest FFT the core supports)."""


@dataclass(frozen=True)
class CfarParams:
    """2-D CFAR window, in cells: ``guard`` and ``train`` per side along (range, Doppler).

    ``pfa``: configured false-alarm probability per cell. ``kind``: ``"ca"`` (cell
    averaging) or ``"os"`` (ordered statistic, ``os_rank`` = fraction of training cells
    below the chosen one, 0.75 by default).
    """

    pfa: float = 1e-6
    guard: tuple[int, int] = (2, 2)
    train: tuple[int, int] = (4, 8)
    kind: str = "ca"
    os_rank: float = 0.75

    def __post_init__(self) -> None:
        if isinstance(self.pfa, bool) or not isinstance(self.pfa, int | float) or \
                not 1e-15 <= self.pfa < 0.5:
            raise ValueError(f"pfa: must be in [1e-15, 0.5), got {self.pfa}")
        if self.kind not in ("ca", "os"):
            raise ValueError(f"kind: must be 'ca' or 'os', got {self.kind!r}")
        for name, cells, lo in (("guard", self.guard, 0), ("train", self.train, 1)):
            if len(cells) != 2 or any(isinstance(c, bool) or not isinstance(c, int | np.integer)
                                      or not lo <= c <= MAX_WINDOW_CELLS for c in cells):
                raise ValueError(f"{name}: must be two integers (range, Doppler) in "
                                 f"{lo}..{MAX_WINDOW_CELLS} cells per side, got {cells}")
        if not 0.0 < self.os_rank < 1.0:
            raise ValueError(f"os_rank: must be in (0, 1), got {self.os_rank}")


def _kernel(params: CfarParams) -> np.ndarray:
    """Training-cell mask, float (2(g_r+t_r)+1, 2(g_d+t_d)+1), CUT at the centre."""
    (gr, gd), (tr, td) = params.guard, params.train
    k = np.ones((2 * (gr + tr) + 1, 2 * (gd + td) + 1))
    k[tr:tr + 2 * gr + 1, td:td + 2 * gd + 1] = 0.0
    return k


@lru_cache(maxsize=64)
def _n_train(params: CfarParams) -> int:
    """The number of training cells of ``params``' window (:func:`_kernel`'s ones)."""
    return int(_kernel(params).sum())


def map_axes(windowed: Windows, shape: tuple[int, int]) -> tuple[FftAxis, FftAxis]:
    """The two axes of a (n_range, n_doppler) map: ``windowed``'s axes as given, a boolean
    as an unpadded complex axis of the map's length."""
    return tuple(w if isinstance(w, FftAxis) else FftAxis(n, n, bool(w))  # type: ignore
                 for w, n in zip(windowed, shape, strict=True))


def effective_cells(params: CfarParams, windowed: Windows = (True, True)) -> float:
    """Number of independent cells with the same averaging power as the training set."""
    if all(isinstance(w, bool) for w in windowed):
        return effective_cells_mask(_kernel(params), windowed)  # type: ignore[arg-type]
    axes = map_axes(windowed, (1, 1))
    return effective_cells_mask(_kernel(params), correlations=(
        axes[0].power_correlation(), axes[1].power_correlation()))


def check_window(params: CfarParams, shape: tuple[int, int]) -> None:
    """ValueError when the CFAR window (guard + training cells, both sides, plus the cell
    under test) does not fit the (n_range, n_doppler) map ``shape``: on a circular axis the
    window would then count cells twice."""
    for axis, name in enumerate(("range", "Doppler")):
        span = 2 * (params.guard[axis] + params.train[axis]) + 1
        if span > shape[axis]:
            raise ValueError(f"CFAR window: 2 x (guard {params.guard[axis]} + train "
                             f"{params.train[axis]}) + 1 = {span} {name} cells does not fit "
                             f"the map's {shape[axis]} {name} bins")
    n_train = _n_train(params)
    if params.kind == "os" and n_train * shape[0] * shape[1] > OS_MAX_ELEMENTS:
        raise ValueError(f"CFAR window: OS-CFAR sorts {n_train} training cells for each of "
                         f"{shape[0] * shape[1]} cells, more than this host allows "
                         f"({OS_MAX_ELEMENTS:.0e} values); use fewer training cells or CA")


@lru_cache(maxsize=64)
def _pad_index(n: int, reach: int, mirrored: bool) -> np.ndarray:
    """The indices of an axis of n cells padded by ``reach`` <= n - 1 cells each side, int
    (n + 2 reach,): circular, or reflected at both ends without repeating the edge cell
    (``mirrored``). Read-only, once per axis."""
    i = np.arange(-reach, n + reach)
    if mirrored:
        i = np.abs(i)
        i = np.where(i > n - 1, 2 * (n - 1) - i, i)
    else:
        i %= n
    i.flags.writeable = False
    return i


@njit()
def _training_sum(power: np.ndarray, guard_r: int, guard_d: int, train_r: int,
                  train_d: int, mirrored: bool) -> np.ndarray:
    """Sum over each cell's CFAR training cells (:func:`_kernel`) of ``power``, float64
    (n_range, n_doppler) in any memory order, both axes circular (``mirrored``: range
    reflected at both ends, without repeating the edge cell, as ``np.pad(mode="reflect")``),
    float64 of that shape. Separable: per range row the Doppler training cells (``side``)
    and those plus the guard cells (``full``); then per cell the range training rows of
    ``full`` plus the range guard rows of ``side``. Sums of positive terms only (no
    cancellation), each added in offset order, negative offsets first; every loop runs
    along a row, so that it vectorises."""
    nr, nd = power.shape
    pr, pd = guard_r + train_r, guard_d + train_d
    n_rows = nr + 2 * pr
    side = np.empty((n_rows, nd))
    full = np.empty((n_rows, nd))
    row = np.empty(nd + 2 * pd)             # one map row, padded circularly
    for i in range(n_rows):
        r = i - pr
        if mirrored:
            r = -r if r < 0 else (2 * (nr - 1) - r if r > nr - 1 else r)
        else:
            r = (r + nr) % nr
        src = power[r]
        for j in range(pd):                 # columns -pd..-1, 0..nd-1, nd..nd+pd-1
            row[j] = src[nd - pd + j]
        for j in range(nd):
            row[pd + j] = src[j]
        for j in range(pd):
            row[pd + nd + j] = src[j]
        # every cell's sums at once, offset by offset (the same additions per cell, in
        # offset order; independent across cells, so they vectorise)
        s = side[i]
        g = full[i]
        for d in range(nd):
            s[d] = 0.0
            g[d] = 0.0
        for o in range(2 * pd + 1):
            if o < pd - guard_d or o > pd + guard_d:
                for d in range(nd):
                    s[d] += row[d + o]
            else:
                for d in range(nd):
                    g[d] += row[d + o]
        for d in range(nd):
            g[d] += s[d]
    out = np.empty((nr, nd))
    a = np.empty(nd)
    for r in range(nr):                     # out = (training rows of full) + (guard rows of side)
        for d in range(nd):
            a[d] = 0.0
        for i in range(r, r + pr - guard_r):
            f = full[i]
            for d in range(nd):
                a[d] += f[d]
        for i in range(r + pr + guard_r + 1, r + 2 * pr + 1):
            f = full[i]
            for d in range(nd):
                a[d] += f[d]
        b = out[r]
        for d in range(nd):
            b[d] = 0.0
        for i in range(r + pr - guard_r, r + pr + guard_r + 1):
            f = side[i]
            for d in range(nd):
                b[d] += f[d]
        for d in range(nd):
            b[d] = a[d] + b[d]
    return out


@warm_up
def _compile_training_sum() -> None:
    """Compile :func:`_training_sum` for the argument types of :func:`cfar_threshold`'s
    calls, maps in C and in Fortran order (a cube's map is Fortran-ordered;
    ``host.kernels.compile_data_dependent``: the FPGA detector's runs never reach it)."""
    for power in (np.zeros((3, 3)), np.zeros((3, 3), order="F")):
        _training_sum(power, 0, 0, 1, 1, False)
        _ca_mask(power, np.zeros((3, 3)), 1.0, 1.0, np.empty((3, 3), np.bool_))


@lru_cache(maxsize=64)
def _ca_alpha(pfa: float, n_channels: int, params: CfarParams, windowed: Windows) -> float:
    """CA-CFAR factor of ``params``' window on a map of ``windowed`` axes (``ca_factor`` at
    :func:`effective_cells`), once per configuration."""
    n_train = float(_n_train(params))
    return float(ca_factor(pfa, n_channels, n_train * effective_cells(params, windowed)
                           / n_train))


def cfar_threshold(power: np.ndarray, n_channels: int, params: CfarParams,
                   windowed: Windows = (True, True)) -> tuple[np.ndarray, np.ndarray]:
    """Per-cell detection threshold and noise estimate (mean power per cell).

    power: float (n_range, n_doppler). Returns (threshold, noise), both float of that shape.
    """
    if power.ndim != 2:
        raise ValueError(f"power: expected a 2-D (range, Doppler) map, got shape {power.shape}")
    (gr, gd), (tr, td) = params.guard, params.train
    if params.kind == "ca":
        noise = np.maximum(_ca_sums(power, params, windowed), 0.0) / _n_train(params)
        return _ca_alpha(params.pfa, n_channels, params, windowed) * noise, noise
    kth = os_kth(_os_padded(power, params, windowed), gr, gd, tr, td, _os_k(params))
    return _os_alpha(params.pfa, n_channels, params) * kth, _os_noise(kth, n_channels, params)


def _ca_sums(power: np.ndarray, params: CfarParams, windowed: Windows) -> np.ndarray:
    """The CA-CFAR's training sums of ``power`` (float (n_range, n_doppler)): float64 of
    its shape (:func:`_training_sum`)."""
    (gr, gd), (tr, td) = params.guard, params.train
    check_window(params, power.shape)
    return _training_sum(np.asarray(power, np.float64), gr, gd, tr, td,
                         map_axes(windowed, power.shape)[0].real)


@njit()
def _ca_mask(power: np.ndarray, sums: np.ndarray, alpha: float, n_train: float,
             mask: np.ndarray) -> None:
    """mask = power > alpha (max(sums, 0) / n_train) (float64 maps of one shape, bool mask
    (n_range, n_doppler)): :func:`cfar_detect`'s CA-CFAR mask, the same operations as
    :func:`cfar_threshold`'s (NaN sums give NaN noise, no detection), in one pass."""
    nr, nd = power.shape
    for r in range(nr):
        for d in range(nd):
            s = sums[r, d]
            noise = (s if s >= 0.0 or s != s else 0.0) / n_train
            mask[r, d] = power[r, d] > alpha * noise


def _os_padded(power: np.ndarray, params: CfarParams, windowed: Windows) -> np.ndarray:
    """``power`` (float (n_range, n_doppler)) as float64 padded by the CFAR window's half
    extent (``host._cfar_os.os_pad``), circularly on both axes (a real ADC's range axis
    reflected at both ends, without repeating the edge cell: ``np.pad``'s ``wrap`` and
    ``reflect``), in C order: the OS kernels read rows."""
    (gr, gd), (tr, td) = params.guard, params.train
    check_window(params, power.shape)
    return os_pad(np.asarray(power), _pad_index(power.shape[0], gr + tr,
                                                 map_axes(windowed, power.shape)[0].real),
                  _pad_index(power.shape[1], gd + td, False))


def _os_k(params: CfarParams) -> int:
    """Rank (1-based) of the OS-CFAR's training cell: ``os_rank`` of the training cells."""
    n_train = _n_train(params)
    return max(1, min(n_train, int(round(params.os_rank * n_train))))


@lru_cache(maxsize=64)
def _os_alpha(pfa: float, n_channels: int, params: CfarParams) -> float:
    """OS-CFAR factor of ``params``' window (``os_factor``), once per configuration."""
    return float(os_factor(pfa, n_channels, _n_train(params), _os_k(params)))


def _os_noise(kth: np.ndarray, n_channels: int, params: CfarParams) -> np.ndarray:
    """The OS-CFAR's mean noise power per cell from its ordered statistic ``kth`` (float,
    any shape): E[k-th of n] ~ theta ppf(k / (n + 1)); the mean power of a cell is L theta."""
    return kth * n_channels / _os_quantile(n_channels, params)


@lru_cache(maxsize=64)
def _os_quantile(n_channels: int, params: CfarParams) -> float:
    """ppf(k / (n + 1)) of Gamma(``n_channels``), the OS-CFAR's k of n training cells."""
    return stats.gamma(n_channels).ppf(_os_k(params) / (_n_train(params) + 1))


def cfar_detect(power: np.ndarray, n_channels: int, params: CfarParams,
                windowed: Windows = (True, True)) -> tuple[np.ndarray, np.ndarray]:
    """The cells above :func:`cfar_threshold`'s threshold, and its noise estimate there.

    power: float (n_range, n_doppler). Returns (mask bool: power > threshold, exactly as
    :func:`cfar_threshold`'s; noise float: its noise estimate, the same values, at every
    cell of ``mask``; elsewhere NaN for OS-CFAR, whose order statistic is found only at the
    detected cells: ``host._cfar_os`` counts instead, the module docstring says why that
    decides alike).
    """
    if params.kind == "ca":
        threshold, noise = cfar_threshold(power, n_channels, params, windowed)
        return power > threshold, noise
    mask, padded = _os_mask(power, n_channels, params, windowed)
    rows, cols = np.nonzero(mask)
    noise = np.full(power.shape, np.nan)
    noise[rows, cols] = _os_noise_at(padded, rows, cols, n_channels, params)
    return mask, noise


def cfar_cells(power: np.ndarray, n_channels: int, params: CfarParams, windowed: Windows,
               select: Callable[[np.ndarray], np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """The detected cells ``select`` keeps and :func:`cfar_detect`'s noise estimate at them:
    (cells int (n, 2) of (range_bin, doppler_bin), noise float (n,)). ``select`` maps the
    detection mask (bool (n_range, n_doppler), :func:`cfar_detect`'s) to the cells kept
    (int (n, 2); a host's peak grouping and reported range bins): the OS-CFAR then finds
    its order statistic at those cells only."""
    if params.kind == "ca":
        sums = _ca_sums(power, params, windowed)
        mask = np.empty(power.shape, bool)
        _ca_mask(np.asarray(power, np.float64), sums,
                 _ca_alpha(params.pfa, n_channels, params, windowed),
                 float(_n_train(params)), mask)
        cells = select(mask)
        return cells, np.maximum(sums[cells[:, 0], cells[:, 1]], 0.0) / _n_train(params)
    mask, padded = _os_mask(power, n_channels, params, windowed)
    cells = select(mask)
    return cells, _os_noise_at(padded, np.ascontiguousarray(cells[:, 0]),
                               np.ascontiguousarray(cells[:, 1]), n_channels, params)


def _os_mask(power: np.ndarray, n_channels: int, params: CfarParams, windowed: Windows
             ) -> tuple[np.ndarray, np.ndarray]:
    """The OS-CFAR's detection mask (bool (n_range, n_doppler), :func:`cfar_detect`) of
    ``power`` and its padded map (:func:`_os_padded`, for :func:`_os_noise_at`)."""
    if power.ndim != 2:
        raise ValueError(f"power: expected a 2-D (range, Doppler) map, got shape {power.shape}")
    padded = _os_padded(power, params, windowed)
    (gr, gd), (tr, td) = params.guard, params.train
    return os_detect(padded, _os_alpha(params.pfa, n_channels, params), gr, gd, tr, td,
                     _os_k(params)), padded


def _os_noise_at(padded: np.ndarray, rows: np.ndarray, cols: np.ndarray, n_channels: int,
                 params: CfarParams) -> np.ndarray:
    """The OS-CFAR's noise estimate (:func:`_os_noise`) at the cells (rows[i], cols[i]) of
    the padded map ``padded`` (:func:`_os_padded`), float (n,)."""
    (gr, gd), (tr, td) = params.guard, params.train
    return _os_noise(os_kth_at(padded, rows, cols, gr, gd, tr, td, _os_k(params)),
                     n_channels, params)


def local_peaks(power: np.ndarray, mask: np.ndarray, size: tuple[int, int] = (3, 3),
                mirrored: bool = False) -> np.ndarray:
    """Peak grouping: cells of ``mask`` that are the maximum of their (range, Doppler)
    neighbourhood of ``size`` cells (both axes circular; ``mirrored``: the range axis
    reflected at its ends, a real ADC's; the neighbourhood of ``scipy.ndimage``'s filters:
    offsets -(s // 2) .. s - s // 2 - 1). Only the cells of ``mask`` are compared with
    their neighbours. Returns int (n, 2) of (range_bin, doppler_bin), row-major order."""
    return local_peak_cells(power, mask, size[0], size[1], mirrored)


def detection_mask(n_range: int, n_doppler: int, bins: tuple[int, int]) -> np.ndarray:
    """bool (n_range, n_doppler): True in the range bins ``bins[0] <= r < bins[1]`` a
    detector may report (``RadarConfig.detection_bins``: DC guard and negative-beat guard)."""
    mask = np.zeros((n_range, n_doppler), bool)
    mask[bins[0]:bins[1]] = True
    return mask


def paper_threshold(cube: np.ndarray, threshold_db: float) -> tuple[np.ndarray, np.ndarray]:
    """The paper's detector: threshold the first channel's range-Doppler map.

    cube: complex (n_virtual, n_range, n_doppler). The threshold is ``threshold_db`` above
    the map's median power (a robust noise-floor estimate). Returns (mask bool
    (n_range, n_doppler), channel-0 power float (n_range, n_doppler)).
    """
    p0 = np.abs(cube[0]) ** 2
    floor = np.median(p0)
    return p0 > floor * 10.0 ** (threshold_db / 10.0), p0


MAIN_LOBE_BINS = HANN_MAIN_LOBE_BINS
"""Half width of the periodic Hann main lobe, bins, unpadded: sidelobe masking starts beyond
it (``model.reference.FftAxis.main_lobe_bins`` when zero-padded)."""


@lru_cache(maxsize=16)
def sidelobe_envelope(n: int, windowed: bool, n_samples: int | None = None) -> np.ndarray:
    """Power envelope of a windowed tone's response on an ``n``-point FFT of ``n_samples``
    samples (default n; zero-padded beyond), float (n,): for circular offset k, the largest
    |W(k + delta)|^2 / |W(0)|^2 over fractional offsets |delta| <= 0.5 of the tone from
    the bin centre; 0 within the main lobe (|k| <= MAIN_LOBE_BINS, or the padded axis'
    ``FftAxis.main_lobe_bins``)."""
    m = n if n_samples is None else n_samples
    axis = FftAxis(n, m, windowed)
    w = np.zeros(n)
    w[:m] = axis.window()
    k = np.arange(n)
    k = np.where(k > n // 2, k - n, k)
    delta = np.linspace(-0.5, 0.5, 21)
    # response at k + delta for every k: the DFT of w * exp(-j 2 pi delta t / n), one FFT
    # per fractional offset
    shifted = w[None, :] * np.exp(-2j * np.pi * np.outer(delta, np.arange(n)) / n)
    resp = np.abs(np.fft.fft(shifted, axis=1)) / w.sum()                  # (delta, k)
    env = np.max(resp**2, axis=0)
    env[np.abs(k) <= (MAIN_LOBE_BINS if m == n else axis.main_lobe_bins)] = 0.0
    return env


def sidelobe_masked(power: np.ndarray, cells: np.ndarray, windowed: Windows,
                    margin_db: float) -> np.ndarray:
    """bool (n,): cells (int (n, 2) of (range, Doppler)) of ``power`` (float (n_range,
    n_doppler)) that are not ``margin_db`` above the window sidelobes of some stronger cell
    in the same Doppler column (range sidelobes, circular; on a real ADC's mirrored range
    axis those of the cell and of its mirror image) or range row (Doppler sidelobes). A
    target 95 dB above the noise has Hann sidelobes above the noise 30 bins away, which a
    CFAR window a few cells wide cannot tell from targets."""
    ax_r, ax_d = map_axes(windowed, power.shape)
    scale = 10 ** (margin_db / 10)
    env_r = sidelobe_envelope(ax_r.n_fft, ax_r.hann, ax_r.n_samples) * scale
    env_d = sidelobe_envelope(ax_d.n_fft, ax_d.hann, ax_d.n_samples) * scale
    cells = np.asarray(cells).reshape(-1, 2)
    return sidelobe_cells(power, cells, env_r, env_d, ax_r.real)
