"""Console summaries of the command line: rich tables and progress displays.

Presentation only: each ``print_*`` function reads a finished result and
prints it; :class:`Status`, :class:`ProgressBar` and :class:`FractionBar` are
the progress callbacks the CLI passes into the library. rich is imported
inside the functions, so ``fi-design --help`` stays fast.
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import TYPE_CHECKING, Any, Optional

from .display import axis_unit, number, percent, quantity, scale, unit_text
from .effects import values_text as _effects_text

if TYPE_CHECKING:  # pragma: no cover
    from rich.console import Console

_STYLES = {"PASS": "bold green", "FAIL": "bold red", "WARN": "bold yellow", "INFO": "cyan"}


def make_console(stderr: bool = False) -> "Console":
    """A rich console; wide enough for the tables when output is not a terminal.

    Parameters
    ----------
    stderr : bool, optional
        Print to standard error (progress displays) instead of standard output.

    Returns
    -------
    rich.console.Console
    """
    from rich.console import Console

    console = Console(stderr=stderr, highlight=False)
    if not console.is_terminal and "COLUMNS" not in os.environ:
        console = Console(stderr=stderr, highlight=False, width=120)
    return console


def _table(title: str | None = None, **options: Any):
    """A compact rich table: simple head rule, one space between columns, title on the left."""
    from rich import box
    from rich.table import Table

    return Table(title=title, title_justify="left", box=box.SIMPLE_HEAD, pad_edge=False,
                 collapse_padding=True, **options)


def _status_text(status: Any):
    from rich.text import Text

    name = getattr(status, "value", status)
    name = str(name) if name is not None else "INFO"
    return Text(name, style=_STYLES.get(name, ""))


def _heading(console: "Console", text: str, spec_path: Optional[Path]) -> None:
    """A summary's bold first line, with the spec file dimmed beside it."""
    from rich.text import Text

    head = Text(text, style="bold")
    if spec_path is not None:
        head.append(f"  ({spec_path})", style="dim")
    console.print(head)


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

    from .report.checks import check_row

    table = _table(title)
    table.add_column("Check", ratio=1, min_width=24, overflow="fold")
    table.add_column("Status", no_wrap=True)
    table.add_column("Value", justify="right", no_wrap=True)
    table.add_column("Limit", justify="right", no_wrap=True)
    table.add_column("Unit", no_wrap=True)
    step = None
    for c in checks:
        if (c.step or "") != step:
            step = c.step or ""
            if step:
                table.add_row(Text(step, style="bold underline"))
        row = check_row(c, cases)
        cell = Text(row["label"], style="bold")
        if row["message"]:
            cell.append("\n")
            cell.append(Text(row["message"], style="dim"))
        limit = number(row["limit"])
        if row["sense"] and row["limit"] is not None:
            limit = f"{row['sense']} {limit}"
        table.add_row(cell, _status_text(c.status), number(row["value"]), limit,
                      Text(row["unit"] or ""))
    return table


class Status:
    """A spinner with a changing message on a terminal; silent otherwise.

    Used as ``with Status(console, text) as update: update("next step")``; ``update``
    is the ``progress(text)`` callback of :func:`fi_design.design` and
    :func:`fi_design.render_report`.
    """

    def __init__(self, console: "Console", text: str) -> None:
        self._console = console
        self._text = text
        self._live = None

    def __enter__(self):
        if self._console.is_terminal:
            self._live = self._console.status(self._text, spinner="dots")
            self._live.__enter__()
        return self.update

    def update(self, text: str) -> None:
        if self._live is not None:
            self._live.update(text)

    def __exit__(self, *exc) -> None:
        if self._live is not None:
            self._live.__exit__(*exc)


def print_design(console: "Console", result, spec_path: Path | None = None) -> None:
    """Print the readable summary of a :class:`~fi_design.guideline.DesignResult`.

    Parameters
    ----------
    console : rich.console.Console
        Where to print.
    result : fi_design.guideline.DesignResult
        The design result.
    spec_path : pathlib.Path, optional
        The spec file, named in the heading.
    """
    from rich.text import Text

    data = result.to_dict()
    name = _spec_name(result)
    _heading(console, name or "fi-design", spec_path)

    gap = data.get("friction_gap") or {}
    if gap:
        risk = gap.get("hunting_risk")
        console.print(Text(
            f"Friction gap Fs - Fc = {number(gap.get('gap'))} N (threshold "
            f"{number(gap.get('threshold'))} N): "
            + ("hunting is a risk" if risk else "hunting unlikely" if risk is not None else "")))

    loop = getattr(result, "loop", None)
    console.print(checks_table(result.checks,
                               cases={c.name: c for c in getattr(loop, "cases", ())}))

    pid = data.get("pid") or {}
    if pid:
        console.print(_gains_table(pid))

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
        cases = xo.get("cases") or []
        if cases:
            console.print(_cases_table(cases, {c.name: c.number for c in result.loop.cases}))

    stiff = data.get("stiffness") or {}
    if stiff.get("maximum") is not None:
        if stiff.get("suggested"):
            text = (f"Drive stiffness (suggestion for an isolator with a "
                    f"{number(1e3 * stiff['stroke'], 3)} mm stroke): k_max = "
                    f"{number(stiff['maximum'])} N/m, start from k = {number(stiff.get('chosen'))} N/m")
        else:
            text = (f"Drive stiffness: k_max = {number(stiff['maximum'])} N/m, chosen k = "
                    f"{number(stiff.get('chosen'))} N/m")
            if stiff.get("source"):
                text += f" ({stiff['source']})"
            if stiff.get("force_at_stroke") is not None:
                text += f", flexure force at full stroke {number(stiff['force_at_stroke'], 3)} N"
        console.print(Text(text))

    sim = data.get("simulation")
    if isinstance(sim, dict) and "isolated" in sim:
        h = result.spec.requirements.hunting
        console.print(_simulation_table(sim, (h.window_start, h.window_start + h.window_length),
                                        data.get("stage_hunting")))
        for line in moves_strips(data.get("stage_hunting") or {},
                                 bool(sim.get("suggested_isolator"))):
            console.print(line)

    conclusion = getattr(result, "conclusion", "") or data.get("conclusion", "")
    if conclusion:
        console.print(Text("Conclusion: ", style="bold").append(Text(str(conclusion),
                                                                        style="")))
    if getattr(result, "verdict", None) is not None:
        print_verdict(console, result)   # the input warnings are among its reasons
        return
    for w in getattr(result, "warnings", ()) or ():
        console.print(Text("warning: ", style="bold yellow").append(Text(_warning_text(w))))


def _gains_table(pid: dict) -> Any:
    """Step 4's gains in the form the spec's ``controller.gains`` takes (``pid.hand_off``).

    With the hardware's own gains, the rule's at the same crossover in the same
    form beside them. The roll-off is ``controller.roll_off``: a low-pass on the
    D term only; the sampling and delay are the ones the analysis used.
    """
    from rich.text import Text

    hand = pid["hand_off"]
    rows = [("hardware" if pid.get("source") == "gains" else "rule", hand)]
    if pid.get("source") == "gains":
        rows.append(("rule", {**hand, **pid["rule_in_hardware_form"],
                              "roll_off": pid["rule_in_hardware_form"]["roll_off"]
                              / (2 * math.pi)}))
    t = _table("PID gains (step 4) as controller.gains takes them: kp + ki/s + kd s / (1 + "
               "s/(2 pi roll_off)), the roll-off on the D term only")
    t.add_column("")
    for col in ("kp [N/m]", "ki [N/(m s)]", "kd [N s/m]", "roll_off [Hz]"):
        t.add_column(Text(col), justify="right", no_wrap=True)
    for label, g in rows:
        t.add_row(label, number(g["kp"]), number(g["ki"]), number(g["kd"]),
                  "none" if g["roll_off"] is None else number(g["roll_off"]))
    sampled = ("continuous" if hand["sample_rate"] is None
               else f"sampled at {quantity(hand['sample_rate'], 'Hz')}")
    delay = "no delay" if not hand["delay"] else f"delay {quantity(hand['delay'], 's')}"
    t.caption = Text(f"D on the {hand['derivative_on']}, {sampled}, {delay}, tuned on "
                     f"{quantity(pid['tuning_mass'], 'kg')} (controller.derivative_on, "
                     "sample_rate and delay); --write-spec writes them into a spec",
                     style="dim")
    t.caption_justify = "left"
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
        body.add_row(_status_text(r.severity), Text(r.text))
    rob, mar = result.robustness, result.margins
    if rob is not None:
        body.add_row(Text("Scatter", style="bold"), Text(
            f"does not settle in {percent(rob.hunting_probability)} of {rob.valid} samples "
            f"({percent(rob.interval[0])} to {percent(rob.interval[1])} at "
            f"{percent(rob.confidence)}), limit {percent(rob.limit)}"))
    if mar is not None:
        items = []
        if mar.crossover_factor is not None:
            items.append(f"crossover {'>= ' if mar.crossover_factor_bound else ''}"
                         f"{mar.crossover_factor:.3g}x the hunting-free "
                         f"{number(mar.hunting_free_crossover, 4)} Hz")
        if mar.end_stop_clearance is not None:
            items.append(f"end stop {quantity(mar.end_stop_clearance, 'm', 3)} away at rest")
        if mar.stiffness_factor is not None:
            items.append(f"k_max / k = {mar.stiffness_factor:.3g}")
        if mar.stiffness_range is not None:
            lo, hi = mar.stiffness_range
            items.append(f"k {lo:.4g}-{hi:.4g} N/m for t = {1e3 * mar.thickness:.3g} \u00b1 "
                         f"{1e3 * mar.thickness_tolerance:.2g} mm")
        if mar.static_error is not None:
            items.append(f"static error {quantity(mar.static_error, 'm', 3)} of "
                         f"{quantity(mar.static_error_bound, 'm', 3)} (Fc + |offset|) / kp")
        if items:
            body.add_row(Text("Margins", style="bold"), Text("; ".join(items)))
    if result.recommendation is not None:
        body.add_row(Text("Advice", style="bold"), Text(result.recommendation.text))
    console.print(Panel(body, title=Text(f"Verdict: {v.status}", style=f"bold {colour}"),
                        title_align="left", border_style=colour, box=getattr(box, frame)))


#: Friction models as the literature names them.
_MODEL_NAMES = {"lugre": "LuGre", "switch": "switch"}

#: One character per move outcome in :func:`moves_strips`, with its style.
MOVE_GLYPHS = {"hunts": ("\u25cf", "bold red"), "settles": ("\u00b7", "green"),
               "rests": ("\u25aa", "green"), "stuck": ("\u25aa", "bold yellow"),
               "undetermined": ("?", "bold yellow")}


def moves_strips(stages: dict, suggested: bool = False) -> list:
    """The move family at a glance: one character per move, small to large, per plant.

    ``●`` ends in a cycle, ``·`` settles, ``▪`` rests off target (yellow: stuck),
    ``?`` undetermined; negative moves on a second strip.

    Parameters
    ----------
    stages : dict
        ``DesignResult.to_dict()["stage_hunting"]``.
    suggested : bool
        Whether the isolated plant is the suggested isolator.

    Returns
    -------
    list of rich.text.Text
    """
    from rich.text import Text

    names = {"isolated": "suggested isolator" if suggested else "with isolator",
             "non_isolated": "without isolator"}
    out = []
    for key in ("isolated", "non_isolated"):
        st = stages.get(key)
        if not st:
            continue
        moves = [m for m in st.get("moves", []) if m.get("label") == "family"]
        for sign, word in ((1.0, ""), (-1.0, " (negative)")):
            side = sorted((m for m in moves if m["distance"] * sign > 0),
                          key=lambda m: abs(m["distance"]))
            if not side:
                continue
            lo, hi = abs(side[0]["distance"]), abs(side[-1]["distance"])
            unit, f = scale("m", [lo, hi])
            line = Text(f"Moves {number(lo * f, 3)} to {number(hi * f, 3)} {unit}, "
                        f"{names[key]}{word}: ")
            for m in side:
                glyph, style = MOVE_GLYPHS.get(m["outcome"], ("x", "bold yellow"))
                line.append(glyph, style=style)
            out.append(line)
    if out:
        out.append(Text("  \u25cf ends in a hunting cycle, \u00b7 settles, \u25aa rests off "
                        "target, ? not judged", style="dim"))
    return out


def _simulation_table(sim: dict, window: tuple[float, float] | None = None,
                      stages: dict | None = None) -> Any:
    """Table of the simulated verdicts from the confirmation's JSON form.

    One column per plant, one row per quantity, so it reads at any width;
    lengths carry their unit (``1.37 mm``, ``25.2 µm``).

    Parameters
    ----------
    sim : dict
        ``DesignResult.to_dict()["simulation"]``.
    window : tuple of float, optional
        The counting window [s], named in the cycles row.
    stages : dict, optional
        ``DesignResult.to_dict()["stage_hunting"]``: the stage-level rows.
    """
    from rich.text import Text

    label = "suggested isolator" if sim.get("suggested_isolator") else "with isolator"
    model = sim["isolated"].get("friction_model") or "lugre"
    other = sim.get("cross_check") or {}
    other_model = next((v.get("friction_model") for v in other.values() if v),
                       "switch" if model == "lugre" else "lugre")
    mins = sim.get("min_hunting_free_crossover") or {}
    t = _table(f"Nonlinear confirmation ({_MODEL_NAMES.get(model, model)} simulation, paper "
               "section 2.3)")
    t.add_column("", no_wrap=True)
    plants = (("isolated", label), ("non_isolated", "without isolator"))
    for _, name in plants:
        t.add_column(Text(name), justify="right")
    counted = "in the window" if window is None else \
        f"in [{number(float(window[0]))} s, {number(float(window[1]))} s)"

    def verdict_text(verdict: str) -> Any:
        style = {"settled": "bold green", "settles": "bold green", "static_error": "bold green",
                 "hunting": "bold red", "hunts": "bold red"}.get(verdict, "bold yellow")
        return Text(verdict.replace("_", " "), style=style)

    stages = stages or {}

    def stage(key: str) -> dict:
        return stages.get(key) or {}

    def free_from(key: str) -> str:
        m = mins.get(key)
        b = stage(key).get("boundary") or {}
        if m is None:
            return "above the search" if b.get("kind") == "bound" else "-"
        return f"{number(m, 4)} Hz" + ("" if b.get("kind") == "fold" else " (bound)")

    def hunting_moves(key: str) -> str:
        st = stage(key)
        if not st:
            return "-"
        return f"{st.get('moves_hunting')} of {st.get('moves_tried')}"

    def entered(key: str) -> str:
        d = sorted(abs(x) for x in stage(key).get("entered_by") or [])
        if not d:
            return "-"
        unit, f = scale("m", d)
        return quantity(d[0], "m", 3) if len(d) == 1 else \
            f"{number(d[0] * f, 3)} to {number(d[-1] * f, 3)} {unit}"

    def cycle(key: str, name: str, unit: str | None = None) -> Any:
        c = stage(key).get("cycle")
        if not c or c.get(name) is None:
            return "-"
        value = c[name]
        if unit == "m":
            return quantity(value, "m", 3)
        if unit == "s":
            return f"{number(value, 3)} s"
        if isinstance(value, bool):
            return "yes" if value else "no"
        return number(value, 3)

    def period(v: dict) -> str:
        return "-" if v.get("period") is None else f"{number(v['period'], 3)} s"

    def settling(v: dict) -> str:
        st = v.get("settling_time")
        return "never" if st is None else f"{number(st, 3)} s"

    rows = [
        ("Stage, after every move", lambda k, v: verdict_text(stage(k).get("outcome", ""))),
        ("Moves ending in a cycle", lambda k, v: hunting_moves(k)),
        ("Moves that enter it", lambda k, v: entered(k)),
        ("Cycle, peak to peak", lambda k, v: cycle(k, "amplitude", "m")),
        ("Cycle period", lambda k, v: cycle(k, "period", "s")),
        ("Floquet multiplier", lambda k, v: cycle(k, "multiplier")),
        ("Joint on its limiter", lambda k, v: cycle(k, "on_limiter")),
        ("No move hunts from", lambda k, v: free_from(k)),
        ("Spec's motion: verdict", lambda k, v: verdict_text(v.get("verdict", ""))),
        (f"Hunting cycles {counted}", lambda k, v: str(v.get("hunting_cycles"))),
        ("Amplitude, peak to peak", lambda k, v: quantity(v.get("amplitude"), "m", 3)),
        ("Period", lambda k, v: period(v)),
        ("Settling time after the motion", lambda k, v: settling(v)),
        ("Final error x1 - r", lambda k, v: quantity(v.get("final_error"), "m", 3)),
    ]
    if other:
        rows.append((f"Cross-check, {_MODEL_NAMES.get(other_model, other_model)} model",
                     lambda k, v: verdict_text((other.get(k) or {}).get("verdict", ""))))
    for title, cell in rows:
        t.add_row(Text(title), *[cell(key, sim[key]) for key, _ in plants])
    return t


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
                "(inf: no crossing); an unstable case fails with 'stability'")
_CASE_SKIP = {"name", "description", "passed", "failed", "crossovers", "stable", "in_band",
              "status"}


def _cases_table(cases: list, numbers: dict) -> Any:
    """Table of the linear limit cases (paper Figure 2) from their JSON form and numbers."""
    from rich.text import Text

    keys = [k for k in CASE_COLUMNS if any(k in c for c in cases)]
    for case in cases:
        keys += [k for k, v in case.items() if k not in keys and k not in _CASE_SKIP
                 and not isinstance(v, (dict, list))]
    t = _table("Linear limit cases at the desired crossover (paper Figure 2)")
    t.caption = Text(CASE_CAPTION, style="dim")
    t.caption_justify = "left"
    t.add_column("#", justify="right", no_wrap=True)
    t.add_column("Limit case", ratio=1, min_width=12)
    for k in keys:
        t.add_column(Text(CASE_COLUMNS.get(k, _header(k))), justify="right", no_wrap=True)
    t.add_column("Status", min_width=6)
    for i, case in enumerate(cases, 1):
        case_no = str(numbers.get(case.get("name"), i))
        label = case.get("description") or case.get("name") or ""
        cells = [Text("inf" if case.get(k) is None and "margin" in k else number(case.get(k)))
                 for k in keys]
        status = _status_text(case["status"])  # as the analysis judged it
        if case.get("failed"):
            status.append(" " + ", ".join(map(str, case["failed"])))
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


def print_simulation(console: "Console", result) -> None:
    """Print the metrics and solver statistics of a :class:`~fi_design.simulation.SimulationResult`.

    A replay of a measured record shows its agreement with the record
    instead of the hunting metric (which judges a settling stage, not a
    record in motion).

    Parameters
    ----------
    console : rich.console.Console
        Where to print.
    result : fi_design.simulation.SimulationResult
        The simulation.
    """
    from rich import box
    from rich.table import Table
    from rich.text import Text

    m = result.metrics
    plant = "with isolator" if result.isolated else "without isolator"
    loop = "closed loop" if result.drive == "closed" else "open loop, measured force"
    what = "Simulation" if result.replay is None else f"Replay of {result.record} ({loop})"
    t = Table(title=f"{what} {plant} at {result.crossover:.4g} Hz ({result.friction_model}, "
                    f"{result.method} solver)", title_justify="left", box=box.SIMPLE_HEAD,
              pad_edge=False)
    t.add_column("Quantity")
    t.add_column("Value", justify="right")
    rows = []
    fit = result.replay
    if fit is not None:
        rows += [
            ("position, model - measured, rms [\u00b5m]", number(1e6 * fit.position_rms, 4)),
            ("position, model - measured, max [\u00b5m]", number(1e6 * fit.position_max, 4)),
            ("tracking error r - x1 rms, model [\u00b5m]", number(1e6 * fit.tracking_rms_model, 4)),
            ("tracking error r - x1 rms, measured [\u00b5m]",
             number(1e6 * fit.tracking_rms_measured, 4)),
            ("commanded force, model - measured, rms [N]", number(fit.force_rms, 4)),
        ]
        if result.window is not None:
            rows.append(("re-anchored windows [-]", str(int(result.window.max()) + 1)))
    else:
        rows += [
            ("verdict", m.verdict),
            ("hunting cycles in the window [-]", str(m.hunting_cycles)),
            ("amplitude (peak to peak)", quantity(m.amplitude, "m")),
            ("period [s]", number(m.period, 4)),
            ("settling time [s]", number(m.settling_time, 4)),
            ("final error", quantity(m.final_error, "m")),
        ]
    rows += [
        ("integration", "ok" if result.success else result.message),
        ("steps / rejected / events [-]", f"{result.n_steps} / {result.n_rejected} / "
                                          f"{result.n_events}"),
        ("wall time [ms]", number(1e3 * result.wall_time, 3)),
    ]
    for k, v in rows:
        t.add_row(Text(k), Text(str(v)))
    console.print(t)
    if result.replay is None:
        console.print(Text(m.reason))


class ProgressBar:
    """A rich progress bar with ETA on stderr, fed by the library's ``progress(done, total)``."""

    def __init__(self, console: "Console", text: str) -> None:
        from rich.progress import (BarColumn, MofNCompleteColumn, Progress, TextColumn,
                                   TimeElapsedColumn, TimeRemainingColumn)

        self._progress = Progress(TextColumn("[progress.description]{task.description}"),
                                  BarColumn(), MofNCompleteColumn(), TextColumn("points"),
                                  TimeElapsedColumn(), TextColumn("ETA"), TimeRemainingColumn(),
                                  console=console, transient=False,
                                  disable=not console.is_terminal)
        self._task = self._progress.add_task(text, total=None)
        self._first: Optional[int] = None

    def __enter__(self) -> "ProgressBar":
        self._progress.__enter__()
        return self

    def __call__(self, done: int, total: int) -> None:
        if self._first is None:  # cached points arrive at once; the ETA counts the rest
            self._first = done
            self._progress.reset(self._task, total=total, completed=done)
            return
        self._progress.update(self._task, total=total, completed=done)

    def __exit__(self, *exc) -> None:
        self._progress.__exit__(*exc)


#: Exit code of a study interrupted with Ctrl-C (128 + SIGINT, as shells report it).


def _axis_values_text(axis) -> str:
    from .plots import quantity_name

    unit, f = axis_unit(axis.unit)
    v = axis.values
    scale = "log" if axis.log else "linear"
    return (f"{quantity_name(axis.path)} ({axis.path}): {len(v)} values {number(v[0] * f)} to "
            f"{number(v[-1] * f)} {unit} ({scale})")


_CELL = {"settled": ("·", "green"), "stuck": ("s", "yellow"), "undetermined": ("?", "yellow"),
         "invalid": ("-", "dim"), "failed": ("×", "bold red")}


#: Widest map printed on the console [columns]; a wider one is named by its file.
MAX_MAP_COLUMNS = 60


def sweep_grid_table(result, columns: slice | None = None):
    """The map (or a block of its columns) as a rich table: cycles per point, marks otherwise.

    Parameters
    ----------
    result : fi_design.studies.SweepResult
        A two-dimensional sweep (a line is shown as one row).
    columns : slice, optional
        The x values to tabulate (default all): :func:`sweep_grid_tables`
        splits a wide map into blocks that fit the console.

    Returns
    -------
    rich.table.Table
        Rows are y values, columns x values, both in display units; a cell
        holds the cycle count of a hunting point, ``·`` settled, ``s`` stuck,
        ``?`` undetermined, ``-`` invalid, ``×`` failed.
    """
    from rich import box
    from rich.table import Table
    from rich.text import Text

    x, y = result.x, result.y
    cols = range(len(x.values))[columns or slice(None)]
    xu, xf = axis_unit(x.unit)
    if y is not None:
        yu, yf = axis_unit(y.unit)
    t = Table(box=box.SIMPLE_HEAD, pad_edge=False)
    t.add_column(Text("" if y is None else f"[{yu}]"), justify="right", no_wrap=True)
    for j in cols:
        t.add_column(Text(number(x.values[j] * xf, 3)), justify="right", no_wrap=True)
    rows = result.verdict.reshape(-1, len(x.values))
    stage = getattr(result, "measure", "move") == "stage"
    values = (result.amplitude * 1e3 if stage else result.hunting_cycles).reshape(
        -1, len(x.values))
    labels = [""] if y is None else [number(v * yf, 3) for v in y.values]
    for label, vrow, crow in zip(labels, rows, values):
        cells = []
        for j in cols:
            v, c = vrow[j], crow[j]
            if v == "hunting":
                cells.append(Text(f"{c:.2g}" if stage else str(int(c)), style="bold red"))
            else:
                mark, style = _CELL.get(str(v), ("", ""))
                cells.append(Text(mark, style=style))
        t.add_row(label, *cells)
    return t


def sweep_grid_tables(result, width: int) -> list:
    """The map in blocks of columns that each fit ``width`` characters, whole values in headers.

    Returns
    -------
    list of rich.table.Table
        One table when the map fits, else one per block of x values (each
        with the row labels); empty when the map has more than
        :data:`MAX_MAP_COLUMNS` columns.
    """
    from rich.console import Console

    n = len(result.x.values)
    if n > MAX_MAP_COLUMNS:
        return []
    probe = Console(width=10_000, color_system=None, legacy_windows=False)

    def fits(a: int, b: int) -> bool:
        table = sweep_grid_table(result, slice(a, b))
        return probe.measure(table).maximum <= width

    tables, a = [], 0
    while a < n:
        b = n
        while b > a + 1 and not fits(a, b):
            b -= 1
        tables.append(sweep_grid_table(result, slice(a, b)))
        a = b
    return tables


def grid_caption(result) -> str:
    """What the cells and axes of :func:`sweep_grid_table` mean, in one line.

    Parameters
    ----------
    result : fi_design.studies.SweepResult
        The sweep.

    Returns
    -------
    str
    """
    from .plots import axis_label

    what = ("peak to peak of the cycle some move ends in [mm]"
            if getattr(result, "measure", "move") == "stage"
            else "hunting cycles of the spec's move in the window")
    text = f"{what}; columns: {axis_label(result.x.path, result.x.unit)}"
    if result.y is not None:
        text += f", rows: {axis_label(result.y.path, result.y.unit)}"
    return text + "; · settled, s stuck, ? undetermined, - invalid, × failed"


def _print_grid(console: "Console", result, files: tuple = ()) -> None:
    """The map at the console's width: in blocks of columns where it is wider.

    A map wider than :data:`MAX_MAP_COLUMNS` is not tabulated: the line says
    so and names the files that hold it (``files``), or the options that
    write them.
    """
    from rich.text import Text

    tables = sweep_grid_tables(result, console.width)
    if not tables:
        where = (", ".join(str(f) for f in files) if files else
                 "--figure OUT.svg or --csv OUT.csv (not written in this run)")
        console.print(Text(f"the map has {len(result.x.values)} columns, too many to print "
                           f"here: see {where}"))
        return
    console.print(Text(grid_caption(result), style="dim"))
    if len(tables) > 1:
        console.print(Text(f"(in {len(tables)} blocks of columns to fit {console.width} "
                           "characters)", style="dim"))
    for t in tables:
        console.print(t)


def _print_counts(console: "Console", counts: dict) -> None:
    text = ", ".join(f"{n} {v}" for v, n in counts.items() if n)
    console.print(f"points: {text}", markup=False, highlight=False)


def _print_run(console: "Console", run, executor: str) -> None:
    console.print(f"{run.points} points: {run.computed} simulated, {run.cached} from the cache; "
                  f"{executor}; {run.wall_time:.2f} s", markup=False, highlight=False)


def print_sweep(console: "Console", result, spec_path: Optional[Path] = None,
                executor: str = "", files: tuple = ()) -> None:
    """Print the summary of a :class:`~fi_design.studies.SweepResult`.

    Parameters
    ----------
    console : rich.console.Console
        Where to print.
    result : fi_design.studies.SweepResult
        The sweep.
    spec_path : pathlib.Path, optional
        The spec file, named in the heading.
    executor : str, optional
        How the points ran, for the last line.
    files : tuple of pathlib.Path, optional
        The files written with the map (named when the map is too wide to print).
    """
    from rich.text import Text

    from .plots import quantity_name

    _heading(console, f"Sweep of {result.spec.name}", spec_path)
    plant = "with isolator" if result.isolated else "without isolator"
    console.print(Text(f"{_axis_values_text(result.x)}; {plant}"))
    if result.y is not None:
        console.print(Text(_axis_values_text(result.y)))
    _print_grid(console, result, files)
    _print_counts(console, result.counts())
    xu, xf = axis_unit(result.x.unit)
    above = result.boundary("above")
    if result.y is None:
        if not math.isnan(above[0]):
            console.print(Text(f"no hunting from {quantity_name(result.x.path).lower()} = "
                               f"{number(above[0] * xf)} {xu} upwards"))
    failed = [p for p in result.points if p.status == "failed"]
    for p in failed[:3]:
        console.print(Text(f"failed at {dict(zip(result.paths, p.values))}: {p.message}",
                           style="red"))
    if len(failed) > 3:
        console.print(Text(f"... and {len(failed) - 3} more failed point(s); see --csv or --json",
                           style="red"))
    _print_run(console, result.run, executor)


def print_study(console: "Console", result, spec_path: Optional[Path] = None,
                executor: str = "", out: Optional[Path] = None) -> None:
    """Print the summary of a :class:`~fi_design.studies.StudyResult`: one grid per map.

    Parameters
    ----------
    console : rich.console.Console
        Where to print.
    result : fi_design.studies.StudyResult
        The study.
    spec_path : pathlib.Path, optional
        The spec file, named in the heading.
    executor : str, optional
        How the points ran, for the last line.
    out : pathlib.Path, optional
        The study's directory, whose files are named when a map is too wide to print.
    """
    from rich.text import Text

    _heading(console, f"Paper study (Figure 4) around {result.spec.name}", spec_path)
    for m in result.maps:
        d = m.definition
        console.print(Text(f"\n{d.key}) {d.title}", style="bold"))
        console.print(Text(f"paper: {d.paper}", style="dim"))
        files = () if out is None else (out / f"map_{d.key}.csv", out / "figure4.svg")
        _print_grid(console, m.result, files)
        _print_counts(console, m.result.counts())
    _print_run(console, result.run, executor)


def print_robustness(console: "Console", result, spec_path: Optional[Path] = None,
                     executor: str = "") -> None:
    """Print the summary of a :class:`~fi_design.studies.RobustnessResult`.

    Parameters
    ----------
    console : rich.console.Console
        Where to print.
    result : fi_design.studies.RobustnessResult
        The robustness study.
    spec_path : pathlib.Path, optional
        The spec file, named in the heading.
    executor : str, optional
        How the points ran, for the last line.
    """
    from rich.text import Text

    _heading(console, f"Robustness of {result.spec.name}", spec_path)
    for sc in result.scatter:
        unit, f = axis_unit("") if sc.relative else axis_unit(
            _path_unit(sc.path, result.spec))
        spread = f"{sc.spread:.3g} of nominal ({100 * sc.spread:.3g} %)" if sc.relative else \
            f"{number(sc.spread * f)} {unit}"
        console.print(Text(f"scatter {sc.path}: {result.distribution}, spread {spread}"))
    if result.position_friction is not None:
        pf = result.position_friction
        console.print(Text(f"position-dependent friction: amplitude {100 * pf.amplitude:.3g} %, "
                           f"wavelength {pf.wavelength * 1e3:.4g} mm, random phase"))
    conf = result.not_isolated.confidence
    t = _table(f"Probability of hunting, {result.samples} samples, seed {result.seed}")
    plants = [(label, p) for label, p in (("with isolator", result.isolated),
                                          ("without isolator", result.not_isolated))
              if p is not None]
    t.add_column("")
    for label, _ in plants:
        t.add_column(Text(label), justify="right")
    rows = [
        ("Probability of hunting", lambda p: "-" if p.probability is None
         else f"{100 * p.probability:.1f} %"),
        (f"{conf:.0%} Wilson interval", lambda p: f"{100 * p.low:.1f} to {100 * p.high:.1f} %"),
        ("Hunting / valid samples", lambda p: f"{p.hunting} / {p.valid}"),
    ] + [(f"  {v}", lambda p, v=v: str(p.counts[v]))
         for v in ("settled", "stuck", "undetermined", "invalid", "failed")]
    for title, cell in rows:
        t.add_row(Text(title), *[cell(p) for _, p in plants])
    t.caption = Text("Probability among the valid samples; the indented rows count every "
                     "sample by its verdict", style="dim")
    t.caption_justify = "left"
    console.print(t)
    _print_run(console, result.run, executor)


def _path_unit(path: str, spec) -> str:
    from .specfile import path_unit

    try:
        return path_unit(path, spec)
    except Exception:  # noqa: BLE001 -- a label only
        return ""


class FractionBar:
    """A rich progress bar on stderr fed by ``progress(message, fraction)``."""

    def __init__(self, console: "Console", text: str) -> None:
        from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

        self._progress = Progress(TextColumn("{task.description}"), BarColumn(),
                                  TimeElapsedColumn(), console=console, transient=True,
                                  disable=not console.is_terminal)
        self._text = text
        self._task = self._progress.add_task(text, total=1.0)

    def __enter__(self) -> "FractionBar":
        self._progress.__enter__()
        return self

    def __call__(self, message: str, fraction: float) -> None:
        self._progress.update(self._task, completed=fraction,
                              description=f"{self._text}: {message}")

    def __exit__(self, *exc) -> None:
        self._progress.__exit__(*exc)


def print_reconcile(console: "Console", result) -> None:
    """Print the readable summary of a :class:`~fi_design.results.reconciliation.ReconcileResult`.

    Parameters
    ----------
    console : rich.console.Console
        Where to print.
    result : fi_design.results.reconciliation.ReconcileResult
        The reconciliation.
    """
    from rich.text import Text

    head = Text("Effect: ", style="bold")
    head.append(Text(result.effect, style="bold green" if result.effect != "none" else "bold"))
    console.print(head)
    console.print(Text(result.conclusion))
    if result.diagnosis.mismatch and result.diagnosis.causes:
        d = _table("Likely causes of the structural gap")
        for col, just in (("Cause", "left"), ("Share", "right"), ("What was measured", "left")):
            d.add_column(col, justify=just, no_wrap=col == "Share",
                         ratio=1 if col == "What was measured" else None)
        for c in result.diagnosis.causes:
            d.add_row(Text(c.name.replace("_", " ")), f"{100 * c.share:.0f} %", Text(c.detail))
        console.print(d)
    if len(result.steps) > 1:
        s = _table("Effects in order")
        for col in ("Effect", "Misfit before", "Misfit after"):
            s.add_column(col, justify="left" if col == "Effect" else "right", no_wrap=True)
        for st in result.steps:
            s.add_row(Text(st.name), number(st.misfit_before), number(st.misfit_after))
        console.print(s)
    t = _table("Candidates (best first)")
    longest = max((len(c.name) for c in result.candidates), default=6)
    for col, just in (("Effect", "left"), ("Score", "right"), ("Explained", "right"),
                      ("Fitted parameters", "left")):
        t.add_column(col, justify=just, no_wrap=col != "Fitted parameters",
                     min_width=longest if col == "Effect" else None,
                     ratio=1 if col == "Fitted parameters" else None)
    for c in result.candidates:
        params = _effects_text(c.name, c.parameters, c.uncertainty)
        t.add_row(Text(c.name), number(c.score), f"{100 * c.explained:.1f} %", Text(params))
    console.print(t)
    for c in result.candidates:
        if c.name not in result.effects and c.reasons:
            console.print(Text(f"{c.name} not named: {c.reasons[0]}", style="dim"))
    g = _table("Gap before and after")
    for col in ("Metric", "Unit", "Before", "After", "Noise"):
        g.add_column(col, justify="left" if col in ("Metric", "Unit") else "right",
                     no_wrap=True)
    for m in result.gaps:
        unit, factor = scale(m.unit, (m.before, m.after, m.noise))
        g.add_row(Text(m.name), Text(unit or "-"), *[number(None if v is None else v * factor)
                                                     for v in (m.before, m.after, m.noise)])
    console.print(g)
    nz = result.noise
    parts = [f"position {quantity(nz.position, 'm', 3)} ({nz.source.get('position')})"]
    if nz.force is not None:
        parts.append(f"force {quantity(nz.force, 'N', 3)} ({nz.source.get('force')})")
    if nz.deflection is not None:
        parts.append(f"deflection {quantity(nz.deflection, 'm', 3)} "
                     f"({nz.source.get('deflection')})")
    console.print(Text("Noise: " + ", ".join(parts)))
    console.print(Text("Position lattice: " + result.lattice.detail))
    for name, why in result.skipped.items():
        console.print(Text(f"skipped {name}: {why}", style="dim"))


def print_identification(console: "Console", result) -> None:
    """Print an :class:`~fi_design.identification.IdentificationResult`: table, fit, notes.

    Parameters
    ----------
    console : rich.console.Console
        Where to print.
    result : fi_design.identification.IdentificationResult
        The identification.
    """
    from rich import box
    from rich.table import Table
    from rich.text import Text

    m = result.measurement
    console.print(Text(f"Identification from {m.source or 'the record'}: {m.n} samples, "
                       f"{result.form.replace('_', '-')} form, {result.model.replace('_', ' ')} "
                       "model", style="bold"))
    t = Table(title="Parameters (SI; standard error one sigma)", title_justify="left",
              box=box.SIMPLE_HEAD, pad_edge=False)
    for col, just in (("Parameter", "left"), ("Value", "right"), ("Std. error", "right"),
                      ("Unit", "left"), ("Identifiable", "left")):
        t.add_column(col, justify=just, no_wrap=True)
    for name, p in result.parameters.items():
        t.add_row(Text(name), number(p.value, 6), number(p.std_error, 3), Text(unit_text(p.unit)),
                  Text("yes" if p.identifiable else "no",
                       style="green" if p.identifiable else "yellow"))
    console.print(t)
    f = result.fit
    console.print(Text(f"Fit: RMS force residual {number(f.force_rms_residual, 3)} N, relative "
                       f"error {number(f.relative_error, 3)}, condition number "
                       f"{number(f.condition_number, 3)}, {f.samples_used} samples used "
                       f"({number(f.effective_samples, 3)} effective)"))
    ms = result.masses
    console.print(Text(f"Masses: stage {number(ms.stage, 5)} kg, cart {number(ms.cart, 5)} kg "
                       f"({ms.source})"))
    for name in ("static", "stribeck_velocity", "bristle_stiffness"):
        p = result.parameters[name]  # how it was estimated, or why not
        console.print(Text(f"{name}: {p.note}", style=None if p.identifiable else "dim"))
    for note in result.notes:
        console.print(Text(f"note: {note}", style="dim"))


#: One character per design-space status in :func:`print_recommendation`'s map.
CANDIDATE_GLYPHS = {"feasible": ("\u2713", "bold green"), "robustness": ("r", "yellow"),
                    "end_stop": ("e", "yellow"), "checks": ("c", "yellow"),
                    "hunts": ("\u25cf", "red"), "margins": ("m", "magenta"),
                    "flexure": ("f", "magenta"), "k_max": ("k", "dim"), "bounds": ("b", "dim"),
                    "not_evaluated": ("\u00b7", "green"), "failed": ("\u00d7", "bold red")}


def print_recommendation(console: "Console", result, spec_path: Optional[Path] = None) -> None:
    """Print a design search: the design, what binds it, the design space as a map.

    Parameters
    ----------
    console : rich.console.Console
        Where to print.
    result : fi_design.results.recommend.RecommendResult
        The search.
    spec_path : pathlib.Path, optional
        The spec file, named in the heading.
    """
    from rich import box
    from rich.table import Table
    from rich.text import Text

    _heading(console, f"Recommendation for {result.spec.name}", spec_path)
    d, sd, m = result.design, result.spec_design, result.margins
    head = "a design that passes" if result.feasible else "no design passes; the nearest"
    t = _table(f"The search found {head}")
    t.add_column("")
    t.add_column(Text("as specified" + (" (suggested)" if sd.get("suggested") else "")),
                 justify="right")
    t.add_column(Text("recommended" if result.feasible else "nearest"), justify="right")
    t.add_row("Stroke", quantity(sd["stroke"], "m", 3), quantity(d.stroke, "m", 3))
    t.add_row("Drive stiffness", f"{number(sd['stiffness'])} N/m", f"{number(d.stiffness)} N/m")
    t.add_row("Joint damping", "", "default ratio" if d.damping is None
              else f"{number(d.damping, 3)} N s/m")
    t.add_row("Crossover", f"{number(sd['crossover'])} Hz", f"{number(d.crossover)} Hz")
    t.add_row("No move hunts from", "", "-" if d.hunting_free_from is None
              else f"{number(d.hunting_free_from)} Hz")
    t.add_row("Crossover factor", "", "-" if m.get("crossover_factor") is None
              else number(m["crossover_factor"], 3))
    t.add_row("k_max / k", "", number(m.get("stiffness_factor"), 3))
    t.add_row("End-stop clearance at rest", "", quantity(m.get("end_stop_clearance"), "m", 3))
    t.add_row("Not settling under scatter", "", "-" if d.unsettled_probability is None
              else f"{number(100 * d.unsettled_probability, 3)} %")
    console.print(t)
    if result.binding:
        console.print(Text("Binds it: ", style="bold").append("; ".join(result.binding)))
    for v in result.violates:
        console.print(Text("Violates: ", style="bold red").append(v))
    # the design space at a glance: rows of stiffness (top: stiff), columns of stroke
    grid = Table(box=box.SIMPLE_HEAD, pad_edge=False)
    grid.add_column(Text("k [N/m]"), justify="right", no_wrap=True)
    unit, f = scale("m", result.strokes)
    for s in result.strokes:
        grid.add_column(Text(number(s * f, 3)), justify="center", no_wrap=True)
    nk = len(result.stiffnesses)
    for j in reversed(range(nk)):
        cells = []
        for i in range(len(result.strokes)):
            c = result.candidates[i * nk + j]
            glyph, style = CANDIDATE_GLYPHS.get(c.status, ("?", ""))
            if c is not None and c.stroke == d.stroke and c.stiffness == d.stiffness:
                style += " reverse"
            cells.append(Text(glyph, style=style))
        grid.add_row(number(result.stiffnesses[j], 3), *cells)
    console.print(Text(f"Design space at {number(d.crossover)} Hz: columns stroke [{unit}], "
                       "rows drive stiffness", style="dim"))
    console.print(grid)
    console.print(Text("\u2713 passes, \u00b7 not signed off (ranked below), \u25cf some move "
                       "hunts, r scatter, e end stop, m margins, f flexure, k above k_max, "
                       "b bounds; the chosen point reversed", style="dim"))
    console.print(Text("Advice: ", style="bold").append(result.advice))
    console.print(f"{result.evaluations} stage-level evaluations in {result.wall_time:.1f} s",
                  markup=False, highlight=False)
