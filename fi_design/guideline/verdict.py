"""The sign-off verdict on the hardware as specified: robustness, margins, recommendation.

:func:`fi_design.guideline.evaluate.evaluate` runs the four steps and the nonlinear
confirmation; this module turns them into what a review board signs:

- :func:`run_robustness` -- the probability of hunting under the friction
  scatter of ``requirements.robustness`` (default +-20 % on static and
  Coulomb friction, 100 samples), with the study machinery of
  :func:`fi_design.studies.robustness` (the spec's own plant, and the other
  one on the same samples for comparison); :func:`robustness_check` compares
  it with the limit;
- :func:`margins` -- design crossover / lowest hunting-free crossover,
  end-stop clearance at rest, k_max / k and the stiffness range the flexure's
  thickness tolerance gives, each only where it means something (a loop
  without integrator has no hunting boundary; a crossover scan that settles
  everywhere gives a bound; the search cap of step 2 is a bound, not a
  result);
- :func:`recommendation` -- what to build so that the stage passes, from
  the design search of :mod:`fi_design.recommend`, kept apart from the
  verdict;
- :func:`judge` -- the :class:`~fi_design.results.design.Verdict`.

The verdict judges the spec's own plant: the isolated stage when the spec has
an isolator, else the stage without. It fails when a check fails, when that
plant hunts, sticks away from its target or cannot be determined at the
design crossover (a loop without integrator resting within its expected
static error (Fs + |offset|) / kp is neither), or when it hunts under scatter
more often than ``requirements.robustness.hunting_probability``. It passes
with warnings when nothing fails but something needs review: a warning
check, a warning on the user's own input, a loop without the hardware's
sampling and delay, a probability not demonstrated by the samples, a cart
resting within the friction scatter of its end stop, or no simulation.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import replace
from typing import Any

from ..model import Model
from ..display import percent, quantities, quantity
from ..results import Check, Status
from ..results.design import (Confirmation, CrossoverResult, FlexureResult, FrictionGapResult,
                              Margins, PidResult,
                              Reason, Recommendation, RobustnessCheck, StiffnessResult, Verdict,
                              VerdictStatus)

__all__ = ["recommend_command", "friction_gap_judged", "simulated_isolator_advice",
           "simulation_sentence",
           "run_robustness", "robustness_check", "robustness_as_check", "margins",
           "recommendation", "judge"]

#: Plant judged for a spec with / without isolator.
_OWN = {True: "isolated", False: "non_isolated"}


def _pct(x: float | None) -> str:
    return percent(x, 3)


def _um(x: float) -> str:
    return quantity(x, "m", 3)


# --------------------------------------------------------------------------- robustness


def run_robustness(model: Model, suggestion: tuple[float, float] | None = None,
                   progress: Callable[[int, int], None] | None = None,
                   executor: Any = None) -> Any:
    """Simulate the samples of ``requirements.robustness`` (the study, not yet judged).

    Every sample draws Coulomb friction and the gap Fs - Fc together (static
    friction never below Coulomb friction: no sample is lost), the true masses
    (the controller keeps its nominal tuning), the drive stiffness (the
    flexure's stock tolerance by default) and the loop delay, by the fractions
    of ``requirements.robustness`` (and a ripple along the rail when set); the
    parasitic modes do not enter the nonlinear simulation, so they do not
    scatter here (the recommendation's reserve checks them). Every sample is
    judged at the stage level
    (every move of its family, :mod:`fi_design.stage`), with and without the
    isolator, in chunks on ``executor`` (or here). A spec without isolator is
    studied with the suggested isolator added, so the same samples show what
    it would do; the spec's own plant is the one without.

    Parameters
    ----------
    model : Model
        The resolved model; the study varies it by dotted spec paths
        (:meth:`~fi_design.model.Model.varied`).
    suggestion : (stroke, stiffness), optional
        Isolator to add when the spec has none [m, N/m].
    progress : callable, optional
        ``progress(done, total)`` in samples.
    executor : concurrent.futures-style executor, optional
        Runs the samples in chunks; None runs them here.

    Returns
    -------
    fi_design.studies.RobustnessResult or None
        None when ``samples`` is 0 or nothing scatters.
    """
    from ..stage.confirm import with_isolator
    from ..studies import PositionFriction, Scatter, robustness

    cfg = model.requirements.robustness
    ripple = None if cfg.ripple is None else PositionFriction(cfg.ripple.amplitude,
                                                              cfg.ripple.wavelength)
    if cfg.samples == 0:
        return None
    nominal = model
    if not model.has_isolator and suggestion is not None:
        nominal = with_isolator(model, *suggestion)
    target = nominal.spec
    scatter = [Scatter("friction.coulomb", cfg.coulomb)] if cfg.coulomb > 0 else []
    values: dict[str, Any] = {}
    if cfg.mass > 0:  # the true masses: the controller keeps its nominal tuning
        entries = [e.model_dump(exclude_none=True) for e in target.effects
                   if e.type != "mass_error"]
        entries.append({"type": "mass_error", "stage_mass": target.stage.mass,
                        "cart_mass": target.cart.mass})
        values["effects"] = entries
        scatter += [Scatter("effects[type=mass_error].stage_mass", cfg.mass),
                    Scatter("effects[type=mass_error].cart_mass", cfg.mass)]
    k_spread = model.stiffness_scatter
    if k_spread > 0 and target.isolator is not None:
        if target.isolator.stiffness is None:  # a drawn guide: its net stiffness, as measured
            values["isolator.stiffness"] = model.joint.stiffness if model.joint else None
        scatter.append(Scatter("isolator.stiffness", k_spread))
    if cfg.delay > 0 and target.controller.delay > 0:
        scatter.append(Scatter("controller.delay", cfg.delay))
    if values:
        nominal = nominal.varied({k: v for k, v in values.items() if v is not None})
        target = nominal.spec
    gap = cfg.gap if target.friction.static > target.friction.coulomb else None
    if not scatter and ripple is None and gap is None:
        return None
    return robustness(nominal, scatter, cfg.samples, seed=cfg.seed,
                      distribution=cfg.distribution, position_friction=ripple,
                      confidence=cfg.confidence, executor=executor, progress=progress,
                      cache=None, friction_gap=gap)


def robustness_check(model: Model, study: Any) -> RobustnessCheck:
    """Judge a robustness study against ``requirements.robustness.hunting_probability``.

    FAIL when the estimated probability exceeds the limit; WARN when it does
    not but the Wilson interval reaches above it (the samples do not
    demonstrate the limit); PASS when the whole interval lies at or below.

    Parameters
    ----------
    model : Model
        The resolved model (its requirements, its loop and whether it has an
        isolator).
    study : fi_design.studies.RobustnessResult
        From :func:`run_robustness`.

    Returns
    -------
    RobustnessCheck
    """
    cfg = model.requirements.robustness
    own = _OWN[model.has_isolator]
    mine = study.isolated if own == "isolated" else study.not_isolated
    other = study.not_isolated if own == "isolated" else study.isolated
    # a sample fails when its stage does not settle, whatever the reason
    p, limit = mine.unsettled_probability, cfg.hunting_probability
    if p is None:
        status = "WARN"
    elif p > limit:
        status = "FAIL"
    elif mine.unsettled_high > limit:
        status = "WARN"
    else:
        status = "PASS"
    comparison = None if other is None else {
        "plant": "isolated" if other.isolated else "non_isolated",
        "hunting_probability": other.unsettled_probability,
        "interval": (other.unsettled_low, other.unsettled_high)}
    ripple = None if study.position_friction is None else {
        "amplitude": study.position_friction.amplitude,
        "wavelength": study.position_friction.wavelength}
    return RobustnessCheck(
        plant=own, samples=mine.samples, valid=mine.valid, hunting=mine.unsettled,
        hunting_probability=p, interval=(mine.unsettled_low, mine.unsettled_high),
        confidence=mine.confidence,
        limit=limit, status=status,
        scatter={(s.meaning or s.path): s.spread for s in study.scatter},
        distribution=study.distribution, ripple=ripple, seed=study.seed,
        counts=dict(mine.counts), comparison=comparison, study=study)


def robustness_as_check(r: RobustnessCheck) -> Check:
    """The robustness check as one of the design's checks (FAIL, WARN or PASS).

    Parameters
    ----------
    r : RobustnessCheck
        From :func:`robustness_check`.

    Returns
    -------
    Check
        Named ``robustness``; value and limit as probabilities [-].
    """
    if r.hunting_probability is None:
        text = (f"no scatter sample was simulated to the end ({r.samples} drawn, none valid): "
                f"the hunting probability could not be determined, limit {_pct(r.limit)}")
    else:
        text = (f"the stage as specified does not settle after every move in "
                f"{_pct(r.hunting_probability)} of {r.valid} scatter samples "
                f"({percent(r.confidence, 3)} interval {_pct(r.interval[0])} to "
                f"{_pct(r.interval[1])}), limit {_pct(r.limit)}")
    return Check("robustness", None if r.status == "WARN" else r.status == "PASS",
                 r.hunting_probability, r.limit, "-", text, "robustness under friction scatter",
                 status=Status(r.status))


def _scatter_words(r: RobustnessCheck) -> str:
    names = {"friction.static": "Fs", "friction.coulomb": "Fc",
             "the gap Fs - Fc": "the gap Fs \u2212 Fc",
             "effects[type=mass_error].stage_mass": "m1",
             "effects[type=mass_error].cart_mass": "m2", "isolator.stiffness": "k",
             "controller.delay": "the delay"}
    # the judged plant's scatter: without an isolator the drive stiffness scatters only on the
    # comparison's isolator, not on the stage as specified
    scatter = {k: v for k, v in r.scatter.items()
               if not (k == "isolator.stiffness" and r.plant == "non_isolated")}
    spread = sorted(set(scatter.values()))
    if len(spread) == 1 and spread[0] > 0:
        parts = [f"\u00b1{percent(spread[0], 3)} on " + " and ".join(names.get(k, k)
                                                                      for k in scatter)]
    else:
        parts = [f"\u00b1{percent(v, 3)} on {names.get(k, k)}" for k, v in scatter.items()]
    if r.ripple is not None:
        parts.append(f"a {percent(r.ripple['amplitude'], 3)} ripple every "
                     f"{quantity(r.ripple['wavelength'], 'm', 3)} along the rail")
    kind = "standard deviation" if r.distribution == "normal" else "uniform half-width"
    return f"{', '.join(parts)} ({r.distribution}, {kind}; {r.samples} samples)"


# --------------------------------------------------------------------------- margins


def _hunting_loop(model: Model, crossover: CrossoverResult, stage, free_from: float) -> dict:
    """The loop the hunting cycle slides in, and its actual crossover at the design and at the
    hunting-free crossover (the hunting margin's two loops).

    The cycle slides with the joint on its limiter (case 3, the rigid m1 + m2 sliding), or
    with the joint free (case 1); without isolator, the one rigid case that slides. Its 0 dB
    crossing at the two crossovers [Hz].
    """
    from ..loop import linear

    if not model.has_isolator:
        case = "sliding"
    else:
        cyc = stage.cycle
        case = "sliding_limited" if cyc is None or cyc.on_limiter is not False else "sliding_free"

    def top(cases) -> float | None:
        c = next((c for c in cases if c.name == case), None)
        inside = [g.frequency for g in (c.gain_crossings if c else ()) if g.in_band]
        return max(inside) if inside else None

    at_design = top(crossover.cases)
    at_free = top(linear.analyse(model.at(crossover=free_from)).cases)
    return {"hunting_case": case, "hunting_loop_crossover": at_design,
            "hunting_free_loop_crossover": at_free}


def margins(model: Model, crossover: CrossoverResult, stiffness: StiffnessResult,
            flexure: FlexureResult | None, pid: PidResult,
            simulation: Confirmation | None) -> Margins:
    """Distances to the limits, each only where it means something.

    Parameters
    ----------
    model : Model
        The resolved model.
    crossover : CrossoverResult
        Step 2.
    stiffness : StiffnessResult
        Step 3.
    flexure : FlexureResult or None
        Step 3's flexure sizing.
    pid : PidResult
        Step 4 (whether the loop integrates).
    simulation : Confirmation or None
        The nonlinear confirmation.

    Returns
    -------
    Margins
    """
    notes: list[str] = []
    out: dict[str, Any] = {}
    own = _OWN[model.has_isolator]
    fc = crossover.desired

    if crossover.achievable is None:
        notes.append("no crossover meets the linear requirements: no bandwidth margin")
    elif crossover.limit_kind == "scan_limit":
        out["achievable_crossover_bound"] = crossover.achievable
        notes.append(f"step 2: the linear model limits the crossover nowhere below "
                     f"{quantity(crossover.achievable, 'Hz', 4)}, the search cap: a bound, not a "
                     "result (sampling, delay and parasitic modes in the spec would set the "
                     "real limit)")
    else:
        out["achievable_factor"] = crossover.achievable / fc
    for c in crossover.cases:
        if not c.in_band:
            where = (f"crosses 0 dB only at {quantity(c.crossover, 'Hz', 3)}, below its band "
                     f"(from {quantity(fc / 10, 'Hz', 3)})" if c.crossover is not None
                     else "never crosses 0 dB")
            notes.append(f"{c.description}: the loop {where}: no phase or delay margin to "
                         "report")

    if simulation is None:
        notes.append("no simulation: no hunting boundary, end-stop clearance or static error")
    else:
        st = simulation.stage[own]
        m = st.hunting_free_from
        if not pid.controller.integrator:
            notes.append("the loop has no integrator: it cannot hunt by the paper's mechanism, "
                         "so there is no hunting-free crossover to keep a distance from")
        elif m is None and st.boundary is not None and st.boundary.kind == "not_found":
            notes.append(f"no crossover from which no move of the stage as specified hunts "
                         f"was found ({st.boundary.note}): no crossover factor")
        elif m is None:
            top = simulation.min_hunting_free_crossover["search"][1]
            notes.append(f"the stage as specified hunts for some move up to the top of the "
                         f"search ({quantity(top, 'Hz', 6)}): no crossover factor")
        else:
            out["hunting_free_crossover"] = m
            out["crossover_factor"] = fc / m
            out.update(_hunting_loop(model, crossover, st, m))
            if st.boundary is not None and st.boundary.kind == "bound":
                out["crossover_factor_bound"] = True
                notes.append(f"no move of the family hunts from {quantity(m, 'Hz', 6)}, the bottom "
                             "of the search: the crossover factor is a lower bound")
        if st.static_error_bound is not None and st.outcome in ("static_error", "stuck"):
            rest = [abs(mv.final_error) for mv in st.moves
                    if mv.outcome in ("settles", "rests", "stuck")]
            out["static_error"] = max(rest) if rest else 0.0
            out["static_error_bound"] = st.static_error_bound
        land = simulation.landing
        if model.has_isolator and land is not None and math.isfinite(land.deflection):
            out["resting_deflection"] = land.deflection
            out["end_stop_clearance"] = land.clearance(0.0 if flexure is None else flexure.sag)
    if model.has_isolator:
        out["stiffness_factor"] = stiffness.maximum / stiffness.chosen
        if flexure is not None and flexure.feasible:
            lo, hi = flexure.stiffness_range
            out["stiffness_range"] = (lo, hi)
            out["stiffness_factor_worst"] = stiffness.maximum / hi
            if hi > stiffness.maximum * (1 + 1e-9):
                top, kmax = quantities((hi, stiffness.maximum), "N/m", 4)
                notes.append(
                    f"leaves at the thick end of the stock's tolerance reach k = {top}, above "
                    f"k_max = {kmax}: at full stroke such a flexure pushes the cart with more "
                    "than Fs = k_max s; the robustness study draws k within that tolerance, "
                    "and its samples at the thick end answer for them")
            out["thickness"] = flexure.thickness
            out["thickness_tolerance"] = flexure.thickness_tolerance
    else:
        notes.append("no isolator in the spec: no end-stop clearance or stiffness margin (the "
                     "isolator the design simulates for comparison is not the hardware)")
    return Margins(notes=tuple(notes), **out)


# --------------------------------------------------------------------------- recommendation


def recommendation(search: Any) -> Recommendation:
    """The design's recommendation from the design search (:func:`fi_design.recommend.recommend`).

    Parameters
    ----------
    search : fi_design.results.recommend.RecommendResult
        The search.

    Returns
    -------
    Recommendation
    """
    return Recommendation(text=search.advice, isolator=search.isolator,
                          crossover=search.crossover, feasible=search.feasible, search=search)


# --------------------------------------------------------------------------- statements


def friction_gap_judged(gap: FrictionGapResult, stage: Any, integrator: bool
                        ) -> FrictionGapResult:
    """Step 1 once the stage is simulated: a screening rule, the stage-level answer decides.

    The threshold (``requirements.friction_gap``, 1 N by default) is the
    paper's rule for its own stage. Once every move of the family is
    simulated, step 1 no longer passes or warns on its own: its check becomes
    INFO and names what the simulation found, so it never reads as a pass
    (or a risk) that the same report refutes.

    Parameters
    ----------
    gap : FrictionGapResult
        Step 1 before the simulation.
    stage : fi_design.results.stage.StageHunting
        The stage-level answer of the spec's own plant.
    integrator : bool
        Whether the loop integrates.

    Returns
    -------
    FrictionGapResult
        The same values with the check re-worded (status INFO).
    """
    c = gap.checks[0]
    where = ("at or above" if gap.hunting_risk else "below")
    if gap.hunting_risk and not integrator:
        rule = "stick-slip can make an integrating controller hunt, but this loop has none"
    elif gap.hunting_risk:
        rule = "stick-slip can make an integrating controller hunt"
    else:
        rule = "stick-slip, and so hunting, is less likely"
    msg = (f"Fs - Fc = {quantity(gap.gap, 'N', 3)} is {where} the "
           f"{quantity(gap.threshold, 'N', 3)} threshold, the "
           f"paper's rule of thumb for its own stage: {rule}; a screening rule, not a "
           f"requirement: the simulation of every move decides, and the stage as specified "
           f"{stage.summary()}")
    return replace(gap, checks=(replace(c, passed=None, status=Status.INFO, message=msg),)
                   + gap.checks[1:])


def simulation_sentence(sim: Confirmation) -> str:
    """The conclusion's sentences on the simulated stage, the spec's own plant first.

    Parameters
    ----------
    sim : Confirmation
        The simulated confirmation.

    Returns
    -------
    str
        Each plant's stage-level answer and how the hunting-free crossover was found.
    """
    if sim.suggested_isolator:
        own, other = "non_isolated", "isolated"
        labels = ("The stage as specified, without isolator,",
                  "with the rule's first isolator (simulated for comparison, not the "
                  "hardware) it")
        names = ("as specified", "with that isolator")
    else:
        own, other = "isolated", "non_isolated"
        labels = ("The isolated stage as specified", "without the isolator it")
        names = ("as specified", "without the isolator")
    fm = "LuGre" if sim.isolated.friction_model == "lugre" else sim.isolated.friction_model
    text = (f" Simulated with {fm} friction after every move of its family: "
            + sim.stage[own].describe(labels[0]) + "; "
            + sim.stage[other].describe(labels[1]) + ".")
    bounds = [f"{name}, {sim.stage[key].boundary_text()}"
              for key, name in zip((own, other), names) if sim.stage[key].boundary is not None]
    if bounds:
        text += " The lowest crossover from which no move hunts: " + "; ".join(bounds) + "."
    elif sim.stage[own].static_error_bound is not None:
        text += (" The loop has no integrator: no crossover bounds hunting, so none is "
                 "computed.")
    if not sim.models_agree:
        text += " The other friction model disagrees on the spec's own move (see the checks)."
    return text


def simulated_isolator_advice(spec: Any, gap: Any, simulation: Confirmation, rule: str,
                              isolator: tuple[float, float, float]) -> Any:
    """For a stage without isolator, once simulated: is one needed, and is the rule's a start.

    The advice reads the judged stage-level answers, so it never advises what the same
    report shows failing: not needed when the stage as specified comes to rest after every
    move; needed otherwise, starting from the rule's isolator (simulated beside it) when every
    move comes to rest with it, else from the design search (``fi-design recommend``).

    Parameters
    ----------
    spec : fi_design.spec.Spec
        The spec (its file names the command of the design search).
    gap : FrictionGapResult
        Step 1.
    simulation : Confirmation
        The simulated confirmation.
    rule : str
        The rule's isolator in words.
    isolator : (float, float, float)
        Its stroke [m], stiffness [N/m] and k_max [N/m].

    Returns
    -------
    fi_design.results.design.IsolatorAdvice
    """
    from ..results.design import IsolatorAdvice

    own, iso = simulation.stage["non_isolated"], simulation.stage["isolated"]
    if own.acceptable:
        return IsolatorAdvice(False, (
            f"the stage as specified {own.summary()}: no isolator is needed at "
            "this crossover" + (f", whatever the {quantity(gap.gap, 'N', 3)} friction gap "
                                "of step 1 suggests" if gap.hunting_risk else "")), *isolator)
    if iso.acceptable:
        return IsolatorAdvice(True, (
            f"the stage as specified {own.summary()}; with {rule} it "
            f"{iso.summary()}: an isolator is needed, and that one is a start"), *isolator)
    return IsolatorAdvice(True, (
        f"the stage as specified {own.summary()}, and {rule} {iso.summary()} too: an "
        "isolator is needed, but not that one; the design search looks for one that "
        f"passes ({recommend_command(spec)})"), *isolator)


# --------------------------------------------------------------------------- verdict


_BEHAVIOUR = {
    "settles": "settles after every move",
    "hunts": "hunts",
    "stuck": "sticks away from its target",
    "undetermined": "cannot be judged",
    "static_error": "rests within its static error after every move",
}


def _behaviour_reason(st: Any, label: str) -> Reason:
    """The verdict's reason on the plant's stage-level answer (every move of its family)."""
    text = st.describe(label) + "."
    if st.outcome == "settles":
        return Reason("PASS", "simulation", text + " No move ends in a hunting cycle.")
    if st.outcome == "static_error":
        return Reason("PASS", "simulation", text + " Every rest is the loop's static error, "
                                                   "and without an integrator the stage "
                                                   "cannot hunt by the paper's mechanism.")
    return Reason("FAIL", "simulation", text[0].upper() + text[1:])


def judge(model: Model, checks: Sequence[Check], warnings: Sequence[tuple[str, str]],
          simulation: Confirmation | None, robustness: RobustnessCheck | None,
          margin: Margins, not_valid: str | None = None) -> Verdict:
    """The verdict on the hardware as specified.

    Parameters
    ----------
    model : Model
        The resolved model.
    checks : sequence of Check
        Every check of the four steps and the confirmation.
    warnings : sequence of (path, message)
        Warnings on the spec's values (:func:`fi_design.spec.warnings_for`).
    simulation : Confirmation or None
        The nonlinear confirmation (None: not run).
    robustness : RobustnessCheck or None
        The robustness check (None: not run).
    margin : Margins
        From :func:`margins`.
    not_valid : str, optional
        :func:`linear_loop_note`: the simulated stage's and the scatter's passing
        answers become warnings with this clause.

    Returns
    -------
    Verdict
    """
    own = _OWN[model.has_isolator]
    fc = model.crossover
    label = ("The isolated stage as specified" if model.has_isolator
             else "The stage as specified (without isolator)")
    reasons: list[Reason] = []
    behaviour = None
    judged_check = f"simulation_{own}"
    if simulation is not None:
        st = simulation.stage[own]
        behaviour = st.outcome
        reasons.append(_behaviour_reason(st, label))
    for c in checks:
        if c.status == Status.FAIL and c.name not in (judged_check, "robustness"):
            reasons.append(Reason("FAIL", c.name, f"{c.step}: {c.message}."))
    if robustness is not None:
        r = robustness
        kinds = ("hunting", "stuck", "undetermined") if model.law.integrator else \
            ("hunting", "undetermined")
        why = ", ".join(f"{r.counts[k]} {'hunt' if k == 'hunting' else k}"
                        for k in kinds if r.counts[k])
        what = (f"Under friction scatter of {_scatter_words(r)} the stage as specified does not "
                f"settle after every move in {_pct(r.hunting_probability)} of {r.valid} valid "
                f"samples ({percent(r.confidence, 3)} interval {_pct(r.interval[0])} to "
                f"{_pct(r.interval[1])}" + (f"; {why}" if why else "") + ")")
        left = r.counts["invalid"] + r.counts["failed"]
        notes = []
        if left:
            notes.append(f"{left} sample(s) are left out (a draw the spec refuses, Fs below Fc, "
                         "or a failed simulation)")
        tail = "".join(f" {n[0].upper()}{n[1:]}." for n in notes)
        if r.status == "FAIL":
            text = f"{what}, above the {_pct(r.limit)} limit.{tail}"
        elif r.status == "WARN" and r.hunting_probability is None:
            text = "No scatter sample simulated to the end: the robustness is unknown."
        elif r.status == "WARN" and r.interval[1] > r.limit:
            text = (f"{what}: at or below the {_pct(r.limit)} limit, but the interval reaches "
                    f"above it; more samples (requirements.robustness.samples) would show "
                    f"whether the limit holds.{tail}")
        else:
            text = f"{what}, within the {_pct(r.limit)} limit.{tail}"
        reasons.append(Reason(r.status, "robustness", text))
    elif simulation is not None:
        reasons.append(Reason("WARN", "robustness",
                              "The robustness check did not run (requirements.robustness."
                              "samples: 0, or no scatter): behaviour under friction scatter "
                              "is unknown."))
    clearance = margin.end_stop_clearance
    if clearance is not None and margin.resting_deflection and clearance > 0:
        d = abs(margin.resting_deflection)
        sag = model.joint.stroke - d - clearance  # the weight's share (a vertical drive axis)
        weight = f", with a sag of {quantity(sag, 'm', 3)} under the cart's weight" \
            if sag > 1e-9 * model.joint.stroke else ""
        rise = (d + clearance) / d - 1.0
        spread = model.requirements.robustness.coulomb
        if rise <= spread:
            reasons.append(Reason(
                "WARN", "end_stop_clearance",
                "The cart rests {} from its end stop (joint deflection {} of the \u00b1{} "
                "stroke{}): a friction force ".format(*quantities(
                    (clearance, margin.resting_deflection, model.joint.stroke), "m", 3), weight)
                + f"{percent(rise, 2)} higher would put it on the limiter, within the "
                f"\u00b1{percent(spread)} scatter of Fc."))
    if not_valid is not None:  # what the simulation shows passing does not hold here
        reasons = [Reason("WARN", r.source, f"{r.text.rstrip('.')}; {not_valid}.")
                   if r.severity == "PASS" and r.source in ("simulation", "robustness") else r
                   for r in reasons]
    for c in checks:
        if c.status == Status.WARN and c.name not in ("robustness", judged_check):
            reasons.append(Reason("WARN", c.name, f"{c.step}: {c.message}."))
    for path, message in warnings:
        reasons.append(Reason("WARN", "input", f"{path}: {message}."))
    if simulation is None:
        reasons.append(Reason("WARN", "confirmation",
                              "Not confirmed by simulation: whether the stage hunts, sticks "
                              "or settles, and its robustness, are unchecked."))
    fails = [c for c in checks if c.status == Status.FAIL]
    if not fails:
        passes = sum(c.status == Status.PASS for c in checks)
        reasons.append(Reason("PASS", "checks", f"No check fails ({passes} pass)."))
    order = {"FAIL": 0, "WARN": 1, "PASS": 2}
    reasons.sort(key=lambda r: order[r.severity])
    status = ("FAIL" if any(r.severity == "FAIL" for r in reasons) else
              "NOT_CONFIRMED" if simulation is None else
              "PASS_WITH_WARNINGS" if any(r.severity == "WARN" for r in reasons) else "PASS")
    nwarn = sum(r.severity == "WARN" for r in reasons)
    what = (f"{label} {_BEHAVIOUR.get(behaviour, behaviour)} at {quantity(fc, 'Hz', 4)}"
            if behaviour is not None else f"{label} was not simulated")
    if behaviour is not None and not_valid is not None:
        what += (" in the simulation, which leaves out the parasitic modes with which step 2 "
                 "finds the loop unstable")
    if behaviour == "hunts":
        st = simulation.stage[own]
        c = st.cycle
        what += (f" ({len(st.hunting_moves)} of {len(st.moves)} moves"
                 + (f", a {quantity(c.amplitude, 'm', 3)} cycle of "
                    f"{quantity(c.period, 's', 3)})" if c else ")"))
    steps = {c.name: c.step for c in checks}
    on = []
    for r in reasons:
        word = _SOURCES.get(r.source) or _STEP_WORDS.get(steps.get(r.source, ""),
                                                        steps.get(r.source) or r.source)
        if r.severity == "FAIL" and word not in on:
            on.append(word)
    warned = _warnings_words([r for r in reasons if r.severity == "WARN"], steps)
    listed = ", ".join(on[:-1]) + " and on " + on[-1] if len(on) > 1 else "".join(on)
    tail = {"FAIL": f"It fails on {listed}" + (f"; {warned}" if nwarn else ""),
            "PASS_WITH_WARNINGS": f"Nothing fails; {warned}",
            "NOT_CONFIRMED": "Nothing of the linear steps fails, but without the simulation "
                             "it does not pass" + (f"; {warned}" if nwarn > 1 else ""),
            "PASS": "Nothing fails, nothing to review"}[status]
    return Verdict(status=VerdictStatus(status), reasons=tuple(reasons), plant=own,
                   behaviour=behaviour, headline=f"{what}. {tail}.",
                   next_step=_next_step(model) if status == "FAIL" else "")


def _warnings_words(warned: Sequence[Reason], steps: dict) -> str:
    """``"3 warnings to review (1 check, 2 on the spec's values)"``: counted as the checks
    table and the reasons count them."""
    n = len(warned)
    checks = sum(r.source in steps for r in warned)
    inputs = sum(r.source == "input" for r in warned)
    parts = [f"{k} {word}{'s' if k != 1 else ''}" for k, word in
             ((checks, "check"), (inputs, "on the spec's value")) if k]
    others = [r.source for r in warned if r.source not in steps and r.source != "input"]
    parts += [f"1 on {_OTHER_WORDS.get(s, s.replace('_', ' '))}" for s in others]
    return (f"{n} warning{'s' if n != 1 else ''} to review"
            + (f" ({', '.join(parts)})" if parts else ""))


def recommend_command(spec: Any) -> str:
    """The design search as a command on this spec: ``fi-design recommend PATH --write-spec
    OUT.yaml`` (``SPEC.yaml`` for a spec not read from a file)."""
    from ..spec.file import origin

    import os

    org = origin(spec)
    if org is None or org.path is None:
        path = "SPEC.yaml"
    else:  # as a command in the working directory: relative below it, absolute elsewhere
        rel = os.path.relpath(os.path.abspath(org.path))
        path = str(org.path) if rel.startswith("..") else rel
    return f"fi-design recommend {path} --write-spec OUT.yaml"


def _next_step(model: Model) -> str:
    """What to run after a FAIL: the design search, with this spec's path."""
    return (f"{recommend_command(model.spec)} runs the design search and writes its design "
            "into a copy of the spec")


#: Warnings that are neither a check nor a spec value, as the headline counts them.
_OTHER_WORDS = {"end_stop_clearance": "the end-stop clearance",
                "robustness": "friction scatter", "confirmation": "the missing simulation"}


#: The guideline steps as a FAIL headline names them (never a check's internal name).
_STEP_WORDS = {
    "step 1 friction gap": "step 1 (the friction gap)",
    "step 2 crossover": "step 2 (the crossover and the loop's margins)",
    "step 3 drive stiffness": "step 3 (the drive stiffness)",
    "step 3 flexure": "step 3 (the leaf-spring guide)",
    "step 4 PID": "step 4 (the PID)",
    "simulation (paper section 2.3)": "the simulation",
    "step 3 refinement: landing": "where the cart comes to rest",
    "positioning": "positioning (requirements.positioning)",
}


#: Sources of reasons in the headline's words (others: the check's name).
_SOURCES = {"simulation": "the simulation of its moves",
            "robustness": "friction scatter", "confirmation": "the missing simulation"}
