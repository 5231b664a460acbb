"""Mutant schemata (Untch): every mutant of one RTL module compiled into one copy of its
source, each guarded by a run-time mutant number, so one Verilator build per module and
parameter set serves all of its mutants (``tools/mutate.py --schemata``).

The number is ``mut_id``, a module variable declared after the module header of the copy and
set from the plusarg ``+MUTANT=<k>`` (0 or absent: the original design) by an ``initial``
block; ``rtlsim/toolchain.py`` passes ``RTLSIM_PLUSARGS`` to the simulator. A mutant is one
changed line; the guarded line keeps its line number (errors map back to the source line).
Three line forms are guarded, each sound by construction:

  stmt    a complete procedural statement, after an optional ``end`` / ``else`` / case label
          / ``always_ff @(...)`` prefix (``x <= e;``, ``if (c) x <= e;``, ``for (int ...)
          x[i] <= e;``, ``begin ... end``): ``PREFIX begin if (mut_id == K) begin S_K end
          else begin S end end`` (a mutant that removes the statement has an empty S_K).
          Not where the statement's ``if`` takes an ``else`` from the next line.
  cond    the condition of an ``if (...)`` whose parentheses close on the line (``if (c)
          begin`` openers, ``end else if (c) begin``): ``if ((mut_id == K) ? (c_K) : (c))``.
          Not a labelled (generate) ``if``.
  assign  ``assign lhs = e;`` on one line: ``assign lhs = (mut_id == K) ? (e_K) : (e);``
          (the operands of ``?:`` are evaluated at the wider of the two widths: a mutant
          that narrows ``e`` under a right shift or a division could differ; the soundness
          check of docs/verification.md compares verdicts with the per-mutant builds).

Several mutants of one line nest (``K1 ? ... : K2 ? ... : original``). Everything else
(declarations, generate loops and conditions, continuation lines of multi-line statements,
port connections) goes through the per-mutant build. The sticky operator's multi-line form
(``f <= c;`` inserted before ``if (c) begin``) is guarded as ``if (mut_id == K) f <= c;``
before the line.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from mutate_gen import Mutant

MUT_VAR = "mut_id"
PLUSARG = "MUTANT"
_PREFIX = re.compile(r"^\s*(always_ff\s*@\s*\([^()]*\)\s*|always_comb\s+"
                     r"|(?:[\w']+(?:\s*,\s*[\w']+)*)\s*:(?!:)\s*|(?:end\s+)?(?:else\s+)?)")
_STMT_START = re.compile(r"(if\b|for\b|begin\b|\{|[A-Za-z_]\w*)")
_NOT_STMT = re.compile(r"(logic|wire|reg|int|integer|bit|genvar|localparam|parameter|assign|"
                       r"typedef|case|unique|priority|module|function|task|end|else|"
                       r"for\s*\(\s*genvar)\b|\w+(\s*\[[^\]]*\])*\s+\w+\s*(=|;)")
_PREV_OK = re.compile(r"(;|\bbegin|\bend|\belse|\)|:|\bbegin\s*:\s*\w+|\bend\s*:\s*\w+)$")


@dataclass
class Schemata:
    """A module's schemata source and which of its mutants it holds."""

    text: str                   # the guarded source
    ids: dict[str, int]         # mutant ident -> its mut_id (1, 2, ...)
    classic: list[Mutant]       # the mutants it does not hold (per-mutant builds)


def _code(line: str) -> tuple[str, str]:
    k = line.find("//")
    return (line, "") if k < 0 else (line[:k].rstrip(), " " + line[k:])


def _balanced(t: str) -> bool:
    return all(t.count(a) == t.count(b) for a, b in ("()", "[]", "{}")) and \
        len(re.findall(r"\bbegin\b", t)) == len(re.findall(r"\bend\b", t))


def _code_line(lines: list[str], i: int, step: int) -> str:
    """The nearest non-blank code line from ``i`` in direction ``step`` (comments and
    preprocessor lines skipped), stripped; '' at the file's end."""
    i += step
    while 0 <= i < len(lines):
        c = _code(lines[i])[0].strip()
        if c and not c.startswith("`"):
            return c
        i += step
    return ""


def _stmt_split(code: str) -> tuple[str, str] | None:
    """(prefix, statement) of a line holding one complete procedural statement, else None."""
    m = _PREFIX.match(code)
    pre, rest = (m.group(0), code[m.end():]) if m else ("", code)
    rest = rest.rstrip()
    if not rest or _NOT_STMT.match(rest) or not _STMT_START.match(rest) \
            or not _balanced(rest) or "=" not in rest:
        return None
    if not (rest.endswith(";") or (rest.startswith("begin") and rest.endswith("end"))):
        return None
    return pre, rest


def _cond_span(code: str) -> tuple[int, int] | None:
    """Span of the condition of the line's first ``if (...)`` when it closes on the line."""
    m = re.search(r"\bif\s*\(", code)
    if not m:
        return None
    depth, j = 1, m.end()
    while j < len(code) and depth:
        depth += {"(": 1, ")": -1}.get(code[j], 0)
        j += 1
    return (m.end(), j - 1) if depth == 0 else None


def _assign_split(code: str) -> tuple[str, str] | None:
    m = re.match(r"^(\s*assign\s+[^=;]*?[^=!<>]=)(?!=)\s*(.*);$", code.rstrip())
    return (m.group(1), m.group(2)) if m and _balanced(m.group(2)) else None


def _nest(alts: list[tuple[int, str]], orig: str) -> str:
    return "".join(f"({MUT_VAR} == {k}) ? ({e}) : " for k, e in alts) + f"({orig})"


def guard_line(lines: list[str], i: int, muts: list[tuple[int, Mutant]]
               ) -> tuple[str, list[tuple[int, Mutant]]]:
    """The guarded version of line ``i`` holding ``muts`` ((mut_id, mutant) pairs), and the
    pairs it holds (the rest go through per-mutant builds)."""
    line = lines[i]
    code, comment = _code(line)
    prev, nxt = _code_line(lines, i, -1), _code_line(lines, i, 1)
    seq_ok = bool(_PREV_OK.search(prev)) and not re.search(r"\belse$", prev)
    # the sticky operator's insertion before an ``if (c) begin`` line
    ins: list[tuple[int, str]] = []
    rest: list[tuple[int, Mutant]] = []
    held: list[tuple[int, Mutant]] = []
    for k, m in muts:
        new = _code(m.after)[0].strip()
        head = new[: max(0, len(new) - len(code.strip()))]
        if m.op == "sticky" and new.endswith(code.strip()) and seq_ok and \
                re.fullmatch(r"\w+ <= [^;]*; ", head):
            ins.append((k, head.strip()))
            held.append((k, m))
        else:
            rest.append((k, m))
    stmt = _stmt_split(code)
    if stmt and (not prev or _PREV_OK.search(prev)) and not (
            re.search(r"\bif\b", stmt[1]) and re.match(r"else\b", nxt)):
        pre, orig = stmt
        alts = []
        for k, m in rest:
            new = _code(m.after)[0]
            if not new.strip():
                alts.append((k, ""))
                held.append((k, m))
                continue
            s2 = _stmt_split(new)
            if s2 and s2[0] == pre:
                alts.append((k, s2[1]))
                held.append((k, m))
        body = "".join(f"if ({MUT_VAR} == {k}) begin {s} end else " for k, s in alts)
        guarded = f"{pre}begin {body}begin {orig} end end" if alts else code
    elif (a := _assign_split(code)) is not None:
        head, orig = a
        alts = []
        for k, m in rest:
            a2 = _assign_split(_code(m.after)[0])
            if a2 and a2[0] == head:
                alts.append((k, a2[1]))
                held.append((k, m))
        guarded = f"{head} {_nest(alts, orig)};" if alts else code
    elif (span := _cond_span(code)) is not None and not re.search(r"begin\s*:", code):
        a, b = span
        alts = []
        for k, m in rest:
            new = _code(m.after)[0]
            tail = len(code) - b
            if new[:a] == code[:a] and new[len(new) - tail:] == code[b:] and \
                    len(new) - tail >= a:
                alts.append((k, new[a:len(new) - tail]))
                held.append((k, m))
        guarded = code[:a] + _nest(alts, code[a:b]) + code[b:] if alts else code
    else:
        guarded = code
    if ins:
        ind = len(guarded) - len(guarded.lstrip())
        pre_ins = "".join(f"if ({MUT_VAR} == {k}) {s} " for k, s in ins)
        guarded = guarded[:ind] + pre_ins + guarded[ind:]
    return guarded + comment, held


def declaration(lines: list[str], module: str) -> tuple[int, int]:
    """(line, column) just after the ``;`` ending the header of ``module``."""
    start = next(i for i, ln in enumerate(lines) if re.match(rf"\s*module\s+{module}\b", ln))
    depth = 0
    for i in range(start, len(lines)):
        code = _code(lines[i])[0]
        for j, ch in enumerate(code):
            depth += {"(": 1, ")": -1}.get(ch, 0)
            if ch == ";" and depth == 0:
                return i, j + 1
    raise ValueError(f"no header end of module {module}")


def schemata(module: str, text: str, mutants: list[Mutant], numbers: list[int] | None = None,
             exclude: frozenset[int] = frozenset()) -> Schemata:
    """Guard every mutant of ``text`` (the source of ``module``) it can; the mutant numbers
    are ``numbers`` (default 1, 2, ... in the order of ``mutants``). Lines in ``exclude``
    (0-based) are left as they are (their mutants go to ``classic``)."""
    lines = text.splitlines()
    by_line: dict[int, list[tuple[int, Mutant]]] = {}
    classic: list[Mutant] = []
    for k, m in zip(numbers or range(1, len(mutants) + 1), mutants, strict=True):
        i = m.line - 1
        if i in exclude or i >= len(lines) or lines[i] != m.before:
            classic.append(m)
        else:
            by_line.setdefault(i, []).append((k, m))
    out = list(lines)
    ids: dict[str, int] = {}
    for i, muts in by_line.items():
        out[i], held = guard_line(lines, i, muts)
        ids.update({m.ident: k for k, m in held})
        classic += [m for _, m in muts if m.ident not in ids]
    if ids:
        li, col = declaration(out, module)
        decl = (f" int {MUT_VAR} = 0; initial if (!$value$plusargs(\"{PLUSARG}=%d\", "
                f"{MUT_VAR})) {MUT_VAR} = 0;")
        out[li] = out[li][:col] + decl + out[li][col:]
    order = {m.ident: n for n, m in enumerate(mutants)}
    classic.sort(key=lambda m: order[m.ident])
    return Schemata("\n".join(out) + "\n", ids, classic)
