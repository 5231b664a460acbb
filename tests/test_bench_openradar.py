"""``benchmarks/bench_openradar.py`` without OpenRadar's virtualenv: the matching against a
fake peer JSON (the runner's format), the printed table, and the missing-virtualenv exit.
``tests/test_benchmarks_import.py`` imports the script."""

from __future__ import annotations

import numpy as np
import pytest

from benchmarks.bench_openradar import Detections, Run, compare, main, modes, near, table

N_DOPPLER = 128


def ours() -> Detections:
    """Points of ours: a target and a spurious second component in its cell, a second
    target, a point at the Doppler wrap, and one where the peer has nothing."""
    return Detections(range_bin=np.array([60, 60, 72, 10, 100]),
                      doppler_bin=np.array([7, 7, 12, -64, 3]),
                      azimuth_deg=np.array([-6.7, 40.0, 21.5, 0.5, 0.0]),
                      strength=np.array([37.7, 20.0, 23.5, 15.0, 13.0]))


def peer_doc() -> dict:
    """The peer runner's JSON: a 15 dB setting with a static and a missed detection."""
    det15 = {"range_bin": [60, 62, 72, 80, 110, 10], "doppler_bin": [7, 8, 12, 5, 0, 63],
             "azimuth_deg": [-6.5, -5.6, 19.2, 3.0, 66.0, 1.0],
             "det_value": [300.0, 280.0, 250.0, 200.0, 210.0, 190.0]}
    demo = {"range_bin": list(range(50)), "doppler_bin": [1] * 50, "azimuth_deg": [0.0] * 50,
            "det_value": [1.0] * 50}
    return {"versions": {"openradar": "1.0.1", "numpy": "2.4", "scikit-learn": "1.9",
                         "python": "3.11"},
            "tdm_compensation_error": "TypeError: slice indices must be integers",
            "settings": {"demo": {"bounds": [1.5, 2.5], "cfar_cells": 120, "detections": demo,
                                  "times_s": [0.25, 0.3, 0.2]},
                         "15 dB": {"bounds": [19.9, 19.9], "cfar_cells": 9, "detections": det15,
                                   "times_s": [0.05, 0.04, 0.06]}}}


def test_near_is_two_bins_and_circular_in_doppler():
    o = Detections(np.array([60, 60, 60]), np.array([7, 12, -64]), np.zeros(3), np.zeros(3))
    p = Detections(np.array([62, 58]), np.array([9, 63]), np.zeros(2), np.zeros(2))
    assert near(o, p, N_DOPPLER).tolist() == [[True, False], [False, False], [False, True]]


def test_compare_counts_finds_angles_and_clusters():
    peer = Detections.of_peer(peer_doc()["settings"]["15 dB"]["detections"])
    a = compare(ours(), peer, N_DOPPLER, angle_tol_deg=14.3)
    assert a.peer_moving == 5                          # the zero-Doppler one is not counted
    assert a.missed == [(80, 5)]
    # (60, 7) of ours is near two of its detections, (60, 7) and (62, 8): one of them once
    assert a.one_to_one == 3
    # strongest per cell, each against its nearest peer detection: same cell, fewest bins
    assert sorted(np.round(a.angle_strongest, 2).tolist()) == [0.2, 0.5, 2.3]
    assert sorted(np.round(a.angle_all, 2).tolist()) == [0.2, 0.5, 2.3, 46.5]
    assert (a.ours, a.outside_cells) == (5, 1)
    assert a.outside == [(60, 7, 40.0), (100, 3, 0.0)]


def test_table_reports_against_the_goals():
    doc = peer_doc()
    peer = Detections.of_peer(doc["settings"]["15 dB"]["detections"])
    a = compare(ours(), peer, N_DOPPLER, angle_tol_deg=14.3)
    first = ours()
    second = Detections(*(x[[0, 2, 3]] for x in (first.range_bin, first.doppler_bin,
                                                  first.azimuth_deg, first.strength)))
    runs = [Run("default", (), first, [0.01, 0.012, 0.011], a, [0.004] * 3),
            Run("peer-ca", modes(15.0)["peer-ca"], second, [0.02, 0.03, 0.025],
                compare(second, peer, N_DOPPLER, angle_tol_deg=14.3), [0.005] * 3)]
    for setting, cpu in (("15 dB", 0.01), ("demo", 0.05)):
        doc["settings"][setting]["cpu_s"] = [cpu] * 3
    text = table(doc, runs, 15.0, (1.0, 1.5, 2.0))
    lines = text.splitlines()
    assert "OpenRadar 1.0.1" in lines[0] and "load average 1.00 1.50 2.00" in lines[1]
    assert "peer BLAS threads 1, ours 1" in lines[1] and lines[2].startswith("near: <= 2")
    assert lines[4].split() == ["default", "peer-ca", "peer", "15", "dB", "peer", "demo"]
    row = next(line for line in lines if line.startswith("host time per frame"))
    assert row.split()[-4:] == ["11.00", "25.00", "50.00", "250.00"]
    row = next(line for line in lines if line.startswith("... its CPU time"))
    assert row.split()[-4:] == ["4.00", "5.00", "10.00", "50.00"]
    row = next(line for line in lines if line.startswith("detections"))
    assert row.split()[-4:] == ["5", "3", "6", "50"]
    default, matched = text.split("ours default (no options) vs the peer's 15 dB")[1].split(
        "ours peer-ca (--grouping doppler --min-snr-db 15) vs the peer's 15 dB")
    assert "4 of 5  goal all: MISSED" in default
    assert "  ... each cell of ours counted once        3 of 5\n" in default
    assert "max 2.30 deg (n=3)  goal <= 2 deg: MISSED" in default
    assert "2 of 5 (40 %)  goal <= 10 %: MISSED" in default
    assert "0.22  goal <= 1/3: met" in default
    assert "CPU time / its CPU time               0.40  goal <= 1/3: MISSED" in default
    assert "ours misses (range bin,Doppler bin): (80,5)" in default
    assert "(range bin,Doppler bin,az deg): (60,7,40) (100,3,0)" in default
    assert "0 of 3 (0 %)  goal <= 10 %: met" in matched
    assert "0.50  goal <= 1/3: MISSED" in matched
    assert "TypeError: slice indices must be integers" in matched


def test_modes_match_the_peer_threshold_and_grouping():
    m = modes(12.5)
    assert m["default"] == ()
    assert m["peer-ca"] == ("--grouping", "doppler", "--min-snr-db", "12.5")
    assert m["peer-os"] == ("--detector", "os", *m["peer-ca"])


def test_no_peer_virtualenv(tmp_path, capsys):
    assert main(["--peer-python", str(tmp_path / "python")]) == 2
    assert "make bench-openradar" in capsys.readouterr().err


@pytest.mark.parametrize("missing", [[], [40.0]])
def test_table_without_angles(missing):
    """No point of ours near any peer detection: no angle numbers, the angle goal missed."""
    doc = peer_doc()
    peer = Detections.of_peer(doc["settings"]["15 dB"]["detections"])
    far = Detections(np.array([120] * len(missing)), np.array([40] * len(missing)),
                     np.array(missing), np.array(missing))
    run = Run("default", (), far, [0.01], compare(far, peer, N_DOPPLER, 14.3))
    text = table(doc, [run], 15.0, (0.0, 0.0, 0.0))
    assert "every point" in text and "-  goal <= 2 deg: MISSED" in text


def test_cells_cause_names_the_step_that_lost_a_cell():
    """``benchmarks/openradar_cells.py``: a cell of the peer's that a setting of ours misses
    is under its CFAR's threshold (CA: with the Pfa it would need), under --min-snr-db, or
    detected but grouped into a peak more than 2 bins away; found cells give ''."""
    from benchmarks.openradar_cells import cause, markdown

    row = {"r": 64, "d": 5, "az": -8.5, "peer_margin": 17.0, "peer_floor": 35.0,
           "ours_floor": 32.9, "ca_snr": 3.2, "ca_margin": -2.5, "ca_pfa": 0.008,
           "os_snr": 12.9, "os_margin": 7.2, "peak": True,
           "default": "", "peer-ca": "", "peer-os": "", "os-peak": "(64,5)"}
    assert cause(row, "default", 15.0) == "CA-CFAR: -2.5 dB under its threshold, needs " \
                                           "Pfa 0.008"
    assert cause(row, "peer-os", 15.0) == "--min-snr-db 15: 12.9 dB over the OS noise"
    assert cause({**row, "os_snr": 16.0}, "peer-os", 15.0) == \
        "detected, grouped into a peak > 2 bins away"
    assert cause(row, "os-peak", 15.0) == ""
    text = markdown([row], ["default", "os-peak"], 15.0)
    assert "| 64 | 5 | -8.5 | +17.0 |" in text and "| (64,5) |" in text
    assert "- os-peak: 1 of 1 found" in text and "- default: 0 of 1 found; missed: (64,5)" \
        in text
