"""The guide's geometry from the spec: the stage as a rigid body, spacings, orientation.

The spec describes the stage (``stage.size`` or ``stage.inertia``, the
sensor's and actuator's offsets) and the guide (``isolator.flexure``: leaves,
material, orientation, spacings, and one value or bounds per leaf dimension).
:func:`stage_body` and :func:`leaf_guide` turn them into the values the
closed forms read; defaults are filled in here and nowhere else:

- the stage's body: a steel cube of the stage's mass (density
  :data:`STEEL_DENSITY`) unless ``stage.size`` or ``stage.inertia`` is given;
  its centre of mass half its z size beyond the guide's clamp;
- ``spacing``: the stage's x size; ``lateral_spacing`` (4 leaves): the stage's
  y size less one leaf width, at least one leaf width.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..results.mechanism import LeafGuide, box_inertia, steel_cube

__all__ = ["STEEL_DENSITY", "StageBody", "stage_body", "leaf_guide"]

#: Density of the default stage body, a steel cube [kg/m^3].
STEEL_DENSITY = 7850.0


@dataclass(frozen=True)
class StageBody:
    """The stage as a rigid body (SI).

    Attributes
    ----------
    mass : float
        m1 [kg].
    size : tuple of float or None
        Edge lengths (x, y, z) of the box [m]; None when the inertia is given.
    inertia : tuple of float
        (Ixx, Iyy, Izz) about the centre of mass [kg m^2].
    com_height : float
        The centre of mass beyond the guide's clamp [m].
    sensor_offset, actuator_offset : tuple of float
        (y, z) from the centre of mass [m].
    assumed : bool
        True when the body is the default steel cube.
    """

    mass: float
    size: tuple[float, float, float] | None
    inertia: tuple[float, float, float]
    com_height: float
    sensor_offset: tuple[float, float]
    actuator_offset: tuple[float, float]
    assumed: bool


def stage_body(stage) -> StageBody:
    """The stage of a spec (``fi_design.spec.Stage``) as a rigid body, defaults filled in."""
    size = stage.size
    assumed = size is None and stage.inertia is None
    if assumed:
        size = steel_cube(stage.mass, STEEL_DENSITY)
    if stage.inertia is not None:
        inertia = tuple(stage.inertia)
    else:
        inertia = box_inertia(stage.mass, size)
    h = stage.centre_of_mass_height
    if h is None:
        h = 0.5 * size[2]
    return StageBody(mass=stage.mass, size=None if size is None else tuple(size),
                     inertia=inertia, com_height=h, sensor_offset=tuple(stage.sensor_offset),
                     actuator_offset=tuple(stage.actuator_offset), assumed=assumed)


def leaf_guide(flexure, body: StageBody, *, length: float, width: float, thickness: float,
               cart_mass: float = 0.0, stop_stiffness: float = math.inf) -> LeafGuide:
    """A leaf guide of the spec's ``isolator.flexure`` with the given leaf dimensions [m].

    Parameters
    ----------
    flexure : fi_design.spec.Flexure
        Material, leaves, orientation, spacings, damping.
    body : StageBody
        The stage it carries.
    length, width, thickness : float
        L, b, t [m].
    cart_mass : float, optional
        m2 [kg] (a vertical drive axis: the joint carries the cart).
    stop_stiffness : float, optional
        The end stop's contact stiffness k_stop [N/m]; default inf (rigid).
    """
    mat = flexure.material
    # without a size the spec gives both spacings (fi_design.spec.Spec checks it)
    spacing = flexure.spacing if flexure.spacing is not None else body.size[0]
    lateral = 0.0
    if flexure.leaves == 4:
        lateral = flexure.lateral_spacing
        if lateral is None:
            lateral = max(width, body.size[1] - width)
    return LeafGuide(leaves=flexure.leaves, length=length, width=width, thickness=thickness,
                     spacing=spacing, lateral_spacing=lateral,
                     youngs_modulus=mat.youngs_modulus, poisson_ratio=mat.poisson_ratio,
                     density=mat.density, allowed_stress=mat.allowed_stress,
                     orientation=flexure.orientation, stage_mass=body.mass,
                     stage_inertia=body.inertia, com_height=body.com_height,
                     sensor_offset=body.sensor_offset, actuator_offset=body.actuator_offset,
                     damping_ratio=flexure.damping_ratio, cart_mass=cart_mass,
                     stop_stiffness=stop_stiffness)
