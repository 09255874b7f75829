"""Equations of the reports: rendered by matplotlib's mathtext to SVG, read as plain text.

An equation is written in the TeX subset mathtext understands. :func:`equation`
gives what the templates place: the SVG (glyphs as paths, so a browser and
WeasyPrint draw the same picture without the fonts installed) and a plain-text
reading (:func:`math_text`) for screen readers, text search and the golden
report contexts.
"""

from __future__ import annotations

import contextlib
import contextvars
import os
import re
from collections.abc import Iterator

from ..cachedir import cache_dir
from ..display import fixed, plain

__all__ = ["equation", "equation_svg", "equation_img", "equations_left_out", "math_text",
           "EQUATION_RC", "EQUATION_SIZE"]

#: matplotlib settings of the equations: STIX, a Times-like face that matches the body text.
EQUATION_RC = {"mathtext.fontset": "stix"}
#: Font size of the equations [pt].
EQUATION_SIZE = 11.5


_LEFT_OUT: contextvars.ContextVar[bool] = contextvars.ContextVar("fi_design_equations_left_out",
                                                                  default=False)


@contextlib.contextmanager
def equations_left_out() -> Iterator[None]:
    """Within this block :func:`equation` draws nothing (its ``svg`` None): for a report's
    context built only for what else it holds (a worker's figures, placed by name)."""
    token = _LEFT_OUT.set(True)
    try:
        yield
    finally:
        _LEFT_OUT.reset(token)


def equation(tex: str, name: str, render: bool = True) -> dict:
    """One equation for a report template.

    Parameters
    ----------
    tex : str
        The formula (mathtext TeX, without ``$``).
    name : str
        Identifier, unique within the report (prefixes the SVG's ids).
    render : bool, optional
        Draw the SVG (default); False, or within :func:`equations_left_out`,
        leaves ``svg`` None (golden tests, a worker's figures).

    Returns
    -------
    dict
        ``tex`` (the source), ``text`` (:func:`math_text`) and ``svg``
        (markup, or None).
    """
    svg = None
    if render and not _LEFT_OUT.get():
        from markupsafe import Markup

        from ..plots import raster_dpi

        dpi = raster_dpi()
        svg = Markup(equation_svg(tex, name) if dpi is None else equation_img(tex, dpi))
    return {"tex": tex, "text": math_text(tex), "svg": svg}


def equation_svg(tex: str, name: str) -> str:
    """A formula as an inline ``<svg>`` element: its glyph outlines, from matplotlib's mathtext.

    Fractions are set in display style (``\\dfrac``), as in a printed
    equation. The outline comes from one mathtext parse
    (:class:`matplotlib.textpath.TextPath`); the picture is as large as the
    formula plus a thin margin, sized in pt. Parsing costs about 40 ms a
    formula, so the drawn element is kept in the user cache
    (:func:`fi_design.cachedir.cache_dir`), keyed by the formula, its size
    and font set and the matplotlib version: a report drawn again (the same
    spec, or the formulas without numbers) draws nothing twice.

    Parameters
    ----------
    tex : str
        The formula (mathtext TeX, without ``$``).
    name : str
        Prefix of the SVG's ids (it has none; kept for the figure interface).

    Returns
    -------
    str
        The ``<svg>`` element, sized in pt.
    """
    return _cached(tex, "svg", lambda: _draw(tex))


def equation_img(tex: str, dpi: float) -> str:
    """A formula as an ``<img>`` element: the outline of :func:`equation_svg` filled at ``dpi``.

    For PDF reports (:func:`fi_design.plots.raster_figures`), where WeasyPrint
    would otherwise parse and fill the outline's path in Python. Kept in the
    user cache like the SVG.

    Parameters
    ----------
    tex : str
        The formula (mathtext TeX, without ``$``).
    dpi : float
        Resolution [dots per inch].

    Returns
    -------
    str
        The ``<img>`` element (a PNG data URL), as wide in pt as the SVG.
    """
    return _cached(tex, f"{plain(dpi)}.img", lambda: _draw_img(tex, dpi))


def _cached(tex: str, kind: str, draw) -> str:
    """The drawing of ``tex`` of this ``kind`` from the user cache, else ``draw()`` (stored)."""
    import hashlib

    import matplotlib

    key = hashlib.sha256(repr((tex, EQUATION_SIZE, EQUATION_RC, matplotlib.__version__,
                               _FORMAT)).encode()).hexdigest()
    path = cache_dir("equations") / f"{key}.{kind}"
    try:
        return path.read_text(encoding="utf-8")
    except OSError:
        pass
    text = draw()
    try:  # a cache that cannot be written only costs the next run the time
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_suffix(f".{os.getpid()}.tmp")
        tmp.write_text(text, encoding="utf-8")
        os.replace(tmp, path)
    except OSError:
        pass
    return text


#: Version of the drawing below (part of the cache key: change it when the output changes).
_FORMAT = 2
#: Margin around the formula's outline [pt].
_MARGIN = 1.0


def _outline(tex: str):
    """The glyph outline of a formula (a matplotlib Path, in pt) and its extents."""
    import matplotlib
    from matplotlib.font_manager import FontProperties
    from matplotlib.textpath import TextPath

    source = "$" + tex.replace("\\frac", "\\dfrac") + "$"
    with matplotlib.rc_context(EQUATION_RC):
        outline = TextPath((0.0, 0.0), source, prop=FontProperties(size=EQUATION_SIZE))
    return outline, outline.get_extents()


#: Colour of a rasterised formula: the report's ink (report.css).
_INK = "#1d2329"


def _draw_img(tex: str, dpi: float) -> str:
    """The ``<img>`` element of a formula at ``dpi`` (no cache)."""
    from matplotlib.figure import Figure
    from matplotlib.patches import PathPatch

    from ..plots import png_img, rgb_png

    outline, box = _outline(tex)
    width, height = box.width + 2 * _MARGIN, box.height + 2 * _MARGIN
    fig = Figure(figsize=(width / 72.0, height / 72.0), dpi=dpi, facecolor="white")
    ax = fig.add_axes((0.0, 0.0, 1.0, 1.0))
    ax.set_axis_off()
    ax.set_xlim(box.x0 - _MARGIN, box.x1 + _MARGIN)
    ax.set_ylim(box.y0 - _MARGIN, box.y1 + _MARGIN)
    ax.add_patch(PathPatch(outline, facecolor=_INK, edgecolor="none", linewidth=0.0))
    return png_img(rgb_png(fig, dpi), width_pt=width, alt=math_text(tex))


def _draw(tex: str) -> str:
    """The SVG element of a formula (no cache)."""
    from matplotlib.path import Path as MplPath

    outline, box = _outline(tex)
    x0, y1 = box.x0 - _MARGIN, box.y1 + _MARGIN
    width, height = box.width + 2 * _MARGIN, box.height + 2 * _MARGIN
    letters = {MplPath.MOVETO: "M", MplPath.LINETO: "L", MplPath.CURVE3: "Q",
               MplPath.CURVE4: "C"}
    d = []
    for points, code in outline.iter_segments(simplify=False, curves=True):
        if code == MplPath.CLOSEPOLY:
            d.append("Z")
            continue
        xy = points.reshape(-1, 2)
        d.append(letters[code] + " ".join(f"{fixed(x - x0, 3)} {fixed(y1 - y, 3)}" for x, y in xy))
    return (f'<svg xmlns="http://www.w3.org/2000/svg" width="{fixed(width, 2)}pt" '
            f'height="{fixed(height, 2)}pt" viewBox="0 0 {fixed(width, 3)} {fixed(height, 3)}" '
            'role="img">'
            f'<path d="{"".join(d)}" fill="currentColor"/></svg>')


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
