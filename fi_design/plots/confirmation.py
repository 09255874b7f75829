"""The nonlinear confirmation of the spec's own motion: position error and joint deflection.

Read from a design's confirmation (its ``results``: the two simulated
plants' traces and hunting metrics).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .figure import decimate, report_figure, styled
from ..display import quantity


def _micro(x: float) -> str:
    """A band [m] as the zoomed axis reads it, in µm."""
    return quantity(x, "m", 6, shown=("\u00b5m", 1e6))


#: Colour of each simulated plant.
PLANT_COLOURS = {"isolated": "C0", "non_isolated": "C3"}


def plant_names(confirmation: Any) -> dict:
    """Legend name of each plant: ``"with isolator"`` (or the suggested one), ``"without isolator"``."""
    label = "rule's isolator" if confirmation.suggested_isolator else "with isolator"
    return {"isolated": label, "non_isolated": "without isolator"}


def motion_end(time: np.ndarray, reference: np.ndarray) -> float:
    """When the reference comes to rest for good: the last change of r [s].

    Parameters
    ----------
    time, reference : numpy.ndarray, shape (n,)
        Sample times [s] and reference r [m].

    Returns
    -------
    float
        The first sample time from which r keeps its final value; ``time[0]``
        for a constant reference.
    """
    r = np.asarray(reference, dtype=float)
    moving = np.nonzero(r != r[-1])[0]
    return float(time[0]) if not len(moving) else float(time[min(moving[-1] + 1, len(r) - 1)])


#: Half-height of the settling panels of :func:`error_figure`, in settle bands.
SETTLE_ZOOM = 5.0


def _plant_title(v: Any, label: str) -> str:
    m = v.metrics
    cycles = f"{m.hunting_cycles} cycle{'s' if m.hunting_cycles != 1 else ''}"
    return f"{label}: {m.verdict} ({cycles} counted)"


@styled
def error_figure(confirmation: Any, spec: Any) -> Any:
    """Position error x1 - r over time with and without the isolator (paper Figure 5).

    One row per plant. Left: the whole error in mm, as the paper's Figure 5;
    the counting window of the hunting metric is shaded, its minimum peak
    height dashed, the counted peaks circled. Right: the same error after the
    motion in µm, zoomed to ``SETTLE_ZOOM`` settle bands either side, where a
    settling of micrometres shows: the settle band shaded, the settling time
    dotted. Both plants share each column's scale.

    Parameters
    ----------
    confirmation : fi_design.stage.confirm.Confirmation
        The simulated confirmation (its ``results`` hold the traces).
    spec : fi_design.spec.Spec
        The design spec (hunting-metric settings).

    Returns
    -------
    matplotlib.figure.Figure
    """
    h = spec.requirements.hunting
    fig = report_figure(4.3, top=0.3, hspace=0.55, right=0.1)
    fig.subplots_adjust(wspace=0.32)
    axes = fig.subplots(2, 2, sharex="col", sharey="col", width_ratios=(1.55, 1.0))
    label = "rule's isolator" if confirmation.suggested_isolator else "with isolator"
    band = h.settle_band * 1e6
    zoom = SETTLE_ZOOM * band
    end = float(confirmation.results["isolated"].time[-1])
    for (ax, axz), key, name in zip(axes, ("isolated", "non_isolated"),
                                    (label, "without isolator")):
        res = confirmation.results[key]
        verdict = getattr(confirmation, key)
        m = res.metrics
        ax.axvspan(m.window[0], m.window[1], color="0.93", lw=0, zorder=0)
        ax.axhline(0.0, color="0.6", lw=0.6, zorder=1)
        ax.axhline(h.min_height * 1e3, color="0.35", lw=0.8, ls="--", zorder=1)
        t, e = decimate(res.time, res.error * 1e3)
        ax.plot(t, e, color=PLANT_COLOURS[key], lw=1.0, zorder=2)
        if len(m.peak_times):
            ax.plot(m.peak_times, np.asarray(m.peak_heights) * 1e3, "o", mfc="none",
                    mec="navy", ms=6, mew=1.1, label="counted peak")
        ax.set_title(_plant_title(verdict, name), loc="left")
        ax.set_ylabel("x1 - r [mm]")
        ax.text(m.window[0], 0.03, " counting window", transform=ax.get_xaxis_transform(),
                va="bottom", ha="left", fontsize=7, color="0.35")
        ax.text(0.03, h.min_height * 1e3, f"min. peak height {quantity(h.min_height, 'm', 6, shown=('mm', 1e3))}",
                transform=ax.get_yaxis_transform(), va="bottom", ha="left", fontsize=7,
                color="0.35", bbox={"facecolor": "white", "alpha": 0.8, "lw": 0, "pad": 0.5})
        # the settling, in micrometres, after the motion
        t0 = motion_end(res.time, res.reference)
        after = res.time >= t0
        axz.axhspan(-band, band, color="#dcefe0", lw=0, zorder=0)
        axz.axhline(0.0, color="0.6", lw=0.6, zorder=1)
        tz, ez = decimate(res.time[after], res.error[after] * 1e6)
        axz.plot(tz, np.clip(ez, -1.5 * zoom, 1.5 * zoom), color=PLANT_COLOURS[key], lw=1.0,
                 zorder=2)
        if m.settling_time is not None:
            ts = t0 + m.settling_time
            axz.axvline(ts, color="0.25", lw=0.9, ls=":", zorder=3)
            note = (f"in the band from t = {quantity(ts, 's', 3)}\n"
                    f"({quantity(m.settling_time, 's', 3)} after the motion)")
        else:
            note = "never stays in the band"
        axz.text(0.98, 0.04, note, transform=axz.transAxes, ha="right", va="bottom",
                 fontsize=7, color="0.25",
                 bbox={"facecolor": "white", "alpha": 0.85, "lw": 0, "pad": 0.6})
        axz.set_title(f"after the motion: \u00b1{_micro(h.settle_band)} settle band", loc="left",
                      fontsize=7.5)
        axz.set_ylabel("x1 - r [\u00b5m]")
    for ax in axes[-1]:
        ax.set_xlabel("time [s]")
    axes[-1][0].set_xlim(0, end)
    t0 = min(motion_end(r.time, r.reference) for r in confirmation.results.values())
    axes[-1][1].set_xlim(t0, end)
    axes[-1][1].set_ylim(-zoom, zoom)
    return fig


@styled
def deflection_figure(confirmation: Any, spec: Any) -> Any:
    """Joint deflection x1 - x2 of the isolated plant over time, against the stroke.

    Parameters
    ----------
    confirmation : fi_design.stage.confirm.Confirmation
        The simulated confirmation.
    spec : fi_design.spec.Spec
        The design spec (the stroke; a spec without isolator uses the
        suggested one of the confirmation).

    Returns
    -------
    matplotlib.figure.Figure
    """
    res = confirmation.results["isolated"]
    stroke = confirmation.landing.stroke if confirmation.landing is not None else \
        spec.isolator.stroke
    fig = report_figure(2.5, top=0.35)
    ax = fig.add_subplot()
    t, d = decimate(res.time, res.deflection * 1e6)
    ax.plot(t, d, color=PLANT_COLOURS["isolated"], lw=1.0, label="deflection x1 - x2")
    for sign in (1, -1):
        ax.axhline(sign * stroke * 1e6, color="C3", lw=0.9, ls="--",
                   label="stroke (limiter engages)" if sign > 0 else None)
    if confirmation.landing is not None:
        land = confirmation.landing
        # at the last instant, on the frame: drawn whole over it, not clipped in half
        ax.plot([res.time[-1]], [land.deflection * 1e6], "o", color="black", ms=4,
                clip_on=False, zorder=3,
                label=f"at rest: {quantity(land.deflection, 'm', 3, shown=('µm', 1e6))}")
    ax.set_ylim(-1.35 * stroke * 1e6, 1.35 * stroke * 1e6)
    ax.set_xlim(0, float(res.time[-1]))
    ax.set_xlabel("time [s]")
    ax.set_ylabel("x1 - x2 [µm]")
    fig.legend(*ax.get_legend_handles_labels(), loc="upper center", ncols=3,
               bbox_to_anchor=(0.5, 1.0))
    return fig
