"""ADC frames through the Verilated ``radar_pipeline`` from ordinary Python, driven by cocotb
(:mod:`rtlsim.pipeline_test`, :class:`rtlsim.pipeline.PipelineTB`), and the top's RTL file
list :data:`PIPELINE_SOURCES`.

``radar detect --backend rtl`` runs the faster C++ harness (:mod:`rtlsim.harness`);
:func:`run_pipeline_rtl` is the cocotb path the harness is checked against
(``tb/radar_pipeline/test_harness.py``: identical DMA bytes and counters) and timed against
(``tb/radar_pipeline/bench_harness.py``). The model is built once per parameter set under
``sim_build/radar_pipeline/`` (the first run compiles for a minute or two), then the frames
stream through it back to back at one sample per clock and the DMA packets come back as
bytes, exactly as the board sends them.
"""

from __future__ import annotations

import json
import tempfile
from pathlib import Path

import numpy as np

from model.axis_packetizer import words_to_bytes
from model.config import RadarConfig
from model.radar_pipeline import PipelineParams
from rtlsim.toolchain import build_and_test, rtl_sources

PIPELINE_SOURCES = ("common/*.sv", "fft/*.sv", "buffers/*.sv", "detect/*.sv", "regs/*.sv",
                    "top/*.sv")
"""Globs (under ``rtl/``) of the files the ``radar_pipeline`` top elaborates."""


def _cfar_scales(cfg: RadarConfig, chain: PipelineParams) -> str:
    """The CFAR_SCALE register table, comma-separated hex (mode 1; empty in mode 0)."""
    return ",".join(hex(v) for v in chain.cfar_scales(cfg)) if chain.output_mode == 1 else ""


def run_pipeline_rtl(adc_frames: list[np.ndarray], cfg: RadarConfig,
                     chain: PipelineParams | None = None) -> tuple[list[bytes], dict[str, int]]:
    """Stream ``adc_frames`` (each complex (n_chirps, num_rx, n_range)) through the RTL.

    Returns (DMA packets as bytes in arrival order, the pipeline's status counters)."""
    chain = chain or PipelineParams()
    chain.check(cfg)
    with tempfile.TemporaryDirectory(prefix="radar_rtl_") as tmp:
        d = Path(tmp)
        np.save(d / "adc.npy", np.stack(adc_frames).astype(np.complex64))
        build_and_test("radar_pipeline", rtl_sources(*PIPELINE_SOURCES),
                       "rtlsim.pipeline_test", chain.hdl_parameters(cfg),
                       extra_env={"RADAR_RTL_ADC": str(d / "adc.npy"),
                                  "RADAR_RTL_DMA": str(d / "dma.npz"),
                                  "RADAR_RTL_STATUS": str(d / "status.json"),
                                  "RADAR_RTL_CFAR_SCALES": _cfar_scales(cfg, chain)},
                       testcase="stream_frames")
        if not (d / "dma.npz").exists():
            raise RuntimeError("the RTL simulation produced no DMA stream (see its log)")
        with np.load(d / "dma.npz") as dma:
            ends = np.cumsum(dma["lengths"])
            packets = [words_to_bytes(p) for p in np.split(dma["words"], ends[:-1])]
        return packets, json.loads((d / "status.json").read_text())
