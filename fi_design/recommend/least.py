"""The least change of the spec that passes: one or two of its own values.

Beside the best design (a new guide, stroke and crossover) a user asks what
the smallest edit of the spec is that the sign-off passes. Tried in order,
each with the design command's own verdict, until one passes:

1. the crossover alone (a spec tuned by the rule): the hunting margin above
   the fold of the spec's own isolator, if the loop's cap allows it;
2. the drive stiffness alone, at the spec's stroke and crossover: the
   stiffest that keeps the hunting margin (bisection), at most
   :func:`top_stiffness` (0.99 k_max, and within k_max for the stock's
   thickest leaves where the spec sizes its guide);
3. the stroke and the stiffness, at the spec's crossover: a longer stroke
   (two and four times the spec's), each with its stiffest stiffness.

The spec's other values stay as written (its flexure section sizes the
guide for the new stiffness, its measured modes stay).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from .. import spec as _spec
from ..display import number, quantity
from ..model import Model
from ..results.recommend import LeastChange
from . import constraints as _c

__all__ = ["least_change", "least_change_task", "top_stiffness", "Scope", "BISECTION_STEPS",
           "STROKE_FACTORS"]

#: Bisection steps of the stiffness.
BISECTION_STEPS = 4
#: Strokes tried for the stroke-and-stiffness change, as factors on the spec's [-].
STROKE_FACTORS = (2.0, 4.0)


@dataclass
class Scope:
    """What the least change reads of the search (picklable, for a worker).

    Attributes
    ----------
    model : Model
        The spec's own resolved model.
    margin : float
        ``requirements.hunting_margin`` [-].
    rule : bool
        Whether the spec's loop is tuned by the rule (its crossover may change).
    fc : float
        The loop's crossover cap [Hz].
    fc_why : str
        What sets the cap.
    envelope : tuple of float
        The strokes the search may reach (lowest, highest) [m].
    evaluations : int
        Stage-level evaluations run (counted up by :func:`least_change`).
    """

    model: Model
    margin: float
    rule: bool
    fc: float
    fc_why: str
    envelope: tuple[float, float]
    evaluations: int = 0


def least_change_task(scope: Scope) -> tuple[LeastChange | None, int]:
    """:func:`least_change` as one task (on a worker, beside the search): its result and the
    stage-level evaluations it ran. Its design verdicts run in the task's process."""
    found = least_change(scope)
    return found, scope.evaluations


def _margin_ok(model: Model, margin: float) -> tuple[bool, dict]:
    ans = _c.margin_screen(model, margin)
    return ans["keeps"], ans


def _stiffest(model: Model, stroke: float, margin: float,
              k_top: float) -> tuple[float | None, Model | None, int]:
    """The stiffest drive stiffness at a stroke that keeps the margin (bisection on log k, up
    to ``k_top``, :func:`top_stiffness`), the model there (resolved once, as screened) and the
    screens run."""
    kmax = _spec.stiffness_limit(model.spec, stroke)
    lo, hi = math.log(kmax / 40.0), math.log(k_top)
    at = lambda k: model.varied({"isolator.stroke": stroke, "isolator.stiffness": k})
    n = 1
    top = at(k_top)
    if _margin_ok(top, margin)[0]:
        return k_top, top, n
    n += 1
    best = at(math.exp(lo))
    if not _margin_ok(best, margin)[0]:
        return None, None, n
    for _ in range(BISECTION_STEPS):
        mid = 0.5 * (lo + hi)
        n += 1
        m = at(math.exp(mid))
        if _margin_ok(m, margin)[0]:
            lo, best = mid, m
        else:
            hi = mid
    return math.exp(lo), best, n


def top_stiffness(model: Model, stroke: float) -> float:
    """The stiffest joint a change of the spec may ask for at a stroke [N/m].

    The search's top target, :data:`~.constraints.TOP` x k_max; where the spec's
    flexure section sizes the guide from stock, lower still, so that the
    stock's thickest leaves keep k_max (:func:`~.constraints.guide_for`), as
    the recommended design does; rounded down to the digits the change is
    written with (:data:`~.write.DIGITS`).
    """
    from .write import DIGITS

    k = _c.TOP * _spec.stiffness_limit(model.spec, stroke)
    fx = model.flexure if model.flexure_spec is not None else None
    if fx is not None and not fx.drawn:  # a guide from stock: its tolerance scatters k
        sized = _c.guide_for(model, k, stroke, _spec.design_crossover(model.spec))
        if sized.feasible:
            k = min(k, sized.mechanics.net_drive_stiffness)
    # rounded down to the digits the change is written with: the spec gets what was judged
    step = 10.0 ** (math.floor(math.log10(k)) - DIGITS + 1)
    return math.floor(k / step) * step


def _passes(model: Model, executor: Any) -> tuple[bool, str]:
    from ..guideline.evaluate import evaluate as design

    r = design(model, executor=executor)
    if r.verdict.status == "FAIL":
        fails = [x.text for x in r.verdict.reasons if x.severity == "FAIL"]
        return False, fails[0] if fails else "the sign-off fails"
    return True, ""


def least_change(search: Any, *, executor: Any = None,
                 progress: Callable[[str], None] | None = None) -> LeastChange | None:
    """The smallest edit of the spec that passes the sign-off.

    Parameters
    ----------
    search : Scope or fi_design.recommend.search._Search
        The search's spec model, crossover cap, margin and stroke envelope (its
        ``evaluations`` are counted up).
    executor : concurrent.futures-style executor, optional
        Runs the sign-off's simulations.
    progress : callable, optional
        ``progress(text)``.

    Returns
    -------
    LeastChange or None
        None for a spec without isolator (any change adds one: the best
        design is the answer).
    """
    say = progress or (lambda text: None)
    model = search.model
    spec = model.spec
    if spec.isolator is None:
        return None
    margin = search.margin
    tried: list[str] = []
    fc0 = _spec.design_crossover(spec)
    s0 = spec.isolator.stroke
    bounds = spec.requirements.recommend  # the user's bounds hold for the least change too

    def done(changes: dict, text: str, binding: tuple[str, ...]) -> LeastChange:
        from .write import DIGITS, written

        shown = {p: written(spec, p, v, digits=DIGITS) for p, v in changes.items()}
        return LeastChange(changes=shown, feasible=True, binding=binding, text=text,
                           tried=tuple(tried))

    # 1. the crossover alone
    if search.rule:
        say("the least change: the crossover alone ...")
        ans = _c.stage_answer(model, fold="always")
        fold = ans["free_from"]
        if fold is not None:
            fc = 1.01 * margin * fold
            if bounds.crossover is not None and fc < bounds.crossover[0]:
                tried.append(f"the crossover alone, {quantity(fc, 'Hz', 4)}: below "
                             "requirements.recommend.crossover")
            elif fc <= search.fc:
                cand = model.varied({"controller.crossover": fc})
                ok, why = _passes(cand, executor)
                if ok:
                    return done({"controller.crossover": fc},
                                f"tune the loop to {quantity(fc, 'Hz', 4)} ({number(margin, 6)} x "
                                f"the hunting-free {quantity(fold, 'Hz', 4)})",
                                (f"the crossover's cap {quantity(search.fc, 'Hz', 4)}",))
                tried.append(f"the crossover alone, {quantity(fc, 'Hz', 4)}: {why}")
            else:
                tried.append(f"the crossover alone: {number(margin, 6)} x the hunting-free "
                             f"{quantity(fold, 'Hz', 4)} is {quantity(margin * fold, 'Hz', 4)}, "
                             f"above the loop's cap of {quantity(search.fc, 'Hz', 4)} "
                             f"({search.fc_why})")
        else:
            tried.append("the crossover alone: the spec's isolator hunts up to the top of the "
                         "crossover search")
    # 2. the stiffness alone, 3. the stroke and the stiffness, at the spec's crossover
    options = [(s0, "the stiffness alone")] + [
        (s0 * f, "the stroke and the stiffness") for f in STROKE_FACTORS
        if search.envelope[0] <= s0 * f <= search.envelope[1]]
    for stroke, what in options:
        say(f"the least change: {what} ({quantity(stroke, 'm')}) ...")
        k_top = top_stiffness(model, stroke)
        k, cand, n = _stiffest(model, stroke, margin, k_top)
        search.evaluations += n
        if k is None:
            tried.append(f"{what} at {quantity(stroke, 'm')}: no stiffness keeps the hunting "
                         f"margin at {quantity(fc0, 'Hz', 4)}")
            continue
        if bounds.stiffness is not None and not bounds.stiffness[0] <= k <= bounds.stiffness[1]:
            tried.append(f"{what} at {quantity(stroke, 'm')}: {quantity(k, 'N/m', 4)}, outside "
                         "requirements.recommend.stiffness")
            continue
        values = {"isolator.stiffness": k} if stroke == s0 else \
            {"isolator.stroke": stroke, "isolator.stiffness": k}
        ok, why = _passes(cand, executor)
        if ok:
            words = (f"a drive stiffness of {quantity(k, 'N/m', 4)}" if stroke == s0 else
                     f"a {quantity(stroke, 'm')} stroke at {quantity(k, 'N/m', 4)}")
            kmax = _spec.stiffness_limit(spec, stroke)
            bound = (f"k_max = Fs / stroke = {quantity(kmax, 'N/m', 4)} at "
                     f"{quantity(stroke, 'm')} stroke" if k >= k_top else
                     f"the hunting margin {number(margin, 6)} at {quantity(fc0, 'Hz', 4)}")
            return done(values, words + f", the loop at {quantity(fc0, 'Hz', 4)}", (bound,))
        tried.append(f"{what} at {quantity(stroke, 'm')}, {quantity(k, 'N/m', 4)}: {why}")
    return LeastChange(changes={}, feasible=False, binding=(), text="no edit of one or two "
                       "values passes", tried=tuple(tried))
