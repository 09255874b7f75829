"""The identification report: friction and mass identified from a measured record.

Built from :class:`fi_design.identification.IdentificationResult` as generic
report sections (:class:`fi_design.report.Section`, :class:`~fi_design.report.Table`,
:func:`~fi_design.report.figure_block`) and rendered with
:func:`fi_design.report.render_document`: the title block, layout, escaping
and appendix of the other reports. Sections: the identified parameters, the
force-velocity map with the fitted friction curve (both directions), the force
residual over time, the fit statistics, what is and is not identifiable, and
the processing. The figures are drawn here with matplotlib's ``Figure`` API
(never pyplot).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from .plots import report_figure, styled

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


def friction_curve(result: Any, velocity: np.ndarray) -> np.ndarray:
    """The identified steady-state friction plus offset at ``velocity`` [N].

    Coulomb plus viscous friction per direction and the offset, in the
    identification's form; where static friction and the Stribeck velocity
    are both identified, the Stribeck term (Fs - Fc) exp(-(v/vs)^2) on top
    (the negative direction's scaled by its Coulomb ratio). Zero velocity
    gets the mean of the two sides.

    Parameters
    ----------
    result : fi_design.identification.IdentificationResult
        The identification.
    velocity : ndarray
        Velocities [m/s].

    Returns
    -------
    ndarray
        Force [N], the shape of ``velocity``.
    """
    v = np.asarray(velocity, dtype=float)
    p = {k: (x.value if x.value is not None else 0.0) for k, x in result.parameters.items()}
    symmetric = result.form == "symmetric"
    fc_pos = p["coulomb"] + (p["offset"] if symmetric else 0.0)
    fc_neg = (p["coulomb"] - p["offset"]) if symmetric else p["coulomb_negative"]
    one_way = getattr(result, "direction", "both")
    if one_way == "negative":  # the level of the one direction the record holds, offset in it
        fc_neg = p["coulomb_negative"]
    pos = fc_pos + p["viscous"] * v
    neg = -fc_neg + p["viscous_negative"] * v
    par = result.parameters
    if par["static"].identifiable and par["stribeck_velocity"].identifiable:
        level = fc_neg if one_way == "negative" else p["coulomb"]
        gap = p["static"] - level  # the form's positive direction, offset aside
        e = np.exp(-(v / p["stribeck_velocity"]) ** 2)
        ratio = 1.0 if symmetric or one_way != "both" else p["coulomb_negative"] / p["coulomb"]
        pos = pos + gap * e
        neg = neg - gap * ratio * e
    curve = np.where(v > 0, pos, np.where(v < 0, neg, 0.5 * (pos + neg)))
    if one_way != "both":  # nothing is known of the other direction: no curve there
        curve = np.where(v < 0 if one_way == "positive" else v > 0, np.nan, curve)
    return curve


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
        ax.plot(vv, friction_curve(result, vv / 1e3), color=COLOURS["fit"], lw=1.4,
                label="identified friction + offset" if side > 0 else None)
    ax.axhline(0.0, color="0.5", lw=0.6)
    ax.axvline(0.0, color="0.5", lw=0.6)
    ax.set_xlabel("velocity of the bearing side [mm/s]")
    ax.set_ylabel("force - mass x acceleration [N]")
    ax.text(0.0, 1.0, f" |v| < {th:.3g} mm/s: left out", transform=ax.get_xaxis_transform(),
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
    ax.set_title(f"grey band: ±2 RMS ({2 * rms:.3g} N)", loc="right", fontsize=7, color="0.35")
    return fig


def _value_text(p: Any, digits: int = 5) -> str:
    from .report import num

    return "not identifiable" if p.value is None else num(p.value, digits)


def identification_sections(result: Any, figures: bool = True) -> list:
    """Report sections of an identification.

    Parameters
    ----------
    result : fi_design.identification.IdentificationResult
        The identification.
    figures : bool, optional
        Draw the figures (False: captions only, for tests of the structure).

    Returns
    -------
    list of fi_design.report.Section
        Parameters, force-velocity map, residual, fit statistics,
        identifiability, processing.
    """
    from .report import FigureBlock, Section, Table, figure_block, num, qty

    def fig(make, caption, name):
        if not figures:
            return FigureBlock(None, caption, name)
        return figure_block(make(result), caption, name)

    meas = result.measurement
    rows = tuple((name, _value_text(p), "-" if p.std_error is None else num(p.std_error, 2),
                  p.unit, "yes" if p.identifiable else "no", p.note)
                 for name, p in result.parameters.items())
    m = result.masses
    mass_rows = (("stage (m1)", qty(m.stage, "kg"),
                  "-" if m.stage_std_error is None else qty(m.stage_std_error, "kg", 2), m.source),
                 ("cart (m2)", qty(m.cart, "kg"),
                  "-" if m.cart_std_error is None else qty(m.cart_std_error, "kg", 2), m.source))
    s1 = Section(
        "parameters", "Identified parameters",
        paragraphs=(f"Record: {meas.source or 'in memory'}, {meas.n} samples over "
                    f"{num(meas.duration)} s ({', '.join(meas.columns)}). Form: "
                    f"{result.form.replace('_', '-')}; model: {result.model.replace('_', ' ')}. "
                    "Standard errors are one standard deviation, corrected for the "
                    "autocorrelation of the residuals.",),
        tables=(Table(("Parameter", "Value", "Std. error", "Unit", "Identifiable", "Note"), rows,
                      caption="Parameters (SI)",
                      numeric=(False, True, True, False, False, False)),
                Table(("Body", "Mass", "Std. error", "Source"), mass_rows,
                      caption="Stage and cart mass", numeric=(False, True, True, False))))
    s2 = Section(
        "map", "Force-velocity map",
        paragraphs=("The measured actuator force minus the identified inertial force, against "
                    "the velocity of the bearing side: the friction the record shows, offset "
                    "included. The curve is the identified Coulomb plus viscous friction of "
                    "each direction, with the Stribeck term where static friction and the "
                    "Stribeck velocity are identified.",),
        figures=(fig(force_velocity_figure, "Measured friction (points; grey: left out of the "
                                            "fit) and the identified friction curve of both "
                                            "directions (red). Shaded: the velocity band left "
                                            "out.", "ident-map"),))
    f = result.fit
    stats = (("RMS force residual", qty(f.force_rms_residual, "N")),
             ("relative error ||u - u_model|| / ||u||", num(f.relative_error, 3)),
             ("condition number (columns scaled)", num(f.condition_number, 3)),
             ("samples used", str(f.samples_used)),
             ("effective samples", num(f.effective_samples, 3)))
    s3 = Section(
        "residual", "Force residual and fit statistics",
        paragraphs=(f"Standard errors: {f.error_method}.",),
        tables=(Table(("Statistic", "Value"), stats, caption="Fit statistics"),),
        figures=(fig(residual_figure, "Measured minus modelled actuator force at the used "
                                      "samples (filtered, decimated).", "ident-residual"),))
    e = result.excitation
    exc_rows = (("breakaways after a stop", str(e.breakaways)),
                ("time at rest", qty(e.rest_time, "s")),
                ("reversals", str(e.reversals)),
                ("presliding reversals", str(e.presliding_reversals)),
                ("time moving below the velocity threshold", qty(e.low_speed_time, "s")),
                ("shortest rest counted", qty(e.dwell, "s")),
                ("largest motion at rest", qty(e.rest_band, "m")),
                ("largest presliding excursion", qty(e.presliding_band, "m")))
    notes = [f"{name}: {result.parameters[name].note}"
             for name in ("static", "stribeck_velocity", "bristle_stiffness")]
    notes += list(result.notes)
    tables = [Table(("Excitation", "Value"), exc_rows, caption="Excitation in the record")]
    dyn = getattr(result, "dynamic", None)
    if dyn is not None and dyn.branches:
        tables.append(Table(
            ("Event", "Time [s]", "Samples", "Static friction [N]", "Bristle stiffness [N/m]",
             "Force at onset [N]", "Creep at onset [mm/s]", "Counts for", "Why not"),
            tuple(_event_row(b) for b in dyn.branches),
            caption="Breakaways and presliding cycles (value ± standard error of each fit)",
            numeric=(False, True, True, True, True, True, True, False, False)))
    if dyn is not None and dyn.sweep is not None:
        w = dyn.sweep
        tables.append(Table(("Steady low-speed sliding", "Value"), (
            ("samples (effective)", f"{w.samples} ({num(w.effective_samples, 3)})"),
            ("speed range", f"{qty(w.speed_min, 'm/s', 3)} – {qty(w.speed_max, 'm/s', 3)}"),
            ("below 0.7 vs / above 1.5 vs", f"{w.below} / {w.above}"),
            ("Stribeck velocity", f"{qty(w.stribeck_velocity, 'm/s')} ± "
                                  f"{qty(w.stribeck_velocity_std_error, 'm/s', 2)}"),
            ("RMS weighted residual", num(w.rms_residual, 3))),
            caption="Fit of the Stribeck curve", numeric=(False, True)))
    s4 = Section(
        "identifiability", "What is and is not identifiable",
        paragraphs=("Static friction, Stribeck velocity and bristle stiffness act only near "
                    "zero velocity, where the inverse-dynamics fit leaves the samples out. Each "
                    "is estimated from the part of the record that carries it, with the sliding "
                    "friction above fixed and its errors propagated: static friction from the "
                    "loading branch before each breakaway after a stop (the level the bristles "
                    "saturate at, LuGre's presliding curve fitted to friction against "
                    "displacement), the bristle stiffness from the same branches and from "
                    "presliding cycles, the Stribeck velocity from steady sliding at low speed "
                    "(a slow velocity sweep through zero). Where the record lacks the "
                    "excitation the parameter is not identifiable and the note names the "
                    "experiment that would identify it: never a guessed number.",),
        tables=tuple(tables), notes=tuple(notes))
    p = result.processing
    proc_rows = (("sample rate", qty(p.sample_rate, "Hz")),
                 ("low-pass cut-off", f"{qty(p.cutoff, 'Hz')} ({p.cutoff_rule})"),
                 ("Butterworth order (forwards and backwards)", str(p.filter_order)),
                 ("decimation factor", str(p.decimation)),
                 ("velocity threshold", qty(p.velocity_threshold, "m/s")),
                 ("force read later by", qty(p.force_delay, "s")),
                 ("left out at each end", qty(p.edge, "s")))
    s5 = Section("processing", "Processing",
                 paragraphs=("Inverse-dynamics least squares (IDIM-LS): zero-phase low-pass of "
                             "position and force, central differences, the same filtering and "
                             "decimation of force and regressors, weighted least squares.",),
                 tables=(Table(("Setting", "Value"), proc_rows, caption="Settings",
                               numeric=(False, False)),))
    return [s1, s2, s3, s4, s5]


def _event_row(b: Any) -> tuple:
    """A row of the events table."""
    from .report import num

    def pm(value, se, digits=4):
        if value is None:
            return "–"
        return num(value, digits) + ("" if se is None else f" ± {num(se, 2)}")

    what = {"breakaway": "breakaway " + ("+" if b.direction > 0 else "−"),
            "presliding": "presliding cycle"}[b.kind]
    return (what, num(b.time, 4), str(b.samples), pm(b.static, b.static_std_error),
            pm(b.bristle_stiffness, b.bristle_stiffness_std_error),
            num(b.peak_force, 4),
            "–" if b.creep_velocity is None else num(b.creep_velocity * 1e3, 3),
            ", ".join(b.used_for) or "–", b.note or "–")


def conclusion(result: Any) -> str:
    """A one-paragraph summary of an identification."""
    from .report import num

    p = result.parameters
    parts = [f"{name} = {num(x.value, 4)} ± {num(x.std_error, 2)} {x.unit}"
             for name, x in p.items() if x.value is not None]
    missing = [name for name, x in p.items() if not x.identifiable and x.value is None
               and name in ("static", "stribeck_velocity", "bristle_stiffness")]
    text = (f"Identified from {result.measurement.source or 'the record'} "
            f"({result.form.replace('_', '-')} form): " + "; ".join(parts) +
            f". Relative force error {num(result.fit.relative_error, 3)}.")
    if missing:
        text += (" Not identifiable from this record: " + ", ".join(missing) +
                 " (see 'What is and is not identifiable').")
    return text


def render_identification_report(result: Any, path: str | os.PathLike, *, date: Any = None,
                                  command: str | None = None) -> Path:
    """Write the identification report (HTML or PDF).

    Parameters
    ----------
    result : fi_design.identification.IdentificationResult
        The identification, with its spec.
    path : str or os.PathLike
        ``.html`` or ``.pdf``.
    date : str or datetime.date, optional
        Report date (default today).
    command : str, optional
        The command line, shown in the title block.

    Returns
    -------
    pathlib.Path
        The written file.

    Raises
    ------
    fi_design.errors.SpecError
        The identification has no spec (the title block needs one).
    """
    from .errors import SpecError
    from .report import render_document

    if result.spec is None:
        raise SpecError("the identification report needs the stage's spec (give --spec)")
    return render_document(path, title="Friction identification from a measured record",
                           spec=result.spec, sections=identification_sections(result),
                           date=date, command=command, kind="identify",
                           conclusion=conclusion(result))
