"""Number and unit formatting for readers: the jinja filters of the reports.

The formatting itself lives in :mod:`fi_design.display` (the one home of every
formatted value, so that the console, the sentences of the results and the
reports read alike); this module registers it as the filters ``num``, ``qty``
and ``unit`` of :func:`fi_design.report.render.environment`, with a no-break
space between number and unit. :func:`tex_num` and :func:`tex_qty` do the same
for the equations (mathtext).
"""

from __future__ import annotations

from typing import Any

from ..display import (DISPLAY_SCALES, NBSP, UNIT_TEXT, display_scale, number, quantity,
                       unit_text)

__all__ = ["num", "qty", "unit_text", "display_scale", "tex_num", "tex_qty", "wrapped_lines",
           "FILTERS", "UNIT_TEXT", "DISPLAY_SCALES", "WRAP_WIDTH", "WRAP_MARK"]

_PLAIN_DIGITS = str.maketrans("\u207b\u2070\u00b9\u00b2\u00b3\u2074\u2075\u2076\u2077\u2078"
                              "\u2079", "-0123456789")


def num(value: Any, digits: int = 4) -> str:
    """A number for a reader (:func:`fi_design.display.number`).

    Examples
    --------
    >>> num(13333.33), num(0.3), num(3.2e-8), num(None)
    ('13333', '0.3', '3.2\xa0×\xa010⁻⁸', '–')
    """
    return number(value, digits)


def qty(value: Any, unit: str = "", digits: int = 4) -> str:
    """A value with its unit for a report, a no-break space between them.

    :func:`fi_design.display.quantity`: lengths in mm (µm below 0.1 mm), speeds
    in mm/s, stresses and moduli with a prefix; a pair or list in one unit.

    Examples
    --------
    >>> qty(3e-4, "m"), qty(2e11, "Pa"), qty(47.31, "deg"), qty(5, "cycles")
    ('0.3\u00a0mm', '200\u00a0GPa', '47.31°', '5\u00a0cycles')
    """
    return quantity(value, unit, digits, sep=NBSP)


def tex_num(value: float, digits: int = 4) -> str:
    """A number for an equation (mathtext): as :func:`num`, powers as ``\\times 10^{n}``.

    Parameters
    ----------
    value : float
        The number.
    digits : int, optional
        Significant digits, as :func:`num`.

    Returns
    -------
    str
        TeX source, e.g. ``13333`` or ``2 \\times 10^{11}``.
    """
    text = num(value, digits)
    if "\u00d7" in text:
        mant, power = text.split(f"{NBSP}\u00d7{NBSP}10")
        return f"{mant} \\times 10^{{{power.translate(_PLAIN_DIGITS)}}}"
    return text


def tex_qty(value: float, unit: str, digits: int = 4) -> str:
    """A quantity for an equation: converted from SI as :func:`qty` does, the unit upright.

    Parameters
    ----------
    value : float
        SI value.
    unit : str
        Its SI unit.
    digits : int, optional
        Significant digits.

    Returns
    -------
    str
        TeX source, e.g. ``0.3\\ \\mathrm{mm}``.
    """
    shown, factor = display_scale(unit, value)
    text = tex_num(value * factor, digits)
    if not shown:
        return text
    if shown == "\u00b0":
        return text + "^\\circ"
    unit_tex = shown.replace(" ", "\\,").replace("\u00b5", "\\mu ").replace(
        "\u00b7", "\\cdot ").replace("\u00b2", "^2").replace("\u00b3", "^3")
    return f"{text}\\ \\mathrm{{{unit_tex}}}"


#: Characters of a spec line the appendix prints in one row (A4 at the appendix's 7.8 pt
#: monospace: about 100 fit); a longer line continues in rows marked by ``WRAP_MARK``.
WRAP_WIDTH = 96
#: What the appendix prints before a row that continues the line above (CSS-generated: a mark
#: of the page, not a character of the text, whose SHA-256 stays the file's).
WRAP_MARK = "\u21aa "


def wrapped_lines(text: str, width: int = WRAP_WIDTH) -> list[list[str]]:
    """The text's lines cut into rows of at most ``width`` characters (the line end kept).

    Joined, the rows give the text back exactly: ``"".join(sum(rows, []))``.
    A continuation row holds ``len(WRAP_MARK)`` characters fewer, room for the mark.
    """
    out = []
    for line in text.splitlines(keepends=True):
        body = line.rstrip("\r\n")
        end = line[len(body):]
        rows, rest, room = [], body, width
        while len(rest) > room:
            rows.append(rest[:room])
            rest = rest[room:]
            room = width - len(WRAP_MARK)
        rows.append(rest + end)
        out.append(rows)
    return out


#: The jinja filters of every report template.
FILTERS = {"num": num, "qty": qty, "unit": unit_text, "rows": wrapped_lines}
