"""Private backend of ``host.cfar``: the compiled OS-CFAR (ordered statistic over each cell's
training cells, ``host.cfar._kernel``'s window), exact.

The OS-CFAR's threshold of a cell is alpha x_(k), x_(k) the k-th smallest of its n training
cells. Two ways to it, both on the map padded by the window's half extent (:func:`os_pad`,
float64, C order: the kernels read rows):

- :func:`os_kth`: x_(k) of every cell (``host.cfar.cfar_threshold``'s maps): per cell the
  training cells gathered and the k-th found from the previous cell's x_(k), which the
  heavily overlapping windows of neighbours keep a few ranks away (:func:`_kth_near`: the
  guess's rank counted, then the value that many ranks away found without data-dependent
  branches; a quickselect, :func:`_select`, when it is far).
- :func:`os_detect`: whether at least k training cells x of a cell have fl(alpha x) < the
  cell's power p. Multiplying by a positive alpha in floating point is monotone (x <= y
  gives fl(alpha x) <= fl(alpha y)), so p > fl(alpha x_(k)), the threshold test, holds
  exactly when at least k training cells have fl(alpha x) < p: the detection without any
  order statistic; x_(k) is then needed only at the detected cells (:func:`os_kth_at`,
  ``host.cfar.cfar_detect``). The count is taken in float64 for float32 maps too: for a
  float32 p, fl(alpha x) < p exactly when fl(alpha x) rounded down to float32 is < p, the
  comparison of the threshold float32 maps had. Most cells are decided on 16-bit keys of
  the values (:func:`_keys`, an upper bound of the count), the rest counted exactly.

Both return exactly what sorting would (the oracle: the numpy implementation they replaced,
``tests/oracles/cfar.py``; ``tests/test_cfar_os.py``).
"""

from __future__ import annotations

import numpy as np

from host.kernels import njit, warm_up


@njit()
def _select(buf: np.ndarray, n: int, k: int, first_pivot: float) -> float:
    """The k-th smallest (k 0-based) of buf[:n] (float64), rearranging buf[:n]: quickselect
    with three-way (less / equal / greater) partitions, the first pivot ``first_pivot``
    (any value: a guess of the answer; NaN for none), then the median of three."""
    lo, hi = 0, n - 1
    pivot = first_pivot
    while lo < hi:
        if pivot != pivot:                     # NaN: the median of the first, middle, last
            a, b, c = buf[lo], buf[(lo + hi) // 2], buf[hi]
            pivot = max(min(a, b), min(max(a, b), c))
        lt, i, gt = lo, lo, hi
        while i <= gt:
            v = buf[i]
            if v < pivot:
                buf[i] = buf[lt]
                buf[lt] = v
                lt += 1
                i += 1
            elif v > pivot:
                buf[i] = buf[gt]
                buf[gt] = v
                gt -= 1
            else:
                i += 1
        if k < lt:
            hi = lt - 1
        elif k > gt:
            lo = gt + 1
        else:
            return pivot
        pivot = np.nan
    return buf[lo]


NEAR_RANKS = 32
""":func:`_kth_near` finds the k-th by a scan when it is at most this many ranks from its
guess (else it selects)."""


@njit()
def _kth_near(buf: np.ndarray, n: int, k: int, guess: float, side: np.ndarray) -> float:
    """The k-th smallest (k 0-based) of buf[:n] (float64), near ``guess`` (NaN: none): the
    ranks of ``guess`` counted (less, equal); when the k-th is j <= :data:`NEAR_RANKS`
    ranks above (below) them, it is the j-th smallest value above (largest below) the
    guess: those values gathered into ``side`` (float64 (n,), scratch; negated below) and
    the minimum taken out j times, all without data-dependent branches (a scan that
    inserts into a sorted list mispredicts on every other value); else :func:`_select`
    (which may rearrange buf)."""
    if guess == guess:
        less, equal = 0, 0
        for i in range(n):
            v = buf[i]
            less += v < guess
            equal += v == guess
        if less <= k < less + equal:
            return guess
        above = k >= less + equal
        j = k - less - equal + 1 if above else less - k
        if j <= NEAR_RANKS:
            sign = 1.0 if above else -1.0          # below: the same on -v
            g = sign * guess
            m = 0
            for i in range(n):
                v = sign * buf[i]
                side[m] = v
                m += v > g
            value = 0.0
            for _ in range(j):
                value = np.inf
                at = 0
                for i in range(m):
                    v = side[i]
                    at = i if v < value else at
                    value = v if v < value else value
                m -= 1
                side[at] = side[m]
            return sign * value
    return _select(buf, n, k, guess)


@njit()
def _gather(padded: np.ndarray, r: int, d: int, guard_r: int, guard_d: int, train_r: int,
            train_d: int, buf: np.ndarray) -> int:
    """The training cells of cell (r, d) (``padded``: float64 (n_range + 2 pr, n_doppler +
    2 pd), cell (r, d) at padded[r + pr, d + pd]) into ``buf``, row by row; returns their
    number."""
    pr, pd = guard_r + train_r, guard_d + train_d
    m = 0
    for i in range(2 * pr + 1):
        row = padded[r + i]
        if train_r <= i <= train_r + 2 * guard_r:          # a guard row: its two sides
            for j in range(train_d):
                buf[m] = row[d + j]
                buf[m + train_d] = row[d + pd + guard_d + 1 + j]
                m += 1
            m += train_d
        else:
            for j in range(2 * pd + 1):
                buf[m] = row[d + j]
                m += 1
    return m


@njit()
def os_kth(padded: np.ndarray, guard_r: int, guard_d: int, train_r: int, train_d: int,
           k: int) -> np.ndarray:
    """The k-th smallest (k 1-based) training cell of every cell, float64 (n_range,
    n_doppler), of the padded map ``padded`` (float64 (n_range + 2 pr, n_doppler + 2 pd),
    pr = guard_r + train_r, pd = guard_d + train_d)."""
    pr, pd = guard_r + train_r, guard_d + train_d
    nr, nd = padded.shape[0] - 2 * pr, padded.shape[1] - 2 * pd
    n = (2 * pr + 1) * (2 * pd + 1) - (2 * guard_r + 1) * (2 * guard_d + 1)
    buf = np.empty(n)
    side = np.empty(n)
    out = np.empty((nr, nd))
    guess = np.nan
    for r in range(nr):
        for d in range(nd):
            _gather(padded, r, d, guard_r, guard_d, train_r, train_d, buf)
            guess = _kth_near(buf, n, k - 1, guess, side)
            out[r, d] = guess
        guess = out[r, 0]                   # the next row starts beside this one's first
    return out


@njit()
def os_pad(power: np.ndarray, row_index: np.ndarray, col_index: np.ndarray) -> np.ndarray:
    """``power`` (float32 or float64 (n_range, n_doppler), any memory order) padded by the
    window's reach: float64 (len(row_index), len(col_index)), C order, element (i, j) =
    power[row_index[i], col_index[j]] (``host.cfar._pad_index``'s circular or mirrored
    indices). The columns outermost: a cube's map is Fortran-ordered."""
    out = np.empty((len(row_index), len(col_index)))
    for j in range(len(col_index)):
        src = power[:, col_index[j]]
        for i in range(len(row_index)):
            out[i, j] = src[row_index[i]]
    return out


KEY_LANES = 64
""":func:`os_detect` counts this many cells of a map row at once: its rows of keys are
padded to a multiple (a 127-bin row otherwise leaves a third of it to a scalar loop)."""


@njit()
def _keys(values: np.ndarray, alpha: float, out: np.ndarray) -> np.ndarray:
    """The key of fl(``alpha`` v) for every v of ``values`` (float64 (a, b), any layout)
    into out[:a, :b] (int16 (>= a, >= b)); returns ``out``. The key of a float64 x: x
    rounded to float32, its bits read as an integer ordered as the floats are (negative
    ones flipped), the top 16 bits: non-decreasing in x (each step is), so x < y gives
    key(x) <= key(y) (:func:`os_detect`'s upper bound)."""
    nr, nc = values.shape
    f = np.empty(nc, np.float32)
    b = f.view(np.int32)
    for i in range(nr):
        for j in range(nc):
            f[j] = np.float32(alpha * values[i, j])
        o = out[i]
        for j in range(nc):
            x = b[j]
            o[j] = np.int16((x ^ ((x >> 31) & 0x7FFFFFFF)) >> 16)
    return out


@njit()
def os_detect(padded: np.ndarray, alpha: float, guard_r: int, guard_d: int, train_r: int,
              train_d: int, k: int) -> np.ndarray:
    """Whether at least ``k`` training cells x of each cell have fl(``alpha`` x) < the
    cell's power p, bool (n_range, n_doppler), of the padded map ``padded`` (:func:`os_kth`'s
    layout; p is its centre cell).

    Two passes over each map row. First, for every cell at once (vectorised, on 16-bit
    keys, :func:`_keys`): the first training rows, m >= 2 (n - k + 1) cells of the n,
    counted as key(fl(alpha x)) <= key(p), at least the number with fl(alpha x) < p: a cell
    where that is below k - (n - m) cannot reach k (the noise: nearly every cell). Then the
    others (cells near targets) count fl(alpha x) < p exactly, in float64, row by row until
    the count reaches k or cannot: whole rows first, those the first pass did not see
    first (where a cell that fails mostly fails)."""
    pr, pd = guard_r + train_r, guard_d + train_d
    nr, nd = padded.shape[0] - 2 * pr, padded.shape[1] - 2 * pd
    width = 2 * pd + 1
    n = (2 * pr + 1) * width - (2 * guard_r + 1) * (2 * guard_d + 1)
    lanes = -(-nd // KEY_LANES) * KEY_LANES
    key_x = _keys(padded, alpha, np.zeros((padded.shape[0], lanes + 2 * pd), np.int16))
    key_p = _keys(padded[pr:pr + nr, pd:pd + nd], 1.0, np.zeros((nr, lanes), np.int16))
    rows, m = 0, 0                              # the first pass: whole training rows
    while rows < train_r and m < min(n, 2 * (n - k + 1)):
        rows += 1
        m += width
    need = k - (n - m)
    order = np.empty(2 * pr + 1, np.int64)    # the exact count's rows: whole rows first,
    for i in range(train_r):                  # the bottom ones (not in the first pass) first
        order[i] = 2 * pr - i
        order[train_r + i] = i
    for i in range(2 * guard_r + 1):
        order[2 * train_r + i] = train_r + i
    # int16 counts: n < 2^15, since the map holds the window (cells > n) and
    # host.cfar.check_window bounds n x cells by OS_MAX_ELEMENTS (so n < 14 143)
    count = np.zeros(lanes, np.int16)
    out = np.zeros((nr, nd), np.bool_)
    for r in range(nr):
        q = key_p[r]
        count[:] = 0
        for i in range(rows):
            row = key_x[r + i]
            for o in range(width):
                seg = row[o:o + lanes]
                for d in range(lanes):
                    count[d] += np.int16(seg[d] <= q[d])
        p = padded[r + pr]
        for d in range(nd):
            if count[d] < need:
                continue
            c = 0
            left = n                            # training cells not counted yet
            for i in order:
                if c >= k or c + left < k:      # decided: the rest cannot change it
                    break
                row = padded[r + i]
                if train_r <= i <= train_r + 2 * guard_r:      # a guard row: its two sides
                    for o in range(train_d):
                        c += alpha * row[d + o] < p[d + pd]
                    for o in range(width - train_d, width):
                        c += alpha * row[d + o] < p[d + pd]
                    left -= 2 * train_d
                else:
                    for o in range(width):
                        c += alpha * row[d + o] < p[d + pd]
                    left -= width
            out[r, d] = c >= k
    return out


@njit()
def _kth_keyed(buf: np.ndarray, n: int, k: int, f: np.ndarray, keys: np.ndarray) -> float:
    """The k-th smallest (k 0-based) of buf[:n] (float64) by 16-bit keys, rearranging buf;
    NaN (buf unchanged) when a value is NaN or has its sign bit set (then :func:`_kth_near`
    decides). The keys of :func:`_keys` (unscaled; non-negative values: the float32 bits'
    top half), non-decreasing in the value, so the k-th value has the k-th key K, found by
    a binary search on counts of keys <= t (vectorised); it is then the j-th smallest of
    the few values with key K, j = k - #(key < K) (:func:`_select`). f float32 (n,), keys
    int16 (n,): scratch."""
    for i in range(n):
        f[i] = np.float32(buf[i])
    b = f.view(np.int32)
    lo = b[0]
    hi = b[0]
    for i in range(n):
        lo = min(lo, b[i])
        hi = max(hi, b[i])
    if lo < 0 or hi > 0x7F800000:         # a sign bit or a NaN
        return np.nan
    for i in range(n):
        keys[i] = np.int16(b[i] >> 16)
    lo >>= 16                               # the least t with #(key <= t) > k: between
    hi >>= 16                               # the smallest and the largest key
    while lo < hi:
        mid = (lo + hi) >> 1
        t = np.int16(mid)
        c = np.int32(0)
        for i in range(n):
            c += np.int32(keys[i] <= t)
        if c > k:
            hi = mid
        else:
            lo = mid + 1
    key = np.int16(lo)
    m = 0
    less = 0
    for i in range(n):
        less += keys[i] < key
    for i in range(n):                      # the values of key K, to the front
        if keys[i] == key:
            buf[m] = buf[i]
            m += 1
    return _select(buf, m, k - less, np.nan)


@njit()
def os_kth_at(padded: np.ndarray, rows: np.ndarray, cols: np.ndarray, guard_r: int,
              guard_d: int, train_r: int, train_d: int, k: int) -> np.ndarray:
    """:func:`os_kth` at the cells (rows[i], cols[i]) only, float64 (len(rows),): by keys
    (:func:`_kth_keyed`; cells far apart give :func:`_kth_near` poor guesses)."""
    pr, pd = guard_r + train_r, guard_d + train_d
    n = (2 * pr + 1) * (2 * pd + 1) - (2 * guard_r + 1) * (2 * guard_d + 1)
    buf = np.empty(n)
    side = np.empty(n)
    f = np.empty(n, np.float32)
    keys = np.empty(n, np.int16)
    out = np.empty(len(rows))
    guess = np.nan                           # the previous cell's
    for i in range(len(rows)):
        _gather(padded, rows[i], cols[i], guard_r, guard_d, train_r, train_d, buf)
        value = _kth_keyed(buf, n, k - 1, f, keys)
        if value != value:
            value = _kth_near(buf, n, k - 1, guess, side)
        guess = value
        out[i] = value
    return out


@warm_up
def _compile() -> None:
    """Compile the kernels for the argument types of ``host.cfar``'s calls (the FPGA
    detector's runs never reach them)."""
    index = np.arange(3)
    for dtype in (np.float32, np.float64):
        for order in ("C", "F"):
            os_pad(np.zeros((3, 3), dtype, order=order), index, index)
    padded = np.zeros((5, 5))
    os_kth(padded, 0, 0, 1, 1, 4)
    os_detect(padded, 1.0, 0, 0, 1, 1, 4)
    os_kth_at(padded, np.zeros(1, np.int64), np.zeros(1, np.int64), 0, 0, 1, 1, 4)
