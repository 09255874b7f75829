"""Invariants of the LuGre friction model, over bounded random parameters (hypothesis).

- Friction is odd in the velocity when it is symmetric: with v, z and the sliding sign
  reversed, the bristle rate and the friction force reverse (fi_design.kernel.equations.lugre), and so
  does the steady-state force g(v) sign(v) + sigma2 v.
- The bristle deflection stays within Fs / sigma0: at that bound the LuGre bristle equation
  dz/dt = v - sigma0 |v| z / g(v) (with g(v) <= Fs) points inward, and a stage started from
  rest never leaves it.

(k_max = Fs / stroke scaling is a hypothesis test of the guideline: tests/guideline/test_guideline.py.)
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from fi_design.kernel import equations
from fi_design.model import resolve
from fi_design.simulation.run import simulate

FRICTION = dict(static=st.floats(0.5, 20.0), ratio=st.floats(0.05, 1.0),
                vs=st.floats(1e-4, 2e-2), sigma0=st.floats(1e4, 1e8),
                sigma1=st.floats(0.0, 5e3), sigma2=st.floats(0.0, 100.0))


def _parameters(spec, static, ratio, vs, sigma0, sigma1, sigma2) -> np.ndarray:
    """The kernel parameters of the paper stage (rigid) with the friction drawn."""
    friction = {**spec.friction.model_dump(), "static": static, "coulomb": ratio * static,
                "stribeck_velocity": vs, "bristle_stiffness": sigma0, "bristle_damping": sigma1,
                "viscous": sigma2}
    return resolve(spec.with_sections(friction=friction)).plant(False).to_array()


@settings(max_examples=200, deadline=None)
@given(v=st.floats(1e-6, 1.0), fraction=st.floats(-1.0, 1.0), **FRICTION)
def test_symmetric_friction_is_odd_in_velocity(paper_spec, v, fraction, static, ratio, vs,
                                                sigma0, sigma1, sigma2):
    p = _parameters(paper_spec, static, ratio, vs, sigma0, sigma1, sigma2)
    z = fraction * static / sigma0
    ahead = equations.lugre(v, 0.0, z, 1.0, p)
    back = equations.lugre(-v, 0.0, -z, -1.0, p)
    zd, force = ahead[0], ahead[1]
    assert back[0] == pytest.approx(-zd, rel=1e-12, abs=1e-15 * v)
    assert back[1] == pytest.approx(-force, rel=1e-12, abs=1e-12 * static)


@settings(max_examples=200, deadline=None)
@given(v=st.floats(1e-6, 1.0), **FRICTION)
def test_steady_state_force_is_the_stribeck_curve(paper_spec, v, static, ratio, vs, sigma0,
                                                   sigma1, sigma2):
    """At the bristle equilibrium z = g(v) / sigma0 the force is g(v) + sigma2 v, odd in v."""
    p = _parameters(paper_spec, static, ratio, vs, sigma0, sigma1, sigma2)
    g = ratio * static + (static - ratio * static) * math.exp(-(v / vs) ** 2)
    for sign in (1.0, -1.0):
        zd, force = equations.lugre(sign * v, 0.0, sign * g / sigma0, sign, p)[:2]
        assert zd == pytest.approx(0.0, abs=1e-12 * v)
        assert force == pytest.approx(sign * (g + sigma2 * v), rel=1e-12)


@settings(max_examples=200, deadline=None)
@given(v=st.floats(-1.0, 1.0).filter(lambda x: x != 0.0), **FRICTION)
def test_bristle_rate_points_inward_at_fs_over_sigma0(paper_spec, v, static, ratio, vs, sigma0,
                                                       sigma1, sigma2):
    p = _parameters(paper_spec, static, ratio, vs, sigma0, sigma1, sigma2)
    bound = static / sigma0
    sign = math.copysign(1.0, v)
    assert equations.lugre(v, 0.0, bound, sign, p)[0] <= 1e-12 * abs(v)
    assert equations.lugre(v, 0.0, -bound, sign, p)[0] >= -1e-12 * abs(v)


@settings(max_examples=12, deadline=None)
@given(distance=st.floats(0.5e-3, 20e-3), static=st.floats(1.0, 8.0), ratio=st.floats(0.2, 1.0),
       sigma0=st.floats(1e5, 1e7), isolated=st.booleans())
def test_bristle_deflection_from_rest_stays_within_fs_over_sigma0(paper_spec, distance, static,
                                                                  ratio, sigma0, isolated):
    friction = paper_spec.friction.model_copy(update={
        "static": static, "coulomb": ratio * static, "bristle_stiffness": sigma0,
        "bristle_damping": None})
    move = paper_spec.motion.moves[0].model_copy(update={"distance": distance})
    spec = paper_spec.model_copy(update={
        "friction": friction, "motion": paper_spec.motion.model_copy(update={"moves": (move,)})})
    r = simulate(spec, isolated)
    assert r.success
    bound = static / sigma0
    assert np.max(np.abs(r.bristle)) <= bound * (1 + 1e-6)
    # it slid: sliding loads the bristles to g(v) / sigma0 >= Fc / sigma0
    assert np.max(np.abs(r.bristle)) > 0.9 * ratio * bound
