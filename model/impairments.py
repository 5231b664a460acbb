"""Real-world effects the simulator can add to a radar (docs/profiles.md, "Real-world effects
in the simulator"): what a real board has and the ideal simulator does not.

Each effect is off by default and switched on by its field of :class:`Impairments` (the scene
JSON's ``"impairments"`` table); ``model.simulate.simulate_frame`` applies them in the order
of the signal path:

1. static clutter (``walls``, ``ground``): extra scatterers at zero radial velocity (a static
   radar), echoes like any target's (radar equation, azimuth-only antenna patterns);
2. TX-RX leakage (``leakage_dbfs``, ``leakage_range_m``): a tone at the beat frequency of
   ``leakage_range_m``, complex amplitude ``full_scale * 10**(leakage_dbfs / 20)`` with a
   fixed random phase per (TX, RX) pair, identical in every chirp of that TX;
3. per-channel gain / phase errors (``tx_*``, ``rx_*``): echoes, clutter and leakage of chirp
   c at RX r are multiplied by g_tx(tx of c) * g_rx(r), g = 10**(gain_db / 20) exp(j phase);
   explicit per-channel lists, or Gaussian draws of the given rms (dB, deg); thermal noise
   keeps its level (it is referred to the ADC);
4. phase noise (``phase_noise_rms_deg``, ``phase_noise_bandwidth_hz``): the IF of every
   echo is multiplied by exp(j phi(t)), phi a stationary first-order Gauss-Markov process
   (a PLL-locked oscillator's phase error: rms ``phase_noise_rms_deg``, Lorentzian spectrum
   of 3 dB bandwidth B, correlation time 1 / (2 pi B)) evaluated at every sample time of the
   frame, common to all RX (one LO) and to every echo. ``phase_noise_rms_deg`` is the IF's
   residual phase noise: the range correlation that makes it smaller for nearer echoes
   (phi(t) - phi(t - tau)) is not modelled, so give the rms of the ranges of interest;
   leakage and near clutter get the same (a worst case). Frames are independent;
5. thermal noise (``Scene.noise``);
6. I/Q imbalance (``iq_gain_db``, ``iq_phase_deg``; complex ADC only): I' = I,
   Q' = g (Q cos(phi) - I sin(phi)), i.e. y = mu x + nu conj(x) with mu = (1 + g e^{-j phi}) / 2,
   nu = (1 - g e^{j phi}) / 2: each tone gets an image at the mirror frequency (range bin
   n_range - k), |nu|^2 / |mu|^2 below it (:func:`image_rejection_db`);
7. DC offset (``dc_offset_dbfs``): a constant per RX of magnitude
   ``full_scale * 10**(dc_offset_dbfs / 20)``, fixed random phase (complex ADC) or sign (real).

Fixed draws (channel errors, leakage and DC phases, clutter positions: the hardware and the
room) come from the seed sequence (``seed``, stream), the same in every frame; the phase noise
of a frame comes from the frame's noise generator. A real ADC samples the real part of the
complex IF after step 4 (``model.simulate``).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import MISSING, asdict, dataclass, fields
from typing import Any

import numpy as np
from scipy.signal import lfilter

from model.config import RadarConfig
from model.json_fields import check_keys, integer, number

MAX_SEED = 2**63 - 1
"""Largest impairments seed."""
MAX_CLUTTER_SCATTERERS = 1024
"""Scatterers per wall or ground patch."""
_STREAMS = {"tx_gain_db": 1, "tx_phase_deg": 2, "rx_gain_db": 3, "rx_phase_deg": 4,
            "leakage": 5, "dc_offset": 6, "ground": 7, "walls": 8}
"""Seed-sequence stream of each fixed draw (one effect switched on leaves the others' draws
as they were)."""


def _check(value: object, name: str, lo: float, hi: float) -> None:
    if isinstance(value, bool) or not isinstance(value, int | float) or \
            not math.isfinite(value) or not lo <= value <= hi:
        raise ValueError(f"{name}: must be a number in [{lo:g}, {hi:g}], got {value!r}")


def _count(value: object, name: str, hi: int) -> None:
    if isinstance(value, bool) or not isinstance(value, int) or not 1 <= value <= hi:
        raise ValueError(f"{name}: must be an integer in 1..{hi}, got {value!r}")


@dataclass(frozen=True)
class Wall:
    """A static wall: a vertical segment from (x1_m, y1_m) to (x2_m, y2_m) (m, radar frame, in
    the radar's horizontal plane), ``n_scatterers`` points spread uniformly along it sharing
    ``rcs_m2`` (exponential weights, as an object's)."""

    x1_m: float
    y1_m: float
    x2_m: float
    y2_m: float
    rcs_m2: float
    n_scatterers: int = 32

    def __post_init__(self) -> None:
        for name in ("x1_m", "x2_m"):
            _check(getattr(self, name), name, 0.01, 1e4)
        for name in ("y1_m", "y2_m"):
            _check(getattr(self, name), name, -1e4, 1e4)
        _check(self.rcs_m2, "rcs_m2", 1e-9, 1e6)
        _count(self.n_scatterers, "n_scatterers", MAX_CLUTTER_SCATTERERS)
        if (self.x1_m, self.y1_m) == (self.x2_m, self.y2_m):
            raise ValueError("x2_m/y2_m: the wall's two ends coincide")

    def points(self, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(x, y, z) m of its scatterers, float (n_scatterers,) each."""
        t = rng.random(self.n_scatterers)
        x = self.x1_m + t * (self.x2_m - self.x1_m)
        y = self.y1_m + t * (self.y2_m - self.y1_m)
        return x, y, np.zeros_like(x)


@dataclass(frozen=True)
class Ground:
    """Ground clutter: the radar ``height_m`` above flat ground; ``n_scatterers`` points spread
    uniformly over the area between ``min_range_m`` and ``max_range_m`` (slant range) within
    +-``max_azimuth_deg``, below the radar (elevation -asin(height / range)), sharing
    ``rcs_m2``."""

    height_m: float
    rcs_m2: float
    min_range_m: float
    max_range_m: float
    max_azimuth_deg: float = 60.0
    n_scatterers: int = 64

    def __post_init__(self) -> None:
        _check(self.height_m, "height_m", 0.01, 100.0)
        _check(self.rcs_m2, "rcs_m2", 1e-9, 1e6)
        _check(self.min_range_m, "min_range_m", 0.0, 1e4)
        _check(self.max_range_m, "max_range_m", 0.0, 1e4)
        _check(self.max_azimuth_deg, "max_azimuth_deg", 0.1, 89.0)
        _count(self.n_scatterers, "n_scatterers", MAX_CLUTTER_SCATTERERS)
        if self.min_range_m <= self.height_m:
            raise ValueError(f"min_range_m: must exceed height_m {self.height_m:g} m (the "
                             f"ground starts below the radar), got {self.min_range_m:g}")
        if self.max_range_m <= self.min_range_m:
            raise ValueError(f"max_range_m: must exceed min_range_m {self.min_range_m:g}, got "
                             f"{self.max_range_m:g}")

    def points(self, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(x, y, z) m of its scatterers, float (n_scatterers,) each (uniform in area)."""
        g_lo = math.sqrt(self.min_range_m**2 - self.height_m**2)
        g_hi = math.sqrt(self.max_range_m**2 - self.height_m**2)
        g = np.sqrt(g_lo**2 + rng.random(self.n_scatterers) * (g_hi**2 - g_lo**2))
        az = np.radians(self.max_azimuth_deg) * (2.0 * rng.random(self.n_scatterers) - 1.0)
        return g * np.cos(az), g * np.sin(az), np.full(self.n_scatterers, -self.height_m)


CHANNEL_LISTS = ("tx_gain_db", "tx_phase_deg", "rx_gain_db", "rx_phase_deg")
"""Explicit per-channel error lists; each has an rms alternative ``<name with _rms>``."""


def _rms_name(name: str) -> str:
    return name.replace("_db", "_rms_db").replace("_deg", "_rms_deg")


@dataclass(frozen=True)
class Impairments:
    """The real-world effects of one simulated radar, all off by default (module docstring:
    the physics and order of each). ``seed`` fixes the hardware's and the room's draws."""

    seed: int = 0
    tx_gain_rms_db: float = 0.0
    tx_phase_rms_deg: float = 0.0
    rx_gain_rms_db: float = 0.0
    rx_phase_rms_deg: float = 0.0
    tx_gain_db: tuple[float, ...] | None = None
    tx_phase_deg: tuple[float, ...] | None = None
    rx_gain_db: tuple[float, ...] | None = None
    rx_phase_deg: tuple[float, ...] | None = None
    leakage_dbfs: float | None = None
    leakage_range_m: float = 0.1
    dc_offset_dbfs: float | None = None
    iq_gain_db: float = 0.0
    iq_phase_deg: float = 0.0
    phase_noise_rms_deg: float = 0.0
    phase_noise_bandwidth_hz: float = 1e6
    walls: tuple[Wall, ...] = ()
    ground: Ground | None = None

    def __post_init__(self) -> None:
        if isinstance(self.seed, bool) or not isinstance(self.seed, int) or \
                not 0 <= self.seed <= MAX_SEED:
            raise ValueError(f"seed: must be an integer in 0..2**63-1, got {self.seed!r}")
        for name in CHANNEL_LISTS:
            rms = _rms_name(name)
            _check(getattr(self, rms), rms, 0.0, 10.0 if name.endswith("_db") else 180.0)
            values = getattr(self, name)
            if values is None:
                continue
            if not isinstance(values, tuple | list) or not values:
                raise ValueError(f"{name}: must be a list of numbers, one per channel, "
                                 f"got {values!r}")
            for i, x in enumerate(values):
                _check(x, f"{name}[{i}]", -40.0 if name.endswith("_db") else -360.0,
                       40.0 if name.endswith("_db") else 360.0)
            if getattr(self, rms):
                raise ValueError(f"{name}: give the list or {rms}, not both")
            object.__setattr__(self, name, tuple(values))
        for name in ("leakage_dbfs", "dc_offset_dbfs"):
            if getattr(self, name) is not None:
                _check(getattr(self, name), name, -200.0, 0.0)
        _check(self.leakage_range_m, "leakage_range_m", 1e-3, 10.0)
        _check(self.iq_gain_db, "iq_gain_db", -6.0, 6.0)
        _check(self.iq_phase_deg, "iq_phase_deg", -30.0, 30.0)
        _check(self.phase_noise_rms_deg, "phase_noise_rms_deg", 0.0, 90.0)
        _check(self.phase_noise_bandwidth_hz, "phase_noise_bandwidth_hz", 1e3, 1e9)
        if not isinstance(self.walls, tuple | list) or not all(isinstance(w, Wall)
                                                                for w in self.walls):
            raise ValueError(f"walls: must be a list of Wall, got {self.walls!r}")
        object.__setattr__(self, "walls", tuple(self.walls))
        if self.ground is not None and not isinstance(self.ground, Ground):
            raise ValueError(f"ground: must be a Ground, got {self.ground!r}")

    # ---- which effects are on ------------------------------------------------------------
    @property
    def channel_errors(self) -> bool:
        """Any per-channel gain or phase error."""
        return any(getattr(self, n) is not None or getattr(self, _rms_name(n))
                   for n in CHANNEL_LISTS)

    @property
    def iq_imbalance(self) -> bool:
        """An I/Q gain or phase imbalance."""
        return bool(self.iq_gain_db or self.iq_phase_deg)

    @property
    def clutter(self) -> bool:
        """Any wall or ground clutter."""
        return bool(self.walls) or self.ground is not None

    def check(self, cfg: RadarConfig) -> None:
        """ValueError naming the field that does not fit radar ``cfg``: a channel list of the
        wrong length, I/Q imbalance with a real ADC, leakage beyond the IF band."""
        for name in CHANNEL_LISTS:
            values = getattr(self, name)
            n = cfg.num_tx if name.startswith("tx") else cfg.num_rx
            if values is not None and len(values) != n:
                raise ValueError(f"{name}: {len(values)} values for the {n} "
                                 f"{name[:2].upper()} of radar {cfg.name!r}")
        if self.iq_imbalance and cfg.adc != "complex":
            raise ValueError(f"iq_gain_db/iq_phase_deg: I/Q imbalance needs a complex ADC; "
                             f"radar {cfg.name!r} has a real one")
        if self.leakage_dbfs is not None and \
                cfg.beat_frequency_hz(self.leakage_range_m) >= cfg.if_bandwidth_hz:
            raise ValueError(f"leakage_range_m: {self.leakage_range_m:g} m is beyond radar "
                             f"{cfg.name!r}'s maximum range {cfg.max_range_m:g} m")

    # ---- the fixed draws -----------------------------------------------------------------
    def _rng(self, stream: str) -> np.random.Generator:
        return np.random.default_rng([self.seed, _STREAMS[stream]])

    def _errors(self, name: str, n: int) -> np.ndarray:
        values = getattr(self, name)
        if values is not None:
            return np.asarray(values, dtype=float)
        return getattr(self, _rms_name(name)) * self._rng(name).standard_normal(n)

    def channel_gains(self, cfg: RadarConfig) -> tuple[np.ndarray, np.ndarray]:
        """Complex gain of each TX and each RX, complex128 (num_tx,), (num_rx,):
        10**(gain_db / 20) exp(j phase)."""
        return tuple(10.0 ** (self._errors(f"{k}_gain_db", n) / 20.0)  # type: ignore[return-value]
                     * np.exp(1j * np.radians(self._errors(f"{k}_phase_deg", n)))
                     for k, n in (("tx", cfg.num_tx), ("rx", cfg.num_rx)))

    def leakage_amplitudes(self, cfg: RadarConfig) -> np.ndarray:
        """Complex amplitude (ADC codes) of the leakage tone per (TX, RX), complex128
        (num_tx, num_rx): the ``leakage_dbfs`` level, a fixed random phase each."""
        assert self.leakage_dbfs is not None
        phase = 2.0 * np.pi * self._rng("leakage").random((cfg.num_tx, cfg.num_rx))
        return cfg.adc_full_scale * 10.0 ** (self.leakage_dbfs / 20.0) * np.exp(1j * phase)

    def dc_offsets(self, cfg: RadarConfig) -> np.ndarray:
        """DC offset per RX in ADC codes, (num_rx,): complex128 of the ``dc_offset_dbfs``
        magnitude and a random phase, or for a real ADC float64 of a random sign."""
        assert self.dc_offset_dbfs is not None
        level = cfg.adc_full_scale * 10.0 ** (self.dc_offset_dbfs / 20.0)
        u = self._rng("dc_offset").random(cfg.num_rx)
        if cfg.adc == "real":
            return level * np.where(u < 0.5, -1.0, 1.0)
        return level * np.exp(2j * np.pi * u)

    def clutter_points(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The static clutter scatterers (walls, then the ground): range_m, azimuth_deg,
        elevation_deg, rcs_m2, float (n,) each."""
        rng_w = self._rng("walls")
        groups: list[tuple[Wall | Ground, np.random.Generator]] = [(w, rng_w) for w in self.walls]
        if self.ground is not None:
            groups.append((self.ground, self._rng("ground")))
        cols = []
        for item, rng in groups:
            x, y, z = item.points(rng)
            weights = rng.exponential(size=item.n_scatterers)
            r = np.sqrt(x * x + y * y + z * z)
            cols.append(np.stack([r, np.degrees(np.arctan2(y, x)), np.degrees(np.arcsin(z / r)),
                                  item.rcs_m2 * weights / weights.sum()]))
        a = np.concatenate(cols, axis=1) if cols else np.zeros((4, 0))
        return a[0], a[1], a[2], a[3]

    # ---- JSON ----------------------------------------------------------------------------
    @classmethod
    def from_dict(cls, d: Mapping[str, Any], where: str = "impairments") -> Impairments:
        """The impairments table of the scene JSON; ValueError naming ``where.field``."""
        names = {f.name for f in fields(cls)}
        check_keys(d, names, where)
        kw: dict[str, Any] = {"seed": integer(d, "seed", where, 0, 0, MAX_SEED)}
        for name in names - {"seed", "walls", "ground", *CHANNEL_LISTS}:
            if name in d and not (name in ("leakage_dbfs", "dc_offset_dbfs") and d[name] is None):
                kw[name] = number(d, name, where)
        for name in CHANNEL_LISTS:
            if d.get(name) is not None:
                if not isinstance(d[name], list):
                    raise ValueError(f"{where}.{name}: must be a list of numbers, one per "
                                     f"channel, got {d[name]!r}")
                kw[name] = tuple(number({name: x}, name, f"{where}.{name}[{i}]")
                                 for i, x in enumerate(d[name]))
        walls = d.get("walls", [])
        if not isinstance(walls, list):
            raise ValueError(f"{where}.walls: must be a list")
        kw["walls"] = tuple(_item(Wall, w, f"{where}.walls[{i}]") for i, w in enumerate(walls))
        if d.get("ground") is not None:
            kw["ground"] = _item(Ground, d["ground"], f"{where}.ground")
        try:
            return cls(**kw)
        except ValueError as exc:
            raise ValueError(f"{where}.{exc}") from None

    def to_dict(self) -> dict[str, Any]:
        """The JSON table: the fields that differ from the defaults (lists as lists)."""
        out: dict[str, Any] = {}
        for f in fields(self):
            value = getattr(self, f.name)
            if value == f.default:
                continue
            if f.name == "walls":
                value = [asdict(w) for w in value]
            elif f.name == "ground":
                value = asdict(value)
            elif isinstance(value, tuple):
                value = list(value)
            out[f.name] = value
        return out


def _item(kind: type, d: object, where: str) -> Any:
    """A Wall or Ground from its JSON object."""
    if not isinstance(d, Mapping):
        raise ValueError(f"{where}: must be a JSON object, got {type(d).__name__}")
    check_keys(d, {f.name for f in fields(kind)}, where)
    kw: dict[str, Any] = {}
    for f in fields(kind):
        if f.name == "n_scatterers":
            kw[f.name] = integer(d, f.name, where, f.default, 1, MAX_CLUTTER_SCATTERERS)
        elif f.name in d or f.default is MISSING:
            kw[f.name] = number(d, f.name, where)
    try:
        return kind(**kw)
    except ValueError as exc:
        raise ValueError(f"{where}.{exc}") from None


NO_IMPAIRMENTS = Impairments()
"""The ideal radar."""


def image_rejection_db(gain_db: float, phase_deg: float) -> float:
    """Image rejection of an I/Q imbalance, |mu|^2 / |nu|^2 in dB:
    (1 + g^2 + 2 g cos(phi)) / (1 + g^2 - 2 g cos(phi)), g = 10**(gain_db / 20) (inf when
    balanced)."""
    g, c = 10.0 ** (gain_db / 20.0), math.cos(math.radians(phase_deg))
    image = 1.0 + g * g - 2.0 * g * c
    return math.inf if image <= 0.0 else 10.0 * math.log10((1.0 + g * g + 2.0 * g * c) / image)


def apply_iq_imbalance(x: np.ndarray, gain_db: float, phase_deg: float) -> np.ndarray:
    """I' = I, Q' = g (Q cos(phi) - I sin(phi)) of complex ``x`` (any shape), complex128."""
    g, phi = 10.0 ** (gain_db / 20.0), math.radians(phase_deg)
    return x.real + 1j * g * (x.imag * math.cos(phi) - x.real * math.sin(phi))


def phase_noise_rad(imp: Impairments, cfg: RadarConfig, rng: np.random.Generator
                    ) -> np.ndarray:
    """One frame's phase noise at every ADC sample, float64 (n_chirps, n_samples), rad.

    A first-order Gauss-Markov process of rms ``phase_noise_rms_deg`` and 3 dB bandwidth
    ``phase_noise_bandwidth_hz`` (phi[k+1] = a phi[k] + sqrt(1 - a^2) sigma xi, a =
    exp(-2 pi B / fs)) on the 1/fs grid of the frame's chirps; chirp c starts at grid
    point round(c Tc fs) (within half a sample of its start: the process is stationary).
    """
    fs = cfg.sample_rate_hz
    starts = np.rint(np.arange(cfg.n_chirps) * cfg.chirp_period_s * fs).astype(np.int64)
    length = int(starts[-1]) + cfg.n_samples
    a = math.exp(-2.0 * math.pi * imp.phase_noise_bandwidth_hz / fs)
    sigma = math.radians(imp.phase_noise_rms_deg)
    xi = rng.standard_normal(length)
    phi0 = sigma * rng.standard_normal()            # the stationary state before the frame
    phi, _ = lfilter([sigma * math.sqrt(1.0 - a * a)], [1.0, -a], xi, zi=[a * phi0])
    return phi[starts[:, None] + np.arange(cfg.n_samples)]
