"""The isolator as a mechanism: the parallel leaf-spring guide and what it does.

Values of :mod:`fi_design.mechanism`: the guide's geometry (:class:`LeafGuide`),
its stiffness in six directions (:class:`Stiffness6`), gravity's effect
(:class:`Gravity`), its modes (:class:`Mode`) and all of them together
(:class:`GuideMechanics`). SI throughout: lengths m, masses kg, stiffnesses N/m
and N m/rad, forces N, stresses Pa, frequencies Hz.

Frame of the guide (every value here): ``x`` the drive direction (the leaves'
thickness), ``y`` along the leaves' width, ``z`` along their length, pointing
from the cart's clamp to the stage's clamp. Rotations ``rx, ry, rz`` about
those axes. The stage is a rigid body whose centre of mass lies on the
guide's axis, ``com_height`` beyond the stage's clamp.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from . import Result

__all__ = ["ORIENTATIONS", "DIRECTIONS", "GRAVITY", "LeafGuide", "Stiffness6", "Gravity", "Mode",
           "GuideMechanics", "FeMechanics", "box_inertia", "steel_cube"]

#: Orientations of the guide against gravity (``isolator.flexure.orientation``).
ORIENTATIONS = ("standing", "hanging", "flat", "vertical_axis")

#: Directions of the guide's frame, in the order of its 6 x 6 matrices.
DIRECTIONS = ("x", "y", "z", "rx", "ry", "rz")

#: Standard gravity [m/s^2].
GRAVITY = 9.80665


@dataclass(frozen=True)
class LeafGuide(Result):
    """A parallel leaf-spring guide carrying a rigid stage.

    Attributes
    ----------
    leaves : int
        Number of leaves: 2 (one per row) or 4 (two side by side per row).
    length, width, thickness : float
        Leaf length L (along z), width b (along y), thickness t (along x) [m].
    spacing : float
        Distance between the two rows of leaves along x [m].
    lateral_spacing : float
        Centre distance along y of the two leaves of a row [m]; 0 with 2 leaves.
    youngs_modulus : float
        E [Pa].
    poisson_ratio : float
        nu [-]; the shear modulus is E / (2 (1 + nu)).
    density : float
        rho [kg/m^3] of the leaves.
    allowed_stress : float
        Allowed stress of the leaves [Pa].
    orientation : str
        One of :data:`ORIENTATIONS`: ``standing`` (leaves vertical, the stage on
        top: gravity along -z), ``hanging`` (the stage below: gravity along +z),
        ``flat`` (leaves horizontal, gravity along -y), ``vertical_axis`` (the
        drive axis vertical: gravity along -x).
    stage_mass : float
        Mass of the stage m1 [kg].
    stage_inertia : tuple of float
        Moments of inertia of the stage about its centre of mass, (Ixx, Iyy,
        Izz) [kg m^2].
    com_height : float
        Distance of the stage's centre of mass beyond the stage's clamp, along z
        [m].
    sensor_offset, actuator_offset : tuple of float
        Where the position sensor and the actuator act, (y, z) from the centre
        of mass [m]; both measure and push along x.
    damping_ratio : float
        Modal damping ratio of the computed modes [-].
    cart_mass : float
        Mass of the bearing cart m2 [kg]: on a vertical drive axis the joint
        carries its weight.
    stop_stiffness : float
        Contact stiffness k_stop of the joint's end stop [N/m]
        (``isolator.limiter.stiffness``): on a vertical drive axis a cart whose
        weight sags the joint beyond the stroke rests on it and compresses it.
        Default inf (a rigid stop).
    """

    leaves: int
    length: float
    width: float
    thickness: float
    spacing: float
    lateral_spacing: float
    youngs_modulus: float
    poisson_ratio: float
    density: float
    allowed_stress: float
    orientation: str
    stage_mass: float
    stage_inertia: tuple[float, float, float]
    com_height: float
    sensor_offset: tuple[float, float] = (0.0, 0.0)
    actuator_offset: tuple[float, float] = (0.0, 0.0)
    damping_ratio: float = 0.01
    cart_mass: float = 0.0
    stop_stiffness: float = math.inf

    @property
    def shear_modulus(self) -> float:
        """G = E / (2 (1 + nu)) [Pa]."""
        return self.youngs_modulus / (2.0 * (1.0 + self.poisson_ratio))

    @property
    def leaf_mass(self) -> float:
        """Mass of all leaves [kg]."""
        return self.leaves * self.density * self.length * self.width * self.thickness

    @property
    def weight(self) -> float:
        """The stage's weight m1 g [N]."""
        return self.stage_mass * GRAVITY

    def leaf_positions(self) -> tuple[tuple[float, float], ...]:
        """(x, y) of each leaf's centre line in the clamp plane [m], relative to the axis."""
        xs = (-0.5 * self.spacing, 0.5 * self.spacing)
        if self.leaves == 2:
            return tuple((x, 0.0) for x in xs)
        e = 0.5 * self.lateral_spacing
        return tuple((x, y) for x in xs for y in (-e, e))


@dataclass(frozen=True)
class Stiffness6(Result):
    """Stiffness in the six directions of the guide's frame at the stage's centre of mass.

    Each value is 1 / the diagonal of the compliance there: the stiffness in
    that direction with the other five free.

    Attributes
    ----------
    x, y, z : float
        Translational stiffness [N/m]; x is the drive direction.
    rx, ry, rz : float
        Rotational stiffness [N m/rad].
    """

    x: float
    y: float
    z: float
    rx: float
    ry: float
    rz: float

    def as_tuple(self) -> tuple[float, ...]:
        """The six values in the order of :data:`DIRECTIONS`."""
        return (self.x, self.y, self.z, self.rx, self.ry, self.rz)


@dataclass(frozen=True)
class Gravity(Result):
    """What the stage's weight does to the guide.

    Attributes
    ----------
    orientation : str
        One of :data:`ORIENTATIONS`.
    axial_load : float
        Force along the leaves, all leaves together [N]: positive in tension
        (hanging), negative in compression (standing), 0 otherwise.
    geometric_stiffness : float
        Gravity's stiffness in the drive direction (signed) [N/m]: about
        -1.2 m1 g / L standing, +1.2 m1 g / L hanging.
    buckling_load : float or None
        Weight at which the guide buckles (the load factor times the weight)
        [N]; None where the weight does not compress the guide.
    buckling_factor : float or None
        Buckling load over the weight [-]; None where the weight does not
        compress the guide.
    sag : float
        Static deflection of the joint along x under the weight it carries [m]:
        on a vertical drive axis the actuator holds the stage and the joint
        the cart, m2 g / k (the spring's alone: beyond the stroke the joint
        rests on its end stop); 0 in the other orientations.
    """

    orientation: str
    axial_load: float
    geometric_stiffness: float
    buckling_load: float | None
    buckling_factor: float | None
    sag: float


@dataclass(frozen=True)
class Mode(Result):
    """One mode the loop may see: computed from the guide, or given by the user.

    Attributes
    ----------
    name : str
        Label (``stage y``, ``leaf bending``, or the user's).
    frequency : float
        Natural frequency [Hz].
    damping_ratio : float
        Modal damping ratio [-].
    direction : str
        Dominant direction: one of :data:`DIRECTIONS`, ``leaf`` for a leaf's own
        mode, ``given`` for a mode the user typed.
    coupling : float
        How strongly the mode shows in the measured drive coordinate, 0 to 1:
        its share of the stage's modal compliance from the actuator to the
        sensor (``|participation|`` over the sum over the stage's modes).
    participation : float
        Signed modal participation from the actuator force to the sensor,
        relative to the stage mass: m1 (c . phi) (b . phi) with the mass
        normalised mode shape phi, the sensor row c and the actuator column b
        [-]. Positive: an antiresonance below the resonance (collocated-like);
        negative: none (non-collocated).
    source : str
        ``computed`` (from the guide) or ``given`` (``isolator.parasitic_modes``).
    collocated : bool
        For a given mode: its factor has an antiresonance below the resonance.
    antiresonance : float or None
        For a given collocated mode: its antiresonance [Hz].
    drive : bool
        The drive (joint) mode itself, which the limit-case models carry as the
        joint: not a parasitic mode.
    """

    name: str
    frequency: float
    damping_ratio: float
    direction: str
    coupling: float
    participation: float
    source: str
    collocated: bool = False
    antiresonance: float | None = None
    drive: bool = False


@dataclass(frozen=True)
class GuideMechanics(Result):
    """The guide as a mechanism: stiffness, stress, gravity and modes.

    Attributes
    ----------
    guide : LeafGuide
        The geometry, material and stage.
    stroke : float
        One-sided stroke the leaves deflect to [m].
    stiffness : Stiffness6
        Elastic stiffness at the stage's centre of mass, undeflected.
    stiffness_at_stroke : Stiffness6
        Elastic stiffness with the joint deflected by the stroke: the support
        directions lose stiffness (the leaves' axial compliance grows with the
        deflection).
    net_drive_stiffness : float
        The drive stiffness with gravity's geometric stiffness [N/m]: the joint
        the loop and the simulation see.
    gravity : Gravity
        What the weight does.
    stress : float
        Peak stress in the leaves at their largest deflection (the stroke: the
        limiter bounds the joint; on a vertical drive axis sagging beyond the
        stroke, the stroke plus the end stop's compression under the cart's
        weight, :func:`fi_design.mechanism.guide.largest_deflection`): bending
        plus the axial stress of the weight [Pa].
    stress_margin : float
        Allowed stress over ``stress`` [-].
    modes : tuple of Mode
        The stage's six modes on the guide (the weight's pre-stress included),
        then the leaves' own first modes, each sorted by frequency.
    """

    guide: LeafGuide
    stroke: float
    stiffness: Stiffness6
    stiffness_at_stroke: Stiffness6
    net_drive_stiffness: float
    gravity: Gravity
    stress: float
    stress_margin: float
    modes: tuple[Mode, ...] = field(default=())

    @property
    def drive_stiffness(self) -> float:
        """Elastic drive stiffness at the stage's centre of mass, ``stiffness.x`` [N/m]."""
        return self.stiffness.x

    @property
    def parasitic_modes(self) -> tuple[Mode, ...]:
        """The modes other than the drive mode, by frequency."""
        return tuple(m for m in self.modes if not m.drive)

    @property
    def lowest_parasitic(self) -> Mode | None:
        """The lowest parasitic mode, or None."""
        par = self.parasitic_modes
        return min(par, key=lambda m: m.frequency) if par else None

    @property
    def buckles(self) -> bool:
        """Whether the weight alone buckles the guide (load factor at or below 1)."""
        f = self.gravity.buckling_factor
        return f is not None and not f > 1.0

    def to_dict(self) -> dict:
        """JSON ``flexure``: leaves, length, width, thickness, spacing, orientation,
        stiffness, stiffness_at_stroke, gravity, modes (units in the docstrings)."""
        g = self.guide
        return {
            "leaves": g.leaves, "length": g.length, "width": g.width, "thickness": g.thickness,
            "spacing": g.spacing, "lateral_spacing": g.lateral_spacing,
            "orientation": g.orientation, "stroke": self.stroke,
            "drive_stiffness": self.drive_stiffness,
            "net_drive_stiffness": self.net_drive_stiffness,
            "stiffness": self.stiffness.to_dict(),
            "stiffness_at_stroke": self.stiffness_at_stroke.to_dict(),
            "gravity": self.gravity.to_dict(), "stress": self.stress,
            "stress_margin": self.stress_margin, "leaf_mass": g.leaf_mass,
            "modes": [m.to_dict() for m in self.modes],
        }


@dataclass(frozen=True)
class FeMechanics(Result):
    """The same guide from a finite-element model: the independent check of the closed forms.

    Attributes
    ----------
    library : str
        The FE library and its version (``pyfe3d 0.11.0``).
    elements_per_leaf : int
        Beam elements along each leaf.
    stiffness : Stiffness6
        Elastic stiffness at the stage's centre of mass, undeflected (static
        solves of unit loads there).
    geometric_stiffness : float
        Change of the drive-direction stiffness at the centre of mass by the
        weight's pre-stress [N/m] (signed).
    buckling_factor : float or None
        Lowest positive load factor of a linear buckling analysis under the
        weight [-]; None where the weight does not compress the guide.
    modes : tuple of Mode
        The stage's six modes on the guide with the weight's pre-stress, then
        the leaves' lowest own modes (``direction`` ``leaf``), by frequency.
    """

    library: str
    elements_per_leaf: int
    stiffness: Stiffness6
    geometric_stiffness: float
    buckling_factor: float | None
    modes: tuple[Mode, ...] = field(default=())


def box_inertia(mass: float, size: tuple[float, float, float]) -> tuple[float, float, float]:
    """Moments of inertia (Ixx, Iyy, Izz) of a uniform box about its centre [kg m^2].

    Parameters
    ----------
    mass : float
        Mass [kg].
    size : (float, float, float)
        Edge lengths along x, y, z [m].

    Examples
    --------
    >>> [round(i * 1e4, 3) for i in box_inertia(1.2, (0.1, 0.1, 0.1))]
    [20.0, 20.0, 20.0]
    """
    a, b, c = size
    return (mass * (b * b + c * c) / 12.0, mass * (a * a + c * c) / 12.0,
            mass * (a * a + b * b) / 12.0)


def steel_cube(mass: float, density: float = 7850.0) -> tuple[float, float, float]:
    """Edge lengths of a steel cube of the given mass [m] (the default stage body)."""
    a = (mass / density) ** (1.0 / 3.0)
    return (a, a, a)

