"""Equations of the reports: rendered by matplotlib's mathtext to SVG, read as plain text.

An equation is written in the TeX subset mathtext understands. :func:`equation`
gives what the templates place: the SVG (glyphs as paths, so a browser and
WeasyPrint draw the same picture without the fonts installed) and a plain-text
reading (:func:`math_text`) for screen readers, text search and the golden
report contexts.
"""

from __future__ import annotations

import re

__all__ = ["equation", "equation_svg", "math_text", "EQUATION_RC", "EQUATION_SIZE"]

#: matplotlib settings of the equations: STIX, a Times-like face that matches the body text.
EQUATION_RC = {"mathtext.fontset": "stix"}
#: Font size of the equations [pt].
EQUATION_SIZE = 11.5


def equation(tex: str, name: str, render: bool = True) -> dict:
    """One equation for a report template.

    Parameters
    ----------
    tex : str
        The formula (mathtext TeX, without ``$``).
    name : str
        Identifier, unique within the report (prefixes the SVG's ids).
    render : bool, optional
        Draw the SVG (default); False leaves ``svg`` None (golden tests).

    Returns
    -------
    dict
        ``tex`` (the source), ``text`` (:func:`math_text`) and ``svg``
        (markup, or None).
    """
    svg = None
    if render:
        from markupsafe import Markup

        svg = Markup(equation_svg(tex, name))
    return {"tex": tex, "text": math_text(tex), "svg": svg}


def equation_svg(tex: str, name: str) -> str:
    """A formula as an inline ``<svg>`` element, drawn by matplotlib's mathtext.

    Fractions are set in display style (``\\dfrac``), as in a printed
    equation. The picture is as large as the formula, with its baseline where
    matplotlib puts it (as :func:`matplotlib.mathtext.math_to_image` does).

    Parameters
    ----------
    tex : str
        The formula (mathtext TeX, without ``$``).
    name : str
        Prefix of the SVG's ids.

    Returns
    -------
    str
        The ``<svg>`` element, sized in pt.
    """
    import matplotlib
    from matplotlib.figure import Figure
    from matplotlib.font_manager import FontProperties
    from matplotlib.mathtext import MathTextParser

    from ..plots import figure_svg

    source = "$" + tex.replace("\\frac", "\\dfrac") + "$"
    with matplotlib.rc_context(EQUATION_RC):
        prop = FontProperties(size=EQUATION_SIZE)
        width, height, depth, _, _ = MathTextParser("path").parse(source, dpi=72, prop=prop)
        fig = Figure(figsize=(width / 72.0, height / 72.0))
        fig.text(0.0, depth / height, source, fontproperties=prop)
        return figure_svg(fig, name, text_as_paths=True)


# --------------------------------------------------------------------------- plain reading

_GREEK = {"alpha": "\u03b1", "beta": "\u03b2", "gamma": "\u03b3", "delta": "\u03b4",
          "Delta": "\u0394", "epsilon": "\u03b5", "zeta": "\u03b6", "eta": "\u03b7",
          "theta": "\u03b8", "lambda": "\u03bb", "mu": "\u00b5", "pi": "\u03c0",
          "rho": "\u03c1", "sigma": "\u03c3", "tau": "\u03c4", "phi": "\u03c6",
          "omega": "\u03c9", "Omega": "\u03a9"}
_SYMBOLS = {"times": "\u00d7", "leq": "\u2264", "geq": "\u2265", "cdot": "\u00b7",
            "infty": "\u221e", "pm": "\u00b1", "approx": "\u2248", "neq": "\u2260",
            "circ": "\u00b0", "quad": " ", ",": " ", " ": " ", ";": " "}
_FUNCTIONS = ("min", "max", "ln", "log", "exp", "sin", "cos")
#: Relations and operators set off by spaces outside sub- and superscripts.
_SPACED = set("=+<>-\u00d7\u2264\u2265\u2248\u2260")


def math_text(tex: str) -> str:
    """A plain-text reading of a formula: ``k_\\max = \\frac{F_s}{s}`` -> ``k_max = (F_s)/(s)``.

    Greek letters and symbols as Unicode, sub- and superscripts as ``_`` and
    ``^``, fractions as ``(numerator)/(denominator)``, relations and operators
    between spaces, units as written.

    Parameters
    ----------
    tex : str
        The formula (the TeX subset of the reports' equations).

    Returns
    -------
    str

    Examples
    --------
    >>> math_text(r"\\Delta F = F_s - F_c")
    'ΔF = F_s - F_c'
    """
    items, _ = _parse(_tokens(tex), 0, False, None)
    return re.sub(r"\s+", " ", _read(items, spaced=True)).strip()


def _tokens(tex: str) -> list[tuple[str, str]]:
    """``("cmd", name)``, ``("char", c)`` or a brace, ``_`` or ``^`` as ``(c, c)``."""
    out, i = [], 0
    while i < len(tex):
        c = tex[i]
        if c == "\\":
            m = re.match(r"[A-Za-z]+|.", tex[i + 1:])
            name = m.group(0) if m else ""
            out.append(("cmd", name))
            i += 1 + len(name)
        else:
            out.append((c, c) if c in "{}_^" else ("char", c))
            i += 1
    return out


def _parse(tokens: list, i: int, upright: bool, until: str | None) -> tuple[list, int]:
    """Items ``["text", text, sub, sup]`` and ``["frac", items, items]`` up to ``until``."""
    items: list = []
    while i < len(tokens):
        kind = tokens[i][0]
        if kind == until:
            return items, i + 1
        if kind in ("_", "^"):
            script, i = _atom(tokens, i + 1, True)
            if not items or items[-1][0] != "text":
                items.append(["text", "", "", ""])
            items[-1][2 if kind == "_" else 3] += _read(script, spaced=False)
            continue
        atom, i = _atom(tokens, i, upright)
        items += atom
    return items, i


def _atom(tokens: list, i: int, upright: bool) -> tuple[list, int]:
    """One group, command or character."""
    kind, val = tokens[i]
    if kind == "{":
        return _parse(tokens, i + 1, upright, "}")
    if kind == "cmd":
        if val == "frac":
            top, i = _atom(tokens, i + 1, upright)
            bottom, i = _atom(tokens, i, upright)
            return [["frac", top, bottom]], i
        if val in ("mathrm", "text"):
            return _atom(tokens, i + 1, True)
        if val in ("left", "right"):
            return [], i + 1
        if val in _FUNCTIONS and not upright:
            val = " " + val
        return [["text", _GREEK.get(val, _SYMBOLS.get(val, val)), "", ""]], i + 1
    if kind == "char" and val != " ":
        return [["text", val + (" " if val == "," and not upright else ""), "", ""]], i + 1
    return [], i + 1


def _read(items: list, spaced: bool) -> str:
    """The items as text; ``spaced`` sets relations and operators off by spaces."""
    out = []
    for item in items:
        if item[0] == "frac":
            out.append(f"({_read(item[1], spaced)})/({_read(item[2], spaced)})")
            continue
        _, text, sub, sup = item
        if spaced and text in _SPACED:
            text = f" {text} "
        out.append(text + (f"_{sub}" if sub else "") + (f"^{sup}" if sup else ""))
    return "".join(out)
