"""Yosys estimate results: the mapped cells of a job (parsed from ``stat -json``), counted into
the table columns, and the report (``OUT/estimate.md`` beside the paper's Table II and the
xczu7ev capacity, ``OUT/estimate.json``). docs/synth.md explains the columns.
"""

from __future__ import annotations

import json
import sys
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path

from synth.jobs import PAPER_TABLE_II, Job, job_sets

# Yosys cell type -> (column, LUTs of the cell for the LUTRAM column)
_LUT_CELLS = {f"LUT{i}" for i in range(1, 7)} | {"INV"}
_FF_CELLS = {"FDRE", "FDSE", "FDCE", "FDPE", "LDCE", "LDPE"}
_LUTRAM_LUTS = {
    "RAM16X1S": 1, "RAM32X1S": 1, "RAM64X1S": 1, "RAM128X1S": 2, "RAM256X1S": 4,
    "RAM512X1S": 8, "RAM16X1D": 2, "RAM32X1D": 2, "RAM64X1D": 2, "RAM128X1D": 4,
    "RAM256X1D": 8, "RAM32M": 4, "RAM64M": 4, "RAM32M16": 8, "RAM64M8": 8,
    "SRL16E": 1, "SRLC16E": 1, "SRLC32E": 1,
}


# xczu7ev (ZCU106) capacity, the denominators of the utilization percentages.
XCZU7EV: dict[str, float] = {"LUT": 230400, "FF": 460800, "DSP": 1728, "BRAM": 312, "URAM": 96}


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


def parse_stat(text: str) -> dict[str, int]:
    """Mapped cell counts by Yosys cell type from the text of ``stat -json``."""
    design = json.loads(text).get("design", {})
    return {k: int(v) for k, v in design.get("num_cells_by_type", {}).items()}


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


def result_line(r: Result) -> str:
    """One progress line of a finished job: why it has no counts, or its time, memory and
    columns."""
    if r.skipped:
        return f"  skipped: {r.skipped}"
    if r.error:
        return f"  FAILED after {r.seconds:.0f} s: {r.error}"
    return (f"  {r.seconds:.0f} s, {r.peak_mb:.0f} MB: "
            + ", ".join(f"{k} {_fmt(v)}" for k, v in r.columns.items()))


def write_report(results: list[Result], out: Path, set_name: str, version: str) -> int:
    """Write ``out/estimate.md`` (job table, capacity table) and ``out/estimate.json``; print
    the tables; 1 if a job failed."""
    table = markdown(results)
    cap = capacity_table(results)
    notes = (f"\nYosys {version} `synth_xilinx -family xcup -flatten -noiopad -noclkbuf` "
             "with the multipliers' registers packed into the DSP48E2s (docs/synth.md) "
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
