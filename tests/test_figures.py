"""Issue 32, the figures: Fig. 6 says which targets channel 0 misses and how far it is
zoomed, every power map explains its unit, the point cloud uses the live view's axes with a
colour bar as tall as the plot and marks scene objects, the demo names the JSON it writes."""

from __future__ import annotations

from pathlib import Path

import matplotlib.figure
import numpy as np
import pytest

from host import plots
from model.config import get_preset
from model.scene import load_scene
from radar.cli import main
from radar.figures import truth_xy


def _texts(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """Every figure-level text and axis label drawn from now on."""
    seen: list[str] = []
    real_text = matplotlib.figure.Figure.text
    real_savefig = matplotlib.figure.Figure.savefig

    def text(self, x, y, s, *a, **k):  # noqa: ANN001, ANN002, ANN003, ANN202
        seen.append(s)
        return real_text(self, x, y, s, *a, **k)

    def savefig(self, *a, **k):  # noqa: ANN001, ANN002, ANN003, ANN202
        self.canvas.draw()                      # the layout as it will be saved
        for ax in self.axes:
            seen.extend([ax.get_xlabel(), ax.get_ylabel(), ax.get_title()])
            if ax.get_xlabel().startswith("y (m"):
                seen.append("xlim {} {}".format(*map(float, ax.get_xlim())))
                pos, bar = ax.get_position(), self.axes[-1].get_position()
                seen.append(f"heights {pos.height:.3f} {bar.height:.3f}")
        seen.append(self.get_suptitle())
        return real_savefig(self, *a, **k)

    monkeypatch.setattr(matplotlib.figure.Figure, "text", text)
    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", savefig)
    return seen


def test_fig6_names_missed_targets_zoom_and_units(tmp_path: Path,
                                                  monkeypatch: pytest.MonkeyPatch) -> None:
    cfg = get_preset("full")
    power = np.ones((cfg.n_range, cfg.n_doppler))
    mask = np.zeros_like(power, bool)
    mask[29, 5] = True                          # V2 at 50 m, 1 m/s
    seen = _texts(monkeypatch)
    plots.plot_detection_mask(power, mask, cfg, tmp_path / "f6.png", "t", 150.0,
                              [(100.0, 3.0, "V1"), (50.0, 1.0, "V2")])
    text = "\n".join(seen)
    assert "not over the threshold in channel 0: V1 (100 m)" in text and "V2 (" not in text
    assert "0-150 of 442 m shown" in text and "+ receding" in text
    assert "black: over the threshold" in text
    assert "LSB = one ADC code" in plots.POWER_LABEL


def test_point_cloud_axes_as_the_live_view(tmp_path: Path,
                                           monkeypatch: pytest.MonkeyPatch) -> None:
    seen = _texts(monkeypatch)
    plots.plot_point_cloud(np.array([10.0, 20.0]), np.array([5.0, -5.0]), np.array([20., 30.]),
                           tmp_path / "pc.png", "t", [(10.0, 5.0, "T1")],
                           [{"x": 20, "y": -5, "length": 4, "width": 2, "heading_deg": 0,
                             "label": "car 0.5"}])
    assert "y (m, left +)" in seen
    lim = next(s for s in seen if s.startswith("xlim"))
    left, right = (float(v) for v in lim.split()[1:])
    assert left > right                         # y grows to the left
    heights = next(s for s in seen if s.startswith("heights")).split()[1:]
    assert abs(float(heights[0]) - float(heights[1])) < 0.01   # colour bar as tall


def test_scene_objects_get_truth_markers() -> None:
    scene = load_scene("table1")
    assert [label for *_, label in truth_xy(scene, "V")] == ["V1", "V2", "V3", "V4"]
    from model.scene import ExtendedObject, Scene
    obj = ExtendedObject(20, 2, 4, 2, 0, -5, 0, 10, label="pedestrian")
    with_obj = Scene(preset="paper-fpga", objects=(obj,))
    assert truth_xy(with_obj) == [(20, 2, "O1 pedestrian")]


def test_demo_says_where_the_json_went(tmp_path: Path,
                                       capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["demo", "--backend", "float", "--no-gnn", "--preset", "paper-fpga",
                 "--out", str(tmp_path)]) == 0
    assert f"{tmp_path / 'table1_points.json'}" in capsys.readouterr().out
