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

import numpy as np

from .flexure import size_flexure
from .pid import ControlLaw, control_law
from .results import Check, Status, frozen_array
from .results.design import (CaseResponse, Confirmation, CrossoverResult, DesignResult,
                             FlexureResult, FrictionGapResult, IsolatorAdvice, LoopResponses,
                             ModeSeparation, PidResult, StiffnessResult)
from .spec import (Spec, design_crossover, drive_stiffness, proposed_stiffness, stiffness_limit,
                   warnings_for)

if TYPE_CHECKING:  # pragma: no cover
    from .execution import Executor

__all__ = [
    "SUGGESTED_STROKE", "FrictionGapResult", "ModeSeparation", "CrossoverResult",
    "StiffnessResult", "PidResult", "IsolatorAdvice", "DesignResult", "step1_friction_gap",
    "step2_crossover", "step3_stiffness", "step3_flexure", "step4_pid", "isolator_advice",
    "design",
]

log = logging.getLogger(__name__)

#: Stroke suggested for a first isolator design [m]: the paper's 0.3 mm.
SUGGESTED_STROKE = 0.3e-3


def _g(x: float | None, digits: int = 4) -> str:
    """``digits`` significant digits; plain (no exponent) from 1e4 to 1e6."""
    if x is None:
        return "-"
    if 1e4 <= abs(x) < 1e6:
        return f"{x:.0f}"
    return f"{x:.{digits}g}"


# --------------------------------------------------------------------------- step 1


def step1_friction_gap(spec: Spec) -> FrictionGapResult:
    """Guideline step 1: compare Fs - Fc with ``requirements.friction_gap``.

    Parameters
    ----------
    spec : fi_design.spec.Spec
        The design spec.

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
    f = spec.friction
    gap = f.static - f.coulomb
    thr = spec.requirements.friction_gap
    risk = gap >= thr
    status = Status.PASS
    if risk:
        msg = (f"Fs - Fc = {gap:.3g} N is at or above the {thr:.3g} N threshold: stick-slip "
               "can make an integrating controller hunt")
        if not control_law(spec).integrator:
            status = Status.INFO
            msg += "; this loop has no integrator"
        elif spec.isolator is not None:
            status = Status.INFO
            msg += "; the isolator is there to prevent it (the simulation checks it)"
        else:
            status = Status.WARN
    else:
        msg = (f"Fs - Fc = {gap:.3g} N is below the {thr:.3g} N threshold: stick-slip, and so "
               "hunting, is unlikely")
    check = Check("friction_gap", not risk if status != Status.INFO else None, gap, thr, "N",
                  msg, step="step 1 friction gap", status=status)
    return FrictionGapResult(static=f.static, coulomb=f.coulomb, gap=gap, threshold=thr,
                             hunting_risk=risk, checks=(check,))


# --------------------------------------------------------------------------- step 2


def step2_crossover(spec: Spec) -> CrossoverResult:
    """Guideline step 2: desired versus achievable crossover.

    The limit cases use the spec's joint stiffness (the proposed one when the
    spec gives none, as step 3 would choose).

    Parameters
    ----------
    spec : fi_design.spec.Spec
        The design spec.

    Returns
    -------
    CrossoverResult
        Achievable crossover and its limit, per-case margins at the desired
        crossover, the parasitic separation, and the checks: one reachability
        check, phase and gain margin (and modulus margin if required) per case,
        one separation check per parasitic mode.
    """
    from . import linear

    req = spec.requirements
    fc = design_crossover(spec)
    cases = linear.limit_cases(spec)
    at = linear.analyse(spec, fc, cases=cases)
    ach = linear.achievable_crossover(spec)
    step = "step 2 crossover"
    checks: list[Check] = []
    reach = ach.frequency is not None and fc <= ach.frequency * (1 + 1e-9)
    if ach.frequency is None:
        msg = f"no crossover is achievable: {ach.limited_by}"
    elif ach.kind == "scan_limit":
        msg = (f"the desired crossover {fc:.4g} Hz: the linear model limits the crossover "
               f"nowhere below {ach.frequency:.4g} Hz, the search cap (a bound, not a result; "
               "the hardware's sampling, delay and parasitic modes set the real limit)")
    elif reach:
        msg = (f"the desired crossover {fc:.4g} Hz is at or below the achievable "
               f"{ach.frequency:.4g} Hz (limited by {ach.limited_by})")
    else:
        msg = (f"the desired crossover {fc:.4g} Hz is above the achievable {ach.frequency:.4g} Hz "
               f"(limited by {ach.limited_by})")
    checks.append(Check("crossover_achievable", reach, fc, ach.frequency, "Hz", msg, step=step))

    for c in at.cases:
        where = f"case {linear.CASE_NUMBERS[c.name]} ({c.description})"
        at_f = f" at {c.crossover:.3g} Hz" if c.crossover is not None else ""
        ok = c.stable and c.phase_margin_deg >= req.phase_margin
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
        checks.append(Check(f"phase_margin.{c.name}", ok if c.in_band or not ok else None,
                            c.phase_margin_deg, req.phase_margin, "deg", msg, step=step))
        gm = c.gain_margin_db
        if math.isinf(gm):
            msg = f"{where}: the phase never crosses -180 deg, unlimited gain margin"
        elif gm < 0:
            msg = (f"{where}: gain margin {gm:.3g} dB (a lower margin: the loop goes unstable "
                   f"if the gain falls {abs(gm):.3g} dB)")
        else:
            msg = f"{where}: gain margin {gm:.3g} dB"
        checks.append(Check(f"gain_margin.{c.name}", c.stable and abs(gm) >= req.gain_margin,
                            abs(gm), req.gain_margin, "dB", msg, step=step))
        if req.modulus_margin is not None:
            checks.append(Check(f"modulus_margin.{c.name}",
                                c.stable and c.modulus_margin >= req.modulus_margin,
                                c.modulus_margin, req.modulus_margin, "-",
                                f"{where}: modulus margin min|1 + L| = {c.modulus_margin:.3g}",
                                step=step))

    modes = []
    sep = req.parasitic_separation
    for m in (spec.isolator.parasitic_modes if spec.isolator is not None else ()):
        need = sep * fc
        ok = m.frequency >= need
        modes.append(ModeSeparation(m.name, m.frequency, need, m.collocated, ok))
        checks.append(Check(
            f"parasitic_separation.{m.name}", ok, m.frequency, need, "Hz",
            f"parasitic mode '{m.name}' at {m.frequency:.4g} Hz "
            + ("lies above" if ok else "lies below")
            + f" {sep:g} x the desired crossover ({need:.4g} Hz)", step=step))

    return CrossoverResult(
        desired=fc, achievable=ach.frequency, limited_by=ach.limited_by, limit_kind=ach.kind,
        limiting_case=ach.case, feasible_ranges=ach.feasible_ranges, delay=at.delay,
        stiffness=at.stiffness, cases=at.cases, parasitic_modes=tuple(modes),
        checks=tuple(checks))


# --------------------------------------------------------------------------- loop responses


def loop_responses(spec: Spec, crossover: CrossoverResult, points: int = 500) -> LoopResponses:
    """The loop of every limit case over a frequency grid that holds every crossover and mode.

    The loop is the one whose margins step 2 reports: the spec's controller at
    the desired crossover, the joint stiffness of the cases.

    Parameters
    ----------
    spec : fi_design.spec.Spec
        The design spec.
    crossover : CrossoverResult
        Step 2 (desired crossover, the gain crossovers of each case, the
        joint stiffness the cases use).
    points : int, optional
        Number of frequencies.

    Returns
    -------
    LoopResponses
    """
    from . import linear

    fc = crossover.desired
    lows = [fc / 30.0] + [c / 3.0 for case in crossover.cases for c in case.crossovers
                          if c and c > 0]
    modes = spec.isolator.parasitic_modes if spec.isolator is not None else ()
    highs = [30.0 * fc] + [2.0 * m.frequency for m in modes]
    lo = 10.0 ** math.floor(math.log10(min(lows)))
    hi = 10.0 ** math.ceil(math.log10(max(highs)))
    f = np.geomspace(lo, hi, points)
    s = 2j * math.pi * f
    cases = []
    for lc in linear.limit_cases(spec, crossover.stiffness):
        num, den = linear.loop_polynomials(spec, lc)
        cases.append(CaseResponse(name=lc.name, number=lc.number, description=lc.description,
                                  loop=frozen_array(np.polyval(num, s) / np.polyval(den, s),
                                                    dtype=complex)))
    return LoopResponses(frequency=frozen_array(f), cases=tuple(cases))


# --------------------------------------------------------------------------- step 3


def step3_stiffness(spec: Spec) -> StiffnessResult:
    """Guideline step 3: maximum drive stiffness from static friction and stroke.

    ``k_max = Fs / (stiffness_safety * stroke)``: at full stroke the flexure must
    push the cart with less than static friction, or the joint cannot keep the
    cart still while the stage settles. Lower is better for hunting; the
    flexure's parasitic frequencies bound how low (step 3 flexure sizing).

    Parameters
    ----------
    spec : fi_design.spec.Spec
        The design spec. Without an isolator the suggested stroke
        (:data:`SUGGESTED_STROKE`) is used and the result is a suggestion.

    Returns
    -------
    StiffnessResult
        k_max, the chosen stiffness and why, with a check chosen <= k_max.
    """
    Fs = spec.friction.static
    safety = spec.requirements.stiffness_safety
    step = "step 3 drive stiffness"
    if spec.isolator is None:
        s = SUGGESTED_STROKE
        kmax = stiffness_limit(spec, s)
        k = proposed_stiffness(spec, s)
        msg = (f"no isolator in the spec; for a {s * 1e3:.3g} mm stroke k_max = {_g(kmax)} N/m, "
               f"start from k = {_g(k)} N/m (k_max / 2)")
        check = Check("drive_stiffness", None, k, kmax, "N/m", msg, step=step)
        return StiffnessResult(maximum=kmax, chosen=k, source="suggested: k_max / 2 for the "
                               "paper's 0.3 mm stroke (no isolator in the spec)", stroke=s,
                               static=Fs, safety=safety, force_at_stroke=k * s, suggested=True,
                               checks=(check,))
    s = spec.isolator.stroke
    kmax = stiffness_limit(spec, s)
    k = drive_stiffness(spec)
    if spec.isolator.stiffness is not None:
        source = "given in the spec (isolator.stiffness)"
    else:
        source = ("proposed: k_max / 2, so the flexure force at full stroke is Fs / 2, leaving "
                  "room for friction scatter")
    ok = k <= kmax * (1 + 1e-12)
    msg = (f"k = {_g(k)} N/m ({source.split(':')[0].split(' (')[0]}) "
           + ("is at or below" if ok else "exceeds")
           + f" k_max = Fs / {'stroke' if safety == 1 else f'({safety:g} x stroke)'} = "
           f"{_g(kmax)} N/m; flexure force at full "
           f"stroke {k * s:.3g} N against Fs = {Fs:.3g} N")
    check = Check("drive_stiffness", ok, k, kmax, "N/m", msg, step=step)
    return StiffnessResult(maximum=kmax, chosen=k, source=source, stroke=s, static=Fs,
                           safety=safety, force_at_stroke=k * s, suggested=False,
                           checks=(check,))


def step3_flexure(spec: Spec, stiffness: StiffnessResult | None = None) -> FlexureResult | None:
    """Guideline step 3, second half: size the leaf-spring guide of ``isolator.flexure``.

    Parameters
    ----------
    spec : fi_design.spec.Spec
        The design spec.
    stiffness : StiffnessResult, optional
        Step 3's stiffness result (computed when omitted).

    Returns
    -------
    FlexureResult or None
        None when the spec has no ``isolator.flexure`` section. The required
        parasitic frequency is ``parasitic_separation`` x the desired crossover.
    """
    if spec.isolator is None or spec.isolator.flexure is None:
        return None
    st = stiffness if stiffness is not None else step3_stiffness(spec)
    return size_flexure(spec.isolator.flexure, target_stiffness=st.chosen,
                        maximum_stiffness=st.maximum, stroke=st.stroke,
                        stage_mass=spec.stage.mass,
                        required_frequency=spec.requirements.parasitic_separation
                        * design_crossover(spec))


def _flexure_checks(fx: FlexureResult | None) -> tuple[Check, ...]:
    if fx is None:
        return ()
    step = "step 3 flexure"
    if not fx.feasible:
        return (Check("flexure", False, None, None, "-",
                      f"no {fx.leaves}-leaf guide within the bounds fits: {fx.reason}",
                      step=step),)
    dims = (f"{fx.leaves} leaves L x b x t = {fx.length * 1e3:.3g} x {fx.width * 1e3:.3g} x "
            f"{fx.thickness * 1e3:.3g} mm")
    return (
        Check("flexure.stiffness", fx.drive_stiffness <= fx.maximum_stiffness * (1 + 1e-9),
              fx.drive_stiffness, fx.maximum_stiffness, "N/m",
              f"{dims}: drive stiffness {_g(fx.drive_stiffness)} N/m (target "
              f"{_g(fx.target_stiffness)} N/m, k_max {_g(fx.maximum_stiffness)} N/m)", step=step),
        Check("flexure.stress", fx.stress <= fx.allowed_stress, fx.stress, fx.allowed_stress,
              "Pa", f"bending stress at full stroke {fx.stress / 1e6:.3g} MPa, allowed "
              f"{fx.allowed_stress / 1e6:.4g} MPa (margin x{fx.stress_margin:.3g})", step=step),
        Check("flexure.support_frequency", fx.support_frequency >= fx.required_frequency,
              fx.support_frequency, fx.required_frequency, "Hz",
              f"support-direction frequency {fx.support_frequency:.4g} Hz with the stage "
              f"mass, required {fx.required_frequency:.4g} Hz", step=step),
        Check("flexure.bending_frequency", fx.bending_frequency >= fx.required_frequency,
              fx.bending_frequency, fx.required_frequency, "Hz",
              f"leaf bending resonance {fx.bending_frequency:.4g} Hz (clamped-guided, "
              f"conservative), required {fx.required_frequency:.4g} Hz", step=step),
    )


# --------------------------------------------------------------------------- step 4


def _controller_words(c: ControlLaw) -> str:
    """The structure of a controller in words (D input, roll-off, sampling)."""
    parts = [f"D on the {c.derivative_on}",
             "ideal D" if math.isinf(c.roll_off) else
             f"D roll-off {c.roll_off / (2 * math.pi):.4g} Hz"]
    parts.append("continuous" if c.sample_period == 0 else
                 f"sampled at {1.0 / c.sample_period:.4g} Hz")
    if c.delay > 0:
        parts.append(f"delay {c.delay * 1e3:.3g} ms")
    return ", ".join(parts)


def step4_pid(spec: Spec) -> PidResult:
    """Guideline step 4: PID gains from the moving mass and the desired crossover.

    With the hardware's own gains (``controller.gains``) the loop uses them;
    the rule's gains at the crossover the hardware achieves are shown beside
    them, in the same form, as the recommendation.

    Parameters
    ----------
    spec : fi_design.spec.Spec
        The design spec.

    Returns
    -------
    PidResult
        The gains and the loop's controller, with an informational check;
        tuning on the stage mass alone gives a WARN (the paper found the
        maximum moving mass best); a loop without integrator an INFO with its
        static error Fc / kp (no hunting by the paper's mechanism).
    """
    ctl = spec.controller
    law = control_law(spec)
    g = law.rule
    step = "step 4 PID"
    if law.source == "rule":
        msg = (f"tuned at {g.crossover:.4g} Hz on {g.tuning_mass:.4g} kg: kp = {g.kp:.4g} N/m, "
               f"ki = {g.ki:.4g} N/(m s), kd = {g.kd:.4g} N s/m, wt = {g.wt:.4g} rad/s")
        checks = [Check("pid", None, g.kp, None, "N/m", msg, step=step)]
    else:
        r = law.rule_in_this_form()
        msg = (f"the hardware's gains kp = {law.kp:.4g} N/m, ki = {law.ki:.4g} N/(m s), "
               f"kd = {law.kd:.4g} N s/m ({_controller_words(law)}) cross over at "
               f"{law.crossover:.4g} Hz on {law.tuning_mass:.4g} kg; the rule there would give "
               f"kp = {r['kp']:.4g} N/m, ki = {r['ki']:.4g} N/(m s), kd = {r['kd']:.4g} N s/m "
               f"with a D roll-off of {r['roll_off'] / (2 * math.pi):.4g} Hz")
        checks = [Check("pid", None, law.kp, g.kp, "N/m", msg, step=step)]
    static = law.static_error(spec.friction.coulomb)
    if static is not None:
        checks.append(Check(
            "pid.integrator", None, static, None, "m",
            f"the loop has no integrator: no hunting by the paper's mechanism (integral action "
            f"building up through stiction), a static error instead of up to Fc / kp = "
            f"{static * 1e6:.3g} um against the Coulomb friction", step=step))
    if ctl.tuning_mass == "stage" and spec.isolator is not None:
        checks.append(Check(
            "pid.tuning_mass", None, g.tuning_mass, spec.total_mass, "kg",
            "tuned on the stage mass alone: with the limiter engaged the loop sees m1 + m2 and "
            "crosses over lower (the paper tunes on the maximum moving mass)", step=step,
            status=Status.WARN))
    return PidResult(gains=g, tuning_rule=ctl.tuning_mass, derivative_ratio=ctl.derivative_ratio,
                     integrator_ratio=ctl.integrator_ratio, controller=law, static_error=static,
                     checks=tuple(checks))


# --------------------------------------------------------------------------- no isolator


def suggested_isolator(spec: Spec) -> tuple[float, float]:
    """Stroke [m] and drive stiffness [N/m] to start from when the spec has no isolator.

    The paper's 0.3 mm stroke (:data:`SUGGESTED_STROKE`) and k = Fs / (2 x
    safety x stroke), half the maximum of step 3.
    """
    return SUGGESTED_STROKE, proposed_stiffness(spec, SUGGESTED_STROKE)


def isolator_advice(spec: Spec, gap: FrictionGapResult, crossover: CrossoverResult,
                    ) -> IsolatorAdvice:
    """For a stage without isolator: does one look needed, and where to start.

    Parameters
    ----------
    spec : fi_design.spec.Spec
        The design spec (no isolator section).
    gap : FrictionGapResult
        Step 1.
    crossover : CrossoverResult
        Step 2.

    Returns
    -------
    IsolatorAdvice
        Needed when the friction gap is a hunting risk and the reachable
        crossover is limited; not needed below the gap threshold; undecided
        when the linear model sets no crossover limit within the scan.
    """
    s, k = suggested_isolator(spec)
    kmax = stiffness_limit(spec, s)
    start = (f"start from a {s * 1e3:.3g} mm stroke (the paper's) and k = {_g(k)} N/m "
             f"(Fs / (2 x stroke); k_max = {_g(kmax)} N/m)")
    if not gap.hunting_risk:
        return IsolatorAdvice(False, f"the friction gap {gap.gap:.3g} N is below the "
                              f"{gap.threshold:.3g} N threshold: an isolator is not needed",
                              s, k, kmax)
    if crossover.limit_kind == "scan_limit":
        return IsolatorAdvice(None, (
            f"the friction gap {gap.gap:.3g} N is a hunting risk, but the linear model limits "
            f"the crossover nowhere up to {_g(crossover.achievable)} Hz: a high enough crossover "
            "may avoid hunting without an isolator (the paper needed about 3x the isolated "
            "crossover); add the loop delay to the spec and simulate to decide; for an "
            f"isolator, {start}"), s, k, kmax)
    return IsolatorAdvice(True, (
        f"the friction gap {gap.gap:.3g} N is a hunting risk and the crossover is limited to "
        f"{_g(crossover.achievable)} Hz ({crossover.limited_by}): an isolator is recommended; "
        f"{start}"), s, k, kmax)


# --------------------------------------------------------------------------- the design


def _sha256(spec: Spec) -> str:
    from .specfile import origin

    org = origin(spec)
    if org is not None:
        return org.sha256
    return hashlib.sha256(spec.model_dump_json().encode()).hexdigest()


def design(spec: Spec | str | Path | Mapping[str, Any], *, confirm: bool = True,
           executor: Executor | None = None,
           progress: Callable[[str], None] | None = None) -> DesignResult:
    """Run the four guideline steps on a spec and confirm them by simulation.

    Parameters
    ----------
    spec : Spec, path or mapping
        A validated spec, or a YAML path or mapping for
        :func:`fi_design.specfile.load_spec`.
    confirm : bool, optional
        Simulate the stage with and without the isolator, scan the crossover
        for the lowest hunting-free one, check the landing deflection and
        cross-check with the other friction model
        (:func:`fi_design.confirm.confirm`, about a second once the kernel is
        compiled). Default True; CAD loops that only need the linear steps pass
        False.
    executor : concurrent.futures-style executor, optional
        Runs the confirmation and the robustness study, as two tasks
        (``submit`` returning a future with ``result`` and ``cancel``), while
        this process does the linear analysis: with a process pool of two
        workers the three overlap (and a first run compiles the simulation
        kernel there). None runs them here, after the linear steps. The
        library creates no pool.
    progress : callable, optional
        ``progress(text)`` with a short message as the work proceeds (the
        confirmation's own messages too when it runs here).

    Returns
    -------
    DesignResult
        Steps 1 to 4, the confirmation, all checks, warnings, a conclusion
        and the sign-off: ``verdict`` on the hardware as specified,
        ``robustness`` under the friction scatter of
        ``requirements.robustness`` (simulated on ``executor`` beside the
        confirmation; about 200 simulations of a few ms by default),
        ``margins`` and a ``recommendation`` (:mod:`fi_design.verdict`).

    Raises
    ------
    fi_design.errors.SpecError
        When ``spec`` is a path or mapping that does not validate.
    """
    from . import __version__
    from . import verdict as _verdict
    from .confirm import confirm as run_confirmation

    from .specfile import as_spec

    spec = as_spec(spec)
    suggestion = suggested_isolator(spec) if spec.isolator is None else None
    robust = confirm and spec.requirements.robustness.samples > 0
    pending = []
    if confirm and executor is not None:
        pending.append(executor.submit(run_confirmation, spec, suggestion))
        if robust:
            pending.append(executor.submit(_verdict.run_robustness, spec, suggestion))
    try:
        gap = step1_friction_gap(spec)
        xo = step2_crossover(spec)
        st = step3_stiffness(spec)
        fx = step3_flexure(spec, st)
        pid = step4_pid(spec)
    except BaseException:
        for fut in pending:
            fut.cancel()
        raise
    advice = isolator_advice(spec, gap, xo) if spec.isolator is None else None
    checks = gap.checks + xo.checks + st.checks + _flexure_checks(fx) + pid.checks
    result = DesignResult(
        spec=spec, friction_gap=gap, crossover=xo, stiffness=st, flexure=fx, pid=pid,
        loop=loop_responses(spec, xo), isolator_advice=advice, checks=checks,
        warnings=tuple(warnings_for(spec)),
        conclusion=_conclusion(spec, gap, xo, st, fx, pid, advice, checks),
        fi_design_version=__version__, spec_sha256=_sha256(spec), simulation=None)
    sim = study = None
    if confirm:
        if progress is not None:
            progress("simulating with and without the isolator ...")
        sim = pending[0].result() if pending else \
            run_confirmation(spec, suggestion, progress=progress)
        if robust:
            if progress is not None:
                progress("simulating the friction scatter of requirements.robustness ...")
            study = pending[1].result() if pending else _verdict.run_robustness(
                spec, suggestion, None if progress is None else
                (lambda done, total: progress(f"friction scatter: {done}/{total} simulations")))
        result = replace(result, simulation=sim, checks=result.checks + sim.checks,
                         conclusion=result.conclusion + _simulation_sentence(spec, sim))
    rob = None if study is None else _verdict.robustness_check(spec, study)
    margins = _verdict.margins(spec, xo, st, fx, pid, sim)
    result = replace(
        result, robustness=rob, margins=margins,
        recommendation=_verdict.recommend(spec, xo, sim, rob),
        verdict=_verdict.judge(spec, result.checks, result.warnings, sim, rob, margins))
    log.info("design of %r: %s, %d checks, %d failed", spec.name, result.verdict.status,
             len(result.checks), len(result.failed_checks))
    return result


def _simulation_sentence(spec: Spec, sim: Confirmation) -> str:
    """The conclusion's sentence on the simulated verdicts (the spec's own plant first)."""
    iso, non = sim.isolated, sim.non_isolated
    mins = sim.min_hunting_free_crossover
    fc = design_crossover(spec)

    def f(x):
        return "beyond the scan" if x is None else f"from {x:g} Hz"

    def o(v):
        return f"{v.outcome.replace('_', ' ')} ({v.metrics.hunting_cycles} cycles)"

    if sim.suggested_isolator:
        text = (f" The LuGre simulation at {fc:g} Hz gives: the stage as specified, without "
                f"isolator, {o(non)}, hunting-free {f(mins['non_isolated'])}; with the "
                f"suggested isolator (a recommendation, not the hardware) it would be {o(iso)}, "
                f"hunting-free {f(mins['isolated'])} (resolution {mins['resolution']:g} Hz).")
    else:
        text = (f" The LuGre simulation at {fc:g} Hz gives: with the isolator {o(iso)}, "
                f"without it {o(non)}; hunting-free {f(mins['isolated'])} with the isolator "
                f"and {f(mins['non_isolated'])} without (resolution {mins['resolution']:g} Hz).")
    model = sim.isolated.friction_model
    if model != "lugre":
        text = text.replace("The LuGre simulation", f"The {model} simulation")
    if not sim.models_agree:
        text += " The other friction model disagrees on the verdict (see the checks)."
    return text


def _conclusion(spec: Spec, gap: FrictionGapResult, xo: CrossoverResult, st: StiffnessResult,
                fx: FlexureResult | None, pid: PidResult, advice: IsolatorAdvice | None,
                checks: tuple[Check, ...]) -> str:
    from .linear import CASE_NUMBERS

    parts = []
    if gap.hunting_risk and not pid.controller.integrator:
        parts.append(f"Static friction exceeds Coulomb friction by {gap.gap:.3g} N, at or above "
                     f"the {gap.threshold:.3g} N threshold, but the loop has no integrator to "
                     "push the cart through stiction, so it cannot hunt by the paper's "
                     "mechanism.")
    elif gap.hunting_risk:
        parts.append(f"Static friction exceeds Coulomb friction by {gap.gap:.3g} N, at or above "
                     f"the {gap.threshold:.3g} N threshold, so stick-slip can make the "
                     "integrating controller hunt.")
    else:
        parts.append(f"Static friction exceeds Coulomb friction by only {gap.gap:.3g} N, below "
                     f"the {gap.threshold:.3g} N threshold, so hunting is unlikely"
                     + (" and the isolator may not be needed." if spec.isolator is not None
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
        ach = f"the achievable crossover is {xo.achievable:.3g} Hz, limited by {xo.limited_by}"
    at = ("the desired crossover" if pid.controller.source == "rule"
          else "the hardware's crossover")
    if not bad:
        every = "both" if n == 2 else f"all {n}"
        parts.append(f"At {at} of {xo.desired:.3g} Hz {every} linear limit "
                     f"cases are stable with {margins}; {ach}.")
    else:
        which = ", ".join(f"case {CASE_NUMBERS[c.name]} ({c.description}: "
                          f"{', '.join(c.failed)})" for c in bad)
        parts.append(f"At {at} of {xo.desired:.3g} Hz the margins fail in "
                     f"{which}; {ach}.")
    if spec.isolator is not None:
        ok = st.chosen <= st.maximum * (1 + 1e-12)
        parts.append(f"The drive stiffness of {_g(st.chosen)} N/m is "
                     + ("within" if ok else "above")
                     + f" the maximum of {_g(st.maximum)} N/m, so the flexure pushes the cart "
                     f"with {st.force_at_stroke:.3g} N at full stroke against {st.static:.3g} N "
                     "of static friction.")
        if fx is not None:
            if fx.feasible:
                parts.append(
                    f"A {fx.leaves}-leaf spring guide (L x b x t = {fx.length * 1e3:.3g} x "
                    f"{fx.width * 1e3:.3g} x {fx.thickness * 1e3:.3g} mm) realises it with a "
                    f"stress margin of {fx.stress_margin:.3g} and parasitic frequencies of "
                    f"{fx.bending_frequency:.4g} Hz (leaf) and {fx.support_frequency:.4g} Hz "
                    f"(support), above the {fx.required_frequency:.4g} Hz required.")
            else:
                parts.append(f"No leaf-spring guide within the given bounds fits ({fx.reason}).")
    elif advice is not None:
        parts.append(advice.reason[0].upper() + advice.reason[1:] + ".")
    g = pid.gains
    law = pid.controller
    if law.source == "rule":
        parts.append(f"The PID tuned on {g.tuning_mass:.3g} kg has kp = {g.kp:.4g} N/m, "
                     f"ki = {g.ki:.4g} N/(m s) and kd = {g.kd:.4g} N s/m.")
    else:
        parts.append(f"The hardware's controller (kp = {law.kp:.4g} N/m, ki = {law.ki:.4g} "
                     f"N/(m s), kd = {law.kd:.4g} N s/m; {_controller_words(law)}) crosses over "
                     f"at {law.crossover:.3g} Hz on {law.tuning_mass:.3g} kg; the rule would tune "
                     f"kp = {g.kp:.4g} N/m, ki = {g.ki:.4g} N/(m s), kd = {g.kd:.4g} N s/m there.")
    if pid.static_error is not None:
        parts.append(f"The loop has no integrator, so it cannot hunt by the paper's mechanism; "
                     f"it leaves a static error of up to Fc / kp = "
                     f"{pid.static_error * 1e6:.3g} um instead.")
    failed = [c.name for c in checks if c.status == Status.FAIL]
    if failed:
        parts.append(f"{len(failed)} check(s) fail ({', '.join(failed)}): revise the design "
                     "before the nonlinear confirmation.")
    else:
        parts.append("No check of the four steps fails.")
    return " ".join(parts)
