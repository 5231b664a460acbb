"""Private backend of ``host.angle`` for virtual arrays other than the contiguous lambda/2
ULA (non-uniform, two-dimensional): Bartlett beamforming over the steering vectors of
``model.array.steering`` on a grid of directions, local refinement, and RELAX over it.

Directions are the direction cosines (u, w) = (sin(az) cos(el), sin(el)) of ``model.array``.
The grid steps u by 2 / ((H + 1) ``OVERSAMPLE``), H the array's horizontal aperture in
half-wavelengths (2 / (H + 1): the Rayleigh resolution); an array with vertical aperture
V > 0 steps w by 2 / ((V + 1) ``OVERSAMPLE``) over the visible directions u^2 + w^2 <= 1, a
planar one has w = 0. The
spectrum of a channel vector x (complex (n,)) is P(u, w) = |s(u, w)^H x|^2 (for the ULA,
the |X(k)|^2 of its angle FFT). Its maximum: the grid's, then a pattern search around it
that halves its step ``ZOOM_STEPS`` times (3 candidates in u, or 3 x 3 in (u, w), the
best one kept, staying visible): the grid step / 2^ZOOM_STEPS from the lobe's maximum.

:func:`relax_general` runs RELAX (``host.angle`` module docstring) over these peaks: each
further component of the residual is kept while it passes the gates of
``host.angle.AngleParams`` (:func:`supported`), every component re-estimated with the
others removed. This path is numpy (the ULA's runs in compiled kernels).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import Protocol

import numpy as np

from model.array import has_vertical_extent, steering

OVERSAMPLE = 4
"""Grid points per Rayleigh resolution 2 / (aperture + 1) along each axis (a lobe's grid
maximum is at most 1/8 of a resolution off its peak: about 0.2 dB down, so the grid picks
the strongest lobe unless two are within that of each other)."""
ZOOM_STEPS = 12
"""Halvings of the step in the refinement (precision: the grid step / 4096)."""
_GRID_BLOCK = 1 << 21
"""Rows x grid points per grid product (bounds the (rows, grid) power matrix: 32 MiB)."""


class GateSettings(Protocol):
    """The settings :func:`supported` reads (``host.angle.AngleParams``)."""

    max_targets: int
    min_snr_db: float
    dynamic_range_db: float
    array_error_db: float
    refine_iterations: int


@dataclass(frozen=True)
class ArrayGrid:
    """The search grid of one virtual array: ``positions`` float (n, 2) half-wavelengths;
    ``u``, ``w`` float (g,) the grid's direction cosines; ``conj_steering`` complex (g, n)
    conj(steering) of each; ``step`` (du, dw) the grid steps (dw 0: a planar array);
    ``span`` (H + 1, V + 1) the apertures plus one, half-wavelengths."""

    positions: np.ndarray
    u: np.ndarray
    w: np.ndarray
    conj_steering: np.ndarray
    step: tuple[float, float]
    span: tuple[float, float]

    @property
    def planar(self) -> bool:
        """No vertical extent: every element at one height, elevation not measured."""
        return self.step[1] == 0.0


def array_grid(positions: np.ndarray) -> ArrayGrid:
    """The :class:`ArrayGrid` of an array (positions float (n, 2), half-wavelengths; one
    computed per array)."""
    p = np.asarray(positions, dtype=float)
    return _grid(tuple(map(tuple, p.tolist())))


@lru_cache(maxsize=8)
def _grid(positions: tuple[tuple[float, float], ...]) -> ArrayGrid:
    p = np.array(positions, dtype=float).reshape(-1, 2)
    span_h = float(np.ptp(p[:, 0])) + 1.0
    span_v = float(np.ptp(p[:, 1])) + 1.0
    du = 2.0 / (span_h * OVERSAMPLE)
    u1 = np.linspace(-1.0, 1.0, int(np.ceil(2.0 / du)) + 1)
    if not has_vertical_extent(p):
        u, w, dw = u1, np.zeros_like(u1), 0.0
    else:
        dw = 2.0 / (span_v * OVERSAMPLE)
        w1 = np.linspace(-1.0, 1.0, int(np.ceil(2.0 / dw)) + 1)
        uu, ww = (a.ravel() for a in np.meshgrid(u1, w1))
        visible = uu ** 2 + ww ** 2 <= 1.0 + 1e-12
        u, w = uu[visible], ww[visible]
    cs = np.conj(steering(p, u, w))
    for a in (u, w, cs):
        a.flags.writeable = False
    return ArrayGrid(p, u, w, cs, (float(u1[1] - u1[0]), dw), (span_h, span_v))


def bartlett_peaks(x: np.ndarray, grid: ArrayGrid) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The strongest peak of the Bartlett spectrum of each row of x (complex (m, n)),
    refined (module docstring): (u float (m,), w float (m,), power |s^H x|^2 float (m,))."""
    m = len(x)
    u, w, power = np.zeros(m), np.zeros(m), np.zeros(m)
    chunk = max(1, _GRID_BLOCK // len(grid.u))
    for lo in range(0, m, chunk):
        part = slice(lo, min(lo + chunk, m))
        spec = np.abs(x[part] @ grid.conj_steering.T) ** 2                   # (rows, g)
        k = np.argmax(spec, axis=1)
        u[part], w[part], power[part] = grid.u[k], grid.w[k], spec[np.arange(len(k)), k]
    du, dw = grid.step
    o = np.array([-1.0, 0.0, 1.0])
    ou, ow = (o, np.zeros(3)) if grid.planar else (np.repeat(o, 3), np.tile(o, 3))
    rows = np.arange(m)
    for _ in range(ZOOM_STEPS):
        du, dw = du / 2, dw / 2
        cu = u[:, None] + du * ou[None, :]
        cw = w[:, None] + dw * ow[None, :]
        # s(u + a, w + b) = s(u, w) s(a, b) elementwise: demodulate each row once, then
        # one small product with the candidates' offsets (the same for every row)
        y = np.conj(steering(grid.positions, u, w)) * x
        p = np.abs(y @ steering(grid.positions, -du * ou, -dw * ow).T) ** 2     # (m, c)
        p[cu ** 2 + cw ** 2 > 1.0] = -1.0
        best = np.argmax(p, axis=1)
        u, w, power = cu[rows, best], cw[rows, best], p[rows, best]
    return u, w, power


def supported(power: np.ndarray, first: np.ndarray, held: np.ndarray, noise: np.ndarray,
              n: int, params: GateSettings) -> np.ndarray:
    """The gates of a further component (``host.angle.AngleParams``), bool (m,): power
    |a|^2 of the candidate, first |a_1|^2 of the row's first component, held sum |a_j|^2 of
    the components held, noise per channel (float (m,) each), n channels: the level gates
    (:func:`level_gates`) and the model-order test (:func:`model_order`)."""
    return level_gates(power, first, noise, n, params) & model_order(power, held, noise,
                                                                     params)


def level_gates(power: np.ndarray, first: np.ndarray, noise: np.ndarray, n: int,
                params: GateSettings) -> np.ndarray:
    """bool (m,): coherent SNR |a|^2 n / noise >= ``min_snr_db`` and first / |a|^2 within
    ``dynamic_range_db`` (arguments as :func:`supported`'s)."""
    with np.errstate(divide="ignore"):
        return (10 * np.log10(power * n / noise) >= params.min_snr_db) & (
            10 * np.log10(first / np.maximum(power, 1e-300)) <= params.dynamic_range_db)


def model_order(power: np.ndarray, held: np.ndarray, noise: np.ndarray,
                params: GateSettings) -> np.ndarray:
    """bool (m,): the model-order test |a|^2 >= noise + 10^(``array_error_db`` / 10) held
    (arguments as :func:`supported`'s)."""
    return power >= noise + 10 ** (params.array_error_db / 10) * held


def relax_general(x: np.ndarray, noise: np.ndarray, grid: ArrayGrid, params: GateSettings
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """RELAX on the rows of x (complex (m, n), TDM-compensated; noise float (m,) per
    channel, >= 1e-30) over :func:`bartlett_peaks`: the first component always, each
    further one while :func:`supported`, every component re-estimated
    ``refine_iterations`` times with the others removed. Returns (u float (m, k), w float
    (m, k), amplitude complex (m, k), count int (m,): the first count slots of each row are
    valid), k = ``max_targets``."""
    m, n = x.shape
    kmax = params.max_targets
    u_c, w_c = np.zeros((m, kmax)), np.zeros((m, kmax))
    a_c = np.zeros((m, kmax), complex)
    st_c = np.zeros((m, kmax, n), complex)
    count = np.zeros(m, np.int64)
    first = np.zeros(m)
    residual = x.copy()
    live = np.arange(m)
    for t in range(kmax):
        if not len(live):
            break
        u, w, _ = bartlett_peaks(residual[live], grid)
        st = steering(grid.positions, u, w)
        a = np.sum(np.conj(st) * residual[live], axis=1) / n
        if t:
            held = np.sum(np.abs(a_c[live, :t]) ** 2, axis=1)
            keep = supported(np.abs(a) ** 2, first[live], held, noise[live], n, params)
            live, u, w, a, st = live[keep], u[keep], w[keep], a[keep], st[keep]
            if not len(live):
                break
        u_c[live, t], w_c[live, t], a_c[live, t], st_c[live, t] = u, w, a, st
        count[live] = t + 1
        if not t:
            first[live] = np.abs(a) ** 2
        for _ in range(params.refine_iterations if t else 0):
            for j in range(t + 1):
                r = x[live] - np.einsum("mq,mqn->mn", np.delete(a_c[live, :t + 1], j, 1),
                                        np.delete(st_c[live, :t + 1], j, 1))
                uj, wj, _ = bartlett_peaks(r, grid)
                stj = steering(grid.positions, uj, wj)
                u_c[live, j], w_c[live, j], st_c[live, j] = uj, wj, stj
                a_c[live, j] = np.sum(np.conj(stj) * r, axis=1) / n
        residual[live] = x[live] - np.einsum("mq,mqn->mn", a_c[live, :t + 1],
                                             st_c[live, :t + 1])
    return u_c, w_c, a_c, count
