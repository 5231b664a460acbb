"""Sanity checks of the verification tools (tools/mutate.py, tools/formal.py) and the fixed
CI mutant subset: realistic one-line RTL bugs that the regression must kill."""

from __future__ import annotations

import importlib.util
import os
import re
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]


def _load(name: str):
    spec = importlib.util.spec_from_file_location(name, REPO / "tools" / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules[name] = mod
    spec.loader.exec_module(mod)
    return mod


mutate = _load("mutate")
formal = _load("formal")
coverage = _load("coverage")


def test_every_operator_has_mutants() -> None:
    ops = {m.op for mod in mutate.TESTS for m in mutate.candidates(mod)}
    assert ops == {"rel", "arith", "logic", "drop", "neg", "const", "noreset", "sticky", "swap"}


def test_checks_are_never_mutated() -> None:
    for mod in mutate.TESTS:
        for m in mutate.candidates(mod):
            assert "assert" not in m.before and "assume" not in m.before, m.ident
            assert not re.search(r"\bf_\w+", m.before.split("//")[0]), m.ident
            assert "$fatal" not in m.before, m.ident


def test_sample_is_deterministic_and_spread() -> None:
    a = mutate.sample(list(mutate.TESTS), 26, seed=3)
    b = mutate.sample(list(mutate.TESTS), 26, seed=3)
    assert [m.ident for m in a] == [m.ident for m in b]
    with_mutants = {mod for mod in mutate.TESTS if mutate.candidates(mod)}
    assert {m.module for m in a} == with_mutants
    assert [m.ident for m in mutate.sample(list(mutate.TESTS), 26, seed=4)] != \
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
