"""Figures, built with matplotlib's object API (``matplotlib.figure.Figure``, never pyplot).

Every function returns a :class:`~matplotlib.figure.Figure` (or draws into a
given ``Axes``); :func:`figure_bytes` renders one to SVG or PNG bytes with
fixed metadata, so the same result gives the same file. Values arrive in SI;
axes show them in engineering units (mm, N/mm, ...) named in the label.
"""

from __future__ import annotations

import io
import math
from typing import Any

import numpy as np

# --------------------------------------------------------------------------- parameter studies
# (fi_design.sweep: hunting maps, the paper's Figure 4, robustness)

#: SI unit -> (unit shown on axes, factor applied to SI values).
DISPLAY_UNITS: dict[str, tuple[str, float]] = {
    "m": ("mm", 1e3),
    "N/m": ("N/mm", 1e-3),
    "m/s": ("mm/s", 1e3),
    "m/s**2": ("m/s²", 1.0),
    "N*s/m": ("N s/m", 1.0),
    "kg/m**3": ("kg/m³", 1.0),
    "1": ("-", 1.0),
}

#: Marks drawn on map cells whose verdict is not a plain count.
VERDICT_MARKS = {"stuck": "s", "undetermined": "?", "failed": "×"}


def display_unit(unit: str) -> tuple[str, float]:
    """Unit shown on an axis for an SI unit, and the factor from SI.

    Parameters
    ----------
    unit : str
        SI unit as stored in the spec (``"m"``, ``"N/m"``, ``"Hz"``, ...).

    Returns
    -------
    label : str
        Unit text for axis labels (``"mm"`` for metres).
    factor : float
        Multiply SI values by this to get the shown unit.
    """
    return DISPLAY_UNITS.get(unit, (unit, 1.0))


def axis_label(path: str, unit: str) -> str:
    """Axis label ``"isolator.stroke [mm]"`` for a dotted path and its SI unit.

    Parameters
    ----------
    path : str
        Dotted spec path.
    unit : str
        SI unit of the values.

    Returns
    -------
    str
    """
    shown, _ = display_unit(unit)
    return f"{path} [{shown}]" if shown else path


def _edges(values: np.ndarray, log: bool) -> np.ndarray:
    """Cell edges around centres (geometric midpoints on a log axis)."""
    v = np.asarray(values, dtype=float)
    if len(v) == 1:
        return np.array([v[0] * 0.9, v[0] * 1.1]) if log else np.array([v[0] - 0.5, v[0] + 0.5])
    if log:
        lv = np.log(v)
        mid = (lv[1:] + lv[:-1]) / 2
        return np.exp(np.concatenate([[2 * lv[0] - mid[0]], mid, [2 * lv[-1] - mid[-1]]]))
    mid = (v[1:] + v[:-1]) / 2
    return np.concatenate([[2 * v[0] - mid[0]], mid, [2 * v[-1] - mid[-1]]])


def draw_sweep(ax: Any, result: Any, *, title: str | None = None, colorbar: bool = True,
               annotate: bool | None = None, vmax: float | None = None) -> Any:
    """Draw a :class:`~fi_design.sweep.SweepResult` into ``ax``.

    A map is a heatmap of hunting cycles (paper Figure 4): invalid points
    hatched grey, stuck points marked ``s``, undetermined ``?``, failed ``×``,
    the design point a red cross. A line is a step plot of the cycles over x.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Where to draw.
    result : fi_design.sweep.SweepResult
        The sweep.
    title : str, optional
        Axes title; default the swept paths and the plant.
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
    from matplotlib.colors import BoundaryNorm
    from matplotlib import colormaps

    x = result.x
    xu, xf = display_unit(x.unit)
    xs = np.asarray(x.values) * xf
    plant = "with isolator" if result.isolated else "without isolator"
    cycles = np.asarray(result.hunting_cycles, dtype=float)
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
        if result.design_point[0] is not None:
            ax.axvline(result.design_point[0] * xf, color="red", lw=1, ls="--",
                       label="design point")
            ax.legend(loc="best", fontsize=8, frameon=False)
        ax.set_xlabel(axis_label(x.path, x.unit))
        ax.set_ylabel("hunting cycles in window [-]")
        if x.log:
            ax.set_xscale("log")
        ax.set_ylim(bottom=0)
        ax.set_title(title or f"{x.path} ({plant})", fontsize=10)
        return artist
    y = result.y
    yu, yf = display_unit(y.unit)
    ys = np.asarray(y.values) * yf
    top = int(np.nanmax(cycles)) if np.any(np.isfinite(cycles)) else 0
    top = max(top, 1) if vmax is None else max(int(math.ceil(vmax)), 1)
    cmap = colormaps["viridis"].resampled(top + 1).with_extremes(bad="0.85")
    norm = BoundaryNorm(np.arange(-0.5, top + 1.5), cmap.N)
    data = np.ma.masked_invalid(cycles)
    mesh = ax.pcolormesh(_edges(xs, x.log), _edges(ys, y.log), data, cmap=cmap, norm=norm,
                         shading="flat")
    invalid = verdict == "invalid"
    if invalid.any():
        ax.pcolor(_edges(xs, x.log), _edges(ys, y.log), np.ma.masked_where(~invalid, invalid),
                  hatch="//", alpha=0.0, edgecolor="0.6", lw=0)
    if annotate is None:
        annotate = len(xs) * len(ys) <= 225
    for j in range(len(ys)):
        for i in range(len(xs)):
            v = verdict[j, i]
            c = cycles[j, i]
            mark = VERDICT_MARKS.get(v)
            if mark is not None:
                ax.text(xs[i], ys[j], mark, ha="center", va="center", fontsize=8,
                        color="white" if v == "failed" else "0.1")
            elif annotate and np.isfinite(c):
                ax.text(xs[i], ys[j], f"{int(c)}", ha="center", va="center", fontsize=6,
                        color="white" if c < 0.6 * top else "black")
    dx, dy = result.design_point
    if dx is not None and dy is not None:
        ax.plot([dx * xf], [dy * yf], marker="X", color="red", ms=10, mec="white", mew=1.0,
                ls="none", label="design point")
    if x.log:
        ax.set_xscale("log")
    if y.log:
        ax.set_yscale("log")
    ax.set_xlabel(axis_label(x.path, x.unit))
    ax.set_ylabel(axis_label(y.path, y.unit))
    ax.set_title(title or f"{y.path} vs {x.path} ({plant})", fontsize=10)
    if colorbar:
        cb = ax.figure.colorbar(mesh, ax=ax, ticks=_ticks(top))
        w0, w1 = _window(result)
        cb.set_label(f"hunting cycles in [{w0:g} s, {w1:g} s) [-]")
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
    result : fi_design.sweep.SweepResult
        The sweep.
    title : str, optional
        Figure title; default the spec name.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.figure import Figure

    fig = Figure(figsize=(6.4, 4.8), layout="constrained")
    ax = fig.add_subplot()
    draw_sweep(ax, result)
    fig.suptitle(title or result.spec.name, fontsize=11)
    fig.text(0.01, 0.005, _legend_text(result), fontsize=7, color="0.35", ha="left",
             va="bottom")
    return fig


def _legend_text(result: Any) -> str:
    marks = ", ".join(f"{m} {v}" for v, m in VERDICT_MARKS.items()
                      if np.any(np.asarray(result.verdict) == v))
    extra = "hatched: invalid spec" if np.any(np.asarray(result.verdict) == "invalid") else ""
    parts = [p for p in (marks, extra) if p]
    return ("red cross: design point" if result.y is not None else "dashed: design point") + \
        ("; " + "; ".join(parts) if parts else "")


def study_figure(study: Any, *, title: str | None = None) -> Any:
    """The paper's Figure 4: maps A to D of a :class:`~fi_design.sweep.StudyResult`.

    Parameters
    ----------
    study : fi_design.sweep.StudyResult
        The study.
    title : str, optional
        Figure title; default the spec name.

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
    fig.suptitle(title or f"{study.spec.name}: hunting maps (paper Figure 4)", fontsize=12)
    return fig


def robustness_figure(result: Any, *, title: str | None = None) -> Any:
    """Probability of hunting with and without the isolator, with confidence intervals.

    Parameters
    ----------
    result : fi_design.sweep.RobustnessResult
        The robustness study.
    title : str, optional
        Figure title; default the spec name.

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
        ax.text(k, 100 * p.high + 2, f"{p.hunting}/{p.valid}", ha="center", fontsize=8)
    ax.set_xticks(range(len(bars)), [b[0] for b in bars])
    ax.set_ylim(0, 110)
    ax.set_ylabel("probability of hunting [%]")
    conf = bars[0][1].confidence if bars else 0.95
    ax.set_title(title or f"{result.spec.name}: {result.samples} samples, "
                          f"{conf:.0%} Wilson interval", fontsize=10)
    return fig


def figure_bytes(fig: Any, fmt: str = "svg") -> bytes:
    """Render a figure to SVG or PNG bytes, reproducibly (no date, fixed SVG ids).

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.
    fmt : {"svg", "png"}
        Output format.

    Returns
    -------
    bytes
    """
    import matplotlib

    fmt = fmt.lower().lstrip(".")
    if fmt not in ("svg", "png"):
        raise ValueError(f"unsupported figure format {fmt!r}; use svg or png")
    buf = io.BytesIO()
    meta = {"Date": None} if fmt == "svg" else {"Software": None}
    with matplotlib.rc_context({"svg.hashsalt": "fi_design", "svg.fonttype": "path"}):
        fig.savefig(buf, format=fmt, dpi=150 if fmt == "png" else None, metadata=meta)
    return buf.getvalue()
