"""One frame -> its point cloud, whatever carried it: a radar cube (the host runs the CFAR,
``host.pipeline.process_cube_nci``) or the on-chip detector's records
(``host.record_points.process_records``). Every command that makes clouds (``radar detect``,
``radar receive``, ``radar view``) goes through :func:`frame_cloud`."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from host.pipeline import DetectionParams, process_cube_nci, real_only
from host.pointcloud import PointCloud
from host.receiver import LinkFrame
from host.record_points import process_records
from host.records import DetectionFrame, RecordArrays, inside_map, outside_problem
from model.config import RadarConfig
from radar.common import note_compile, warn

REAL_ONLY = ("the cube is Hermitian (real-only samples in a complex profile?): every "
             "target has a mirror ghost at range bin N - k, opposite Doppler")
_real_only_noted = False


def note_real_only(command: str, frame_id: int) -> None:
    """Once per process: the one-line warning that a cube looks real-only."""
    global _real_only_noted
    if not _real_only_noted:
        _real_only_noted = True
        warn([f"frame {frame_id}: {REAL_ONLY}"], command)


class CubeFrame(Protocol):
    """A cube frame decoded on demand (``host.receiver.PayloadFrame``)."""

    def cube(self) -> np.ndarray: ...


@dataclass(frozen=True)
class FrameCloud:
    """A frame's point cloud and what it came from.

    ``cube``: complex (n_virtual, n_range_bins, n_doppler) and ``nci``: float
    (n_range_bins, n_doppler) its integrated power, both float-reference units (None for records);
    ``records``: the records inside the map, float-reference units (None for a cube);
    ``problems``: what was dropped (records outside the map: corrupt words that still looked
    like records)."""

    cloud: PointCloud
    cube: np.ndarray | None = None
    nci: np.ndarray | None = None
    records: RecordArrays | None = None
    problems: list[str] = field(default_factory=list)


def frame_cloud(frame: np.ndarray | CubeFrame | DetectionFrame, cfg: RadarConfig,
                params: DetectionParams, frame_id: int, command: str) -> FrameCloud:
    """The point cloud of one frame of ``cfg``: a cube complex (n_virtual, n_range,
    n_doppler) in float-reference units, a cube frame (decoded here), or a record frame
    (its intact leading records inside the map). ``command``: the ``radar`` command, named
    in the one-time note when the host kernels compile."""
    if isinstance(frame, DetectionFrame):
        arr, dropped = inside_map(frame.arrays(), cfg)
        note_compile(command)           # the kernels may compile now (once per checkout)
        cloud = process_records(arr, cfg, params, frame=frame_id)
        return FrameCloud(cloud, records=arr, problems=[
            outside_problem(frame_id, dropped, cfg)] if dropped else [])
    cube = frame if isinstance(frame, np.ndarray) else frame.cube()
    cloud, nci = process_cube_nci(cube, cfg, params, frame_id)
    problems = []
    if cfg.adc == "complex" and real_only(cube):
        problems.append(f"frame {frame_id}: {REAL_ONLY}")
        note_real_only(command, frame_id)
    return FrameCloud(cloud, cube=cube, nci=nci, problems=problems)


def dma_frame_info(frame: LinkFrame, frame_id: int, command: str, max_detections: int = 0
                   ) -> dict[str, object]:
    """What a frame decoded from the chain's DMA bytes adds to its ``frame_info`` entry in
    the point cloud JSON: for a record frame (``--detect fpga``) the records sent, the cells
    past the CFAR, the truncated and complete flags; for a cube frame nothing. One-line
    warnings (``radar <command>``) when it arrived damaged or was truncated at
    ``max_detections``."""
    records = isinstance(frame, DetectionFrame)
    if records and frame.truncated:
        warn([f"frame {frame_id}: {frame.detections} cells passed the CFAR, only "
              f"--max-detections {max_detections} were sent"], command)
    if not frame.complete:
        warn([f"frame {frame_id} damaged: {'; '.join(frame.problems[:3])}"], command)
    if not records:
        return {}
    return {"records": len(frame.records), "detections": frame.detections,
            "truncated": frame.truncated, "complete": frame.complete}
