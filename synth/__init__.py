"""Synthesis flows: the open Yosys resource estimate and the Vivado scripts (docs/synth.md)."""
