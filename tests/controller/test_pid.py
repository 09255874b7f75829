"""The PID tuning rule (guideline step 4) against its closed-form consequences."""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from fi_design.controller.pid import PidGains, pid_gains, tune_pid


def free_mass_crossover_ratio(r: float, ri: float) -> float:
    """Exact crossover of the rule on a free mass, as x = w / wc.

    |L(j w)|^2 = (1 + r^2 x^2)(1 + 1/(ri^2 x^2)) / (x^4 (r^2 + x^2)) = 1 with
    y = x^2 gives the quartic
        ri^2 y^4 + ri^2 r^2 y^3 - r^2 ri^2 y^2 - (ri^2 + r^2) y - 1 = 0,
    whose positive real root near 1 is the crossover.
    """
    roots = np.roots([ri ** 2, ri ** 2 * r ** 2, -(r ** 2) * ri ** 2, -(ri ** 2 + r ** 2), -1.0])
    y = [z.real for z in roots if abs(z.imag) < 1e-9 and z.real > 0]
    assert len(y) == 1
    return math.sqrt(y[0])


def free_mass_phase_margin(x: float, r: float, ri: float) -> float:
    """Phase margin [deg] of C/(m s^2) at x = w/wc: the lead minus the lag of the
    roll-off minus the integrator's lag, atan(r x) - atan(x / r) - atan(1 / (ri x))."""
    return math.degrees(math.atan(r * x) - math.atan(x / r) - math.atan(1.0 / (ri * x)))


def test_gains_of_the_paper_setup(paper_spec):
    g = tune_pid(paper_spec)
    wc = 2 * math.pi * 8.0
    m = 1.6 + 0.4
    assert g.crossover == 8.0 and g.tuning_mass == m
    assert g.wc == pytest.approx(wc, rel=1e-15)
    assert g.ks == pytest.approx(m * wc ** 2 / 3, rel=1e-14)       # DESIGN: kp = m wc^2 / 3
    assert g.wd == pytest.approx(wc / 3, rel=1e-15)
    assert g.wt == pytest.approx(3 * wc, rel=1e-15)
    assert g.wi == pytest.approx(wc / 10, rel=1e-15)
    assert g.kp == pytest.approx(g.ks * (1 + g.wi / g.wd), rel=1e-15)
    assert g.ki == pytest.approx(g.ks * g.wi, rel=1e-15)
    assert g.kd == pytest.approx(g.ks / g.wd, rel=1e-15)
    # worked numbers: wc = 50.265 rad/s, ks = 2 * 2526.6 / 3 = 1684.4 N/m,
    # kp = 1.3 ks = 2189.7 N/m, ki = 1684.4 * 5.0265 = 8466.8 N/(m s), kd = 1684.4 / 16.755
    assert (round(g.ks, 1), round(g.kp, 1), round(g.ki, 1), round(g.kd, 2)) == \
        (1684.4, 2189.7, 8466.8, 100.53)


def test_tuning_mass_rule_and_overrides(paper_spec):
    spec = paper_spec.model_copy(update={
        "controller": paper_spec.controller.model_copy(update={"tuning_mass": "stage"})})
    assert tune_pid(spec).tuning_mass == 1.6
    assert tune_pid(paper_spec, mass=3.0).tuning_mass == 3.0
    assert tune_pid(paper_spec, crossover=20.0).crossover == 20.0


def test_parallel_form_equals_series_form():
    g = pid_gains(2.0, 8.0)
    s = 1j * np.geomspace(0.1, 1e4, 7)
    parallel = (g.kp + g.ki / s + g.kd * s) / (1 + s / g.wt)
    np.testing.assert_allclose(parallel, g.series(s), rtol=1e-12)


def test_free_mass_crosses_over_just_above_wc_with_the_rule_phase(paper_spec):
    """The rule on a free mass: exact crossover and phase margin, via python-control."""
    from fi_design.loop.linear import controller_polynomials, loop_margins

    g = tune_pid(paper_spec)
    x = free_mass_crossover_ratio(3.0, 10.0)
    # a fraction of a percent above wc (the integrator's sqrt(1 + 1/100) = 1.005 in |L(j wc)|)
    assert 1.0 < x < 1.005
    cn, cd = controller_polynomials(g)
    m = loop_margins(cn, np.polymul(cd, [g.tuning_mass, 0.0, 0.0]), scale=g.wc)
    assert m.crossovers == pytest.approx((x * g.crossover,), rel=1e-9)
    assert m.crossover == pytest.approx(x * 8.0, rel=1e-9)
    assert m.phase_margin_deg == pytest.approx(free_mass_phase_margin(x, 3.0, 10.0), abs=1e-7)
    # the rule's phase at wc itself: atan 3 - atan 1/3 - atan 0.1 = 71.565 - 18.435 - 5.711 deg
    assert free_mass_phase_margin(1.0, 3.0, 10.0) == pytest.approx(47.4195, abs=1e-4)
    assert m.stable


@settings(max_examples=60, deadline=None)
@given(mass=st.floats(0.01, 100.0), fc=st.floats(0.1, 1000.0), r=st.floats(1.5, 10.0),
       ri=st.floats(2.0, 50.0))
def test_rule_invariants(mass, fc, r, ri):
    """|L(j wc)| = sqrt(1 + 1/ri^2) for a free mass; the exact crossover solves the quartic."""
    g = pid_gains(mass, fc, r, ri)
    wc = 2 * math.pi * fc
    loop = lambda w: g.series(1j * w) / (mass * (1j * w) ** 2)  # noqa: E731
    assert abs(loop(wc)) == pytest.approx(math.sqrt(1 + 1 / ri ** 2), rel=1e-12)
    x = free_mass_crossover_ratio(r, ri)
    assert abs(loop(x * wc)) == pytest.approx(1.0, rel=1e-9)
    assert 1.0 < x < 1.0 + 1.0 / ri ** 2
    assert (math.degrees(np.angle(loop(x * wc))) + 360.0) % 360.0 - 180.0 == \
        pytest.approx(free_mass_phase_margin(x, r, ri), abs=1e-9)
    assert g.kp > 0 and g.ki > 0 and g.kd > 0 and g.wd < g.wc < g.wt


@pytest.mark.parametrize("args", [(0.0, 8.0), (2.0, -1.0), (2.0, 8.0, 1.0, 10.0)])
def test_bad_arguments(args):
    with pytest.raises(ValueError):
        pid_gains(*args)


def test_to_dict_is_plain_si():
    d = pid_gains(2.0, 8.0).to_dict()
    assert set(d) == {f for f in PidGains.__dataclass_fields__}
    assert all(isinstance(v, float) for v in d.values())


def test_pid_module_stays_light():
    code = ("import sys, fi_design.controller.pid; "
            "print(' '.join(m for m in ('control', 'scipy', 'pint', 'numba') if m in sys.modules))")
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert p.returncode == 0, p.stderr
    assert p.stdout.strip() == ""
