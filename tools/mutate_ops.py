"""The mutation operators added for the bug kinds outside checks kept finding (issue 33 item
4), beside the original ones of ``tools/mutate.py``:

  dropfirst  the FIRST operand of an ``&&`` / ``||`` chain dropped (``drop`` drops only the
             operands after an operator): a counter guard losing its corner term
             (``!skip_q && ovf_drop`` -> ``ovf_drop``: drops counted while skipping), a sticky
             merge losing its hold term (``framing_q || err`` -> ``err``)
  merge      one operand dropped from a bitwise ``|`` merge of flags, any position,
             continuation lines of a multi-line assignment included (AND merges of flags are
             written ``&&`` here, where ``drop`` / ``dropfirst`` reach them; ``&`` is a mask)
             (``pp | ct | pk | fft_q`` / ``| det_err;`` -> the flag no longer reaches the top)
  count      a status counter (a register that saturates, ``X != '1``, or drives an output
             directly) miscounts in a corner: its increment removed (``+ 32'd1`` -> ``+ 32'd0``;
             ``+ 1'b1`` is ``const``'s already), or its increment gains a ``!L`` term for each
             last/end term L of the module (``if (!s_axis_tlast) cnt <= cnt + 1``)
  tie        a comparison wrong only on a tie where ``rel`` does not reach (continuation lines,
             port connections): ``<`` <-> ``<=``, ``>`` <-> ``>=``; and a counter compared with
             a bound by ``==`` made ``>=``
  last       a last/end term (``*last*``, ``*_end``) of a condition or assignment stuck at 0
             (the TLAST never seen), not in port connections and not where it is an operand
             of ``||`` (there ``drop``/``dropfirst`` already remove it)

Generated sources (``GENERATED`` in ``tools/mutate.py``) get none of them: they model slips of
a hand-written block. Each operator's mutants are numbered in source order
(``module:op:index``; the original operators' numbering is untouched); a new mutant whose text
some earlier operator already produced on the same line is left out.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterator

Spans = list[tuple[int, int]]
NEW_OPS = ("dropfirst", "merge", "count", "tie", "last")
LAST_RE = re.compile(r"(?<![\w.'])(\w*last\w*|\w+_end)\b(?!\s*\()")
_INC_RE = re.compile(r"^(\s*)(?:if \((.*)\) )?(\w+)(\s*<=\s*)\3 \+ (1'b1|\d+'d1|'d1|1);(\s*)$")
_ZERO = {"1": "0", "'d1": "'d0"}


def wide_spans(code: str, spans: Spans) -> tuple[Spans, int]:
    """The expression spans of a line for the new operators: ``spans`` (those of the original
    operators) or, where those are empty, a continuation line of a multi-line expression
    (it starts with an operator) or the expression of a port connection ``.p(expr)``.
    Returns (spans, 0 | 1 | 2: within the original operators' reach | a continuation line |
    port connections)."""
    if spans:
        return spans, 0
    s = code.lstrip()
    if re.match(r"(\|\||&&|[|&+?:]|<=?|>=?|==|!=)\s", s):
        return [(len(code) - len(s), len(code))], 1
    out = []
    for m in re.finditer(r"\.\w+\s*\(", code):
        depth, j = 1, m.end()
        while j < len(code) and depth:
            depth += {"(": 1, ")": -1}.get(code[j], 0)
            j += 1
        if depth == 0 and j - 1 > m.end():
            out.append((m.end(), j - 1))
    return out, 2 if out else 0


def operand_end(code: str, j: int, stops: tuple[str, ...]) -> int:
    """End of the operand starting at ``j``: the next ``stops`` operator, ``;?:,`` or closing
    bracket at depth 0."""
    depth = 0
    while j < len(code):
        ch = code[j]
        if ch in "([{":
            depth += 1
        elif ch in ")]}":
            if depth == 0:
                break
            depth -= 1
        elif depth == 0 and (any(code.startswith(s, j) for s in stops) or ch in ";?:,") \
                and "::" not in code[j - 1:j + 2]:
            break
        j += 1
    return j


def _operand_start(code: str, j: int, lo: int, stops: tuple[str, ...]) -> tuple[int, bool]:
    """Start of the operand ending just before ``j`` (scanning left, not past ``lo``), and
    whether it is the first of its chain (not preceded by one of ``stops``)."""
    depth = 0
    k = j - 1
    while k >= lo:
        ch = code[k]
        if ch in ")]}":
            depth += 1
        elif ch in "([{":
            if depth == 0:
                break
            depth -= 1
        elif depth == 0 and ch in "?:,=" and "::" not in code[k - 1:k + 2] \
                and not (ch == "=" and code[k - 1:k] in "=!<>" and k > lo) \
                and code[k + 1:k + 2] != "=":
            break
        elif depth == 0 and any(code.startswith(s, k - len(s) + 1) for s in stops):
            return k + 1, False
        k -= 1
    return k + 1, True


def _chain_drops(code: str, spans: Spans, op_re: re.Pattern[str], stops: tuple[str, ...],
                 every: bool) -> Iterator[str]:
    """Lines with one operand of a chain dropped: the first operand of each chain, and (with
    ``every``) also each operand after an operator."""
    for a, b in spans:
        for m in op_re.finditer(code, a, b):
            start, first = _operand_start(code, m.start(), a, stops)
            if first and code[start:m.start()].strip():
                lead = len(code[start:m.start()]) - len(code[start:m.start()].lstrip())
                yield code[:start + lead] + code[m.end():].lstrip()
            if every:
                end = operand_end(code, m.end(), stops)
                if end > m.end():
                    yield code[:m.start()].rstrip() + code[end:] if code[end:end + 1] in \
                        (";", ")", ",", "") else code[:m.start()] + " " + code[end:].lstrip()


def _status_counter(name: str, text: str) -> bool:
    return bool(re.search(rf"\b{name}\s*!=\s*'1", text)
                or re.search(rf"assign\s+\w+\s*=\s*{name}\s*;", text))


def extra_mutants(text: str, design: list[tuple[int, str]],
                  split: Callable[[str], tuple[str, str]],
                  expr_spans: Callable[[str], Spans]) -> Iterator[tuple[str, int, str]]:
    """(operator, 0-based line, mutated line) of the new operators over the ``design`` lines
    of one file, in source order per operator (not yet deduplicated)."""
    lasts = sorted({m.group(1) for _, line in design
                    for a, b in expr_spans(split(line)[0])
                    for m in LAST_RE.finditer(split(line)[0][a:b])})
    for i, line in design:
        code, comment = split(line)
        spans, beyond = wide_spans(code, expr_spans(code))
        for new in _chain_drops(code, spans, re.compile(r"\s(&&|\|\|)\s"), ("&&", "||"),
                                every=False):
            yield "dropfirst", i, new + comment
        for new in _chain_drops(code, spans, re.compile(r"(?<![|&])\s?\|\s(?![|&=])"),
                                ("|",), every=True):
            if new.strip():
                yield "merge", i, new + comment
        m = _INC_RE.match(code)
        if m and _status_counter(m.group(3), text):
            ind, guard, reg, asg, one, tail = m.groups()
            if one != "1'b1":
                zero = _ZERO.get(one, one[:-1] + "0")
                yield "count", i, code[:m.start(5)] + zero + code[m.end(5):] + comment
            for last in lasts:
                if guard is not None and re.search(rf"\b{last}\b", guard):
                    continue
                cond = f"{guard} && !{last}" if guard is not None else f"!{last}"
                yield "count", i, f"{ind}if ({cond}) {reg}{asg}{reg} + {one};{tail}{comment}"
        for a, b in spans:
            for t in re.finditer(r"(?<![<>=!])(<=?|>=?)(?![<>=])", code[a:b]):
                if not beyond or code[a:b][t.start() - 1:t.start()] == "-":
                    continue
                swap = {"<": "<=", "<=": "<", ">": ">=", ">=": ">"}[t.group()]
                yield "tie", i, code[:a + t.start()] + swap + code[a + t.end():] + comment
            for t in re.finditer(r"==", code[a:b]):
                lhs = re.search(r"(\w+)(\[[^\]]*\])?\s*$", code[a:a + t.start()])
                rhs = code[a + t.end():b].lstrip()
                if lhs and re.search(r"_q$|cnt|count|idx|pos", lhs.group(1)) \
                        and "state" not in lhs.group(1) \
                        and not re.match(r"'[01]\b|\d+'[bd]0\b|'0|0\b", rhs):
                    yield "tie", i, code[:a + t.start()] + ">=" + code[a + t.end():] + comment
            for t in LAST_RE.finditer(code, a, b) if beyond != 2 else ():
                before = code[a:t.start()].rstrip()
                after = code[t.end():b].lstrip()
                if before.endswith("||") or after.startswith("||") or \
                        before.endswith(".") or after.startswith("["):
                    continue
                yield "last", i, code[:t.start()] + "1'b0" + code[t.end():] + comment
