"""The reference solver (fi_design.refsolve) against an exact solution.

Without static and Coulomb friction the rigid stage is linear, m x'' = u - sigma2 x', and
under the PID C(s) = (kd s^2 + kp s + ki) / (s (1 + s / wt)) its position follows the
reference through the closed loop T = C P / (1 + C P) exactly. scipy.signal solves that
linear system independently of the simulation's equations and events.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

from fi_design.simulation import simulate

from conftest import variant


@pytest.fixture(scope="module")
def linear_stage(paper_spec):
    return variant(paper_spec, **{
        "friction.static": 1e-9, "friction.coulomb": 1e-9, "friction.viscous": "20 N*s/m",
        "motion.moves": [{"distance": "1 mm", "velocity": "20 mm/s",
                          "acceleration": "0.5 m/s^2"}],
        "motion.duration": "1.2 s", "requirements.hunting.window_start": "0.6 s",
        "requirements.hunting.window_length": "0.6 s", "simulation.output_rate": "10 kHz"})


def _closed_loop(spec, result) -> np.ndarray:
    """x(t) of the linear closed loop driven by the simulation's own reference samples."""
    p = result.parameters
    m, sigma2 = spec.total_mass, spec.friction.viscous
    controller = np.array([p.kd, p.kp, p.ki])                  # over s (1 + s / wt)
    loop_den = np.polymul([1.0 / p.wt, 1.0, 0.0], [m, sigma2, 0.0])
    closed = signal.lti(controller, np.polyadd(loop_den, controller))
    _, x, _ = signal.lsim(closed, U=result.reference, T=result.time)
    return x


@pytest.mark.parametrize("method", ["reference", "fast"])
def test_solvers_equal_the_linear_closed_loop(linear_stage, method):
    r = simulate(linear_stage, isolated=False, method=method,
                 rtol=1e-7 if method == "reference" else None)
    assert r.success and r.method == method
    distance = 1e-3
    error = np.max(np.abs(r.position - _closed_loop(linear_stage, r)))
    assert error < 2e-6 * distance           # about six digits of the move, at every sample
    assert np.max(np.abs(r.position)) > distance  # the stage moved (and overshot a little)
