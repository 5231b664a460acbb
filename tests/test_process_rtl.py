"""`radar process --backend rtl` on a real capture (docs/profiles.md): the OpenRadar frame
(2 TX x 4 RX, 128 samples x 128 loops, complex; tests/data/openradar) through the Verilated
``radar_pipeline`` built with the profile's HDL parameters (``rtlsim.harness``) against the
bit-accurate model: identical DMA bytes, identical points.

The plain chain is one harness build (about 35 s on an idle machine, two minutes on a loaded
one; then 0.25 s per frame). Static-clutter removal (STATIC_REMOVAL = 1) and the on-chip
detector (OUTPUT_MODE = 1, about four minutes loaded) are a build each:
``make test-process-rtl`` (``PROCESS_RTL=1``)."""

from __future__ import annotations

import json
import os
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from host.adc_capture import open_capture
from model.profile import load_profile
from model.radar_pipeline import PipelineParams, range_scale_for_peak
from radar.cli import main
from radar.sources import get_source

DATA = Path(__file__).parent / "data" / "openradar"
CFG_FILE = DATA / "openradar_2tx4rx.cfg"
BIN_FILE = DATA / "doppler_example_1.bin"
OPENRADAR = load_profile(CFG_FILE)
LONG = pytest.mark.skipif(os.environ.get("PROCESS_RTL", "0") in ("", "0"),
                          reason="an RTL build per chain (minutes): make test-process-rtl")


def process(tmp_path: Path, backend: str, *extra: str) -> dict:
    out = tmp_path / f"{backend}.json"
    assert main(["process", "--radar", str(CFG_FILE), "--capture", str(BIN_FILE), "--json",
                 str(out), "--backend", backend, *extra]) == 0
    return json.loads(out.read_text())


def dma_bytes_equal(remove_static: bool) -> None:
    """Two frames (the real one, then its chirps two loops on) through both chains built as
    ``radar process`` builds them: the same DMA bytes, packet for packet."""
    cfg = OPENRADAR.config
    frame = open_capture(BIN_FILE, OPENRADAR).frame(0)
    frames = [frame, np.roll(frame, 2 * cfg.num_tx, axis=0)]
    chain = PipelineParams(static_removal=remove_static)
    chain = replace(chain, range_scale_sch=range_scale_for_peak(cfg, 265, chain))
    model = list(get_source("model", chain).cube_packets(iter(frames), cfg))
    rtl = list(get_source("rtl", chain).cube_packets(iter(frames), cfg))
    assert len(model) == 2 * 32 and rtl == model


def same_points(tmp_path: Path, *extra: str) -> dict:
    """The capture through ``--backend rtl`` and ``--backend model``: the same JSON but for
    the backend's name."""
    rtl = process(tmp_path, "rtl", *extra)
    model = process(tmp_path, "model", *extra)
    assert rtl.pop("backend") == "rtl" and model.pop("backend") == "model"
    assert rtl == model and len(rtl["points"]) >= 10
    return rtl


def test_openradar_frame_rtl_equals_model(tmp_path):
    dma_bytes_equal(False)
    doc = same_points(tmp_path)
    assert len(doc["points"]) == 48 and doc["range_scale_sch"] == 0x3


@LONG
def test_openradar_frame_rtl_equals_model_static_removal(tmp_path):
    dma_bytes_equal(True)
    assert len(same_points(tmp_path, "--remove-static")["points"]) == 20   # the model's


@LONG
def test_openradar_frame_rtl_equals_model_on_chip_detector(tmp_path):
    doc = same_points(tmp_path, "--detect", "fpga")
    assert doc["frame_info"][0]["complete"] and doc["frame_info"][0]["records"] == 189
