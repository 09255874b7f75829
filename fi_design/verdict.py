"""The sign-off verdict on the hardware as specified: robustness, margins, recommendation.

:func:`fi_design.guideline.design` runs the four steps and the nonlinear
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
- :func:`recommend` -- what would make the stage pass (the isolator the
  guideline suggests and what the simulation says it would do, a higher
  crossover), kept apart from the verdict;
- :func:`judge` -- the :class:`~fi_design.results.design.Verdict`.

The verdict judges the spec's own plant: the isolated stage when the spec has
an isolator, else the stage without. It fails when a check fails, when that
plant hunts, sticks away from its target or cannot be determined at the
design crossover (a loop without integrator resting within its expected
static error (Fc + |offset|) / kp is neither), or when it hunts under scatter
more often than ``requirements.robustness.hunting_probability``. It passes
with warnings when nothing fails but something needs review: a warning
check, a warning on the user's own input, a loop without the hardware's
sampling and delay, a probability not demonstrated by the samples, a cart
resting within the friction scatter of its end stop, or no simulation.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

from . import spec as _spec
from .display import percent, quantities, quantity
from .results import Check, Status
from .results.design import (Confirmation, CrossoverResult, FlexureResult, Margins, PidResult,
                             Reason, Recommendation, RobustnessCheck, StiffnessResult, Verdict)

__all__ = ["run_robustness", "robustness_check", "margins", "recommend", "judge"]

#: Plant judged for a spec with / without isolator.
_OWN = {True: "isolated", False: "non_isolated"}


def _pct(x: float | None) -> str:
    return percent(x, 3)


def _um(x: float) -> str:
    return quantity(x, "m", 3)


# --------------------------------------------------------------------------- robustness


def run_robustness(spec: _spec.Spec, suggestion: tuple[float, float] | None = None,
                   progress: Callable[[int, int], None] | None = None) -> Any:
    """Simulate the samples of ``requirements.robustness`` (the study, not yet judged).

    Static and Coulomb friction scatter by the given fractions (and ripple
    along the rail when set); every sample is simulated with and without the
    isolator, in this process (:func:`fi_design.guideline.design` submits this
    function to the caller's executor). A spec without isolator is studied
    with the suggested isolator added, so the same samples show what it would
    do; the spec's own plant is the one without.

    Parameters
    ----------
    spec : Spec
        The design spec.
    suggestion : (stroke, stiffness), optional
        Isolator to add when the spec has none [m, N/m].
    progress : callable, optional
        ``progress(done, total)`` in simulations.

    Returns
    -------
    fi_design.studies.RobustnessResult or None
        None when ``samples`` is 0 or nothing scatters.
    """
    from .confirm import with_isolator
    from .studies import PositionFriction, Scatter, robustness

    cfg = spec.requirements.robustness
    scatter = [Scatter(path, spread) for path, spread in (("friction.static", cfg.static),
                                                         ("friction.coulomb", cfg.coulomb))
               if spread > 0]
    ripple = None if cfg.ripple is None else PositionFriction(cfg.ripple.amplitude,
                                                              cfg.ripple.wavelength)
    if cfg.samples == 0 or (not scatter and ripple is None):
        return None
    target = spec
    if not spec.has_isolator and suggestion is not None:
        target = with_isolator(spec, *suggestion)
    return robustness(target, scatter, cfg.samples, seed=cfg.seed,
                      distribution=cfg.distribution, position_friction=ripple,
                      confidence=cfg.confidence, executor=None, progress=progress, cache=None)


def robustness_check(spec: _spec.Spec, study: Any) -> RobustnessCheck:
    """Judge a robustness study against ``requirements.robustness.hunting_probability``.

    FAIL when the estimated probability exceeds the limit; WARN when it does
    not but the Wilson interval reaches above it (the samples do not
    demonstrate the limit); PASS when the whole interval lies at or below.

    Parameters
    ----------
    spec : Spec
        The design spec (its requirements and whether it has an isolator).
    study : fi_design.studies.RobustnessResult
        From :func:`run_robustness`.

    Returns
    -------
    RobustnessCheck
    """
    cfg = spec.requirements.robustness
    own = _OWN[spec.has_isolator]
    mine = study.isolated if own == "isolated" else study.not_isolated
    other = study.not_isolated if own == "isolated" else study.isolated
    p, limit = mine.probability, cfg.hunting_probability
    unsettled = mine.counts["undetermined"] + (mine.counts["stuck"] if _spec_integrates(spec)
                                               else 0)
    if p is None:
        status = "WARN"
    elif p > limit:
        status = "FAIL"
    elif mine.high > limit or unsettled > limit * mine.valid:
        status = "WARN"
    else:
        status = "PASS"
    comparison = None if other is None else {
        "plant": "isolated" if other.isolated else "non_isolated",
        "hunting_probability": other.probability, "interval": (other.low, other.high)}
    ripple = None if study.position_friction is None else {
        "amplitude": study.position_friction.amplitude,
        "wavelength": study.position_friction.wavelength}
    return RobustnessCheck(
        plant=own, samples=mine.samples, valid=mine.valid, hunting=mine.hunting,
        hunting_probability=p, interval=(mine.low, mine.high), confidence=mine.confidence,
        limit=limit, status=status, scatter={s.path: s.spread for s in study.scatter},
        distribution=study.distribution, ripple=ripple, seed=study.seed,
        counts=dict(mine.counts), comparison=comparison, study=study)


def _spec_integrates(spec: _spec.Spec) -> bool:
    from .pid import control_law

    return control_law(spec).integrator


def _scatter_words(r: RobustnessCheck) -> str:
    names = {"friction.static": "Fs", "friction.coulomb": "Fc"}
    spread = sorted(set(r.scatter.values()))
    if len(spread) == 1 and spread[0] > 0:
        parts = [f"+-{100 * spread[0]:.3g} % on " + " and ".join(names.get(k, k)
                                                                  for k in r.scatter)]
    else:
        parts = [f"+-{100 * v:.3g} % on {names.get(k, k)}" for k, v in r.scatter.items()]
    if r.ripple is not None:
        parts.append(f"a {100 * r.ripple['amplitude']:.3g} % ripple every "
                     f"{r.ripple['wavelength'] * 1e3:.3g} mm along the rail")
    kind = "standard deviation" if r.distribution == "normal" else "uniform half-width"
    return f"{', '.join(parts)} ({r.distribution}, {kind}; {r.samples} samples)"


# --------------------------------------------------------------------------- margins


def margins(spec: _spec.Spec, crossover: CrossoverResult, stiffness: StiffnessResult,
            flexure: FlexureResult | None, pid: PidResult,
            simulation: Confirmation | None) -> Margins:
    """Distances to the limits, each only where it means something.

    Parameters
    ----------
    spec : Spec
        The design spec.
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
    own = _OWN[spec.has_isolator]
    fc = crossover.desired

    if crossover.achievable is None:
        notes.append("no crossover meets the linear requirements: no bandwidth margin")
    elif crossover.limit_kind == "scan_limit":
        out["achievable_crossover_bound"] = crossover.achievable
        notes.append(f"step 2: the linear model limits the crossover nowhere below "
                     f"{crossover.achievable:.4g} Hz, the search cap: a bound, not a result "
                     "(sampling, delay and parasitic modes in the spec would set the real limit)")
    else:
        out["achievable_factor"] = crossover.achievable / fc
    for c in crossover.cases:
        if not c.in_band:
            where = (f"crosses 0 dB only at {c.crossover:.3g} Hz, below its band (from "
                     f"{fc / 10:.3g} Hz)" if c.crossover is not None else "never crosses 0 dB")
            notes.append(f"{c.description}: the loop {where}: no phase or delay margin to "
                         "report")

    if simulation is None:
        notes.append("no simulation: no hunting boundary, end-stop clearance or static error")
    else:
        scan = simulation.scans[own]
        m = scan.minimum
        if not pid.controller.integrator:
            notes.append("the loop has no integrator: it cannot hunt by the paper's mechanism, "
                         "so there is no hunting-free crossover to keep a distance from")
        elif m is None:
            notes.append(f"the stage as specified does not settle even at the top of the "
                         f"crossover scan ({scan.grid[1]:g} Hz): no crossover factor")
        else:
            out["hunting_free_crossover"] = m
            out["crossover_factor"] = fc / m
            if abs(m - scan.grid[0]) < 1e-9 * max(1.0, m):
                out["crossover_factor_bound"] = True
                notes.append(f"the stage settles over the whole crossover scan from "
                             f"{scan.grid[0]:g} Hz: the crossover factor is a lower bound")
        v = getattr(simulation, own)
        if v.static_error_bound is not None and v.outcome in ("static_error", "stuck"):
            out["static_error"] = abs(v.metrics.final_error)
            out["static_error_bound"] = v.static_error_bound
        land = simulation.landing
        if spec.has_isolator and land is not None:
            out["resting_deflection"] = land.deflection
            out["end_stop_clearance"] = land.stroke - abs(land.deflection)
    if spec.has_isolator:
        out["stiffness_factor"] = stiffness.maximum / stiffness.chosen
        if flexure is not None and flexure.feasible:
            lo, hi = flexure.stiffness_range
            out["stiffness_range"] = (lo, hi)
            out["stiffness_factor_worst"] = stiffness.maximum / hi
            out["thickness"] = flexure.thickness
            out["thickness_tolerance"] = flexure.thickness_tolerance
    else:
        notes.append("no isolator in the spec: no end-stop clearance or stiffness margin (the "
                     "recommendation gives the suggested isolator's)")
    return Margins(notes=tuple(notes), **out)


# --------------------------------------------------------------------------- recommendation


def recommend(spec: _spec.Spec, crossover: CrossoverResult, simulation: Confirmation | None,
              robustness: RobustnessCheck | None) -> Recommendation | None:
    """What would make the stage pass, kept apart from the verdict.

    For a stage without isolator whose simulation does not settle (or that
    fails the robustness check): the isolator step 3 suggests, with what the
    simulation says it would do. For any stage that hunts at its crossover but
    settles higher up, and whose loop reaches that crossover: the crossover to
    raise it to.

    Parameters
    ----------
    spec : Spec
        The design spec.
    crossover : CrossoverResult
        Step 2 (the achievable crossover).
    simulation : Confirmation or None
        The nonlinear confirmation.
    robustness : RobustnessCheck or None
        The robustness check.

    Returns
    -------
    Recommendation or None
        None when nothing needs recommending (or nothing was simulated).
    """
    if simulation is None:
        return None
    own = _OWN[spec.has_isolator]
    mine = getattr(simulation, own)
    scatter_fails = robustness is not None and robustness.status == "FAIL"
    if mine.acceptable and not scatter_fails:
        return None
    parts: list[str] = []
    iso_info = None
    if not spec.has_isolator:
        sug = simulation.isolated
        land = simulation.landing
        k = land.stiffness if land is not None else None
        iso_info = {"stroke": land.stroke if land is not None else None, "stiffness": k,
                    "outcome": sug.outcome, "hunting_cycles": sug.metrics.hunting_cycles,
                    "hunting_free_from": simulation.min_hunting_free_crossover["isolated"],
                    "end_stop_clearance": None if land is None
                    else land.stroke - abs(land.deflection)}
        text = (f"add a friction isolator: the guideline suggests a "
                f"{land.stroke * 1e3:.3g} mm stroke and k = {k:.4g} N/m; simulated at "
                f"{crossover.desired:g} Hz the stage would then be "
                f"{sug.outcome.replace('_', ' ')} ({sug.metrics.hunting_cycles} cycles)")
        m = iso_info["hunting_free_from"]
        text += ", hunting-free from " + (f"{m:g} Hz" if m is not None else "no scanned crossover")
        if robustness is not None and robustness.comparison is not None:
            c = robustness.comparison
            iso_info["hunting_probability"] = c["hunting_probability"]
            iso_info["interval"] = c["interval"]
            text += (f", hunting in {_pct(c['hunting_probability'])} of the scatter samples "
                     f"({_pct(c['interval'][0])} to {_pct(c['interval'][1])})")
            if c["hunting_probability"] is not None and \
                    c["hunting_probability"] > robustness.limit:
                text += (f", above the {_pct(robustness.limit)} limit: as it stands it would "
                         "not pass the robustness check either")
        parts.append(text + ". Specify it (the isolator section) and run the design again "
                     "to sign it off")
    m_own = simulation.min_hunting_free_crossover[own]
    raise_to = None
    if (not mine.acceptable and m_own is not None and m_own > crossover.desired
            and mine.static_error_bound is None):
        raise_to = m_own
        reach = crossover.achievable
        if reach is not None and crossover.limit_kind != "scan_limit" and reach < m_own:
            parts.append(f"a crossover of {m_own:g} Hz would settle, but the loop reaches only "
                         f"{reach:.3g} Hz (step 2)")
        else:
            bound = (" (step 2 sets no limit below its search cap; check it with the "
                     "hardware's sampling and delay)" if crossover.limit_kind == "scan_limit"
                     else f" (step 2: achievable {reach:.3g} Hz)" if reach is not None else "")
            parts.append(("or " if parts else "") + f"raise the crossover to at least "
                         f"{m_own:g} Hz, from which the stage as specified settles in the "
                         f"scan{bound}")
    if not parts and scatter_fails:
        parts.append("look for more margin to hunting under scatter: the command fi-design "
                     "robustness studies the scatter, and the hunting map of the report (the "
                     "option --map) shows where crossover and stroke give room")
    if not parts:
        return None
    text = "; ".join(parts)
    return Recommendation(text=text[0].upper() + text[1:] + ".", isolator=iso_info,
                          crossover=raise_to)


# --------------------------------------------------------------------------- verdict


_BEHAVIOUR = {
    "settled": "settles",
    "hunting": "hunts",
    "stuck": "sticks away from its target",
    "undetermined": "cannot be judged",
    "static_error": "rests within its static error",
}


def _behaviour_reason(v: Any, fc: float, label: str) -> Reason:
    m = v.metrics
    if v.outcome == "settled":
        after = (f" {m.settling_time:.3g} s after the move" if m.settling_time is not None
                 else "")
        return Reason("PASS", "simulation",
                      f"{label} settles at {fc:.4g} Hz: |x1 - r| within "
                      f"{_um(m.settle_band)}{after}, no hunting cycle.")
    if v.outcome == "static_error":
        return Reason("PASS", "simulation",
                      f"{label} comes to rest {_um(abs(m.final_error))} from its target at "
                      f"{fc:.4g} Hz, within the static error (Fc + |offset|) / kp = "
                      f"{_um(v.static_error_bound)} of a loop without integrator: not stuck, and "
                      "no hunting by the paper's mechanism.")
    if v.outcome == "hunting":
        period = f", period {m.period:.3g} s" if m.period is not None else ""
        return Reason("FAIL", "simulation",
                      f"{label} hunts at {fc:.4g} Hz: {m.hunting_cycles} cycle(s) of "
                      f"{m.amplitude * 1e3:.3g} mm peak to peak{period}.")
    if v.outcome == "stuck":
        extra = ""
        if v.static_error_bound is not None:
            extra = (f", beyond the static error (Fc + |offset|) / kp = "
                     f"{_um(v.static_error_bound)} its loop without integrator explains")
        return Reason("FAIL", "simulation",
                      f"{label} sticks {_um(abs(m.final_error))} away from its target at "
                      f"{fc:.4g} Hz{extra}: no cycles counted, but it does not settle.")
    return Reason("FAIL", "simulation",
                  f"Whether {label.lower()} settles cannot be determined at {fc:.4g} Hz: "
                  f"{m.reason}.")


def judge(spec: _spec.Spec, checks: Sequence[Check], warnings: Sequence[tuple[str, str]],
          simulation: Confirmation | None, robustness: RobustnessCheck | None,
          margin: Margins) -> Verdict:
    """The verdict on the hardware as specified.

    Parameters
    ----------
    spec : Spec
        The design spec.
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

    Returns
    -------
    Verdict
    """
    own = _OWN[spec.has_isolator]
    fc = _spec.design_crossover(spec)
    label = ("The isolated stage as specified" if spec.has_isolator
             else "The stage as specified (without isolator)")
    reasons: list[Reason] = []
    behaviour = None
    judged_check = f"simulation_{own}"
    if simulation is not None:
        v = getattr(simulation, own)
        behaviour = v.outcome
        reasons.append(_behaviour_reason(v, fc, label))
    for c in checks:
        if c.status == Status.FAIL and c.name != judged_check:
            reasons.append(Reason("FAIL", c.name, f"{c.step}: {c.message}."))
    if robustness is not None:
        r = robustness
        what = (f"Under friction scatter of {_scatter_words(r)} the stage as specified hunts in "
                f"{_pct(r.hunting_probability)} of {r.valid} valid samples "
                f"({100 * r.confidence:.3g} % interval {_pct(r.interval[0])} to "
                f"{_pct(r.interval[1])})")
        left = r.counts["invalid"] + r.counts["failed"]
        kinds = ("stuck", "undetermined") if _spec_integrates(spec) else ("undetermined",)
        others = {k: r.counts[k] for k in kinds if r.counts[k]}
        notes = []
        if others:
            notes.append(" and ".join(f"{n} {k}" for k, n in others.items()) + " sample(s) do "
                         "not settle either")
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
        elif r.status == "WARN":
            text = (f"{what}, within the {_pct(r.limit)} limit; but more than "
                    f"{_pct(r.limit)} of the samples do not settle, so the stage is not shown "
                    f"to be robust.{tail}")
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
        rise = (d + clearance) / d - 1.0
        spread = spec.requirements.robustness.coulomb
        if rise <= spread:
            reasons.append(Reason(
                "WARN", "end_stop_clearance",
                "The cart rests {} from its end stop (joint deflection {} of the {} stroke): "
                "a friction force ".format(*quantities((clearance, d, d + clearance), "m", 3))
                + f"{percent(rise, 2)} higher would put it on the limiter, within the "
                f"\u00b1{percent(spread)} scatter of Fc."))
    for c in checks:
        if c.status == Status.WARN:
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
    what = (f"{label} {_BEHAVIOUR.get(behaviour, behaviour)} at {fc:.4g} Hz"
            if behaviour is not None else f"{label} was not simulated")
    on = []
    for r in reasons:
        word = _SOURCES.get(r.source, r.source.replace("_", " "))
        if r.severity == "FAIL" and word not in on:
            on.append(word)
    warned = f"{nwarn} warning{'s' if nwarn != 1 else ''} to review"
    listed = ", ".join(on[:-1]) + " and on " + on[-1] if len(on) > 1 else "".join(on)
    tail = {"FAIL": f"It fails on {listed}" + (f"; {warned}" if nwarn else ""),
            "PASS_WITH_WARNINGS": f"Nothing fails; {warned}",
            "NOT_CONFIRMED": "Nothing of the linear steps fails, but without the simulation "
                             "it does not pass" + (f"; {warned}" if nwarn > 1 else ""),
            "PASS": "Nothing fails, nothing to review"}[status]
    return Verdict(status=status, reasons=tuple(reasons), plant=own, behaviour=behaviour,
                   headline=f"{what}. {tail}.")


#: Sources of reasons in the headline's words (others: the check's name).
_SOURCES = {"simulation": "the simulation at the design crossover",
            "robustness": "friction scatter", "confirmation": "the missing simulation"}
