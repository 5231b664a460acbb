"""The chain model gives the same DMA bytes with the corner turn on chip (FRAME_STORE = 0)
and in external memory (FRAME_STORE = 1, through the store's real address layout), for the
cube (OUTPUT_MODE 0, read order (t, r, d)) and the detection records (OUTPUT_MODE 1, read
order (r, t, d))."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from model.config import RadarConfig, get_preset
from model.detect_chain import DetectConfig
from model.radar_pipeline import PipelineParams, dma_packets
from model.scene import PointTarget, Scene, table1_scene
from model.simulate import simulate_frame, simulate_scene

SMALL4 = RadarConfig(name="small4", num_tx=4, num_rx=4, n_range=32, n_doppler=32,
                     sample_rate_hz=10e6, chirp_period_s=4e-6, design_max_range_m=50.0)


def _same_dma(frames: list[np.ndarray], cfg: RadarConfig, params: PipelineParams) -> None:
    on_chip = dma_packets(frames, cfg, params)
    external = dma_packets(frames, cfg, replace(params, frame_store=True))
    assert len(on_chip) == len(external)
    for a, b in zip(on_chip, external, strict=True):
        assert a.tobytes() == b.tobytes()


def test_paper_fpga_table1() -> None:
    scene = table1_scene("paper-fpga", seed=1)
    frames = [simulate_scene(scene, k).samples for k in range(2)]
    _same_dma(frames, scene.config, PipelineParams(packet_words=1024))


@pytest.mark.parametrize("axi_data_w,tile_r", [(128, 4), (256, 8), (512, 32)])
def test_small_4tx(axi_data_w: int, tile_r: int) -> None:
    sc = Scene(preset="full", targets=(PointTarget(12.0, -20.0, -8.0, 5.0),)).scatterers()
    frames = [simulate_frame(SMALL4, sc, rng=np.random.default_rng([3, k]), frame_index=k)
              .samples for k in range(2)]
    _same_dma(frames, SMALL4, PipelineParams(packet_words=256, axi_data_w=axi_data_w,
                                             fs_tile_r=tile_r))


@pytest.mark.parametrize("tile_r", [None, 2, 8])
def test_small_4tx_detect(tile_r: int | None) -> None:
    """Mode 1 with the store (READ_ORDER = 1) gives the on-chip mode-1 record packets."""
    sc = Scene(preset="full", targets=(PointTarget(12.0, -20.0, -8.0, 5.0),
                                       PointTarget(30.0, 10.0, 4.0, 8.0))).scatterers()
    frames = [simulate_frame(SMALL4, sc, rng=np.random.default_rng([5, k]), frame_index=k)
              .samples for k in range(2)]
    det = DetectConfig(num_tx=4, num_rx=4, n_range=32, n_doppler=32, max_detections=24,
                       report=SMALL4.detection_bins)
    _same_dma(frames, SMALL4, PipelineParams(packet_words=64, output_mode=1, detect=det,
                                             fs_tile_r=tile_r))


def test_store_tile_r() -> None:
    """FS_TILE_R picked for the store: mode 1 keeps the mode-0 read buffer size."""
    full = get_preset("full")
    p0 = PipelineParams(frame_store=True, axi_data_w=512)
    p1 = replace(p0, output_mode=1)
    assert (p0.store_tile_r(full), p1.store_tile_r(full)) == (16, 4)
    assert (p0.store_geometry(full).strip_buffer_bits
            == p1.store_geometry(full).strip_buffer_bits == 4 << 20)
    assert p1.store_geometry(full).read_order == 1
    assert p1.hdl_parameters(full)["FS_TILE_R"] == 4
    assert replace(p1, fs_tile_r=16).store_tile_r(full) == 16
