"""The design's linear analysis: Bode, Nyquist and sensitivity of the four limit cases.

Read from a :class:`~fi_design.results.design.DesignResult` (its loop over
frequency and its crossovers); one colour and line style per limit case in
every figure.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..display import number, quantity
from .figure import log_x, report_figure, styled


#: Colour of each linear limit case (the same in the Bode, Nyquist and sensitivity plots).
CASE_COLOURS = {"sliding_free": "C0", "stuck_free": "C1", "sliding_limited": "C2",
                "stuck_limited": "C3", "sliding": "C0", "stuck": "C3"}


#: Line style of each limit case: the limiter cases dashed (they overlap the free ones).
CASE_STYLES = {"sliding_limited": "--", "stuck_limited": "--"}


def case_label(case: Any) -> str:
    """Legend label of a limit case: ``"1 cart sliding, joint free"``.

    Parameters
    ----------
    case : fi_design.guideline.steps.CaseResponse
        The case (``number`` and ``description``).

    Returns
    -------
    str
    """
    return f"{case.number} {case.description}".strip()


def _phase_deg(L: np.ndarray, f: np.ndarray, near: float) -> np.ndarray:
    """Unwrapped phase [deg], shifted by whole turns so it lies in (-270, 90] at ``near`` Hz.

    ``near`` is the case's gain crossover: there the phase margin is read, and
    the shift puts the phase where the margin is plainly its distance from -180.
    """
    ph = np.degrees(np.unwrap(np.angle(L)))
    i = int(np.argmin(np.abs(np.log(f / near))))
    return ph - 360.0 * math.ceil((ph[i] - 90.0) / 360.0)


#: The loop's band reaches this factor below the design crossover (the limit cases' in-band
#: test, ``linear.BAND_FACTOR``); the Bode and sensitivity plots start 3 times lower still.
BAND_FACTOR = 10.0


def design_band(result: Any) -> tuple[float, float]:
    """The frequency span of the Bode and sensitivity plots [Hz]: the design band.

    From a decade below the lowest in-band gain crossover (at least 30 times
    below the design crossover) to the top of the loop's grid (30 times the
    crossover, twice the highest parasitic mode), on whole decades. A
    crossover far below the band (the integrator against a stuck cart's
    bristles, millihertz) is not drawn: the caption names it
    (:func:`out_of_band_crossovers`).

    Parameters
    ----------
    result : fi_design.results.design.DesignResult
        The design.

    Returns
    -------
    (float, float)
        Lowest and highest frequency [Hz].
    """
    fc = result.crossover.desired
    low = fc / BAND_FACTOR
    inside = [x for c in result.crossover.cases for x in c.crossovers if x and x >= low]
    lo = min([fc / 30.0] + [x / 3.0 for x in inside])
    f = np.asarray(result.loop.frequency)
    lo = max(10.0 ** math.floor(math.log10(lo)), float(f[0]))
    return lo, float(f[-1])


def out_of_band_crossovers(result: Any) -> list[tuple[Any, float]]:
    """(case, crossover [Hz]) of the gain crossovers below :func:`design_band`."""
    lo, _ = design_band(result)
    return [(c, x) for c in result.crossover.cases for x in c.crossovers if x and x < lo]


@styled
def bode_figure(result: Any) -> Any:
    """Open-loop Bode plot of the four limit cases (paper Figure 2) in one figure.

    Magnitude and phase of L = C D P for every case (the design's
    :class:`~fi_design.guideline.steps.LoopResponses`), the desired crossover
    (dashed), 0 dB and -180 deg, and each case's gain crossovers (dots).

    Parameters
    ----------
    result : fi_design.guideline.steps.DesignResult
        The design.

    Returns
    -------
    matplotlib.figure.Figure
    """
    f = result.loop.frequency
    responses = [(c, c.loop) for c in result.loop.cases]
    fc = result.crossover.desired
    fig = report_figure(4.3, top=0.62, right=0.3, hspace=0.1)
    mag, pha = fig.subplots(2, 1, sharex=True, height_ratios=(1.1, 1.0))
    by_name = {c.name: c for c in result.crossover.cases}
    phases = []
    for lc, L in responses:
        col = CASE_COLOURS.get(lc.name, None)
        ls = CASE_STYLES.get(lc.name, "-")
        db = 20.0 * np.log10(np.abs(L))
        mag.plot(f, db, color=col, ls=ls, label=case_label(lc))
        case = by_name.get(lc.name)
        near = case.crossover if case is not None and case.crossover else fc
        phases.append(_phase_deg(L, f, near))
        pha.plot(f, phases[-1], color=col, ls=ls)
    for lc, L in responses:
        case = by_name.get(lc.name)
        for fx in (case.crossovers if case is not None else ()):
            mag.plot([fx], [0.0], "o", ms=3.5, color=CASE_COLOURS.get(lc.name), zorder=5)
    for ax in (mag, pha):
        ax.axvline(fc, color="0.3", lw=0.9, ls="--")
    mag.axhline(0.0, color="0.3", lw=0.8)
    pha.axhline(-180.0, color="0.3", lw=0.8)
    allmag = np.concatenate([20 * np.log10(np.abs(L)) for _, L in responses])
    top = min(np.nanmax(allmag), 160.0)
    bottom = max(np.nanmin(allmag), -120.0)
    mag.set_ylim(bottom - 5, top + 5)
    log_x(pha)
    allpha = np.concatenate(phases)
    lo = max(-90.0 * math.ceil(-np.nanmin(allpha) / 90.0), -450.0)
    hi = min(90.0 * math.ceil(np.nanmax(allpha) / 90.0), 180.0)
    pha.set_ylim(lo, max(hi, 0.0))
    pha.set_yticks(np.arange(lo, max(hi, 0.0) + 1, 90))
    mag.set_ylabel("|L| [dB]")
    pha.set_ylabel("phase of L [deg]")
    pha.set_xlabel("frequency [Hz]")
    lo, hi = design_band(result)
    mag.set_xlim(lo, hi)
    inside = (f >= lo) & (f <= hi)
    band_mag = np.concatenate([20 * np.log10(np.abs(L[inside])) for _, L in responses])
    mag.set_ylim(max(np.nanmin(band_mag), -120.0) - 5, min(np.nanmax(band_mag), 160.0) + 5)
    _mark_nyquist(result, (mag, pha))
    mag.annotate(f"fc = {quantity(fc, 'Hz', 4)}", (fc, 0.02), xycoords=mag.get_xaxis_transform(),
                 xytext=(3, 0), textcoords="offset points", ha="left", va="bottom",
                 fontsize=7.5, color="0.3")
    fig.legend(*mag.get_legend_handles_labels(), loc="upper center", ncols=2,
               bbox_to_anchor=(0.5, 1.0), title="limit case (paper Figure 2)",
               title_fontsize=7.5)
    return fig


def _mark_nyquist(result: Any, axes) -> None:
    """A sampled loop's Nyquist frequency, where its curves end (dotted, labelled on the first axes)."""
    fn = getattr(result.loop, "nyquist", None)
    if fn is None:
        return
    for ax in axes:
        ax.axvline(fn, color="0.45", lw=0.8, ls=":")
    axes[0].annotate("Nyquist", (fn, 0.98), xycoords=axes[0].get_xaxis_transform(),
                     xytext=(-3, 0), textcoords="offset points", ha="right", va="top",
                     fontsize=7, color="0.4")


@styled
def nyquist_figure(result: Any) -> Any:
    """Nyquist plot of the limit cases (positive frequencies), zoomed on the critical point -1.

    The curves are drawn on the loop's own grid, refined where they move fast
    (:func:`fi_design.loop.responses.frequency_grid`), so they are smooth; a
    sampled loop's end at its Nyquist frequency. Colours and line styles as
    in :func:`bode_figure`; the circle
    ``|1 + L| = m`` marks the modulus margin ``m`` (the spec's requirement, else
    0.5, i.e. 6 dB of sensitivity peak).

    Parameters
    ----------
    result : fi_design.guideline.steps.DesignResult
        The design.

    Returns
    -------
    matplotlib.figure.Figure
    """
    responses = [(c, c.loop) for c in result.loop.cases]
    fig = report_figure(3.0, 3.3, left=0.55, right=0.1, top=0.1, bottom=0.45)
    ax = fig.add_subplot()
    for lc, L in responses:
        col = CASE_COLOURS.get(lc.name)
        ax.plot(L.real, L.imag, color=col, ls=CASE_STYLES.get(lc.name, "-"),
                label=f"case {lc.number}")
    req = result.spec.requirements.modulus_margin
    m = req if req is not None else 0.5
    t = np.linspace(0, 2 * math.pi, 200)
    ax.plot(-1 + m * np.cos(t), m * np.sin(t), color="0.4", lw=0.8, ls=":")
    ax.plot([-1], [0], marker="+", color="red", ms=9, mew=1.5, ls="none")
    ax.annotate(f"|1 + L| = {number(m, 6)}", (-1 + m * math.cos(2.3), m * math.sin(2.3)),
                xytext=(-2.4, 1.15), fontsize=7, color="0.35",
                arrowprops={"arrowstyle": "-", "color": "0.6", "lw": 0.6})
    ax.set_xlim(-2.5, 1.0)
    ax.set_ylim(-2.0, 1.5)
    ax.set_aspect("equal")
    ax.set_xlabel("Re L [-]")
    ax.set_ylabel("Im L [-]")
    return fig


@styled
def sensitivity_figure(result: Any) -> Any:
    """Sensitivity |S| = |1 / (1 + L)| of the limit cases, peaks marked.

    The grid holds each case's sensitivity peak (its modulus margin's
    frequency), so the dot is the table's peak, 1 / modulus margin.

    Parameters
    ----------
    result : fi_design.guideline.steps.DesignResult
        The design.

    Returns
    -------
    matplotlib.figure.Figure
    """
    f = result.loop.frequency
    responses = [(c, c.loop) for c in result.loop.cases]
    # right: half a '10000' tick label (0.18 in) beyond the band's top decade, on the frame
    fig = report_figure(3.0, 3.3, left=0.55, right=0.25, top=0.1, bottom=0.45)
    ax = fig.add_subplot()
    for lc, L in responses:
        col = CASE_COLOURS.get(lc.name)
        s_db = -20.0 * np.log10(np.abs(1.0 + L))
        ax.plot(f, s_db, color=col, ls=CASE_STYLES.get(lc.name, "-"), label=f"case {lc.number}")
        i = int(np.argmax(s_db))
        ax.plot([f[i]], [s_db[i]], "o", ms=3.5, color=col)
    req = result.spec.requirements.modulus_margin
    m = req if req is not None else 0.5
    peak = -20 * math.log10(m)
    ax.axhline(peak, color="0.4", lw=0.8, ls=":")
    ax.text(0.02, peak, f"|S| = {quantity(peak, 'dB', 3)} (|1 + L| = {number(m, 6)})",
            transform=ax.get_yaxis_transform(), va="bottom", ha="left", fontsize=7,
            color="0.35")
    ax.axhline(0.0, color="0.3", lw=0.8)
    ax.axvline(result.crossover.desired, color="0.3", lw=0.9, ls="--")
    _mark_nyquist(result, (ax,))
    ax.set_ylim(-60, 15)
    log_x(ax, numticks=6)
    ax.set_xlim(*design_band(result))
    ax.legend(loc="lower right")
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("|S| [dB]")
    return fig
