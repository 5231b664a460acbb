"""A :class:`radar.view.feed.ViewFrame` -> the JSON message one browser draws.

Heat maps are reduced before they leave the host: max-pooled (so a one-cell target never
disappears) to at most :data:`MAX_AXIS` cells per axis (``full`` 256 x 256 -> 128 x 128),
converted to dB, and quantised to 8 bits over [``lo``, ``hi``] dB (``lo``: a little under the
median, i.e. the noise floor; ``hi``: the peak; both rounded out to a 5 dB grid so the
colour scale is steady), sent as base64. The page maps a code q back
to ``lo + q * (hi - lo) / 255`` dB. Doppler is shifted so velocity increases left to right.
"""

from __future__ import annotations

import base64
import functools
import json
import math
import threading
from collections import OrderedDict
from typing import Any

import numpy as np

from host.records import RecordArrays
from model.array import has_vertical_extent
from model.config import RadarConfig
from model.reference import signed_bins
from radar.view.feed import ViewFrame

MAX_AXIS = 128
"""Largest heat-map size per axis sent to the browser, cells."""

FLOOR_BELOW_MEDIAN_DB = 3.0
"""The colour scale starts this far below the map's median (noise floor), dB."""

SCALE_STEP_DB = 5.0
"""Colour-scale limits are rounded out to multiples of this, dB."""


def pool_max(a: np.ndarray, max_axis: int = MAX_AXIS) -> np.ndarray:
    """Max-pool a 2-D array by integer factors so neither axis exceeds ``max_axis``
    (axes whose length is not a multiple of the factor are cropped at the end)."""
    fr = max(1, math.ceil(a.shape[0] / max_axis))
    fc = max(1, math.ceil(a.shape[1] / max_axis))
    r, c = a.shape[0] // fr, a.shape[1] // fc
    a = a[:r * fr, :c * fc]
    # element-wise maximum of the fr * fc strided sub-grids: ~4x faster than a reduction
    # over reshaped axes for the small factors used here
    out = a[::fr, ::fc].copy()
    for i in range(fr):
        for j in range(fc):
            if i or j:
                np.maximum(out, a[i::fr, j::fc], out=out)
    return out


def pool_axis(x: np.ndarray, n_out: int) -> np.ndarray:
    """Centre of each group when ``x`` (n,) is pooled down to ``n_out`` groups."""
    f = len(x) // n_out
    return x[:n_out * f].reshape(n_out, f).mean(axis=1)


def velocity_axis(cfg: RadarConfig) -> np.ndarray:
    """Velocity of each fft-shifted Doppler bin, m/s (n_doppler,), increasing."""
    return (np.arange(cfg.n_doppler) - cfg.n_doppler // 2) * cfg.velocity_bin_mps


def range_axis(cfg: RadarConfig) -> np.ndarray:
    """Range of each range bin, m (n_range,)."""
    return np.arange(cfg.n_range) * cfg.range_bin_m


@functools.lru_cache(maxsize=16)
def _axes(cfg: RadarConfig, rows: int, cols: int) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """(range_m of the rows, velocity_mps of the columns) of a pooled map, rounded (the same
    for every frame of a preset: computed once)."""
    return (tuple(_r(pool_axis(range_axis(cfg), rows))),
            tuple(_r(pool_axis(velocity_axis(cfg), cols))))


def heatmap(power: np.ndarray, cfg: RadarConfig) -> dict[str, Any]:
    """Power map float (n_range, n_doppler), linear -> quantised heat-map message part."""
    shifted = np.fft.fftshift(power, axes=1)
    pooled = pool_max(shifted)
    db = 10 * np.log10(np.maximum(pooled, 1e-20))
    # on a SCALE_STEP_DB grid: the colour scale stays put from frame to frame, so the page
    # redraws only the image, not the colour bar
    hi = SCALE_STEP_DB * math.ceil(float(db.max()) / SCALE_STEP_DB)
    lo = min(SCALE_STEP_DB * math.floor((float(np.median(db)) - FLOOR_BELOW_MEDIAN_DB)
                                        / SCALE_STEP_DB), hi - SCALE_STEP_DB)
    q = np.clip(np.rint((db - lo) * (255.0 / (hi - lo))), 0, 255).astype(np.uint8)
    range_m, velocity_mps = _axes(cfg, int(q.shape[0]), int(q.shape[1]))
    return {"q": base64.b64encode(q.tobytes()).decode("ascii"),
            "rows": int(q.shape[0]), "cols": int(q.shape[1]),
            "lo": round(lo, 2), "hi": round(hi, 2),
            "range_m": range_m, "velocity_mps": velocity_mps}


def box_outline(obj: dict[str, Any]) -> tuple[list[float], list[float]]:
    """Closed outline (x, y lists, 5 corners) of a GNN object's rotated box, m."""
    h = math.radians(obj["heading_deg"])
    c, s = math.cos(h), math.sin(h)
    half_l, half_w = obj["length_m"] / 2, obj["width_m"] / 2
    xs, ys = [], []
    for dl, dw in ((1, 1), (1, -1), (-1, -1), (-1, 1), (1, 1)):
        xs.append(round(obj["x_m"] + c * dl * half_l - s * dw * half_w, 3))
        ys.append(round(obj["y_m"] + s * dl * half_l + c * dw * half_w, 3))
    return xs, ys


def _r(a: np.ndarray, nd: int = 3) -> list[float]:
    return [round(float(v), nd) for v in a]


def record_cells(rec: RecordArrays, cfg: RadarConfig) -> dict[str, list[float]]:
    """A record stream's cells (every record, n of them) as the page draws them in the
    range-Doppler plane and over range: range m, radial velocity m/s (the cell's signed
    Doppler bin, as the heat maps' axis), integrated power dB and CFAR SNR dB (power over
    the noise estimate), each a list of n."""
    with np.errstate(divide="ignore", invalid="ignore"):
        db = 10 * np.log10(np.maximum(rec.power, 1e-20))
        snr = 10 * np.log10(np.maximum(rec.power, 1e-20) / np.maximum(rec.noise, 1e-20))
    return {"range": _r(rec.range_bin * cfg.range_bin_m),
            "v": _r(signed_bins(cfg.n_doppler)[rec.doppler_bin] * cfg.velocity_bin_mps),
            "db": _r(db, 1), "snr": _r(snr, 1)}


def frame_message(frame: ViewFrame, channel: int, health: dict[str, Any]) -> dict[str, Any]:
    """The message for one frame with virtual channel ``channel`` (clamped to the array);
    its ``points`` (lists of n): x, y m, v m/s, snr dB, range m, and, when the radar's array
    has vertical extent (``model.array.has_vertical_extent``, as the point JSON), z m and
    el (elevation) deg."""
    cfg = frame.cfg
    ch = min(max(int(channel), 0), cfg.n_virtual - 1)
    cloud = frame.cloud
    msg: dict[str, Any] = {
        "type": "frame", "seq": frame.seq, "frame_id": frame.frame_id, "preset": cfg.name,
        "source": frame.source, "channel": ch, "n_virtual": cfg.n_virtual,
        "limits": {"max_range_m": round(cfg.max_range_m, 2),
                   "max_velocity_mps": round(cfg.max_velocity_mps, 3)},
        "rd": None, "nci": None, "profile": None, "cells": None,
        "points": {"x": _r(cloud.x_m), "y": _r(cloud.y_m),
                   "v": _r(cloud.radial_velocity_mps), "snr": _r(cloud.snr_db, 1),
                   "range": _r(cloud.range_m)},
        "boxes": [],
        "health": health,
    }
    if has_vertical_extent(cfg.virtual_positions_hw):   # as the point JSON (PointCloud)
        msg["points"].update(z=_r(cloud.z_m), el=_r(cloud.elevation_deg, 2))
    if frame.cube is not None:
        p = frame.cube[ch].real.astype(np.float32) ** 2 + frame.cube[ch].imag.astype(
            np.float32) ** 2
        msg["rd"] = heatmap(p, cfg)
    if frame.nci is not None:
        msg["nci"] = heatmap(frame.nci, cfg)
        prof = 10 * np.log10(np.maximum(frame.nci.sum(axis=1), 1e-20))
        msg["profile"] = {"kind": "cube", "range_m": _axes(cfg, cfg.n_range, cfg.n_doppler)[0],
                          "db": _r(prof, 2),
                          "det_range_m": _r(cloud.range_m),
                          "det_db": _r(prof[np.clip(cloud.range_bin, 0, cfg.n_range - 1)]
                                       if len(cloud) else np.zeros(0), 2)}
    if frame.records is not None:
        msg["cells"] = cells = record_cells(frame.records, cfg)
        if frame.nci is None:  # the profile the records allow: their powers over range
            best = np.full(cfg.n_range, min(cells["db"], default=0.0))
            np.maximum.at(best, frame.records.range_bin, np.asarray(cells["db"]))
            msg["profile"] = {"kind": "records", "range_m": cells["range"], "db": cells["db"],
                              "det_range_m": _r(cloud.range_m),
                              "det_db": _r(best[np.clip(cloud.range_bin, 0, cfg.n_range - 1)]
                                           if len(cloud) else np.zeros(0), 1)}
    for o in frame.objects:
        xs, ys = box_outline(o)
        msg["boxes"].append({"x": xs, "y": ys, "cls": o["class"],
                             "label": f"{o['class']} {o['score']:.2f}",
                             "cx": round(o["x_m"], 3), "cy": round(o["y_m"], 3)})
    return msg


class MessageCache:
    """Serialised frame messages by (frame seq, channel), so browsers watching the same
    channel share the work. Health is refreshed per send (it is cheap and changes often)."""

    def __init__(self, size: int = 8) -> None:
        self._lock = threading.Lock()
        self._items: OrderedDict[tuple[int, int], dict[str, Any]] = OrderedDict()
        self.size = size

    def get(self, frame: ViewFrame, channel: int, health: dict[str, Any]) -> str:
        key = (frame.seq, channel)
        with self._lock:
            msg = self._items.get(key)
        if msg is None:
            msg = frame_message(frame, channel, {})
            with self._lock:
                self._items[key] = msg
                while len(self._items) > self.size:
                    self._items.popitem(last=False)
        return json.dumps({**msg, "health": health}, separators=(",", ":"))
