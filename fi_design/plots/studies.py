"""Parameter studies: hunting maps and lines (paper Figure 4), the paper's study, robustness.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..display import number, percent, quantity
from .figure import REPORT_RC, REPORT_WIDTH, cell_edges, nice_ticks, plain_tick
from .labels import axis_label, display_unit, quantity_name


#: Marks drawn on map cells whose verdict is not a plain count.
VERDICT_MARKS = {"stuck": "s", "undetermined": "?", "failed": "×"}

#: Fill of the cells whose drawn guide the stage's weight buckles (not simulated), and its
#: legend entry.
BUCKLED_COLOUR = "#6a3d9a"
BUCKLED_LABEL = "guide buckled by the weight (not simulated)"


#: A stage map's colour scale turns logarithmic when its cycles span more than this [-].
LOG_SPAN = 20.0


def _physical_edges(edges: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Cell edges clipped to the physical range: none below zero when every value is >= 0."""
    out = np.array(edges, dtype=float)
    if np.all(np.asarray(values, dtype=float) >= 0.0):
        out[0] = max(out[0], 0.0)
    return out


def draw_sweep(ax: Any, result: Any, *, title: str | None = None, colorbar: bool = True,
               annotate: bool | None = None, vmax: float | None = None) -> Any:
    """Draw a :class:`~fi_design.studies.SweepResult` into ``ax``.

    A map is a heatmap (paper Figure 4) of the hunting cycles counted on the
    spec's move (``measure "move"``), or of the peak-to-peak amplitude of the
    cycle some move of the family ends in (``measure "stage"``): white where
    there is none, invalid points hatched grey, points whose drawn guide the
    stage's weight buckles filled purple (in the legend), stuck points marked
    ``s``, undetermined ``?``, failed ``×``, the design point a red cross. A
    line is a step plot of the same over x.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Where to draw.
    result : fi_design.studies.SweepResult
        The sweep.
    title : str, optional
        Axes title; default the swept paths and the plant; ``""`` for none.
    colorbar : bool, optional
        Add a colour bar (maps only). Default True.
    annotate : bool, optional
        Write the cycle count into each cell; default for maps of at most 15 x 15.
    vmax : float, optional
        Top of the colour scale [cycles]; default the largest count.

    Returns
    -------
    matplotlib.collections.QuadMesh or list of matplotlib.lines.Line2D
        The drawn artist.
    """
    from matplotlib import colormaps
    from matplotlib.colors import BoundaryNorm, ListedColormap
    from matplotlib.patches import Rectangle

    x = result.x
    xu, xf = display_unit(x.unit, x.values)
    xs = np.asarray(x.values) * xf
    plant = "with isolator" if result.isolated else "without isolator"
    stage = getattr(result, "measure", "move") == "stage"
    # the stage's cycle amplitude in mm, or the cycles the metric counts on the spec's move
    cycles = np.asarray(result.amplitude if stage else result.hunting_cycles, dtype=float)
    if stage:
        cycles = cycles * 1e3
    label = ("Cycle peak to peak, any move [mm]" if stage
             else "Hunting cycles in the window [-]")
    verdict = np.asarray(result.verdict)
    if result.y is None:
        shown = np.where(np.isnan(cycles), np.nan, cycles)
        artist = ax.plot(xs, shown, drawstyle="steps-mid", color="C0", marker="o", ms=3)
        for xi, v, c in zip(xs, verdict, shown):
            if v in VERDICT_MARKS:
                ax.annotate(VERDICT_MARKS[v], (xi, 0 if np.isnan(c) else c), ha="center",
                            va="bottom", fontsize=8, color="0.3")
            elif v == "invalid":
                ax.axvspan(xi - 0.5 * _step(xs), xi + 0.5 * _step(xs), color="0.85", lw=0)
        buckled = False
        for xi, v in zip(xs, verdict):
            if v == "buckled":
                ax.axvspan(xi - 0.5 * _step(xs), xi + 0.5 * _step(xs), color=BUCKLED_COLOUR,
                           alpha=0.35, lw=0, label=None if buckled else BUCKLED_LABEL)
                buckled = True
        if result.design_point[0] is not None:
            ax.axvline(result.design_point[0] * xf, color="red", lw=1, ls="--",
                       label="design point")
        if buckled or result.design_point[0] is not None:
            ax.legend(loc="best", fontsize=8, frameon=False)
        ax.set_xlabel(axis_label(x.path, x.unit, x.values))
        ax.set_ylabel(label)
        if x.log:
            ax.set_xscale("log")
        else:
            ex = _physical_edges(cell_edges(xs, False), xs)
            ax.set_xlim(ex[0], ex[-1])
        ax.set_ylim(bottom=0)
        ax.set_title(f"{quantity_name(x.path)} ({plant})" if title is None else title,
                     fontsize=10)
        return artist
    y = result.y
    yu, yf = display_unit(y.unit, y.values)
    ys = np.asarray(y.values) * yf
    log_scale = False
    if stage:
        from matplotlib.colors import LogNorm, Normalize

        top_mm = float(np.nanmax(cycles)) if np.any(np.isfinite(cycles)) else 0.0
        top_mm = max(top_mm, 1e-3) if vmax is None else max(float(vmax), 1e-3)
        cmap = colormaps["YlOrRd"].with_extremes(under="white", bad="0.8")
        small = cycles[np.isfinite(cycles) & (cycles > 0)]
        low = float(np.min(small)) if len(small) else top_mm
        # cycles spanning more than a decade (76 mm at 1 Hz beside 0.2 mm near the
        # fold) on a log scale, so that the small ones do not look like no cycle at all
        log_scale = top_mm > LOG_SPAN * low
        if log_scale:
            low = max(low, top_mm / 1e3)
            norm = LogNorm(vmin=low, vmax=top_mm)
            data = np.ma.masked_invalid(np.where(cycles > 0, np.maximum(cycles, low), 0.1 * low))
        else:
            norm = Normalize(vmin=0.0, vmax=top_mm)
            data = np.ma.masked_invalid(np.where(cycles > 0, cycles, -1.0))
        top = top_mm
    else:
        top = int(np.nanmax(cycles)) if np.any(np.isfinite(cycles)) else 0
        top = max(top, 1) if vmax is None else max(int(math.ceil(vmax)), 1)
        cmap = ListedColormap(["white"] + list(colormaps["YlOrRd"](np.linspace(0.15, 1.0, top)))
                              ).with_extremes(bad="0.8")
        norm = BoundaryNorm(np.arange(-0.5, top + 1.5), cmap.N)
        data = np.ma.masked_invalid(cycles)
    # half a cell beyond the first value would reach below zero (a negative stroke or
    # crossover): the cells end at the physical range
    ex, ey = _physical_edges(cell_edges(xs, x.log), xs), _physical_edges(cell_edges(ys, y.log), ys)
    mesh = ax.pcolormesh(ex, ey, data, cmap=cmap, norm=norm, shading="flat")
    for j, i in zip(*np.nonzero(verdict == "invalid")):
        ax.add_patch(Rectangle((ex[i], ey[j]), ex[i + 1] - ex[i], ey[j + 1] - ey[j], fill=False,
                               hatch="//", edgecolor="0.55", lw=0))
    buckled = np.nonzero(verdict == "buckled")
    for j, i in zip(*buckled):
        ax.add_patch(Rectangle((ex[i], ey[j]), ex[i + 1] - ex[i], ey[j + 1] - ey[j],
                               facecolor=BUCKLED_COLOUR, alpha=0.6, lw=0))
    if annotate is None:
        annotate = len(xs) * len(ys) <= 225
    for j in range(len(ys)):
        for i in range(len(xs)):
            v = verdict[j, i]
            c = cycles[j, i]
            mark = VERDICT_MARKS.get(v)
            if mark is not None:
                ax.text(xs[i], ys[j], mark, ha="center", va="center", fontsize=8,
                        color="0.1")
            elif annotate and np.isfinite(c) and c > 0:
                dark = norm(c) > 0.6 if log_scale else c >= 0.6 * top
                ax.text(xs[i], ys[j], number(c, 2) if stage else f"{int(c)}", ha="center",
                        va="center", fontsize=6, color="white" if dark else "black")
    dx, dy = result.design_point
    if dx is not None and dy is not None:
        ax.plot([dx * xf], [dy * yf], marker="X", color="red", ms=10, mec="white", mew=1.0,
                ls="none", label="design point")
    if len(buckled[0]):
        from matplotlib.patches import Patch

        handles = [Patch(facecolor=BUCKLED_COLOUR, alpha=0.6, label=BUCKLED_LABEL)]
        if dx is not None and dy is not None:
            handles += ax.get_legend_handles_labels()[0]
        ax.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.14),
                  fontsize=7, frameon=False, ncol=len(handles))
    if x.log:
        ax.set_xscale("log")
    if y.log:
        ax.set_yscale("log")
    ax.set_xlim(ex[0], ex[-1])
    ax.set_ylim(ey[0], ey[-1])
    ax.set_xlabel(axis_label(x.path, x.unit, x.values))
    ax.set_ylabel(axis_label(y.path, y.unit, y.values))
    ax.set_title(f"{quantity_name(y.path)} vs {quantity_name(x.path).lower()} ({plant})"
                 if title is None else title, fontsize=10)
    if colorbar:
        if stage:
            cb = ax.figure.colorbar(mesh, ax=ax, extend="min")
            cb.set_label("Cycle peak to peak [mm]" + (", log scale" if log_scale else ""))
        else:
            cb = ax.figure.colorbar(mesh, ax=ax, ticks=_ticks(top))
            w0, w1 = _window(result)
            cb.set_label(f"Hunting cycles in [{quantity(w0, 's', 6)}, {quantity(w1, 's', 6)}) [-]")
    return mesh


def _step(xs: np.ndarray) -> float:
    return float(np.min(np.diff(xs))) if len(xs) > 1 else 1.0


def _ticks(top: int) -> list[int]:
    step = max(1, int(math.ceil((top + 1) / 10)))
    return list(range(0, top + 1, step))


def _window(result: Any) -> tuple[float, float]:
    h = result.spec.requirements.hunting
    return h.window_start, h.window_start + h.window_length


def sweep_figure(result: Any, *, title: str | None = None) -> Any:
    """A figure of one sweep: heatmap of hunting cycles (map) or cycles over x (line).

    Parameters
    ----------
    result : fi_design.studies.SweepResult
        The sweep.
    title : str, optional
        Figure title; default from the spec name; ``""`` for none.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.figure import Figure

    fig = Figure(figsize=(6.4, 4.8), layout="constrained")
    ax = fig.add_subplot()
    draw_sweep(ax, result)
    if title != "":
        fig.suptitle(result.spec.name if title is None else title, fontsize=11)
    fig.supxlabel(_legend_text(result), fontsize=7, color="0.35")
    return fig


def design_map_figure(result: Any) -> Any:
    """The hunting map around a design point, sized for the design report.

    Parameters
    ----------
    result : fi_design.studies.SweepResult
        The crossover x stroke map (:class:`~fi_design.studies.DesignMap`'s ``sweep``).

    Returns
    -------
    matplotlib.figure.Figure
        Log axes labelled with plain 1-2-5 numbers, not mathtext powers.
    """
    import matplotlib
    from matplotlib.figure import Figure
    from matplotlib.ticker import FuncFormatter, NullFormatter

    with matplotlib.rc_context(REPORT_RC):
        fig = Figure(figsize=(REPORT_WIDTH, 3.8), layout="constrained")
        ax = fig.add_subplot()
        draw_sweep(ax, result, title="")
        for axis, swept in ((ax.xaxis, result.x), (ax.yaxis, result.y)):
            if swept is not None and swept.log:
                _, factor = display_unit(swept.unit, swept.values)
                axis.set_major_formatter(FuncFormatter(plain_tick))
                axis.set_minor_formatter(NullFormatter())
                lo, hi = min(swept.values) * factor, max(swept.values) * factor
                axis.set_ticks(nice_ticks(lo, hi))
    return fig


def _legend_text(result: Any, verdicts: Any = None) -> str:
    """The figure's key: what white, the marks and the hatching mean (``verdicts``: of every
    map of a study; default the result's own)."""
    verdicts = np.asarray(result.verdict if verdicts is None else verdicts)
    marks = ", ".join(f"{m} {v}" for v, m in VERDICT_MARKS.items() if np.any(verdicts == v))
    extra = "hatched: invalid spec" if np.any(verdicts == "invalid") else ""
    white = ("white: every move settles (colour: the largest cycle any move ends in)"
             if getattr(result, "measure", "move") == "stage" and result.y is not None else "")
    buckled = "purple: the guide buckles (not simulated)" if np.any(verdicts == "buckled") \
        else ""
    parts = [p for p in (white, marks, extra, buckled) if p]
    return ("red cross: design point" if result.y is not None else "dashed: design point") + \
        ("; " + "; ".join(parts) if parts else "")


def study_figure(study: Any, *, title: str | None = None) -> Any:
    """The paper's Figure 4: maps A to D of a :class:`~fi_design.studies.StudyResult`.

    Parameters
    ----------
    study : fi_design.studies.StudyResult
        The study.
    title : str, optional
        Figure title; default from the spec name; ``""`` for none.

    Returns
    -------
    matplotlib.figure.Figure
        One panel per map, two columns.
    """
    from matplotlib.figure import Figure

    n = len(study.maps)
    cols = 2 if n > 1 else 1
    rows = int(math.ceil(n / cols))
    fig = Figure(figsize=(6.0 * cols, 4.6 * rows), layout="constrained")
    axes = fig.subplots(rows, cols, squeeze=False)
    for k, m in enumerate(study.maps):
        ax = axes[k // cols][k % cols]
        d = m.definition
        draw_sweep(ax, m.result, title=f"{d.key}) {d.title}")
    for k in range(n, rows * cols):
        axes[k // cols][k % cols].set_visible(False)
    if title != "":
        fig.suptitle(f"{study.spec.name}: hunting maps (paper Figure 4)" if title is None
                     else title, fontsize=12)
    if n:
        every = np.concatenate([np.ravel(m.result.verdict) for m in study.maps])
        fig.supxlabel(_legend_text(study.maps[0].result, every), fontsize=8, color="0.35")
    return fig


def robustness_figure(result: Any, *, title: str | None = None) -> Any:
    """Probability of hunting with and without the isolator, with confidence intervals.

    Parameters
    ----------
    result : fi_design.studies.RobustnessResult
        The robustness study.
    title : str, optional
        Figure title; default from the spec name; ``""`` for none.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.figure import Figure

    fig = Figure(figsize=(5.0, 3.6), layout="constrained")
    ax = fig.add_subplot()
    bars = [(label, p) for label, p in (("with isolator", result.isolated),
                                        ("without isolator", result.not_isolated))
            if p is not None]
    for k, (label, p) in enumerate(bars):
        prob = p.probability if p.probability is not None else float("nan")
        ax.bar(k, 100 * prob, color="C0" if p.isolated else "C3", width=0.6)
        ax.errorbar(k, 100 * prob, yerr=[[100 * max(prob - p.low, 0)],
                                         [100 * max(p.high - prob, 0)]],
                    color="black", capsize=6, lw=1)
        # the count's box (its descent too) 4 pt above the interval's cap, whatever the scale
        ax.annotate(f"{p.hunting}/{p.valid}", (k, 100 * p.high), xytext=(0, 4),
                    textcoords="offset points", ha="center", va="bottom", fontsize=8)
    ax.set_xticks(range(len(bars)), [b[0] for b in bars])
    ax.set_ylim(0, 110)
    ax.set_ylabel("probability of hunting [%]")
    conf = bars[0][1].confidence if bars else 0.95
    if title != "":
        ax.set_title(f"{result.spec.name}: {result.samples} samples, {percent(conf, 2)} Wilson "
                     "interval" if title is None else title, fontsize=10)
    return fig
