"""The synthesis jobs both flows run (Yosys estimate, Vivado) and the RTL file list they read.

A job is one block (HDL top) at one parameter set; :func:`job_sets` names the sets
(``ci``, ``paper-fpga``, ``full``, ``full-blocks``, ``all``). Every job reads ``rtl/`` as
written: the plain file list ``rtl/**/*.sv``, packages first (:func:`rtl_files`), narrowed to
the files its top elaborates (:func:`files_for`). docs/synth.md describes the sets.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field, replace
from pathlib import Path

from model.fft_axis import multipliers_per_lane
from model.hdl import FULL_AXI_DATA_W

ROOT = Path(__file__).resolve().parent.parent
RTL = ROOT / "rtl"
TOP_FILE = RTL / "top" / "radar_pipeline.sv"

# The paper's Table II (Vivado, ZCU106, 1 TX x 4 RX prototype with the Xilinx FFT IP).
# BRAM is counted in 36 Kb blocks (one RAMB18 = 0.5).
PAPER_TABLE_II: dict[str, float] = {
    "LUT": 20029, "LUTRAM": 4406, "FF": 26584, "BRAM": 62.5, "URAM": 16, "DSP": 96,
}


@dataclass(frozen=True)
class Job:
    """One synthesis run: a block (HDL top) at one parameter set.

    Every job reads its part of the file list (:func:`files_for`); ``uram`` adds ``-uram`` (the big
    buffers: corner turn, packetizer, top); ``expect_dsp``
    is the DSP48E2 count the architecture calls for (docs/fft_axis.md), checked by the tests;
    ``ecp5_params`` are added to ``params`` in the timing flow's ECP5 mapping only
    (:mod:`synth.timing`; its xcup depth, the estimate and Vivado keep ``params``).
    """

    name: str
    top: str
    params: dict[str, int]
    uram: bool = False
    note: str = ""
    expect_dsp: int | None = None
    # instances of this job in the chain (the sum-of-blocks row multiplies by it)
    instances: int = 1
    # counted in the sum-of-blocks row (the mode-0 chain; not the detector)
    in_sum: bool = True
    ecp5_params: dict[str, int] = field(default_factory=dict)

    @property
    def label(self) -> str:
        """Human-readable parameter list, e.g. ``N=64 NUM_CH=4`` (``MUL_W=18 (ECP5)`` after
        it for an ECP5-only parameter)."""
        return " ".join([*(f"{k}={v}" for k, v in self.params.items()),
                         *(f"{k}={v} (ECP5)" for k, v in self.ecp5_params.items())])


def _fft_dsp(n: int, lanes: int, window: bool, data_w: int = 16, guard_w: int = 4) -> int:
    """DSP48E2 of one fft_axis: 3 per complex twiddle multiplier (Gauss; 4 when the internal
    width W = DATA_W + 1 + GUARD_W is 27, rtl/fft/fft_twiddle.sv), 2 per lane for the window.

    Twiddle multipliers per lane: :func:`model.fft_axis.multipliers_per_lane`.
    """
    per_twiddle = 3 if data_w + 1 + guard_w + 1 <= 27 else 4
    return lanes * (per_twiddle * multipliers_per_lane(n) + (2 if window else 0))


def _jobs_for(preset: str, num_tx: int, num_rx: int, n_range: int, n_doppler: int,
              packet_words: int = 1024, out_banks: int = 4,
              frame_store: bool = False) -> list[Job]:
    """The blocks of radar_pipeline with the parameters the top gives them (its defaults:
    PACKET_WORDS 1024, OUT_BANKS 4, Hann window on both FFTs); the corner turn on chip, or
    with ``frame_store`` the external store's AXI4 master (FRAME_STORE = 1)."""
    frame_words = num_tx * n_range * n_doppler
    if frame_store:
        store = Job(f"{preset}/frame_store_axi", "frame_store_axi",
                    {"NUM_TX": num_tx, "NUM_RX": num_rx, "N_RANGE": n_range,
                     "N_DOPPLER": n_doppler, "DATA_W": 16, "AXI_DATA_W": FULL_AXI_DATA_W},
                    uram=True)
    else:
        store = Job(f"{preset}/corner_turn", "corner_turn",
                    {"NUM_TX": num_tx, "NUM_RX": num_rx, "N_RANGE": n_range,
                     "N_DOPPLER": n_doppler, "DATA_W": 16}, uram=True)
    jobs = [
        Job(f"{preset}/chirp_pingpong", "chirp_pingpong",
            {"NUM_RX": num_rx, "N_RANGE": n_range, "DATA_W": 16}),
        Job(f"{preset}/range_fft", "fft_axis",
            {"N": n_range, "NUM_CH": num_rx, "DATA_W": 16, "WINDOW": 1},
            expect_dsp=_fft_dsp(n_range, num_rx, True)),
        store,
        Job(f"{preset}/doppler_fft", "fft_axis",
            {"N": n_doppler, "NUM_CH": num_rx, "DATA_W": 16, "WINDOW": 1},
            expect_dsp=_fft_dsp(n_doppler, num_rx, True)),
        Job(f"{preset}/axis_packetizer", "axis_packetizer",
            {"NUM_RX": num_rx, "DATA_W": 16, "PACKET_WORDS": packet_words,
             "FRAME_WORDS": frame_words, "NUM_BANKS": out_banks, "TLAST_PERIOD": n_doppler},
            uram=True),
    ]
    return jobs


def _top_job(preset: str, frame_store: bool = False) -> Job:
    """The whole radar_pipeline with the HDL parameters the model/RTL source give it
    (:meth:`model.radar_pipeline.PipelineParams.hdl_parameters`)."""
    from model.config import get_preset
    from model.radar_pipeline import PipelineParams

    chain = PipelineParams(frame_store=frame_store,
                           axi_data_w=FULL_AXI_DATA_W if frame_store else 128)
    params = chain.hdl_parameters(get_preset(preset))
    return Job(f"{preset}/radar_pipeline", "radar_pipeline", params, uram=True,
               note="whole top (rtl/top/radar_pipeline.sv)"
                    + (", FRAME_STORE = 1" if frame_store else ""))


def _detect_job(preset: str) -> Job:
    """The on-chip detector (rtl/detect/detect_chain.sv) with the default detector settings
    (:class:`model.detect_chain.DetectConfig`) at the preset's dimensions; not part of the
    mode-0 chain, so not in the sum of the blocks."""
    from model.detect_chain import DetectConfig

    params = DetectConfig(*_dims(preset)).hdl_parameters()
    return Job(f"{preset}/detect_chain", "detect_chain", params, uram=True, in_sum=False,
               note="OUTPUT_MODE = 1 detector")


def _dims(preset: str) -> tuple[int, int, int, int]:
    """(NUM_TX, NUM_RX, N_RANGE, N_DOPPLER) of a preset (:func:`model.hdl.hdl_parameters`)."""
    from model.config import get_preset
    from model.hdl import hdl_parameters

    p = hdl_parameters(get_preset(preset))
    return p["NUM_TX"], p["NUM_RX"], p["N_RANGE"], p["N_DOPPLER"]


def job_sets() -> dict[str, list[Job]]:
    """The named job sets: ``ci`` (quick), ``paper-fpga`` (blocks, top, detector), ``full``
    (blocks, detector and the top with FRAME_STORE = 1), ``full-blocks`` (``full`` without
    its top), ``all`` (``paper-fpga`` + ``full``)."""
    paper = (_jobs_for("paper-fpga", *_dims("paper-fpga"))
             + [_top_job("paper-fpga"), _detect_job("paper-fpga")])
    # full: the range and Doppler FFTs are the same 256-point 16-lane core (one run, x2);
    # the 128 Mib frame lives in DDR4 (FRAME_STORE = 1, frame_store_axi)
    full = [j for j in _jobs_for("full", *_dims("full"), frame_store=True)
            if not j.name.endswith("doppler_fft")]
    full = [replace(j, name="full/range_doppler_fft", instances=2)
            if j.name.endswith("range_fft") else j for j in full]
    full_blocks = full + [_detect_job("full")]
    full = full_blocks + [_top_job("full", frame_store=True)]
    ci = [
        Job("ci/fft_axis", "fft_axis", {"N": 16, "NUM_CH": 1, "DATA_W": 16, "WINDOW": 0},
            expect_dsp=_fft_dsp(16, 1, False)),
        Job("ci/corner_turn", "corner_turn",
            {"NUM_TX": 1, "NUM_RX": 1, "N_RANGE": 64, "N_DOPPLER": 256, "DATA_W": 16},
            uram=True),
    ]
    return {"ci": ci, "paper-fpga": paper, "full": full, "full-blocks": full_blocks,
            "all": paper + full}


def select(jobs: list[Job], only: str) -> list[Job]:
    """The jobs whose name contains one of the comma-separated substrings ``only`` (all of
    them when ``only`` is empty)."""
    keys = [k for k in only.split(",") if k]
    return [j for j in jobs if not keys or any(k in j.name for k in keys)]


def jobs_of(sets: dict[str, list[Job]], name: str, only: str | None) -> list[Job]:
    """The jobs of set ``name`` that ``--only`` (:func:`select`; None: all) keeps;
    ValueError naming the option when it keeps none."""
    jobs = sets[name]
    if only:
        jobs = select(jobs, only)
        if not jobs:
            raise ValueError(f"--only {only} matches no job of set {name}")
    return jobs


def rtl_files(rtl: Path = RTL) -> list[Path]:
    """The plain file list every tool reads: every ``rtl/**/*.sv``, packages (``*_pkg.sv``)
    first, each group sorted by path. Absolute paths, so any working directory works."""
    files = sorted(rtl.rglob("*.sv"), key=lambda p: (not p.stem.endswith("_pkg"), str(p)))
    return [p.resolve() for p in files]


def files_for(top: str, files: list[Path]) -> list[Path]:
    """The part of the file list :func:`rtl_files` that ``top`` elaborates: the files of the
    modules and packages it names, directly or below (a file is named after its module or
    package). Still read as written, in the same order; the subset only keeps Yosys' wasm
    build inside its 4 GiB address space, which the whole tree's ASTs plus the Xilinx cell
    library exceed."""
    by_name = {p.stem: p for p in files}
    words = {name: set(re.findall(r"\b\w+\b", p.read_text())) for name, p in by_name.items()}
    need, todo = set(), [top]
    while todo:
        name = todo.pop()
        if name in need or name not in by_name:
            continue
        need.add(name)
        todo.extend(w for w in words[name] if w in by_name and w != name)
    return [p for p in files if p.stem in need]
