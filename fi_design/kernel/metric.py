"""The hunting metric's loops, compiled: scipy's ``find_peaks``, one peak per plateau, a trace's
extremes and its last sample outside a band.

:func:`fi_design.simulation.metrics.hunting_metrics` counts the peaks of a
trace with scipy's ``find_peaks(y, height=h, prominence=h, distance=d)``
and keeps one per plateau. In numpy and scipy that was most of the time
``simulate()`` spends after the kernel (some 0.3 ms on a hunting trace of
10,000 samples: many small array operations). Here the same steps run as
loops, in scipy's order and with scipy's comparisons, so the indices are the
same (``tests/simulation/test_peaks.py`` checks it against scipy):

1. :func:`local_maxima`: scipy's local maxima (a flat top's middle sample)
   that reach the height;
2. the caller sorts their heights with numpy's ``argsort``, as scipy does
   (the order of equal heights is numpy's; this module does not sort);
3. :func:`select_peaks`: scipy's least distance, highest peak first, then
   the least prominence;
4. :func:`one_per_plateau`: peaks that no dip of the least height parts are
   one, placed in the middle of their flat top.

:func:`extremes`, :func:`step_range` and :func:`last_outside` replace
numpy's ``min``, ``max``, ``diff`` and a search over the whole trace (each
an array operation of 10 to 25 us on 20,000 samples) by one loop, or a
search from the end that stops at the first sample outside the band.

The traces are position errors [m]; heights, prominences and dips are in the
trace's unit, distances in samples.
"""

from __future__ import annotations

import numpy as np

from .jit import A1, I1, f8, i8, kernel_function


@kernel_function((A1, f8, I1))
def local_maxima(x, height, out):
    """scipy's local maxima of ``x`` that reach ``height``, into ``out``; returns their count.

    A maximum is a sample (or a run of equal samples: its middle, the lower
    of two) with a lower neighbour on each side, the trace's ends excluded
    (scipy's ``_local_maxima_1d``); it is kept where ``height <= x``.
    ``out`` holds at least ``len(x) // 2`` indices.
    """
    m = 0
    i = 1
    i_max = x.shape[0] - 1
    while i < i_max:
        # a top below the height is no peak here: skipped at once (scipy finds it, then
        # drops it; the maxima are the same runs of equal samples either way)
        if height <= x[i] and x[i - 1] < x[i]:
            ahead = i + 1
            while ahead < i_max and x[ahead] == x[i]:
                ahead += 1
            if x[ahead] < x[i]:
                out[m] = (i + ahead - 1) // 2
                m += 1
                i = ahead
        i += 1
    return m


@kernel_function((A1, i8, i8, f8), inline=True)
def _prominent(x, peak, n, prominence):
    """Whether the peak's prominence (scipy's) reaches ``prominence``.

    The prominence is ``top - max(left, right)``, the lowest samples on each
    side before a strictly higher one; rounding keeps ``top - max(a, b) =
    min(top - a, top - b)``, so it reaches ``prominence`` exactly when some
    sample on each side lies ``prominence`` below the top: each side's search
    stops at the first such sample, not at the next higher one (for the
    highest peak, the trace's end).
    """
    top = x[peak]
    i = peak
    while True:
        if i < 0 or x[i] > top:
            return False
        if prominence <= top - x[i]:
            break
        i -= 1
    i = peak
    while True:
        if i >= n or x[i] > top:
            return False
        if prominence <= top - x[i]:
            return True
        i += 1


@kernel_function((A1, I1, i8, I1, i8, f8), refcounted=True)
def select_peaks(x, peaks, m, order, distance, prominence):
    """Keep the first ``m`` ``peaks`` that scipy's ``distance`` and ``prominence`` keep.

    ``order``: numpy's ``argsort`` of ``x[peaks[:m]]``. From the highest peak
    down, a peak still kept drops its neighbours closer than ``distance``
    samples (scipy's ``_select_by_peak_distance``); then a peak stays where
    ``prominence <=`` its prominence (:func:`_prominent`). The kept indices
    are moved to the front of ``peaks``, in order; returns their count.
    """
    keep = np.ones(m, dtype=np.bool_)
    for i in range(m - 1, -1, -1):
        j = order[i]
        if not keep[j]:
            continue
        k = j - 1
        while 0 <= k and peaks[j] - peaks[k] < distance:
            keep[k] = False
            k -= 1
        k = j + 1
        while k < m and peaks[k] - peaks[j] < distance:
            keep[k] = False
            k += 1
    n = x.shape[0]
    c = 0
    for j in range(m):
        if keep[j] and _prominent(x, peaks[j], n, prominence):
            peaks[c] = peaks[j]
            c += 1
    return c


@kernel_function((A1, i8, i8, f8), inline=True)
def _parted(x, a, b, min_height):
    """Whether ``x`` falls by ``min_height`` below the lower of ``x[a]`` and ``x[b]`` in
    between (both included).

    As for the prominence (:func:`_prominent`), the lower of the two less the
    lowest sample reaches ``min_height`` exactly when one sample does: the
    search stops there.
    """
    lower = min(x[a], x[b])
    for i in range(a, b + 1):
        if lower - x[i] >= min_height:
            return True
    return False


@kernel_function((A1, I1, i8, f8))
def one_per_plateau(x, peaks, m, min_height):
    """One peak per plateau among the first ``m`` ``peaks`` (increasing); returns the count kept.

    Adjacent peaks are one unless ``x`` falls by ``min_height`` below the
    lower of the two between them (both included). Of each such group the
    highest peak (the first of equal ones) marks the flat top: the samples
    around it at or above its height less a millionth of ``min_height``; the
    index kept is that top's middle (the lower of two). The kept indices
    replace the first entries of ``peaks``.
    """
    c = 0
    first = 0
    while first < m:
        # the group: until a dip of min_height parts a peak from the next
        best = first
        last = first
        while last + 1 < m:
            if _parted(x, peaks[last], peaks[last + 1], min_height):
                break
            last += 1
            if x[peaks[last]] > x[peaks[best]]:
                best = last
        top = peaks[best]
        level = x[top] - 1e-6 * min_height
        lo = top
        while lo > 0 and not (x[lo - 1] < level):
            lo -= 1
        hi = top
        while hi < x.shape[0] - 1 and not (x[hi + 1] < level):
            hi += 1
        peaks[c] = (lo + hi) // 2
        c += 1
        first = last + 1
    return c


@kernel_function((A1,))
def extremes(x):
    """The smallest and largest sample of ``x`` (numpy's ``min`` and ``max`` of finite samples).

    ``x`` holds at least one sample, all finite.
    """
    lo = x[0]
    hi = x[0]
    for i in range(1, x.shape[0]):
        v = x[i]
        if v < lo:
            lo = v
        elif v > hi:
            hi = v
    return lo, hi


@kernel_function((A1,))
def step_range(t):
    """The smallest and largest step ``t[i + 1] - t[i]`` of at least two times [s]."""
    lo = t[1] - t[0]
    hi = lo
    for i in range(1, t.shape[0] - 1):
        d = t[i + 1] - t[i]
        if d < lo:
            lo = d
        elif d > hi:
            hi = d
    return lo, hi


@kernel_function((A1, i8, f8))
def last_outside(x, start, band):
    """The last index from ``start`` on where ``|x| <= band`` fails (NaN fails), or -1."""
    for i in range(x.shape[0] - 1, start - 1, -1):
        if not abs(x[i]) <= band:
            return i
    return -1
