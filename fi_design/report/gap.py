"""The reconciliation report: which effect the model misses, and the gap before and after.

Built from :class:`fi_design.results.reconciliation.ReconcileResult` as generic report
sections (:class:`~fi_design.report.blocks.Section`, :func:`gap_sections`) and
rendered like every other report (:func:`gap_context`,
:func:`render_gap_report`): the same title block, layout, escaping and
appendix as the design report. All wording and number formatting happens
here, in Python; the templates only place it.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from .. import effects as _effects
from ..results.reconciliation import ReconcileResult
from .blocks import FigureBlock, Section, Table, figure_block
from .context import build_context, document_context
from ..display import NBSP, fixed, percent, scale
from .filters import num, qty

__all__ = ["gap_sections", "gap_context", "render_gap_report", "TITLE"]

#: Title of the reconciliation report.
TITLE = "Model-measurement reconciliation"


def _params_text(effect: str, values: dict, unc: dict | None = None) -> str:
    return _effects.values_text(effect, values, unc, sep=NBSP)


def _overlay_caption(result: Any) -> str:
    """What the overlay draws: the traces there are, the shading where segments have it."""
    text = "Measured trace (wide grey line, underneath), nominal model (red, dashed)"
    if result.effects:
        text += (f" and the model corrected by {', '.join(result.effects)} (blue, thin, on top: "
                 "where it follows the measurement the grey shows around it)")
    text += "."
    if any(not seg.coherent for seg in result.segments):
        text += " Shaded: holds with stick-slip, compared by phase-free features."
    failed = [n for n, run in (("nominal", result.nominal), ("corrected", result.corrected))
              if (n == "nominal" or result.effects) and not run.success]
    if failed:
        text += f" The {' and '.join(failed)} run failed and is drawn as far as it got."
    return text


def _short(reasons: tuple) -> str:
    """The first reason a candidate was not named, for a table cell."""
    return reasons[0] if reasons else ""


def gap_sections(result: Any, figures: bool = True) -> list:
    """Report sections of a reconciliation.

    Parameters
    ----------
    result : fi_design.results.reconciliation.ReconcileResult
        The reconciliation.
    figures : bool, optional
        Draw the figures (False: captions only, for golden tests).

    Returns
    -------
    list of fi_design.report.Section
        Structure (when the model's structure misses the record), finding,
        effects one by one, gap before and after, candidates, signatures,
        segments.
    """
    from .. import plots

    def fig(make, caption, name):
        if not figures:
            return FigureBlock(None, caption, name)
        return figure_block(make(result), caption, name)

    sections = []
    diag = result.diagnosis
    if diag.mismatch:
        crows = tuple((c.name.replace("_", " "), percent(c.share, 2), c.detail)
                      for c in diag.causes)
        figs = ()
        if len(diag.frequency):
            figs = (fig(plots.structure_figure,
                        f"The nominal model's {diag.channel} residual over time and its amplitude "
                        "spectrum, with the loop's crossover and a third of it marked.",
                        "gap-structure"),)
        sections.append(Section(
            "structure", "The model's structure misses the record", paragraphs=(diag.message,),
            tables=(Table(("Likely cause", "Share of the residual", "What was measured"), crows,
                          caption="Shares are of the residual's energy ("
                                  + ("measured force" if result.drive == "force" else "controller")
                                  + ", initial state, disturbance) or its R² (mass)",
                          numeric=(False, True, False)),) if crows else (),
            figures=figs))
    meas = result.measurement
    finding = [result.conclusion]
    if result.effect != "none":  # the conclusion gives the values: say what their ± is
        finding.append("The uncertainties (\u00b1) are one standard deviation: the fit's "
                       "covariance in effective samples (or the block jackknife's error where "
                       "larger), with the same fit's error on a noise-only record and the "
                       "numerical error added in quadrature.")
    finding.append(
        f"Measured trace: {meas.source or 'in memory'}, {meas.n} samples over "
        f"{num(meas.duration)} s ({', '.join(meas.columns)}). Model: "
        f"{'isolated (two-mass) plant' if result.isolated else 'stage without isolator'}, "
        + ("driven by the measured reference and started from the state in the data"
           if result.drive == "closed" else
           "driven open loop by the measured force in windows re-anchored to the data")
        + (f"; initial command {qty(result.initial_command, 'N')} (fitted within the force "
           "noise)" if result.initial_command is not None else "") + ".")
    noise = result.noise
    nrows = [("position", qty(noise.position, "m"), noise.source.get("position", ""))]
    if noise.force is not None:
        nrows.append(("force", qty(noise.force, "N"), noise.source.get("force", "")))
    if noise.deflection is not None:
        nrows.append(("deflection", qty(noise.deflection, "m"),
                      noise.source.get("deflection", "")))
    lat = result.lattice
    if lat.found:
        nrows.append(("position lattice step", qty(lat.step, "m"),
                      f"read from the data ({percent(lat.fraction, 3)} of tested samples on it, "
                      f"chance {percent(lat.chance, 2)})"))
    notes = [f"Position lattice: {lat.detail}."]
    if result.ambiguous:
        notes.append("Not decisively worse than the chosen effect: "
                     + ", ".join(result.ambiguous) + ".")
    for name, why in result.skipped.items():
        notes.append(f"{name}: {why}.")
    if not result.nominal.success:
        notes.append(f"The nominal model's simulation failed: {result.nominal.message}.")
    if result.effects and not result.corrected.success:
        notes.append(f"The corrected model's simulation failed: {result.corrected.message}.")
    sections.append(Section(
        "finding", "Finding", paragraphs=tuple(finding),
        tables=(Table(("Channel", "Noise (std)", "Source"), tuple(nrows),
                      caption="Noise levels every gap is judged against",
                      numeric=(False, True, False)),),
        figures=(fig(plots.gap_overlay_figure, _overlay_caption(result), "gap-overlay"),
                 fig(plots.gap_residual_figure,
                     "Measured minus modelled position; the grey band is two noise "
                     "standard deviations.", "gap-residual")),
        notes=tuple(notes)))
    if result.steps:
        srows = []
        for i, st in enumerate(result.steps, 1):
            srows.append((str(i), st.name, _params_text(st.name, st.parameters, st.uncertainty),
                          f"{num(st.misfit_before)} → {num(st.misfit_after)}",
                          f"{qty(st.position_rms_before, 'm')} → {qty(st.position_rms_after, 'm')}",
                          "\u2013" if st.force_rms_before is None else
                          f"{qty(st.force_rms_before, 'N')} → {qty(st.force_rms_after, 'N')}"))
        sections.append(Section(
            "effects", "Effects found, in order",
            paragraphs=("Each effect was searched on the gap the ones before it leave, and "
                        "refitted with them; each row is the gap it closed.",),
            tables=(Table(("#", "Effect", "Parameters", "Misfit", "Position RMS",
                           "Force RMS"), tuple(srows),
                          numeric=(True, False, False, True, True, True)),)))
    grows = []
    for g in result.gaps:
        flag = "" if g.significant_after is None else ("yes" if g.significant_after else "no")
        values = (g.measured, g.nominal, g.corrected, g.before, g.after, g.noise)
        shown, factor = scale(g.unit, values)  # one unit per row, named in the unit column
        grows.append((g.name, shown or "\u2013",
                      *("\u2013" if v is None else num(v * factor) for v in values), flag))
    sections.append(Section(
        "gap", "Gap before and after",
        paragraphs=("Sample-wise measures compare the traces point by point in the move, settle "
                    "and hold segments; the features (hunting cycles, amplitude, period, "
                    "settling time, final error, error spread) stay meaningful when stick-slip "
                    "drifts out of phase. 'Beyond noise' says whether the corrected model still "
                    "misses by more than noise explains." if grows else
                    "No gap table: the nominal model did not run through the record, so there "
                    "is no gap to measure (the finding above says what failed).",),
        tables=(Table(("Metric", "Unit", "Measured", "Nominal", "Corrected", "Gap before",
                       "Gap after", "Noise", "Beyond noise"), tuple(grows),
                      numeric=(False, False) + (True,) * 6 + (False,)),) if grows else ()))
    crows = []
    for i, c in enumerate(result.candidates, 1):
        dist = ", ".join(f"{k} {'+' if v >= 0 else ''}{num(v, 3)}"  # signed: which side
                         for k, v in c.distance.items() if v is not None)
        crows.append((str(i), c.name, "named" if c.name in result.effects else c.status,
                      num(c.score), percent(c.explained, 3),
                      _params_text(c.name, c.parameters, c.uncertainty), dist or "\u2013",
                      f"{c.n_failed} of {c.n_simulations}" if c.n_failed else
                      str(c.n_simulations), _short(c.reasons)))
    if not result.candidates:  # nothing was fitted: say why, with no empty table or figure
        sections.append(Section("candidates", "Candidate effects", paragraphs=(
            "No catalogue effect was fitted: " + (
                "the nominal model agrees with the measurement within noise, so there is no "
                "gap for an effect to explain." if not result.diagnosis.mismatch else
                "the diagnosis above says why the record or the nominal model does not allow "
                "a fit."),)))
    else:
        sections.append(Section(
            "candidates", "Candidate effects",
            paragraphs=(f"Every applicable catalogue effect was fitted by bounded least "
                        f"squares (bounds widened up to twice where a fit ended on one). An "
                        f"effect is named only when its simulation ran, its fit is off every "
                        f"bound, its score (the improvement in effective samples less k ln "
                        f"n_eff) exceeds {num(result.threshold)}, it removes at least half the "
                        f"gap above noise, a parameter lies three standard errors from the "
                        f"model's own value (a force limit from the peak force, above which it "
                        f"never acts; a parameter without a standard error is not shown to "
                        f"differ), and a refit on a noise-only record improves three times "
                        f"less. Distances are in those standard errors; runs that failed or ran "
                        f"away (an unstable loop) scored ten times the nominal misfit and could "
                        f"never win.",),
            tables=(Table(("#", "Effect", "Status", "Score", "Explained", "Fitted parameters",
                           "Distance from the model's value", "Simulations (failed)",
                           "Why not named"), tuple(crows),
                          numeric=(True, False, False, True, True, False, False, True, False)),),
            figures=(fig(plots.candidate_scores_figure,
                         "Candidate scores (signed log scale); named effects in blue.",
                         "gap-scores"),)))
    srows = tuple((s.name, ", ".join(s.effects), fixed(s.strength, 2),
                   "\u2013" if s.value is None else qty(s.value, s.unit, 4), s.detail)
                  for s in result.signatures)
    sections.append(Section(
        "signatures", "Signatures in the nominal residual",
        paragraphs=("What the residual of the nominal model looks like, and which effects each "
                    "pattern points at. Signatures only give the fits their starting values; "
                    "the tests decide.",),
        tables=(Table(("Signature", "Points at", "Strength (R²)", "Value", "Detail"), srows,
                      numeric=(False, False, True, True, False)),)))
    seg_rows = tuple((s.kind, num(s.start), num(s.end),
                      "samples" if s.coherent else "features") for s in result.segments)
    sections.append(Section("segments", "Segments",
                            tables=(Table(("Segment", "Start [s]", "End [s]", "Compared by"),
                                          seg_rows),)))
    return sections


@build_context.register(ReconcileResult)
def gap_context(result: Any, *, date: Any = None, command: str | None = None,
                figures: bool = True) -> dict:
    """The report context of a reconciliation.

    Parameters
    ----------
    result : fi_design.results.reconciliation.ReconcileResult
        The reconciliation.
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
    """
    return document_context(TITLE, result.spec, gap_sections(result, figures), date=date,
                            command=command, kind="reconcile")


def render_gap_report(result: Any, path: str | os.PathLike, *, date: Any = None,
                      command: str | None = None) -> Path:
    """Write the reconciliation report (HTML or PDF).

    Parameters
    ----------
    result : fi_design.results.reconciliation.ReconcileResult
        The reconciliation.
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
    """
    from .render import output_format, render_html, write_document

    out = Path(path)
    output_format(out)  # refuse a wrong extension before any work
    return write_document(render_html(gap_context(result, date=date, command=command)), out)
