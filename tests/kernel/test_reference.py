"""The reference solver (fi_design.kernel.reference) against an exact solution.

Without static and Coulomb friction the rigid stage is linear, m x'' = u - sigma2 x', and
under the PID C(s) = (kd s^2 + kp s + ki) / (s (1 + s / wt)) its position follows the
reference through the closed loop T = C P / (1 + C P) exactly. scipy.signal solves that
linear system independently of the simulation's equations and events.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

from fi_design.simulation.run import simulate

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


# --------------------------------------------------------------------------- the mode switch


def _plant(paper_spec, *, isolated, switch, quantization, wt, sample_period):
    from dataclasses import replace

    from fi_design.model import resolve

    p = resolve(paper_spec).plant(isolated)
    return replace(p, switch_model=float(switch), quantization=quantization, wt=wt,
                   sample_period=sample_period, kdm=5.0)


def _crossing(name, params, y, modes):
    """The state and modes just before the solver's event ``name``, and the end of a trial step
    that went past it (what the fast integrator's switch reads the direction from)."""
    from fi_design.kernel.layout import MODE_LEVEL, MODE_LIMIT, MODE_STICK

    q, s = params.quantization, params.s
    trial = y.copy()
    if name == "unstick":
        modes[MODE_STICK] = 1
    elif name in ("limit+", "limit-"):
        trial[0] = trial[2] + (1.5 if name == "limit+" else -1.5) * s
    elif name == "limit0":
        modes[MODE_LIMIT] = 1
        trial[0] = trial[2]
    elif name in ("level+", "level-"):
        modes[MODE_LEVEL] = int(np.floor(y[0] / q + 0.5))
        trial[0] = (modes[MODE_LEVEL] + (0.7 if name == "level+" else -0.7)) * q
    return trial


@pytest.mark.parametrize("name", ["sign", "unstick", "limit+", "limit-", "limit0", "level+",
                                  "level-"])
@pytest.mark.parametrize("controller", ["filtered", "ideal D", "sampled"])
def test_the_reference_switches_modes_as_the_fast_integrator(paper_spec, name, controller):
    """At every event the reference solver locates, it changes the modes and jumps the state
    exactly as the fast integrator does at the same crossing: both call one compiled switch.
    (A second transcription once jumped a sampled controller's held output at a quantization
    level, where the reference did not.)"""
    from fi_design.kernel import integrator
    from fi_design.kernel.layout import MODE_SIGN
    from fi_design.kernel.reference import EVENTS, switch

    rng = np.random.default_rng(7)
    wt = np.inf if controller == "ideal D" else 2e3
    ts = 1e-3 if controller == "sampled" else 0.0
    isolated_plants = (True,) if name.startswith("limit") else (True, False)
    checked = 0
    for isolated in isolated_plants:
        for switch_model in (False, True) if name in ("sign", "unstick") else (False,):
            params = _plant(paper_spec, isolated=isolated, switch=switch_model,
                            quantization=2e-6, wt=wt, sample_period=ts)
            p = params.to_array()
            n = params.n_states
            iv2, iu = (3 if isolated else 1), n - 1
            for _ in range(20):
                y = rng.normal(size=n) * np.array([1e-4, 1e-3, 1e-4, 1e-3, 1e-6, 1.0, 1.0])[-n:]
                modes = np.array([rng.choice([-1, 1]), 0, 0, 0], dtype=np.int64)
                modes[MODE_SIGN] = rng.choice([-1, 1])
                trial = _crossing(name, params, y, modes)
                r, rd, fa = rng.normal() * 1e-4, rng.normal() * 1e-3, rng.normal()
                fa_state = ts == 0.0
                y_fast, m_fast = y.copy(), modes.copy()
                integrator.apply_event(EVENTS[name][0], y_fast, p, m_fast, iv2, iu, r, rd, fa,
                                       fa_state, trial)
                y_ref, m_ref = y.copy(), modes.copy()
                switch(name, y_ref, p, m_ref, iv2, iu, r, rd, fa, fa_state)
                assert np.array_equal(m_ref, m_fast), (isolated, switch_model, y, modes)
                assert np.array_equal(y_ref, y_fast), (isolated, switch_model, y, modes)
                checked += not (np.array_equal(m_fast, modes) and np.array_equal(y_fast, y))
    assert checked > 0  # the events did switch something


def test_a_level_jumps_the_filtered_controller_only(paper_spec):
    """The derivative impulse of a quantization step, -wt (kd + kdm) q, moves a filtered
    continuous controller's output; a sampled controller's held output stays."""
    from fi_design.kernel.reference import switch

    for ts, jump in ((0.0, True), (1e-3, False)):
        params = _plant(paper_spec, isolated=True, switch=False, quantization=2e-6, wt=2e3,
                        sample_period=ts)
        y = np.zeros(7)
        modes = np.array([1, 0, 0, 0], dtype=np.int64)
        switch("level+", y, params.to_array(), modes, 3, 6, 0.0, 0.0, 0.0, ts == 0.0)
        assert modes[2] == 1
        expected = -params.wt * (params.kd + params.kdm) * params.quantization if jump else 0.0
        assert y[6] == pytest.approx(expected, rel=1e-12, abs=0.0)
        assert expected != 0.0 or not jump
