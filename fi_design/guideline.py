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

:func:`design` runs the four steps and returns a :class:`DesignResult`, whose
``to_dict()`` is the JSON contract of ``fi-design SPEC.yaml --json``. Without
an isolator in the spec, :func:`isolator_advice` says whether one looks needed
and which stroke and stiffness to start from.

:func:`design` also runs the nonlinear confirmation
(:func:`fi_design.confirm.confirm`) on the executor the caller passes, so that
its simulations overlap the linear analysis; it appears in JSON under
``simulation`` when it ran.

The linear analysis (python-control) is imported inside the step functions,
so importing this module stays fast.
"""

from __future__ import annotations

import hashlib
import logging
import math
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Mapping


from .controller import discrete_controller, drive_gains
from .errors import ArgumentError
from .display import number, quantity
from .mechanism.checks import flexure_checks
from .model import Model, as_model
from .results import Check, Status
from .results.controller import ControlLaw
from .results.stage import STATIC_ERROR_FORMULA
from .results.design import (Confirmation, CrossoverResult, DesignResult,
                             FlexureResult, FrictionGapResult, IsolatorAdvice, ModeSeparation,
                             NotchSuggestion, PidResult, StiffnessResult)
from .spec import Spec, proposed_stiffness, stiffness_limit, warnings_for
from .verdict import friction_gap_judged

if TYPE_CHECKING:  # pragma: no cover
    from .execution import Executor

__all__ = [
    "SUGGESTED_STROKE", "FrictionGapResult", "ModeSeparation", "CrossoverResult",
    "StiffnessResult", "PidResult", "IsolatorAdvice", "DesignResult", "step1_friction_gap",
    "step2_crossover", "step3_stiffness", "step3_flexure", "step4_pid", "isolator_advice",
    "friction_gap_judged", "design",
]

log = logging.getLogger(__name__)

#: Stroke suggested for a first isolator design [m]: the paper's 0.3 mm.
SUGGESTED_STROKE = 0.3e-3


def _g(x: float | None, digits: int = 4) -> str:
    """A number as every table prints it (:func:`fi_design.display.number`)."""
    return number(x, digits)


# --------------------------------------------------------------------------- step 1


def step1_friction_gap(model: Model | Spec) -> FrictionGapResult:
    """Guideline step 1: compare Fs - Fc with ``requirements.friction_gap``.

    Parameters
    ----------
    model : fi_design.model.Model or fi_design.spec.Spec
        The resolved model (a spec is resolved).

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
    model = as_model(model)
    f = model.friction
    gap = f.Fs - f.Fc
    thr = model.requirements.friction_gap
    risk = gap >= thr
    status = Status.PASS
    if risk:
        msg = (f"Fs - Fc = {gap:.3g} N is at or above the {thr:.3g} N threshold: stick-slip "
               "can make an integrating controller hunt")
        if not model.law.integrator:
            status = Status.INFO
            msg += "; this loop has no integrator"
        elif model.has_isolator:
            status = Status.INFO
            msg += "; the isolator is there to prevent it (the simulation checks it)"
        else:
            status = Status.WARN
    else:
        msg = (f"Fs - Fc = {gap:.3g} N is below the {thr:.3g} N threshold: stick-slip, and so "
               "hunting, is unlikely")
    check = Check("friction_gap", not risk if status != Status.INFO else None, gap, thr, "N",
                  msg, step="step 1 friction gap", status=status)
    return FrictionGapResult(static=f.Fs, coulomb=f.Fc, gap=gap, threshold=thr,
                             hunting_risk=risk, checks=(check,))


# --------------------------------------------------------------------------- step 2


def step2_crossover(model: Model | Spec) -> CrossoverResult:
    """Guideline step 2: desired versus achievable crossover.

    The limit cases use the model's joint stiffness (the proposed one when the
    spec gives none, as step 3 would choose).

    Parameters
    ----------
    model : fi_design.model.Model or fi_design.spec.Spec
        The resolved model (a spec is resolved).

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
    from . import linear
    from .notch import limiting_mode, notched, with_notch

    model = as_model(model)
    req = model.requirements
    fc = model.crossover
    cases = linear.limit_cases(model)
    at = linear.analyse(model, cases=cases)
    ach = linear.achievable_crossover(model)
    mode = limiting_mode(model, ach)
    suggestion = None
    limited_by = ach.limited_by
    if mode is not None and ach.kind == "margin":
        limited_by = (f"{ach.limited_by}, caused by the parasitic mode '{mode.name}' "
                      f"({mode.frequency:.4g} Hz, {mode.source}): without that mode the case "
                      "keeps its margins")
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
        msg = (f"the desired crossover {fc:.4g} Hz: the linear model limits the crossover "
               f"nowhere below {ach.frequency:.4g} Hz, the search cap (a bound, not a result; "
               "the hardware's sampling, delay and parasitic modes set the real limit)")
    elif reach:
        msg = (f"the desired crossover {fc:.4g} Hz is at or below the achievable "
               f"{ach.frequency:.4g} Hz (limited by {limited_by})")
    else:
        msg = (f"the desired crossover {fc:.4g} Hz is above the achievable {ach.frequency:.4g} Hz "
               f"(limited by {limited_by})")
    if suggestion is not None:
        msg += f"; {_notch_words(suggestion)}"
    checks.append(Check("crossover_achievable", reach, fc, ach.frequency, "Hz", msg, step=step))

    for c in at.cases:
        where = f"case {linear.CASE_NUMBERS[c.name]} ({c.description})"
        at_f = f" at {c.crossover:.3g} Hz" if c.crossover is not None else ""
        if not c.stable:
            msg = f"{where}: the closed loop is unstable"
        elif not c.in_band:
            msg = (f"{where}: " + (f"the loop crosses 0 dB only at {c.crossover:.3g} Hz, more "
                                   f"than {linear.BAND_FACTOR:g}x below the {fc:.4g} Hz "
                                   "crossover (the integrator against a stiff support)"
                                   if c.crossover is not None else "the loop never crosses "
                                   "0 dB") + ": no phase margin in the loop's band")
        else:
            msg = f"{where}: phase margin {c.phase_margin_deg:.3g} deg{at_f}"
        checks.append(_criterion_check(c, "phase margin", f"phase_margin.{c.name}",
                                       c.phase_margin_deg, req.phase_margin, "deg", msg, step))
        gm = c.gain_margin_db
        if math.isinf(gm):
            msg = f"{where}: the phase never crosses -180 deg, unlimited gain margin"
        elif gm < 0:
            msg = (f"{where}: gain margin {gm:.3g} dB (a lower margin: the loop goes unstable "
                   f"if the gain falls {abs(gm):.3g} dB)")
        else:
            msg = f"{where}: gain margin {gm:.3g} dB"
        checks.append(_criterion_check(c, "gain margin", f"gain_margin.{c.name}", abs(gm),
                                       req.gain_margin, "dB", msg, step))
        if req.modulus_margin is not None:
            checks.append(_criterion_check(
                c, "modulus margin", f"modulus_margin.{c.name}", c.modulus_margin,
                req.modulus_margin, "-",
                f"{where}: modulus margin min|1 + L| = {c.modulus_margin:.3g}", step))

    modes = []
    sep = req.parasitic_separation
    loop_fc = fc if at.loop_crossover is None else at.loop_crossover
    if at.loop_crossover is None:
        which = "the desired crossover (no case crosses 0 dB in the loop's band)"
    else:
        which = (f"the loop's crossover, {loop_fc:.4g} Hz (case "
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
                f"parasitic mode '{m.name}' (given) at {m.frequency:.4g} Hz "
                + ("lies above" if ok else "lies below")
                + f" {sep:g} x {which}: {need:.4g} Hz", step=step))

    return CrossoverResult(
        desired=fc, achievable=ach.frequency, limited_by=limited_by, limit_kind=ach.kind,
        limiting_case=ach.case, feasible_ranges=ach.feasible_ranges, delay=at.delay,
        stiffness=at.stiffness, cases=at.cases, parasitic_modes=tuple(modes),
        loop_crossover=at.loop_crossover, loop_crossover_case=at.loop_crossover_case,
        limiting_mode=None if mode is None else mode.name,
        limiting_mode_frequency=None if mode is None else mode.frequency, notch=suggestion,
        checks=tuple(checks))


def _notch_words(n: NotchSuggestion) -> str:
    """What a notch at the limiting mode would allow, in words."""
    head = f"a {n.notch.describe()} in controller.filters would "
    if n.achievable is None:
        return head + f"not help: {n.limited_by}"
    return head + f"allow {n.achievable:.4g} Hz (then limited by {n.limited_by})"


def _criterion_check(case, criterion: str, name: str, value, limit, unit: str, message: str,
                     step: str) -> Check:
    """A check of one requirement of a limit case, judged as the linear analysis judged it."""
    status = case.criteria[criterion]
    passed = None if status == Status.INFO else status == Status.PASS
    return Check(name, passed, value, limit, unit, message, step=step, status=status)


# --------------------------------------------------------------------------- step 3


def step3_stiffness(model: Model | Spec) -> StiffnessResult:
    """Guideline step 3: maximum drive stiffness from static friction and stroke.

    ``k_max = Fs / (stiffness_safety * stroke)``: at full stroke the flexure must
    push the cart with less than static friction, or the joint cannot keep the
    cart still while the stage settles. Lower is better for hunting; the
    flexure's parasitic frequencies bound how low (step 3 flexure sizing).

    Parameters
    ----------
    model : fi_design.model.Model or fi_design.spec.Spec
        The resolved model (a spec is resolved). Without an isolator the
        suggested stroke (:data:`SUGGESTED_STROKE`) is used and the result is
        a suggestion.

    Returns
    -------
    StiffnessResult
        k_max, the chosen stiffness and why, with a check chosen <= k_max.
    """
    model = as_model(model)
    spec = model.spec
    Fs = model.friction.Fs
    safety = model.requirements.stiffness_safety
    step = "step 3 drive stiffness"
    if model.joint is None:
        s = SUGGESTED_STROKE
        kmax = stiffness_limit(spec, s)
        k = proposed_stiffness(spec, s)
        msg = (f"no isolator in the spec; for a {s * 1e3:.3g} mm stroke (the paper's) the rule "
               f"gives k_max = {_g(kmax)} N/m and k = k_max / 2 = {_g(k)} N/m: the isolator "
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
    rule = f"k_max = Fs / {'stroke' if safety == 1 else f'({safety:g} x stroke)'} = {_g(kmax)} N/m"
    if k <= 0.0:
        msg = (f"k = {_g(k)} N/m ({source.split(':')[0].split(' (')[0]}) is not positive: "
               f"the joint has no drive stiffness left to centre the cart ({rule})")
    else:
        msg = (f"k = {_g(k)} N/m ({source.split(':')[0].split(' (')[0]}) "
               + ("is at or below " if ok else "exceeds ") + rule
               + f"; flexure force at full stroke {k * s:.3g} N against Fs = {Fs:.3g} N")
    check = Check("drive_stiffness", ok, k, kmax, "N/m", msg, step=step)
    return StiffnessResult(maximum=kmax, chosen=k, source=source, stroke=s, static=Fs,
                           safety=safety, force_at_stroke=k * s, suggested=False,
                           checks=(check,))


def step3_flexure(model: Model | Spec,
                  stiffness: StiffnessResult | None = None) -> FlexureResult | None:
    """Guideline step 3, second half: the isolator's leaf-spring guide as a mechanism.

    Parameters
    ----------
    model : fi_design.model.Model or fi_design.spec.Spec
        The resolved model (a spec is resolved).
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
    return as_model(model).flexure


# --------------------------------------------------------------------------- step 4


def _controller_words(c: ControlLaw) -> str:
    """The structure of a controller in words (D input, roll-off, sampling)."""
    parts = [f"D on the {c.derivative_on}",
             "ideal D" if math.isinf(c.roll_off) else
             f"D roll-off {_g(c.roll_off / (2 * math.pi))} Hz"]
    parts.append("continuous" if c.sample_period == 0 else
                 f"sampled at {quantity(1.0 / c.sample_period, 'Hz')}")
    parts.append("no delay" if c.delay == 0 else f"delay {quantity(c.delay, 's')}")
    parts += [f.describe() for f in c.filters]
    return ", ".join(parts)


def step4_pid(model: Model | Spec) -> PidResult:
    """Guideline step 4: PID gains from the moving mass and the desired crossover.

    With the hardware's own gains (``controller.gains``) the loop uses them;
    the rule's gains at the crossover the hardware achieves are shown beside
    them, in the same form, as the recommendation.

    Parameters
    ----------
    model : fi_design.model.Model or fi_design.spec.Spec
        The resolved model (a spec is resolved).

    Returns
    -------
    PidResult
        The gains and the loop's controller, with an informational check;
        tuning on the stage mass alone gives a WARN (the paper found the
        maximum moving mass best); a loop without integrator an INFO with its
        static error bound (Fs + |offset|) / kp (no hunting by the paper's
        mechanism; :attr:`fi_design.model.Model.static_error_bound`).
    """
    model = as_model(model)
    ctl = model.spec.controller
    law = model.law
    g = law.rule
    step = "step 4 PID"
    if law.source == "rule":
        msg = (f"tuned at {_g(g.crossover)} Hz on {_g(g.tuning_mass)} kg; the gains a drive "
               f"takes (controller.gains, with controller.roll_off on the D term only): kp = "
               f"{_g(law.kp)} N/m, ki = {_g(law.ki)} N/(m s), kd = {_g(law.kd)} N s/m "
               f"({_controller_words(law)})")
        checks = [Check("pid", None, law.kp, None, "N/m", msg, step=step)]
    else:
        r = law.rule_in_this_form()
        msg = (f"the hardware's gains kp = {_g(law.kp)} N/m, ki = {_g(law.ki)} N/(m s), "
               f"kd = {_g(law.kd)} N s/m ({_controller_words(law)}) cross over at "
               f"{law.crossover:.4g} Hz on {law.tuning_mass:.4g} kg; the rule there would give "
               f"kp = {_g(r['kp'])} N/m, ki = {_g(r['ki'])} N/(m s), kd = {_g(r['kd'])} N s/m "
               f"with a D roll-off of {r['roll_off'] / (2 * math.pi):.4g} Hz")
        # the rule's gains are a recommendation beside the hardware's, not a limit: they are in
        # the message and the gains table, never in the limit column
        checks = [Check("pid", None, law.kp, None, "N/m", msg, step=step)]
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
            f"in the drive's units ({_g(d.motor_constant)} N/A, {quantity(d.encoder_resolution, 'm')}"
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


def suggested_isolator(model: Model | Spec) -> tuple[float, float]:
    """Stroke [m] and drive stiffness [N/m] to start from when the spec has no isolator.

    The paper's 0.3 mm stroke (:data:`SUGGESTED_STROKE`) and k = Fs / (2 x
    safety x stroke), half the maximum of step 3.
    """
    return SUGGESTED_STROKE, proposed_stiffness(as_model(model).spec, SUGGESTED_STROKE)


def isolator_advice(model: Model | Spec, gap: FrictionGapResult, crossover: CrossoverResult,
                    simulation: Confirmation | None = None) -> IsolatorAdvice:
    """For a stage without isolator: is one needed, and which one.

    Before the simulation the linear steps can only say whether one looks
    needed. Once the stage is simulated the advice reads the judged
    stage-level answers, so it never advises what the same report shows
    failing: the stage as specified, and the rule's first isolator
    (:func:`suggested_isolator`) simulated beside it.

    Parameters
    ----------
    model : fi_design.model.Model or fi_design.spec.Spec
        The resolved model (a spec is resolved) of a stage without isolator.
    gap : FrictionGapResult
        Step 1.
    crossover : CrossoverResult
        Step 2.
    simulation : Confirmation, optional
        The simulated confirmation (:func:`fi_design.confirm.confirm`).

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
    model = as_model(model)
    s, k = suggested_isolator(model)
    kmax = stiffness_limit(model.spec, s)
    rule = (f"the rule's first isolator (a {s * 1e3:.3g} mm stroke, the paper's, and k = {_g(k)} "
            f"N/m = Fs / (2 x stroke); k_max = {_g(kmax)} N/m)")
    if simulation is not None:
        from .verdict import simulated_isolator_advice

        return simulated_isolator_advice(model.spec, gap, simulation, rule, (s, k, kmax))
    start = f"{rule} is the one to simulate first"
    if not gap.hunting_risk:
        return IsolatorAdvice(False, f"the friction gap {gap.gap:.3g} N is below the "
                              f"{gap.threshold:.3g} N threshold: an isolator looks not needed "
                              "(the simulation decides)", s, k, kmax)
    if crossover.limit_kind == "scan_limit":
        return IsolatorAdvice(None, (
            f"the friction gap {gap.gap:.3g} N is a hunting risk, but the linear model limits "
            f"the crossover nowhere up to {_g(crossover.achievable)} Hz: a high enough crossover "
            "may avoid hunting without an isolator (the paper needed about 3x the isolated "
            "crossover); add the loop delay to the spec and simulate to decide; for an "
            f"isolator, {start}"), s, k, kmax)
    return IsolatorAdvice(True, (
        f"the friction gap {gap.gap:.3g} N is a hunting risk and the crossover is limited to "
        f"{_g(crossover.achievable)} Hz ({crossover.limited_by}): an isolator looks needed "
        f"(the simulation decides); {start}"), s, k, kmax)


# --------------------------------------------------------------------------- the design


def _sha256(spec: Spec) -> str:
    from .specfile import origin

    org = origin(spec)
    if org is not None:
        return org.sha256
    return hashlib.sha256(spec.model_dump_json().encode()).hexdigest()


def design(spec: Spec | Model | str | Path | Mapping[str, Any], *, confirm: bool = True,
           executor: Executor | None = None,
           progress: Callable[[str], None] | None = None,
           fe_check: bool = False, sensitivity: bool = False) -> DesignResult:
    """Run the four guideline steps on a spec and confirm them by simulation.

    The spec is resolved once (:func:`fi_design.model.resolve`) and every
    step, the confirmation and the verdict read the resolved model.

    Parameters
    ----------
    spec : Spec, Model, path or mapping
        A validated spec, its resolved model, or a YAML path or mapping for
        :func:`fi_design.specfile.load_spec`. The robustness study of the
        sign-off varies the spec, so a model varied with
        :meth:`~fi_design.model.Model.at` is designed with ``confirm=False``
        (or ``requirements.robustness.samples: 0``).
    confirm : bool, optional
        Simulate the stage with and without the isolator, scan the crossover
        for the lowest hunting-free one, check the landing deflection and
        cross-check with the other friction model
        (:func:`fi_design.confirm.confirm`, about a second once the kernel is
        compiled). Default True; CAD loops that only need the linear steps pass
        False.
    executor : concurrent.futures-style executor, optional
        Runs the confirmation as one task and the robustness samples in
        chunks (``submit`` returning a future with ``result``, ``cancel`` and
        ``add_done_callback``), while this process does the linear analysis:
        with a process pool of two workers they overlap (and a first run
        compiles the simulation kernel there). None runs them here, after the
        linear steps. The library creates no pool.
    progress : callable, optional
        ``progress(text)`` with a short message as the work proceeds (the
        confirmation's own messages too when it runs here).
    fe_check : bool, optional
        Also build the flexure guide as a finite-element model
        (:func:`fi_design.mechanism.fe.fe_mechanics`, pyfe3d; a fraction of a
        second), the independent check of its closed forms, as
        ``flexure_fe``. Default False; skipped without a guide or without
        pyfe3d.
    sensitivity : bool, optional
        Also find the hunting-free crossover of the spec's own plant with the
        unidentified LuGre values sigma0, sigma1 and vs divided and multiplied
        by 3 (:func:`fi_design.studies.crossover_sensitivity`: six stage-level
        answers, about a second each on the paper setup, on ``executor``), as
        ``sensitivity``; the report's validation section shows it. Default
        False; skipped for a loop without integrator.

    Returns
    -------
    DesignResult
        Steps 1 to 4, the confirmation, all checks, warnings, a conclusion
        and the sign-off: ``verdict`` on the hardware as specified,
        ``robustness`` under the friction scatter of
        ``requirements.robustness`` (simulated on ``executor`` beside the
        confirmation; about 200 simulations of a few ms by default),
        ``margins``; no ``recommendation`` (:func:`fi_design.signoff.design`
        adds the design search's when the verdict fails).

    Raises
    ------
    fi_design.errors.SpecError
        When ``spec`` is a path or mapping that does not validate.
    fi_design.errors.ArgumentError
        A model varied with :meth:`~fi_design.model.Model.at` with the
        robustness study to run.
    """
    from . import __version__
    from . import verdict as _verdict
    from .confirm import confirm as run_confirmation
    from .responses import loop_responses
    from .stage import positioning, positioning_checks

    if not isinstance(spec, Model):
        from .specfile import as_spec

        spec = as_spec(spec)
    model = as_model(spec)
    spec = model.spec
    suggestion = suggested_isolator(model) if not model.has_isolator else None
    robust = confirm and model.requirements.robustness.samples > 0
    if robust and model.changed:
        raise ArgumentError(
            f"this model differs from its spec at {', '.join(model.changed)} (Model.at), but "
            "the robustness study of the sign-off varies the spec: design it with "
            "confirm=False, or write the values into the spec "
            "(fi_design.specfile.with_values) and design that")
    pending = []
    if confirm and executor is not None:
        pending.append(executor.submit(run_confirmation, model, suggestion))
    try:
        gap = step1_friction_gap(model)
        xo = step2_crossover(model)
        st = step3_stiffness(model)
        fx = step3_flexure(model, st)
        pid = step4_pid(model)
    except BaseException:
        for fut in pending:
            fut.cancel()
        raise
    advice = isolator_advice(model, gap, xo) if not model.has_isolator else None
    fe = _fe_check(fx) if fe_check else None
    checks = (gap.checks + xo.checks + st.checks
              + flexure_checks(fx, xo.desired, model.requirements.parasitic_separation)
              + pid.checks)
    result = DesignResult(
        spec=spec, friction_gap=gap, crossover=xo, stiffness=st, flexure=fx, pid=pid,
        loop=loop_responses(model, xo), isolator_advice=advice, checks=checks,
        warnings=tuple(warnings_for(spec)),
        conclusion=_conclusion(model, gap, xo, st, fx, pid, advice, checks),
        fi_design_version=__version__, spec_sha256=_sha256(spec), simulation=None,
        model=model, flexure_fe=fe)
    sim = study = None
    if confirm:
        if progress is not None:
            progress("simulating with and without the isolator ...")
        if robust:
            # the samples go to the executor in chunks, beside the confirmation
            if progress is not None:
                progress("simulating the friction scatter of requirements.robustness ...")
            study = _verdict.run_robustness(
                model, suggestion, None if progress is None else
                (lambda done, total: progress(f"friction scatter: {done}/{total} samples")),
                executor=executor)
        sim = pending[0].result() if pending else \
            run_confirmation(model, suggestion, progress=progress)
        own = "isolated" if model.has_isolator else "non_isolated"
        # the stage-level answer decides: step 1 and the advice now read it
        n_gap = len(gap.checks)
        gap = _verdict.friction_gap_judged(gap, sim.stage[own], model.law.integrator)
        checks = gap.checks + checks[n_gap:]
        if not model.has_isolator:
            advice = isolator_advice(model, gap, xo, sim)
        text = _conclusion(model, gap, xo, st, fx, pid, advice, checks, simulated=True)
        pos = positioning(model, sim.stage[own])
        result = replace(result, friction_gap=gap, isolator_advice=advice,
                         simulation=sim, positioning=pos,
                         checks=checks + sim.checks + (() if pos is None
                                                       else positioning_checks(pos)),
                         conclusion=text + _verdict.simulation_sentence(sim))
    rob = None if study is None else _verdict.robustness_check(model, study)
    if rob is not None:  # a check like the others: the tally counts it
        result = replace(result, checks=result.checks + (_verdict.robustness_as_check(rob),))
    if sensitivity and sim is not None:
        from .studies import crossover_sensitivity

        if progress is not None:
            progress("the hunting-free crossover over sigma0, sigma1 and vs ...")
        own = "isolated" if model.has_isolator else "non_isolated"
        result = replace(result, sensitivity=crossover_sensitivity(
            model, sim.stage[own].hunting_free_from, executor=executor))
    margins = _verdict.margins(model, xo, st, fx, pid, sim)
    result = replace(
        result, robustness=rob, margins=margins,
        verdict=_verdict.judge(model, result.checks, result.warnings, sim, rob, margins))
    log.info("design of %r: %s, %d checks, %d failed", spec.name, result.verdict.status,
             len(result.checks), len(result.failed_checks))
    return result


def _fe_check(fx: FlexureResult | None):
    """The guide as a finite-element model, or None without a guide or without pyfe3d."""
    if fx is None or fx.mechanics is None:
        return None
    try:
        from .mechanism.fe import fe_mechanics

        return fe_mechanics(fx.guide)
    except ImportError:
        log.info("pyfe3d is not installed: the flexure's FE check did not run")
        return None


def _conclusion(model: Model, gap: FrictionGapResult, xo: CrossoverResult, st: StiffnessResult,
                fx: FlexureResult | None, pid: PidResult, advice: IsolatorAdvice | None,
                checks: tuple[Check, ...], simulated: bool = False) -> str:
    from .linear import CASE_NUMBERS

    parts = []
    where = "at or above" if gap.hunting_risk else "below"
    first = (f"Static friction exceeds Coulomb friction by {gap.gap:.3g} N, {where} the "
             f"{gap.threshold:.3g} N threshold of step 1 (the paper's rule for its own stage)")
    if gap.hunting_risk and not pid.controller.integrator:
        first += (", but the loop has no integrator to push the cart through stiction, so it "
                  "cannot hunt by the paper's mechanism")
    elif gap.hunting_risk:
        first += ", so stick-slip can make the integrating controller hunt"
    else:
        first += ", so hunting is less likely"
    parts.append(first + ("; the simulation of every move decides (below)." if simulated
                          else "."))
    n = len(xo.cases)
    bad = [c for c in xo.cases if not c.passed]
    pms = [c.phase_margin_deg for c in xo.cases if c.in_band] or [math.inf]
    gms = [abs(c.gain_margin_db) for c in xo.cases]
    margins = (f"phase margins of at least {min(pms):.3g} deg and gain margins of at least "
               f"{min(gms):.3g} dB" if all(math.isfinite(x) for x in gms)
               else f"phase margins of at least {min(pms):.3g} deg")
    if xo.achievable is None:
        ach = f"no crossover meets the requirements ({xo.limited_by})"
    elif xo.limit_kind == "scan_limit":
        ach = (f"the linear model limits the crossover nowhere up to the scan limit of "
               f"{xo.achievable:.4g} Hz")
    else:
        ach = (f"the achievable crossover is {number(xo.achievable, 4)} Hz, limited by "
               f"{xo.limited_by}")
    if xo.notch is not None:
        ach += f"; {_notch_words(xo.notch)}"
    at = ("the desired crossover" if pid.controller.source == "rule"
          else "the hardware's crossover")
    if not bad:
        every = "both" if n == 2 else f"all {n}"
        parts.append(f"At {at} of {number(xo.desired, 4)} Hz {every} linear limit "
                     f"cases are stable with {margins}; {ach}.")
    else:
        which = ", ".join(f"case {CASE_NUMBERS[c.name]} ({c.description}: "
                          f"{', '.join(c.failed)})" for c in bad)
        parts.append(f"At {at} of {number(xo.desired, 4)} Hz the margins fail in "
                     f"{which}; {ach}.")
    if model.has_isolator:
        ok = st.chosen <= st.maximum * (1 + 1e-12)
        parts.append(f"The drive stiffness of {_g(st.chosen)} N/m is "
                     + ("within" if ok else "above")
                     + f" the maximum of {_g(st.maximum)} N/m, so the flexure pushes the cart "
                     f"with {st.force_at_stroke:.3g} N at full stroke against {st.static:.3g} N "
                     "of static friction.")
        if fx is not None:
            if fx.feasible:
                low = fx.lowest_mode
                parts.append(
                    f"A {fx.leaves}-leaf spring guide (L x b x t = "
                    f"{quantity(fx.length, 'm', 3, shown=('mm', 1e3))} x "
                    f"{quantity(fx.width, 'm', 3, shown=('mm', 1e3))} x "
                    f"{quantity(fx.thickness, 'm', 3, shown=('mm', 1e3))}, "
                    f"{fx.guide.orientation}) "
                    + ("as drawn" if fx.drawn else "sized from stock")
                    + f" has a net drive stiffness of {_g(fx.drive_stiffness)} N/m with "
                    f"gravity, a stress margin of {fx.stress_margin:.3g} and its lowest "
                    f"parasitic mode ({low.name}) at {_g(low.frequency)} Hz.")
            else:
                parts.append(f"No leaf-spring guide within the given bounds fits ({fx.reason}).")
    elif advice is not None:
        parts.append(advice.reason[0].upper() + advice.reason[1:] + ".")
    g = pid.gains
    law = pid.controller
    if law.source == "rule":
        parts.append(f"The PID tuned on {_g(g.tuning_mass)} kg gives the drive (in the form "
                     f"controller.gains takes) kp = {_g(law.kp)} N/m, ki = {_g(law.ki)} "
                     f"N/(m s) and kd = {_g(law.kd)} N s/m ({_controller_words(law)}).")
    else:
        r = law.rule_in_this_form()
        parts.append(f"The hardware's controller (kp = {_g(law.kp)} N/m, ki = {_g(law.ki)} "
                     f"N/(m s), kd = {_g(law.kd)} N s/m; {_controller_words(law)}) crosses over "
                     f"at {number(law.crossover, 4)} Hz on {_g(law.tuning_mass)} kg; the rule "
                     f"would tune kp = {_g(r['kp'])} N/m, ki = {_g(r['ki'])} N/(m s), kd = "
                     f"{_g(r['kd'])} N s/m with a D roll-off of "
                     f"{_g(r['roll_off'] / (2 * math.pi))} Hz there.")
    if pid.static_error is not None:
        parts.append(f"The loop has no integrator, so it cannot hunt by the paper's mechanism; "
                     f"it leaves a static error of up to {STATIC_ERROR_FORMULA} = "
                     f"{quantity(pid.static_error, 'm', 3)} instead.")
    failed = [c for c in checks if c.status == Status.FAIL]
    if failed:
        steps = ", ".join(dict.fromkeys(c.step for c in failed))
        parts.append(f"{len(failed)} check(s) of the four steps fail ({steps}; see the checks): "
                     "revise the design.")
    else:
        parts.append("No check of the four steps fails.")
    return " ".join(parts)
