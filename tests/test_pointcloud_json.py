"""``PointCloud.from_json_dict`` reads back what ``to_json_dict`` writes."""

from __future__ import annotations

import json

import numpy as np
import pytest

from host.pointcloud import FLOAT_FIELDS, PointCloud


def cloud() -> PointCloud:
    rng = np.random.default_rng(3)
    n = 7
    return PointCloud.from_polar(
        range_m=rng.uniform(1, 200, n), azimuth_deg=rng.uniform(-60, 60, n),
        radial_velocity_mps=rng.uniform(-27, 27, n), power_db=rng.uniform(20, 90, n),
        snr_db=rng.uniform(10, 40, n), rcs_dbsm=rng.uniform(-10, 20, n),
        range_bin=rng.integers(0, 256, n), doppler_bin=rng.integers(-128, 128, n),
        ambiguous=rng.random(n) < 0.5, frame=rng.integers(0, 3, n))


def test_round_trip() -> None:
    c = cloud()
    doc = json.loads(json.dumps(c.to_json_dict("full", 3)))
    back = PointCloud.from_json_dict(doc)
    assert len(back) == len(c)
    for k in ("range_bin", "doppler_bin", "frame", "ambiguous"):
        assert np.array_equal(getattr(back, k), getattr(c, k)), k
    for k in FLOAT_FIELDS:  # JSON keeps 4 decimals; x, y, vx, vy are derived again
        np.testing.assert_allclose(getattr(back, k), getattr(c, k), atol=2e-3, err_msg=k)
    again = back.to_json_dict("full", 3)["points"]
    for p, q in zip(again, doc["points"], strict=True):
        assert p.keys() == q.keys()
        assert all(p[k] == pytest.approx(q[k], abs=2e-3) for k in p)


def test_minimal_points_and_errors() -> None:
    doc = {"points": [{"range_m": 10.0, "azimuth_deg": 90.0, "radial_velocity_mps": 1.0,
                       "power_db": 50.0, "snr_db": 20.0}]}
    c = PointCloud.from_json_dict(doc)
    assert c.y_m[0] == pytest.approx(10.0) and c.range_bin[0] == 0 and not c.ambiguous[0]
    assert len(PointCloud.from_json_dict({"points": []})) == 0
    with pytest.raises(ValueError, match="point cloud"):
        PointCloud.from_json_dict({"points": [{"range_m": 1.0}]})
    with pytest.raises(ValueError, match="point cloud"):
        PointCloud.from_json_dict({"preset": "full"})
