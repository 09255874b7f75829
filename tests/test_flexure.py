"""Parallel leaf-spring formulas and sizing (guideline step 3)."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings, strategies as st

from fi_design import flexure as fx
from fi_design.spec import Flexure

E, SIGMA, RHO = 200e9, 300e6, 7800.0


def make_flexure(length=(10e-3, 60e-3), width=(5e-3, 30e-3), thickness=(0.1e-3, 1e-3), leaves=2):
    return Flexure(material={"youngs_modulus": E, "allowed_stress": SIGMA, "density": RHO},
                   leaves=leaves, length=length, width=width, thickness=thickness)


PAPER = dict(target_stiffness=6667.0, maximum_stiffness=4.0 / 0.3e-3, stroke=0.3e-3,
             stage_mass=1.6, required_frequency=3 * 8.0)


def test_leaf_spring_formulas_against_worked_numbers():
    # two leaves of L = 40 mm, b = 10 mm, t = 0.5 mm, steel (E = 200 GPa)
    n, L, b, t = 2, 40e-3, 10e-3, 0.5e-3
    # drive: n E b t^3 / L^3 = 2 * 200e9 * 0.01 * 1.25e-10 / 6.4e-5 = 0.5 / 6.4e-5 = 7812.5 N/m
    assert fx.drive_stiffness(n, E, b, t, L) == pytest.approx(7812.5, rel=1e-12)
    # support: n E b t / L = 4e9 * 5e-4 / 0.04 = 5e7 N/m
    assert fx.support_stiffness(n, E, b, t, L) == pytest.approx(5e7, rel=1e-12)
    # stress at 0.3 mm: 3 E t s / L^2 = 6e11 * 5e-4 * 3e-4 / 1.6e-3 = 5.625e7 Pa
    assert fx.bending_stress(E, t, L, 0.3e-3) == pytest.approx(56.25e6, rel=1e-12)
    # stroke limit at 300 MPa: sigma L^2 / (3 E t) = 3e8 * 1.6e-3 / 3e8 = 1.6 mm
    assert fx.stroke_limit(SIGMA, E, t, L) == pytest.approx(1.6e-3, rel=1e-12)
    # support frequency on 1.6 kg: sqrt(5e7 / 1.6) = 5590.17 rad/s = 889.70 Hz
    assert fx.support_frequency(5e7, 1.6) == pytest.approx(889.7036, rel=1e-6)
    # leaf bending, clamped-guided: 2.36502^2 / (2 pi 0.04^2) * 5e-4 * sqrt(2e11 / 93600)
    #   = 5.593321 / 0.0100531 * 5e-4 * 1461.7705 = 406.65 Hz
    assert fx.bending_frequency(E, RHO, t, L) == pytest.approx(406.647, rel=1e-5)


def test_clamped_guided_root():
    x = fx.CLAMPED_GUIDED_ROOT
    assert math.tan(x) + math.tanh(x) == pytest.approx(0.0, abs=1e-12)
    assert 2.36 < x < 2.37


@settings(max_examples=80, deadline=None)
@given(L=st.floats(5e-3, 0.2), b=st.floats(1e-3, 0.1), t=st.floats(2e-5, 3e-3),
       n=st.integers(2, 8), scale=st.floats(0.25, 4.0))
def test_formula_scaling(L, b, t, n, scale):
    k = fx.drive_stiffness(n, E, b, t, L)
    assert fx.drive_stiffness(n, E, scale * b, t, L) == pytest.approx(scale * k, rel=1e-12)
    assert fx.drive_stiffness(n, E, b, scale * t, L) == pytest.approx(scale ** 3 * k, rel=1e-12)
    assert fx.drive_stiffness(n, E, b, t, scale * L) == pytest.approx(k / scale ** 3, rel=1e-12)
    # at the stroke limit the stress is exactly the allowed stress
    s_max = fx.stroke_limit(SIGMA, E, t, L)
    assert fx.bending_stress(E, t, L, s_max) == pytest.approx(SIGMA, rel=1e-12)
    # support over drive stiffness is (L / t)^2, independent of n, E and b
    ratio = fx.support_stiffness(n, E, b, t, L) / k
    assert ratio == pytest.approx((L / t) ** 2, rel=1e-12)


def test_paper_sizing_meets_every_constraint():
    r = fx.size_flexure(make_flexure(), **PAPER)
    assert r.feasible and r.reason == ""
    assert r.drive_stiffness == pytest.approx(6667.0, rel=1e-3)
    assert r.drive_stiffness <= r.maximum_stiffness
    assert 10e-3 <= r.length <= 60e-3 and 5e-3 <= r.width <= 30e-3
    assert 0.1e-3 <= r.thickness <= 1e-3
    # the reported values follow from the dimensions
    assert r.drive_stiffness == pytest.approx(
        fx.drive_stiffness(2, E, r.width, r.thickness, r.length), rel=1e-12)
    assert r.stress == pytest.approx(fx.bending_stress(E, r.thickness, r.length, 0.3e-3))
    assert r.stress_margin == pytest.approx(SIGMA / r.stress) and r.stress_margin > 1
    assert r.stroke_limit > 0.3e-3
    assert r.support_frequency >= 24.0 and r.bending_frequency >= 24.0
    assert r.frequency_margin == pytest.approx(min(r.support_frequency, r.bending_frequency) / 24)
    assert r.leaf_mass == pytest.approx(2 * RHO * r.length * r.width * r.thickness)
    assert r.to_dict()["length"] == r.length


@pytest.mark.parametrize("kwargs, bounds, words", [
    # the longest (10 mm), thinnest (0.5 mm) leaf bends 0.1 mm at 300 MPa
    (dict(), dict(length=(5e-3, 10e-3), thickness=(0.5e-3, 1e-3)),
     ["stress: even the longest, thinnest leaf", "only allows 0.1 mm stroke", "needs 0.3 mm"]),
    # the softest corner: 2 * 200e9 * 5e-3 * 1e-12 / 2.16e-4 = 9.26 N/m
    (dict(maximum_stiffness=5.0, target_stiffness=2.5), dict(),
     ["stiffness: even the longest, narrowest, thinnest", "9.259 N/m", "k_max = 5 N/m"]),
    (dict(required_frequency=5000.0), dict(),
     ["support stiffness: even the shortest, widest, thickest", "below the required 5000 Hz"]),
    (dict(stroke=3e-3, maximum_stiffness=1000.0, target_stiffness=500.0,
          required_frequency=400.0), dict(),
     ["leaf resonance: among leaves within the stress limit", "below the required 400 Hz"]),
    # a long stroke needs thin, long leaves, which are soft in support too: a 1 t stage
    # on the stiffest leaves that pass stress and k_max sits near 30 Hz
    (dict(stroke=10e-3, maximum_stiffness=400.0, target_stiffness=200.0, stage_mass=1000.0,
          required_frequency=50.0), dict(),
     ["support stiffness: among leaves within the stress limit and below k_max"]),
])
def test_infeasible_sizing_names_the_binding_constraint(kwargs, bounds, words):
    r = fx.size_flexure(make_flexure(**bounds), **{**PAPER, **kwargs})
    assert not r.feasible and r.length is None and r.stress is None
    for w in words:
        assert w in r.reason, r.reason


@settings(max_examples=40, deadline=None)
@given(k_target=st.floats(50.0, 5e4), headroom=st.floats(1.0, 4.0),
       stroke=st.floats(0.05e-3, 3e-3), f_req=st.floats(5.0, 600.0))
def test_feasible_designs_meet_their_constraints(k_target, headroom, stroke, f_req):
    r = fx.size_flexure(make_flexure(), target_stiffness=k_target,
                        maximum_stiffness=k_target * headroom, stroke=stroke, stage_mass=1.6,
                        required_frequency=f_req, points=41)
    if r.feasible:
        assert r.drive_stiffness <= r.maximum_stiffness * (1 + 1e-9)
        assert r.stress <= SIGMA * (1 + 1e-9)
        assert min(r.support_frequency, r.bending_frequency) >= f_req * (1 - 1e-9)
    else:
        assert r.reason and r.length is None
