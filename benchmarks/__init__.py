"""Benchmark scripts (print tables; reported, never asserted). Not part of the installed
library: they import it (and the tests' scenes, ``tests.scenes``), nothing imports them but
the tests. Run from the repository root, ``python -m benchmarks.<name>``; see README.md."""
