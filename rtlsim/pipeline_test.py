"""cocotb test run by :func:`rtlsim.pipeline_rtl.run_pipeline_rtl`: stream ADC frames
(``RADAR_RTL_ADC``: .npy of shape (frames, n_chirps, num_rx, n_range)) through
``radar_pipeline`` back to back, write the DMA packets to ``RADAR_RTL_DMA`` (.npz: ``words``
uint32 (total words, num_rx) and ``lengths``, words per packet) and the status to
``RADAR_RTL_STATUS`` (JSON). ``RADAR_RTL_CFAR_SCALES``: the CFAR_SCALE register table,
comma-separated (OUTPUT_MODE = 1; empty: none written)."""

from __future__ import annotations

import json
import os
from pathlib import Path

import cocotb
import numpy as np

from rtlsim.pipeline import PipelineTB


@cocotb.test()
async def stream_frames(dut) -> None:
    tb = PipelineTB(dut)
    frames = np.load(os.environ["RADAR_RTL_ADC"])
    tb.cfar_scales = [int(v, 0) for v in os.environ.get("RADAR_RTL_CFAR_SCALES", "").split(",")
                      if v]
    await tb.reset()
    for adc in frames:
        await tb.send_frame(adc)
    packets = await tb.recv_frames(len(frames), tb.frame_timeout_cycles())
    np.savez(os.environ["RADAR_RTL_DMA"], words=np.concatenate(packets).astype(np.uint32),
             lengths=np.array([len(p) for p in packets], dtype=np.int64))
    Path(os.environ["RADAR_RTL_STATUS"]).write_text(json.dumps(tb.status()))
