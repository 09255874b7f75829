"""The building blocks of generic report sections: tables, figures and sections.

Other reports than the design report (parameter studies, the reconciliation,
friction identification) are lists of :class:`Section` values, each with
paragraphs, :class:`Table` values and :class:`FigureBlock` values, rendered by
``generic.html.jinja`` (:func:`fi_design.report.render_document`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

__all__ = ["Table", "FigureBlock", "Section", "figure_block", "figure_entry"]


@dataclass(frozen=True)
class Table:
    """A table for a generic report section.

    Attributes
    ----------
    columns : tuple of str
        Column headers (with the unit in brackets where the cells are numbers).
    rows : tuple of tuple of str
        Cell texts, already formatted (use :func:`~fi_design.report.filters.num`
        and :func:`~fi_design.report.filters.qty`).
    caption : str
        Caption above the table.
    numeric : tuple of bool
        Right-align the column; default: every column but the first.
    """

    columns: tuple[str, ...]
    rows: tuple[tuple[str, ...], ...]
    caption: str = ""
    numeric: tuple[bool, ...] = ()

    def as_context(self) -> dict:
        """Plain data for the templates."""
        numeric = self.numeric or tuple(i > 0 for i in range(len(self.columns)))
        return {"caption": self.caption,
                "columns": [{"text": c, "numeric": bool(n)} for c, n in zip(self.columns, numeric)],
                "rows": [[{"text": str(cell), "numeric": bool(n)} for cell, n in zip(row, numeric)]
                         for row in self.rows]}


@dataclass(frozen=True)
class FigureBlock:
    """A figure for a report: inline SVG and a caption.

    Attributes
    ----------
    svg : str or None
        The figure's element (:func:`fi_design.plots.figure_markup`: inline
        ``<svg>``, or an ``<img>`` in a PDF); None leaves
        only the caption (the golden tests build contexts without figures).
    caption : str
        Caption below the figure.
    name : str
        Short identifier (the SVG id prefix).
    width : str
        ``"full"`` (text width) or ``"half"`` (two side by side).
    """

    svg: str | None
    caption: str
    name: str = "figure"
    width: str = "full"


def figure_block(fig: Any, caption: str, name: str = "figure", width: str = "full") -> FigureBlock:
    """Turn a matplotlib figure into a :class:`FigureBlock` with inline SVG.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure (never pyplot).
    caption : str
        Caption.
    name : str, optional
        Identifier; must be unique within a report (it prefixes the SVG ids).
    width : {"full", "half"}, optional
        Text width or half of it.

    Returns
    -------
    FigureBlock
    """
    from ..plots import figure_markup

    return FigureBlock(svg=figure_markup(fig, name), caption=caption, name=name, width=width)


@dataclass(frozen=True)
class Section:
    """A generic report section: paragraphs, then tables, then figures.

    Attributes
    ----------
    id : str
        Anchor (letters, digits, ``-``).
    title : str
        Heading.
    paragraphs : tuple of str
        Plain text paragraphs (escaped, never HTML).
    tables : tuple of Table
        Tables.
    figures : tuple of FigureBlock
        Figures.
    notes : tuple of str
        Bulleted notes after the figures.
    """

    id: str
    title: str
    paragraphs: tuple[str, ...] = ()
    tables: tuple[Table, ...] = ()
    figures: tuple[FigureBlock, ...] = ()
    notes: tuple[str, ...] = ()


def figure_entry(make: Callable[[], Any] | None, name: str, caption: str, number: int,
                 width: str = "full") -> dict:
    """A numbered figure of the design report, as the templates read it.

    Parameters
    ----------
    make : callable or None
        Returns the :class:`matplotlib.figure.Figure`; None leaves ``svg``
        None (contexts without figures). Called here, or later within
        :func:`fi_design.plots.deferred_figures` (a PDF's figures).
    name : str
        Identifier (``fig-NAME`` anchor and SVG id prefix).
    caption : str
        Caption.
    number : int
        Figure number.
    width : {"full", "half"}, optional
        Text width or half of it.

    Returns
    -------
    dict
        ``name``, ``number``, ``caption``, ``svg`` (markup or None), ``width``.
    """
    from markupsafe import Markup

    svg = None
    if make is not None:
        from ..plots import figure_from

        svg = Markup(figure_from(make, name))
    return {"name": name, "number": number, "caption": caption, "svg": svg, "width": width}
