"""Hunting as a property of the stage: the move family, the cycles, the boundary in crossover.

Read from a design's confirmation (its ``stage``: every move's outcome, the
converged cycle, the branch and fold on the crossover axis).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .confirmation import PLANT_COLOURS, SETTLE_ZOOM, motion_end, plant_names
from .figure import decimate, log_x, report_figure, styled
from ..display import quantity


#: Markers of the move outcomes: (marker, filled).
MOVE_MARKS = {"hunts": ("o", True), "settles": ("o", False), "rests": ("s", False),
              "stuck": ("s", True), "undetermined": ("D", False)}


@styled
def moves_figure(confirmation: Any) -> Any:
    """How each plant ends after every move of its family (stage-level hunting).

    x: the move distance (log); y: the peak-to-peak amplitude of the cycle a
    move ends in, 0 for a move that comes to rest. Filled circles hunt, open
    circles settle, squares rest off target (open: within a loop's static
    error; filled: stuck), diamonds could not be judged; a star marks the
    spec's own motion. Negative moves are drawn at their distance with a
    lighter colour.

    Parameters
    ----------
    confirmation : fi_design.results.design.Confirmation
        The simulated confirmation (its ``stage``).

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig = report_figure(2.7, top=0.35)
    ax = fig.add_subplot()
    names = plant_names(confirmation)
    top = 0.0
    for key in ("isolated", "non_isolated"):
        st = confirmation.stage[key]
        col = PLANT_COLOURS[key]
        ax.plot([], [], "o", color=col, label=names[key])
        for m in st.moves:
            d = abs(m.distance) * 1e3
            if d <= 0:
                continue
            amp = (m.amplitude or 0.0) * 1e3 if m.hunts else 0.0
            top = max(top, amp)
            mk, filled = MOVE_MARKS.get(m.outcome, ("x", True))
            if m.label == "spec":
                mk, filled = "*", m.hunts
            alpha = 1.0 if m.distance > 0 else 0.45
            ax.plot([d], [amp], mk, ms=7 if m.label == "spec" else 4.5, color=col,
                    mfc=col if filled else "white", mew=1.0, alpha=alpha, ls="none")
    log_x(ax)
    ax.set_xlabel("move distance [mm]")
    ax.set_ylabel("cycle peak to peak [mm]")
    ax.set_ylim(-0.08 * max(top, 0.1), 1.15 * max(top, 0.1))
    from matplotlib.lines import Line2D

    handles, labels = ax.get_legend_handles_labels()
    for word, (mk, filled) in (("hunts", MOVE_MARKS["hunts"]), ("settles", MOVE_MARKS["settles"]),
                               ("rests off target", MOVE_MARKS["rests"]),
                               ("spec's motion", ("*", False))):
        handles.append(Line2D([], [], marker=mk, ls="none", ms=5, color="0.25",
                              mfc="0.25" if filled else "white", mew=0.9))
        labels.append(word)
    fig.legend(handles, labels, loc="upper center", ncols=len(labels), bbox_to_anchor=(0.5, 1.0))
    return fig


@styled
def cycle_figure(confirmation: Any, spec: Any) -> Any:
    """The hunting cycles themselves, beside the settling of the spec's own motion.

    Left: phase portrait of each plant's converged cycle, x1 - r [mm] against
    the stage velocity v1 [mm/s]. Middle: the joint deflection x1 - x2 over
    one period of the isolated stage's cycle, with its stroke (the limiter
    beyond). Right: x1 - r of the plant as specified after the spec's own
    motion [µm], with the settle band: the move the spec names may settle
    while others hunt.

    Parameters
    ----------
    confirmation : fi_design.results.design.Confirmation
        The simulated confirmation (``stage`` and ``results``).
    spec : fi_design.spec.Spec
        The design spec (settle band).

    Returns
    -------
    matplotlib.figure.Figure
    """
    h = spec.requirements.hunting
    names = plant_names(confirmation)
    fig = report_figure(2.8, top=0.5, right=0.1)
    fig.subplots_adjust(wspace=0.42)
    ax_p, ax_d, ax_s = fig.subplots(1, 3, width_ratios=(1.15, 1.0, 1.0))
    for key in ("isolated", "non_isolated"):
        c = confirmation.stage[key].cycle
        if c is None or c.trace is None:
            continue
        tr = c.trace
        ax_p.plot(np.asarray(tr.error) * 1e3, np.asarray(tr.velocity) * 1e3,
                  color=PLANT_COLOURS[key], lw=1.1,
                  label=f"{names[key]}: cycle of {quantity(c.amplitude, 'm', 3)}, {quantity(c.period, 's', 3)}")
    ax_p.axvline(0.0, color="0.6", lw=0.6)
    ax_p.set_xlabel("x1 - r [mm]")
    ax_p.set_ylabel("v1 [mm/s]")
    ax_p.set_title("phase portrait", loc="left", fontsize=7.5)
    if ax_p.get_legend_handles_labels()[0]:
        fig.legend(*ax_p.get_legend_handles_labels(), loc="upper center", ncols=2,
                   bbox_to_anchor=(0.5, 1.0))
    c = confirmation.stage["isolated"].cycle
    stroke = confirmation.landing.stroke if confirmation.landing is not None else None
    if c is not None and c.trace is not None and c.trace.deflection is not None:
        ax_d.plot(c.trace.time, np.asarray(c.trace.deflection) * 1e6,
                  color=PLANT_COLOURS["isolated"], lw=1.1)
        ax_d.set_xlim(0, float(c.trace.time[-1]))
    else:
        ax_d.text(0.5, 0.5, "no cycle with the isolator", transform=ax_d.transAxes,
                  ha="center", va="center", fontsize=7.5, color="0.35")
    if stroke is not None:
        for sign in (1, -1):
            ax_d.axhline(sign * stroke * 1e6, color="0.3", lw=0.8, ls="--")
        ax_d.set_ylim(-1.4 * stroke * 1e6, 1.4 * stroke * 1e6)
    ax_d.set_xlabel("time in the period [s]")
    ax_d.set_ylabel("x1 - x2 [µm]")
    ax_d.set_title("joint deflection, isolated cycle", loc="left", fontsize=7.5)
    band = h.settle_band * 1e6
    zoom = SETTLE_ZOOM * band
    ax_s.axhspan(-band, band, color="#dcefe0", lw=0, zorder=0)
    own = "non_isolated" if confirmation.suggested_isolator else "isolated"
    res = confirmation.results[own]
    t0 = motion_end(res.time, res.reference)
    after = res.time >= t0
    tz, ez = decimate(res.time[after], res.error[after] * 1e6)
    ax_s.plot(tz, np.clip(ez, -1.5 * zoom, 1.5 * zoom), color=PLANT_COLOURS[own], lw=1.0)
    ax_s.set_ylim(-zoom, zoom)
    ax_s.set_xlim(t0, float(res.time[-1]))
    ax_s.set_xlabel("time [s]")
    ax_s.set_ylabel("x1 - r [µm]")
    ax_s.set_title(f"spec's motion, ±{quantity(h.settle_band, 'm', 6, shown=('µm', 1e6))} band", loc="left", fontsize=7.5)
    return fig


@styled
def boundary_figure(confirmation: Any) -> Any:
    """The stage-level boundary on the crossover axis.

    For each plant, the peak-to-peak amplitude of its hunting cycle as the
    crossover rises (the points the bisection found the cycle at), ending at
    the cycle's fold: from there on no move of the family hunts (dotted). The
    design crossover is dashed.

    Parameters
    ----------
    confirmation : fi_design.results.design.Confirmation
        The simulated confirmation (``stage``: the crossover its plants were
        judged at, their branches and folds).

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig = report_figure(2.6, top=0.35)
    ax = fig.add_subplot()
    names = plant_names(confirmation)
    fc = confirmation.stage["isolated"].crossover
    folds = [st.hunting_free_from for st in confirmation.stage.values()
             if st.hunting_free_from is not None]
    x_top = 1.08 * max(folds + [fc])
    top_mm = 0.0
    for n, key in enumerate(("isolated", "non_isolated")):
        st = confirmation.stage[key]
        col = PLANT_COLOURS[key]
        b = st.boundary
        pts = [p for p in (b.branch if b is not None else ()) if p[1] is not None]
        if pts:
            f, a = np.array([p[0] for p in pts]), np.array([p[1] for p in pts]) * 1e3
            ax.plot(f, a, "o-", color=col, ms=3, lw=1.1, label=f"{names[key]}: cycle")
            top_mm = max(top_mm, float(np.max(a)))
        m = st.hunting_free_from
        if m is not None and b is not None and b.kind == "fold":
            ax.axvline(m, color=col, lw=0.9, ls=":")
            # in the headroom above the curves, on the side of the line with more room
            left = m < 0.6 * x_top
            ax.text(m, 0.96 - 0.1 * n, f" no move hunts from {quantity(m, 'Hz', 4)} ", color=col,
                    fontsize=7, transform=ax.get_xaxis_transform(), va="top",
                    ha="left" if left else "right")
    ax.axvline(fc, color="0.3", lw=0.9, ls="--")
    ax.text(fc, 0.04, f" design {quantity(fc, 'Hz', 4)}", color="0.3", fontsize=7,
            transform=ax.get_xaxis_transform(), va="bottom", ha="left")
    ax.set_xlim(0.0, x_top)
    ax.set_ylim(0.0, 1.35 * top_mm if top_mm > 0 else None)
    ax.set_xlabel("crossover fc [Hz]")
    ax.set_ylabel("cycle peak to peak [mm]")
    fig.legend(*ax.get_legend_handles_labels(), loc="upper center", ncols=2,
               bbox_to_anchor=(0.5, 1.0))
    return fig


@styled
def positioning_figure(positioning: Any) -> Any:
    """Settle time and static error against move distance (``requirements.positioning``).

    Left: the time after each move until |x1 - r| stays within the band, a
    dashed line at the required settle time; a move that never settles is
    drawn as a cross at the top. Right: the error each move rests at, a
    dashed line at the allowed static error and a dotted one at the band.
    Negative moves lighter; a star marks the spec's own motion.

    Parameters
    ----------
    positioning : fi_design.results.positioning.PositioningResult
        The requirement judged over the move family.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig = report_figure(2.6, top=0.2)
    ax_t, ax_e = fig.subplots(1, 2)
    col = PLANT_COLOURS[positioning.plant]
    times = [m.settle_time for m in positioning.moves if m.settle_time is not None]
    t_top = max(times + [positioning.settle_time_limit or 0.0, 1e-3]) * 1.15
    errors = [m.static_error for m in positioning.moves if m.static_error is not None]
    e_top = max(errors + [positioning.static_error_limit or 0.0, positioning.band]) * 1e6 * 1.15
    for m in positioning.moves:
        d = abs(m.distance) * 1e3
        if d <= 0:
            continue
        alpha = 1.0 if m.distance > 0 else 0.45
        mk = "*" if m.label == "spec" else "o"
        face = col if m.passed else "white"
        ms = 7 if m.label == "spec" else 4.5
        if m.settle_time is None:
            ax_t.plot([d], [t_top], "x", ms=5, color="0.2", alpha=alpha)
        else:
            ax_t.plot([d], [m.settle_time], mk, ms=ms, color=col, mfc=face, alpha=alpha)
        if m.static_error is not None:
            ax_e.plot([d], [m.static_error * 1e6], mk, ms=ms, color=col, mfc=face, alpha=alpha)
    if positioning.settle_time_limit is not None:
        ax_t.axhline(positioning.settle_time_limit, color="0.3", ls="--", lw=0.9)
    if positioning.static_error_limit is not None:
        ax_e.axhline(positioning.static_error_limit * 1e6, color="0.3", ls="--", lw=0.9)
    ax_e.axhline(positioning.band * 1e6, color="0.5", ls=":", lw=0.9)
    for ax in (ax_t, ax_e):
        log_x(ax)
        ax.set_xlabel("move distance [mm]")
    ax_t.set_ylim(0.0, t_top * 1.05)
    ax_e.set_ylim(0.0, e_top * 1.05)
    ax_t.set_ylabel("settle time [s]")
    ax_e.set_ylabel("rest error |x1 \u2212 r| [\u00b5m]")
    return fig
