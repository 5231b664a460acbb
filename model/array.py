"""The array's geometry convention, one place for the simulator and the angle estimators.

Positions are (horizontal, vertical) in half-wavelengths at the carrier
(``RadarConfig.tx_positions_hw``, ``rx_positions_hw``, ``virtual_positions_hw``; virtual
element (tx, rx) at tx + rx, row v = tx * num_rx + rx). Horizontal is +y (left, looking
along the boresight +x), vertical is +z (up). A far-field direction is (azimuth, elevation):
azimuth positive towards +y, elevation positive upwards, so a point at range R sits at

    x = R cos(el) cos(az),  y = R cos(el) sin(az),  z = R sin(el).

Its echo reaches the element at (h, v) with the phase exp(-j pi (h u + v w)) relative to the
origin, where u = sin(az) cos(el) and w = sin(el) are the direction cosines along y and z
(the 1-D ULA case, ``exp(-j pi v sin(az))`` of ``model.reference``, is v = 0, el = 0).

TDM: chirp c of a frame is slot ``c % num_tx`` of loop ``c // num_tx`` and is fired by TX
``cfg.tx_sequence[c % num_tx]``; TX t therefore fires ``tx_slots(cfg)[t] * chirp_period_s``
after the start of its loop (the delay the TDM phase compensation undoes).
"""

from __future__ import annotations

import numpy as np

from model.config import RadarConfig


def direction_cosines(azimuth_rad: np.ndarray | float, elevation_rad: np.ndarray | float = 0.0
                      ) -> tuple[np.ndarray, np.ndarray]:
    """(u, w) = (sin(az) cos(el), sin(el)), float arrays of the broadcast input shape."""
    az = np.asarray(azimuth_rad, dtype=float)
    el = np.asarray(elevation_rad, dtype=float)
    return np.sin(az) * np.cos(el), np.sin(el) + 0.0 * az


def steering(positions_hw: np.ndarray, u: np.ndarray | float, w: np.ndarray | float = 0.0
             ) -> np.ndarray:
    """Steering vectors exp(-j pi (h u + v w)): positions_hw float (n, 2) half-wavelengths,
    u, w direction cosines of any broadcast shape S -> complex128 (*S, n)."""
    p = np.asarray(positions_hw, dtype=float)
    u = np.asarray(u, dtype=float)[..., None]
    w = np.asarray(w, dtype=float)[..., None]
    return np.exp(-1j * np.pi * (u * p[:, 0] + w * p[:, 1]))


def cartesian(range_m: np.ndarray, azimuth_rad: np.ndarray, elevation_rad: np.ndarray | float
              = 0.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(x, y, z) in m of points at (range, azimuth, elevation), float arrays of the broadcast
    input shape."""
    r = np.asarray(range_m, dtype=float)
    az = np.asarray(azimuth_rad, dtype=float)
    el = np.asarray(elevation_rad, dtype=float)
    return r * np.cos(el) * np.cos(az), r * np.cos(el) * np.sin(az), r * np.sin(el)


def has_vertical_extent(positions_hw: np.ndarray) -> bool:
    """Whether an array (positions float (n, 2), half-wavelengths) has elements at more than
    one height, so that it measures elevation (a planar array's points have el = 0)."""
    v = np.asarray(positions_hw, dtype=float)[:, 1]
    return bool(v.size and np.ptp(v) > 0)


def tx_slots(cfg: RadarConfig) -> np.ndarray:
    """Chirp slot (0..num_tx-1) of each TX index within a loop, int (num_tx,): the inverse
    permutation of ``cfg.tx_sequence``."""
    slots = np.empty(cfg.num_tx, dtype=int)
    slots[list(cfg.tx_sequence)] = np.arange(cfg.num_tx)
    return slots


def slot_channels(cfg: RadarConfig) -> np.ndarray | None:
    """The FPGA chain's channel of each virtual channel, int (n_virtual,), or None when they
    are the same (TXs firing in index order). The chain's corner turn keeps chirp slots: its
    cube's and its detection records' channel s * num_rx + r is RX r in chirp slot s, fired
    by TX ``cfg.tx_sequence[s]``; ``chain[..., slot_channels(cfg)]`` is in the order of
    virtual channel v = tx * num_rx + rx (TX by index), the float chain's and the host's."""
    if cfg.tx_sequence == tuple(range(cfg.num_tx)):
        return None
    v = np.arange(cfg.n_virtual)
    return tx_slots(cfg)[v // cfg.num_rx] * cfg.num_rx + v % cfg.num_rx
