"""Timing results (docs/synth.md "Timing"): the nextpnr-ecp5 report of a job (resources, Fmax,
critical path), the logic depth of its Yosys ``synth_xilinx -family xcup`` netlist, and the
Markdown table of ``make timing``.
"""

from __future__ import annotations

import json
import re
from collections import defaultdict
from dataclasses import asdict, dataclass
from pathlib import Path

# Xilinx cells a register-to-register path runs through, and what they count as
_XLUT = {f"LUT{i}" for i in range(1, 7)} | {"INV", "MUXF7", "MUXF8", "MUXF9"}
_XCARRY = {"CARRY4", "CARRY8"}


@dataclass
class Row:
    """One job's line of the table. ``lut4`` counts nextpnr's TRELLIS_COMB cells (a LUT4 each;
    a CCU2C carry takes two, a distributed-RAM slice's LUTs count too), ``levels`` the LUT4
    and PFUMX/L6MUX cells with a delay on the ECP5 critical path (not the 0 ns hop into a
    distributed-RAM write port), ``carry`` the CCU2C carry cells on it, ``xlut``/``xcarry`` the
    LUT6 (+ MUXF) levels and carry cells of the longest xcup register-to-register path."""

    name: str
    label: str
    lut4: int = 0
    ff: int = 0
    ebr: int = 0
    mult18: int = 0
    fmax_mhz: float = 0.0
    start: str = ""
    end: str = ""
    levels: int = 0
    carry: int = 0
    xlut: int | None = None
    xcarry: int | None = None
    xstart: str = ""
    xend: str = ""
    seconds: float = 0.0
    error: str = ""
    misfit: str = ""   # the netlist does not fit the device: why (synth.timing_run.fit_problem)


def short_cell(name: str) -> str:
    """A nextpnr / Yosys cell or net name without the mapping suffixes Yosys appends and
    without the wrapper's instance prefix, e.g. ``dut.u_bf.sum_q_TRELLIS_FF_Q_12`` ->
    ``u_bf.sum_q``."""
    name = name.removeprefix("dut.").removeprefix("\\")
    return re.split(r"_(?:TRELLIS|LUT4|CCU2C|DP16KD|MULT18|PFUMX|L6MUX|DPR16X4)|(?<=.)\$",
                    name)[0]


def parse_nextpnr(report: dict) -> dict:
    """Resources, Fmax of ``clk`` (MHz) and the critical path (start and end cell, LUT levels
    and carry cells on it) of a nextpnr ``--report`` JSON."""
    used = {k: v["used"] for k, v in report["utilization"].items()}
    fmax = report.get("fmax", {})
    clk = fmax.get("clk") or next(iter(fmax.values()), {"achieved": 0.0})
    out = {"lut4": used.get("TRELLIS_COMB", 0), "ff": used.get("TRELLIS_FF", 0),
           "ebr": used.get("DP16KD", 0), "mult18": used.get("MULT18X18D", 0),
           "fmax_mhz": float(clk["achieved"]), "start": "", "end": "", "levels": 0,
           "carry": 0}
    paths = [p for p in report.get("critical_paths", []) if p.get("path")]
    if paths:
        path = paths[0]["path"]
        out["start"] = short_cell(path[0]["from"]["cell"])
        out["end"] = short_cell(path[-1]["to"]["cell"])
        logic = [s["to"]["cell"] for s in path if s["type"] == "logic" and s["delay"] > 0]
        out["levels"] = sum(1 for c in logic if "$CCU2_COMB" not in c)
        out["carry"] = len({c.split("$")[0] for c in logic if "$CCU2_COMB" in c})
    return out


def lut_depth(netlist: dict) -> dict:
    """Longest register-to-register path of a flattened ``synth_xilinx`` netlist (Yosys
    ``write_json``), counted in LUT levels (LUT1-6, INV, MUXF7-9 each one level), carry cells
    (CARRY4/8) beside them. Every other cell (FD*, DSP48E2, RAMB*, URAM, SRL, LUTRAM) starts
    and ends paths: a DSP48E2 or block RAM is taken as registered. The longest path is the one
    with the most LUT levels (ties: the most carry cells); ``start``/``end`` are the named nets
    at its two registers."""
    mod = next(m for m in netlist["modules"].values() if m.get("attributes", {}).get("top"))
    cells = mod["cells"]
    names: dict[int, str] = {}
    for n, info in mod["netnames"].items():
        for b in info["bits"]:
            if isinstance(b, int) and (b not in names or names[b].startswith("$")):
                names[b] = n
    driver: dict[int, str] = {}
    sinks: dict[int, list[str]] = defaultdict(list)
    for cn, c in cells.items():
        for port, bits in c["connections"].items():
            d = c["port_directions"].get(port)
            for b in bits:
                if not isinstance(b, int):
                    continue
                if d == "output":
                    driver[b] = cn
                else:
                    sinks[b].append(cn)
    comb = {cn for cn, c in cells.items() if c["type"] in _XLUT | _XCARRY}

    def inputs(cn: str) -> list[int]:
        c = cells[cn]
        return [b for p, bits in c["connections"].items()
                if c["port_directions"].get(p) != "output" for b in bits if isinstance(b, int)]

    def outputs(cn: str) -> list[int]:
        c = cells[cn]
        return [b for p, bits in c["connections"].items()
                if c["port_directions"].get(p) == "output" for b in bits if isinstance(b, int)]

    preds = {cn: {driver[b] for b in inputs(cn) if driver.get(b) in comb} for cn in comb}
    succs: dict[str, set[str]] = defaultdict(set)
    for cn, ps in preds.items():
        for p in ps:
            succs[p].add(cn)
    # Kahn order over the combinational cells; best[cn] = (luts, carries) ending at cn
    todo = [cn for cn in comb if not preds[cn]]
    left = {cn: len(ps) for cn, ps in preds.items()}
    best: dict[str, tuple[int, int]] = {}
    back: dict[str, str | None] = {}
    while todo:
        cn = todo.pop()
        w = (0, 1) if cells[cn]["type"] in _XCARRY else (1, 0)
        prev = max(preds[cn], key=lambda p: best[p], default=None)
        base = best[prev] if prev else (0, 0)
        best[cn] = (base[0] + w[0], base[1] + w[1])
        back[cn] = prev
        for s in succs[cn]:
            left[s] -= 1
            if not left[s]:
                todo.append(s)
    if not best:
        return {"xlut": 0, "xcarry": 0, "xstart": "", "xend": ""}
    last = max(best, key=lambda cn: best[cn])
    first = last
    while back[first]:
        first = back[first]
    start_bits = [b for b in inputs(first) if b in driver and driver[b] not in comb]
    end_regs = [s for b in outputs(last) for s in sinks[b] if s not in comb]
    end_bits = [b for r in end_regs[:1] for b in outputs(r)]
    return {"xlut": best[last][0], "xcarry": best[last][1],
            "xstart": short_cell(names.get(start_bits[0], "")) if start_bits else "",
            "xend": short_cell(names.get(end_bits[0], "")) if end_bits else ""}


def job_row(name: str, label: str, job_dir: Path) -> Row:
    """The table row of a finished job directory (``report.json``, ``xcup.json``)."""
    row = Row(name, label)
    for k, v in parse_nextpnr(json.loads((job_dir / "report.json").read_text())).items():
        setattr(row, k, v)
    xcup = job_dir / "xcup.json"
    if xcup.exists():
        for k, v in lut_depth(json.loads(xcup.read_text())).items():
            setattr(row, k, v)
    done = job_dir / "done.json"
    if done.exists():
        row.seconds = json.loads(done.read_text()).get("seconds", 0.0)
    return row


def markdown(rows: list[Row], freq_mhz: float, header: str) -> str:
    """The ``make timing`` table: one line per job, failed jobs with their error, jobs whose
    netlist does not fit the device with what it lacks."""
    lines = [header, "",
             "| job | parameters | LUT4 | FF | EBR | MULT18 | ECP5 Fmax MHz | "
             f">= {freq_mhz:g} | critical path (start -> end) | LUT4 levels (+carry) | "
             "xcup LUT6 levels (+carry) | xcup path | s |",
             "|---|---|---:|---:|---:|---:|---:|---|---|---:|---:|---|---:|"]
    for r in rows:
        if r.error or r.misfit:
            fit, why = ("", f"failed: {r.error}") if r.error else ("does not fit", r.misfit)
            lines.append(f"| {r.name} | {r.label} | | | | | | {fit} | {why} | | | | "
                         f"{r.seconds:.0f} |")
            continue
        ok = "yes" if r.fmax_mhz >= freq_mhz else "**no**"
        x = "" if r.xlut is None else f"{r.xlut} (+{r.xcarry})"
        xp = "" if r.xlut is None else f"`{r.xstart}` -> `{r.xend}`"
        lines.append(
            f"| {r.name} | {r.label} | {r.lut4} | {r.ff} | {r.ebr} | {r.mult18} | "
            f"{r.fmax_mhz:.1f} | {ok} | `{r.start}` -> `{r.end}` | {r.levels} (+{r.carry}) | "
            f"{x} | "
            f"{xp} | {r.seconds:.0f} |")
    return "\n".join(lines) + "\n"


def write_report(rows: list[Row], out: Path, freq_mhz: float, header: str) -> Path:
    """``out/timing.md`` (the table) and ``out/timing.json`` (the rows)."""
    out.mkdir(parents=True, exist_ok=True)
    (out / "timing.json").write_text(json.dumps([asdict(r) for r in rows], indent=1))
    md = out / "timing.md"
    md.write_text(markdown(rows, freq_mhz, header))
    return md
