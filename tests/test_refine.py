"""The whole-frame refinement of range and Doppler (``host.refine``, docs/curves.md "The
refinement"): the cube's inverse gives back the weighted samples, the estimate is exact for
noise-free tones (also beside a strong neighbour, which biases the three-cell
interpolation), reaches the Cramer-Rao bound of the whole data within the weighting's
derived loss in noise, and the CLI switches it on."""

from __future__ import annotations

from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest

from campaign.curves import taper_loss_db
from host.cells import peak_offsets
from host.params import DetectionParams, params_for
from host.pipeline import process_cube
from host.refine import FIXED_POINT_FLOOR, FLOAT_FLOOR, frame_samples, refine_offsets, weights
from model import detection_theory as dt
from model.config import PRESETS
from model.reference import FftAxis, fft_axes, radar_cube, range_doppler_power
from radar.cli import main

CFG = PRESETS["paper-fpga"]           # 4 channels, 64 samples, 256 chirps, one TX


def tones(rng: np.random.Generator, freqs: np.ndarray, amps: np.ndarray, noise: float
          ) -> np.ndarray:
    """ADC frame (n_chirps, num_rx, n_samples) of tones at ``freqs`` float (k, 2) (range,
    Doppler) bins with per-channel amplitudes ``amps`` complex (k, num_rx), white noise of
    power ``noise`` per sample."""
    t, c = np.arange(CFG.n_samples), np.arange(CFG.n_loops)
    x = np.zeros((CFG.n_loops, CFG.num_rx, CFG.n_samples), complex)
    for f, a in zip(freqs, amps, strict=True):
        x += (np.exp(2j * np.pi * f[1] * c / CFG.n_doppler)[:, None, None] * a[None, :, None]
              * np.exp(2j * np.pi * f[0] * t / CFG.n_range)[None, None, :])
    shape = x.shape
    return x + np.sqrt(noise / 2) * (rng.standard_normal(shape) + 1j * rng.standard_normal(shape))


def interpolated(cube: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """The host's three-cell interpolation at ``cells`` int (k, 2)."""
    return peak_offsets(range_doppler_power(cube), cells, fft_axes(CFG))


def test_frame_samples_are_the_weighted_adc_samples() -> None:
    rng = np.random.default_rng(1)
    adc = tones(rng, np.array([[10.3, 40.6]]), np.ones((1, CFG.num_rx)), 1.0)
    floor = 0.05
    got = frame_samples(radar_cube(adc, CFG), CFG, (True, True), floor)
    ax_r, ax_d = fft_axes(CFG)
    want = adc.transpose(1, 2, 0) * weights(ax_r, floor)[1][:, None] * weights(ax_d, floor)[1]
    assert got.shape == (CFG.n_virtual, CFG.n_samples, CFG.n_loops)
    np.testing.assert_allclose(got, want, atol=1e-4 * np.abs(want).max())


def test_weights() -> None:
    ax = FftAxis(64, 64)
    g, v = weights(ax, 0.1)
    w = ax.window()
    np.testing.assert_allclose(v, w * w / (w * w + 0.01))
    np.testing.assert_allclose(g * w, v)
    assert np.all(weights(FftAxis(64, 64, hann=False), 0.1)[1] == 1.0)


def test_noise_free_tone_beside_a_strong_one_is_exact() -> None:
    """Two noise-free tones 3 range bins apart, the second 20 dB stronger: the three-cell
    interpolation of the weak one is pulled by the strong one's response by 0.03 bin; the
    refinement (RELAX passes against the other's fitted tone) finds both within 1e-3 bin."""
    freqs = np.array([[20.27, 100.41], [23.27, 100.62]])
    amps = np.array([np.ones(CFG.num_rx), 10 * np.exp(1j * np.arange(CFG.num_rx))])
    cube = radar_cube(tones(np.random.default_rng(0), freqs, amps, 0.0), CFG)
    cells = np.rint(freqs).astype(int)
    coarse = interpolated(cube, cells)
    fine = refine_offsets(cube, cells[:, 0], cells[:, 1], coarse, CFG, (True, True))
    truth = freqs - cells
    assert np.abs(coarse - truth)[0].max() > 0.02                  # the interpolation is off
    np.testing.assert_allclose(fine, truth, atol=1e-3)


def test_a_refinement_that_cannot_climb_keeps_the_interpolation() -> None:
    """No tone at all near the start: whatever the steps find is not kept unless the
    periodogram is higher there; an empty list stays empty."""
    empty = np.zeros((0, 2))
    cube = radar_cube(tones(np.random.default_rng(2), np.array([[30.0, 50.0]]),
                            np.ones((1, CFG.num_rx)), 1e-6), CFG)
    assert refine_offsets(cube, np.zeros(0, int), np.zeros(0, int), empty, CFG,
                          (True, True)).shape == (0, 2)
    got = refine_offsets(cube, np.array([30]), np.array([50]), np.array([[0.0, 0.0]]), CFG,
                         (True, True))
    np.testing.assert_allclose(got, [[0.0, 0.0]], atol=1e-6)


def test_refinement_reaches_the_whole_data_bound() -> None:
    """One tone per frame, 300 frames at a per-sample SNR of -10 dB (cell SNR 23 dB per
    channel): the interpolation's MSE is several dB above the whole data's CRB, the
    refinement's within 1 dB of the CRB plus its weighting's derived loss (0.1 dB here)."""
    snr_db = -10.0
    rng = np.random.default_rng(5)
    se = np.zeros((2, 2))
    for _ in range(300):
        f = np.array([[30.0, 120.0]]) + rng.random((1, 2)) - 0.5
        amp = np.exp(2j * np.pi * rng.random()) * np.exp(-1j * np.pi * 0.2
                                                          * np.arange(CFG.num_rx))
        cube = radar_cube(tones(rng, f, amp[None] * 10 ** (snr_db / 20), 1.0), CFG)
        cells = np.array([[30, 120]])
        coarse = interpolated(cube, cells)
        fine = refine_offsets(cube, cells[:, 0], cells[:, 1], coarse, CFG, (True, True))
        se += [((coarse - (f - cells)) ** 2)[0], ((fine - (f - cells)) ** 2)[0]]
    mse = se / 300
    crb = [dt.tone_frequency_crb(10 ** (snr_db / 10), n, looks) * n
           for n, looks in ((CFG.n_range, CFG.n_doppler * 4), (CFG.n_doppler, CFG.n_range * 4))]
    excess = 10 * np.log10(mse / np.square(crb))
    ax_r, ax_d = fft_axes(CFG)
    loss = [taper_loss_db(ax_r, ax_d, FLOAT_FLOOR), taper_loss_db(ax_d, ax_r, FLOAT_FLOOR)]
    assert np.all(excess[0] > 4.0), excess
    assert np.all(excess[1] < np.array(loss) + 1.0), (excess, loss)


def test_taper_loss() -> None:
    """The weighting's first-order loss: 0 for rectangular axes; for Hann axes 0.29 dB at
    the float floor, growing with the floor towards the loss of the squared Hann window
    (v = w^2 / floor^2 where w << floor), computed here from the estimator's variance
    sum(v^2 t^2) / (sum v t^2)^2 against the CRB's 1 / sum t^2, times the other axis'
    N sum v^2 / (sum v)^2."""
    hann, rect = FftAxis(256, 256), FftAxis(256, 256, hann=False)
    assert taper_loss_db(rect, rect, 0.3) == pytest.approx(0.0, abs=1e-9)
    assert taper_loss_db(hann, hann, FLOAT_FLOOR) == pytest.approx(0.29, abs=0.01)
    v, t = hann.window() ** 2, np.arange(256) - 128.0
    squared = 10 * np.log10(np.sum(v * v * t * t) * np.sum(t * t) / np.sum(v * t * t) ** 2
                            * 256 * np.sum(v * v) / np.sum(v) ** 2)
    assert taper_loss_db(hann, hann, 1e4) == pytest.approx(squared, abs=0.01)
    losses = [taper_loss_db(hann, hann, f) for f in (1e-3, 1e-2, 0.1, FIXED_POINT_FLOOR, 1.0)]
    assert losses == sorted(losses)


def test_process_cube_refines_only_when_asked() -> None:
    rng = np.random.default_rng(3)
    f = np.array([[20.3, 60.2]])
    cube = radar_cube(tones(rng, f, np.full((1, CFG.num_rx), 0.3), 1.0), CFG)
    base = params_for(CFG)
    plain = process_cube(cube, CFG, base)
    fine = process_cube(cube, CFG, replace(base, refine=True))
    assert len(plain) == len(fine) == 1
    assert plain.range_m[0] != fine.range_m[0]
    assert abs(fine.range_m[0] - plain.range_m[0]) < 0.5 * CFG.range_bin_m


def test_refine_settings_are_checked() -> None:
    with pytest.raises(ValueError, match="refine_floor"):
        DetectionParams(refine_floor=0.0)
    real = SimpleNamespace(adc="real", name="real")
    with pytest.raises(ValueError, match="complex-ADC"):
        DetectionParams(refine=True).check(real)


@pytest.mark.parametrize("argv, message", [
    (["--refine", "--detect", "fpga", "--backend", "model"], "--refine: needs the radar cube"),
    (["--refine-floor", "0.1"], "--refine-floor: only with --refine"),
])
def test_cli_refuses_refine_misfits(tmp_path, capsys, argv: list[str], message: str) -> None:
    code = main(["detect", "--scene", "table1", "--json", str(tmp_path / "p.json"), *argv])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and message in err[0], err


def test_refine_settings_pick_the_floor_of_the_source() -> None:
    from argparse import Namespace

    from radar.common import CliError, refine_settings
    assert refine_settings(Namespace()) == {}
    assert refine_settings(Namespace(refine=False, refine_floor=None)) == {}
    assert refine_settings(Namespace(refine=True, refine_floor=None, backend="float")) == {
        "refine": True, "refine_floor": FLOAT_FLOOR}
    for backend in ("model", "rtl"):
        assert refine_settings(Namespace(refine=True, refine_floor=None, backend=backend)
                               )["refine_floor"] == FIXED_POINT_FLOOR
    assert refine_settings(Namespace(refine=True, refine_floor=0.05, backend="model")
                           )["refine_floor"] == 0.05
    with pytest.raises(CliError, match="only with --refine"):
        refine_settings(Namespace(refine=False, refine_floor=0.1))
