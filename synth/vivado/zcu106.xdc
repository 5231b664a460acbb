# SPDX-License-Identifier: Apache-2.0
# Timing constraints of every block and of radar_pipeline on the ZCU106 (xczu7ev-ffvc1156-2-e),
# read for out-of-context synthesis and implementation (synth/vivado/run.tcl): 100 MHz on `clk`.
# Out of context there are no pins: the I/O delays below leave half a cycle to the logic
# outside the block, so port-to-register paths are timed instead of unconstrained.

create_clock -period 10.000 -name clk [get_ports clk]
# OOC place and route: the clock arrives from a global buffer, as it would in a full design.
set_property HD.CLK_SRC BUFGCTRL_X0Y0 [get_ports clk]

# (XDC accepts only a subset of Tcl: no `if`; every block has inputs besides clk and outputs)
set_input_delay  -clock clk 5.000 [get_ports -filter {DIRECTION == IN && NAME != clk}]
set_output_delay -clock clk 5.000 [get_ports -filter {DIRECTION == OUT}]
