"""Sanity checks of the verification tools (tools/mutate.py, tools/formal.py) and the fixed
CI mutant subset: realistic one-line RTL bugs that the regression must kill."""

from __future__ import annotations

import dataclasses
import importlib.util
import json
import os
import re
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]


def _load(name: str):
    """tools/<name>.py as the module ``tools_<name>`` (not ``<name>``: tools/coverage.py must
    not stand in for the coverage package that numba imports, in this process or in the
    processes it forks)."""
    key = f"tools_{name}"
    spec = importlib.util.spec_from_file_location(key, REPO / "tools" / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules[key] = mod
    spec.loader.exec_module(mod)
    return mod


mutate = _load("mutate")
formal = _load("formal")
coverage = _load("coverage")


def test_loading_the_tools_leaves_imports_alone() -> None:
    """Neither tools/ on sys.path nor a tools module under a package's name: the cocotb runner
    hands this process's sys.path to every later simulation as PYTHONPATH, where numba's
    `import coverage` would find tools/coverage.py and fail."""
    assert not any(Path(p).resolve() == REPO / "tools" for p in sys.path if p)
    assert "coverage" not in sys.modules or "tools" not in str(
        getattr(sys.modules["coverage"], "__file__", ""))


def test_every_operator_has_mutants() -> None:
    ops = {m.op for mod in mutate.TESTS for m in mutate.candidates(mod)}
    assert ops == {"rel", "arith", "logic", "drop", "neg", "const", "noreset", "sticky", "swap",
                   *mutate.NEW_OPS}


def test_checks_are_never_mutated() -> None:
    for mod in mutate.TESTS:
        for m in mutate.candidates(mod):
            assert "assert" not in m.before and "assume" not in m.before, m.ident
            assert not re.search(r"\bf_\w+", m.before.split("//")[0]), m.ident
            assert "$fatal" not in m.before, m.ident


def test_sample_is_deterministic_and_spread() -> None:
    with_mutants = {mod for mod in mutate.TESTS if mutate.candidates(mod)}
    n = len(with_mutants)      # one mutant per module at least
    a = mutate.sample(list(mutate.TESTS), n, seed=3)
    b = mutate.sample(list(mutate.TESTS), n, seed=3)
    assert [m.ident for m in a] == [m.ident for m in b]
    assert {m.module for m in a} == with_mutants
    assert [m.ident for m in mutate.sample(list(mutate.TESTS), n, seed=4)] != \
        [m.ident for m in a]


def test_apply_writes_only_the_copy(tmp_path: Path) -> None:
    m = mutate.candidates("mark_fifo")[0]
    (tmp_path / Path(m.path).parent).mkdir(parents=True)
    original = (REPO / m.path).read_text()
    (tmp_path / m.path).write_text(original)
    mutate.apply(m, tmp_path)
    assert (REPO / m.path).read_text() == original
    changed = (tmp_path / m.path).read_text().splitlines()
    assert changed[m.line - 1] == m.after
    assert sum(x != y for x, y in zip(changed, original.splitlines(), strict=True)) == 1


def test_formal_files_declare_tasks_and_depths() -> None:
    files = sorted((REPO / "formal").glob("*.sby"))
    assert len(files) >= 7
    for sby in files:
        props, tasks, depths = formal.sby_tasks(sby)
        assert props and any(t.startswith("cover") for t in tasks), sby
        assert any(t.startswith(("prove", "bmc")) for t in tasks), sby
        assert all(depths[t] > 0 for t in tasks)


def test_every_block_testbench_is_mapped() -> None:
    """Every RTL module with a testbench (its own or its parent's) has mutation stages, and
    every testbench folder is run by the coverage tool."""
    tb_modules = set(coverage.TBS)
    assert {"nci", "cfar_2d", "detect_records", "detect_chain", "frame_store_axi",
            "mark_fifo", "fft_axis", "radar_pipeline"} <= tb_modules
    rtl = {p.stem for p in (REPO / "rtl").rglob("*.sv")
           if not p.stem.endswith("_pkg") and p.stem != "axis_checker"}
    assert rtl - set(mutate.TESTS) == set(), "RTL modules without mutation stages"
    for stages in mutate.TESTS.values():
        for stage in stages:
            for arg in stage:
                path = arg.split("::")[0]
                assert arg == "-k" or not path.startswith("tb") or (REPO / path).exists(), arg
    assert set(mutate.CHEAPEST) <= tb_modules


def test_mutant_applies_after_lines_moved(tmp_path: Path) -> None:
    m = mutate.candidates("frame_store_fifo")[0]
    (tmp_path / Path(m.path).parent).mkdir(parents=True)
    (tmp_path / m.path).write_text("// a new first line\n" + (REPO / m.path).read_text())
    mutate.apply(m, tmp_path)
    assert (tmp_path / m.path).read_text().splitlines()[m.line] == m.after


def _row(m, verdict: str = "killed", **change) -> dict:
    return {**dataclasses.asdict(m), "ident": m.ident, "verdict": verdict, "seconds": 1,
            **change}


def test_a_verdict_whose_line_changed_is_stale(tmp_path: Path, capsys) -> None:
    """A recorded verdict counts for the mutant whose line it recorded: an RTL edit renumbers
    a module's mutants (frame_align's look-ahead flags did), so a verdict follows its line to
    its new identifier, and one whose line changed must not stand in for today's mutant, in
    ``--resume`` or in ``--report``."""
    a, b, c, d = mutate.candidates("frame_store_fifo")[:4]
    current = [_row(a), _row(b, "survived", after="  " + b.after + "  ")]  # spaces only
    changed = _row(c, after=c.after + " // elsewhere", before="x <= y;")
    renumbered = _row(d, ident="frame_store_fifo:rel:999", line=1)  # d's line, another name
    cur, stale = mutate.split_stale([*current, changed, renumbered])
    def by_ident(rows: list[dict]) -> list[dict]:
        return sorted(rows, key=lambda r: r["ident"])

    assert by_ident(cur) == by_ident([*current, {**renumbered, "ident": d.ident,
                                                 "index": d.index, "line": d.line}])
    assert stale == [changed]
    assert mutate.split_stale([_row(d, "survived"), renumbered])[0] == [_row(d, "survived")]
    # --report leaves the stale out; --merge: a current verdict wins over a stale one
    res, other = tmp_path / "res.json", tmp_path / "other.json"
    res.write_text(json.dumps([*current, changed]))
    other.write_text(json.dumps([_row(c, "survived")]))
    assert mutate.main(["--report", "--json", str(res)]) == 0
    out = capsys.readouterr().out
    assert "| frame_store_fifo | 2 | 1 | 0 | 1 |" in out and "stale verdicts" in out
    assert mutate.main(["--report", "--json", str(res), "--merge", str(other)]) == 0
    out = capsys.readouterr().out
    assert "| frame_store_fifo | 3 | 1 | 0 | 2 |" in out and "stale" not in out
    assert {r["ident"]: r["verdict"] for r in json.loads(res.read_text())}[c.ident] == \
        "survived"
    # a renumbered verdict is written back under its new identifier
    res.write_text(json.dumps([renumbered]))
    assert mutate.main(["--report", "--json", str(res), "--merge", str(other)]) == 0
    assert sorted(r["ident"] for r in json.loads(res.read_text())) == sorted([c.ident, d.ident])


def test_coverage_table_and_parse(tmp_path: Path) -> None:
    dat = tmp_path / "a.dat"
    key = "\x01f\x02/x/rtl/buffers/m.sv\x01l\x02{}\x01page\x02v_line/m__P3\x01h\x02top.u{}"
    # line 12 hit in one instance only (the instance is dropped from the key), 13 never
    dat.write_text(f"# SystemC::Coverage-3\nC '{key.format(12, 1)}' 0\n"
                   f"C '{key.format(12, 2)}' 5\nC '{key.format(13, 1)}' 0\n")
    points = coverage.parse_points([dat, dat])
    table = coverage.summary(points)
    assert table["m"]["line"] == [1, 2]
    text = coverage.table_text(table, markdown=True)
    assert "| `m` | 1/2 (50.0%) | - | - |" in text


def test_coverage_waivers(tmp_path: Path) -> None:
    """The project's waiver file loads; a waiver leaves its points out of hit and total alike
    (toggle: by signal name, line: by source text); a malformed entry names itself."""
    assert coverage.load_waivers(), "tools/coverage_waivers.toml holds no waiver"
    w = coverage.Waiver(name="ctr", kind="toggle", module="*", signal=r"\w+_count",
                        reason="counters")
    tog = "\x01page\x02v_toggle/m\x01o\x02{}"
    dat = tmp_path / "a.dat"
    dat.write_text("# SystemC::Coverage-3\n" + "".join(
        f"C '{tog.format(o)}' {n}\n" for o, n in [("x_count[31]:0->1", 0),
                                                    ("x_count[0]:0->1", 3),
                                                    ("data[3]:0->1", 0), ("data[0]:0->1", 1)]))
    points = coverage.parse_points([dat])
    assert coverage.summary(points)["m"]["toggle"] == [2, 4]
    waived = coverage.assign_waivers(points, [w])
    assert coverage.summary(points, waived)["m"]["toggle"] == [1, 2]
    text = coverage.table_text(coverage.summary(points), markdown=True,
                               waived=coverage.summary(points, waived))
    assert "| `m` | - | - | 2/4 (50.0%) | - | 50.0% |" in text
    bad = tmp_path / "w.toml"
    bad.write_text('[[waiver]]\nname = "nope"\nkind = "toggle"\nmodule = "*"\nsignal = "x"\n')
    with pytest.raises(ValueError, match="waiver nope: no reason"):
        coverage.load_waivers(bad)
    bad.write_text('[[waiver]]\nname = "l"\nkind = "line"\nmodule = "m"\nsignal = "x"\n'
                   'reason = "r"\n')
    with pytest.raises(ValueError, match="names source text"):
        coverage.load_waivers(bad)


@pytest.mark.skipif(os.environ.get("MUTATE_CI", "0") in ("", "0"),
                    reason="MUTATE_CI=1 (make mutate-ci): one Verilator build per mutant")
@pytest.mark.parametrize("mutant", mutate.ci_mutants(), ids=lambda m: m.ident)
def test_ci_mutant_is_killed(mutant) -> None:
    verdict, _ = mutate.run_mutant(mutant, timeout=300, quick=True)
    assert verdict in ("killed", "timeout"), f"{mutant.ident} {verdict}:\n{mutant.diff()}"


# A small block holding each bug kind the new operators model (tools/mutate_ops.py).
_SNIPPET = """\
module snip (input logic clk, rst, beat, skip_q, ovf, s_axis_tlast, a_err, b_err,
             output logic err, output logic [31:0] drops);
  logic [31:0] drop_cnt_q, frames_q;
  logic        framing_q, pos_end;
  assign pos_end = (frames_q == 32'd7);
  assign err = a_err | b_err
             | framing_q;
  always_ff @(posedge clk) begin
    if (rst) begin
      drop_cnt_q <= '0;
    end else begin
      if (!skip_q && ovf && drop_cnt_q != '1) drop_cnt_q <= drop_cnt_q + 32'd1;
      framing_q <= framing_q || a_err;
      if (beat && s_axis_tlast) frames_q <= frames_q + 1'b1;
    end
  end
  assign drops = drop_cnt_q;
endmodule
"""


def _snippet_mutants_of(text: str) -> dict[str, str]:
    """ident -> mutated line (stripped) of every mutant of ``text``."""
    return {m.ident: m.after.strip() for m in mutate.candidates_text("snip", "rtl/snip.sv", text)}


def _snippet_mutants() -> dict[str, str]:
    return _snippet_mutants_of(_SNIPPET)


def test_new_operators_generate_the_intended_mutants() -> None:
    """Each operator added for issue 33 produces the bug it models on a small block, with
    fixed identifiers (the campaign's results and the equivalent list are keyed by them)."""
    got = _snippet_mutants()
    expected = {
        # (a) a counter guard losing its corner term: drops counted while skipping
        "snip:dropfirst:0": "if (ovf && drop_cnt_q != '1) drop_cnt_q <= drop_cnt_q + 32'd1;",
        # (b) a sticky merge losing its hold term (`||`) and a top-level merge losing a flag
        "snip:dropfirst:1": "framing_q <= a_err;",
        "snip:merge:0": "assign err = b_err",
        "snip:merge:1": "assign err = a_err",
        "snip:merge:2": ";",
        # (a) a status counter's increment removed, and gaining a last-beat corner term (the
    # last/end terms are those the block's conditions and right-hand sides read)
        "snip:count:0": "if (!skip_q && ovf && drop_cnt_q != '1) drop_cnt_q <= drop_cnt_q + 32'd0;",
        "snip:count:1": ("if (!skip_q && ovf && drop_cnt_q != '1 && !s_axis_tlast) "
                         "drop_cnt_q <= drop_cnt_q + 32'd1;"),
        # (c) a counter compared with its bound: wrong past the tie
        "snip:tie:0": "assign pos_end = (frames_q >= 32'd7);",
        # (d) the TLAST term dropped from a condition, or never seen
        "snip:dropfirst:2": "if (s_axis_tlast) frames_q <= frames_q + 1'b1;",
        "snip:drop:3": "if (beat) frames_q <= frames_q + 1'b1;",
        "snip:last:0": "if (beat && 1'b0) frames_q <= frames_q + 1'b1;",
    }
    for ident, after in expected.items():
        assert got.get(ident) == after, (ident, got.get(ident))
    # frames_q is not a status counter (neither saturating nor an output): no count mutant
    assert not [k for k, v in got.items() if ":count:" in k and "frames_q <=" in v]
    # the original `drop` drops only operands after an operator; `dropfirst` the first one
    assert got["snip:drop:0"].startswith("if (!skip_q && drop_cnt_q")
    # no two mutants of the new operators write the same line
    lines = [v for k, v in got.items() if k.split(":")[1] in mutate.NEW_OPS]
    assert len(lines) == len(set(lines))


def test_tie_reaches_continuation_lines() -> None:
    text = _SNIPPET.replace("assign pos_end = (frames_q == 32'd7);",
                            "assign pos_end = beat\n                 && (frames_q < 32'd7);")
    got = _snippet_mutants_of(text)
    assert "&& (frames_q <= 32'd7);" in got.values()


def test_original_operator_ids_are_stable() -> None:
    """The new operators leave the original operators' numbering untouched: every mutant named
    as equivalent or in the CI subset still names the same line."""
    by_id = {m.ident: m for mod in mutate.TESTS for m in mutate.candidates(mod)}
    assert set(mutate.EQUIVALENT) <= set(by_id)
    assert "snap_room" in by_id["detect_chain:drop:0"].before
    assert "b_err || r_err" in by_id["frame_store_axi:drop:24"].before
    assert mutate.ci_mutants()
    old = [m for m in by_id.values() if m.op not in mutate.NEW_OPS]
    assert {m.op for m in old} == {"rel", "arith", "logic", "drop", "neg", "const", "noreset",
                                   "sticky", "swap"}


def test_equivalent_entries_name_their_line() -> None:
    """Every EQUIVALENT entry's identifier still names the mutant it argues about: its
    recorded mutated line is the current mutant's (whitespace collapsed, comment left out).
    An identifier existing is not enough: ``nci:const:2`` (step 2: ``s1_valid_q`` set by
    reset) outlived ``s1_valid_q`` and named ``framing_q``'s reset line instead."""
    by_id = {m.ident: m for mod in mutate.TESTS for m in mutate.candidates(mod)}
    for ident, eq in mutate.EQUIVALENT.items():
        assert ident in by_id, f"{ident}: no such mutant"
        after = " ".join(by_id[ident].after.split())
        assert eq.mutated in after, f"{ident} is now {after!r}, not {eq.mutated!r}"


def test_dropfirst_keeps_comparisons_whole() -> None:
    """A comparison binds tighter than ``||``: the first operand dropped is all of it."""
    text = _SNIPPET.replace("assign pos_end = (frames_q == 32'd7);",
                            "assign pos_end = (frames_q == 32'd7 || beat);")
    got = set(_snippet_mutants_of(text).values())
    assert "assign pos_end = (beat);" in got
    assert not [v for v in got if "frames_q == beat" in v]


# Mutant schemata (tools/mutate_schemata.py): a small block with each guarded line form.
_TINY = """\
module tiny (input logic clk, rst, a, b, c, input logic [3:0] d,
             output logic y, output logic [3:0] q, output logic f);
  logic [3:0] n;
  assign y = (a && b) || !c;
  always_comb begin
    unique case (d[1:0])
      2'd0: n = d + 4'd1;
      2'd1: n = d - 4'd1;
      default: n = d;
    endcase
  end
  always_ff @(posedge clk) begin
    if (rst) begin
      q <= '0;
      f <= 1'b0;
    end else begin
      if (a && d < 4'd9) begin
        q <= n;
      end else if (b) q <= q + 1'b1;
      else q <= q;
      if (c) f <= 1'b1;
    end
  end
endmodule
"""

_TINY_TB = """\
module tb;
  logic clk = 0, rst = 1, a, b, c;
  logic [3:0] d;
  logic y, f, ys[NM], fs[NM];
  logic [3:0] q, qs[NM];
  int k = 0;
  tiny dut (.*);
{classic}
  initial begin
    void'($value$plusargs("MUTANT=%d", k));
    for (int t = 0; t < 400; t++) begin
      {a, b, c, d} = 7'($urandom);
      rst = t < 2 || t == 200;
      #1 if ({y, q, f} !== {ys[k], qs[k], fs[k]}) $fatal(1, "mutant %0d differs at %0d", k, t);
      clk = 1; #1 clk = 0;
    end
    $display("SAME %0d", k);
    $finish;
  end
endmodule
"""


def test_schemata_of_a_small_block_behave_as_each_mutant(tmp_path: Path) -> None:
    """The schemata of a small block hold most of its mutants (each line form: assign, case
    item, reset branch, ``if`` opener, ``else if`` with an ``else`` on the next line, sticky
    flag); with ``+MUTANT=0`` the guarded block matches the original and with ``+MUTANT=K``
    the per-mutant copy of mutant K, cycle by cycle under random inputs (Verilator)."""
    sys.path.insert(0, str(REPO / "tools"))
    try:
        import mutate_schemata
    finally:
        sys.path.pop(0)
    import subprocess

    from rtlsim.toolchain import ensure_verilator_env

    muts = mutate.candidates_text("tiny", "rtl/tiny.sv", _TINY)
    sch = mutate_schemata.schemata("tiny", _TINY, muts)
    assert len(sch.ids) + len(sch.classic) == len(muts)
    assert len(sch.ids) >= 0.8 * len(muts), [m.ident for m in sch.classic]
    assert len(sch.text.splitlines()) == len(_TINY.splitlines())   # line numbers kept
    copies = [_TINY.replace("module tiny", "module tiny_c0")]
    inst = ["  tiny_c0 c0 (.clk, .rst, .a, .b, .c, .d, .y(ys[0]), .q(qs[0]), .f(fs[0]));"]
    for m in muts:
        k = sch.ids.get(m.ident)
        if k is None:
            continue
        lines = _TINY.splitlines()
        lines[m.line - 1] = m.after
        copies.append("\n".join(lines).replace("module tiny", f"module tiny_c{k}") + "\n")
        inst.append(f"  tiny_c{k} c{k} (.clk, .rst, .a, .b, .c, .d, .y(ys[{k}]), .q(qs[{k}]), "
                    f".f(fs[{k}]));")
    (tmp_path / "tiny.sv").write_text(sch.text)
    (tmp_path / "copies.sv").write_text("".join(copies))
    nm = len(muts) + 1
    (tmp_path / "tb.sv").write_text(_TINY_TB.replace("{classic}", "\n".join(inst))
                                    .replace("[NM]", f"[{nm}]"))
    ensure_verilator_env()
    build = subprocess.run(
        ["verilator", "--binary", "-Wno-fatal", "-Wno-lint", "-Wno-style", "-O0",
         "--top-module", "tb", "-Mdir", str(tmp_path / "obj"), "tb.sv", "tiny.sv",
         "copies.sv", "-CFLAGS", "-O0 -std=c++20 -fcoroutines"],   # (the wheel's timing flags)
        cwd=tmp_path, capture_output=True, text=True)
    assert build.returncode == 0, build.stdout + build.stderr
    for k in [0, *sch.ids.values()]:
        run = subprocess.run([str(tmp_path / "obj" / "Vtb"), f"+MUTANT={k}"],
                             capture_output=True, text=True, timeout=60)
        assert f"SAME {k}" in run.stdout, run.stdout + run.stderr
