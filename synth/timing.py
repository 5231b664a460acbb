"""``make timing``: every block placed and routed by an open flow (docs/synth.md "Timing").

Per job (a block at its ``paper-fpga`` parameters, :mod:`synth.jobs`), every port registered by
a generated wrapper: Yosys ``synth_ecp5`` + ``nextpnr-ecp5`` for an LFE5U-85F, speed 8, out of
context with only a clock constraint (``--freq``), and the logic depth of the same wrapper in
Yosys' ``synth_xilinx -family xcup`` mapping. Jobs run in parallel (``-j``), each within a
wall-clock limit, and are cached by a hash of their sources and settings
(:mod:`synth.timing_run`); the table goes to ``OUT/timing.md`` (:mod:`synth.timing_report`).

Usage (from the repository root, through ``tools/venv-run``)::

    python -m synth.timing                        # paper-fpga blocks and detector
    python -m synth.timing --set top              # the paper-fpga radar_pipeline top
    python -m synth.timing --set full             # the full preset's blocks, where they fit
    python -m synth.timing --only range_fft --seeds 1,2,3   # seed spread of one block
"""

from __future__ import annotations

import argparse
import sys
from concurrent.futures import ThreadPoolExecutor
from dataclasses import replace
from pathlib import Path

from synth.jobs import ROOT, Job, files_for, job_sets, jobs_of, rtl_files
from synth.timing_report import Row, job_row, write_report
from synth.timing_run import DEVICE, Settings, run_job

# The ECP5's multiplier is a MULT18X18D: the FFTs' twiddle products split their data operands
# to 18 bits there (fft_twiddle MUL_W, docs/fft_axis.md); the xcup depth keeps the DSP48E2's 27.
# Yosys' ECP5 mapping leaves the DP16KD's output register unused: the corner turn's frame memory
# (16384 words, 8 DP16KD deep in 2048 x 9 mode) is split into 8 banks, each with its own fabric
# output register, the bank chosen after it (buf_sdp_ram BANKS, docs/synth.md note 18).
ECP5_PARAMS: dict[str, dict[str, int]] = {"fft_axis": {"MUL_W": 18},
                                          "corner_turn": {"RAM_BANKS": 8},
                                          "radar_pipeline": {"MUL_W": 18}}


def timing_sets() -> dict[str, list[Job]]:
    """``ci`` (one small block, the regression's job), ``paper-fpga`` (the blocks and the
    detector of :func:`synth.jobs.job_sets`), ``top`` (the ``paper-fpga`` radar_pipeline),
    ``all`` (``paper-fpga`` + ``top``), ``full`` (the ``full`` preset's blocks and detector,
    :func:`synth.jobs.job_sets` ``full-blocks``: those that do not fit the ECP5-85 are
    reported so after synthesis, :func:`synth.timing_run.fit_problem`); the FFTs, the corner
    turn and the top with :data:`ECP5_PARAMS`."""
    sets = {name: [replace(j, ecp5_params=ECP5_PARAMS.get(j.top, {})) for j in jobs]
            for name, jobs in job_sets().items()}
    paper = sets["paper-fpga"]
    blocks = [j for j in paper if j.top != "radar_pipeline"]
    top = [j for j in paper if j.top == "radar_pipeline"]
    full = sets["full-blocks"]
    ci = [Job("ci/mark_fifo", "mark_fifo", {"DEPTH": 4, "WIDTH": 1})]
    return {"ci": ci, "paper-fpga": blocks, "top": top, "all": blocks + top, "full": full}


def main(argv: list[str] | None = None) -> int:
    """Command line entry: run (or reuse) the jobs, write ``OUT/timing.md``; exit 1 if a job
    failed (a job that does not fit the device is a result, not a failure)."""
    sets = timing_sets()
    ap = argparse.ArgumentParser(prog="python -m synth.timing",
                                 description="ECP5 place and route + xcup logic depth per "
                                             "block (docs/synth.md, Timing).")
    ap.add_argument("--set", default="paper-fpga", choices=sorted(sets))
    ap.add_argument("--only", default="",
                    help="comma-separated substrings: run only jobs whose name contains one")
    ap.add_argument("--out", type=Path, default=ROOT / "out" / "timing")
    ap.add_argument("-j", "--jobs", type=int, default=2, help="jobs in parallel (default 2)")
    ap.add_argument("--timeout", type=float, default=3600.0, metavar="S",
                    help="wall-clock limit of one job (default 3600 s)")
    ap.add_argument("--freq", type=float, default=100.0, help="clock constraint, MHz")
    ap.add_argument("--seeds", default="1", help="nextpnr seeds, comma-separated (default 1)")
    ap.add_argument("--router", default="router1", choices=("router1", "router2"),
                    help="nextpnr router (default router1; router2 for the top's congestion)")
    ap.add_argument("--placer", default="heap", choices=("heap", "static", "sa"),
                    help="nextpnr placer (default heap; static spreads cells by density)")
    ap.add_argument("--no-xcup", action="store_true", help="skip the synth_xilinx depth")
    args = ap.parse_args(argv)

    try:
        jobs = jobs_of(sets, args.set, args.only)
    except ValueError as exc:
        print(f"timing: {exc}", file=sys.stderr)
        return 2
    seeds = [int(s) for s in args.seeds.split(",") if s]
    runs = [(replace(j, name=j.name + (f"@seed{s}" if len(seeds) > 1 else "")), s)
            for j in jobs for s in seeds]
    files = rtl_files()
    out: Path = args.out.resolve()

    def one(run: tuple[Job, int]) -> Row:
        job, seed = run
        res = run_job(job, files_for(job.top, files), out / "jobs",
                      Settings(args.freq, seed, args.router, args.placer), args.timeout,
                      xcup=not args.no_xcup)
        row = Row(job.name, job.label, seconds=res.seconds, error=res.error, misfit=res.misfit)
        if not (res.error or res.misfit):
            row = job_row(job.name, job.label, res.dir)
        state = "cached" if res.cached else f"{res.seconds:.0f} s"
        print(f"timing: {job.name}: " + (
            f"FAILED {res.error}" if res.error else f"{res.misfit} ({state})" if res.misfit else
            f"{row.fmax_mhz:.1f} MHz, {row.lut4} LUT4, xcup {row.xlut} LUT6 levels ({state})"),
            flush=True)
        return row

    with ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        rows = list(pool.map(one, runs))
    header = (f"# make timing: set {args.set}, ECP5 {' '.join(DEVICE)} out of context, "
              f"--freq {args.freq:g}, seeds {args.seeds}"
              + (f", --router {args.router}" if args.router != "router1" else "")
              + (f", --placer {args.placer}" if args.placer != "heap" else ""))
    md = write_report(rows, out, args.freq, header)
    print(md.read_text())
    return 1 if any(r.error for r in rows) else 0


if __name__ == "__main__":
    sys.exit(main())
