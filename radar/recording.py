"""``--mcap OUT.mcap`` of ``radar detect`` and ``radar receive``: the options, the recording
opened (and its path checked) before the work starts, and a failing write reported as one
line (``host.ros.recording``; topics and fields in docs/ros.md)."""

from __future__ import annotations

import argparse
import sys

from host.ros.messages import Mount
from host.ros.recording import Recorder, RecordingError
from radar.common import CliError, out_file


def add_mcap_options(p: argparse.ArgumentParser) -> None:
    """``--mcap`` and ``--mount``."""
    p.add_argument("--mcap", default=None, metavar="OUT.mcap",
                   help="also record what the command computes as ROS 2 messages in an MCAP "
                        "file (point cloud, status, GNN objects, radar mount; docs/ros.md), "
                        "for Foxglove and ros2 bag tools")
    p.add_argument("--mount", type=float, nargs=4, default=(0.0, 0.0, 0.0, 0.0),
                   metavar=("X", "Y", "Z", "YAW"),
                   help="--mcap: the radar's pose on the robot (base_link -> radar on "
                        "/tf_static): x, y, z in m, yaw in deg (default 0 0 0 0)")


def open_recording(args: argparse.Namespace, frame_period_s: float | None,
                   start_ns: int = 0) -> Recorder | None:
    """The recorder of ``--mcap`` (None without it), opened now, before the work starts: a
    path that cannot be written is a CliError. Close it with :func:`close_recording` in a
    ``finally`` block."""
    if not args.mcap:
        return None
    x, y, z, yaw = args.mount
    try:
        return Recorder(out_file(args.mcap, ".mcap", "--mcap"), frame_period_s, start_ns,
                        Mount(x, y, z, yaw))
    except OSError as exc:
        raise CliError(f"--mcap: cannot write {args.mcap}: {exc.strerror or exc}") from None


def close_recording(rec: Recorder | None) -> None:
    """Close ``rec`` (in the ``finally`` block of the work): the recording so far becomes a
    complete file, also when an error or Ctrl-C is stopping the work (that error goes on).
    A failed write (full disk), now or during the work, becomes a one-line CliError."""
    if rec is None:
        return
    stopping = sys.exc_info()[1]
    try:
        rec.__exit__(*sys.exc_info())
    except RecordingError as exc:
        stopping = exc
    if isinstance(stopping, RecordingError):
        raise CliError(f"--mcap: {stopping} (`radar mcap info` reads what it holds)"
                       ) from None
