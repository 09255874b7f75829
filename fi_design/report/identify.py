"""The identification report: friction and mass identified from a measured record.

Built from :class:`fi_design.results.identification.IdentificationResult` as
generic report sections (:class:`~fi_design.report.blocks.Section`,
:func:`identification_sections`) and registered with :func:`build_context`
like every other report (:func:`identification_context`), so
:func:`fi_design.render_report` writes it: the same title block, layout,
escaping and appendix as the design report. Sections: the identified
parameters, the force-velocity map with the fitted friction curve (both
directions), the force residual over time, the fit statistics, what is and is
not identifiable, and the processing. The figures come from
:mod:`fi_design.plots.identification`; the fitted curve is the result's own
(:meth:`~fi_design.results.identification.IdentificationResult.friction_curve`).
"""

from __future__ import annotations

from typing import Any

from ..errors import SpecError
from ..results.identification import IdentificationResult
from .blocks import FigureBlock, Section, Table, figure_block
from .context import build_context, document_context
from .filters import num, qty
from .meta import TITLES

__all__ = ["identification_context", "identification_sections", "conclusion"]


def _value_text(p: Any, digits: int = 5) -> str:
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
    from .. import plots

    def fig(make, caption, name):
        if not figures:
            return FigureBlock(None, caption, name)
        return figure_block(make(result), caption, name)

    meas = result.measurement
    rows = tuple((name, _value_text(p), "\u2013" if p.std_error is None else num(p.std_error, 2),
                  p.unit, "yes" if p.identifiable else "no", p.note)
                 for name, p in result.parameters.items())
    m = result.masses
    mass_rows = (("stage (m1)", qty(m.stage, "kg"),
                  "\u2013" if m.stage_std_error is None else qty(m.stage_std_error, "kg", 2), m.source),
                 ("cart (m2)", qty(m.cart, "kg"),
                  "\u2013" if m.cart_std_error is None else qty(m.cart_std_error, "kg", 2), m.source))
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
        figures=(fig(plots.force_velocity_figure, "Measured friction (points; grey: left out of the "
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
        figures=(fig(plots.residual_figure, "Measured minus modelled actuator force at the used "
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



@build_context.register
def identification_context(result: IdentificationResult, *, date: Any = None,
                           command: str | None = None, figures: bool = True) -> dict:
    """The report context of an identification.

    Parameters
    ----------
    result : fi_design.results.identification.IdentificationResult
        The identification, with its spec.
    date : str or datetime.date, optional
        Report date (default today).
    command : str, optional
        The command line, shown in the title block.
    figures : bool, optional
        Draw the figures (default).

    Returns
    -------
    dict
        For :func:`~fi_design.report.render.render_html`.

    Raises
    ------
    fi_design.errors.SpecError
        The identification has no spec (the title block needs one).
    """
    if result.spec is None:
        raise SpecError("the identification report needs the stage's spec (give --spec)")
    return document_context(TITLES["identify"], result.spec,
                            identification_sections(result, figures), date=date,
                            command=command, kind="identify", conclusion=conclusion(result))
