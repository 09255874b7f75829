"""The verdict of a design report: the verdict box, its key figures, every check by step.

The verdict box reads the design's :class:`~fi_design.results.design.Verdict`
(the hardware as specified), so a stage that settles and one that hunts look
different: ``behaviour_css`` (``settles``, ``hunts``, ``stuck``,
``undetermined``, ``static-error``, ``not-simulated``) styles the frame and the
stamp. The key figures are the robustness under friction scatter and the
margins, each only where it means something; the notes say why one is
missing or only a bound.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from ..display import NBSP, percent, quantity, scale
from ..results import Status
from ..results.stage import STATIC_ERROR_FORMULA
from .filters import display_scale, num, qty

__all__ = ["PERCENT_CHECKS", "STEP_SOURCES", "SENSE", "STATUS_TEXT", "BEHAVIOUR", "check_label", "check_row",
           "key_figures", "verdict"]

#: The verdict's status as printed.
STATUS_TEXT = {"PASS": "PASS", "PASS_WITH_WARNINGS": "PASS with warnings",
               "NOT_CONFIRMED": "NOT CONFIRMED (not simulated)", "FAIL": "FAIL"}

#: The judged plant's behaviour: (css class, stamp) by outcome; None: not simulated.
BEHAVIOUR = {
    "settles": ("settles", "settles after every move"),
    "hunts": ("hunts", "hunts"),
    "stuck": ("stuck", "sticks away from its target"),
    "undetermined": ("undetermined", "cannot be judged"),
    "static_error": ("static-error", "rests within its static error"),
    None: ("not-simulated", "not simulated"),
}
#: The stamp of a stage that settles at nominal friction inside a failing verdict: no green.
NOMINAL = ("nominal", "settles at nominal friction")


#: Where each guideline step comes from in the paper, for the checks' "source" column.
STEP_SOURCES = {
    "step 1 friction gap": "step 1; paper \u00a74, Fig. 4A",
    "step 2 crossover": "step 2; paper \u00a72.2, \u00a74, Fig. 2",
    "step 3 drive stiffness": "step 3; paper \u00a74, Fig. 4C",
    "step 3 flexure": "step 3; paper \u00a74, \u00a75",
    "step 3 refinement: landing": "step 3 (simulated landing)",
    "step 4 PID": "step 4; paper \u00a72.2",
    "simulation (paper section 2.3)": "simulation; paper \u00a72.3, Fig. 5",
    "robustness under friction scatter": "simulation under friction scatter",
    "positioning": "requirements.positioning, every move simulated",
}

#: Requirement sense of each check (by name, or by the name's part before the first dot).
SENSE = {
    "friction_gap": "<", "crossover_achievable": "\u2264", "phase_margin": "\u2265",
    "gain_margin": "\u2265", "modulus_margin": "\u2265", "parasitic_separation": "\u2265",
    "drive_stiffness": "\u2264", "flexure.stiffness": "\u2264", "flexure.joint": "\u2248", "flexure.stress": "\u2264",
    "flexure.buckling": "\u2265", "flexure.modes": "\u2265", "flexure.sag": "<",
    "flexure.slenderness": "\u2265",
    "simulation_isolated": "=", "min_crossover_isolated": "\u2264", "landing_force": "<",
    "simulation_non_isolated": "=", "min_crossover_non_isolated": "\u2264", "robustness": "\u2264",
    "end_stop_force": "\u2264", "actuator_force": "<",
    "positioning": "\u2264",
}


#: Checks whose value is a probability [-], shown in % wherever it is printed.
PERCENT_CHECKS = frozenset({"robustness"})

#: The limit cases the hunting margin names (case number and words).
_CASE_WORDS = {"sliding_limited": "case 3, cart sliding, limiter engaged",
               "sliding_free": "case 1, cart sliding, joint free",
               "sliding": "case 1, cart sliding, no isolator"}


def check_label(name: str, cases: Mapping[str, Any] | None = None) -> str:
    """A check's name in words: ``phase_margin.stuck_free`` -> ``Phase margin, case 2 ...``.

    Parameters
    ----------
    name : str
        :attr:`fi_design.results.Check.name`.
    cases : mapping, optional
        The design's limit cases by name (``number`` and ``description``,
        e.g. :attr:`fi_design.results.design.LoopResponses.cases`), which name
        the case of a margin check.

    Returns
    -------
    str
    """
    head, _, tail = name.partition(".")
    case = tail
    if head in ("phase_margin", "gain_margin", "modulus_margin") and tail in (cases or {}):
        case = f"case {cases[tail].number} ({cases[tail].description})"
    labels = {
        "friction_gap": "Friction gap Fs \u2212 Fc",
        "crossover_achievable": "Desired crossover within the achievable",
        "phase_margin": f"Phase margin, {case}",
        "gain_margin": f"Gain margin, {case}",
        "modulus_margin": f"Modulus margin, {case}",
        "parasitic_separation": f"Parasitic mode \u2018{tail}\u2019 above the crossover",
        "drive_stiffness": "Drive stiffness k within k_max",
        "flexure": "Leaf-spring flexure",
        "pid": "PID gains (proportional gain kp)",
        "simulation_isolated": "Hunting after any move, with the isolator",
        "simulation_non_isolated": "Hunting after any move, without the isolator",
        "spec_move_isolated": "The spec's own motion with the isolator (paper metric)",
        "spec_move_non_isolated": "The spec's own motion without the isolator (paper metric)",
        "min_crossover_isolated": "Lowest crossover from which no move hunts, with the isolator",
        "min_crossover_non_isolated": "Lowest crossover from which no move hunts, without the "
                                      "isolator",
        "isolator_needed": "Is the isolator needed at this crossover?",
        "landing_force": "Flexure force on the resting cart",
        "robustness": "Probability of not settling under friction scatter",
        "friction_model_cross_check": "Cross-check with the other friction model",
        "end_stop_force": "End-stop contact force over the move family",
        "actuator_force": "Actuator's peak force over the move family",
    }
    if head == "positioning":
        return {"settle_time": "Settle time after every move",
                "static_error": "Static error after every move"}.get(tail, name)
    flex = {"stiffness": "Flexure net drive stiffness within k_max",
            "joint": "Flexure realises the joint's drive stiffness",
            "stress": "Flexure stress at full stroke",
            "buckling": "Flexure buckling load over the stage's weight",
            "modes": "Flexure's lowest parasitic mode above the crossover",
            "sag": "Joint sag under the cart's weight within the stroke",
            "slenderness": "Flexure leaves slender enough for beam theory (L/t)"}
    if head == "flexure" and tail in flex:
        return flex[tail]
    if head == "pid" and tail == "tuning_mass":
        return "PID tuning mass"
    if head == "pid" and tail == "integrator":
        return f"Loop without integrator: static error up to {STATIC_ERROR_FORMULA}"
    if head == "pid" and tail == "drive_units":
        return "PID gains in the drive's units (counts, current)"
    if head == "pid" and tail == "discrete":
        return "PID and filters per sample (the drive's recursion)"
    return labels.get(head, name.replace("_", " ").capitalize())


def _sense(name: str, limit: Any = None) -> str:
    if name.startswith("gain_margin.") and isinstance(limit, (int, float)) and limit < 0:
        return "\u2264"  # a stable loop's lower gain margin: at or below -required
    if name in SENSE:
        return SENSE[name]
    return SENSE.get(name.split(".")[0], "")


def check_row(check: Any, cases: Mapping[str, Any] | None = None) -> dict:
    """One row of the verdict table: label, status, value and limit in a shared unit, source.

    Parameters
    ----------
    check : fi_design.results.Check
        The check.
    cases : mapping, optional
        The design's limit cases by name (:func:`check_label`).

    Returns
    -------
    dict
        ``name``, ``label``, ``status``, ``css`` (status class), ``value``,
        ``limit`` (numbers in the shown ``unit``; None when absent), ``sense``
        (the requirement's relation), ``unit`` (shown), ``source`` and
        ``message``.
    """
    status = check.status.value if isinstance(check.status, Status) else str(check.status)
    ref = check.limit if isinstance(check.limit, (int, float)) else check.value
    shown, factor = display_scale(check.unit, ref)
    if check.unit == "cycles":
        shown = "cycles"
    if check.name in PERCENT_CHECKS:  # a probability reads in %, as the key figures give it
        shown, factor = "%", 100.0

    def conv(x):
        if x is None or not isinstance(x, (int, float)) or isinstance(x, bool):
            return x
        return float(x) * factor

    return {
        "name": check.name,
        "label": check_label(check.name, cases),
        "status": status,
        "css": status.lower(),
        "value": conv(check.value),
        "limit": conv(check.limit),
        "sense": _sense(check.name, check.limit) if check.limit is not None else "",
        "unit": shown,
        "source": STEP_SOURCES.get(check.step, check.step),
        "message": check.message,
    }


def _figure(label: str, value: Any, unit: str, requirement: str = "", note: str = "",
            css: str = "info", digits: int = 4) -> dict:
    """One key figure: the value scaled for reading with its shown unit."""
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        shown, factor = display_scale(unit, value)
        value = num(value * factor, digits)
    else:
        shown = unit
    if shown in ("1", "-"):
        shown = ""
    return {"label": label, "value": value, "unit": shown or "\u2013",
            "requirement": requirement, "note": note, "css": css}


def _pct(x: float | None) -> str:
    return num(None if x is None else 100.0 * x, 3)


def key_figures(result: Any) -> list[dict]:
    """The verdict's figures: behaviour, robustness and the margins that mean something.

    Parameters
    ----------
    result : fi_design.results.design.DesignResult
        The design, with its verdict.

    Returns
    -------
    list of dict
        ``label``, ``value`` (text, scaled), ``unit`` (shown), ``requirement``,
        ``note`` and ``css`` (pass, warn, fail, info) per row.
    """
    rows = []
    v, rob, m = result.verdict, result.robustness, result.margins
    spec = result.spec
    sim = result.simulation
    fc = result.crossover.desired
    if sim is not None:
        st = sim.stage[v.plant]
        css = "pass" if st.acceptable else "fail"
        c = st.cycle
        if st.hunts:
            note = (f"{len(st.hunting_moves)} of {len(st.moves)} moves end in "
                    + (f"a cycle of {qty(c.amplitude, 'm', 3)} peak to peak, period "
                       f"{qty(c.period, 's', 3)}" if c is not None else "a cycle"))
        elif st.outcome in ("settles", "static_error"):
            note = f"all {len(st.moves)} moves of the family come to rest"
        else:
            bad = next(m for m in st.moves if m.outcome in ("stuck", "rests", "undetermined"))
            note = f"after the {qty(abs(bad.distance), 'm')} move: {bad.reason}"
        need = ("no move hunts" if st.static_error_bound is None
                else f"every move rests within {qty(st.static_error_bound, 'm', 3)}")
        short = {"stuck": "sticks", "static_error": "static error",
                 "settles": "settles"}.get(st.outcome, BEHAVIOUR[st.outcome][1])
        rows.append(_figure(f"Every move of the family at {qty(fc, 'Hz')}", short, "", need,
                            note, css))
    if rob is not None:
        css = {"PASS": "pass", "WARN": "warn", "FAIL": "fail"}[rob.status]
        note = (f"{percent(rob.confidence, 3)} interval {_pct(rob.interval[0])} \u2013 "
                f"{_pct(rob.interval[1])} %; {rob.hunting} of {rob.valid} valid samples")
        if rob.comparison is not None and rob.comparison["hunting_probability"] is not None:
            other = ("without the isolator" if rob.comparison["plant"] == "non_isolated"
                     else "with the rule's isolator")
            note += f"; {other}: {_pct(rob.comparison['hunting_probability'])} %"
        rows.append(_figure("Probability of not settling under friction scatter",
                            _pct(rob.hunting_probability), "%", f"\u2264 {_pct(rob.limit)}",
                            note, css))
    pos = result.positioning
    if pos is not None:
        for c in result.checks:
            if not c.name.startswith("positioning."):
                continue
            unit = "s" if c.name.endswith("settle_time") else "m"
            rows.append(_figure(check_label(c.name), "never" if c.value is None else c.value,
                                unit if c.value is not None else "", f"\u2264 {qty(c.limit, unit)}",
                                f"requirements.positioning, band \u00b1{qty(pos.band, 'm')}",
                                c.status.value.lower(), 3))
    if m is None:
        return rows
    if m.crossover_factor is not None:
        # the requirement the min_crossover check judges: the hunting margin (1.2 by default);
        # between 1 and it the check fails (the cycle is a little friction away), below 1 the
        # simulation fails and the check warns
        need = spec.requirements.hunting_margin
        css = ("pass" if m.crossover_factor >= need else
               "fail" if m.crossover_factor >= 1 else "warn")
        rows.append(_figure(
            "Crossover factor: design / lowest hunting-free",
            ("\u2265 " if m.crossover_factor_bound else "") + num(m.crossover_factor, 3), "1",
            f"\u2265 {num(need, 3)}",  # the key's name in the basis: it overran the column
            "the hunting margin (requirements.hunting_margin); no move hunts from "
            f"{qty(m.hunting_free_crossover, 'Hz')} (the fold of the cycle); the ratio of the "
            "set crossovers, the loop's frequency scale"
            + (f"; the loop the cycle slides in ({_CASE_WORDS.get(m.hunting_case, m.hunting_case)})"
               f" crosses 0 dB at {qty(m.hunting_loop_crossover, 'Hz')} with the design's PID "
               f"and at {qty(m.hunting_free_loop_crossover, 'Hz')} with the PID at the "
               "hunting-free crossover, a ratio of "
               f"{num(m.hunting_loop_crossover / m.hunting_free_loop_crossover, 3)}"
               if m.hunting_loop_crossover and m.hunting_free_loop_crossover else ""), css))
    if m.achievable_factor is not None:
        rows.append(_figure("Achievable / desired crossover (linear, step 2)",
                            num(m.achievable_factor, 3), "1", "\u2265 1",
                            f"achievable {qty(result.crossover.achievable, 'Hz')}",
                            "pass" if m.achievable_factor >= 1 else "fail"))
    elif m.achievable_crossover_bound is not None:
        rows.append(_figure("Achievable crossover (linear, step 2)",
                            f"\u2265 {num(m.achievable_crossover_bound)}", "Hz", "",
                            "not limited below the search cap: a bound, not a result", "info"))
    if m.end_stop_clearance is not None:
        css = "fail" if m.end_stop_clearance <= 0 else "info"
        if any(r.source == "end_stop_clearance" for r in v.reasons):
            css = "warn"
        # the clearance, the deflection and the stroke are read together: one unit
        one = scale("m", (m.end_stop_clearance, m.resting_deflection, spec.isolator.stroke))
        defl, stroke = (quantity(x, "m", 3, sep=NBSP, shown=one) for x in
                        (m.resting_deflection, spec.isolator.stroke))
        rows.append(_figure("End-stop clearance at rest", num(m.end_stop_clearance * one[1], 3),
                            one[0], "> 0", f"joint deflection {defl} of the \u00b1{stroke} "
                                           "stroke", css))
    if m.stiffness_factor is not None:
        rows.append(_figure("k_max / k", num(m.stiffness_factor, 3), "1", "\u2265 1",
                            f"k = {qty(result.stiffness.chosen, 'N/m')}, k_max = "
                            f"{qty(result.stiffness.maximum, 'N/m')}",
                            "pass" if m.stiffness_factor >= 1 else "fail"))
    if m.stiffness_range is not None:
        lo, hi = m.stiffness_range
        rows.append(_figure(
            f"Net drive stiffness of the flexure, t = {qty(m.thickness, 'm')} \u00b1 "
            f"{qty(m.thickness_tolerance, 'm')}", f"{num(lo)} \u2013 {num(hi)}", "N/m",
            f"\u2264 {num(result.stiffness.maximum)}",
            f"the elastic part goes with t\u00b3, gravity's does not; k_max / k \u2265 "
            f"{num(m.stiffness_factor_worst, 3)}",
            "pass" if m.stiffness_factor_worst >= 1 else "fail"))
    if m.static_error is not None:
        ok = m.static_error <= m.static_error_bound + spec.requirements.hunting.settle_band
        rows.append(_figure("Static error at rest (loop without integrator)", m.static_error,
                            "m", f"\u2264 {qty(m.static_error_bound, 'm', 3)}",
                            STATIC_ERROR_FORMULA, "pass" if ok else "fail", 3))
    return rows


def verdict(result: Any) -> dict:
    """The verdict section: the verdict box, key figures, recommendation, the checks by step.

    Parameters
    ----------
    result : fi_design.results.design.DesignResult
        The design, with its :class:`~fi_design.results.design.Verdict`.

    Returns
    -------
    dict
        ``status`` (``PASS``, ``PASS_WITH_WARNINGS``, ``NOT_CONFIRMED``, ``FAIL``), ``overall``
        (as printed), ``css`` (pass, warn, fail), ``behaviour`` (the stamp),
        ``behaviour_css``, ``headline``, ``reasons`` (``severity``, ``css``,
        ``text``), ``figures`` (:func:`key_figures`), ``notes`` (margins not
        reported, and why), ``recommendation`` (text or None), ``next_step``
        (after a FAIL, the command that searches a design that passes), ``counts`` and
        ``total`` of the checks, ``groups`` (``step``, ``title``, ``rows`` of
        :func:`check_row`) and ``conclusion``.
    """
    v = result.verdict
    cases = {c.name: c for c in result.loop.cases}
    rows = [check_row(c, cases) for c in result.checks]
    counts = {s.value: sum(1 for r in rows if r["status"] == s.value) for s in Status}
    by_step: dict[str, dict] = {}  # one group per step, in the order steps first appear
    for row, check in zip(rows, result.checks):
        group = by_step.setdefault(check.step, {"step": check.step,
                                                "title": _step_title(check.step), "rows": []})
        group["rows"].append(row)
    groups = list(by_step.values())
    css = {"PASS": "pass", "PASS_WITH_WARNINGS": "warn", "NOT_CONFIRMED": "warn",
           "FAIL": "fail"}[v.status]
    behaviour_css, stamp = BEHAVIOUR[v.behaviour]
    if v.status == "FAIL" and behaviour_css in ("settles", "static-error"):
        behaviour_css, stamp = NOMINAL
    return {
        "status": str(v.status), "overall": STATUS_TEXT[v.status], "css": css,
        "behaviour": stamp, "behaviour_css": behaviour_css, "headline": v.headline,
        "reasons": [{"severity": r.severity, "css": r.severity.lower(), "text": r.text}
                    for r in v.reasons],
        "figures": key_figures(result),
        "notes": list(result.margins.notes) if result.margins is not None else [],
        "recommendation": None if result.recommendation is None
        else result.recommendation.text,
        "next_step": v.next_step,
        "counts": [{"status": s, "count": n, "css": s.lower()} for s, n in counts.items()],
        "total": len(rows),
        "groups": groups,
        "conclusion": result.conclusion,
    }


def _step_title(step: str) -> str:
    titles = {
        "step 1 friction gap": "Step 1 \u2013 friction gap",
        "step 2 crossover": "Step 2 \u2013 crossover and loop margins",
        "step 3 drive stiffness": "Step 3 \u2013 drive stiffness",
        "step 3 flexure": "Step 3 \u2013 leaf-spring flexure",
        "step 4 PID": "Step 4 \u2013 PID gains",
        "simulation (paper section 2.3)": "Nonlinear confirmation (simulated hunting)",
        "step 3 refinement: landing": "Step 3 refinement \u2013 where the cart comes to rest",
        "robustness under friction scatter": "Robustness under friction scatter",
        "positioning": "Positioning after every move (requirements.positioning)",
    }
    return titles.get(step, step[:1].upper() + step[1:] if step else "Other")
