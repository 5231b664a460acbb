"""Synthetic scenes, rendering, labelling and the dataset cache."""

import numpy as np
import pytest

from gnn.classes import BACKGROUND, OBJECT_CLASSES
from gnn.dataset import build_split, generate, load_frames, make_frame, save_frames
from gnn.render import render_points, resolve_backend
from gnn.synth_scenes import CLASS_SPECS, random_scene


def test_random_scene_is_deterministic_and_plausible():
    a, b = random_scene(5), random_scene(5)
    assert a.scene == b.scene and np.array_equal(a.boxes, b.boxes)
    assert set(CLASS_SPECS) == set(OBJECT_CLASSES)
    for s in range(20):
        ls = random_scene(s)
        assert len(ls.boxes) == len(ls.box_class) >= 1
        for box, c in zip(ls.boxes, ls.box_class, strict=True):
            spec = CLASS_SPECS[OBJECT_CLASSES[c]]
            assert spec.length_m[0] <= box[2] <= spec.length_m[1]
        labels = {o.label for o in ls.scene.objects}
        assert labels <= set(OBJECT_CLASSES) | {"static"}
        assert 0 <= ls.ego_speed_mps <= 12
    with pytest.raises(ValueError, match="seed"):
        random_scene(-1)


def test_stand_in_frame_is_labelled():
    f = make_frame(3, backend="stand-in")
    assert len(f.cloud) > 10
    assert (f.point_class != BACKGROUND).any() and (f.point_class == BACKGROUND).any()
    assert np.all((f.point_object >= 0) == (f.point_class != BACKGROUND))


def test_pipeline_backend_renders_one_frame():
    assert resolve_backend("auto") == "pipeline"
    cloud = render_points(random_scene(1).scene, "pipeline")
    assert len(cloud) > 0 and np.all(np.isfinite(cloud.x_m))


def test_cache_roundtrip_and_reuse(tmp_path):
    frames = generate([0, 1, 2], "stand-in", workers=1, progress=False)
    save_frames(tmp_path / "x.npz", frames, {"a": 1})
    back, meta = load_frames(tmp_path / "x.npz")
    assert meta == {"a": "1"} and len(back) == 3
    for f, g in zip(frames, back, strict=True):
        assert np.array_equal(f.cloud.x_m, g.cloud.x_m)
        assert np.array_equal(f.point_object, g.point_object)
        assert np.array_equal(f.boxes, g.boxes)
    p = build_split(tmp_path, "test", 4, "stand-in", workers=2, progress=False)
    mtime = p.stat().st_mtime_ns
    assert build_split(tmp_path, "test", 4, "stand-in", workers=1, progress=False) == p
    assert p.stat().st_mtime_ns == mtime                     # cached
    par = load_frames(p)[0]
    seq = generate(list(range(1_000_000, 1_000_004)), "stand-in", workers=1, progress=False)
    assert all(np.array_equal(a.cloud.x_m, b.cloud.x_m) for a, b in zip(par, seq, strict=True))
    with pytest.raises(ValueError, match="split"):
        build_split(tmp_path, "holdout", 4)
    with pytest.raises(ValueError, match="not a gnn dataset"):
        (tmp_path / "bad.npz").write_bytes(b"nope")
        load_frames(tmp_path / "bad.npz")
