"""The forces over the move family: the output rate of long moves, and the simulation's bound."""

from __future__ import annotations

import pytest

from fi_design.errors import ArgumentError
from fi_design.model import resolve
from fi_design.simulation.run import simulate
from fi_design.stage import forces
from fi_design.trajectory import profile_duration


def test_long_moves_lower_the_rate_instead_of_failing(paper_spec, monkeypatch):
    """Slow scans (a 50 mm move at 50 um/s: a family up to 5000 s) failed after a minute with
    the simulation's sample bound; the rate now drops so the longest run holds MAX_SAMPLES.

    Here the bound is lowered so that the paper family's 2.25 s runs drop from 5 kHz to
    about 2 kHz; the end-stop and actuator peaks stay within a few per cent of the full rate.
    """
    model = resolve(paper_spec)
    full = forces.move_forces(model, family=[0.4e-3, -10e-3])
    monkeypatch.setattr(forces, "MAX_SAMPLES", 5_000)
    low = forces.move_forces(model, family=[0.4e-3, -10e-3])
    (move,) = model.spec.motion.moves
    longest = forces.SETTLE + max(model.spec.motion.end_time, profile_duration(
        10e-3, move.velocity, move.acceleration, move.jerk))
    assert full.rate == forces.RATE and low.rate < 0.5 * forces.RATE
    assert low.rate * longest <= 5_000 * (1 + 1e-9)
    assert low.peak_actuator_force == pytest.approx(full.peak_actuator_force, rel=0.03)
    assert low.peak_stop_force == pytest.approx(full.peak_stop_force, rel=0.1)
    assert [m.impacts for m in low.moves] == [m.impacts for m in full.moves]


def test_the_sample_bound_counts_the_rate_asked_for(paper_spec):
    """simulate(rate=) was bounded at simulation.output_rate: 5 s at 1 MHz passed the check
    (5001 samples at 1 kHz) and allocated 5e6 samples; 5002 s at 200 Hz was refused."""
    with pytest.raises(ArgumentError, match="at rate = "):
        simulate(paper_spec, duration=5.0, rate=1e6)
    with pytest.raises(ArgumentError, match="rate"):
        simulate(paper_spec, duration=1.0, rate=-5.0)


def _vertical(paper_spec, **values):
    from fi_design.spec.file import with_values

    return resolve(with_values(paper_spec, {"isolator.flexure.orientation": "vertical_axis",
                                            **values}))


def test_the_actuator_on_a_vertical_axis_also_holds_the_weight(paper_spec):
    """On a vertical drive axis the actuator holds the stage and, through the joint, the cart:
    (m1 + m2) g = 2 kg x 9.80665 m/s^2 = 19.6 N at rest, which the simulation (no weight)
    leaves out. The actuator's peak over the moves was the simulated 4 N the paper move
    needs; now it is that plus the weight. The paper spec gives the joint's stiffness, so the
    simulated stage is the same standing and vertical: the peaks differ by the weight."""
    weight = (1.6 + 0.4) * 9.80665  # N: (m1 + m2) g by hand
    standing = forces.move_forces(resolve(paper_spec), family=[0.4e-3, -10e-3])
    vertical = forces.move_forces(_vertical(paper_spec), family=[0.4e-3, -10e-3])
    assert standing.held_weight == 0.0
    assert vertical.held_weight == pytest.approx(weight, rel=1e-12)
    assert 3.0 < standing.peak_actuator_force < 5.0  # N: m a + Fc + sigma2 v = 2 + 1 + 1
    for up, flat in zip(vertical.moves, standing.moves):
        assert up.peak_actuator_force == pytest.approx(flat.peak_actuator_force + weight,
                                                       rel=1e-12)
        assert up.peak_command == pytest.approx(flat.peak_command + weight, rel=1e-12)
    assert vertical.to_dict()["held_weight"] == vertical.held_weight


@pytest.mark.parametrize("limit,status,says", [
    ("10 N", "FAIL", "cannot hold the stage"), ("22 N", "FAIL", "saturates"),
    ("30 N", "PASS", "below controller.force_limit")])
def test_a_force_limit_below_the_weight_and_the_move_fails_on_a_vertical_axis(
        paper_spec, limit, status, says):
    """A 10 N limit is above the 4 N the paper move needs and passed the actuator check, yet
    below the 19.6 N the actuator holds on a vertical axis: it cannot hold the stage. 22 N
    holds it, not it and the move (23.7 N): the actuator saturates where the simulation, with
    the whole limit for the move, does not. 30 N holds both."""
    from fi_design.stage.confirm import _force_checks

    model = _vertical(paper_spec, **{"controller.force_limit": limit})
    stage = forces.move_forces(model, family=[0.4e-3])
    (check,) = [c for c in _force_checks(model, stage) if c.name == "actuator_force"]
    assert check.status.name == status, check.message
    assert check.value == pytest.approx(min(stage.peak_command, check.limit))
    assert "19.6 N" in check.message and "vertical drive axis" in check.message
    assert says in check.message, check.message


def test_the_report_says_the_actuator_force_holds_the_weight(paper_spec):
    """The report's forces table gives the actuator's peak per move: on a vertical axis the
    intro says the weight is in it, which the simulation alone does not carry."""
    from fi_design.report.design import _forces

    vertical = _forces(forces.move_forces(_vertical(paper_spec), family=[0.4e-3]))
    standing = _forces(forces.move_forces(resolve(paper_spec), family=[0.4e-3]))
    assert "weight" in vertical["intro"] and "19.61" in vertical["intro"], vertical["intro"]
    assert "weight" not in standing["intro"]
