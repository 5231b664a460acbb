"""GNN glue of the application: objects of a point cloud from the shipped checkpoint, and
their boxes for the point-cloud figure."""

from __future__ import annotations

from typing import Any

from host.pointcloud import PointCloud


def gnn_objects(cloud: PointCloud, ego_speed_mps: float) -> list[dict[str, Any]]:
    """Classified boxes from the shipped GNN checkpoint (imports torch: only when asked)."""
    from gnn.infer import detect_objects

    return detect_objects(cloud, ego_speed_mps=ego_speed_mps)


def object_boxes(objects: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """GNN objects -> boxes for :func:`host.plots.plot_point_cloud`."""
    return [{"x": o["x_m"], "y": o["y_m"], "length": o["length_m"], "width": o["width_m"],
             "heading_deg": o["heading_deg"], "label": f"{o['class']} {o['score']:.2f}"}
            for o in objects]


def describe(objects: list[dict[str, Any]], limit: int = 8) -> str:
    """``class (score) at x .. y ..`` for the first ``limit`` objects."""
    return ", ".join(f"{o['class']} ({o['score']:.2f}) at x {o['x_m']:.1f} y {o['y_m']:.1f}"
                     for o in objects[:limit])
