"""``requirements.positioning``: what the stage is for, judged over every move of the family.

A stage that never hunts can still fail it: the industrial PD axis rests up to 15.2 um off
its target (its static error), so a 15 um static error requirement fails it. The settle time
of the spec's own move agrees with the one the paper's metric reads from an independent
simulation of that move (fi_design.simulate, its own trace and settling time).
"""

from __future__ import annotations

import numpy as np
import pytest

from conftest import EXAMPLES, variant


def test_settle_time_is_the_last_exit_from_the_band():
    from fi_design.stage import settle_time

    t = np.linspace(0.0, 4.0, 401)
    e = np.where(t < 2.0, 1.0, 0.0) + np.where((t > 2.5) & (t < 2.6), 0.5, 0.0)
    assert settle_time(t, e, 0.1, 1.0) == pytest.approx(1.6, abs=0.011)   # last exit 2.6 s
    assert settle_time(t, np.zeros_like(t), 0.1, 1.0) == 0.0
    assert settle_time(t, np.ones_like(t), 0.1, 1.0) is None              # never in the band


def test_spec_and_band_are_checked():
    from fi_design.errors import SpecError
    from fi_design.spec.file import load_spec

    spec = load_spec(EXAMPLES / "industrial_axis.yaml")
    with pytest.raises(SpecError, match="settle_time, static_error or both"):
        variant(spec, **{"requirements.positioning": {"band": "10 um"}})
    with pytest.raises(SpecError, match="requirements.positioning.settle_time"):
        variant(spec, **{"requirements.positioning": {"settle_time": "-1 s"}})


@pytest.fixture(scope="module")
def industrial_positioned():
    """The industrial PD axis asked for a 15 um static error and a 0.5 s settle time in a
    20 um band (robustness off: the requirement is what is read)."""
    from fi_design.signoff import design
    from fi_design.spec.file import load_spec

    spec = variant(load_spec(EXAMPLES / "industrial_axis.yaml"), **{
        "requirements.positioning": {"static_error": "15 um", "settle_time": "0.5 s",
                                     "band": "20 um"},
        "requirements.robustness": {"samples": 0}})
    return design(spec, recommend=False)


def test_a_stage_that_does_not_hunt_fails_on_its_static_error(industrial_positioned):
    r = industrial_positioned
    st = r.simulation.stage["non_isolated"]
    assert not st.hunts and st.outcome == "static_error"   # it never hunts ...
    assert r.verdict.status == "FAIL"                       # ... and fails on positioning
    assert "positioning (requirements.positioning)" in r.verdict.headline
    pos = r.positioning
    assert not pos.passed and pos.worst_static_error > 15e-6
    # the worst rest error is the stage-level answer's, bounded by the loop's static error
    rests = [abs(m.final_error) for m in st.moves if m.outcome in ("settles", "rests")]
    assert pos.worst_static_error == pytest.approx(max(rests), rel=1e-12)
    assert pos.worst_static_error <= r.pid.static_error
    checks = {c.name: c for c in r.checks if c.name.startswith("positioning.")}
    assert checks["positioning.static_error"].status.value == "FAIL"
    assert checks["positioning.settle_time"].status.value == "PASS"
    assert pos.worst_settle_time <= 0.5
    far = [m for m in pos.moves if m.static_error > 15e-6]
    assert far and all(not m.passed for m in far)
    data = r.to_dict()["positioning"]
    assert data["passed"] is False and len(data["moves"]) == len(st.moves)


def test_the_report_draws_settle_time_against_distance(industrial_positioned):
    from fi_design import plots
    from fi_design.report import build_context

    fig = plots.positioning_figure(industrial_positioned.positioning)
    ax_t, ax_e = fig.axes
    assert ax_t.get_xscale() == "log" and "settle time" in ax_t.get_ylabel()
    ctx = build_context(industrial_positioned, figures=False, date="2026-11-28")
    pos = ctx["nonlinear"]["positioning"]
    assert pos["figure"]["caption"].startswith("Positioning after every move")
    assert [c["status"] for c in pos["checks"]] == ["PASS", "FAIL"]
    labels = [f["label"] for f in ctx["verdict"]["figures"]]
    assert "Static error after every move" in labels and "Settle time after every move" in labels


def test_the_spec_moves_settle_time_is_the_metrics(paper_spec):
    """With the band the metric's settle band, the spec's own move settles when the paper's
    metric, on its own simulation of that move, says it does."""
    from fi_design.model import resolve
    from fi_design.simulation.run import simulate
    from fi_design.stage import positioning, stage_hunting

    spec = variant(paper_spec, **{"requirements.positioning": {"settle_time": "10 s"}})
    model = resolve(spec)
    st = stage_hunting(model, True, family=[], boundary=False, converge=False)
    pos = positioning(model, st)
    [move] = pos.moves
    sim = simulate(spec, isolated=True)
    assert sim.metrics.settling_time is not None
    assert move.settle_time == pytest.approx(sim.metrics.settling_time, abs=2e-3)
    assert pos.passed
