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
