"""Replaying a record from rest (fi_design.simulation.replay): noise must not start the model sliding.

A record taken from rest holds sensor noise in its first samples. A velocity
estimate within its own noise is zero, the bristles then carry the static load
(not the full sliding friction), and the controller's state follows from the
reference's own derivatives at the first sample; the replay must then match
the record as closely as a simulation started exactly at rest. The one
thing a single sample cannot tell is the controller's output at the start: its
force noise sets the integrator, and that offset decays with the integrator's
time constant; given the true initial command the replay is within noise.
"""

from __future__ import annotations

import numpy as np

from fi_design.measured import measurement_from_arrays
from fi_design.simulation.replay import record_state, reference_state
from fi_design.simulation.run import simulate

from hidden_effect import NOISE, Case, base_spec


def _record(case: Case, seed: int):
    spec = base_spec(case)
    res = simulate(spec, case.isolated, rtol=1e-8)
    rng = np.random.default_rng(seed)
    n = len(res.time)
    defl = (np.asarray(res.deflection) + NOISE["deflection"] * rng.standard_normal(n)
            if case.isolated else None)
    data = measurement_from_arrays(
        res.time, res.reference, res.position + NOISE["position"] * rng.standard_normal(n),
        res.force + NOISE["force"] * rng.standard_normal(n), defl)
    return spec, data


def test_noisy_start_at_rest_is_at_rest():
    case = Case("rest", True, None, {}, duration=2.0)
    _, data = _record(case, seed=5)
    st = record_state(data, 0)
    assert not st.moving
    assert st.dof >= 2 and st.velocity_error > 0
    # the reference accelerates from rest at the first sample: no initial velocity
    r, rd, rdd = reference_state(data, 0)
    assert abs(rd) < 1e-6 and abs(rdd - 1.0) < 0.05


def _misfit(res, data):
    pos = (res.position - data.position) / NOISE["position"]
    force = (res.force - data.force) / NOISE["force"]
    return float(np.sqrt(np.mean(pos ** 2))), float(np.sqrt(np.mean(force ** 2)))


def test_replay_from_rest_matches_the_record_within_noise():
    case = Case("rest", True, None, {}, duration=2.0)
    spec, data = _record(case, seed=6)
    # the simulated record starts with no command at all
    exact = simulate(spec, record=data, initial_command=0.0)
    assert exact.success
    assert max(_misfit(exact, data)) < 1.1
    # from the first force sample alone, its noise offsets the start (before the at-rest
    # handling, a noisy start slid the bristles and missed by about 40 noise units)
    first = simulate(spec, record=data)
    assert max(_misfit(first, data)) < 3.0
