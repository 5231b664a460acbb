"""The points of the real TI frame (``tests/data/openradar``), pinned bit for bit: what
``radar process`` makes of it at the settings ``benchmarks/bench_openradar.py`` compares with
OpenRadar (:func:`benchmarks.bench_openradar.modes`, with ``--remove-static``) and at the
defaults without static removal, every field of every point, against
``tests/data/openradar/points_pinned.json``. A change meant to speed the per-frame path up
must leave them as they are; a change meant to move them rewrites the file
(``python -m tests.test_openradar_points``) and says why. The values were written on this
project's machine; numpy's and scipy's SIMD paths may round a last bit differently on another
CPU, so integer and flag fields must match exactly and float fields to :data:`RTOL` (a
speed-up checked on this machine shows the same bytes: ``PIN_BITS=1``)."""

from __future__ import annotations

import json
import os
from dataclasses import fields
from pathlib import Path

import numpy as np
import pytest

from benchmarks.bench_openradar import modes
from host.adc_capture import open_capture
from host.pointcloud import PointCloud
from radar.cli import build_parser
from radar.commands.process import capture_frame_cloud, process_params, profile_of

DATA = Path(__file__).parent / "data" / "openradar"
CFG_FILE = DATA / "openradar_2tx4rx.cfg"
BIN_FILE = DATA / "doppler_example_1.bin"
PINNED = DATA / "points_pinned.json"
SETTINGS = {**{f"{name} --remove-static": ("--remove-static", *extra)
               for name, extra in modes(15.0).items()}, "default": ()}
"""The pinned settings by name: ``radar process`` options."""
RTOL = 1e-9
"""Relative tolerance of float fields (a moved point moves by far more; 1e-12 absolute
around zero)."""


def clouds() -> dict[str, PointCloud]:
    """Frame 0's point cloud at each of :data:`SETTINGS`, through the benchmark's path
    (``radar.commands.process.capture_frame_cloud``)."""
    profile = profile_of(str(CFG_FILE))
    adc = open_capture(BIN_FILE, profile).frame(0)
    out = {}
    for name, options in SETTINGS.items():
        args = build_parser().parse_args(["process", "--radar", str(CFG_FILE), "--capture",
                                          str(BIN_FILE), "--json", "-", *options])
        params = process_params(args, profile)[0]
        out[name] = capture_frame_cloud(adc, profile.config, params, 0,
                                        args.remove_static).cloud
    return out


def as_lists(cloud: PointCloud) -> dict[str, list]:
    """Every field of ``cloud`` as a list (floats exact through JSON: repr round-trips)."""
    return {f.name: getattr(cloud, f.name).tolist() for f in fields(PointCloud)}


@pytest.mark.parametrize("name", list(SETTINGS))
def test_points_of_the_real_frame_pinned(name):
    pinned = json.loads(PINNED.read_text())[name]
    got = as_lists(clouds()[name])
    assert len(got["range_m"]) == len(pinned["range_m"]) > 0
    for field, values in pinned.items():
        g, w = np.asarray(got[field]), np.asarray(values)
        assert g.shape == w.shape, field
        if os.environ.get("PIN_BITS") == "1":
            assert g.tobytes() == w.tobytes(), field
        elif np.issubdtype(w.dtype, np.floating):
            np.testing.assert_allclose(g, w, rtol=RTOL, atol=1e-12, err_msg=field)
        else:
            assert np.array_equal(g, w), field


if __name__ == "__main__":
    PINNED.write_text(json.dumps({k: as_lists(c) for k, c in clouds().items()}) + "\n")
