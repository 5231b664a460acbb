"""Bit-accurate model of the streaming radix-2^2 SDF FFT core ``rtl/fft/fft_axis.sv``,
plus a float64 reference path.

Arithmetic (identical in RTL and model, stage by stage, lane by lane):

- Internal width ``W = DATA_W + 1 + GUARD_W`` bits per I/Q component: one integer guard bit
  and ``GUARD_W`` fraction bits. The input is ``x << GUARD_W`` or, with the window,
  ``rnd(x * HANN[n*4096/N], 16 - GUARD_W)``.
- Decimation in frequency, ``L = log2 N`` radix-2 butterfly stages ``s = 0..L-1`` of span
  ``D = N >> (s+1)``, grouped in radix-2^2 pairs (s even = BF-I, s odd = BF-II). BF-II
  multiplies its second input by ``-j`` (``+j`` for the inverse) when bit ``log2(2D)`` of the
  sample index is set. After every pair that is followed by another stage, the sample at
  index ``p`` is multiplied by ``W_M^(i0*(b1 + 2*b0))`` with ``M = N >> s_pair_first``,
  ``b1 = p[log2 M - 1]``, ``b0 = p[log2 M - 2]``, ``i0 = p mod M/4`` (conjugated for the
  inverse). For odd L the last stage is a plain radix-2 stage (twiddle 1).
- Butterfly: ``a + b`` and ``a - b`` exact, then, if bit ``s`` of ``SCALE_SCH`` is set,
  ``rnd(., 1)`` (divide by 2), then saturate to W bits.
- Twiddle: ``(re*C + im*S, im*C - re*S)`` with Q1.16 ROM values, ``rnd(., 16)``, saturate.
- Output: ``rnd(., GUARD_W)``, saturate to DATA_W bits, bit-reverse reorder.
- ``rnd(v, k)`` is convergent rounding (round half to even) of ``v / 2**k``.
- Overflow: each sample carries a flag, set by any saturation of any lane in its own
  computation and OR-ed from both butterfly inputs; the RTL pulses ``event_overflow`` for
  each output beat whose flag is set.

The default ``SCALE_SCH`` (all ones) gives ``round(DFT(x)/N)`` up to rounding noise.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from model.fft_rom import COEF_FRAC, ROM_LOG2, cos_table, hann_window, sin_table

N_MIN = 16
N_MAX = 1 << ROM_LOG2


@dataclass(frozen=True)
class FftFixedResult:
    """Output of :func:`fft_fixed`.

    ``y``: complex128 (frames, N, lanes), integer-valued I/Q, natural bin order.
    ``overflow``: bool (frames, N), per output beat (any lane saturated somewhere).
    """

    y: np.ndarray
    overflow: np.ndarray


def rnd(v: np.ndarray, k: int) -> np.ndarray:
    """Convergent rounding (half to even) of ``v / 2**k``; ``v`` int64 array, ``k >= 0``.

    ``(v + 2**(k-1) - 1 + lsb) >> k`` with ``lsb`` the bit that becomes the result's LSB:
    a remainder above one half carries, below does not, exactly one half carries only when
    the truncated result is odd (one add and one shift instead of compare-and-select).
    """
    if k == 0:
        return v
    return (v + ((1 << (k - 1)) - 1) + ((v >> k) & 1)) >> k


def sat(v: np.ndarray, w: int) -> tuple[np.ndarray, np.ndarray]:
    """Saturate int64 ``v`` to ``w``-bit signed; returns (clipped, overflow mask)."""
    lo, hi = -(1 << (w - 1)), (1 << (w - 1)) - 1
    return np.clip(v, lo, hi), (v < lo) | (v > hi)


def bitrev(n: int) -> np.ndarray:
    """int64 (n,): bit-reversed indices for an n-point (power of two) transform."""
    bits = n.bit_length() - 1
    idx = np.arange(n)
    out = np.zeros(n, dtype=np.int64)
    for b in range(bits):
        out |= ((idx >> b) & 1) << (bits - 1 - b)
    return out


def default_scale_sch(n: int) -> int:
    """All stages scaled by 1/2: overall 1/N."""
    return (1 << (n.bit_length() - 1)) - 1


def twiddle_index(n: int, m: int) -> np.ndarray:
    """int64 (n,): ROM index of the twiddle after a radix-2^2 pair of sub-length ``m``."""
    lg = m.bit_length() - 1
    p = np.arange(n) & (m - 1)
    b1 = (p >> (lg - 1)) & 1
    b0 = (p >> (lg - 2)) & 1
    i0 = p & (m // 4 - 1)
    e = i0 * (b1 + 2 * b0)
    return e << (ROM_LOG2 - lg)


def multipliers_per_lane(n: int) -> int:
    """Complex twiddle multipliers per lane (window multiplier not counted)."""
    lg = n.bit_length() - 1
    return sum(1 for s in range(1, lg, 2) if s + 1 < lg)


def _check(n: int, data_w: int, guard_w: int) -> None:
    if n < N_MIN or n > N_MAX or n & (n - 1):
        raise ValueError(f"N={n}: must be a power of two in {N_MIN}..{N_MAX}")
    if not 8 <= data_w <= 24:
        raise ValueError(f"DATA_W={data_w}: must be 8..24")
    if not 0 <= guard_w <= COEF_FRAC or data_w + 1 + guard_w > 27:
        raise ValueError(f"GUARD_W={guard_w}: need 0..16 and DATA_W+1+GUARD_W <= 27")


def _as_frames(x: np.ndarray) -> np.ndarray:
    x = np.asarray(x)
    if x.ndim == 2:
        x = x[:, :, None]
    if x.ndim != 3:
        raise ValueError("x must be (frames, N) or (frames, N, lanes)")
    return x


def fft_fixed(x: np.ndarray, *, inverse: bool = False, window: bool = False,
              scale_sch: int | None = None, data_w: int = 16,
              guard_w: int = 4) -> FftFixedResult:
    """Bit-accurate fixed-point FFT of ``fft_axis``.

    ``x``: complex (frames, N, lanes) or (frames, N) with integer-valued I/Q in
    ``[-2**(data_w-1), 2**(data_w-1)-1]``. ``scale_sch``: bit s = 1 divides stage s by 2
    (default all ones: 1/N overall). Returns :class:`FftFixedResult` (natural order).
    """
    x = _as_frames(x)
    frames, n, lanes = x.shape
    _check(n, data_w, guard_w)
    lg = n.bit_length() - 1
    if scale_sch is None:
        scale_sch = default_scale_sch(n)
    w = data_w + 1 + guard_w
    re = np.real(x).astype(np.int64)
    im = np.imag(x).astype(np.int64)
    lim = 1 << (data_w - 1)
    if re.min(initial=0) < -lim or re.max(initial=0) >= lim or im.min(initial=0) < -lim \
            or im.max(initial=0) >= lim:
        raise ValueError(f"input does not fit {data_w}-bit two's complement")
    if window:
        h = hann_window(n)[None, :, None]
        re = rnd(re * h, COEF_FRAC - guard_w)
        im = rnd(im * h, COEF_FRAC - guard_w)
    else:
        re = re << guard_w
        im = im << guard_w
    ov = np.zeros((frames, n), dtype=bool)
    cos_t, sin_t = cos_table(), sin_table()

    for s in range(lg):
        d = n >> (s + 1)
        if s % 2 == 1:  # BF-II: trivial -j (+j inverse) on the second input of odd blocks
            r4 = re.reshape(frames, n // (4 * d), 2, 2, d, lanes)
            i4 = im.reshape(frames, n // (4 * d), 2, 2, d, lanes)
            br, bi = r4[:, :, 1, 1].copy(), i4[:, :, 1, 1].copy()
            if inverse:
                r4[:, :, 1, 1], i4[:, :, 1, 1] = -bi, br
            else:
                r4[:, :, 1, 1], i4[:, :, 1, 1] = bi, -br
        r2 = re.reshape(frames, n // (2 * d), 2, d, lanes)
        i2 = im.reshape(frames, n // (2 * d), 2, d, lanes)
        o2 = ov.reshape(frames, n // (2 * d), 2, d)
        k = 1 if (scale_sch >> s) & 1 else 0
        sr, so_r = sat(rnd(r2[:, :, 0] + r2[:, :, 1], k), w)
        si, so_i = sat(rnd(i2[:, :, 0] + i2[:, :, 1], k), w)
        dr, do_r = sat(rnd(r2[:, :, 0] - r2[:, :, 1], k), w)
        di, do_i = sat(rnd(i2[:, :, 0] - i2[:, :, 1], k), w)
        o_in = o2[:, :, 0] | o2[:, :, 1]
        o_sum = o_in | (so_r | so_i).any(axis=-1)
        o_dif = o_in | (do_r | do_i).any(axis=-1)
        re = np.stack([sr, dr], axis=2).reshape(frames, n, lanes)
        im = np.stack([si, di], axis=2).reshape(frames, n, lanes)
        ov = np.stack([o_sum, o_dif], axis=2).reshape(frames, n)
        if s % 2 == 1 and s + 1 < lg:  # twiddle after the pair (s-1, s)
            kk = twiddle_index(n, n >> (s - 1))
            c = cos_t[kk][None, :, None]
            sn = sin_t[kk][None, :, None]
            if inverse:
                pr, pi = re * c - im * sn, im * c + re * sn
            else:
                pr, pi = re * c + im * sn, im * c - re * sn
            re, o_r = sat(rnd(pr, COEF_FRAC), w)
            im, o_i = sat(rnd(pi, COEF_FRAC), w)
            ov = ov | (o_r | o_i).any(axis=-1)

    re, o_r = sat(rnd(re, guard_w), data_w)
    im, o_i = sat(rnd(im, guard_w), data_w)
    ov = ov | (o_r | o_i).any(axis=-1)
    br = bitrev(n)
    y = (re + 1j * im)[:, br, :]
    return FftFixedResult(y=y, overflow=ov[:, br])


def fft_float(x: np.ndarray, *, inverse: bool = False, window: bool = False,
              scale_sch: int | None = None) -> np.ndarray:
    """float64 reference: complex128 (frames, N, lanes) = DFT (IDFT sign for ``inverse``)
    of the (ideal periodic Hann windowed) input divided by 2**(number of scaled stages)."""
    x = _as_frames(x).astype(np.complex128)
    n = x.shape[1]
    if scale_sch is None:
        scale_sch = default_scale_sch(n)
    lg = n.bit_length() - 1
    scale = 2.0 ** -bin(scale_sch & ((1 << lg) - 1)).count("1")
    if window:
        x = x * (0.5 - 0.5 * np.cos(2 * np.pi * np.arange(n) / n))[None, :, None]
    y = np.fft.ifft(x, axis=1) * n if inverse else np.fft.fft(x, axis=1)
    return y * scale


def sqnr_db(y: np.ndarray, ref: np.ndarray) -> float:
    """Signal to quantization noise ratio in dB of ``y`` against ``ref`` (same shape)."""
    err = np.sum(np.abs(y - ref) ** 2)
    return float(10 * np.log10(np.sum(np.abs(ref) ** 2) / max(err, 1e-300)))


def pack_words(x: np.ndarray, data_w: int = 16) -> np.ndarray:
    """complex (beats, lanes) integer I/Q -> Python-int-ready uint64 words per lane
    ``{Q, I}`` (I in the low half), object array (beats,) of the full multi-lane words."""
    mask = (1 << data_w) - 1
    re = np.real(x).astype(np.int64) & mask
    im = np.imag(x).astype(np.int64) & mask
    lane = (im << data_w) | re
    out = np.zeros(lane.shape[0], dtype=object)
    for c in range(lane.shape[1]):
        out = out + (lane[:, c].astype(object) << (2 * data_w * c))
    return out


def unpack_words(words: np.ndarray, lanes: int, data_w: int = 16) -> np.ndarray:
    """Inverse of :func:`pack_words`: (beats,) ints -> complex128 (beats, lanes)."""
    mask = (1 << data_w) - 1
    out = np.zeros((len(words), lanes), dtype=np.complex128)
    for c in range(lanes):
        lane = np.array([(int(v) >> (2 * data_w * c)) & ((1 << 2 * data_w) - 1) for v in words],
                        dtype=np.int64)
        re = lane & mask
        im = (lane >> data_w) & mask
        re = np.where(re >= 1 << (data_w - 1), re - (1 << data_w), re)
        im = np.where(im >= 1 << (data_w - 1), im - (1 << data_w), im)
        out[:, c] = re + 1j * im
    return out
