"""The compiled kernels of ``host.angle`` (``host._angle_peaks``, ``host._angle_relax``)
against the numpy implementations they replaced (``tests.oracles``: the fast peak search
``angle_peaks``, the screened estimator ``angle_screened``, RELAX in step over rows
``angle``): the same peaks and decisions, floats equal to rounding; and the same results
with numba absent (the uncompiled fallback of ``host.kernels``)."""

from __future__ import annotations

import ast
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from host._angle_peaks import class_peaks, peak_sins
from host._angle_relax import first_components, relax_rows, split_rows, steering_rows
from host.angle import AngleParams, _relax, estimate_angles, peak_powers
from host.tdm import tx_phasors
from model.config import get_preset
from radar.common import note_compile
from tests.oracles.angle import estimate_angles_rows
from tests.oracles.angle_peaks import _steering_rows, peak_power_fast, peak_sin_fast
from tests.oracles.angle_screened import (
    estimate_angles_screened,
    first_component_screen,
    split_pairs,
)
from tests.oracles.points import tdm_compensate


def _rows(rng: np.random.Generator, m: int, n: int, targets: int = 3) -> np.ndarray:
    """m rows of n channels: up to ``targets`` plane waves 0..40 dB over unit noise, some
    pairs a beamwidth apart (two lobes of nearly equal height), complex64."""
    v = np.arange(n)
    x = (rng.normal(size=(m, n)) + 1j * rng.normal(size=(m, n))) / np.sqrt(2)
    s0 = rng.uniform(-0.95, 0.95, m)
    for t in range(targets):
        amp = 10 ** rng.uniform(0, 2, m) * (rng.random(m) < [1.0, 0.5, 0.3][t])
        s = s0 + 2.0 / n * (t if rng.random() < 0.5 else rng.uniform(-20, 20))
        x += amp[:, None] * np.exp(-1j * np.pi * v * s[:, None])
    return x.astype(np.complex64)


@pytest.mark.parametrize("n_fft", [1024, 256, 64])
def test_class_peaks_are_the_numpy_peaks(n_fft: int) -> None:
    """Every (cell, class) pair of 4-TX snapshots, random phasors and cell order; rows that
    are 0 (every bin ties) and constant; blocks not filled to the end."""
    cfg = get_preset("full")
    rng = np.random.default_rng(5)
    n = 203
    x = _rows(rng, n, cfg.n_virtual)
    x[7] = 0
    x[8] = 1 + 1j
    cell = rng.integers(0, n, 3 * n + 5)
    cell[:2] = (7, 8)
    k = rng.integers(-cfg.n_doppler // 2, cfg.n_doppler // 2, len(cell)) + \
        rng.integers(0, cfg.num_tx, len(cell)) * cfg.n_doppler
    ph = tx_phasors(cfg, k)
    got_p, got_s = class_peaks(x, cell, ph, n_fft)
    want_p, want_s = peak_power_fast(tdm_compensate(cfg, x.astype(complex)[cell], k), n_fft)
    np.testing.assert_allclose(got_p, want_p, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(got_s, want_s, rtol=0, atol=1e-12)
    assert got_p[0] == 0 and np.isfinite(got_s).all()


@pytest.mark.parametrize("n, n_fft", [(4, 1024), (16, 1024), (64, 1024), (128, 1024),
                                       (4, 16), (16, 16), (16, 32), (32, 32), (8, 64)])
def test_peak_sins_are_peak_sin_fast(n: int, n_fft: int) -> None:
    """Single rows of several array sizes (paper-fpga's 4 channels up to the coarse FFT's
    length) and coarse FFT lengths (128, 64, 32 and 16 points; zero-padded or not)."""
    rng = np.random.default_rng(n + n_fft)
    x = _rows(rng, 150, n).astype(complex)
    s, p = peak_sins(x, n_fft)
    ws, wp = peak_sin_fast(x, n_fft)
    np.testing.assert_allclose(s, ws, atol=1e-12)
    np.testing.assert_allclose(p, wp, rtol=1e-9)
    assert peak_sins(np.zeros((0, n)), n_fft)[0].shape == (0,)


@pytest.mark.parametrize("n", [1, 4, 17, 64])
def test_steering_rows_are_the_numpy_ones(n: int) -> None:
    s = np.random.default_rng(n).uniform(-1, 1, 200)
    np.testing.assert_allclose(steering_rows(s, n), _steering_rows(s, n), rtol=0, atol=1e-13)
    assert steering_rows(np.zeros(0), n).shape == (0, n)


def test_uncompiled_kernels_are_named(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                      capsys: pytest.CaptureFixture[str]) -> None:
    """With an empty numba cache every kernel is named (the CLI then says it compiles);
    after a call, its kernels are cached."""
    code = ("import host.kernels as K, host._angle_relax as R, numpy as np;"
            "print(sorted(K.uncompiled_kernels()));"
            "R.steering_rows(np.zeros(2), 4); print(sorted(K.uncompiled_kernels()))")
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path)}
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                         text=True, check=True, cwd=Path(__file__).parents[1]).stdout.split("\n")
    before, after = ast.literal_eval(out[0]), ast.literal_eval(out[1])
    assert {"_class_peaks", "_relax", "_steering", "_steer_row", "_select",
            "_fold_decisions"} <= set(before)
    assert "_steering" in before and "_steering" not in after and "_relax" in after
    import host.kernels as kernels
    import radar.common
    for missing, said in ((["_relax"], True), ([], False)):
        monkeypatch.setattr(radar.common, "_compile_noted", False)
        monkeypatch.setattr(kernels, "uncompiled_kernels", lambda m=missing: m)
        note_compile("detect")
        assert ("radar detect: compiling the host kernels" in capsys.readouterr().err) == said
    monkeypatch.setattr(radar.common, "_compile_noted", False)
    monkeypatch.setattr(kernels, "uncompiled_kernels", lambda: ["_relax"])
    note_compile("detect")
    note_compile("detect")                          # once per process
    assert capsys.readouterr().err.count("compiling") == 1


def test_kernel_inputs_are_checked() -> None:
    with pytest.raises(ValueError, match="exceed the coarse FFT"):
        class_peaks(np.zeros((2, 256), complex), np.zeros(2, np.int64), np.ones((2, 1)), 1024)
    with pytest.raises(ValueError, match="phasors"):
        class_peaks(np.zeros((2, 64), complex), np.zeros(3, np.int64), np.ones((2, 4)), 1024)
    with pytest.raises(ValueError, match="phasors"):
        first_components(np.zeros((2, 64), complex), np.ones((2, 3)), np.zeros(2),
                         np.ones(2), 12.0, 20.0, -10.0)
    with pytest.raises(ValueError, match="exceed the coarse FFT"):
        relax_rows(np.zeros((2, 64), complex), np.ones(2), 32, 3, 2, 12.0, 20.0, -10.0)
    with pytest.raises(ValueError, match="at most 128"):
        estimate_angles(np.zeros((2, 256), complex), np.ones(2), AngleParams())
    with pytest.raises(ValueError, match="at most 128"):
        peak_powers(np.zeros((2, 256), complex), 1024)
    with pytest.raises(ValueError, match=r"noise \(3,\) for 2 rows"):
        estimate_angles(np.zeros((2, 64), complex), np.ones(3), AngleParams())
    with pytest.raises(ValueError, match="TX phasors"):
        estimate_angles(np.zeros((2, 64), complex), np.ones(2), AngleParams(),
                        tx_phasors=np.ones((2, 3)))
    with pytest.raises(ValueError, match=r"\(n, n_channels\)"):
        estimate_angles(np.zeros(64, complex), np.ones(1), AngleParams())


def test_first_components_are_the_screened_ones() -> None:
    """The compensated rows, first amplitude and power, and the screen, against the numpy
    first half of ``estimate_angles_screened``; the components after it the same."""
    cfg = get_preset("full")
    rng = np.random.default_rng(9)
    n = 300
    x = _rows(rng, n, cfg.n_virtual)
    k = rng.integers(-cfg.n_doppler, cfg.n_doppler, n)
    ph = tx_phasors(cfg, k)
    xc = tdm_compensate(cfg, x.astype(complex), k)
    s1, _ = peak_sin_fast(xc, 1024)
    noise = rng.uniform(0.5, 2, n)
    p = AngleParams()
    xs, a1, p1, maybe, split = first_components(x, ph, s1, noise, p.min_snr_db,
                                                p.dynamic_range_db, p.array_error_db)
    np.testing.assert_allclose(xs, xc, rtol=1e-12, atol=1e-9)
    want_a, want_p, want_maybe, want_split = first_component_screen(xc, noise, p, s1)
    np.testing.assert_allclose(a1, want_a, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(p1, want_p, rtol=1e-9)
    np.testing.assert_array_equal(maybe, want_maybe)
    np.testing.assert_array_equal(split, want_split)
    assert 0 < maybe.sum() < n
    none = first_components(x, ph, s1, noise, p.min_snr_db, p.dynamic_range_db,
                            p.array_error_db, screen=False)
    assert not none[3].any()
    # and the components that follow: the numpy screened estimator's
    got = estimate_angles(x, noise, p, tx_phasors=ph, first_sin=s1)
    want = estimate_angles_screened(xc, noise, p, first_sin=s1)
    np.testing.assert_array_equal(got.cell, want.cell)
    np.testing.assert_allclose(got.sin_az, want.sin_az, atol=1e-9)


def test_relax_with_compiled_peaks() -> None:
    """``estimate_angles_rows`` with the compiled peak search: the components of the FFT
    peak search (the fine-grid maximum is the same on these rows)."""
    rng = np.random.default_rng(13)
    x = _rows(rng, 150, 64).astype(complex)
    noise = rng.uniform(0.5, 2.0, 150)
    for p in (AngleParams(), AngleParams(max_targets=2, refine_iterations=1, n_fft=256)):
        got = estimate_angles_rows(x, noise, p, peaks=peak_sins, steer=steering_rows)
        want = estimate_angles_rows(x, noise, p)
        assert len(want.cell) > 150
        np.testing.assert_array_equal(got.cell, want.cell)
        np.testing.assert_allclose(got.sin_az, want.sin_az, atol=1e-9)
        np.testing.assert_allclose(got.amplitude, want.amplitude, rtol=1e-9, atol=1e-9)


@pytest.mark.parametrize("n", [16, 64])
def test_relax_rows_is_estimate_angles_rows(n: int) -> None:
    """The compiled RELAX: the components of ``estimate_angles_rows`` with the same peak
    search and steering (three settings; rows of noise only, of zeros, and one row)."""
    rng = np.random.default_rng(21)
    x = _rows(rng, 200, n).astype(complex)
    x[:10] = (rng.normal(size=(10, n)) + 1j * rng.normal(size=(10, n))) / np.sqrt(2)
    x[10:13] = 0.0
    noise = rng.uniform(0.5, 2.0, 200)
    for p in (AngleParams(), AngleParams(max_targets=2, refine_iterations=1, n_fft=256),
              AngleParams(max_targets=4, refine_iterations=0, min_snr_db=6.0,
                          array_error_db=-np.inf)):
        for rows in (slice(None), slice(5, 6)):
            got = _relax(x[rows], noise[rows], p)
            want = estimate_angles_rows(x[rows], noise[rows], p, peaks=peak_sins,
                                        steer=steering_rows)
            np.testing.assert_array_equal(got.cell, want.cell)
            np.testing.assert_allclose(got.sin_az, want.sin_az, atol=1e-9)
            np.testing.assert_allclose(got.amplitude, want.amplitude, rtol=1e-9, atol=1e-9)
            np.testing.assert_allclose(got.snr_db, want.snr_db, atol=1e-9)
    counts = np.bincount(_relax(x, noise, AngleParams()).cell, minlength=200)
    assert (counts[13:] >= 1).all() and (counts >= 2).sum() > 40 and (counts == 3).any()
    assert len(_relax(np.zeros((0, n)), np.zeros(0), AngleParams()).cell) == 0
    with pytest.raises(ValueError, match="noise"):
        _relax(x, noise[:3], AngleParams())


def test_without_numba_the_same_python_runs() -> None:
    """numba absent (blocked in a subprocess): the kernels run as plain Python
    (``host.kernels.COMPILED`` False, nothing to compile) and give the compiled results:
    the peaks, the components and a point cloud."""
    code = (
        "import sys; sys.modules['numba'] = None\n"
        "import numpy as np, host.kernels as K\n"
        "from tests.test_angle_kernels import uncompiled_case\n"
        "print(K.COMPILED, K.uncompiled_kernels()); np.save(sys.argv[1], uncompiled_case())\n")
    out = Path(os.environ.get("TMPDIR", "/tmp")) / f"nonumba_{os.getpid()}.npy"
    run = subprocess.run([sys.executable, "-c", code, str(out)], capture_output=True,
                         text=True, timeout=600, cwd=Path(__file__).parents[1])
    assert run.returncode == 0, run.stderr
    assert run.stdout.split("\n")[0] == "False []"
    try:
        np.testing.assert_allclose(np.load(out), uncompiled_case(), rtol=1e-9, atol=1e-9)
    finally:
        out.unlink(missing_ok=True)


def uncompiled_case() -> np.ndarray:
    """A few rows through every kernel: the class peaks, the angle components and the
    points of a small cube scene, as one float array."""
    from host.pipeline import process_frame
    from model.scene import table1_scene
    from model.simulate import simulate_scene
    cfg = get_preset("full")
    rng = np.random.default_rng(3)
    x = _rows(rng, 6, cfg.n_virtual).astype(complex)
    ph = tx_phasors(cfg, np.arange(6) * 40 - 100)
    p, s = class_peaks(x, np.arange(6), ph, 1024)
    ang = estimate_angles(x, np.ones(6), AngleParams(min_snr_db=3.0), tx_phasors=ph)
    scene = table1_scene("paper-fpga")
    cloud = process_frame(simulate_scene(scene).samples, scene.config)
    return np.concatenate([p, s, ang.cell, ang.sin_az, np.abs(ang.amplitude),
                           cloud.range_m, cloud.azimuth_deg, cloud.radial_velocity_mps])


@pytest.mark.parametrize("n", [16, 64])
def test_split_rows_is_split_pairs(n: int) -> None:
    """The compiled split of a first component between two targets: the numpy
    ``split_pairs`` with the same peak search and steering (pairs 0.4-0.9 beamwidths apart,
    a single target with array errors, noise only)."""
    rng = np.random.default_rng(31)
    m = 120
    u = rng.uniform(-0.5, 0.5, m)
    sep = rng.uniform(0.4, 0.9, m) * 2 / n
    v = np.arange(n)
    x = np.exp(-1j * np.pi * np.outer(u, v)) + np.exp(2j * np.pi * rng.random((m, 1))) * \
        np.exp(-1j * np.pi * np.outer(u + sep, v))
    x[:20] = np.exp(-1j * np.pi * np.outer(u[:20], v)) * np.exp(
        0.2j * rng.normal(size=(20, n)))
    x[20:25] = 0.0
    noise = np.full(m, 1e-3)
    x = x + np.sqrt(noise[:, None] / 2) * (rng.normal(size=(m, n)) + 1j * rng.normal(
        size=(m, n)))
    p = AngleParams()
    s1, _ = peak_sins(x, p.n_fft)
    st = steering_rows(s1, n)
    a1 = np.sum(np.conj(st) * x, axis=1) / n
    r = x - a1[:, None] * st
    s2, _ = peak_sins(r, p.n_fft)
    a2 = np.sum(np.conj(steering_rows(s2, n)) * r, axis=1) / n
    start_s, start_a = np.stack([s1, s2], axis=1), np.stack([a1, a2], axis=1)
    got = split_rows(x, noise, start_s, start_a, p.n_fft, p.min_snr_db, p.dynamic_range_db,
                     p.array_error_db)
    want = split_pairs(x, noise, p, start_s, start_a, peaks=peak_sins, steer=steering_rows)
    np.testing.assert_array_equal(got[2], want[2])
    assert 0 < got[2].sum() < m - 25
    np.testing.assert_allclose(got[0], want[0], atol=1e-9)
    np.testing.assert_allclose(got[1], want[1], rtol=1e-9, atol=1e-9)
    assert len(split_rows(np.zeros((0, n)), np.zeros(0), np.zeros((0, 2)),
                          np.zeros((0, 2), complex), 1024, 12.0, 20.0, -10.0)[2]) == 0
