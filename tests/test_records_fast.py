"""The host's records path and its one cells -> points path against the implementations
they replaced (issue 14, host time; issue 28, one path: the oracles in ``tests/oracles``):
same records, same selection, same peaks, same clouds.

Tolerance of "same cloud": integer and flag fields exactly, float fields within 1e-9
(relative and absolute): the fast path evaluates the same sums, partly in another order."""

from __future__ import annotations

import warnings
from dataclasses import fields, replace

import numpy as np
import pytest

from host.angle import AngleParams, estimate_angles
from host.cells import Cells, peak_offsets
from host.pipeline import DetectionParams, detect_cells
from host.points import points_from_cells
from host.record_points import process_records, record_cells, select_records
from host.records import (
    RecordArrays,
    RecordDecoder,
    RecordList,
    decode_record_fields,
    fpga_detect_config,
    inside_map,
    outside_map,
    record_arrays,
)
from host.tdm import choose_folds, hypothesis_classes
from model import cfar_2d as cm
from model.axis_packetizer import packetize_stream, words_to_bytes
from model.config import get_preset
from model.detect_records import (
    TAG_RECORD,
    decode_frame,
    encode_frame,
    record_words,
)
from model.radar_pipeline import PipelineParams, chain_gain, run_chain
from model.reference import fft_axes, radar_cube
from model.scene import table1_scene
from model.simulate import simulate_scene
from tests.oracles.angle import estimate_angles as estimate_angles_row
from tests.oracles.angle import estimate_angles_rows, peak_sin_batch
from tests.oracles.angle_peaks import fine_peaks, peak_sin_fast
from tests.oracles.angle_screened import first_component_screen, screened_components
from tests.oracles.points import (
    assert_same_cloud,
    choose_fold,
    points_from_cells_numpy,
    points_from_cells_reference,
    process_records_reference,
    select_records_reference,
    velocity_hypotheses,
)
from tests.oracles.records import (
    RecordDecoderReference,
    decode_frame_reference,
    record_arrays_reference,
)
from tests.scenes import random_scene, synthetic_records


def _same_records(a: list, b: list) -> None:
    assert len(a) == len(b)
    for x, y in zip(a, b, strict=True):
        assert (x.range_bin, x.doppler_bin, x.power, x.noise_sum, x.cells, x.index,
                x.frame_id) == (y.range_bin, y.doppler_bin, y.power, y.noise_sum, y.cells,
                                y.index, y.frame_id)
        assert x.neighbours == y.neighbours
        assert x.snapshot.dtype == y.snapshot.dtype
        np.testing.assert_array_equal(x.snapshot, y.snapshot)


def _same_arrays(a: RecordArrays, b: RecordArrays) -> None:
    for name in ("range_bin", "doppler_bin", "power", "noise", "snapshot"):
        x, y = getattr(a, name), getattr(b, name)
        assert x.dtype == y.dtype and x.shape == y.shape, name
        np.testing.assert_array_equal(x, y, err_msg=name)
    assert (a.neighbours is None) == (b.neighbours is None)
    if a.neighbours is not None:
        assert a.neighbours.dtype == b.neighbours.dtype
        np.testing.assert_array_equal(a.neighbours, b.neighbours)


def _same_decode(words: np.ndarray, num_tx: int) -> None:
    a, b = decode_frame(words, num_tx), decode_frame_reference(words, num_tx)
    assert a.errors == b.errors
    assert a.trailer == b.trailer
    _same_records(a.records, b.records)
    # the array decode (host.records) against the same specification
    fields, trailer, errors = decode_record_fields(words, num_tx)
    assert (trailer, errors) == (b.trailer, b.errors)
    lst = RecordList(fields)
    _same_records(list(lst), b.records)
    cut = len(lst) // 2
    _same_records(list(lst[:cut]), b.records[:cut])
    if len(lst):
        _same_records([lst[-1]], b.records[-1:])
    nv = words.shape[1] * num_tx
    for gain in (1.0, 37.0):
        ref = record_arrays_reference(b.records, nv, gain)
        _same_arrays(record_arrays(lst, nv, gain), ref)
        _same_arrays(record_arrays(b.records, nv, gain), ref)     # from Record objects
        _same_arrays(record_arrays(lst[:cut], nv, gain),
                     record_arrays_reference(b.records[:cut], nv, gain))


@pytest.mark.parametrize("num_tx,num_rx", [(4, 16), (1, 4), (3, 8), (2, 2), (1, 1)])
def test_decode_matches_reference_on_random_frames(num_tx: int, num_rx: int) -> None:
    rng = np.random.default_rng(num_tx * 100 + num_rx)
    cfg = get_preset("full")
    for trial in range(40):
        n = int(rng.integers(0, 12))
        maxd = int(rng.integers(max(n, 1), 16))
        recs = synthetic_records(cfg, n, seed=trial)
        recs = [type(r)(range_bin=r.range_bin, doppler_bin=r.doppler_bin,
                        power=int(rng.integers(0, 2**63)) * 2 + int(rng.integers(0, 2)),
                        noise_sum=int(rng.integers(0, 2**64, dtype=np.uint64)),
                        cells=int(rng.integers(0, 2**16)),
                        snapshot=rng.integers(0, 2**32, (num_tx, num_rx), dtype=np.uint32))
                for r in recs]
        w = encode_frame(recs, n + int(rng.integers(0, 3)), num_tx, num_rx, maxd,
                         frame_id=int(rng.integers(0, 2**32)), sticky=bool(trial % 2))
        _same_decode(w, num_tx)
        bad = w.copy()
        kind = trial % 5
        rw = record_words(num_tx, num_rx)
        if kind == 0 and n:             # bad tag in a record header
            bad[rw * int(rng.integers(0, n)), 0] ^= np.uint32(0x40 << 24)
        elif kind == 1:                 # cut anywhere
            bad = bad[:int(rng.integers(0, len(bad) + 1))]
        elif kind == 2:                 # random words
            bad = rng.integers(0, 2**32, bad.shape, dtype=np.uint32)
            bad[0, 0] = (TAG_RECORD << 24) | (bad[0, 0] & 0xFFFFFF)
        elif kind == 3:                 # all zero (lost packets zero-fill)
            bad[:] = 0
        _same_decode(bad, num_tx)


def test_select_records_matches_reference() -> None:
    for preset in ("full", "paper-fpga"):
        cfg = get_preset(preset)
        for seed in range(12):
            rng = np.random.default_rng(seed)
            n = int(rng.integers(0, 1500))
            span = cfg.n_range * cfg.n_doppler if seed % 2 else 30 * cfg.n_doppler
            c = rng.choice(span, n, replace=seed % 3 != 0)      # duplicates, clusters
            r, d = np.divmod(c, cfg.n_doppler)
            pw = 10 ** rng.uniform(0, 9, n)
            pw[rng.random(n) < 0.05] = 0.0
            # neighbour powers: mostly weaker than the cell, sometimes stronger (undetected)
            nb = pw[:, None] * 10 ** rng.uniform(-3, 0.1, (n, 4))
            snap = np.zeros((n, cfg.n_virtual), np.complex64)
            for arr in (RecordArrays(r, d, pw, np.ones(n), snap),
                        RecordArrays(r, d, pw, np.ones(n), snap, nb)):
                for p in (DetectionParams(), DetectionParams(sidelobe_margin_db=None),
                          DetectionParams(range_window=False, doppler_window=False)):
                    np.testing.assert_array_equal(select_records(arr, cfg, p),
                                                  select_records_reference(arr, cfg, p)[0])
            if n > 10:                    # a stronger direct neighbour drops the record
                kept = set(select_records(RecordArrays(r, d, pw, np.ones(n), snap, nb), cfg,
                                          DetectionParams()).tolist())
                assert not any(nb[k].max() > pw[k] for k in kept)


@pytest.mark.parametrize("sources", [1, 2, 3])
def test_fine_peaks_match_the_full_fft(sources: int) -> None:
    """Same peak as the zero-padded FFT with one or two targets (plus noise); with three of
    similar strength the coarse grid may pick a lobe up to ~0.5 dB below the strongest (a
    few rows in a thousand)."""
    rng = np.random.default_rng(3 + sources)
    rows, v = 600, np.arange(64)
    s = rng.uniform(-1, 1, (rows, sources))
    amp = rng.uniform(0.3, 1.0, (rows, sources)) * np.exp(2j * np.pi * rng.random((rows,
                                                                                   sources)))
    x = np.einsum("ik,ikv->iv", amp, np.exp(-1j * np.pi * s[:, :, None] * v))
    x += 0.05 * (rng.normal(size=x.shape) + 1j * rng.normal(size=x.shape))
    for n_fft in (256, 1024):
        s_ref, p_ref = peak_sin_batch(x, n_fft)
        s_new, p_new = peak_sin_fast(x, n_fft)
        same = np.isclose(p_new, p_ref, rtol=1e-9, atol=0)
        if sources < 3:
            assert same.all()
        else:
            assert same.mean() >= 0.99
            assert np.all(10 * np.log10(p_ref[~same] / p_new[~same]) < 1.0)
        np.testing.assert_allclose(s_new[same], s_ref[same], atol=1e-9)
        k, _, b, _ = fine_peaks(x, n_fft)
        np.testing.assert_array_equal(b * b, p_new)


def test_choose_folds_matches_per_cell_decision() -> None:
    rng = np.random.default_rng(4)
    for preset in ("full", "paper-fpga"):
        cfg = get_preset(preset)
        n = 500
        v = rng.uniform(-1.2, 1.2, n) * cfg.max_velocity_mps
        snr = rng.uniform(10, 50, n)
        cp = 10 ** rng.uniform(0, 0.2, (n, cfg.num_tx))   # close powers: margins decide
        for params in (DetectionParams(), DetectionParams(max_speed_mps=5.0),
                       DetectionParams(unfold_velocity=False)):
            use = cp if cfg.num_tx > 1 and params.unfold_velocity else np.zeros((n, 0))
            m, amb = choose_folds(use, cfg, v, snr, params)
            for i in range(n):
                powers = {c: float(p) for c, p in enumerate(use[i])}
                assert (m[i], amb[i]) == choose_fold(powers, cfg, float(v[i]), float(snr[i]),
                                                     params)


def test_hypothesis_classes_are_the_per_cell_hypotheses() -> None:
    """The alias classes of ``velocity_hypotheses`` (m = 0 when no order is within
    max_speed), at random velocities, the alias boundaries and several max_speed_mps."""
    rng = np.random.default_rng(6)
    for preset in ("full", "paper-fpga"):
        cfg = get_preset(preset)
        v = np.concatenate([rng.uniform(-1, 1, 300), [-1.0, 1.0, 0.0]]) * cfg.max_velocity_mps
        for speed in (100.0, 30.0, 1.0, 0.01, 400.0):
            got = hypothesis_classes(cfg, v, speed)
            for i in range(len(v)):
                classes = {m % cfg.num_tx for m in velocity_hypotheses(cfg, float(v[i]), speed)}
                assert set(np.flatnonzero(got[i])) == classes, (preset, speed, v[i])


@pytest.mark.parametrize("preset", ["full", "paper-fpga"])
def test_points_match_reference(preset: str) -> None:
    cfg = get_preset(preset)
    recs = synthetic_records(cfg, 300, seed=7)
    arr = record_arrays(recs, cfg.n_virtual, 37.0)
    params = DetectionParams()
    new = process_records(arr, cfg, params)
    assert len(new) > 0
    assert_same_cloud(new, process_records_reference(arr, cfg, params))
    idx = select_records(arr, cfg, params)
    cells = np.stack([arr.range_bin[idx], arr.doppler_bin[idx]], axis=1)
    off = np.zeros((len(idx), 2))
    a = points_from_cells(Cells(cells[:, 0], cells[:, 1], arr.power[idx], arr.noise[idx], off,
                                arr.snapshot[idx]), cfg, params)
    b = points_from_cells_reference(cells, arr.snapshot[idx], arr.power[idx], arr.noise[idx],
                                    off, cfg, params)
    np.testing.assert_allclose(a.azimuth_deg, b.azimuth_deg, atol=1e-9)
    np.testing.assert_array_equal(a.doppler_bin, b.doppler_bin)


def test_decoder_frames_are_arrays_with_the_reference_records() -> None:
    """RecordDecoder's frames (RecordList over arrays) against the oracle's (Record
    objects): same records, problems and counts; a lost packet keeps the intact prefix."""
    cfg = get_preset("full")
    params = DetectionParams()
    dcfg = fpga_detect_config(cfg, params.cfar, max_detections=64)
    frames = [encode_frame(synthetic_records(cfg, n, seed=n), n, cfg.num_tx, cfg.num_rx, 64,
                           frame_id=i) for i, n in enumerate((0, 5, 64, 64))]
    frames[3][5 * 3, 0] ^= np.uint32(1 << 30)      # a bad tag: frame 3's record 3
    packets = [words_to_bytes(p) for p in packetize_stream(frames, 100)]   # 4 per frame
    packets = packets[:9] + packets[10:]           # frame 2 loses words 100..199
    out = []
    for ref in (False, True):
        dec = (RecordDecoderReference if ref else RecordDecoder)(dcfg, 100)
        got = [f for p in packets for f in dec.push_packet(p)] + dec.flush()
        out.append(sorted(got, key=lambda f: f.frame_id))   # a damaged frame closes late
    assert isinstance(out[0][0].records, RecordList)
    assert len(out[0]) == len(out[1]) == 4
    for a, b in zip(*out, strict=True):
        assert (a.frame_id, a.problems, a.trailer, a.usable_records, a.complete,
                a.detections) == (b.frame_id, b.problems, b.trailer, b.usable_records,
                                  b.complete, b.detections)
        _same_records(list(a.records), b.records)
        _same_arrays(record_arrays(a.records[:a.usable_records], cfg.n_virtual, 5.0),
                     record_arrays(b.records[:b.usable_records], cfg.n_virtual, 5.0))
    assert [f.complete for f in out[0]] == [True, True, False, False]
    assert [f.usable_records for f in out[0]] == [0, 5, 20, 3]


def test_angles_are_the_numpy_screened_ones() -> None:
    """One, two and three targets per row over a wide SNR range: ``host.angle`` gives the
    components of the numpy screened estimator with the same (fine-grid) peak search, and
    the screen skips most strong single targets."""
    rng = np.random.default_rng(12)
    rows, v = 300, np.arange(64)
    x = np.zeros((rows, 64), complex)
    for t in range(3):
        amp = 10 ** rng.uniform(-1, 2.5, rows) * (rng.random(rows) < [1.0, 0.3, 0.1][t])
        x += amp[:, None] * np.exp(-1j * np.pi * v * rng.uniform(-0.95, 0.95, (rows, 1)))
    x += (rng.normal(size=x.shape) + 1j * rng.normal(size=x.shape)) / np.sqrt(2)
    noise = np.ones(rows)
    for p in (AngleParams(), AngleParams(max_targets=1), AngleParams(min_snr_db=3.0)):
        a = estimate_angles(x, noise, p)
        s1 = peak_sin_fast(x, p.n_fft)[0]
        b = screened_components(x, noise, p, s1, *first_component_screen(x, noise, p, s1),
                                peaks=peak_sin_fast)
        np.testing.assert_array_equal(a.cell, b.cell)
        for name in ("sin_az", "amplitude", "snr_db"):
            np.testing.assert_allclose(getattr(a, name), getattr(b, name), rtol=1e-9,
                                       atol=1e-9)
        assert len(a.cell) > rows or p.max_targets == 1


@pytest.mark.parametrize("preset", ["full", "paper-fpga"])
def test_process_records_is_the_reference_on_synthetic_frames(preset: str) -> None:
    """Many detections (strong, and a mixed frame: 0-45 dB, aliased velocities the TDM
    test must unfold, two targets in every 8th cell), other settings, an empty frame and a
    frame whose records are all outside the reported bins."""
    cfg = get_preset(preset)
    big = 600 if preset == "full" else 300
    for recs in (synthetic_records(cfg, big, seed=1),
                 synthetic_records(cfg, big, seed=2, varied=True)):
        arr = record_arrays(recs, cfg.n_virtual, 37.0)
        for params in (DetectionParams(), DetectionParams(max_speed_mps=30.0),
                       DetectionParams(max_speed_mps=5.0),     # cells with no hypothesis
                       DetectionParams(unfold_velocity=False, sidelobe_margin_db=None)):
            new = process_records(arr, cfg, params, frame=3)
            assert_same_cloud(new, process_records_reference(arr, cfg, params, frame=3))
        assert len(new) > 0.8 * big
    empty = record_arrays([], cfg.n_virtual)
    assert len(process_records(empty, cfg)) == 0 == len(process_records_reference(empty, cfg))
    recs = [r for r in synthetic_records(cfg, 200, seed=3) if r.range_bin == 0]
    arr = record_arrays(recs, cfg.n_virtual)
    assert len(process_records(arr, cfg)) == 0 == len(process_records_reference(arr, cfg))
    z = np.zeros(0)
    none = Cells(z.astype(int), z.astype(int), z, z, np.zeros((0, 2)),
                 np.zeros((0, cfg.n_virtual), complex))
    assert len(points_from_cells(none, cfg, DetectionParams())) == 0
    assert len(record_cells(empty, cfg, DetectionParams())) == 0


def test_table1_full_cells_as_records() -> None:
    """Table I on ``full``: every CFAR cell of the float cube as a record (its snapshot,
    NCI power and noise): the records path's cloud is the reference's, and the cube path's
    (one path, ``host.points``) is the numpy path the cube took before."""
    scene = table1_scene("full")
    cfg = scene.config
    params = DetectionParams()
    cube = radar_cube(simulate_scene(scene).samples, cfg)
    cells, noise, nci = detect_cells(cube, cfg, params)
    arr = RecordArrays(cells[:, 0], cells[:, 1], nci[cells[:, 0], cells[:, 1]], noise,
                       cube[:, cells[:, 0], cells[:, 1]].T.astype(np.complex64),
                       cm.neighbours(nci)[cells[:, 0], cells[:, 1]])
    new = process_records(arr, cfg, params)
    assert len(new) >= 4
    assert_same_cloud(new, process_records_reference(arr, cfg, params))
    off = peak_offsets(nci, cells, fft_axes(cfg))
    cube_cells = Cells(cells[:, 0], cells[:, 1], arr.power, noise, off, arr.snapshot)
    assert_same_cloud(points_from_cells(cube_cells, cfg, params),
                points_from_cells_numpy(cells, arr.snapshot, arr.power, noise, off, cfg,
                                        params))


def test_random_scenes_through_the_chain() -> None:
    """Random paper-fpga scenes through the bit-accurate mode-1 chain and the decoder."""
    for seed in range(6):
        scene = random_scene("paper-fpga", seed)
        cfg = scene.config
        params = DetectionParams()
        dcfg = fpga_detect_config(cfg, params.cfar)
        chain = PipelineParams(output_mode=1, detect=dcfg)
        out = run_chain(simulate_scene(scene).samples, cfg, chain)
        dec = RecordDecoder(dcfg, chain.packet_words)
        f = [f for p in packetize_stream([out.records], chain.packet_words)
             for f in dec.push_packet(words_to_bytes(p))] + dec.flush()
        arr = record_arrays(f[0].records, cfg.n_virtual, chain_gain(cfg, chain))
        assert_same_cloud(process_records(arr, cfg, params),
                    process_records_reference(arr, cfg, params))


def test_estimate_angles_rows_is_estimate_angles_per_row() -> None:
    """RELAX on all rows in step against the one-row estimator: one to three targets,
    close pairs (components that collapse), weak rows that stop early, other settings."""
    rng = np.random.default_rng(13)
    rows, v = 120, np.arange(64)
    x = np.zeros((rows, 64), complex)
    s0 = rng.uniform(-0.9, 0.9, rows)
    for t in range(3):
        amp = 10 ** rng.uniform(0, 2, rows) * (rng.random(rows) < [1.0, 0.7, 0.4][t])
        st = s0 + (rng.uniform(-0.02, 0.02, rows) if t == 1 else rng.uniform(-0.9, 0.9, rows))
        x += amp[:, None] * np.exp(-1j * np.pi * v * st[:, None])
    x += (rng.normal(size=x.shape) + 1j * rng.normal(size=x.shape)) / np.sqrt(2)
    noise = rng.uniform(0.5, 2.0, rows)
    for p in (AngleParams(), AngleParams(max_targets=2, refine_iterations=1, n_fft=256),
              AngleParams(min_snr_db=0.0, dynamic_range_db=40.0)):
        got = estimate_angles_rows(x, noise, p)
        want = [(i, c) for i in range(rows)
                for c in estimate_angles_row(x[i], float(noise[i]), p)]
        assert len(want) > rows
        np.testing.assert_array_equal(got.cell, [i for i, _ in want])
        np.testing.assert_allclose(got.sin_az, [c.sin_az for _, c in want], atol=1e-9)
        np.testing.assert_allclose(got.amplitude, [c.amplitude for _, c in want], rtol=1e-9,
                                   atol=1e-9)
        np.testing.assert_allclose(got.snr_db, [c.snr_db for _, c in want], atol=1e-9)


@pytest.mark.parametrize("field,value", [("range_bin", 64), ("range_bin", -1),
                                         ("doppler_bin", 256), ("doppler_bin", 4095)])
def test_records_outside_the_map_are_refused_or_dropped(field: str, value: int) -> None:
    """Bins outside the map (12-bit header fields: corrupt words, another configuration's
    records) get a ValueError naming them from process_records (both paths; the compiled
    kernels would index out of bounds); inside_map drops them and counts them."""
    cfg = get_preset("paper-fpga")
    arr = record_arrays(synthetic_records(cfg, 40, seed=5), cfg.n_virtual, 37.0)
    assert not outside_map(arr, cfg).any() and inside_map(arr, cfg) == (arr, 0)
    bins = getattr(arr, field).copy()
    bins[[3, 17]] = value
    bad = replace(arr, **{field: bins})
    for process in (process_records, process_records_reference):
        with pytest.raises(ValueError, match=r"2 record\(s\) outside paper-fpga's 64 x 256 "
                                             rf"map \(first: .*{value}"):
            process(bad, cfg)
    kept, dropped = inside_map(bad, cfg)
    assert dropped == 2 and len(kept) == 38
    keep = np.setdiff1d(np.arange(40), [3, 17])
    for f in fields(arr):
        np.testing.assert_array_equal(getattr(kept, f.name), getattr(arr, f.name)[keep])
    assert len(process_records(kept, cfg)) > 0
    no_nb = inside_map(replace(bad, neighbours=None), cfg)[0]
    assert no_nb.neighbours is None and len(no_nb) == 38


def test_zero_noise_estimates_give_finite_points() -> None:
    """A CFAR noise estimate of 0 (noiseless input: every training cell 0) is the noise
    floor 1e-30 (host.points.cell_snr_db, the angle estimator): no divide warning, the
    same points as that floor, every value finite; on both paths."""
    cfg = get_preset("full")
    arr = record_arrays(synthetic_records(cfg, 60, seed=9, varied=True), cfg.n_virtual, 37.0)
    zero = replace(arr, noise=np.zeros_like(arr.noise))
    floor = replace(arr, noise=np.full_like(arr.noise, 1e-30))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for process in (process_records, process_records_reference):
            got = process(zero, cfg)
            want = process(floor, cfg)
            assert len(got) == len(want) > 0
            for f in fields(got):
                a = getattr(got, f.name)
                np.testing.assert_array_equal(a, getattr(want, f.name), err_msg=f.name)
                if a.dtype.kind == "f":
                    assert np.isfinite(a).all(), f.name
