"""TI mmWave SDK CLI configuration (``*.cfg``) -> :class:`model.profile.Profile`.

Read (TI mmWave SDK user guide, "Configuration (.cfg) File Format"): ``channelCfg``,
``adcCfg``, ``adcbufCfg``, ``profileCfg``, ``chirpCfg``, ``frameCfg`` and
``compRangeBiasAndRxChanPhase``; the SDK's other commands (detection, GUI and monitoring
settings, ``sensorStart`` ...) are recognised and do not change the radar. Anything else, a
command given twice, a wrong argument count or settings that contradict each other raise a
one-line ValueError naming the command. Supported: one profile, identical chirps (no
per-chirp variations), one TX per chirp (TDM), each enabled TX once per loop, legacy frames
(``dfeDataOutputMode 1``).

Array: RX ``r`` of the RX mask at (r, 0) half-wavelengths; the TXs a loop fires at (4 k, 0),
k = 0, 1, ... in the order of their TX number (the xWR16xx and the azimuth TXs of the
xWR18xx / xWR14xx boards), except when TX0, TX1 and TX2 all fire: then TX1 sits at (2, 1),
raised by half a wavelength (xWR1843BOOST / xWR1443BOOST). Another layout needs a TOML
profile. Captures: 2-lane non-interleaved DCA1000 data unless ``adcbufCfg`` asks for
interleaved channels (xWR14xx: 4 lanes, interleaved).
"""

from __future__ import annotations

from model.profile import (
    Calibration,
    CaptureFormat,
    Profile,
    build_config,
    next_pow2,
    normalised,
    sourced,
    with_profile_defaults,
)

READ = {"channelCfg": 3, "adcCfg": 2, "profileCfg": 14, "frameCfg": 7}
"""Commands read exactly once, with their argument counts."""
IGNORED = frozenset({
    "sensorStop", "sensorStart", "flushCfg", "dfeDataOutputMode", "lowPower", "guiMonitor",
    "cfarCfg", "multiObjBeamForming", "clutterRemoval", "calibDcRangeSig", "extendedMaxVelocity",
    "bpmCfg", "lvdsStreamCfg", "CQRxSatMonitor", "CQSigImgMonitor", "analogMonitor",
    "aoaFovCfg", "cfarFovCfg", "calibData", "measureRangeBiasAndRxChanPhase", "nearFieldCfg",
    "compressionCfg", "idlePowerCycleCfg", "antGeometry0", "antGeometry1", "antPhaseRot",
    "fovCfg", "staticBoundaryBox", "boundaryBox", "gatingParam", "stateParam",
    "allocationParam", "maxAcceleration", "trackingCfg", "sceneryParam", "presenceBoundaryBox",
    "mpdBoundaryBox", "sensorPosition", "clusterCfg", "RangeLimitCfg", "dynamicRACfarCfg",
    "staticRACfarCfg", "dynamicRangeAngleCfg", "dynamic2DAngleCfg", "staticRangeAngleCfg",
    "dbscanCfg", "zoneDef", "mmwavelinkCfg", "adcDataSource", "adcDataDitherCfg",
    "rangeSelCfg", "vitalSignsCfg", "motionDetection", "heatmapGenCfg", "featureExtractionCfg",
})
"""SDK and demo commands that do not describe the radar's waveform or array."""
_CFG_NAMES = {"fc_hz": "profileCfg startFreq", "sample_rate_hz": "profileCfg digOutSampleRate",
              "chirp_period_s": "profileCfg idleTime + rampEndTime",
              "sweep_bandwidth_hz": "profileCfg freqSlopeConst", "n_range":
              "profileCfg numAdcSamples", "samples_per_chirp": "profileCfg numAdcSamples",
              "loops": "frameCfg numLoops", "n_doppler": "frameCfg numLoops",
              "frame_period_s": "frameCfg framePeriodicity", "num_tx": "channelCfg txChannelEn",
              "num_rx": "channelCfg rxChannelEn", "design_max_range_m":
              "profileCfg digOutSampleRate"}
"""RadarConfig field -> the .cfg command and argument a message names."""


def _numbers(cmd: str, args: list[str]) -> list[float]:
    try:
        return [float(a) for a in args]
    except ValueError:
        raise ValueError(f"{cmd}: arguments must be numbers, got {' '.join(args)!r}") from None


def _int(cmd: str, what: str, x: float) -> int:
    if x != int(x):
        raise ValueError(f"{cmd}: {what} must be an integer, got {x:g}")
    return int(x)


def _bits(mask: int) -> list[int]:
    return [b for b in range(mask.bit_length()) if mask >> b & 1]


def parse_commands(text: str) -> tuple[dict[str, list[float]], list[list[float]]]:
    """The read commands of a .cfg (name -> numbers) and its ``chirpCfg`` lines."""
    single: dict[str, list[float]] = {}
    chirps: list[list[float]] = []
    for raw in text.splitlines():
        line = raw.split("%", 1)[0].strip()
        if not line:
            continue
        cmd, *args = line.split()
        if cmd in IGNORED:
            if cmd == "dfeDataOutputMode" and args != ["1"]:
                raise ValueError(f"dfeDataOutputMode: only 1 (legacy frames) is supported, "
                                 f"got {' '.join(args)}")
            continue
        if cmd == "chirpCfg":
            if len(args) != 8:
                raise ValueError(f"chirpCfg: expected 8 arguments, got {len(args)}")
            chirps.append(_numbers(cmd, args))
            continue
        if cmd not in READ and cmd not in ("adcbufCfg", "compRangeBiasAndRxChanPhase"):
            raise ValueError(f"{cmd}: unknown command")
        if cmd in single:
            raise ValueError(f"{cmd}: given twice")
        if cmd in READ and len(args) != READ[cmd]:
            raise ValueError(f"{cmd}: expected {READ[cmd]} arguments, got {len(args)}")
        single[cmd] = _numbers(cmd, args)
    for cmd in READ:
        if cmd not in single:
            raise ValueError(f"{cmd}: missing")
    if not chirps:
        raise ValueError("chirpCfg: missing")
    return single, chirps


def _tx_order(single: dict[str, list[float]], chirps: list[list[float]]
              ) -> tuple[list[int], int, int, int]:
    """(TX number fired in each chirp slot of a loop, profile id, loops, TX mask)."""
    rx_mask, tx_mask = (_int("channelCfg", "a mask", x) for x in single["channelCfg"][:2])
    start, end, loops = (_int("frameCfg", "an index", x) for x in single["frameCfg"][:3])
    if not 0 <= start <= end:
        raise ValueError(f"frameCfg: chirpStartIdx {start} .. chirpEndIdx {end} is empty")
    if loops < 1:
        raise ValueError(f"frameCfg: numLoops must be at least 1, got {loops}")
    slot: dict[int, tuple[int, int]] = {}
    for c in chirps:
        a, b, pid = (_int("chirpCfg", "an index", x) for x in c[:3])
        if any(c[3:7]):
            raise ValueError(f"chirpCfg: chirps {a}..{b} vary start frequency, slope, idle or "
                             f"ADC start time (per-chirp variations are not supported)")
        mask = _int("chirpCfg", "txEnable", c[7])
        if len(_bits(mask)) != 1:
            raise ValueError(f"chirpCfg: chirps {a}..{b} enable TX mask {mask}: exactly one "
                             f"TX per chirp (TDM) is supported")
        if mask & ~tx_mask:
            raise ValueError(f"chirpCfg: chirps {a}..{b} fire TX mask {mask}, not enabled "
                             f"by channelCfg txChannelEn {tx_mask}")
        for i in range(a, b + 1):
            if i in slot:
                raise ValueError(f"chirpCfg: chirp {i} configured twice")
            slot[i] = (pid, _bits(mask)[0])
    missing = [i for i in range(start, end + 1) if i not in slot]
    if missing:
        raise ValueError(f"chirpCfg: chirp {missing[0]} of frameCfg {start}..{end} is not "
                         f"configured")
    order = [slot[i][1] for i in range(start, end + 1)]
    pids = {slot[i][0] for i in range(start, end + 1)}
    if len(pids) != 1:
        raise ValueError(f"chirpCfg: the frame's chirps use profiles {sorted(pids)}; one "
                         f"profile is supported")
    if len(set(order)) != len(order):
        raise ValueError(f"chirpCfg: a TX fires twice in one loop (TX order {order}); each TX "
                         f"once per loop is supported")
    if rx_mask < 1:
        raise ValueError("channelCfg: rxChannelEn enables no RX")
    return order, pids.pop(), loops, rx_mask


def profile_from_cfg(text: str, source: str = "<cfg>") -> Profile:
    """The :class:`Profile` of a TI mmWave SDK ``.cfg`` text; ValueError ``"<source>:
    <command>: <reason>"`` on an unknown, missing, repeated or contradictory command."""
    return sourced(_profile, text, source)


def _profile(text: str, source: str) -> Profile:
    single, chirps = parse_commands(text)
    order, pid, loops, rx_mask = _tx_order(single, chirps)
    p = single["profileCfg"]
    if _int("profileCfg", "profileId", p[0]) != pid:
        raise ValueError(f"profileCfg: profileId {p[0]:g} is not the chirps' profile {pid}")
    fc_ghz, idle_us, adc_start_us, ramp_us = p[1:5]
    slope_mhz_us, n_samples, fs_ksps = p[7], _int("profileCfg", "numAdcSamples", p[9]), p[10]
    for what, x in (("startFreq", fc_ghz), ("idleTime", idle_us), ("rampEndTime", ramp_us),
                    ("freqSlopeConst", slope_mhz_us), ("digOutSampleRate", fs_ksps)):
        if x <= 0:
            raise ValueError(f"profileCfg: {what} must be positive, got {x:g}")
    if n_samples < 8:
        raise ValueError(f"profileCfg: numAdcSamples must be at least 8, got {n_samples}")
    sampled_us = n_samples / fs_ksps * 1e3
    if adc_start_us + sampled_us > ramp_us * (1 + 1e-9):
        raise ValueError(f"profileCfg: rampEndTime {ramp_us:g} us ends before the ADC window "
                         f"(adcStartTime + numAdcSamples / digOutSampleRate = "
                         f"{adc_start_us + sampled_us:g} us)")
    bits_code, fmt = (_int("adcCfg", "a code", x) for x in single["adcCfg"])
    if bits_code not in (0, 1, 2) or fmt not in (0, 1, 2):
        raise ValueError(f"adcCfg: numADCBits must be 0..2 and adcOutputFmt 0..2, got "
                         f"{bits_code} {fmt}")
    adc = "real" if fmt == 0 else "complex"
    interleaved = False
    if "adcbufCfg" in single:
        buf = [_int("adcbufCfg", "a flag", x) for x in single["adcbufCfg"]]
        if len(buf) not in (4, 5):
            raise ValueError(f"adcbufCfg: expected 4 or 5 arguments, got {len(buf)}")
        buf_fmt, interleave_flag = buf[-4], buf[-2]
        if (buf_fmt == 1) != (adc == "real"):
            kind = "real" if buf_fmt == 1 else "complex"
            raise ValueError(f"adcbufCfg: adcOutputFmt {buf_fmt} ({kind}) contradicts adcCfg "
                             f"adcOutputFmt {fmt} ({adc})")
        interleaved = interleave_flag == 0
    tx_numbers = sorted(order)
    frame_period_s = single["frameCfg"][4] * 1e-3
    rx_numbers = _bits(rx_mask)
    cfg = normalised(build_config(_CFG_NAMES, **dict(
        name=source.rsplit("/", 1)[-1].rsplit(".", 1)[0] or "cfg", num_tx=len(order),
        num_rx=len(rx_numbers), n_range=next_pow2(n_samples), n_doppler=next_pow2(loops),
        sample_rate_hz=fs_ksps * 1e3, chirp_period_s=(idle_us + ramp_us) * 1e-6,
        fc_hz=fc_ghz * 1e9, sweep_bandwidth_hz=slope_mhz_us * 1e12 * n_samples / (fs_ksps * 1e3),
        adc_bits=(12, 14, 16)[bits_code], samples_per_chirp=n_samples, loops=loops,
        tx_order=tuple(tx_numbers.index(t) for t in order), adc=adc,
        tx_positions=_tx_layout(tx_numbers), rx_positions=tuple((float(r), 0.0)
                                                                  for r in rx_numbers),
        frame_period_s=frame_period_s if frame_period_s > 0 else None)))
    cfg = with_profile_defaults(cfg)
    calibration = None
    if "compRangeBiasAndRxChanPhase" in single:
        calibration = _calibration(single["compRangeBiasAndRxChanPhase"], tx_numbers,
                                   rx_numbers)
    lanes = 4 if interleaved else 2
    return Profile(config=cfg, capture=CaptureFormat("dca1000", lanes, interleaved),
                   calibration=calibration, source=source)


def _tx_layout(tx_numbers: list[int]) -> tuple[tuple[float, float], ...]:
    """TX positions in half-wavelengths (module docstring)."""
    if tx_numbers == [0, 1, 2]:
        return ((0.0, 0.0), (2.0, 1.0), (4.0, 0.0))
    return tuple((4.0 * k, 0.0) for k in range(len(tx_numbers)))


def _calibration(values: list[float], tx_numbers: list[int], rx_numbers: list[int]
                 ) -> Calibration:
    """compRangeBiasAndRxChanPhase: range bias (m), then (re, im) per physical virtual
    channel tx * 4 + rx of the device (8 on xWR16xx, 12 on xWR14xx/18xx/68xx)."""
    pairs = len(values) - 1
    if pairs % 2 or pairs // 2 % 4 or pairs // 2 // 4 <= max(tx_numbers):
        raise ValueError(f"compRangeBiasAndRxChanPhase: expected a range bias and 4 (re, im) "
                         f"pairs per TX of the device (8 or 12 pairs), got {len(values)} "
                         f"numbers")
    gains = [complex(values[1 + 2 * k], values[2 + 2 * k]) for k in range(pairs // 2)]
    return Calibration(range_bias_m=values[0], channel_gain=tuple(
        gains[t * 4 + r] for t in tx_numbers for r in rx_numbers))
