"""The unit boundary: strings with units in, SI floats out.

pint is used here and nowhere else. Inside the package every physical value is
an SI float; the spec file may give a bare number (read as SI) or a string such
as ``"0.3 mm"``, ``"2 N/mm"`` or ``"5 Hz"``.

Three kinds of quantity need care:

- Frequencies are stored in Hz. pint treats the radian as dimensionless, so
  ``"62.8 rad/s"`` would silently convert to 62.8 Hz. Here any angle unit in a
  frequency (rad/s, deg/s, rpm, cycles/s) is converted through rad/s and divided
  by 2 pi, so ``"62.83 rad/s"`` is 10 Hz.
- Phase margins are stored in degrees and must carry a unit: a bare 30 could
  be degrees or radians. Other angles (the phases of the effects) are SI
  radians, bare or with a unit.
- Gain ratios given in decibels (``"6 dB"``) are stored in dB; a bare number is
  refused for the same reason.

A string is one number followed by its unit (``"1e6 N/m"``, ``"2 1/s"``,
``"1 m/s^2"``): pint reads only the unit, never an expression (``"2 kg * 2"``,
``"9**9**9 kg"`` are refused). Values of every dimensioned kind must lie within
:data:`PLAUSIBLE`.
"""

from __future__ import annotations

import math
import numbers
import re
import sys
import tokenize
from functools import lru_cache
from typing import Any

from ..display import quantity, unit_text
from ..errors import ArgumentError, UnitError

#: Target units understood by :func:`to_si`, with the dimension users see in messages.
KNOWN_UNITS = {
    "1": "dimensionless",
    "kg": "mass",
    "m": "length",
    "s": "time",
    "N": "force",
    "N/m": "stiffness (force per length)",
    "N*s/m": "damping (force per velocity)",
    "N/(m*s)": "integral gain (force per length and time)",
    "m/s": "velocity",
    "m/s**2": "acceleration",
    "m/s**3": "jerk",
    "Hz": "frequency",
    "Pa": "pressure or stress",
    "kg/m**3": "density",
    "kg*m**2": "moment of inertia",
    "rad": "angle",
    "deg": "angle",
    "dB": "gain in decibels",
    "A": "electric current",
    "N/A": "motor force constant (force per current)",
}

#: Plausible magnitudes (SI; Hz for frequencies) of a nonzero value of each kind, ``(least,
#: most)``: far beyond any positioning stage (a milligram to a thousand tonnes; 1e12 N is a
#: force limit never reached; a femtometre to a kilometre; a nanohertz to a gigahertz); a
#: value outside is a slip of unit or exponent, and the analysis overflows on it (1e300 kg,
#: a 1e300 m stroke, a 1e300 Hz crossover, a leaf 1e300 mm long).
PLAUSIBLE = {"kg": (1e-6, 1e6), "N": (0.0, 1e15), "N/m": (1e-6, 1e15), "N*s/m": (0.0, 1e15),
             "N/(m*s)": (0.0, 1e20), "m": (1e-15, 1e3), "s": (1e-15, 1e9),
             "m/s": (1e-15, 1e4), "m/s**2": (1e-12, 1e8), "m/s**3": (1e-12, 1e12),
             "Hz": (1e-9, 1e9), "Pa": (1e-3, 1e14), "kg/m**3": (1e-3, 1e6),
             "kg*m**2": (1e-15, 1e6), "A": (0.0, 1e6), "N/A": (0.0, 1e6)}

_DB = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*dB\s*$")
#: A comma between digits: a decimal comma ("1,25 kg") or a thousands separator ("6,667 N/m").
_COMMA = re.compile(r"\d\s*,\s*\d")
#: Two numbers side by side ("3 5 N"), which pint multiplies; "2 1/s" (a reciprocal unit) is fine.
_TWO_NUMBERS = re.compile(r"(?:\d|\d\.)\s+[-+]?\.?\d(?![\d.eE+-]*\s*/)")
#: A quantity as written: one number, then its unit (possibly none).
_QUANTITY = re.compile(r"([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(.*)", re.S)
#: nan or inf as YAML or Python write them (``.nan``, ``-inf``, ``Infinity``), a unit or not.
_NOT_FINITE = re.compile(r"[-+]?\.?(?:nan|inf(?:inity)?)(?![A-Za-z])", re.I)
#: The digits a unit may hold: a unit's power (``m/s^2``, ``s**-1``, not ``9**9``) and a
#: reciprocal's 1 (``1/s``).
_UNIT_DIGITS = re.compile(r"(?:(?<=[^\W\d_])|(?<=\)))(?:\^|\*\*)[-+]?\d(?![\d.])|^1\s*/")


@lru_cache(maxsize=1)
def registry():
    """Return the shared pint UnitRegistry.

    pint's definition cache (in the user cache directory) makes this take
    about 15 ms instead of 0.2 s after the first use; without a writable
    cache directory the registry is parsed afresh.
    """
    import pint

    try:
        return pint.UnitRegistry(cache_folder=":auto:")
    except OSError:
        return pint.UnitRegistry()


def _is_number(value) -> bool:
    """A real number: Python's or numpy's (``np.int64``, ``np.float32``), not a bool."""
    return isinstance(value, numbers.Real) and not isinstance(value, bool)  # np.bool_ is no Real


def _cut(text: str) -> str:
    """Text read from the spec, quoted for a message and cut to about 40 characters."""
    text = repr(text)
    return text if len(text) <= 40 else text[:28] + "..." + text[-8:]


def _finite(x: float, path: str | None, text) -> float:
    if not math.isfinite(x):
        shown = _cut(text) if isinstance(text, str) else repr(float(text))
        overflow = isinstance(text, str) and not _NOT_FINITE.match(text.strip())
        raise UnitError(f"value {shown} is not a finite number"
                        + (" (too large to hold)" if overflow else ""), path=path)
    return float(x)


def _plausible(x: float, unit: str, path: str | None, text) -> float:
    """``x``, refused when it lies outside :data:`PLAUSIBLE` (zero is always plausible)."""
    least, most = PLAUSIBLE.get(unit, (0.0, math.inf))
    if x != 0 and not least <= abs(x) <= most:
        shown = _cut(text) if isinstance(text, str) else repr(float(text))
        si = (unit_text(unit), 1.0)  # the bounds in the SI unit, as docs/spec.md gives them
        written = _QUANTITY.match(text.strip()) if isinstance(text, str) else None
        if written and written.group(2).strip() and float(written.group(1)) != x:
            shown += f" ({quantity(x, unit, shown=si)})"  # a prefix's slip shows in SI
        span = (f"lies within {quantity((least, most), unit, joiner=' to ', shown=si)}"
                if least > 0 else f"is at most {quantity(most, unit, shown=si)}")
        raise UnitError(f"{shown} is not a plausible {KNOWN_UNITS[unit]}: a nonzero one {span}; "
                        "check its unit and exponent", path=path)
    return x


def to_si(value, unit: str, path: str | None = None) -> float:
    """Convert a spec value to an SI float (or Hz, deg, dB for those kinds).

    Parameters
    ----------
    value : float, int or str
        A bare number (taken as already in ``unit``; numpy's numbers too) or a
        string of one number and its unit (``"0.3 mm"``, ``"1e6 N/m"``).
    unit : str
        Target unit, one of :data:`KNOWN_UNITS`.
    path : str, optional
        Dotted spec path, used in error messages.

    Returns
    -------
    float
        The value in ``unit``.

    Raises
    ------
    UnitError
        Unparsable text, no number or more than one (an expression), wrong
        dimension, not finite, outside :data:`PLAUSIBLE`, or a bare number
        where a unit is required (angles, decibels).
    """
    if unit not in KNOWN_UNITS:  # programming error, not user input
        raise ArgumentError(f"unknown target unit {unit!r}")
    if _is_number(value):
        if isinstance(value, numbers.Integral) and abs(int(value)) > 2 ** 1023:
            raise UnitError(f"the number {shown_digits(int(value))} is too large for a physical value",
                            path=path)
        if unit == "deg":
            raise UnitError(f"a bare number is ambiguous for an angle; write e.g. '{value} deg'",
                            path=path)
        if unit == "dB":
            raise UnitError(f"a bare number is ambiguous for a gain; write e.g. '{value} dB'",
                            path=path)
        return _plausible(_finite(float(value), path, value), unit, path, value)
    if not isinstance(value, str):
        raise UnitError(f"expected a number or a string with units, got {type(value).__name__}",
                        path=path)
    text = value.strip()
    if not text:
        raise UnitError("empty value", path=path)
    _refuse_misread(text, path)
    if unit == "dB":
        m = _DB.match(text)
        if not m:
            raise UnitError(f"cannot read {value!r} as a gain in dB (write e.g. '6 dB')", path=path)
        return _finite(float(m.group(1)), path, value)
    return _plausible(_finite(_convert(text, unit, path), path, value), unit, path, value)


def huge(value: Any) -> bool:
    """Whether ``value`` is an integer too long to show whole in a message (over 997 bits,
    about 300 digits; Python's ``str`` refuses those of more than 4300 digits)."""
    return isinstance(value, int) and not isinstance(value, bool) and \
        abs(value).bit_length() > 997


def shown_digits(value: int) -> str:
    """A huge integer for a message: its first digits and how many it has."""
    try:
        text = str(abs(value))
    except ValueError:  # beyond Python's limit of digits for str()
        return f"of more than {sys.get_int_max_str_digits()} digits"
    return f"{text[:12]}... ({len(text)} digits)"


def _refuse_misread(text: str, path: str | None) -> None:
    """Refuse text that pint would read as another number than the one written.

    pint drops a comma between digits (``"1,25 kg"`` is 125 kg, ``"0,3 mm"``
    is 0 mm) and multiplies two numbers written side by side (``"3 5 N"`` is
    15 N); either is a value the user did not mean.
    """
    if _COMMA.search(text):
        fixed = _COMMA.sub(lambda m: m.group(0).replace(",", ".").replace(" ", ""), text)
        raise UnitError(f"cannot read {text!r}: a comma inside a number is not read; write "
                        f"{fixed!r} if it is a decimal comma, or leave out a thousands "
                        "separator", path=path)
    if _TWO_NUMBERS.search(text):
        raise UnitError(f"cannot read {text!r}: two numbers separated by a space (read as "
                        "their product); write one number and its unit", path=path)


def _convert(text: str, unit: str, path: str | None) -> float:
    try:
        return _quantity(text, unit, path)
    except UnitError as exc:
        fixes = _case_fixes(text, unit)
        if not fixes:
            raise
        meant = " or ".join(repr(f) for f in fixes)
        raise UnitError(f"{exc.message}; did you mean {meant}? (units are case-sensitive)",
                        path=path) from None


def _quantity(text: str, unit: str, path: str | None) -> float:
    import pint

    ureg = registry()
    magnitude, unit_text = _number_and_unit(text, unit, path)
    try:
        q = ureg.Quantity(magnitude, unit_text)
    except (pint.errors.PintError, ValueError, TypeError, AttributeError, SyntaxError,
            AssertionError, KeyError, ZeroDivisionError, tokenize.TokenError) as exc:
        raise UnitError(f"cannot read {_cut(text)} as a quantity in {unit} ({exc})",
                        path=path) from None
    if unit == "1":
        if not q.dimensionless:
            raise UnitError(f"{text!r} has units of {q.dimensionality}, expected a plain number",
                            path=path)
        return float(q.to("dimensionless").magnitude)
    if unit == "Hz" and _has_angle(q):
        try:
            return float(q.to("rad/s").magnitude) / (2.0 * math.pi)
        except pint.errors.DimensionalityError:
            pass
    if unit == "deg" and q.unitless:
        raise UnitError(f"{text!r} has no unit; write e.g. '{text} deg'", path=path)
    try:
        return float(q.to(unit).magnitude)
    except pint.errors.DimensionalityError:
        raise UnitError(f"{text!r} is not a {KNOWN_UNITS[unit]} (expected units convertible to {unit},"
                        f" got {q.dimensionality})", path=path) from None


def _number_and_unit(text: str, unit: str, path: str | None) -> tuple[float, str]:
    """The number and the unit of a quantity as written: ``"1e6 N/m"`` is ``(1e6, "N/m")``.

    Only the unit goes to pint, so an expression (``"2 kg * 2"``, ``"9**9**9 kg"``) is never
    evaluated: the unit may hold digits only in a power (``m/s^2``, ``s**-1``) and as the
    1 of a reciprocal (``1/s``).

    Raises
    ------
    UnitError
        No number (``"kg"``), nan or inf, or more than one number.
    """
    m = _QUANTITY.fullmatch(text)
    if m is None:
        if _NOT_FINITE.match(text):
            raise UnitError(f"value {_cut(text)} is not a finite number", path=path)
        if _is_unit(text):
            raise UnitError(f"{_cut(text)} needs a number before its unit, e.g. '1 {text}'",
                            path=path)
        raise UnitError(f"cannot read {_cut(text)} as a quantity in {unit}: write a number and "
                        "its unit", path=path)
    number, unit_text = m.groups()
    if re.search(r"\d", _UNIT_DIGITS.sub("", unit_text)):
        raise UnitError(f"cannot read {_cut(text)}: write one number followed by its unit (e.g. "
                        "'2 kg', '1e6 N/m'); arithmetic on numbers is not read", path=path)
    return float(number), unit_text


def _is_unit(text: str) -> bool:
    """True if ``text`` is a unit that pint knows, without a number (``"kg"``, ``"mm/s"``)."""
    if re.search(r"\d", _UNIT_DIGITS.sub("", text)):
        return False
    try:
        registry().parse_units(text)
    except Exception:  # noqa: BLE001  (pint raises assorted errors on odd text)
        return False
    return True


def from_si(value: float, unit: str, shown: str) -> float:
    """An SI value in another unit of the same dimension (the unit a user wrote).

    Parameters
    ----------
    value : float
        The value in ``unit`` (SI, Hz, deg or dB as the spec's fields hold them).
    unit : str
        Its unit.
    shown : str
        The unit to express it in (``"mm"``, ``"N/mm"``).

    Returns
    -------
    float

    Raises
    ------
    UnitError
        ``shown`` is not a unit of that dimension.

    Examples
    --------
    >>> from_si(0.0003, "m", "mm")
    0.3
    """
    import pint

    ureg = registry()
    try:
        return float(ureg.Quantity(value, unit).to(shown).magnitude)
    except (pint.errors.PintError, ValueError, TypeError, AttributeError) as exc:
        raise UnitError(f"cannot express {unit} in {shown!r} ({exc})") from None


#: A unit's name in a quantity's text (letters; an exponent's ``e`` is skipped by the caller).
_WORD = re.compile(r"[A-Za-z_]+")


def _case_fixes(text: str, unit: str, most: int = 2) -> list[str]:
    """The text with its unit names' letter case changed so that it reads as ``unit``.

    ``"15 hz"`` is ``["15 Hz"]``, ``"1 KN"`` is ``["1 kN"]``, ``"10 MM"`` (megamolar)
    is ``["10 Mm", "10 mm"]`` for a length: every casing of each name that the
    registry defines, kept when the whole text then converts to ``unit``, fewest
    changed letters first.

    Parameters
    ----------
    text : str
        The quantity as written.
    unit : str
        Target unit, one of :data:`KNOWN_UNITS`.
    most : int
        How many to return at most.

    Returns
    -------
    list of str
        Empty when no change of case helps.
    """
    import itertools

    ureg = registry()
    words, options = [], []
    for m in _WORD.finditer(text):
        w = m.group(0)
        before, after = text[:m.start()], text[m.end():]
        if w in ("e", "E") and re.search(r"[\d.]$", before) and re.match(r"[-+]?\d", after):
            continue  # the exponent of a number
        if len(w) <= 5:
            casings = {"".join(c) for c in itertools.product(*((ch.lower(), ch.upper())
                                                               for ch in w))}
        else:
            casings = {w, w.lower(), w.upper(), w.capitalize()}
        defined = sorted(c for c in casings if c == w or _defined(ureg, c))
        words.append(m)
        options.append(defined)
    found = []
    for combo in itertools.islice(itertools.product(*options), 256):
        parts, last = [], 0
        for m, c in zip(words, combo):
            parts += [text[last:m.start()], c]
            last = m.end()
        candidate = "".join(parts) + text[last:]
        if candidate == text:
            continue
        try:
            _quantity(candidate, unit, None)
        except UnitError:
            continue
        found.append(candidate)
    found.sort(key=lambda c: (sum(a != b for a, b in zip(c, text)), c))
    return found[:most]


def _defined(ureg, name: str) -> bool:
    try:
        return name in ureg
    except Exception:  # noqa: BLE001  (pint raises assorted errors on odd names)
        return False


def _has_angle(q) -> bool:
    """True if the quantity's units contain an angle (radian, degree, revolution, ...)."""
    ureg = registry()
    for uname, _power in q.unit_items():
        _, root = ureg.get_root_units(uname)
        if "radian" in str(root):
            return True
    return False
