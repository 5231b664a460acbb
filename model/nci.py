"""Bit-exact model of ``rtl/detect/nci.sv``: non-coherent integration of the Doppler-FFT
output over the NUM_TX x NUM_RX virtual channels.

Input words are uint32-style lane arrays of packed ``{Q, I}`` samples (``DATA_W`` bits each,
two's complement; the DMA format has ``data_w = 16``). Input order (mode 1, docs/design.md 3.4): for
range bin r, for TX t, for Doppler bin d: ``(n_range * num_tx * n_doppler, num_rx)``.
Output: the power map int64 ``(n_range, n_doppler)``, streamed for r, for d.

Width: one lane's ``I^2 + Q^2 <= 2^(2*data_w - 1)``, so the exact sum over ``num_tx * num_rx``
channels needs :func:`power_width` ``= 2*data_w + ceil(log2(num_tx*num_rx))`` bits and can
never saturate.
"""

from __future__ import annotations

import numpy as np


def power_width(num_tx: int, num_rx: int, data_w: int = 16) -> int:
    """Bits of the integrated power (RTL parameter POW_W)."""
    return 2 * data_w + (num_tx * num_rx - 1).bit_length()


def lane_iq(words: np.ndarray, data_w: int = 16) -> tuple[np.ndarray, np.ndarray]:
    """Packed lanes ``{Q, I}`` -> (I, Q) as int64 arrays of the same shape."""
    w = np.asarray(words).astype(np.uint64)
    mask = np.uint64((1 << data_w) - 1)
    half = 1 << (data_w - 1)
    i = (w & mask).astype(np.int64)
    q = ((w >> np.uint64(data_w)) & mask).astype(np.int64)
    return (i ^ half) - half, (q ^ half) - half


def nci(words: np.ndarray, num_tx: int, n_range: int, n_doppler: int,
        data_w: int = 16) -> np.ndarray:
    """Integrated power map of one frame.

    words: ``(n_range * num_tx * n_doppler, num_rx)`` packed lanes in (r, t, d) order.
    Returns int64 ``(n_range, n_doppler)``: sum over t and lanes of ``I^2 + Q^2``.
    """
    w = np.asarray(words)
    num_rx = w.shape[-1]
    if w.shape[0] != n_range * num_tx * n_doppler:
        raise ValueError(f"words: expected {n_range * num_tx * n_doppler} words, got {w.shape[0]}")
    if power_width(num_tx, num_rx, data_w) > 62:
        raise ValueError("power width above 62 bits does not fit the int64 model")
    i, q = lane_iq(w, data_w)
    p = (i * i + q * q).reshape(n_range, num_tx, n_doppler, num_rx)
    return p.sum(axis=(1, 3))
