"""``radar curves``: detection and estimation curves against theory, a Monte-Carlo
campaign on Ray (``campaign.curves``, docs/curves.md)."""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import sys

from campaign.curves import Plan, run_curves
from campaign.runner import CampaignError, check_address
from radar.common import CliError, add_command, out_file, out_folder


def plan_of(args: argparse.Namespace) -> Plan:
    """The campaign plan of the options (``--quick`` then the overrides), checked."""
    plan = Plan.quick() if args.quick else Plan()
    over: dict = {}
    if args.pfa is not None:
        over["pfas"] = tuple(args.pfa)
    if args.trials is not None:
        over.update(pd_trials=args.trials, est_trials=args.trials, res_trials=args.trials)
    if args.cell_snr is not None:
        over.update(cell_snr_sw0=tuple(args.cell_snr), cell_snr_sw1=tuple(args.cell_snr))
    if args.snr is not None:
        over["snr"] = tuple(args.snr)
    if args.pfa_cells is not None:
        over["pfa_cells"] = args.pfa_cells
    if args.frame_trials is not None:
        over["frame_trials"] = args.frame_trials
    plan = dataclasses.replace(plan, **over)
    try:
        plan.check()
    except CampaignError as exc:
        raise CliError(str(exc)) from None
    return plan


def cmd_curves(args: argparse.Namespace) -> int:
    plan = plan_of(args)
    if args.workers < 1:
        raise CliError(f"--workers: must be at least 1, got {args.workers}")
    if not 0 <= args.seed < 2**63:
        raise CliError(f"--seed: must be an integer in 0..2^63-1, got {args.seed}")
    out = out_file(args.json, ".json", "--json")
    results = out_file(args.results or str(out.with_suffix(".campaign.jsonl")), ".jsonl",
                       "--results")
    plots = out_folder(args.plots, "--plots") if args.plots else None
    address = args.ray_address or os.environ.get("RAY_ADDRESS") or None
    try:
        if address:
            check_address(address)
        doc = run_curves(plan, args.seed, results, args.workers, address)
    except CampaignError as exc:
        raise CliError(str(exc)) from None
    doc["quick"] = bool(args.quick)
    out.write_text(json.dumps(doc, indent=1) + "\n")
    print(f"wrote {out} ({len(doc['detection'])} detection curves, "
          f"{len(doc['estimation'])} estimation curves, {len(doc['estimation_frames'])} "
          f"whole-frame ones; campaign results in {results})")
    if plots is not None:
        from campaign.plots import detection_figures, estimation_figures
        files = detection_figures(doc, plots) + estimation_figures(doc, plots)
        print(f"wrote {len(files)} figures to {plots}", file=sys.stderr)
    return 0


def add_parsers(sub: argparse._SubParsersAction, presets: list[str]) -> None:
    s = add_command(sub, "curves", "detection and estimation curves against theory (Ray)", """
        Monte-Carlo campaign on Ray: Pd against SNR at fixed Pfa for the host CFAR (CA, OS)
        and the FPGA detector's bit-accurate model (CA, GO, SO), Swerling 0 and 1, beside
        the theoretical curves; range, velocity and azimuth RMSE against the Cramer-Rao
        bound; two-target angle resolution (docs/curves.md). Results go to a resumable file
        (--results): running the same command again continues an interrupted campaign.""")
    s.add_argument("--json", required=True, help="output JSON file (docs/curves.md)")
    s.add_argument("--plots", default=None, help="folder for the figures (pd_*.png, crb_*.png)")
    s.add_argument("--quick", action="store_true",
                   help="coarse grids and fewer trials: a few minutes on 2 cores")
    s.add_argument("--ray-address", default=None, metavar="ADDR",
                   help="attach to the Ray cluster at HOST:PORT (default: RAY_ADDRESS, else "
                        "a local Ray started for the run)")
    s.add_argument("--workers", type=int, default=os.cpu_count() or 1,
                   help="tasks in flight at once (and the local Ray's CPUs; default: this "
                        "machine's CPU count)")
    s.add_argument("--results", default=None, metavar="FILE.jsonl",
                   help="resumable campaign results (default: the --json file with "
                        ".campaign.jsonl)")
    s.add_argument("--seed", type=int, default=1, help="campaign seed (default 1)")
    s.add_argument("--trials", type=int, default=None,
                   help="trials per point of every curve (default 2000 Pd targets, 1000 "
                        "estimation and resolution trials; --quick: 420 / 300)")
    s.add_argument("--frame-trials", type=int, default=None, metavar="N",
                   help="targets per SNR point of the whole-frame curves (refinement, "
                        "bit-accurate chain; 64 per frame, about 15 s a frame; default 512, "
                        "--quick 64; 0: none)")
    s.add_argument("--pfa", type=float, nargs="+", default=None,
                   help="false-alarm probabilities of the detection curves (default 1e-4 1e-6)")
    s.add_argument("--pfa-cells", type=int, default=None,
                   help="noise-only cells the measured Pfa counts over (default 1e7; "
                        "--quick: 1.2e6)")
    s.add_argument("--cell-snr", type=float, nargs=3, default=None,
                   metavar=("LO", "HI", "STEP"),
                   help="per-channel cell SNR grid of the Pd curves, dB (default per Swerling "
                        "case: -8..2 and -6..16)")
    s.add_argument("--snr", type=float, nargs=3, default=None, metavar=("LO", "HI", "STEP"),
                   help="per-sample SNR grid of the estimation curves, dB (default -64 -20 2)")
    s.set_defaults(func=cmd_curves)
