"""Hunting metrics, computed from simulated or measured traces only.

The paper's metric (section 2.3): count the peaks of the position error
x1 - r in a window after the expected settling time ([10 s, 20 s) by
default), with a minimum distance between peaks (0.5 s) and a minimum peak
height (0.1 mm); one peak per hunting cycle. A peak must also stand out from
its surroundings by the minimum height (its prominence), so a stage at rest
or the plateau of a stick phase is never a cycle, and one period with a main
and a secondary bump counts once. A plateau at a cycle's top is one peak, in
its middle, even where round-off steps its samples up and down; a cycle that
stays below the target counts its negative peaks.

The metric judges one trace: whether the *stage* hunts is answered over a
family of moves and by the cycle itself (:mod:`fi_design.stage`).

The count alone is blind in two ways, and the verdict here is not:

- a stage stuck far from its target shows no peaks: verdict ``stuck``;
- a cycle slower than the window, or a slow creep, shows none either:
  verdict ``undetermined`` ("too slow to judge in this window").

Only a stage whose error stays inside the settle band at the end of the
window is ``settled``; a run that ends, or a window that closes, before the
motion does is never settled: ``undetermined`` ("not finished"), since a
stage on its ramp follows the reference within the band. A motion that ends
inside the window is ``undetermined`` too (the count would take the move's
own overshoot for a cycle); so is a trace that ends inside the window
without a counted peak (it sees part of the window only).
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from ..display import quantity
from ..kernel import taken
from ..kernel.build import compiled
from ..results import frozen_array
from ..results.simulation import VERDICTS, HuntingMetrics

__all__ = ["VERDICTS", "HuntingMetrics", "counted_peaks", "find_peaks", "hunting_metrics"]

#: :func:`~fi_design.display.quantity` for the verdict's reason: the settings' values, which
#: every trace judged under them repeats, and the trace's (a pure function of its
#: arguments, kept by their type).
_shown = lru_cache(maxsize=64, typed=True)(quantity)


def hunting_metrics(time_s, error_m, *, window_start: float = 10.0, window_length: float = 10.0,
                    min_distance: float = 0.5, min_height: float = 1e-4,
                    settle_band: float = 1e-5, motion_end: float = 0.0,
                    success: bool = True, failure: str = "") -> HuntingMetrics:
    """Evaluate the hunting metric and the verdict on a trace.

    Parameters
    ----------
    time_s : array_like, shape (n,)
        Sample times [s], increasing (uniform sampling expected by the
        paper's metric; the peak distance is converted with the median step).
    error_m : array_like, shape (n,)
        Position error x1 - r [m].
    window_start, window_length : float
        Counting window [s].
    min_distance : float
        Minimum time between counted peaks [s].
    min_height : float
        Minimum peak height of x1 - r [m].
    settle_band : float
        Band for ``settled`` and the settling time [m].
    motion_end : float
        End of the last move [s]; the settling time counts from here. A
        trace or window that ends before it is not finished: ``undetermined``.
    success : bool
        Whether the trace is complete; an incomplete one is ``undetermined``.
    failure : str
        Why the trace is incomplete (used in ``reason``).

    Returns
    -------
    HuntingMetrics
    """
    t = taken(time_s)
    e = taken(error_m)
    w0, w1 = window_start, window_start + window_length
    # the times increase: the window and its last quarter are slices
    a, b = int(t.searchsorted(w0)), int(t.searchsorted(w1))
    tw, ew = _finite(t[a:b], e[a:b])
    finite = len(ew) == b - a  # every sample of the window is
    idx = _NO_PEAKS
    lowest, highest = compiled().extremes(ew) if len(ew) else (math.nan, math.nan)
    amplitude = highest - lowest
    # a peak's prominence is at most the trace's range: below min_height, no side has one
    if len(tw) > 1 and amplitude >= min_height:
        distance = _peak_distance(tw, min_distance)
        # a peak must stand out by min_height from its surroundings (prominence), so a
        # plateau's numerical noise or a secondary bump of one period is no cycle; a cycle
        # below the target shows its negative peaks: count the side that shows more
        for side, top in ((1.0, highest), (-1.0, -lowest)):
            if top < min_height:
                continue  # no sample reaches the least peak height on this side
            found = counted_peaks(ew if side > 0.0 else -ew, min_height, distance)
            if len(found) > len(idx):
                idx = found
    peaks_t, peaks_h = tw[idx], ew[idx]
    cycles = int(len(idx))
    # np.mean(np.diff(peaks_t)) without its Python layers: the same sum and division
    period = float(np.add.reduce(peaks_t[1:] - peaks_t[:-1]) / (cycles - 1)) \
        if cycles >= 2 else None
    # the last finite error (a failed run ends in NaN)
    end = e[-1:] if len(e) and math.isfinite(e[-1]) else e[np.isfinite(e)][-1:]
    final_error = float(end[0]) if len(end) else float("nan")

    t_last = float(t[-1]) if len(t) else 0.0
    moving = motion_end > min(w1, t_last)  # the motion outlasts the window or the run
    # the motion ends after the window opens: the count would take its own overshoot
    late = not moving and motion_end > w0
    # the trace ends inside the window (more than a step and a half before its end)
    step = float(t[-1] - t[-2]) if len(t) > 1 else 0.0
    short = not moving and w0 < t_last < w1 - 1.5 * step
    c = max(a, int(t.searchsorted(w1 - window_length / 4.0)))
    settled = bool(success and not moving and _within(e, c, b, settle_band, finite))
    settling_time = _settling_time(t, e, settle_band, motion_end) if success else None

    if not success:
        verdict, reason = "undetermined", f"the simulation did not complete: {failure}"
    elif moving:
        what = "run" if t_last <= w1 else "counting window"
        verdict = "undetermined"
        reason = (f"not finished: the motion runs until {_shown(motion_end, 's', 4)}, past "
                  f"the end of the {what} at {_shown(min(w1, t_last), 's', 4)}; the stage is "
                  "still moving")
    elif late:
        verdict = "undetermined"
        reason = (f"the motion ends at {_shown(motion_end, 's', 4)}, after the counting window "
                  f"opens at {_shown(w0, 's', 4)}: the count would take the move's own "
                  "overshoot for hunting (start the window after the motion)")
    elif len(ew) < 2:
        verdict, reason = "undetermined", "the trace does not cover the counting window"
    elif cycles > 0:
        verdict = "hunting"
        reason = (f"{cycles} peak(s) of at least {_shown(min_height, 'm', 6)} in "
                  f"[{_shown(w0, 's', 6)}, {_shown(w1, 's', 6)})"
                  + (f", period {_shown(period, 's', 3)}" if period else ""))
    elif short:
        verdict = "undetermined"
        reason = (f"the trace ends at {_shown(t_last, 's', 4)}, inside the counting window "
                  f"[{_shown(w0, 's', 6)}, {_shown(w1, 's', 6)}): it covers the window in "
                  "part only")
    elif settled:
        verdict = "settled"
        reason = f"|x1 - r| stays within {_shown(settle_band, 'm', 3)} at the end of the window"
    elif amplitude <= settle_band:
        verdict = "stuck"
        reason = (f"the stage rests {_shown(abs(final_error), 'm', 3)} from its target: no peaks, "
                  "but not settled either (the integrator has not broken it loose in the window)")
    else:
        verdict = "undetermined"
        reason = (f"no peaks counted, but the error still moves by {_shown(amplitude, 'm', 3)} in "
                  "the window: a cycle or creep too slow to judge in this window")
    return HuntingMetrics(
        hunting_cycles=cycles, peak_times=frozen_array(peaks_t), peak_heights=frozen_array(peaks_h),
        amplitude=amplitude, period=period, settled=settled, settling_time=settling_time,
        final_error=final_error, verdict=verdict, reason=reason, window=(w0, w1),
        settle_band=settle_band)


def find_peaks(y, height: float, prominence: float, distance: int) -> np.ndarray:
    """scipy's ``find_peaks(y, height=height, prominence=prominence, distance=distance)[0]``.

    The same indices, by the compiled steps of :mod:`fi_design.kernel.metric`
    (the order of equal heights from numpy's ``argsort``, as scipy takes it).

    Parameters
    ----------
    y : array_like, shape (n,)
        The trace, finite [m].
    height, prominence : float
        The least peak height and prominence [m].
    distance : int
        The least distance between peaks [samples], at least 1.

    Returns
    -------
    ndarray of int
        The peaks' indices, increasing.
    """
    return _peak_search(taken(y), height, prominence, distance)


def counted_peaks(y, min_height: float, distance: int) -> np.ndarray:
    """The peaks the metric counts: :func:`find_peaks` with ``min_height`` as the least height
    and prominence, one peak per plateau.

    scipy's prominence looks past a neighbour of *equal* height (it stops at a
    strictly higher one), so the samples of a stick plateau that round to the
    same value, with dips of a unit in the last place between them, would each
    stand out by the whole cycle. Adjacent peaks are one peak unless the trace
    falls by ``min_height`` below the lower of the two between them. The peak
    kept is the middle of its flat top (the samples within a millionth of
    ``min_height`` of its highest one), as scipy places a peak on an exactly
    flat top: one time per cycle, wherever the rounding puts the highest sample.

    Parameters
    ----------
    y : array_like, shape (n,)
        The trace, finite [m].
    min_height : float
        The least peak height and prominence, and the dip that parts two peaks [m].
    distance : int
        The least distance between peaks [samples], at least 1.

    Returns
    -------
    ndarray of int
        The indices kept, increasing.
    """
    y = taken(y)
    found = _peak_search(y, min_height, min_height, distance)
    return found[:compiled().one_per_plateau(y, found, len(found), float(min_height))]


def _peak_search(y: np.ndarray, height: float, prominence: float, distance: int) -> np.ndarray:
    """:func:`find_peaks` on a float64, C-contiguous, writable ``y`` (a fresh index array)."""
    k = compiled()
    found = np.empty(len(y) // 2 + 1, dtype=np.int64)
    m = k.local_maxima(y, float(height), found)
    if m == 0:
        return found[:0]
    order = y[found[:m]].argsort().astype(np.int64, copy=False)
    m = k.select_peaks(y, found, m, order, int(distance), float(prominence))
    return found[:m]


#: No peak (the metric's indices before a side has any; never written).
_NO_PEAKS = np.zeros(0, dtype=int)


def _finite(t: np.ndarray, e: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The samples of ``t`` and ``e`` where ``e`` is finite (the arrays themselves if all are)."""
    if math.isfinite(np.add.reduce(e)):  # NaN and infinity carry into a sum: all are finite
        return t, e
    ok = np.isfinite(e)
    return (t, e) if ok.all() else (t[ok], e[ok])


def _within(e: np.ndarray, c: int, b: int, band: float, finite: bool) -> bool:
    """Whether ``e[c:b]`` holds a finite sample and its finite samples stay within ``band`` [m].

    ``finite``: every sample there is (the search runs from the end and stops at the
    first sample outside).
    """
    if finite:
        return bool(c < b and compiled().last_outside(e[:b], c, band) < 0)
    tail = e[c:b][np.isfinite(e[c:b])]
    return bool(len(tail) and np.all(np.abs(tail) <= band))


def _peak_distance(t: np.ndarray, min_distance: float) -> int:
    """The least distance between peaks in samples: ``min_distance`` over the median step of
    the times ``t`` [s] (at least two).

    The median is taken only when the steps' range leaves a choice (the
    rounded count of the smallest and of the largest step differ): on a
    uniform trace they agree, and a median costs more than the peak search.
    """
    def samples(dt: float) -> int:
        return max(1, int(round(min_distance / dt)))

    shortest, longest = compiled().step_range(t)
    few, many = samples(longest), samples(shortest)
    return few if few == many else samples(float(np.median(np.diff(t))))


def _settling_time(t: np.ndarray, e: np.ndarray, band: float, start: float) -> float | None:
    after = int(t.searchsorted(start))  # the times increase
    if after == len(t):
        return None
    last = compiled().last_outside(e, after, band)  # searched from the end
    if last < 0:
        return 0.0
    if last == len(t) - 1:
        return None
    return float(t[last + 1] - start)
