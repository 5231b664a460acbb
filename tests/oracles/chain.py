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
    """``run_chain`` of adc, (num_tx * n_loops, num_rx, n_samples) int16 I/Q (complex, or
    real for a real ADC), through the reference FFT (slow)."""
    params = params or PipelineParams()
    params.check_mode(cfg)
    cfg.check_adc(adc)
    nr = cfg.n_range_bins
    rng = fft_fixed_reference(np.transpose(adc, (0, 2, 1)), window=params.window,
                              scale_sch=params.range_schedule(cfg), n_fft=cfg.n_range)
    turned = turn(rng.y[:, :nr].reshape(-1, cfg.num_rx), cfg, params)   # chirp-major input
    dop = fft_fixed_reference(turned.reshape(-1, cfg.n_loops, cfg.num_rx),
                              window=params.window, scale_sch=params.doppler_scale_sch,
                              n_fft=cfg.n_doppler)
    return chain_output(dop.y.reshape(-1, cfg.num_rx), int(rng.overflow[:, :nr].sum()),
                        int(dop.overflow.sum()), cfg, params)
