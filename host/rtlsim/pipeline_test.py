"""cocotb test run by :func:`host.rtlsim.pipeline_rtl.run_pipeline_rtl`: stream ADC frames
(``RADAR_RTL_ADC``: .npy of shape (frames, n_chirps, num_rx, n_range)) through
``radar_pipeline`` back to back, write the DMA packets to ``RADAR_RTL_DMA`` (.dmacap) and
the status to ``RADAR_RTL_STATUS`` (JSON)."""

from __future__ import annotations

import json
import os
from pathlib import Path

import cocotb
import numpy as np

from host.capture import CaptureInfo, write_capture
from host.rtlsim.driver import PipelineTB


@cocotb.test()
async def stream_frames(dut) -> None:
    tb = PipelineTB(dut)
    frames = np.load(os.environ["RADAR_RTL_ADC"])
    await tb.reset()
    for adc in frames:
        await tb.send_frame(adc)
    packets = await tb.recv_frames(len(frames), tb.frame_timeout_cycles())
    info = CaptureInfo(tb.num_rx, tb.packet_words, tb.num_tx, tb.n_range, tb.n_doppler)
    write_capture(Path(os.environ["RADAR_RTL_DMA"]), info,
                  [np.ascontiguousarray(p, dtype="<u4").tobytes() for p in packets])
    Path(os.environ["RADAR_RTL_STATUS"]).write_text(json.dumps(tb.status()))
