"""The verdict of a design report: every check as a row, grouped by guideline step."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from ..results import Status
from .filters import display_scale

__all__ = ["STEP_SOURCES", "SENSE", "check_label", "check_row", "verdict"]


#: Where each guideline step comes from in the paper, for the checks' "source" column.
STEP_SOURCES = {
    "step 1 friction gap": "step 1; paper \u00a74, Fig. 4A",
    "step 2 crossover": "step 2; paper \u00a72.2, \u00a74, Fig. 2",
    "step 3 drive stiffness": "step 3; paper \u00a74, Fig. 4C",
    "step 3 flexure": "step 3; paper \u00a74, \u00a75",
    "step 3 refinement: landing": "step 3 (simulated landing)",
    "step 4 PID": "step 4; paper \u00a72.2",
    "simulation (paper section 2.3)": "simulation; paper \u00a72.3, Fig. 5",
}

#: Requirement sense of each check (by name, or by the name's part before the first dot).
SENSE = {
    "friction_gap": "<", "crossover_achievable": "\u2264", "phase_margin": "\u2265",
    "gain_margin": "\u2265", "modulus_margin": "\u2265", "parasitic_separation": "\u2265",
    "drive_stiffness": "\u2264", "flexure.stiffness": "\u2264", "flexure.stress": "\u2264",
    "flexure.support_frequency": "\u2265", "flexure.bending_frequency": "\u2265",
    "simulation_isolated": "=", "min_crossover_isolated": "\u2264", "landing_force": "<",
}


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
        "simulation_isolated": "Simulated hunting with the isolator",
        "simulation_non_isolated": "Simulated hunting without the isolator",
        "min_crossover_isolated": "Lowest hunting-free crossover with the isolator",
        "min_crossover_non_isolated": "Lowest hunting-free crossover without the isolator",
        "isolator_needed": "Is the isolator needed at this crossover?",
        "landing_force": "Flexure force on the resting cart",
        "friction_model_cross_check": "Cross-check with the other friction model",
    }
    flex = {"stiffness": "Flexure drive stiffness within k_max",
            "stress": "Flexure bending stress at full stroke",
            "support_frequency": "Flexure support-direction frequency",
            "bending_frequency": "Flexure leaf bending resonance"}
    if head == "flexure" and tail in flex:
        return flex[tail]
    if head == "pid" and tail == "tuning_mass":
        return "PID tuning mass"
    return labels.get(head, name.replace("_", " ").capitalize())


def _sense(name: str) -> str:
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
        "sense": _sense(check.name) if check.limit is not None else "",
        "unit": shown,
        "source": STEP_SOURCES.get(check.step, check.step),
        "message": check.message,
    }


def verdict(result: Any) -> dict:
    """The verdict section: overall status, counts per status, the checks grouped by step.

    Parameters
    ----------
    result : fi_design.results.design.DesignResult
        The design.

    Returns
    -------
    dict
        ``overall``, ``css``, ``headline``, ``counts``, ``total``, ``groups``
        (``step``, ``title``, ``rows`` of :func:`check_row`), ``conclusion``
        and ``warnings``.
    """
    cases = {c.name: c for c in result.loop.cases}
    rows = [check_row(c, cases) for c in result.checks]
    counts = {s.value: sum(1 for r in rows if r["status"] == s.value) for s in Status}
    if counts["FAIL"]:
        overall, css = "FAIL", "fail"
        headline = (f"{counts['FAIL']} of {len(rows)} checks fail: the design does not meet "
                    "its requirements as specified.")
    elif counts["WARN"]:
        overall, css = "PASS with warnings", "warn"
        headline = (f"No check fails; {counts['WARN']} warning"
                    f"{'s' if counts['WARN'] != 1 else ''} to review.")
    else:
        overall, css = "PASS", "pass"
        headline = "Every check passes."
    groups: list[dict] = []
    for row, check in zip(rows, result.checks):
        if not groups or groups[-1]["step"] != check.step:
            groups.append({"step": check.step, "title": _step_title(check.step), "rows": []})
        groups[-1]["rows"].append(row)
    return {
        "overall": overall, "css": css, "headline": headline,
        "counts": [{"status": s, "count": n, "css": s.lower()} for s, n in counts.items()],
        "total": len(rows),
        "groups": groups,
        "conclusion": result.conclusion,
        "warnings": [{"path": p, "message": m} for p, m in result.warnings],
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
    }
    return titles.get(step, step[:1].upper() + step[1:] if step else "Other")
