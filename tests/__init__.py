"""The Python tests: a package, so tests share support modules (``tests.scenes``)."""
