"""Number and unit formatting for readers: the jinja filters of the reports.

Reports carry SI values to the templates and these functions format them
(registered as the filters ``num``, ``qty`` and ``unit`` by
:func:`fi_design.report.render.environment`); the context builders use them
for text that is ready-made. :func:`tex_num` and :func:`tex_qty` do the same
for the equations (mathtext).
"""

from __future__ import annotations

import math
from typing import Any

__all__ = ["num", "qty", "unit_text", "display_scale", "tex_num", "tex_qty", "FILTERS",
           "UNIT_TEXT", "DISPLAY_SCALES"]

_NBSP = "\u00a0"
_NNBSP = "\u202f"  # narrow no-break space: thousands separator
_SUPERSCRIPT = str.maketrans("-0123456789", "\u207b\u2070\u00b9\u00b2\u00b3\u2074\u2075\u2076"
                                            "\u2077\u2078\u2079")
_PLAIN_DIGITS = str.maketrans("\u207b\u2070\u00b9\u00b2\u00b3\u2074\u2075\u2076\u2077\u2078"
                              "\u2079", "-0123456789")


def num(value: Any, digits: int = 4) -> str:
    """A number for a reader: ``digits`` significant digits, plain where sensible.

    Parameters
    ----------
    value : float, int, bool, str or None
        The number; ``None`` gives an en dash, ``inf`` the infinity sign, ``nan``
        ``n/a``, a bool ``yes``/``no``; strings pass through.
    digits : int, optional
        Significant digits (default 4); integers and numbers with more integer
        digits are shown in full.

    Returns
    -------
    str
        Plain notation from 1e-4 to 1e6 (``0.0003``, ``13333``), else a power of
        ten (``3.2 × 10⁻⁸``); groups of three digits from 10 000 up are
        separated by a narrow no-break space.

    Examples
    --------
    >>> num(13333.33), num(0.3), num(2.0), num(3.2e-8), num(None)
    ('13\u202f333', '0.3', '2', '3.2 × 10⁻⁸', '–')
    """
    if value is None:
        return "\u2013"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, str):
        return value
    if isinstance(value, int) or (hasattr(value, "dtype") and value.dtype.kind in "iu"):
        return _group(str(int(value)))
    x = float(value)
    if math.isnan(x):
        return "n/a"
    if math.isinf(x):
        return "\u221e" if x > 0 else "-\u221e"
    if x == 0:
        return "0"
    ax = abs(x)
    if 1e-4 <= ax < 1e6:
        exp = math.floor(math.log10(ax))
        decimals = max(0, digits - 1 - exp)
        text = f"{x:.{decimals}f}"
        if "." in text:
            text = text.rstrip("0").rstrip(".")
        if text in ("-0", ""):
            text = "0"
        return _group(text)
    mant, exp = f"{x:.{digits - 1}e}".split("e")
    if "." in mant:
        mant = mant.rstrip("0").rstrip(".")
    return f"{mant} \u00d7 10{str(int(exp)).translate(_SUPERSCRIPT)}"


def _group(text: str) -> str:
    """Narrow-space thousands groups for integer parts of 5 digits and more."""
    sign = "-" if text.startswith("-") else ""
    body = text.lstrip("-")
    whole, dot, frac = body.partition(".")
    if len(whole) >= 5:
        groups = []
        while whole:
            groups.insert(0, whole[-3:])
            whole = whole[:-3]
        whole = _NNBSP.join(groups)
    return sign + whole + dot + frac


#: SI unit (as the spec and the checks store it) -> unit shown to readers.
UNIT_TEXT = {
    "N*s/m": "N\u00b7s/m", "N s/m": "N\u00b7s/m", "m/s**2": "m/s\u00b2", "m/s**3": "m/s\u00b3",
    "kg/m**3": "kg/m\u00b3", "deg": "\u00b0", "um": "\u00b5m", "1": "", "-": "",
    "N/(m s)": "N/(m\u00b7s)", "rad/s": "rad/s",
}

#: Units converted for display: SI unit -> list of (threshold, shown unit, factor), the first
#: threshold at or below |value| wins.
DISPLAY_SCALES = {
    "m": [(1e-4, "mm", 1e3), (0.0, "\u00b5m", 1e6)],
    "m/s": [(0.0, "mm/s", 1e3)],
    "Pa": [(1e9, "GPa", 1e-9), (1e6, "MPa", 1e-6), (1e3, "kPa", 1e-3), (0.0, "Pa", 1.0)],
}


def unit_text(unit: str) -> str:
    """A unit as readers write it: ``N*s/m`` -> ``N·s/m``, ``m/s**2`` -> ``m/s²``, ``1`` -> ````.

    Parameters
    ----------
    unit : str
        Unit as stored in the spec or a check.

    Returns
    -------
    str
    """
    if unit is None:
        return ""
    return UNIT_TEXT.get(unit, unit.replace("**2", "\u00b2").replace("**3", "\u00b3")
                         .replace("*", "\u00b7"))


def display_scale(unit: str, reference: Any) -> tuple[str, float]:
    """The shown unit and the factor from SI for a value of ``unit`` near ``reference``.

    Parameters
    ----------
    unit : str
        SI unit.
    reference : float or None
        A typical value (SI), which picks the prefix (``Pa`` -> ``MPa``).

    Returns
    -------
    shown : str
        The unit text to print.
    factor : float
        Multiply SI values by it.
    """
    scales = DISPLAY_SCALES.get(unit)
    if scales is None:
        return unit_text(unit), 1.0
    ref = abs(float(reference)) if isinstance(reference, (int, float)) and \
        not isinstance(reference, bool) and math.isfinite(reference) else None
    if ref is None or ref == 0:
        shown, factor = scales[0][1], scales[0][2]
        if unit == "Pa":
            shown, factor = "MPa", 1e-6
        return shown, factor
    for threshold, shown, factor in scales:
        if ref >= threshold:
            return shown, factor
    return scales[-1][1], scales[-1][2]


def qty(value: Any, unit: str = "", digits: int = 4) -> str:
    """A value with its unit, converted from SI for reading: ``qty(3e-4, "m")`` -> ``0.3 mm``.

    Parameters
    ----------
    value : float, int, bool, str, None or sequence
        SI value; a pair or list gives ``10 – 60 mm``; strings and bools pass
        through :func:`num`.
    unit : str, optional
        Its SI unit (``"m"``, ``"N/m"``, ``"Pa"``, ``"deg"``, ``"cycles"``, ...);
        lengths are shown in mm (µm below 0.1 mm), speeds in mm/s, stresses and
        moduli with a prefix.
    digits : int, optional
        Significant digits.

    Returns
    -------
    str
        Number, no-break space, unit (degrees follow the number directly).

    Examples
    --------
    >>> qty(3e-4, "m"), qty(2e11, "Pa"), qty(47.31, "deg"), qty(5, "cycles")
    ('0.3\u00a0mm', '200\u00a0GPa', '47.31°', '5\u00a0cycles')
    """
    if isinstance(value, (list, tuple)):
        if not value:
            return "\u2013"
        shown, factor = display_scale(unit, max((abs(v) for v in value
                                                 if isinstance(v, (int, float))), default=None))
        parts = [num(v * factor if isinstance(v, (int, float)) and not isinstance(v, bool)
                     else v, digits) for v in value]
        return _attach(" \u2013 ".join(parts), shown)
    if value is None or isinstance(value, (str, bool)):
        return num(value, digits)
    if unit == "m" and 0 < abs(value) < 5e-10:
        return _attach("< 0.001", "\u00b5m")
    shown, factor = display_scale(unit, value)
    scaled = value if factor == 1.0 else value * factor
    return _attach(num(scaled, digits), shown)


def _attach(text: str, shown: str) -> str:
    if not shown:
        return text
    if shown == "\u00b0":
        return text + shown
    return text + _NBSP + shown


def tex_num(value: float, digits: int = 4) -> str:
    """A number for an equation (mathtext): thin-space thousands, ``\\times 10^{n}`` powers.

    Parameters
    ----------
    value : float
        The number.
    digits : int, optional
        Significant digits, as :func:`num`.

    Returns
    -------
    str
        TeX source, e.g. ``13\\,333`` or ``2 \\times 10^{11}``.
    """
    text = num(value, digits)
    if "\u00d7" in text:
        mant, power = text.split(" \u00d7 10")
        return f"{mant} \\times 10^{{{power.translate(_PLAIN_DIGITS)}}}"
    return text.replace(_NNBSP, "\\,")


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
    number = tex_num(value * factor, digits)
    if not shown:
        return number
    if shown == "\u00b0":
        return number + "^\\circ"
    unit_tex = shown.replace(" ", "\\,").replace("\u00b5", "\\mu ").replace(
        "\u00b7", "\\cdot ").replace("\u00b2", "^2").replace("\u00b3", "^3")
    return f"{number}\\ \\mathrm{{{unit_tex}}}"


#: The jinja filters of every report template.
FILTERS = {"num": num, "qty": qty, "unit": unit_text}
