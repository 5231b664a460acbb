"""End-to-end cocotb regression of ``radar_pipeline`` on radar shapes other than the presets'
(docs/profiles.md): fewer samples per chirp than the range FFT (N_SAMPLES), fewer loops than
the Doppler FFT (N_LOOPS), both zero-filled inside the FFTs, and a real ADC (REAL_ADC: the I
half of each lane, the range FFT's positive half). Frames of the simulator go through the
RTL with chirp bursts and DMA stalls; the DMA packets are bit-identical to the model's
(``model.radar_pipeline.dma_packets``), the host decodes them with the profile's geometry
(``host.stream``) and finds the model backend's detections."""

from __future__ import annotations

from pathlib import Path

import cocotb
import numpy as np
import pytest
from test_radar_pipeline import assert_model_detections, decode, watched

from model.config import RadarConfig
from model.radar_pipeline import PipelineParams, run_chain
from model.scene import PointTarget, Scene
from model.simulate import simulate_frame
from rtlsim.axis import chirp_bursts, random_pause
from rtlsim.pipeline import PipelineTB
from rtlsim.pipeline_rtl import PIPELINE_SOURCES
from rtlsim.toolchain import param, rtl_sources, run_cocotb


def _cfg(name: str, **shape) -> RadarConfig:
    return RadarConfig(name=name, num_rx=4, sample_rate_hz=10e6, chirp_period_s=30e-6,
                       design_max_range_m=30.0, **shape)


SETS = {
    # 50 of 64 samples, 15 of 16 loops, 2 TX, static removal over the 15 loops
    "padded": (_cfg("padded", num_tx=2, n_range=64, n_doppler=16, samples_per_chirp=50,
                    loops=15),
               PipelineParams(packet_words=256, static_removal=True)),
    # a real ADC (32 range bins out), 15 of 32 loops (a map the host CFAR window fits)
    "padded-real": (_cfg("padded-real", num_tx=2, n_range=64, n_doppler=32,
                         samples_per_chirp=50, loops=15, adc="real"),
                    PipelineParams(packet_words=256)),
    # the TI setting of the issue: 200 of 256 samples, 255 of 256 loops, real ADC
    "ti-real": (_cfg("ti-real", num_tx=1, n_range=256, n_doppler=256, samples_per_chirp=200,
                     loops=255, adc="real"),
                PipelineParams(packet_words=1024)),
}
TARGETS = (PointTarget(12.0, -20.0, -8.0, 5.0), PointTarget(25.0, 15.0, 3.0, 20.0))
FRAMES = {"padded": 3, "padded-real": 3, "ti-real": 2}


def set_of(tb: PipelineTB) -> tuple[str, RadarConfig, PipelineParams]:
    """The parameter set the simulation was built with."""
    for name, (cfg, chain) in SETS.items():
        hdl = chain.hdl_parameters(cfg)
        if all(param(k, v) == v for k, v in hdl.items()):
            return name, cfg, chain
    raise AssertionError("unknown parameter set")


@cocotb.test()
async def profile_frames_bit_exact(dut) -> None:
    """Frames back to back, chirps at one sample per clock with idle gaps, 30 % DMA stalls;
    a real ADC's Q halves driven with noise (ignored): packets bit-exact with the model,
    clean status, every chirp counted, the host's decoded cubes the model's, and (where the
    map holds the host CFAR's window) its detections on them the model backend's."""
    tb = watched(dut)
    name, cfg, chain = set_of(tb)
    n = FRAMES[name]
    sc = Scene(preset="full", targets=TARGETS).scatterers()
    frames = [simulate_frame(cfg, sc, rng=np.random.default_rng([3, k]), frame_index=k).samples
              for k in range(n)]
    rng = np.random.default_rng(4)
    # chirp gaps that leave the DMA at 70 % twice the time it needs for a frame's words
    words = chain.frame_words(cfg)
    idle = max(cfg.n_samples // 2, -(-3 * words // cfg.n_chirps) - cfg.n_samples)
    sent = frames
    if cfg.adc == "real":           # Q lanes carry junk the RTL must ignore
        sent = [adc + 1j * rng.integers(-32768, 32768, adc.shape) for adc in frames]
    got = await tb.stream_under_stalls(frames, cfg, chain, name,
                                       idle=chirp_bursts(cfg.n_samples, idle),
                                       backpressure=random_pause(0.3, 5), timeout_frames=4,
                                       sent=sent)
    decoded = decode(cfg, chain, got)
    assert [f.complete for f in decoded] == [True] * n
    assert decoded[0].cube.shape == cfg.cube_shape
    for f, adc in zip(decoded, frames, strict=True):
        assert np.array_equal(f.cube, run_chain(adc, cfg, chain).cube())
        if cfg.n_doppler >= 32:      # the default CFAR window (23 Doppler cells) fits
            assert_model_detections(f.cube, adc, cfg, chain, 1)
    tb.dut._log.info("%s: %d frames bit-exact, cube %s", name, n, cfg.cube_shape)


@pytest.mark.parametrize("name", list(SETS))
def test_radar_pipeline_shapes(name: str) -> None:
    cfg, chain = SETS[name]
    run_cocotb("radar_pipeline", rtl_sources(*PIPELINE_SOURCES),
               "test_radar_pipeline_shapes", Path(__file__).parent, chain.hdl_parameters(cfg))
