"""The isolator as a mechanism: the parallel leaf-spring guide, its stiffness, weight and modes.

The friction isolator's joint is a flexure guide carrying the stage: a
mechanism with six directions, a weight to carry and modes of its own, which
the control loop sees. This package computes them from the geometry:

- :mod:`.leaf`: one leaf in closed form (Timoshenko beam blocks, geometric
  stiffness, stress, its own modes);
- :mod:`.guide`: the guide at the stage's centre of mass (six stiffnesses,
  gravity's geometric and load stiffness, buckling, the stage's six modes);
- :mod:`.sizing`: sizing a guide from stock for a drive stiffness and stroke;
- :mod:`.bounds`: a sized guide's dimensions on the sizing's bounds, and whether
  beyond them adds margin;
- :mod:`.fe`: the same guide as a finite-element model (pyfe3d), the
  independent check of the closed forms.

:func:`mechanics` gives a :class:`~fi_design.results.mechanism.GuideMechanics`
for one guide and stroke. A new flexure type is a new geometry value in
:mod:`fi_design.results.mechanism` and its closed forms here.
"""

from __future__ import annotations

from ..results.mechanism import GRAVITY, Gravity, GuideMechanics, LeafGuide
from . import guide as _guide
from . import leaf as _leaf

__all__ = ["mechanics"]


def mechanics(guide: LeafGuide, stroke: float) -> GuideMechanics:
    """The guide as a mechanism: six stiffnesses, at stroke too, gravity, stress and modes.

    Parameters
    ----------
    guide : LeafGuide
        Geometry, material, orientation and the stage it carries.
    stroke : float
        One-sided stroke the leaves deflect to [m].

    Returns
    -------
    GuideMechanics

    Examples
    --------
    >>> from fi_design.results.mechanism import LeafGuide, box_inertia
    >>> g = LeafGuide(leaves=2, length=0.05, width=0.02, thickness=0.4e-3, spacing=0.03,
    ...               lateral_spacing=0.0, youngs_modulus=200e9, poisson_ratio=0.3,
    ...               density=7800.0, allowed_stress=300e6, orientation="standing",
    ...               stage_mass=1.0, stage_inertia=box_inertia(1.0, (0.05,) * 3),
    ...               com_height=0.025)
    >>> m = mechanics(g, 0.3e-3)
    >>> round(m.stiffness.x), round(m.gravity.geometric_stiffness), round(m.net_drive_stiffness)
    (4092, -235, 3857)
    """
    h = guide.com_height
    Kc = _guide.clamp_stiffness(guide)
    Kgc = _guide.clamp_geometric_stiffness(guide)
    K, Kg = _guide.at_centre(Kc, h), _guide.at_centre(Kgc, h)
    K_stroke = _guide.at_centre(_guide.clamp_stiffness(guide, deflection=stroke), h)
    elastic = float(_guide.drive_stiffness(K))
    net = float(_guide.net_drive_stiffness(K, Kg))
    force = _guide.leaf_force(guide)
    compressed = force < 0.0
    factor = _guide.buckling_factor(guide) if compressed else None
    sag = guide.cart_mass * GRAVITY / net if guide.orientation == "vertical_axis" else 0.0
    gravity = Gravity(orientation=guide.orientation, axial_load=force * guide.leaves,
                      geometric_stiffness=net - elastic,
                      buckling_load=None if factor is None else factor * guide.weight,
                      buckling_factor=factor, sag=sag)
    E, L, b, t = guide.youngs_modulus, guide.length, guide.width, guide.thickness
    # the limiter bounds the joint at the stroke: a sag within it only moves where it rests
    u = _guide.largest_deflection(guide, stroke, net)
    stress = float(_leaf.bending_stress(E, t, L, u)) + abs(force) / (b * t)
    if guide.orientation == "flat":  # the weight as shear along the leaves' width
        stress += 3.0 * guide.weight * L / (guide.leaves * t * b * b)
    stage = _guide.stage_modes(guide, K + Kg)
    modes = tuple(sorted(stage + _guide.leaf_modes(guide, stage), key=lambda m: m.frequency))
    return GuideMechanics(guide=guide, stroke=stroke, stiffness=_guide.stiffness6(K),
                          stiffness_at_stroke=_guide.stiffness6(K_stroke),
                          net_drive_stiffness=net, gravity=gravity, stress=stress,
                          stress_margin=guide.allowed_stress / stress if stress > 0 else
                          float("inf"), modes=modes)
