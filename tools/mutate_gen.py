"""Candidate mutants of the RTL (``tools/mutate.py``): the original operators on the design
lines of ``rtl/**/<module>.sv`` (checks, comments and declarations left out), the operators
of ``tools/mutate_ops.py``, the seeded sample and the fixed CI subset."""

from __future__ import annotations

import difflib
import random
import re
from collections.abc import Iterator
from dataclasses import dataclass

from mutate_ops import NEW_OPS, extra_mutants, operand_end
from mutate_stages import CI_MUTANTS, GENERATED, REPO

RTL = REPO / "rtl"


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


def ci_mutants() -> list[Mutant]:
    """The fixed CI subset as mutants (fails loudly if the RTL no longer has one)."""
    out = []
    for module, op, text in CI_MUTANTS:
        found = [m for m in candidates(module) if m.op == op and text in m.after]
        if not found:
            raise SystemExit(f"error: CI mutant {module}/{op} '{text}' no longer exists")
        out.append(found[0])
    return out



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
        # formal-only code: `ifdef FORMAL, a proof's own define (`ifdef F_<NAME>), simulation checks
        if re.match(r"`ifdef\s+(FORMAL|F_\w+)\b|`ifndef\s+SYNTHESIS", s):
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
        m = re.match(r"^(\s*)(\w+)\s*<=[^/]*;\s*(//.*)?$", lines[j])  # a comment may follow
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

