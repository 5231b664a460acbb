"""Detector models (model/nci.py, model/cfar_2d.py, model/cfar_stats.py,
model/detect_records.py): cross-checks against the host CFAR and against statistics."""

from __future__ import annotations

import numpy as np
import pytest

from host.cfar import CfarParams, cfar_threshold
from model import cfar_2d as cm
from model import detect_chain as dc
from model import detect_records as dr
from model import nci
from model.cfar_stats import go_so_factor


@pytest.mark.parametrize("num_tx,num_rx", [(1, 1), (1, 4), (4, 16), (3, 2)])
def test_nci_width_holds_the_worst_case(num_tx: int, num_rx: int) -> None:
    """All lanes at -32768 + j(-32768): the largest sum fits POW_W bits exactly."""
    words = np.full((num_tx * 2 * 2, num_rx), 0x80008000, dtype=np.uint32)
    p = nci.nci(words, num_tx, 2, 2)
    assert (p == num_tx * num_rx * 2 ** 31).all()
    assert int(p.max()) < 2 ** nci.power_width(num_tx, num_rx)


def test_ca_model_matches_host_cfar() -> None:
    """Same detections and noise as host.cfar on every row whose window does not reach a
    range edge (the host wraps the range axis, the FPGA cuts the window: docs/detect.md)."""
    rng = np.random.default_rng(0)
    p = rng.gamma(4, 1000.0, (64, 256)).astype(np.int64)
    p[[10, 30, 50, 20], [20, 5, 100, 255]] *= 60
    cfg = cm.Cfar2dConfig(n_range=64, n_doppler=256, pow_w=34)
    res = cm.cfar_2d(p, cfg, cm.scale_table(cfg, 1e-3, 4))
    thr, noise = cfar_threshold(p.astype(float), 4, CfarParams(pfa=1e-3))
    inner = slice(cfg.pr, cfg.n_range - cfg.pr)
    assert res.detect[inner].sum() >= 4
    assert np.array_equal(res.detect[inner], (p > thr)[inner])
    np.testing.assert_allclose(res.noise()[inner], noise[inner], rtol=1e-12)


@pytest.mark.parametrize("kind", ["go", "so"])
def test_go_so_factor_monte_carlo(kind: str) -> None:
    """The GO/SO factor gives the requested Pfa for independent Gamma cells."""
    rng = np.random.default_rng(1)
    n, pfa, half = 200_000, 1e-2, 16
    a = go_so_factor(pfa, 2, float(half), kind)
    x = rng.gamma(2, 1, n)
    y1, y2 = rng.gamma(2, 1, (2, n, half)).mean(axis=2)
    y = np.maximum(y1, y2) if kind == "go" else np.minimum(y1, y2)
    assert abs((x > a * y).mean() / pfa - 1) < 0.1


def test_blanked_rows_never_detect_or_train() -> None:
    cfg = cm.Cfar2dConfig(n_range=16, n_doppler=16, pow_w=34, guard=(1, 1), train=(2, 2),
                          blank_top=3)
    p = np.full((16, 16), 1000, dtype=np.int64)
    p[13:] = 10 ** 9     # blanked rows: huge, must neither detect nor raise the noise
    res = cm.cfar_2d(p, cfg, cm.scale_table(cfg, 1e-3, 4))
    assert not res.detect.any()
    assert (res.noise()[:13] == 1000).all()


@pytest.mark.parametrize("table", [dr.RECORD_FIELDS, dr.TRAILER_FIELDS])
def test_header_fields_are_disjoint_and_round_trip(table: tuple[dr.Field, ...]) -> None:
    """No two fields of a header (tag included) share a bit; any values, cut to their
    widths, come back from ``unpack_headers`` (and ``unpack_header``) of ``pack_headers``."""
    used = np.zeros((dr.HDR_LANES, 32), bool)
    for f in (dr.TAG, *table):
        for j in range(f.count):
            for b in range(f.lsb, f.lsb + f.width):
                lane, bit = f.lane + j * f.span + b // 32, b % 32
                assert not used[lane, bit], (f.name, lane, bit)
                used[lane, bit] = True
    rng = np.random.default_rng(5)
    n = 20
    values = {f.name: [int(v) for v in rng.integers(0, 2 ** 64, n * f.count, np.uint64)]
              for f in table}
    lanes = dr.pack_headers(dr.TAG_RECORD, table, {
        f.name: ([values[f.name][i * f.count:(i + 1) * f.count] for i in range(n)]
                 if f.count > 1 else values[f.name]) for f in table})
    assert lanes.dtype == np.uint32 and lanes.shape == (n, dr.HDR_LANES)
    assert (dr.tag_of(lanes, np.arange(n)) == dr.TAG_RECORD).all()
    got = dr.unpack_headers(lanes, table)
    for f in table:
        want = [v & ((1 << f.width) - 1) for v in values[f.name]]
        assert got[f.name].shape == ((n, f.count) if f.count > 1 else (n,))
        assert got[f.name].dtype == (np.uint64 if f.width > 32 else np.int64)
        assert got[f.name].reshape(-1).tolist() == want, f.name
        one = dr.unpack_header(lanes[-1], table)[f.name]
        assert one == (tuple(want[-f.count:]) if f.count > 1 else want[-1]), f.name


def test_records_round_trip_and_truncation() -> None:
    cfg = dc.DetectConfig(num_tx=2, num_rx=4, n_range=8, n_doppler=8, guard=(0, 0),
                          train=(1, 1), max_detections=3, pfa=1e-2)
    rng = np.random.default_rng(2)
    recs = [dr.Record(range_bin=r, doppler_bin=r + 1, power=2 ** 40 + r, noise_sum=2 ** 35,
                      cells=8, snapshot=rng.integers(0, 2 ** 32, (2, 4), dtype=np.uint32))
            for r in range(5)]
    words = dr.encode_frame(recs, 5, 2, 4, 3, frame_id=7)
    assert words.shape == (cfg.frame_words, 4)
    f = dr.decode_frame(words, 2)
    assert not f.errors and f.trailer is not None
    assert f.trailer.truncated and f.trailer.detections == 5 and f.trailer.records == 3
    for a, b in zip(f.records, recs[:3], strict=True):
        assert (a.range_bin, a.doppler_bin, a.power, a.noise_sum, a.cells) == (
            b.range_bin, b.doppler_bin, b.power, b.noise_sum, b.cells)
        assert np.array_equal(a.snapshot, b.snapshot) and a.frame_id == 7
    bad = words.copy()
    bad[0, 0] ^= 0xFF000000
    assert dr.decode_frame(bad, 2).errors
