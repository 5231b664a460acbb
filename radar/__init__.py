"""The application: the ``radar`` command line (:mod:`radar.cli`, one module per command
group under :mod:`radar.commands`), the frame sources (:mod:`radar.sources`: model, float,
rtl), the demo and the figure glue. Imports ``model``, ``rtlsim``, ``host``, ``gnn`` and
``synth``; nothing imports ``radar`` (docs/design.md section 1)."""
