"""The design search's summary: the design and its guide, the least change, what binds it.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Optional

from ..display import fixed, number, percent, quantity
from .common import heading, table

if TYPE_CHECKING:  # pragma: no cover
    from rich.console import Console


def _mm(x: float | None) -> str:
    return "-" if x is None else quantity(x, "m", 3, shown=("mm", 1e3))


def _margin(x: float | None) -> str:
    if x is None:
        return "-"
    return "no cycle found" if math.isinf(x) else number(x, 3)


def search_origin(result) -> str | None:
    """Where a design search's result came from, when it was read from the cache.

    Parameters
    ----------
    result : fi_design.results.recommend.RecommendResult
        The search.

    Returns
    -------
    str or None
        ``from the cache (FOLDER), run earlier with N stage-level evaluations
        in T s``; None for a search run by this call.
    """
    if result.from_cache is None:
        return None
    return (f"from the cache ({Path(result.from_cache).parent}), run earlier with "
            f"{result.evaluations} stage-level evaluations in {fixed(result.wall_time, 1)} s")


def print_recommendation(console: "Console", result, spec_path: Optional[Path] = None) -> None:
    """Print a design search: the design beside the spec's, its guide, reserves, least change.

    Parameters
    ----------
    console : rich.console.Console
        Where to print.
    result : fi_design.results.recommend.RecommendResult
        The search.
    spec_path : pathlib.Path, optional
        The spec file, named in the heading.
    """
    from rich.text import Text

    heading(console, f"Recommendation for {result.spec.name}", spec_path)
    d, sd, m = result.design, result.spec_design, result.margins
    req = result.spec.requirements
    head = "the stiffest buildable joint that keeps the hunting margin" if result.feasible \
        else "no design that passes; the nearest"
    t = table(f"The search found {head}")
    t.add_column("")
    t.add_column(Text("as specified" + (" (suggested)" if sd.get("suggested") else "")),
                 justify="right")
    t.add_column(Text("recommended" if result.feasible else "nearest"), justify="right")
    t.add_row("Stroke", quantity(sd["stroke"], "m", 3), quantity(d.stroke, "m", 3))
    guide = "-" if d.length is None else \
        f"{_mm(d.length)} x {_mm(d.width)} x {_mm(d.thickness)}"
    fx = result.flexure
    t.add_row("Leaves L x b x t", "", guide + ("" if fx is None or fx.guide is None else
                                               f", {fx.leaves} {fx.guide.orientation}"))
    t.add_row("Drive stiffness k (recommended: the guide's, net of gravity)",
              f"{number(sd['stiffness'])} N/m",
              f"{number(d.stiffness)} N/m")
    t.add_row("Lowest parasitic mode", "", "-" if d.lowest_mode is None
              else f"{number(d.lowest_mode)} Hz")
    if fx is not None and fx.mechanics is not None and \
            fx.mechanics.gravity.buckling_factor is not None:
        t.add_row("Buckling load / weight", "", number(fx.mechanics.gravity.buckling_factor, 3))
    t.add_row("Joint damping", "", "default ratio" if d.damping is None
              else quantity(d.damping, "N*s/m", 3))
    t.add_row("Crossover", f"{number(sd['crossover'])} Hz", f"{number(d.crossover)} Hz")
    t.add_row("No move hunts from", "", "-" if d.hunting_free_from is None
              else f"{number(d.hunting_free_from)} Hz")
    t.add_row(f"Hunting margin (required {number(req.hunting_margin, 3)})", "",
              _margin(m.get("hunting_margin")))
    t.add_row("k_max / k", "", number(m.get("stiffness_factor"), 3))
    lo, hi = (fx.stiffness_range or (None, None)) if fx is not None else (None, None)
    if lo is not None and hi > lo:  # the stock's tolerance: k goes with t^3
        t.add_row(f"k over the leaves' tolerance (\u00b1{_mm(fx.thickness_tolerance)})", "",
                  f"{number(lo)} to {number(hi)} N/m")
    t.add_row("End-stop clearance at rest", "", "-" if m.get("end_stop_clearance") is None
              else quantity(m["end_stop_clearance"], "m", 3))
    t.add_row("Not settling under scatter", "", "-" if d.unsettled_probability is None
              else percent(d.unsettled_probability, 3))
    console.print(t)
    if result.reserves:
        bad = [r for r in result.reserves if not r["passed"]]
        words = ", ".join(r["name"] for r in result.reserves)
        console.print(Text("Reserves: ", style="bold").append(
            f"passes with {words}" if not bad else
            "; ".join(f"{r['name']}: {r['why']}" for r in bad)))
    if result.binding:
        console.print(Text("Binds it: ", style="bold").append("; ".join(result.binding)))
    for n in result.flexure_bounds:
        console.print(Text("On a bound: ", style="bold").append(n.text))
    for v in result.violates:
        console.print(Text("Violates: ", style="bold red").append(v))
    lc = result.least_change
    if lc is not None:
        if lc.feasible:
            edits = ", ".join(f"{p} = {v}" for p, v in lc.changes.items())
            console.print(Text("Least change that passes: ", style="bold").append(
                f"{lc.text} ({edits})"))
        else:
            console.print(Text("Least change: ", style="bold").append(
                lc.text + ("; build the recommended design" if result.feasible else "")))
    if result.pareto:
        front = [p for p in result.pareto if p["hunting_margin"] is not None][:6]
        if front:
            console.print(Text("Trade-off (Pareto front, stiffest first): ", style="dim").append(
                "; ".join(f"{number(p['stiffness'], 3)} N/m at {_mm(p['stroke'])} keeps "
                          f"{number(p['hunting_margin'], 3)}" for p in front), style="dim"))
    for a in result.assumptions:
        console.print(Text("Assumed: ", style="dim").append(a, style="dim"))
    console.print(Text("Advice: ", style="bold").append(result.advice))
    cached = search_origin(result)
    console.print(f"The design search: {cached}" if cached is not None else
                  f"{result.evaluations} stage-level evaluations in {fixed(result.wall_time, 1)} s",
                  markup=False, highlight=False)
