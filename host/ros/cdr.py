"""ROS 2 messages (the dicts of :mod:`host.ros.messages`) -> CDR bytes, the encoding of both
the MCAP recordings and the live Foxglove channel: the encoder ``mcap-ros2-support`` builds
from a ``ros2msg`` schema (its writer's own, ``mcap_ros2._dynamic``; the version is pinned)."""

from __future__ import annotations

from collections.abc import Callable
from functools import cache
from typing import Any

from mcap_ros2._dynamic import serialize_dynamic

from host.ros.msgdefs import schema_text


@cache
def encoder(typename: str) -> Callable[[dict[str, Any]], bytes]:
    """The CDR encoder of ``typename`` (``pkg/msg/Type`` of ``host.ros.msgdefs``): message
    dict -> bytes (4-byte encapsulation header, little-endian)."""
    return serialize_dynamic(typename, schema_text(typename))[typename]
