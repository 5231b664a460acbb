"""Running mutants through their module's schemata (``tools/mutate.py --schemata``,
transform in ``tools/mutate_schemata.py``): one persistent copy of the tree per module under
``out/mutate/schemata/<module>/`` holding the guarded source, its own ``sim_build`` (built once
per parameter set, reused by every mutant: Verilator skips an unchanged build), and each
mutant a simulation run with ``RTLSIM_PLUSARGS=+MUTANT=<k>``.

Per module: each mutant is linted alone (as the per-mutant path does: one that does not
compile is "invalid"); the schemata source is linted and the lines Verilator rejects are
left unguarded; the original design (``+MUTANT=0``) must pass every stage, else the whole
module goes through per-mutant builds; the mutants the schemata does not hold do too.
"""

from __future__ import annotations

import os
import re
import shutil
import time
from collections.abc import Iterator
from pathlib import Path

from mutate_gen import Mutant, candidates
from mutate_run import COPY_DIRS, OUT, apply, compiles, lint, run_mutant, run_stages
from mutate_schemata import MUT_VAR, Schemata, schemata
from mutate_stages import REPO, TESTS

ROOT = OUT / "schemata"
BASE_TIMEOUT = 4 * 3600.0
"""Seconds per stage of the original design's run (its builds included)."""
_LOC = re.compile(r"(\S+?\.sv):(\d+):")


def log(text: str) -> None:
    """A line of the campaign's log (stdout of tools/mutate.py)."""
    print(f"[schemata {time.strftime('%H:%M:%S')}] {text}", flush=True)


def tree(module: str) -> Path:
    """The module's copy of the tree (fresh sources, the old ``sim_build`` kept)."""
    root = ROOT / module
    for d in COPY_DIRS:
        shutil.rmtree(root / d, ignore_errors=True)
        shutil.copytree(REPO / d, root / d,
                        ignore=shutil.ignore_patterns("__pycache__", "sim_build"))
    shutil.copy(REPO / "pyproject.toml", root / "pyproject.toml")
    return root


def environment(root: Path) -> dict[str, str]:
    """Environment of the stages run in ``root``: its packages first, Verilator's generated
    Makefile through ccache (normal optimisation: the model is built once, run often)."""
    from rtlsim.toolchain import ccache_exe
    env = dict(os.environ)
    env["PYTHONPATH"] = f"{root}{os.pathsep}{env.get('PYTHONPATH', '')}"
    exe = ccache_exe()
    if exe:
        env["MAKEFLAGS"] = f"{env.get('MAKEFLAGS', '')} OBJCACHE={exe}".strip()
        env["CCACHE_DIR"] = str(OUT / "ccache")
    return env


def prepare(module: str, mutants: list[Mutant], root: Path
            ) -> tuple[Schemata, list[Mutant]]:
    """Write the schemata of ``mutants`` into ``root``; returns it and the invalid mutants
    (those that do not compile alone)."""
    number = {m.ident: n for n, m in enumerate(candidates(module), start=1)}
    path = mutants[0].path
    text = (REPO / path).read_text()
    valid, invalid = [], []
    for m in mutants:
        apply(m, root)
        (valid if compiles(m, root) else invalid).append(m)
        (root / path).write_text(text)
    exclude: set[int] = set()
    while True:
        sch = schemata(module, text, valid, [number[m.ident] for m in valid],
                       frozenset(exclude))
        (root / path).write_text(sch.text)
        proc = lint(root, path)
        if proc.returncode == 0:
            return sch, invalid
        # every guarded line an error names (a constant function's guard is named as the
        # "location of non-constant" line, the error itself at the function's call)
        lines = sch.text.splitlines()
        bad = {int(n) - 1 for f, n in _LOC.findall(proc.stdout + proc.stderr)
               if Path(f).name == Path(path).name and MUT_VAR in lines[int(n) - 1]}
        if not bad - exclude:   # an error the guards did not cause: no schemata
            log(f"{module}: schemata do not lint:\n{proc.stderr[-2000:]}")
            (root / path).write_text(text)
            return Schemata(text, {}, list(valid)), invalid
        exclude |= bad


def run_schemata(mutants: list[Mutant], timeout: float, quick: bool
                 ) -> Iterator[tuple[Mutant, str, float]]:
    """(mutant, verdict, seconds) of every mutant, module after module (in the order they
    first appear); a schemata mutant's seconds are its simulations only."""
    modules = list(dict.fromkeys(m.module for m in mutants))
    for module in modules:
        mine = [m for m in mutants if m.module == module]
        t0 = time.monotonic()
        root = tree(module)
        sch, invalid = prepare(module, mine, root)
        log(f"{module}: {len(mine)} mutants, {len(invalid)} invalid, {len(sch.ids)} in the "
            f"schemata, {len(sch.classic)} per-mutant builds ({time.monotonic() - t0:.0f} s)")
        for m in invalid:
            yield m, "invalid", 0.0
        env = environment(root)
        stages = TESTS[module][:1] if quick else TESTS[module]
        held = [m for m in mine if m.ident in sch.ids]
        classic = list(sch.classic)
        budgets: list[float] = []
        if held:
            base = run_stages(root, {**env, "RTLSIM_PLUSARGS": "+MUTANT=0"}, stages,
                              BASE_TIMEOUT, times=budgets)
            log(f"{module}: original design through the schemata: {base} (stages "
                f"{', '.join(f'{t:.0f}' for t in budgets)} s, builds included)")
            # a mutant's stage may take 3x the original's (builds included), at least
            # --timeout, before it is a hang (whole testbench folders overran a fixed budget)
            budgets = [3 * t for t in budgets]
            if base != "survived":
                classic, held = sorted(held + classic, key=mine.index), []
        for m in held:
            t0 = time.monotonic()
            verdict = run_stages(root, {**env, "RTLSIM_PLUSARGS": f"+MUTANT={sch.ids[m.ident]}"},
                                 stages, timeout, budgets, failed_first=True)
            yield m, verdict, time.monotonic() - t0
        for m in classic:
            yield m, *run_mutant(m, timeout, quick=quick)
