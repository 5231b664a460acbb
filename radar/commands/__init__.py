"""One module per ``radar`` command group; each has ``add_parsers(sub, presets)``."""
