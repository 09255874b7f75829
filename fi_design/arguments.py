"""Checks of the arguments a library function takes.

A spec's values are checked by the spec itself (:mod:`fi_design.spec`); the
other arguments of the public functions (a crossover to shift to, a number of
samples, a method name) are checked here, at the function's entry, so that a
script passing ``crossover="5 Hz"`` or ``form="bogus"`` gets an
:class:`~fi_design.errors.ArgumentError` naming the argument and what it got,
never a ``ValueError`` from deep inside numpy. Text with units is read by
:func:`fi_design.spec.units.to_si`; these functions take numbers (SI) only.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Iterable
from typing import Any

from .display import number as shown_number  # this module's number() reads one
from .errors import ArgumentError

__all__ = ["number", "integer", "choice"]


def _shown(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 40 else text[:28] + "..." + text[-8:]


def number(value: Any, name: str, unit: str, *, positive: bool = False,
           minimum: float | None = None, maximum: float | None = None) -> float:
    """A finite real number argument, as a float.

    Parameters
    ----------
    value : object
        What the caller passed.
    name : str
        The argument's name, for the message.
    unit : str
        Its unit (``"Hz"``, ``"s"``, ``"-"``), for the message.
    positive : bool, optional
        Refuse zero and negative values.
    minimum, maximum : float, optional
        Inclusive bounds.

    Returns
    -------
    float

    Raises
    ------
    ArgumentError
        Not a real number (text, None, a bool, a complex), not finite, or out
        of bounds; the message names the argument and the value.
    """
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        hint = " (read text with units by fi_design.spec.units.to_si)" if isinstance(value, str) else ""
        raise ArgumentError(f"{name} must be a number in {unit}, got {_shown(value)}{hint}")
    try:
        x = float(value)
    except OverflowError:
        raise ArgumentError(f"{name} = {_shown(value)} is too large") from None
    if not math.isfinite(x):
        raise ArgumentError(f"{name} must be a finite number in {unit}, got {_shown(value)}")
    if positive and not x > 0.0:
        raise ArgumentError(f"{name} must be above zero [{unit}], got {shown_number(x, 6)}")
    if minimum is not None and x < minimum:
        raise ArgumentError(f"{name} must be at least {shown_number(minimum, 6)} {unit}, "
                            f"got {shown_number(x, 6)}")
    if maximum is not None and x > maximum:
        raise ArgumentError(f"{name} must be at most {shown_number(maximum, 6)} {unit}, "
                            f"got {shown_number(x, 6)}")
    return x


def integer(value: Any, name: str, *, minimum: int | None = None,
            maximum: int | None = None) -> int:
    """A whole-number argument (a count, a factor), as an int.

    Parameters
    ----------
    value : object
        What the caller passed (an int or a numpy integer).
    name : str
        The argument's name.
    minimum, maximum : int, optional
        Inclusive bounds; a maximum says what can finish on the machine.

    Returns
    -------
    int

    Raises
    ------
    ArgumentError
        Not a whole number, or out of bounds.
    """
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise ArgumentError(f"{name} must be a whole number, got {_shown(value)}")
    n = int(value)
    if minimum is not None and n < minimum:
        raise ArgumentError(f"{name} must be at least {minimum}, got {n}")
    if maximum is not None and n > maximum:
        raise ArgumentError(f"{name} must be at most {maximum}, got {_shown(n)}")
    return n


def choice(value: Any, name: str, options: Iterable[str]) -> str:
    """One of a few names (a method, a form, a drive).

    Raises
    ------
    ArgumentError
        ``value`` is not one of ``options``; the message lists them.
    """
    allowed = tuple(options)
    if not isinstance(value, str) or value not in allowed:
        raise ArgumentError(f"{name} must be one of {', '.join(repr(a) for a in allowed)}, got "
                            f"{_shown(value)}")
    return value
