"""Nonlinear confirmation of the guideline's verdict (the design command's last part).

The guideline's four steps are linear and static. This module simulates the
stage with friction, with and without the isolator, at the design crossover
(paper section 2.3 and Figure 5), and adds what a reviewer wants to know:

- whether each plant hunts as a *stage*: after any move of its family, with
  the cycle it then enters converged as a periodic orbit
  (:func:`fi_design.stage.stage_hunting`); the paper's metric on the spec's
  own move stays beside it, labelled as that move's answer;
- the lowest crossover from which each plant no longer hunts for any move:
  the fold of its cycle, found by bisection (the paper's headline: the
  isolator needs far less bandwidth);
- where the cart lands: the joint deflection at rest after the move and the
  flexure force there against Fs. The paper's rule k * stroke < Fs is
  sufficient but conservative; the force the cart actually sees at rest is
  k * min(stroke, landing deflection), and once the landing deflection
  reaches the stroke the limiter carries the cart and hunting returns;
- a cross-check with the other friction model (LuGre against the
  Karnopp-type switch model), flagged when the verdicts disagree.

A spec without an isolator is confirmed against the isolator step 3 suggests
(:func:`fi_design.guideline.steps.isolator_advice`), so the comparison is always
"with" against "without". Only the spec's own plant is judged (its checks
PASS or FAIL): the isolated one when the spec has an isolator, else the stage
without. The other plant is information, and for a spec without isolator a
recommendation (:class:`~fi_design.results.design.Recommendation`), never a
reason to pass.

A loop without integrator (``controller.gains.ki: 0`` or
``integrator_ratio: .inf``) cannot hunt by the paper's mechanism: it comes to
rest with a static error of up to (Fs + |offset|) / kp, what static friction can hold
against it (:attr:`fi_design.model.Model.static_error_bound`). At rest within that
error its outcome is ``static_error``, not ``stuck``
(:class:`~fi_design.results.design.PlantVerdict`).
"""

from __future__ import annotations

import math

from ..display import number, quantities, quantity
from ..errors import ArgumentError
from ..model import Model, require_model
from ..results import Check, Status
from ..results.design import Confirmation, Landing, PlantVerdict
from ..results.simulation import SimulationResult
from ..results.stage import STATIC_ERROR_FORMULA
from ..simulation.run import simulate
from .forces import move_forces
from . import stage_hunting

PLANTS = ("isolated", "non_isolated")


def _hunts(v: PlantVerdict) -> bool:
    return v.metrics.verdict == "hunting"


def landing(model: Model, result: SimulationResult) -> Landing:
    """Landing deflection and flexure force of an isolated simulation of ``model``.

    Parameters
    ----------
    model : Model
        The resolved model (:func:`fi_design.model.resolve`) the result simulated.
    result : SimulationResult
        The isolated simulation.

    Returns
    -------
    Landing
    """
    model = require_model(model)
    k, s = model.joint.stiffness, model.joint.stroke
    d = float(result.deflection[-1])
    return Landing(deflection=d, stroke=s, stiffness=k, force=k * min(abs(d), s),
                   static_friction=model.friction.Fs, on_limiter=abs(d) >= s,
                   rule_force=k * s)


def with_isolator(model: Model, stroke: float, stiffness: float) -> Model:
    """The model with an isolator of the given stroke and stiffness, its spec holding it.

    ``model.varied({"isolator": {...}})`` (:meth:`fi_design.model.Model.varied`):
    the spec's isolator section replaced by one of this stroke and stiffness
    (the defaults' damping and limiter, no flexure, no given modes), the spec
    validated again and resolved once. The same plant as the fast form
    ``model.at(stroke=..., stiffness=...)``, which keeps the spec as it was;
    this one is for what reads the spec too (a study varying it by dotted
    paths and caching its points by its hash, the sign-off's robustness
    samples).

    Parameters
    ----------
    model : Model
        The model resolved from its spec (:func:`fi_design.model.resolve`),
        usually one without isolator.
    stroke : float
        One-sided stroke before the limiter engages [m].
    stiffness : float
        Drive stiffness [N/m].

    Returns
    -------
    Model

    Raises
    ------
    SpecError
        A stroke or stiffness the spec refuses; the message names the path.
    ArgumentError
        ``model`` was varied by :meth:`~fi_design.model.Model.at`.
    """
    return require_model(model).varied({"isolator": {"stiffness": stiffness, "stroke": stroke}})


def static_error_bound(model: Model) -> float | None:
    """The static error a loop without integrator may leave against friction [m].

    :attr:`fi_design.model.Model.static_error_bound`, ``(Fs + |offset|) / kp``
    with the larger static friction of the two directions: the cart stays put
    while the loop's force stays below static friction; None when the loop
    integrates. The one bound every statement of the design names.

    Parameters
    ----------
    model : Model
        The resolved model (:func:`fi_design.model.resolve`).

    Returns
    -------
    float or None
    """
    return require_model(model).static_error_bound


def _other_model(model: Model) -> Model:
    return model.at(friction_model="switch" if model.friction.model == "lugre" else "lugre")


def confirm(model: Model, suggestion: tuple[float, float] | None = None,
            progress=None) -> Confirmation:
    """Simulate both plants, scan the crossover, check the landing and cross-check.

    Parameters
    ----------
    model : Model
        The design's resolved model (:func:`fi_design.model.resolve`).
    suggestion : (stroke, stiffness), optional
        Isolator to simulate when the spec has none [m, N/m]; required then.
    progress : callable, optional
        Called with a short message as the work proceeds (about 130
        simulations of a few ms each).

    Returns
    -------
    Confirmation
    """
    model = require_model(model)
    suggested = not model.has_isolator
    if suggested:
        if suggestion is None:
            raise ArgumentError("a spec without isolator needs a suggested (stroke, stiffness)")
        stroke, stiffness = suggestion
        model_iso = model.at(stroke=stroke, stiffness=stiffness)
    else:
        model_iso = model

    def say(text: str) -> None:
        if progress is not None:
            progress(text)

    say("simulating the stage with and without the isolator ...")
    bound = static_error_bound(model)
    res_iso = simulate(model_iso, isolated=True)
    res_non = simulate(model, isolated=False)
    iso = PlantVerdict.of("isolated", res_iso, bound)
    non = PlantVerdict.of("non_isolated", res_non, bound)
    stage = {"isolated": stage_hunting(model_iso, True, progress=progress),
             "non_isolated": stage_hunting(model, False, progress=progress)}
    cfg = model.spec.simulation.crossover_scan
    widths = [st.boundary.resolution for st in stage.values() if st.boundary is not None]
    mins = {"isolated": stage["isolated"].hunting_free_from,
            "non_isolated": stage["non_isolated"].hunting_free_from,
            "resolution": max(widths) if widths else None,
            "search": [cfg.start, max(cfg.stop, res_iso.crossover)]}
    land = landing(model_iso, res_iso)
    say("the forces over the move family ...")
    own = model if suggested else model_iso
    forces = move_forces(own, not suggested)
    say("cross-checking with the other friction model ...")
    other_iso = PlantVerdict.of("isolated", simulate(_other_model(model_iso), isolated=True),
                                bound)
    other_non = PlantVerdict.of("non_isolated", simulate(_other_model(model), isolated=False),
                                bound)
    agree = _hunts(other_iso) == _hunts(iso) and _hunts(other_non) == _hunts(non)
    checks = _checks(model, iso, non, stage, mins, land, agree, other_iso, other_non,
                     suggested) + _force_checks(own, forces)
    return Confirmation(isolated=iso, non_isolated=non, stage=stage,
                        min_hunting_free_crossover=mins, landing=land, forces=forces,
                        cross_check={"isolated": other_iso, "non_isolated": other_non},
                        models_agree=agree, suggested_isolator=suggested, checks=tuple(checks),
                        results={"isolated": res_iso, "non_isolated": res_non})


def _force_checks(model: Model, forces) -> list[Check]:
    """The forces over the move family, judged: the end stop's contact force against
    ``requirements.end_stop_force``, the actuator's peak against ``controller.force_limit``."""
    step = "simulation (paper section 2.3)"
    out = []
    n = len(forces.moves)
    if forces.stop_stiffness is not None:
        limit = model.requirements.end_stop_force
        peak = forces.peak_stop_force
        stop = (f"the end stop ({quantity(forces.stop_stiffness, 'N/m', 3)}, "
                f"{quantity(forces.stop_damping, 'N*s/m', 3)}"
                + (", the spec's defaults: an assumption, the contact force goes with "
                   "the square root of the stiffness" if forces.stop_default else "")
                + ")")
        text = (f"{forces.moves_on_stop} of {n} moves run the joint onto {stop}, up to "
                f"{forces.most_impacts} times a move; the largest contact force "
                f"{quantity(peak, 'N', 4)}"
                if forces.moves_on_stop else f"no move of the family reaches {stop}")
        if limit is None:
            out.append(Check("end_stop_force", None, peak, None, "N", text, step))
        else:
            ok = peak <= limit
            out.append(Check("end_stop_force", ok, peak, limit, "N", text + (
                f", within requirements.end_stop_force" if ok else
                f", above requirements.end_stop_force = {quantity(limit, 'N', 3)}"), step))
    peak = forces.peak_actuator_force
    flim = model.law.force_limit
    weight = forces.held_weight
    text = f"the largest actuator force over the {n} moves is {quantity(peak, 'N', 3)}" + (
        f", the weight (m1 + m2) g = {quantity(weight, 'N', 3)} it holds on the "
        "vertical drive axis included (the simulation carries no weight)" if weight else "")
    if flim is None or not math.isfinite(flim):
        out.append(Check("actuator_force", None, peak, None, "N", text, step))
    elif weight >= flim:
        out.append(Check("actuator_force", False, peak, flim, "N", text + (
            f": the actuator cannot hold the stage, its controller.force_limit = "
            f"{quantity(flim, 'N', 3)} is not above the weight"), step))
    else:
        # saturating, the simulated stage is the hardware's (a warning) unless it leaves out a
        # weight: then the actuator has that much less for the moves than was simulated
        cmd = forces.peak_command
        ok = cmd < flim
        out.append(Check("actuator_force", ok, peak, flim, "N", text + (
            f", below controller.force_limit = {quantity(flim, 'N', 3)}" if ok else
            f": the actuator saturates at controller.force_limit = {quantity(flim, 'N', 3)} "
            f"(the loop commands up to {quantity(cmd, 'N', 3)})" + (
                "; the simulated moves, with the whole limit left for them, are not the "
                "hardware's" if weight else "")), step,
            status=None if ok or weight else Status.WARN))
    return out


def _plant_text(v: PlantVerdict, label: str, fc: float) -> str:
    m = v.metrics
    if v.outcome == "static_error":
        rest, bound = quantities((abs(m.final_error), v.static_error_bound), "m", 3)
        return (f"{label} at {number(fc, 4)} Hz: at rest {rest} from its target, within the static "
                f"error {STATIC_ERROR_FORMULA} = {bound} of a loop without integrator")
    return f"{label} at {number(fc, 4)} Hz: {m.verdict} ({m.reason})"


def _checks(model, iso, non, stage, mins, land, agree, other_iso, other_non,
            suggested) -> list[Check]:
    """The confirmation's checks: the spec's own plant judged, the other one information."""
    fc = model.crossover
    margin = model.requirements.hunting_margin
    step = "simulation (paper section 2.3)"
    if suggested:
        own_key, labels = "non_isolated", {
            "non_isolated": "the stage as specified (without isolator)",
            "isolated": "with the rule's isolator (for comparison, not the hardware)"}
    else:
        own_key, labels = "isolated", {
            "isolated": "the isolated design as specified",
            "non_isolated": "without the isolator (for comparison)"}
    plants = {"isolated": iso, "non_isolated": non}
    out = []
    for key in ("isolated", "non_isolated"):
        st = stage[key]
        judged = key == own_key
        # the hunting moves counted against none; a stage that sticks or cannot be judged
        # fails on that (the message says which move and why), not on a count of 0 = 0
        counted = st.hunts or st.acceptable
        out.append(Check(f"simulation_{key}", st.acceptable if judged else None,
                         float(len(st.hunting_moves)) if counted else None,
                         0.0 if judged and counted else None, "moves",
                         st.describe(labels[key]), step))
    for key in ("isolated", "non_isolated"):
        v = plants[key]
        text = "the spec's own motion, the paper's metric: " + _plant_text(v, labels[key], fc)
        slow = key == own_key and not v.acceptable and stage[key].acceptable
        if slow:  # every move comes to rest, but the spec's not within the metric's window
            text += ("; every move comes to rest in the end, but not within the window of the "
                     "metric: a slow settling to review")
        counted = v.metrics.verdict != "undetermined"  # no count of a run that did not finish
        out.append(Check(f"spec_move_{key}", None,
                         float(v.metrics.hunting_cycles) if counted else None, None,
                         "cycles", text, step, status=Status.WARN if slow else None))
    for key in ("isolated", "non_isolated"):
        st = stage[key]
        m = mins[key]
        judged = key == own_key
        text = f"{labels[key]}: {st.boundary_text()}; design crossover {number(fc, 4)} Hz"
        if st.boundary is None:  # not computed: a loop without integrator
            out.append(Check(f"min_crossover_{key}", None, None, None, "Hz", text, step))
        elif not judged:
            out.append(Check(f"min_crossover_{key}", None, m, None, "Hz", text, step))
        elif m is None:
            out.append(Check(f"min_crossover_{key}", False, m, fc, "Hz", text + (
                ": a crossover that ends hunting was not found"), step, status=Status.WARN))
        elif fc >= margin * m:
            out.append(Check(f"min_crossover_{key}", True, m, fc / margin, "Hz", text + (
                f", at least {number(margin, 6)} x above it (requirements.hunting_margin)"
                if margin > 1 else ""), step))
        elif fc >= m:
            out.append(Check(f"min_crossover_{key}", False, m, fc / margin, "Hz", text + (
                f": the design crossover lies only {number(fc / m, 3)} x above it, within the "
                f"hunting margin of {number(margin, 6)} (requirements.hunting_margin): a little "
                "more friction gap or a little less loop gain brings the cycle back"), step))
        else:
            out.append(Check(f"min_crossover_{key}", False, m, fc / margin, "Hz", text + (
                ": the design crossover lies below it, where the cycle exists"
                + ("" if st.hunts else " although no move of the family enters it")),
                step, status=Status.WARN))
    stn = stage["non_isolated"]
    if stn.acceptable:
        out.append(Check("isolator_needed", None, None, None, "-",
                         f"the stage without isolator {stn.summary()}: the isolator is not "
                         "needed at this crossover", step))
    if land is not None and not math.isfinite(land.deflection):
        where = "the rule's isolator's cart" if suggested else "the cart"
        out.append(Check("landing_force", None, None, None, "N",
                         f"where {where} comes to rest could not be determined "
                         f"({iso.metrics.reason})",
                         "step 3 refinement: landing"))
    elif land is not None:
        ok = (not land.on_limiter) and land.force < land.static_friction
        where = "the rule's isolator's cart" if suggested else "the cart"
        d = quantity(land.deflection, 'm', 3)
        if land.on_limiter:
            text = (f"{where} lands at {d} joint deflection, on the limiter (stroke "
                    f"{quantity(land.stroke, 'm', 3)}): the end stop, not the flexure, holds "
                    "the cart, so the controller pushes on the friction again and hunting can "
                    f"return (the flexure alone would push with k s = "
                    f"{quantity(land.rule_force, 'N', 3)} against Fs = "
                    f"{quantity(land.static_friction, 'N', 3)})")
        else:
            text = (f"{where} lands at {d} joint deflection (inside the stroke): flexure force "
                    f"k min(|d|, s) = {quantity(land.force, 'N', 3)} against Fs = "
                    f"{quantity(land.static_friction, 'N', 3)} (the rule's bound k s = "
                    f"{quantity(land.rule_force, 'N', 3)})")
            # the simulation carries no weight: on a vertical drive axis the joint sags too
            fx = None if suggested else model.flexure
            sag = 0.0 if fx is None else fx.sag
            if sag > 0.0 and land.clearance(sag) < 0.0:
                ok = False
                text += (f"; but on the vertical axis the joint sags a further "
                         f"{quantity(sag, 'm', 3)} under the cart's weight, which the "
                         f"simulation does not carry: |d| + sag = "
                         f"{quantity(abs(land.deflection) + sag, 'm', 3)} is beyond the "
                         f"{quantity(land.stroke, 'm', 3)} stroke, so the cart rests on its "
                         "end stop, not on the flexure")
            elif sag > 0.0:
                text += (f"; on the vertical axis with a further sag of "
                         f"{quantity(sag, 'm', 3)} under the cart's weight, "
                         f"{quantity(land.clearance(sag), 'm', 3)} from the end stop")
        out.append(Check("landing_force", None if suggested else ok, land.force,
                         land.static_friction, "N", text, "step 3 refinement: landing"))
    if not agree:
        other = {"isolated": other_iso, "non_isolated": other_non}
        own_differs = _hunts(other[own_key]) != _hunts(plants[own_key])
        out.append(Check(
            "friction_model_cross_check", None, None, None, "-",
            f"the {other_iso.friction_model} model disagrees: isolated "
            f"{other_iso.metrics.verdict}, without isolator {other_non.metrics.verdict}"
            + ("" if own_differs else " (not on the stage as specified)"), step,
            status=Status.WARN if own_differs else Status.INFO))
    return out
