"""cocotb testbench of ``rtl/buffers/mark_fifo.sv`` against ``model/mark_fifo.py``.

Random push/pop with phases that fill the queue (pushes without pops: full, refused pushes,
sticky overflow) and drain it (pops without pushes: empty, refused pops, sticky underflow),
random gaps, simultaneous push and pop at every fill level, and resets in mid-stream. Every
output is compared with the model on every clock.
"""

from __future__ import annotations

import os
from pathlib import Path

import cocotb
import numpy as np
import pytest
from cocotb.clock import Clock
from cocotb.triggers import ReadOnly, RisingEdge

from model.mark_fifo import MarkFifo
from rtlsim.toolchain import param, rtl_sources, run_cocotb


async def _compare(dut, model: MarkFifo, cycle: int) -> None:
    got = (int(dut.head.value), int(dut.empty.value), int(dut.full.value),
           int(dut.count.value), int(dut.overflow.value), int(dut.underflow.value))
    want = (model.head, int(model.empty), int(model.full), model.count,
            int(model.overflow), int(model.underflow))
    assert got == want, f"cycle {cycle}: (head, empty, full, count, ovf, unf) {got} != {want}"


@cocotb.test()
async def random_traffic(dut) -> None:
    depth, width = param("DEPTH"), param("WIDTH")
    rng = np.random.default_rng(int(os.environ.get("SEED", "1")))
    model = MarkFifo(depth, width)
    cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start())
    dut.push.value = 0
    dut.pop.value = 0
    dut.push_data.value = 0
    dut.rst.value = 1
    for _ in range(3):
        await RisingEdge(dut.clk)
    dut.rst.value = 0
    model.reset()
    # phases: (push probability, pop probability, cycles)
    phases = [(0.9, 0.1, 40), (0.1, 0.9, 40), (0.5, 0.5, 200), (1.0, 0.0, 3 * depth),
              (1.0, 1.0, 50), (0.0, 1.0, 3 * depth), (0.3, 0.7, 100), (0.7, 0.3, 100)]
    seen = {"full": False, "empty": False, "ovf": False, "unf": False, "both": set()}
    cycle = 0
    for rep in range(2):
        for p_push, p_pop, n in phases:
            for _ in range(n):
                push = bool(rng.random() < p_push)
                pop = bool(rng.random() < p_pop)
                data = int(rng.integers(0, 1 << width))
                rst = rep == 1 and cycle % 257 == 100  # resets in mid-stream
                dut.push.value = int(push)
                dut.pop.value = int(pop)
                dut.push_data.value = data
                dut.rst.value = int(rst)
                await ReadOnly()
                await _compare(dut, model, cycle)  # outputs before this edge
                seen["full"] |= model.full
                seen["empty"] |= model.empty
                if push and pop and not rst:
                    seen["both"].add(model.count)
                await RisingEdge(dut.clk)
                model.step(push, data, pop, rst)
                seen["ovf"] |= model.overflow
                seen["unf"] |= model.underflow
                cycle += 1
    assert seen["full"] and seen["empty"] and seen["ovf"] and seen["unf"], seen
    assert set(range(depth + 1)) <= seen["both"], f"push+pop levels {sorted(seen['both'])}"


PARAMS = [dict(DEPTH=4, WIDTH=1), dict(DEPTH=2, WIDTH=3), dict(DEPTH=5, WIDTH=8)]


@pytest.mark.parametrize("parameters", PARAMS, ids=lambda p: "_".join(
    f"{k}{v}" for k, v in p.items()))
def test_mark_fifo(parameters: dict) -> None:
    here = Path(__file__).resolve().parent
    run_cocotb("mark_fifo", rtl_sources("buffers/mark_fifo.sv"), "test_mark_fifo", here,
               parameters=parameters)
