"""The reconciliation report: which effect the model misses, and the gap before and after.

Built from :class:`fi_design.reconciliation.ReconcileResult` as generic report
sections (:class:`fi_design.report.Section`) and rendered with the report
engineer's templates through :func:`fi_design.report.render_document`: the
same title block, layout, escaping and appendix as the design report. All
wording and number formatting happens here, in Python; the templates only
place it.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from . import effects as _effects


def _param_unit(effect: str, name: str) -> str:
    try:
        return _effects.get(effect).parameter(name).unit
    except KeyError:
        return ""


def _params_text(effect: str, values: dict, unc: dict | None = None) -> str:
    from .report import qty

    parts = []
    for k, v in values.items():
        if v is None:
            continue
        unit = _param_unit(effect, k)
        text = f"{k} = {qty(v, unit if unit not in ('1', 'rad') else '')}"
        if unit == "rad":
            text += " rad"
        s = (unc or {}).get(k)
        if s:
            text += f" ± {qty(s, unit if unit not in ('1', 'rad') else '', 2)}"
        parts.append(text)
    return ", ".join(parts)


def gap_sections(result: Any, figures: bool = True) -> list:
    """Report sections of a reconciliation.

    Parameters
    ----------
    result : fi_design.reconciliation.ReconcileResult
        The reconciliation.
    figures : bool, optional
        Draw the figures (False: captions only, for golden tests).

    Returns
    -------
    list of fi_design.report.Section
        Finding, gap before and after, candidates, signatures, method.
    """
    from .report import FigureBlock, Section, Table, figure_block, num, qty

    def fig(make, caption, name):
        if not figures:
            return FigureBlock(None, caption, name)
        return figure_block(make(result), caption, name)

    from . import plots

    meas = result.measurement
    finding = [result.conclusion]
    if result.effect != "none":
        finding.append(f"Fitted parameters (SI, one standard deviation): "
                       f"{_params_text(result.effect, result.parameters, result.uncertainty)}.")
    finding.append(
        f"Measured trace: {meas.source or 'in memory'}, {meas.n} samples over "
        f"{num(meas.duration)} s ({', '.join(meas.columns)}). Model: "
        f"{'isolated (two-mass) plant' if result.isolated else 'stage without isolator'}, "
        f"driven by the measured reference and started at rest at the first sample.")
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
                      f"read from the data ({100 * lat.fraction:.0f} % of tested samples on it)"))
    notes = []
    if result.ambiguous:
        notes.append("Not decisively worse than the chosen effect: "
                     + ", ".join(result.ambiguous) + ".")
    for name, why in result.skipped.items():
        notes.append(f"{name}: {why}.")
    s1 = Section("finding", "Finding", paragraphs=tuple(finding),
                 tables=(Table(("Channel", "Noise (std)", "Source"), tuple(nrows),
                               caption="Noise levels every gap is judged against",
                               numeric=(False, True, False)),),
                 figures=(fig(plots.gap_overlay_figure,
                              "Measured trace (grey), nominal model (red, dashed) and corrected "
                              "model (blue). Shaded: holds with stick-slip, compared by "
                              "phase-free features.", "gap-overlay"),
                          fig(plots.gap_residual_figure,
                              "Measured minus modelled position; the grey band is two noise "
                              "standard deviations.", "gap-residual")),
                 notes=tuple(notes))

    def cell(v, unit):
        if v is None:
            return "-"
        if unit == "-":
            return num(v)
        return qty(v, unit)

    grows = []
    for g in result.gaps:
        flag = "" if g.significant_after is None else ("yes" if g.significant_after else "no")
        grows.append((g.name, g.unit, cell(g.measured, g.unit), cell(g.nominal, g.unit),
                      cell(g.corrected, g.unit), cell(g.before, g.unit), cell(g.after, g.unit),
                      cell(g.noise, g.unit), flag))
    s2 = Section("gap", "Gap before and after",
                 paragraphs=("Sample-wise measures compare the traces point by point in the "
                             "move, settle and hold segments; the features (hunting cycles, "
                             "amplitude, period, settling time, final error, error spread) stay "
                             "meaningful when stick-slip drifts out of phase. 'Beyond noise' "
                             "says whether the corrected model still misses by more than noise "
                             "explains.",),
                 tables=(Table(("Metric", "Unit", "Measured", "Nominal", "Corrected",
                                "Gap before", "Gap after", "Noise", "Beyond noise"),
                               tuple(grows), numeric=(False, False) + (True,) * 6 + (False,)),))
    crows = []
    for i, c in enumerate(result.candidates, 1):
        crows.append((str(i), c.name, num(c.score), f"{100 * c.explained:.1f} %",
                      _params_text(c.name, c.parameters, c.uncertainty),
                      str(c.n_simulations), c.message or ""))
    s3 = Section("candidates", "Candidate effects",
                 paragraphs=(f"Every catalogue effect was fitted by bounded least squares. Score: "
                             f"BIC difference against the model without it, with the variance "
                             f"rescaled by the fit's reduced chi-square; an effect is named when "
                             f"its score exceeds {num(result.threshold)}. 'Explained' is the "
                             f"share of the gap above noise that the fit removes.",),
                 tables=(Table(("#", "Effect", "Score", "Explained", "Fitted parameters (SI)",
                                "Simulations", "Note"), tuple(crows),
                               numeric=(True, False, True, True, False, True, False)),),
                 figures=(fig(plots.candidate_scores_figure,
                              "Candidate scores (signed log scale); chosen effects in blue.",
                              "gap-scores"),))
    srows = tuple((s.name, ", ".join(s.effects), f"{s.strength:.2f}",
                   "-" if s.value is None else f"{s.value:.4g} {s.unit}", s.detail)
                  for s in result.signatures)
    s4 = Section("signatures", "Signatures in the nominal residual",
                 paragraphs=("What the residual of the nominal model looks like, and which "
                             "effects each pattern points at. Signatures only give the fits "
                             "their starting values; the scores decide.",),
                 tables=(Table(("Signature", "Points at", "Strength (R²)", "Value", "Detail"),
                               srows, numeric=(False, False, True, True, False)),))
    seg_rows = tuple((s.kind, num(s.start), num(s.end),
                      "samples" if s.coherent else "features") for s in result.segments)
    s5 = Section("segments", "Segments",
                 tables=(Table(("Segment", "Start [s]", "End [s]", "Compared by"), seg_rows),))
    return [s1, s2, s3, s4, s5]


def render_gap_report(result: Any, path: str | os.PathLike, *, date: Any = None,
                      command: str | None = None) -> Path:
    """Write the reconciliation report (HTML or PDF).

    Parameters
    ----------
    result : fi_design.reconciliation.ReconcileResult
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
    from .report import render_document

    return render_document(path, title="Model-measurement reconciliation", spec=result.spec,
                           sections=gap_sections(result), date=date, command=command,
                           kind="reconcile")
