"""Radar profiles (docs/profiles.md): a preset name, a TOML profile or a TI mmWave SDK ``.cfg``
becomes one :class:`Profile`, a :class:`model.config.RadarConfig` plus how its captures are
stored and, from a ``.cfg``, the channel calibration it states.

Every field is checked; a bad one raises ValueError with one line naming it as the file spells
it (``waveform.slope_hz_per_s: ...``, ``profileCfg: ...``). The TOML is in SI units; array
positions are in half-wavelengths at the start frequency. :func:`profile_to_toml` writes the
TOML of any profile, so the presets, a ``.cfg`` and a hand-written profile round-trip.
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Callable
from dataclasses import dataclass, fields, replace
from pathlib import Path

from model.config import NEGATIVE_BEAT_GUARD_BINS, PRESETS, RadarConfig
from model.reference import HANN_MAIN_LOBE_BINS

CAPTURE_FORMATS = ("dca1000", "npy")
"""Capture file formats (docs/profiles.md, "Captures")."""
LVDS_LAYOUTS = {(4, True): "xWR12xx/14xx", (2, False): "xWR16xx/18xx/68xx"}
"""The DCA1000 LVDS layouts TI documents, (lanes, interleaved) -> devices."""
LEAKAGE_RANGE_M = 0.1
"""Range within which a radar board's TX-RX leakage arrives (on-chip and antenna coupling,
the radome), m: the near-range guard of a profile that states none starts here
(:func:`default_min_range_m`)."""


@dataclass(frozen=True)
class CaptureFormat:
    """How a profile's captures are stored: ``dca1000`` raw ``.bin`` (``lanes`` LVDS lanes,
    ``interleaved`` or not) or ``npy`` arrays."""

    format: str = "npy"
    lanes: int = 2
    interleaved: bool = False

    def __post_init__(self) -> None:
        if self.format not in CAPTURE_FORMATS:
            raise ValueError(f"capture.format: must be one of {', '.join(CAPTURE_FORMATS)}, "
                             f"got {self.format!r}")
        if (self.lanes, self.interleaved) not in LVDS_LAYOUTS:
            raise ValueError(f"capture.lanes: TI documents 4 lanes interleaved (xWR12xx/14xx) "
                             f"or 2 lanes non-interleaved (xWR16xx/18xx/68xx), got "
                             f"lanes = {self.lanes!r}, interleaved = {self.interleaved!r}")


@dataclass(frozen=True)
class Calibration:
    """Range bias and per-virtual-channel complex gain correction (channel v = tx * num_rx +
    rx, multiply the channel by its gain), as TI's ``compRangeBiasAndRxChanPhase`` states."""

    range_bias_m: float
    channel_gain: tuple[complex, ...]


@dataclass(frozen=True)
class Profile:
    """A radar (``config``), its capture format and, if the source states one, its
    calibration; ``source`` is the preset name or the file it was read from."""

    config: RadarConfig
    capture: CaptureFormat
    calibration: Calibration | None = None
    source: str = ""


def next_pow2(n: int, lo: int = 16) -> int:
    """Smallest power of two >= max(n, lo)."""
    return 1 << (max(n, lo) - 1).bit_length()


def default_max_range_m(cfg: RadarConfig) -> float:
    """The range a profile covers when it does not say: its maximum range less the top
    ``NEGATIVE_BEAT_GUARD_BINS`` range bins the detectors never report, m."""
    return cfg.max_range_m * (1.0 - NEGATIVE_BEAT_GUARD_BINS / cfg.n_range_bins)


def default_min_range_m(cfg: RadarConfig) -> float:
    """The near-range guard of a TOML or ``.cfg`` profile that states no ``min_range_m``, m:
    the leakage zone ``LEAKAGE_RANGE_M`` plus the range window's main lobe
    (``HANN_MAIN_LOBE_BINS`` range bins, times n_range / n_samples when zero-padded) that
    spreads the leakage beyond it. The presets keep ``min_range_m`` None (only range bin 0
    guarded)."""
    return LEAKAGE_RANGE_M + HANN_MAIN_LOBE_BINS * (cfg.n_range / cfg.n_samples) \
        * cfg.range_bin_m


def build_config(names: dict[str, str], **kw: object) -> RadarConfig:
    """RadarConfig(**kw); a ValueError of a field (``field: ...`` or ``field[i]: ...``) is
    re-raised naming the field as the source spells it (``names``: RadarConfig field ->
    source name). Without ``design_max_range_m`` the profile's :func:`default_max_range_m`
    is used."""
    try:
        if "design_max_range_m" in kw:
            return RadarConfig(**kw)  # type: ignore[arg-type]
        cfg = RadarConfig(design_max_range_m=1e-9, **kw)  # type: ignore[arg-type]
        return replace(cfg, design_max_range_m=default_max_range_m(cfg))
    except ValueError as exc:
        field, _, rest = str(exc).partition(": ")
        base, bracket, index = field.partition("[")
        raise ValueError(f"{names.get(base, base)}{bracket}{index}: {rest}") from None


def sourced(parse: Callable[[str, str], Profile], text: str, source: str) -> Profile:
    """``parse(text, source)`` with the one-line ValueError it raises prefixed by
    ``source`` (the file a message is about)."""
    try:
        return parse(text, source)
    except ValueError as exc:
        raise ValueError(f"{source}: {exc}") from None


# ---- TOML -----------------------------------------------------------------------------------
_FRONT_END = ("tx_power_dbm", "element_gain_dbi", "subarray_gain_dbi", "subarray_elements",
              "rx_gain_dbi", "element_cos_power", "noise_figure_db", "system_loss_db",
              "temperature_k", "adc_full_scale_dbm")
"""RadarConfig RF fields an optional ``[front_end]`` table may set (simulation only)."""
_WAVEFORM = {"start_frequency_hz": float, "slope_hz_per_s": float, "sample_rate_hz": float,
             "samples_per_chirp": int, "range_fft": int, "idle_time_s": float,
             "ramp_end_time_s": float, "chirp_period_s": float, "adc_start_time_s": float,
             "loops": int, "doppler_fft": int, "tx_order": list, "adc": str,
             "frame_period_s": float, "max_speed_mps": float, "max_range_m": float,
             "min_range_m": float, "adc_bits": int}
"""Keys of ``[waveform]`` and their types (docs/profiles.md)."""
_REQUIRED = ("start_frequency_hz", "slope_hz_per_s", "sample_rate_hz", "samples_per_chirp",
             "loops")
_TOML_NAMES = {"fc_hz": "waveform.start_frequency_hz", "sample_rate_hz":
               "waveform.sample_rate_hz", "chirp_period_s": "waveform.chirp_period_s",
               "design_max_range_m": "waveform.max_range_m", "n_range": "waveform.range_fft",
               "n_doppler": "waveform.doppler_fft", "samples_per_chirp":
               "waveform.samples_per_chirp", "loops": "waveform.loops",
               "tx_order": "waveform.tx_order", "adc": "waveform.adc", "tx_positions":
               "array.tx", "rx_positions": "array.rx", "num_tx": "array.tx", "num_rx":
               "array.rx", "frame_period_s": "waveform.frame_period_s", "max_speed_mps":
               "waveform.max_speed_mps", "min_range_m": "waveform.min_range_m",
               "sweep_bandwidth_hz": "waveform.slope_hz_per_s",
               "adc_bits": "waveform.adc_bits", **{f: f"front_end.{f}" for f in _FRONT_END}}
"""RadarConfig field -> the TOML key a message names."""


def _typed(table: dict, key: str, kind: type, where: str) -> object:
    """``table[key]`` checked to be of ``kind`` (int for int, int or float for float)."""
    value = table[key]
    ok = {int: lambda v: isinstance(v, int) and not isinstance(v, bool),
          float: lambda v: isinstance(v, int | float) and not isinstance(v, bool)
          and math.isfinite(v),
          str: lambda v: isinstance(v, str), list: lambda v: isinstance(v, list),
          bool: lambda v: isinstance(v, bool)}[kind](value)
    if not ok:
        what = {int: "an integer", float: "a finite number", str: "a string",
                list: "a list", bool: "true or false"}[kind]
        raise ValueError(f"{where}.{key}: must be {what}, got {value!r}")
    return float(value) if kind is float else value


def _table(doc: dict, name: str, allowed: tuple[str, ...] | dict, required: bool) -> dict:
    """``doc[name]`` checked to be a table with only ``allowed`` keys."""
    if name not in doc:
        if required:
            raise ValueError(f"[{name}]: missing table")
        return {}
    table = doc[name]
    if not isinstance(table, dict):
        raise ValueError(f"{name}: must be a table, got {table!r}")
    for key in table:
        if key not in allowed:
            raise ValueError(f"{name}.{key}: unknown key (known: {', '.join(allowed)})")
    return table


def _positions(value: object, key: str) -> tuple[object, ...]:
    """Array positions as tuples (RadarConfig checks each is two numbers)."""
    if not isinstance(value, list) or not value:
        raise ValueError(f"{key}: must be a non-empty list of [horizontal, vertical] "
                         f"positions in half-wavelengths, got {value!r}")
    return tuple(tuple(p) if isinstance(p, list) else p for p in value)


def profile_from_toml(text: str, source: str = "<profile>") -> Profile:
    """The :class:`Profile` of a TOML profile's text (docs/profiles.md); ValueError
    ``"<source>: <key>: <reason>"`` on a missing or impossible field."""
    return sourced(_profile_from_text, text, source)


def _profile_from_text(text: str, source: str) -> Profile:
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"not valid TOML: {exc}") from None
    for key in doc:
        if key not in ("name", "waveform", "array", "capture", "front_end"):
            raise ValueError(f"{key}: unknown key (known: name, [waveform], [array], "
                             f"[capture], [front_end])")
    name = doc.get("name", Path(source).stem)
    if not isinstance(name, str) or not name:
        raise ValueError(f"name: must be a non-empty string, got {name!r}")
    wf = _table(doc, "waveform", _WAVEFORM, True)
    arr = _table(doc, "array", ("tx", "rx"), True)
    cap = _table(doc, "capture", ("format", "lanes", "interleaved"), False)
    fe = _table(doc, "front_end", _FRONT_END, False)
    for key in _REQUIRED:
        if key not in wf:
            raise ValueError(f"waveform.{key}: missing")
    w = {k: _typed(wf, k, t, "waveform") for k, t in _WAVEFORM.items() if k in wf}
    for key in ("start_frequency_hz", "slope_hz_per_s", "sample_rate_hz", "idle_time_s",
                "ramp_end_time_s", "chirp_period_s", "max_range_m", "min_range_m"):
        if key in w and w[key] <= 0:
            raise ValueError(f"waveform.{key}: must be positive, got {w[key]!r}")
    if "adc_start_time_s" in w and w["adc_start_time_s"] < 0:
        raise ValueError(f"waveform.adc_start_time_s: must be >= 0, got {w['adc_start_time_s']}")
    for key in ("tx", "rx"):
        if key not in arr:
            raise ValueError(f"array.{key}: missing")
    tx = _positions(arr["tx"], "array.tx")
    rx = _positions(arr["rx"], "array.rx")
    ns, loops, fs = w["samples_per_chirp"], w["loops"], w["sample_rate_hz"]
    if ns < 8:
        raise ValueError(f"waveform.samples_per_chirp: must be at least 8, got {ns}")
    if loops < 1:
        raise ValueError(f"waveform.loops: must be at least 1, got {loops}")
    period = _chirp_period(w, ns / fs)
    order = w.get("tx_order", list(range(len(tx))))
    kw: dict[str, object] = dict(
        name=name, num_tx=len(tx), num_rx=len(rx),
        n_range=w.get("range_fft", next_pow2(ns)), n_doppler=w.get("doppler_fft",
                                                                    next_pow2(loops)),
        sample_rate_hz=fs, chirp_period_s=period, fc_hz=w["start_frequency_hz"],
        sweep_bandwidth_hz=w["slope_hz_per_s"] * ns / fs, adc=w.get("adc", "complex"),
        samples_per_chirp=ns, loops=loops,
        tx_order=tuple(order) if isinstance(order, list) else order,
        tx_positions=tx, rx_positions=rx, frame_period_s=w.get("frame_period_s"),
        max_speed_mps=w.get("max_speed_mps"), min_range_m=w.get("min_range_m"))
    if "adc_bits" in w:
        kw["adc_bits"] = w["adc_bits"]
    if "max_range_m" in w:
        kw["design_max_range_m"] = w["max_range_m"]
    kw.update({k: _typed(fe, k, int if k == "subarray_elements" else float, "front_end")
               for k in fe})
    cfg = with_profile_defaults(normalised(build_config(_TOML_NAMES, **kw)))
    capture = CaptureFormat(
        format=_typed(cap, "format", str, "capture") if "format" in cap else "dca1000",
        lanes=_typed(cap, "lanes", int, "capture") if "lanes" in cap else 2,
        interleaved=_typed(cap, "interleaved", bool, "capture") if "interleaved" in cap
        else False)
    return Profile(config=cfg, capture=capture, source=source)


def with_profile_defaults(cfg: RadarConfig) -> RadarConfig:
    """``cfg`` with the defaults a TOML or ``.cfg`` profile gets where it states none
    (docs/profiles.md): ``max_speed_mps`` its unambiguous speed, ``min_range_m``
    :func:`default_min_range_m`."""
    return replace(cfg, max_speed_mps=cfg.max_velocity_mps if cfg.max_speed_mps is None
                   else cfg.max_speed_mps, min_range_m=default_min_range_m(cfg)
                   if cfg.min_range_m is None else cfg.min_range_m)


def _chirp_period(w: dict, sampled_s: float) -> float:
    """Chirp period from ``chirp_period_s`` or idle + ramp end (consistent if both), with the
    ADC window checked to lie inside the ramp."""
    idle, ramp = w.get("idle_time_s"), w.get("ramp_end_time_s")
    if (idle is None) != (ramp is None):
        raise ValueError("waveform.idle_time_s: give idle_time_s and ramp_end_time_s together")
    if idle is None and "chirp_period_s" not in w:
        raise ValueError("waveform.chirp_period_s: missing (or give idle_time_s and "
                         "ramp_end_time_s)")
    if idle is not None:
        end = w.get("adc_start_time_s", 0.0) + sampled_s
        if end > ramp * (1 + 1e-9):
            raise ValueError(f"waveform.ramp_end_time_s: {ramp * 1e6:.3f} us ends before the "
                             f"ADC window (adc_start_time_s + samples_per_chirp / "
                             f"sample_rate_hz = {end * 1e6:.3f} us)")
        if "chirp_period_s" in w and not math.isclose(w["chirp_period_s"], idle + ramp,
                                                      rel_tol=1e-9):
            raise ValueError(f"waveform.chirp_period_s: {w['chirp_period_s']} s contradicts "
                             f"idle_time_s + ramp_end_time_s = {idle + ramp} s")
        return idle + ramp
    return w["chirp_period_s"]


def normalised(cfg: RadarConfig) -> RadarConfig:
    """``cfg`` with each profile field that equals its default (the presets' behaviour) set
    to None, so equal radars compare equal however they were written."""
    ch: dict[str, object] = {}
    if cfg.samples_per_chirp == cfg.n_range:
        ch["samples_per_chirp"] = None
    if cfg.loops == cfg.n_doppler:
        ch["loops"] = None
    if cfg.tx_order is not None and tuple(cfg.tx_order) == tuple(range(cfg.num_tx)):
        ch["tx_order"] = None
    default = replace(cfg, tx_positions=None, rx_positions=None)
    if cfg.tx_positions is not None and (cfg.tx_positions_hw == default.tx_positions_hw).all():
        ch["tx_positions"] = None
    if cfg.rx_positions is not None and (cfg.rx_positions_hw == default.rx_positions_hw).all():
        ch["rx_positions"] = None
    return replace(cfg, **ch) if ch else cfg


def _num(x: float | int) -> str:
    """A TOML number that reads back to the same float."""
    return repr(int(x)) if isinstance(x, int) else repr(float(x))


def profile_to_toml(profile: Profile) -> str:
    """The TOML profile of ``profile`` (the calibration is not part of a TOML profile); it
    reads back (:func:`profile_from_toml`) to the same radar up to float rounding of the
    slope."""
    cfg, cap = profile.config, profile.capture
    pos = lambda a: "[" + ", ".join(f"[{_num(h)}, {_num(v)}]" for h, v in a) + "]"  # noqa: E731
    lines = [f'name = "{cfg.name}"', "", "[waveform]",
             f"start_frequency_hz = {_num(cfg.fc_hz)}",
             f"slope_hz_per_s = {_num(cfg.slope_hz_per_s)}",
             f"sample_rate_hz = {_num(cfg.sample_rate_hz)}",
             f"samples_per_chirp = {cfg.n_samples}", f"range_fft = {cfg.n_range}",
             f"chirp_period_s = {_num(cfg.chirp_period_s)}", f"loops = {cfg.n_loops}",
             f"doppler_fft = {cfg.n_doppler}",
             f"tx_order = [{', '.join(map(str, cfg.tx_sequence))}]", f'adc = "{cfg.adc}"',
             f"adc_bits = {cfg.adc_bits}", f"max_range_m = {_num(cfg.design_max_range_m)}"]
    if cfg.frame_period_s is not None:
        lines.append(f"frame_period_s = {_num(cfg.frame_period_s)}")
    if cfg.max_speed_mps is not None:
        lines.append(f"max_speed_mps = {_num(cfg.max_speed_mps)}")
    if cfg.min_range_m is not None:
        lines.append(f"min_range_m = {_num(cfg.min_range_m)}")
    lines += ["", "[array]", f"tx = {pos(cfg.tx_positions_hw.tolist())}",
              f"rx = {pos(cfg.rx_positions_hw.tolist())}", "", "[capture]",
              f'format = "{cap.format}"', f"lanes = {cap.lanes}",
              f"interleaved = {str(cap.interleaved).lower()}", "", "[front_end]"]
    defaults = {f.name: f.default for f in fields(RadarConfig)}
    lines += [f"{k} = {_num(getattr(cfg, k))}" for k in _FRONT_END
              if getattr(cfg, k) != defaults[k]]
    return "\n".join(lines) + "\n"


# ---- any source -----------------------------------------------------------------------------
def preset_profile(name: str) -> Profile:
    """The preset ``name`` as a profile: its RadarConfig unchanged, ``npy`` captures (what the
    simulator writes)."""
    return Profile(config=PRESETS[name], capture=CaptureFormat(), source=name)


def load_profile(spec: str | Path) -> Profile:
    """A preset name, a ``.toml`` profile or a TI ``.cfg`` file; ValueError (one line) on an
    unknown name, a missing file or a bad field."""
    text_spec = str(spec)
    if text_spec in PRESETS:
        return preset_profile(text_spec)
    path = Path(text_spec)
    if path.suffix not in (".toml", ".cfg"):
        raise ValueError(f"radar: {text_spec!r} is neither a preset ({', '.join(PRESETS)}) "
                         f"nor a .toml profile nor a TI .cfg file")
    if not path.is_file():
        raise ValueError(f"radar: no such file {text_spec!r}")
    try:
        text = path.read_text()
    except UnicodeDecodeError:
        raise ValueError(f"{path}: not a text file") from None
    if path.suffix == ".toml":
        return profile_from_toml(text, str(path))
    from model.ti_cfg import profile_from_cfg
    return profile_from_cfg(text, str(path))
