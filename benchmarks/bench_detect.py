"""Benchmark of the on-chip detection path (``OUTPUT_MODE = 1``, issue 14): the FPGA's CFAR
and records (bit-accurate model) against the host CFAR on the cube, and what the records
cost on the link and on the host. Prints four tables:

1. detection: true targets found through ``--detect fpga`` and ``--detect host`` on the
   Table I scene (``full``) and on random point-target scenes (both presets), and their
   agreement (targets the host path finds that the FPGA path finds too; goal >= 99 %);
   then Table I over ``--table1-seeds`` noise seeds: per vehicle, how often each path finds
   it and its mean |range|, |azimuth|, |velocity| errors (goal: fpga no worse than host);
2. false alarms on noise-only frames (thermal noise through the fixed-point chain) against
   the configured Pfa: CFAR detections per reportable cell (records) and points per cell
   for both paths (goal: within 2x);
3. link: bytes per frame and Mbit/s at 111 frames/s of the record stream for ``full`` with
   10, 100, 1000 detections (measured on encoded, packetized frames) vs the radar cube
   (goal: fits the paper's measured 766 Mbit/s);
4. host time per frame for 10, 100, 1000 detections on one core, CPU and wall, the replaced
   code ("old": ``Record`` objects, the numpy records path kept as the oracle
   ``tests.oracles.points.process_records_reference``) beside the current one (arrays,
   ``process_records``) in the same run: DMA bytes ->
   records (decoder), records -> point cloud, and both (goal <= 5 ms for 1000), on strong
   isolated targets and on a mixed frame (``synthetic_records(varied=True)``). One core:
   the process is pinned to one CPU and the BLAS / OpenMP pools get one thread (set before
   numpy loads). Table 1 also gives the azimuth errors of both, and in how many scenes old
   and new clouds agree. Then where the 1000-detection frames spend their time, per step of
   ``process_records``, and the spread of records -> point cloud over ``--spread-runs``
   runs (best, median, 90th percentile; velocity unfolding on and off).

    python -m benchmarks.bench_detect [--scenes 100] [--full-scenes 20] [--noise-frames 40]
                                      [--repeat 5] [--spread-runs 100] [--host-only]

Uses the bit-accurate model of the chain (mode 0 cube, mode 1 records). Reported, never
asserted in tests.
"""

from __future__ import annotations

import os

if __name__ == "__main__":     # one core: one-thread BLAS / OpenMP pools, before numpy loads
    for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import math  # noqa: E402
import time  # noqa: E402
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import fields
from typing import Any

import numpy as np

from host import angle, points, record_points
from host.cfar import CfarParams
from host.evaluate import match_targets
from host.pipeline import DetectionParams, process_cube
from host.pointcloud import PointCloud
from host.record_points import process_records
from host.records import RecordArrays, RecordDecoder, fpga_detect_config, record_arrays
from model.axis_packetizer import packetize, packetize_stream, words_to_bytes
from model.config import RadarConfig, get_preset
from model.detect_chain import DetectConfig
from model.detect_records import encode_frame
from model.radar_pipeline import PipelineParams, chain_gain, run_chain
from model.scene import Scene, table1_scene
from model.simulate import simulate_scene, thermal_noise
from tests.oracles.points import process_cube_reference, process_records_reference
from tests.oracles.records import RecordDecoderReference, record_arrays_reference
from tests.scenes import random_scene, synthetic_records

FRAME_RATE_HZ = 111.0
"""The radar's frame rate (the paper's 111 frames/s)."""
LINK_MBPS = 766.0
"""The paper's measured Gigabit Ethernet throughput, Mbit/s."""
UDP_PACKET_WORDS = {"full": 1021, "paper-fpga": 4092}
"""PACKET_WORDS that fill one UDP datagram (``host.udp.max_packet_words``)."""


def _both_paths(adc: np.ndarray, cfg: RadarConfig, params: DetectionParams,
                dcfg: DetectConfig, reference: bool = False
                ) -> tuple[PointCloud, PointCloud, int] | tuple[PointCloud, PointCloud, int,
                                                                PointCloud, PointCloud]:
    """Point clouds of one ADC frame through the host CFAR (cube) and the on-chip detector
    (records, as bytes through the decoder), and the FPGA's detection count; with
    ``reference`` also both clouds through the replaced host code (``*_reference``)."""
    chain = PipelineParams(output_mode=1, detect=dcfg)
    out = run_chain(adc, cfg, chain)                   # mode 1: the cube and the records
    gain = chain_gain(cfg, chain)
    host = process_cube(out.cube().astype(np.complex64) / gain, cfg, params)
    dec = RecordDecoder(dcfg, chain.packet_words)
    frames = [f for p in packetize_stream([out.records], chain.packet_words)
              for f in dec.push_packet(words_to_bytes(p))] + dec.flush()
    f = frames[0]
    arr = record_arrays(f.records, cfg.n_virtual, gain)
    fpga = process_records(arr, cfg, params)
    if not reference:
        return host, fpga, f.detections
    host_ref = process_cube_reference(out.cube().astype(np.complex64) / gain, cfg, params)
    return host, fpga, f.detections, host_ref, process_records_reference(arr, cfg, params)


def detection_rows(scenes: list[Scene]) -> dict[str, float]:
    """Targets found by each path over ``scenes`` and their agreement."""
    n = host_found = fpga_found = both = fpga_only = 0
    err_host: list[float] = []
    err_fpga: list[float] = []
    az: dict[str, list[float]] = {"host": [], "fpga": [], "host_ref": [], "fpga_ref": []}
    same = 0
    for sc in scenes:
        cfg = sc.config
        params = DetectionParams()
        dcfg = fpga_detect_config(cfg, params.cfar)
        host, fpga, _, host_ref, fpga_ref = _both_paths(  # type: ignore[misc]
            simulate_scene(sc).samples, cfg, params, dcfg, reference=True)
        same += _same_cloud(fpga, fpga_ref) and _same_cloud(host, host_ref)
        for name, cloud in (("host", host), ("fpga", fpga), ("host_ref", host_ref),
                            ("fpga_ref", fpga_ref)):
            az[name] += [abs(m.azimuth_err_deg) for m in match_targets(cloud, sc.targets,
                                                                       cfg)[0]
                         if m.index >= 0]
        mh, _ = match_targets(host, sc.targets, cfg)
        mf, _ = match_targets(fpga, sc.targets, cfg)
        for a, b in zip(mh, mf, strict=True):
            n += 1
            host_found += a.index >= 0
            fpga_found += b.index >= 0
            both += a.index >= 0 and b.index >= 0
            fpga_only += b.index >= 0 and a.index < 0
            if a.index >= 0 and b.index >= 0:
                err_host.append(abs(a.range_err_m))
                err_fpga.append(abs(b.range_err_m))
    azm = {f"az_{k}": float(np.mean(v)) if v else float("nan") for k, v in az.items()}
    return {**azm, "same_clouds": same, "scenes": len(scenes),
            "targets": n, "host": host_found, "fpga": fpga_found,
            "agree": 100.0 * both / max(host_found, 1), "fpga_only": fpga_only,
            "rerr_host": float(np.mean(err_host)) if err_host else float("nan"),
            "rerr_fpga": float(np.mean(err_fpga)) if err_fpga else float("nan")}


def table1_seed_rows(seeds: int) -> tuple[list[tuple[int, str, int, float, float, float]],
                                          int]:
    """Table I (``full``) over ``seeds`` noise realisations through both paths: rows
    (vehicle, path, frames found, mean |range err| m, mean |azimuth err| deg, mean
    |velocity err| m/s) and the number of seeds whose two clouds are the same."""
    acc: dict[tuple[int, str], list[tuple[float, float, float]]] = {}
    same = 0
    for seed in range(seeds):
        sc = table1_scene("full", seed=seed)
        cfg = sc.config
        params = DetectionParams()
        host, fpga, _ = _both_paths(simulate_scene(sc).samples, cfg, params,  # type: ignore[misc]
                                    fpga_detect_config(cfg, params.cfar))
        same += _same_cloud(host, fpga)
        for path, cloud in (("host", host), ("fpga", fpga)):
            for i, m in enumerate(match_targets(cloud, sc.targets, cfg)[0]):
                if m.index >= 0:
                    acc.setdefault((i, path), []).append(
                        (abs(m.range_err_m), abs(m.azimuth_err_deg), abs(m.velocity_err_mps)))
    rows = []
    for i in range(len(table1_scene("full").targets)):
        for path in ("host", "fpga"):
            e = np.array(acc.get((i, path), []), dtype=float).reshape(-1, 3)
            mean = e.mean(axis=0) if len(e) else np.full(3, np.nan)
            rows.append((i, path, len(e), *map(float, mean)))
    return rows, same


def false_alarm_rows(preset: str, frames: int, pfas: tuple[float, ...]
                     ) -> list[tuple[float, float, float, float]]:
    """(Pfa, FPGA CFAR detections per cell, FPGA-path points per cell, host points per
    cell) on noise-only frames through the fixed-point chain."""
    cfg = get_preset(preset)
    rng = np.random.default_rng(5)
    adcs = [np.round(thermal_noise(cfg, (cfg.n_chirps, cfg.num_rx, cfg.n_range), rng))
            for _ in range(frames)]
    lo, hi = cfg.detection_bins
    cells = (hi - lo) * cfg.n_doppler * frames
    out = []
    for pfa in pfas:
        params = DetectionParams(cfar=CfarParams(pfa=pfa))
        dcfg = fpga_detect_config(cfg, params.cfar, max_detections=4096)
        det = pts_f = pts_h = 0
        for adc in adcs:
            host, fpga, n = _both_paths(adc.astype(np.complex64), cfg, params, dcfg)
            det += n
            pts_f += len(fpga)
            pts_h += len(host)
        out.append((pfa, det / cells, pts_f / cells, pts_h / cells))
    return out


def link_rows(preset: str, counts: tuple[int, ...]) -> list[tuple[str, int, float]]:
    """(what, bytes per frame, Mbit/s at FRAME_RATE_HZ) of the cube and of record frames
    with MAX_DETECTIONS = n detections, measured on packetized frames."""
    cfg = get_preset(preset)
    pw = UDP_PACKET_WORDS[preset]
    wb = 4 * cfg.num_rx
    frame_words = cfg.num_tx * cfg.n_range * cfg.n_doppler
    n_pk = -(-frame_words // pw)
    cube_bytes = (frame_words + 2 * n_pk) * wb   # every packet: a header and a CRC word
    rows = [("radar cube (mode 0)", cube_bytes, cube_bytes * 8 * FRAME_RATE_HZ / 1e6)]
    for n in counts:
        frame = encode_frame(synthetic_records(cfg, n), n, cfg.num_tx, cfg.num_rx, n)
        b = sum(len(words_to_bytes(p)) for p in packetize(frame, pw))
        rows.append((f"records, {n} detections", b, b * 8 * FRAME_RATE_HZ / 1e6))
    return rows


def _same_cloud(a: PointCloud, b: PointCloud, tol: float = 1e-6) -> bool:
    """Same points (bins, flags exactly; float fields within ``tol``)."""
    if len(a) != len(b):
        return False
    for f in fields(a):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if x.dtype.kind in "fc":
            if not np.allclose(x, y, rtol=tol, atol=tol, equal_nan=True):
                return False
        elif not np.array_equal(x, y):
            return False
    return True


def _best_ms(fn: Callable[[], object], repeat: int) -> tuple[float, float]:
    """(CPU ms, wall ms) of ``fn``, each the best of ``repeat`` runs."""
    cpu = wall = math.inf
    for _ in range(repeat):
        c0, t0 = time.process_time(), time.perf_counter()
        fn()
        cpu = min(cpu, time.process_time() - c0)
        wall = min(wall, time.perf_counter() - t0)
    return cpu * 1e3, wall * 1e3


def _frame_packets(cfg: RadarConfig, n: int, varied: bool) -> list[bytes]:
    """The UDP payloads of one frame of ``n`` synthetic records (:func:`synthetic_records`)."""
    frame = encode_frame(synthetic_records(cfg, n, varied=varied), n, cfg.num_tx, cfg.num_rx,
                         n)
    return [words_to_bytes(p) for p in packetize(frame, UDP_PACKET_WORDS[cfg.name])]


def _decoded(packets: list[bytes], cfg: RadarConfig, dcfg: DetectConfig, gain: float,
             reference: bool = False) -> RecordArrays:
    """The record arrays the host decoder makes of a frame's payloads (DMA bytes); gain:
    the chain's (``model.radar_pipeline.chain_gain``)."""
    dec = (RecordDecoderReference if reference else RecordDecoder)(dcfg,
                                                                   UDP_PACKET_WORDS[cfg.name])
    got = [f for p in packets for f in dec.push_packet(p)] + dec.flush()
    to_arrays = record_arrays_reference if reference else record_arrays
    return to_arrays(got[0].records[:got[0].usable_records], cfg.n_virtual, gain)


def _frame_arrays(cfg: RadarConfig, n: int, varied: bool, params: DetectionParams
                  ) -> RecordArrays:
    """The record arrays of one decoded frame of ``n`` synthetic records (what
    :func:`stage_rows` and :func:`spread_ms` time ``process_records`` on)."""
    return _decoded(_frame_packets(cfg, n, varied), cfg,
                    fpga_detect_config(cfg, params.cfar, max_detections=n),
                    chain_gain(cfg, PipelineParams()))


def host_time_rows(preset: str, n: int, repeat: int, reference: bool = False,
                   varied: bool = False
                   ) -> tuple[tuple[float, float], tuple[float, float], tuple[float, float],
                              int]:
    """((CPU, wall) ms of DMA bytes -> record arrays, of records -> point cloud, of both
    in one go, points) for one frame of ``n`` synthetic records (``varied``: see
    :func:`synthetic_records`); ``reference``: through the replaced code (``Record``
    objects from ``model.detect_records.decode_frame``, ``record_arrays_reference``, the
    oracle ``process_records_reference``)."""
    cfg = get_preset(preset)
    params = DetectionParams()
    dcfg = fpga_detect_config(cfg, params.cfar, max_detections=n)
    packets = _frame_packets(cfg, n, varied)
    gain = chain_gain(cfg, PipelineParams())

    def decode() -> RecordArrays:
        return _decoded(packets, cfg, dcfg, gain, reference)

    def cloud(arr: RecordArrays) -> PointCloud:
        process = process_records_reference if reference else process_records
        return process(arr, cfg, params)

    arr = decode()
    cloud(arr)                          # the kernels compile (or load) on their first call
    t_dec = _best_ms(decode, repeat)
    t_pc = _best_ms(lambda: cloud(arr), repeat)
    t_all = _best_ms(lambda: cloud(decode()), repeat)
    return t_dec, t_pc, t_all, len(cloud(arr))


STAGES = {"select_records": record_points, "record_offsets": record_points,
          "hypothesis_classes": points, "peak_powers": points, "choose_folds": points,
          "estimate_angles": points, "first_components": angle, "_relax": angle,
          "cloud": points}
"""The steps of ``host.record_points.process_records`` timed by :func:`stage_rows`, each
with the module that calls it (it is wrapped there); ``first_components`` and ``_relax``
(RELAX) run inside ``estimate_angles``: :data:`NESTED`."""
NESTED = ("first_components", "_relax")


@contextmanager
def _stage_clock(spent: dict[str, float]) -> Iterator[None]:
    """While active, the CPU seconds of each of :data:`STAGES` add up in ``spent`` (the
    functions are wrapped where their callers look them up, and restored)."""
    saved = {name: getattr(module, name) for name, module in STAGES.items()}

    def timed(name: str, fn: Callable[..., Any]) -> Callable[..., Any]:
        def run(*a: Any, **k: Any) -> Any:
            t0 = time.process_time()
            try:
                return fn(*a, **k)
            finally:
                spent[name] = spent.get(name, 0.0) + time.process_time() - t0
        return run

    try:
        for name, fn in saved.items():
            setattr(STAGES[name], name, timed(name, fn))
        yield
    finally:
        for name, fn in saved.items():
            setattr(STAGES[name], name, fn)


def stage_rows(preset: str, n: int, repeat: int, varied: bool) -> dict[str, float]:
    """CPU ms per step of records -> point cloud (:data:`STAGES`, and ``total``) for one
    frame of ``n`` synthetic records, from the fastest of ``repeat`` runs."""
    cfg = get_preset(preset)
    params = DetectionParams()
    arr = _frame_arrays(cfg, n, varied, params)
    process_records(arr, cfg, params)             # compile / load the kernels
    best: dict[str, float] = {"total": math.inf}
    for _ in range(repeat):
        spent: dict[str, float] = {}
        with _stage_clock(spent):
            t0 = time.process_time()
            process_records(arr, cfg, params)
            spent["total"] = time.process_time() - t0
        if spent["total"] < best["total"]:
            best = spent
    return {k: v * 1e3 for k, v in best.items()}


def spread_ms(preset: str, n: int, runs: int, varied: bool, unfold: bool
              ) -> tuple[float, float, float]:
    """(best, median, 90th percentile) CPU ms of records -> point cloud over ``runs`` runs
    of one frame of ``n`` synthetic records; ``unfold``: ``DetectionParams.
    unfold_velocity``. The spread a frame loop sees on this machine, not just its best."""
    cfg = get_preset(preset)
    params = DetectionParams(unfold_velocity=unfold)
    arr = _frame_arrays(cfg, n, varied, params)
    process_records(arr, cfg, params)             # compile / load the kernels
    spent = []
    for _ in range(runs):
        t0 = time.process_time()
        process_records(arr, cfg, params)
        spent.append(time.process_time() - t0)
    best, median, p90 = np.percentile(spent, (0, 50, 90)) * 1e3
    return float(best), float(median), float(p90)


def calibration_ms(repeat: int) -> float:
    """CPU ms of 10^6 complex128 multiplications: this machine's speed and load at the time
    (to compare runs on differently loaded machines)."""
    a = np.ones(1_000_000, complex)
    return _best_ms(lambda: a * a, repeat)[0]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", type=int, default=100, help="random paper-fpga scenes")
    ap.add_argument("--full-scenes", type=int, default=20,
                    help="random full scenes (about 6 s each on this machine)")
    ap.add_argument("--noise-frames", type=int, default=40, help="noise-only paper-fpga frames")
    ap.add_argument("--table1-seeds", type=int, default=30,
                    help="noise seeds of the Table I error table (about 2 s each)")
    ap.add_argument("--repeat", type=int, default=5, help="timing runs; best is reported")
    ap.add_argument("--spread-runs", type=int, default=100,
                    help="runs of the best / median / 90th percentile table")
    ap.add_argument("--host-only", action="store_true",
                    help="only table 4 (host time per frame), a minute instead of ~15")
    args = ap.parse_args()
    try:
        os.sched_setaffinity(0, {min(os.sched_getaffinity(0))})   # one core
    except (AttributeError, OSError):
        pass

    if not args.host_only:
        other_tables(args)
    host_table(args)


def other_tables(args: argparse.Namespace) -> None:
    """Tables 1 to 3 (module docstring)."""
    print("## Detection: --detect fpga (on-chip CFAR, records) vs --detect host (cube)")
    print("| scenes | true targets | found, host | found, fpga | fpga finds of host's | "
          "fpga only | mean range err host / fpga (m) | mean az err host / fpga (deg), "
          "new | the same, old host code | scenes with old = new clouds |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    groups = [("Table I, full", [table1_scene("full")]),
              (f"{args.scenes} random, paper-fpga",
               [random_scene("paper-fpga", s) for s in range(args.scenes)]),
              (f"{args.full_scenes} random, full",
               [random_scene("full", s) for s in range(args.full_scenes)])]
    for name, scenes in groups:
        if not scenes:
            continue
        r = detection_rows(scenes)
        print(f"| {name} | {r['targets']} | {r['host']} | {r['fpga']} | {r['agree']:.1f} % | "
              f"{r['fpga_only']} | {r['rerr_host']:.2f} / {r['rerr_fpga']:.2f} | "
              f"{r['az_host']:.3f} / {r['az_fpga']:.3f} | {r['az_host_ref']:.3f} / "
              f"{r['az_fpga_ref']:.3f} | {r['same_clouds']} of {r['scenes']} |")

    t1 = table1_scene("full")
    rows, same = table1_seed_rows(args.table1_seeds)
    print(f"\n## Table I, full, {args.table1_seeds} noise seeds: errors of the point nearest "
          f"each vehicle ({same} of {args.table1_seeds} seeds give the same cloud on both "
          f"paths)")
    print("| vehicle (range, az, v) | path | found | mean abs range err (m) | "
          "mean abs az err (deg) | mean abs v err (m/s) |")
    print("|---|---|---|---|---|---|")
    for i, path, found, dr, daz, dv in rows:
        t = t1.targets[i]
        print(f"| {t.range_m:g} m, {t.azimuth_deg:+g} deg, {t.radial_velocity_mps:+.1f} m/s | "
              f"{path} | {found}/{args.table1_seeds} | {dr:.4f} | {daz:.4f} | {dv:.4f} |")

    print(f"\n## False alarms, {args.noise_frames} noise-only paper-fpga frames (fixed-point "
          f"chain; per reportable cell)")
    print("| configured Pfa | FPGA CFAR detections | ratio | points, fpga path | "
          "points, host path |")
    print("|---|---|---|---|---|")
    for pfa, det, pf, ph in false_alarm_rows("paper-fpga", args.noise_frames, (1e-3, 1e-4)):
        print(f"| {pfa:.0e} | {det:.2e} | {det / pfa:.2f} | {pf:.2e} | {ph:.2e} |")

    print(f"\n## Link, full, {UDP_PACKET_WORDS['full']}-word packets, {FRAME_RATE_HZ:g} "
          f"frames/s (paper's link: {LINK_MBPS:g} Mbit/s)")
    print("| stream | bytes/frame | Mbit/s | fits |")
    print("|---|---|---|---|")
    for what, b, mbps in link_rows("full", (10, 100, 1000)):
        print(f"| {what} | {b:,} | {mbps:,.1f} | {'yes' if mbps <= LINK_MBPS else 'no'} |")



def host_table(args: argparse.Namespace) -> None:
    """Table 4 (module docstring)."""
    print(f"\n## Host time per full frame, one core (best of {args.repeat}; CPU = "
          f"process_time, wall = perf_counter; old = the replaced code, same run; "
          f"10^6 complex multiplications take {calibration_ms(args.repeat):.2f} ms CPU here)")
    print("| detections | frame | step | old CPU ms | new CPU ms | old wall ms | new wall ms | "
          "CPU speed-up |")
    print("|---|---|---|---|---|---|---|---|")
    for varied in (False, True):
        for n in (10, 100, 1000):
            od, op, oa, _ = host_time_rows("full", n, args.repeat, reference=True,
                                           varied=varied)
            nd_, np_, na, pts = host_time_rows("full", n, args.repeat, varied=varied)
            kind = "mixed" if varied else "strong"
            for step, o, w in (("DMA bytes -> records", od, nd_),
                               (f"records -> point cloud ({pts} points)", op, np_),
                               ("DMA bytes -> point cloud", oa, na)):
                print(f"| {n} | {kind} | {step} | {o[0]:.2f} | {w[0]:.2f} | {o[1]:.2f} | "
                      f"{w[1]:.2f} | {o[0] / max(w[0], 1e-9):.1f}x |")
    rows = {kind: stage_rows("full", 1000, args.repeat, kind == "mixed")
            for kind in ("strong", "mixed")}
    print("\n## Where records -> point cloud spends its time, 1000 detections, `full`, one "
          f"core (CPU ms, the fastest of {args.repeat} runs)")
    print("| step (`host.record_points`, `host.points`, `host.angle`) | strong | mixed |")
    print("|---|---|---|")
    for name in (*STAGES, "other"):
        got = [r.get(name, 0.0) if name != "other" else r["total"] - sum(
            r.get(k, 0.0) for k in STAGES if k not in NESTED) for r in rows.values()]
        label = f"of which `{name}`" if name in NESTED else f"`{name}`"
        print(f"| {label} | {got[0]:.2f} | {got[1]:.2f} |")
    print(f"| total | {rows['strong']['total']:.2f} | {rows['mixed']['total']:.2f} |")
    print(f"\n## Records -> point cloud, 1000 detections, `full`, one core: CPU ms over "
          f"{args.spread_runs} runs")
    print("| frame | velocity unfolding | best | median | 90th percentile |")
    print("|---|---|---|---|---|")
    for kind in ("strong", "mixed"):
        for unfold in (True, False):
            b, m, p = spread_ms("full", 1000, args.spread_runs, kind == "mixed", unfold)
            print(f"| {kind} | {'on' if unfold else 'off'} | {b:.2f} | {m:.2f} | {p:.2f} |")
    print(f"\nCPU calibration after the runs: {calibration_ms(args.repeat):.2f} ms per 10^6 "
          f"complex multiplications")


if __name__ == "__main__":
    main()
