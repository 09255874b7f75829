"""Axis names and display units of the values sweeps and studies vary (dotted spec paths).
"""

from __future__ import annotations

from typing import Any

from ..display import axis_unit


def display_unit(unit: str, values: Any = None) -> tuple[str, float]:
    """Unit shown on an axis for an SI unit (and the axis's values, which pick ms or s for a
    time), and the factor from SI (:func:`fi_design.display.axis_unit`)."""
    return axis_unit(unit, values)


#: Names of the values sweeps and studies usually vary, by dotted spec path.
QUANTITY_NAMES: dict[str, str] = {
    "controller.crossover": "Crossover frequency",
    "controller.delay": "Loop delay",
    "controller.sample_rate": "Sample rate",
    "controller.force_limit": "Force limit",
    "controller.derivative_ratio": "Derivative ratio",
    "controller.integrator_ratio": "Integrator ratio",
    "isolator.stroke": "Isolator stroke",
    "isolator.stiffness": "Drive stiffness",
    "isolator.damping": "Joint damping",
    "friction.static": "Static friction",
    "friction.coulomb": "Coulomb friction",
    "friction.stribeck_velocity": "Stribeck velocity",
    "friction.viscous": "Viscous friction",
    "friction.bristle_stiffness": "Bristle stiffness",
    "friction.bristle_damping": "Bristle damping",
    "friction.offset": "Load force offset",
    "stage.mass": "Stage mass",
    "cart.mass": "Cart mass",
}


def quantity_name(path: str) -> str:
    """A readable name for the value at a dotted spec path: ``"Isolator stroke"``.

    Parameters
    ----------
    path : str
        Dotted spec path.

    Returns
    -------
    str
        From :data:`QUANTITY_NAMES`, else the first words of the schema's
        description of the field (``"Extra loop delay"``; an index into a list
        of typed entries, ``effects[0].delay``, read by the entry types that
        have the field), else the key (``"Amplitude"``), else the path.
    """
    if path in QUANTITY_NAMES:
        return QUANTITY_NAMES[path]
    from ..errors import SpecError
    from ..spec.paths import parse_path, path_description, typed_readings

    try:
        names = {_name(path_description(path))}
    except SpecError:
        names = {_name(path_description(p)) for p in typed_readings(path)}
    if len(names) == 1 and "" not in names:
        return names.pop()
    try:
        key = parse_path(path)[-1][0].replace("_", " ")
    except SpecError:
        return path
    return key[:1].upper() + key[1:]


def _name(description: str) -> str:
    """The first words of a field's description: ``"Extra loop delay"``."""
    text = description
    for stop in (" [", ";", ". ", " ("):
        text = text.split(stop)[0]
    text = text.strip().rstrip(".")
    return text[:1].upper() + text[1:]


def axis_label(path: str, unit: str, values: Any = None) -> str:
    """Axis label with the quantity's name and display unit: ``"Isolator stroke [mm]"``.

    Parameters
    ----------
    path : str
        Dotted spec path.
    unit : str
        SI unit of the values.
    values : array of float, optional
        The axis's values (SI), which pick the unit of a time (:func:`display_unit`).

    Returns
    -------
    str
    """
    shown, _ = display_unit(unit, values)
    name = quantity_name(path)
    return f"{name} [{shown}]" if shown else name
