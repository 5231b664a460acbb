"""ADC captures of a radar profile (docs/profiles.md "Captures"): a DCA1000 ``.bin``
(``host.dca1000``) or a ``.npy`` array, opened the same way and read frame by frame.

``.npy``: complex (frames, chirps in firing order, rx, samples) or one frame (chirps, rx,
samples); real-valued for a real ADC. Opened with ``mmap_mode="r"``, so only the frames asked
for are read. A real-valued array for a complex-ADC profile, or a complex one for a real ADC,
is refused (a real frame taken as complex gives mirror images).
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from pathlib import Path

import numpy as np

from host.dca1000 import Dca1000Capture
from model.config import RadarConfig
from model.profile import Profile


class NpyCapture:
    """A ``.npy`` capture of radar ``cfg``, memory-mapped; ``n_frames`` frames."""

    dropped_bytes = 0

    def __init__(self, path: str | Path, cfg: RadarConfig) -> None:
        self.path, self.config = Path(path), cfg
        try:
            data = np.load(self.path, mmap_mode="r", allow_pickle=False)
        except ValueError as exc:
            raise ValueError(f"{self.path}: not a numpy array file: {exc}") from None
        if data.ndim == 3:
            data = data[None]
        if data.ndim != 4 or data.shape[1:] != cfg.adc_shape:
            raise ValueError(f"{self.path}: expected shape (frames, *{cfg.adc_shape}) or "
                             f"{cfg.adc_shape} (chirps in firing order, rx, samples) for "
                             f"radar {cfg.name!r}, got {np.shape(data)}")
        if (data.dtype.kind == "c") != (cfg.adc == "complex"):
            raise ValueError(f"{self.path}: dtype {data.dtype} is "
                             f"{'complex' if data.dtype.kind == 'c' else 'real'}, radar "
                             f"{cfg.name!r} has a {cfg.adc} ADC")
        if data.dtype.kind not in "cfiu":
            raise ValueError(f"{self.path}: dtype {data.dtype} is not numeric")
        self._data = data
        self.n_frames = data.shape[0]

    def frame(self, index: int) -> np.ndarray:
        """Frame ``index``: complex64 or float32 (n_chirps, num_rx, n_samples)."""
        if not 0 <= index < self.n_frames:
            raise IndexError(f"{self.path}: frame {index} not in 0..{self.n_frames - 1}")
        kind = np.complex64 if self.config.adc == "complex" else np.float32
        return np.asarray(self._data[index], dtype=kind)

    def frames(self, start: int = 0, stop: int | None = None) -> Iterator[np.ndarray]:
        """Frames start..stop-1 (stop: n_frames if None), one at a time."""
        for i in range(start, self.n_frames if stop is None else min(stop, self.n_frames)):
            yield self.frame(i)

    def report(self) -> str:
        """One line: the frames the capture holds."""
        return f"{self.path}: {self.n_frames} frame(s)"


def open_capture(path: str | Path, profile: Profile) -> Dca1000Capture | NpyCapture:
    """The capture at ``path`` in the profile's capture format (``.npy`` files are read as
    numpy arrays whatever the profile says); ValueError (one line) on a file that does not
    fit the profile."""
    p = Path(path)
    if not p.is_file():
        raise ValueError(f"capture: no such file {str(p)!r}")
    if p.suffix == ".npy" or profile.capture.format == "npy":
        return NpyCapture(p, profile.config)
    return Dca1000Capture(p, profile.config, profile.capture)


def write_npy(path: str | Path, frames: Iterable[np.ndarray], n_frames: int,
              cfg: RadarConfig) -> int:
    """Write ``n_frames`` frames (n_chirps, num_rx, n_samples) as one (frames, chirps, rx,
    samples) ``.npy``, one frame at a time (complex64, or float32 for a real ADC); returns the
    number written (ValueError if ``frames`` holds fewer or more, or a frame of another
    shape; the file is then removed, never left half written)."""
    kind = np.complex64 if cfg.adc == "complex" else np.float32
    out = np.lib.format.open_memmap(path, mode="w+", dtype=kind, shape=(n_frames,
                                                                        *cfg.adc_shape))
    count = 0
    try:
        for frame in frames:
            x = np.asarray(frame)
            if count >= n_frames or x.shape != cfg.adc_shape or (x.dtype.kind == "c") != (
                    cfg.adc == "complex"):
                raise ValueError(f"frame {count}: expected {n_frames} {cfg.adc} frames of "
                                 f"shape {cfg.adc_shape}, got shape {x.shape}, dtype {x.dtype}")
            out[count] = x
            count += 1
        if count != n_frames:
            raise ValueError(f"frames: expected {n_frames}, got {count}")
        out.flush()
    except ValueError:
        del out
        Path(path).unlink()
        raise
    return count
