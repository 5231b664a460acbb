"""Bit-accurate model of the whole FPGA chain: scaling, DMA packets, detections."""

import numpy as np
import pytest

from host.evaluate import match_targets
from host.pipeline import process_cube
from host.stream import StreamDecoder
from model.axis_packetizer import words_to_bytes
from model.config import get_preset
from model.radar_pipeline import PipelineParams, chain_gain, dma_packets, run_chain
from model.reference import radar_cube
from model.scene import table1_scene
from model.simulate import simulate_scene


def test_chain_gain():
    for name in ("paper-fpga", "full"):
        # range 1/N (gain 1), Doppler 0x555 on 8 stages -> 4 unscaled -> 16
        assert chain_gain(get_preset(name), PipelineParams()) == 16.0
    assert chain_gain(get_preset("full"), PipelineParams(doppler_scale_sch=0xFFF)) == 1.0


def test_chain_tracks_the_float_reference():
    scene = table1_scene("paper-fpga", seed=2)
    cfg = scene.config
    adc = simulate_scene(scene).samples
    out = run_chain(adc, cfg)
    assert out.range_overflow == 0 and out.doppler_overflow == 0
    fixed = out.cube()
    assert np.array_equal(fixed, np.round(fixed))
    ref = radar_cube(adc, cfg) * chain_gain(cfg, PipelineParams())
    err = fixed - ref
    # rounding noise of the fixed-point chain: well below the thermal noise it carries
    assert np.sqrt(np.mean(np.abs(err) ** 2)) < 0.5 * np.sqrt(np.mean(np.abs(ref[:, 40:]) ** 2))
    # the strong vehicles agree to a fraction of an LSB relative to their amplitude
    peak = np.unravel_index(np.argmax(np.abs(ref[0])), ref[0].shape)
    assert abs(fixed[0][peak] - ref[0][peak]) < 1e-2 * abs(ref[0][peak])


def test_same_detections_as_float():
    scene = table1_scene("paper-fpga", seed=3)
    cfg = scene.config
    adc = simulate_scene(scene).samples
    fixed = process_cube(run_chain(adc, cfg).cube() / 16.0, cfg)
    flt = process_cube(radar_cube(adc, cfg), cfg)
    mf, _ = match_targets(fixed, scene.targets, cfg)
    mr, _ = match_targets(flt, scene.targets, cfg)
    assert [m.index >= 0 for m in mf] == [m.index >= 0 for m in mr]
    for a, b in zip(mf, mr, strict=True):
        if a.index >= 0:
            assert a.range_err_m == pytest.approx(b.range_err_m, abs=0.05)
            assert a.azimuth_err_deg == pytest.approx(b.azimuth_err_deg, abs=0.2)


def test_dma_packets_decode_to_the_chain_cube():
    scene = table1_scene("paper-fpga", seed=1)
    cfg = scene.config
    adcs = [simulate_scene(scene, k).samples for k in range(2)]
    params = PipelineParams(packet_words=1000)  # last packet of a frame is short
    packets = dma_packets(adcs, cfg, params)
    dec = StreamDecoder(cfg, params.packet_words)
    frames = [f for p in packets for f in dec.push_packet(words_to_bytes(p))] + dec.flush()
    assert [f.frame_id for f in frames] == [0, 1] and all(f.complete for f in frames)
    for f, adc in zip(frames, adcs, strict=True):
        assert np.array_equal(f.cube, run_chain(adc, cfg, params).cube())


def test_bad_inputs():
    cfg = get_preset("paper-fpga")
    with pytest.raises(ValueError, match="expected shape"):
        run_chain(np.zeros((3, 4, 64), complex), cfg)
    with pytest.raises(ValueError, match="packet_words"):
        dma_packets([np.zeros((256, 4, 64), complex)], cfg, PipelineParams(packet_words=1))
