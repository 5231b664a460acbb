"""Radar profiles (docs/profiles.md): TOML and TI .cfg -> RadarConfig, the presets as profiles,
every bad field named in one line, `radar profile show`, and the chain refusing what it does
not support yet."""

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from model.config import PRESETS
from model.profile import (
    default_min_range_m,
    load_profile,
    preset_profile,
    profile_from_toml,
    profile_to_toml,
)
from model.profile_fields import preset_chain_features
from model.scene import Scatterers
from model.simulate import simulate_frame
from model.ti_cfg import profile_from_cfg
from radar.cli import main

DATA = Path(__file__).parent / "data" / "openradar"
OPENRADAR_CFG = DATA / "openradar_2tx4rx.cfg"

CONTRACT_TOML = """
name = "awr1843-boost"
[waveform]
start_frequency_hz = 77.0e9
slope_hz_per_s     = 60.0e12
sample_rate_hz     = 2.5e6
samples_per_chirp  = 128
range_fft          = 128
idle_time_s        = 30.0e-6
ramp_end_time_s    = 62.0e-6
adc_start_time_s   = 6.0e-6
loops              = 128
doppler_fft        = 128
tx_order           = [0, 1]
adc                = "complex"
frame_period_s     = 0.05
max_speed_mps      = 5.26
[array]
tx = [[0, 0], [4, 0]]
rx = [[0, 0], [1, 0], [2, 0], [3, 0]]
[capture]
format      = "dca1000"
lanes       = 2
interleaved = false
"""
"""The example profile of docs/profiles.md."""


def toml_with(**changes: str) -> str:
    """CONTRACT_TOML with lines ``key = ...`` replaced (``key`` -> new right-hand side)."""
    lines = []
    for line in CONTRACT_TOML.splitlines():
        key = line.split("=")[0].strip()
        lines.append(f"{key} = {changes[key]}" if key in changes else line)
    return "\n".join(lines)


def test_presets_are_profiles_unchanged():
    for name, cfg in PRESETS.items():
        p = load_profile(name)
        assert p.config is cfg and p.capture.format == "npy"
        assert cfg.unsupported_features() == [] and cfg.uniform_linear_array
        assert (cfg.n_samples, cfg.n_loops) == (cfg.n_range, cfg.n_doppler)
        assert np.array_equal(cfg.virtual_positions_hw[:, 0], np.arange(cfg.n_virtual))
        # TOML round trip: the same radar (a profile's max speed defaults to its own
        # unambiguous speed and its near-range guard to the leakage zone; the preset
        # keeps the host's default speed and guards range bin 0 only)
        back = profile_from_toml(profile_to_toml(p), "x.toml").config
        assert back.max_speed_mps == pytest.approx(cfg.max_velocity_mps)
        assert back.min_range_m == pytest.approx(default_min_range_m(cfg))
        assert cfg.min_range_m is None and cfg.detection_bins[0] == 1
        back = replace(back, max_speed_mps=None, min_range_m=None, name=cfg.name)
        assert back.sweep_bandwidth_hz == pytest.approx(cfg.sweep_bandwidth_hz, rel=1e-15)
        assert replace(back, sweep_bandwidth_hz=cfg.sweep_bandwidth_hz) == cfg


def test_contract_toml():
    p = profile_from_toml(CONTRACT_TOML, "awr.toml")
    c = p.config
    assert (c.name, c.num_tx, c.num_rx, c.n_range, c.n_doppler) == ("awr1843-boost", 2, 4,
                                                                     128, 128)
    assert c.chirp_period_s == pytest.approx(92e-6)
    assert c.slope_hz_per_s == pytest.approx(60e12)
    assert c.sweep_bandwidth_hz == pytest.approx(3.072e9)
    assert c.range_bin_m == pytest.approx(0.0488, abs=1e-4)
    assert c.max_speed_mps == 5.26 and c.frame_period_s == 0.05
    assert (p.capture.format, p.capture.lanes, p.capture.interleaved) == ("dca1000", 2, False)
    # the defaults are normalised away: the same radar as the default ULA, in order
    assert c.tx_positions is None and c.tx_order is None and c.samples_per_chirp is None
    assert c.unsupported_features() == []
    assert profile_from_toml(profile_to_toml(p), "awr.toml").config == c


def test_openradar_cfg_documented_numbers():
    p = load_profile(OPENRADAR_CFG)
    c = p.config
    assert (c.num_tx, c.num_rx, c.n_samples, c.n_loops, c.adc) == (2, 4, 128, 128, "complex")
    assert c.fc_hz == pytest.approx(77.4201e9)
    assert c.sweep_bandwidth_hz == pytest.approx(3.072e9)          # README: 3.072 GHz
    assert c.range_bin_m * 100 == pytest.approx(4.88, abs=0.005)   # 4.88 cm
    assert c.max_range_m == pytest.approx(6.25, abs=0.005)         # 6.25 m
    assert c.velocity_bin_mps == pytest.approx(0.082, abs=0.0005)  # 0.082 m/s
    assert c.max_velocity_mps == pytest.approx(5.26, abs=0.005)    # +-5.26 m/s
    assert c.tx_repetition_s == pytest.approx(184e-6)              # 184 us per loop
    assert np.array_equal(c.virtual_positions_hw[:, 0], np.arange(8))
    assert c.unsupported_features() == []                           # the chain takes it
    assert (p.capture.lanes, p.capture.interleaved) == (2, False)
    assert p.calibration is not None and p.calibration.channel_gain == (1 + 0j,) * 8
    # .cfg -> TOML -> the same radar
    back = profile_from_toml(profile_to_toml(p), "openradar_2tx4rx.toml").config
    assert replace(back, sweep_bandwidth_hz=c.sweep_bandwidth_hz) == c


BEYOND_CFG = """\
sensorStop
channelCfg 15 7 0
adcCfg 2 0
adcbufCfg -1 1 1 1 1
profileCfg 0 77 7 6 60 0 0 30 1 200 5000 0 0 30
chirpCfg 0 0 0 0 0 0 0 4
chirpCfg 1 1 0 0 0 0 0 1
chirpCfg 2 2 0 0 0 0 0 2
frameCfg 0 2 255 0 100 1 0
compRangeBiasAndRxChanPhase 0.05 1 0 1 0 1 0 1 0 0 1 0 1 0 1 0 1 -1 0 -1 0 -1 0 -1 0
sensorStart
"""
"""An xWR1843-style .cfg: 3 TX (TX1 raised), real ADC, 200 samples, 255 loops, TX2 first."""


def test_cfg_beyond_the_chain_loads_and_is_refused_by_the_chain():
    p = profile_from_cfg(BEYOND_CFG, "xwr1843.cfg")
    c = p.config
    assert (c.num_tx, c.n_samples, c.n_range, c.n_loops, c.n_doppler) == (3, 200, 256, 255,
                                                                          256)
    assert c.adc == "real" and c.tx_sequence == (2, 0, 1)
    assert c.tx_positions_hw.tolist() == [[0, 0], [2, 1], [4, 0]]
    assert c.max_range_m == pytest.approx(c.n_range * c.range_bin_m / 2)
    assert p.calibration.range_bias_m == 0.05
    assert p.calibration.channel_gain == (1,) * 4 + (1j,) * 4 + (-1,) * 4
    features = " ".join(preset_chain_features(c))
    for word in ("200 samples", "255 loops", "firing order", "real-valued ADC"):
        assert word in features
    assert c.unsupported_features() == []                 # the float chain takes them all
    c.check_adc(np.zeros(c.adc_shape))
    assert simulate_frame(c, Scatterers(*(np.ones(1),) * 4, np.zeros(1, dtype=int))
                          ).samples.shape == c.adc_shape      # the simulator models it all
    back = profile_from_toml(profile_to_toml(p)).config
    assert replace(back, sweep_bandwidth_hz=c.sweep_bandwidth_hz) == c


@pytest.mark.parametrize("changes, message", [
    (dict(slope_hz_per_s="-60.0e12"), "waveform.slope_hz_per_s: must be positive"),
    (dict(sample_rate_hz="0.5e6"), "waveform.ramp_end_time_s"),
    (dict(samples_per_chirp="4"), "waveform.samples_per_chirp: must be at least 8"),
    (dict(samples_per_chirp="130"), "waveform.samples_per_chirp: must be an integer in 8..128"),
    (dict(range_fft="100"), "waveform.range_fft"),
    (dict(loops="2.5"), "waveform.loops: must be an integer"),
    (dict(tx_order="[0, 2]"), "waveform.tx_order: TX index 2 out of range 0..1"),
    (dict(tx_order="[1, 1]"), "waveform.tx_order: every TX"),
    (dict(adc='"iq"'), "waveform.adc"),
    (dict(frame_period_s="0.001"), "waveform.frame_period_s"),
    (dict(ramp_end_time_s="40e-6"), "waveform.ramp_end_time_s: 40.000 us ends before"),
    (dict(tx="[[0, 0], [4]]"), r"array.tx\[1\]: must be two numbers"),
    (dict(rx='"abc"'), "array.rx: must be a non-empty list"),
    (dict(lanes="3"), "capture.lanes"),
    (dict(format='"wav"'), "capture.format"),
    (dict(interleaved="true"), "capture.lanes"),
    (dict(name='""'), "name"),
])
def test_bad_toml_field_named(changes, message):
    with pytest.raises(ValueError, match=message) as err:
        profile_from_toml(toml_with(**changes), "bad.toml")
    assert str(err.value).startswith("bad.toml: ") and "\n" not in str(err.value)


@pytest.mark.parametrize("text, message", [
    (CONTRACT_TOML + "max_range_m = 10.0\n", "unknown key"),
    (CONTRACT_TOML.replace("adc_start_time_s   = 6.0e-6",
                           "adc_start_time_s = 6.0e-6\nmax_range_m = 10.0"),
     "waveform.max_range_m: beat frequency 4.00 MHz of 10.0 m is at or above sample_rate_hz"),
    (CONTRACT_TOML.replace("adc_start_time_s   = 6.0e-6", "colour = 1"),
     "waveform.colour: unknown key"),
    (CONTRACT_TOML.replace("samples_per_chirp  = 128", ""), "waveform.samples_per_chirp: "
                                                            "missing"),
    (CONTRACT_TOML.replace("idle_time_s        = 30.0e-6", ""), "waveform.idle_time_s"),
    ("name = 1 2", "not valid TOML"),
])
def test_bad_toml_named(text, message):
    with pytest.raises(ValueError, match=message):
        profile_from_toml(text, "bad.toml")


def cfg_with(old: str, new: str) -> str:
    text = OPENRADAR_CFG.read_text()
    assert old in text
    return text.replace(old, new)


@pytest.mark.parametrize("text, message", [
    (cfg_with("lowPower 0 0", "fooCfg 1 2"), "fooCfg: unknown command"),
    (cfg_with("adcCfg 2 1", "adcCfg 2 1\nadcCfg 2 1"), "adcCfg: given twice"),
    (cfg_with("adcCfg 2 1", "adcCfg 2 0"), "adcbufCfg: adcOutputFmt 0 .complex. contradicts"),
    (cfg_with("chirpCfg 1 1 0 0 0 0 0 2", "chirpCfg 1 1 0 0 0 0 0 4"),
     "chirpCfg: chirps 1..1 fire TX mask 4, not enabled by channelCfg"),
    (cfg_with("chirpCfg 1 1 0 0 0 0 0 2", "chirpCfg 1 1 0 0 0 0 0 3"), "exactly one TX"),
    (cfg_with("chirpCfg 1 1 0 0 0 0 0 2", "chirpCfg 0 1 0 0 0 0 0 2"),
     "chirpCfg: chirp 0 configured twice"),
    (cfg_with("chirpCfg 1 1 0 0 0 0 0 2", ""), "chirpCfg: chirp 1 of frameCfg 0..1"),
    (cfg_with("chirpCfg 1 1 0 0 0 0 0 2", "chirpCfg 1 1 0 0 0 0 0 1"), "TX fires twice"),
    (cfg_with("chirpCfg 1 1 0 0 0 0 0 2", "chirpCfg 1 1 0 0 5 0 0 2"), "per-chirp"),
    (cfg_with("frameCfg 0 1 128 0 50 1 0", ""), "frameCfg: missing"),
    (cfg_with("frameCfg 0 1 128 0 50 1 0", "frameCfg 0 1 128 0 10 1 0"),
     "frameCfg framePeriodicity"),
    (cfg_with(" 60 1 128 2500 ", " -60 1 128 2500 "), "profileCfg: freqSlopeConst must be "
                                                      "positive"),
    (cfg_with(" 60 1 128 2500 ", " 60 1 128 1000 "), "profileCfg: rampEndTime 62 us ends"),
    (cfg_with("profileCfg 0 77.4201", "profileCfg 0 x"), "profileCfg: arguments must be"),
    (cfg_with("channelCfg 15 3 0", "channelCfg 15 3"), "channelCfg: expected 3 arguments"),
    (cfg_with("dfeDataOutputMode 1", "dfeDataOutputMode 3"), "dfeDataOutputMode"),
    (cfg_with("compRangeBiasAndRxChanPhase 0.0 1 0", "compRangeBiasAndRxChanPhase 0.0"),
     "compRangeBiasAndRxChanPhase: expected"),
])
def test_bad_cfg_command_named(text, message):
    with pytest.raises(ValueError, match=message) as err:
        profile_from_cfg(text, "bad.cfg")
    assert str(err.value).startswith("bad.cfg: ") and "\n" not in str(err.value)


def test_load_profile_bad_spec(tmp_path):
    with pytest.raises(ValueError, match="neither a preset"):
        load_profile("nope")
    with pytest.raises(ValueError, match="no such file"):
        load_profile(str(tmp_path / "x.toml"))


def test_profile_show_preset(capsys):
    assert main(["profile", "show", "full"]) == 0
    out = capsys.readouterr().out
    cfg = preset_profile("full").config
    for text in ("4 TX x 16 RX = 64 virtual channels", "1.7275 m", "442.24 m", "0.217 m/s",
                 "+-27.78 m/s", "1.79 deg", "8.76 us period", "supported by the chain"):
        assert text in out, text
    assert f"{cfg.frame_time_s * 1e3:.4g} ms" in out


def test_profile_show_files(tmp_path, capsys):
    assert main(["profile", "show", str(OPENRADAR_CFG)]) == 0
    out = capsys.readouterr().out
    for text in ("2 TX x 4 RX", "0.048794 m", "6.2457 m", "+-5.261 m/s", "2 LVDS lanes",
                 "   0 1 2 3 4 5 6 7", "supported by the chain"):
        assert text in out, text
    beyond = tmp_path / "xwr1843.cfg"
    beyond.write_text(BEYOND_CFG)
    assert main(["profile", "show", str(beyond)]) == 0
    out = capsys.readouterr().out
    assert "elevation resolution" in out and "supported by the chain" in out
    assert "200 (zero-padded to 256)" in out and "255 (zero-padded to 256)" in out
    profile = tmp_path / "awr.toml"
    profile.write_text(CONTRACT_TOML)
    assert main(["profile", "show", str(profile)]) == 0
    assert "awr1843-boost" in capsys.readouterr().out


def test_profile_show_bad_input_one_line_exit_2(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text(toml_with(slope_hz_per_s="-1.0"))
    assert main(["profile", "show", str(bad)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "waveform.slope_hz_per_s" in err
    assert main(["profile", "show", "nope"]) == 2
    assert "neither a preset" in capsys.readouterr().err
