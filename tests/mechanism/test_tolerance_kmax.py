"""The stock's thickness tolerance against k_max: the search sizes its guides so that the
thickest leaves of the stock stay within it (the recommendation: tests/recommend)."""

from __future__ import annotations

import pytest

from fi_design import spec as _spec
from fi_design.mechanism.sizing import net_stiffness
from fi_design.recommend import constraints as C
from fi_design.recommend.search import TOP, _Search


@pytest.fixture(scope="module")
def search(paper_spec_path):
    from fi_design.model import as_model
    from fi_design.spec.file import as_spec

    return _Search(as_model(as_spec(paper_spec_path)), None, lambda text: None)


def test_top_target_sized_within_kmax_over_the_tolerance(search):
    """At the search's top target (0.99 k_max) the thickest stock (t + dt) stays within k_max,
    computed here from the closed form at t + dt (not the sizing's own range), while the
    nominal guide is as stiff as that allows: within 1 % of k_max (t / (t + dt))^3."""
    stroke = search.base.isolator.stroke
    kmax = _spec.stiffness_limit(search.base, stroke)
    fx = C.guide_for(search.base_model, TOP * kmax, stroke, search.fc)
    assert fx.feasible
    g, dt = fx.guide, fx.thickness_tolerance
    assert dt > 0
    thick = float(net_stiffness(g, g.length, g.width, g.thickness + dt))
    assert thick <= kmax * (1 + 1e-6)
    assert fx.stiffness_range[1] == pytest.approx(thick, rel=1e-9)
    # as stiff as the tolerance allows (k goes about with t^3; gravity shifts it a little)
    k = fx.mechanics.net_drive_stiffness
    assert k == pytest.approx(kmax * (g.thickness / (g.thickness + dt)) ** 3, rel=0.01)
    assert k < TOP * kmax


def test_soft_target_sized_as_asked(search):
    """Far below k_max the tolerance binds nothing: the guide hits its target."""
    stroke = search.base.isolator.stroke
    kmax = _spec.stiffness_limit(search.base, stroke)
    fx = C.guide_for(search.base_model, 0.3 * kmax, stroke, search.fc)
    assert fx.feasible
    assert fx.mechanics.net_drive_stiffness == pytest.approx(0.3 * kmax, rel=2e-3)


@pytest.mark.parametrize("tolerance", [0.05e-3, 0.09e-3])
def test_a_coarse_tolerance_is_kept_or_the_guide_refused(paper_spec_path, tolerance):
    """A tolerance of a fifth of the leaf changes k by a factor of about 2 over the stock: the
    guide of every stroke either keeps the thickest leaves within k_max or is no guide, with the
    tolerance named; never a guide above k_max."""
    from fi_design.model import as_model
    from fi_design.spec.file import as_spec, with_values

    spec = with_values(as_spec(paper_spec_path),
                       {"isolator.flexure.thickness_tolerance": tolerance})
    srch = _Search(as_model(spec), None, lambda text: None)
    kept = 0
    for stroke in (0.3e-3, 0.9e-3, 2e-3):
        kmax = _spec.stiffness_limit(srch.base, stroke)
        fx = C.guide_for(srch.base_model, TOP * kmax, stroke, srch.fc)
        if fx.feasible:
            g = fx.guide
            thick = float(net_stiffness(g, g.length, g.width, g.thickness + tolerance))
            assert thick <= kmax * (1 + 1e-6), (stroke, thick / kmax)
            kept += 1
        else:
            assert "thickness tolerance" in fx.reason and "k_max" in fx.reason
    assert kept >= 2
