"""The recommendation resolves each design it judges once (issue 32: the model is the currency).

A short search of the paper setup (two strokes, two stiffnesses, no widening or refinement, 30
scatter samples) with :func:`fi_design.model.resolve` counted per spec resolved: every spec
the search, its sign-off and the least change resolve (the spec's own, the base, each
candidate, each least-change edit) is resolved exactly once; the screen, the fold, the loop's
reserve, the reserve corners and the design command all read the candidate's one model. The
robustness study's own draws (a spec per sample) are counted apart. Before the search passed
models, one candidate was resolved up to four times (the screen twice, the fold twice; at the
sign-off the loop's reserve, the corners and the design once each).
"""

from __future__ import annotations

import collections
import importlib

import pytest

from conftest import variant


def test_every_design_the_search_judges_is_resolved_once(paper_spec, monkeypatch):
    import fi_design.model as fm

    search = importlib.import_module("fi_design.recommend.search")
    verdict = importlib.import_module("fi_design.guideline.verdict")
    monkeypatch.setattr(search, "STROKES", 2)
    monkeypatch.setattr(search, "STIFFNESSES", 2)
    monkeypatch.setattr(search, "REFINE_STEPS", 0)
    monkeypatch.setattr(search, "WIDEN_ROUNDS", 0)

    per_spec: collections.Counter = collections.Counter()
    candidates: set = set()
    in_robustness = [0]
    draws = [0]
    resolve = fm.resolve

    def counted(spec):
        if in_robustness[0]:
            draws[0] += 1
        else:
            per_spec[spec.model_dump_json()] += 1
            fx = spec.isolator.flexure if spec.isolator is not None else None
            if fx is not None and fx.drawn:  # a candidate: a guide drawn from stock
                candidates.add((spec.isolator.stroke, fx.length, fx.width, fx.thickness))
        return resolve(spec)

    run_robustness = verdict.run_robustness

    def robustness(*args, **kwargs):
        in_robustness[0] += 1
        try:
            return run_robustness(*args, **kwargs)
        finally:
            in_robustness[0] -= 1

    monkeypatch.setattr(fm, "resolve", counted)
    monkeypatch.setattr(verdict, "run_robustness", robustness)
    r = search.recommend(variant(paper_spec, **{"requirements.robustness.samples": 30}))

    assert r.feasible and r.design.status == "feasible"
    assert len(candidates) >= 3  # the grid's guides and the signed-off one at full resolution
    assert draws[0] > 0  # the sign-off's scatter ran (and is counted apart)
    twice = [n for n in per_spec.values() if n > 1]
    assert not twice, f"{len(twice)} specs resolved more than once ({sorted(twice)})"
    assert sum(per_spec.values()) == len(per_spec) >= len(candidates) + 2


def test_the_search_refuses_a_model_varied_by_at(paper_spec):
    from fi_design.errors import ArgumentError
    from fi_design.model import resolve

    search = importlib.import_module("fi_design.recommend.search")
    with pytest.raises(ArgumentError, match="controller.crossover"):
        search.recommend(resolve(paper_spec).at(crossover=9.0))
