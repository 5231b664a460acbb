"""Issue 32: real-only samples in a complex profile (a Hermitian cube, a mirror ghost per
target) are detected and warned about in one line."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import radar.commands.detect as detect_cmd
from host.pipeline import REAL_ONLY_ASYMMETRY, hermitian_asymmetry, real_only
from radar.cli import main


def test_hermitian_asymmetry() -> None:
    rng = np.random.default_rng(0)
    x = rng.normal(size=(2, 64, 32)) + 1j * rng.normal(size=(2, 64, 32))
    assert hermitian_asymmetry(x) > 5 * REAL_ONLY_ASYMMETRY and not real_only(x)
    y = np.fft.fft2(rng.normal(size=(2, 64, 32)))       # real input: Hermitian spectrum
    assert hermitian_asymmetry(y) < 1e-20 and real_only(y)
    assert not real_only(np.zeros((2, 8, 8), complex))


@pytest.mark.parametrize("backend", ["float", "model"])
def test_real_only_data_is_warned(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                  capsys: pytest.CaptureFixture[str], backend: str) -> None:
    import dataclasses

    import radar.frame_cloud
    real = detect_cmd.simulate_scene

    def real_only(scene, frame_index=0):  # noqa: ANN001, ANN202 - as model.simulate
        adc = real(scene, frame_index=frame_index)
        return dataclasses.replace(adc, samples=adc.samples.real.astype(adc.samples.dtype))

    out = tmp_path / "pc.json"
    argv = ["detect", "--scene", "table1", "--preset", "paper-fpga", "--backend", backend,
            "--frames", "2", "--json", str(out)]
    monkeypatch.setattr(radar.frame_cloud, "_real_only_noted", False)
    assert main(argv) == 0
    assert "Hermitian" not in capsys.readouterr().err      # complex data: no warning
    monkeypatch.setattr(detect_cmd, "simulate_scene", real_only)
    assert main(argv) == 0
    err = capsys.readouterr().err
    assert err.count("Hermitian") == 1 and "mirror ghost" in err     # one line, once
    assert all("Hermitian" in f["problems"][0] for f in json.loads(out.read_text())[
        "frame_info"])
