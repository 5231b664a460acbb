"""Shared pytest fixtures of the Python tests."""

from __future__ import annotations

import signal
from collections.abc import Iterator

import pytest


@pytest.fixture
def sigint_raises() -> Iterator[None]:
    """SIGINT raises KeyboardInterrupt during the test (Python's default handler), whatever
    disposition the test run inherited: a run started in the background of a
    non-interactive shell has SIGINT ignored, and a Ctrl-C test would then wait forever."""
    old = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, old)
