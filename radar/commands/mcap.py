"""``radar mcap info FILE``: what an MCAP recording of ``--mcap`` holds (topics, message
counts, frames, time span), also when it was cut short (``host.ros.summary``)."""

from __future__ import annotations

import argparse
import sys
from datetime import UTC, datetime
from pathlib import Path

from host.ros.summary import summarize
from radar.common import CliError, add_command


def _time(t_ns: int) -> str:
    """ISO time (UTC, ms) of a stamp in ns since the Unix epoch."""
    return datetime.fromtimestamp(t_ns / 1e9, UTC).isoformat(timespec="milliseconds")


def cmd_mcap_info(args: argparse.Namespace) -> int:
    path = Path(args.file)
    if not path.is_file():
        raise CliError(f"{path}: no such file")
    try:
        s = summarize(path)
    except ValueError as exc:
        raise CliError(str(exc)) from None
    span = (s.end_ns - s.start_ns) / 1e9
    print(f"{path}: {s.size_bytes / 1e6:.2f} MB, {s.frames} frame(s), "
          f"{_time(s.start_ns)} .. {_time(s.end_ns)} ({span:.3f} s)")
    width = max((len(t.topic) for t in s.topics), default=0)
    for t in s.topics:
        print(f"  {t.topic:<{width}}  {t.messages:>8} msgs  {t.schema}")
    if s.cut_short:
        print(f"radar mcap info: warning: {path} is cut short ({s.cut_short}; it was not "
              f"closed: the disk filled or the program was killed): the counts are what it "
              f"holds before the cut", file=sys.stderr)
    return 0


def add_parsers(sub: argparse._SubParsersAction, presets: list[str]) -> None:
    m = add_command(sub, "mcap", "MCAP recordings of --mcap (radar mcap info FILE)", """
        Tools for the MCAP recordings that `radar detect --mcap` and `radar receive --mcap`
        write (ROS 2 messages; docs/ros.md).""")
    msub = m.add_subparsers(dest="mcap_command", required=True, metavar="MCAP_COMMAND")
    i = add_command(msub, "info", "summarise a recording", """
        Print a recording's topics with their message counts and types, its frames and
        its time span; a recording cut short (no footer) is read up to the cut and said so
        in one line.""")
    i.add_argument("file", help="the .mcap recording")
    i.set_defaults(func=cmd_mcap_info)
