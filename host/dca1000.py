"""TI DCA1000 raw ADC captures (``.bin``, docs/profiles.md "Captures"): read and write.

A DCA1000 ``.bin`` (what mmWave Studio and the DCA1000 CLI write once the packets are
stripped) is a headerless stream of little-endian int16 words, frame after frame, chirp after
chirp in firing order. Within a chirp TI documents two layouts (mmWave Studio user guide, "raw
ADC data format"; TI's ``readDCA1000.m`` scripts):

- **4 LVDS lanes, interleaved** (xWR12xx/14xx): sample after sample; for each sample the
  four lanes' I, then the four lanes' Q (complex: ``I0 I1 I2 I3 Q0 Q1 Q2 Q3`` per sample,
  lane = RX), or the four lanes' real values. The stream always carries four lanes: RX
  ``r`` of the profile is lane ``r``, lanes without an RX hold zeros.
- **2 LVDS lanes, non-interleaved** (xWR16xx/18xx/68xx): RX after RX, each RX's samples in
  order; complex samples come in pairs as ``I(n) I(n+1) Q(n) Q(n+1)`` (the pairing runs over
  the stream, as TI's script reads it), real samples one word each.

Frames are read through ``np.memmap``: opening a capture reads nothing, each frame is
converted when asked for, so a capture of any size streams. A capture cut short keeps its
whole frames; the bytes after the last whole frame are reported (``dropped_bytes``), never
assembled into a frame.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from pathlib import Path

import numpy as np

from host.kernels import njit, warm_up
from model.config import RadarConfig
from model.profile import CaptureFormat

WORD = np.dtype("<i2")
"""One ADC value of the stream: little-endian int16."""
INTERLEAVED_LANES = 4
"""Lanes the interleaved (xWR12xx/14xx) stream always carries."""


@njit()
def _pairs_to_iq(words: np.ndarray, out: np.ndarray) -> None:
    """The 2-lane complex layout's words (int16 (4 m,): each sample pair's I(n) I(n+1)
    Q(n) Q(n+1)) into ``out`` (float32 (4 m,)) as I(n) Q(n) I(n+1) Q(n+1): one pass,
    the cast exact."""
    for q in range(words.shape[0] // 4):
        i = 4 * q
        out[i] = words[i]
        out[i + 1] = words[i + 2]
        out[i + 2] = words[i + 1]
        out[i + 3] = words[i + 3]


@warm_up
def _warm_up() -> None:
    """The 2-lane reorder (reached only by captures in that layout) on one sample pair."""
    _pairs_to_iq(np.zeros(4, WORD), np.empty(4, np.float32))


def frame_words(cfg: RadarConfig, fmt: CaptureFormat) -> int:
    """int16 words of one frame of ``cfg`` in layout ``fmt``."""
    per_value = 2 if cfg.adc == "complex" else 1
    lanes = INTERLEAVED_LANES if fmt.interleaved else cfg.num_rx
    return cfg.n_chirps * lanes * cfg.n_samples * per_value


def _check_layout(cfg: RadarConfig, fmt: CaptureFormat) -> None:
    if fmt.interleaved and cfg.num_rx > INTERLEAVED_LANES:
        raise ValueError(f"capture: the interleaved layout carries {INTERLEAVED_LANES} RX "
                         f"lanes, the radar has {cfg.num_rx} RX")
    if not fmt.interleaved and cfg.adc == "complex" and cfg.n_chirps * cfg.num_rx \
            * cfg.n_samples % 2:
        raise ValueError("capture: the 2-lane complex layout pairs samples; a frame of this "
                         "radar holds an odd number of them")


def words_to_frame(words: np.ndarray, cfg: RadarConfig, fmt: CaptureFormat) -> np.ndarray:
    """One frame from its int16 stream words, shape (``frame_words``,): complex64 (complex
    ADC) or float32 (real ADC) of shape (n_chirps in firing order, num_rx, n_samples), the
    integer ADC codes."""
    _check_layout(cfg, fmt)
    w = np.asarray(words, dtype=WORD)
    if w.shape != (frame_words(cfg, fmt),):
        raise ValueError(f"capture: a frame is {frame_words(cfg, fmt)} words, got {w.shape}")
    c, r, n = cfg.n_chirps, cfg.num_rx, cfg.n_samples
    if cfg.adc == "real":
        if fmt.interleaved:
            x = w.reshape(c, n, INTERLEAVED_LANES)[:, :, :r].transpose(0, 2, 1)
        else:
            x = w.reshape(c, r, n)
        return x.astype(np.float32)
    if fmt.interleaved:
        out = np.empty((c, r, n), dtype=np.complex64)
        iq = w.reshape(c, n, 2, INTERLEAVED_LANES)[:, :, :, :r]    # (chirp, sample, I/Q, rx)
        out.real = iq[:, :, 0, :].transpose(0, 2, 1)
        out.imag = iq[:, :, 1, :].transpose(0, 2, 1)
    else:
        # each pair's words reordered to I(n) Q(n) I(n+1) Q(n+1) and cast in one compiled
        # pass, then read as complex (numpy's gather and cast took 9 times as long)
        iq = np.empty(w.shape, np.float32)
        _pairs_to_iq(np.ascontiguousarray(w), iq)
        out = iq.view(np.complex64).reshape(c, r, n)
    return out


def frame_to_words(frame: np.ndarray, cfg: RadarConfig, fmt: CaptureFormat) -> np.ndarray:
    """The int16 stream words of one frame (the inverse of :func:`words_to_frame`).

    frame: (n_chirps, num_rx, n_samples), complex for a complex ADC, real for a real one,
    integer codes within int16 (ValueError otherwise: nothing is rounded or clipped)."""
    _check_layout(cfg, fmt)
    x = np.asarray(frame)
    if x.shape != cfg.adc_shape:
        raise ValueError(f"frame: expected shape {cfg.adc_shape} (chirps, rx, samples), got "
                         f"{x.shape}")
    if (x.dtype.kind == "c") != (cfg.adc == "complex"):
        raise ValueError(f"frame: a {cfg.adc} ADC needs "
                         f"{'complex' if cfg.adc == 'complex' else 'real'} samples, got "
                         f"dtype {x.dtype}")
    parts = (x.real, x.imag) if cfg.adc == "complex" else (x,)
    for p in parts:
        if not np.array_equal(p, np.round(p)) or p.min(initial=0) < -32768 \
                or p.max(initial=0) > 32767:
            raise ValueError("frame: samples must be integer ADC codes in -32768..32767")
    c, r, n = cfg.n_chirps, cfg.num_rx, cfg.n_samples
    if fmt.interleaved:
        lanes = np.zeros((len(parts), c, n, INTERLEAVED_LANES), dtype=WORD)
        for k, p in enumerate(parts):
            lanes[k, :, :, :r] = p.transpose(0, 2, 1)
        return lanes.transpose(1, 2, 0, 3).reshape(-1)            # (chirp, sample, I/Q, lane)
    if cfg.adc == "real":
        return x.astype(WORD).reshape(-1)
    pairs = np.empty((c * r * n // 2, 2, 2), dtype=WORD)
    pairs[:, 0, :] = x.real.reshape(-1, 2)
    pairs[:, 1, :] = x.imag.reshape(-1, 2)
    return pairs.reshape(-1)


class Dca1000Capture:
    """A DCA1000 ``.bin`` of radar ``cfg`` in layout ``fmt``, memory-mapped.

    ``n_frames`` whole frames; ``dropped_bytes`` after the last of them (a capture cut short
    mid-frame). ValueError when the file holds no whole frame."""

    def __init__(self, path: str | Path, cfg: RadarConfig, fmt: CaptureFormat) -> None:
        _check_layout(cfg, fmt)
        self.path, self.config, self.format = Path(path), cfg, fmt
        size = self.path.stat().st_size
        self.frame_bytes = frame_words(cfg, fmt) * WORD.itemsize
        self.n_frames = size // self.frame_bytes
        self.dropped_bytes = size - self.n_frames * self.frame_bytes
        if self.n_frames == 0:
            raise ValueError(f"{self.path}: {size} bytes hold no whole frame of radar "
                             f"{cfg.name!r} ({self.frame_bytes} bytes per frame)")
        # a plain array over the mapping (it keeps the map open): indexing a np.memmap
        # makes a memmap object per frame, a few microseconds of Python each
        self._words = np.asarray(np.memmap(self.path, dtype=WORD, mode="r",
                                           shape=(self.n_frames, frame_words(cfg, fmt))))

    def frame(self, index: int) -> np.ndarray:
        """Frame ``index`` (see :func:`words_to_frame`); IndexError outside 0..n_frames-1."""
        if not 0 <= index < self.n_frames:
            raise IndexError(f"{self.path}: frame {index} not in 0..{self.n_frames - 1}")
        return words_to_frame(self._words[index], self.config, self.format)

    def frames(self, start: int = 0, stop: int | None = None) -> Iterator[np.ndarray]:
        """Frames start..stop-1 (stop: n_frames if None), one at a time."""
        for i in range(start, self.n_frames if stop is None else min(stop, self.n_frames)):
            yield self.frame(i)

    def report(self) -> str:
        """One line: frames kept and, if any, bytes dropped."""
        text = f"{self.path}: {self.n_frames} frame(s) of {self.frame_bytes} bytes"
        if self.dropped_bytes:
            text += (f"; the capture ends mid-frame: {self.dropped_bytes} bytes after the "
                     f"last whole frame dropped")
        return text


def write_dca1000(path: str | Path, frames: Iterable[np.ndarray], cfg: RadarConfig,
                  fmt: CaptureFormat) -> int:
    """Write ``frames`` (each as :func:`frame_to_words` takes it) as a DCA1000 ``.bin``, one
    frame at a time; returns the number of frames written. On a bad frame (ValueError) the
    file is removed, never left half written."""
    count = 0
    try:
        with open(path, "wb") as f:
            for frame in frames:
                f.write(frame_to_words(frame, cfg, fmt).tobytes())
                count += 1
    except ValueError:
        Path(path).unlink()
        raise
    return count
