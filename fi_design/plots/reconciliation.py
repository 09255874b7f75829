"""Reconciliation: the measured trace against the nominal and the corrected model.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .figure import decimate, report_figure, styled


#: Colours of the reconciliation overlays.
GAP_COLOURS = {"measured": "0.45", "nominal": "C3", "corrected": "C0"}


#: Line widths [pt] and drawing order of the overlays: the measurement wide underneath.
GAP_WIDTHS = {"measured": 3.2, "nominal": 1.0, "corrected": 0.9}


GAP_ORDER = {"measured": 1, "nominal": 2, "corrected": 3}


def _gap_label(result: Any) -> str:
    return ("corrected: + " + ", ".join(result.effects)) if result.effects else \
        "corrected (no effect added)"


@styled
def gap_overlay_figure(result: Any) -> Any:
    """Measured trace with the nominal and the corrected model on top.

    Panels: position error x1 - r [µm]; commanded force [N] when measured;
    joint deflection [µm] when measured. The measurement is drawn wide and
    light underneath, the models thin on top, so that it shows where the
    corrected model follows it. Segments compared by features (stick-slip
    holds) are shaded.

    Parameters
    ----------
    result : fi_design.results.reconciliation.ReconcileResult
        The reconciliation.

    Returns
    -------
    matplotlib.figure.Figure
    """
    meas = result.measurement
    t = result.nominal.time
    r = np.asarray(meas.reference)
    panels = [("position", "x1 - r [µm]", 1e6, True)]
    if meas.force is not None:
        panels.append(("force", "force u [N]", 1.0, False))
    if meas.deflection is not None and result.nominal.deflection is not None:
        panels.append(("deflection", "deflection x1 - x2 [µm]", 1e6, False))
    fig = report_figure(1.9 * len(panels) + 0.7, top=0.3, hspace=0.3)
    axes = np.atleast_1d(fig.subplots(len(panels), 1, sharex=True))
    for ax, (key, label, scale, minus_ref) in zip(axes, panels):
        for seg in result.segments:
            if not seg.coherent:
                ax.axvspan(seg.start, seg.end, color="0.94", lw=0, zorder=0)
        for name, src in (("measured", meas), ("nominal", result.nominal),
                          ("corrected", result.corrected)):
            if name == "corrected" and not result.effects:
                continue
            y = np.asarray(getattr(src, key), dtype=float)
            if minus_ref:
                y = y - r
            tt, yy = decimate(t, y * scale)
            # the measured trace wide and light underneath, the models thin on top: where the
            # corrected model follows the measurement, the measurement still shows around it
            ax.plot(tt, yy, color=GAP_COLOURS[name], lw=GAP_WIDTHS[name],
                    ls="-" if name != "nominal" else "--", zorder=GAP_ORDER[name],
                    alpha=0.55 if name == "measured" else 1.0, solid_capstyle="butt",
                    label={"measured": "measured", "nominal": "nominal model",
                           "corrected": _gap_label(result)}[name])
        ax.set_ylabel(label)
    axes[0].legend(loc="lower left", bbox_to_anchor=(0.0, 1.0), ncol=3, borderaxespad=0.1)
    axes[-1].set_xlabel("time from the first sample [s]")
    axes[-1].set_xlim(float(t[0]), float(t[-1]))
    return fig


@styled
def gap_residual_figure(result: Any) -> Any:
    """Measured minus modelled position, nominal and corrected, against the noise band.

    Parameters
    ----------
    result : fi_design.results.reconciliation.ReconcileResult
        The reconciliation.

    Returns
    -------
    matplotlib.figure.Figure
    """
    meas = result.measurement
    t = result.nominal.time
    x = np.asarray(meas.position)
    sigma = result.noise.position * 1e6
    fig = report_figure(2.6, top=0.3)
    ax = fig.subplots()
    ax.axhspan(-2 * sigma, 2 * sigma, color="0.9", lw=0, zorder=0)
    for name, src in (("nominal", result.nominal), ("corrected", result.corrected)):
        if name == "corrected" and not result.effects:
            continue
        tt, yy = decimate(t, (x - np.asarray(src.position)) * 1e6)
        ax.plot(tt, yy, color=GAP_COLOURS[name], lw=0.9,
                label="nominal model" if name == "nominal" else _gap_label(result))
    ax.set_ylabel("measured - model [µm]")
    ax.set_xlabel("time from the first sample [s]")
    ax.set_xlim(float(t[0]), float(t[-1]))
    ax.text(0.01, 2 * sigma, " ±2 noise std", transform=ax.get_yaxis_transform(), va="bottom",
            fontsize=7, color="0.35")
    ax.legend(loc="lower left", bbox_to_anchor=(0.0, 1.0), ncol=2, borderaxespad=0.1)
    return fig


@styled
def candidate_scores_figure(result: Any) -> Any:
    """Score of every fitted candidate effect (horizontal bars), with the threshold.

    Parameters
    ----------
    result : fi_design.results.reconciliation.ReconcileResult
        The reconciliation.

    Returns
    -------
    matplotlib.figure.Figure
    """
    cands = list(result.candidates)[::-1]
    fig = report_figure(0.28 * max(len(cands), 1) + 0.9, left=1.9, top=0.15)
    ax = fig.subplots()
    names = [c.name for c in cands]
    # signed log scale: scores span many decades
    vals = np.array([math.copysign(math.log10(1.0 + abs(c.score)), c.score) for c in cands])
    colours = ["C0" if c.name in result.effects else "0.6" for c in cands]
    ax.barh(names, vals, color=colours)
    thr = math.log10(1.0 + result.threshold)
    ax.axvline(thr, color="C3", lw=0.9, ls="--")
    ax.text(thr, 1.0, " threshold", transform=ax.get_xaxis_transform(), va="bottom",
            fontsize=7, color="C3")
    ax.set_xlabel("score: sign(s) log10(1 + |s|), s = BIC difference [-]")
    return fig


@styled
def structure_figure(result: Any) -> Any:
    """The nominal model's residual over time and its amplitude spectrum (structure diagnosis).

    Left: measured minus nominal model (force [N] when recorded, else position
    [µm]) over time. Right: its Welch amplitude spectral density with the
    loop's crossover and a third of it marked (energy above a third of the
    crossover points at the controller description, slow energy at a missing
    disturbance).

    Parameters
    ----------
    result : fi_design.results.reconciliation.ReconcileResult
        The reconciliation.

    Returns
    -------
    matplotlib.figure.Figure
    """
    d = result.diagnosis
    meas = result.measurement
    t = result.nominal.time
    if d.channel == "force":
        r = np.asarray(meas.force) - np.asarray(result.nominal.force)
        scale, label, dens = 1.0, "measured - nominal force [N]", "ASD [N/√Hz]"
    else:
        r = np.asarray(meas.position) - np.asarray(result.nominal.position)
        scale, label, dens = 1e6, "measured - nominal position [µm]", "ASD [µm/√Hz]"
    fig = report_figure(2.6, top=0.25)
    fig.subplots_adjust(wspace=0.4)
    ax1, ax2 = fig.subplots(1, 2)
    tt, yy = decimate(t, r * scale)
    ax1.plot(tt, yy, color=GAP_COLOURS["nominal"], lw=0.8)
    ax1.set_xlabel("time from the first sample [s]")
    ax1.set_ylabel(label)
    f = np.asarray(d.frequency)
    a = np.asarray(d.spectrum) * scale
    keep = f > 0
    ax2.loglog(f[keep], a[keep], color=GAP_COLOURS["nominal"], lw=0.9)
    for x, text in ((d.crossover, "crossover"), (d.crossover / 3.0, "crossover / 3")):
        if x > 0:
            ax2.axvline(x, color="0.5", lw=0.8, ls="--")
            ax2.text(x, 0.97, text + " ", transform=ax2.get_xaxis_transform(), va="top",
                     ha="right", fontsize=7, color="0.35", rotation=90)
    ax2.set_xlabel("frequency [Hz]")
    ax2.set_ylabel(dens)
    return fig
