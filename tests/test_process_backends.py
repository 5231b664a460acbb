"""`radar process --backend model` (docs/profiles.md): a capture through the bit-accurate
model of the FPGA chain built with its profile's parameters, the DMA bytes decoded as the
board's, against the float backend; the range FFT scaled for the capture's level; the TX
firing order and a 2-D array handled by the host from the chain's chirp slots. The RTL
against the model on the same frame: tb/radar_pipeline/test_process_openradar.py."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from host.adc_capture import open_capture, write_npy
from model.array import slot_channels
from model.config import RadarConfig
from model.hdl import hdl_unsupported
from model.profile import load_profile, profile_from_toml, profile_to_toml
from model.radar_pipeline import RANGE_SCALE_SCH, PipelineParams, range_scale_for_peak, run_chain
from model.scene import Scatterers
from model.simulate import simulate_frame
from radar.cli import main
from radar.sources import get_source

DATA = Path(__file__).parent / "data" / "openradar"
CFG_FILE = DATA / "openradar_2tx4rx.cfg"
BIN_FILE = DATA / "doppler_example_1.bin"
OPENRADAR = load_profile(CFG_FILE)


def process(tmp_path: Path, backend: str, *extra: str, radar: str = str(CFG_FILE),
            capture: str = str(BIN_FILE)) -> dict:
    out = tmp_path / f"{backend}.json"
    assert main(["process", "--radar", radar, "--capture", capture, "--json", str(out),
                 "--backend", backend, *extra]) == 0
    return json.loads(out.read_text())


def by_cell(doc: dict) -> dict[tuple[int, int, int], list[dict]]:
    """Points by (frame, range bin, Doppler bin), each cell's sorted by azimuth."""
    cells: dict[tuple[int, int, int], list[dict]] = {}
    for p in doc["points"]:
        cells.setdefault((p["frame"], p["range_bin"], p["doppler_bin"]), []).append(p)
    return {c: sorted(ps, key=lambda p: p["azimuth_deg"]) for c, ps in cells.items()}


def largest_differences(a: dict, b: dict, other_counts: int = 0) -> dict[str, float]:
    """Largest |difference| of each point field between two clouds with the same cells and
    the same number of points in each (asserted), but for at most ``other_counts`` cells
    (left out of the differences)."""
    ca, cb = by_cell(a), by_cell(b)
    assert ca.keys() == cb.keys()
    same = [c for c in ca if len(ca[c]) == len(cb[c])]
    assert len(ca) - len(same) <= other_counts, (ca.keys() - set(same))
    fields = ("range_m", "radial_velocity_mps", "azimuth_deg", "snr_db", "elevation_deg")
    return {f: max(abs(p[f] - q[f]) for c in same for p, q in zip(ca[c], cb[c], strict=True))
            for f in fields if f in a["points"][0]}


@pytest.mark.parametrize("remove_static", [False, True])
def test_openradar_frame_model_close_to_float(tmp_path, remove_static):
    """The real frame through the model gives the float backend's cells, the same number of
    points in each; measured largest differences: plain (48 points in 30 cells) 0.9 mm,
    0.7 mm/s, 0.26 deg, 0.13 dB; with --remove-static (21 in 16) 3 mm, 2.1 mm/s, 1.07 deg
    (a weak second component of a two-point cell), 0.41 dB, and one cell, (117, -1) at
    13-15 dB, with a third component at -73 deg (13.3 dB) in float that the model's
    rounding leaves below the angle's model-order test (20 points)."""
    extra = ["--remove-static"] if remove_static else []
    ref = process(tmp_path, "float", *extra)
    got = process(tmp_path, "model", *extra)
    assert got["backend"] == "model" and got["range_scale_sch"] == 0x3
    assert len(ref["points"]) == (21 if remove_static else 48)
    assert len(got["points"]) == (20 if remove_static else 48)
    assert [{**f, "points": 0} for f in got["frame_info"]] == \
        [{**f, "points": 0} for f in ref["frame_info"]]
    diff = largest_differences(ref, got, 1 if remove_static else 0)
    assert diff["range_m"] < 0.005 and diff["radial_velocity_mps"] < 0.005, diff
    assert diff["azimuth_deg"] < (1.5 if remove_static else 0.5), diff
    assert diff["snr_db"] < 0.5, diff


def test_range_scale_for_the_capture_level():
    """The range FFT halves as few stages as keep a worst-case frame of the capture's peak
    (a tone of magnitude sqrt(2) x peak, coherent over samples and chirps) inside the cube's
    16 bits: a frame of the peak on I and Q, coherent, does not overflow with the chosen
    schedule (half of full scale) and does with two stages fewer halved (the bound is within
    sqrt(2) of it); the chain's default (every stage) at full scale. The OpenRadar frame
    peaks at 265: 0x3 (with the default, 97 % of its cube's cells are 0)."""
    cfg = OPENRADAR.config
    frame = open_capture(BIN_FILE, OPENRADAR).frame(0)
    peak = float(np.abs(frame.view(np.float32)).max())
    assert peak == 265 and range_scale_for_peak(cfg, peak) == 0x3
    # the default 1/N range FFT rounds this frame's noise away: a cube of zeros, mostly
    assert np.mean(run_chain(frame, cfg, PipelineParams()).cube() == 0) > 0.95
    assert range_scale_for_peak(cfg, 32767) == RANGE_SCALE_SCH
    worst = np.full(cfg.adc_shape, 1000 + 1000j, np.complex64)
    sch = range_scale_for_peak(cfg, 1000)
    assert sch == 0xF
    out = run_chain(worst, cfg, PipelineParams(range_scale_sch=sch))
    assert out.range_overflow == out.doppler_overflow == 0
    assert np.abs(out.payload.real).max() == 16000
    less = run_chain(worst, cfg, PipelineParams(range_scale_sch=sch >> 2))
    assert less.doppler_overflow > 0


ZERO_FILLED = RadarConfig(name="zero-filled", num_tx=2, num_rx=4, n_range=64, n_doppler=16,
                          sample_rate_hz=10e6, chirp_period_s=40e-6, design_max_range_m=3.0,
                          sweep_bandwidth_hz=1.5e9, samples_per_chirp=50, loops=15)
"""50 samples of a 64-point range FFT, 15 loops of a 16-point Doppler FFT (window ROMs of
both counts exist: ``model.fft_rom.WINDOW_LENGTHS``)."""


@pytest.mark.parametrize("window,peak", [(True, 1500), (True, 7000), (False, 200),
                                         (False, 1500)])
def test_range_scale_for_a_zero_filled_profile(window, peak):
    """Zero fill adds nothing to a tone: the worst case sums the samples and loops that
    exist (each axis' window over its own count), so the schedule is the tightest one: the
    worst frame of the peak (constant peak on I and Q) does not saturate, and with one
    stage fewer halved it does (a bound over the FFT lengths, 64 / 50 x 16 / 15 = 1.37 too
    high, halves one stage more at these peaks)."""
    assert not hdl_unsupported(ZERO_FILLED)
    worst = np.full(ZERO_FILLED.adc_shape, peak + 1j * peak, np.complex64)
    sch = range_scale_for_peak(ZERO_FILLED, peak, PipelineParams(window=window))
    out = run_chain(worst, ZERO_FILLED, PipelineParams(window=window, range_scale_sch=sch))
    assert out.range_overflow == out.doppler_overflow == 0
    less = run_chain(worst, ZERO_FILLED, PipelineParams(window=window,
                                                        range_scale_sch=sch >> 1))
    assert less.range_overflow + less.doppler_overflow > 0


def test_model_detect_fpga_on_the_real_frame(tmp_path):
    """--detect fpga: the chain's on-chip detector, its records decoded from the DMA bytes;
    the moving return at 2.93 m, +0.6 m/s (docs/profiles.md) is among the points."""
    doc = process(tmp_path, "model", "--detect", "fpga", "--remove-static")
    info = doc["frame_info"][0]
    assert doc["detect"] == "fpga" and info["complete"] and not info["truncated"]
    assert info["records"] >= len(doc["points"]) >= 10
    best = max(doc["points"], key=lambda p: p["snr_db"])
    assert abs(best["range_m"] - 2.93) < 0.05 and 0.5 < best["radial_velocity_mps"] < 0.7


def test_frames_selected_and_the_same_whatever_the_selection(tmp_path):
    """--frames A:B through the model: the frames' indices in the capture, and a frame gives
    the same points whatever else is selected (one scaling for the whole capture)."""
    frame = open_capture(BIN_FILE, OPENRADAR).frame(0)
    path = tmp_path / "frames.npy"
    write_npy(path, (frame * s for s in (1, -1, 2, 1)), 4, OPENRADAR.config)
    two = process(tmp_path, "model", "--frames", "1:3", capture=str(path))
    assert [f["frame"] for f in two["frame_info"]] == [1, 2]
    assert {p["frame"] for p in two["points"]} == {1, 2}
    one = process(tmp_path, "model", "--frames", "2", capture=str(path))
    assert one["points"] == [p for p in two["points"] if p["frame"] == 2]


def profile_file(tmp_path: Path, tx_order: str, tx: str) -> Path:
    """The OpenRadar profile as TOML with another firing order and TX positions."""
    text = profile_to_toml(OPENRADAR)
    text = text.replace("tx_order = [0, 1]", f"tx_order = {tx_order}")
    text = text.replace("tx = [[0.0, 0.0], [4.0, 0.0]]", f"tx = {tx}")
    path = tmp_path / "radar.toml"
    path.write_text(text)
    return path


@pytest.mark.parametrize("tx", ["[[0.0, 0.0], [4.0, 0.0]]", "[[0.0, 0.0], [4.0, 1.0]]"])
def test_tx_order_and_2d_array_from_the_chain_slots(tmp_path, tx):
    """TX 1 firing first (tx_order [1, 0]), with the ULA and with TX 1 half a wavelength up
    (a 2-D array): the chain keeps chirp slots, the host puts its channels in TX order
    (model.array.slot_channels: the decoded cube, the records' snapshots, the model's own
    cube) and applies the geometry, so the model gives the float backend's cells and points
    (three, one per target; measured largest differences: range and velocity identical,
    azimuth 0.004 deg, elevation 0.01 deg, SNR 0.16 dB), and each target's strongest point
    sits at its azimuth (and elevation), also from the on-chip detector's records."""
    path = profile_file(tmp_path, "[1, 0]", tx)
    cfg = profile_from_toml(path.read_text(), str(path)).config
    assert slot_channels(cfg) is not None
    rows = np.array([(2.0, -25.0, 1.5, 1.0, 12.0), (3.5, 10.0, -2.0, 1.0, -15.0),
                     (4.5, 30.0, 3.0, 1.0, 0.0)])
    planar = "1.0]]" not in tx
    if planar:
        rows[:, 4] = 0.0
    targets = Scatterers(rows[:, 0], rows[:, 1], rows[:, 2], rows[:, 3], np.full(3, -1),
                         rows[:, 4])
    frame = simulate_frame(cfg, targets, rng=np.random.default_rng(3)).samples
    capture = tmp_path / "sim.npy"
    write_npy(capture, iter([frame]), 1, cfg)
    ref = process(tmp_path, "float", radar=str(path), capture=str(capture))
    got = process(tmp_path, "model", radar=str(path), capture=str(capture))
    diff = largest_differences(ref, got)
    assert len(got["points"]) == 3
    assert diff["range_m"] < 0.005 and diff["radial_velocity_mps"] < 0.005, diff
    assert diff["azimuth_deg"] < 0.1 and diff.get("elevation_deg", 0.0) < 0.1, diff
    fpga = process(tmp_path, "model", "--detect", "fpga", radar=str(path),
                   capture=str(capture))
    for doc in (got, fpga):
        for r, az, v, _, el in rows:
            near = [p for p in doc["points"] if abs(p["range_m"] - r) < 0.15
                    and abs(p["radial_velocity_mps"] - v) < 0.3]
            best = max(near, key=lambda p: p["snr_db"])
            assert abs(best["azimuth_deg"] - az) < 1.0, (r, best)
            assert abs(best.get("elevation_deg", 0.0) - el) < 2.0, (r, best)
    # `radar detect --backend model` takes the model's own cube: the decoded one
    source = get_source("model", PipelineParams(range_scale_sch=got["range_scale_sch"]))
    decoded = next(source.dma_frames(iter([frame]), cfg)).cube()
    assert np.array_equal(source.cube(frame, cfg), decoded)


@pytest.mark.parametrize("argv,want", [
    (["--backend", "float", "--detect", "fpga"], "--detect fpga: the on-chip detector"),
    (["--backend", "model", "--max-detections", "8"], "--max-detections: does not apply"),
])
def test_bad_options_one_line(tmp_path, capsys, argv, want):
    out = tmp_path / "x.json"
    assert main(["process", "--radar", str(CFG_FILE), "--capture", str(BIN_FILE), "--json",
                 str(out), *argv]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and want in err, err
    assert not out.exists()


def test_a_profile_the_rtl_cannot_run_is_refused(tmp_path, capsys):
    """An 18-bit ADC is wider than the RTL's 16-bit sample streams: one line before any work,
    naming the float backend that runs it."""
    text = profile_to_toml(OPENRADAR).replace("adc_bits = 16", "adc_bits = 18")
    path = tmp_path / "wide.toml"
    path.write_text(text)
    out = tmp_path / "x.json"
    for backend in ("model", "rtl"):
        assert main(["process", "--radar", str(path), "--capture", str(BIN_FILE), "--json",
                     str(out), "--backend", backend]) == 2
        err = capsys.readouterr().err.strip()
        assert err.count("\n") == 0 and f"--backend {backend}" in err and "18-bit" in err
        assert "(--backend float runs it)" in err, err
    assert not out.exists()


def test_a_frame_the_chain_does_not_send_is_an_error(tmp_path, monkeypatch, capsys):
    """A frame missing from the chain's DMA stream (here the model's last frame dropped):
    the frames that came are written, then one line, exit status 2."""
    from radar.sources import ModelSource

    send = ModelSource.cube_packets

    def drop_last(self, adc_frames, cfg):  # noqa: ANN001, ANN202 - as cube_packets
        packets = list(send(self, adc_frames, cfg))
        return iter(packets[:len(packets) // 2])

    monkeypatch.setattr(ModelSource, "cube_packets", drop_last)
    frame = open_capture(BIN_FILE, OPENRADAR).frame(0)
    path = tmp_path / "frames.npy"
    write_npy(path, iter([frame, frame]), 2, OPENRADAR.config)
    out = tmp_path / "x.json"
    assert main(["process", "--radar", str(CFG_FILE), "--capture", str(path), "--json",
                 str(out), "--backend", "model"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "1 of 2 frame(s) did not come out of the chain" in err
    assert json.loads(out.read_text())["frames"] == 1
