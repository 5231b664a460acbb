"""Benchmark of ``fft_axis``: continuous-streaming period and latency per N and lane count,
against the paper's Xilinx radix-4 burst figures.

Runs the cocotb test ``test_throughput_latency`` of ``test_fft_axis.py`` (no stalls, four
back-to-back frames) on Verilator for each configuration through
``rtlsim.toolchain.run_cocotb`` (builds are shared with the regression under ``sim_build/``)
and prints a table.

    tools/venv-run python tb/fft_axis/bench_fft_axis.py [--quick]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path[:0] = [str(HERE.parents[1]), str(HERE)]

from test_fft_axis import run  # noqa: E402

from rtlsim.toolchain import ensure_verilator_env  # noqa: E402

# Xilinx FFT IP, radix-4 burst I/O, cycles per transform as quoted in the paper.
PAPER_CYCLES = {64: 231, 256: 837}

CONFIGS = [
    dict(N=16, NUM_CH=1),
    dict(N=64, NUM_CH=1),
    dict(N=64, NUM_CH=4),
    dict(N=128, NUM_CH=4, INVERSE=1),
    dict(N=256, NUM_CH=1),
    dict(N=256, NUM_CH=4),
    dict(N=1024, NUM_CH=1, WINDOW=1),
    dict(N=4096, NUM_CH=1),
]
QUICK = [dict(N=64, NUM_CH=4), dict(N=256, NUM_CH=1)]


def measure(params: dict) -> dict:
    """Run the throughput/latency cocotb test for one parameter set; return its numbers."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "bench.json"
        run(params, testcase="test_throughput_latency", extra_env={"FFT_BENCH_JSON": str(out)})
        return json.loads(out.read_text())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true",
                        help="only N=64 x 4 lanes and N=256 x 1 lane (builds may be cached)")
    parser.add_argument("--json", type=Path, help="also write the rows to this JSON file")
    args = parser.parse_args()
    ensure_verilator_env()
    os.environ.setdefault("COCOTB_LOG_LEVEL", "WARNING")
    os.environ.setdefault("PYTHONWARNINGS", "ignore")
    rows = []
    for params in QUICK if args.quick else CONFIGS:
        print(f"measuring {params} ...", file=sys.stderr, flush=True)
        res = measure(params)
        res["params"] = params
        rows.append(res)
    head = (f"{'N':>5} {'lanes':>5} {'win':>3} {'inv':>3} {'period':>7} {'paper':>6} "
            f"{'speedup':>7} {'lat first':>9} {'lat last':>8} {'cmult/lane':>10} "
            f"{'log4(N)-1':>9}")
    print(head)
    print("-" * len(head))
    for r in rows:
        n = r["N"]
        paper = PAPER_CYCLES.get(n)
        speed = f"{paper / r['period']:.2f}x" if paper else "-"
        goal = math.ceil(math.log(n, 4) - 1)
        print(f"{n:>5} {r['NUM_CH']:>5} {r['WINDOW']:>3} {r['INVERSE']:>3} {r['period']:>7} "
              f"{paper or '-':>6} {speed:>7} {r['latency_first']:>9} {r['latency_last']:>8} "
              f"{r['multipliers_per_lane']:>10} {goal:>9}")
    print("period: cycles between successive frames' first outputs (continuous streaming);"
          " lat first/last: first input -> first output, last input -> last output (cycles);"
          " paper: Xilinx radix-4 burst cycles per transform.")
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
