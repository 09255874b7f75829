"""Sizing a parallel leaf-spring guide for the friction isolator (guideline step 3).

A parallel leaf-spring guide of ``n`` identical leaves (length L, width b,
thickness t [m], Young's modulus E [Pa]), each clamped at the frame and guided
(clamped, without rotation) at the stage, gives:

===========================  ===============================================
drive stiffness              ``k = n E b t^3 / L^3`` [N/m]
support (axial) stiffness    ``k_support = n E b t / L`` [N/m]
bending stress at stroke s   ``sigma = 3 E t s / L^2`` [Pa]
stroke limit                 ``s_max = sigma_allow L^2 / (3 E t)`` [m]
support frequency            ``sqrt(k_support / m1) / (2 pi)`` [Hz]
leaf bending frequency       ``lambda^2 / (2 pi L^2) t sqrt(E / (12 rho))`` [Hz]
===========================  ===============================================

The support stiffness is the undeflected value; it falls as the leaves deflect,
so a design with little frequency margin deserves a check at full stroke. The
leaf's own first bending resonance uses the clamped-guided beam,
``lambda = 2.36502`` (first root of ``tan x + tanh x = 0``): a massless guided
end. With the heavy stage at the guided end a leaf behaves closer to
clamped-clamped (``lambda = 4.73004``, four times the frequency), so the
reported value is conservative.

:func:`size_flexure` searches a grid over length and thickness within the
spec's bounds and, per grid point, takes the width that brings the drive
stiffness closest to the target while keeping it at or below ``k_max`` and the
support frequency at or above the required one (the width enters the drive and
support stiffness linearly and nothing else). Among the designs that meet every
constraint it keeps those within 1 % of the closest stiffness and picks the one
with the largest smallest margin (stress, support frequency, leaf frequency).

Thickness comes from stock: the grid holds only multiples of
``flexure.thickness_step`` (0.05 mm by default) within the bounds, so the
sized leaf can be bought, while length and width, which are machined, stay
continuous. The stock's thickness tolerance +-dt moves the drive stiffness
with t^3: :func:`stiffness_range` gives ``k (1 -+ dt / t)^3``, the range the
built isolator may have (``null`` ``thickness_step`` sizes an unrounded
thickness, for studies).
"""

from __future__ import annotations

import math

import numpy as np

from .display import quantity
from .results.design import FlexureResult

__all__ = [
    "CLAMPED_GUIDED_ROOT", "FlexureResult", "drive_stiffness", "support_stiffness",
    "bending_stress", "stroke_limit", "support_frequency", "bending_frequency",
    "stock_thicknesses", "stiffness_range", "size_flexure",
]

#: First root of tan(x) + tanh(x) = 0: the clamped-guided beam's first mode, lambda [-].
CLAMPED_GUIDED_ROOT = 2.365020372431352

#: Grid points per dimension (length, thickness) of the sizing search.
GRID_POINTS = 161

#: Designs within this relative stiffness error of the closest one count as equally close.
STIFFNESS_TIE = 0.01


# --------------------------------------------------------------------------- formulas


def drive_stiffness(leaves, youngs_modulus, width, thickness, length):
    """Drive stiffness ``n E b t^3 / L^3`` [N/m] of ``n`` clamped-guided leaves.

    Parameters
    ----------
    leaves : int
        Number of parallel leaves n.
    youngs_modulus : float
        E [Pa].
    width, thickness, length : float or numpy.ndarray
        b, t, L [m]; arrays broadcast.

    Returns
    -------
    float or numpy.ndarray
        Drive stiffness [N/m].
    """
    return leaves * youngs_modulus * width * thickness ** 3 / length ** 3


def support_stiffness(leaves, youngs_modulus, width, thickness, length):
    """Axial (support-direction) stiffness ``n E b t / L``, undeflected.

    Parameters
    ----------
    leaves : int
        Number of parallel leaves n.
    youngs_modulus : float
        E [Pa].
    width, thickness, length : float or numpy.ndarray
        b, t, L [m]; arrays broadcast.

    Returns
    -------
    float or numpy.ndarray
        Support stiffness [N/m].
    """
    return leaves * youngs_modulus * width * thickness / length


def bending_stress(youngs_modulus, thickness, length, stroke):
    """Peak bending stress ``3 E t s / L^2`` of a clamped-guided leaf.

    Parameters
    ----------
    youngs_modulus : float
        E [Pa].
    thickness, length : float or numpy.ndarray
        t, L [m].
    stroke : float
        Deflection s of the guided end [m].

    Returns
    -------
    float or numpy.ndarray
        Stress at the clamped ends [Pa].
    """
    return 3.0 * youngs_modulus * thickness * stroke / length ** 2


def stroke_limit(allowed_stress, youngs_modulus, thickness, length):
    """Largest deflection ``sigma_allow L^2 / (3 E t)`` within the allowed stress.

    Parameters
    ----------
    allowed_stress : float
        sigma_allow [Pa].
    youngs_modulus : float
        E [Pa].
    thickness, length : float or numpy.ndarray
        t, L [m].

    Returns
    -------
    float or numpy.ndarray
        Stroke limit [m].
    """
    return allowed_stress * length ** 2 / (3.0 * youngs_modulus * thickness)


def support_frequency(support_stiffness_value, mass):
    """First parasitic (support-direction) frequency ``sqrt(k_support / m) / (2 pi)`` [Hz].

    Parameters
    ----------
    support_stiffness_value : float or numpy.ndarray
        Support stiffness [N/m].
    mass : float
        Supported mass [kg] (the stage, m1).

    Returns
    -------
    float or numpy.ndarray
        Frequency [Hz].
    """
    return np.sqrt(support_stiffness_value / mass) / (2.0 * math.pi)


def bending_frequency(youngs_modulus, density, thickness, length):
    """First bending resonance of one leaf as a clamped-guided beam.

    ``lambda^2 / (2 pi L^2) sqrt(E I / (rho A))`` with ``I / A = t^2 / 12`` and
    ``lambda`` = :data:`CLAMPED_GUIDED_ROOT`.

    Parameters
    ----------
    youngs_modulus : float
        E [Pa].
    density : float
        rho [kg/m^3].
    thickness, length : float or numpy.ndarray
        t, L [m].

    Returns
    -------
    float or numpy.ndarray
        Frequency [Hz].
    """
    return (CLAMPED_GUIDED_ROOT ** 2 / (2.0 * math.pi * length ** 2)) * thickness \
        * np.sqrt(youngs_modulus / (12.0 * density))


def stock_thicknesses(bounds: tuple[float, float], step: float | None,
                      points: int = GRID_POINTS) -> np.ndarray:
    """Leaf thicknesses the sizing may use [m].

    Parameters
    ----------
    bounds : (float, float)
        Smallest and largest thickness [m].
    step : float or None
        Stock step [m]: the multiples of it within the bounds; None gives
        ``points`` log-spaced thicknesses (an unrounded sizing).
    points : int, optional
        Grid points without a step.

    Returns
    -------
    numpy.ndarray
        Thicknesses [m], ascending; empty when no multiple of ``step`` lies
        within the bounds.

    Examples
    --------
    >>> [round(t * 1e3, 2) for t in stock_thicknesses((0.12e-3, 0.3e-3), 0.05e-3)]
    [0.15, 0.2, 0.25, 0.3]
    """
    t0, t1 = bounds
    if step is None:
        return np.geomspace(t0, t1, points)
    lo = math.ceil(t0 / step - 1e-9)
    hi = math.floor(t1 / step + 1e-9)
    return np.array([float(f"{i * step:.12g}") for i in range(lo, hi + 1)])  # 0.45e-3, not ...04


def stiffness_range(stiffness: float, thickness: float, tolerance: float) -> tuple[float, float]:
    """Drive stiffness of leaves at the thickness tolerance: ``k (1 -+ dt / t)^3`` [N/m].

    Parameters
    ----------
    stiffness : float
        Drive stiffness at the nominal thickness [N/m].
    thickness : float
        Nominal leaf thickness t [m].
    tolerance : float
        Thickness tolerance +-dt [m], below t.

    Returns
    -------
    (float, float)
        Lowest and highest drive stiffness [N/m] (k goes with t^3, width and
        length as drawn).

    Examples
    --------
    >>> [round(k) for k in stiffness_range(1000.0, 0.4e-3, 0.01e-3)]
    [927, 1077]
    """
    r = tolerance / thickness
    return stiffness * (1.0 - r) ** 3, stiffness * (1.0 + r) ** 3


# --------------------------------------------------------------------------- result


# --------------------------------------------------------------------------- sizing


def _mm(x: float) -> str:
    """A flexure dimension: always in mm, so that the lengths of one sentence share a unit."""
    return quantity(x, "m", 3, shown=("mm", 1e3))


def size_flexure(flexure, *, target_stiffness: float, maximum_stiffness: float, stroke: float,
                 stage_mass: float, required_frequency: float,
                 points: int = GRID_POINTS) -> FlexureResult:
    """Size a parallel leaf-spring guide.

    Parameters
    ----------
    flexure : fi_design.spec.Flexure
        Material (E [Pa], allowed stress [Pa], density [kg/m^3]), number of
        leaves and [min, max] bounds of length, width and thickness [m].
    target_stiffness : float
        Drive stiffness to aim at [N/m].
    maximum_stiffness : float
        k_max [N/m]; the design stays at or below it.
    stroke : float
        One-sided stroke the leaves must reach within the allowed stress [m].
    stage_mass : float
        Mass carried in the support direction, m1 [kg].
    required_frequency : float
        Lowest allowed parasitic frequency (support and leaf bending) [Hz].
    points : int, optional
        Grid points per searched dimension. Default :data:`GRID_POINTS`.

    Returns
    -------
    FlexureResult
        The design, or ``feasible=False`` with the binding constraint in ``reason``.
    """
    mat = flexure.material
    E, sa, rho, n = mat.youngs_modulus, mat.allowed_stress, mat.density, flexure.leaves
    (L0, L1), (b0, b1), (t0, t1) = flexure.length, flexure.width, flexure.thickness
    kt, kmax = float(target_stiffness), float(maximum_stiffness)
    w_req = 2.0 * math.pi * required_frequency
    step, tol = flexure.thickness_step, flexure.thickness_tolerance
    empty = dict(leaves=n, target_stiffness=kt, maximum_stiffness=kmax, stroke=stroke,
                 allowed_stress=sa, required_frequency=required_frequency,
                 thickness_step=step, thickness_tolerance=tol)
    stock = stock_thicknesses((t0, t1), step, points)
    none = dict(length=None, width=None, thickness=None, drive_stiffness=None,
                support_stiffness=None, stroke_limit=None, stress=None, stress_margin=None,
                support_frequency=None, bending_frequency=None, frequency_margin=None,
                leaf_mass=None, stiffness_range=None)
    if stock.size == 0:
        return FlexureResult(feasible=False, reason=(
            f"stock: no multiple of the {_mm(step)} thickness step lies within the thickness "
            f"bounds {_mm(t0)} to {_mm(t1)}"), **none, **empty)

    L = np.geomspace(L0, L1, points)[:, None]
    t = stock[None, :]
    per_width = n * E * t ** 3 / L ** 3             # drive stiffness per metre of width
    b_target = kt / per_width
    b_kmax = kmax / per_width
    b_support = stage_mass * w_req ** 2 * L / (n * E * t)
    b_lo = np.maximum(b0, b_support)
    b_hi = np.minimum(b1, b_kmax)
    stress = bending_stress(E, t, L, stroke)
    f_bend = bending_frequency(E, rho, t, L)
    ok_stress = stress <= sa
    ok_stiff = b0 <= b_kmax
    ok_width = b_lo <= b_hi
    ok_bend = f_bend >= required_frequency
    ok = ok_stress & ok_width & ok_bend

    if not ok.any():
        return FlexureResult(feasible=False, reason=_why(
            flexure, E, sa, rho, n, kmax, stroke, stage_mass, required_frequency, L, t,
            ok_stress, ok_stiff, per_width, f_bend), **none, **empty)

    b = np.clip(b_target, b_lo, b_hi)
    k = per_width * b
    err = np.where(ok, np.abs(np.log(k / kt)), np.inf)
    f_sup = support_frequency(support_stiffness(n, E, b, t, L), stage_mass)
    margin = np.minimum(sa / stress, np.minimum(f_sup, f_bend) / required_frequency)
    close = err <= err.min() + STIFFNESS_TIE
    i, j = np.unravel_index(np.argmax(np.where(close, margin, -np.inf)), err.shape)
    Lx, tx, bx = float(L[i, 0]), float(t[0, j]), float(b[i, j])
    kx = float(drive_stiffness(n, E, bx, tx, Lx))
    ks = float(support_stiffness(n, E, bx, tx, Lx))
    sx = float(bending_stress(E, tx, Lx, stroke))
    fs = float(support_frequency(ks, stage_mass))
    fb = float(bending_frequency(E, rho, tx, Lx))
    return FlexureResult(
        feasible=True, reason="", length=Lx, width=bx, thickness=tx, drive_stiffness=kx,
        support_stiffness=ks, stroke_limit=float(stroke_limit(sa, E, tx, Lx)), stress=sx,
        stress_margin=sa / sx, support_frequency=fs, bending_frequency=fb,
        frequency_margin=min(fs, fb) / required_frequency, leaf_mass=n * rho * Lx * bx * tx,
        stiffness_range=stiffness_range(kx, tx, tol), **empty)


def _why(flexure, E, sa, rho, n, kmax, stroke, m1, f_req, L, t, ok_stress, ok_stiff,
         per_width, f_bend) -> str:
    """Name the binding constraint of an infeasible sizing."""
    (L0, L1), (b0, b1), (t0, t1) = flexure.length, flexure.width, flexure.thickness
    # each constraint alone, at its most favourable corner of the bounds
    s_max = float(stroke_limit(sa, E, t0, L1))
    if s_max < stroke:
        return (f"stress: even the longest, thinnest leaf (L = {_mm(L1)}, t = {_mm(t0)}) only "
                f"allows {_mm(s_max)} stroke within {sa / 1e6:.4g} MPa; the isolator needs "
                f"{_mm(stroke)}")
    k_min = float(drive_stiffness(n, E, b0, t0, L1))
    if k_min > kmax:
        return (f"stiffness: even the longest, narrowest, thinnest leaves (L = {_mm(L1)}, "
                f"b = {_mm(b0)}, t = {_mm(t0)}) give {k_min:.4g} N/m, above k_max = "
                f"{kmax:.6g} N/m")
    f_sup_max = float(support_frequency(support_stiffness(n, E, b1, t1, L0), m1))
    if f_sup_max < f_req:
        return (f"support stiffness: even the shortest, widest, thickest leaves (L = {_mm(L0)}, "
                f"b = {_mm(b1)}, t = {_mm(t1)}) give a support frequency of {f_sup_max:.4g} Hz, "
                f"below the required {f_req:.4g} Hz")
    f_b_max = float(bending_frequency(E, rho, t1, L0))
    if f_b_max < f_req:
        return (f"leaf resonance: even the shortest, thickest leaf (L = {_mm(L0)}, t = "
                f"{_mm(t1)}) bends at {f_b_max:.4g} Hz, below the required {f_req:.4g} Hz")
    # combinations, in the order stress -> stiffness -> support -> leaf resonance
    sel = ok_stress
    if not (sel & ok_stiff).any():
        k_low = float(np.min(np.where(sel, per_width * b0, np.inf)))
        return (f"stiffness with stress: leaves thin and long enough for {_mm(stroke)} stroke "
                f"within {sa / 1e6:.4g} MPa are at least {k_low:.4g} N/m stiff, above k_max = "
                f"{kmax:.6g} N/m")
    sel = sel & ok_stiff
    b_best = np.minimum(b1, kmax / per_width)
    f_sup = support_frequency(support_stiffness(n, E, b_best, t, L), m1)
    ok_joint = f_sup >= f_req
    if not (sel & ok_joint).any():
        best = float(np.max(np.where(sel, f_sup, -np.inf)))
        return (f"support stiffness: among leaves within the stress limit and below k_max = "
                f"{kmax:.6g} N/m, the highest support frequency is {best:.4g} Hz, below the "
                f"required {f_req:.4g} Hz")
    sel = sel & ok_joint
    best = float(np.max(np.where(sel, f_bend, -np.inf)))
    return (f"leaf resonance: among leaves within the stress limit, below k_max and stiff "
            f"enough in support, the highest leaf bending frequency is {best:.4g} Hz, below "
            f"the required {f_req:.4g} Hz")
