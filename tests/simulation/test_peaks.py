"""The metric's compiled peak search gives scipy's answer, index for index.

scipy's ``find_peaks`` is the independent reference: on random traces with
plateaus (flat, and stepped by round-off), noise, ties of equal heights and
negative values, :func:`fi_design.simulation.metrics.find_peaks` returns the
same indices for random least heights, prominences and distances, and
:func:`~fi_design.simulation.metrics.counted_peaks` the same as scipy's
search followed by the numpy merge of plateaus the metric used before
(:func:`_numpy_one_per_plateau`, kept here as the reference).
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import signal

from fi_design.simulation.metrics import counted_peaks, find_peaks


def _numpy_one_per_plateau(y, peaks, min_height):
    """The metric's merge of plateaus in numpy (fi_design before the compiled search)."""
    if len(peaks) == 0:
        return peaks
    heights = y[peaks]
    dips = np.minimum(np.minimum.reduceat(y, peaks)[:-1], heights[1:])
    parted = np.minimum(heights[:-1], heights[1:]) - dips >= min_height
    starts = [0, *(np.flatnonzero(parted) + 1)]
    keep = []
    for a, b in zip(starts, [*starts[1:], len(peaks)]):
        top = int(peaks[a + int(np.argmax(heights[a:b]))])
        level = y[top] - 1e-6 * min_height
        below = np.flatnonzero(y < level)
        lo = int(below[below < top].max()) + 1 if np.any(below < top) else 0
        hi = int(below[below > top].min()) - 1 if np.any(below > top) else len(y) - 1
        keep.append((lo + hi) // 2)
    return np.asarray(keep, dtype=int)


def _trace(seed: int, n: int, kind: str) -> np.ndarray:
    """A random trace of ``n`` samples [m]: levels with ties, noisy sines, stepped plateaus."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / 1000.0
    if kind == "levels":  # few distinct values: plateaus and ties everywhere
        return rng.integers(-3, 4, n) * 0.2e-3
    if kind == "walk":  # a random walk with flat stretches
        steps = rng.standard_normal(n) * 0.05e-3 * (rng.random(n) < 0.3)
        return np.cumsum(steps) - 0.2e-3
    period = rng.uniform(0.05, 3.0)
    y = rng.uniform(0.05e-3, 2e-3) * np.sin(2 * np.pi * t / period + rng.uniform(0, 6.3))
    y += rng.uniform(-1e-3, 1e-3)
    if kind == "noisy":
        return y + rng.standard_normal(n) * rng.choice([1e-16, 1e-6, 0.05e-3])
    # "stick": a cycle clipped to plateaus, stepped by round-off as a stuck stage's error is
    top = rng.uniform(0.1, 0.9) * np.max(np.abs(y), initial=0.0)
    y = np.clip(y, -top, top)
    flat = np.abs(y) == top
    return np.where(flat, y + rng.integers(-1, 2, n) * 1.1e-16, y)


KINDS = ("levels", "walk", "noisy", "stick")


@settings(max_examples=300, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(0, 3000), kind=st.sampled_from(KINDS),
       height=st.floats(-2e-3, 2e-3), prominence=st.floats(0.0, 1e-3),
       distance=st.integers(1, 800), sign=st.sampled_from((1.0, -1.0)))
def test_find_peaks_is_scipys(seed, n, kind, height, prominence, distance, sign):
    y = sign * _trace(seed, n, kind)
    expected, _ = signal.find_peaks(y, height=height, prominence=prominence, distance=distance)
    np.testing.assert_array_equal(find_peaks(y, height, prominence, distance), expected)


@settings(max_examples=300, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(0, 3000), kind=st.sampled_from(KINDS),
       min_height=st.floats(1e-6, 1e-3), distance=st.integers(1, 800),
       sign=st.sampled_from((1.0, -1.0)))
def test_counted_peaks_are_scipys_with_one_per_plateau(seed, n, kind, min_height, distance, sign):
    y = sign * _trace(seed, n, kind)
    found, _ = signal.find_peaks(y, height=min_height, prominence=min_height, distance=distance)
    expected = _numpy_one_per_plateau(y, found, min_height)
    np.testing.assert_array_equal(counted_peaks(y, min_height, distance), expected)


@pytest.mark.parametrize("kind", KINDS)
def test_many_long_traces_at_the_metrics_settings(kind):
    """10,000-sample windows (the paper's 10 s at 1 kHz), 0.1 mm and 500 samples, both sides."""
    for seed in range(40):
        for y in (_trace(seed, 10_000, kind), -_trace(seed, 10_000, kind)):
            found, _ = signal.find_peaks(y, height=1e-4, prominence=1e-4, distance=500)
            np.testing.assert_array_equal(find_peaks(y, 1e-4, 1e-4, 500), found)
            np.testing.assert_array_equal(counted_peaks(y, 1e-4, 500),
                                          _numpy_one_per_plateau(y, found, 1e-4))


def test_a_read_only_trace_is_read():
    y = 1e-3 * np.sin(np.arange(5000) / 100.0)
    y.setflags(write=False)
    np.testing.assert_array_equal(find_peaks(y, 1e-4, 1e-4, 10),
                                  signal.find_peaks(y, height=1e-4, prominence=1e-4,
                                                    distance=10)[0])
