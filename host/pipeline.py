"""Host processing of one frame: radar cube -> detections -> angles -> point cloud.

Steps (DESIGN.md section 1, host side):

1. Detection on the range-Doppler map: 2-D CA-CFAR (default) or OS-CFAR on the map
   integrated non-coherently over all virtual channels, or the paper's threshold on channel
   0; peak grouping keeps local maxima; only ``RadarConfig.detection_bins`` are reported
   (the top range bins are negative beat frequencies), and cells within
   ``sidelobe_margin_db`` of a stronger cell's window sidelobes are dropped.
2. Range and Doppler refined by log-parabolic (Gaussian) interpolation around each peak.
3. TDM Doppler phase compensation per TX slot, with velocity unfolding. The measured
   Doppler fixes the velocity only modulo the alias period 2 vmax: the hypotheses are
   v + 2 m vmax for every integer m with |v + 2 m vmax| <= ``max_speed_mps`` (the fastest
   radial speed the application expects, default 100 m/s). With num_tx > 1 the TDM phase
   test separates hypotheses whose m differ modulo num_tx (compensation for the wrong one
   blurs the angle spectrum); hypotheses m and m + num_tx are indistinguishable. A point is
   ``ambiguous`` when more than one hypothesis survives (always with one TX once
   ``max_speed_mps`` > vmax: paper-fpga can never unfold) or when the reported velocity is
   an unfolded one (it rests on the TDM test). The velocity reported is the surviving
   hypothesis of smallest magnitude.
4. Angle: zero-padded angle FFT with interpolated peaks, RELAX-style so several targets in
   a cell give several points (``host.angle``). The CFAR already decided that the cell holds
   a target, so its strongest component always gives a point (no second, hidden SNR gate:
   the point cloud's false-alarm rate is the CFAR's Pfa); further components must pass
   ``AngleParams.min_snr_db``.
5. Point cloud: range corrected for range-Doppler coupling, x/y, vx/vy, power, coherent
   SNR and an RCS estimate from the radar equation (``host.pointcloud``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np

from host.angle import (
    AngleParams,
    estimate_angles_batch,
    estimate_angles_fast,
    peak_power_batch,
    peak_power_fast,
)
from host.cell_kernels import fold_decisions
from host.cfar import (
    CfarParams,
    cfar_threshold,
    check_window,
    detection_mask,
    local_peaks,
    paper_threshold,
    sidelobe_masked,
)
from host.pointcloud import PointCloud
from model.config import RadarConfig, dbm_to_w
from model.reference import (
    radar_cube,
    range_doppler_power,
    signed_bin,
    signed_bins,
    tdm_phase_compensation,
)
from model.simulate import rx_gain, tx_gain

DETECTORS = ("ca", "os", "paper")
MAX_RADIAL_SPEED_MPS = 100.0
"""Default fastest radial speed the application expects, m/s (360 km/h: two cars at
180 km/h head-on). Velocities are unfolded and flagged ``ambiguous`` against it."""


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
    speed considered when unfolding and flagging ``ambiguous`` (module docstring, step 3).
    Reported range bins are ``RadarConfig.detection_bins`` (DC and negative-beat guards).
    ``sidelobe_margin_db``: a detected cell must exceed the window sidelobes of every
    stronger cell in its Doppler column and range row by this much (``host.cfar.
    sidelobe_masked``; beyond the +-2-bin main lobe); None turns the masking off.
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

    def __post_init__(self) -> None:
        if self.detector not in DETECTORS:
            raise ValueError(f"detector: must be one of {', '.join(DETECTORS)}, got "
                             f"{self.detector!r}")
        if not isinstance(self.paper_threshold_db, int | float) or not \
                0.0 <= self.paper_threshold_db <= 200.0:
            raise ValueError(f"threshold_db: must be a number of dB in [0, 200], got "
                             f"{self.paper_threshold_db!r}")
        if not isinstance(self.max_speed_mps, int | float) or not \
                0.0 < self.max_speed_mps <= 3.0e4:
            raise ValueError(f"max_speed_mps: must be in (0, 30000] m/s, got "
                             f"{self.max_speed_mps!r}")

    def check(self, cfg: RadarConfig) -> None:
        """ValueError when the settings do not fit ``cfg`` (CFAR window larger than the
        range-Doppler map)."""
        if self.detector != "paper":
            check_window(self.cfar, (cfg.n_range, cfg.n_doppler))


def _dirichlet_ratio(y: np.ndarray, n: int, sin_pi_y: np.ndarray) -> np.ndarray:
    """The real factor of the Dirichlet kernel D(y) = sum_{t<n} exp(-j 2 pi y t / n) =
    exp(-j pi y (n - 1) / n) sin(pi y) / sin(pi y / n), float like y (|y| < n; n at y = 0);
    sin_pi_y: sin(pi y), given (callers share it)."""
    den = np.sin(np.pi * y / n)
    small = np.abs(den) < 1e-12
    return np.where(small, n, sin_pi_y / np.where(small, 1.0, den))


def _window_response(n: int, offset: np.ndarray | float, windowed: bool) -> np.ndarray:
    """|W(offset)| / |W(0)|: amplitude of a tone ``offset`` bins (float (m,) or scalar) off
    a bin centre, float (m,) or scalar; W is the DFT of the periodic Hann window
    (``model.reference.hann_periodic``: 0.5 D(x) - 0.25 D(x - 1) - 0.25 D(x + 1) with the
    Dirichlet kernel D) or of the rectangular one (D). The three kernels share their phase
    up to exp(+-j phi), phi = pi (n - 1) / n, and sin(pi (x +- 1)) = -sin(pi x): |W| is
    |0.5 R(x) - 0.25 e^{j phi} R(x - 1) - 0.25 e^{-j phi} R(x + 1)| with the real factors
    R of :func:`_dirichlet_ratio` (four sines, no complex exponential)."""
    x = np.asarray(offset, dtype=float)
    s = np.sin(np.pi * x)
    r0 = _dirichlet_ratio(x, n, s)
    if not windowed:
        return np.abs(r0) / n
    rm = _dirichlet_ratio(x - 1, n, -s)
    rp = _dirichlet_ratio(x + 1, n, -s)
    phi = np.pi * (n - 1) / n
    re = 0.5 * r0 - 0.25 * np.cos(phi) * (rm + rp)
    im = 0.25 * np.sin(phi) * (rp - rm)
    return np.hypot(re, im) / (n / 2)


def gaussian_offset(lm: np.ndarray | float, c: np.ndarray | float, lp: np.ndarray | float
                    ) -> np.ndarray:
    """Offset in (-0.5, 0.5) of a peak from 3 log-power samples (Gaussian interpolation);
    element-wise over arrays, 0 where the samples do not curve down."""
    lm, c, lp = (np.asarray(v, dtype=float) for v in (lm, c, lp))
    den = lm - 2 * c + lp
    with np.errstate(divide="ignore", invalid="ignore"):
        off = np.clip(0.5 * (lm - lp) / np.where(den < 0, den, -1.0), -0.5, 0.5)
    return np.where(den < 0, off, 0.0)


def detect_cells(cube: np.ndarray, cfg: RadarConfig, params: DetectionParams
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Detected range-Doppler cells of a cube.

    cube: complex (n_virtual, n_range, n_doppler). Returns (cells int (n, 2) of
    (range_bin, doppler_bin natural order), noise float (n,) mean noise power per cell of the
    non-coherent map, nci float (n_range, n_doppler) the non-coherent map).
    """
    nci = range_doppler_power(cube)
    windowed = (params.range_window, params.doppler_window)
    cf = params.cfar if params.detector != "os" else CfarParams(
        pfa=params.cfar.pfa, guard=params.cfar.guard, train=params.cfar.train, kind="os",
        os_rank=params.cfar.os_rank)
    if params.detector == "paper":
        mask, p0 = paper_threshold(cube, params.paper_threshold_db)
        cells = local_peaks(p0, mask)
        noise_map = np.full(nci.shape, np.median(nci))
    else:
        if params.detector == "ca":
            cf = CfarParams(pfa=cf.pfa, guard=cf.guard, train=cf.train, kind="ca")
        threshold, noise_map = cfar_threshold(nci, cfg.n_virtual, cf, windowed)
        cells = local_peaks(nci, nci > threshold)
    ok = detection_mask(cfg.n_range, cfg.n_doppler, cfg.detection_bins)
    cells = cells[ok[cells[:, 0], cells[:, 1]]]
    if params.sidelobe_margin_db is not None and len(cells):
        cells = cells[~sidelobe_masked(nci, cells, windowed, params.sidelobe_margin_db)]
    return cells, noise_map[cells[:, 0], cells[:, 1]], nci


def _tdm_comp(cfg: RadarConfig, k: np.ndarray | int) -> np.ndarray:
    """TDM compensation phasors, complex (..., n_virtual), for the *unfolded* signed Doppler
    bins ``k`` (any integers, int or int (...)). ``tdm_phase_compensation`` takes
    natural-order bins and maps k >= n_doppler/2 back to k - n_doppler, which would undo an
    unfolding by +1; its phase has period num_tx * n_doppler in k, so k is shifted by that
    period instead."""
    k = np.asarray(k)
    k = np.where(k >= cfg.n_doppler // 2, k - cfg.num_tx * cfg.n_doppler, k)
    return tdm_phase_compensation(cfg, k)


def velocity_hypotheses(cfg: RadarConfig, velocity_mps: float, max_speed_mps: float
                        ) -> list[int]:
    """Alias orders m with |velocity + 2 m vmax| <= max_speed (m = 0 when none is)."""
    period = 2.0 * cfg.max_velocity_mps
    lo = int(np.ceil((-max_speed_mps - velocity_mps) / period))
    hi = int(np.floor((max_speed_mps - velocity_mps) / period))
    return list(range(lo, hi + 1)) or [0]


def _choose_fold(power: dict[int, float], cfg: RadarConfig, velocity_mps: float,
                 snr_db: float, params: DetectionParams) -> tuple[int, bool]:
    """Alias order m of a cell's velocity and whether it is ambiguous (module docstring,
    step 3). ``power``: peak angle-spectrum power of the cell's channel vector compensated
    for each alias class c = m mod num_tx (``_class_powers``; empty when the TDM test does
    not run); ``velocity_mps``: measured (aliased)."""
    hyps = velocity_hypotheses(cfg, velocity_mps, params.max_speed_mps)
    if cfg.num_tx > 1 and params.unfold_velocity and len(hyps) > 1:
        classes = sorted({m % cfg.num_tx for m in hyps})
        best = max(classes, key=power.__getitem__)
        margin = 10 ** (params.unfold_margin_db / 10)
        others = [power[c] for c in classes if c != best]
        beats_all = not others or power[best] >= margin * max(others)
        if best != 0 and not (beats_all and snr_db >= params.unfold_min_snr_db):
            best = 0 if 0 in classes else best
            beats_all = not others or power[best] >= margin * max(
                power[c] for c in classes if c != best)
        if beats_all:
            hyps = [m for m in hyps if m % cfg.num_tx == best] or hyps
    m = min(hyps, key=lambda h: abs(velocity_mps + 2.0 * h * cfg.max_velocity_mps))
    return m, len(hyps) > 1 or m != 0


def _class_powers(x: np.ndarray, cfg: RadarConfig, k: np.ndarray, n_fft: int) -> np.ndarray:
    """Peak angle-spectrum power of each cell compensated for alias class c, float
    (n, num_tx): x complex (n, n_virtual), k int (n,) signed Doppler bins (one batched FFT
    of all cells and classes)."""
    c = np.arange(cfg.num_tx)
    comp = _tdm_comp(cfg, k[:, None] + c[None, :] * cfg.n_doppler)      # (n, num_tx, n_v)
    return peak_power_batch(x[:, None, :] * comp, n_fft)


def rcs_estimate_dbsm(cfg: RadarConfig, amplitude_adc: np.ndarray, range_m: np.ndarray,
                      azimuth_deg: np.ndarray, beamforming: bool) -> np.ndarray:
    """Radar-equation inverse: RCS (dBsm) from the ADC-referred tone amplitude (LSB)."""
    pr = (np.asarray(amplitude_adc) / cfg.adc_full_scale) ** 2 * dbm_to_w(cfg.adc_full_scale_dbm)
    lam = cfg.wavelength_m
    g = dbm_to_w(cfg.tx_power_dbm) * tx_gain(cfg, azimuth_deg, beamforming) \
        * rx_gain(cfg, azimuth_deg) * lam**2
    loss = 10 ** (cfg.system_loss_db / 10)
    with np.errstate(divide="ignore"):
        sigma = pr * (4 * np.pi) ** 3 * np.asarray(range_m) ** 4 * loss / np.maximum(g, 1e-30)
        return 10 * np.log10(np.maximum(sigma, 1e-30))


def neighbour_offsets(logc: np.ndarray, lognb: np.ndarray, inner: np.ndarray) -> np.ndarray:
    """Fractional (range, Doppler) offsets of peaks from their cell centres, float (n, 2)
    in (-0.5, 0.5), by Gaussian interpolation over the 3 log-power samples along each axis;
    the range offset is 0 where ``inner`` is False (a range end). logc: float (n,) the
    cells' log powers; lognb: float (n, 4) their neighbours' at range - 1, range + 1,
    Doppler - 1, Doppler + 1 (``model.cfar_2d.NEIGHBOURS``); inner: bool (n,)."""
    dr = np.where(inner, gaussian_offset(lognb[:, 0], logc, lognb[:, 1]), 0.0)
    dd = gaussian_offset(lognb[:, 2], logc, lognb[:, 3])
    return np.stack([dr, dd], axis=1).reshape(len(logc), 2)


def peak_offsets(logp: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """:func:`neighbour_offsets` of cells on a map (Doppler circular; 0 at the range ends).
    logp: float (n_range, n_doppler) log power; cells: int (n, 2) of (range_bin,
    doppler_bin). Returns float (n, 2) bins."""
    nr, nd = logp.shape
    r, d = cells[:, 0], cells[:, 1]
    rm, rp = np.clip(r - 1, 0, nr - 1), np.clip(r + 1, 0, nr - 1)
    lognb = np.stack([logp[rm, d], logp[rp, d], logp[r, (d - 1) % nd],
                      logp[r, (d + 1) % nd]], axis=1).reshape(len(cells), 4)
    return neighbour_offsets(logp[r, d], lognb, (r > 0) & (r < nr - 1))


def points_from_cells_reference(cells: np.ndarray, snapshots: np.ndarray, power: np.ndarray,
                                noise: np.ndarray, offsets: np.ndarray, cfg: RadarConfig,
                                params: DetectionParams, frame: int = 0) -> PointCloud:
    """The implementation :func:`points_from_cells` replaced (1024-point angle FFTs of
    every cell and TDM hypothesis, per-cell Python unfolding decision); kept for the
    benchmark's old-vs-new timing and the tests. Point cloud of detected cells (steps 3 to
    5 of the module docstring), whether they come from a cube (:func:`process_cube`) or
    from the FPGA's records (``host.record_points``). Vectorised over the cells: the angle
    FFTs of all cells and TDM hypotheses run as batches.

    cells: int (n, 2) of (range_bin, doppler_bin natural order); snapshots: complex
    (n, n_virtual) the cells' Doppler-FFT values per virtual channel (cube units, LSB);
    power: float (n,) non-coherent power sum_v |x_v|^2; noise: float (n,) mean noise power
    per cell of the non-coherent map; offsets: float (n, 2) fractional (range, Doppler)
    offsets of the peak from the cell centre, bins.
    """
    n = len(cells)
    if not n:
        return PointCloud.empty()
    nd, nv = cfg.n_doppler, cfg.n_virtual
    r, d = np.asarray(cells[:, 0]), np.asarray(cells[:, 1])
    x = np.asarray(snapshots)
    noise = np.asarray(noise, dtype=float)
    dd = offsets[:, 1]
    sb = signed_bins(nd)[d].astype(np.int64)
    snr_db = cell_snr_db(power, noise, nv)
    measured = (sb + dd) * cfg.velocity_bin_mps
    # step 3: TDM hypothesis powers of every cell and class in one batch, then the decision
    class_power = (_class_powers(x, cfg, sb, params.angle.n_fft)
                   if cfg.num_tx > 1 and params.unfold_velocity else np.zeros((n, 0)))
    fold = np.zeros(n, np.int64)
    ambiguous = np.zeros(n, bool)
    for i in range(n):
        powers = {c: float(p) for c, p in enumerate(class_power[i])}
        fold[i], ambiguous[i] = _choose_fold(powers, cfg, float(measured[i]),
                                             float(snr_db[i]), params)
    k = sb + fold * nd
    # step 4: angles of the TDM-compensated channel vectors
    comps = estimate_angles_batch(x * _tdm_comp(cfg, k), noise / nv, params.angle)
    # step 5: one point per angle component
    cell = np.array([i for i, cs in enumerate(comps) for _ in cs], dtype=np.int64)
    flat = [c for cs in comps for c in cs]
    return _cloud(cfg, params, r, offsets, k, ambiguous, cell,
                  np.array([c.azimuth_deg for c in flat]),
                  np.array([c.amplitude for c in flat], dtype=complex),
                  np.array([c.snr_db for c in flat]), frame)


def cell_snr_db(power: np.ndarray, noise: np.ndarray, n_virtual: int) -> np.ndarray:
    """SNR of detected cells over the coherent sum of their channels, dB, float (n,):
    (power - noise) / noise of the non-coherent map (power, noise float (n,)) plus the
    coherent gain 10 log10(n_virtual); a zero noise estimate (noiseless input: every
    training cell 0) counts as 1e-30, as the angle estimator's noise floor."""
    noise = np.maximum(noise, 1e-30)
    return 10 * np.log10(np.maximum(power - noise, 1e-30) / noise) + 10 * np.log10(n_virtual)


def _cloud(cfg: RadarConfig, params: DetectionParams, r: np.ndarray, offsets: np.ndarray,
           k: np.ndarray, ambiguous: np.ndarray, cell: np.ndarray, az: np.ndarray,
           amplitude: np.ndarray, snr_db: np.ndarray, frame: int) -> PointCloud:
    """Step 5, one point per angle component: range (Doppler coupling removed), velocity of
    the unfolded bin ``k``, power and RCS (window scalloping and coherent gain undone).

    Per cell (n,): r range bin, k unfolded signed Doppler bin, ambiguous flag; offsets
    float (n, 2) bins. Per component (m,): ``cell`` its cell index, ``az`` deg,
    ``amplitude`` complex (LSB), ``snr_db``."""
    nr, nd = cfg.n_range, cfg.n_doppler
    dr, dd = offsets[:, 0], offsets[:, 1]
    velocity = (k + dd) * cfg.velocity_bin_mps
    # the beat frequency includes the Doppler shift 2v/lambda: remove it from the range
    coupling = 2 * velocity / cfg.wavelength_m / cfg.sample_rate_hz * nr
    range_m = (r + dr - coupling) * cfg.range_bin_m
    scallop = _window_response(nr, dr, params.range_window) * _window_response(
        nd, dd, params.doppler_window)
    cg = (0.5 if params.range_window else 1.0) * (0.5 if params.doppler_window else 1.0)
    amp = np.abs(amplitude)
    amp_adc = amp / (cg * scallop[cell])
    rcs = rcs_estimate_dbsm(cfg, amp_adc, range_m[cell], az, params.tx_beamforming)
    return PointCloud.from_polar(
        range_m[cell], az, velocity[cell], 20 * np.log10(np.maximum(amp, 1e-30)), snr_db,
        rcs, r[cell].astype(int), k[cell].astype(int), ambiguous[cell], frame=frame)


@lru_cache(maxsize=8)
def _unit_circle(n: int) -> np.ndarray:
    """exp(-2 pi j m / n) for m = 0..n-1, complex (n,), read-only."""
    w = np.exp(-2j * np.pi * np.arange(n) / n)
    w.flags.writeable = False
    return w


def _tdm_tx_phasors(cfg: RadarConfig, k: np.ndarray) -> np.ndarray:
    """:func:`_tdm_comp`'s phasors per TX, complex (..., num_tx): the phase depends on the
    channel's TX only, so one complex exponential per TX gives the same values (looked up:
    the phase k t / (n_doppler num_tx) turns is an integer multiple of one step)."""
    k = np.asarray(k)
    k = np.where(k >= cfg.n_doppler // 2, k - cfg.num_tx * cfg.n_doppler, k)
    k = signed_bin(k, cfg.n_doppler)
    n = cfg.n_doppler * cfg.num_tx
    m = np.multiply.outer(k, np.arange(cfg.num_tx))
    return _unit_circle(n)[m & (n - 1) if n & (n - 1) == 0 else m % n]   # & : mod 2^b


def _tdm_compensate(cfg: RadarConfig, x: np.ndarray, k: np.ndarray) -> np.ndarray:
    """x complex (n, n_virtual) times :func:`_tdm_comp` of k (int (n,) or (n, h)) without
    forming the per-channel phasors: complex (n, n_virtual) or (n, h, n_virtual)."""
    ph = _tdm_tx_phasors(cfg, k)                                   # (n, [h,] num_tx)
    n = len(x)
    xt = x.reshape(n, *([1] * (ph.ndim - 2)), cfg.num_tx, cfg.num_rx)
    return (xt * ph[..., None]).reshape(*ph.shape[:-1], cfg.n_virtual)


def alias_orders(cfg: RadarConfig, velocity_mps: np.ndarray, params: DetectionParams
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The velocity hypotheses of every cell: alias orders m with |v + 2 m max_velocity| <=
    max_speed_mps, as (lo, hi) int (n,), the range lo..hi of each cell (empty when lo > hi:
    the cell then takes m = 0), and ms int (h,), every order any cell may take, and 0.
    velocity_mps: float (n,) measured (aliased)."""
    v = np.asarray(velocity_mps, dtype=float)
    period = 2.0 * cfg.max_velocity_mps
    lo = np.ceil((-params.max_speed_mps - v) / period).astype(np.int64)
    hi = np.floor((params.max_speed_mps - v) / period).astype(np.int64)
    ms = np.arange(int(min(lo.min(initial=0), 0)), int(max(hi.max(initial=0), 0)) + 1)
    return lo, hi, ms


def choose_folds(class_power: np.ndarray, cfg: RadarConfig, velocity_mps: np.ndarray,
                 snr_db: np.ndarray, params: DetectionParams) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_choose_fold` of every cell at once (compiled,
    ``host.cell_kernels.fold_decisions``): (alias order int (n,), ambiguous bool (n,)).
    class_power: float (n, num_tx) (``_class_powers``; (n, 0) when the TDM test does not
    run); velocity_mps, snr_db: float (n,)."""
    v = np.asarray(velocity_mps, dtype=float)
    lo, hi, ms = alias_orders(cfg, v, params)
    test = cfg.num_tx > 1 and params.unfold_velocity and class_power.shape[1] == cfg.num_tx
    return fold_decisions(class_power if test else np.zeros((len(v), cfg.num_tx)), v,
                          np.asarray(snr_db, dtype=float), lo, hi, ms, cfg.max_velocity_mps,
                          test, 10 ** (params.unfold_margin_db / 10), params.unfold_min_snr_db)


def points_from_cells(cells: np.ndarray, snapshots: np.ndarray, power: np.ndarray,
                      noise: np.ndarray, offsets: np.ndarray, cfg: RadarConfig,
                      params: DetectionParams, frame: int = 0) -> PointCloud:
    """Point cloud of detected cells (steps 3 to 5 of the module docstring), whether they
    come from a cube (:func:`process_cube`) or from the FPGA's records
    (``host.record_points``). Vectorised over the cells: the TDM hypotheses' phasors, their
    angle peaks (coarse FFT + fine-grid search, ``host.angle.fine_peaks``, the same peaks as
    ``AngleParams.n_fft``-point FFTs), the unfolding decision (:func:`choose_folds`) and
    the angles run on all cells at once.

    cells: int (n, 2) of (range_bin, doppler_bin natural order); snapshots: complex
    (n, n_virtual) the cells' Doppler-FFT values per virtual channel (cube units, LSB);
    power: float (n,) non-coherent power sum_v |x_v|^2; noise: float (n,) mean noise power
    per cell of the non-coherent map; offsets: float (n, 2) fractional (range, Doppler)
    offsets of the peak from the cell centre, bins.
    """
    n = len(cells)
    if not n:
        return PointCloud.empty()
    nd, nv = cfg.n_doppler, cfg.n_virtual
    r, d = np.asarray(cells[:, 0]), np.asarray(cells[:, 1])
    x = np.asarray(snapshots)
    noise = np.asarray(noise, dtype=float)
    dd = offsets[:, 1]
    sb = signed_bins(nd)[d].astype(np.int64)
    snr_db = cell_snr_db(power, noise, nv)
    measured = (sb + dd) * cfg.velocity_bin_mps
    # step 3: TDM hypothesis powers of every cell and class in one batch, then the decision
    if cfg.num_tx > 1 and params.unfold_velocity:
        c = np.arange(cfg.num_tx)
        xc = _tdm_compensate(cfg, x, sb[:, None] + c[None, :] * nd)    # (n, num_tx, n_v)
        class_power, class_sin = peak_power_fast(xc, params.angle.n_fft)
    else:
        class_power = np.zeros((n, 0))
    fold, ambiguous = choose_folds(class_power, cfg, measured, snr_db, params)
    k = sb + fold * nd
    # step 4: angles of the TDM-compensated channel vectors (the phasors of k are those of
    # its class k mod num_tx n_doppler: the class's vector and peak serve)
    if class_power.shape[1]:
        rows, cls = np.arange(n), fold % cfg.num_tx
        ang = estimate_angles_fast(xc[rows, cls], noise / nv, params.angle,
                                   first_sin=class_sin[rows, cls])
    else:
        ang = estimate_angles_fast(_tdm_compensate(cfg, x, k), noise / nv, params.angle)
    return _cloud(cfg, params, r, offsets, k, ambiguous, ang.cell, ang.azimuth_deg,
                  ang.amplitude, ang.snr_db, frame)


def process_cube(cube: np.ndarray, cfg: RadarConfig, params: DetectionParams | None = None,
                 frame: int = 0, reference: bool = False) -> PointCloud:
    """Point cloud of one radar cube, complex (n_virtual, n_range, n_doppler) (LSB units).
    ``reference``: through :func:`points_from_cells_reference` (benchmark comparison)."""
    return process_cube_nci(cube, cfg, params, frame, reference)[0]


def process_cube_nci(cube: np.ndarray, cfg: RadarConfig, params: DetectionParams | None = None,
                     frame: int = 0, reference: bool = False
                     ) -> tuple[PointCloud, np.ndarray]:
    """:func:`process_cube` that also returns the integrated power map it computed, float
    (n_range, n_doppler), LSB^2 (a display needs it; computing it again costs a cube pass)."""
    params = params or DetectionParams()
    cfg.check_cube(cube)
    dtype = np.asarray(cube).dtype
    if dtype.kind != "c":
        raise ValueError(f"cube: must be complex (Doppler FFT values), got dtype {dtype}")
    cells, noise, nci = detect_cells(cube, cfg, params)
    if not np.isfinite(nci).all():         # NaN / inf anywhere in the cube reach the map
        raise ValueError("cube: contains NaN or infinite values")
    offsets = peak_offsets(np.log(np.maximum(nci, 1e-30)), cells)
    r, d = cells[:, 0], cells[:, 1]
    fn = points_from_cells_reference if reference else points_from_cells
    return fn(cells, cube[:, r, d].T, nci[r, d], noise, offsets, cfg, params, frame), nci


def process_frame(adc: np.ndarray, cfg: RadarConfig, params: DetectionParams | None = None,
                  frame: int = 0) -> PointCloud:
    """ADC frame, complex (n_chirps, num_rx, n_range) -> point cloud, through the float
    reference of the FPGA chain (``model.reference.radar_cube``) and :func:`process_cube`."""
    params = params or DetectionParams()
    cube = radar_cube(adc, cfg, params.range_window, params.doppler_window)
    return process_cube(cube, cfg, params, frame)
