"""Vivado flow driver: every job of a set through ``synth/vivado/run.tcl``, one at a time.

Same job sets and HDL parameters as the Yosys estimate (:func:`synth.yosys_estimate.job_sets`).
Each job runs Vivado in batch mode, out of context for xczu7ev-ffvc1156-2-e at 100 MHz
(``synth/vivado/zcu106.xdc``), optionally through place and route, and leaves its reports in
``OUT/<set>/<block>/`` (utilization_*.rpt, timing_*.rpt, post_*.dcp, vivado.log). The summary
table of the utilization reports goes to ``OUT/vivado.md``.

    python -m synth.vivado_flow --set paper-fpga [--impl] [--only corner_turn]
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import time
from pathlib import Path

from synth.yosys_estimate import PAPER_TABLE_II, ROOT, TOP_FILE, Job, job_sets

TCL = ROOT / "synth" / "vivado" / "run.tcl"
INSTALL_HINT = ("vivado is not on PATH: install AMD Vivado ML (the free Standard edition "
                "covers xczu7ev) and `source <install>/settings64.sh`")

# utilization report row -> table column (UltraScale+ report_utilization wording)
_ROWS = {
    "CLB LUTs": "LUT", "LUT as Memory": "LUTRAM", "CLB Registers": "FF", "CARRY8": "CARRY8",
    "Block RAM Tile": "BRAM", "URAM": "URAM", "DSPs": "DSP",
}


def parse_utilization(text: str) -> dict[str, float]:
    """Used counts of the main resources from a ``report_utilization`` file."""
    out: dict[str, float] = {}
    for line in text.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) < 2:
            continue
        name = cells[0].rstrip("*").strip()
        if name in _ROWS and _ROWS[name] not in out:
            try:
                out[_ROWS[name]] = float(cells[1])
            except ValueError:
                continue
    return out


def run_job(job: Job, out: Path, impl: bool, vivado: str) -> tuple[dict[str, float], str]:
    """One Vivado batch run; returns the parsed utilization and a status string."""
    if job.top == "radar_pipeline" and not TOP_FILE.exists():
        return {}, f"skipped: {TOP_FILE.relative_to(ROOT)} does not exist yet"
    jdir = out / job.name
    jdir.mkdir(parents=True, exist_ok=True)
    cmd = [vivado, "-mode", "batch", "-nojournal", "-log", str(jdir / "vivado.log"),
           "-source", str(TCL), "-tclargs", job.top, str(jdir), "1" if impl else "0",
           *[f"{k}={v}" for k, v in job.params.items()]]
    t0 = time.monotonic()
    proc = subprocess.run(cmd, cwd=jdir, capture_output=True, text=True, check=False)
    secs = time.monotonic() - t0
    if proc.returncode != 0:
        err = [ln for ln in proc.stdout.splitlines() if ln.startswith("ERROR")]
        return {}, f"FAILED ({err[-1] if err else f'exit {proc.returncode}'}; {jdir}/vivado.log)"
    rpt = jdir / ("utilization_impl.rpt" if impl else "utilization_synth.rpt")
    util = parse_utilization(rpt.read_text()) if rpt.exists() else {}
    wns = (jdir / "wns.txt").read_text().strip() if (jdir / "wns.txt").exists() else "?"
    return util, f"{secs:.0f} s, WNS {wns} ns"


def main(argv: list[str] | None = None) -> int:
    """Command line entry: run the jobs, write ``OUT/vivado.md``."""
    sets = job_sets()
    ap = argparse.ArgumentParser(prog="python -m synth.vivado_flow",
                                 description="Vivado out-of-context synthesis (and optional "
                                             "place and route) per block, docs/synth.md.")
    ap.add_argument("--set", default="paper-fpga", choices=sorted(sets),
                    help="job set (the same as synth.yosys_estimate; default paper-fpga)")
    ap.add_argument("--only", default="", help="comma-separated substrings of job names")
    ap.add_argument("--impl", action="store_true", help="also place and route every job")
    ap.add_argument("--out", type=Path, default=ROOT / "out" / "vivado",
                    help="output folder (default out/vivado)")
    args = ap.parse_args(argv)

    vivado = shutil.which("vivado")
    if not vivado:
        print(f"synth-vivado: {INSTALL_HINT}", file=sys.stderr)
        return 1
    jobs = sets[args.set]
    if args.only:
        keys = [k for k in args.only.split(",") if k]
        jobs = [j for j in jobs if any(k in j.name for k in keys)]
    out: Path = args.out.resolve()
    cols = ["LUT", "LUTRAM", "FF", "CARRY8", "DSP", "BRAM", "URAM"]
    rows = ["| block | parameters | " + " | ".join(cols) + " | run |",
            "|---|---|" + "---:|" * len(cols) + "---|"]
    failed = 0
    for job in jobs:
        print(f"synth-vivado: {job.name} ({job.top} {job.label}) ...", flush=True)
        util, status = run_job(job, out, args.impl, vivado)
        failed += status.startswith("FAILED")
        print(f"  {status}", flush=True)
        rows.append(f"| {job.name} | {job.label} | "
                    + " | ".join(f"{util[c]:g}" if c in util else "-" for c in cols)
                    + f" | {status} |")
    p = PAPER_TABLE_II
    rows.append(f"| paper Table II | 1 TX x 4 RX | {p['LUT']:g} | {p['LUTRAM']:g} | "
                f"{p['FF']:g} | - | {p['DSP']:g} | {p['BRAM']:g} | {p['URAM']:g} | |")
    table = "\n".join(rows) + "\n"
    out.mkdir(parents=True, exist_ok=True)
    (out / "vivado.md").write_text(table)
    print(table)
    print(f"synth-vivado: wrote {out / 'vivado.md'}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
