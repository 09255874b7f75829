"""The design report: the context of a :class:`~fi_design.guideline.steps.DesignResult`.

Sections in order: verdict, inputs, the four guideline steps, the linear
analysis, the nonlinear confirmation, a hunting map around the design point
(when the caller passes one), assumptions and limitations, references and an
appendix. All wording and arithmetic happen here; the templates only place
it.
"""

from __future__ import annotations

from typing import Any

from ..display import NBSP, column, quantity
from ..effects import simulated_only
from ..results.design import DesignResult
from ..results.linear import NOT_JUDGED, phase_margin_judged
from ..results.stage import STATIC_ERROR_FORMULA, length_range
from ..results.studies import DesignMap
from .assumptions import assumptions, family_words
from .blocks import figure_entry
from .checks import verdict
from .context import build_context
from .filters import num, qty
from .glossary import glossary
from .guide import guide_section
from .inputs import spec_inputs, split_inputs
from .meta import spec_listing, title_block, versions
from .steps import guideline_steps
from .validation import validation_section

__all__ = ["design_context", "REFERENCES"]


def _cases_table(result: Any) -> list[dict]:
    """Rows of the margins table, with each case's status as the analysis judged it; a case
    whose phase margin is not judged (:func:`~fi_design.results.linear.phase_margin_judged`,
    as in the console) shows no phase or delay margin, and says why."""
    numbers = {c.name: c.number for c in result.loop.cases}
    rows = []
    for c in result.crossover.cases:
        status = c.status.value
        judged = phase_margin_judged(c.criteria)
        rows.append({
            "number": numbers.get(c.name, ""), "description": c.description,
            "crossover": c.crossover, "crossovers": len(c.crossovers),
            "phase_margin": c.phase_margin_deg if judged else None,
            "gain_margin": c.gain_margin_db, "modulus_margin": c.modulus_margin,
            "delay_margin": c.delay_margin if judged else None,
            "stable": "yes" if c.stable else "no", "status": status, "css": status.lower(),
            "failed": ", ".join(c.failed + (() if judged else (NOT_JUDGED,))),
        })
    return rows


def _crossings(result: Any) -> list[dict]:
    """Every 0 dB and -180 deg crossing of each case with its margin, one row a case."""
    numbers = {c.name: c.number for c in result.loop.cases}
    rows = []
    for c in result.crossover.cases:
        gains = "; ".join(
            f"{qty(g.frequency, 'Hz')}: {qty(g.phase_margin_deg, 'deg', 3)}, "
            f"{qty(g.delay_margin, 's', 3)}" + ("" if g.in_band else " (below the band)")
            for g in c.gain_crossings) or "none"
        phases = "; ".join(f"{qty(p.frequency, 'Hz')}: {qty(p.gain_margin_db, 'dB', 3)}"
                           for p in c.phase_crossings) or "none"
        rows.append({"number": numbers.get(c.name, ""), "description": c.description,
                     "gain_crossings": gains, "phase_crossings": phases,
                     "peak": "none" if c.modulus_frequency is None
                     else qty(c.modulus_frequency, "Hz")})
    return rows


class _Numbering:
    """Figure numbers in order of appearance."""

    def __init__(self) -> None:
        self.n = 0

    def __call__(self) -> int:
        self.n += 1
        return self.n


def _linear(result: Any, figures: bool, fig_no: _Numbering) -> dict:
    from .. import plots

    req = result.spec.requirements
    xo = result.crossover
    n = len(xo.cases)
    m = req.modulus_margin if req.modulus_margin is not None else 0.5
    simulated = simulated_only(result.spec.effects, sep=NBSP)
    delayed = any(e.type == "time_delay" for e in result.spec.effects)
    return {
        "intro": (
            f"The loop L = C D P of each of the {n} linear limit cases (paper Figure 2) with the "
            f"PID of step 4 at the desired crossover of {qty(xo.desired, 'Hz')}"
            + (f" and a Pad\u00e9 model of the {qty(xo.delay, 's')} loop delay"
               + (", the spec's effect time_delay included" if delayed else "")
               if xo.delay > 0 else "")
            + (f" (the margins of the loop without the spec's {'other ' if delayed else ''}"
               f"effects: {simulated})" if simulated else "")
            + ". Margins come from python-control's stability_margins; closed-loop stability "
            "from the roots of the characteristic polynomial. A case can cross 0 dB more than "
            "once; the first table gives the crossing with the smallest phase margin and the "
            "number of crossings, the second every crossing with the margin read there."
            + (f" The drive's filters on the PID's output: "
               + "; ".join(f.describe() for f in result.pid.controller.filters) + "."
               if result.pid.controller.filters else "")),
        "bode": figure_entry(
            (lambda: plots.bode_figure(result)) if figures else None, "bode",
            _bode_caption(result), fig_no()),
        "nyquist": figure_entry(
            (lambda: plots.nyquist_figure(result)) if figures else None, "nyquist",
            f"Nyquist plot near the critical point -1 (+). Dotted: |1 + L| = {num(m)}. Colours "
            "and line styles as in the Bode plot.", fig_no(), "half"),
        "sensitivity": figure_entry(
            (lambda: plots.sensitivity_figure(result)) if figures else None, "sensitivity",
            "Sensitivity |S| = |1/(1 + L)| over the band of the Bode plot; dots mark each "
            "case's peak (1 / modulus margin), dotted: the modulus margin's limit, dashed: the "
            "desired crossover.", fig_no(), "half"),
        "cases": _cases_table(result),
        "crossings": _crossings(result),
        "loop_crossover": (
            f"The parasitic separation is judged on the loop's crossover, the highest 0 dB "
            f"crossing in the band: {qty(xo.loop_crossover, 'Hz')} (case "
            f"{next((c.number for c in result.loop.cases if c.name == xo.loop_crossover_case), '?')}"
            f", {next((c.description for c in xo.cases if c.name == xo.loop_crossover_case), '')})"
            f", so every parasitic mode must lie above "
            f"{qty(req.parasitic_separation * xo.loop_crossover, 'Hz')}."
            if xo.loop_crossover is not None else
            "No case crosses 0 dB in the loop's band: the parasitic separation is judged on the "
            "desired crossover."),
        "requirements": {"phase_margin": req.phase_margin, "gain_margin": req.gain_margin,
                         "modulus_margin": req.modulus_margin},
        "note": ("A negative gain margin marks a lower gain margin: the integrator on a free mass "
                 "starts the phase below -180\u00b0, and the loop goes unstable if the gain "
                 "falls by that much. An infinite gain margin means the phase never crosses "
                 "-180\u00b0. A case whose loop crosses 0 dB only more than a decade below the "
                 f"{qty(xo.desired, 'Hz')} crossover (the integrator against the bristles of a "
                 "stuck cart), or never, has no phase or delay margin in the loop's band: "
                 "shown as \u2013 (INFO), its gain margin still counts."),
    }


def _bode_caption(result: Any) -> str:
    """What the Bode plot draws: its band, the marks, and the crossovers it leaves out."""
    from .. import plots

    lo, hi = plots.design_band(result)
    text = (f"Open-loop Bode plot of the {len(result.crossover.cases)} limit cases from "
            f"{qty(lo, 'Hz')} to {qty(hi, 'Hz')}, the loop's band around the desired "
            f"crossover of {qty(result.crossover.desired, 'Hz')} (dashed). Dots: the gain "
            "crossovers.")
    numbers = {c.name: c.number for c in result.loop.cases}
    far = plots.out_of_band_crossovers(result)
    if far:
        text += " Below the band, not drawn: " + "; ".join(
            f"case {numbers.get(c.name, '?')} "
            + ("also crosses" if any(y and y >= lo for y in c.crossovers) else "crosses")
            + f" 0 dB at {qty(x, 'Hz', 3)}"
            for c, x in far) + " (the integrator against a stiff support, outside the loop's band)."
    return text


def _error_caption(sim: Any, spec: Any) -> str:
    """What the position-error figure draws, mark by mark: only what is there."""
    h = spec.requirements.hunting
    plants = [sim.isolated, sim.non_isolated]
    which = ("with the rule's isolator (for comparison) and without it" if sim.suggested_isolator
             else "with and without the isolator")
    marks = ["grey, the counting window", "dashed, the minimum peak height"]
    if any(len(p.metrics.peak_times) for p in plants):
        marks.append("circles, the peaks the metric counts")
    else:
        marks.append("no peak counted in either plant")
    right = [f"green, the settle band of \u00b1{qty(h.settle_band, 'm')}"]
    if any(p.metrics.settling_time is not None for p in plants):
        right.append("dotted, where the error enters it for good (the settling time)")
    return (f"Position error after the spec's own motion {which}. Left, in mm, as the "
            "paper's Figure 5: "
            + "; ".join(marks) + ". Right, in \u00b5m after the motion: " + "; ".join(right)
            + ".")


#: Friction models as the literature names them.
_MODEL_NAMES = {"lugre": "LuGre", "switch": "switch (Karnopp-type)"}


def _plant_labels(sim: Any) -> dict[str, str]:
    """The two plants' row labels: which one the spec specifies, which one is compared."""
    if sim.suggested_isolator:
        return {"isolated": "rule's isolator (comparison)",
                "non_isolated": "without isolator (as specified)"}
    return {"isolated": "with isolator (as specified)",
            "non_isolated": "without isolator (comparison)"}


def _plant_rows(sim: Any) -> list[dict]:
    names = _plant_labels(sim)
    rows = []
    for key, name in names.items():
        v = getattr(sim, key)
        m = v.metrics
        other = sim.cross_check.get(key)
        rows.append({
            "plant": name, "verdict": v.outcome.replace("_", " "),
            "css": {"settled": "pass", "static_error": "pass",
                    "hunting": "fail"}.get(v.outcome, "warn"),
            # a run that did not complete counted nothing and ended nowhere: no values
            "cycles": m.hunting_cycles if v.success else None,
            "amplitude": m.amplitude if v.success else None, "period": m.period,
            "settling_time": m.settling_time,
            "final_error": m.final_error if v.success else None,
            "other": other.outcome.replace("_", " ") if other is not None else "",
            "other_model": other.friction_model if other is not None else "",
            "reason": m.reason if v.outcome != "static_error" else (
                f"at rest {qty(abs(m.final_error), 'm')} from the target, within the static "
                f"error {STATIC_ERROR_FORMULA} = {qty(v.static_error_bound, 'm', 3)} of a loop "
                "without integrator"),
        })
    return rows


#: The columns of the nonlinear tables that carry a unit: key -> (header, SI unit, digits).
_STAGE_COLUMNS = {"amplitude": ("Cycle (p-p)", "m", 3), "period": ("Period", "s", 3),
                  "free_from": ("No move hunts from", "Hz", 4)}
_PLANT_COLUMNS = {"amplitude": ("Amplitude (p-p)", "m", 3), "period": ("Period", "s", 3),
                  "settling_time": ("Settling time", "s", 3),
                  "final_error": ("Final error", "m", 3)}


def _in_columns(rows: list[dict], columns: dict) -> dict:
    """Each column of a table in one unit, named in its header (:func:`display.column`): the
    cells' text in ``row["cells"]``; returns the headers."""
    heads = {}
    for key, (title, unit, digits) in columns.items():
        shown, cells = column([r[key] for r in rows], unit, digits)
        heads[key] = f"{title} [{shown}]" if shown else title
        for r, cell in zip(rows, cells):
            r.setdefault("cells", {})[key] = cell
    return heads


def _stage_rows(sim: Any) -> list[dict]:
    """One row per plant of the stage-level answer (every move of its family)."""
    names = _plant_labels(sim)
    rows = []
    for key, name in names.items():
        st = sim.stage[key]
        c = st.cycle
        dist = sorted(abs(d) for d in st.entered_by)
        rows.append({
            "plant": name, "outcome": st.outcome.replace("_", " "),
            "css": "pass" if st.acceptable else ("fail" if st.hunts else "warn"),
            "moves": f"{len(st.hunting_moves)} of {len(st.moves)}",
            "entered": ("" if not dist else qty(dist[0], "m") if len(dist) == 1
                        else length_range(dist[0], dist[-1])),
            "amplitude": None if c is None else c.amplitude,
            "period": None if c is None else c.period,
            "multiplier": None if c is None else c.multiplier,
            "limiter": "" if c is None or c.on_limiter is None else
            ("yes" if c.on_limiter else "no"),
            "free_from": st.hunting_free_from,
            "bracket": st.boundary_text(),
            "text": st.describe(name[0].upper() + name[1:]),
        })
    return rows


def _nonlinear(result: Any, figures: bool, fig_no: _Numbering) -> dict | None:
    from .. import plots

    sim = result.simulation
    if sim is None:
        return None
    spec = result.spec
    h = spec.requirements.hunting
    iso = sim.results["isolated"]
    label = ("the rule's isolator (step 3's k_max / 2 for the paper's 0.3 mm stroke)"
             if sim.suggested_isolator else "the isolator")
    land = sim.landing
    out = {
        "intro": (
            f"Hunting is a property of the stage, not of one move: with {label} and without it, "
            "at the design crossover and with "
            f"{_MODEL_NAMES.get(sim.isolated.friction_model, sim.isolated.friction_model)} "
            f"friction, the stage is simulated after every move of a family "
            f"({family_words(result)}). A run stops once the "
            "stage rests within the settle band for good (the friction force the loop will "
            "ask of the resting cart stays below its static friction) or once its state repeats "
            "at the Poincar\u00e9 section x1 - r = 0: a sustained cycle. The cycle is then "
            "converged as a periodic orbit by Newton's method on the return map, whose Floquet "
            "multiplier below 1 shows it attracts (a multiplier that two perturbation sizes "
            "disagree on is not shown: the moves that end in the cycle show it attracts); the "
            "crossover from which no move hunts is "
            "the cycle's fold, found by bisection."),
        "stage": (stage := _stage_rows(sim)),
        "stage_heads": _in_columns(stage, _STAGE_COLUMNS),
        "spec_intro": (
            "The spec's own motion alone, as the paper judges it (section 2.3): the peaks of "
            f"the position error x1 - r of at least {qty(h.min_height, 'm')} and standing out "
            f"by as much, at least {qty(h.min_distance, 's')} apart, in the window "
            f"[{num(h.window_start)} s, {num(h.window_start + h.window_length)} s); one peak "
            "is one hunting cycle. This answers for one move only."),
        "plants": (plants := _plant_rows(sim)),
        "plant_heads": _in_columns(plants, _PLANT_COLUMNS),
        "moves": figure_entry(
            (lambda: plots.moves_figure(sim)) if figures else None, "moves",
            "How the stage ends after each move of its family: the cycle's peak to peak for a "
            "move that hunts (filled), 0 for one that comes to rest (open); the star is the "
            "spec's own motion.", fig_no()),
        # the cycles' and the boundary's figures only where a plant hunts or a boundary was
        # found: no empty phase portrait, no boundary axis for a loop without integrator
        "cycle": None if not any(st.cycle is not None for st in sim.stage.values()) else
        figure_entry(
            (lambda: plots.cycle_figure(sim, spec)) if figures else None, "cycle",
            "The hunting cycles: phase portraits (left), the isolated stage's joint deflection "
            "over one period against its stroke (middle), and the settling after the spec's "
            f"own motion in the \u00b1{quantity(h.settle_band, 'm', shown=('µm', 1e6))} settle band "
            "(right).",
            fig_no()),
        "boundary": None if not any(st.boundary is not None and st.boundary.branch
                                    for st in sim.stage.values()) else figure_entry(
            (lambda: plots.boundary_figure(sim)) if figures else None, "boundary",
            "The stage-level boundary: the peak to peak of each plant's hunting cycle as the "
            "crossover rises, up to the cycle's fold (dotted), from which no move of the "
            "family hunts; dashed, the design crossover.", fig_no()),
        "positioning": _positioning(result, figures, fig_no),
        "error": figure_entry(
            (lambda: plots.error_figure(sim, spec)) if figures else None, "error",
            _error_caption(sim, spec), fig_no()),
        "deflection": figure_entry(
            (lambda: plots.deflection_figure(sim, spec)) if figures else None, "deflection",
            "Joint deflection of the isolated stage after the spec's own motion, against the "
            "stroke; beyond the dashed lines the limiter carries the cart.", fig_no()),
        "landing": None if land is None else {
            "deflection": land.deflection, "stroke": land.stroke, "force": land.force,
            "static_friction": land.static_friction, "rule_force": land.rule_force,
            "on_limiter": "yes" if land.on_limiter else "no",
            # the one judged statement of the landing: the check's
            "text": next(c.message for c in result.checks if c.name == "landing_force"),
        },
        "forces": _forces(sim.forces),
        "models_agree": sim.models_agree,
        "cross_check": (
            "Cross-check with the "
            f"{_MODEL_NAMES.get(sim.cross_check['isolated'].friction_model, '')} friction model: "
            + ("both models give the same hunting / no-hunting call for both plants."
               if sim.models_agree else
               "the models disagree on the verdict (see the checks); treat the margin to hunting "
               "as small.")),
        "solver": {"steps": iso.n_steps, "rejected": iso.n_rejected, "events": iso.n_events},
    }
    return out


def _forces(forces: Any) -> dict | None:
    """The forces over the move family, a row per move (the spec's motion and every second
    move of the family where the table would run long, which the intro says)."""
    if forces is None:
        return None
    moves = list(forces.moves)
    thinned = len(moves) > 13
    if thinned:  # the spec's own motion and every second move of the family
        moves = moves[:1] + moves[1::2]
    rows = [{"label": "the spec's motion" if m.label == "spec" else "family",
             "distance": abs(m.distance) * 1e3, "impacts": m.impacts,
             "stop": m.peak_stop_force, "contact": m.contact_time,
             "actuator": m.peak_actuator_force} for m in moves]
    n = len(forces.moves)
    if forces.stop_stiffness is None:
        intro = (f"Without the isolator there is no end stop; the largest actuator force over "
                 f"the {n} moves is {qty(forces.peak_actuator_force, 'N')}.")
    else:
        intro = (f"{forces.moves_on_stop} of {n} moves run the joint onto its end stop (contact "
                 f"stiffness {qty(forces.stop_stiffness, 'N/m')}, damping "
                 f"{qty(forces.stop_damping, 'N*s/m')}"
                 + (", the spec's defaults: an assumption, the contact force goes with the "
                    "square root of the stiffness" if forces.stop_default else "")
                 + f"), up to {forces.most_impacts} times a move, with a contact force of up to "
                   f"{qty(forces.peak_stop_force, 'N')}; the actuator's largest force is "
                   f"{qty(forces.peak_actuator_force, 'N')}. Each move is simulated from rest "
                   f"through its settling ({qty(forces.settle, 's')} after its end) with traces "
                   f"at {qty(forces.rate, 'Hz')}.")
    if forces.held_weight:
        intro += (f" On the vertical drive axis the actuator also holds the weight (m\u2081 + "
                  f"m\u2082) g = {qty(forces.held_weight, 'N')}, which the simulation does not "
                  "carry: every actuator force here adds it to the simulated force's largest "
                  "magnitude.")
    if thinned:
        intro += (f" The table lists {len(rows)} of the {n} moves: the spec's motion and every "
                  f"second move of the family; the numbers above are over all {n}.")
    return {"intro": intro, "rows": rows}


def _positioning(result: Any, figures: bool, fig_no: _Numbering) -> dict | None:
    """The positioning requirement over the move family: what it asks, the figure, the checks."""
    from .. import plots

    pos = result.positioning
    if pos is None:
        return None
    asks = []
    if pos.settle_time_limit is not None:
        asks.append(f"within \u00b1{qty(pos.band, 'm')} of its target at most "
                    f"{qty(pos.settle_time_limit, 's')} after the end of each move")
    if pos.static_error_limit is not None:
        asks.append(f"at rest at most {qty(pos.static_error_limit, 'm')} from it")
    checks = [c for c in result.checks if c.name.startswith("positioning.")]
    return {
        "intro": ("What the stage is for (requirements.positioning): " + " and ".join(asks)
                  + f", after every move of the family ({len(pos.moves)} moves of the stage as "
                  "specified). The settle time is read from each move's trace sampled every "
                  f"{qty(pos.resolution, 's')}: the last instant the error lies outside the "
                  "band, counted from the end of the move."),
        "checks": [{"status": c.status.value, "css": c.status.value.lower(),
                    "text": c.message} for c in checks],
        "figure": figure_entry(
            (lambda: plots.positioning_figure(pos)) if figures else None, "positioning",
            "Positioning after every move of the family: left, the settle time (dashed: the "
            "requirement; a cross at the top: never within the band); right, the error the "
            "stage rests at (dashed: the allowed static error, dotted: the band). Filled: the "
            "move meets the requirement; lighter: negative moves; star: the spec's motion.",
            fig_no()),
    }


def _map_section(design_map: DesignMap | None, figures: bool, fig_no: _Numbering) -> dict | None:
    if design_map is None:
        return None
    from .. import plots

    result = design_map.sweep
    x, y = result.x, result.y
    note = ""
    if design_map.suggested:
        note = (f"The spec has no isolator: the map uses the rule's one "
                f"({qty(design_map.stroke, 'm')} stroke, {qty(design_map.stiffness, 'N/m')}). ")
    held = ("the drive stiffness held at the design value" if design_map.stiffness is not None
            else "the drive stiffness following the stroke (k_max / 2: the spec gives none)")
    note += (f"Computed with fi_design.studies.sweep: crossover {num(x.values[0])} to "
             f"{num(x.values[-1])} Hz, stroke {qty(y.values[0], 'm')} to "
             f"{qty(y.values[-1], 'm')} (log), {held}.")
    counts = result.counts()
    xname, yname = plots.quantity_name(x.path).lower(), plots.quantity_name(y.path).lower()
    return {
        "intro": (
            f"Hunting cycles of the isolated stage around the design point (red cross) over "
            f"{xname} \u00d7 {yname}, as the paper's Figure 4D: {len(x.values)} \u00d7 "
            f"{len(y.values)} simulations with the PID retuned at every crossover. " + note),
        "figure": figure_entry((lambda: plots.design_map_figure(result)) if figures else None,
                               "map", f"Hunting cycles over {xname} and {yname} (isolated). "
                               "Marks: s stuck, ? undetermined, \u00d7 failed.", fig_no()),
        "counts": ", ".join(f"{k} {v}" for k, v in counts.items() if v),
    }


#: The paper and the standard works it builds on.
REFERENCES = (
    ("Fix2024", "J. A. Fix et al., \u201cMitigating friction induced limit cycles by an "
                "intermediate flexure stage\u201d (the paper this tool implements; design "
                "guideline in \u00a74)."),
    ("Fix2023", "J. A. Fix, A Linearized Parameter Study of a Friction Isolator System: "
                "Towards a Frequency Domain Design Guideline, MSc thesis, University of Twente, "
                "2023."),
    ("Canudas1995", "C. Canudas de Wit, H. Olsson, K. J. \u00c5str\u00f6m and P. Lischinsky, "
                    "\u201cA new model for control of systems with friction\u201d, IEEE "
                    "Transactions on Automatic Control 40(3), 1995 (the LuGre model)."),
    ("Astrom2008", "K. J. \u00c5str\u00f6m and C. Canudas-de-Wit, \u201cRevisiting the LuGre "
                   "friction model\u201d, IEEE Control Systems Magazine 28(6), 2008."),
    ("Hensen2003", "R. H. A. Hensen, M. J. G. van de Molengraft and M. Steinbuch, \u201cFriction "
                   "induced hunting limit cycles: a comparison between the LuGre and switch "
                   "friction model\u201d, Automatica 39(12), 2003."),
    ("Hensen2002", "R. H. A. Hensen and M. J. G. van de Molengraft, \u201cFriction induced "
                   "hunting limit cycles: an event mapping approach\u201d, Proc. American "
                   "Control Conference, 2002."),
    ("Karnopp1985", "D. Karnopp, \u201cComputer simulation of stick-slip friction in mechanical "
                    "dynamic systems\u201d, ASME J. Dynamic Systems, Measurement and Control "
                    "107(1), 1985 (the switch model)."),
    ("Hairer1996", "E. Hairer and G. Wanner, Solving Ordinary Differential Equations II: Stiff "
                   "and Differential-Algebraic Problems, 2nd ed., Springer, 1996 (RODAS4)."),
    ("Dong2018", "X. Dong and C. E. Okwudire, \u201cAn experimental investigation of the effects "
                 "of the compliant joint method on feedback compensation of pre-sliding/"
                 "pre-rolling friction\u201d, Precision Engineering 54, 2018."),
    ("Dong2020", "X. Dong and C. E. Okwudire, \u201cInfluence of design parameters on the "
                 "effectiveness of friction isolators in mitigating pre-motion friction in "
                 "mechanical bearings\u201d, Mechatronics 71, 2020."),
    ("Wang2022", "J. Wang, X. Dong, O. R. Barry and C. Okwudire, \u201cFriction-induced "
                 "instability and vibration in a precision motion stage with a friction "
                 "isolator\u201d, Journal of Vibration and Control 28(15-16), 2022."),
    ("AlBender2008", "F. Al-Bender and J. Swevers, \u201cCharacterization of friction force "
                     "dynamics\u201d, IEEE Control Systems Magazine 28(6), 2008."),
    ("Maeda2013", "Y. Maeda and M. Iwasaki, \u201cRolling friction model-based analyses and "
                  "compensation for slow settling response in precise positioning\u201d, IEEE "
                  "Transactions on Industrial Electronics 60(12), 2013 (PID from mass and "
                  "crossover)."),
    ("Skogestad2005", "S. Skogestad and I. Postlethwaite, Multivariable Feedback Control, 2nd "
                      "ed., Wiley, 2005 (margins and sensitivity)."),
)


def _appendix(result: Any) -> dict:
    spec = result.spec
    sim = spec.simulation
    scan = sim.crossover_scan
    solver = [
        {"quantity": "integrator", "value": "RODAS4 (fast kernel, numba)", "unit": ""},
        {"quantity": "relative tolerance", "value": sim.tolerance, "unit": "1"},
        {"quantity": "output rate", "value": sim.output_rate, "unit": "Hz"},
        {"quantity": "step budget per simulation", "value": sim.max_steps, "unit": "1"},
        {"quantity": "simulated time", "value": spec.motion.duration, "unit": "s"},
        {"quantity": "hunting-free crossover searched within", "value": [scan.start, scan.stop],
         "unit": "Hz"},
        {"quantity": "friction model", "value": spec.friction.model, "unit": ""},
        {"quantity": "loop delay (linear analysis, Pad\u00e9 order "
                     f"{spec.controller.pade_order})", "value": result.crossover.delay,
         "unit": "s"},
    ]
    sim_res = result.simulation
    if sim_res is not None:
        for key, res in sim_res.results.items():
            solver.append({"quantity": f"steps / rejected / events ({key.replace('_', '-')})",
                           "value": f"{res.n_steps} / {res.n_rejected} / {res.n_events}",
                           "unit": ""})
    return {**spec_listing(spec), "solver": solver, "versions": versions()}


def _texts(node: Any) -> list[str]:
    """Every sentence of a report context (figures and equations left out), for the glossary."""
    if isinstance(node, str):
        return [node]
    if isinstance(node, dict):
        return [t for k, v in node.items() if k not in ("svg", "tex") for t in _texts(v)]
    if isinstance(node, (list, tuple)):
        return [t for v in node for t in _texts(v)]
    return []


def _design_sections(ctx: dict) -> list[dict]:
    sections = [
        {"id": "verdict", "title": "Verdict", "template": "verdict.html.jinja"},
        {"id": "inputs", "title": "Inputs", "template": "inputs.html.jinja"},
        {"id": "steps", "title": "The four guideline steps", "template": "steps.html.jinja"},
    ]
    if ctx.get("guide") is not None:
        sections.append({"id": "guide", "title": "The isolator's leaf-spring guide",
                         "template": "guide.html.jinja"})
    sections += [
        {"id": "linear", "title": "Linear analysis", "template": "linear.html.jinja"},
        {"id": "nonlinear", "title": "Nonlinear confirmation", "template": "nonlinear.html.jinja"},
    ]
    if ctx.get("map") is not None:
        sections.append({"id": "map", "title": "Hunting map around the design point",
                         "template": "map.html.jinja"})
    sections += [
        {"id": "validation", "title": "Validation", "template": "validation.html.jinja"},
        {"id": "assumptions", "title": "Assumptions and limitations",
         "template": "assumptions.html.jinja"},
        {"id": "glossary", "title": "Glossary", "template": "glossary.html.jinja"},
        {"id": "references", "title": "References", "template": "references.html.jinja"},
        {"id": "settings", "title": "Analysis settings", "template": "inputs.html.jinja"},
        {"id": "appendix", "title": "Appendix: spec, solver and software",
         "template": "appendix.html.jinja"},
    ]
    for i, s in enumerate(sections, 1):
        s["number"] = i
    return sections


@build_context.register
def design_context(result: DesignResult, *, date: Any = None, command: str | None = None,
                   figures: bool = True, design_map: DesignMap | None = None) -> dict:
    """Everything a design report shows, as plain data.

    Parameters
    ----------
    result : fi_design.guideline.steps.DesignResult
        The design (with its simulated confirmation, if any).
    date : str or datetime.date, optional
        The report date; default :func:`~fi_design.report.meta.report_date` (today).
    command : str, optional
        The command line that made the report (shown in the title block).
    figures : bool, optional
        Render figures and equations to SVG (default). False leaves ``svg``
        None everywhere: the golden tests compare the rest.
    design_map : fi_design.studies.DesignMap, optional
        A crossover x stroke map around the design point
        (:func:`fi_design.studies.design_map`) for its own section.

    Returns
    -------
    dict
        Keys ``meta`` (title block), ``sections`` (the contents, in order),
        ``verdict``, ``inputs``, ``steps``, ``linear``, ``nonlinear`` (None
        without simulation), ``map`` (None without map), ``validation``, ``assumptions``,
        ``glossary`` (the terms the report uses), ``references``, ``appendix``. Numbers are SI floats with a ``unit`` key
        beside them (the templates format them with the ``qty`` filter), or text.
    """
    spec = result.spec
    fig_no = _Numbering()
    ctx: dict[str, Any] = {
        "meta": title_block(spec, "design", date=date, command=command,
                            sha256=result.spec_sha256, version=result.fi_design_version,
                            source=result.fi_design_source),
        "verdict": verdict(result),
        "steps": guideline_steps(result, figures),
    }
    ctx["inputs"], ctx["settings"] = split_inputs(spec_inputs(spec, result.model))
    ctx["guide"] = guide_section(result, figures, fig_no()) if result.flexure is not None \
        else None
    ctx |= {
        "linear": _linear(result, figures, fig_no),
        "nonlinear": _nonlinear(result, figures, fig_no),
    }
    if ctx["nonlinear"] is None:
        ctx["nonlinear_missing"] = ("The nonlinear confirmation was not run (fi-design "
                                    "--no-simulation, or design(spec, confirm=False)): the "
                                    "verdict rests on the linear steps alone.")
    ctx["map"] = _map_section(design_map, figures, fig_no)
    ctx["validation"] = validation_section(result)
    ctx["assumptions"] = assumptions(result)
    ctx["references"] = [{"key": k, "text": t} for k, t in REFERENCES]
    ctx["appendix"] = _appendix(result)
    ctx["glossary"] = glossary(" ".join(_texts(ctx)))
    ctx["sections"] = _design_sections(ctx)
    return ctx
