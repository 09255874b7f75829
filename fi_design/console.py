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


def _fmt(value: Any, digits: int = 4) -> str:
    """A number for a table cell: ``digits`` significant digits, '-' for none."""
    if value is None:
        return "-"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, (int, float)):
        return f"{value:.{digits}g}"
    return str(value)


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


def checks_table(checks, title: str = "Checks"):
    """A rich table of :class:`~fi_design.results.Check` values, status coloured.

    Checks are grouped by their ``step``: a bold heading row starts each group.

    Parameters
    ----------
    checks : sequence of fi_design.results.Check
        The checks, in report order.
    title : str, optional
        Table title.

    Returns
    -------
    rich.table.Table
        Columns check, status, value, limit, unit, message.
    """
    from rich import box
    from rich.table import Table
    from rich.text import Text

    table = Table(title=title, title_justify="left", box=box.SIMPLE_HEAD, pad_edge=False)
    table.add_column("Check", no_wrap=True)
    table.add_column("Status", no_wrap=True)
    table.add_column("Value", justify="right", no_wrap=True)
    table.add_column("Limit", justify="right", no_wrap=True)
    table.add_column("Unit", no_wrap=True)
    table.add_column("Message", ratio=1, min_width=30)
    step = None
    for c in checks:
        if (c.step or "") != step:
            step = c.step or ""
            if step:
                table.add_row(Text(step, style="bold"))
        table.add_row(Text(c.name), _status_text(c.status), _fmt(c.value), _fmt(c.limit),
                      Text(c.unit or ""), Text(c.message or ""))
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
    from rich import box
    from rich.table import Table
    from rich.text import Text

    data = result.to_dict()
    name = _spec_name(result)
    _heading(console, name or "fi-design", spec_path)

    gap = data.get("friction_gap") or {}
    if gap:
        risk = gap.get("hunting_risk")
        console.print(Text(
            f"Friction gap Fs - Fc = {_fmt(gap.get('gap'))} N (threshold "
            f"{_fmt(gap.get('threshold'))} N): "
            + ("hunting is a risk" if risk else "hunting unlikely" if risk is not None else "")))

    console.print(checks_table(result.checks))

    pid = data.get("pid") or {}
    if pid:
        if pid.get("source") == "gains":
            # the hardware's loop beside the rule's gains in the same form
            hw, rule = pid["controller"], pid["rule_in_hardware_form"]
            t = Table(title="PID gains (step 4): the hardware's, and the rule's at the same "
                            "crossover", title_justify="left", box=box.SIMPLE_HEAD,
                      pad_edge=False)
            t.add_column("")
            for col in ("kp [N/m]", "ki [N/(m s)]", "kd [N s/m]", "D roll-off [Hz]"):
                t.add_column(Text(col), justify="right", no_wrap=True)
            for label, g in (("hardware", hw), ("rule", rule)):
                wf = g.get("roll_off")
                t.add_row(label, _fmt(g.get("kp")), _fmt(g.get("ki")), _fmt(g.get("kd")),
                          "none" if wf is None else _fmt(wf / (2 * math.pi)))
            console.print(t)
        else:
            t = Table(title="PID gains (step 4)", title_justify="left", box=box.SIMPLE_HEAD,
                      pad_edge=False)
            for col in ("kp [N/m]", "ki [N/(m s)]", "kd [N s/m]", "wt [rad/s]",
                        "tuning mass [kg]"):
                t.add_column(Text(col), justify="right", no_wrap=True)
            t.add_row(_fmt(pid.get("kp")), _fmt(pid.get("ki")), _fmt(pid.get("kd")),
                      _fmt(pid.get("wt")), _fmt(pid.get("tuning_mass")))
            console.print(t)

    xo = data.get("crossover") or {}
    if xo:
        line = (f"Crossover: desired {_fmt(xo.get('desired'))} Hz, achievable "
                f"{_fmt(xo.get('achievable'))} Hz")
        if xo.get("limited_by"):
            line += f", limited by {xo['limited_by']}"
        console.print(Text(line))
        cases = xo.get("cases") or []
        if cases:
            console.print(_cases_table(cases, {c.name: c.number for c in result.loop.cases}))

    stiff = data.get("stiffness") or {}
    if stiff.get("maximum") is not None:
        if stiff.get("suggested"):
            text = (f"Drive stiffness (suggestion for an isolator with a "
                    f"{_fmt(1e3 * stiff['stroke'], 3)} mm stroke): k_max = "
                    f"{_fmt(stiff['maximum'])} N/m, start from k = {_fmt(stiff.get('chosen'))} N/m")
        else:
            text = (f"Drive stiffness: k_max = {_fmt(stiff['maximum'])} N/m, chosen k = "
                    f"{_fmt(stiff.get('chosen'))} N/m")
            if stiff.get("source"):
                text += f" ({stiff['source']})"
            if stiff.get("force_at_stroke") is not None:
                text += f", flexure force at full stroke {_fmt(stiff['force_at_stroke'], 3)} N"
        console.print(Text(text))

    sim = data.get("simulation")
    if isinstance(sim, dict) and "isolated" in sim:
        console.print(_simulation_table(sim))

    conclusion = getattr(result, "conclusion", "") or data.get("conclusion", "")
    if conclusion:
        console.print(Text("Conclusion: ", style="bold").append(Text(str(conclusion),
                                                                        style="")))
    for w in getattr(result, "warnings", ()) or ():
        console.print(Text("warning: ", style="bold yellow").append(Text(_warning_text(w))))


def _simulation_table(sim: dict) -> Any:
    """Table of the simulated verdicts from the confirmation's JSON form."""
    from rich import box
    from rich.table import Table
    from rich.text import Text

    label = "suggested isolator" if sim.get("suggested_isolator") else "with isolator"
    t = Table(title="Nonlinear confirmation (LuGre simulation, paper section 2.3)"
              if sim["isolated"].get("friction_model") == "lugre"
              else "Nonlinear confirmation (switch friction model)",
              title_justify="left", box=box.SIMPLE_HEAD, pad_edge=False)
    for col, just in (("Plant", "left"), ("Verdict", "left"), ("Cycles", "right"),
                      ("Amplitude [um]", "right"), ("Period [s]", "right"),
                      ("Final error [um]", "right"), ("Hunting-free from [Hz]", "right"),
                      ("Other model", "left")):
        t.add_column(Text(col), justify=just, no_wrap=True)
    mins = sim.get("min_hunting_free_crossover") or {}
    other = sim.get("cross_check") or {}
    for key, name in (("isolated", label), ("non_isolated", "without isolator")):
        v = sim[key]
        verdict = v.get("verdict", "")
        style = {"settled": "bold green", "hunting": "bold red"}.get(verdict, "bold yellow")
        m = mins.get(key)
        t.add_row(name, Text(verdict, style=style), str(v.get("hunting_cycles")),
                  _fmt(None if v.get("amplitude") is None else 1e6 * v["amplitude"], 3),
                  _fmt(v.get("period"), 3),
                  _fmt(None if v.get("final_error") is None else 1e6 * v["final_error"], 3),
                  "not found" if m is None else f"{m:g} (+-{mins.get('resolution', 0):g})",
                  (other.get(key) or {}).get("verdict", ""))
    return t


def _spec_name(result) -> str:
    spec = getattr(result, "spec", None)
    return getattr(spec, "name", "") if spec is not None else ""


def _warning_text(w: Any) -> str:
    if isinstance(w, (tuple, list)) and len(w) == 2:
        return f"{w[0]}: {w[1]}"
    return str(w)


#: Columns of the limit-case table: JSON key -> header with unit (others are appended).
CASE_COLUMNS = {
    "crossover": "Crossover [Hz]",
    "phase_margin_deg": "Phase margin [deg]",
    "gain_margin_db": "Gain margin [dB]",
    "modulus_margin": "Modulus margin [-]",
    "delay_margin": "Delay margin [s]",
    "stable": "Stable",
}
_CASE_SKIP = {"name", "description", "passed", "failed", "crossovers"}


def _cases_table(cases: list, numbers: dict) -> Any:
    """Table of the linear limit cases (paper Figure 2) from their JSON form and numbers."""
    from rich import box
    from rich.table import Table
    from rich.text import Text

    keys = [k for k in CASE_COLUMNS if any(k in c for c in cases)]
    for case in cases:
        keys += [k for k, v in case.items() if k not in keys and k not in _CASE_SKIP
                 and not isinstance(v, (dict, list))]
    t = Table(title="Linear limit cases at the desired crossover (paper Figure 2)",
              title_justify="left", box=box.SIMPLE_HEAD, pad_edge=False)
    t.add_column("#", justify="right", no_wrap=True)
    t.add_column("Case", no_wrap=True)
    for k in keys:
        t.add_column(Text(CASE_COLUMNS.get(k, _header(k))), justify="right")
    t.add_column("Status", no_wrap=True)
    for i, case in enumerate(cases, 1):
        number = str(numbers.get(case.get("name"), i))
        label = case.get("description") or case.get("name") or ""
        cells = [Text("inf" if case.get(k) is None and "margin" in k else _fmt(case.get(k)))
                 for k in keys]
        passed = case.get("passed")
        status = _status_text("INFO" if passed is None else "PASS" if passed else "FAIL")
        if case.get("failed"):
            status.append(" " + ", ".join(map(str, case["failed"])))
        t.add_row(number, Text(str(label)), *cells, status)
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
            ("position, model - measured, rms [um]", _fmt(1e6 * fit.position_rms, 4)),
            ("position, model - measured, max [um]", _fmt(1e6 * fit.position_max, 4)),
            ("tracking error r - x1 rms, model [um]", _fmt(1e6 * fit.tracking_rms_model, 4)),
            ("tracking error r - x1 rms, measured [um]",
             _fmt(1e6 * fit.tracking_rms_measured, 4)),
            ("commanded force, model - measured, rms [N]", _fmt(fit.force_rms, 4)),
        ]
        if result.window is not None:
            rows.append(("re-anchored windows [-]", str(int(result.window.max()) + 1)))
    else:
        rows += [
            ("verdict", m.verdict),
            ("hunting cycles in the window [-]", str(m.hunting_cycles)),
            ("amplitude (peak to peak) [um]", _fmt(1e6 * m.amplitude, 4)),
            ("period [s]", _fmt(m.period, 4)),
            ("settling time [s]", _fmt(m.settling_time, 4)),
            ("final error [um]", _fmt(1e6 * m.final_error, 4)),
        ]
    rows += [
        ("integration", "ok" if result.success else result.message),
        ("steps / rejected / events [-]", f"{result.n_steps} / {result.n_rejected} / "
                                          f"{result.n_events}"),
        ("wall time [ms]", _fmt(1e3 * result.wall_time, 3)),
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
    from .plots import display_unit

    unit, f = display_unit(axis.unit)
    v = axis.values
    scale = "log" if axis.log else "linear"
    return (f"{axis.path}: {len(v)} values {_fmt(v[0] * f)} to {_fmt(v[-1] * f)} {unit} "
            f"({scale})")


_CELL = {"settled": ("·", "green"), "stuck": ("s", "yellow"), "undetermined": ("?", "yellow"),
         "invalid": ("-", "dim"), "failed": ("×", "bold red")}


def sweep_grid_table(result, max_columns: int = 25):
    """The map as a rich table: hunting cycles per point, marks for the other verdicts.

    Parameters
    ----------
    result : fi_design.studies.SweepResult
        A two-dimensional sweep (a line is shown as one row).
    max_columns : int, optional
        Wider maps are not tabulated (None is returned).

    Returns
    -------
    rich.table.Table or None
        Rows are y values, columns x values, both in display units; a cell
        holds the cycle count of a hunting point, ``·`` settled, ``s`` stuck,
        ``?`` undetermined, ``-`` invalid, ``×`` failed.
    """
    from rich import box
    from rich.table import Table
    from rich.text import Text

    from .plots import display_unit

    x, y = result.x, result.y
    if len(x.values) > max_columns:
        return None
    xu, xf = display_unit(x.unit)
    if y is not None:
        yu, yf = display_unit(y.unit)
    t = Table(box=box.SIMPLE_HEAD, pad_edge=False)
    t.add_column(Text("" if y is None else f"[{yu}]"), justify="right", no_wrap=True)
    for v in x.values:
        t.add_column(Text(_fmt(v * xf, 3)), justify="right", no_wrap=True)
    rows = result.verdict.reshape(-1, len(x.values))
    cycles = result.hunting_cycles.reshape(-1, len(x.values))
    labels = [""] if y is None else [_fmt(v * yf, 3) for v in y.values]
    for label, vrow, crow in zip(labels, rows, cycles):
        cells = []
        for v, c in zip(vrow, crow):
            if v == "hunting":
                cells.append(Text(str(int(c)), style="bold red"))
            else:
                mark, style = _CELL.get(str(v), ("", ""))
                cells.append(Text(mark, style=style))
        t.add_row(label, *cells)
    return t


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
    from .plots import display_unit

    text = f"hunting cycles in the window; columns {result.x.path} " \
           f"[{display_unit(result.x.unit)[0]}]"
    if result.y is not None:
        text += f", rows {result.y.path} [{display_unit(result.y.unit)[0]}]"
    return text + "; · settled, s stuck, ? undetermined, - invalid, × failed"


def _print_grid(console: "Console", result) -> None:
    from rich.text import Text

    table = sweep_grid_table(result)
    if table is not None:
        console.print(Text(grid_caption(result), style="dim"))
        console.print(table)


def _print_counts(console: "Console", counts: dict) -> None:
    text = ", ".join(f"{n} {v}" for v, n in counts.items() if n)
    console.print(f"points: {text}", markup=False, highlight=False)


def _print_run(console: "Console", run, executor: str) -> None:
    console.print(f"{run.points} points: {run.computed} simulated, {run.cached} from the cache; "
                  f"{executor}; {run.wall_time:.2f} s", markup=False, highlight=False)


def print_sweep(console: "Console", result, spec_path: Optional[Path] = None,
                executor: str = "") -> None:
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
    """
    from rich.text import Text

    from .plots import display_unit

    _heading(console, f"Sweep of {result.spec.name}", spec_path)
    plant = "with isolator" if result.isolated else "without isolator"
    console.print(Text(f"{_axis_values_text(result.x)}; {plant}"))
    if result.y is not None:
        console.print(Text(_axis_values_text(result.y)))
    _print_grid(console, result)
    _print_counts(console, result.counts())
    xu, xf = display_unit(result.x.unit)
    above = result.boundary("above")
    if result.y is None:
        if not math.isnan(above[0]):
            console.print(Text(f"no hunting from {result.x.path} = {_fmt(above[0] * xf)} {xu} "
                               "upwards"))
    failed = [p for p in result.points if p.status == "failed"]
    for p in failed[:3]:
        console.print(Text(f"failed at {dict(zip(result.paths, p.values))}: {p.message}",
                           style="red"))
    if len(failed) > 3:
        console.print(Text(f"... and {len(failed) - 3} more failed point(s); see --csv or --json",
                           style="red"))
    _print_run(console, result.run, executor)


def print_study(console: "Console", result, spec_path: Optional[Path] = None,
                executor: str = "") -> None:
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
    """
    from rich.text import Text

    _heading(console, f"Paper study (Figure 4) around {result.spec.name}", spec_path)
    for m in result.maps:
        d = m.definition
        console.print(Text(f"\n{d.key}) {d.title}", style="bold"))
        console.print(Text(f"paper: {d.paper}", style="dim"))
        _print_grid(console, m.result)
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
    from rich import box
    from rich.table import Table
    from rich.text import Text

    from .plots import display_unit

    _heading(console, f"Robustness of {result.spec.name}", spec_path)
    for sc in result.scatter:
        unit, f = display_unit("") if sc.relative else display_unit(
            _path_unit(sc.path, result.spec))
        spread = f"{sc.spread:.3g} of nominal ({100 * sc.spread:.3g} %)" if sc.relative else \
            f"{_fmt(sc.spread * f)} {unit}"
        console.print(Text(f"scatter {sc.path}: {result.distribution}, spread {spread}"))
    if result.position_friction is not None:
        pf = result.position_friction
        console.print(Text(f"position-dependent friction: amplitude {100 * pf.amplitude:.3g} %, "
                           f"wavelength {pf.wavelength * 1e3:.4g} mm, random phase"))
    conf = result.not_isolated.confidence
    t = Table(title=f"Probability of hunting, {result.samples} samples, seed {result.seed}",
              title_justify="left", box=box.SIMPLE_HEAD, pad_edge=False)
    t.caption = Text(f"P: probability of hunting among the valid samples; CI: {conf:.0%} Wilson "
                     "interval", style="dim")
    t.caption_justify = "left"
    for col in ("Plant", "Hunting", "Valid", "P [%]", "CI [%]", "Settled", "Stuck",
                "Undetermined", "Invalid", "Failed"):
        t.add_column(Text(col), justify="left" if col == "Plant" else "right", no_wrap=True)
    for label, p in (("with isolator", result.isolated),
                     ("without isolator", result.not_isolated)):
        if p is None:
            continue
        prob = "-" if p.probability is None else f"{100 * p.probability:.1f}"
        c = p.counts
        t.add_row(label, str(p.hunting), str(p.valid), prob,
                  f"{100 * p.low:.1f} to {100 * p.high:.1f}", str(c["settled"]), str(c["stuck"]),
                  str(c["undetermined"]), str(c["invalid"]), str(c["failed"]))
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
    from rich import box
    from rich.table import Table
    from rich.text import Text

    head = Text("Effect: ", style="bold")
    head.append(Text(result.effect, style="bold green" if result.effect != "none" else "bold"))
    console.print(head)
    console.print(Text(result.conclusion))
    if result.diagnosis.mismatch and result.diagnosis.causes:
        d = Table(title="Likely causes of the structural gap", title_justify="left",
                  box=box.SIMPLE_HEAD, pad_edge=False)
        for col, just in (("Cause", "left"), ("Share", "right"), ("What was measured", "left")):
            d.add_column(col, justify=just)
        for c in result.diagnosis.causes:
            d.add_row(Text(c.name.replace("_", " ")), f"{100 * c.share:.0f} %", Text(c.detail))
        console.print(d)
    if len(result.steps) > 1:
        s = Table(title="Effects in order", title_justify="left", box=box.SIMPLE_HEAD,
                  pad_edge=False)
        for col in ("Effect", "Misfit before", "Misfit after"):
            s.add_column(col, justify="left" if col == "Effect" else "right")
        for st in result.steps:
            s.add_row(Text(st.name), _fmt(st.misfit_before), _fmt(st.misfit_after))
        console.print(s)
    t = Table(title="Candidates (best first)", title_justify="left", box=box.SIMPLE_HEAD,
              pad_edge=False)
    for col, just in (("Effect", "left"), ("Score", "right"), ("Explained", "right"),
                      ("Fitted parameters (SI)", "left"), ("Not named because", "left")):
        t.add_column(col, justify=just)
    for c in result.candidates:
        params = ", ".join(f"{k} = {_fmt(v)}" + (f" +- {_fmt(c.uncertainty.get(k), 2)}"
                                                 if c.uncertainty.get(k) else "")
                           for k, v in c.parameters.items() if v is not None)
        why = "" if c.name in result.effects else (c.reasons[0] if c.reasons else "")
        t.add_row(Text(c.name), _fmt(c.score), f"{100 * c.explained:.1f} %", Text(params),
                  Text(why, style="dim"))
    console.print(t)
    g = Table(title="Gap before and after", title_justify="left", box=box.SIMPLE_HEAD,
              pad_edge=False)
    for col in ("Metric", "Unit", "Before", "After", "Noise"):
        g.add_column(col, justify="left" if col in ("Metric", "Unit") else "right")
    for m in result.gaps:
        g.add_row(Text(m.name), Text(m.unit), _fmt(m.before), _fmt(m.after), _fmt(m.noise))
    console.print(g)
    nz = result.noise
    parts = [f"position {_fmt(nz.position, 3)} m ({nz.source.get('position')})"]
    if nz.force is not None:
        parts.append(f"force {_fmt(nz.force, 3)} N ({nz.source.get('force')})")
    if nz.deflection is not None:
        parts.append(f"deflection {_fmt(nz.deflection, 3)} m ({nz.source.get('deflection')})")
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
        t.add_row(Text(name), _fmt(p.value, 6), _fmt(p.std_error, 3), Text(p.unit),
                  Text("yes" if p.identifiable else "no",
                       style="green" if p.identifiable else "yellow"))
    console.print(t)
    f = result.fit
    console.print(Text(f"Fit: RMS force residual {_fmt(f.force_rms_residual, 3)} N, relative "
                       f"error {_fmt(f.relative_error, 3)}, condition number "
                       f"{_fmt(f.condition_number, 3)}, {f.samples_used} samples used "
                       f"({_fmt(f.effective_samples, 3)} effective)"))
    ms = result.masses
    console.print(Text(f"Masses: stage {_fmt(ms.stage, 5)} kg, cart {_fmt(ms.cart, 5)} kg "
                       f"({ms.source})"))
    for name in ("static", "stribeck_velocity", "bristle_stiffness"):
        p = result.parameters[name]  # how it was estimated, or why not
        console.print(Text(f"{name}: {p.note}", style=None if p.identifiable else "dim"))
    for note in result.notes:
        console.print(Text(f"note: {note}", style="dim"))
