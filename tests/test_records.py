"""Host decoder of the FPGA's detection-record stream (host/records.py): round trip through
the packetizer and bytes, lost / repeated / reordered / cut packets reported (never
raised), truncation flagged, and records -> point cloud equal to the cube path's."""

import numpy as np
import pytest

from host.cells import peak_offsets
from host.pipeline import DetectionParams, process_cube
from host.record_points import process_records, record_offsets
from host.records import RecordDecoder, fpga_detect_config, record_arrays
from model import cfar_2d as cm
from model.axis_packetizer import pack_iq, packetize_stream, words_to_bytes
from model.config import get_preset
from model.detect_chain import DetectConfig, detect_stream, detections
from model.radar_pipeline import PipelineParams, chain_gain, run_chain
from model.reference import fft_axes
from model.scene import table1_scene
from model.simulate import simulate_scene

DCFG = DetectConfig(num_tx=2, num_rx=4, n_range=32, n_doppler=32, guard=(1, 1),
                    train=(2, 4), max_detections=8)
PW = 16


def _frames(n: int, seed: int = 0, targets: int = 3) -> list[np.ndarray]:
    """Doppler-FFT words (r, t, d) order, uint32 (n_range * num_tx * n_doppler, num_rx):
    noise plus ``targets`` strong cells per frame."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        x = rng.normal(0, 30, (DCFG.n_range, DCFG.num_tx, DCFG.n_doppler, DCFG.num_rx, 2))
        for _ in range(targets):
            r, d = rng.integers(4, DCFG.n_range - 4), rng.integers(0, DCFG.n_doppler)
            x[r, :, d] += rng.normal(0, 3000, (DCFG.num_tx, DCFG.num_rx, 2))
        c = np.round(x[..., 0]) + 1j * np.round(x[..., 1])
        out.append(pack_iq(c.reshape(-1, DCFG.num_rx)))
    return out


def _packets(frames: list[np.ndarray]) -> list[bytes]:
    return [words_to_bytes(p) for p in packetize_stream(detect_stream(frames, DCFG), PW)]


def _decode(packets: list[bytes]) -> tuple[list, RecordDecoder]:
    dec = RecordDecoder(DCFG, PW)
    out = [f for p in packets for f in dec.push_packet(p)] + dec.flush()
    return out, dec


def test_round_trip_bit_exact():
    frames = _frames(3)
    decoded, dec = _decode(_packets(frames))
    assert [f.frame_id for f in decoded] == [0, 1, 2]
    scale = DCFG.scale()
    for f, words in zip(decoded, frames, strict=True):
        want, _ = detections(words, DCFG, scale)
        assert f.complete and not f.problems and f.usable_records == len(want) > 0
        assert f.detections == len(want) and not f.truncated
        for got, w in zip(f.records, want, strict=True):
            assert (got.range_bin, got.doppler_bin, got.power, got.noise_sum, got.cells) == (
                w.range_bin, w.doppler_bin, w.power, w.noise_sum, w.cells)
            assert np.array_equal(got.snapshot, w.snapshot)
    arr = record_arrays(decoded[0].records, DCFG.num_tx * DCFG.num_rx, gain=2.0)
    assert arr.snapshot.shape == (len(decoded[0].records), 8)
    # snapshot channel order = the cube's (v = tx * num_rx + rx), power = sum |x|^2
    assert np.allclose(np.sum(np.abs(arr.snapshot) ** 2, axis=1), arr.power, rtol=1e-5)
    assert dec.stats.frames_complete == 3 and not dec.stream_problems


def test_lost_repeated_reordered_cut_packets():
    packets = _packets(_frames(3, seed=1))
    per_frame = len(packets) // 3
    # duplicates and a swap inside a frame lose nothing
    shuffled = packets[:1] + [packets[2], packets[1]] + packets[2:] + [packets[-1]]
    decoded, dec = _decode(shuffled)
    assert [f.complete for f in decoded] == [True] * 3
    assert dec.stats.reordered_packets >= 1 and dec.stats.late_packets + \
        dec.stats.duplicate_packets >= 1
    # a lost packet: that frame is damaged, the others are complete, no exception
    lost = per_frame + 1
    decoded, dec = _decode(packets[:lost] + packets[lost + 1:])
    decoded.sort(key=lambda f: f.frame_id)   # a damaged frame closes late
    assert [f.complete for f in decoded] == [True, False, True]
    bad = decoded[1]
    assert any("missing packets" in p for p in bad.problems) and bad.trailer is None
    assert bad.usable_records <= len(bad.records)
    assert dec.stats.frames_damaged == 1
    # a packet cut short (its CRC fails: not used) and garbage bytes: reported, never raised
    decoded, dec = _decode([packets[0][:-5], b"\x00" * 7] + packets[1:])
    decoded.sort(key=lambda f: f.frame_id)   # a damaged frame closes late
    assert not decoded[0].complete and all(f.complete for f in decoded[1:])
    assert dec.stream_problems and dec.stats.crc_errors == 1
    assert any("packet 0 failed its CRC" in p for p in decoded[0].problems)
    # a raw byte stream with garbage in front resynchronises
    dec = RecordDecoder(DCFG, PW)
    got = dec.push_bytes(b"\x11" * 13 + b"".join(packets)) + dec.finish()
    assert [f.complete for f in got] == [True] * 3 and dec.stats.garbage_bytes == 13


def test_truncated_frame_is_flagged_not_damaged():
    frames = _frames(2, seed=2, targets=12)
    decoded, _ = _decode(_packets(frames))
    f = decoded[0]
    assert f.truncated and f.complete and f.detections > DCFG.max_detections
    assert len(f.records) == DCFG.max_detections
    assert decoded[1].trailer.truncated_sticky


def test_frame_id_mismatch_is_reported():
    """Records and trailer stamped with another frame id than their packets: damaged."""
    stream = detect_stream(_frames(1), DCFG, first_frame_id=5)
    got, _ = _decode([words_to_bytes(p) for p in packetize_stream(stream, PW)])
    assert len(got) == 1 and not got[0].complete
    assert any("trailer carries frame id 5" in p for p in got[0].problems)
    assert any("records carry frame id" in p for p in got[0].problems)


def test_wrong_max_detections_is_reported():
    packets = _packets(_frames(1))
    other = DetectConfig(**{**DCFG.__dict__, "max_detections": 9})
    dec = RecordDecoder(other, PW)
    got = [f for p in packets for f in dec.push_packet(p)] + dec.flush()
    assert got and not any(f.complete for f in got)


def test_offsets_from_neighbour_powers():
    """The records' neighbour powers give the cube path's interpolation
    (``host.cells.peak_offsets`` on the map), detected or not; 0 in range at the ends.
    The powers are the N -> infinity Hann response: paper-fpga's 64 x 256-bin axes' exact
    tables are off by O(1/N^2) from it."""
    def hann(x):
        return abs(np.sinc(x) / (1 - x * x))
    pmap = np.full((64, 256), 1e-3)
    # a Hann-windowed tone 0.3 bins above range bin 10, 0.2 below Doppler bin 5
    for dr in (-1, 0, 1):
        for dd in (-1, 0, 1):
            pmap[10 + dr, 5 + dd] = (hann(dr - 0.3) * hann(dd + 0.2)) ** 2
    cells = np.array([[10, 5], [0, 5], [63, 7]])
    nb = cm.neighbours(pmap)[cells[:, 0], cells[:, 1]]
    cfg = get_preset("paper-fpga")
    params = DetectionParams()
    off = record_offsets(pmap[cells[:, 0], cells[:, 1]], nb, cells[:, 0], cfg, params)
    np.testing.assert_array_equal(off, peak_offsets(pmap, cells, fft_axes(cfg)))
    assert off[0] == pytest.approx([0.3, -0.2], abs=2e-3)
    assert off[1, 0] == 0.0 and off[2, 0] == 0.0


def test_records_give_the_cube_points_paper_fpga():
    """paper-fpga Table I through the mode-1 chain model: the point cloud from the records
    has the cube path's points (same cells, same angles and velocities)."""
    scene = table1_scene("paper-fpga")
    cfg = scene.config
    adc = simulate_scene(scene).samples
    params = DetectionParams()
    dcfg = fpga_detect_config(cfg, params.cfar)
    out = run_chain(adc, cfg, PipelineParams(output_mode=1, detect=dcfg))
    gain = chain_gain(cfg, PipelineParams())
    cube_cloud = process_cube(out.cube() / gain, cfg, params)
    dec = RecordDecoder(dcfg, 1024)
    frames = [f for p in packetize_stream([out.records], 1024)
              for f in dec.push_packet(words_to_bytes(p))] + dec.flush()
    assert len(frames) == 1 and frames[0].complete
    cloud = process_records(record_arrays(frames[0].records, cfg.n_virtual, gain), cfg, params)
    assert len(cube_cloud) >= 3 and len(cloud) == len(cube_cloud)
    for i in range(len(cube_cloud)):
        j = np.flatnonzero((cloud.range_bin == cube_cloud.range_bin[i])
                           & (cloud.doppler_bin == cube_cloud.doppler_bin[i]))
        assert len(j), f"cube point {i} missing from the records' cloud"
        j = j[np.argmin(np.abs(cloud.azimuth_deg[j] - cube_cloud.azimuth_deg[i]))]
        assert abs(cloud.azimuth_deg[j] - cube_cloud.azimuth_deg[i]) < 0.5
        assert abs(cloud.range_m[j] - cube_cloud.range_m[i]) < 0.9   # half a range bin
        assert abs(cloud.radial_velocity_mps[j] - cube_cloud.radial_velocity_mps[i]) < 0.2


def test_records_need_the_configs_channels():
    cfg = get_preset("paper-fpga")
    arr = record_arrays([], 8)
    with pytest.raises(ValueError, match="virtual channels"):
        process_records(arr, cfg)


def test_window_response_closed_form_is_the_windows_dft():
    from model.reference import FftAxis, hann_periodic

    off = np.linspace(-0.5, 0.5, 41)
    for n in (64, 256):
        for windowed in (True, False):
            w = hann_periodic(n) if windowed else np.ones(n)
            ref = np.abs(np.exp(-2j * np.pi * np.outer(off, np.arange(n)) / n) @ w) / w.sum()
            assert np.allclose(FftAxis(n, n, windowed).response(off), ref, atol=1e-12)
