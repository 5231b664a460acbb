"""``radar detect --backend rtl``: ADC frames through the Verilated ``radar_pipeline``.

The model is built once per parameter set under ``sim_build/radar_pipeline/`` (the first
run compiles for a minute or two), then the frames stream through it back to back at one
sample per clock and the DMA packets come back as bytes, exactly as the board sends them.
"""

from __future__ import annotations

import json
import tempfile
from pathlib import Path

import numpy as np

from host.capture import read_capture
from host.rtlsim.toolchain import build_and_test, rtl_sources
from model.config import RadarConfig
from model.pipeline import PipelineParams

PIPELINE_SOURCES = ("common/*.sv", "fft/*.sv", "buffers/*.sv", "top/*.sv")


def hdl_parameters(cfg: RadarConfig, chain: PipelineParams) -> dict[str, int]:
    """``radar_pipeline`` HDL parameters for a radar configuration and chain settings."""
    return {"NUM_RX": cfg.num_rx, "NUM_TX": cfg.num_tx, "N_RANGE": cfg.n_range,
            "N_DOPPLER": cfg.n_doppler, "DATA_W": 16, "PACKET_WORDS": chain.packet_words,
            "WINDOW": int(chain.window), "RANGE_SCALE_SCH": chain.range_scale_sch,
            "DOPPLER_SCALE_SCH": chain.doppler_scale_sch, "HEADER": int(chain.header)}


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
                       "host.rtlsim.pipeline_test", hdl_parameters(cfg, chain),
                       extra_env={"RADAR_RTL_ADC": str(d / "adc.npy"),
                                  "RADAR_RTL_DMA": str(d / "dma.dmacap"),
                                  "RADAR_RTL_STATUS": str(d / "status.json")},
                       testcase="stream_frames")
        if not (d / "dma.dmacap").exists():
            raise RuntimeError("the RTL simulation produced no DMA stream (see its log)")
        _, packets = read_capture(d / "dma.dmacap")
        return list(packets), json.loads((d / "status.json").read_text())
