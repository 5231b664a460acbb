"""Whole frames for the estimation curves (``campaign.frames``, the ``estimation_frames``
trial function and its JSON rows, docs/curves.md "Whole frames")."""

from __future__ import annotations

import math

import numpy as np

from campaign import frames
from campaign import trials as tr
from campaign.curves import Plan, frame_rows
from model import detection_theory as dt
from model.config import PRESETS
from model.reference import radar_cube, range_doppler_power

CFG = PRESETS["full"]


def test_targets_share_no_row_or_column_and_keep_apart() -> None:
    cells = frames.target_cells(CFG)
    assert len(cells) == frames.TARGETS
    dr = np.abs(cells[:, None, 0] - cells[None, :, 0])
    dd = np.abs(cells[:, None, 1] - cells[None, :, 1])
    dd = np.minimum(dd, CFG.n_doppler - dd)                      # Doppler is circular
    off = ~np.eye(len(cells), dtype=bool)
    assert dr[off].min() >= frames.PITCH and dd[off].min() >= frames.PITCH


def test_tone_frame_puts_each_target_in_its_cell() -> None:
    rng = np.random.default_rng(1)
    off = rng.random((frames.TARGETS, 2)) * 0.6 - 0.3
    adc = frames.tone_frame(rng, CFG, 1.0, 1e-12, off, np.zeros(frames.TARGETS))
    nci = range_doppler_power(radar_cube(adc, CFG))
    cells = frames.target_cells(CFG)
    top = np.argsort(nci.ravel())[::-1][:frames.TARGETS]
    assert set(top) == set(np.ravel_multi_index(cells.T, nci.shape))


def test_estimation_frames_float_refined_and_bit_accurate() -> None:
    """One frame of 64 targets at -20 dB per sample (cell SNR 24.6 dB): the refinement is
    near the whole data's CRB, the bit-accurate chain's interpolation near the bound of the
    three cells it reads (wide margins: 64 trials)."""
    out = tr.estimation_frames({"snr_db": -20.0, "chains": ["float_refined", "bit_accurate"]},
                               range(1), 1, 3)
    assert out["trials"] == frames.TARGETS and out["float_refined:refine_s"] > 0
    crb = dt.tone_frequency_crb(0.01, CFG.n_range, CFG.n_doppler * CFG.n_virtual) \
        * CFG.n_range * CFG.range_bin_m
    excess = {c: 10 * math.log10(out[f"{c}:se_range_m"] / 64 / crb ** 2)
              for c in ("float_refined", "bit_accurate")}
    assert excess["float_refined"] < 2.5, excess
    assert 7.1 - 2.0 < excess["bit_accurate"] < 7.1 + 4.0, excess


def test_frame_rows() -> None:
    plan = Plan(snr=(-30.0, -20.0, 10.0), frame_trials=64)
    fake = {}
    for s in (-30.0, -20.0):
        r = {"trials": 64}
        for chain in tr.FRAME_CHAINS:
            r.update({f"{chain}:se_range_m": 64 * 1e-4, f"{chain}:se_velocity_mps": 64 * 1e-6,
                      f"{chain}:se_azimuth_deg": 64 * 1e-2, f"{chain}:refine_s": 0.64})
        fake[f"frames:{s}"] = r
    rows = frame_rows(plan, fake, CFG)
    got = {(r["chain"], r["quantity"]) for r in rows}
    assert ("bit_accurate", "azimuth") in got and ("float_refined", "azimuth") not in got
    assert len(rows) == 3 + 2 * 3
    ref = next(r for r in rows if r["chain"] == "float_refined" and r["quantity"] == "range")
    assert ref["rmse"] == [0.01, 0.01] and ref["refine_ms_per_cell"] == 10.0
    assert ref["taper_loss_db"] > 0 and "crb_cells" in ref and ref["trials"] == 64
    assert frame_rows(Plan(frame_trials=0), {}, CFG) == []
