"""Parameter studies: the map as a table at the console's width, the paper's study, robustness.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Optional

from ..display import axis_unit, fixed, number, percent, quantity
from .common import heading, table

if TYPE_CHECKING:  # pragma: no cover
    from rich.console import Console


def _axis_values_text(axis) -> str:
    from ..plots import quantity_name

    unit, f = axis_unit(axis.unit, axis.values)
    v = axis.values
    scale = "log" if axis.log else "linear"
    name = quantity_name(axis.path)
    named = name if name == axis.path else f"{name} ({axis.path})"  # the path once
    return (f"{named}: {len(v)} values {number(v[0] * f)} to {number(v[-1] * f)} {unit} "
            f"({scale})")


_CELL = {"settled": ("·", "green"), "stuck": ("s", "yellow"), "undetermined": ("?", "yellow"),
         "buckled": ("b", "bold magenta"), "invalid": ("-", "dim"), "failed": ("×", "bold red")}


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
        ``?`` undetermined, ``b`` the drawn guide buckled under the stage (not
        simulated), ``-`` invalid, ``×`` failed.
    """
    from rich import box
    from rich.table import Table
    from rich.text import Text

    x, y = result.x, result.y
    cols = range(len(x.values))[columns or slice(None)]
    xu, xf = axis_unit(x.unit, x.values)
    if y is not None:
        yu, yf = axis_unit(y.unit, y.values)
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
                cells.append(Text(number(c, 2) if stage else str(int(c)), style="bold red"))
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
    from ..plots import axis_label

    what = ("peak to peak of the cycle some move ends in [mm]"
            if getattr(result, "measure", "move") == "stage"
            else "hunting cycles of the spec's move in the window")
    text = f"{what}; columns: {axis_label(result.x.path, result.x.unit, result.x.values)}"
    if result.y is not None:
        text += f", rows: {axis_label(result.y.path, result.y.unit, result.y.values)}"
    marks = "; · settled, s stuck, ? undetermined, - invalid, × failed"
    if "buckled" in result.verdict:
        marks += "; b the weight has buckled the guide (not simulated)"
    return text + marks


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
    # "evaluated": a point whose guide the weight buckles is judged without a simulation
    console.print(f"{run.points} points: {run.computed} evaluated now, {run.cached} from the cache; "
                  f"{executor}; {fixed(run.wall_time, 2)} s", markup=False, highlight=False)


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

    from ..plots import quantity_name

    heading(console, f"Sweep of {result.spec.name}", spec_path)
    plant = "with isolator" if result.isolated else "without isolator"
    console.print(Text(f"{_axis_values_text(result.x)}; {plant}"))
    if result.y is not None:
        console.print(Text(_axis_values_text(result.y)))
    _print_grid(console, result, files)
    _print_counts(console, result.counts())
    for note in result.notes:
        console.print(Text(f"note: {note}", style="yellow"))
    xu, xf = axis_unit(result.x.unit, result.x.values)
    above = result.boundary("above")
    if result.y is None:
        if not math.isnan(above[0]):
            console.print(Text(f"no hunting from {quantity_name(result.x.path).lower()} = "
                               f"{number(above[0] * xf)} {xu} upwards"))
    buckled = [p for p in result.points if p.verdict == "buckled"]
    if buckled:
        console.print(Text(f"buckled: at {len(buckled)} point(s) the stage's weight buckles the "
                           "drawn guide (net drive stiffness at or below 0, which the design "
                           "fails in step 3); they are not simulated and count as no design",
                           style="magenta"))
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

    heading(console, f"Paper study (Figure 4) around {result.spec.name}", spec_path)
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

    heading(console, f"Robustness of {result.spec.name}", spec_path)
    for sc, path_unit in zip(result.scatter, result.units or ("",) * len(result.scatter)):
        unit, f = axis_unit("" if sc.relative else path_unit)
        spread = (f"{number(sc.spread, 3)} of nominal ({percent(sc.spread, 3)})" if sc.relative
                  else f"{number(sc.spread * f)} {unit}")
        console.print(Text(f"scatter {sc.path}: {result.distribution}, spread {spread}"))
    if result.position_friction is not None:
        pf = result.position_friction
        console.print(Text(f"position-dependent friction: amplitude {percent(pf.amplitude, 3)}, "
                           f"wavelength {quantity(pf.wavelength, 'm', 4)}, random phase"))
    conf = result.not_isolated.confidence
    t = table(f"Probability of hunting, {result.samples} samples, seed {result.seed}")
    plants = [(label, p) for label, p in (("with isolator", result.isolated),
                                          ("without isolator", result.not_isolated))
              if p is not None]
    t.add_column("")
    for label, _ in plants:
        t.add_column(Text(label), justify="right")
    rows = [
        ("Probability of hunting", lambda p: "-" if p.probability is None
         else percent(p.probability, 3)),
        (f"{percent(conf, 2)} Wilson interval",
         lambda p: f"{percent(p.low, 3)} to {percent(p.high, 3)}"),
        ("Hunting / valid samples", lambda p: f"{p.hunting} / {p.valid}"),
    ] + [(f"  {v}", lambda p, v=v: str(p.counts.get(v, 0)))
         for v in ("settled", "stuck", "undetermined", "buckled", "invalid", "failed")
         if v != "buckled" or any(p.counts.get(v, 0) for _, p in plants)]
    for title, cell in rows:
        t.add_row(Text(title), *[cell(p) for _, p in plants])
    t.caption = Text("Probability among the valid samples; the indented rows count every "
                     "sample by its verdict", style="dim")
    t.caption_justify = "left"
    console.print(t)
    _print_run(console, result.run, executor)
