"""Bit-accurate model of the streaming radix-2^2 SDF FFT core ``rtl/fft/fft_axis.sv``,
plus a float64 reference path.

Arithmetic (identical in RTL and model, stage by stage, lane by lane):

- Internal width ``W = DATA_W + 1 + GUARD_W`` bits per I/Q component: one integer guard bit
  and ``GUARD_W`` fraction bits. The input is ``x << GUARD_W`` or, with the window,
  ``rnd(x * HANN[n*4096/N], 16 - GUARD_W)``.
- Zero fill (the RTL's N_IN < N): a vector of ``n_in`` samples is windowed over its own count
  (``model.fft_rom.hann_window(n_in)``), then zeros up to N; the RTL's N_OUT keeps the
  first bins of the natural-order output (the caller slices them).
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


def _check_n_in(n_in: int, n: int) -> None:
    if not 2 <= n_in <= n:
        raise ValueError(f"N_IN={n_in}: must be 2..N ({n})")


def _as_frames(x: np.ndarray) -> np.ndarray:
    x = np.asarray(x)
    if x.ndim == 2:
        x = x[:, :, None]
    if x.ndim != 3:
        raise ValueError("x must be (frames, N) or (frames, N, lanes)")
    return x


def fft_fixed_reference(x: np.ndarray, *, inverse: bool = False, window: bool = False,
                        scale_sch: int | None = None, data_w: int = 16,
                        guard_w: int = 4, n_fft: int | None = None) -> FftFixedResult:
    """Bit-accurate fixed-point FFT of ``fft_axis``, stage by stage in int64: the plain
    statement of the arithmetic above, kept as the reference of :func:`fft_fixed`.

    ``x``: complex (frames, N_IN, lanes) or (frames, N_IN) with integer-valued I/Q in
    ``[-2**(data_w-1), 2**(data_w-1)-1]``; ``n_fft``: the transform length N (default N_IN;
    larger: zero fill after the window). ``scale_sch``: bit s = 1 divides stage s by 2
    (default all ones: 1/N overall). Returns :class:`FftFixedResult` (natural order, N bins).
    """
    x = _as_frames(x)
    frames, n_in, lanes = x.shape
    n = n_in if n_fft is None else n_fft
    _check(n, data_w, guard_w)
    _check_n_in(n_in, n)
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
        h = hann_window(n_in)[None, :, None]
        re = rnd(re * h, COEF_FRAC - guard_w)
        im = rnd(im * h, COEF_FRAC - guard_w)
    else:
        re = re << guard_w
        im = im << guard_w
    if n > n_in:
        pad = ((0, 0), (0, n - n_in), (0, 0))
        re, im = np.pad(re, pad), np.pad(im, pad)
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



# ---- fast path ------------------------------------------------------------------------------
# Same arithmetic as :func:`fft_fixed_reference`, computed on floating-point integers: sums
# of integers and products of a W-bit sample with a Q1.16 coefficient are exact in float64
# (< 2**53), so are the W+1-bit butterfly sums in float32 when W + 1 <= 24; ``rnd(v, k)``
# is ``rint(v * 2**-k)`` (scaling by a power of two is exact and ``rint`` rounds half to
# even). I and Q sit side by side on a last axis of 2, so each numpy call handles both; frames
# are processed in chunks that fit the L2 cache; saturation is checked with two reductions
# per stage and the per-beat overflow flags are only built once something saturated.

CHUNK_BYTES = 1 << 19
"""Working-set size of one chunk of frames (fits a 1 MiB L2 cache with its temporaries)."""


def planar_dtype(data_w: int = 16, guard_w: int = 4) -> type:
    """float32 when the internal width (plus one carry bit) fits its 24-bit mantissa."""
    return np.float32 if data_w + 1 + guard_w + 1 <= 24 else np.float64


def _rint_scaled(v: np.ndarray, k: int) -> np.ndarray:
    """In place: ``v <- rint(v / 2**k)`` (convergent rounding, exact for integers)."""
    if k:
        np.multiply(v, 2.0 ** -k, out=v)
        np.rint(v, out=v)
    return v


class _Sat:
    """Saturation to ``w``-bit signed of planar (chunk, n, lanes, 2) arrays, in place.

    ``bound`` carries a proven upper bound of the magnitudes so far: while it stays inside
    the range the check is skipped; otherwise two reductions decide and re-tighten it.
    """

    def __init__(self, w: int, bound: float) -> None:
        self.lo, self.hi = -float(1 << (w - 1)), float((1 << (w - 1)) - 1)
        self.bound = bound

    def __call__(self, v: np.ndarray) -> np.ndarray | None:
        """Clip ``v`` in place; returns the (chunk, n) beats that saturated, or None."""
        if self.bound <= self.hi or v.size == 0:
            return None
        mx, mn = float(v.max()), float(v.min())
        self.bound = max(mx, -mn)
        if mx <= self.hi and mn >= self.lo:
            return None
        mask = ((v < self.lo) | (v > self.hi)).any(axis=(-1, -2))
        np.clip(v, self.lo, self.hi, out=v)
        self.bound = -self.lo
        return mask


TWIDDLE_GAIN = (1.0 + 0.71 / (1 << COEF_FRAC)) * 2.0 ** 0.5
"""Bound of |rnd((re C + im S) / 2**16)| / max(|re|, |im|): |(C, S)| <= 2**16 + 0.71 (ROM
rounding), |(re, im)| <= sqrt(2) max(|re|, |im|)."""


def _or(a: np.ndarray | None, b: np.ndarray | None) -> np.ndarray | None:
    if a is None:
        return b
    return a if b is None else a | b


def _fft_chunk(p: np.ndarray, n: int, inverse: bool, scale_sch: int, w: int, guard_w: int,
               data_w: int, tw: list[np.ndarray | None]) -> tuple[np.ndarray, np.ndarray | None]:
    """Stages of :func:`fft_fixed_reference` on a planar chunk (c, n, lanes, 2), windowed and
    shifted already; returns (output before bit reversal, overflow (c, n) or None)."""
    c, _, lanes, _ = p.shape
    lg = n.bit_length() - 1
    bound = float(np.abs(p).max(initial=0.0))
    sat_w = _Sat(w, bound)
    ov: np.ndarray | None = None
    out = np.empty_like(p)
    for s in range(lg):
        d = n >> (s + 1)
        if s % 2 == 1:  # BF-II: second input of odd blocks times -j (+j inverse)
            q = p.reshape(c, n // (4 * d), 2, 2, d, lanes, 2)[:, :, 1, 1]
            tmp = q[..., 0].copy()
            if inverse:
                np.negative(q[..., 1], out=q[..., 0])
                q[..., 1] = tmp
            else:
                q[..., 0] = q[..., 1]
                np.negative(tmp, out=q[..., 1])
        a = p.reshape(c, n // (2 * d), 2, d, lanes, 2)
        o = out.reshape(c, n // (2 * d), 2, d, lanes, 2)
        np.add(a[:, :, 0], a[:, :, 1], out=o[:, :, 0])
        np.subtract(a[:, :, 0], a[:, :, 1], out=o[:, :, 1])
        scaled = (scale_sch >> s) & 1
        _rint_scaled(out, scaled)
        sat_w.bound = sat_w.bound if scaled else 2.0 * sat_w.bound
        mask = sat_w(out)
        if ov is not None:
            o2 = ov.reshape(c, n // (2 * d), 2, d)
            o_in = o2[:, :, 0] | o2[:, :, 1]
            ov = np.stack([o_in, o_in], axis=2).reshape(c, n)
        ov = _or(ov, mask)
        p, out = out, p
        if tw[s] is not None:  # twiddle after the pair (s-1, s): exact in complex128
            z = p.astype(np.float64).view(np.complex128)[..., 0]     # (c, n, lanes)
            z *= tw[s][None, :, None]                    # twiddles pre-scaled by 2**-16
            zf = np.rint(z.view(np.float64).reshape(p.shape), out=z.view(np.float64)
                         .reshape(p.shape))
            sat_w.bound = np.floor(sat_w.bound * TWIDDLE_GAIN) + 1.0
            ov = _or(ov, sat_w(zf))
            p[...] = zf
    _rint_scaled(p, guard_w)
    ov = _or(ov, _Sat(data_w, np.ceil(sat_w.bound / (1 << guard_w)))(p))
    return p, ov


def fft_fixed_planar(p: np.ndarray, *, inverse: bool = False, window: bool = False,
                     scale_sch: int | None = None, data_w: int = 16, guard_w: int = 4,
                     n_fft: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Fast bit-accurate ``fft_axis`` on planar I/Q, identical to :func:`fft_fixed_reference`.

    ``p``: real array (frames, N_IN, lanes, 2) of integer I (index 0) and Q (index 1) in
    ``data_w``-bit range; ``n_fft``: the transform length N (default N_IN; larger: zero fill
    after the window). Returns (array (frames, N, lanes, 2) of the integer outputs in
    natural bin order, dtype :func:`planar_dtype`; bool (frames, N) overflow per beat).
    """
    if p.ndim != 4 or p.shape[-1] != 2:
        raise ValueError("planar input must be (frames, N, lanes, 2)")
    frames, n_in, lanes, _ = p.shape
    n = n_in if n_fft is None else n_fft
    _check(n, data_w, guard_w)
    _check_n_in(n_in, n)
    lg = n.bit_length() - 1
    if scale_sch is None:
        scale_sch = default_scale_sch(n)
    lim = 1 << (data_w - 1)
    if p.size and (p.min() < -lim or p.max() >= lim):
        raise ValueError(f"input does not fit {data_w}-bit two's complement")
    dt = planar_dtype(data_w, guard_w)
    w = data_w + 1 + guard_w
    cos_t, sin_t = cos_table(), sin_table()
    tw: list[np.ndarray | None] = [None] * lg
    for s in range(1, lg, 2):
        if s + 1 < lg:
            kk = twiddle_index(n, n >> (s - 1))
            sgn = 1.0 if inverse else -1.0        # (re + j im) * (C -+ j S)
            tw[s] = (cos_t[kk] + 1j * sgn * sin_t[kk]) * 2.0 ** -COEF_FRAC
    # window and its rounding shift in one exact factor (x * h < 2**31, scaled by 2**-k)
    h = (hann_window(n_in) * 2.0 ** (guard_w - COEF_FRAC))[None, :, None, None] if window \
        else None
    br = bitrev(n)
    y = np.empty((frames, n, lanes, 2), dtype=dt)
    ov = np.zeros((frames, n), dtype=bool)
    step = max(1, CHUNK_BYTES // (n * lanes * 2 * np.dtype(dt).itemsize))
    for f0 in range(0, frames, step):
        sl = slice(f0, min(f0 + step, frames))
        if window:
            x = np.rint(p[sl] * h).astype(dt, order="C")
        else:
            x = p[sl].astype(dt, order="C") * float(1 << guard_w)
        if n > n_in:                                    # the zero fill
            x = np.concatenate([x, np.zeros((x.shape[0], n - n_in, lanes, 2), dt)], axis=1)
        out, o = _fft_chunk(x, n, inverse, scale_sch, w, guard_w, data_w, tw)
        y[sl] = out[:, br]
        if o is not None:
            ov[sl] = o[:, br]
    return y, ov


def to_planar(x: np.ndarray) -> np.ndarray:
    """complex (...) -> float (..., 2) with I at index 0 and Q at index 1 (a view when the
    input is contiguous complex64/complex128)."""
    x = np.asarray(x)
    if x.dtype in (np.complex64, np.complex128) and x.flags.c_contiguous:
        return x.view(x.real.dtype).reshape(x.shape + (2,))
    return np.stack([np.real(x), np.imag(x)], axis=-1).astype(np.float64)


def from_planar(p: np.ndarray) -> np.ndarray:
    """Inverse of :func:`to_planar`: complex128 (...)."""
    return p[..., 0].astype(np.float64) + 1j * p[..., 1]


def fft_fixed(x: np.ndarray, *, inverse: bool = False, window: bool = False,
              scale_sch: int | None = None, data_w: int = 16,
              guard_w: int = 4, n_fft: int | None = None) -> FftFixedResult:
    """Bit-accurate fixed-point FFT of ``fft_axis`` (fast path, identical results to
    :func:`fft_fixed_reference`).

    ``x``: complex (frames, N_IN, lanes) or (frames, N_IN) with integer-valued I/Q in
    ``[-2**(data_w-1), 2**(data_w-1)-1]``; ``n_fft``: N (default N_IN; larger: zero fill).
    ``scale_sch``: bit s = 1 divides stage s by 2 (default all ones: 1/N overall). Returns
    :class:`FftFixedResult` (natural order, N bins).
    """
    x = _as_frames(x)
    y, ov = fft_fixed_planar(to_planar(x), inverse=inverse, window=window,
                             scale_sch=scale_sch, data_w=data_w, guard_w=guard_w,
                             n_fft=n_fft)
    return FftFixedResult(y=from_planar(y), overflow=ov)


def fft_float(x: np.ndarray, *, inverse: bool = False, window: bool = False,
              scale_sch: int | None = None, n_fft: int | None = None) -> np.ndarray:
    """float64 reference: complex128 (frames, N, lanes) = DFT (IDFT sign for ``inverse``)
    of the (ideal periodic Hann windowed over its N_IN samples, zero-filled to ``n_fft``)
    input divided by 2**(number of scaled stages)."""
    x = _as_frames(x).astype(np.complex128)
    n_in = x.shape[1]
    n = n_in if n_fft is None else n_fft
    if scale_sch is None:
        scale_sch = default_scale_sch(n)
    lg = n.bit_length() - 1
    scale = 2.0 ** -bin(scale_sch & ((1 << lg) - 1)).count("1")
    if window:
        x = x * (0.5 - 0.5 * np.cos(2 * np.pi * np.arange(n_in) / n_in))[None, :, None]
    y = np.fft.ifft(x, n=n, axis=1) * n if inverse else np.fft.fft(x, n=n, axis=1)
    return y * scale


def sqnr_db(y: np.ndarray, ref: np.ndarray) -> float:
    """Signal to quantization noise ratio in dB of ``y`` against ``ref`` (same shape)."""
    err = np.sum(np.abs(y - ref) ** 2)
    return float(10 * np.log10(np.sum(np.abs(ref) ** 2) / max(err, 1e-300)))
