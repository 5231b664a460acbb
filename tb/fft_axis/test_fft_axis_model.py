"""Plain pytest unit tests of the bit-accurate FFT model (no simulator)."""

from __future__ import annotations

import numpy as np
import pytest

from model import fft_axis as ff
from model.fft_rom import (
    QUARTER,
    ROM_SIZE,
    cos_table,
    hann_from_quarters,
    hann_quarters,
    hann_table,
    sin_table,
    stale_files,
    twiddle_from_quarters,
    twiddle_quarters,
)


def test_rom_package_up_to_date() -> None:
    """rtl/fft/fft_rom_pkg.sv, fft_twiddle_rom.sv and fft_hann_rom.sv are exactly what
    model/fft_rom.py generates."""
    assert not stale_files(), "stale: run `make gen`"


def test_quarter_wave_roms_rebuild_the_full_tables() -> None:
    """The RTL's quarter-wave tables plus quadrant symmetry give every entry bit for bit."""
    k = np.arange(ROM_SIZE)
    c, s = twiddle_from_quarters(k)
    assert np.array_equal(c, cos_table()) and np.array_equal(s, sin_table())
    assert np.array_equal(hann_from_quarters(k), hann_table())
    cq, sq = twiddle_quarters()
    h0, h3 = hann_quarters()
    assert len(cq) == len(sq) == len(h0) == len(h3) == QUARTER
    # widths the generated modules declare: 17-bit and 16-bit unsigned
    assert 0 <= min(cq.min(), sq.min()) and max(cq.max(), sq.max()) < 1 << 17
    assert 0 <= min(h0.min(), h3.min()) and max(h0.max(), h3.max()) < 1 << 16


def test_rom_values() -> None:
    c, s, h = cos_table(), sin_table(), hann_table()
    assert c[0] == 65536 and c[1024] == 0 and c[2048] == -65536
    assert s[1024] == 65536 and s[0] == 0
    assert h[0] == 0 and h[2048] == 65536
    assert np.abs(c).max() <= 65536 and h.min() >= 0


def test_convergent_rounding() -> None:
    v = np.array([-7, -6, -5, -3, -2, -1, 1, 2, 3, 5, 6, 7], dtype=np.int64)
    # v / 2 = -3.5 -3 -2.5 -1.5 -1 -0.5 0.5 1 1.5 2.5 3 3.5 -> half to even
    assert ff.rnd(v, 1).tolist() == [-4, -3, -2, -2, -1, 0, 0, 1, 2, 2, 3, 4]
    assert ff.rnd(np.array([6, 10, 14, -6]), 2).tolist() == [2, 2, 4, -2]


@pytest.mark.parametrize(("n", "need"), [(64, 70.0), (256, 64.0)])
@pytest.mark.parametrize("inverse", [False, True])
def test_model_sqnr(n: int, need: float, inverse: bool) -> None:
    rng = np.random.default_rng(n)
    x = rng.integers(-32768, 32768, (16, n, 2)) + 1j * rng.integers(-32768, 32768, (16, n, 2))
    res = ff.fft_fixed(x, inverse=inverse)
    sq = ff.sqnr_db(res.y, ff.fft_float(x, inverse=inverse))
    print(f"model SQNR N={n} inverse={inverse}: {sq:.2f} dB")
    assert sq >= need
    assert not res.overflow.any()


@pytest.mark.parametrize("n", [16, 32, 128, 512, 2048, 4096])
def test_model_matches_dft_all_sizes(n: int) -> None:
    """Every supported length (even and odd log2 N), with and without window."""
    rng = np.random.default_rng(n)
    x = rng.integers(-32768, 32768, (2, n)) + 1j * rng.integers(-32768, 32768, (2, n))
    for window in (False, True):
        res = ff.fft_fixed(x, window=window)
        ref = ff.fft_float(x, window=window)
        assert np.max(np.abs(res.y - ref)) < 4.0 + 0.02 * np.log2(n) ** 2


def test_impulse_and_dc_exact() -> None:
    n = 64
    x = np.zeros((1, n), dtype=np.complex128)
    x[0, 0] = 32767 - 32768j
    y = ff.fft_fixed(x).y[0, :, 0]
    assert np.all(y == np.round(32767 / n) + 1j * (-32768 / n))
    x = np.full((1, n), -32768 - 32768j)
    y = ff.fft_fixed(x).y[0, :, 0]
    assert y[0] == -32768 - 32768j and np.all(y[1:] == 0)


def test_overflow_flagged_and_saturated() -> None:
    n = 64
    t = np.arange(n)
    ph = np.exp(2j * np.pi * t / 8)
    x = (np.clip(np.round(46341 * ph.real), -32768, 32767)
         + 1j * np.clip(np.round(46341 * ph.imag), -32768, 32767))[None, :]
    res = ff.fft_fixed(x)
    assert res.overflow[0, n // 8] and res.overflow.sum() == 1
    assert res.y[0, n // 8, 0].real == 32767


def test_bad_parameters() -> None:
    with pytest.raises(ValueError, match="N=48"):
        ff.fft_fixed(np.zeros((1, 48)))
    with pytest.raises(ValueError, match="16-bit"):
        ff.fft_fixed(np.full((1, 16), 40000.0))


@pytest.mark.parametrize("w", [15, 21, 26])
@pytest.mark.parametrize("inverse", [False, True])
def test_gauss_twiddle_identity_and_widths(w: int, inverse: bool) -> None:
    """rtl/fft/fft_twiddle.sv's three-product form (W <= 26) equals the four-product complex
    product exactly, for every ROM coefficient pair and the extreme W-bit operands, and every
    operand fits the width the RTL gives it (coefficient sums 18 bits, re + im W+1 bits)."""
    c, s = cos_table(), sin_table()                          # (4096,) each
    d = s if inverse else -s
    p_coef, m_coef = d - c, -c - d                           # RTL p1_q, m1_q
    lim = 1 << 17
    assert (np.abs(p_coef) < lim).all() and (np.abs(m_coef) < lim).all()
    lo, hi = -(1 << (w - 1)), (1 << (w - 1)) - 1
    vals = np.array([lo, lo + 1, -1, 0, 1, hi - 1, hi], dtype=object)
    re, im = (v.ravel() for v in np.meshgrid(vals, vals))
    for k in range(0, 4096, 7):
        ci, si, pi, mi = (int(v) for v in (c[k], s[k], p_coef[k], m_coef[k]))
        a = re + im
        assert all(-(1 << w) <= v < (1 << w) for v in a)    # W+1 bits
        k1, k2, k3 = a * ci, re * pi, im * mi
        sg = 1 if inverse else -1                            # x * (C + sg*jS)
        assert (k1 + k3 == re * ci - sg * im * si).all()
        assert (k1 + k2 == im * ci + sg * re * si).all()
