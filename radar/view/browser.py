"""Helpers to drive ``radar view`` in a real browser (the browser test and the benchmark).

The browser is Debian's chromium (``make setup`` installs it with apt) driven by Playwright;
Playwright's own browser downloads are never used. Each launch gets a fresh profile folder.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

CHROMIUM = Path("/usr/bin/chromium")
"""Debian's chromium (apt-get install -y chromium)."""

CHROMIUM_ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic",
                 "--no-first-run", "--disable-background-networking",
                 "--disable-component-update", "--disable-sync"]

_BANNER = re.compile(r"radar view: (http://\S+/) showing (.*) \(Ctrl-C stops\)")


def chromium_missing_reason() -> str | None:
    """Why the browser cannot run here, or None when it can."""
    if not CHROMIUM.exists():
        return f"{CHROMIUM} missing: run `make setup` (apt-get install -y chromium)"
    try:
        import playwright.sync_api  # noqa: F401
    except ImportError:
        return "playwright missing: run `make setup` (dev extras)"
    return None


def launch(pw: Any, profile_dir: Path, width: int = 1500, height: int = 820) -> Any:
    """A persistent Playwright browser context on a fresh profile ``profile_dir``."""
    return pw.chromium.launch_persistent_context(
        user_data_dir=str(profile_dir), executable_path=str(CHROMIUM), headless=True,
        args=CHROMIUM_ARGS, viewport={"width": width, "height": height})


@dataclass
class ViewProcess:
    """A ``radar view`` subprocess and where it serves."""

    proc: subprocess.Popen[str]
    url: str
    source: str

    @property
    def udp_port(self) -> int:
        m = re.search(r"UDP [\d.]+:(\d+)", self.source)
        if not m:
            raise ValueError(f"not a UDP source: {self.source}")
        return int(m.group(1))

    def rss_kib(self) -> int:
        """Resident memory of the process, KiB (Linux /proc)."""
        for line in Path(f"/proc/{self.proc.pid}/status").read_text().splitlines():
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
        return 0

    def cpu_s(self) -> float:
        """User + system CPU time of the process so far, s (Linux /proc)."""
        fields = Path(f"/proc/{self.proc.pid}/stat").read_text().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")

    def stop(self) -> None:
        self.proc.terminate()
        try:
            self.proc.wait(10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait(5)


def start_view(args: list[str], timeout_s: float = 60.0) -> ViewProcess:
    """Start ``radar view ARGS --port 0`` and wait for its banner line."""
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}
    err = tempfile.TemporaryFile("w+")  # noqa: SIM115 - read only when the start fails
    proc = subprocess.Popen([sys.executable, "-m", "radar.cli", "view", *args, "--port", "0"],
                            stdout=subprocess.PIPE, stderr=err, text=True, env=env)
    deadline = time.monotonic() + timeout_s
    assert proc.stdout is not None
    while time.monotonic() < deadline:
        line = proc.stdout.readline()
        if not line:
            break
        m = _BANNER.search(line)
        if m:
            return ViewProcess(proc, m.group(1), m.group(2))
    proc.kill()
    proc.wait(10)
    err.seek(0)
    raise RuntimeError(f"radar view did not start: {err.read().strip()[-2000:]}")
