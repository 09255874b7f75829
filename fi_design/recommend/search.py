"""The search: the stiffest buildable joint that keeps the hunting margin and passes the sign-off.

Over strokes (log-spaced, first a factor of :data:`~.space.STROKE_SPAN` either
way of the spec's, widened up to the envelope of :func:`~.space.stroke_envelope`
while the best design lies on the range's edge) and, per stroke, target
stiffnesses up to k_max = Fs / stroke, each point is:

1. built: a guide from stock for that net drive stiffness and stroke, at the
   crossover of :func:`~.constraints.crossover_cap` (stress, buckling, every
   parasitic mode at the separation times the crossover); a point no guide
   realises is out (``flexure``);
2. judged: the stage after every move of its family at the crossover, and
   the fold of its cycle (:func:`~.constraints.stage_answer`, on the
   caller's executor): its hunting margin, the crossover over the fold;
3. ordered (:mod:`.objective`): the stiffest joint whose margin reaches
   ``requirements.hunting_margin``; at its stroke the stiffness is refined by
   bisection towards the next stiffer point, which fails the margin;
4. signed off, stiffest first until one passes: the loop's margins with their
   reserve (its own modes in), the reserve corners (masses, stiffness, modes,
   delay) and the design command's verdict (robustness included).

On an executor, each stroke row's guides are sized as tasks, and the least
change of the spec (:mod:`.least`, which reads none of the search's points)
runs as one task beside the search; the result is the same as in one process.
"""

from __future__ import annotations

import logging
import math
import time as _time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .. import spec as _spec
from ..display import number, quantity
from ..model import Model
from ..results.recommend import DesignCandidate, RecommendResult
from . import constraints as _c
from . import objective as _o
from .constraints import TOP
from .space import STROKE_SPAN, Candidate, base_model, damping_ratio, stroke_envelope

log = logging.getLogger(__name__)

__all__ = ["STROKES", "STIFFNESSES", "REFINE_STEPS", "WIDEN_ROUNDS", "recommend"]

#: Strokes of the first range.
STROKES = 5
#: Target stiffnesses per stroke, log-spaced from k_max / :data:`STIFFNESS_SPAN` to k_max.
STIFFNESSES = 6
STIFFNESS_SPAN = 40.0
#: Bisection steps of the stiffness at the best stroke.
REFINE_STEPS = 3
#: Lengths of the chosen guide's sizing grid (the search's is coarser).
FULL_POINTS = 161
#: Rounds of widening the stroke range towards the envelope.
WIDEN_ROUNDS = 3


@dataclass
class _Point:
    """A point of the search as it is worked on (the result keeps DesignCandidate)."""

    stroke: float
    target: float
    crossover: float
    status: str | None = None
    violations: list = field(default_factory=list)
    candidate: Candidate | None = None
    lowest_mode: float | None = None
    thickest: float | None = None
    free_from: float | None = None
    hunts: bool = False
    margin: float | None = None
    folded: bool = False
    p: float | None = None
    clearance: float | None = None
    model: Model | None = None
    guide: Any = None  # the FlexureResult whose leaves the candidate holds

    @property
    def stiffness(self) -> float:
        return self.candidate.stiffness if self.candidate is not None else self.target

    def result(self) -> DesignCandidate:
        c = self.candidate
        return DesignCandidate(
            stroke=self.stroke, stiffness=self.stiffness,
            damping=None if c is None else c.damping, crossover=self.crossover,
            status=self.status or "not_evaluated", violations=tuple(self.violations),
            length=None if c is None else c.length, width=None if c is None else c.width,
            thickness=None if c is None else c.thickness, lowest_mode=self.lowest_mode,
            hunting_free_from=self.free_from, hunting_margin=self.margin,
            unsettled_probability=self.p, end_stop_clearance=self.clearance)


def _map(executor: Any, fn: Callable, items: list) -> list:
    """``fn`` over ``items`` (tuples of arguments), on the executor when there is one."""
    if executor is None or len(items) < 2:
        return [fn(*x) for x in items]
    futures = [executor.submit(fn, *x) for x in items]
    return [f.result() for f in futures]


class _Search:
    """The state of one search (internal): the base, the crossover, the points judged."""

    def __init__(self, model: Model, executor: Any, say: Callable[[str], None]):
        self.model = model
        self.spec = model.spec
        self.executor = executor
        self.say = say
        base, self.assumed = base_model(model)
        self.rule = self.spec.controller.gains is None
        self.fc, self.fc_why, self.notch = _c.crossover_cap(model, self.rule)
        if self.notch is not None:  # every candidate carries the notch the search adds
            base = _c.notched_model(base, self.notch)
        self.base_model = base
        self.base = base.spec
        self.margin = self.base.requirements.hunting_margin
        self.zeta = damping_ratio(base)
        m1, m2 = self.base.stage.mass, self.base.cart.mass
        self.mred = m1 * m2 / (m1 + m2)
        self.points: list[_Point] = []
        self.evaluations = 0
        lo, hi, self.why_lo, self.why_hi = stroke_envelope(self.base)
        self.envelope = (lo, hi)

    # ---- points

    def build(self, stroke: float, target: float) -> _Point:
        """A point with its guide from stock (or the reason it has none)."""
        p = self.planned(stroke, target)
        if p.status is None:
            self.place(p, _c.guide_for(self.base_model, target, stroke, self.fc))
        return p

    def build_all(self, pairs: list[tuple[float, float]]) -> list[_Point]:
        """:meth:`build` over (stroke, target) pairs, the guides sized on the executor."""
        pts = [self.planned(s, k) for s, k in pairs]
        todo = [p for p in pts if p.status is None]
        tasks = [(self.base_model, p.target, p.stroke, self.fc) for p in todo]
        for p, fx in zip(todo, _map(self.executor, _c.guide_for, tasks)):
            self.place(p, fx)
        return pts

    def planned(self, stroke: float, target: float) -> _Point:
        """A new point of the search, out already where its target breaks k_max or the bounds."""
        p = _Point(stroke=stroke, target=target, crossover=self.fc)
        self.points.append(p)
        kmax = _spec.stiffness_limit(self.base, stroke)
        b = self.base.requirements.recommend
        if target > kmax * (1 + 1e-9):
            p.status = "k_max"
            p.violations.append(f"k = {quantity(target, 'N/m', 4)} exceeds k_max = "
                                f"{quantity(kmax, 'N/m', 4)}")
            return p
        if b.stiffness is not None and not b.stiffness[0] <= target <= b.stiffness[1]:
            p.status = "bounds"
            p.violations.append("outside requirements.recommend.stiffness")
        return p

    def place(self, p: _Point, fx: Any) -> None:
        """The point's guide (:func:`~.constraints.guide_for`'s answer): its candidate, or out
        (``flexure``) where no guide realises it."""
        if not fx.feasible:
            p.status = "flexure"
            p.violations.append(f"no guide: {fx.reason}")
            return
        k = fx.drive_stiffness
        c = None if self.zeta is None else 2.0 * self.zeta * math.sqrt(k * self.mred)
        p.candidate = Candidate(stroke=p.stroke, length=fx.length, width=fx.width,
                                thickness=fx.thickness, stiffness=k, crossover=self.fc,
                                damping=c)
        p.lowest_mode = fx.lowest_mode.frequency if fx.lowest_mode is not None else None
        p.thickest = _c.thickest_stiffness(fx)
        p.guide = fx

    def candidate_model(self, p: _Point) -> Model:
        """The point's candidate resolved into its model, once: every judgement reads it."""
        if p.model is None:
            p.model = p.candidate.model(self.base_model, self.rule)
        return p.model

    def judge(self, points: list[_Point]) -> None:
        """Screen the points' hunting margin (two quick stage answers each, on the executor)."""
        todo = [p for p in points if p.status is None]
        if not todo:
            return
        self.say(f"simulating the move family of {len(todo)} guides at "
                 f"{quantity(self.fc, 'Hz', 4)} and {quantity(self.fc / self.margin, 'Hz', 4)} ...")
        tasks = [(self.candidate_model(p), self.margin) for p in todo]
        for p, ans in zip(todo, _map(self.executor, _c.margin_screen, tasks)):
            self.evaluations += ans["tests"]
            p.hunts = ans["hunts"]
            if p.hunts:
                p.margin = 0.0
                p.status = "hunts"
                p.violations.append(
                    f"at {quantity(self.fc, 'Hz', 4)} some move of the family hunts")
            elif ans["outcome"] not in ("settles", "hunts_below"):
                p.status = "hunts"
                p.violations.append(f"at {quantity(self.fc, 'Hz', 4)} some move of the family ends "
                                    f"{ans['outcome'].replace('_', ' ')}")
            elif not ans["keeps"]:
                p.status = "margin"
                p.violations.append(
                    f"no move hunts at {quantity(self.fc, 'Hz', 4)}, but some does at "
                    f"{quantity(self.fc / self.margin, 'Hz', 4)}: the hunting-free crossover lies "
                    f"less than {number(self.margin, 6)} x below the crossover")

    def fold(self, points: list[_Point]) -> None:
        """The hunting-free crossover (the fold of the cycle) of points, and their margin."""
        todo = [p for p in points if p.candidate is not None and not p.folded and not p.hunts]
        if not todo:
            return
        self.say(f"finding the hunting-free crossover of {len(todo)} guides ...")
        tasks = [(self.candidate_model(p),) for p in todo]
        for p, ans in zip(todo, _map(self.executor, _c.stage_answer, tasks)):
            self.evaluations += 1 + ans["tests"]
            p.folded = True
            p.free_from = ans["free_from"]
            p.margin = _c.hunting_margin(self.fc, p.free_from, ans["hunts"])
            if p.status is None and p.margin < self.margin:  # the fold: a band the screen missed
                p.status = "margin"
                p.violations.append(
                    f"the crossover lies only {number(p.margin, 4)} x above the hunting-free "
                    f"{quantity(p.free_from, 'Hz', 4)} (the margin asks "
                    f"{number(self.margin, 6)} x)")

    def stroke_row(self, strokes) -> None:
        pairs = []
        for s in strokes:
            kmax = _spec.stiffness_limit(self.base, s)
            pairs += [(float(s), float(k))
                      for k in np.geomspace(kmax / STIFFNESS_SPAN, TOP * kmax, STIFFNESSES)]
        self.judge(self.build_all(pairs))

    def best(self) -> _Point | None:
        ok = [p for p in self.points if p.status is None]
        return max(ok, key=_o.order) if ok else None

    def stiffest_per_stroke(self) -> list[_Point]:
        out = []
        for s in sorted({p.stroke for p in self.points}):
            ok = [p for p in self.points if p.stroke == s and p.status is None]
            if ok:
                out.append(max(ok, key=lambda p: p.stiffness))
        return out

    def confirm(self) -> None:
        """Fold the stiffest screened design of every stroke until each one's margin stands
        (the screen sees which moves enter the cycle, the fold where the cycle exists)."""
        while True:
            todo = [p for p in self.stiffest_per_stroke() if not p.folded]
            if not todo:
                return
            self.fold(todo)

    # ---- the search

    def run(self) -> None:
        lo, hi = self.envelope
        s0 = min(max(self.base.isolator.stroke, lo), hi)
        s_lo, s_hi = max(lo, s0 / STROKE_SPAN), min(hi, s0 * STROKE_SPAN)
        self.say(f"building guides and judging the stage for strokes {quantity(s_lo, 'm')} to "
                 f"{quantity(s_hi, 'm')} at {quantity(self.fc, 'Hz', 4)} ...")
        self.stroke_row(list(np.geomspace(s_lo, s_hi, STROKES)))
        self.confirm()
        for _ in range(WIDEN_ROUNDS):
            b = self.best()
            if b is None:
                break
            done = sorted({p.stroke for p in self.points})
            if b.stroke == done[0] and done[0] > lo * (1 + 1e-9):
                new = [max(lo, done[0] / 1.8), max(lo, done[0] / 1.8 ** 2)]
            elif b.stroke == done[-1] and done[-1] < hi * (1 - 1e-9):
                new = [min(hi, done[-1] * 1.8), min(hi, done[-1] * 1.8 ** 2)]
            else:
                break
            new = [s for s in dict.fromkeys(new) if s not in done]
            self.say(f"the best design lies on the edge of the strokes: widening to "
                     f"{', '.join(quantity(s, 'm') for s in new)} ...")
            self.stroke_row(new)
            self.confirm()
        self.refine()

    def refine(self) -> None:
        """Bisect the stiffness at the best stroke towards the next stiffer point."""
        b = self.best()
        if b is None:
            return
        row = sorted((p for p in self.points if p.stroke == b.stroke), key=lambda p: p.target)
        stiffer = [p for p in row if p.target > b.target]
        if not stiffer:
            return
        lo, hi = math.log(b.target), math.log(stiffer[0].target)
        for _ in range(REFINE_STEPS):
            mid = 0.5 * (lo + hi)
            p = self.build(b.stroke, math.exp(mid))
            self.judge([p])
            if p.status is None:
                self.fold([p])
            if p.status is None:
                lo = mid
            else:
                hi = mid

    # ---- the sign-off

    def sign_off(self, p: _Point) -> tuple[bool, Any]:
        """The guide at full resolution, the loop with its reserve, the reserve corners, the
        design command's verdict. Returns (passed, (guide, corners, design result))."""
        from ..guideline.evaluate import evaluate as design

        fx = _c.guide_for(self.base_model, p.stiffness, p.stroke, self.fc, points=FULL_POINTS)
        if fx.feasible and abs(fx.drive_stiffness / p.stiffness - 1.0) < 0.02:
            p.candidate = Candidate(stroke=p.stroke, length=fx.length, width=fx.width,
                                    thickness=fx.thickness, stiffness=fx.drive_stiffness,
                                    crossover=self.fc, damping=p.candidate.damping)
            p.model = None  # the guide at full resolution is another candidate
            p.lowest_mode = fx.lowest_mode.frequency
            p.thickest = _c.thickest_stiffness(fx)
            p.guide = fx
        else:  # the candidate's own guide (one sized again for the stiffness it reached differs)
            fx = p.guide
        model = self.candidate_model(p)
        ok, why = _c.loop_meets(model)
        if not ok:
            p.status = "margins"
            p.violations.append(why)
            return False, (fx, None, None)
        self.say(f"checking the reserves of {quantity(p.stroke, 'm')}, "
                 f"{quantity(p.stiffness, 'N/m', 4)} ...")
        corners = _c.reserve_corners(model)
        self.evaluations += len(corners)
        bad = [c for c in corners if not c["passed"]]
        if bad:
            p.status = "reserve"
            p.violations += [f"with {c['name']}: {c['why']}" for c in bad]
            return False, (fx, corners, None)
        self.say(f"signing off {quantity(p.stroke, 'm')}, {quantity(p.stiffness, 'N/m', 4)} at "
                 f"{quantity(self.fc, 'Hz', 4)} (scatter included) ...")
        r = design(model, executor=self.executor)
        rob = r.robustness
        p.p = None if rob is None else rob.hunting_probability
        self.evaluations += 0 if rob is None else rob.samples
        land = r.simulation.landing if r.simulation is not None else None
        if land is not None:
            p.clearance = land.clearance(0.0 if fx is None else fx.sag)
        if r.verdict.status == "FAIL":
            fails = [x for x in r.verdict.reasons if x.severity == "FAIL"]
            p.status = "robustness" if fails and fails[0].source == "robustness" else "checks"
            p.violations += [x.text for x in fails]
            return False, (fx, corners, r)
        p.status = "feasible"
        return True, (fx, corners, r)


def recommend(spec: _spec.Spec | Model | str | Any, *, executor: Any = None,
              progress: Callable[[str], None] | None = None,
              cache: Any = None) -> RecommendResult:
    """Search a buildable isolator (and the rule's crossover) that the sign-off passes.

    Parameters
    ----------
    spec : Spec, Model, path or mapping
        The design spec (a YAML path or mapping is loaded), or its resolved
        model; without an isolator the search is for one to add, without a
        flexure section for a steel leaf-spring guide. The spec is resolved
        once here; every candidate is a variation of it
        (:meth:`~fi_design.model.Model.varied`), resolved once and read by
        every judgement.
    executor : concurrent.futures-style executor, optional
        Runs the stage-level evaluations and the robustness samples; None
        runs them here. The library creates no pool.
    progress : callable, optional
        ``progress(text)`` as the search proceeds.
    cache : bool, path or fi_design.recommend.stored.SearchStore, optional
        Where searches are kept (:mod:`fi_design.recommend.stored`): a search
        of the same spec by the same code is read back instead of run again
        (its result's ``from_cache`` says so), a search run is stored. None or
        False (default): none; True: the user cache folder
        (``$FI_DESIGN_CACHE_DIR/recommend`` when the variable is set); a path:
        that folder. The executor and ``progress`` do not change the result,
        so they are not part of its key.

    Returns
    -------
    RecommendResult
        The stiffest joint that keeps ``requirements.hunting_margin`` with its
        reserves and passes the sign-off, its guide, what binds it, the least
        change of the spec that passes, and the trade-off; or the nearest
        design and what it violates.

    Raises
    ------
    ArgumentError
        ``spec`` is not a spec, a model, a path or a mapping, or a model
        varied with :meth:`~fi_design.model.Model.at` (the search varies its
        spec); ``executor`` is no executor; ``cache`` is none of the above
        (a file's path, not a folder).
    SpecError
        A path or mapping that does not validate.
    """
    from ..execution import check_executor
    from ..model import as_model
    from ..spec.file import as_spec
    from .stored import open_store

    start = _time.perf_counter()
    check_executor(executor)
    store = open_store(cache)
    model = as_model(spec if isinstance(spec, Model) else as_spec(spec, model=True))  # once
    if model.departures:
        from ..errors import ArgumentError

        raise ArgumentError(f"this model differs from its spec at {', '.join(model.departures)} "
                            "(Model.at), but the search varies the spec: recommend for the "
                            "spec with the values written in (Model.varied)")
    say = progress or (lambda text: None)
    if store is not None:
        found = store.get(model.spec)
        if found is not None:
            say(f"the design search: from the cache ({store.directory})")
            log.info("recommendation for %r read from %s", model.spec.name, found.from_cache)
            return found
    result = _searched(model, executor, say, start)
    if store is not None:
        store.put(model.spec, result)
    return result


def _searched(model: Model, executor: Any, say: Callable[[str], None],
              start: float) -> RecommendResult:
    """The search itself on a resolved model (:func:`recommend` without the cache); ``start``
    is when the call began (:func:`time.perf_counter`), for its wall time."""
    from ..loop.achievable import achievable_crossover

    spec = model.spec
    srch = _Search(model, executor, say)
    aside = _least_aside(srch, executor, say)
    srch.run()
    chosen, signed = None, (None, None, None)
    for p in sorted((p for p in srch.points if p.status is None), key=_o.order, reverse=True):
        srch.fold([p])
        if p.status is not None:
            continue
        passed, out = srch.sign_off(p)
        if passed:
            chosen, signed = p, out
            break
    feasible = chosen is not None
    if not feasible:
        chosen = _o.nearest(srch.points)
    for p in srch.points:
        if p.status is None:
            p.status = "not_evaluated"
    fx, corners, report = signed
    if fx is None and chosen.candidate is not None:
        fx = chosen.guide  # the leaves the nearest design holds
    bounds = _c.guide_bounds(srch.base_model, fx) if fx is not None else ()
    st = report.simulation.stage["isolated"] if report is not None else None
    rob = report.robustness if report is not None else None
    binding = _o.binding(srch, chosen) if feasible else ()
    least = _least_collected(aside, srch, executor, say)
    achievable = achievable_crossover(srch.base_model).frequency
    kmax = _spec.stiffness_limit(srch.base, chosen.stroke)
    margins = {"hunting_margin": chosen.margin, "stiffness_factor": kmax / chosen.stiffness,
               "end_stop_clearance": chosen.clearance,
               "achievable_factor": (achievable / srch.fc if achievable else None)}
    spec_design = {"stroke": srch.base.isolator.stroke,
                   "stiffness": _spec.drive_stiffness(srch.base),
                   "crossover": _spec.design_crossover(srch.base),
                   "suggested": spec.isolator is None}
    advice = _o.advice(srch, chosen, feasible, binding, least, bounds)
    log.info("recommendation for %r: feasible %s, %d evaluations", spec.name, feasible,
             srch.evaluations)
    return RecommendResult(
        spec=spec, feasible=feasible, design=chosen.result(), binding=binding,
        violates=() if feasible else tuple(chosen.violations), advice=advice, flexure=fx,
        least_change=least, stage_hunting=st, robustness=rob,
        reserves=tuple(corners or ()),
        forces=None if report is None or report.simulation is None else report.simulation.forces,
        margins=margins,
        pareto=_o.pareto(srch.points),
        strokes=tuple(sorted({p.stroke for p in srch.points})),
        stiffnesses=tuple(sorted({p.target for p in srch.points})),
        candidates=tuple(p.result() for p in srch.points), spec_design=spec_design,
        crossover_limit=srch.fc_why, assumptions=srch.assumed, rule=srch.rule,
        evaluations=srch.evaluations, wall_time=_time.perf_counter() - start, notch=srch.notch,
        flexure_bounds=bounds)


def _least_aside(srch: _Search, executor: Any, say: Callable[[str], None]) -> Any:
    """The least change of the spec started as one task on the executor, beside the search:
    it reads the spec's model, the crossover cap, the margin and the stroke envelope, none of
    the search's points, so the two share the cores. None without an executor or an isolator
    (it then runs after the search)."""
    from .least import Scope, least_change_task

    if executor is None or srch.spec.isolator is None:
        return None
    say("the least change of the spec: on a worker, beside the search ...")
    return executor.submit(least_change_task,
                           Scope(srch.model, srch.margin, srch.rule, srch.fc, srch.fc_why,
                                 srch.envelope))


def _least_collected(aside: Any, srch: _Search, executor: Any,
                     say: Callable[[str], None]) -> Any:
    """The least change: the task's result (its evaluations counted into the search's), or
    computed here when it was not started aside."""
    from .least import least_change

    if aside is None:
        return least_change(srch, executor=executor, progress=say)
    if not aside.done():
        say("waiting for the least change of the spec ...")
    found, evaluations = aside.result()
    srch.evaluations += evaluations
    return found
