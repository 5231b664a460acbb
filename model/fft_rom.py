"""Single source of the FFT coefficient ROMs shared by the RTL (``rtl/fft/fft_rom_pkg.sv``,
``rtl/fft/fft_twiddle_rom.sv``, ``rtl/fft/fft_hann_rom.sv``, ``rtl/fft/fft_win_rom.sv``) and
the bit-accurate models (:mod:`model.fft_axis`, :mod:`model.static_removal`).

Two tables of ``ROM_SIZE = 4096`` entries define every coefficient for N = 16..4096:

- ``COS[k] = rint(2**16 * cos(2*pi*k/4096))``: 18-bit signed, Q1.16 (1.0 = 65536). The sine
  is *defined* as ``SIN[k] = COS[(k - 1024) mod 4096]`` (no second table) and the twiddle
  ``W_M^e`` of an M-point stage is ``COS[e*4096/M] - j*SIN[e*4096/M]``.
- ``HANN[k] = rint(2**16 * (0.5 - 0.5*cos(2*pi*k/4096)))``: periodic Hann, Q1.16, 0..65536;
  the N-point window is ``HANN[n*4096/N]`` (exactly the periodic N-point Hann sampled).

A window over a count ``n`` that is not a power of two (a profile's samples per chirp or
loops per frame below the FFT length, zero-padded, docs/profiles.md) is its own table,
``rint(2**16 * (0.5 - 0.5*cos(2*pi*k/n)))`` for ``n`` in :data:`WINDOW_LENGTHS`, generated
into ``fft_win_rom`` (which reads ``fft_hann_rom`` for powers of two, so both FFT axes and
the static-clutter removal take every window from it). Every table sums to ``n * 2**15``
like the powers of two (the static removal's divisor; :func:`check_window_sums`).

``rint`` is numpy's round-half-to-even. The model uses these full tables. The RTL stores only
quarter waves and rebuilds every entry by symmetry from the quadrant ``q = k >> 10`` and the
offset ``r = k & 1023`` (:func:`twiddle_from_quarters`, :func:`hann_from_quarters`; the
generator checks they give the full tables exactly):

- twiddle: ``CQ[r] = COS[r]`` and ``SQ[r] = COS[3072 + r]`` (= rint(2**16 sin(2 pi r/4096))),
  17-bit unsigned; ``(COS, SIN)[k]`` = ``(CQ, SQ)``, ``(-SQ, CQ)``, ``(-CQ, -SQ)``,
  ``(SQ, -CQ)`` for q = 0..3;
- window: ``HQ0[r] = HANN[r]`` and ``HQ3[r] = HANN[3072 + r]``, 16-bit unsigned (<= 32768);
  ``HANN[k]`` = ``HQ0``, ``65536 - HQ3``, ``65536 - HQ0``, ``HQ3`` for q = 0..3.

No index arithmetic (no ``1024 - r``): the offset addresses the tables directly, so an
N-point transform's constant low index bits prune each table to the entries it can reach.

The tables are generated as *modules* with one ``case`` item per entry, not as package
functions: Yosys clones every package into each module it reads afterwards, and
``synth_xilinx`` then reads 328 cell models (``cells_xtra.v``), so the 4096-entry package
functions of the old form cost ~3.5 GB and crashed the 4 GiB WebAssembly Yosys (docs/synth.md).

``make gen`` (``python -m model.fft_rom``) rewrites the files (only when their contents
change); ``tb/fft_axis/test_fft_axis_model.py`` and the FFT testbench fail when one is stale.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from model.reference import hann_periodic

ROM_LOG2 = 12
"""log2 of the ROM length: the largest supported transform is 2**ROM_LOG2 points."""
ROM_SIZE = 1 << ROM_LOG2
COEF_FRAC = 16
"""Fraction bits of every coefficient (Q1.16)."""
COEF_W = 18
"""Coefficient width in bits (signed), the B port of a DSP48E2 (27 x 18)."""
QUARTER = ROM_SIZE // 4
"""Entries of each quarter-wave table (1024)."""

RTL_FFT = Path(__file__).resolve().parents[1] / "rtl" / "fft"
PKG_PATH = RTL_FFT / "fft_rom_pkg.sv"
TWIDDLE_ROM_PATH = RTL_FFT / "fft_twiddle_rom.sv"
HANN_ROM_PATH = RTL_FFT / "fft_hann_rom.sv"
WIN_ROM_PATH = RTL_FFT / "fft_win_rom.sv"

WINDOW_LENGTHS = (15, 50, 200, 255)
"""Window lengths other than powers of two that ``fft_win_rom`` holds a table for: the TI
settings' 200 samples per chirp and 255 loops, and the small shapes of the testbenches
(15 of 16, 50 of 64). Another profile's count is added here and ``make gen`` run
(``model.hdl.hdl_unsupported`` names it until then)."""


def cos_table() -> np.ndarray:
    """int64 (4096,): Q1.16 cosine, ``rint(65536*cos(2*pi*k/4096))``."""
    k = np.arange(ROM_SIZE)
    return np.rint((1 << COEF_FRAC) * np.cos(2.0 * np.pi * k / ROM_SIZE)).astype(np.int64)


def sin_table() -> np.ndarray:
    """int64 (4096,): Q1.16 sine, defined as ``COS[(k - 1024) mod 4096]``."""
    k = np.arange(ROM_SIZE)
    return cos_table()[(k - ROM_SIZE // 4) % ROM_SIZE]


def hann_table() -> np.ndarray:
    """int64 (4096,): Q1.16 periodic Hann of length 4096 (values 0..65536)."""
    w = hann_periodic(ROM_SIZE)
    return np.rint((1 << COEF_FRAC) * w).astype(np.int64)


def hann_window(n: int) -> np.ndarray:
    """int64 (n,): the quantized n-point periodic Hann window used by the RTL (Q1.16):
    ``HANN[k*4096/n]`` for a power of two n (exactly the n-point window rounded), else
    ``rint(2**16 * hann_periodic(n))`` (the ``fft_win_rom`` table of n, n in 2..4096)."""
    if n & (n - 1) == 0:
        return hann_table()[np.arange(n) * (ROM_SIZE // n)]
    return np.rint((1 << COEF_FRAC) * hann_periodic(n)).astype(np.int64)


def twiddle_quarters() -> tuple[np.ndarray, np.ndarray]:
    """int64 (1024,) each: ``CQ[r] = COS[r]``, ``SQ[r] = COS[3072 + r]`` (both 0..65536)."""
    c = cos_table()
    return c[:QUARTER].copy(), c[3 * QUARTER:].copy()


def hann_quarters() -> tuple[np.ndarray, np.ndarray]:
    """int64 (1024,) each: ``HQ0[r] = HANN[r]``, ``HQ3[r] = HANN[3072 + r]`` (0..32768)."""
    h = hann_table()
    return h[:QUARTER].copy(), h[3 * QUARTER:].copy()


def twiddle_from_quarters(k: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(COS[k], SIN[k]) rebuilt from the quarter tables exactly as ``fft_twiddle_rom`` does;
    ``k`` int array of indices 0..4095."""
    cq, sq = twiddle_quarters()
    q, r = np.asarray(k) >> (ROM_LOG2 - 2), np.asarray(k) & (QUARTER - 1)
    c_sel = np.select([q == 0, q == 1, q == 2], [cq[r], -sq[r], -cq[r]], sq[r])
    s_sel = np.select([q == 0, q == 1, q == 2], [sq[r], cq[r], -sq[r]], -cq[r])
    return c_sel, s_sel


def hann_from_quarters(k: np.ndarray) -> np.ndarray:
    """HANN[k] rebuilt from the quarter tables exactly as ``fft_hann_rom`` does."""
    h0, h3 = hann_quarters()
    q, r = np.asarray(k) >> (ROM_LOG2 - 2), np.asarray(k) & (QUARTER - 1)
    one = 1 << COEF_FRAC
    return np.select([q == 0, q == 1, q == 2], [h0[r], one - h3[r], one - h0[r]], h3[r])


def check_window_sums() -> None:
    """Raise unless every window of :data:`WINDOW_LENGTHS` sums to ``n * 2**15`` exactly
    (what ``static_removal`` divides by; the powers of two do by symmetry)."""
    for n in WINDOW_LENGTHS:
        if int(hann_window(n).sum()) != n << (COEF_FRAC - 1):
            raise ValueError(f"the {n}-point window sums to {int(hann_window(n).sum())}, not "
                             f"{n} * 2**{COEF_FRAC - 1}: static_removal's divisor needs it")


def check_quarters() -> None:
    """Raise if the quarter-wave tables do not rebuild the full tables bit for bit."""
    k = np.arange(ROM_SIZE)
    c, s = twiddle_from_quarters(k)
    if not (np.array_equal(c, cos_table()) and np.array_equal(s, sin_table())):
        raise ValueError("quarter-wave twiddle tables do not rebuild COS/SIN exactly")
    if not np.array_equal(hann_from_quarters(k), hann_table()):
        raise ValueError("quarter-wave Hann tables do not rebuild HANN exactly")


_HEADER = ("// SPDX-License-Identifier: Apache-2.0\n"
           "// {what}, GENERATED by\n"
           "// `python -m model.fft_rom` (make gen) from model/fft_rom.py: do not edit by hand.\n"
           "`default_nettype none\n\n")


def _sv_case(sig: str, values: np.ndarray, width: int) -> str:
    """One ``always_comb case`` with an item per entry, indexed by the quarter offset ``r``."""
    digits = (width + 3) // 4
    items = "".join(f"      {ROM_LOG2 - 2}'d{r}: {sig} = {width}'h{int(v):0{digits}X};\n"
                    for r, v in enumerate(values))
    return (f"  always_comb begin\n    case (r)\n{items}"
            f"      default: {sig} = '0;\n    endcase\n  end\n")


def render_rom_pkg() -> str:
    """Text of ``rtl/fft/fft_rom_pkg.sv``: the ROM geometry shared by the FFT modules."""
    return (
        _HEADER.format(what="FFT coefficient ROM geometry")
        + "// Every module's lint sees this package, most without using it.\n"
        "/* verilator lint_off UNUSEDPARAM */\n"
        "package fft_rom_pkg;\n"
        "  // log2 of the ROM length; the largest transform is 2**ROM_LOG2 points.\n"
        f"  localparam int ROM_LOG2 = {ROM_LOG2};\n"
        "  localparam int ROM_SIZE = 1 << ROM_LOG2;\n"
        "  // Coefficient width (signed two's complement) and fraction bits (Q1.16).\n"
        f"  localparam int COEF_W = {COEF_W};\n"
        f"  localparam int COEF_FRAC = {COEF_FRAC};\n"
        "  // 1 when fft_win_rom holds an n-point window (a power of two or WINDOW_LENGTHS).\n"
        "  function automatic bit has_window(input int n);\n"
        "    has_window = (n >= 2 && n <= ROM_SIZE && (n & (n - 1)) == 0)"
        + "".join(f" || n == {n}" for n in WINDOW_LENGTHS) + ";\n"
        "  endfunction\n"
        "endpackage\n/* verilator lint_on UNUSEDPARAM */\n\n`default_nettype wire\n"
    )


def render_twiddle_rom() -> str:
    """Text of ``rtl/fft/fft_twiddle_rom.sv``: COS[k] and SIN[k] from two quarter waves."""
    cq, sq = twiddle_quarters()
    return (
        _HEADER.format(what="Twiddle ROM: COS(k) = rint(2^16 cos(2 pi k/4096)) and "
                       "SIN(k) = COS((k-1024) mod 4096)\n// from two quarter-wave tables")
        + "module fft_twiddle_rom (\n"
        "  // ROM index 0..4095 (quadrant k[11:10], offset k[9:0]).\n"
        "  input  logic [fft_rom_pkg::ROM_LOG2-1:0] k,\n"
        "  // Q1.16 cosine and sine, signed; combinational.\n"
        "  output logic [fft_rom_pkg::COEF_W-1:0]   cos_o,\n"
        "  output logic [fft_rom_pkg::COEF_W-1:0]   sin_o\n"
        ");\n"
        "  logic [9:0]  r;\n"
        "  logic [16:0] cq, sq;   // CQ[r] = COS[r], SQ[r] = COS[3072 + r]: 0..65536\n"
        "  assign r = k[9:0];\n\n"
        + _sv_case("cq", cq, 17) + "\n" + _sv_case("sq", sq, 17) + "\n"
        "  // quadrant symmetry: (C, S) = (CQ, SQ), (-SQ, CQ), (-CQ, -SQ), (SQ, -CQ)\n"
        "  always_comb begin\n"
        "    case (k[11:10])\n"
        "      2'd0: begin cos_o = {1'b0, cq};  sin_o = {1'b0, sq};  end\n"
        "      2'd1: begin cos_o = -{1'b0, sq}; sin_o = {1'b0, cq};  end\n"
        "      2'd2: begin cos_o = -{1'b0, cq}; sin_o = -{1'b0, sq}; end\n"
        "      default: begin cos_o = {1'b0, sq}; sin_o = -{1'b0, cq}; end\n"
        "    endcase\n"
        "  end\n"
        "endmodule\n\n`default_nettype wire\n"
    )


def render_hann_rom() -> str:
    """Text of ``rtl/fft/fft_hann_rom.sv``: HANN[k] from two quarter waves."""
    h0, h3 = hann_quarters()
    return (
        _HEADER.format(what="Window ROM: HANN(k) = rint(2^16 (0.5 - 0.5 cos(2 pi k/4096))), "
                       "periodic Hann,\n// from two quarter-wave tables")
        + "module fft_hann_rom (\n"
        "  // ROM index 0..4095 (quadrant k[11:10], offset k[9:0]).\n"
        "  input  logic [fft_rom_pkg::ROM_LOG2-1:0] k,\n"
        "  // Q1.16 window value 0..65536 (non-negative, 18-bit signed); combinational.\n"
        "  output logic [fft_rom_pkg::COEF_W-1:0]   hann_o\n"
        ");\n"
        "  logic [9:0]  r;\n"
        "  logic [15:0] h0, h3;   // HQ0[r] = HANN[r], HQ3[r] = HANN[3072 + r]: 0..32768\n"
        "  assign r = k[9:0];\n\n"
        + _sv_case("h0", h0, 16) + "\n" + _sv_case("h3", h3, 16) + "\n"
        "  // symmetry HANN(2048 - j) = 65536 - HANN(j), HANN(4096 - j) = HANN(j)\n"
        "  always_comb begin\n"
        "    case (k[11:10])\n"
        "      2'd0: hann_o = {2'b0, h0};\n"
        f"      2'd1: hann_o = {COEF_W}'d{1 << COEF_FRAC} - {{2'b0, h3}};\n"
        f"      2'd2: hann_o = {COEF_W}'d{1 << COEF_FRAC} - {{2'b0, h0}};\n"
        "      default: hann_o = {2'b0, h3};\n"
        "    endcase\n"
        "  end\n"
        "endmodule\n\n`default_nettype wire\n"
    )


def render_win_rom() -> str:
    """Text of ``rtl/fft/fft_win_rom.sv``: the N-point window for any N of the chain."""
    tables = []
    for n in WINDOW_LENGTHS:
        items = "".join(f"        {ROM_LOG2}'d{k}: w_o = {COEF_W}'h{int(v):05X};\n"
                        for k, v in enumerate(hann_window(n)))
        tables.append(f"  end else if (N == {n}) begin : g_{n}\n    always_comb begin\n"
                      f"      case (k)\n{items}        default: w_o = '0;\n      endcase\n"
                      "    end\n")
    return (
        _HEADER.format(what="Window ROM of any length N: HANN(k * 4096/N) of fft_hann_rom "
                       "for a power of two N,\n// else the N-point table "
                       "rint(2^16 (0.5 - 0.5 cos(2 pi k/N))) of WINDOW_LENGTHS")
        + "module fft_win_rom #(\n"
        "  // Window length (samples), 2..4096: a power of two or one of WINDOW_LENGTHS.\n"
        "  parameter int N = 64\n"
        ") (\n"
        "  // Sample index 0..N-1 (0 past N-1).\n"
        "  input  logic [fft_rom_pkg::ROM_LOG2-1:0] k,\n"
        "  // Q1.16 window value 0..65536 (non-negative, 18-bit signed); combinational.\n"
        "  output logic [fft_rom_pkg::COEF_W-1:0]   w_o\n"
        ");\n"
        "  if (N >= 2 && N <= fft_rom_pkg::ROM_SIZE && (N & (N - 1)) == 0) begin : g_pow2\n"
        "    fft_hann_rom u_rom (.k(k << (fft_rom_pkg::ROM_LOG2 - $clog2(N))), .hann_o(w_o));\n"
        + "".join(tables)
        + "  end else begin : g_bad_n\n"
        "    $fatal(1, \"%m: N=%0d: no window ROM of that length (add it to "
        "model.fft_rom.WINDOW_LENGTHS, make gen)\", N);\n"
        "  end\n"
        "endmodule\n\n`default_nettype wire\n"
    )


def generated_files() -> dict[Path, str]:
    """Every generated RTL file and the text it must have (checked quarter tables)."""
    check_quarters()
    check_window_sums()
    return {PKG_PATH: render_rom_pkg(), TWIDDLE_ROM_PATH: render_twiddle_rom(),
            HANN_ROM_PATH: render_hann_rom(), WIN_ROM_PATH: render_win_rom()}


def stale_files() -> list[Path]:
    """The generated files that are missing or differ from what :func:`generated_files`
    renders (empty when ``make gen`` has nothing to do)."""
    return [p for p, text in generated_files().items()
            if not p.exists() or p.read_text() != text]


def write_rom_files(out_dir: Path | None = None) -> list[Path]:
    """Write every generated file whose contents differ (into ``out_dir`` if given, else
    ``rtl/fft/``); return the paths written."""
    written = []
    for path, text in generated_files().items():
        dest = (out_dir / path.name) if out_dir else path
        if dest.exists() and dest.read_text() == text:
            continue
        dest.parent.mkdir(parents=True, exist_ok=True)
        dest.write_text(text)
        written.append(dest)
    return written


def main() -> None:
    parser = argparse.ArgumentParser(description="Regenerate the FFT ROM files of rtl/fft/ "
                                     "from model/fft_rom.py (the single source of FFT ROMs).")
    parser.add_argument("--out-dir", type=Path, default=None,
                        help="write into this folder instead of rtl/fft/")
    args = parser.parse_args()
    written = write_rom_files(args.out_dir)
    names = ", ".join(p.name for p in written) if written else "all up to date"
    print(f"model.fft_rom: {names}")


if __name__ == "__main__":
    main()
