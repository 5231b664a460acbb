"""Issue 32: the "compiling the host kernels" note comes once per checkout, not on every
``--detect fpga`` run (the RELAX kernels, which only cells with several targets reach, used
to stay uncompiled, so every run announced a compile)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path


def test_compile_note_only_on_the_first_run(tmp_path: Path) -> None:
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "numba")}
    argv = [sys.executable, "-m", "radar.cli", "detect", "--scene", "table1", "--preset",
            "paper-fpga", "--detect", "fpga", "--json", str(tmp_path / "d.json")]
    errs = [subprocess.run(argv, env=env, capture_output=True, text=True, check=True,
                           cwd=Path(__file__).parents[1]).stderr for _ in range(2)]
    assert "compiling the host kernels" in errs[0]
    assert "compiling" not in errs[1], errs[1]
    code = "import host.kernels as K; print(K.uncompiled_kernels())"
    left = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                          text=True, check=True, cwd=Path(__file__).parents[1]).stdout
    assert left.strip() == "[]"
