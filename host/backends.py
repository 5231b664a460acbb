"""Where a frame's radar cube comes from: the FPGA chain's models (or, later, the RTL).

- ``model``: bit-accurate model of ``radar_pipeline`` (``model.pipeline``), fixed point,
  exactly what the FPGA sends; the cube is divided by the chain's gain so the host works in
  the float reference's units (LSB of a 1/N-per-FFT chain).
- ``float``: the float64 reference of the chain (``model.reference.radar_cube``), fast.
"""

from __future__ import annotations

import numpy as np

from model.config import RadarConfig
from model.pipeline import PipelineParams, chain_gain, run_chain
from model.reference import radar_cube

BACKENDS = ("model", "float", "rtl")


def cube_from_adc(adc: np.ndarray, cfg: RadarConfig, backend: str,
                  chain: PipelineParams | None = None) -> np.ndarray:
    """Radar cube complex (n_virtual, n_range, n_doppler) in reference units."""
    chain = chain or PipelineParams()
    if backend == "model":
        # complex64 like the cube decoded from the DMA stream, so both give identical clouds
        return run_chain(adc, cfg, chain).cube().astype(np.complex64) / chain_gain(cfg, chain)
    if backend == "float":
        return radar_cube(adc, cfg, chain.window, chain.window)
    raise ValueError(f"backend: {backend!r} is not a model backend (model, float)")
