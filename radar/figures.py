"""Figure glue of the application: the scene's truth markers and the ``radar detect --plots``
figures (the plotting itself is :mod:`host.plots`)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from host.pointcloud import PointCloud
from model.array import has_vertical_extent
from model.config import RadarConfig
from model.reference import range_doppler_power
from model.scene import Scene


def truth_xy(scene: Scene, prefix: str = "T") -> list[tuple[float, float, str]]:
    """(x m, y m, label) of each target (``T<i>``) and of each object's centre (``O<i>
    <class>``), for the point-cloud figure."""
    return [(t.x_m, t.y_m, f"{prefix}{i + 1}") for i, t in enumerate(scene.targets)] + [
        (o.x_m, o.y_m, f"O{i + 1} {o.label}") for i, o in enumerate(scene.objects)]


def truth_range_doppler(scene: Scene, prefix: str = "T") -> list[tuple[float, float, str]]:
    """(range m, radial velocity m/s, label) of each target, for range-Doppler maps."""
    return [(t.range_m, t.radial_velocity_mps, f"{prefix}{i + 1}")
            for i, t in enumerate(scene.targets)]


def missed_labels(scene: Scene, cloud: PointCloud, prefix: str = "T") -> list[str]:
    """Labels of the scene's targets no point of ``cloud`` matched (for the x-y figure)."""
    from host.evaluate import match_targets

    matches, _ = match_targets(cloud, scene.targets, scene.config)
    return [f"{prefix}{i + 1}" for i, m in enumerate(matches) if m.index < 0]


def detect_plots(folder: Path, cfg: RadarConfig, scene: Scene, cube: np.ndarray,
                 cloud: PointCloud, boxes: list[dict[str, Any]] | None = None) -> None:
    """Range-Doppler map of ``cube`` (complex (n_virtual, n_range, n_doppler)) and the x-y
    point cloud with ``boxes``, written to ``folder``."""
    from host.plots import plot_point_cloud, plot_range_doppler

    zoom = 1.5 * max([t.range_m for t in scene.targets] + [10.0])
    paths = [plot_range_doppler(range_doppler_power(cube), cfg, folder / "range_doppler.png",
                                f"{cfg.name}: range-Doppler (all channels)",
                                truth_range_doppler(scene), zoom),
             plot_point_cloud(cloud.x_m, cloud.y_m, cloud.snr_db, folder / "point_cloud.png",
                              f"{cfg.name}: point cloud ({len(cloud)} points)",
                              truth_xy(scene), boxes, missed_labels(scene, cloud))]
    print("figures: " + ", ".join(str(p) for p in paths))


def process_plots(folder: Path, cfg: RadarConfig, cube: np.ndarray, cloud: PointCloud,
                  frame: int) -> None:
    """``radar process --plots``: frame ``frame``'s range-Doppler map (cube complex
    (n_virtual, n_range, n_doppler)) with its detections circled, its range-azimuth map and
    its x-y point cloud (and its x-z side view when the array measures elevation), written
    to ``folder``."""
    from host.angle import range_azimuth_power
    from host.plots import (
        plot_point_cloud,
        plot_range_azimuth_pair,
        plot_range_doppler,
        plot_side_view,
    )

    title = f"{cfg.name} frame {frame}"
    ra, az = range_azimuth_power(cube, cfg)
    marks = [(float(r), float(v), "") for r, v in zip(cloud.range_m, cloud.radial_velocity_mps,
                                                      strict=True)]
    paths = [plot_range_doppler(range_doppler_power(cube), cfg, folder / "range_doppler.png",
                                f"{title}: range-Doppler, detections circled", marks),
             plot_range_azimuth_pair([(ra, f"{title}: range-azimuth")], az, cfg,
                                     folder / "range_azimuth.png"),
             plot_point_cloud(cloud.x_m, cloud.y_m, cloud.snr_db, folder / "point_cloud.png",
                              f"{title}: point cloud ({len(cloud)} points)")]
    if has_vertical_extent(cfg.virtual_positions_hw):
        paths.append(plot_side_view(cloud.x_m, cloud.z_m, cloud.snr_db,
                                    folder / "side_view.png",
                                    f"{title}: side view x-z ({len(cloud)} points)"))
    print("figures: " + ", ".join(str(p) for p in paths))
