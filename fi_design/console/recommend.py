"""The design search's summary: the design, what binds it, the design space as a map.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Optional

from ..display import number, quantity, scale
from .common import heading, table

if TYPE_CHECKING:  # pragma: no cover
    from rich.console import Console


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

    heading(console, f"Recommendation for {result.spec.name}", spec_path)
    d, sd, m = result.design, result.spec_design, result.margins
    head = "a design that passes" if result.feasible else "no design passes; the nearest"
    t = table(f"The search found {head}")
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
    console.print(Text("\u2713 passes, \u00b7 no move hunts, less margin (not signed off), "
                       "\u25cf some move hunts, r scatter, e end stop, m margins, f flexure, k above "
                       "k_max, b bounds; the chosen point reversed", style="dim"))
    console.print(Text("Advice: ", style="bold").append(result.advice))
    console.print(f"{result.evaluations} stage-level evaluations in {result.wall_time:.1f} s",
                  markup=False, highlight=False)
