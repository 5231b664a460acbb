"""Real-world effects of the simulator (model.impairments), each measured in its output."""

import math
from dataclasses import replace

import numpy as np
import pytest

from model.config import RadarConfig
from model.impairments import Ground, Impairments, Wall, image_rejection_db
from model.scene import PointTarget, Scatterers, Scene
from model.simulate import chirp_tx, simulate_frame, simulate_scene

TI = RadarConfig(name="ti", num_tx=2, num_rx=4, n_range=64, n_doppler=32, sample_rate_hz=10e6,
                 chirp_period_s=10e-6, design_max_range_m=2.5, sweep_bandwidth_hz=3e9)
"""A short-range radar (5 cm range bins, 3.2 m) where leakage at 0.15 m is bin 3."""
BIN = TI.range_bin_m
REAL_TI = replace(TI, name="ti-real", adc="real", design_max_range_m=1.5)


def target(range_m: float, rcs_m2: float = 1.0, v: float = 0.0) -> Scatterers:
    return Scatterers(np.array([range_m]), np.zeros(1), np.array([v]), np.array([rcs_m2]),
                      np.full(1, -1))


def none() -> Scatterers:
    return Scatterers.concat([])


def frame(imp: Impairments, sc: Scatterers | None = None, cfg: RadarConfig = TI, **kw
          ) -> np.ndarray:
    f = simulate_frame(cfg, none() if sc is None else sc, impairments=imp, **kw)
    assert f.saturated == 0
    return f.samples


def spectrum(x: np.ndarray, window: np.ndarray | None = None) -> np.ndarray:
    """Range FFT over the samples, normalised to the tone amplitude (unwindowed: A at its bin)."""
    w = np.ones(x.shape[-1]) if window is None else window
    return np.fft.fft(x * w, axis=-1) / w.sum()


def test_channel_errors_in_the_peak_phases_and_gains():
    imp = Impairments(tx_gain_db=(0.0, 2.0), tx_phase_deg=(0.0, 30.0),
                      rx_gain_db=(0.0, -1.0, 1.0, 0.5), rx_phase_deg=(0.0, 10.0, -20.0, 5.0))
    peak = spectrum(frame(imp, target(20 * BIN), noise=False))[:, :, 20]     # (C, R)
    tx = chirp_tx(TI)
    want_deg = np.array(imp.tx_phase_deg)[tx][:, None] + np.array(imp.rx_phase_deg)[None, :]
    want_db = np.array(imp.tx_gain_db)[tx][:, None] + np.array(imp.rx_gain_db)[None, :]
    got_deg = np.degrees(np.angle(peak / peak[0, 0]))
    got_db = 20 * np.log10(np.abs(peak / peak[0, 0]))
    assert np.max(np.abs(got_deg - want_deg)) < 0.05 and np.max(np.abs(got_db - want_db)) < 0.01


def test_random_channel_errors_are_seeded_draws_of_the_rms():
    big = replace(TI, num_rx=64, rx_positions=None)
    imp = Impairments(seed=5, rx_phase_rms_deg=10.0, rx_gain_rms_db=1.5)
    _, g_rx = imp.channel_gains(big)
    assert np.std(np.degrees(np.angle(g_rx))) == pytest.approx(10.0, rel=0.25)
    assert np.std(20 * np.log10(np.abs(g_rx))) == pytest.approx(1.5, rel=0.25)
    assert np.array_equal(imp.channel_gains(big)[1], g_rx)
    assert not np.array_equal(replace(imp, seed=6).channel_gains(big)[1], g_rx)
    peak = spectrum(frame(imp, target(20 * BIN), cfg=big, noise=False))[0, :, 20]
    want = np.angle(g_rx / g_rx[0])
    assert np.max(np.abs(np.angle(peak / peak[0]) - want)) < np.radians(0.05)


def test_leakage_at_its_range_bin_and_level():
    imp = Impairments(leakage_dbfs=-20.0, leakage_range_m=3 * BIN)
    s = np.abs(spectrum(frame(imp, noise=False)))
    level = TI.adc_full_scale * 10 ** (-20 / 20)
    assert np.allclose(s[:, :, 3], level, rtol=2e-3)
    assert np.max(np.delete(s, 3, axis=-1)) < 1e-3 * level
    # the same tone in every chirp of a TX, a fixed phase per (TX, RX)
    x = frame(imp, noise=False)
    assert np.array_equal(x[0], x[2]) and not np.array_equal(x[0], x[1])


def test_dc_offset_in_range_bin_zero():
    imp = Impairments(dc_offset_dbfs=-40.0)
    level = TI.adc_full_scale * 10 ** (-40 / 20)
    s = spectrum(frame(imp, noise=False))
    assert np.allclose(np.abs(s[:, :, 0]), level, atol=0.5)
    assert np.max(np.abs(s[:, :, 1:])) < 0.1
    per_rx = s[0, :, 0]
    assert len(set(np.round(np.angle(per_rx), 3))) == TI.num_rx     # one offset per RX
    real = frame(imp, cfg=REAL_TI, noise=False)
    assert np.allclose(np.abs(real.mean(axis=(0, 2))), level, atol=0.5)


@pytest.mark.parametrize("gain_db, phase_deg", [(1.0, 0.0), (0.0, 5.0), (-0.5, -3.0)])
def test_iq_imbalance_image_at_the_mirror_bin(gain_db, phase_deg):
    imp = Impairments(iq_gain_db=gain_db, iq_phase_deg=phase_deg)
    s = np.abs(spectrum(frame(imp, target(20 * BIN), noise=False)))
    image_db = 20 * np.log10(s[:, :, TI.n_range - 20] / s[:, :, 20])
    assert np.allclose(image_db, -image_rejection_db(gain_db, phase_deg), atol=0.2)


def test_image_rejection_formula():
    g = 10 ** (1 / 20)
    assert image_rejection_db(1.0, 0.0) == pytest.approx(20 * math.log10((1 + g) / (g - 1)))
    assert image_rejection_db(0.0, 0.0) == math.inf
    assert image_rejection_db(0.0, 1.0) == pytest.approx(41.2, abs=0.1)


def test_phase_noise_raises_the_doppler_skirt_as_expected():
    """A strong static target: the Doppler floor of its range bin relative to its peak is
    Var(z) sum(v^2) / (|E z|^2 (sum v)^2), z the chirp's windowed range-FFT peak factor
    sum(w_n exp(j phi_n)) / sum(w) (Gauss-Markov phi: E exp(j(phi_n - phi_m)) =
    exp(-s^2 (1 - a^|n-m|))), chirps independent (Tc >> the correlation time)."""
    cfg = replace(TI, num_tx=1, n_doppler=256)
    rms, bw = 3.0, 1e6
    sc = target(20 * BIN, rcs_m2=1.2)
    w = np.hanning(cfg.n_samples)
    v = np.hanning(cfg.n_loops)

    def skirt_db(imp: Impairments) -> float:
        x = frame(imp, sc, cfg=cfg, noise=False, rng=np.random.default_rng(3))
        peak = spectrum(x[:, 0, :], w)[:, 20]
        d = np.abs(np.fft.fft(peak * v)) ** 2
        return float(10 * np.log10(np.mean(d[8:-8]) / d[0]))

    s2 = math.radians(rms) ** 2
    a = math.exp(-2 * math.pi * bw / cfg.sample_rate_hz)
    lag = np.abs(np.subtract.outer(np.arange(cfg.n_samples), np.arange(cfg.n_samples)))
    var = w @ (np.exp(-s2 * (1 - a**lag)) - math.exp(-s2)) @ w / w.sum() ** 2
    want = 10 * math.log10(var * (v**2).sum() / (math.exp(-s2) * v.sum() ** 2))
    got = skirt_db(Impairments(phase_noise_rms_deg=rms, phase_noise_bandwidth_hz=bw))
    assert abs(got - want) < 1.0
    assert skirt_db(Impairments()) < want - 30


def test_static_clutter_only_at_zero_doppler():
    imp = Impairments(walls=(Wall(2.0, -0.5, 2.0, 0.5, rcs_m2=2.0, n_scatterers=16),),
                      ground=Ground(height_m=0.5, rcs_m2=1.0, min_range_m=1.0, max_range_m=2.5,
                                    n_scatterers=32))
    moving = target(1.5 * math.sqrt(2), rcs_m2=0.5, v=0.5)
    r, _, el, rcs = imp.clutter_points()
    assert r.size == 48 and np.isclose(rcs[:16].sum(), 2.0) and np.isclose(rcs[16:].sum(), 1.0)
    assert np.allclose(el[16:], -np.degrees(np.arcsin(0.5 / r[16:])))
    assert np.all((r[:16] >= 2.0) & (r[:16] <= math.hypot(2.0, 0.5)))
    x = frame(imp, noise=False)
    slow = np.fft.fft(x.reshape(TI.n_loops, TI.num_tx, TI.num_rx, -1), axis=0)
    p = np.abs(slow) ** 2
    assert p[1:].sum() < 1e-6 * p[0].sum()
    assert 38 <= np.argmax(np.abs(spectrum(x[0, 0]))) <= 42      # the wall at 2 m (bin 40)
    d = np.abs(np.fft.fft(frame(imp, moving, noise=False)
                          .reshape(TI.n_loops, TI.num_tx, TI.num_rx, -1), axis=0)) ** 2
    assert d[1:].sum() > 1e-3 * d[0].sum()                       # a mover leaves bin 0


def test_real_adc_with_effects_and_iq_refused():
    real = REAL_TI
    imp = Impairments(leakage_dbfs=-30.0, leakage_range_m=3 * BIN, phase_noise_rms_deg=1.0,
                      rx_phase_rms_deg=5.0)
    x = frame(imp, target(20 * BIN), cfg=real)
    assert x.dtype == np.float32 and x.shape == real.adc_shape
    with pytest.raises(ValueError, match="iq_gain_db"):
        simulate_frame(real, none(), impairments=Impairments(iq_gain_db=0.5))
    with pytest.raises(ValueError, match="tx_gain_db: 3 values"):
        simulate_frame(TI, none(), impairments=Impairments(tx_gain_db=(0, 1, 2)))
    with pytest.raises(ValueError, match="leakage_range_m"):
        simulate_frame(TI, none(), impairments=Impairments(leakage_dbfs=-10, leakage_range_m=5))


def test_all_off_equals_no_impairments_and_effects_are_seeded():
    sc = Scene(preset="paper-fpga", seed=2, targets=(PointTarget(20.0, 10.0, 3.0, 10.0),))
    assert np.array_equal(simulate_scene(sc).samples,
                          simulate_scene(replace(sc, impairments=Impairments(seed=9))).samples)
    imp = Impairments(rx_phase_rms_deg=5.0, phase_noise_rms_deg=2.0, dc_offset_dbfs=-50.0)
    a = simulate_scene(replace(sc, impairments=imp)).samples
    assert np.array_equal(a, simulate_scene(replace(sc, impairments=imp)).samples)
    assert not np.array_equal(a, simulate_scene(replace(sc, impairments=replace(imp, seed=1))
                                                ).samples)


SCENE = {"preset": "paper-fpga", "targets": [{"range_m": 20, "azimuth_deg": 0,
                                              "radial_velocity_mps": 0, "rcs_m2": 1}]}


def test_scene_json_round_trip():
    table = {"seed": 4, "rx_phase_deg": [0, 3, -2, 1], "tx_gain_rms_db": 0.5,
             "leakage_dbfs": -25, "leakage_range_m": 0.15, "dc_offset_dbfs": -60,
             "iq_gain_db": 0.2, "iq_phase_deg": 1.5, "phase_noise_rms_deg": 1,
             "phase_noise_bandwidth_hz": 5e5,
             "walls": [{"x1_m": 10, "y1_m": -3, "x2_m": 12, "y2_m": 4, "rcs_m2": 5}],
             "ground": {"height_m": 0.8, "rcs_m2": 2, "min_range_m": 2, "max_range_m": 30}}
    s = Scene.from_dict({**SCENE, "impairments": table})
    assert s.impairments.rx_phase_deg == (0, 3, -2, 1) and s.impairments.walls[0].n_scatterers == 32
    assert Scene.from_dict(s.to_dict()) == s
    assert "impairments" not in Scene.from_dict(SCENE).to_dict()
    assert Impairments(rx_phase_deg=[1, 2], walls=[]) == Impairments(rx_phase_deg=(1, 2))
    builtin = Scene.from_dict({"scene": "table1", "impairments": {"dc_offset_dbfs": -40}})
    assert builtin.impairments.dc_offset_dbfs == -40


@pytest.mark.parametrize("table, message", [
    ({"leakage_dbfs": 3}, r"impairments\.leakage_dbfs: .*\[-200, 0\]"),
    ({"bogus": 1}, r"impairments: unknown field\(s\) \['bogus'\]"),
    ({"rx_phase_deg": [0, "x"]}, r"impairments\.rx_phase_deg\[1\]\.rx_phase_deg"),
    ({"rx_phase_deg": [1], "rx_phase_rms_deg": 2}, r"impairments\.rx_phase_deg: give the list"),
    ({"iq_phase_deg": 45}, r"impairments\.iq_phase_deg"),
    ({"phase_noise_bandwidth_hz": 0}, r"impairments\.phase_noise_bandwidth_hz"),
    ({"walls": [{"x1_m": 1, "y1_m": 0, "x2_m": 1, "y2_m": 0, "rcs_m2": 1}]},
     r"impairments\.walls\[0\]\.x2_m/y2_m"),
    ({"walls": [{"x1_m": 1, "y1_m": 0, "x2_m": 2}]}, r"impairments\.walls\[0\]: missing"),
    ({"ground": {"height_m": 1, "rcs_m2": 1, "min_range_m": 0.5, "max_range_m": 9}},
     r"impairments\.ground\.min_range_m"),
    ({"seed": -1}, r"impairments\.seed"),
    ({"tx_gain_db": [0, 1]}, r"impairments\.tx_gain_db: 2 values for the 1 TX"),
    ({"leakage_dbfs": -10, "leakage_range_m": 0.1, "iq_gain_db": 0.1}, None),
])
def test_bad_impairments_name_the_field(table, message):
    """Checked as the scene loads, against its radar (None: a valid table)."""
    if message is None:
        assert Scene.from_dict({**SCENE, "impairments": table}).impairments.iq_imbalance
        return
    with pytest.raises(ValueError, match=message):
        Scene.from_dict({**SCENE, "impairments": table})


def test_clutter_counts_towards_the_scene_limit():
    walls = tuple(Wall(5.0, -1.0, 5.0, 1.0, 1.0, 1000) for _ in range(3))
    with pytest.raises(ValueError, match="scatterers"):
        Scene(preset="paper-fpga", targets=(PointTarget(20.0, 0.0, 0.0, 1.0),),
              impairments=Impairments(walls=walls))
