"""Bit-accurate model of ``rtl/buffers/frame_align.sv``: keeps the chirp stream frame-aligned
after the ADC ping-pong lost chirps.

Input chirps carry two flags on their first sample: ``sof`` (frame start) and ``gap`` (chirps
were discarded before this one). A frame is ``frame_chirps`` chirps. Rules, applied to every
input chirp in order (``c`` = chirps already emitted in the current frame):

- while discarding: a chirp with ``sof`` ends the discard and is handled below; any other
  chirp is dropped (counted);
- ``c > 0`` and (``sof`` or ``gap``): the rest of the frame is zero-filled (frame damaged);
  then a ``sof`` chirp starts the next frame, a ``gap`` chirp without ``sof`` is dropped and
  input is discarded up to the next frame start;
- ``c == 0``, ``gap`` and not ``sof`` (the frame's start chirp was lost): a whole frame of
  zeros is emitted (damaged), this chirp is dropped and input discarded up to a frame start;
- ``c == 0`` and neither flag (the ADC was mid-frame, e.g. after reset): dropped, discard;
- otherwise the chirp is forwarded.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class AlignResult:
    """What ``frame_align`` emits for an input sequence.

    ``chirps``: output chirps in order, each uint32 (n_range, num_rx) (zeros when filled);
    ``frames_damaged``: one bool per completed output frame; counters as the RTL's.
    """

    chirps: list[np.ndarray] = field(default_factory=list)
    frames_damaged: list[bool] = field(default_factory=list)
    chirps_filled: int = 0
    chirps_discarded: int = 0


def frame_align(chirps: list[np.ndarray], sof: list[bool], gap: list[bool],
                frame_chirps: int) -> AlignResult:
    """Apply the rules above. ``chirps``: uint32 (n_range, num_rx) each; ``sof``/``gap``: the
    flags on each chirp's first sample. Output frames that are not complete at the end of
    the input are not reported in ``frames_damaged``."""
    if not len(chirps) == len(sof) == len(gap):
        raise ValueError("chirps, sof and gap must have the same length")
    res = AlignResult()
    if not chirps:
        return res
    zero = np.zeros_like(chirps[0])
    c = 0
    discarding = False

    def emit(chirp: np.ndarray) -> None:
        nonlocal c
        res.chirps.append(chirp)
        c += 1
        if c == frame_chirps:
            res.frames_damaged.append(False)
            c = 0

    def fill() -> None:
        nonlocal c
        n = frame_chirps - c
        res.chirps.extend([zero] * n)
        res.chirps_filled += n
        res.frames_damaged.append(True)
        c = 0

    for chirp, s, g in zip(chirps, sof, gap, strict=True):
        if discarding:
            if not s:
                res.chirps_discarded += 1
                continue
            discarding = False
        if c > 0 and (s or g):
            fill()
            if g and not s:
                discarding = True
                res.chirps_discarded += 1
                continue
        elif c == 0 and g and not s:
            fill()
            discarding = True
            res.chirps_discarded += 1
            continue
        elif c == 0 and not s:
            discarding = True
            res.chirps_discarded += 1
            continue
        emit(chirp)
    return res
