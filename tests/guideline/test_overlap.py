"""The design's simulations start before its linear steps and stop with them.

With an executor, :func:`fi_design.guideline.evaluate.evaluate` submits the confirmation and
the robustness study's chunks first (the study from a thread of its own), so the workers
simulate while the calling process imports python-control and scans the loop; a step that
raises cancels the study's chunks not yet started.
"""

from __future__ import annotations

import threading
from concurrent.futures import ThreadPoolExecutor

import pytest

import fi_design.guideline.evaluate as evaluate_module
import fi_design.studies.points as points
from fi_design.execution import Background


def test_background_hands_back_the_value_and_the_error():
    assert Background(sorted, [3, 1, 2]).result() == [1, 2, 3]
    with pytest.raises(ZeroDivisionError):
        Background(lambda: 1 / 0).result()


def _failing_step2_with(monkeypatch, module, name: str, what: str, spec, **options) -> list:
    """Run the design with ``module.name`` counted (what it returns, in order) and step 2
    failing once the first of them has started; the values the ones that ran returned."""
    started = threading.Event()
    ran = []
    real = getattr(module, name)

    def counted(*args, **kwargs):
        started.set()
        out = real(*args, **kwargs)
        ran.append(out)
        return out

    def step2_fails(model):
        # the first task starts while this step still runs
        assert started.wait(60), f"no {what} started during step 2"
        raise RuntimeError("step 2 failed")

    monkeypatch.setattr(module, name, counted)
    monkeypatch.setattr(evaluate_module, "step2_crossover", step2_fails)
    with ThreadPoolExecutor(1) as pool:
        with pytest.raises(RuntimeError, match="step 2 failed"):
            evaluate_module.evaluate(spec, executor=pool, **options)
        pool.shutdown(wait=True)
    return ran


def test_the_study_runs_while_the_steps_do_and_a_failing_step_cancels_it(paper_spec,
                                                                        monkeypatch):
    from fi_design.spec.paths import with_values

    spec = with_values(paper_spec, {"requirements.robustness.samples": 32})
    chunks = _failing_step2_with(monkeypatch, points, "run_chunk",
                                 "chunk of the robustness study", spec)
    samples = spec.requirements.robustness.samples
    total = len(points.chunks(2 * samples, points.chunk_size(2 * samples)))  # both plants
    # the chunks already queued when the step failed may run; the rest never start
    assert 1 <= len(chunks) < total, (len(chunks), total)


def test_the_sensitivity_starts_with_the_simulations_and_stops_with_a_failing_step(
        paper_spec, monkeypatch):
    """With an executor the sensitivity's six answers are submitted with the confirmation
    (they need none of its results, only the nominal they are reported beside), so they
    run while the steps do; a step that raises cancels those not yet started."""
    import fi_design.studies.sensitivity as sensitivity
    from fi_design.spec.paths import with_values

    spec = with_values(paper_spec, {"requirements.robustness.samples": 0})
    folds = _failing_step2_with(monkeypatch, sensitivity, "_fold",
                                "answer of the sensitivity", spec, sensitivity=True)
    assert 1 <= len(folds) < 6, len(folds)


def test_the_sensitivity_started_early_is_the_one_computed_after(paper_spec):
    """The sensitivity submitted with the design's simulations and read at its end is the one
    the design computes without an executor, answer for answer."""
    from fi_design.spec.paths import with_values

    spec = with_values(paper_spec, {"requirements.robustness.samples": 0})
    with ThreadPoolExecutor(2) as pool:
        early = evaluate_module.evaluate(spec, executor=pool, sensitivity=True)
    after = evaluate_module.evaluate(spec, sensitivity=True)
    assert early.sensitivity is not None and len(early.sensitivity.points) == 6
    assert early.sensitivity == after.sensitivity
