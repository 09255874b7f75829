"""The content of a report as plain data: one context builder per result type.

:func:`build_context` is a :func:`functools.singledispatch` function: each
report module registers the builder of its result type (the design report in
:mod:`fi_design.report.design`, the parameter studies in
:mod:`fi_design.report.study`, the design search in
:mod:`fi_design.report.recommend`, the reconciliation in
:mod:`fi_design.report.gap`, the identification in
:mod:`fi_design.report.identify`). :func:`document_context` builds the context of
a generic report from :class:`~fi_design.report.blocks.Section` values (the
parameter studies, the reconciliation and other commands' reports).
"""

from __future__ import annotations

import functools
from typing import Any, Sequence

from ..errors import ReportError
from .blocks import Section
from .meta import spec_listing, title_block, versions

__all__ = ["build_context", "document_context"]


@functools.singledispatch
def build_context(result: Any, *, date: Any = None, command: str | None = None,
                  figures: bool = True) -> dict:
    """Everything the report of a result shows, as plain data (for :func:`render_html`).

    Builders are registered per result type: a
    :class:`~fi_design.guideline.steps.DesignResult` (which also takes
    ``design_map``), :class:`~fi_design.studies.SweepResult`,
    :class:`~fi_design.studies.StudyResult`,
    :class:`~fi_design.studies.RobustnessResult`,
    :class:`~fi_design.results.recommend.RecommendResult`,
    :class:`~fi_design.results.reconciliation.ReconcileResult` and
    :class:`~fi_design.results.identification.IdentificationResult`. Any other object with
    ``report_sections()`` (a list of :class:`Section`) and ``report_title`` is
    reported through :func:`document_context`.

    Parameters
    ----------
    result : object
        The result to report.
    date : str or datetime.date, optional
        Report date; default today (or ``SOURCE_DATE_EPOCH``).
    command : str, optional
        The command line, shown in the title block.
    figures : bool, optional
        Draw the figures (default); False leaves every ``svg`` None.

    Returns
    -------
    dict
        ``meta`` (title block), ``sections`` (id, number, title, template)
        and the data of each section under its id.

    Raises
    ------
    fi_design.errors.ReportError
        There is no report for this kind of result (a ``TypeError`` too).
    """
    if hasattr(result, "report_sections"):
        return document_context(getattr(result, "report_title", "Report"), result.spec,
                                result.report_sections(), date=date, command=command,
                                kind=getattr(result, "report_kind", "report"),
                                source=getattr(result, "fi_design_source", None))
    raise ReportError(f"no report for a {type(result).__name__}; expected a DesignResult, a "
                      "sweep result or an object with report_sections()")


def document_context(title: str, spec: Any, sections: Sequence[Section], *, date: Any = None,
                     command: str | None = None, kind: str = "report",
                     conclusion: str = "", source: Any = None) -> dict:
    """The context of a generic report: title block, :class:`Section` values, appendix.

    Parameters
    ----------
    title : str
        Report title (under the project name).
    spec : fi_design.spec.Spec
        The spec the work started from (title block, appendix).
    sections : sequence of Section
        The content, in order.
    date : str or datetime.date, optional
        Report date.
    command : str, optional
        The command line.
    kind : str, optional
        Short kind (``"sweep"``, ``"reconcile"``): it sets the document id
        (:meth:`fi_design.spec.ReportInfo.id_for`).
    conclusion : str, optional
        A paragraph shown first, under "Summary".
    source : fi_design.provenance.Source, optional
        The code that computed the result; default the running package's.

    Returns
    -------
    dict
        For :func:`~fi_design.report.render.render_html`.
    """
    from markupsafe import Markup

    ctx: dict[str, Any] = {"meta": title_block(spec, kind, date=date, command=command,
                                               title=title, source=source)}
    entries = []
    if conclusion:
        sections = [Section("summary", "Summary", paragraphs=(conclusion,))] + list(sections)
    figure_number = 0
    for number, s in enumerate(sections, 1):
        entries.append({"id": s.id, "title": s.title, "template": "generic.html.jinja",
                        "number": number})
        figures = []
        for f in s.figures:
            figure_number += 1
            figures.append({"name": f.name, "caption": f.caption,
                            "svg": None if f.svg is None else Markup(f.svg), "width": f.width,
                            "number": figure_number})
        ctx[s.id] = {"paragraphs": list(s.paragraphs),
                     "tables": [t.as_context() for t in s.tables],
                     "figures": figures, "notes": list(s.notes)}
    ctx["appendix"] = {**spec_listing(spec), "solver": [], "versions": versions()}
    entries.append({"id": "appendix", "title": "Appendix: spec and software",
                    "template": "appendix.html.jinja", "number": len(entries) + 1})
    ctx["sections"] = entries
    return ctx
