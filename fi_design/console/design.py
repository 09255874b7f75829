"""The design's summary: the checks, the gains, the crossover and limit cases, the verdict.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..display import number, percent, quantity, unit_text, with_error
from ..effects import delay_words, simulated_only
from ..results.controller import filter_label
from ..results.linear import NOT_JUDGED, phase_margin_judged
from ..results.stage import STATIC_ERROR_FORMULA
from .common import heading, status_text, table
from .confirmation import moves_strips, simulation_table
from .recommend import search_origin

if TYPE_CHECKING:  # pragma: no cover
    from rich.console import Console


def checks_table(checks, title: str = "Checks", cases: Any = None):
    """A rich table of :class:`~fi_design.results.Check` values, status coloured.

    Checks are grouped by their ``step``: a bold heading row starts each group.
    Each check's name in words sits above its message in the first column,
    which wraps, so the table reads at 80 columns as at 200; value and limit
    share the unit the report shows them in (13.33 N/mm, 31.55 MPa, 47.31°),
    the limit with the requirement's sense (``≥ 30``).

    Parameters
    ----------
    checks : sequence of fi_design.results.Check
        The checks, in report order.
    title : str, optional
        Table title.
    cases : mapping, optional
        The design's limit cases by name, which name the case of a margin check
        (:func:`fi_design.report.check_label`).

    Returns
    -------
    rich.table.Table
        Columns check (with its message), status, value, limit, unit.
    """
    from rich.text import Text

    from ..report.checks import check_row

    t = table(title)
    t.add_column("Check", ratio=1, min_width=24, overflow="fold")
    t.add_column("Status", no_wrap=True)
    t.add_column("Value", justify="right", no_wrap=True)
    t.add_column("Limit", justify="right", no_wrap=True)
    t.add_column("Unit", no_wrap=True)
    step = None
    for c in checks:
        if (c.step or "") != step:
            step = c.step or ""
            if step:
                t.add_row(Text(step, style="bold underline"))
        row = check_row(c, cases)
        cell = Text(row["label"], style="bold")
        if row["message"]:
            cell.append("\n")
            cell.append(Text(row["message"], style="dim"))
        limit = number(row["limit"])
        if row["sense"] and row["limit"] is not None:
            limit = f"{row['sense']} {limit}"
        t.add_row(cell, status_text(c.status), number(row["value"]), limit,
                  Text(row["unit"] or ""))
    return t


def print_design(console: "Console", result, spec_path: Path | None = None) -> None:
    """Print the readable summary of a :class:`~fi_design.guideline.steps.DesignResult`.

    Parameters
    ----------
    console : rich.console.Console
        Where to print.
    result : fi_design.guideline.steps.DesignResult
        The design result.
    spec_path : pathlib.Path, optional
        The spec file, named in the heading.
    """
    from rich.text import Text

    data = result.to_dict()
    name = _spec_name(result)
    heading(console, name or "fi-design", spec_path)

    gap = data.get("friction_gap") or {}
    if gap:
        risk = gap.get("hunting_risk")
        where = "at or above" if risk else "below"
        console.print(Text(
            f"Friction gap Fs - Fc = {number(gap.get('gap'))} N, {where} the "
            f"{number(gap.get('threshold'))} N threshold of step 1 (the paper's rule for its own "
            "stage" + ("; the simulation decides)" if data.get("simulation") else ")")))

    loop = getattr(result, "loop", None)
    console.print(checks_table(result.checks,
                               cases={c.name: c for c in getattr(loop, "cases", ())}))

    spec = getattr(result, "spec", None)
    effects = tuple(spec.effects) if spec is not None else ()
    pid = data.get("pid") or {}
    if pid:
        console.print(_gains_table(pid, effects))
        sampled = discrete_table(pid)
        if sampled is not None:
            console.print(sampled)

    xo = data.get("crossover") or {}
    if xo:
        line = (f"Crossover: desired {number(xo.get('desired'))} Hz, achievable "
                f"{number(xo.get('achievable'))} Hz")
        if xo.get("limit_kind") == "scan_limit":   # the search cap: a bound, not a result
            line = (f"Crossover: desired {number(xo.get('desired'))} Hz; the linear model limits "
                    f"it nowhere below {number(xo.get('achievable'))} Hz (the search cap)")
        elif xo.get("limited_by"):
            line += f", limited by {xo['limited_by']}"
        console.print(Text(line))
        notch = xo.get("notch")
        if notch:
            console.print(Text(f"A {_filter_words(notch['notch'])} in controller.filters would "
                               + (f"allow {number(notch['achievable'])} Hz, then limited by "
                                  f"{notch['limited_by']}" if notch["achievable"] is not None
                                  else f"not help: {notch['limited_by']}")))
        cases = xo.get("cases") or []
        numbers = {c.name: c.number for c in result.loop.cases}
        if cases:
            console.print(cases_table(cases, numbers, effects))
            console.print(crossings_table(cases, numbers))
        if xo.get("loop_crossover") is not None:
            console.print(Text(
                f"Loop crossover {number(xo['loop_crossover'])} Hz: the highest 0 dB crossing "
                f"in the band, case {numbers.get(xo['loop_crossover_case'], '?')}; the parasitic "
                f"separation is judged on it (requirements.parasitic_separation)"))

    stiff = data.get("stiffness") or {}
    if stiff.get("maximum") is not None:
        if stiff.get("suggested"):
            text = (f"Drive stiffness by the rule for a {quantity(stiff['stroke'], 'm', 3)} "
                    f"stroke (no isolator in the spec): k_max = {number(stiff['maximum'])} N/m, "
                    f"k = k_max / 2 = {number(stiff.get('chosen'))} N/m")
        else:
            text = (f"Drive stiffness: k_max = {number(stiff['maximum'])} N/m, chosen k = "
                    f"{number(stiff.get('chosen'))} N/m")
            if stiff.get("source"):  # it holds parentheses of its own: after a comma
                text += f", {stiff['source']}"
            if stiff.get("force_at_stroke") is not None:
                text += f", flexure force at full stroke {number(stiff['force_at_stroke'], 3)} N"
        console.print(Text(text))

    sim = data.get("simulation")
    if isinstance(sim, dict) and "isolated" in sim:
        h = result.spec.requirements.hunting
        console.print(simulation_table(sim, (h.window_start, h.window_start + h.window_length),
                                        data.get("stage_hunting")))
        for line in moves_strips(data.get("stage_hunting") or {},
                                 bool(sim.get("suggested_isolator"))):
            console.print(line)

    _print_terms(console, result, data)
    conclusion = getattr(result, "conclusion", "") or data.get("conclusion", "")
    if conclusion:
        console.print(Text("Conclusion: ", style="bold").append(Text(str(conclusion),
                                                                        style="")))
    if getattr(result, "verdict", None) is not None:
        print_verdict(console, result)   # the input warnings are among its reasons
        return
    for w in getattr(result, "warnings", ()) or ():
        console.print(Text("warning: ", style="bold yellow").append(Text(_warning_text(w))))


#: The terms the console defines under its tables, where the summary uses them.
CONSOLE_TERMS = ("limit case", "Floquet multiplier", "fold", "landing")


def _print_terms(console: "Console", result, data: dict) -> None:
    """One dim line per term of :data:`CONSOLE_TERMS` that the summary prints."""
    from rich.text import Text

    from ..report.glossary import glossary

    text = " ".join([str(data.get("conclusion", ""))] + [c.message for c in result.checks]
                    + ["limit case"]   # the limit-case table
                    + (["Floquet multiplier"] if data.get("simulation") else []))
    for g in glossary(text):
        if g["term"] in CONSOLE_TERMS:
            console.print(Text(f"  {g['term']}: {g['definition']}", style="dim"))


def _gains_table(pid: dict, effects: tuple = ()) -> Any:
    """Step 4's gains, the one set a drive takes (``pid.drive``), named so.

    ``kp + ki/s + kd s / (1 + s/(2 pi roll_off))`` with the roll-off on the D
    term only (``controller.gains`` and ``controller.roll_off``), the filters
    on the output; with the hardware's own gains, the rule's at the same
    crossover in the same form beside them (``pid.rule.in_drive_form``); with
    ``controller.drive`` the same gains in counts and the drive's current unit.
    The caption names the loop's delay (``controller.delay`` and a ``time_delay``
    effect's) and the spec's other ``effects``, which the simulation carries and
    the gains and margins leave out.
    """
    from rich.text import Text

    drive = pid["drive"]
    rows = [("drive (hardware)" if pid.get("source") == "gains" else "drive", drive)]
    if pid.get("source") == "gains":
        rows.append(("rule, for comparison", pid["rule"]["in_drive_form"]))
    t = table("PID gains (step 4) a drive takes: kp + ki/s + kd s / (1 + s/(2 pi roll_off)), the "
              "roll-off on the D term only (controller.gains, controller.roll_off)")
    t.add_column("")
    for col in ("kp [N/m]", f"ki [{unit_text('N/(m*s)')}]", f"kd [{unit_text('N*s/m')}]",
                "roll_off [Hz]"):
        t.add_column(Text(col), justify="right", no_wrap=True)
    for label, g in rows:
        t.add_row(label, number(g["kp"]), number(g["ki"]), number(g["kd"]),
                  "none" if g["roll_off"] is None else number(g["roll_off"]))
    units = drive.get("in_drive_units")
    if units:
        u = units["units"]
        t.add_row(f"drive, in {units['current_unit']} and counts", f"{number(units['kp'])} {u['kp']}",
                  f"{number(units['ki'])} {u['ki']}", f"{number(units['kd'])} {u['kd']}", "")
    sampled = ("continuous" if drive["sample_rate"] is None
               else f"sampled at {quantity(drive['sample_rate'], 'Hz')}")
    delay = delay_words(drive["delay"] or 0.0, effects)
    simulated = simulated_only(effects)
    filters = "; ".join(_filter_words(f) for f in drive.get("filters") or ())
    rule = pid["rule"]
    t.caption = Text(f"D on the {drive['derivative_on']}, {sampled}, {delay}"
                     + (f"; filters on the output: {filters}" if filters else "; no filters")
                     + f"; the rule tunes on {quantity(rule['tuning_mass'], 'kg')} (controller."
                     "derivative_on, sample_rate, delay, filters); --write-spec writes them "
                     "into a spec" + (f"; {simulated}" if simulated else ""), style="dim")
    t.caption_justify = "left"
    return t


def _filter_words(f: dict) -> str:
    """One filter of ``pid.drive.filters`` in words."""
    if f["type"] == "notch":
        depth = "full" if f["depth"] is None else f"{number(f['depth'], 3)} dB"
        return (f"notch{filter_label(f['type'], f['name'])} {number(f['frequency'])} Hz, "
                f"{number(f['width'], 3)} Hz "
                f"wide, depth {depth}")
    if f["order"] == 1:
        return (f"low-pass{filter_label(f['type'], f['name'])} {number(f['frequency'])} Hz, "
                "first order")
    return (f"low-pass{filter_label(f['type'], f['name'])} {number(f['frequency'])} Hz, "
            "second order, damping "
            f"{number(f['damping'], 3)}")


def discrete_table(pid: dict) -> Any:
    """The sampled controller a drive computes each period (``pid.drive.discrete``), or None."""
    from rich.text import Text

    d = pid["drive"].get("discrete")
    if not d:
        return None
    t = table(f"The controller per sample at {quantity(d['sample_rate'], 'Hz')} (PID recursion, "
              "filter biquads)")
    t.add_column("")
    t.add_column("coefficients", ratio=1)
    t.add_row("PID", Text(f"kp {number(d['kp'])} N/m; integrator ki T/2 "
                          f"{number(d['integrator_gain'])} N/m; D pole "
                          f"{number(d['derivative_pole'])}, gain "
                          f"{number(d['derivative_gain'])} N/m"))
    for f in d["filters"]:
        t.add_row(f["name"], Text("b = " + ", ".join(number(x, 6) for x in f["b"]) + "; a = "
                                  + ", ".join(number(x, 6) for x in f["a"])))
    t.caption = Text("I_k = I_(k-1) + (ki T/2)(e_k + e_(k-1)); D_k = pole D_(k-1) + gain "
                     "(d_k - d_(k-1)); u_k = kp e_k + I_k + D_k, then each biquad y_k = b0 x_k "
                     "+ b1 x_(k-1) + b2 x_(k-2) - a1 y_(k-1) - a2 y_(k-2) (Tustin prewarped at "
                     "the filter's frequency)", style="dim")
    t.caption_justify = "left"
    return t


def crossings_table(cases: list, numbers: dict) -> Any:
    """Every 0 dB and -180 deg crossing of each limit case with the margin read there."""
    from rich.text import Text

    t = table("Every crossing of each limit case")
    t.add_column("#", justify="right", no_wrap=True)
    t.add_column("0 dB crossings: frequency (phase margin, delay margin)", ratio=1)
    t.add_column("-180° crossings: frequency (gain margin)", ratio=1)
    for i, case in enumerate(cases, 1):
        gains = ", ".join(
            f"{number(g['frequency'])} Hz ({number(g['phase_margin_deg'], 3)}°, "
            f"{number(g['delay_margin'], 3)} s" + ("" if g["in_band"] else ", below the band")
            + ")" for g in case.get("gain_crossings") or ()) or "none"
        phases = ", ".join(f"{number(p['frequency'])} Hz ({number(p['gain_margin_db'], 3)} dB)"
                           for p in case.get("phase_crossings") or ()) or "none"
        t.add_row(str(numbers.get(case.get("name"), i)), Text(gains), Text(phases))
    return t


#: Border and title style of the verdict box per status; a stage that does not settle gets a
#: heavy frame, so the box differs in shape too (monochrome terminals, logs).
_VERDICT_LOOK = {"PASS": ("green", "ROUNDED"), "PASS_WITH_WARNINGS": ("yellow", "ROUNDED"),
                 "NOT_CONFIRMED": ("yellow", "DOUBLE"),
                 "FAIL": ("red", "HEAVY")}


def print_verdict(console: "Console", result) -> None:
    """Print the sign-off verdict of a design as a framed box: status, reasons, figures.

    The box names what the stage as specified does (settles, hunts, ...), lists
    the reasons (FAIL, WARN, PASS), then the robustness under friction scatter,
    the margins with units and the recommendation. A green rounded frame for
    PASS, yellow for PASS_WITH_WARNINGS, a double yellow one for NOT_CONFIRMED (not
    simulated: it does not pass), a heavy red one for FAIL.

    Parameters
    ----------
    console : rich.console.Console
        Where to print.
    result : fi_design.results.design.DesignResult
        The design, with its verdict.
    """
    from rich import box
    from rich.panel import Panel
    from rich.table import Table
    from rich.text import Text

    v = result.verdict
    colour, frame = _VERDICT_LOOK[v.status]
    body = Table.grid(padding=(0, 1))
    body.add_column(no_wrap=True)
    body.add_column(ratio=1)
    body.add_row("", Text(v.headline, style="bold"))
    for r in v.reasons:
        body.add_row(status_text(r.severity), Text(r.text))
    rob, mar = result.robustness, result.margins
    if rob is not None and rob.hunting_probability is None:
        body.add_row(Text("Scatter", style="bold"), Text(
            f"not determined: none of the {rob.samples} samples was simulated to the end, "
            f"limit {percent(rob.limit)}"))
    elif rob is not None:
        body.add_row(Text("Scatter", style="bold"), Text(
            f"does not settle in {percent(rob.hunting_probability)} of {rob.valid} samples "
            f"({percent(rob.interval[0])} to {percent(rob.interval[1])} at "
            f"{percent(rob.confidence)}), limit {percent(rob.limit)}"))
    if mar is not None:
        items = []
        if mar.crossover_factor is not None:
            items.append(f"crossover {'>= ' if mar.crossover_factor_bound else ''}"
                         f"{number(mar.crossover_factor, 3)}x the hunting-free "
                         f"{number(mar.hunting_free_crossover, 4)} Hz"
                         + (f" (the sliding loop crosses 0 dB at "
                            f"{number(mar.hunting_loop_crossover, 4)} Hz with the design's "
                            f"PID, at {number(mar.hunting_free_loop_crossover, 4)} Hz with "
                            "the PID at the hunting-free crossover)"
                            if mar.hunting_loop_crossover and mar.hunting_free_loop_crossover
                            else ""))
        if mar.end_stop_clearance is not None:
            items.append(f"end stop {quantity(mar.end_stop_clearance, 'm', 3)} away at rest")
        if mar.stiffness_factor is not None:
            items.append(f"k_max / k = {number(mar.stiffness_factor, 3)}")
        if mar.stiffness_range is not None:
            lo, hi = mar.stiffness_range
            items.append(f"k {quantity((lo, hi), 'N/m', 4)} for t = "
                         f"{with_error(mar.thickness, mar.thickness_tolerance, 'm', 3, 2)}")
        if mar.static_error is not None:
            items.append(f"static error {quantity(mar.static_error, 'm', 3)} of "
                         f"{quantity(mar.static_error_bound, 'm', 3)} {STATIC_ERROR_FORMULA}")
        if items:
            body.add_row(Text("Margins", style="bold"), Text("; ".join(items)))
    if result.recommendation is not None:
        body.add_row(Text("Advice", style="bold"), Text(result.recommendation.text))
    if v.next_step:
        body.add_row(Text("Next", style="bold"), Text(v.next_step))
    console.print(Panel(body, title=Text(f"Verdict: {v.status}", style=f"bold {colour}"),
                        title_align="left", border_style=colour, box=getattr(box, frame)))
    search = None if result.recommendation is None else result.recommendation.search
    cached = None if search is None else search_origin(search)
    if cached is not None:  # the advice's search read from the cache: where from (a path folds)
        console.print(f"The design search: {cached}", markup=False, highlight=False)


def _spec_name(result) -> str:
    spec = getattr(result, "spec", None)
    return getattr(spec, "name", "") if spec is not None else ""


def _warning_text(w: Any) -> str:
    if isinstance(w, (tuple, list)) and len(w) == 2:
        return f"{w[0]}: {w[1]}"
    return str(w)


#: Columns of the limit-case table: JSON key -> short header with unit (others are appended).
CASE_COLUMNS = {
    "crossover": "fc [Hz]",
    "phase_margin_deg": "PM [deg]",
    "gain_margin_db": "GM [dB]",
    "modulus_margin": "MM [-]",
    "delay_margin": "DM [s]",
}


#: What the short headers of the limit-case table mean (the table's caption).
CASE_CAPTION = ("fc: gain crossover; PM, GM, MM, DM: phase, gain, modulus and delay margin "
                "(inf: no crossing; \u2013: the loop crosses 0 dB only outside its band, where "
                "the phase and delay margins are not judged); an unstable case fails with "
                "'stability'")

#: The columns a case whose phase margin is not judged shows as "–", as the report does.
_UNJUDGED = ("phase_margin_deg", "delay_margin")


_CASE_SKIP = {"name", "description", "passed", "failed", "crossovers", "stable", "in_band",
              "status", "modulus_frequency"}


def cases_table(cases: list, numbers: dict, effects: tuple = ()) -> Any:
    """Table of the linear limit cases (paper Figure 2) from their JSON form and numbers; the
    caption names the spec's ``effects`` the margins leave out (all but a ``time_delay``)."""
    from rich.text import Text

    keys = [k for k in CASE_COLUMNS if any(k in c for c in cases)]
    for case in cases:
        keys += [k for k, v in case.items() if k not in keys and k not in _CASE_SKIP
                 and not isinstance(v, (dict, list))]
    t = table("Linear limit cases at the desired crossover (paper Figure 2)")
    simulated = simulated_only(effects)
    t.caption = Text(CASE_CAPTION + (f". {simulated[0].upper()}{simulated[1:]}" if simulated
                                     else ""), style="dim")
    t.caption_justify = "left"
    t.add_column("#", justify="right", no_wrap=True)
    t.add_column("Limit case", ratio=1, min_width=12)
    for k in keys:
        t.add_column(Text(CASE_COLUMNS.get(k, _header(k))), justify="right", no_wrap=True)
    t.add_column("Status", min_width=6)
    for i, case in enumerate(cases, 1):
        case_no = str(numbers.get(case.get("name"), i))
        label = case.get("description") or case.get("name") or ""
        judged = phase_margin_judged(case.get("criteria") or {})
        cells = [Text("\u2013" if k in _UNJUDGED and not judged else
                      "inf" if case.get(k) is None and "margin" in k else number(case.get(k)))
                 for k in keys]
        status = status_text(case["status"])  # as the analysis judged it
        why = [*map(str, case.get("failed") or ()), *(() if judged else (NOT_JUDGED,))]
        if why:
            status.append(" " + ", ".join(why))
        t.add_row(case_no, Text(str(label)), *cells, status)
    return t


def _header(key: str) -> str:
    """``crossover_hz`` -> ``Crossover [Hz]``; other keys capitalised."""
    units = {"_hz": "Hz", "_deg": "deg", "_db": "dB", "_s": "s", "_m": "m", "_n": "N",
             "_rad_s": "rad/s"}
    for suffix, unit in units.items():
        if key.endswith(suffix):
            return f"{key[: -len(suffix)].replace('_', ' ').capitalize()} [{unit}]"
    return key.replace("_", " ").capitalize()
