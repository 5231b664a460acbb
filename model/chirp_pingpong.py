"""Bit-exact model of ``rtl/buffers/chirp_pingpong.sv`` (ADC-side chirp ping-pong buffer).

Words are uint32 lane arrays ``(n, num_rx)``; each lane a ``{Q[31:16], I[15:0]}`` sample.
The block forwards only complete, correctly framed chirps of ``n_range`` samples. Framing
(data dependent, so modelled exactly): a chirp attempt starts at the first sample after a
TLAST (or reset); it is good if its TLAST is on sample ``n_range-1``; an early TLAST ends a
bad attempt; a missing TLAST at sample ``n_range-1`` makes a bad attempt that runs up to and
including the next TLAST. Overflow drops (timing dependent: ADC_BACKPRESSURE=0 and a stalled
range FFT) are given to the model as the set of dropped attempt indices.

Output per forwarded chirp: its words, TUSER[0] (frame start, the TUSER[0] of the chirp's
first input sample) and TUSER[1] (gap: an attempt was discarded since the previous forwarded
chirp), both on the first output sample only.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from model.axis_packetizer import pack_iq


@dataclass
class ChirpAttempt:
    """One input chirp attempt. words: ``(n_samples, num_rx)`` as received."""

    index: int
    words: np.ndarray
    sof: bool
    good: bool


@dataclass
class OutChirp:
    """One forwarded chirp. words: ``(n_range, num_rx)``."""

    index: int
    words: np.ndarray
    sof: bool
    gap: bool


def split_attempts(words: np.ndarray, tlast: np.ndarray, sof: np.ndarray,
                   n_range: int) -> tuple[list[ChirpAttempt], int]:
    """Cut an input sample stream into chirp attempts with the RTL's framing rules.

    words: ``(n, num_rx)``; tlast, sof: bool ``(n,)``. Returns (attempts, framing errors),
    where a framing error is each TLAST off sample ``n_range-1`` and each missing TLAST.
    A trailing incomplete attempt (no TLAST yet) is not returned.
    """
    words = np.asarray(words)
    attempts: list[ChirpAttempt] = []
    errors = 0
    pos, start, skip = 0, 0, False
    good = True
    for i in range(len(words)):
        last = bool(tlast[i])
        if skip:
            if last:
                attempts.append(ChirpAttempt(len(attempts), words[start:i + 1],
                                             bool(sof[start]), False))
                skip, pos, start = False, 0, i + 1
            continue
        at_end = pos == n_range - 1
        if last != at_end:
            errors += 1
            good = False
        if last:
            attempts.append(ChirpAttempt(len(attempts), words[start:i + 1], bool(sof[start]),
                                         good))
            pos, start, good = 0, i + 1, True
        elif at_end:
            skip = True  # missing TLAST: drop up to and including the next one
            good = True
        else:
            pos += 1
    return attempts, errors


def pingpong_output(attempts: Iterable[ChirpAttempt],
                    dropped: Iterable[int] = ()) -> list[OutChirp]:
    """Forwarded chirps, given the attempt indices dropped by overflow."""
    dropped = set(dropped)
    out: list[OutChirp] = []
    gap = False
    for a in attempts:
        if a.good and a.index not in dropped:
            out.append(OutChirp(a.index, a.words, a.sof, gap))
            gap = False
        else:
            gap = True
    return out


def chirp_pingpong(words: np.ndarray, tlast: np.ndarray, sof: np.ndarray, n_range: int,
                   dropped: Iterable[int] = ()) -> list[OutChirp]:
    """Whole model: input stream ``(n, num_rx)`` with TLAST/TUSER[0] -> forwarded chirps."""
    attempts, _ = split_attempts(words, tlast, sof, n_range)
    return pingpong_output(attempts, dropped)


def adc_frame_to_stream(adc: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """ADC frame -> input stream of the block.

    adc: integer-valued complex ``(n_chirps, num_rx, n_range)`` (the ``radar simulate``
    layout). Returns words uint32 ``(n_chirps * n_range, num_rx)``, tlast and sof bool
    ``(n_chirps * n_range,)`` (sof on the very first sample).
    """
    adc = np.asarray(adc)
    n_chirps, num_rx, n_range = adc.shape
    s = adc.transpose(0, 2, 1).reshape(-1, num_rx)
    words = pack_iq(s)
    n = n_chirps * n_range
    tlast = (np.arange(n) % n_range) == n_range - 1
    sof = np.zeros(n, bool)
    sof[0] = True
    return words, tlast, sof
