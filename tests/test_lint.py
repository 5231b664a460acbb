"""`make lint` stays clean: Verilator --lint-only -Wall on every RTL module, ruff on Python."""

import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def test_rtl_lint_clean():
    from rtlsim.toolchain import ensure_verilator_env

    ensure_verilator_env()
    r = subprocess.run(["bash", str(REPO / "tools" / "lint.sh")], cwd=REPO,
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    assert "FAILED" not in r.stdout


def test_python_lint_clean():
    ruff = str(Path(sys.executable).parent / "ruff")  # pinned in the dev extras
    folders = [f for f in ("model", "rtlsim", "host", "gnn", "radar", "tb", "tests", "tools",
                           "synth", "benchmarks")
               if (REPO / f).is_dir()]
    r = subprocess.run([ruff, "check", *folders], cwd=REPO, capture_output=True, text=True)
    assert r.returncode == 0, r.stdout[-3000:]
