"""The design search on a process pool is the search in one process.

On an executor the search sizes each stroke row's guides as tasks and runs the least change of
the spec as one task beside the search (it reads the spec's model, the crossover cap, the margin
and the stroke envelope, none of the search's points). A short search of the paper setup (two
strokes, two stiffnesses, no widening or refinement, 10 scatter samples) on two forked workers
gives every candidate, the signed-off design, the least change and the count of evaluations of
the search run in one process, value for value.
"""

from __future__ import annotations

import importlib
import multiprocessing
from concurrent.futures import ProcessPoolExecutor

from conftest import variant


def test_the_search_on_a_pool_is_the_search_in_one_process(paper_spec, monkeypatch):
    search = importlib.import_module("fi_design.recommend.search")
    monkeypatch.setattr(search, "STROKES", 2)
    monkeypatch.setattr(search, "STIFFNESSES", 2)
    monkeypatch.setattr(search, "REFINE_STEPS", 0)
    monkeypatch.setattr(search, "WIDEN_ROUNDS", 0)
    spec = variant(paper_spec, **{"requirements.robustness.samples": 10})

    said: list[str] = []
    here = search.recommend(spec)
    with ProcessPoolExecutor(2, mp_context=multiprocessing.get_context("fork")) as ex:
        pooled = search.recommend(spec, executor=ex, progress=said.append)

    assert any("least change" in s and "beside the search" in s for s in said), said
    assert here.least_change is not None and here.least_change.feasible
    assert pooled.least_change == here.least_change
    assert pooled.candidates == here.candidates and len(here.candidates) == 4
    assert pooled.design == here.design and pooled.feasible == here.feasible
    assert pooled.evaluations == here.evaluations
