"""The report of a design search (``fi-design recommend --report``)."""

from __future__ import annotations

from typing import Any

from ..display import NBSP, quantities, quantity
from ..results.recommend import RecommendResult
from .blocks import FigureBlock, Section, Table, figure_block
from .context import build_context, document_context
from .filters import num, qty
from .meta import TITLES

__all__ = ["recommend_context", "STIFFNESS_ROW"]

#: The drive stiffness's row: the spec's column holds the joint's stiffness the analysis uses
#: (isolator.stiffness where given, which need not be its guide's net), the recommended one the
#: sized guide's, net of gravity.
STIFFNESS_ROW = "Drive stiffness k (recommended: the guide's, net of gravity)"


def _mm(x: float | None) -> str:
    # 3 digits, as the advice above the table and the console's table give the guide
    return "" if x is None else qty(x, "m", 3)


def _design_rows(result: RecommendResult) -> tuple[tuple[str, str, str], ...]:
    d, sd, m = result.design, result.spec_design, result.margins
    req = result.spec.requirements
    fx = result.flexure
    hm = m.get("hunting_margin")
    rows = [("Stroke", qty(sd["stroke"], "m", 3), qty(d.stroke, "m", 3)),
            ("Leaves L \u00d7 b \u00d7 t", "", "" if d.length is None else
             f"{_mm(d.length)} \u00d7 {_mm(d.width)} \u00d7 {_mm(d.thickness)}"),
            (STIFFNESS_ROW, qty(sd["stiffness"], "N/m"),
             qty(d.stiffness, "N/m")),
            ("Lowest parasitic mode", "", qty(d.lowest_mode, "Hz"))]
    if fx is not None and fx.mechanics is not None and \
            fx.mechanics.gravity.buckling_factor is not None:
        rows.append(("Buckling load / weight", "", num(fx.mechanics.gravity.buckling_factor, 3)))
    rows += [("Joint damping", "", "default ratio" if d.damping is None
              else qty(d.damping, "N*s/m", 3)),
             ("Crossover", qty(sd["crossover"], "Hz"), qty(d.crossover, "Hz")),
             ("No move hunts from", "", qty(d.hunting_free_from, "Hz")),
             (f"Hunting margin (required {num(req.hunting_margin, 3)})", "",
              "no cycle found" if hm is not None and hm == float("inf") else num(hm, 3)),
             ("k_max / k", "", num(m.get("stiffness_factor"), 3))]
    lo, hi = (fx.stiffness_range or (None, None)) if fx is not None else (None, None)
    if lo is not None and hi > lo:  # the stock's tolerance: k goes with t^3
        dt = quantity(fx.thickness_tolerance, "m", 3, shown=("mm", 1e3), sep=NBSP)
        rows.append((f"k over the leaves' tolerance (\u00b1{dt})", "",
                     f"{num(lo)} to {qty(hi, 'N/m')}"))
    rows += [("End-stop clearance at rest", "", qty(m.get("end_stop_clearance"), "m", 3)),
             ("Not settling under scatter", "",
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
    paras = []  # the advice itself is the document's summary (its conclusion), not repeated
    if result.binding:
        paras.append("What binds it: " + "; ".join(result.binding) + ".")
    paras += [f"On a bound: {n.text}." for n in result.flexure_bounds]
    if result.violates:
        paras.append("What the nearest design violates: " + " ".join(result.violates))
    paras += [f"Assumed: {a}." for a in result.assumptions]
    tables = [table]
    if result.reserves:
        tables.append(Table(("Reserve corner", "Passes", "Why not"),
                            tuple((r["name"], "yes" if r["passed"] else "no", r["why"])
                                  for r in result.reserves),
                            caption="The design with the reserve's deviations "
                                    "(requirements.reserve)"))
    lc = result.least_change
    least_paras: list[str] = []
    if lc is not None:
        if lc.feasible:
            least_paras.append(f"The least change of the spec that passes: {lc.text}.")
            tables.append(Table(("Spec path", "New value"), tuple(lc.changes.items()),
                                caption="The least change"))
        else:
            least_paras.append(f"Least change: {lc.text}"
                               + ("; build the recommended design." if result.feasible else "."))
        least_paras += [f"Tried first: {t}." for t in lc.tried]
    figs: tuple[FigureBlock, ...] = ()
    if figures:
        import matplotlib

        with matplotlib.rc_context(plots.REPORT_RC):
            fig = plots.recommend_figure(result)
        figs = (figure_block(fig, "Left, the design space: every guide the search built or "
                                  "judged, coloured by what it fails first; dashed, k_max = "
                                  "Fs / stroke; the spec's design a cross, the recommended one "
                                  "a star. Right, the trade-off: the hunting margin of every "
                                  "judged guide against its net drive stiffness, the Pareto "
                                  "front joined, the required margin dashed.",
                             name="design-space"),)
    counts: dict[str, int] = {}
    for c in result.candidates:
        counts[c.status] = counts.get(c.status, 0) + 1
    space = Table(("Status", "Points"), tuple((plots.CANDIDATE_LOOK.get(k, (None, k))[1], num(v))
                                              for k, v in counts.items()),
                  caption="Points of the design space")
    shortest, longest = quantities([result.strokes[0], result.strokes[-1]], "m", sep=NBSP)
    method = (f"Strokes from {shortest} to {longest} "
              "(log-spaced, widened towards the envelope while the best design lay on the "
              "range's edge), at each up to k_max = Fs / stroke; each point a guide sized from "
              "stock (stress, buckling, every parasitic mode at the separation times the "
              f"crossover), judged at {qty(result.crossover, 'Hz')} ({result.crossover_limit}) "
              "after every move of its family with the fold of its cycle; the stiffest that "
              "keeps the hunting margin refined, then signed off with its reserves, stiffest "
              f"first. {result.evaluations} stage-level evaluations in "
              f"{num(result.wall_time, 3)} s"
              + (" (read from the result cache: the same search of the same spec by the same "
                 "code, run earlier)." if result.from_cache is not None else "."))
    sections = [Section("recommendation", head, paragraphs=tuple(paras + least_paras),
                        tables=tuple(tables)),
                Section("design-space", "The design space and the trade-off",
                        paragraphs=(method,), tables=(space,), figures=figs)]
    return document_context(TITLES["recommend"], result.spec, sections, date=date,
                            command=command, kind="recommend", conclusion=result.advice,
                            source=result.fi_design_source)
