"""What binds a recommendation (fi_design.recommend.objective.binding), on a search made up here.

The points are those the paper setup's search judged at three strokes (its recommendation, 0.9
mm at 4400 N/m, lies at k_max = 4444 N/m): a shorter stroke raises k_max = Fs / stroke, a
longer one lowers it, and what stops the joint at each is said with that stroke's own numbers.
The whole search of the paper setup is checked against its Pareto front in test_recommend.py.
"""

from __future__ import annotations

from types import SimpleNamespace

from fi_design import spec as _spec
from fi_design.display import quantity
from fi_design.recommend.objective import binding

MARGIN = "the crossover lies only 1.197 x above the hunting-free 8.858 Hz (the margin asks 1.2 x)"


def _point(stroke, k, status, margin=None, why=()):
    return SimpleNamespace(stroke=stroke, target=k, stiffness=k, status=status, margin=margin,
                           violations=list(why), candidate=None if status == "flexure" else k,
                           thickest=None)


def _search(spec, points):
    return SimpleNamespace(points=points, base=spec, envelope=(1e-4, 3e-3), why_lo="",
                           why_hi="", rule=False)


def _paper_rows():
    """The paper setup's points at 0.52, 0.9 and 1.62 mm (stroke m, k N/m, status, margin)."""
    short, chosen, long_ = 0.5196152422706629e-3, 0.9e-3, 1.62e-3
    return [
        _point(short, 401.7, "flexure", why=["no guide: parasitic modes"]),
        _point(short, 838.3, "not_evaluated"),
        _point(short, 1749.6, "not_evaluated", 1.34),
        _point(short, 3651.5, "margin", 1.197, [MARGIN]),
        _point(short, 7610.8, "margin", 1.094, ["the crossover lies only 1.094 x above"]),
        _point(chosen, 2108.2, "not_evaluated"),
        _point(chosen, 4400.0, "feasible", 1.41),
        _point(long_, 1171.2, "not_evaluated"),
        _point(long_, 2444.4, "not_evaluated", 1.88),
    ]


def test_a_neighbouring_stroke_is_said_with_its_own_k_max_and_its_own_points(paper_spec):
    """The sentence read 'a shorter stroke (0.5196 mm) allows a softer joint at most: 3652 N/m
    fails on the hunting margin' while the front listed 7611 N/m at 0.52 mm: 3652 N/m was the
    first joint that failed there, not the most it allows, and a shorter stroke raises k_max."""
    points = _paper_rows()
    chosen = points[6]
    out = binding(_search(paper_spec, points), chosen)
    kmax = {s: _spec.stiffness_limit(paper_spec, s) for s in {p.stroke for p in points}}
    assert out[0] == f"k_max = Fs / stroke = {quantity(kmax[0.9e-3], 'N/m', 4)} at 0.9 mm stroke"
    shorter = next(b for b in out if b.startswith("a shorter stroke"))
    assert shorter == (f"a shorter stroke (0.5196 mm) raises k_max to "
                       f"{quantity(kmax[points[0].stroke], 'N/m', 4)}, but the stiffest joint "
                       f"there that keeps the margin is 1750 N/m: 3652 N/m fails on the hunting "
                       f"margin ({MARGIN})")
    assert kmax[points[0].stroke] > kmax[0.9e-3] > kmax[1.62e-3]
    longer = next(b for b in out if b.startswith("a longer stroke"))
    assert longer == (f"a longer stroke (1.62 mm) lowers k_max to "
                      f"{quantity(kmax[1.62e-3], 'N/m', 4)}, and the stiffest joint there that "
                      f"keeps the margin is 2444 N/m")
    assert not any("at most" in b for b in out)


def test_a_neighbouring_stroke_with_no_joint_kept_names_its_stiffest(paper_spec):
    """Where every joint of a stroke fails, the stiffest judged says why (the softest, without a
    guide, says nothing about a stiffer joint)."""
    short, chosen = 0.3e-3, 0.5196152422706629e-3
    points = [_point(short, 333.3, "flexure", why=["no guide"]),
              _point(short, 695.7, "margin", why=["some move hunts at 8.835 Hz"]),
              _point(short, 6324.6, "hunts", 0.0, ["at 10.6 Hz some move of the family hunts"]),
              _point(chosen, 1749.6, "feasible", 1.34)]
    out = binding(_search(paper_spec, points), points[-1])
    kmax = quantity(_spec.stiffness_limit(paper_spec, short), "N/m", 4)
    assert (f"a shorter stroke (0.3 mm) raises k_max to {kmax}, but no joint there passes: "
            "6325 N/m fails on hunting at the crossover (at 10.6 Hz some move of the family "
            "hunts)") in out


def test_the_nearest_infeasible_design_is_the_stiffest_that_kept_the_margin():
    """The paper setup on a vertical axis (its search's points, tests/recommend's slow test):
    every design sags past its stroke under the cart, and ranked by hunting margin alone the
    nearest was the softest, 310 N/m sagging 12.6 mm on a 2.92 mm stroke, beside 4211 N/m
    sagging 0.93 mm on 0.9 mm. A design that kept the margin and fails a check is nearer the
    stiffer it is; one short of the margin, the more margin it has."""
    from fi_design.recommend.objective import nearest

    sags = ["it sags %s of its stroke" % s for s in ("12.6 mm", "3.11 mm", "0.932 mm")]
    checks = [_point(2.916e-3, 310.3, "checks", 3.11, [sags[0]]),
              _point(2.916e-3, 1260.6, "checks", 2.51, [sags[1]]),
              _point(0.9e-3, 4210.7, "checks", 1.41, [sags[2]])]
    short = [_point(0.52e-3, 3651.5, "margin", 1.197, [MARGIN]),
             _point(0.52e-3, 7353.6, "margin", 1.099, ["the crossover lies only 1.099 x"]),
             _point(0.1e-3, 9091.1, "hunts", 0.0, ["some move of the family hunts"])]
    assert nearest(checks + short) is checks[2]
    assert nearest(short) is short[0]  # the most margin, not the stiffest
    assert nearest(short[1:]) is short[1]


def test_a_reason_ending_its_sentence_is_not_ended_twice():
    """The nearest design's advice read "... it rests on its end stop.)." with the reason's
    own period inside the parenthesis."""
    from types import SimpleNamespace

    from fi_design.recommend.objective import _why

    point = SimpleNamespace(status="violates", violations=[
        "step 3 flexure: it sags 0.932 mm of its 0.9 mm stroke: it rests on its end stop."])
    text = _why(point)
    assert text.endswith("it rests on its end stop)") and ".)" not in text, text


def test_a_stiffer_joint_that_fails_at_the_chosen_stroke_binds_it_as_a_noun_phrase(paper_spec):
    """Where a stiffer joint fails at the chosen stroke (below k_max), the advice read 'it is
    bound by at 100 µm stroke a stiffer joint (39600 N/m) fails on ...': a clause where the
    sentence wants what binds it."""
    chosen = _point(1e-4, 20000.0, "feasible", 1.95)
    stiffer = _point(1e-4, 39600.0, "margin", 1.1, [MARGIN])
    out = binding(_search(paper_spec, [chosen, stiffer]), chosen)
    assert out[0] == (f"what fails a stiffer joint (39600 N/m) at 0.1 mm stroke: the hunting "
                      f"margin ({MARGIN})"), out[0]
