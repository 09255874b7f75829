"""The design space of a recommendation and its trade-off: stiffness against hunting margin.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..display import number, quantity
from .figure import log_x, plain_tick, report_figure, styled

__all__ = ["CANDIDATE_LOOK", "recommend_figure"]

#: Colour and legend text of each status of a design-space point.
CANDIDATE_LOOK = {
    "feasible": ("#4daf4a", "passes the sign-off"),
    "robustness": ("#fdb863", "fails under scatter"),
    "reserve": ("#fdb863", "fails a reserve corner"),
    "checks": ("#e08214", "fails another check"),
    "margin": ("#fee08b", "within the hunting margin"),
    "hunts": ("#d7301f", "some move hunts"),
    "margins": ("#8073ac", "loop margins"),
    "flexure": ("#b2abd2", "no guide can be built"),
    "k_max": ("0.55", "k > k_max"),
    "bounds": ("0.75", "outside the bounds"),
    "not_evaluated": ("#c7e9c0", "keeps the margin, softer (not signed off)"),
    "failed": ("black", "simulation failed"),
}


@styled
def recommend_figure(result: Any) -> Any:
    """The design space (stroke x stiffness) and the trade-off (stiffness x hunting margin).

    Left: every point the search built or judged, coloured by what it fails
    first (:data:`CANDIDATE_LOOK`); dashed, k_max = Fs / stroke; the spec's
    design a cross, the recommended (or nearest) one a star. Right: the
    hunting margin (crossover over the hunting-free crossover) of every judged
    guide against its net drive stiffness; the line joins the Pareto front
    (no other design is both stiffer and further from hunting), dashed the
    required margin; the star the recommended design.

    Parameters
    ----------
    result : fi_design.results.recommend.RecommendResult
        The search.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.lines import Line2D
    from matplotlib.ticker import FuncFormatter, LogLocator, NullLocator

    fig = report_figure(3.4, top=0.75, left=0.62, right=0.15, bottom=0.5)
    left = fig.add_axes([0.115, 0.15, 0.37, 0.62])
    right = fig.add_axes([0.59, 0.15, 0.38, 0.62])
    seen: list[str] = []
    for c in result.candidates:
        col, _ = CANDIDATE_LOOK.get(c.status, ("white", c.status))
        left.plot([c.stroke * 1e3], [c.stiffness], "o", color=col, ms=6, mec="0.35", mew=0.5)
        if c.status not in seen:
            seen.append(c.status)
    s = np.asarray(result.strokes)
    spec = result.spec
    fs = spec.friction.static / spec.requirements.stiffness_safety
    line = np.geomspace(s.min() * 0.8, s.max() * 1.25, 50)
    left.plot(line * 1e3, fs / line, color="0.15", lw=1.0, ls="--")
    sd = result.spec_design
    left.plot([sd["stroke"] * 1e3], [sd["stiffness"]], "X", color="black", ms=9, mec="white",
              mew=1.0)
    d = result.design
    star = dict(marker="*", color="gold" if result.feasible else "white", ms=15, mec="black",
                mew=1.0, ls="none")
    left.plot([d.stroke * 1e3], [d.stiffness], **star)
    log_x(left)
    left.set_yscale("log")
    left.yaxis.set_major_formatter(FuncFormatter(plain_tick))
    left.set_xlabel("stroke [mm]")
    left.set_ylabel("net drive stiffness [N/m]")
    left.set_title(f"design space at {quantity(d.crossover, 'Hz', 4)}", loc="left", fontsize=7.5)

    req = spec.requirements.hunting_margin
    judged = [c for c in result.candidates
              if c.hunting_margin is not None and c.hunting_margin > 0
              and math.isfinite(c.hunting_margin)]
    for c in judged:
        col, _ = CANDIDATE_LOOK.get(c.status, ("white", c.status))
        right.plot([c.stiffness], [c.hunting_margin], "o", color=col, ms=5, mec="0.35", mew=0.5)
    front = [p for p in result.pareto if p["hunting_margin"] is not None]
    if front:
        right.plot([p["stiffness"] for p in front], [p["hunting_margin"] for p in front],
                   color="0.2", lw=1.0, zorder=1)
    right.axhline(req, color="#d7301f", lw=1.0, ls="--")
    right.text(0.02, req, f" required {number(req, 6)}", transform=right.get_yaxis_transform(),
               va="bottom", fontsize=7, color="#d7301f")
    if d.hunting_margin is not None and math.isfinite(d.hunting_margin) and d.hunting_margin:
        right.plot([d.stiffness], [d.hunting_margin], **star)
    right.set_xscale("log")  # often less than a decade: ticks at 1, 2 and 5
    right.xaxis.set_major_locator(LogLocator(base=10.0, subs=(1.0, 2.0, 5.0)))
    right.xaxis.set_major_formatter(FuncFormatter(plain_tick))
    right.xaxis.set_minor_locator(NullLocator())
    right.set_xlabel("net drive stiffness [N/m]")
    right.set_ylabel("hunting margin: crossover / hunting-free [-]")
    right.set_title("trade-off: the stiffer, the closer to hunting", loc="left", fontsize=7.5)

    handles = [Line2D([], [], color="0.15", ls="--"),
               Line2D([], [], marker="X", color="black", ls="none", ms=7),
               Line2D([], [], **{**star, "ms": 11}),
               Line2D([], [], color="0.2", lw=1.0)]
    labels = ["k_max = Fs / stroke",
              "suggested isolator" if sd.get("suggested") else "the spec's design",
              "recommended" if result.feasible else "nearest (not feasible)", "Pareto front"]
    for st in seen:
        col, words = CANDIDATE_LOOK.get(st, ("white", st))
        handles.append(Line2D([], [], marker="o", color=col, mec="0.35", ls="none", ms=6))
        labels.append(words)
    fig.legend(handles, labels, loc="upper center", ncols=4, bbox_to_anchor=(0.5, 1.0),
               fontsize=6.8)
    return fig
