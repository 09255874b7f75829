"""Numbers and units for readers: the one home of every formatted value.

Inside the package every value is an SI float; what a reader sees is made
here and only here, so that a value reads the same in the console, in the
sentences of checks, verdicts and conclusions, in report tables and on figure
axes:

- :func:`number`: ``digits`` significant digits, plain notation from 1e-4 to
  below 1e6 (``33073``, ``0.001348``), a power of ten outside
  (``3.2 × 10⁻⁸``), no thousands separator (a number can be copied into a
  spec as it is printed);
- :func:`quantity`: a value with its unit, converted from SI for reading
  (lengths in mm, below 0.1 mm in µm; speeds in mm/s; stresses and moduli with
  a prefix): ``0.3 mm``, ``22 µm``, ``200 GPa``;
- :func:`scale` and :func:`quantities`: one unit for values read together
  (a table row, the lengths of one sentence), picked by the largest, so that
  ``22 µm`` never stands beside ``0.278 mm``;
- :func:`column`: the values of one table column (or row) as numbers in one unit,
  named once in its header: ``Final error [mm]`` over ``-0.625`` and ``< 1 × 10⁻⁶``;
- :func:`with_error`: a value and its standard error in one unit
  (``5 ± 3.5 × 10⁻⁵ mm``);
- :func:`percent`, :func:`unit_text` (``N*s/m`` -> ``N·s/m``) and
  :func:`axis_unit` (the unit of a figure axis or a map's header);
- :func:`fixed`: a fixed number of decimals where a field reads that way
  (margins in dB and degrees to 0.1);
- :func:`plain`: a number a program reads back (a value written into a spec, a
  cache key): ``%g`` notation, never a power-of-ten sign;
- :func:`code_point`: a character by its code (``U+0007``).

Pure Python on purpose: every layer may import it.
"""

from __future__ import annotations

import math
from typing import Any, Iterable, Sequence

__all__ = ["number", "quantity", "millimetres", "quantities", "column", "scale", "display_scale", "with_error",
           "percent", "fixed", "plain", "code_point", "unit_text", "axis_unit", "UNIT_TEXT",
           "DISPLAY_SCALES", "AXIS_UNITS", "AXIS_SCALES", "NBSP", "tick_label"]

#: No-break space: between a number and its unit in reports.
NBSP = "\u00a0"
_SUPERSCRIPT = str.maketrans("-0123456789", "\u207b\u2070\u00b9\u00b2\u00b3\u2074\u2075\u2076"
                                            "\u2077\u2078\u2079")

#: SI unit (as the spec and the checks store it) -> unit shown to readers.
UNIT_TEXT = {
    "N*s/m": "N\u00b7s/m", "N s/m": "N\u00b7s/m", "m/s**2": "m/s\u00b2", "m/s**3": "m/s\u00b3",
    "kg/m**3": "kg/m\u00b3", "deg": "\u00b0", "um": "\u00b5m", "1": "", "-": "",
    "N/(m s)": "N/(m\u00b7s)", "N/(m*s)": "N/(m\u00b7s)", "rad/s": "rad/s",
}

#: Units converted for reading: SI unit -> list of (threshold, shown unit, factor); the first
#: threshold at or below |value| wins.
DISPLAY_SCALES = {
    "m": [(1e-4, "mm", 1e3), (0.0, "\u00b5m", 1e6)],
    "m/s": [(0.0, "mm/s", 1e3)],
    "Pa": [(1e9, "GPa", 1e-9), (1e6, "MPa", 1e-6), (1e3, "kPa", 1e-3), (0.0, "Pa", 1.0)],
}

#: SI unit -> (unit of a figure axis or a map's header, factor from SI): one unit per axis,
#: whatever its values.
AXIS_UNITS: dict[str, tuple[str, float]] = {
    "m": ("mm", 1e3),
    "N/m": ("N/mm", 1e-3),
    "m/s": ("mm/s", 1e3),
    "m/s**2": ("m/s\u00b2", 1.0),
    "N*s/m": ("N\u00b7s/m", 1.0),
    "kg/m**3": ("kg/m\u00b3", 1.0),
    "1": ("-", 1.0),
}

#: SI unit -> (threshold, unit, factor) of an axis whose unit follows the size of its values
#: (a sweep of a delay from 1 ms to 2 ms reads in ms, of a duration in s); the first threshold
#: at or below the axis's largest |value| wins.
AXIS_SCALES: dict[str, list[tuple[float, str, float]]] = {
    "s": [(1.0, "s", 1.0), (1e-3, "ms", 1e3), (0.0, "\u00b5s", 1e6)],
}

#: Below this a length is not resolved by any position sensor: shown as ``< 0.001 µm``.
_SUB_NANO = 5e-10


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) or (
        hasattr(value, "dtype") and getattr(value, "shape", None) == ())


def number(value: Any, digits: int = 4) -> str:
    """A number for a reader: ``digits`` significant digits, plain where sensible.

    Parameters
    ----------
    value : float, int, bool, str or None
        The number; ``None`` gives an en dash, ``inf`` the infinity sign, ``nan``
        ``n/a``, a bool ``yes``/``no``; strings pass through.
    digits : int, optional
        Significant digits (default 4); integers, and numbers with more integer
        digits, are shown in full.

    Returns
    -------
    str
        Plain notation from 1e-4 to below 1e6 (``0.0003``, ``13333``), else a
        power of ten (``3.2 × 10⁻⁸``, no-break spaces around the sign).

    Examples
    --------
    >>> number(13333.33), number(0.3), number(2.0), number(3.2e-8), number(None)
    ('13333', '0.3', '2', '3.2\xa0×\xa010⁻⁸', '–')
    >>> number(33073.4), number(0.0013481, 3)
    ('33073', '0.00135')
    """
    if value is None:
        return "\u2013"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, str):
        return value
    if isinstance(value, int) or (hasattr(value, "dtype") and value.dtype.kind in "iu"):
        return str(int(value))
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
        if float(text) != 0 and abs(float(text)) >= 1e6:  # rounded up to a million
            return number(float(text), digits)
        return "0" if text in ("-0", "") else text
    mant, exp = f"{x:.{digits - 1}e}".split("e")
    if "." in mant:
        mant = mant.rstrip("0").rstrip(".")
    # no-break spaces: a number never wraps at the end of a line
    return f"{mant}{NBSP}\u00d7{NBSP}10{str(int(exp)).translate(_SUPERSCRIPT)}"


def unit_text(unit: str | None) -> str:
    """A unit as readers write it: ``N*s/m`` -> ``N·s/m``, ``m/s**2`` -> ``m/s²``, ``1`` -> ````.

    Parameters
    ----------
    unit : str or None
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
    ref = abs(float(reference)) if _is_number(reference) and math.isfinite(reference) else None
    if ref is None or ref == 0:
        if unit == "Pa":
            return "MPa", 1e-6
        return scales[0][1], scales[0][2]
    for threshold, shown, factor in scales:
        if ref >= threshold:
            return shown, factor
    return scales[-1][1], scales[-1][2]


def scale(unit: str, values: Iterable[Any]) -> tuple[str, float]:
    """One shown unit and factor for values read together, picked by the largest.

    Parameters
    ----------
    unit : str
        Their SI unit.
    values : iterable of float or None
        SI values; None, infinities and NaN are passed over.

    Returns
    -------
    shown : str
        Unit text (``""`` for a plain number).
    factor : float
        Multiply SI values by it.

    Examples
    --------
    >>> scale("m", [22e-6, 278e-6, 300e-6])
    ('mm', 1000.0)
    >>> scale("m", [22e-6, 31e-6])
    ('µm', 1000000.0)
    """
    finite = [abs(float(v)) for v in values if _is_number(v) and math.isfinite(v) and v != 0]
    return display_scale(unit, max(finite) if finite else None)


def _attach(text: str, shown: str, sep: str) -> str:
    if not shown:
        return text
    if shown == "\u00b0":
        return text + shown
    return text + sep + shown


def quantity(value: Any, unit: str = "", digits: int = 4, *, sep: str = " ",
             shown: tuple[str, float] | None = None, joiner: str = " \u2013 ") -> str:
    """A value with its unit, converted from SI for reading: ``quantity(3e-4, "m")`` -> ``0.3 mm``.

    Parameters
    ----------
    value : float, int, bool, str, None or sequence
        SI value; a pair or list gives ``10 – 60 mm`` in one unit; strings and
        bools pass through :func:`number`.
    unit : str, optional
        Its SI unit (``"m"``, ``"N/m"``, ``"Pa"``, ``"deg"``, ``"cycles"``, ...).
    digits : int, optional
        Significant digits.
    sep : str, optional
        Between number and unit: a space (default), or :data:`NBSP` in reports.
    shown : (str, float), optional
        The unit and factor to use (from :func:`scale`, for values read
        together); default picked by the value.
    joiner : str, optional
        Between the values of a sequence: an en dash (default), ``" to "`` for a
        range in a sentence, ``" x "`` for dimensions.

    Returns
    -------
    str
        Number, separator, unit (degrees follow the number directly).

    Examples
    --------
    >>> quantity(3e-4, "m"), quantity(22e-6, "m"), quantity(2e11, "Pa"), quantity(47.31, "deg")
    ('0.3 mm', '22 µm', '200 GPa', '47.31°')
    >>> quantity((396e-6, 0.05), "m", 3, joiner=" to ")
    '0.396 to 50 mm'
    >>> quantity((0.04, 0.01, 5e-4), "m", 3, joiner=" x ")
    '40 x 10 x 0.5 mm'
    """
    if isinstance(value, (list, tuple)):
        if not value:
            return "\u2013"
        unit_shown, factor = shown or scale(unit, value)
        parts = [number(v * factor if _is_number(v) else v, digits) for v in value]
        return _attach(joiner.join(parts), unit_shown, sep)
    if value is None or isinstance(value, (str, bool)):
        return number(value, digits)
    if unit == "m" and shown is None and 0 < abs(value) < _SUB_NANO:
        return _attach("< 0.001", "\u00b5m", sep)  # below what a position sensor resolves
    if not math.isfinite(value):  # no unit on n/a or an infinity
        return number(value)
    unit_shown, factor = shown or display_scale(unit, value)
    return _attach(number(value if factor == 1.0 else value * factor, digits), unit_shown, sep)


def millimetres(value: float, digits: int = 3) -> str:
    """A length always in mm (a flexure's dimensions, so that the lengths of one sentence share
    a unit): ``millimetres(6e-5)`` -> ``0.06 mm``.

    Parameters
    ----------
    value : float
        [m].
    digits : int, optional
        Significant digits.
    """
    return quantity(value, "m", digits, shown=("mm", 1e3))


def quantities(values: Sequence[Any], unit: str, digits: int = 4, *,
               sep: str = " ") -> list[str]:
    """Values read together (one sentence, one row) in one unit, picked by the largest.

    Parameters
    ----------
    values : sequence of float or None
        SI values.
    unit : str
        Their SI unit.
    digits : int, optional
        Significant digits.
    sep : str, optional
        Between number and unit.

    Returns
    -------
    list of str
        One text per value, all in the unit :func:`scale` picks.

    Examples
    --------
    >>> quantities([22e-6, 278e-6, 300e-6], "m", 3)
    ['0.022 mm', '0.278 mm', '0.3 mm']
    """
    shown = scale(unit, values)
    return [quantity(v, unit, digits, sep=sep, shown=shown) for v in values]


def column(values: Sequence[Any], unit: str, digits: int = 4) -> tuple[str, list[str]]:
    """The values of one table column in one unit, picked by the largest, named once.

    A column never mixes units (``0.0252 µm`` over ``1.37 mm``): its header
    carries the unit, its cells the numbers. A length below what a position
    sensor resolves reads as less than 0.001 µm in the column's unit.

    Parameters
    ----------
    values : sequence of float or None
        SI values; None gives an en dash, as :func:`number` does.
    unit : str
        Their SI unit.
    digits : int, optional
        Significant digits.

    Returns
    -------
    shown : str
        The column's unit text (``""`` for a plain number).
    cells : list of str
        One number per value, in that unit.

    Examples
    --------
    >>> column([1e-13, -6.25e-4, None], "m", 3)
    ('mm', ['< 1\xa0×\xa010⁻⁶', '-0.625', '–'])
    >>> column([2.52e-11, 3.1e-8], "m", 3)
    ('µm', ['< 0.001', '0.031'])
    """
    shown, factor = scale(unit, values)
    cells = []
    for v in values:
        if unit == "m" and _is_number(v) and 0 < abs(v) < _SUB_NANO:
            cells.append("< " + number(1e-9 * factor))
        elif _is_number(v) and math.isfinite(v):
            cells.append(number(v * factor, digits))
        else:
            cells.append(number(v))
    return shown, cells


def with_error(value: Any, error: Any, unit: str = "", digits: int = 4, error_digits: int = 2,
               *, sep: str = " ") -> str:
    """A value and its standard error in one unit: ``5 ± 3.5 × 10⁻⁵ mm``.

    Parameters
    ----------
    value : float or None
        SI value.
    error : float or None
        Its standard error (SI); None or 0 leaves it out.
    unit : str, optional
        The SI unit of both.
    digits, error_digits : int, optional
        Significant digits of the value and of the error.
    sep : str, optional
        Between number and unit.

    The value is shown to the error's last significant decimal, both in plain
    decimals where the value is plain (``5.000013 ± 0.000031 mm``, not ``5 ±
    3.1 × 10⁻⁵ mm``, which reads as a value of 5 × 10⁻⁵); an error above the
    value's units place, or numbers outside the plain range, as :func:`number`
    writes them.

    Examples
    --------
    >>> with_error(0.005000013, 3.1e-8, "m")
    '5.000013 ± 0.000031 mm'
    >>> with_error(0.249993, 1.1e-5, "1"), with_error(94.62, 0.234, "kg")
    ('0.249993 ± 0.000011', '94.62 ± 0.23 kg')
    """
    if value is None or not _is_number(value):
        return number(value, digits)
    shown, factor = display_scale(unit, value) if unit not in ("", "1", "-") else ("", 1.0)
    v = float(value) * factor
    text = number(v, digits)
    if error is not None and _is_number(error) and error != 0 and math.isfinite(error):
        e = abs(float(error)) * factor
        decimals = error_digits - 1 - math.floor(math.log10(e))
        if 0 <= decimals <= 12 and (v == 0 or 1e-4 <= abs(v) < 1e6):
            text = f"{v:.{decimals}f} \u00b1 {e:.{decimals}f}"
        else:
            text += f" \u00b1 {number(e, error_digits)}"
    return _attach(text, shown, sep)


def percent(fraction: Any, digits: int = 3) -> str:
    """A fraction as a percentage: ``percent(0.0612)`` -> ``6.12 %``; None -> ``n/a``.

    Parameters
    ----------
    fraction : float or None
        The fraction [-].
    digits : int, optional
        Significant digits of the percentage.

    Returns
    -------
    str
    """
    if fraction is None or not _is_number(fraction):
        return "n/a"
    return f"{number(100.0 * fraction, digits)} %"


def fixed(value: Any, decimals: int = 1) -> str:
    """A number with a fixed count of decimals: ``fixed(6.02)`` -> ``6.0``.

    For fields read to a fixed resolution (a margin in dB or degrees, a
    percentage of a slider); otherwise prefer :func:`number`.

    Parameters
    ----------
    value : float, None or str
        The number; None, nan, infinities and strings as in :func:`number`.
    decimals : int, optional
        Digits after the point (default 1).

    Returns
    -------
    str

    Examples
    --------
    >>> fixed(6.02), fixed(47.0, 0), fixed(None), fixed(float("inf"))
    ('6.0', '47', '–', '∞')
    """
    if value is None or isinstance(value, (str, bool)) or not math.isfinite(float(value)):
        return number(value)
    text = f"{float(value):.{decimals}f}"
    return "0" if decimals == 0 and text == "-0" else text


def plain(value: Any, digits: int = 6) -> str:
    """A number a program reads back: ``%g`` notation (``3e-08``, ``0.45``), round trip by float().

    For values written into a spec or a data file and for cache keys, where the
    reader's :func:`number` (``3 × 10⁻⁸``) would not parse.

    Parameters
    ----------
    value : float or int
        The number.
    digits : int, optional
        Significant digits (default 6, as ``%g``); 17 round-trips any float.

    Returns
    -------
    str

    Examples
    --------
    >>> plain(3e-8), plain(0.45e-3), plain(1/3, 4), plain(2.0)
    ('3e-08', '0.00045', '0.3333', '2')
    """
    return f"{float(value):.{digits}g}"


def code_point(code: int) -> str:
    """A character by its code, as Unicode names it: ``code_point(7)`` -> ``U+0007``.

    Parameters
    ----------
    code : int
        The character's code point.

    Returns
    -------
    str
    """
    return f"U+{code:04X}"


def tick_label(value: float, _pos: Any = None) -> str:
    """Tick label of a log axis as a plain number: ``0.001``, ``10``, ``1000``, ``1e6``.

    Plain text instead of matplotlib's mathtext powers of ten: readable, and
    much faster to draw. Decimals as far as the tick's leading digit (log axes
    carry 1-2-5 ticks); a short power of ten from 1e5 up and below 1e-4.
    Usable as a ``matplotlib.ticker.FuncFormatter``.

    Parameters
    ----------
    value : float
        Tick value (in the axis's shown unit).
    _pos : optional
        The tick's position, as a formatter is called; not used.

    Returns
    -------
    str
        Empty for values at or below zero (no tick on a log axis).

    Examples
    --------
    >>> tick_label(0.001), tick_label(0.05), tick_label(1000.0), tick_label(1e6), tick_label(2e-5)
    ('0.001', '0.05', '1000', '1e6', '2e-5')
    """
    if value <= 0:
        return ""
    if 1e-4 <= value < 1e5:
        if value >= 1:
            return f"{value:g}"
        return f"{value:.{max(0, -math.floor(math.log10(value) + 1e-9))}f}"
    return f"{value:.0e}".replace("e+0", "e").replace("e-0", "e-")


def axis_unit(unit: str, values: Iterable[Any] | None = None) -> tuple[str, float]:
    """The unit of a figure axis or a map's header for an SI unit, and the factor from SI.

    One unit per axis (:data:`AXIS_UNITS`: lengths in mm, stiffness in N/mm,
    ...); times follow the axis's largest value (:data:`AXIS_SCALES`: a delay
    of milliseconds in ms) when its ``values`` are given; other units are shown
    as stored.

    Parameters
    ----------
    unit : str
        SI unit as stored in the spec (``"m"``, ``"N/m"``, ``"Hz"``, ...).
    values : iterable of float, optional
        The axis's values (SI), for a unit of :data:`AXIS_SCALES`.

    Returns
    -------
    label : str
        Unit text (``"mm"`` for metres).
    factor : float
        Multiply SI values by this to get the shown unit.

    Examples
    --------
    >>> axis_unit("m"), axis_unit("s", [1e-3, 2e-3]), axis_unit("s", [5.0, 20.0])
    (('mm', 1000.0), ('ms', 1000.0), ('s', 1.0))
    """
    scales = AXIS_SCALES.get(unit)
    if scales is not None and values is not None:
        finite = [abs(float(v)) for v in values if _is_number(v) and math.isfinite(v) and v != 0]
        if finite:
            top = max(finite)
            return next((shown, f) for threshold, shown, f in scales if top >= threshold)
    return AXIS_UNITS.get(unit, (unit, 1.0))
