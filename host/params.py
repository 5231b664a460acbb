"""Host processing settings (``host.pipeline``, ``host.record_points``)."""

from __future__ import annotations

from dataclasses import dataclass, field

from host.angle import AngleParams
from host.calibration import check_calibration
from host.cfar import CfarParams, check_window
from host.refine import FLOAT_FLOOR
from model.config import RadarConfig
from model.profile import Calibration
from model.reference import fft_axes

DETECTORS = ("ca", "os", "paper")
GROUPINGS = ("peak", "doppler")
"""Peak grouping of detected cells (:class:`DetectionParams` ``grouping``)."""
MAX_RADIAL_SPEED_MPS = 100.0
"""Default fastest radial speed the application expects, m/s (360 km/h: two cars at
180 km/h head-on). Velocities are unfolded and flagged ``ambiguous`` against it."""


def default_guard(cfg: RadarConfig) -> tuple[int, int]:
    """CFAR guard cells per side (range, Doppler) for ``cfg`` when the user gives none: the
    Hann main lobe of each axis, (2, 2) unpadded (``model.reference.FftAxis.main_lobe_bins``;
    a zero-padded axis' lobe is wider)."""
    ax_r, ax_d = fft_axes(cfg)
    return ax_r.main_lobe_bins, ax_d.main_lobe_bins


def params_for(cfg: RadarConfig) -> DetectionParams:
    """The default settings for ``cfg``: :class:`DetectionParams` () with the CFAR guard
    of :func:`default_guard` (the presets': the defaults unchanged)."""
    return DetectionParams(cfar=CfarParams(guard=default_guard(cfg)))


def default_max_speed_mps(cfg: RadarConfig) -> float:
    """The fastest radial speed to expect for ``cfg`` when the user gives none, m/s: the
    profile's ``max_speed_mps`` (a TOML or ``.cfg`` profile: its unambiguous speed unless it
    states one, ``model.profile``), else (the presets) :data:`MAX_RADIAL_SPEED_MPS`."""
    return MAX_RADIAL_SPEED_MPS if cfg.max_speed_mps is None else cfg.max_speed_mps


@dataclass(frozen=True)
class DetectionParams:
    """Host processing settings.

    ``detector``: ``ca`` / ``os`` CFAR on the non-coherent map, or ``paper`` (threshold
    ``paper_threshold_db`` above the median of channel 0's map). ``cfar``: window and Pfa.
    ``range_window``/``doppler_window``: whether the FPGA chain applied Hann windows (for the
    CFAR cell correlation, scalloping and RCS corrections). ``tx_beamforming``: TX gain
    model used for the RCS estimate. ``unfold_velocity``: TDM Doppler hypothesis test.
    ``unfold_min_snr_db`` / ``unfold_margin_db``: a hypothesis other than the aliased one
    wins only in cells at least this strong and by at least this margin; the aliased one
    excludes the others when it beats them by the margin. ``max_speed_mps``: fastest radial
    speed considered when unfolding and flagging ``ambiguous`` (``host.pipeline`` module
    docstring, step 3; ``host.tdm``).
    Reported range bins are ``RadarConfig.detection_bins`` (DC and negative-beat guards).
    ``sidelobe_margin_db``: a detected cell must exceed the window sidelobes of every
    stronger cell in its Doppler column and range row by this much (``host.cfar.
    sidelobe_masked``; beyond the Hann main lobe); None turns the masking off.
    ``calibration``: channel gains and range bias applied to the detected cells before the
    angle estimation (``host.calibration.apply_calibration``); None: none.
    ``refine``: on the cube path, the detected cells' range and Doppler re-estimated from
    the whole frame (``host.refine``, weighting floor ``refine_floor``); needs a
    complex-ADC radar.
    ``grouping`` (the host's detector on a cube; ``host.pipeline.detect_cells``): ``peak``
    keeps the cells that are the maximum of their 3 x 3 range-Doppler neighbourhood (one
    detection per peak of the map); ``doppler`` those that are the maximum of their 3
    Doppler neighbours in the same range bin (one per range bin of a return that spans
    several: a person, a car's body; OpenRadar's ``peak_grouping_along_doppler``).
    ``min_snr_db``: a detected cell must also be this far above its detector's noise
    estimate (the map's cell power over the mean noise power per cell: the mean SNR per
    channel, which a threshold in dB such as OpenRadar's tests); None: the detector's
    threshold alone (a CFAR's: its Pfa).
    ``static_removed``: the cube's static clutter was removed (``radar process|detect
    --remove-static``): its zero-Doppler bin is empty and its neighbours' noise lowered
    (``host.cube.static_noise_gain``), so the CFAR leaves bin 0 out and rescales the
    touched bins to plain noise, or their training cells would pull the noise estimate of
    the cells beside zero Doppler down (there 2.6 times the configured Pfa of 1e-3 and 3.7
    times 1e-4 on noise, CA; ``tests/test_static_cfar.py``).
    """

    detector: str = "ca"
    cfar: CfarParams = field(default_factory=CfarParams)
    paper_threshold_db: float = 15.0
    angle: AngleParams = field(default_factory=AngleParams)
    range_window: bool = True
    doppler_window: bool = True
    tx_beamforming: bool = True
    unfold_velocity: bool = True
    unfold_min_snr_db: float = 30.0
    unfold_margin_db: float = 0.45
    max_speed_mps: float = MAX_RADIAL_SPEED_MPS
    sidelobe_margin_db: float | None = 10.0
    calibration: Calibration | None = None
    refine: bool = False
    refine_floor: float = FLOAT_FLOOR
    grouping: str = "peak"
    min_snr_db: float | None = None
    static_removed: bool = False

    def __post_init__(self) -> None:
        if self.detector not in DETECTORS:
            raise ValueError(f"detector: must be one of {', '.join(DETECTORS)}, got "
                             f"{self.detector!r}")
        if self.grouping not in GROUPINGS:
            raise ValueError(f"grouping: must be one of {', '.join(GROUPINGS)}, got "
                             f"{self.grouping!r}")
        if self.min_snr_db is not None and (
                isinstance(self.min_snr_db, bool) or not isinstance(self.min_snr_db, int | float)
                or not 0.0 <= self.min_snr_db <= 200.0):
            raise ValueError(f"min_snr_db: must be a number of dB in [0, 200], got "
                             f"{self.min_snr_db!r}")
        if not isinstance(self.paper_threshold_db, int | float) or not \
                0.0 <= self.paper_threshold_db <= 200.0:
            raise ValueError(f"threshold_db: must be a number of dB in [0, 200], got "
                             f"{self.paper_threshold_db!r}")
        if not isinstance(self.max_speed_mps, int | float) or not \
                0.0 < self.max_speed_mps <= 3.0e4:
            raise ValueError(f"max_speed_mps: must be in (0, 30000] m/s, got "
                             f"{self.max_speed_mps!r}")
        if not isinstance(self.refine_floor, int | float) or not \
                0.0 < self.refine_floor <= 10.0:
            raise ValueError(f"refine_floor: must be in (0, 10], got {self.refine_floor!r}")

    def check(self, cfg: RadarConfig) -> None:
        """ValueError when the settings do not fit ``cfg`` (CFAR window larger than the
        range-Doppler map, a calibration of another channel count)."""
        if self.calibration is not None:
            check_calibration(self.calibration, cfg)
        if self.refine and cfg.adc != "complex":
            raise ValueError(f"refine: needs a complex-ADC radar ({cfg.name!r} has a real ADC: "
                             "its cube keeps half the range spectrum)")
        if self.detector != "paper":
            check_window(self.cfar, (cfg.n_range_bins, cfg.n_doppler))
