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

from .display import axis_unit
from .errors import ArgumentError

# --------------------------------------------------------------------------- design report
# (fi_design.report: the linear analysis and the nonlinear confirmation of a DesignResult)

#: Colour of each linear limit case (the same in the Bode, Nyquist and sensitivity plots).
CASE_COLOURS = {"sliding_free": "C0", "stuck_free": "C1", "sliding_limited": "C2",
                "stuck_limited": "C3", "sliding": "C0", "stuck": "C3"}
#: Line style of each limit case: the limiter cases dashed (they overlap the free ones).
CASE_STYLES = {"sliding_limited": "--", "stuck_limited": "--"}
#: Colour of each simulated plant.
PLANT_COLOURS = {"isolated": "C0", "non_isolated": "C3"}
#: Width of a full-width report figure [in]: the A4 text width (170 mm), so 1 pt is 1 pt.
REPORT_WIDTH = 6.7
#: matplotlib settings of the report figures: fonts readable on paper, light grid.
REPORT_RC = {
    "font.size": 8.5, "axes.titlesize": 9.0, "axes.labelsize": 8.5, "xtick.labelsize": 8.0,
    "ytick.labelsize": 8.0, "legend.fontsize": 7.5, "axes.grid": True, "grid.color": "0.88",
    "grid.linewidth": 0.6, "axes.linewidth": 0.7, "lines.linewidth": 1.3,
    "axes.spines.top": False, "axes.spines.right": False, "legend.frameon": False,
    "figure.dpi": 100,
}


def report_figure(height: float, width: float = REPORT_WIDTH, *, left: float = 0.62,
                   right: float = 0.12, top: float = 0.12, bottom: float = 0.45,
                   hspace: float = 0.35) -> Any:
    """A report figure with fixed margins [in].

    Fixed margins rather than a layout engine: the report's figures have known
    contents, and a layout engine draws every figure twice (it doubled the
    report's figure time).
    """
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width, height))
    fig.subplots_adjust(left=left / width, right=1.0 - right / width, top=1.0 - top / height,
                        bottom=bottom / height, hspace=hspace)
    return fig


def styled(draw):
    """Run a figure function under :data:`REPORT_RC` (fonts are fixed when artists are made)."""
    import functools

    @functools.wraps(draw)
    def wrapper(*args, **kwargs):
        import matplotlib

        with matplotlib.rc_context(REPORT_RC):
            return draw(*args, **kwargs)

    return wrapper


def case_label(case: Any) -> str:
    """Legend label of a limit case: ``"1 cart sliding, joint free"``.

    Parameters
    ----------
    case : fi_design.guideline.CaseResponse
        The case (``number`` and ``description``).

    Returns
    -------
    str
    """
    return f"{case.number} {case.description}".strip()


def plain_tick(value: float, _pos: Any = None) -> str:
    """Tick label of a log axis as a plain number (``0.001``, ``10``, ``1000``).

    Plain text instead of matplotlib's mathtext powers of ten: readable, and
    much faster to draw.

    Parameters
    ----------
    value : float
        Tick value.

    Returns
    -------
    str
    """
    if value <= 0:
        return ""
    if 1e-4 <= value < 1e5:
        return f"{value:g}" if value >= 1 else f"{value:.{max(0, -math.floor(math.log10(value) + 1e-9))}f}"
    return f"{value:.0e}".replace("e+0", "e").replace("e-0", "e-")


def _log_x(ax: Any, numticks: int = 12) -> None:
    """Logarithmic x axis with plain decade labels and no minor ticks (they are slow to draw)."""
    from matplotlib.ticker import FuncFormatter, LogLocator, NullLocator

    ax.set_xscale("log")
    ax.xaxis.set_major_locator(LogLocator(base=10.0, subs=(1.0,), numticks=numticks))
    ax.xaxis.set_major_formatter(FuncFormatter(plain_tick))
    ax.xaxis.set_minor_locator(NullLocator())


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
    :class:`~fi_design.guideline.LoopResponses`), the desired crossover
    (dashed), 0 dB and -180 deg, and each case's gain crossovers (dots).

    Parameters
    ----------
    result : fi_design.guideline.DesignResult
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
    _log_x(pha)
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
    mag.annotate(f"fc = {fc:g} Hz", (fc, 0.02), xycoords=mag.get_xaxis_transform(),
                 xytext=(3, 0), textcoords="offset points", ha="left", va="bottom",
                 fontsize=7.5, color="0.3")
    fig.legend(*mag.get_legend_handles_labels(), loc="upper center", ncols=2,
               bbox_to_anchor=(0.5, 1.0), title="limit case (paper Figure 2)",
               title_fontsize=7.5)
    return fig


@styled
def nyquist_figure(result: Any) -> Any:
    """Nyquist plot of the limit cases (positive frequencies), zoomed on the critical point -1.

    Colours and line styles as in :func:`bode_figure`; the circle
    ``|1 + L| = m`` marks the modulus margin ``m`` (the spec's requirement, else
    0.5, i.e. 6 dB of sensitivity peak).

    Parameters
    ----------
    result : fi_design.guideline.DesignResult
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
    ax.annotate(f"|1 + L| = {m:g}", (-1 + m * math.cos(2.3), m * math.sin(2.3)),
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

    Parameters
    ----------
    result : fi_design.guideline.DesignResult
        The design.

    Returns
    -------
    matplotlib.figure.Figure
    """
    f = result.loop.frequency
    responses = [(c, c.loop) for c in result.loop.cases]
    fig = report_figure(3.0, 3.3, left=0.55, right=0.1, top=0.1, bottom=0.45)
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
    ax.text(0.02, peak, f"|S| = {peak:.3g} dB (|1 + L| = {m:g})", transform=ax.get_yaxis_transform(),
            va="bottom", ha="left", fontsize=7, color="0.35")
    ax.axhline(0.0, color="0.3", lw=0.8)
    ax.axvline(result.crossover.desired, color="0.3", lw=0.9, ls="--")
    ax.set_ylim(-60, 15)
    _log_x(ax, numticks=6)
    ax.set_xlim(*design_band(result))
    ax.legend(loc="lower right")
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("|S| [dB]")
    return fig


def decimate(t: np.ndarray, y: np.ndarray, buckets: int = 700) -> tuple[np.ndarray, np.ndarray]:
    """Thin a trace for plotting, keeping each bucket's minimum and maximum.

    Parameters
    ----------
    t, y : numpy.ndarray, shape (n,)
        Sample times and values.
    buckets : int, optional
        Number of buckets; at most two samples survive per bucket.

    Returns
    -------
    t, y : numpy.ndarray
        The kept samples, in time order (the input when it is short already).
    """
    t = np.asarray(t, dtype=float)
    y = np.asarray(y, dtype=float)
    n = len(t)
    if n <= 2 * buckets:
        return t, y
    edges = np.linspace(0, n, buckets + 1).astype(int)
    keep = [0, n - 1]
    for a, b in zip(edges[:-1], edges[1:]):
        seg = y[a:b]
        if len(seg) and np.any(np.isfinite(seg)):
            keep += [a + int(np.nanargmin(seg)), a + int(np.nanargmax(seg))]
        elif len(seg):  # no value here (a failed run): keep one NaN so the line breaks
            keep.append(a)
    idx = np.unique(np.array(keep))
    return t[idx], y[idx]


def _plant_title(v: Any, label: str) -> str:
    m = v.metrics
    cycles = f"{m.hunting_cycles} cycle{'s' if m.hunting_cycles != 1 else ''}"
    return f"{label}: {m.verdict} ({cycles} counted)"


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
    confirmation : fi_design.confirm.Confirmation
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
    label = "suggested isolator" if confirmation.suggested_isolator else "with isolator"
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
        ax.text(0.03, h.min_height * 1e3, f"min. peak height {h.min_height * 1e3:g} mm",
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
            note = f"in the band from t = {ts:.3g} s\n({m.settling_time:.3g} s after the motion)"
        else:
            note = "never stays in the band"
        axz.text(0.98, 0.04, note, transform=axz.transAxes, ha="right", va="bottom",
                 fontsize=7, color="0.25",
                 bbox={"facecolor": "white", "alpha": 0.85, "lw": 0, "pad": 0.6})
        axz.set_title(f"after the motion: \u00b1{band:g} \u00b5m settle band", loc="left",
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
    confirmation : fi_design.confirm.Confirmation
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
        ax.plot([res.time[-1]], [land.deflection * 1e6], "o", color="black", ms=4,
                label=f"at rest: {land.deflection * 1e6:.0f} µm")
    ax.set_ylim(-1.35 * stroke * 1e6, 1.35 * stroke * 1e6)
    ax.set_xlim(0, float(res.time[-1]))
    ax.set_xlabel("time [s]")
    ax.set_ylabel("x1 - x2 [µm]")
    fig.legend(*ax.get_legend_handles_labels(), loc="upper center", ncols=3,
               bbox_to_anchor=(0.5, 1.0))
    return fig


def _plant_names(confirmation: Any) -> dict:
    label = "suggested isolator" if confirmation.suggested_isolator else "with isolator"
    return {"isolated": label, "non_isolated": "without isolator"}


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
    names = _plant_names(confirmation)
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
    _log_x(ax)
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
    names = _plant_names(confirmation)
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
                  label=f"{names[key]}: cycle of {c.amplitude * 1e3:.3g} mm, {c.period:.3g} s")
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
    ax_s.set_title(f"spec's motion, ±{band:g} µm band", loc="left", fontsize=7.5)
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
    names = _plant_names(confirmation)
    for n, key in enumerate(("isolated", "non_isolated")):
        st = confirmation.stage[key]
        col = PLANT_COLOURS[key]
        b = st.boundary or {}
        pts = [p for p in b.get("branch") or [] if p[1] is not None]
        if pts:
            f, a = np.array([p[0] for p in pts]), np.array([p[1] for p in pts]) * 1e3
            ax.plot(f, a, "o-", color=col, ms=3, lw=1.1, label=f"{names[key]}: cycle")
        m = st.hunting_free_from
        if m is not None and b.get("kind") == "fold":
            ax.axvline(m, color=col, lw=0.9, ls=":")
            ax.text(m, 0.62 - 0.1 * n, f"no move hunts from {m:.4g} Hz ", color=col,
                    fontsize=7, transform=ax.get_xaxis_transform(), va="top", ha="right")
    fc = confirmation.stage["isolated"].crossover
    ax.axvline(fc, color="0.3", lw=0.9, ls="--")
    ax.text(fc, 0.04, f" design {fc:g} Hz", color="0.3", fontsize=7,
            transform=ax.get_xaxis_transform(), va="bottom", ha="left")
    folds = [st.hunting_free_from for st in confirmation.stage.values()
             if st.hunting_free_from is not None]
    ax.set_xlim(0.0, 1.08 * max(folds + [fc]))
    ax.set_ylim(bottom=0.0)
    ax.set_xlabel("crossover fc [Hz]")
    ax.set_ylabel("cycle peak to peak [mm]")
    fig.legend(*ax.get_legend_handles_labels(), loc="upper center", ncols=2,
               bbox_to_anchor=(0.5, 1.0))
    return fig


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
    "not_evaluated": ("#e5f5e0", "not signed off (ranked below)"),
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
    es, ek = _edges(s, True), _edges(k, True)
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


def figure_svg(fig: Any, prefix: str, text_as_paths: bool = False) -> str:
    """A figure as SVG text for inlining in HTML: no XML prolog, unique ids, scalable.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.
    prefix : str
        Prepended to every ``id`` (and the references to it), so several
        figures can share one HTML page; letters, digits and ``-`` only.
    text_as_paths : bool, optional
        Draw text as glyph outlines (equations: exact, with any font);
        default False.

    Returns
    -------
    str
        An ``<svg>`` element with a ``viewBox`` (CSS sizes it), reproducible
        (fixed id salt, no date). By default text stays text
        (``svg.fonttype: none``): searchable, and about twice as fast for
        WeasyPrint to draw as glyph outlines; viewers draw it with their own
        sans-serif font.
    """
    import re

    import matplotlib

    buf = io.BytesIO()
    with matplotlib.rc_context({"svg.hashsalt": "fi_design",
                                "svg.fonttype": "path" if text_as_paths else "none"}):
        fig.savefig(buf, format="svg", metadata={"Date": None})
    text = buf.getvalue().decode("utf-8")
    text = text[text.index("<svg"):]
    text = re.sub(r'\bid="([^"]+)"', lambda m: f'id="{prefix}-{m.group(1)}"', text)
    text = re.sub(r'href="#([^"]+)"', lambda m: f'href="#{prefix}-{m.group(1)}"', text)
    text = re.sub(r"url\(#([^)]+)\)", lambda m: f"url(#{prefix}-{m.group(1)})", text)
    text = re.sub(r"<metadata>.*?</metadata>\s*", "", text, flags=re.DOTALL)
    return text.strip()


# --------------------------------------------------------------------------- parameter studies
# (fi_design.studies: hunting maps, the paper's Figure 4, robustness)

#: Marks drawn on map cells whose verdict is not a plain count.
VERDICT_MARKS = {"stuck": "s", "undetermined": "?", "failed": "×"}


def display_unit(unit: str) -> tuple[str, float]:
    """Unit shown on an axis for an SI unit, and the factor from SI
    (:func:`fi_design.display.axis_unit`)."""
    return axis_unit(unit)


#: Names of the values sweeps and studies usually vary, by dotted spec path.
QUANTITY_NAMES: dict[str, str] = {
    "controller.crossover": "Crossover frequency",
    "controller.delay": "Loop delay",
    "controller.sample_rate": "Sample rate",
    "controller.force_limit": "Force limit",
    "controller.derivative_ratio": "Derivative ratio",
    "controller.integrator_ratio": "Integrator ratio",
    "isolator.stroke": "Isolator stroke",
    "isolator.stiffness": "Drive stiffness",
    "isolator.damping": "Joint damping",
    "friction.static": "Static friction",
    "friction.coulomb": "Coulomb friction",
    "friction.stribeck_velocity": "Stribeck velocity",
    "friction.viscous": "Viscous friction",
    "friction.bristle_stiffness": "Bristle stiffness",
    "friction.bristle_damping": "Bristle damping",
    "friction.offset": "Load force offset",
    "stage.mass": "Stage mass",
    "cart.mass": "Cart mass",
}


def quantity_name(path: str) -> str:
    """A readable name for the value at a dotted spec path: ``"Isolator stroke"``.

    Parameters
    ----------
    path : str
        Dotted spec path.

    Returns
    -------
    str
        From :data:`QUANTITY_NAMES`, else the first words of the schema's
        description of the field (``"Extra loop delay"``), else the path.
    """
    if path in QUANTITY_NAMES:
        return QUANTITY_NAMES[path]
    from .errors import SpecError
    from .specfile import path_description

    try:
        text = path_description(path)
    except SpecError:
        text = ""
    for stop in (" [", ";", ". ", " ("):
        text = text.split(stop)[0]
    text = text.strip().rstrip(".")
    return text[:1].upper() + text[1:] if text else path


def axis_label(path: str, unit: str) -> str:
    """Axis label with the quantity's name and display unit: ``"Isolator stroke [mm]"``.

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
    name = quantity_name(path)
    return f"{name} [{shown}]" if shown else name


def _physical_edges(edges: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Cell edges clipped to the physical range: none below zero when every value is >= 0."""
    out = np.array(edges, dtype=float)
    if np.all(np.asarray(values, dtype=float) >= 0.0):
        out[0] = max(out[0], 0.0)
    return out


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
    """Draw a :class:`~fi_design.studies.SweepResult` into ``ax``.

    A map is a heatmap (paper Figure 4) of the hunting cycles counted on the
    spec's move (``measure "move"``), or of the peak-to-peak amplitude of the
    cycle some move of the family ends in (``measure "stage"``): white where
    there is none, invalid points hatched grey, stuck points marked ``s``,
    undetermined ``?``, failed ``×``, the design point a red cross. A line is
    a step plot of the same over x.

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
    xu, xf = display_unit(x.unit)
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
        if result.design_point[0] is not None:
            ax.axvline(result.design_point[0] * xf, color="red", lw=1, ls="--",
                       label="design point")
            ax.legend(loc="best", fontsize=8, frameon=False)
        ax.set_xlabel(axis_label(x.path, x.unit))
        ax.set_ylabel(label)
        if x.log:
            ax.set_xscale("log")
        else:
            ex = _physical_edges(_edges(xs, False), xs)
            ax.set_xlim(ex[0], ex[-1])
        ax.set_ylim(bottom=0)
        ax.set_title(f"{quantity_name(x.path)} ({plant})" if title is None else title,
                     fontsize=10)
        return artist
    y = result.y
    yu, yf = display_unit(y.unit)
    ys = np.asarray(y.values) * yf
    if stage:
        from matplotlib.colors import Normalize

        top_mm = float(np.nanmax(cycles)) if np.any(np.isfinite(cycles)) else 0.0
        top_mm = max(top_mm, 1e-3) if vmax is None else max(float(vmax), 1e-3)
        cmap = colormaps["YlOrRd"].with_extremes(under="white", bad="0.8")
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
    ex, ey = _physical_edges(_edges(xs, x.log), xs), _physical_edges(_edges(ys, y.log), ys)
    mesh = ax.pcolormesh(ex, ey, data, cmap=cmap, norm=norm, shading="flat")
    for j, i in zip(*np.nonzero(verdict == "invalid")):
        ax.add_patch(Rectangle((ex[i], ey[j]), ex[i + 1] - ex[i], ey[j + 1] - ey[j], fill=False,
                               hatch="//", edgecolor="0.55", lw=0))
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
                ax.text(xs[i], ys[j], f"{c:.2g}" if stage else f"{int(c)}", ha="center",
                        va="center", fontsize=6, color="black" if c < 0.6 * top else "white")
    dx, dy = result.design_point
    if dx is not None and dy is not None:
        ax.plot([dx * xf], [dy * yf], marker="X", color="red", ms=10, mec="white", mew=1.0,
                ls="none", label="design point")
    if x.log:
        ax.set_xscale("log")
    if y.log:
        ax.set_yscale("log")
    ax.set_xlim(ex[0], ex[-1])
    ax.set_ylim(ey[0], ey[-1])
    ax.set_xlabel(axis_label(x.path, x.unit))
    ax.set_ylabel(axis_label(y.path, y.unit))
    ax.set_title(f"{quantity_name(y.path)} vs {quantity_name(x.path).lower()} ({plant})"
                 if title is None else title, fontsize=10)
    if colorbar:
        if stage:
            cb = ax.figure.colorbar(mesh, ax=ax, extend="min")
            cb.set_label("Cycle peak to peak, any move [mm] (white: every move settles)")
        else:
            cb = ax.figure.colorbar(mesh, ax=ax, ticks=_ticks(top))
            w0, w1 = _window(result)
            cb.set_label(f"Hunting cycles in [{w0:g} s, {w1:g} s) [-]")
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
                _, factor = display_unit(swept.unit)
                axis.set_major_formatter(FuncFormatter(plain_tick))
                axis.set_minor_formatter(NullFormatter())
                lo, hi = min(swept.values) * factor, max(swept.values) * factor
                axis.set_ticks(nice_ticks(lo, hi))
    return fig


def nice_ticks(lo: float, hi: float) -> list[float]:
    """1-2-5 ticks between ``lo`` and ``hi`` (for log axes).

    Parameters
    ----------
    lo, hi : float
        The axis range (above zero).

    Returns
    -------
    list of float
    """
    out = []
    for exp in range(math.floor(math.log10(lo)) - 1, math.ceil(math.log10(hi)) + 1):
        for m in (1.0, 2.0, 5.0):
            v = m * 10.0 ** exp
            if lo * 0.999 <= v <= hi * 1.001:
                out.append(float(f"{v:.6g}"))
    return out


def _legend_text(result: Any) -> str:
    marks = ", ".join(f"{m} {v}" for v, m in VERDICT_MARKS.items()
                      if np.any(np.asarray(result.verdict) == v))
    extra = "hatched: invalid spec" if np.any(np.asarray(result.verdict) == "invalid") else ""
    parts = [p for p in (marks, extra) if p]
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
        ax.text(k, 100 * p.high + 2, f"{p.hunting}/{p.valid}", ha="center", fontsize=8)
    ax.set_xticks(range(len(bars)), [b[0] for b in bars])
    ax.set_ylim(0, 110)
    ax.set_ylabel("probability of hunting [%]")
    conf = bars[0][1].confidence if bars else 0.95
    if title != "":
        ax.set_title(f"{result.spec.name}: {result.samples} samples, {conf:.0%} Wilson "
                     "interval" if title is None else title, fontsize=10)
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
        raise ArgumentError(f"unsupported figure format {fmt!r}; use svg or png")
    buf = io.BytesIO()
    meta = {"Date": None} if fmt == "svg" else {"Software": None}
    with matplotlib.rc_context({"svg.hashsalt": "fi_design", "svg.fonttype": "path"}):
        fig.savefig(buf, format=fmt, dpi=150 if fmt == "png" else None, metadata=meta)
    return buf.getvalue()


# --------------------------------------------------------------------------- reconciliation
# (fi_design.reconciliation: measured trace against the nominal and the corrected model)

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
