"""Stage-level hunting: the move family, the cycle as a periodic orbit, the fold.

Checked against what the product did not generate: the independent solve_ivp
simulator of ``tests/independent.py`` (the cycle's amplitude and period after
a long run, moves that hunt just below the fold), Canudas de Wit et al.
(1995)'s unit-mass PID example (a published period and amplitude), and a
dense move scan for the boundary.
"""

from __future__ import annotations

import functools

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from fi_design.model import resolve
from fi_design.stage import (converge_cycle, family_distances, rest_is_final, stage_hunting,
                             stage_hunts)

from published import canudas_spec

#: The paper setup (isolated, 8 Hz): its independent-simulator parameters.
PAPER = dict(m1=1.6, m2=0.4, friction=dict(Fs=4.0, Fc=1.0, vs=3e-3, sigma0=1e6, sigma1=1414.0,
                                           sigma2=20.0),
             isolator=dict(k=6667.0, s=0.3e-3, c=4.62))


@pytest.fixture(scope="module")
def paper_isolated(paper_spec):
    """The stage-level answer of the paper setup's isolated plant at 8 Hz."""
    return stage_hunting(paper_spec, True)


def _upward_crossings(t, e):
    i = np.nonzero((e[:-1] < 0) & (e[1:] >= 0))[0]
    return t[i] - e[i] * (t[i + 1] - t[i]) / (e[i + 1] - e[i])


# --------------------------------------------------------------------------- the family


def test_family_spans_a_tenth_of_the_stroke_to_five_times_the_move(paper_spec):
    d = family_distances(resolve(paper_spec), True)
    assert len(d) == 24
    assert d[0] == pytest.approx(0.03e-3) and d[-1] == pytest.approx(50e-3)
    assert np.all(np.diff(np.log(d)) == pytest.approx(np.log(d[1] / d[0])))
    assert family_distances(resolve(paper_spec), False)[0] == pytest.approx(0.1e-3)


def test_asymmetric_friction_tries_both_directions(paper_spec):
    from conftest import variant

    from fi_design.model import resolve

    spec = variant(paper_spec, **{"friction.coulomb_negative": "1.5 N"})
    d = family_distances(resolve(spec), True, resolve(spec).plant(True))
    assert len(d) == 48 and sum(x < 0 for x in d) == 24
    sym = family_distances(resolve(paper_spec), True, resolve(paper_spec).plant(True))
    assert all(x > 0 for x in sym)


# --------------------------------------------------------------------------- the paper setup


def test_paper_setup_hunts_on_its_cycle_but_rests_after_its_own_move(paper_isolated):
    st = paper_isolated
    spec_move = st.moves[0]
    assert spec_move.label == "spec" and spec_move.outcome == "settles"
    assert st.hunts and st.outcome == "hunts"
    entered = [round(d * 1e3, 1) for d in st.entered_by]
    # issue figures: 1, 15, 20 and 30 mm moves hunt (the family's 1.04, 13.8, 19, 26, 36 mm)
    assert 1.0 in entered and 19.0 in entered and 26.2 in entered
    c = st.cycle
    assert c.method == "shooting" and c.stable and c.residual < 1e-6
    assert c.amplitude == pytest.approx(1.80e-3, rel=2e-3)
    assert c.on_limiter is True and c.deflection_range[1] >= 0.3e-3
    # the multiplier is a property of the orbit, not of the finite differences
    assert c.multiplier == pytest.approx(c.multiplier_check, rel=0.05)
    assert 0.0 < c.multiplier < 1.0
    assert all(m.amplitude == pytest.approx(c.amplitude, rel=1e-2) for m in st.hunting_moves)


def test_paper_cycle_agrees_with_a_long_independent_simulation(paper_isolated):
    """A 20 mm move simulated for 30 s by solve_ivp ends on the same cycle.

    At rtol 1e-7 (the simulator's default is 1e-8, at 1.4 times the CPU): the extrapolated
    period, the amplitude and the convergence ratio are those of rtol 1e-8 to 3e-8, 1e-9 and
    2e-5 (relative, relative, absolute) - the cycle attracts, so errors do not accumulate.
    """
    from independent import generate

    c = paper_isolated.cycle
    rec = generate(PAPER["m1"], PAPER["m2"], friction=PAPER["friction"],
                   isolator=PAPER["isolator"], controller=dict(rule=dict(fc=8.0)),
                   moves=[dict(distance=0.02, velocity=0.05, acceleration=1.0)], t_end=30.0,
                   rate=2000.0, rtol=1e-7)
    t, e = rec.time, rec.truth.x1 - rec.reference
    tc = _upward_crossings(t, e)
    tc = tc[tc > 15.0]
    periods = np.diff(tc)
    # the long run converges on the orbit geometrically: extrapolate its periods (Aitken)
    p0, p1, p2 = periods[-3:]
    limit = p2 - (p2 - p1) ** 2 / ((p2 - p1) - (p1 - p0))
    assert limit == pytest.approx(c.period, rel=2e-4)
    last = (t >= tc[-2]) & (t <= tc[-1])
    assert np.ptp(e[last]) == pytest.approx(c.amplitude, rel=1e-3)
    # the convergence ratio of the periods is the Floquet multiplier
    assert (p2 - p1) / (p1 - p0) == pytest.approx(c.multiplier, abs=0.05)


def test_paper_fold_lies_above_every_hunting_crossover_of_a_dense_scan(paper_spec,
                                                                     paper_isolated):
    fold = paper_isolated.hunting_free_from
    assert paper_isolated.boundary.kind == "fold"
    lo, hi = paper_isolated.boundary.bracket
    assert hi - lo <= max(0.01, 1e-3 * hi) * 1.0001 and fold == hi  # the search's resolution
    assert 11.0 < fold < 11.5  # from about 11 Hz no move of 0.1 to 50 mm hunts
    dense = np.geomspace(1e-5, 0.1, 120)
    below, _ = stage_hunts(paper_spec, True, crossover=11.0, family=dense)
    above, _ = stage_hunts(paper_spec, True, crossover=fold * 1.002, family=dense)
    assert any(m.hunts for m in below)
    assert not any(m.hunts for m in above)


def test_without_isolator_the_cycle_lives_to_its_fold_near_24_5_hz(paper_spec):
    st = stage_hunting(paper_spec, False)
    c = st.cycle
    assert c.period == pytest.approx(2.063, rel=1e-3)
    assert c.amplitude == pytest.approx(1.357e-3, rel=2e-3)
    assert c.multiplier == pytest.approx(0.542, abs=0.02)
    assert st.hunting_free_from == pytest.approx(24.53, abs=0.05)
    assert len(st.hunting_moves) >= 20


# --------------------------------------------------------------------------- published case


def test_canudas_de_wit_1995_pid_example_hunts_with_its_published_cycle():
    """Canudas de Wit et al. (1995), u = 3 e + 4 int e - 6 v on a unit mass: 24.4 s, 127.8 mm."""
    spec = canudas_spec()
    st = stage_hunting(spec, False, family=[1.0], boundary=False)
    assert all(m.hunts for m in st.moves)
    c = st.cycle
    assert c.period == pytest.approx(24.4, abs=0.05)
    assert c.amplitude == pytest.approx(0.1278, abs=0.0005)
    assert c.stable


def test_canudas_de_wit_1995_switch_model_counts_one_peak_per_stick_plateau():
    """The same case with Karnopp (switch) friction over [100 s, 200 s): four cycles.

    The stage sticks for about 9 s at each extreme, where x1 - r rounds to
    neighbouring floats near r = 1 m; the metric counted those rounding steps as
    peaks (32 peaks, period 2.6 s). Its period must agree with the cycle converged on
    the section (an independent route: shooting on section crossings, no peaks) and
    lie near the LuGre run's published 24.4 s.
    """
    from fi_design.simulation.run import simulate

    window = {"window_start": "100 s", "window_length": "100 s"}
    m = simulate(canudas_spec("switch", window, "200 s"), False).metrics
    cycle = stage_hunting(canudas_spec("switch"), False, family=[1.0], boundary=False).cycle
    assert cycle.period == pytest.approx(23.73, abs=0.05)
    assert m.verdict == "hunting" and m.hunting_cycles == 4
    assert m.period == pytest.approx(cycle.period, rel=2e-3)
    assert m.period == pytest.approx(24.4, rel=0.05)
    assert np.ptp(m.peak_heights) < 1e-4  # one level per side: the plateau, not its steps


def test_a_multiplier_the_two_perturbations_disagree_on_is_not_reported(paper_spec):
    """Without isolator at Fs 4 N, Fc 3.0 N the return map's finite differences straddle a
    stick event: the multiplier reads 1.14 at one perturbation and 0.51 at ten times it.
    Four moves end in the cycle, so it attracts; the multiplier is not reported. At Fc
    3.02 N the two agree (0.48) and the cycle is stable by its multiplier."""
    from fi_design.spec.file import with_values

    st = stage_hunting(with_values(paper_spec, {"friction.coulomb": 3.0}), False,
                       boundary=False)
    assert st.hunting_moves and st.cycle.stable
    assert st.cycle.multiplier is None and st.cycle.multiplier_check is not None
    near = stage_hunting(with_values(paper_spec, {"friction.coulomb": 3.02}), False,
                         boundary=False).cycle
    assert near.multiplier == pytest.approx(near.multiplier_check, rel=0.1)
    assert near.multiplier < 1.0 and near.stable


# --------------------------------------------------------------------------- rest


def test_rest_within_the_band_is_final_only_below_static_friction(paper_spec):
    """Without isolator the bristles carry sigma0 (z + r - x1) once the loop pulls x1 to r."""
    from fi_design.kernel.layout import state_index
    from fi_design.model import resolve

    p = resolve(paper_spec).plant(False)
    idx = state_index(False)
    y = np.zeros(p.n_states)
    z_limit = p.Fs / p.sigma0  # 4 um of bristle deflection holds 4 N
    y[idx["x1"]], y[idx["z"]] = -1e-6, 0.5 * z_limit  # 2 N now, 3 N at the target
    assert rest_is_final(p, y, 0.0)
    y[idx["x1"]] = -3e-6  # 2 N now, 5 N > Fs at the target: the integrator breaks it loose
    assert not rest_is_final(p, y, 0.0)


def test_a_stage_creeping_at_its_static_friction_inside_the_band_settles(paper_spec):
    """A robustness sample of the paper setup at 11 Hz (Fs 4.14 N, Fc 1.08 N, friction +-10 %
    along the rail): after a 36 mm move the stage rests at its target with the joint pressing
    the cart at its static friction, so the rest is not final by the static balance; the
    cart creeps and never leaves the band. Such a move settles (it was 'undetermined'), and a
    horizon four times longer finds the same."""
    from fi_design.spec.file import with_values

    point = with_values(paper_spec, {
        "controller.crossover": 11.0, "friction.static": 4.138233676825914,
        "friction.coulomb": 1.082161814350116,
        "effects": [{"type": "position_dependent_friction", "amplitude": 0.1,
                     "wavelength": "20 mm", "phase": "2.26990552582712 rad"}]})
    st = stage_hunting(point, True, boundary=False)
    creeping = [m for m in st.moves if "creeps" in m.reason]
    assert creeping and all(m.outcome == "settles" for m in st.moves), st.moves
    assert all(abs(m.final_error) <= point.requirements.hunting.settle_band for m in creeping)
    longer = with_values(point, {"requirements.hunting.horizon": 1200.0})
    again = stage_hunting(longer, True, family=[abs(m.distance) for m in creeping],
                          boundary=False)
    assert all(m.outcome == "settles" for m in again.moves), again.moves


def test_isolated_rest_is_final_while_the_flexure_force_stays_below_fs(paper_spec):
    from fi_design.kernel.layout import state_index
    from fi_design.model import resolve

    p = resolve(paper_spec).plant(True)
    idx = state_index(True)
    y = np.zeros(p.n_states)
    y[idx["x2"]] = -0.28e-3  # cart stuck 0.28 mm behind: k d = 1.87 N < 4 N
    assert rest_is_final(p, y, 0.0)
    y[idx["x2"]] = -0.35e-3  # the joint on its limiter: k s + k_stop (d - s) = 52 N
    assert not rest_is_final(p, y, 0.0)


def test_orbit_is_found_from_a_rough_guess_and_falls_to_nothing_from_rest(paper_spec,
                                                                        paper_isolated):
    from fi_design.model import resolve

    p = resolve(paper_spec).plant(True)
    c = paper_isolated.cycle
    rough = np.array(c.section_state) * (1 + 0.05)
    again = converge_cycle(p, 0.0, rough, 1, 8.0, period=c.period, trace=False)
    assert again.amplitude == pytest.approx(c.amplitude, rel=1e-4)
    assert again.period == pytest.approx(c.period, rel=1e-5)
    still = np.zeros(p.n_states)
    still[1] = 1e-4  # a gentle nudge through the target: it comes to rest
    assert converge_cycle(p, 0.0, still, 1, 8.0, period=c.period, trace=False) is None


@pytest.mark.slow
def test_moves_hunting_just_below_the_fold_hunt_in_the_independent_simulator(paper_isolated):
    """At 11.2 Hz (below the fold) the 0.408 mm move hunts, at 11.5 Hz it settles: solve_ivp."""
    from independent import generate

    assert paper_isolated.hunting_free_from > 11.2
    ends = {}
    for fc in (11.2, 11.5):
        rec = generate(PAPER["m1"], PAPER["m2"], friction=PAPER["friction"],
                       isolator=PAPER["isolator"], controller=dict(rule=dict(fc=fc)),
                       moves=[dict(distance=0.408e-3, velocity=0.05, acceleration=1.0)],
                       t_end=30.0, rate=1000.0)
        e = rec.truth.x1 - rec.reference
        ends[fc] = np.ptp(e[rec.time > 20.0])
    assert ends[11.2] > 1e-3 and ends[11.5] < 1e-5


# --------------------------------------------------------------------------- the kernel's watch


def test_the_watch_lands_on_the_section_and_leaves_the_trajectory_alone(paper_spec):
    """Section crossings are stepped to (x1 = r to round-off) and agree with the trace."""
    from fi_design.kernel import run
    from fi_design.kernel.layout import N_WATCH, W_ARM, W_LEVEL, W_MAX_CROSSINGS, W_QUIET, W_START
    from fi_design.model import resolve
    from fi_design.simulation.run import tolerances
    from fi_design.stage.family import family_reference

    p = resolve(paper_spec).plant(False)
    ref, end = family_reference(paper_spec, 0.01, 12.0)
    t_out = np.arange(0.0, end + 12.0, 1e-4)
    args = (p.to_array(), np.zeros(p.n_states), ref.breaks, ref.coeffs, True, end + 12.0, t_out,
            1e-8, tolerances(p, 1e-8), 0.05, 2_000_000, 10.0)
    w = np.zeros(N_WATCH)
    w[W_START], w[W_LEVEL], w[W_QUIET], w[W_MAX_CROSSINGS], w[W_ARM] = (end, ref.final,
                                                                        np.inf, 100, 1e-5)
    watched = run(*args, watch=w, crossings=100)
    plain = run(*args)
    assert watched.stop == "end" and plain.stop == "end"
    assert len(watched.crossing_times) >= 4
    assert np.max(np.abs(watched.crossing_states[:, 0] - ref.final)) < 1e-10  # 0.1 nm
    e = plain.states[:, 0] - plain.reference
    tc = _upward_crossings(t_out, e)
    tc = tc[tc >= end]
    assert np.allclose(watched.crossing_times, tc[:len(watched.crossing_times)], atol=1e-5)
    # the section only splits steps: the trajectory is the same within the tolerance
    assert np.nanmax(np.abs(watched.states[:, 0] - plain.states[:, 0])) < 1e-6


def test_a_move_entering_a_known_cycle_stops_there_with_the_same_answer(paper_spec,
                                                                       monkeypatch):
    """The match rule (a move stops once its section state is within MATCH of a cycle an
    earlier move repeated) changes when a move stops, not how the stage ends: against the
    family run with the rule off, every move has the same outcome and every hunting move's
    cycle the same amplitude and period within the repeat tolerance's reach."""
    from fi_design.stage import runs as stage_runs

    spec = paper_spec
    fast, runs = stage_hunts(spec, True, crossover=5.0)
    monkeypatch.setattr(stage_runs, "MATCH", 0.0)  # the kernel's rule off: every move to its repeat
    slow, _ = stage_hunts(spec, True, crossover=5.0)
    assert [m.outcome for m in fast] == [m.outcome for m in slow]
    matched = [(f, s) for f, s in zip(fast, slow) if "enters the cycle" in f.reason]
    assert len(matched) >= 5, [m.reason for m in fast]
    for f, s in zip(fast, slow):
        if f.hunts:
            assert f.amplitude == pytest.approx(s.amplitude, rel=2e-3)
            assert f.period == pytest.approx(s.period, rel=2e-3)
    # and it stopped earlier: the point of the rule
    assert sum(f.time for f, _ in matched) < 0.8 * sum(s.time for _, s in matched)
    assert all(r.cycle_states is not None for r in runs if r.outcome.hunts)


def test_the_match_tolerance_grows_with_the_known_cycle(paper_spec, monkeypatch):
    """A share of the smallest known cycle's peak-to-peak amplitude in the position scale
    (1 mm), between the floor MATCH and the cap; none known or MATCH 0: the floor."""
    from fi_design.results.stage import MoveOutcome
    from fi_design.stage import runs as stage_runs
    from fi_design.stage.settings import MATCH, MATCH_CAP, MATCH_SHARE

    params = resolve(paper_spec).plant(True)

    def cycle(amplitude):
        out = MoveOutcome(1e-3, "family", "hunts", 0.0, amplitude, 2.0, 10.0, "a cycle")
        return stage_runs.MoveRun(out, np.zeros(params.n_states), 1, 0.0,
                                  np.zeros((1, params.n_states)))

    tol = stage_runs.match_tolerance
    assert tol(params, []) == MATCH
    assert tol(params, [cycle(20e-6)]) == MATCH  # 0.3 x 0.02: below the floor
    assert tol(params, [cycle(0.2e-3)]) == pytest.approx(MATCH_SHARE * 0.2)
    assert tol(params, [cycle(0.2e-3), cycle(5e-3)]) == pytest.approx(MATCH_SHARE * 0.2)
    assert tol(params, [cycle(5e-3)]) == MATCH_CAP
    monkeypatch.setattr(stage_runs, "MATCH", 0.0)
    assert tol(params, [cycle(5e-3)]) == 0.0  # the rule off


# --------------------------------------------------------------------------- the order of the moves


def test_spread_order_is_a_permutation_that_starts_large_and_halves_the_sizes():
    from fi_design.stage.moves import spread

    d = tuple(float(x) for x in np.geomspace(1e-5, 1e-2, 8))
    out = spread(d)
    assert sorted(out) == sorted(d)
    # the largest, then the middle of the rest, then the middles of its halves
    assert [d.index(x) for x in out] == [7, 3, 1, 5, 0, 2, 4, 6]
    both = d + tuple(-x for x in d)
    out2 = spread(both)
    assert sorted(out2) == sorted(both)
    assert out2[:2] == (d[7], -d[7])  # one size, both directions, together
    assert spread(()) == ()


@pytest.mark.parametrize("crossover", [5.0, 8.0, 14.0])
def test_the_spread_order_changes_which_hunting_move_is_met_first_never_whether(
        paper_spec, crossover):
    """A caller that reads only whether some move hunts (first_only) gets the same answer in
    either order; the spread order meets it after fewer moves where the large moves hunt.
    At 14 Hz no move hunts: both run every move and agree move for move."""
    size, _ = stage_hunts(paper_spec, True, crossover=crossover, first_only=True)
    fast, _ = stage_hunts(paper_spec, True, crossover=crossover, first_only=True,
                          order="spread")
    assert any(m.hunts for m in size) == any(m.hunts for m in fast)
    assert fast[0].label == "spec" and size[0].label == "spec"
    if any(m.hunts for m in size):
        assert len(fast) < len(size)
        assert fast[-1].hunts and sum(m.hunts for m in fast) == 1
    else:
        assert sorted((m.distance, m.outcome) for m in fast) == \
            sorted((m.distance, m.outcome) for m in size)
    with pytest.raises(Exception, match="order must be one of"):
        stage_hunts(paper_spec, True, order="random")


@functools.lru_cache(maxsize=1)
def _isolated_plant():
    from pathlib import Path

    from fi_design.spec.file import load_spec

    spec = load_spec(Path(__file__).resolve().parents[2] / "examples" / "paper_setup.yaml")
    return resolve(spec).plant(True)


@settings(max_examples=200, deadline=None)
@given(z=st.floats(-5e-6, 5e-6), d0=st.floats(-1e-3, 1e-3), k=st.floats(10.0, 1e5),
       k_stop=st.floats(0.0, 1e8), s=st.floats(1e-5, 1e-3), sigma0=st.floats(1e5, 1e8))
def test_the_presliding_shift_balances_the_bristles_and_the_joint(z, d0, k, k_stop, s, sigma0):
    """The closed form of the stuck cart's shift against a root finder on the force balance
    sigma0 (z + D) = k (d0 - D) + the limiter's contact beyond +-s."""
    from dataclasses import replace as _replace

    from scipy.optimize import brentq

    from fi_design.model import resolve
    from fi_design.stage.rest import presliding_shift

    p = _replace(_isolated_plant(), k=k, k_stop=k_stop, s=s, sigma0=sigma0)

    def joint(e):
        return k * e + (k_stop * (e - s) if e > s else k_stop * (e + s) if e < -s else 0.0)

    def gap(dd):
        return sigma0 * (z + dd) - joint(d0 - dd)

    span = abs(d0) + abs(z) + s + 1e-6
    ref = brentq(gap, -span, span, xtol=1e-18, rtol=1e-14)
    got = presliding_shift(p, z, d0)
    assert got == pytest.approx(ref, rel=1e-9, abs=1e-16)
    assert abs(gap(got)) <= 1e-9 * (sigma0 * (abs(z) + span) + 1e-12)


def test_hunting_moves_without_a_converged_cycle_start_the_fold_at_the_design(paper_spec,
                                                                             monkeypatch):
    """A sampled loop: moves hunt at the design crossover but no cycle converges as an orbit.
    The fold search must start from the cycle a move repeated there, not look below the design
    crossover as if no move hunted (it reported 'no move hunts from 6.425 Hz up' for a stage
    hunting 6 of 25 moves at 8 Hz)."""
    from types import SimpleNamespace

    from fi_design.results.stage import Boundary
    from fi_design.stage import judge

    out = SimpleNamespace(hunts=True, amplitude=1.8e-3, period=3.0)
    run = SimpleNamespace(outcome=out, section_state=np.zeros(4), crossings=2, level=0.0)
    seen = {}

    def boundary(model, iso, cycle, **kw):
        seen["cycle"] = cycle
        return Boundary(hunting_free_from=None, bracket=(8.0, 8.0), kind="bound",
                        resolution=0.0, tests=0, branch=(), note="")

    monkeypatch.setattr(judge, "stage_hunts", lambda *a, **k: ((out,), [run]))
    monkeypatch.setattr(judge, "_distinct_cycles", lambda *a, **k: [])
    monkeypatch.setattr(judge, "hunting_free_boundary", boundary)
    model = resolve(paper_spec)
    judge.stage_hunting(model, True)
    assert seen["cycle"] is not None
    assert seen["cycle"].crossover == model.crossover and seen["cycle"].amplitude == 1.8e-3


def test_moves_hunting_above_every_fold_found_leave_the_boundary_not_found(paper_spec,
                                                                          monkeypatch):
    """Moves that still hunt just above the last fold the continuation found: no crossover from
    which no move hunts is known. It reported that last fold ('no move of the family hunts from
    8.031 Hz up') for a sampled paper setup that still hunts 5 of 25 moves at 10 Hz."""
    from types import SimpleNamespace

    from fi_design.results.stage import Boundary
    from fi_design.stage import boundary as bd

    def fold(model, isolated, cycle, *, top=None, progress=None):
        lo = cycle.crossover
        return Boundary(hunting_free_from=lo + 0.01, bracket=(lo, lo + 0.01), kind="fold",
                        resolution=0.01, tests=3, branch=(), note="the fold of the cycle")

    out = SimpleNamespace(hunts=True, amplitude=1.8e-3, period=3.0)
    run = SimpleNamespace(outcome=out, section_state=np.zeros(4), crossings=2, level=0.0)
    monkeypatch.setattr(bd, "cycle_fold", fold)
    monkeypatch.setattr(bd, "stage_hunts", lambda *a, **k: ((out,), [run]))
    model = resolve(paper_spec)
    b = bd.hunting_free_boundary(model, True, bd.cycle_of_run(run, model.crossover))
    # not the bound of a cycle persisting to the top of the search: a kind of its own, which
    # the console and the report read as not found (tests/report/test_consistency.py)
    assert b.hunting_free_from is None and b.kind == "not_found"
    assert b.note.startswith("not found: moves still hunt at 8.04 Hz")


def test_a_cycle_test_quiet_to_the_end_of_its_horizon_finds_no_cycle(monkeypatch):
    """friction.model: switch crashed the design ('breaks must be increasing ...'): a cycle
    test whose restarts after quiet stretches used up its horizon asked for a hold reference of
    no duration. Quiet to the end of the horizon, no cycle repeated: None, as a run that ends."""
    from types import SimpleNamespace

    from fi_design.stage import orbit

    quiet = SimpleNamespace(code=0, stop="quiet", final_state=np.zeros(4), t_reached=0.5)
    monkeypatch.setattr(orbit, "kernel_run", lambda *a, **k: quiet)
    monkeypatch.setattr(orbit, "watch_array", lambda *a, **k: None)
    monkeypatch.setattr(orbit, "rest_ends_run", lambda *a, **k: False)
    monkeypatch.setattr(orbit, "continued_state", lambda p, out: out.final_state.copy())
    w = SimpleNamespace(horizon=1.0, tolerance=1e-6, max_steps=10, band=1e-5)
    assert orbit.cycle_exists(None, 0.0, np.zeros(4), w) is None


# --------------------------------------------------------------------------- sampled loops


def test_a_sampled_loop_continues_exactly_from_its_quiet_stop(paper_spec):
    """A quiet stop of a sampled loop (1 kHz, 0.5 ms delay) comes on a sample instant; a run
    from its end state with the controller's dx1, dx2 and held output continues the motion:
    against one run straight through, the same positions to the integration's tolerance. A
    run that drops the controller's memory (what the fold search did) does not."""
    from dataclasses import replace

    from conftest import variant

    from fi_design.stage.family import family_reference, hold
    from fi_design.stage.runs import kernel_run, resumes_sampled, watch_array
    from fi_design.stage.settings import watch_settings

    m = resolve(variant(paper_spec, **{"controller.sample_rate": "1 kHz",
                                       "controller.delay": "0.5 ms"}))
    p = m.plant(True)
    w = watch_settings(m, p)
    ref, end = family_reference(m.spec, 1e-3, 40.0)
    y0 = np.zeros(p.n_states)
    first = kernel_run(p, y0, ref, end + 40.0, watch_array(w, end, ref.final), w.tolerance,
                       w.max_steps)
    tq = first.t_reached
    assert first.stop == "quiet" and resumes_sampled(p, first)
    assert tq * 1e3 == pytest.approx(round(tq * 1e3), abs=1e-6)  # on a sample instant
    t_out = np.linspace(0.0, 3.0, 31)
    off = watch_array(w, np.inf, ref.final)
    through = kernel_run(p, y0, ref, tq + 3.0, off, w.tolerance, w.max_steps,
                         t_out=tq + t_out)
    dx1, dx2, held, _ = first.controller
    go_on = kernel_run(replace(p, dx1=dx1, dx2=dx2, u_initial=held), first.final_state,
                       hold(ref.final, 3.0), 3.0, off, w.tolerance, w.max_steps, t_out=t_out)
    forgot = kernel_run(p, first.final_state, hold(ref.final, 3.0), 3.0, off, w.tolerance,
                        w.max_steps, t_out=t_out)
    x = through.states[:, 0]
    assert np.max(np.abs(go_on.states[:, 0] - x)) < 1e-9  # 1 nm
    assert np.max(np.abs(forgot.states[:, 0] - x)) > 1e-6  # 1 um: the memory matters


@pytest.mark.slow
def test_a_sampled_loops_fold_is_found_and_the_independent_simulator_agrees(paper_spec):
    """The paper setup sampled at 1 kHz with a 0.5 ms delay: the fold search follows its cycle
    (its section states carry the controller's memory) to a fold a little above the
    continuous loop's (11.0 to 11.5 Hz: the hold and the delay add lag); it read "not found"
    when each cycle test dropped that memory. solve_ivp: the 0.396 mm move hunts 3 % below
    the fold and settles 3 % above it."""
    from conftest import variant

    from independent import generate

    spec = variant(paper_spec, **{"controller.sample_rate": "1 kHz",
                                  "controller.delay": "0.5 ms"})
    st = stage_hunting(spec, True)
    assert st.boundary.kind == "fold"
    fold = st.hunting_free_from
    assert 11.0 < fold < 12.0
    periods = [b[2] for b in st.boundary.branch]
    assert all(2.5 < p < 4.5 for p in periods)  # one crossing a period, no multiple of it
    ends = {}
    for fc in (0.97 * fold, 1.03 * fold):
        rec = generate(PAPER["m1"], PAPER["m2"], friction=PAPER["friction"],
                       isolator=PAPER["isolator"],
                       controller=dict(rule=dict(fc=fc), sample_rate=1000.0, delay=0.5e-3),
                       moves=[dict(distance=0.396063e-3, velocity=0.05, acceleration=1.0)],
                       t_end=25.0, rate=1000.0)
        e = rec.truth.x1 - rec.reference
        ends[fc] = np.ptp(e[rec.time > 17.0])  # two periods
    assert ends[0.97 * fold] > 1e-3 and ends[1.03 * fold] < 1e-5
