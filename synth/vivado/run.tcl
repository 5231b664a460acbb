# SPDX-License-Identifier: Apache-2.0
# Non-project Vivado flow for one block of the radar array processor (or the whole
# radar_pipeline top): out-of-context synthesis for the ZCU106 part at 100 MHz, optional place
# and route, utilization and timing reports written to files.
#
#   vivado -mode batch -nojournal -source synth/vivado/run.tcl \
#          -tclargs <top> <out_dir> <impl 0|1> [NAME=VALUE ...]
#
# NAME=VALUE pairs are HDL parameters (synth_design -generic). `make synth-vivado` runs every
# job of a set (blocks and the radar_pipeline top, paper-fpga with FRAME_STORE = 0 and full
# with FRAME_STORE = 1) through a generated per-job script, OUT/<job>/job.tcl
# (synth/vivado_flow.py job_tcl), that sets top, out_dir, impl, generics, pkgs and mods and
# then sources this file; docs/synth.md has the details.

set part xczu7ev-ffvc1156-2-e
set here [file dirname [file normalize [info script]]]
set root [file normalize [file join $here .. ..]]
if {![info exists top]} {
  if {[llength $argv] < 3} {
    puts stderr "usage: vivado -mode batch -source run.tcl -tclargs <top> <out_dir> <impl 0|1> \[NAME=VALUE ...\]"
    exit 2
  }
  lassign $argv top out_dir impl
  set generics [lrange $argv 3 end]
}
if {![info exists pkgs]} {
  # every rtl/*/*.sv, packages first (Vivado keeps only what `top` uses)
  set all [lsort [glob -nocomplain [file join $root rtl * *.sv]]]
  set pkgs [lsearch -all -inline -glob $all *_pkg.sv]
  set mods [lsearch -all -inline -not -glob $all *_pkg.sv]
}
file mkdir $out_dir

# ---- sources: packages first, then the modules
create_project -in_memory -part $part
read_verilog -sv $pkgs
read_verilog -sv $mods
read_xdc -mode out_of_context [file join $here zcu106.xdc]

# ---- synthesis (out of context: no I/O buffers, the ports stay ports)
set gen_args {}
foreach g $generics { lappend gen_args -generic $g }
synth_design -top $top -part $part -mode out_of_context -flatten_hierarchy rebuilt \
  -verilog_define SYNTHESIS {*}$gen_args
write_checkpoint -force [file join $out_dir post_synth.dcp]
report_utilization -file [file join $out_dir utilization_synth.rpt]
report_utilization -hierarchical -file [file join $out_dir utilization_synth_hier.rpt]
report_timing_summary -max_paths 10 -file [file join $out_dir timing_synth.rpt]

# ---- optional place and route
if {$impl} {
  opt_design
  place_design
  phys_opt_design
  route_design
  write_checkpoint -force [file join $out_dir post_route.dcp]
  report_utilization -file [file join $out_dir utilization_impl.rpt]
  report_utilization -hierarchical -file [file join $out_dir utilization_impl_hier.rpt]
  report_timing_summary -max_paths 10 -file [file join $out_dir timing_impl.rpt]
}

# one line for the driver: worst setup slack of the last step (ns)
set wns [get_property SLACK [get_timing_paths -max_paths 1 -nworst 1 -setup]]
set fh [open [file join $out_dir wns.txt] w]
puts $fh $wns
close $fh
puts "run.tcl: $top done, WNS $wns ns, reports in $out_dir"
