"""The report of a design search (``fi-design recommend --report``)."""

from __future__ import annotations

from typing import Any

from ..results.recommend import RecommendResult
from .blocks import FigureBlock, Section, Table, figure_block
from .context import build_context, document_context
from .filters import num, qty
from .meta import TITLES

__all__ = ["recommend_context"]


def _design_rows(result: RecommendResult) -> tuple[tuple[str, str, str], ...]:
    d, sd, m = result.design, result.spec_design, result.margins
    rows = [("Stroke", qty(sd["stroke"], "m"), qty(d.stroke, "m")),
            ("Drive stiffness", qty(sd["stiffness"], "N/m"), qty(d.stiffness, "N/m")),
            ("Joint damping", "", "default ratio" if d.damping is None
             else qty(d.damping, "N*s/m")),
            ("Crossover", qty(sd["crossover"], "Hz"), qty(d.crossover, "Hz")),
            ("No move hunts from", "", qty(d.hunting_free_from, "Hz")),
            ("Crossover factor", "", num(m.get("crossover_factor"), 3)),
            ("k_max / k", "", num(m.get("stiffness_factor"), 3)),
            ("End-stop clearance at rest", "", qty(m.get("end_stop_clearance"), "m")),
            ("Not settling under friction scatter", "",
             "" if d.unsettled_probability is None
             else qty(100 * d.unsettled_probability, "%"))]
    return tuple(rows)


@build_context.register
def recommend_context(result: RecommendResult, *, date: Any = None, command: str | None = None,
                      figures: bool = True) -> dict:
    """The report context of a design search: the design, what binds it, the design space.

    Parameters
    ----------
    result : fi_design.results.recommend.RecommendResult
        The search.
    date : str or datetime.date, optional
        Report date.
    command : str, optional
        The command line.
    figures : bool, optional
        Render the figures (default).

    Returns
    -------
    dict
        For :func:`~fi_design.report.render.render_html`.
    """
    from .. import plots

    head = "Recommended design" if result.feasible else "Nearest design (none passes)"
    table = Table(("Quantity", "As specified", "Recommended" if result.feasible else "Nearest"),
                  _design_rows(result), caption=head)
    paras = [result.advice]
    if result.binding:
        paras.append("What binds it: " + "; ".join(result.binding) + ".")
    if result.violates:
        paras.append("What the nearest design violates: " + " ".join(result.violates))
    figs: tuple[FigureBlock, ...] = ()
    if figures:
        import matplotlib

        with matplotlib.rc_context(plots.REPORT_RC):
            fig = plots.recommend_figure(result)
        figs = (figure_block(fig, "The design space: every point of the search, coloured by "
                                  "what it fails first; dashed, k_max = Fs / stroke; the "
                                  "spec's design a cross, the recommended one a star.",
                             name="design-space"),)
    counts: dict[str, int] = {}
    for c in result.candidates:
        counts[c.status] = counts.get(c.status, 0) + 1
    space = Table(("Status", "Points"), tuple((plots.CANDIDATE_LOOK.get(k, (None, k))[1], num(v))
                                              for k, v in counts.items()),
                  caption="Points of the design space")
    method = (f"{len(result.strokes)} strokes from {qty(result.strokes[0], 'm')} to "
              f"{qty(result.strokes[-1], 'm')} and {len(result.stiffnesses)} stiffnesses from "
              f"{qty(result.stiffnesses[0], 'N/m')} to {qty(result.stiffnesses[-1], 'N/m')} "
              "(log-spaced); each point is judged by the constraints of the sign-off, the cheap "
              "ones first: k_max, the flexure, the loop margins at the highest crossover they "
              "allow, then every move of the family at that crossover, then the hunting-free "
              "crossover, and the full sign-off (friction scatter included) for the best points "
              f"in the order of the objective until one passes. {result.evaluations} stage-level "
              f"evaluations in {num(result.wall_time, 3)} s.")
    sections = [Section("recommendation", head, paragraphs=tuple(paras), tables=(table,)),
                Section("design-space", "The design space", paragraphs=(method,),
                        tables=(space,), figures=figs)]
    return document_context(TITLES["recommend"], result.spec, sections, date=date,
                            command=command, kind="recommend", conclusion=result.advice,
                            source=result.fi_design_source)
