"""A sized guide on the bounds of its sizing: the note, and only a true claim of more margin."""

from __future__ import annotations

import pytest

from fi_design.mechanism.bounds import bound_notes
from fi_design.mechanism.geometry import stage_body
from fi_design.mechanism.sizing import size_guide, sizing_margin
from fi_design.spec.file import with_values

#: The sizing terms of the paper setup's recommended design: 4400 N/m at 0.9 mm stroke, k_max
#: 4444 N/m, the modes at 3 x the loop's 16.3 Hz, buckling 3.
TERMS = dict(target_stiffness=4400.0, maximum_stiffness=4.0 / 0.9e-3, stroke=0.9e-3,
             required_frequency=48.987, required_buckling=3.0, cart_mass=0.4,
             stop_stiffness=1e6)


def _sized(paper_spec, **flexure):
    spec = with_values(paper_spec, {f"isolator.flexure.{k}": v for k, v in flexure.items()})
    flex, body = spec.isolator.flexure, stage_body(spec.stage)
    fx = size_guide(flex, body, **TERMS)
    return fx, bound_notes(fx, flex, body, cart_mass=0.4, stop_stiffness=1e6)


def test_a_guide_on_the_length_bound_says_so_and_that_longer_leaves_add_margin(paper_spec):
    """The paper setup's guide is sized 60 mm long, on the upper bound of its [10, 60] mm:
    the sizing's smallest margin grows with length (thicker stock, whose tolerance scatters
    the stiffness less)."""
    fx, notes = _sized(paper_spec)
    assert fx.length == 0.06
    [n] = notes
    assert (n.dimension, n.side, n.key, n.given, n.bound) == (
        "length", "upper", "isolator.flexure.length", True, 0.06)
    # sized at a fixed 66 mm, another guide of the same stiffness has more margin
    flex = with_values(paper_spec, {"isolator.flexure.length": "66 mm"}).isolator.flexure
    longer = size_guide(flex, stage_body(paper_spec.stage), **TERMS)
    assert longer.drive_stiffness == pytest.approx(4400.0, rel=1e-3)
    assert sizing_margin(longer).value > sizing_margin(fx).value * 1.001
    assert n.adds_margin and n.margin_beyond == pytest.approx(sizing_margin(longer).value)
    assert n.text == (
        "the leaves' length, 60 mm, sits on the upper bound of its range 10 mm to 60 mm "
        "(isolator.flexure.length, you set); their smallest margin, k_max over the drive "
        "stiffness of the stock's thickest leaves, is x0.953; with the bound moved to 66 mm "
        "the sizing keeps 66 mm x 15.6 mm x 0.6 mm with x0.958: longer leaves would add margin "
        "(widen isolator.flexure.length to let the sizing choose)")


def test_a_guide_inside_its_bounds_has_no_note(paper_spec):
    # without a thickness tolerance the modes bind: 47.4 mm x 29.8 mm x 0.35 mm, inside
    fx, notes = _sized(paper_spec, thickness_tolerance=0.0)
    assert 0.01 < fx.length < 0.06 and 0.005 < fx.width < 0.03 and 0.1e-3 < fx.thickness < 1e-3
    assert notes == ()


def test_a_bound_past_which_the_margin_does_not_grow_claims_no_margin(paper_spec):
    fx, notes = _sized(paper_spec, length=["10 mm", "300 mm"], width=["5 mm", "100 mm"],
                       thickness=["0.1 mm", "2 mm"])
    by = {n.dimension: n for n in notes}
    assert set(by) == {"length", "thickness"} and fx.thickness == 2e-3
    t = by["thickness"]
    assert not t.adds_margin and t.margin_beyond <= t.margin * 1.001
    assert t.text.endswith("with the bound moved to 2.05 mm the sizing keeps 300 mm x 35 mm x "
                           "2.05 mm with x0.9953: thicker leaves would add no margin")
    # the two margins shown with the digits that tell them apart (both read x0.995 before)
    assert "is x0.9949;" in t.text, t.text
    assert "would add margin" not in t.text
    assert by["length"].adds_margin


def test_a_drawn_guide_has_no_bounds(paper_spec):
    spec = with_values(paper_spec, {"isolator.flexure.length": "60 mm",
                                    "isolator.flexure.width": "15 mm",
                                    "isolator.flexure.thickness": "0.55 mm"})
    from fi_design.mechanism.sizing import drawn_guide

    flex, body = spec.isolator.flexure, stage_body(spec.stage)
    fx = drawn_guide(flex, body, stroke=0.9e-3, maximum_stiffness=4444.0,
                     required_frequency=49.0, required_buckling=3.0)
    assert bound_notes(fx, flex, body) == ()
