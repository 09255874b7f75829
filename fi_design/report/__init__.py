"""Sign-off reports: one self-contained HTML file, or a PDF made from the same HTML.

Presentation only: a report reads a finished result and never computes one.

How a report is made
--------------------
1. :func:`build_context` turns a result into plain data: strings, SI floats
   with their unit, lists and dicts. It is a :func:`functools.singledispatch`
   function with one builder per result type: :mod:`.design` (a
   :class:`~fi_design.guideline.steps.DesignResult`, optionally with a
   :class:`~fi_design.studies.DesignMap` computed by the caller), :mod:`.study`
   (sweeps, the paper's study, robustness), :mod:`.recommend` (a design
   search), :mod:`.gap` (a reconciliation: :func:`gap_context`) and
   :mod:`.identify` (friction identified from a record:
   :func:`identification_context`). All arithmetic, comparison and wording
   happens in these builders; the golden tests compare the contexts (with
   ``figures=False``).
2. Figures come from :mod:`fi_design.plots` (``matplotlib.figure.Figure``,
   never pyplot) and are inlined as SVG; equations are drawn by matplotlib's
   mathtext to SVG as well (:mod:`.equations`), so the HTML and the PDF show
   the same pictures and the HTML makes no external request. A PDF carries
   them as 200 dpi images, the figures placed by name and drawn when the
   layout reaches them, or meanwhile by a worker (:func:`report_figures`).
3. :mod:`.render` holds the one jinja environment (autoescape,
   ``StrictUndefined``, the number filters of :mod:`.filters`) and writes the
   HTML, or the PDF through WeasyPrint (A4, page numbers, the document id and
   revision in the running header), atomically.

The reports of studies, reconciliations, design searches and identifications
are lists of :class:`Section` values with :class:`Table` and :class:`FigureBlock` values
(:func:`figure_block`), written by :func:`render_document` with the same title
block, layout and appendix::

    from fi_design.report import Section, Table, figure_block, render_document
    sections = [Section("summary", "Summary", paragraphs=("...",),
                        tables=(Table(("Effect", "Score"), rows),),
                        figures=(figure_block(fig, "Gap before and after"),))]
    render_document("out.html", title="...", spec=spec, sections=sections, kind="identify")

Reproducibility: the same result gives the same HTML apart from the date
(passed in; the CLI uses today, or ``SOURCE_DATE_EPOCH`` when set):
matplotlib's SVG ids are salted with a fixed string and carry no date, and
solver wall times are left out.
"""

from __future__ import annotations

from . import design, identify, recommend, study  # noqa: F401  (register the context builders)
from .blocks import FigureBlock, Section, Table, figure_block
from .checks import check_label, check_row
from .context import build_context, document_context
from .equations import math_text
from .filters import display_scale, num, qty, tex_num, tex_qty, unit_text
from .gap import gap_context, gap_sections, render_gap_report
from .identify import identification_context, identification_sections
from .meta import report_date
from .render import (FORMATS, environment, output_format, render_document, render_html,
                     render_report, report_figures, template_dir, write_document)

__all__ = [
    "FORMATS", "FigureBlock", "Section", "Table", "build_context", "check_label", "check_row",
    "display_scale", "document_context", "environment", "figure_block", "gap_context",
    "gap_sections", "identification_context", "identification_sections", "math_text", "num", "output_format", "qty", "render_document",
    "render_gap_report", "render_html", "render_report", "report_date", "report_figures",
    "template_dir",
    "tex_num", "tex_qty", "unit_text", "write_document",
]
