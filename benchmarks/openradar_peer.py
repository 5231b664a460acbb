"""OpenRadar's chain on one frame of a DCA1000 capture, for ``benchmarks/bench_openradar.py``.

Runs in OpenRadar's own virtualenv (``make bench-openradar`` creates ``out/openradar-venv``:
``openradar==1.0.1`` with numpy 2, scipy and scikit-learn), never in the project's, and
imports nothing of the project: the peer's chain as its visualizer demo
(``demo/visualizer/main.py`` of PreSenseRadar/OpenRadar) runs it, on a 2-lane DCA1000 frame:

1. ``DCA1000.organize`` of the capture's int16 words -> (chirps, rx, samples). The demo reads
   the words as uint16, which wraps every negative sample; here they are read signed.
2. ``dsp.range_processing`` (Blackman) and ``dsp.doppler_processing`` (TDM channels
   separated, its static-clutter removal on, Hamming): ``det_matrix`` (range, Doppler), the
   sum over the virtual channels of log2 |X|, and the (range, virtual, Doppler) cube.
3. ``dsp.ca_`` along Doppler and along range, guard 4, noise 16, a cell detected where it
   exceeds both: at the demo's additive bounds (1.5 Doppler, 2.5 range, in the map's units:
   1.1 / 1.9 dB for 8 channels) and at a threshold in dB (the bound n_virtual * dB /
   (20 log10 2) on both axes), then ``dsp.prune_to_peaks`` (reserving neighbours) and
   ``dsp.peak_grouping_along_doppler``. The demo's ``range_based_pruning`` is left out (its
   SNR and peak thresholds are set for the demo's 3-TX capture).
4. TDM Doppler compensation, then the Bartlett spectrum (``dsp.gen_steering_vec`` +/-90 deg,
   0.1 deg grid; ``dsp.aoa_bartlett``) of each detection's channel vector, its peak the
   azimuth. ``dsp.add_doppler_compensation`` cannot do step 4's compensation on numpy >= 1.12:
   it slices ``input_data[:, (num_antennas/num_tx_antennas):, :]`` with a float (TypeError:
   slice indices must be integers), and with that slice fixed it still fails for more than
   one detection (its (n, 1) rotation broadcast against each range row's (antennas,
   Doppler) slice) and for one returns j * c * conj(x) for the rotation c of x (its real and
   imaginary parts swapped). The compensation it documents, TX t's channels times
   exp(-j 2 pi k t / (N_doppler * num_tx)) for signed Doppler bin k, is done here instead.
   ``gen_steering_vec`` calls ``np.complex`` (removed in numpy 1.24): shimmed as ``complex``.

    python benchmarks/openradar_peer.py --capture F.bin --chirps 256 --rx 4 --samples 128
        --tx 2 --out peer.json [--threshold-db 15] [--repeat 20]

Writes JSON (and with ``--map F.npz`` the frame's ``det_matrix`` and its two thresholds at
``--threshold-db``, float (range, Doppler) each): ``versions``; ``tdm_compensation_error``
(what ``add_doppler_compensation`` raises when called as its docstring shows); ``settings``:
``demo`` and ``<dB> dB``, each with ``cfar_cells`` (cells over both thresholds),
``detections`` (after the peak pruning and grouping: ``range_bin``, ``doppler_bin`` signed,
``azimuth_deg``, ``det_value`` the map's value) and ``times_s`` / ``cpu_s`` (wall / this
process' CPU time of the whole chain per frame, steps 1-4, ``repeat`` runs after one
warm-up).
"""

from __future__ import annotations

import argparse
import json
import platform
import time
from importlib.metadata import version
from typing import Any

import numpy as np

np.complex = complex  # noqa: NPY001  (the shim: gen_steering_vec calls np.complex)
import mmwave.dsp as dsp  # noqa: E402  (after the shim)
from mmwave.dataloader import DCA1000  # noqa: E402
from mmwave.dsp.utils import Window  # noqa: E402

GUARD, NOISE = 4, 16
"""The demo's CA-CFAR window (cells per side), both axes."""
DEMO_BOUNDS = (1.5, 2.5)
"""The demo's additive CFAR bounds (Doppler, range), in det_matrix units (sum of log2 |X|)."""
ANGLE_RANGE_DEG, ANGLE_STEP_DEG = 90, 0.1


def read_frame(path: str, chirps: int, rx: int, samples: int) -> np.ndarray:
    """Frame 0 of a 2-lane DCA1000 capture: complex (chirps, rx, samples) ADC codes."""
    raw = np.fromfile(path, dtype=np.int16, count=chirps * rx * samples * 2)
    return DCA1000.organize(raw, num_chirps=chirps, num_rx=rx, num_samples=samples)


def thresholds(det: np.ndarray, bound_doppler: float, bound_range: float
               ) -> tuple[np.ndarray, np.ndarray]:
    """The demo's two 1-D CA-CFAR thresholds of every cell of ``det`` (range, Doppler):
    (along Doppler, along range), both of its shape."""
    det_int = det.astype(np.int64)
    thr_d, _ = np.apply_along_axis(dsp.ca_, 0, det_int.T, l_bound=bound_doppler,
                                   guard_len=GUARD, noise_len=NOISE)
    thr_r, _ = np.apply_along_axis(dsp.ca_, 0, det_int, l_bound=bound_range,
                                   guard_len=GUARD, noise_len=NOISE)
    return thr_d.T, thr_r


def cfar_cells(det: np.ndarray, bound_doppler: float, bound_range: float) -> np.ndarray:
    """Cells of ``det`` (range, Doppler) over both :func:`thresholds`: int (n, 2)."""
    thr_d, thr_r = thresholds(det, bound_doppler, bound_range)
    return np.argwhere((det > thr_d) & (det > thr_r))


def grouped(cells: np.ndarray, det: np.ndarray) -> np.ndarray:
    """The demo's ``prune_to_peaks`` + ``peak_grouping_along_doppler``: int (m, 2) cells."""
    dt = np.dtype({"names": ["rangeIdx", "dopplerIdx", "peakVal"],
                   "formats": ["<i4", "<i4", "<f4"]})
    obj = np.zeros(len(cells), dtype=dt)
    obj["rangeIdx"], obj["dopplerIdx"] = cells[:, 0], cells[:, 1]
    obj["peakVal"] = det.astype(np.int64)[cells[:, 0], cells[:, 1]]
    obj = dsp.prune_to_peaks(obj, det, det.shape[1], reserve_neighbor=True)
    obj = dsp.peak_grouping_along_doppler(obj, det, det.shape[1])
    return np.stack([obj["rangeIdx"], obj["dopplerIdx"]], axis=1).astype(np.int64)


def signed(doppler: np.ndarray, n_doppler: int) -> np.ndarray:
    """Doppler bin indices 0..N-1 -> signed -N/2..N/2-1."""
    return np.where(doppler >= n_doppler // 2, doppler - n_doppler, doppler)


def frame_map(path: str, shape: tuple[int, int, int, int]) -> tuple[np.ndarray, np.ndarray]:
    """Steps 1-2 of the module docstring on frame 0 of ``path`` (``shape`` = (chirps, rx,
    samples, tx)): ``det_matrix`` float (range, Doppler) and the cube complex (range,
    virtual, Doppler)."""
    chirps, rx, samples, tx = shape
    frame = read_frame(path, chirps, rx, samples)
    cube = dsp.range_processing(frame, window_type_1d=Window.BLACKMAN)
    return dsp.doppler_processing(cube, num_tx_antennas=tx, clutter_removal_enabled=True,
                                  window_type_2d=Window.HAMMING)


def chain(path: str, shape: tuple[int, int, int, int], bounds: tuple[float, float],
          steering: np.ndarray, grid_deg: np.ndarray) -> dict[str, Any]:
    """Steps 1-4 of the module docstring on frame 0 of ``path``; ``shape`` = (chirps, rx,
    samples, tx)."""
    _, rx, _, tx = shape
    det, aoa = frame_map(path, shape)
    cells = cfar_cells(det, *bounds)
    peaks = grouped(cells, det)
    n_doppler = det.shape[1]
    k = signed(peaks[:, 1], n_doppler)
    x = aoa[peaks[:, 0], :, peaks[:, 1]]                                 # (n, virtual)
    t = np.repeat(np.arange(tx), rx)
    x = x * np.exp(-2j * np.pi * np.outer(k, t) / (n_doppler * tx))
    spectrum = dsp.aoa_bartlett(steering, x.T, axis=0)                  # (angles, n)
    az = grid_deg[np.argmax(spectrum, axis=0)] if len(x) else np.zeros(0)
    return {"cfar_cells": len(cells),
            "detections": {"range_bin": peaks[:, 0].tolist(), "doppler_bin": k.tolist(),
                           "azimuth_deg": np.asarray(az, float).tolist(),
                           "det_value": det[peaks[:, 0], peaks[:, 1]].tolist()}}


def tdm_crash(path: str, shape: tuple[int, int, int, int]) -> str:
    """What ``dsp.add_doppler_compensation`` raises when called as its docstring's example
    does (``add_doppler_compensation(dataIn, num_tx, doppler_indices, num_doppler_bins)``)
    on the frame's (range, virtual, Doppler) cube; '' if it runs."""
    chirps, rx, samples, tx = shape
    cube = dsp.range_processing(read_frame(path, chirps, rx, samples))
    _, aoa = dsp.doppler_processing(cube, num_tx_antennas=tx)
    try:
        dsp.add_doppler_compensation(aoa, tx, np.array([7]), aoa.shape[2])
    except Exception as exc:  # noqa: BLE001 - reported, whatever it is
        return f"{type(exc).__name__}: {exc}"
    return ""


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--capture", required=True, help="DCA1000 .bin (2 LVDS lanes)")
    for name in ("chirps", "rx", "samples", "tx"):
        ap.add_argument(f"--{name}", type=int, required=True)
    ap.add_argument("--threshold-db", type=float, default=15.0)
    ap.add_argument("--repeat", type=int, default=20, help="timed runs per setting")
    ap.add_argument("--out", required=True, help="output .json")
    ap.add_argument("--map", default=None, help="also write the frame's det_matrix and the "
                    "threshold setting's thresholds (along Doppler, along range) to this .npz")
    args = ap.parse_args()
    shape = (args.chirps, args.rx, args.samples, args.tx)
    n_virtual = args.rx * args.tx
    _, steering = dsp.gen_steering_vec(ANGLE_RANGE_DEG, ANGLE_STEP_DEG, n_virtual)
    grid = np.linspace(-ANGLE_RANGE_DEG, ANGLE_RANGE_DEG, len(steering))
    bound = n_virtual * args.threshold_db / (20 * np.log10(2))
    settings: dict[str, Any] = {}
    for name, bounds in (("demo", DEMO_BOUNDS), (f"{args.threshold_db:g} dB", (bound, bound))):
        result = chain(args.capture, shape, bounds, steering, grid)        # warm-up
        times: list[float] = []
        cpu: list[float] = []
        for _ in range(args.repeat):
            t0, c0 = time.perf_counter(), time.process_time()
            chain(args.capture, shape, bounds, steering, grid)
            times.append(time.perf_counter() - t0)
            cpu.append(time.process_time() - c0)
        settings[name] = {"bounds": list(bounds), **result, "times_s": times, "cpu_s": cpu}
    doc = {"versions": {"openradar": version("openradar"), "numpy": np.__version__,
                        "scikit-learn": version("scikit-learn"),
                        "python": platform.python_version()},
           "tdm_compensation_error": tdm_crash(args.capture, shape),
           "settings": settings}
    with open(args.out, "w") as f:
        json.dump(doc, f)
    if args.map:
        det, _ = frame_map(args.capture, shape)
        thr_d, thr_r = thresholds(det, bound, bound)
        np.savez(args.map, det=det, thr_doppler=thr_d, thr_range=thr_r)


if __name__ == "__main__":
    main()
