"""Issue 12 item 6: every numeric setting and scene field is checked in the library, with a
one-line ValueError naming it (the CLI turns these into exit status 2)."""

import math

import numpy as np
import pytest

from host.cfar import CfarParams, check_window
from host.pipeline import DetectionParams
from host.udp import Impairments, UdpSender, check_port, check_seconds
from model.config import get_preset
from model.scene import Scene
from model.simulate import MAX_FRAME_INDEX, check_frame_index, simulate_scene

NAN, INF = float("nan"), float("inf")


def _one_line(exc: pytest.ExceptionInfo) -> str:
    msg = str(exc.value)
    assert "\n" not in msg and len(msg) < 300
    return msg


@pytest.mark.parametrize("kw, word", [
    ({"pfa": 0.0}, "pfa"), ({"pfa": NAN}, "pfa"), ({"pfa": 0.5}, "pfa"), ({"pfa": -1}, "pfa"),
    ({"pfa": INF}, "pfa"), ({"guard": (-1, 2)}, "guard"), ({"train": (0, 8)}, "train"),
    ({"train": (10**9, 8)}, "train"), ({"train": (4.5, 8)}, "train"),
    ({"guard": (2, 2, 2)}, "guard"), ({"os_rank": 1.0}, "os_rank"), ({"kind": "x"}, "kind")])
def test_cfar_params(kw, word):
    with pytest.raises(ValueError, match=word) as exc:
        CfarParams(**kw)
    _one_line(exc)


@pytest.mark.parametrize("preset", ["full", "paper-fpga"])
@pytest.mark.parametrize("guard, train", [((2, 2), (100, 300)), ((130, 2), (1, 1)),
                                          ((2, 2), (4, 200))])
def test_cfar_window_larger_than_the_map(preset, guard, train):
    cfg = get_preset(preset)
    p = DetectionParams(cfar=CfarParams(guard=guard, train=train))
    with pytest.raises(ValueError, match="does not fit") as exc:
        p.check(cfg)
    _one_line(exc)


def test_os_cfar_window_bounded():
    with pytest.raises(ValueError, match="OS-CFAR"):
        check_window(CfarParams(kind="os", train=(60, 60), guard=(0, 0)), (256, 256))


@pytest.mark.parametrize("kw, word", [
    ({"paper_threshold_db": NAN}, "threshold"), ({"paper_threshold_db": -3}, "threshold"),
    ({"paper_threshold_db": INF}, "threshold"), ({"max_speed_mps": NAN}, "max_speed"),
    ({"max_speed_mps": 0}, "max_speed"), ({"detector": "magic"}, "detector")])
def test_detection_params(kw, word):
    with pytest.raises(ValueError, match=word) as exc:
        DetectionParams(**kw)
    _one_line(exc)


@pytest.mark.parametrize("port", [-1, 65536, 1.5, True])
def test_ports(port):
    with pytest.raises(ValueError, match="port"):
        check_port(port)
    with pytest.raises(ValueError, match="port"):
        check_port(0, allow_zero=False)


@pytest.mark.parametrize("value", [-1.0, 0.0, NAN, INF, 1e9])
def test_seconds(value):
    with pytest.raises(ValueError, match="idle"):
        check_seconds(value, "idle timeout")


@pytest.mark.parametrize("kw", [{"loss": NAN}, {"duplicate": -0.1}, {"reorder": 2.0}])
def test_impairments(kw):
    with pytest.raises(ValueError):
        Impairments(**kw)


@pytest.mark.parametrize("rate", [0.0, -5.0, NAN, INF])
def test_send_rate(rate):
    with pytest.raises(ValueError, match="rate"):
        UdpSender("127.0.0.1", 9, rate_bps=rate)


@pytest.mark.parametrize("frame", [-1, MAX_FRAME_INDEX + 1, 10**30, 1.5, True])
def test_frame_index(frame):
    with pytest.raises(ValueError, match="frame") as exc:
        check_frame_index(frame)
    _one_line(exc)
    scene = Scene.from_dict({"preset": "paper-fpga", "targets": [
        {"range_m": 10, "azimuth_deg": 0, "radial_velocity_mps": 0, "rcs_m2": 1}]})
    with pytest.raises(ValueError, match="frame"):
        simulate_scene(scene, frame_index=frame)


_T = {"range_m": 10, "azimuth_deg": 0, "radial_velocity_mps": 0, "rcs_m2": 1}
_O = {"x_m": 20, "y_m": 0, "length_m": 4, "width_m": 2, "rcs_m2": 10}


@pytest.mark.parametrize("target, word", [
    ({**_T, "range_m": NAN}, "range_m"), ({**_T, "range_m": 1e12}, "range_m"),
    ({**_T, "range_m": -3}, "range_m"), ({**_T, "radial_velocity_mps": 1e9}, "radial"),
    ({**_T, "rcs_m2": 1e30}, "rcs_m2"), ({**_T, "rcs_m2": 0}, "rcs_m2"),
    ({**_T, "azimuth_deg": 90}, "azimuth"), ({**_T, "azimuth_deg": "left"}, "azimuth")])
def test_scene_target_fields(target, word):
    with pytest.raises(ValueError, match=word) as exc:
        Scene.from_dict({"preset": "full", "targets": [target]})
    _one_line(exc)


@pytest.mark.parametrize("obj, word", [
    ({**_O, "n_scatterers": 1_000_000}, "n_scatterers"),
    ({**_O, "n_scatterers": 1e6}, "n_scatterers"), ({**_O, "n_scatterers": 0}, "n_scatterers"),
    ({**_O, "length_m": 1e7}, "length_m"), ({**_O, "vx_mps": NAN}, "vx_mps"),
    ({**_O, "x_m": -5}, "x_m"), ({**_O, "heading_deg": 1e300}, "heading"),
    ({**_O, "x_m": 1}, "box reaches x <= 0"), ({**_O, "x_m": 1, "length_m": 4}, "behind"),
    ({**_O, "length_m": 1e-300}, "at least"), ({**_O, "width_m": 0.001}, "at least"),
    ({**_O, "y_m": 10**400}, "y_m")])
def test_scene_object_fields(obj, word):
    with pytest.raises(ValueError, match=word) as exc:
        Scene.from_dict({"preset": "full", "objects": [obj]})
    _one_line(exc)


@pytest.mark.parametrize("doc, word", [
    ({"scene": ["table1"]}, "built-in"), ({"scene": {"a": 1}}, "built-in"),
    ({"targets": [{**_T, "range_m": 10**400}]}, "range_m")])
def test_scene_documents(doc, word):
    """A non-string built-in scene name, an integer beyond float range: named, one line."""
    with pytest.raises(ValueError, match=word) as exc:
        Scene.from_dict({"preset": "full", **doc})
    _one_line(exc)


def test_scene_folder_named(tmp_path):
    from model.scene import load_scene

    with pytest.raises(ValueError, match="is a folder") as exc:
        load_scene(str(tmp_path))
    _one_line(exc)


def test_scene_total_scatterers_and_seed():
    with pytest.raises(ValueError, match="scatterers"):
        Scene.from_dict({"preset": "full", "objects": [{**_O, "n_scatterers": 256}] * 9})
    for seed in (-1, 2**64, 1.5):
        with pytest.raises(ValueError, match="seed"):
            Scene.from_dict({"preset": "full", "seed": seed, "targets": [_T]})


def test_ego_speed_checked():
    from model.scene import check_ego_speed

    for bad in (NAN, INF, 1e4, "fast"):
        with pytest.raises(ValueError, match="ego speed"):
            check_ego_speed(bad)  # type: ignore[arg-type]
    assert check_ego_speed(27.78) == pytest.approx(27.78)


@pytest.mark.parametrize("content", [b"", b"not a checkpoint at all", b"PK\x03\x04garbage",
                                     b"\x80\x04\x95garbage pickle"])
def test_corrupt_checkpoint_one_line_no_unsafe_advice(tmp_path, content):
    from gnn.checkpoint import load_checkpoint

    path = tmp_path / "bad.pt"
    path.write_bytes(content)
    with pytest.raises(ValueError, match="not a readable gnn checkpoint") as exc:
        load_checkpoint(path)
    msg = _one_line(exc)
    assert "weights_only=False" not in msg and "weights_only" in msg


def test_pickled_code_checkpoint_is_refused(tmp_path):
    """A checkpoint that would run code when unpickled is refused, not executed."""
    import pickle

    import torch

    class Evil:
        def __reduce__(self):
            return (math.sqrt, (4.0,))

    path = tmp_path / "evil.pt"
    torch.save({"model": Evil()}, path, pickle_protocol=pickle.HIGHEST_PROTOCOL)
    from gnn.checkpoint import load_checkpoint

    with pytest.raises(ValueError, match="not a readable"):
        load_checkpoint(path)
    assert np.isfinite(1.0)


def test_non_finite_weights_neither_saved_nor_loaded(tmp_path):
    """A diverged training (NaN weights) writes no checkpoint; a checkpoint holding them
    (written by other means) is refused on load, naming the tensor."""
    import torch

    from gnn.checkpoint import DEFAULT_CHECKPOINT, load_checkpoint, save_checkpoint

    model, graph, meta = load_checkpoint(DEFAULT_CHECKPOINT)
    name, weights = next((k, v) for k, v in model.state_dict().items()
                         if v.is_floating_point())
    with torch.no_grad():
        weights.view(-1)[0] = float("nan")
    path = tmp_path / "nan.pt"
    with pytest.raises(ValueError, match=f"{name} holds NaN") as exc:
        save_checkpoint(path, model, graph, meta)
    _one_line(exc)
    assert not path.exists()
    ck = torch.load(DEFAULT_CHECKPOINT, weights_only=True)
    ck["state_dict"][name].view(-1)[0] = float("inf")
    torch.save(ck, path)
    with pytest.raises(ValueError, match=f"{name} holds NaN or infinite") as exc:
        load_checkpoint(path)
    _one_line(exc)
