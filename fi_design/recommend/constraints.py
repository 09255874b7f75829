"""What a recommended design must meet: a buildable guide, the loop's reserves, the stage's answer.

Each function judges one thing and says why in words:

- :func:`crossover_cap` -- how high the loop may be tuned: the reserve's
  fraction of the achievable crossover of the spec's own loop (its drive,
  sampling, delay and the stage structure's measured modes) with the margins
  plus their reserve; never raised where the linear model sets no limit;
- :func:`guide_for` -- a guide from stock for a net drive stiffness and
  stroke (stress, buckling, every parasitic mode at the separation times the
  crossover), its stiffness within k_max over the whole thickness tolerance
  of its stock;
- :func:`loop_meets` -- the candidate's four limit cases, its own modes in,
  meet the margins plus their reserve at the crossover;
- :func:`stage_answer` -- the stage after every move of its family at the
  crossover, with the fold of its cycle (a task for the executor);
- :func:`reserve_corners` -- the candidate still passes (margins met, no move
  hunting) with the masses, the stiffness, the computed modes and the delay
  off by the reserve's fractions.

Every judgement takes the candidate as a :class:`~fi_design.model.Model`,
resolved once by the search (:meth:`~fi_design.model.Model.varied` of the
base model) and read by all of them.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

from .. import spec as _spec
from ..display import number, percent, quantity
from ..model import Model
from ..spec.file import with_values

__all__ = ["SEARCH_POINTS", "TOP", "reserve_values", "reserve_requirements", "crossover_cap",
           "notched_model", "notch_entries", "guide_for", "thickest_stiffness",
           "guide_bounds", "loop_meets", "stage_answer", "longer_delay",
           "margin_screen", "reserve_corners", "hunting_margin"]

#: Lengths of the guide's sizing grid during the search (the chosen design is sized again at
#: full resolution).
SEARCH_POINTS = 41
#: The stiffest target of the search and of the least change, a fraction of k_max [-]: a
#: drawing's rounding stays within k_max.
TOP = 0.99
#: Sizings of a guide at most: the first at the target, the others at a target lowered until
#: the stock's thickest leaves stay within k_max (:func:`guide_for`).
TOLERANCE_SIZINGS = 4


def reserve_values(spec: _spec.Spec) -> dict[str, float]:
    """The margin requirements raised by ``requirements.reserve``, as values at spec paths."""
    req = spec.requirements
    r = req.reserve
    return {"requirements.phase_margin": req.phase_margin + r.phase_margin,
            "requirements.gain_margin": req.gain_margin + r.gain_margin}


def reserve_requirements(model: Model) -> _spec.Requirements:
    """The model's requirements with the margins raised by ``requirements.reserve``.

    Validated as the spec validates them (:func:`fi_design.spec.file.with_values`); the
    model itself is not resolved again: the margins judge a loop, they do not shape it.
    """
    return with_values(model.spec, reserve_values(model.spec)).requirements


def crossover_cap(base: Model, rule: bool) -> tuple[float, str, Any]:
    """The crossover the recommendation tunes to [Hz], why, and the notch it adds.

    The loop's limit is the hardware's: the spec's drive (sampling, delay),
    its stage and its measured modes, without the flexure guide the search
    replaces (each candidate's own guide must then keep its modes at the
    separation times this crossover). Where that loop sets no limit below the
    search cap, the desired crossover is kept. With
    ``requirements.recommend.filters``, a parasitic mode that limits that loop
    gets a notch in the drive's chain (:func:`fi_design.loop.notch.with_notch`)
    where the notch lifts the achievable crossover.

    Parameters
    ----------
    base : Model
        The spec as written (its own isolator, or none), resolved.
    rule : bool
        Whether the spec tunes by the rule (with explicit gains the crossover
        stays the gains').

    Returns
    -------
    (float, str, Filter or None)
        The crossover [Hz], why, and the notch added to the chain (None: none).
    """
    from ..loop.achievable import achievable_crossover
    from ..loop.notch import limiting_mode, notched
    from ..loop.notch import with_notch as notch_for

    fc = _spec.design_crossover(base.spec)
    if not rule:
        return fc, "the hardware's gains: the crossover stays theirs", None
    bounds = base.requirements.recommend.crossover
    reserve = base.requirements.reserve.crossover
    values: dict[str, Any] = {}
    if base.flexure_spec is not None:
        values["isolator.flexure"] = None
    model = base.varied({**values, **reserve_values(base.spec)})
    ach = achievable_crossover(model)
    notch = None
    mode = limiting_mode(model, ach) if (base.requirements.recommend.filters
                                        and ach.frequency is not None
                                        and ach.kind != "scan_limit") else None
    if mode is not None and not notched(model, mode):
        filt, alt = notch_for(model, mode)
        if alt.frequency is not None and alt.frequency > ach.frequency:
            notch, ach = filt, alt
    if ach.frequency is None:
        return fc, (f"no crossover meets the margins with their reserve ({ach.limited_by}): "
                    "the desired one is kept"), None
    if ach.kind == "scan_limit":
        cap, why = fc, (f"kept at the desired {quantity(fc, 'Hz', 4)}: the linear model sets no "
                        "limit below its search cap (give the hardware's sampling, delay and "
                        "measured modes to let the search raise it)")
    else:
        cap = reserve * ach.frequency
        why = (f"{number(reserve, 6)} x the achievable {quantity(ach.frequency, 'Hz', 4)} with the "
               f"margins' reserve, which is limited by {ach.limited_by}")
        if notch is not None:
            why += f" (with the {notch.describe()} the search adds, requirements.recommend.filters)"
    if bounds is not None:
        if cap > bounds[1]:
            cap, why = bounds[1], "the upper bound of requirements.recommend.crossover"
        elif cap < bounds[0]:
            why += f"; below requirements.recommend.crossover ({quantity(bounds[0], 'Hz', 4)})"
    return float(cap), why, notch


def notched_model(model: Model, notch: Any) -> Model:
    """The model with a notch appended to ``controller.filters`` (its spec holding it)."""
    return model.varied({"controller.filters": notch_entries(model.spec, notch)})


def notch_entries(spec: _spec.Spec, notch: Any) -> list[dict]:
    """``controller.filters`` as the spec file takes it, with a notch appended."""
    own = [f.model_dump(mode="json", exclude_none=True) for f in spec.controller.filters]
    return own + [notch.spec_entry()]


def guide_for(base: Model, stiffness: float, stroke: float, crossover: float, *,
              points: int = SEARCH_POINTS) -> Any:
    """A leaf-spring guide from stock for a net drive stiffness and stroke.

    The stock's thickness tolerance +-dt moves the drive stiffness with t^3:
    where the thickest leaves the stock may deliver (t + dt) would pass
    k_max = Fs / stroke, the guide is sized again for a target lowered by that
    excess (up to :data:`TOLERANCE_SIZINGS` sizings in all), so that every leaf
    of the order keeps the drive within k_max. The guide's drive stiffness may
    then lie below ``stiffness``; the search reads it from the result.

    Parameters
    ----------
    base : Model
        The search's base (its ``isolator.flexure`` bounds, stage and cart).
    stiffness : float
        Net drive stiffness [N/m].
    stroke : float
        One-sided stroke [m].
    crossover : float
        The controller's crossover [Hz]; the guide's modes are held at the separation
        times the loop's crossover there (:attr:`fi_design.model.Model.sizing_crossover`).
    points : int, optional
        Lengths of the sizing grid.

    Returns
    -------
    fi_design.results.steps.FlexureResult
        Sized within the base's flexure bounds: k_max (over the stock's
        thickness tolerance), the stress, the buckling factor and every
        parasitic mode at the separation times the loop's crossover.
    """
    kmax = _spec.stiffness_limit(base.spec, stroke)
    target = float(stiffness)
    fx = _sized(base, target, stroke, crossover, points)
    for _ in range(TOLERANCE_SIZINGS - 1):
        high = thickest_stiffness(fx)
        if high is None or high <= kmax * (1.0 + 1e-9):
            return fx
        # the elastic part goes with t^3, gravity's does not: k(t + dt) = a k + b with
        # a = (k(t + dt) - kg) / (k - kg) and b = kg (1 - a); the net stiffness whose thick
        # end is k_max at this thickness, a hair below (the next sizing's rounding)
        k, kg = fx.mechanics.net_drive_stiffness, fx.mechanics.gravity.geometric_stiffness
        a = (high - kg) / (k - kg)
        target *= (kmax - kg * (1.0 - a)) / a / k * (1.0 - 1e-6)
        fx = _sized(base, target, stroke, crossover, points)
    high = thickest_stiffness(fx)
    if high is not None and high > kmax * (1.0 + 1e-9):
        thick = quantity(fx.thickness + fx.thickness_tolerance, "m", 3, shown=("mm", 1e3))
        return replace(fx, feasible=False, reason=(
            f"stiffness over the thickness tolerance: after {TOLERANCE_SIZINGS} sizings the "
            f"stock's thickest leaves ({thick}) still give {quantity(high, 'N/m', 4)}, above "
            f"k_max = {quantity(kmax, 'N/m', 4)}"))
    return fx


def _sized(base: Model, stiffness: float, stroke: float, crossover: float,
           points: int) -> Any:
    """:func:`~fi_design.mechanism.sizing.size_guide` for the search's base at a target."""
    from ..mechanism.sizing import size_guide

    req = base.requirements
    return size_guide(base.flexure_spec, base.body, target_stiffness=stiffness,
                      maximum_stiffness=_spec.stiffness_limit(base.spec, stroke), stroke=stroke,
                      required_frequency=req.parasitic_separation
                      * _loop_at(base, stiffness, stroke, crossover).sizing_crossover,
                      required_buckling=req.buckling_factor, cart_mass=base.m2,
                      stop_stiffness=base.limiter.stiffness, points=points)


def thickest_stiffness(fx: Any) -> float | None:
    """The net drive stiffness of a feasible guide with its stock's thickest leaves (t + dt)
    [N/m]; None for no guide or no tolerance."""
    if not fx.feasible or not fx.stiffness_range:
        return None
    return float(fx.stiffness_range[1])


def _loop_at(base: Model, stiffness: float, stroke: float, crossover: float) -> Model:
    """The base at a candidate's joint and crossover, its damping as the search gives a
    candidate's: the spec's damping ratio kept where the spec gives a damping (else the
    default ratio, which :meth:`~fi_design.model.Model.at` keeps itself)."""
    iso = base.spec.isolator
    c = None
    if iso is not None and iso.damping is not None:
        m1, m2 = base.m1, base.m2
        c = 2.0 * base.joint_damping_ratio * math.sqrt(stiffness * m1 * m2 / (m1 + m2))
    return base.at(stiffness=stiffness, stroke=stroke, crossover=crossover, damping=c)


def guide_bounds(base: Model, fx: Any) -> tuple:
    """The sized guide's leaf dimensions on a bound of the base's flexure, each with its note.

    Parameters
    ----------
    base : Model
        The search's base (its ``isolator.flexure`` bounds, stage, cart and end stop).
    fx : fi_design.results.steps.FlexureResult
        The guide :func:`guide_for` sized.

    Returns
    -------
    tuple of fi_design.results.steps.BoundNote
        (:func:`fi_design.mechanism.bounds.bound_notes`.)
    """
    from ..mechanism.bounds import bound_notes

    return bound_notes(fx, base.flexure_spec, base.body, cart_mass=base.m2,
                       stop_stiffness=base.limiter.stiffness)


def loop_meets(model: Model) -> tuple[bool, str]:
    """Whether the model's four limit cases meet the margins plus their reserve, and why not.

    The model's own modes (a candidate: its guide's computed ones and the
    structure's measured ones) are in the loop; every mode lies at the
    separation times the loop's crossover (the highest 0 dB crossing of the
    cases in the band, as step 2 and step 3 judge them; the controller's
    crossover when no case crosses there).
    """
    from ..loop import linear

    res = linear.analyse(model, requirements=reserve_requirements(model))
    bad = [c for c in res.cases if not c.passed]
    if bad:
        c = bad[0]
        return False, (f"case {linear.CASE_NUMBERS[c.name]} ({c.description}) misses its "
                       f"{', '.join(c.failed)} with the reserve")
    sep = model.requirements.parasitic_separation
    top = model.crossover if res.loop_crossover is None else res.loop_crossover
    low = [m for m in model.modes if m.frequency < sep * top]
    if low:
        m = min(low, key=lambda x: x.frequency)
        return False, (f"the mode '{m.name}' at {quantity(m.frequency, 'Hz', 4)} lies below "
                       f"{number(sep, 6)} x the loop's crossover {quantity(top, 'Hz', 4)}")
    return True, ""


def stage_answer(model: Model, crossover: float | None = None,
                 fold: str = "unless hunting") -> dict:
    """The stage after every move of its family, and the fold of its cycle (plain data).

    A task for the executor: the isolated plant of ``model`` (at
    ``crossover`` when given), every move run (stopping at the first that
    hunts), the hunting-free crossover found by the fold of the cycle: with
    ``fold="unless hunting"`` only where no move hunts (a hunting point has no
    margin to measure), with ``"always"`` also above a hunting crossover.

    Returns
    -------
    dict
        ``hunts`` (bool), ``acceptable`` (bool), ``outcome`` (str), ``free_from``
        (Hz or None: no fold found), ``amplitude`` (m or None), ``period`` (s
        or None), ``tests`` (stage evaluations the fold took).
    """
    from ..stage import stage_hunting

    quick = stage_hunting(model, True, crossover=crossover, first_only=True, boundary=False,
                          trace=False)
    if fold != "always" and (quick.hunts or not quick.acceptable):  # no margin to measure
        st = quick
    else:
        st = stage_hunting(model, True, crossover=crossover, first_only=True, trace=False)
    c = st.cycle
    return {"hunts": st.hunts, "acceptable": st.acceptable, "outcome": st.outcome,
            "free_from": st.hunting_free_from, "amplitude": None if c is None else c.amplitude,
            "period": None if c is None else c.period,
            "tests": 0 if st.boundary is None else st.boundary.tests}


def margin_screen(model: Model, margin: float, crossover: float | None = None) -> dict:
    """Whether the stage keeps the hunting margin, by two quick stage-level answers (a task).

    No move of the family may hunt at the crossover, nor at the crossover over
    the margin: the cycle's fold then lies at least ``margin`` times below the
    crossover (the cycle exists below its fold and not above it; a band where
    it came and went would show in the sign-off, which finds the fold itself).
    Each answer stops at the first move that hunts.

    Returns
    -------
    dict
        ``keeps`` (bool), ``hunts`` (at the crossover), ``outcome`` (str: the
        crossover's stage outcome, or ``hunts_below`` when only the lower one
        hunts), ``tests`` (stage answers run).
    """
    from ..stage import stage_hunting

    fc = model.crossover if crossover is None else crossover
    # the moves' outcomes decide: the cycle is not converged as an orbit (converge=False)
    at = stage_hunting(model, True, crossover=fc, first_only=True, converge=False,
                       boundary=False, trace=False, order="spread")
    if at.hunts or not at.acceptable:
        return {"keeps": False, "hunts": at.hunts, "outcome": at.outcome, "tests": 1}
    below = stage_hunting(model, True, crossover=fc / margin, first_only=True, converge=False,
                          boundary=False, trace=False, order="spread")
    keeps = not below.hunts
    return {"keeps": keeps, "hunts": False,
            "outcome": "settles" if keeps else "hunts_below", "tests": 2}


def _settles(model: Model) -> bool:
    from ..stage import stage_hunting

    return stage_hunting(model, True, first_only=True, converge=False, boundary=False,
                         trace=False, order="spread").acceptable


def longer_delay(model: Model, fraction: float) -> Model:
    """The model with its loop's delay longer by ``fraction`` [-]: the delay the linear
    analysis models (:func:`fi_design.loop.linear.delay_time`: ``controller.delay``, a
    ``time_delay`` effect's and half the sample period), its controller's delay lengthened."""
    hold = 0.5 * model.law.sample_period
    effect = model.loop_delay - model.law.delay
    return model.at(delay=(model.loop_delay + hold) * (1.0 + fraction) - hold - effect)


def reserve_corners(model: Model) -> tuple[dict, ...]:
    """The candidate with the reserve's deviations: does it still pass?

    Each corner: the masses ``+-reserve.mass`` (the controller keeps its
    tuning, the guide as built carries the stage), the drive stiffness at the
    stock's thickness tolerance, the computed modes ``-reserve.modes``, the
    loop delay ``+reserve.delay`` (:func:`longer_delay`; none without a delay or
    sampling). A corner passes when the four limit cases meet the
    margins (the requirements, not the reserve) and no move of the family
    hunts.

    Returns
    -------
    tuple of dict
        ``name``, ``passed`` (bool), ``why`` (str, empty when passed).
    """
    from ..loop import linear

    r = model.requirements.reserve
    m1, m2 = model.m1, model.m2
    corners = [(f"masses +{percent(r.mass, 3)}", model.at(masses=(m1 * (1 + r.mass),
                                                                 m2 * (1 + r.mass)))),
               (f"masses -{percent(r.mass, 3)}", model.at(masses=(m1 * (1 - r.mass),
                                                                 m2 * (1 - r.mass))))]
    fx = model.flexure
    if fx is not None and fx.stiffness_range is not None:
        lo, hi = fx.stiffness_range
        t = quantity_mm(fx.thickness_tolerance)
        corners += [(f"leaves {t} thinner", model.at(stiffness=lo)),
                     (f"leaves {t} thicker", model.at(stiffness=hi))]
    if any(m.source == "computed" for m in model.modes):
        corners.append((f"computed modes -{percent(r.modes, 3)}",
                        model.at(mode_scale=1.0 - r.modes)))
    if model.loop_delay > 0.0 or model.law.sample_period > 0.0:
        corners.append((f"delay +{percent(r.delay, 3)}", longer_delay(model, r.delay)))
    out = []
    for name, m in corners:
        res = linear.analyse(m)
        bad = [c for c in res.cases if not c.passed]
        if bad:
            out.append({"name": name, "passed": False,
                        "why": f"case {linear.CASE_NUMBERS[bad[0].name]} misses its "
                               f"{', '.join(bad[0].failed)}"})
        elif not _settles(m):
            out.append({"name": name, "passed": False, "why": "some move hunts"})
        else:
            out.append({"name": name, "passed": True, "why": ""})
    return tuple(out)


def quantity_mm(x: float) -> str:
    """A length in mm for a sentence."""
    return quantity(x, "m", 3, shown=("mm", 1e3))


def hunting_margin(crossover: float, free_from: float | None, hunts: bool) -> float:
    """The crossover over the hunting-free crossover [-]: 0 when it hunts at the crossover, inf
    when no cycle was found at any crossover."""
    if hunts:
        return 0.0
    if free_from is None:
        return math.inf
    return crossover / free_from
