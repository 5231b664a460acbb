"""The RTL's side of a radar configuration: the HDL parameters a ``model.config.RadarConfig``
gives the top, what of a configuration the top does not elaborate (:func:`check_hdl`) and the
fixed facts of the data path (sample width, fabric clock, the external frame store's bus
width), in one place for the tests, the frame sources and synthesis."""

from __future__ import annotations

from model.config import RadarConfig
from model.fft_rom import WINDOW_LENGTHS

DATA_W = 16
"""Bits of I and of Q on every sample stream of the RTL (docs/design.md section 3)."""

FPGA_CLOCK_HZ = 100e6
"""The fabric clock of the RTL (the paper's 100 MHz, Hz): ADC samples are paced against it,
and the benchmarks turn cycle counts into frame rates and bandwidths with it."""

FULL_AXI_DATA_W = 512
"""AXI_DATA_W (bits) of the external frame store of the ``full`` top (FRAME_STORE = 1): the
ZCU106 PL DDR4 through MIG, 512-bit user interface at the 100 MHz fabric clock
(docs/frame_store.md). The RTL frame source, the synthesis jobs and the tests use it."""


def hdl_parameters(cfg: RadarConfig, **overrides: int) -> dict[str, int]:
    """The HDL parameters a radar configuration gives the RTL: NUM_RX, NUM_TX, N_RANGE,
    N_DOPPLER (the FFT lengths), N_SAMPLES (samples per chirp), N_LOOPS (loops per frame),
    REAL_ADC and DATA_W, then ``overrides`` (e.g. ``PACKET_WORDS=1024``) added or replacing.
    The one place that maps a profile to HDL parameters (tests, RTL source, synthesis)."""
    params = {"NUM_RX": cfg.num_rx, "NUM_TX": cfg.num_tx, "N_RANGE": cfg.n_range,
              "N_DOPPLER": cfg.n_doppler, "N_SAMPLES": cfg.n_samples, "N_LOOPS": cfg.n_loops,
              "REAL_ADC": int(cfg.adc == "real"), "DATA_W": DATA_W}
    params.update(overrides)
    return params


MAX_NUM_RX = 16
"""Largest NUM_RX of the ``radar_pipeline`` top (its ``g_bad_num_rx`` elaboration check)."""
MAX_NUM_TX = 16
"""Largest NUM_TX of the top (``g_bad_num_tx``); any count 1..16 (docs/buffers.md)."""


def hdl_unsupported(cfg: RadarConfig) -> list[str]:
    """What of ``cfg`` the ``radar_pipeline`` top refuses at elaboration
    (rtl/top/radar_pipeline.sv, its ``g_bad_*`` blocks), one phrase each (empty for the
    presets): more than MAX_NUM_RX RX, more than MAX_NUM_TX TX, ADC codes wider than the
    DATA_W-bit sample streams, a sample or loop count with no generated window ROM (a power
    of two or ``model.fft_rom.WINDOW_LENGTHS``; the chain windows both axes), a single loop
    per frame. Every RadarConfig's FFT lengths (powers of two in 16..4096) are the top's
    already."""
    out = []
    for name, value in (("samples per chirp", cfg.n_samples), ("loops", cfg.n_loops)):
        if value & (value - 1) and value not in WINDOW_LENGTHS:
            out.append(f"{value} {name} (no window ROM of that length: add it to "
                       "model.fft_rom.WINDOW_LENGTHS and run make gen)")
    if cfg.n_loops < 2:
        out.append("1 loop per frame (N_LOOPS at least 2)")
    if cfg.num_rx > MAX_NUM_RX:
        out.append(f"{cfg.num_rx} RX (NUM_RX at most {MAX_NUM_RX})")
    if cfg.num_tx > MAX_NUM_TX:
        out.append(f"{cfg.num_tx} TX (NUM_TX at most {MAX_NUM_TX})")
    if cfg.adc_bits > DATA_W:
        out.append(f"a {cfg.adc_bits}-bit ADC (DATA_W = {DATA_W} bits of I and of Q)")
    return out


def check_hdl(cfg: RadarConfig) -> None:
    """ValueError (one line) naming what of ``cfg`` the RTL top, and so its bit-accurate
    model, does not run (:func:`hdl_unsupported`)."""
    missing = hdl_unsupported(cfg)
    if missing:
        raise ValueError(f"radar {cfg.name!r}: the RTL (and its bit-accurate model) does not "
                         f"run {'; '.join(missing)}")
