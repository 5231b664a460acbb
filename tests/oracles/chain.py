"""Oracle of ``model.radar_pipeline.run_chain``: the chain through the stage-by-stage int64
FFT (``model.fft_axis.fft_fixed_reference``) instead of the planar fast path; the same words
(tests/test_model_fast.py, tests/test_pipeline_mode1.py)."""

from __future__ import annotations

import numpy as np

from model.config import RadarConfig
from model.fft_axis import fft_fixed_reference
from model.radar_pipeline import ChainOutput, PipelineParams, chain_output, turn


def run_chain_reference(adc: np.ndarray, cfg: RadarConfig,
                        params: PipelineParams | None = None) -> ChainOutput:
    """``run_chain`` of adc, complex (num_tx * n_doppler, num_rx, n_range) int16 I/Q, through
    the reference FFT (slow)."""
    params = params or PipelineParams()
    params.check_mode(cfg)
    cfg.check_adc(adc)
    rng = fft_fixed_reference(np.transpose(adc, (0, 2, 1)), window=params.window,
                              scale_sch=params.range_scale_sch)
    turned = turn(rng.y.reshape(-1, cfg.num_rx), cfg, params)     # chirp-major input order
    dop = fft_fixed_reference(turned.reshape(-1, cfg.n_doppler, cfg.num_rx),
                              window=params.window, scale_sch=params.doppler_scale_sch)
    return chain_output(dop.y.reshape(-1, cfg.num_rx), int(rng.overflow.sum()),
                        int(dop.overflow.sum()), cfg, params)
