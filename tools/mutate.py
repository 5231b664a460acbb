"""Mutation testing of the RTL: apply one source-level bug at a time, run the testbenches
that cover the mutated module, and count the mutants the regression kills.

Operators (one textual change on one line of ``rtl/**/*.sv``):
  rel      relational swap (== <-> !=, < <-> <=, > <-> >=)
  arith    + <-> -
  logic    && <-> ||
  drop     a term dropped from an && / || condition
  neg      a ! dropped
  const    off-by-one constant (``X - 1`` -> ``X``, ``- 2``; ``1'b1`` <-> ``1'b0``; '0 <-> '1)
  noreset  a register left out of the reset branch
  sticky   a sticky flag made non-sticky (``if (c) f <= 1'b1;`` -> ``f <= c;``)
  swap     two fields of a concatenation swapped
  dropfirst, merge, count, tie, last: the bug kinds outside checks kept finding (a counter
           that miscounts in a corner, a flag dropped from a sticky merge, a comparison wrong
           on a tie, a TLAST term lost), see tools/mutate_ops.py

Lines inside ``ifdef FORMAL`` / ``ifdef F_<NAME>`` (a proof's own define) / ``ifndef SYNTHESIS``
blocks, parameter checks, comments and axis_checker instances are never mutated (they are
checks, not design). Each mutant runs in its own copy of the tree (``rtl``, ``tb``, ``host``,
``model`` copied into a temporary folder), so the worktree is never modified and runs are
parallel-safe. The sample is deterministic for a given ``--seed``.

    python tools/mutate.py --list frame_align          # every candidate mutant
    python tools/mutate.py -n 40 --seed 1              # 40 mutants spread over modules
    python tools/mutate.py --ci                        # the fixed CI subset
    python tools/mutate.py --all --ray --workers 2     # every candidate, as Ray tasks
    python tools/mutate.py --all --schemata --resume   # every candidate, one build a module

Modules: tools/mutate_stages.py (the testbench stages per module, the CI subset, the known
equivalent mutants), tools/mutate_gen.py and tools/mutate_ops.py (the candidates),
tools/mutate_run.py (running one mutant), tools/mutate_ray.py (on Ray),
tools/mutate_schemata.py and tools/mutate_schemata_run.py (mutant schemata); this file the
report, the results file and the command line.
"""


from __future__ import annotations

import argparse
import json
import os
import sys
from dataclasses import asdict
from pathlib import Path

# tools/ on sys.path only while the mutate_* modules are imported: a test that imports this
# module must not leave tools/ (whose coverage.py shadows the coverage package) on the
# sys.path that the cocotb runner hands to later simulations as PYTHONPATH
sys.path.insert(0, str(Path(__file__).resolve().parent))
try:
    from mutate_gen import Mutant, candidates, candidates_text, ci_mutants, sample
    from mutate_ops import NEW_OPS
    from mutate_run import OUT, apply, run_mutant, run_mutant_formal
    from mutate_stages import CHEAPEST, EQUIVALENT, REPO, TESTS
finally:
    sys.path.pop(0)

__all__ = ["CHEAPEST", "EQUIVALENT", "NEW_OPS", "TESTS", "Mutant", "apply", "candidates",
           "candidates_text", "ci_mutants", "main", "report", "run_mutant", "sample", "save",
           "split_stale"]


def report(results: list[tuple[Mutant, str, float]]) -> str:
    """Markdown summary: per module mutants run, killed (timeouts included, also shown
    apart), survived, equivalent and the score = killed / (run - equivalent); then every
    surviving diff."""
    rows: dict[str, list[int]] = {}
    for m, verdict, _ in results:
        if verdict in ("invalid", "unknown"):
            continue
        r = rows.setdefault(m.module, [0, 0, 0, 0])   # killed, timeout, survived, equivalent
        if verdict == "survived":
            r[3 if m.ident in EQUIVALENT else 2] += 1
        else:
            r[0] += 1
            r[1] += verdict == "timeout"
    lines = ["| module | mutants | killed | (of which timeout) | survived | equivalent | score |",
             "|---|---:|---:|---:|---:|---:|---:|"]
    tot = [0, 0, 0, 0]

    def score(k: int, s: int) -> str:
        return f"{100 * k / (k + s):.0f}%" if k + s else "-"

    for mod, r in sorted(rows.items()):
        lines.append(f"| {mod} | {sum(r) - r[1]} | {r[0]} | {r[1]} | {r[2]} | {r[3]} | "
                     f"{score(r[0], r[2])} |")
        tot = [a + b for a, b in zip(tot, r, strict=True)]
    if sum(tot):
        lines.append(f"| **all** | {sum(tot) - tot[1]} | {tot[0]} | {tot[1]} | {tot[2]} | "
                     f"{tot[3]} | **{score(tot[0], tot[2])}** |")
    surv = [m for m, v, _ in results if v == "survived"]
    if surv:
        lines += ["", "Surviving mutants:", ""]
        for m in surv:
            eq = EQUIVALENT.get(m.ident)
            why = eq.why if eq else None
            lines += [f"- `{m.ident}`" + (f" (equivalent: {why})" if why else ""),
                      "```diff", m.diff().rstrip(), "```"]
    return "\n".join(lines)


def _key(row: dict) -> tuple[str, str, str, str]:
    """A verdict's or mutant's line: module, operator, and the line before and after the
    mutation with whitespace collapsed."""
    return (row["module"], row["op"], " ".join(row["before"].split()),
            " ".join(row["after"].split()))


def split_stale(rows: list[dict]) -> tuple[list[dict], list[dict]]:
    """Verdicts of a results file split into (current, stale). Identifiers are numbered per
    module and operator, so one RTL edit renumbers its neighbours: a verdict whose identifier
    names a candidate with the recorded line (before and after the mutation, whitespace
    collapsed) is current; one whose line is now another candidate's (the same module,
    operator and text, exactly one such candidate) is current under that candidate's
    identifier; any other is stale, its line changed or gone, and says nothing about today's
    RTL: ``--resume`` runs that mutant again and ``--report`` leaves it out. Where two current
    verdicts name one identifier, the one recorded under it wins."""
    pool = [m for mod in {r["module"] for r in rows} if mod in TESTS for m in candidates(mod)]
    by_id = {m.ident: m for m in pool}
    by_text: dict[tuple, list[Mutant]] = {}
    for m in pool:
        by_text.setdefault(_key(asdict(m)), []).append(m)
    direct: dict[str, dict] = {}
    moved: dict[str, dict] = {}
    stale = []
    for r in rows:
        key = _key(r)
        m = by_id.get(r["ident"])
        if m is not None and key == _key(asdict(m)):
            direct[r["ident"]] = r
        elif len(by_text.get(key, [])) == 1:
            m = by_text[key][0]
            moved[m.ident] = {**r, **asdict(m), "ident": m.ident}
        else:
            stale.append(r)
    return list({**moved, **direct}.values()), stale


def save(path: Path, m: Mutant, verdict: str, secs: float) -> None:
    """Add (or replace) one verdict in the JSON results file."""
    path.parent.mkdir(parents=True, exist_ok=True)
    rows = json.loads(path.read_text()) if path.exists() else []
    rows = [r for r in rows if r["ident"] != m.ident]
    rows.append({**asdict(m), "ident": m.ident, "verdict": verdict, "seconds": round(secs)})
    path.write_text(json.dumps(rows, indent=1))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("modules", nargs="*", help="RTL module names (default: all in TESTS)")
    ap.add_argument("-n", type=int, default=20, help="mutants to run (spread over modules)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--list", action="store_true", help="print the candidates and stop")
    ap.add_argument("--ci", action="store_true", help="run the fixed CI subset")
    ap.add_argument("--id", action="append", help="run these mutants (module:op:index)")
    ap.add_argument("--quick", action="store_true",
                    help="first (cheapest) test stage only: survivors are not final")
    ap.add_argument("--formal", action="store_true",
                    help="kill mutants with the module's SymbiYosys proof instead of its tests")
    ap.add_argument("--resume", action="store_true",
                    help="keep the verdicts already in --json, run only the rest")
    ap.add_argument("--reverse", action="store_true",
                    help="run the sample from its end (a second worker on another --json "
                         "meets the first one in the middle)")
    ap.add_argument("--timeout", type=float, default=300.0,
                    help="seconds per mutant (a hang counts as killed)")
    ap.add_argument("--all", action="store_true", help="every candidate mutant, not a sample")
    ap.add_argument("--ray", action="store_true",
                    help="run the mutants as Ray tasks (tools/mutate_ray.py): a local Ray "
                         "with --workers CPUs, or --ray-address / RAY_ADDRESS")
    ap.add_argument("--schemata", action="store_true",
                    help="one build per module with every mutant compiled in, each mutant a "
                         "simulation run (tools/mutate_schemata.py); the lines it cannot "
                         "guard go through per-mutant builds")
    ap.add_argument("--workers", type=int, default=os.cpu_count() or 1,
                    help="with --ray: mutants in flight at once")
    ap.add_argument("--ray-address", default=None, metavar="ADDR",
                    help="with --ray: an existing Ray cluster (HOST:PORT)")
    ap.add_argument("--json", type=Path, default=OUT / "results.json")
    ap.add_argument("--report", action="store_true",
                    help="only print the report of the verdicts already in --json")
    ap.add_argument("--merge", type=Path, action="append", default=[],
                    help="with --report: also these results files (other workers' --json); "
                         "the merged verdicts are written to --json")
    args = ap.parse_args(argv)
    modules = args.modules or list(TESTS)
    if args.formal and not args.modules:
        modules = [m for m in TESTS if (REPO / "formal" / f"{m}.sby").exists()]
    unknown = [m for m in modules if m not in TESTS]
    if unknown:
        print(f"error: no testbench mapping for {unknown} (see TESTS)", file=sys.stderr)
        return 2
    if args.list:
        for mod in modules:
            for m in candidates(mod):
                print(f"{m.ident:28s} {m.path}:{m.line}: {m.after.strip()}")
        return 0
    if args.report:
        if not args.json.exists():
            print(f"error: no results file {args.json}", file=sys.stderr)
            return 2
        done = json.loads(args.json.read_text())
        if args.merge:
            # for one identifier a current verdict wins over a stale one, then --json's own
            cur_m, old_m = split_stale([r for f in args.merge for r in json.loads(f.read_text())])
            cur_d, old_d = split_stale(done)
            by_id = {r["ident"]: r for r in old_m + old_d}
            for rows in (cur_m, cur_d):
                by_id.update({r["ident"]: r for r in rows})
            done = list(by_id.values())
            args.json.write_text(json.dumps(done, indent=1))
        done, stale = split_stale(done)
        fields = set(Mutant.__dataclass_fields__)
        print(report([(Mutant(**{k: v for k, v in r.items() if k in fields}), r["verdict"],
                       r["seconds"]) for r in done]))
        if stale:
            print(f"\n{len(stale)} stale verdicts (their line changed since, not counted): "
                  + " ".join(sorted(r["ident"] for r in stale)))
        return 0
    if args.ci:
        chosen = ci_mutants()
    elif args.id:
        wanted = list(args.id)
        pool = {m.ident: m for mod in {w.split(":")[0] for w in wanted}
                for m in candidates(mod)}
        missing = [w for w in wanted if w not in pool]
        if missing:
            print(f"error: unknown mutants {missing}", file=sys.stderr)
            return 2
        chosen = [pool[w] for w in wanted]
    elif args.all:
        chosen = [m for mod in modules for m in candidates(mod)]
    else:
        chosen = sample(modules, args.n, args.seed)
    results: list[tuple[Mutant, str, float]] = []
    if args.resume and args.json.exists():
        done = {r["ident"]: r for r in split_stale(json.loads(args.json.read_text()))[0]}
        results = [(m, done[m.ident]["verdict"], done[m.ident]["seconds"]) for m in chosen
                   if m.ident in done]
        chosen = [m for m in chosen if m.ident not in done]
    if args.reverse:
        chosen = chosen[::-1]
    if (args.ray or args.schemata) and args.formal:
        print("error: --ray / --schemata run the testbenches; not with --formal",
              file=sys.stderr)
        return 2
    if args.schemata:
        from mutate_schemata_run import run_schemata  # tools/ is on sys.path (the script's)
        runs = run_schemata(chosen, args.timeout, args.quick or args.ci)
    elif args.ray:
        from mutate_ray import run_on_ray  # tools/ is on sys.path as the script's folder
        runs = run_on_ray(chosen, args.timeout, args.quick or args.ci, args.workers,
                          args.ray_address)
    else:
        runs = ((m, *(run_mutant_formal(m, args.timeout) if args.formal
                      else run_mutant(m, args.timeout, quick=args.quick or args.ci)))
                for m in chosen)
    for m, verdict, secs in runs:
        results.append((m, verdict, secs))
        print(f"{m.ident:28s} {verdict:8s} {secs:6.0f} s  {m.path}:{m.line}: "
              f"{m.after.strip()[:60]}", flush=True)
        save(args.json, m, verdict, secs)
    text = report(results)
    print()
    print(text)
    return 0 if not args.ci or all(v != "survived" for _, v, _ in results) else 1


if __name__ == "__main__":
    raise SystemExit(main())
