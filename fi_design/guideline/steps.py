"""The four-step design guideline (paper section 4) and its result.

Each step is a function of the spec returning a frozen result that carries its
checks (:class:`~fi_design.results.Check`):

1. :func:`step1_friction_gap` -- is ``Fs - Fc`` above ``requirements.friction_gap``?
   Then stick-slip, and with an integrator hunting, is a risk.
2. :func:`step2_crossover` -- the desired crossover against the achievable one
   (the highest crossover at which all linear limit cases keep the required
   margins and the parasitic modes stay ``parasitic_separation`` times above
   it), with the margins of each limit case at the desired crossover.
3. :func:`step3_stiffness` -- ``k_max = Fs / (stiffness_safety * stroke)``, the
   chosen stiffness (given, or proposed as ``k_max / 2``) checked against it;
   :func:`step3_flexure` sizes a leaf-spring guide when the spec asks for one.
4. :func:`step4_pid` -- the PID gains from the tuning mass and the crossover.

Without an isolator in the spec, :func:`isolator_advice` says whether one
looks needed and which stroke and stiffness to start from.
:func:`fi_design.guideline.evaluate.evaluate` runs the four steps, the
confirmation and the verdict.

The linear analysis (python-control) is imported inside the step functions,
so importing this module stays fast.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Sequence


from ..controller import discrete_controller, drive_gains
from ..display import number, quantity
from ..effects import delay_words, simulated_only
from ..model import Model, require_model
from ..results import Check, Status
from ..results.controller import ControlLaw
from ..results.stage import STATIC_ERROR_FORMULA
from ..results.design import (Confirmation, CrossoverResult, DesignResult, FlexureResult,
                              FrictionGapResult, IsolatorAdvice, ModeSeparation, NotchSuggestion,
                              PidResult, StiffnessResult)
from ..spec import proposed_stiffness, stiffness_limit
from .verdict import friction_gap_judged

__all__ = [
    "SUGGESTED_STROKE", "FrictionGapResult", "ModeSeparation", "CrossoverResult",
    "StiffnessResult", "PidResult", "IsolatorAdvice", "DesignResult", "step1_friction_gap",
    "step2_crossover", "step3_stiffness", "step3_flexure", "step4_pid", "isolator_advice",
    "friction_gap_judged", "controller_words", "notch_words",
]

log = logging.getLogger(__name__)

#: Stroke suggested for a first isolator design [m]: the paper's 0.3 mm.
SUGGESTED_STROKE = 0.3e-3


def _g(x: float | None, digits: int = 4) -> str:
    """A number as every table prints it (:func:`fi_design.display.number`)."""
    return number(x, digits)


# --------------------------------------------------------------------------- step 1


def step1_friction_gap(model: Model) -> FrictionGapResult:
    """Guideline step 1: compare Fs - Fc with ``requirements.friction_gap``.

    Parameters
    ----------
    model : fi_design.model.Model
        The resolved model (:func:`fi_design.model.resolve`).

    Returns
    -------
    FrictionGapResult
        The gap [N], the threshold [N] and whether hunting is a risk. The
        check is PASS below the threshold. At or above it, it is WARN (a
        risk, not a design error) for an integrating loop on a stage without
        isolator, and INFO where the spec answers the risk: with an isolator
        (what it is there for; the simulation confirms it) or with a loop
        without integrator (no hunting by the paper's mechanism).
    """
    model = require_model(model)
    f = model.friction
    gap = f.Fs - f.Fc
    thr = model.requirements.friction_gap
    risk = gap >= thr
    status = Status.PASS
    if risk:
        msg = (f"Fs - Fc = {quantity(gap, 'N', 3)} is at or above the {quantity(thr, 'N', 3)} "
               "threshold: stick-slip can make an integrating controller hunt")
        if not model.law.integrator:
            status = Status.INFO
            msg += "; this loop has no integrator"
        elif model.has_isolator:
            status = Status.INFO
            msg += "; the isolator is there to prevent it (the simulation checks it)"
        else:
            status = Status.WARN
    else:
        msg = (f"Fs - Fc = {quantity(gap, 'N', 3)} is below the {quantity(thr, 'N', 3)} threshold: "
               "stick-slip, and so hunting, is unlikely")
    check = Check("friction_gap", not risk if status != Status.INFO else None, gap, thr, "N",
                  msg, step="step 1 friction gap", status=status)
    return FrictionGapResult(static=f.Fs, coulomb=f.Fc, gap=gap, threshold=thr,
                             hunting_risk=risk, checks=(check,))


# --------------------------------------------------------------------------- step 2


def step2_crossover(model: Model) -> CrossoverResult:
    """Guideline step 2: desired versus achievable crossover.

    The limit cases use the model's joint stiffness (the proposed one when the
    spec gives none, as step 3 would choose).

    Parameters
    ----------
    model : fi_design.model.Model
        The resolved model (:func:`fi_design.model.resolve`).

    Returns
    -------
    CrossoverResult
        Achievable crossover and its limit, per-case margins at the desired
        crossover, the parasitic separation, and the checks: one reachability
        check, phase and gain margin (and modulus margin if required) per case,
        one separation check per parasitic mode. The margin checks take the
        judgement of each case's requirements as the linear analysis made it
        (:attr:`fi_design.results.linear.CaseMargins.criteria`).
    """
    from ..loop import linear
    from ..loop.achievable import achievable_crossover
    from ..loop.notch import limiting_mode, notched, with_notch

    model = require_model(model)
    req = model.requirements
    fc = model.crossover
    cases = linear.limit_cases(model)
    at = linear.analyse(model, cases=cases)
    ach = achievable_crossover(model)
    mode = limiting_mode(model, ach)
    suggestion = None
    limited_by = ach.limited_by
    if mode is not None and ach.kind == "margin":
        limited_by = (f"{ach.limited_by}, caused by the parasitic mode '{mode.name}' "
                      f"({quantity(mode.frequency, 'Hz', 4)}, {mode.source}): without that mode "
                      "the case keeps its margins")
        if not notched(model, mode):  # a notch there already: another would not be the advice
            notch, alt = with_notch(model, mode)
            if alt.frequency is not None and alt.frequency > ach.frequency:
                suggestion = NotchSuggestion(notch=notch, achievable=alt.frequency,
                                             limited_by=alt.limited_by, limit_kind=alt.kind)
    step = "step 2 crossover"
    checks: list[Check] = []
    reach = ach.frequency is not None and fc <= ach.frequency * (1 + 1e-9)
    if ach.frequency is None:
        msg = f"no crossover is achievable: {limited_by}"
    elif ach.kind == "scan_limit":
        msg = (f"the desired crossover {quantity(fc, 'Hz', 4)}: the linear model limits the "
               f"crossover nowhere below {quantity(ach.frequency, 'Hz', 4)}, the search cap (a "
               "bound, not a result; the hardware's sampling, delay and parasitic modes set the "
               "real limit)")
    elif reach:
        msg = (f"the desired crossover {quantity(fc, 'Hz', 4)} is at or below the achievable "
               f"{quantity(ach.frequency, 'Hz', 4)} (limited by {limited_by})")
    else:
        msg = (f"the desired crossover {quantity(fc, 'Hz', 4)} is above the achievable "
               f"{quantity(ach.frequency, 'Hz', 4)} (limited by {limited_by})")
    if suggestion is not None:
        msg += f"; {notch_words(suggestion)}"
    checks.append(Check("crossover_achievable", reach, fc, ach.frequency, "Hz", msg, step=step))

    for c in at.cases:
        where = f"case {linear.CASE_NUMBERS[c.name]} ({c.description})"
        at_f = f" at {quantity(c.crossover, 'Hz', 3)}" if c.crossover is not None else ""
        if not c.stable:
            msg = f"{where}: the closed loop is unstable"
        elif not c.in_band:
            msg = (f"{where}: " + ("the loop crosses 0 dB only at "
                                   f"{quantity(c.crossover, 'Hz', 3)}, more than "
                                   f"{number(linear.BAND_FACTOR, 6)}x below the "
                                   f"{quantity(fc, 'Hz', 4)} crossover (the integrator against "
                                   "a stiff support)"
                                   + (f": its phase margin there, "
                                      f"{number(c.phase_margin_deg, 3)} deg, lies outside the "
                                      "loop's band and is not judged"
                                      if math.isfinite(c.phase_margin_deg) else
                                      ": no phase margin in the loop's band")
                                   if c.crossover is not None else "the loop never crosses "
                                   "0 dB: no phase margin in the loop's band"))
        else:
            msg = f"{where}: phase margin {number(c.phase_margin_deg, 3)} deg{at_f}"
        checks.append(_criterion_check(c, "phase margin", f"phase_margin.{c.name}",
                                       c.phase_margin_deg, req.phase_margin, "deg", msg, step))
        checks.append(_gain_margin_check(c, where, req.gain_margin, step))
        if req.modulus_margin is not None:
            checks.append(_criterion_check(
                c, "modulus margin", f"modulus_margin.{c.name}", c.modulus_margin,
                req.modulus_margin, "-",
                f"{where}: modulus margin min|1 + L| = {number(c.modulus_margin, 3)}", step))

    modes = []
    sep = req.parasitic_separation
    loop_fc = fc if at.loop_crossover is None else at.loop_crossover
    if at.loop_crossover is None:
        which = "the desired crossover (no case crosses 0 dB in the loop's band)"
    else:
        which = (f"the loop's crossover, {quantity(loop_fc, 'Hz', 4)} (case "
                 f"{linear.CASE_NUMBERS[at.loop_crossover_case]}, "
                 f"{linear.CASE_DESCRIPTIONS[at.loop_crossover_case]}, crosses 0 dB highest)")
    for m in model.modes:
        need = sep * loop_fc
        ok = m.frequency >= need
        modes.append(ModeSeparation(m.name, m.frequency, need, m.collocated, ok,
                                    source=m.source, direction=m.direction,
                                    coupling=m.coupling))
        if m.source == "given":  # a computed mode is judged with its guide (step 3)
            checks.append(Check(
                f"parasitic_separation.{m.name}", ok, m.frequency, need, "Hz",
                f"parasitic mode '{m.name}' (given) at {quantity(m.frequency, 'Hz', 4)} "
                + ("lies above" if ok else "lies below")
                + f" {number(sep, 6)} x {which}: {quantity(need, 'Hz', 4)}", step=step))

    return CrossoverResult(
        desired=fc, achievable=ach.frequency, limited_by=limited_by, limit_kind=ach.kind,
        limiting_case=ach.case, feasible_ranges=ach.feasible_ranges, delay=at.delay,
        stiffness=at.stiffness, cases=at.cases, parasitic_modes=tuple(modes),
        loop_crossover=at.loop_crossover, loop_crossover_case=at.loop_crossover_case,
        limiting_mode=None if mode is None else mode.name,
        limiting_mode_frequency=None if mode is None else mode.frequency, notch=suggestion,
        checks=tuple(checks))


def notch_words(n: NotchSuggestion) -> str:
    """What a notch at the limiting mode would allow, in words."""
    head = f"a {n.notch.describe()} in controller.filters would "
    if n.achievable is None:
        return head + f"not help: {n.limited_by}"
    return head + f"allow {quantity(n.achievable, 'Hz', 4)} (then limited by {n.limited_by})"


def _gain_margin_check(case, where: str, required: float, step: str) -> Check:
    """The gain-margin check of a limit case, its value the signed margin [dB].

    The requirement is a distance from instability of ``required`` dB either way
    (:func:`fi_design.loop.linear.analyse` judges ``|gain_margin_db|``): an upper
    margin is held against ``+required``; the lower margin of a stable, conditionally
    stable loop against ``-required`` (it must lie at or below it, shown ``≤``); the
    margin of an unstable loop, negative (:attr:`~fi_design.results.linear.CaseMargins.gain_margin_db`),
    against ``+required``, which it fails.
    """
    gm = case.gain_margin_db
    limit = required
    if math.isinf(gm):
        msg = f"{where}: the phase never crosses -180 deg, unlimited gain margin"
    elif not case.stable:
        msg = f"{where}: the closed loop is unstable (gain margin {number(gm, 3)} dB)"
    elif gm < 0:
        limit = -required
        msg = (f"{where}: gain margin {number(gm, 3)} dB (a lower margin: the loop goes "
               f"unstable if the gain falls {number(abs(gm), 3)} dB)")
    else:
        msg = f"{where}: gain margin {number(gm, 3)} dB"
    return _criterion_check(case, "gain margin", f"gain_margin.{case.name}", gm, limit, "dB",
                            msg, step)


def _criterion_check(case, criterion: str, name: str, value, limit, unit: str, message: str,
                     step: str) -> Check:
    """A check of one requirement of a limit case, judged as the linear analysis judged it."""
    status = case.criteria[criterion]
    passed = None if status == Status.INFO else status == Status.PASS
    return Check(name, passed, value, limit, unit, message, step=step, status=status)


# --------------------------------------------------------------------------- step 3


def step3_stiffness(model: Model) -> StiffnessResult:
    """Guideline step 3: maximum drive stiffness from static friction and stroke.

    ``k_max = Fs / (stiffness_safety * stroke)``: at full stroke the flexure must
    push the cart with less than static friction, or the joint cannot keep the
    cart still while the stage settles. Lower is better for hunting; the
    flexure's parasitic frequencies bound how low (step 3 flexure sizing).

    Parameters
    ----------
    model : fi_design.model.Model
        The resolved model (:func:`fi_design.model.resolve`). Without an isolator the
        suggested stroke (:data:`SUGGESTED_STROKE`) is used and the result is
        a suggestion.

    Returns
    -------
    StiffnessResult
        k_max, the chosen stiffness and why, with a check chosen <= k_max.
    """
    model = require_model(model)
    spec = model.spec
    Fs = model.friction.Fs
    safety = model.requirements.stiffness_safety
    step = "step 3 drive stiffness"
    if model.joint is None:
        s = SUGGESTED_STROKE
        kmax = stiffness_limit(spec, s)
        k = proposed_stiffness(spec, s)
        msg = (f"no isolator in the spec; for a {quantity(s, 'm', 3)} stroke (the paper's) the "
               f"rule gives k_max = {_g(kmax)} N/m and k = k_max / 2 = {_g(k)} N/m: the isolator "
               "simulated beside the stage for comparison")
        check = Check("drive_stiffness", None, k, kmax, "N/m", msg, step=step)
        return StiffnessResult(maximum=kmax, chosen=k, source="suggested: k_max / 2 for the "
                               "paper's 0.3 mm stroke (no isolator in the spec)", stroke=s,
                               static=Fs, safety=safety, force_at_stroke=k * s, suggested=True,
                               checks=(check,))
    s = model.joint.stroke
    kmax = stiffness_limit(spec, s)
    k = model.joint.stiffness
    iso = spec.isolator
    drawn = (iso is not None and iso.stiffness is None and iso.flexure is not None
             and iso.flexure.drawn and "isolator.stiffness" not in model.changed)
    if drawn:
        source = "the flexure guide as drawn (isolator.flexure), net of gravity"
    elif model.joint.stiffness_given:
        source = "given in the spec (isolator.stiffness)"
    else:
        source = ("proposed: k_max / 2, so the flexure force at full stroke is Fs / 2, leaving "
                  "room for friction scatter")
    ok = 0.0 < k <= kmax * (1 + 1e-12)
    per = "stroke" if safety == 1 else f"({number(safety, 6)} x stroke)"
    rule = f"k_max = Fs / {per} = {_g(kmax)} N/m"
    if k <= 0.0:
        msg = (f"k = {_g(k)} N/m ({source.split(':')[0].split(' (')[0]}) is not positive: "
               f"the joint has no drive stiffness left to centre the cart ({rule})")
    else:
        msg = (f"k = {_g(k)} N/m ({source.split(':')[0].split(' (')[0]}) "
               + ("is at or below " if ok else "exceeds ") + rule
               + f"; flexure force at full stroke {quantity(k * s, 'N', 3)} against "
                 f"Fs = {quantity(Fs, 'N', 3)}")
    check = Check("drive_stiffness", ok, k, kmax, "N/m", msg, step=step)
    return StiffnessResult(maximum=kmax, chosen=k, source=source, stroke=s, static=Fs,
                           safety=safety, force_at_stroke=k * s, suggested=False,
                           checks=(check,))


def step3_flexure(model: Model,
                  stiffness: StiffnessResult | None = None) -> FlexureResult | None:
    """Guideline step 3, second half: the isolator's leaf-spring guide as a mechanism.

    Parameters
    ----------
    model : fi_design.model.Model
        The resolved model (:func:`fi_design.model.resolve`).
    stiffness : StiffnessResult, optional
        Unused; kept for callers that pass step 3's stiffness result.

    Returns
    -------
    FlexureResult or None
        None when the spec has no ``isolator.flexure`` section; else the guide
        the spec draws, or the one sized for the joint's stiffness and stroke
        (:attr:`fi_design.model.Model.flexure`): six stiffnesses, gravity,
        stress and modes.
    """
    return require_model(model).flexure


# --------------------------------------------------------------------------- step 4


def controller_words(c: ControlLaw, effects: Sequence = ()) -> str:
    """The structure of a controller in words (D input, roll-off, sampling, delay, filters);
    ``effects``, the spec's effect entries, add a ``time_delay`` effect's delay to the
    loop's (:func:`fi_design.effects.delay_words`)."""
    parts = [f"D on the {c.derivative_on}",
             "ideal D" if math.isinf(c.roll_off) else
             f"D roll-off {_g(c.roll_off / (2 * math.pi))} Hz"]
    parts.append("continuous" if c.sample_period == 0 else
                 f"sampled at {quantity(1.0 / c.sample_period, 'Hz')}")
    parts.append(delay_words(c.delay, effects))
    parts += [f.describe() for f in c.filters]
    return ", ".join(parts)


def step4_pid(model: Model) -> PidResult:
    """Guideline step 4: PID gains from the moving mass and the desired crossover.

    With the hardware's own gains (``controller.gains``) the loop uses them;
    the rule's gains at the crossover the hardware achieves are shown beside
    them, in the same form, as the recommendation.

    Parameters
    ----------
    model : fi_design.model.Model
        The resolved model (:func:`fi_design.model.resolve`).

    Returns
    -------
    PidResult
        The gains and the loop's controller, with an informational check;
        tuning on the stage mass alone gives a WARN (the paper found the
        maximum moving mass best); a loop without integrator an INFO with its
        static error bound (Fs + |offset|) / kp (no hunting by the paper's
        mechanism; :attr:`fi_design.model.Model.static_error_bound`).
    """
    model = require_model(model)
    ctl = model.spec.controller
    law = model.law
    g = law.rule
    step = "step 4 PID"
    simulated = simulated_only(model.effects)
    simulated = f"; {simulated}" if simulated else ""
    if law.source == "rule":
        msg = (f"tuned at {_g(g.crossover)} Hz on {_g(g.tuning_mass)} kg; the gains a drive "
               f"takes (controller.gains, with controller.roll_off on the D term only): kp = "
               f"{_g(law.kp)} N/m, ki = {quantity(law.ki, 'N/(m*s)')}, kd = "
               f"{quantity(law.kd, 'N*s/m')} "
               f"({controller_words(law, model.effects)})")
        checks = [Check("pid", None, law.kp, None, "N/m", msg + simulated, step=step)]
    else:
        r = law.rule_in_this_form()
        msg = (f"the hardware's gains kp = {_g(law.kp)} N/m, ki = "
               f"{quantity(law.ki, 'N/(m*s)')}, kd = {quantity(law.kd, 'N*s/m')} "
               f"({controller_words(law, model.effects)}) cross over at "
               f"{quantity(law.crossover, 'Hz', 4)} on {quantity(law.tuning_mass, 'kg', 4)}; "
               f"the rule there would give kp = {_g(r['kp'])} N/m, ki = "
               f"{quantity(r['ki'], 'N/(m*s)')}, kd = {quantity(r['kd'], 'N*s/m')} with a D "
               f"roll-off of "
               f"{quantity(r['roll_off'] / (2 * math.pi), 'Hz', 4)}")
        # the rule's gains are a recommendation beside the hardware's, not a limit: they are in
        # the message and the gains table, never in the limit column
        checks = [Check("pid", None, law.kp, None, "N/m", msg + simulated, step=step)]
    static = model.static_error_bound
    if static is not None:
        checks.append(Check(
            "pid.integrator", None, static, None, "m",
            f"the loop has no integrator: no hunting by the paper's mechanism (integral action "
            f"building up through stiction), a static error instead, of up to "
            f"{STATIC_ERROR_FORMULA} = {quantity(static, 'm', 3)}: what static friction can "
            "hold against the loop", step=step))
    if ctl.tuning_mass == "stage" and model.has_isolator:
        checks.append(Check(
            "pid.tuning_mass", None, g.tuning_mass, model.total_mass, "kg",
            "tuned on the stage mass alone: with the limiter engaged the loop sees m1 + m2 and "
            "crosses over lower (the paper tunes on the maximum moving mass)", step=step,
            status=Status.WARN))
    discrete = discrete_controller(law)
    units = drive_gains(law, discrete)
    if units is not None:
        d = law.drive
        checks.append(Check(
            "pid.drive_units", None, units.kp, None, units.units["kp"],
            f"in the drive's units ({_g(d.motor_constant)} N/A, "
            f"{quantity(d.encoder_resolution, 'm')}"
            f" per count, a current unit of {_g(d.current_scaling)} A): kp = {_g(units.kp)} "
            f"{units.units['kp']}, ki = {_g(units.ki)} {units.units['ki']}, kd = {_g(units.kd)} "
            f"{units.units['kd']}", step=step))
    if discrete is not None:
        checks.append(Check(
            "pid.discrete", None, discrete.sample_rate, None, "Hz",
            f"sampled at {quantity(discrete.sample_rate, 'Hz')}: per sample kp = "
            f"{_g(discrete.kp)} N/m, integrator gain ki T/2 = {_g(discrete.integrator_gain)} N/m, "
            f"D recursion pole {_g(discrete.derivative_pole)} and gain "
            f"{_g(discrete.derivative_gain)} N/m"
            + (f"; {len(discrete.filters)} filter biquad(s) by the Tustin rule prewarped at "
               "their frequencies" if discrete.filters else ""), step=step))
    return PidResult(gains=g, tuning_rule=ctl.tuning_mass, derivative_ratio=ctl.derivative_ratio,
                     integrator_ratio=ctl.integrator_ratio, controller=law, static_error=static,
                     discrete=discrete, drive_gains=units,
                     checks=tuple(checks))


# --------------------------------------------------------------------------- no isolator


def suggested_isolator(model: Model) -> tuple[float, float]:
    """Stroke [m] and drive stiffness [N/m] to start from when the spec has no isolator.

    The paper's 0.3 mm stroke (:data:`SUGGESTED_STROKE`) and k = Fs / (2 x
    safety x stroke), half the maximum of step 3.
    """
    return SUGGESTED_STROKE, proposed_stiffness(require_model(model).spec, SUGGESTED_STROKE)


def isolator_advice(model: Model, gap: FrictionGapResult, crossover: CrossoverResult,
                    simulation: Confirmation | None = None) -> IsolatorAdvice:
    """For a stage without isolator: is one needed, and which one.

    Before the simulation the linear steps can only say whether one looks
    needed. Once the stage is simulated the advice reads the judged
    stage-level answers, so it never advises what the same report shows
    failing: the stage as specified, and the rule's first isolator
    (:func:`suggested_isolator`) simulated beside it.

    Parameters
    ----------
    model : fi_design.model.Model
        The resolved model (:func:`fi_design.model.resolve`) of a stage without isolator.
    gap : FrictionGapResult
        Step 1.
    crossover : CrossoverResult
        Step 2.
    simulation : Confirmation, optional
        The simulated confirmation (:func:`fi_design.stage.confirm.confirm`).

    Returns
    -------
    IsolatorAdvice
        Without simulation: needed when the friction gap is a hunting risk
        and the reachable crossover is limited, not needed below the gap
        threshold, undecided when the linear model sets no crossover limit.
        With it: not needed when the stage as specified comes to rest after
        every move; needed otherwise, starting from the rule's isolator when
        every move comes to rest with it, else from the design search's
        recommendation (``fi-design recommend``), the rule's isolator failing
        too.
    """
    model = require_model(model)
    s, k = suggested_isolator(model)
    kmax = stiffness_limit(model.spec, s)
    rule = (f"the rule's first isolator (a {quantity(s, 'm', 3)} stroke, the paper's, and k = "
            f"{_g(k)} N/m = Fs / (2 x stroke); k_max = {_g(kmax)} N/m)")
    if simulation is not None:
        from .verdict import simulated_isolator_advice

        return simulated_isolator_advice(model.spec, gap, simulation, rule, (s, k, kmax))
    start = f"{rule} is the one to simulate first"
    if not gap.hunting_risk:
        return IsolatorAdvice(False, f"the friction gap {quantity(gap.gap, 'N', 3)} is below the "
                              f"{quantity(gap.threshold, 'N', 3)} threshold: an isolator looks not "
                              "needed (the simulation decides)", s, k, kmax)
    if crossover.limit_kind == "scan_limit":
        return IsolatorAdvice(None, (
            f"the friction gap {quantity(gap.gap, 'N', 3)} is a hunting risk, but the linear "
            f"model limits the crossover nowhere up to {_g(crossover.achievable)} Hz: a high "
            "enough crossover may avoid hunting without an isolator (the paper needed about 3x "
            "the isolated crossover); add the loop delay to the spec and simulate to decide; "
            f"for an isolator, {start}"), s, k, kmax)
    return IsolatorAdvice(True, (
        f"the friction gap {quantity(gap.gap, 'N', 3)} is a hunting risk and the crossover is "
        f"limited to {_g(crossover.achievable)} Hz ({crossover.limited_by}): an isolator "
        f"looks needed (the simulation decides); {start}"), s, k, kmax)
