"""Radar presets: derived numbers equal DESIGN.md section 2; bad configurations are refused."""

from dataclasses import replace

import pytest

from model.config import PRESETS, get_preset

# DESIGN.md section 2 table, at the precision it is quoted.
EXPECTED = {
    "paper-fpga": dict(num_tx=1, num_rx=4, n_virtual=4, n_range=64, n_doppler=256,
                       sample_rate_msps="19.33", sampled_chirp_us="3.311", chirp_period_us="35.04",
                       tx_repetition_us="35.04", range_bin_m="1.7275", max_range_m="110.6",
                       velocity_bin_mps="0.217", max_velocity_mps="27.78",
                       angle_resolution_deg="28.65", data_rate_per_lane_mbps="618.56"),
    "full": dict(num_tx=4, num_rx=16, n_virtual=64, n_range=256, n_doppler=256,
                 sample_rate_msps="32.5", sampled_chirp_us="7.877", chirp_period_us="8.76",
                 tx_repetition_us="35.04", range_bin_m="1.7275", max_range_m="442",
                 velocity_bin_mps="0.217", max_velocity_mps="27.78", angle_resolution_deg="1.79",
                 data_rate_per_lane_mbps="1040.0"),
}


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_preset_matches_design_table(name):
    summary = PRESETS[name].summary()
    for key, want in EXPECTED[name].items():
        got = summary[key]
        if isinstance(want, int):
            assert got == want, key
        else:
            # quoted as in DESIGN.md: equal to half a unit of the last quoted digit
            digits = len(want.split(".")[1]) if "." in want else 0
            assert abs(got - float(want)) <= 0.5 * 10.0**-digits + 1e-12, (key, got, want)


def test_common_numbers():
    for cfg in PRESETS.values():
        assert cfg.wavelength_m == pytest.approx(3.8934e-3, abs=1e-7)
        assert cfg.max_velocity_mps * 3.6 == pytest.approx(100.0, rel=1e-3)  # 100 km/h
        assert cfg.velocity_bin_mps * 3.6 * 2 == pytest.approx(1.56, abs=0.01)  # paper 1.6 km/h
        assert 2 * cfg.range_bin_m == pytest.approx(3.455, abs=0.01)  # paper "3.5 m"
        assert cfg.beat_frequency_hz(cfg.design_max_range_m) < cfg.sample_rate_hz


def test_paper_fpga_beat_frequency_is_the_papers():
    # "maximum beat frequency of ~17.4 MHz ... sampled at 17.4/0.8 = 19.33 MSPS"
    cfg = get_preset("paper-fpga")
    assert cfg.beat_frequency_hz(100.0) / 1e6 == pytest.approx(17.4, abs=0.1)


def test_full_reaches_300m():
    assert get_preset("full").max_range_m >= 300.0


@pytest.mark.parametrize("change, field", [
    (dict(n_range=100), "n_range"),
    (dict(n_doppler=8192), "n_doppler"),
    (dict(num_rx=0), "num_rx"),
    (dict(num_tx=0), "num_tx"),
    (dict(design_max_range_m=500.0), "design_max_range_m"),
    (dict(chirp_period_s=5e-6), "chirp_period_s"),
    (dict(sample_rate_hz=-1.0), "sample_rate_hz"),
    (dict(adc_bits=40), "adc_bits"),
    (dict(num_rx=2.5), "num_rx"),
    (dict(fc_hz=float("nan")), "fc_hz"),
])
def test_invalid_configuration_names_the_field(change, field):
    with pytest.raises(ValueError, match=field):
        replace(PRESETS["full"], **change)


def test_unknown_preset():
    with pytest.raises(ValueError, match="preset"):
        get_preset("nope")
