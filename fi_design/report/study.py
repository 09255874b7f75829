"""Reports of the parameter studies: a sweep, the paper's four maps, robustness."""

from __future__ import annotations

from typing import Any

from ..display import AXIS_SCALES, NBSP, axis_unit, percent, quantity
from ..results.studies import RobustnessResult, StudyResult, SweepResult
from .blocks import FigureBlock, Section, Table, figure_block
from .context import build_context, document_context
from .filters import num, qty
from .meta import TITLES

__all__ = ["sweep_context", "study_context", "robustness_context", "sweep_section"]


def _axis_qty(value: Any, axis: Any) -> str:
    """A value of an axis in the axis's unit where that follows its values (a delay of 1 to
    2 ms, its design point 1 ms, not 0.001 s), else as :func:`qty` shows it."""
    if axis.unit not in AXIS_SCALES or value is None:
        return qty(value, axis.unit)
    return quantity(value, axis.unit, sep=NBSP, shown=axis_unit(axis.unit, axis.values))


def _axis_text(axis: Any) -> str:
    from ..plots import quantity_name

    vals = list(axis.values)
    return (f"{quantity_name(axis.path).lower()} ({axis.path}): {len(vals)} values from "
            f"{_axis_qty(vals[0], axis)} to {_axis_qty(vals[-1], axis)}"
            f"{' (log)' if axis.log else ''}")


#: What a map's colour shows, by the study's measure (the figure's colour bar says the same).
_FIGURE_MEASURES = {"stage": "Peak to peak of the cycle some move of the family ends in",
                    "move": "Hunting cycles of the spec's own move in the counting window"}


def sweep_section(result: SweepResult, sid: str, title: str, lead: str = "",
                  figures: bool = True) -> Section:
    """One map of hunting cycles as a report section: axes, design point, counts, figure.

    Parameters
    ----------
    result : fi_design.studies.SweepResult
        The map (or line).
    sid : str
        Section id.
    title : str
        Section title.
    lead : str, optional
        A first paragraph.
    figures : bool, optional
        Draw the figure (default).

    Returns
    -------
    Section
    """
    from .. import plots

    counts = result.counts()
    plant = "with isolator" if result.isolated else "without isolator"
    paras = [p for p in (lead,) if p]
    axes = [_axis_text(result.x)] + ([_axis_text(result.y)] if result.y is not None else [])
    paras.append(f"Simulated {plant}; " + "; ".join(axes) + ". Design point: "
                 + ", ".join(_axis_qty(v, a) if v is not None else "n/a"
                             for v, a in zip(result.design_point,
                                             [result.x] + ([result.y] if result.y else [])))
                 + ".")
    paras += [f"Note: {n}." for n in result.notes]
    rows = tuple((k, num(v)) for k, v in counts.items())
    table = Table(("Verdict", "Points"), rows, caption="Points per verdict")
    figs: tuple[FigureBlock, ...] = ()
    if figures:
        import matplotlib

        with matplotlib.rc_context(plots.REPORT_RC):
            fig = plots.sweep_figure(result, title="")
        names = [plots.axis_label(a.path, a.unit, a.values) for a in (result.y, result.x)
                 if a is not None]
        figs = (figure_block(fig, f"{_FIGURE_MEASURES.get(result.measure, 'Hunting cycles')} "
                                  f"({plant}) over {' and '.join(names)}.", name=sid),)
    return Section(sid, title, paragraphs=tuple(paras), tables=(table,), figures=figs)


@build_context.register
def sweep_context(result: SweepResult, *, date: Any = None, command: str | None = None,
                  figures: bool = True) -> dict:
    """The report context of a sweep.

    Parameters
    ----------
    result : fi_design.studies.SweepResult
        The sweep.
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
    sections = [sweep_section(result, "sweep", "Hunting map", figures=figures)]
    return document_context(TITLES["sweep"], result.spec, sections, date=date, command=command,
                            kind="sweep", source=result.fi_design_source)


@build_context.register
def study_context(result: StudyResult, *, date: Any = None, command: str | None = None,
                  figures: bool = True) -> dict:
    """The report context of the paper's study: one section per map.

    Parameters
    ----------
    result : fi_design.studies.StudyResult
        The study.
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
    sections = [sweep_section(m.result, f"map-{m.definition.key.lower()}",
                              f"Map {m.definition.key}: {m.definition.title}",
                              lead=f"Paper: {m.definition.paper}.", figures=figures)
                for m in result.maps]
    return document_context(TITLES["study"], result.spec, sections, date=date, command=command,
                            kind="study", source=result.fi_design_source)


@build_context.register
def robustness_context(result: RobustnessResult, *, date: Any = None,
                       command: str | None = None, figures: bool = True) -> dict:
    """The report context of a robustness study: probabilities of hunting and their intervals.

    Parameters
    ----------
    result : fi_design.studies.RobustnessResult
        The study.
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

    rows = []
    for label, p in (("with isolator", result.isolated), ("without isolator",
                                                          result.not_isolated)):
        if p is None:
            continue
        rows.append((label, num(p.hunting), num(p.valid),
                     percent(p.probability, 3),
                     f"{percent(p.low, 3)} \u2013 {percent(p.high, 3)}"))
    table = Table(("Plant", "Hunting", "Valid samples", "Probability", "Confidence interval"),
                  tuple(rows), caption="Probability of hunting under the scatter")
    figs: tuple[FigureBlock, ...] = ()
    if figures:
        import matplotlib

        with matplotlib.rc_context(plots.REPORT_RC):
            fig = plots.robustness_figure(result, title="")
        figs = (figure_block(fig, "Probability of hunting with its confidence interval.",
                             name="robustness", width="half"),)
    sections = [Section("robustness", "Probability of hunting",
                        paragraphs=(_robustness_lead(result),),
                        tables=(_scatter_table(result), table, _verdict_table(result)),
                        figures=figs)]
    return document_context(TITLES["robustness"], result.spec, sections, date=date,
                            command=command, kind="robustness", source=result.fi_design_source)


#: What one sample's verdict judges, by the study's measure.
_MEASURES = {"stage": "after every move of its family (it hunts when some move ends in a "
                      "hunting cycle)",
             "move": "after the spec's own move, by the paper's metric"}


def _robustness_lead(result: RobustnessResult) -> str:
    """What a robustness study drew and how it judged: the paragraph above its tables."""
    samples = result.samples
    ripple = ""
    if result.position_friction is not None:
        pf = result.position_friction
        ripple = (f"; friction varies along the rail by {percent(pf.amplitude, 3)} with a "
                  f"{qty(pf.wavelength, 'm')} wavelength, at a phase each sample draws")
    conf = result.not_isolated.confidence
    plants = ("with and without the isolator" if result.isolated is not None
              else "without isolator (the spec has none)")
    return (f"{num(samples)} sample{'s' if samples != 1 else ''} of the spec, each value "
            f"below drawn from a {result.distribution} distribution around its nominal value "
            f"(seed {result.seed}){ripple}; each sample simulated {plants} and judged "
            f"{_MEASURES.get(result.measure, result.measure)}. The "
            f"probability is among the valid samples, with its {percent(conf, 2)} Wilson "
            "interval.")


def _scatter_table(result: RobustnessResult) -> Table:
    """The scattered spec values with their spreads, as the console prints them."""
    rows = []
    for sc, unit in zip(result.scatter, result.units or ("",) * len(result.scatter)):
        spread = f"{percent(sc.spread, 3)} of nominal" if sc.relative else qty(sc.spread, unit)
        rows.append((sc.path + (f" ({sc.meaning})" if sc.meaning else ""), spread))
    width = "half-width" if result.distribution == "uniform" else "standard deviation"
    return Table(("Spec value", f"Spread ({width})"), tuple(rows),
                 caption="Scattered spec values")


def _verdict_table(result: RobustnessResult) -> Table:
    """Every sample counted by its verdict, per plant."""
    plants = [(label, p) for label, p in (("with isolator", result.isolated),
                                          ("without isolator", result.not_isolated))
              if p is not None]
    verdicts = [v for v in ("settled", "hunting", "stuck", "undetermined", "buckled",
                            "invalid", "failed")
                if v != "buckled" or any(p.counts.get(v, 0) for _, p in plants)]
    rows = tuple((v, *(num(p.counts.get(v, 0)) for _, p in plants)) for v in verdicts)
    return Table(("Verdict", *(label for label, _ in plants)), rows,
                 caption="Samples per verdict")
