"""The hunting metric and its verdicts on synthetic traces with known answers."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fi_design.simulation.metrics import hunting_metrics

T = np.arange(20001) / 1000.0


def test_counts_one_peak_per_cycle():
    e = 0.5e-3 * np.sin(2 * np.pi * T / 2.0)  # 2 s period: 5 cycles in [10, 20)
    m = hunting_metrics(T, e)
    assert m.hunting_cycles == 5
    assert m.period == pytest.approx(2.0, abs=1e-3)
    assert m.amplitude == pytest.approx(1e-3, rel=1e-4)
    assert m.verdict == "hunting"
    assert np.all((m.peak_times >= 10.0) & (m.peak_times < 20.0))


def test_small_oscillation_below_min_height_is_not_counted():
    e = 0.05e-3 * np.sin(2 * np.pi * T / 2.0)
    m = hunting_metrics(T, e)
    assert m.hunting_cycles == 0
    # it still moves by 100 um in the window: not settled, not stuck
    assert m.verdict == "undetermined"


def test_peaks_closer_than_min_distance_count_once():
    e = 0.5e-3 * np.sin(2 * np.pi * T / 0.3)  # 0.3 s apart < 0.5 s minimum distance
    m = hunting_metrics(T, e)
    assert m.hunting_cycles < 10 / 0.3 and m.hunting_cycles == pytest.approx(10 / 0.6, abs=2)


def test_stuck_far_from_target_is_stuck_not_settled():
    e = np.where(T < 3.0, 1e-3 * (1 - T / 3.0), 0.0) + 50e-6  # rests 50 um off
    m = hunting_metrics(T, e)
    assert m.hunting_cycles == 0
    assert m.verdict == "stuck" and not m.settled
    assert m.final_error == pytest.approx(50e-6)


def test_cycle_slower_than_the_window_is_undetermined():
    e = 1e-3 * np.sin(2 * np.pi * (T - 10.0) / 40.0 - np.pi / 2)  # one slow swing in the window
    m = hunting_metrics(T, e)
    assert m.hunting_cycles == 0
    assert m.verdict == "undetermined"
    assert "too slow" in m.reason


def test_settled_and_settling_time():
    e = 1e-3 * np.exp(-(T - 2.0).clip(0) / 0.5)
    m = hunting_metrics(T, e, motion_end=2.0, settle_band=10e-6)
    assert m.verdict == "settled" and m.settled
    # exp(-t / 0.5) = 0.01 at t = 0.5 ln 100
    assert m.settling_time == pytest.approx(0.5 * np.log(100), abs=2e-3)


def test_incomplete_simulation_is_undetermined():
    m = hunting_metrics(T, np.zeros_like(T), success=False, failure="diverged at t = 3 s")
    assert m.verdict == "undetermined" and "diverged" in m.reason
    assert m.settling_time is None


@settings(max_examples=40, deadline=None)
@given(period=st.floats(0.6, 3.0), amp=st.floats(0.2e-3, 5e-3), phase=st.floats(0, 6.28))
def test_cycle_count_matches_the_window(period, amp, phase):
    """A sine of period P shows floor or ceil of 10 / P peaks in a 10 s window."""
    e = amp * np.sin(2 * np.pi * T / period + phase)
    m = hunting_metrics(T, e)
    assert abs(m.hunting_cycles - 10.0 / period) <= 1.0
    assert m.verdict == "hunting"
    assert m.amplitude == pytest.approx(2 * amp, rel=0.01)


def test_a_stage_at_rest_off_target_is_never_a_cycle():
    """A PD stage resting 2.85 mm past its target with round-off noise: no peak, stuck."""
    rng = np.random.default_rng(1)
    e = 2.85e-3 + 4e-16 * rng.standard_normal(T.shape)
    m = hunting_metrics(T, e)
    assert m.hunting_cycles == 0 and m.verdict == "stuck"


def test_one_period_with_a_secondary_bump_counts_once():
    """A stick-slip period: a slip peak, then a plateau with a small bump 1.2 s later."""
    period = 3.3
    ph = np.mod(T, period)
    main = 0.9e-3 * np.exp(-((ph - 0.2) / 0.1) ** 2)
    bump = 0.4e-3 + 0.02e-3 * np.exp(-((ph - 1.4) / 0.2) ** 2)  # on a 0.4 mm plateau
    low = 0.9e-3 * np.exp(-((ph - 1.85) / 0.1) ** 2)
    e = np.where(ph < 0.2, main, np.where(ph < 1.65, np.maximum(main, bump), -np.where(
        ph < 1.85, low, np.maximum(low, 0.4e-3))))
    m = hunting_metrics(T, e)
    assert m.hunting_cycles == 3
    assert m.period == pytest.approx(period, rel=1e-3)


def test_a_cycle_below_the_target_counts_its_negative_peaks():
    e = -0.6e-3 + 0.4e-3 * np.sin(2 * np.pi * T / 2.0)  # never above -0.2 mm
    m = hunting_metrics(T, e)
    assert m.hunting_cycles == 5 and m.verdict == "hunting"


def test_a_stick_plateau_with_round_off_counts_once():
    """Karnopp stick-slip: a 0.5 s slip, then 0.75 s stuck at +-0.5 mm, period 2.5 s.

    While stuck, x1 - r rounds to three neighbouring floats (as a switch-model run
    does near r = 1 m): equal maxima with dips of 1e-16 m between them are one plateau,
    one peak in its middle, not one peak per rounding step.
    """
    period, slip, a = 2.5, 0.5, 0.5e-3
    ph = np.mod(T, period)
    half = period / 2.0
    up = -a * np.cos(np.pi * np.clip(ph / slip, 0.0, 1.0))  # -a to +a, then stuck at +a
    down = a * np.cos(np.pi * np.clip((ph - half) / slip, 0.0, 1.0))  # +a to -a, then stuck
    e = np.where(ph < half, up, down)
    rng = np.random.default_rng(3)
    stuck = np.abs(np.abs(e) - a) == 0.0
    e = np.where(stuck, e + rng.integers(-1, 2, T.shape) * 1.1e-16, e)
    assert len(np.unique(e[stuck])) > 2  # the plateaus hold rounding steps
    m = hunting_metrics(T, e)
    assert m.hunting_cycles == 4  # plateaus at 10.5, 13, 15.5 and 18 s
    assert m.period == pytest.approx(period, abs=2e-3)
    middles = 10.0 + slip + (half - slip) / 2.0 + period * np.arange(4)
    assert m.peak_times == pytest.approx(middles, abs=0.05)


def test_a_plateau_of_thousands_of_samples_counts_once_in_its_middle():
    """A stage stuck for 3.6 s (3600 samples at 1 kHz, rounding steps on its top) between
    two slips: one peak, in the middle of the stuck stretch, however long it is."""
    a = 0.5e-3
    rise = np.clip((T - 10.2) / 0.8, 0.0, 1.0)  # -a at 10.2 s to +a at 11 s
    fall = np.clip((T - 14.6) / 0.8, 0.0, 1.0)  # +a at 14.6 s to -a at 15.4 s
    e = -a * np.cos(np.pi * rise) * np.cos(np.pi * fall)
    rng = np.random.default_rng(5)
    top = (T >= 11.0) & (T <= 14.6)
    e = np.where(top, a + rng.integers(-1, 2, T.shape) * 1.1e-16, e)
    m = hunting_metrics(T, e)
    assert m.hunting_cycles == 1
    assert m.peak_times[0] == pytest.approx((11.0 + 14.6) / 2.0, abs=2e-3)


@pytest.mark.parametrize("motion_end", [250.0, 20.5, 25.0])
def test_a_motion_that_outlasts_the_run_or_window_is_not_finished(motion_end):
    """A stage on its ramp follows the reference within the band: no cycles, error zero. The
    move ends at 250 s (a 5 m move at 20 mm/s) in a 20 s run: never settled."""
    e = 1e-9 * np.sin(T)
    done = hunting_metrics(T, e, motion_end=2.0)
    assert done.verdict == "settled"
    m = hunting_metrics(T, e, motion_end=motion_end)
    assert m.verdict == "undetermined" and not m.settled
    assert m.reason.startswith("not finished") and f"{motion_end:.4g} s" in m.reason
    assert m.settling_time is None
    longer = np.arange(40001) / 1000.0  # a 40 s run, the window [10 s, 20 s) inside the move
    w = hunting_metrics(longer, 1e-9 * np.sin(longer), motion_end=motion_end)
    assert w.verdict == "undetermined" and "counting window at 20 s" in w.reason


def test_a_motion_that_ends_inside_the_window_is_not_counted():
    """A 0.99 m move at 50 mm/s ends at 19.85 s in a [10 s, 20 s) window: its deceleration
    overshoot (0.15 mm) was counted as one hunting cycle. Now undetermined."""
    after = np.maximum(T - 19.85, 0.0)
    e = np.where(T > 19.85, 0.15e-3 * np.exp(-after / 0.02) * np.sin(2 * np.pi * after / 0.1),
                 0.0)
    m = hunting_metrics(T, e, motion_end=19.85)
    assert m.verdict == "undetermined" and m.hunting_cycles >= 0
    assert "after the counting window opens at 10 s" in m.reason


def test_a_trace_that_ends_inside_the_window_is_undetermined():
    """A 12 s run at rest within the band read 'stuck' (a 5 s run 'does not cover the
    window'); a record sampled at 1 kHz up to 19.999 s still covers [10 s, 20 s)."""
    short = T[T <= 12.0]
    m = hunting_metrics(short, 3.5e-12 + 0.0 * short, motion_end=0.3)
    assert m.verdict == "undetermined" and "covers the window in part only" in m.reason
    cycling = 0.5e-3 * np.sin(2 * np.pi * short / 0.7)  # peaks counted in part: hunting
    assert hunting_metrics(short, cycling, motion_end=0.3).verdict == "hunting"
    record = T[:-1]  # ends one step before the window's end
    assert hunting_metrics(record, 0.0 * record, motion_end=0.3).verdict == "settled"
