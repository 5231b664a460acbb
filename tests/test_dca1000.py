"""ADC captures (docs/profiles.md): the DCA1000 .bin in both TI layouts, complex and real, and
.npy arrays, each read back from its writer; the documented word order; truncated captures;
streaming from disk; the real OpenRadar frame through the chain."""

import tracemalloc
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from host.adc_capture import NpyCapture, open_capture, write_npy
from host.dca1000 import Dca1000Capture, frame_to_words, frame_words, words_to_frame, write_dca1000
from host.params import DetectionParams
from host.pipeline import process_frame
from model.profile import CaptureFormat, load_profile, profile_from_toml
from model.reference import radar_cube, range_doppler_power
from model.scene import Scatterers
from model.simulate import simulate_frame

DATA = Path(__file__).parent / "data" / "openradar"
OPENRADAR = load_profile(DATA / "openradar_2tx4rx.cfg")
LAYOUTS = {"4-lane": CaptureFormat("dca1000", 4, True),
           "2-lane": CaptureFormat("dca1000", 2, False)}


def small(adc: str = "complex", num_rx: int = 4, samples: int = 10, loops: int = 3):
    """A small profile (2 TX) of the given ADC kind, RX count and sizes (its near-range
    guard stated: the default one would leave a 10-sample real ADC no bin)."""
    rx = ", ".join(f"[{r}, 0]" for r in range(num_rx))
    return profile_from_toml(f"""
        [waveform]
        start_frequency_hz = 77e9
        slope_hz_per_s = 30e12
        sample_rate_hz = 5e6
        samples_per_chirp = {samples}
        chirp_period_s = 20e-6
        loops = {loops}
        adc = "{adc}"
        min_range_m = 0.1
        [array]
        tx = [[0, 0], [{num_rx}, 0]]
        rx = [{rx}]""", "small.toml").config


def random_frame(cfg, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    codes = lambda: rng.integers(-32768, 32768, cfg.adc_shape)  # noqa: E731
    if cfg.adc == "real":
        return codes().astype(np.float32)
    return (codes() + 1j * codes()).astype(np.complex64)


def test_documented_word_order():
    """The words of frame samples x[chirp, rx, n] = I + jQ with I = 1000 c + 100 r + n,
    Q = -I (TI: readDCA1000.m)."""
    cfg = small(num_rx=2, samples=8, loops=1)
    c, r, n = np.meshgrid(np.arange(2), np.arange(2), np.arange(8), indexing="ij")
    i = 1000 * c + 100 * r + n
    frame = (i - 1j * i).astype(np.complex64)
    two = frame_to_words(frame, cfg, LAYOUTS["2-lane"])
    # 2 lanes, non-interleaved: per chirp, per RX: I(n) I(n+1) Q(n) Q(n+1)
    assert two[:12].tolist() == [0, 1, 0, -1, 2, 3, -2, -3, 4, 5, -4, -5]
    assert two[16:20].tolist() == [100, 101, -100, -101]
    assert two[32:34].tolist() == [1000, 1001]
    # 4 lanes, interleaved: per chirp, per sample: I of lanes 0..3, Q of lanes 0..3 (lanes
    # without an RX are zero)
    four = frame_to_words(frame, cfg, LAYOUTS["4-lane"])
    assert four[:16].tolist() == [0, 100, 0, 0, 0, -100, 0, 0, 1, 101, 0, 0, -1, -101, 0, 0]
    assert four.size == frame_words(cfg, LAYOUTS["4-lane"]) == 2 * 8 * 4 * 2
    assert four[8 * 8:8 * 8 + 2].tolist() == [1000, 1100]
    real = small("real", num_rx=2, samples=8, loops=1)
    assert frame_to_words(frame.real, real, LAYOUTS["2-lane"])[6:10].tolist() == [6, 7, 100,
                                                                                  101]
    assert frame_to_words(frame.real, real, LAYOUTS["4-lane"])[:6].tolist() == [0, 100, 0, 0,
                                                                                 1, 101]


@pytest.mark.parametrize("layout", sorted(LAYOUTS))
@pytest.mark.parametrize("adc", ["complex", "real"])
@pytest.mark.parametrize("num_rx", [4, 3])
def test_round_trip(tmp_path, layout, adc, num_rx):
    cfg = small(adc, num_rx)
    fmt = LAYOUTS[layout]
    frames = [random_frame(cfg, k) for k in range(3)]
    path = tmp_path / "adc_data.bin"
    assert write_dca1000(path, frames, cfg, fmt) == 3
    assert path.stat().st_size == 3 * frame_words(cfg, fmt) * 2
    cap = Dca1000Capture(path, cfg, fmt)
    assert (cap.n_frames, cap.dropped_bytes) == (3, 0)
    for want, got in zip(frames, cap.frames(), strict=True):
        assert got.dtype == want.dtype and np.array_equal(got, want)
    words = frame_to_words(frames[1], cfg, fmt)
    assert np.array_equal(words_to_frame(words, cfg, fmt), frames[1])


def test_simulated_capture_round_trip(tmp_path):
    """The simulator writes a DCA1000 capture of a profile; the reader gives its frames."""
    cfg = OPENRADAR.config
    sc = Scatterers(np.array([2.0, 4.0]), np.array([10.0, -20.0]), np.array([1.0, -0.5]),
                    np.array([1.0, 1.0]), np.array([-1, -1]))
    frames = [simulate_frame(cfg, sc, frame_index=k).samples for k in range(2)]
    for fmt in LAYOUTS.values():
        path = tmp_path / f"sim_{fmt.lanes}.bin"
        write_dca1000(path, frames, cfg, fmt)
        cap = open_capture(path, replace(OPENRADAR, capture=fmt))
        assert cap.n_frames == 2
        assert all(np.array_equal(a, b) for a, b in zip(cap.frames(), frames, strict=True))


def test_truncated_capture_keeps_whole_frames(tmp_path):
    cfg, fmt = small(), LAYOUTS["2-lane"]
    frames = [random_frame(cfg, k) for k in range(3)]
    path = tmp_path / "cut.bin"
    write_dca1000(path, frames, cfg, fmt)
    frame_bytes = frame_words(cfg, fmt) * 2
    with open(path, "r+b") as f:
        f.truncate(2 * frame_bytes + frame_bytes // 2 + 1)       # mid-frame, odd byte count
    cap = Dca1000Capture(path, cfg, fmt)
    assert (cap.n_frames, cap.dropped_bytes) == (2, frame_bytes // 2 + 1)
    assert "2 frame(s)" in cap.report() and f"{frame_bytes // 2 + 1} bytes" in cap.report()
    assert all(np.array_equal(a, b) for a, b in zip(cap.frames(), frames[:2], strict=True))
    with pytest.raises(IndexError):
        cap.frame(2)
    with open(path, "r+b") as f:
        f.truncate(frame_bytes - 2)
    with pytest.raises(ValueError, match="hold no whole frame"):
        Dca1000Capture(path, cfg, fmt)


def test_large_capture_streams(tmp_path):
    """A 2 GiB capture (sparse file) is opened and its last frame read without loading it."""
    cfg, fmt = OPENRADAR.config, OPENRADAR.capture
    path = tmp_path / "big.bin"
    frame_bytes = frame_words(cfg, fmt) * 2
    last = random_frame(cfg)
    with open(path, "wb") as f:
        f.truncate(2**31 - frame_bytes)
        f.seek(0, 2)
        f.write(frame_to_words(last, cfg, fmt).tobytes())
    tracemalloc.start()
    cap = Dca1000Capture(path, cfg, fmt)
    got = cap.frame(cap.n_frames - 1)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert cap.n_frames == 2**31 // frame_bytes and np.array_equal(got, last)
    assert peak < 20 * frame_bytes


def test_npy_round_trip_and_refusals(tmp_path):
    cfg = small()
    frames = [random_frame(cfg, k) for k in range(2)]
    path = tmp_path / "frames.npy"
    assert write_npy(path, frames, 2, cfg) == 2
    cap = open_capture(path, replace(OPENRADAR, config=cfg))
    assert isinstance(cap, NpyCapture) and cap.n_frames == 2
    assert all(np.array_equal(a, b) for a, b in zip(cap.frames(), frames, strict=True))
    one = tmp_path / "one.npy"
    np.save(one, frames[0])
    assert open_capture(one, replace(OPENRADAR, config=cfg)).n_frames == 1
    np.save(one, frames[0].real)     # a real frame for a complex-ADC radar: mirror images
    with pytest.raises(ValueError, match="complex ADC"):
        NpyCapture(one, cfg)
    np.save(one, frames[0][:, :2])
    with pytest.raises(ValueError, match="expected shape"):
        NpyCapture(one, cfg)
    with pytest.raises(ValueError, match="expected 3"):
        write_npy(tmp_path / "short.npy", frames, 3, cfg)
    assert not (tmp_path / "short.npy").exists()


def test_writer_refuses_non_codes(tmp_path):
    cfg, fmt = small(), LAYOUTS["2-lane"]
    with pytest.raises(ValueError, match="integer ADC codes"):
        write_dca1000(tmp_path / "x.bin", [random_frame(cfg) * 0.5 + 0.25], cfg, fmt)
    assert not (tmp_path / "x.bin").exists()
    with pytest.raises(ValueError, match="needs complex samples"):
        frame_to_words(random_frame(cfg).real, cfg, fmt)


def test_openradar_real_frame():
    """The OpenRadar frame (tests/data/openradar/README.md) read as the DCA1000 capture of
    its .cfg: the original's words, a moving target standing out of the range-Doppler map,
    and the chain's points."""
    cap = open_capture(DATA / "doppler_example_1.bin", OPENRADAR)
    assert (cap.n_frames, cap.dropped_bytes) == (1, 0)
    frame = cap.frame(0)
    cfg = OPENRADAR.config
    # the original (128 loops, virtual tx*4+rx, 128 samples) as uint16: loop 0, virtual 0
    # starts 24+65433j 53+65398j; virtual 4 (TX 1, RX 0) is chirp 1, RX 0
    assert frame[0, 0, :2].tolist() == [24 - 103j, 53 - 138j]
    assert frame[1, 0, :2].tolist() == [-58 - 88j, -19 - 94j]
    nci = range_doppler_power(radar_cube(frame, cfg))
    noise = np.median(nci)
    moving = nci.copy()
    moving[:, [-1, 0, 1]] = 0                    # Doppler bins 0, +-1: static returns
    r, d = np.unravel_index(moving.argmax(), moving.shape)
    assert 2.8 < r * cfg.range_bin_m < 3.1       # the returns moving near 2.9 m
    assert 10 * np.log10(moving[r, d] / noise) > 40
    assert 0.4 < abs(np.fft.fftfreq(cfg.n_doppler, 1 / cfg.n_doppler)[d]
                     * cfg.velocity_bin_mps) < 1.0
    cloud = process_frame(frame, cfg, DetectionParams(max_speed_mps=cfg.max_speed_mps))
    near = (np.abs(cloud.range_m - 2.93) < 0.15) & (np.abs(cloud.radial_velocity_mps) > 0.3)
    assert near.sum() >= 2 and not cloud.ambiguous.any()
