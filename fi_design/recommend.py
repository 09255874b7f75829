"""A recommendation the tool itself would sign off: search the design space, say what binds.

The guideline's steps bound the design (k_max = Fs / stroke, the parasitic
limit on the crossover); the user's question is what to build. This module
searches the isolator's stroke and drive stiffness and, for a spec tuned by
the rule, the controller crossover, for the design with the most margin that
meets every constraint the sign-off checks:

- no move of the family ends in a hunting cycle at the crossover
  (:mod:`fi_design.stage`), nominally and under the spec's friction scatter
  (``requirements.robustness``: the sample fraction that does not settle
  within the limit);
- all four linear limit cases meet the margins with the parasitic modes;
- k <= k_max; a flexure the spec sizes (``isolator.flexure``) can be built
  from stock (stress, leaf and support frequencies), and its stock thickness
  sets the stiffness the design is judged with;
- the bounds of ``requirements.recommend``.

The objective, in this order: the crossover factor (crossover over the
stage-level hunting-free crossover, the fold of the cycle), then the
robustness, then the lowest stiffness (the paper: as low as possible).

The search: the crossover is the highest the linear margins allow (it only
raises the factor; with explicit gains it stays). Over a stroke x stiffness
grid (log-spaced, the map of the result), the cheap constraints (k_max,
flexure, margins) go first; the points left are judged at the stage level
(one move family each, on the caller's executor); the hunting-free crossover
is found only for the points that do not hunt, and the robustness only for the
best of them, in the order of the objective, until one passes. The stiffness of
the point that passes is then refined between its neighbours on the map, at its
stroke: rounds of four log-spaced points (each judged like the map's, with its
fold), the best that the sign-off passes kept, the interval narrowed around it.
What excludes the neighbours of the chosen point on the map is what binds it.
"""

from __future__ import annotations

import logging
import math
import time as _time
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from . import spec as _spec
from .display import quantity
from .errors import ArgumentError
from .results.recommend import DesignCandidate, RecommendResult
from .specfile import with_values

log = logging.getLogger(__name__)

__all__ = ["recommend", "recommended_values", "recommended_spec_text", "GRID"]

#: Points of the design-space map: strokes x stiffnesses.
GRID = (6, 6)
#: Default stroke range around the spec's stroke: this factor either way [-].
STROKE_SPAN = 3.0
#: Strokes searched without an isolator in the spec [m].
BARE_STROKES = (1e-4, 1e-3)
#: Lowest stiffness searched, as a fraction of the smallest k_max [-].
STIFFNESS_SPAN = 1.0 / 30.0
#: Crossover factors are compared to this many decimals (the fold's bisection resolution,
#: 0.1 %, makes closer factors equal) [-].
FACTOR_DIGITS = 3
#: Refinement of the stiffness around the best point of the map: rounds, points per round.
REFINE_ROUNDS = 2
REFINE_POINTS = 4
#: Strokes tried with the flexure's stock when the target stiffness rounds [-].
_FLEX_TOL = 1e-9


def _damping_ratio(spec: _spec.Spec) -> float | None:
    """The joint damping ratio the spec gives (None: the default ratio applies)."""
    iso = spec.isolator
    if iso is None or iso.damping is None:
        return None
    k = _spec.drive_stiffness(spec)
    m1, m2 = spec.stage.mass, spec.cart.mass
    return iso.damping / (2.0 * math.sqrt(k * m1 * m2 / (m1 + m2)))


def _base(spec: _spec.Spec) -> _spec.Spec:
    """The spec with an isolator: its own, or the guideline's suggestion added."""
    if spec.isolator is not None:
        return spec
    from .guideline import suggested_isolator

    s, k = suggested_isolator(spec)
    return with_values(spec, {"isolator": {"stroke": s, "stiffness": k}})


def _axes(spec: _spec.Spec, base: _spec.Spec, grid: tuple[int, int]) \
        -> tuple[np.ndarray, np.ndarray]:
    """Stroke [m] and stiffness [N/m] axes of the map."""
    b = spec.requirements.recommend
    ns, nk = grid
    if b.stroke is not None:
        s_lo, s_hi = b.stroke
    elif spec.isolator is not None:
        s0 = spec.isolator.stroke
        s_lo, s_hi = s0 / STROKE_SPAN, s0 * STROKE_SPAN
    else:
        s_lo, s_hi = BARE_STROKES
    strokes = np.geomspace(s_lo, s_hi, ns) if s_hi > s_lo else np.array([s_lo])
    kmax = [_spec.stiffness_limit(base, s) for s in strokes]
    if b.stiffness is not None:
        k_lo, k_hi = b.stiffness
    else:
        k_lo, k_hi = min(kmax) * STIFFNESS_SPAN, max(kmax)
    stiff = np.geomspace(k_lo, k_hi, nk) if k_hi > k_lo else np.array([k_lo])
    return strokes, stiff


def _candidate_spec(base: _spec.Spec, stroke: float, stiffness: float, damping: float | None,
                    crossover: float | None) -> _spec.Spec:
    values: dict[str, Any] = {"isolator.stroke": stroke, "isolator.stiffness": stiffness}
    if damping is not None:
        values["isolator.damping"] = damping
    if crossover is not None:
        values["controller.crossover"] = crossover
    return with_values(base, values)


def _values(stroke, stiffness, damping, crossover) -> tuple:
    vals = [("isolator.stroke", float(stroke)), ("isolator.stiffness", float(stiffness))]
    if damping is not None:
        vals.append(("isolator.damping", float(damping)))
    if crossover is not None:
        vals.append(("controller.crossover", float(crossover)))
    return tuple(vals)


def _stage_answer(spec: _spec.Spec) -> Any:
    """The stage-level answer of an isolated candidate with its hunting-free crossover
    (a task for the executor)."""
    from .stage import stage_hunting

    return stage_hunting(spec, True, trace=False)


def recommend(spec: _spec.Spec, *, executor: Any = None,
              progress: Callable[[str], None] | None = None,
              grid: tuple[int, int] = GRID) -> RecommendResult:
    """Search the isolator (and the rule's crossover) for a design the sign-off passes.

    Parameters
    ----------
    spec : Spec
        The design spec; without an isolator the search is for one to add.
    executor : concurrent.futures-style executor, optional
        Runs the stage-level evaluations and the robustness samples (``submit``
        with futures having ``result`` and ``add_done_callback``); None runs
        them here. The library creates no pool.
    progress : callable, optional
        ``progress(text)`` as the search proceeds.
    grid : (int, int), optional
        Strokes x stiffnesses of the design-space map (default :data:`GRID`).

    Returns
    -------
    RecommendResult
        ``feasible`` with the design of most margin and what binds it, or the
        nearest design, what it violates and what would open the space.

    Raises
    ------
    ArgumentError
        A grid of fewer than one point per axis.
    """
    from . import linear
    from .guideline import step2_crossover
    from .studies.points import STAGE_FIRST, evaluate

    if min(grid) < 1:
        raise ArgumentError(f"grid needs at least one point per axis, got {grid}")
    start = _time.perf_counter()
    say = progress or (lambda text: None)
    base = _base(spec)
    rule = spec.controller.gains is None
    zeta = _damping_ratio(base)
    m1, m2 = base.stage.mass, base.cart.mass
    mred = m1 * m2 / (m1 + m2)
    strokes, stiffs = _axes(spec, base, grid)
    bounds = spec.requirements.recommend
    fc_design = _spec.design_crossover(base)
    xo = step2_crossover(base)

    # ------------------------------------------------------------ the crossover of a stiffness
    limits: dict[float, tuple[float | None, str]] = {}

    def crossover_for(k: float) -> tuple[float | None, str]:
        """The highest crossover the margins allow with stiffness k, and why [Hz]."""
        if not rule:
            return fc_design, "explicit gains: the crossover stays"
        if k in limits:
            return limits[k]
        if xo.limit_kind == "scan_limit":
            # no limit below the search cap is no licence to raise the crossover to it
            return fc_design, (f"kept at the desired {fc_design:.4g} Hz: the linear model sets no "
                               "limit (give the hardware's sampling, delay and parasitic modes)")
        top = bounds.crossover[1] if bounds.crossover is not None else math.inf
        probe = with_values(base, {"isolator.stiffness": k})
        if xo.achievable is not None and _meets_margins(probe, min(xo.achievable, top)):
            fc, why = (min(xo.achievable, top),
                       xo.limited_by if xo.achievable <= top else
                       "the bound requirements.recommend.crossover")
        else:
            ach = linear.achievable_crossover(probe)
            if ach.frequency is None:
                limits[k] = (None, ach.limited_by)
                return limits[k]
            fc, why = ((ach.frequency, ach.limited_by) if ach.frequency <= top
                       else (top, "the bound requirements.recommend.crossover"))
        if bounds.crossover is not None and fc < bounds.crossover[0]:
            limits[k] = (None, f"the margins allow at most {fc:.4g} Hz, below "
                               f"requirements.recommend.crossover")
            return limits[k]
        limits[k] = (fc, why)
        return limits[k]

    # ------------------------------------------------------------ the map, cheap constraints
    def screen(s: float, k: float) -> dict:
        """A design point with the cheap constraints checked (status None: they pass)."""
        kmax = _spec.stiffness_limit(base, s)
        cell = {"stroke": s, "nominal": k, "stiffness": k, "damping": None,
                "crossover": fc_design, "status": None, "violations": []}
        if k > kmax * (1 + 1e-9):
            cell["status"] = "k_max"
            cell["violations"].append(f"k = {k:.4g} N/m exceeds k_max = Fs / stroke = "
                                      f"{kmax:.4g} N/m")
            return cell
        if bounds.stiffness is not None and not bounds.stiffness[0] <= k <= \
                bounds.stiffness[1] * (1 + 1e-9):
            cell["status"] = "bounds"
            cell["violations"].append("outside requirements.recommend.stiffness")
            return cell
        fc, why = crossover_for(k)
        if fc is None:
            cell["status"] = "margins"
            cell["violations"].append(why)
            return cell
        cell["crossover"] = fc
        cell["limit"] = why
        kk = k
        if base.isolator.flexure is not None:
            fx = _flexure(base, s, k, kmax, fc)
            if not fx.feasible:
                cell["status"] = "flexure"
                cell["violations"].append(f"the flexure: {fx.reason}")
                return cell
            kk = float(fx.drive_stiffness)
        cell["stiffness"] = kk
        if zeta is not None:
            cell["damping"] = 2.0 * zeta * math.sqrt(kk * mred)
        probe = _candidate_spec(base, s, kk, cell["damping"], fc if rule else None)
        if not _meets_margins(probe, fc):
            cell["status"] = "margins"
            cell["violations"].append(f"a limit case misses its margins at {fc:.4g} Hz")
        return cell

    say("screening the design space: stiffness limit, flexure, loop margins ...")
    cells = [screen(float(s), float(k)) for s in strokes for k in stiffs]
    todo = [c for c in cells if c["status"] is None]

    # ------------------------------------------------------------ the stage at the crossover
    say(f"simulating every move of the family at {len(todo)} design points ...")
    tasks = [(_values(c["stroke"], c["stiffness"], c["damping"], c["crossover"] if rule else None),
              True) for c in todo]
    ev = evaluate(base, tasks, executor=executor, measure=STAGE_FIRST)
    evaluations = len(tasks)
    for c, out in zip(todo, ev.outcomes):
        if out["status"] != "ok":
            c["status"] = "failed"
            c["violations"].append(out["message"])
        elif out["verdict"] != "settled":
            c["status"] = "hunts"
            c["violations"].append(f"at {c['crossover']:.4g} Hz {out['message']}")
    quiet = [c for c in todo if c["status"] is None]

    # ------------------------------------------------------------ the hunting-free crossover
    def judge(points: list[dict]) -> int:
        """The stage-level answer with its fold and the landing of points that do not hunt;
        the stage-level evaluations it took."""
        specs = [_candidate_spec(base, c["stroke"], c["stiffness"], c["damping"],
                                 c["crossover"] if rule else None) for c in points]
        n = 0
        for c, st, cs in zip(points, _map(executor, _stage_answer, specs), specs):
            n += 1 + int((st.boundary or {}).get("tests", 0))
            c["stage"], c["spec"] = st, cs
            c["free_from"] = st.hunting_free_from
            if not st.acceptable:  # a move the first-found screen did not try hunts
                c["status"] = "hunts"
                c["violations"].append(f"at {c['crossover']:.4g} Hz some move hunts")
                continue
            c["factor"] = (c["crossover"] / st.hunting_free_from
                           if st.hunting_free_from else None)
            land = _landing(cs)
            c["clearance"] = land.stroke - abs(land.deflection)
            if land.on_limiter or land.force >= land.static_friction:
                c["status"] = "end_stop"
                c["violations"].append(
                    f"the cart rests with the joint {quantity(land.deflection, 'm', 3)} deflected"
                    + (", on its limiter" if land.on_limiter else "")
                    + f": flexure force {land.force:.3g} N against Fs = "
                      f"{land.static_friction:.3g} N")
        return n

    say(f"finding the hunting-free crossover of {len(quiet)} design points ...")
    evaluations += judge(quiet)

    # ------------------------------------------------------------ the sign-off, best first
    from .guideline import design

    def margin(c: dict) -> tuple:
        """The objective, smaller is better: the crossover factor (to the fold's resolution:
        folds bisected to 0.1 % are equal within it), then the stiffness."""
        return -round(c.get("factor") or 0.0, FACTOR_DIGITS), c["stiffness"]

    def sign_off(c: dict) -> bool:
        """The design command's verdict on a point (robustness included); True: it passes."""
        say(f"signing off the design {c['stroke'] * 1e3:.3g} mm, {c['stiffness']:.4g} N/m, "
            f"{c['crossover']:.4g} Hz (friction scatter included) ...")
        r = design(c["spec"], executor=executor)
        rob = r.robustness
        c["robustness"] = rob
        c["samples"] = 0 if rob is None else rob.samples
        c["p"] = None if rob is None else rob.hunting_probability
        c["stage"] = r.simulation.stage["isolated"]
        if r.verdict.status == "FAIL":
            fails = [x for x in r.verdict.reasons if x.severity == "FAIL"]
            c["status"] = {"robustness": "robustness", "simulation": "hunts",
                           "landing_force": "end_stop"}.get(fails[0].source, "checks")
            c["violations"] += [x.text for x in fails]
            return False
        c["status"] = "feasible"
        return True

    chosen = None
    for c in sorted((c for c in quiet if c["status"] is None), key=margin):
        passed = sign_off(c)
        evaluations += c["samples"]
        if passed:
            chosen = c
            break

    # ------------------------------------------------------------ refined along the stiffness
    grid_chosen = chosen
    if chosen is not None and len(stiffs) > 1:
        ki = cells.index(chosen) % len(stiffs)
        lo = math.log(stiffs[max(ki - 1, 0)])
        hi = math.log(stiffs[min(ki + 1, len(stiffs) - 1)])
        for _ in range(REFINE_ROUNDS):
            say(f"refining the stiffness between {math.exp(lo):.4g} and {math.exp(hi):.4g} N/m "
                "...")
            trial = [screen(chosen["stroke"], float(math.exp(x)))
                     for x in np.linspace(lo, hi, REFINE_POINTS + 2)[1:-1]]
            ok = [c for c in trial if c["status"] is None]
            evaluations += judge(ok)
            for c in sorted((c for c in ok if c["status"] is None
                             and margin(c) < margin(chosen)), key=margin):
                passed = sign_off(c)
                evaluations += c["samples"]
                if passed:
                    chosen = c
                    break
            step = (hi - lo) / (REFINE_POINTS + 1)
            at = math.log(chosen["nominal"])
            lo, hi = max(lo, at - step), min(hi, at + step)

    for c in cells:
        if c["status"] is None:
            c["status"] = "not_evaluated"

    # ------------------------------------------------------------ the answer
    feasible = chosen is not None
    if not feasible:
        chosen = _nearest(cells)
    rob = chosen.get("robustness")
    land = chosen.get("clearance")
    cands = tuple(_to_candidate(c) for c in cells)
    best = _to_candidate(chosen)
    binding = _binding(cells, grid_chosen, strokes, stiffs, rule, bounds) if feasible else ()
    st = chosen.get("stage")
    margins = {"crossover_factor": chosen.get("factor"),
               "stiffness_factor": _spec.stiffness_limit(base, chosen["stroke"])
               / chosen["stiffness"],
               "end_stop_clearance": land}
    spec_design = {"stroke": base.isolator.stroke, "stiffness": _spec.drive_stiffness(base),
                   "crossover": fc_design, "suggested": spec.isolator is None}
    advice = _advice(feasible, chosen, cells, base, xo, rule, binding)
    log.info("recommendation for %r: feasible %s, %d evaluations", spec.name, feasible,
             evaluations)
    return RecommendResult(
        spec=spec, feasible=feasible, design=best, binding=binding,
        violates=() if feasible else tuple(chosen["violations"]), advice=advice,
        stage_hunting=st, robustness=rob, margins=margins,
        strokes=tuple(float(s) for s in strokes), stiffnesses=tuple(float(k) for k in stiffs),
        candidates=cands, spec_design=spec_design, rule=rule, evaluations=evaluations,
        wall_time=_time.perf_counter() - start)


# --------------------------------------------------------------------------- pieces


def _meets_margins(spec: _spec.Spec, fc: float) -> bool:
    """Whether every limit case meets its margins (and the modes their separation) at fc."""
    from . import linear
    from .model import resolve

    model = resolve(spec)
    if abs(fc - model.crossover) > 1e-9 * fc:
        model = model.at(crossover=fc)
    res = linear.analyse(model)
    sep = spec.requirements.parasitic_separation
    return all(c.passed for c in res.cases) and all(m.frequency >= sep * fc
                                                     for m in model.modes)


def _flexure(base: _spec.Spec, stroke: float, k: float, kmax: float, fc: float) -> Any:
    from .mechanism.geometry import stage_body
    from .mechanism.sizing import size_guide

    req = base.requirements
    return size_guide(base.isolator.flexure, stage_body(base.stage), target_stiffness=k,
                      maximum_stiffness=kmax, stroke=stroke, cart_mass=base.cart.mass,
                      required_frequency=req.parasitic_separation * fc,
                      required_buckling=req.buckling_factor)


def _map(executor: Any, fn: Callable, items: Sequence) -> list:
    """``fn`` over ``items``, on the executor when there is one (results in order)."""
    if executor is None or len(items) < 2:
        return [fn(x) for x in items]
    futures = [executor.submit(fn, x) for x in items]
    return [f.result() for f in futures]


def _landing(spec: _spec.Spec) -> Any:
    """Where the cart rests after the spec's motion (:func:`fi_design.confirm.landing`)."""
    from .confirm import landing
    from .simulation import simulate

    return landing(spec, simulate(spec, isolated=True))


def _to_candidate(c: dict) -> DesignCandidate:
    return DesignCandidate(
        stroke=c["stroke"], stiffness=c["stiffness"], damping=c["damping"],
        crossover=c["crossover"], status=c["status"], violations=tuple(c["violations"]),
        hunting_free_from=c.get("free_from"), crossover_factor=c.get("factor"),
        unsettled_probability=c.get("p"), end_stop_clearance=c.get("clearance"))


#: How far each status is from feasible (the nearest design has the smallest).
_DISTANCE = {"feasible": 0, "robustness": 1, "end_stop": 2, "checks": 2, "hunts": 2,
             "margins": 3, "flexure": 3, "k_max": 4, "bounds": 5, "failed": 6, "not_evaluated": 7}


def _nearest(cells: list[dict]) -> dict:
    """With none feasible: the point closest to feasible (then most margin, lowest k)."""
    return min(cells, key=lambda c: (_DISTANCE[c["status"]], c.get("p") or 0.0,
                                     -(c.get("factor") or 0.0), c["stiffness"]))


_WORDS = {"robustness": "robustness under friction scatter",
          "end_stop": "the end-stop clearance at rest", "checks": "a check of the sign-off",
          "hunts": "hunting after some move of the family",
          "margins": "a limit case's margins", "flexure": "the flexure's stress or frequencies",
          "k_max": "k_max = Fs / stroke", "bounds": "the bounds of requirements.recommend"}


def _binding(cells, chosen, strokes, stiffs, rule, bounds) -> tuple[str, ...]:
    """What the neighbours of the chosen point violate, and the crossover's limit."""
    ns, nk = len(strokes), len(stiffs)
    i = cells.index(chosen)
    si, ki = divmod(i, nk)
    out: list[str] = []
    for ds, dk in ((0, -1), (0, 1), (-1, 0), (1, 0)):
        a, b = si + ds, ki + dk
        if 0 <= a < ns and 0 <= b < nk:
            word = _WORDS.get(cells[a * nk + b]["status"])
        elif ds:  # the edge of the stroke range: a longer or shorter stroke was not tried
            word = ("the stroke bound of requirements.recommend" if bounds.stroke is not None
                    else "the end of the stroke range searched (requirements.recommend.stroke "
                         "widens it)")
        else:
            word = ("the stiffness bound of requirements.recommend"
                    if bounds.stiffness is not None else
                    "the end of the stiffness range searched (requirements.recommend.stiffness "
                    "widens it)")
        if word and word not in out:
            out.append(word)
    if rule and chosen.get("limit"):
        out.insert(0, f"the crossover: {chosen['limit']}")
    return tuple(out)


def _advice(feasible, chosen, cells, base, xo, rule, binding) -> str:
    """One sentence: what binds the design, or what would open an empty space."""
    fc = chosen["crossover"]
    if feasible:
        k, s = chosen["stiffness"], chosen["stroke"]
        text = (f"Build a {s * 1e3:.3g} mm stroke at k = {k:.4g} N/m"
                + (f" and tune the loop to {fc:.4g} Hz" if rule else "")
                + (f": no move hunts from {chosen['free_from']:.4g} Hz"
                   if chosen.get("free_from") else ": no move of the family hunts"))
        if binding:
            text += f"; it is bound by {binding[0]}"
        return text + "."
    counts: dict[str, int] = {}
    for c in cells:
        counts[c["status"]] = counts.get(c["status"], 0) + 1
    gap = base.friction.static - base.friction.coulomb
    modes = base.isolator.parasitic_modes
    low = min(modes, key=lambda m: m.frequency) if modes else None
    opener = []
    if xo.achievable is not None and rule:
        opener.append(f"a higher achievable crossover than {xo.achievable:.3g} Hz ("
                      + (f"move the parasitic mode '{low.name}' at {low.frequency:.4g} Hz up"
                         if low is not None else f"it is limited by {xo.limited_by}") + ")")
    opener.append("a longer stroke than the search allowed (requirements.recommend.stroke)")
    opener.append(f"less friction gap than Fs - Fc = {gap:.3g} N")
    worst = max((k for k in counts if k not in ("feasible", "not_evaluated")),
                key=lambda k: counts[k], default="hunts")
    return (f"No design of the searched space passes: most points fail on "
            f"{_WORDS.get(worst, worst)}; the nearest ({chosen['stroke'] * 1e3:.3g} mm, "
            f"{chosen['stiffness']:.4g} N/m, {fc:.4g} Hz) fails on "
            f"{_WORDS.get(chosen['status'], chosen['status'])}. What would open the space: "
            + "; or ".join(opener) + ".")


# --------------------------------------------------------------------------- the written spec


def recommended_values(result: RecommendResult) -> dict[str, Any]:
    """The spec values of a recommended design, by dotted path, as the spec file takes them.

    Parameters
    ----------
    result : RecommendResult
        The search.

    Returns
    -------
    dict
        ``isolator.stroke``, ``isolator.stiffness`` (every digit, with units),
        ``isolator.damping`` when the spec gives a damping (its ratio kept),
        and ``controller.crossover`` for a spec tuned by the rule; for a spec
        without isolator the ``isolator`` section as a whole.
    """
    from .specedit import spec_quantity

    d = result.design
    iso = {"stroke": spec_quantity("isolator.stroke", d.stroke),
           "stiffness": spec_quantity("isolator.stiffness", d.stiffness)}
    if d.damping is not None:
        iso["damping"] = spec_quantity("isolator.damping", d.damping)
    values: dict[str, Any] = ({f"isolator.{k}": v for k, v in iso.items()}
                              if result.spec.isolator is not None else {"isolator": iso})
    if result.rule:
        values["controller.crossover"] = spec_quantity("controller.crossover", d.crossover)
    return values


def recommended_spec_text(result: RecommendResult) -> str:
    """YAML text of the input spec with the recommended design written in.

    The input's text is edited (comments and layout kept,
    :func:`fi_design.specedit.edited_spec_text`) and read back; the design
    command on it runs the same computation that signed the design off.

    Parameters
    ----------
    result : RecommendResult
        A feasible search (the nearest design of an infeasible one is not
        written: it does not pass).

    Returns
    -------
    str

    Raises
    ------
    ArgumentError
        The search found no design that passes.
    """
    from .specedit import edited_spec_text

    if not result.feasible:
        raise ArgumentError("no design of the searched space passes: there is no "
                            "recommendation to write (the nearest one fails the sign-off)")
    header = ["isolator and crossover written by fi-design recommend: the design of most "
              "margin that the sign-off passes;",
              f"{result.advice}"]
    comments = {path: "recommended" for path in recommended_values(result)}
    return edited_spec_text(result.spec, recommended_values(result), comments=comments,
                            header=header, source="<spec with the recommended design>")
