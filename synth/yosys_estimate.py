"""Open resource estimate without Vivado: Yosys ``synth_xilinx -family xcup`` per block.

Every job reads ``rtl/`` as written (the plain file list ``rtl/**/*.sv``, packages first, see
:func:`synth.jobs.rtl_files`, narrowed to the files its top elaborates by
:func:`synth.jobs.files_for`), sets the
HDL parameters of one block, synthesizes it out of context for UltraScale+ (no I/O buffers,
no clock buffer, flattened) and counts the mapped cells. The result is a markdown table
beside the paper's Table II, written to ``OUT/estimate.md``
(and ``OUT/estimate.json``).

Usage (from the repository root, through ``tools/venv-run``)::

    python -m synth.yosys_estimate --set paper-fpga   # blocks and top at paper-fpga (default)
    python -m synth.yosys_estimate --set all          # paper-fpga and full blocks
    python -m synth.yosys_estimate --set ci           # the quick CI subset
    python -m synth.yosys_estimate --list             # the jobs of every set

Yosys runs one job at a time under ``nice`` (the build machines are shared). This module is
the command line; the jobs are in :mod:`synth.jobs`, the Yosys run in :mod:`synth.yosys_run`,
the cell counts and the report in :mod:`synth.yosys_report`.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from synth.jobs import ROOT, files_for, job_sets, jobs_of, rtl_files
from synth.yosys_report import Result, merge_reports, result_line, write_report
from synth.yosys_run import run_job, yosys_command, yosys_version


def main(argv: list[str] | None = None) -> int:
    """Command line entry: run a job set, print and write the table."""
    sets = job_sets()
    ap = argparse.ArgumentParser(
        prog="python -m synth.yosys_estimate",
        description="Yosys synth_xilinx -family xcup resource estimate per block "
                    "(docs/synth.md).")
    ap.add_argument("--set", default="paper-fpga", choices=sorted(sets),
                    help="job set: ci (quick), paper-fpga (blocks, top, detector; default), "
                         "full (blocks, detector, top with FRAME_STORE=1), full-blocks "
                         "(full without its top), all (paper-fpga + full)")
    ap.add_argument("--only", default="",
                    help="comma-separated substrings: run only jobs whose name contains one")
    ap.add_argument("--out", type=Path, default=ROOT / "out" / "synth",
                    help="output folder (default out/synth)")
    ap.add_argument("--list", action="store_true", help="list the jobs of every set and exit")
    ap.add_argument("--timeout", type=float, default=None, metavar="S",
                    help="stop a Yosys job after S seconds (reported as failed)")
    ap.add_argument("--merge", type=Path, nargs="+", default=None, metavar="JSON",
                    help="no Yosys: write one report (into --out) from the estimate.json of "
                         "earlier runs")
    args = ap.parse_args(argv)
    if args.merge:
        return merge_reports(args.merge, args.out)

    if args.list:
        for name, jobs in sets.items():
            for j in jobs:
                print(f"{name:11s} {j.name:30s} {j.top:16s} {j.label}{' -uram' if j.uram else ''}")
        return 0
    try:
        jobs = jobs_of(sets, args.set, args.only)
    except ValueError as exc:
        print(f"synth-estimate: {exc}", file=sys.stderr)
        return 2
    yosys = yosys_command()
    out: Path = args.out.resolve()
    work = out / "work"
    work.mkdir(parents=True, exist_ok=True)
    files = rtl_files()
    results: list[Result] = []
    for job in jobs:
        print(f"synth-estimate: {job.name} ({job.top} {job.label}) ...", flush=True)
        r = run_job(job, files_for(job.top, files), work, yosys, args.timeout)
        print(result_line(r), flush=True)
        results.append(r)
    return write_report(results, out, args.set, yosys_version(yosys))


if __name__ == "__main__":
    sys.exit(main())
