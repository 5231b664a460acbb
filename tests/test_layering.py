"""The package layering of DESIGN.md section 1: every import (top level, lazy, or under
``TYPE_CHECKING``) of every Python file of each package goes only to the packages its row of
the table allows; ``model`` imports nothing outside numpy, scipy and the standard library;
no installed (product) package imports ``tests``, ``tb`` or ``benchmarks`` (the benchmark
scripts, which may use the tests' scenes)."""

from __future__ import annotations

import ast
import sys
import tomllib
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
PROJECT = ("model", "rtlsim", "tb", "host", "gnn", "radar", "synth", "campaign", "tests",
           "benchmarks")
"""The project's Python packages (folders) whose imports are checked."""
MAY_IMPORT: dict[str, frozenset[str]] = {
    "model": frozenset({"model"}),
    "rtlsim": frozenset({"rtlsim", "model"}),
    "tb": frozenset({"tb", "model", "rtlsim", "host"}),
    "host": frozenset({"host", "model"}),
    "gnn": frozenset({"gnn", "model", "host"}),
    "radar": frozenset({"radar", "model", "rtlsim", "host", "gnn", "synth", "campaign"}),
    "synth": frozenset({"synth", "model"}),
    "campaign": frozenset({"campaign", "model", "host"}),
    "tests": frozenset({"tests", "model", "rtlsim", "host", "gnn", "radar", "synth",
                        "campaign", "benchmarks"}),
    "benchmarks": frozenset({"benchmarks", "model", "rtlsim", "host", "gnn", "radar", "synth",
                             "campaign", "tests"}),
}
"""Project packages each package may import (DESIGN.md section 1, last column; ``benchmarks``
is the top-level folder of benchmark scripts, not an installed package)."""
PRODUCT = tuple(p.rstrip("*") for p in tomllib.loads((REPO / "pyproject.toml").read_text())
                ["tool"]["setuptools"]["packages"]["find"]["include"])
"""The packages pyproject.toml installs."""
MODEL_THIRD_PARTY = frozenset({"numpy", "scipy"})
"""The only non-standard-library modules ``model`` may import."""


def imported_modules(source: str) -> list[tuple[int, str]]:
    """(line, top-level module name) of every absolute import in ``source``."""
    out = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            out.extend((node.lineno, a.name.split(".")[0]) for a in node.names)
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            out.append((node.lineno, node.module.split(".")[0]))
    return out


def violations(package: str, source: str, where: str = "<source>") -> list[str]:
    """Imports in ``source`` (a file of ``package``) that the layering table forbids."""
    bad = []
    for line, name in imported_modules(source):
        if name in PROJECT:
            if name not in MAY_IMPORT[package]:
                bad.append(f"{where}:{line}: {package} imports {name}")
        elif package == "model" and name not in MODEL_THIRD_PARTY \
                and name not in sys.stdlib_module_names and name != "__future__":
            bad.append(f"{where}:{line}: model imports {name} (numpy/scipy/stdlib only)")
    return bad


def package_files(package: str) -> list[Path]:
    return sorted(p for p in (REPO / package).rglob("*.py") if "sim_build" not in p.parts)


@pytest.mark.parametrize("package", PROJECT)
def test_imports_follow_the_layering(package: str) -> None:
    files = package_files(package)
    assert files, f"no Python files in {package}/"
    bad = [v for f in files
           for v in violations(package, f.read_text(), str(f.relative_to(REPO)))]
    assert not bad, "imports against DESIGN.md section 1:\n" + "\n".join(bad)


@pytest.mark.parametrize(("package", "source"), [
    ("host", "from gnn.infer import detect_objects"),
    ("host", "def f():\n    import rtlsim.toolchain\n"),
    ("gnn", "from radar.cli import main"),
    ("rtlsim", "from host.capture import write_capture"),
    ("tb", "from radar.sources import SOURCES"),
    ("radar", "import tests.test_cli"),
    ("host", "from benchmarks.bench_detect import host_time_rows"),
    ("radar", "def f():\n    import benchmarks.bench_view\n"),
    ("model", "import torch"),
    ("synth", "from host import plots"),
    ("campaign", "from radar.cli import main"),
    ("host", "from campaign.runner import run"),
])
def test_checker_catches_an_upward_import(package: str, source: str) -> None:
    assert violations(package, source)


def test_checker_allows_the_table() -> None:
    assert not violations("radar", "from rtlsim.pipeline_rtl import run_pipeline_rtl\n"
                                   "from gnn.infer import detect_objects\nimport torch")
    assert not violations("model", "import numpy as np\nfrom scipy import signal\nimport math")
    assert not violations("tb", "from host.stream import StreamDecoder\nimport cocotb")
    assert not violations("benchmarks", "from tests.scenes import synthetic_records\n"
                                        "from radar.view.browser import launch")
    assert not violations("tests", "from benchmarks.bench_detect import host_time_rows")


def test_no_product_package_imports_test_or_benchmark_code() -> None:
    """The table keeps ``tests``, ``tb`` and ``benchmarks`` out of every installed package,
    and pyproject.toml installs none of them."""
    assert set(PRODUCT) == {"model", "rtlsim", "host", "gnn", "radar", "synth", "campaign"}
    for package in PRODUCT:
        assert not MAY_IMPORT[package] & {"tests", "tb", "benchmarks"}, package
