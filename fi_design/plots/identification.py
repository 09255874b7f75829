"""Friction identification: the force-velocity map with the identified curve, the residual.

Read from an identification result; the fitted curve is the result's own
(its ``friction_curve``, the model's steady-state friction law), never
computed here.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..display import quantity
from .figure import report_figure, styled


#: Colours: used samples, samples left out, the fitted curve.
COLOURS = {"used": "C0", "unused": "0.75", "fit": "C3"}


#: Most points drawn per scatter (evenly thinned beyond): keeps the SVG small.
MAX_POINTS = 2500


def _thin(mask: np.ndarray) -> np.ndarray:
    """Indices of ``mask``, evenly thinned to at most :data:`MAX_POINTS`."""
    idx = np.nonzero(mask)[0]
    step = max(1, int(np.ceil(len(idx) / MAX_POINTS)))
    return idx[::step]


def _figure(height: float) -> Any:
    """A report-width figure with the design report's fixed margins [in]."""
    return report_figure(height, top=0.3)


@styled
def force_velocity_figure(result: Any) -> Any:
    """The force-velocity map: measured friction (force minus inertia) and the fitted curve.

    Parameters
    ----------
    result : fi_design.identification.IdentificationResult
        The identification.

    Returns
    -------
    matplotlib.figure.Figure
    """
    s = result.samples
    v = np.asarray(s.velocity) * 1e3
    f = np.asarray(s.friction)
    used = np.asarray(s.used)
    th = result.processing.velocity_threshold * 1e3
    fig = _figure(3.4)
    ax = fig.subplots()
    ax.axvspan(-th, th, color="0.93", lw=0, zorder=0)
    out, inn = _thin(~used), _thin(used)
    ax.plot(v[out], f[out], ".", ms=2, color=COLOURS["unused"], label="left out")
    ax.plot(v[inn], f[inn], ".", ms=2, color=COLOURS["used"], label="used in the fit")
    top = float(np.max(np.abs(v))) if len(v) else 1.0
    for side in (-1.0, 1.0):
        vv = side * np.unique(np.concatenate([np.linspace(1e-9, top, 200),
                                              np.geomspace(1e-4 * top, top, 200)]))
        ax.plot(vv, result.friction_curve(vv / 1e3), color=COLOURS["fit"], lw=1.4,
                label="identified friction + offset" if side > 0 else None)
    ax.axhline(0.0, color="0.5", lw=0.6)
    ax.axvline(0.0, color="0.5", lw=0.6)
    ax.set_xlabel("velocity of the bearing side [mm/s]")
    ax.set_ylabel("force - mass x acceleration [N]")
    ax.text(0.0, 1.0, f" |v| < {quantity(result.processing.velocity_threshold, 'm/s', 3)}: left out", transform=ax.get_xaxis_transform(),
            ha="center", va="top", fontsize=7, color="0.35")
    ax.legend(loc="lower left", bbox_to_anchor=(0.0, 1.0), ncol=3, borderaxespad=0.1,
              markerscale=4)
    return fig


@styled
def residual_figure(result: Any) -> Any:
    """Measured minus modelled actuator force over time, used samples.

    Parameters
    ----------
    result : fi_design.identification.IdentificationResult
        The identification.

    Returns
    -------
    matplotlib.figure.Figure
    """
    s = result.samples
    used = np.asarray(s.used)
    t = np.asarray(s.time)
    r = np.asarray(s.residual)
    rms = result.fit.force_rms_residual
    fig = _figure(2.6)
    ax = fig.subplots()
    ax.axhspan(-2 * rms, 2 * rms, color="0.92", lw=0, zorder=0)
    inn = _thin(used)
    ax.plot(t[inn], r[inn], ".", ms=2, color=COLOURS["used"], label="force residual")
    ax.axhline(0.0, color="0.5", lw=0.6)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("measured - modelled force [N]")
    ax.set_xlim(float(t[0]), float(t[-1]))
    ax.set_title(f"grey band: ±2 RMS ({quantity(2 * rms, 'N', 3)})", loc="right", fontsize=7,
                 color="0.35")
    return fig
