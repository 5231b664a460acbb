"""``radar demo``: the paper's Table I scene end to end, a Table III style comparison and the
figures (paper Fig. 5 and 6, range-Doppler map, point cloud with GNN objects)."""

from __future__ import annotations

import argparse
import json
import multiprocessing
import time
from concurrent.futures import Future, ProcessPoolExecutor
from dataclasses import replace
from pathlib import Path
from typing import Any

from host.cfar import paper_threshold
from host.evaluate import alias_note, match_targets, table3
from host.params import default_max_speed_mps
from host.pipeline import DetectionParams
from model.reference import range_doppler_power
from model.scene import Scene, default_ego_speed_mps, table1_scene
from model.simulate import simulate_scene
from radar.common import (
    CliError,
    add_command,
    add_radar_option,
    check_source,
    on_radar,
    out_folder,
    radar_profile,
)
from radar.figures import truth_range_doppler, truth_xy
from radar.frame_cloud import frame_cloud
from radar.objects import gnn_objects, object_boxes
from radar.sources import SOURCES, FrameSource, get_source


def _import_gnn() -> None:
    """Worker warm-up: import the GNN (torch, torch_geometric: most of the demo's start-up)."""
    import gnn.infer  # noqa: F401


class GnnWorker:
    """:func:`radar.objects.gnn_objects` in a worker process (spawned, so nothing of this
    process is forked) that imports torch while this process simulates the scene, runs the
    chain and draws; :meth:`objects` then only waits for the inference. Same function, same
    checkpoint: the same objects as calling it here."""

    def __init__(self) -> None:
        self._pool = ProcessPoolExecutor(max_workers=1,
                                         mp_context=multiprocessing.get_context("spawn"))
        self._warm: Future[None] = self._pool.submit(_import_gnn)

    def objects(self, cloud: Any, ego_speed_mps: float) -> list[dict[str, Any]]:
        """Objects of ``cloud`` (a :class:`host.pointcloud.PointCloud`), as ``gnn_objects``."""
        return self._pool.submit(gnn_objects, cloud, ego_speed_mps).result()

    def close(self) -> None:
        self._pool.shutdown(wait=True, cancel_futures=True)


def cmd_demo(args: argparse.Namespace) -> int:
    scene = on_radar(table1_scene(args.preset or "full"), radar_profile(args))
    out_folder(args.out, "--out")               # before any work
    cfg = scene.config
    source = get_source(args.backend)
    check_source(source, cfg)
    params = DetectionParams(max_speed_mps=default_max_speed_mps(cfg))
    try:
        params.check(cfg)
    except ValueError as exc:
        raise CliError(f"--radar: {exc}") from None
    gnn = None if args.no_gnn else GnnWorker()
    try:
        return _demo(args, gnn, scene, source, params)
    finally:
        if gnn is not None:
            gnn.close()


def _demo(args: argparse.Namespace, gnn: GnnWorker | None, scene: Scene, source: FrameSource,
          params: DetectionParams) -> int:
    from host.angle import range_azimuth_power
    from host.plots import (
        plot_detection_mask,
        plot_point_cloud,
        plot_range_azimuth_pair,
        plot_range_doppler,
    )

    out = Path(args.out)
    cfg = scene.config
    t0 = time.perf_counter()
    adc = simulate_scene(scene)
    cube = source.cube(adc.samples, cfg)
    t_first = time.perf_counter()
    cloud = frame_cloud(cube, cfg, params, 0, "demo").cloud
    t_first = time.perf_counter() - t_first
    t_host = time.perf_counter()              # again: a frame's time once the process runs
    frame_cloud(cube, cfg, params, 0, "demo")
    t_host = time.perf_counter() - t_host
    matches, used = match_targets(cloud, scene.targets, cfg)
    print(f"Table I scene, {'preset' if scene.radar is None else 'radar'} {cfg.name} "
          f"({cfg.num_tx} TX x {cfg.num_rx} RX, "
          f"{cfg.n_range} x {cfg.n_doppler} FFTs), {args.backend} backend, CA-CFAR Pfa "
          f"{params.cfar.pfa:g}: {len(cloud)} points, {int((~used).sum())} unmatched, host "
          f"processing {t_host * 1e3:.0f} ms per frame (the process's first frame "
          f"{t_first * 1e3:.0f} ms: numba loads the compiled kernels once)")
    print("errors are |estimate - actual|; 'paper' = the paper's hardware error (Table III)")
    print(table3(matches, cloud, cfg))

    # figures: Fig. 6 (channel 0 + thresholded), Fig. 5 (with / without TX beamforming),
    # non-coherent range-Doppler map, point cloud
    zoom = 1.5 * max(t.range_m for t in scene.targets)
    mask, p0 = paper_threshold(cube, params.paper_threshold_db)
    figs = [plot_detection_mask(p0, mask, cfg, out / "fig6_range_doppler_ch0.png",
                                f"{cfg.name}: channel 0 and its threshold "
                                f"({params.paper_threshold_db:g} dB over the median)", zoom,
                                truth_range_doppler(scene, "V")),
            plot_range_doppler(range_doppler_power(cube), cfg, out / "range_doppler_nci.png",
                               f"{cfg.name}: range-Doppler, {cfg.n_virtual} channels "
                               f"non-coherent", truth_range_doppler(scene, "V"), zoom)]
    no_bf = replace(scene, tx_beamforming=False, name="table1-no-bf")
    cube_nobf = source.cube(simulate_scene(no_bf).samples, cfg)
    ra_bf, az = range_azimuth_power(cube, cfg)
    ra_nobf, _ = range_azimuth_power(cube_nobf, cfg)
    figs.append(plot_range_azimuth_pair(
        [(ra_bf, "TX subarray beamforming (3 elements)"), (ra_nobf, "single TX element")],
        az, cfg, out / "fig5_range_azimuth_bf_vs_nobf.png", zoom,
        note=alias_note(scene.targets, cfg),
        title=f"{cfg.name}: range-azimuth, {cfg.num_tx} TX x {cfg.num_rx} RX"))
    ego = default_ego_speed_mps(scene)  # the same default as radar detect / radar gnn detect
    objects = gnn.objects(cloud, ego) if gnn is not None else []
    if gnn is not None:
        print(f"GNN (synthetic-trained checkpoint; ego {ego * 3.6:.0f} km/h is beyond its "
              f"training range): " + (", ".join(
                  f"{o['class']} {o['score']:.2f} at ({o['x_m']:.1f}, {o['y_m']:.1f}) m"
                  for o in objects) or "no objects"))
    missed = [f"V{i + 1}" for i, m in enumerate(matches) if m.index < 0]
    figs.append(plot_point_cloud(cloud.x_m, cloud.y_m, cloud.snr_db, out / "point_cloud.png",
                                 f"{cfg.name}: Table I point cloud" + (
                                     " and GNN objects" if objects else ""),
                                 truth_xy(scene, "V"), object_boxes(objects), missed))
    doc = cloud.to_json_dict(cfg, 1, [0] if adc.saturated else [])
    doc.update({"ego_speed_mps": ego, "objects": objects,
                "frame_info": [{"frame": 0, "points": len(cloud), "clipped": adc.saturated,
                                "damaged": False}]})
    points = out / "table1_points.json"
    points.write_text(json.dumps(doc, indent=1))
    print(f"figures in {out}/: " + ", ".join(p.name for p in figs)
          + f"; the point cloud JSON: {points} ({time.perf_counter() - t0:.1f} s)")
    return 0


def add_parsers(sub: argparse._SubParsersAction, presets: list[str]) -> None:
    m = add_command(sub, "demo", "the paper's Table I scene end to end, with figures", """
        Simulate the paper's Table I scene, run the FPGA chain (bit-accurate model) and host
        processing, print a Table III style comparison (with the paper's hardware errors beside
        ours) and write the figures: channel-0 range-Doppler map and its threshold (paper Fig. 6),
        range-azimuth with and without TX beamforming (Fig. 5), the non-coherent range-Doppler map
        and the x-y point cloud.""")
    m.add_argument("--out", default="out", help="folder for figures and JSON (default out/)")
    m.add_argument("--preset", choices=presets, default=None,
                   help="radar preset (default full)")
    add_radar_option(m, "a preset")
    m.add_argument("--backend", choices=[n for n, s in SOURCES.items() if s.per_frame],
                   default="model",
                   help="model: bit-accurate FPGA chain (default, ~20 s on full); float: "
                        "its float64 reference (~3 s)")
    m.add_argument("--no-gnn", action="store_true",
                   help="skip the GNN object classification (saves loading torch)")
    m.set_defaults(func=cmd_demo)
