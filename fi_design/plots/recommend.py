"""The design space of a recommendation: stroke x stiffness, each point by what it fails.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .figure import cell_edges, report_figure, styled


#: Colour and legend text of each status of a design-space point.
CANDIDATE_LOOK = {
    "feasible": ("#4daf4a", "passes the sign-off"),
    "robustness": ("#fdb863", "fails under friction scatter"),
    "end_stop": ("#e08214", "rests on its end stop"),
    "checks": ("#e08214", "fails another check"),
    "hunts": ("#d7301f", "some move hunts"),
    "margins": ("#8073ac", "loop margins"),
    "flexure": ("#b2abd2", "flexure cannot be built"),
    "k_max": ("0.55", "k > k_max"),
    "bounds": ("0.75", "outside the bounds"),
    "not_evaluated": ("#e5f5e0", "no move hunts, less margin (not signed off)"),
    "failed": ("black", "simulation failed"),
}


@styled
def recommend_figure(result: Any) -> Any:
    """The design space of a recommendation: stroke x stiffness at the searched crossover.

    Each point of the search is a cell coloured by what it fails first
    (:data:`CANDIDATE_LOOK`); green cells pass. The dashed line is k_max =
    Fs / stroke; the spec's design is a black cross, the recommended (or
    nearest) design a star.

    Parameters
    ----------
    result : fi_design.results.recommend.RecommendResult
        The search.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.patches import Patch, Rectangle

    fig = report_figure(3.6, top=0.62, right=0.15)
    ax = fig.add_subplot()
    s = np.asarray(result.strokes) * 1e3
    k = np.asarray(result.stiffnesses)
    es, ek = cell_edges(s, True), cell_edges(k, True)
    nk = len(k)
    seen = []
    for n, c in enumerate(result.candidates):
        i, j = divmod(n, nk)
        col, _ = CANDIDATE_LOOK.get(c.status, ("white", c.status))
        ax.add_patch(Rectangle((es[i], ek[j]), es[i + 1] - es[i], ek[j + 1] - ek[j],
                               facecolor=col, edgecolor="white", lw=0.8))
        if c.status not in seen:
            seen.append(c.status)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlim(es[0], es[-1])
    ax.set_ylim(ek[0], ek[-1])
    spec = result.spec
    fs = spec.friction.static / spec.requirements.stiffness_safety
    line = np.geomspace(es[0], es[-1], 50)
    ax.plot(line, fs / (line * 1e-3), color="0.15", lw=1.0, ls="--", label="k_max = Fs / stroke")
    sd = result.spec_design
    ax.plot([sd["stroke"] * 1e3], [sd["stiffness"]], "X", color="black", ms=9, mec="white",
            mew=1.0, ls="none", label="suggested isolator" if sd.get("suggested") else
            "the spec's design")
    d = result.design
    ax.plot([d.stroke * 1e3], [d.stiffness], "*", color="gold" if result.feasible else "white",
            ms=15, mec="black", mew=1.0, ls="none",
            label="recommended" if result.feasible else "nearest (not feasible)")
    ax.set_xlabel("stroke [mm]")
    ax.set_ylabel("drive stiffness [N/m]")
    ax.set_title(f"at {d.crossover:.4g} Hz" + (" (the crossover searched)" if result.rule
                                                 else " (the hardware's gains)"),
                 loc="left", fontsize=7.5)
    handles, labels = ax.get_legend_handles_labels()
    for st in seen:
        col, words = CANDIDATE_LOOK.get(st, ("white", st))
        handles.append(Patch(facecolor=col, edgecolor="0.6"))
        labels.append(words)
    fig.legend(handles, labels, loc="upper center", ncols=4, bbox_to_anchor=(0.5, 1.0))
    return fig
