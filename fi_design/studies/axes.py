"""The axes of a parameter study: spec values at dotted paths, swept over a grid.

:class:`Axis` is one swept value; :func:`make_axis` builds one from values in
SI, :func:`parse_axis` from the command line's text ``PATH=START:STOP:N``
(text is read only here, at the boundary). :func:`design_value` is the spec's
own value at a path (read from the resolved model), the design point a study
is drawn around.
"""

from __future__ import annotations

import re
from collections.abc import Sequence

import numpy as np

from .. import spec as _spec
from ..display import quantity
from ..errors import SpecError
from ..model import Model, require_model
from ..results.studies import Axis
from ..spec.file import path_unit, value_at
from ..spec.paths import split_assignment

__all__ = ["make_axis", "parse_axis", "design_value", "is_number", "held_damping_note",
           "crossover_note"]


def make_axis(path: str, values: Sequence[float], log: bool = False,
              spec: _spec.Spec | None = None) -> Axis:
    """An :class:`Axis` for a dotted path, with the unit looked up in the spec schema.

    Parameters
    ----------
    path : str
        Dotted spec path.
    values : sequence of float
        Values in the path's SI unit.
    log : bool, optional
        Logarithmic spacing (for plots). Default False.
    spec : Spec, optional
        Resolves list indices into ``effects`` and ``controller.filters``.

    Returns
    -------
    Axis

    Raises
    ------
    SpecError
        Unknown path, a path to a section or to a value without a number.
    """
    from .points import MAX_POINTS

    unit = path_unit(path, spec)
    if unit == "":
        raise SpecError("is not a numeric value; only numbers can be swept", path=path)
    try:
        array = np.asarray(values, dtype=float).ravel()
    except (TypeError, ValueError, OverflowError):
        raise SpecError(f"the values must be numbers in {unit} (SI), got {_shown(values)}; read "
                        "text with units by parse_axis", path=path) from None
    if array.size == 0:
        raise SpecError("no values to sweep", path=path)
    if not np.all(np.isfinite(array)):
        raise SpecError(f"the values must be finite numbers, got {_shown(values)}", path=path)
    if array.size > MAX_POINTS:
        raise SpecError(f"{array.size} values; a study holds at most {MAX_POINTS} points",
                        path=path)
    _, first, counts = np.unique(array, return_index=True, return_counts=True)
    if np.any(counts > 1):
        twice = array[first[counts > 1][0]]
        raise SpecError(f"the value {quantity(float(twice), unit, 6)} is given "
                        f"{int(counts.max())} times: each point of the study once", path=path)
    return Axis(path=path, values=array, unit=unit, log=log)


def _shown(value) -> str:
    text = repr(value)
    return text if len(text) <= 40 else text[:28] + "..." + text[-8:]


def parse_axis(text: str, log: bool = False, spec: _spec.Spec | None = None) -> Axis:
    """Read an axis written as ``PATH=START:STOP:N`` (or ``PATH=V1,V2,...``).

    Parameters
    ----------
    text : str
        ``"controller.crossover=2 Hz:30 Hz:15"``, ``"isolator.stroke=0.05 mm:1 mm:12"``
        or ``"stage.mass=1,2,4"``. START and STOP are SI numbers or strings
        with units, both alike (a bare number beside one with units is
        refused; a bare 0 mixes); N is the number of values, end points
        included.
    log : bool, optional
        Space the N values logarithmically (START and STOP above zero).
    spec : Spec, optional
        Resolves list indices into ``effects`` and ``controller.filters``.

    Returns
    -------
    Axis

    Raises
    ------
    SpecError
        Unknown path, malformed range, wrong unit, a bare number beside one
        with units, N below 1.
    """
    from ..spec.units import to_si

    parts = split_assignment(text)
    if parts is None:
        raise SpecError(f"axis {text!r}: expected PATH=START:STOP:N, e.g. "
                        "'controller.crossover=2 Hz:30 Hz:15'")
    path, rng = parts
    if not path:
        raise SpecError(f"axis {text!r}: the path before '=' is empty")
    unit = path_unit(path, spec)
    if unit == "":
        raise SpecError("is not a numeric value; only numbers can be swept", path=path)

    def number(word: str, what: str) -> float:
        word = word.strip()
        if not word:
            raise SpecError(f"range {rng!r}: {what} is empty", path=path)
        try:
            return to_si(float(word) if is_number(word) else word, unit, path=path)
        except SpecError as exc:
            raise SpecError(f"range {rng!r}: {what}: {exc.message}", path=path) from None

    if ":" not in rng and "," in rng:
        words = rng.split(",")
        _one_unit(words, rng, unit, path)
        values = [number(w, f"value {i + 1}") for i, w in enumerate(words)]
        return make_axis(path, values, log=log, spec=spec)
    parts = rng.split(":")
    if len(parts) != 3:
        raise SpecError(f"range {rng!r}: expected START:STOP:N (three parts separated by ':'), "
                        f"e.g. '0.05 mm:1 mm:12'", path=path)
    _one_unit(parts[:2], rng, unit, path)
    start, stop = number(parts[0], "START"), number(parts[1], "STOP")
    try:
        n = int(parts[2].strip())
    except ValueError:
        raise SpecError(f"range {rng!r}: N must be a whole number, got {parts[2].strip()!r}",
                        path=path) from None
    from .points import MAX_POINTS

    if n < 1:
        raise SpecError(f"range {rng!r}: N must be at least 1, got {n}", path=path)
    if n > MAX_POINTS:
        raise SpecError(f"range {rng!r}: N = {n} points; a study holds at most {MAX_POINTS} "
                        "(a few ms to a few tens of ms each)", path=path)
    if n > 1 and start == stop:
        raise SpecError(f"range {rng!r}: START equals STOP; give N = 1 or a wider range",
                        path=path)
    if n == 1 and start != stop:
        raise SpecError(f"range {rng!r}: N = 1 sweeps START alone, and STOP would be ignored; "
                        "give N of 2 or more, or START:START:1 for one value", path=path)
    if log:
        if start <= 0 or stop <= 0:
            raise SpecError(f"range {rng!r}: a logarithmic axis needs START and STOP above "
                            "zero", path=path)
        values = np.geomspace(start, stop, n)
    else:
        values = np.linspace(start, stop, n)
    return Axis(path=path, values=values, unit=unit, log=log)


#: The number that starts a value with units (``"1 mm"``, ``"-2.5e-3 N/m"``).
_LEADING_NUMBER = re.compile(r"^\s*[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?\s*")


def _one_unit(words: Sequence[str], rng: str, unit: str, path: str) -> None:
    """Refuse a range that mixes bare numbers (SI) with values given in units.

    ``0.2:1 mm:3`` would run from 0.2 m down to 1 mm: the bare number is most
    likely meant in the other's unit, so neither reading is taken for granted.
    A bare zero is zero in every unit and mixes freely.

    Raises
    ------
    SpecError
        A nonzero bare number beside a value with units.
    """
    words = [w.strip() for w in words]
    bare = [w for w in words if w and is_number(w) and float(w) != 0.0]
    united = [w for w in words if w and not is_number(w)]
    if not (bare and united):
        return
    lead = _LEADING_NUMBER.match(united[0])
    meant = united[0][lead.end():].strip() if lead else ""
    hint = f" (e.g. '{bare[0]} {meant}' if that is what {bare[0]!r} means)" if meant else ""
    raise SpecError(f"range {rng!r}: {bare[0]!r} is a bare number, read as {bare[0]} {unit} (SI), "
                    f"while {united[0]!r} has a unit; give every value its unit{hint}, or none "
                    "(all SI)", path=path)


def is_number(word: str) -> bool:
    """Whether ``word`` is a plain number (else a string with units)."""
    try:
        float(word)
    except ValueError:
        return False
    return True


#: Spec paths whose default depends on other values: their value in the resolved model.
_DERIVED = {
    "isolator.stiffness": lambda m: m.joint.stiffness,
    "isolator.damping": lambda m: m.joint.damping,
    "friction.bristle_damping": lambda m: m.friction.sigma1,
    "isolator.limiter.damping": lambda m: m.limiter.damping,
}


def design_value(model: Model, path: str) -> float | None:
    """The design's own value at a spec path, derived defaults as resolved [SI].

    Parameters
    ----------
    model : Model
        The model resolved from its spec (:func:`fi_design.model.resolve`).
    path : str
        Dotted spec path.

    Returns
    -------
    float or None
        The spec's value; a derived default (``isolator.stiffness`` left to
        step 3, default dampings) is the model's; None if the spec has no
        such value.
    """
    model = require_model(model)
    try:
        value = value_at(model.spec, path)
    except SpecError:
        return None
    if value is None and path in _DERIVED:
        if model.joint is None and path.startswith("isolator."):
            return None
        value = _DERIVED[path](model)
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return None
    return float(value)


#: Spec values that move the joint's stiffness or its masses, and so the damping ratio of a
#: damping the spec gives.
_JOINT_PATHS = ("isolator.stiffness", "isolator.stroke", "stage.mass", "cart.mass")


def held_damping_note(model: Model, axes: Sequence[Axis]) -> str | None:
    """A sentence when the axes vary the joint while the spec gives its damping, else None.

    A given ``isolator.damping`` c [N s/m] is a damper's: it stays as the
    stiffness (or the stroke, through the proposed stiffness, or a mass)
    varies, so the joint's damping ratio
    (:attr:`fi_design.model.Model.joint_damping_ratio`) moves with it; a damping left to its default keeps the ratio instead.

    Parameters
    ----------
    model : Model
        The study's base model (resolved from its spec).
    axes : sequence of Axis
        The swept axes.

    Returns
    -------
    str or None
    """
    from ..display import number, quantity

    iso = require_model(model).spec.isolator
    moving = [a for a in axes if a is not None and a.path in _JOINT_PATHS]
    if iso is None or iso.damping is None or not moving:
        return None
    ratios = [model.varied({a.path: v}).joint_damping_ratio for a in moving
              for v in (float(np.min(a.values)), float(np.max(a.values)))]
    if max(ratios) - min(ratios) <= 1e-6 * max(ratios):
        return None  # the joint's stiffness and masses stay (a stroke with a given stiffness)
    return (f"isolator.damping is given ({quantity(iso.damping, 'N*s/m')}) and held as "
            f"{', '.join(a.path for a in moving)} varies: the joint's damping ratio runs "
            f"from {number(min(ratios), 3)} to {number(max(ratios), 3)} over the axes (leave "
            "the key out to keep the ratio of the default instead)")


def crossover_note(axes: Sequence[Axis]) -> str | None:
    """A sentence when an axis varies the crossover, else None.

    The map's simulations carry the loop without the parasitic modes; step 2
    (the design run, which holds them) bounds the crossover from above, and
    beyond its achievable crossover the hardware's loop loses its margins or
    its stability whatever the map shows.

    Parameters
    ----------
    axes : sequence of Axis
        The swept axes (None entries are skipped).

    Returns
    -------
    str or None
    """
    if not any(a is not None and a.path == "controller.crossover" for a in axes):
        return None
    return ("the map simulates the loop without the parasitic modes: above the achievable "
            "crossover of step 2 (the design run gives it), the hardware's loop loses its "
            "margins or its stability, whatever the map shows there")
