"""One labelled radar frame: the point cloud and its ground truth, shared by all datasets."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gnn.boxes import check_boxes
from host.pointcloud import PointCloud

IGNORE = -1
"""``point_class`` value of points to leave out of training and evaluation (RadarScenes
"animal" and "other")."""


@dataclass(frozen=True)
class Frame:
    """A point cloud with per-point labels and the true boxes.

    ``cloud``: n points; ``ego_speed_mps``: ego speed along +x over ground (m/s; 0 when the
    cloud's radial velocities are already ego-motion compensated); ``point_class``: int (n,)
    class index (:data:`gnn.classes.CLASSES`, :data:`IGNORE` for unlabelled);
    ``point_object``: int (n,) index into ``boxes`` or -1; ``boxes``: float (m, 5)
    ``[x, y, length, width, heading_rad]``; ``box_class``: int (m,).
    """

    cloud: PointCloud
    ego_speed_mps: float
    point_class: np.ndarray
    point_object: np.ndarray
    boxes: np.ndarray
    box_class: np.ndarray

    def __post_init__(self) -> None:
        n = len(self.cloud)
        for name in ("point_class", "point_object"):
            if np.shape(getattr(self, name)) != (n,):
                raise ValueError(f"Frame.{name}: expected shape ({n},), got "
                                 f"{np.shape(getattr(self, name))}")
        check_boxes(self.boxes, "Frame.boxes")
        if np.shape(self.box_class) != (len(self.boxes),):
            raise ValueError(f"Frame.box_class: expected shape ({len(self.boxes)},), got "
                             f"{np.shape(self.box_class)}")
        if n and self.point_object.max(initial=-1) >= len(self.boxes):
            raise ValueError("Frame.point_object: refers to a box that does not exist")
