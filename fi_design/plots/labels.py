"""Axis names and display units of the values sweeps and studies vary (dotted spec paths).
"""

from __future__ import annotations

from ..display import axis_unit


def display_unit(unit: str) -> tuple[str, float]:
    """Unit shown on an axis for an SI unit, and the factor from SI
    (:func:`fi_design.display.axis_unit`)."""
    return axis_unit(unit)


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
        description of the field (``"Extra loop delay"``), else the path.
    """
    if path in QUANTITY_NAMES:
        return QUANTITY_NAMES[path]
    from ..errors import SpecError
    from ..spec.file import path_description

    try:
        text = path_description(path)
    except SpecError:
        text = ""
    for stop in (" [", ";", ". ", " ("):
        text = text.split(stop)[0]
    text = text.strip().rstrip(".")
    return text[:1].upper() + text[1:] if text else path


def axis_label(path: str, unit: str) -> str:
    """Axis label with the quantity's name and display unit: ``"Isolator stroke [mm]"``.

    Parameters
    ----------
    path : str
        Dotted spec path.
    unit : str
        SI unit of the values.

    Returns
    -------
    str
    """
    shown, _ = display_unit(unit)
    name = quantity_name(path)
    return f"{name} [{shown}]" if shown else name
