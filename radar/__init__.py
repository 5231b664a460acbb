"""The application: the ``radar`` command line, frame sources, demo and live view."""
