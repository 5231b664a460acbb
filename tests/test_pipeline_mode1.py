"""Bit-accurate model of the whole chain in OUTPUT_MODE = 1 (on-chip detection, DESIGN 3.4):
the record stream is the detector model on the chain's Doppler output, in the packetizer's
framing; mode 0 is unchanged."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from host.pipeline import process_cube
from model.axis_packetizer import depacketize, pack_iq, parse_header
from model.config import RadarConfig, get_preset
from model.detect_chain import DetectConfig, detect_stream
from model.detect_records import decode_frame
from model.radar_pipeline import (
    FrameSettings,
    PipelineParams,
    chain_gain,
    dma_packets,
    record_frames,
    run_chain,
)
from model.scene import PointTarget, Scene, table1_scene
from model.simulate import simulate_frame, simulate_scene
from tests.oracles.chain import run_chain_reference

SMALL4 = RadarConfig(name="small4", num_tx=4, num_rx=4, n_range=32, n_doppler=32,
                     sample_rate_hz=10e6, chirp_period_s=4e-6, design_max_range_m=50.0)


def small4_frames(n: int) -> list[np.ndarray]:
    sc = Scene(preset="full", targets=(PointTarget(12.0, -20.0, -8.0, 5.0),
                                       PointTarget(30.0, 15.0, 11.0, 20.0))).scatterers()
    return [simulate_frame(SMALL4, sc, rng=np.random.default_rng([1, k]), frame_index=k).samples
            for k in range(n)]


def small4_detect(**kw: object) -> DetectConfig:
    return DetectConfig(num_tx=4, num_rx=4, n_range=32, n_doppler=32, guard=(1, 1),
                        train=(2, 4), **kw)


def test_mode0_parameters_unchanged() -> None:
    cfg = get_preset("paper-fpga")
    p0 = PipelineParams().hdl_parameters(cfg)
    assert "OUTPUT_MODE" not in p0 and "MAX_DETECTIONS" not in p0
    p1 = PipelineParams(output_mode=1).hdl_parameters(cfg)
    assert {k: v for k, v in p1.items() if k in p0} == p0
    d = DetectConfig(num_tx=1, num_rx=4, n_range=64, n_doppler=256)
    assert p1["OUTPUT_MODE"] == 1 and p1["MAX_DETECTIONS"] == d.max_detections
    assert (p1["GUARD_R"], p1["GUARD_D"], p1["TRAIN_R"], p1["TRAIN_D"]) == (2, 2, 4, 8)
    assert p1["CFAR_KIND"] == 0


def test_detect_sizes_must_match_the_radar() -> None:
    with pytest.raises(ValueError, match="do not match"):
        PipelineParams(output_mode=1, detect=small4_detect()).check(get_preset("paper-fpga"))
    with pytest.raises(ValueError, match="output_mode=2"):
        PipelineParams(output_mode=2).check(SMALL4)


def test_small4_records_are_the_detector_on_the_cube() -> None:
    """Mode 1 reads the corner turn (r, t, d): the same Doppler values as mode 0's cube, and
    the record stream is detect_stream on them (independent transposition here)."""
    frames = small4_frames(2)
    p1 = PipelineParams(packet_words=256, output_mode=1, detect=small4_detect())
    for adc in frames:
        c0 = run_chain(adc, SMALL4, PipelineParams(packet_words=256))
        c1 = run_chain(adc, SMALL4, p1)
        assert c0.records is None
        np.testing.assert_array_equal(c1.payload, c0.payload)
        rtd = pack_iq(c0.payload.transpose(1, 0, 2, 3).reshape(-1, 4))
        np.testing.assert_array_equal(c1.records, detect_stream([rtd], p1.detect)[0])
    recs = record_frames(frames, SMALL4, p1)
    rec = decode_frame(recs[1], 4)
    assert not rec.errors and rec.trailer.frame_id == 1 and len(rec.records) >= 2


def test_reference_path_equals_fast_path_in_mode1() -> None:
    adc = small4_frames(1)[0]
    p1 = PipelineParams(packet_words=256, output_mode=1, detect=small4_detect())
    a, b = run_chain(adc, SMALL4, p1), run_chain_reference(adc, SMALL4, p1)
    np.testing.assert_array_equal(a.records, b.records)


def test_paper_fpga_packets_carry_the_table1_detections() -> None:
    scene = table1_scene("paper-fpga", seed=1)
    cfg = scene.config
    adcs = [simulate_scene(scene, k).samples for k in range(2)]
    params = PipelineParams(packet_words=1000, output_mode=1)
    packets = dma_packets(adcs, cfg, params, first_frame_id=5)
    fw = params.frame_words(cfg)
    assert fw == params.detect_config(cfg).frame_words
    assert [parse_header(p[0]).frame_id for p in packets][::len(packets) // 2] == [5, 6]
    frames = depacketize(packets, fw, params.packet_words, cfg.num_rx)
    assert len(frames) == 2 and all(f.complete for f in frames)
    lo, hi = cfg.detection_bins
    for k, f in enumerate(frames):
        rf = decode_frame(f.words, cfg.num_tx)
        assert not rf.errors and rf.trailer.frame_id == 5 + k
        cells = {(r.range_bin, r.doppler_bin) for r in rf.records}
        assert cells and all(lo <= r < hi for r, _ in cells)
        # every point the host finds from the same frame's cube is a record
        host = process_cube(run_chain(adcs[k], cfg).cube() / chain_gain(cfg, params), cfg)
        assert len(host.range_bin) >= 3
        for r, d in zip(host.range_bin, host.doppler_bin, strict=True):
            assert (int(r), int(d) % cfg.n_doppler) in cells


def test_truncation_is_counted_and_sticky() -> None:
    frames = small4_frames(3)
    p1 = PipelineParams(packet_words=64, output_mode=1,
                        detect=small4_detect(max_detections=1, pfa=1e-2))
    packets = dma_packets(frames, SMALL4, p1)
    dec = depacketize(packets, p1.frame_words(SMALL4), 64, 4)
    trailers = [decode_frame(f.words, 4).trailer for f in dec]
    assert all(t.detections > 1 and t.records == 1 for t in trailers)
    assert all(t.truncated and t.truncated_sticky for t in trailers)


def test_report_rows_only_mask_the_decision() -> None:
    """REPORT_LO/HI (``Cfar2dConfig.report``): rows outside never detect but still train;
    inside, the decisions equal the unrestricted CFAR's."""
    from dataclasses import replace

    from model import cfar_2d as cm

    rng = np.random.default_rng(3)
    p = rng.gamma(4, 1000.0, (32, 32)).astype(np.int64)
    p[[0, 1, 10, 30, 31], [3, 9, 20, 5, 7]] *= 200
    full = cm.Cfar2dConfig(n_range=32, n_doppler=32, pow_w=34, guard=(1, 1), train=(2, 4))
    part = replace(full, report=(1, 28))
    a = cm.cfar_2d(p, full, cm.scale_table(full, 1e-3, 4))
    b = cm.cfar_2d(p, part, cm.scale_table(part, 1e-3, 4))
    assert a.detect[[0, 30, 31]].any() and not b.detect[[0, 28, 29, 30, 31]].any()
    np.testing.assert_array_equal(b.detect[1:28], a.detect[1:28])
    np.testing.assert_array_equal(b.train_sum, a.train_sum)
    assert part.hdl_parameters()["REPORT_HI"] == 28 and "REPORT_LO" not in full.hdl_parameters()


def test_run_time_kind_and_local_max_per_frame() -> None:
    """FrameSettings.kinds / local_max: frame k's records are those of a detector run with
    frame k's kind and local-maximum switch (the registers at that frame's start); the top's
    parameters carry OS_BUILD, OS_RANK and the reset local maximum, not a run_kind."""
    base = small4_detect(max_detections=32, pfa=1e-3)
    params = PipelineParams(packet_words=64, output_mode=1, detect=base)
    frames = small4_frames(3)
    kinds, lm = ["ca", "go", "so"], [False, True, True]
    runs = [replace(base, run_kind=k, local_max=m) for k, m in zip(kinds, lm, strict=True)]
    scales = [r.scale() for r in runs]
    got = dma_packets(frames, SMALL4, params,
                      settings=FrameSettings(scales=scales, kinds=kinds, local_max=lm))
    want = [p for k, r in enumerate(runs)
            for p in dma_packets([frames[k]], SMALL4, replace(params, detect=r),
                                 first_frame_id=k)]
    assert len(got) == len(want)
    assert all(np.array_equal(g, w) for g, w in zip(got, want, strict=True))
    plain = dma_packets(frames, SMALL4, params, settings=FrameSettings(scales=scales))
    assert not all(np.array_equal(g, p) for g, p in zip(got, plain, strict=True))
    hp = replace(params, detect=replace(base, os=True, os_rank=600, local_max=True))
    top = hp.hdl_parameters(SMALL4)
    assert (top["CFAR_OS_BUILD"], top["CFAR_OS_RANK"], top["CFAR_LOCAL_MAX"]) == (1, 600, 1)
    with pytest.raises(ValueError, match="SETTINGS.cfar_kind"):
        replace(params, detect=replace(base, run_kind="go")).hdl_parameters(SMALL4)
