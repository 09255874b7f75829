"""Assumptions and limitations of a design report, generated from the method and settings that ran.

Every statement names the setting it rests on (the spec's value or its
default) and the model the design actually used (:attr:`DesignResult.model`,
the spec resolved once): the end stop's contact law, gravity on the guide, the
loop's sampling, the friction scatter, the judgement of every move and the
paper's metric. Nothing here is copied prose about an older method: change
the method, and these sentences follow.
"""

from __future__ import annotations

import math
from typing import Any

from ..display import NBSP, percent
from ..effects import simulated_only
from ..results.stage import STATIC_ERROR_FORMULA
from .filters import num, qty

__all__ = ["assumptions", "family_words"]


def family_words(result: Any) -> str:
    """The move family that ran, in words: how many moves, from which distance to which."""
    sim = result.simulation
    spec = result.spec
    fam = spec.motion.family
    if sim is None:
        return f"{fam.count} log-spaced distances"
    own = "isolated" if result.model.has_isolator else "non_isolated"
    parts = []
    for key in (own, *(k for k in sim.stage if k != own)):
        moves = [abs(m.distance) for m in sim.stage[key].moves if m.label == "family"]
        if not moves:
            continue
        both = any(m.distance < 0 for m in sim.stage[key].moves if m.label == "family")
        name = {"isolated": "with the isolator", "non_isolated": "without it"}[key]
        if sim.suggested_isolator and key == "isolated":
            name = "with the rule's isolator"
        parts.append(f"{name} {qty(min(moves), 'm')} to {qty(max(moves), 'm')}"
                     + (" in both directions" if both else ""))
    given = "given in motion.family" if fam.distances is not None else (
        f"{fam.count} log-spaced distances from a tenth of the stroke, or 0.1 mm without "
        "isolator, to five times the spec's largest move, at its velocity and acceleration")
    return f"{given}: " + "; ".join(parts) + ", and the spec's own motion"


def _limiter(result: Any) -> str:
    model = result.model
    spec = result.spec
    lim = model.limiter
    given = spec.isolator.limiter
    fields = set() if given is None else set(given.model_fields_set)
    k_src = "given" if "stiffness" in fields else "default"
    c_src = ("given" if "damping" in fields and given.damping is not None
             else "default 2 \u00d7 0.2 \u221a(k_stop m1)")
    return (f"The end stops at \u00b1{qty(model.joint.stroke, 'm')} are a contact spring "
            f"k_stop = {qty(lim.stiffness, 'N/m')} ({k_src}) with a damper c_stop = "
            f"{qty(lim.damping, 'N*s/m')} ({c_src}) acting on the joint's deflection beyond the "
            "stroke: an elastic impact, no restitution coefficient, no wear or play.")


def _bodies(result: Any) -> list[str]:
    model = result.model
    out = []
    if model.has_isolator:
        j = model.joint
        out.append(
            f"Two rigid masses along the drive axis, the stage m1 = {qty(model.m1, 'kg')} "
            f"(actuator and sensor) and the cart m2 = {qty(model.m2, 'kg')} (friction), joined "
            f"by a linear spring k = {qty(j.stiffness, 'N/m')} and damper c = "
            f"{qty(j.damping, 'N*s/m')}" + ("" if j.damping_given else
                                           " (the spec's default damping ratio of the joint "
                                           "mode; it follows k when k varies)") + ".")
        out.append(_limiter(result))
    else:
        out.append(f"One rigid mass m1 + m2 = {qty(model.total_mass, 'kg')} along the drive "
                   "axis: the spec has no isolator. The rule's isolator simulated beside it for "
                   "comparison has the spec's default joint damping and end stop.")
    fx = result.flexure
    if fx is not None and fx.mechanics is not None:
        g = fx.mechanics.gravity
        words = {"standing": "the leaves stand under the stage and carry its weight in "
                             "compression", "hanging": "the stage hangs from the leaves, in "
                             "tension", "flat": "the leaves lie flat, gravity along their width",
                 "vertical_axis": "the drive axis is vertical: the joint carries the cart's "
                                  "weight and sags"}.get(g.orientation, g.orientation)
        buck = ("" if g.buckling_factor is None else
                f"; the guide buckles at {num(g.buckling_factor, 3)} times the weight")
        out.append(
            f"Gravity is modelled on the leaf-spring guide ({g.orientation}: {words}"
            + (", as assumed by default" if "orientation" not in
               result.spec.isolator.flexure.model_fields_set else "") + "): its geometric "
            f"stiffness {qty(g.geometric_stiffness, 'N/m')} is part of the drive stiffness{buck}. "
            "The guide's six stage modes and the leaves' own modes are computed from closed "
            "forms (checked against a finite-element model in the tests) and enter the linear "
            "limit cases by their coupling into the drive coordinate; the nonlinear simulation "
            "moves along the drive axis only.")
    elif model.has_isolator:
        out.append("The isolator is its drive stiffness and stroke only (no isolator.flexure): "
                   "gravity's stiffness on a guide, its buckling and its modes are not modelled; "
                   "parasitic modes enter the linear analysis only as the spec gives them.")
    else:
        out.append("Motion along one axis only: tilt, yaw and support compliance are not "
                   "modelled.")
    if result.model.offset:
        out.append(f"A constant load force friction.offset = {qty(result.model.offset, 'N')} "
                   "acts on the stage (a drive offset, or gravity on an inclined axis).")
    return out


def _friction(result: Any) -> list[str]:
    model = result.model
    f = result.spec.friction
    fr = model.friction
    out = [
        f"{'LuGre' if f.model == 'lugre' else 'Switch (Karnopp-type)'} friction "
        "(Canudas de Wit et al. 1995) with constant parameters along the rail and in time; the "
        f"{'switch (Karnopp-type)' if f.model == 'lugre' else 'LuGre'} model serves as a "
        "cross-check on the spec's own move. Real friction varies with position, time, "
        "temperature and wear (paper \u00a73.2): a simulated cycle count is an indication, "
        "not a prediction."]
    gap = fr.Fs - fr.Fc
    if f.model == "lugre" and gap > 0:
        bound = f.viscous * f.coulomb / gap
        s1 = fr.sigma1
        if s1 >= bound:
            out.append(
                f"The bristle damping sigma1 = {qty(s1, 'N*s/m')} lies above sigma2 Fc / (Fs "
                f"\u2212 Fc) = {qty(bound, 'N*s/m')}, so the LuGre model is not guaranteed "
                "dissipative (Barabanov and Ortega); the default sqrt(sigma0 (m1 + m2)) breaks "
                "the bound deliberately, to damp the presliding mode at a ratio of 0.5. The "
                "dynamic parameters sigma0, sigma1 and vs are seldom identified: the validation "
                "section shows how much the hunting-free crossover depends on them.")
    return out


def _loop(result: Any) -> list[str]:
    law = result.pid.controller
    spec = result.spec
    effects = [e.type for e in spec.effects]
    delays = [e.delay for e in spec.effects if e.type == "time_delay"]
    steps = [e.resolution for e in spec.effects if e.type == "quantization"]
    sampled = (("a continuous-time controller without delay" if not delays else
                "a continuous-time controller without a delay of its own")
               if law.sample_period == 0 and law.delay == 0 else
               ("continuous-time" if law.sample_period == 0 else
                f"sampled at {qty(1.0 / law.sample_period, 'Hz')} with a zero-order hold")
               + ("" if law.delay == 0 else f", delay {qty(law.delay, 's')}"))
    simulated = simulated_only(spec.effects, sep=NBSP)
    out = [f"The loop is {sampled}"
           + (" (the hardware samples and computes with a delay: give controller.sample_rate "
              "and controller.delay to judge the loop it has)" if law.sample_period == 0
              and law.delay == 0 and not delays else "")
           + "".join(f"; the spec's effect time_delay adds {qty(d, 's')} to the loop's delay, "
                     "in the simulation and in the linear analysis (its margins and crossover)"
                     for d in delays) + "."]
    limit = law.force_limit
    sensor = ("The sensor is ideal: no sensor noise, no quantization, no latency beyond the "
              "loop's delay" if not steps else
              "The sensor has no noise and no latency beyond the loop's delay, and resolves the "
              "position in steps of " + " and ".join(qty(q, "m") for q in steps)
              + " (the spec's effect quantization)")
    out.append(
        "The actuator is an ideal force source: no actuator dynamics (current loop, motor "
        "inductance, amplifier bandwidth)"
        + (f", saturating at \u00b1{qty(limit, 'N')}" if math.isfinite(limit)
           else "" if "force_saturation" in effects else ", no saturation")
        + f". {sensor}."
        + (f" {simulated[0].upper()}{simulated[1:]}." if simulated else ""))
    return out


def _robustness(result: Any) -> str:
    r = result.spec.requirements.robustness
    if r.samples == 0:
        return ("No robustness check (requirements.robustness.samples: 0): friction is "
                "simulated at its nominal values only.")
    ripple = ("" if r.ripple is None else
              f", and a {percent(r.ripple.amplitude, 3)} ripple with a "
              f"{qty(r.ripple.wavelength, 'm')} wavelength along the rail at a random phase")
    check = getattr(result, "robustness", None)
    spread = None if check is None else check.scatter.get("isolator.stiffness")
    fx = result.flexure
    if spread is None:
        stiff = ""
    else:
        stiff = ("; the drive stiffness ("
                 + (f"{percent(spread, 3)}, the flexure's stock tolerance, k going with "
                    "t\u00b3" if r.stiffness is None and fx is not None and fx.feasible
                    else percent(spread, 3) + ("" if r.stiffness is not None else
                                               ", the default without a sized flexure"))
                 + (", of the isolator simulated for comparison only" if check.plant ==
                    "non_isolated" else "") + ")")
    delay = (f", the loop delay {percent(r.delay, 3)}"
             if result.spec.controller.delay > 0 else "")
    return (f"Robustness: {r.samples} samples ({r.distribution}, seed {r.seed}), each drawing "
            f"Coulomb friction ({percent(r.coulomb, 3)}) and the gap Fs \u2212 Fc "
            f"({percent(r.gap, 3)}) together, so static friction never falls below "
            "Coulomb friction and no sample is lost; the true masses "
            f"({percent(r.mass, 3)}, the controller keeping its tuning)"
            f"{stiff}{delay}{ripple}. The parasitic modes do not enter the "
            "nonlinear simulation, and the LuGre dynamics (sigma0, sigma1, vs, sigma2) stay "
            "nominal. The probability of not settling carries a Wilson interval at "
            f"{percent(r.confidence, 3)} confidence.")


def _judgement(result: Any) -> list[str]:
    spec = result.spec
    h = spec.requirements.hunting
    scan = spec.simulation.crossover_scan
    sim = result.simulation
    out = [
        f"Every move of the family ({family_words(result)}) is simulated until the stage "
        f"rests within the \u00b1{qty(h.settle_band, 'm')} settle band for good (the force "
        "the loop asks of the resting cart stays below its static friction), until its state "
        "repeats at the Poincar\u00e9 section x1 \u2212 r = 0 (a sustained cycle, whatever "
        f"its size), or for {qty(h.horizon, 's')} after the motion (requirements.hunting."
        "horizon), after which the move is 'undetermined'."]
    if result.pid.static_error is not None:
        out.append(
            "The loop has no integrator: a move that rests off its target within the static "
            f"error {STATIC_ERROR_FORMULA} = {qty(result.pid.static_error, 'm', 3)} rests as "
            "the loop explains it (its static error), beyond that it is stuck. No "
            "hunting-free crossover is computed: the paper's mechanism needs an integrator.")
    else:
        out.append(
            "Hunting can come and go with the crossover (the paper saw a hunting-free run at "
            "9.5 Hz): the lowest crossover from which no move hunts is the fold of the hunting "
            f"cycle, bisected on the stage-level answer (to the resolution the checks give) "
            f"between {qty(scan.start, 'Hz')} "
            f"and {qty(max(scan.stop, result.crossover.desired), 'Hz')} "
            "(simulation.crossover_scan) and confirmed by the whole move family just above "
            "it. It holds for these moves, the nominal friction and the model's LuGre "
            "parameters.")
    return out


def _metric(result: Any) -> list[str]:
    h = result.spec.requirements.hunting
    window = f"[{num(h.window_start)} s, {num(h.window_start + h.window_length)} s)"
    out = [
        f"The paper's metric judges the spec's own motion only: it counts the peaks of "
        f"x1 \u2212 r of at least {qty(h.min_height, 'm')} that stand out by as much "
        f"(prominence), at least {qty(h.min_distance, 's')} apart, in the window {window}; "
        "a cycle below the target counts its negative peaks. A cycle smaller than "
        f"{qty(h.min_height, 'm')} counts as none there, though the stage-level answer calls "
        "it hunting.",
        f"A cycle slower than the {qty(h.window_length, 's')} window shows no peak: the metric "
        "then says 'undetermined', never 'settled'; the stage-level answer watches each move "
        f"for up to {qty(h.horizon, 's')}.",
        "A stage resting away from its target shows no peaks either: the metric calls it "
        f"'stuck' unless it rests within the {qty(h.settle_band, 'm')} settle band"
        + (f" or, for this loop without integrator, within its static error "
           f"{STATIC_ERROR_FORMULA}" if result.pid.static_error is not None else "") + ".",
    ]
    return out


def assumptions(result: Any) -> dict:
    """The assumptions section: the model, the loop, the judgement, the solver, the metric.

    Parameters
    ----------
    result : fi_design.results.design.DesignResult
        The design; its resolved ``model`` holds the values that ran.

    Returns
    -------
    dict
        ``model``, ``judgement``, ``solver`` and ``metric``: lists of sentences.
    """
    spec = result.spec
    sim = spec.simulation
    linear = ("The linear analysis linearises friction in the limit cases (cart sliding or "
              "stuck" + (", joint free or on its limiter" if result.model.has_isolator else "")
              + ", paper Figure 2): the margins hold near each case, not during the "
              "transitions between them.")
    return {
        "model": _bodies(result) + _friction(result) + _loop(result) + [_robustness(result),
                                                                          linear],
        "judgement": _judgement(result),
        "solver": [
            "Fast path: a linearly implicit Rosenbrock method of order 4 (RODAS4, Hairer and "
            f"Wanner) with step-size control at relative tolerance {num(sim.tolerance)}, mode "
            "switches of the end stops and of stick and slip located as events; traces sampled "
            f"at {qty(sim.output_rate, 'Hz')}; at most {num(sim.max_steps)} steps per run.",
            "The fast integrator is tested against scipy's solve_ivp (Radau) at a tolerance "
            "10\u2074 times tighter on the same equations (see the validation section).",
        ],
        "metric": _metric(result),
    }
