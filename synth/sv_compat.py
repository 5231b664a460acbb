"""Source-to-source rewrites that let Yosys' built-in SystemVerilog frontend read our RTL.

Yosys 0.70 (``read_verilog -sv``) does not accept four constructs the RTL uses; Verilator and
Vivado accept all of them, so the RTL stays as it is and only the copy handed to Yosys is
rewritten. Each rewrite keeps the meaning of the code exactly and is done on a copy under the
build folder (``build/synth/yosys/src``); nothing in ``rtl/`` is touched.

1. ``return EXPR;`` in a function (Yosys: ``syntax error, unexpected TOK_ID``). A final
   ``return EXPR;`` becomes ``NAME = EXPR;``; an early one-line guard ``if (C) return EXPR;``
   becomes ``if (C) NAME = EXPR; else begin ... end`` around the rest of the body. Any other
   ``return`` stops the flow with a message naming the file and line.
2. Unpacked constant arrays ``localparam T NAME [SIZE] = '{v0, v1, ...};`` (the generated ROM
   package; Yosys: ``syntax error, unexpected '['``) become a function with a ``case`` per
   entry, and every ``NAME[idx]`` in a file that imports the package becomes ``NAME(idx)``.
3. ``import PKG::*;`` inside a module (Yosys: ``unexpected TOK_IMPORT``) and wildcard-imported
   package functions (Yosys 0.70 asserts ``wire != nullptr`` in ``simplify.cc``): the package
   body is pasted into the module in place of the import, so every function is module-local.
4. Named assignment patterns for packed structs ``'{field: value, ...}`` become a plain
   concatenation in declaration order (see ``_struct_patterns``).

``rewrite_tree`` returns the list of rewrites done, which the estimate prints in its report.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path


class CompatError(RuntimeError):
    """A construct the rewrites do not cover: the message names the file and line."""


@dataclass
class Package:
    """A SystemVerilog package: its name, body text (between the header and ``endpackage``)
    and the names of the unpacked constant arrays rewritten into functions."""

    name: str
    body: str
    rom_names: list[str] = field(default_factory=list)


# header (up to the first ';', which closes the port list), body, endfunction
_FUNC_RE = re.compile(
    r"(?P<head>^[ \t]*function\b[^;]*;)(?P<body>.*?)(?P<tail>^[ \t]*endfunction\b)",
    re.S | re.M,
)
_GUARD_RE = re.compile(r"^(?P<ind>[ \t]*)if\s*(?P<cond>\(.*\))\s*return\s+(?P<expr>[^;]+);\s*$")
_RET_RE = re.compile(r"^(?P<ind>[ \t]*)return\s+(?P<expr>[^;]+);\s*$")
_ROM_RE = re.compile(
    r"^(?P<ind>[ \t]*)localparam\s+(?P<type>logic\s*(?:signed\s*)?\[[^\]]+\])\s+(?P<name>\w+)"
    r"\s*\[(?P<size>[^\]]+)\]\s*=\s*'\{(?P<vals>.*?)\}\s*;",
    re.S | re.M,
)
_PKG_RE = re.compile(r"^[ \t]*package\s+(?P<name>\w+)\s*;(?P<body>.*?)^[ \t]*endpackage\b",
                     re.S | re.M)
_IMPORT_RE = re.compile(r"^[ \t]*import\s+(?P<name>\w+)::\*\s*;[ \t]*\n", re.M)


def _line_of(text: str, pos: int) -> int:
    return text.count("\n", 0, pos) + 1


def _balanced(cond: str) -> bool:
    """True when ``cond`` is one parenthesised expression ``( ... )``."""
    depth = 0
    for i, ch in enumerate(cond):
        depth += ch == "("
        depth -= ch == ")"
        if depth == 0 and i != len(cond) - 1:
            return False
    return depth == 0


def _func_name(head: str) -> str:
    """The name in a function header: the identifier before the port list's '(' once the
    bracketed ranges (which may hold calls such as ``$clog2(N)``) are removed."""
    m = re.search(r"(\w+)\s*\(", re.sub(r"\[[^\]]*\]", " ", head))
    if not m:
        raise CompatError(f"cannot find the function name in: {head.strip()}")
    return m.group(1)


def rewrite_returns(text: str, path: str, done: list[str]) -> str:
    """Rewrite 1: ``return`` statements of every function in ``text``."""

    def one(m: re.Match[str]) -> str:
        body = m.group("body")
        if not re.search(r"\breturn\b", re.sub(r"//[^\n]*", "", body)):
            return m.group(0)
        name = _func_name(m.group("head"))
        out: list[str] = []
        opened: list[str] = []
        for line in body.split("\n"):
            code = line.split("//")[0].rstrip()   # a trailing comment is dropped
            g = _GUARD_RE.match(code)
            r = _RET_RE.match(code)
            if g and _balanced(g.group("cond")):
                ind = g.group("ind")
                out.append(f"{ind}if {g.group('cond')} {name} = {g.group('expr')};")
                out.append(f"{ind}else begin")
                opened.append(ind)
            elif r:
                out.append(f"{r.group('ind')}{name} = {r.group('expr')};")
            elif re.search(r"\breturn\b", code):
                lineno = _line_of(m.string, m.start("body")) + len(out)
                raise CompatError(
                    f"{path}:{lineno}: return in function {name} is neither a final "
                    "'return EXPR;' nor a one-line 'if (C) return EXPR;' guard; "
                    "synth/sv_compat.py cannot rewrite it for Yosys")
            else:
                out.append(line)
        # close the else-blocks just before the line holding endfunction's indentation
        while opened:
            ind = opened.pop()
            out.insert(len(out) - 1, f"{ind}end")
        done.append(f"{path}: function {name}: return -> assignment to {name}")
        return m.group("head") + "\n".join(out) + m.group("tail")

    return _FUNC_RE.sub(one, text)


def rewrite_roms(text: str, path: str, done: list[str]) -> tuple[str, list[str]]:
    """Rewrite 2 (declaration side): unpacked constant arrays become case functions."""
    names: list[str] = []

    def one(m: re.Match[str]) -> str:
        ind, typ, name = m.group("ind"), m.group("type"), m.group("name")
        vals = [v.strip() for v in re.sub(r"//[^\n]*", "", m.group("vals")).split(",")]
        vals = [v for v in vals if v]
        names.append(name)
        lines = [f"{ind}function automatic {typ} {name}(input integer i);",
                 f"{ind}  case (i)"]
        lines += [f"{ind}    {k}: {name} = {v};" for k, v in enumerate(vals)]
        lines += [f"{ind}    default: {name} = '0;", f"{ind}  endcase", f"{ind}endfunction"]
        done.append(f"{path}: localparam {name}[{m.group('size').strip()}] "
                    f"({len(vals)} entries) -> case function {name}()")
        return "\n".join(lines)

    return _ROM_RE.sub(one, text), names


def _index_to_call(text: str, name: str) -> tuple[str, int]:
    """``NAME[expr]`` -> ``NAME(expr)`` with bracket matching; returns text and count."""
    out, i, n = [], 0, 0
    pat = re.compile(rf"\b{re.escape(name)}\s*\[")
    while True:
        m = pat.search(text, i)
        if not m:
            out.append(text[i:])
            return "".join(out), n
        depth, j = 1, m.end()
        while depth:
            if j >= len(text):
                raise CompatError(f"unbalanced '[' after {name}")
            depth += text[j] == "["
            depth -= text[j] == "]"
            j += 1
        out.append(text[i:m.start()] + f"{name}(" + text[m.end():j - 1] + ")")
        i, n = j, n + 1


def _struct_patterns(text: str, path: str, done: list[str]) -> str:
    """Rewrite 4: ``'{f1: v1, f2: v2}`` assigned to a packed struct -> ``{v1, v2}`` in the
    struct's declaration order (packed structs are declared MSB first)."""
    structs: dict[str, list[str]] = {}
    for m in re.finditer(r"typedef\s+struct\s+packed\s*\{(?P<body>.*?)\}\s*(?P<name>\w+)\s*;",
                         text, re.S):
        body = re.sub(r"//[^\n]*", "", m.group("body"))
        fields = [re.findall(r"(\w+)\s*$", d.strip())[0]
                  for d in body.split(";") if d.strip()]
        structs[m.group("name")] = fields

    out, i = [], 0
    start = re.compile(r"'\{(?=\s*\w+\s*:(?!:))")
    while m := start.search(text, i):
        depth, j, parts, last = 1, m.end(), [], m.end()
        while depth:
            if j >= len(text):
                raise CompatError(f"{path}:{_line_of(text, m.start())}: unbalanced '{{")
            ch = text[j]
            if ch in "([{":
                depth += 1
            elif ch in ")]}":
                depth -= 1
            if (ch == "," and depth == 1) or depth == 0:
                parts.append(text[last:j])
                last = j + 1
            j += 1
        items = {}
        for part in parts:
            key, _, val = part.partition(":")
            items[key.strip()] = val.strip()
        for name, fields in structs.items():
            if set(fields) == set(items):
                done.append(f"{path}:{_line_of(text, m.start())}: '{{...}} of {name} -> "
                            "concatenation")
                out.append(text[i:m.start()] + "{" + ", ".join(items[f] for f in fields) + "}")
                break
        else:
            raise CompatError(f"{path}:{_line_of(text, m.start())}: named assignment pattern "
                              "matches no packed struct of this file")
        i = j
    out.append(text[i:])
    return "".join(out)


def rewrite_tree(files: list[Path], out_dir: Path) -> tuple[list[Path], list[str]]:
    """Write Yosys-readable copies of ``files`` into ``out_dir``.

    Returns the rewritten paths (same order, packages included) and one line per rewrite.
    """
    out_dir.mkdir(parents=True, exist_ok=True)
    done: list[str] = []
    texts = {f: f.read_text() for f in files}
    pkgs: dict[str, Package] = {}
    for f, text in texts.items():
        text = rewrite_returns(text, f.name, done)
        text, roms = rewrite_roms(text, f.name, done)
        texts[f] = text
        for m in _PKG_RE.finditer(text):
            pkgs[m.group("name")] = Package(m.group("name"), m.group("body"), roms)
    out: list[Path] = []
    for f, text in texts.items():
        if not _PKG_RE.search(text):
            imported = [m.group("name") for m in _IMPORT_RE.finditer(text)]
            for name in imported:
                if name not in pkgs:
                    raise CompatError(f"{f.name}: imports {name}, no such package in the list")
                pkg = pkgs[name]
                text = re.sub(rf"^[ \t]*import\s+{name}::\*\s*;[ \t]*\n",
                              lambda _m, p=pkg: f"  // ---- package {p.name} (inlined)"
                              f"{p.body}  // ---- end of package {p.name}\n",
                              text, count=1, flags=re.M)
                done.append(f"{f.name}: import {name}::* -> package body inlined")
                for rom in pkg.rom_names:
                    text, n = _index_to_call(text, rom)
                    if n:
                        done.append(f"{f.name}: {n} x {rom}[...] -> {rom}(...)")
            text = _struct_patterns(text, f.name, done)
        dst = out_dir / f.name
        dst.write_text(text)
        out.append(dst)
    return out, done
