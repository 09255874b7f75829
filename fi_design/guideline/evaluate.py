"""The design evaluated: the four steps, the nonlinear confirmation, the verdict, the conclusion.

:func:`evaluate` resolves the spec once, runs the four steps of
:mod:`fi_design.guideline.steps` on the model, the nonlinear confirmation
(:func:`fi_design.stage.confirm.confirm`) on the executor the caller passes, so
that its simulations overlap the linear analysis, and the verdict
(:mod:`fi_design.guideline.verdict`), and returns a
:class:`~fi_design.results.design.DesignResult`, whose ``to_dict()`` is the JSON
contract of ``fi-design SPEC.yaml --json``. The sign-off
(:func:`fi_design.signoff.design`) adds the recommendation when the verdict fails.
"""

from __future__ import annotations

import logging
import math
import threading
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Mapping

from ..display import number, quantity
from ..effects import simulated_only
from ..errors import ArgumentError
from ..execution import Background, check_executor
from ..mechanism.checks import flexure_checks
from ..model import Model, as_model
from ..results import Check, Status
from ..results.design import DesignResult, FlexureResult, IsolatorAdvice
from ..results.linear import phase_margin_judged
from ..results.stage import STATIC_ERROR_FORMULA
from ..spec import Spec, warnings_for
from .steps import (controller_words, isolator_advice, notch_words, step1_friction_gap,
                    step2_crossover, step3_flexure, step3_stiffness, step4_pid,
                    suggested_isolator)
from .validity import beyond_the_linear_loop, linear_loop_note

if TYPE_CHECKING:  # pragma: no cover
    from ..execution import Executor
    from ..results.design import CrossoverResult, FrictionGapResult, PidResult, StiffnessResult

log = logging.getLogger(__name__)

__all__ = ["evaluate"]


def _g(x: float | None, digits: int = 4) -> str:
    """A number as every table prints it (:func:`fi_design.display.number`)."""
    return number(x, digits)




def evaluate(spec: Spec | Model | str | Path | Mapping[str, Any], *, confirm: bool = True,
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
        :func:`fi_design.spec.file.load_spec`. The robustness study of the
        sign-off varies the spec, so a model varied with
        :meth:`~fi_design.model.Model.at` is designed with ``confirm=False``
        (or ``requirements.robustness.samples: 0``).
    confirm : bool, optional
        Simulate the stage with and without the isolator, scan the crossover
        for the lowest hunting-free one, check the landing deflection and
        cross-check with the other friction model
        (:func:`fi_design.stage.confirm.confirm`, about a second once the kernel is
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
        robustness study to run; an ``executor`` that is none.
    """
    from .. import __version__
    from . import verdict as _verdict
    from ..stage.confirm import confirm as run_confirmation
    from ..stage import positioning, positioning_checks

    check_executor(executor)
    if not isinstance(spec, Model):
        from ..spec.file import as_spec

        spec = as_spec(spec, model=True)
    model = as_model(spec)
    spec = model.spec
    suggestion = suggested_isolator(model) if not model.has_isolator else None
    robust = confirm and model.requirements.robustness.samples > 0
    if (robust or (confirm and sensitivity)) and model.departures:
        raise ArgumentError(
            f"this model differs from its spec at {', '.join(model.departures)} (Model.at), but "
            "the robustness study (and the sensitivity) of the sign-off vary the spec's values "
            "(Model.varied): design it with confirm=False, or vary the model resolved from "
            "the spec with every value in Model.varied and design that")
    pending = []
    scatter = stop = sens = None
    if confirm and executor is not None:
        # the simulations start first: the workers run them while this process imports
        # python-control and scans the loop (step 2)
        pending.append(executor.submit(run_confirmation, model, suggestion))
        if robust:
            stop = threading.Event()
            scatter = Background(_verdict.run_robustness, model, suggestion,
                                 _scatter_progress(progress, stop), executor=executor)
        if sensitivity:
            from ..studies.sensitivity import started_sensitivity

            # its six answers need none of the others: they fill the workers' idle time
            sens = started_sensitivity(model, executor=executor)
    from ..loop.responses import loop_responses  # python-control: after the workers start

    try:
        gap = step1_friction_gap(model)
        xo = step2_crossover(model)
        st = step3_stiffness(model)
        fx = step3_flexure(model, st)
        pid = step4_pid(model)
        advice = isolator_advice(model, gap, xo) if not model.has_isolator else None
        fe = _fe_check(fx) if fe_check else None
        checks = (gap.checks + xo.checks + st.checks
                  + flexure_checks(fx, xo.desired if xo.loop_crossover is None
                                   else xo.loop_crossover,
                                   model.requirements.parasitic_separation,
                                   model.joint.stiffness if model.joint else None,
                                   st.maximum if fx is not None and fx.stroke == st.stroke
                                   else None)
                  + pid.checks)
        result = DesignResult(
            spec=spec, friction_gap=gap, crossover=xo, stiffness=st, flexure=fx, pid=pid,
            loop=loop_responses(model, xo), isolator_advice=advice, checks=checks,
            warnings=tuple(warnings_for(spec)),
            conclusion=_conclusion(model, gap, xo, st, fx, pid, advice, checks),
            fi_design_version=__version__, spec_sha256=spec.sha256(), simulation=None,
            model=model, flexure_fe=fe)
        sim = study = None
        if confirm:
            if progress is not None:
                progress("simulating with and without the isolator ...")
            if scatter is not None:
                study = scatter.result()
            elif robust:
                if progress is not None:
                    progress("simulating the friction scatter of requirements.robustness ...")
                study = _verdict.run_robustness(model, suggestion,
                                                _scatter_progress(progress, None))
            sim = pending[0].result() if pending else \
                run_confirmation(model, suggestion, progress=progress)
    except BaseException:
        for fut in pending:
            fut.cancel()
        if sens is not None:
            sens.cancel()
        if stop is not None:
            stop.set()  # the scatter's chunks not yet started are cancelled
        raise
    if confirm:
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
        from ..studies.sensitivity import started_sensitivity

        if progress is not None:
            progress("the hunting-free crossover over sigma0, sigma1 and vs ...")
        own = "isolated" if model.has_isolator else "non_isolated"
        if sens is None:
            sens = started_sensitivity(model, executor=executor)
        result = replace(result, sensitivity=sens.result(sim.stage[own].hunting_free_from))
    elif sens is not None:
        sens.cancel()
    margins = _verdict.margins(model, xo, st, fx, pid, sim)
    # the simulated stage stands for the hardware only where step 2's loop is stable
    note = linear_loop_note(xo) if sim is not None or rob is not None else None
    result = replace(result, checks=beyond_the_linear_loop(result.checks, note))
    result = replace(
        result, robustness=rob, margins=margins,
        verdict=_verdict.judge(model, result.checks, result.warnings, sim, rob, margins, note))
    log.info("design of %r: %s, %d checks, %d failed", spec.name, result.verdict.status,
             len(result.checks), len(result.failed_checks))
    return result


class _Stopped(Exception):
    """The design stopped before the scatter's samples were collected."""


def _scatter_progress(progress: Callable[[str], None] | None,
                      stop: threading.Event | None) -> Callable[[int, int], None] | None:
    """The robustness study's ``progress(done, total)``: a message on ``progress``; once
    ``stop`` is set it raises, which cancels the chunks not yet started."""
    if progress is None and stop is None:
        return None

    def tell(done: int, total: int) -> None:
        if stop is not None and stop.is_set():
            raise _Stopped
        if progress is not None:
            progress(f"friction scatter: {done}/{total} samples")

    return tell


def _fe_check(fx: FlexureResult | None):
    """The guide as a finite-element model, or None without a guide or without pyfe3d."""
    if fx is None or fx.mechanics is None:
        return None
    try:
        from ..mechanism.fe import fe_mechanics

        return fe_mechanics(fx.guide)
    except ImportError:
        log.info("pyfe3d is not installed: the flexure's FE check did not run")
        return None


def _conclusion(model: Model, gap: FrictionGapResult, xo: CrossoverResult, st: StiffnessResult,
                fx: FlexureResult | None, pid: PidResult, advice: IsolatorAdvice | None,
                checks: tuple[Check, ...], simulated: bool = False) -> str:
    from ..loop.linear import CASE_NUMBERS

    parts = []
    where = "at or above" if gap.hunting_risk else "below"
    first = (f"Static friction exceeds Coulomb friction by {quantity(gap.gap, 'N', 3)}, {where} "
             f"the {quantity(gap.threshold, 'N', 3)} threshold of step 1 (the paper's rule for "
             "its own stage)")
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
    pms = [c.phase_margin_deg for c in xo.cases if phase_margin_judged(c.criteria)] or [math.inf]
    gms = [abs(c.gain_margin_db) for c in xo.cases]
    margins = (f"phase margins of at least {number(min(pms), 3)} deg and gain margins of at least "
               f"{number(min(gms), 3)} dB" if all(math.isfinite(x) for x in gms)
               else f"phase margins of at least {number(min(pms), 3)} deg")
    if xo.achievable is None:
        ach = f"no crossover meets the requirements ({xo.limited_by})"
    elif xo.limit_kind == "scan_limit":
        ach = (f"the linear model limits the crossover nowhere up to the scan limit of "
               f"{quantity(xo.achievable, 'Hz', 4)}")
    else:
        ach = (f"the achievable crossover is {quantity(xo.achievable, 'Hz', 4)}, limited by "
               f"{xo.limited_by}")
    if xo.notch is not None:
        ach += f"; {notch_words(xo.notch)}"
    at = ("the desired crossover" if pid.controller.source == "rule"
          else "the hardware's crossover")
    if not bad:
        every = "both" if n == 2 else f"all {n}"
        parts.append(f"At {at} of {quantity(xo.desired, 'Hz', 4)} {every} linear limit "
                     f"cases are stable with {margins}; {ach}.")
    else:
        which = ", ".join(f"case {CASE_NUMBERS[c.name]} ({c.description}: "
                          f"{', '.join(c.failed)})" for c in bad)
        parts.append(f"At {at} of {quantity(xo.desired, 'Hz', 4)} the margins fail in "
                     f"{which}; {ach}.")
    if model.has_isolator:
        ok = st.chosen <= st.maximum * (1 + 1e-12)
        parts.append(f"The drive stiffness of {_g(st.chosen)} N/m is "
                     + ("within" if ok else "above")
                     + f" the maximum of {_g(st.maximum)} N/m, so the flexure pushes the cart "
                     f"with {quantity(st.force_at_stroke, 'N', 3)} at full stroke against "
                     f"{quantity(st.static, 'N', 3)} of static friction.")
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
                    f"gravity, a stress margin of {number(fx.stress_margin, 3)} and its lowest "
                    f"parasitic mode ({low.name}) at {_g(low.frequency)} Hz.")
            else:
                parts.append(f"No leaf-spring guide within the given bounds fits ({fx.reason}).")
    elif advice is not None:
        parts.append(advice.reason[0].upper() + advice.reason[1:] + ".")
    g = pid.gains
    law = pid.controller
    if law.source == "rule":
        parts.append(f"The PID tuned on {_g(g.tuning_mass)} kg gives the drive (in the form "
                     f"controller.gains takes) kp = {_g(law.kp)} N/m, ki = "
                     f"{quantity(law.ki, 'N/(m*s)')} and kd = {quantity(law.kd, 'N*s/m')} "
                     f"({controller_words(law, model.effects)}).")
    else:
        r = law.rule_in_this_form()
        parts.append(f"The hardware's controller (kp = {_g(law.kp)} N/m, ki = "
                     f"{quantity(law.ki, 'N/(m*s)')}, kd = {quantity(law.kd, 'N*s/m')}; "
                     f"{controller_words(law, model.effects)}) crosses over "
                     f"at {quantity(law.crossover, 'Hz', 4)} on {_g(law.tuning_mass)} kg; the rule "
                     f"would tune kp = {_g(r['kp'])} N/m, ki = {quantity(r['ki'], 'N/(m*s)')}, "
                     f"kd = {quantity(r['kd'], 'N*s/m')} with a D roll-off of "
                     f"{_g(r['roll_off'] / (2 * math.pi))} Hz there.")
    simulated = simulated_only(model.effects)
    if simulated:
        parts.append(simulated[0].upper() + simulated[1:] + ".")
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
