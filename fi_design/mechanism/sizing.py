"""Sizing the leaf-spring guide from stock: the drive stiffness, and everything else it must meet.

:func:`evaluate` computes the guide's mechanics over a whole grid of leaf
dimensions at once (the closed forms of :mod:`.guide` broadcast): the net
drive stiffness (gravity included), the buckling factor, the lowest
parasitic mode of the stage undeflected and at full stroke, the leaves' own
modes and the stress. :func:`size_guide` searches that grid for step 3:

- thickness from stock (multiples of ``flexure.thickness_step`` within the
  bounds, so the leaf can be bought), length log-spaced within its bounds,
  and per point the width that brings the net drive stiffness to the target
  (the width enters the drive stiffness about linearly), within its bounds;
- constraints: net drive stiffness at or below k_max, stress within the
  allowed, buckling factor at or above ``requirements.buckling_factor``,
  every parasitic mode (the stage's five, undeflected and at full stroke, and
  the leaves' own) at or above the required frequency;
- among the designs that meet them, those within :data:`STIFFNESS_TIE` of the
  closest stiffness; of these the one with the largest smallest margin (the
  stress's, the modes', buckling's, and k_max over the drive stiffness of the
  stock's thickest leaves: thin stock's tolerance scatters k the most).

A dimension given as one value (a drawn guide) is not searched;
:func:`drawn_guide` evaluates a guide drawn in full. The stock's thickness
tolerance +-dt moves the drive stiffness with t^3 (:func:`stiffness_range`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..display import millimetres as _mm
from ..display import number, plain, quantity
from ..results.mechanism import LeafGuide
from ..results.steps import FlexureResult
from . import guide as _guide
from . import leaf as _leaf
from . import mechanics
from .geometry import StageBody, leaf_guide

__all__ = ["GRID_POINTS", "STIFFNESS_TIE", "GridMechanics", "stock_thicknesses",
           "stiffness_range", "net_stiffness", "evaluate", "reevaluate", "drawn_guide",
           "size_guide", "MARGIN_WORDS", "SizingMargin", "sizing_margin"]

#: Grid points of a searched continuous dimension (length).
GRID_POINTS = 161
#: Designs within this relative stiffness error of the closest one count as equally close.
STIFFNESS_TIE = 0.01


def stock_thicknesses(bounds: tuple[float, float], step: float | None,
                      points: int = GRID_POINTS) -> np.ndarray:
    """Leaf thicknesses the sizing may use [m].

    Parameters
    ----------
    bounds : (float, float)
        Smallest and largest thickness [m] (equal for a drawn thickness).
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
    >>> [round(float(t) * 1e3, 2) for t in stock_thicknesses((0.12e-3, 0.3e-3), 0.05e-3)]
    [0.15, 0.2, 0.25, 0.3]
    """
    t0, t1 = bounds
    if t0 == t1:
        return np.array([t0])
    if step is None:
        return np.geomspace(t0, t1, points)
    lo = math.ceil(t0 / step - 1e-9)
    hi = math.floor(t1 / step + 1e-9)
    return np.array([float(plain(i * step, 12)) for i in range(lo, hi + 1)])  # 0.45e-3, not ...04


def stiffness_range(guide: LeafGuide, tolerance: float) -> tuple[float, float]:
    """Net drive stiffness of the guide's leaves at the thickness tolerance [N/m].

    The elastic stiffness goes with t^3 (about ``k (1 -+ dt / t)^3``);
    gravity's part does not change.

    Parameters
    ----------
    guide : LeafGuide
        The guide as drawn.
    tolerance : float
        Thickness tolerance +-dt [m], below t.

    Returns
    -------
    (float, float)
        Lowest and highest net drive stiffness [N/m].
    """
    t = guide.thickness
    lo, hi = net_stiffness(guide, guide.length, guide.width,
                           np.array([t - tolerance, t + tolerance]))
    return float(lo), float(hi)


@dataclass(frozen=True, eq=False)
class GridMechanics:
    """The guide's mechanics over a grid of leaf dimensions (arrays of one shape, SI).

    Attributes
    ----------
    length, width, thickness : numpy.ndarray
        L, b, t [m].
    net : numpy.ndarray
        Net drive stiffness at the centre of mass, gravity included [N/m].
    buckling : numpy.ndarray
        Buckling factor [-]; inf where the weight does not compress the guide.
    lowest_mode : numpy.ndarray
        Lowest parasitic mode of the stage, undeflected or at full stroke, or
        of a leaf [Hz].
    stress : numpy.ndarray
        Peak stress at full stroke [Pa].
    """

    length: np.ndarray
    width: np.ndarray
    thickness: np.ndarray
    net: np.ndarray
    buckling: np.ndarray
    lowest_mode: np.ndarray
    stress: np.ndarray


def _parasitic_low(guide: LeafGuide, K: np.ndarray) -> np.ndarray:
    """Lowest stage mode other than the drive (x) mode [Hz], batched."""
    M = np.diag(_guide.mass_matrix(guide))
    s = 1.0 / np.sqrt(M)
    A = K * s[:, None] * s[None, :]
    w2, psi = np.linalg.eigh(0.5 * (A + np.swapaxes(A, -1, -2)))
    share_x = psi[..., 0, :] ** 2  # x's share of each mode's kinetic energy
    drive = np.argmax(share_x, axis=-1)
    w2 = np.where(np.arange(6) == drive[..., None], np.inf, w2)
    return np.sqrt(np.maximum(w2.min(axis=-1), 0.0)) / (2.0 * math.pi)


def net_stiffness(guide: LeafGuide, length, width, thickness) -> np.ndarray:
    """Net drive stiffness at the centre of mass, gravity included, over broadcast arrays [N/m]."""
    dims = dict(length=length, width=width, thickness=thickness)
    h = guide.com_height
    return _guide.net_drive_stiffness(_guide.at_centre(_guide.clamp_stiffness(guide, **dims), h),
                                      _guide.at_centre(_guide.clamp_geometric_stiffness(
                                          guide, **dims), h))


def evaluate(guide: LeafGuide, stroke: float, length, width, thickness) -> GridMechanics:
    """The mechanics of the guide with other leaf dimensions, over broadcast arrays.

    Parameters
    ----------
    guide : LeafGuide
        Material, leaves, spacings, orientation and the stage; its own leaf
        dimensions are replaced.
    stroke : float
        One-sided stroke [m].
    length, width, thickness : numpy.ndarray
        L, b, t [m]; broadcast together.

    Returns
    -------
    GridMechanics
    """
    L, b, t = np.broadcast_arrays(*(np.asarray(a, float) for a in (length, width, thickness)))
    h = guide.com_height
    dims = dict(length=L, width=b, thickness=t)
    Kc = _guide.clamp_stiffness(guide, **dims)
    Kgc = _guide.clamp_geometric_stiffness(guide, **dims)
    K, Kg = _guide.at_centre(Kc, h), _guide.at_centre(Kgc, h)
    Ks = _guide.at_centre(_guide.clamp_stiffness(guide, deflection=stroke, **dims), h)
    net = _guide.net_drive_stiffness(K, Kg)
    force = _guide.leaf_force(guide)
    buckling = np.broadcast_to(_guide.buckling_factor(guide, **dims), L.shape)
    E, G, rho = guide.youngs_modulus, guide.shear_modulus, guide.density
    low = np.minimum(_parasitic_low(guide, K + Kg), _parasitic_low(guide, Ks + Kg))
    low = np.minimum(low, _leaf.bending_frequency(E, rho, L, b, t, force))
    low = np.minimum(low, _leaf.torsion_frequency(G, rho, L, b, t))
    u = _guide.largest_deflection(guide, stroke, net)
    stress = _leaf.bending_stress(E, t, L, u) + abs(force) / (b * t)
    if guide.orientation == "flat":
        stress = stress + 3.0 * guide.weight * L / (guide.leaves * t * b * b)
    return GridMechanics(length=L, width=b, thickness=t, net=net, buckling=buckling,
                         lowest_mode=low, stress=stress)


#: What each of the sizing's margins (:func:`sizing_margin`) compares, in words.
MARGIN_WORDS = ("the allowed stress over the stress", "the lowest parasitic mode over the "
                "required", "the buckling factor over the required", "k_max over the drive "
                "stiffness of the stock's thickest leaves")


def _margins(grid: GridMechanics, guide: LeafGuide, kmax: float, f_req: float, b_req: float,
             dt: float) -> np.ndarray:
    """The sizing's margins over a grid, stacked along a first axis in the order of
    :data:`MARGIN_WORDS` (the last one 1 / 0 = inf without a thickness tolerance)."""
    k_thick = (net_stiffness(guide, grid.length, grid.width, grid.thickness + dt) if dt > 0.0
               else np.zeros(grid.net.shape))
    with np.errstate(divide="ignore"):
        return np.stack([guide.allowed_stress / grid.stress, grid.lowest_mode / f_req,
                         grid.buckling / b_req,
                         np.where(dt > 0.0, kmax / np.maximum(k_thick, 1e-300), np.inf)])


@dataclass(frozen=True)
class SizingMargin:
    """The smallest of a sized guide's margins, the one its sizing's tie-break maximises.

    Attributes
    ----------
    value : float
        The smallest margin [-].
    limited_by : str
        What it compares (one of :data:`MARGIN_WORDS`).
    """

    value: float
    limited_by: str


def sizing_margin(fx: FlexureResult) -> SizingMargin:
    """The smallest margin of a feasible guide, as its sizing ranks the guides.

    The stress's, the lowest parasitic mode's, the buckling factor's (each over
    its requirement) and k_max over the drive stiffness of the stock's thickest
    leaves; :func:`size_guide` keeps, among the guides closest to the target
    stiffness, the one with the largest.

    Parameters
    ----------
    fx : FlexureResult
        A feasible guide (its sizing's terms: k_max, the required frequency and
        buckling factor, the thickness tolerance).
    """
    g = fx.guide
    grid = evaluate(g, fx.stroke, g.length, g.width, g.thickness)
    m = _margins(grid, g, fx.maximum_stiffness, fx.required_frequency, fx.required_buckling,
                 fx.thickness_tolerance).reshape(len(MARGIN_WORDS))
    i = int(np.argmin(m))
    return SizingMargin(value=float(m[i]), limited_by=MARGIN_WORDS[i])


def _modes_at_stroke(guide: LeafGuide, stroke: float) -> tuple:
    h = guide.com_height
    K = _guide.at_centre(_guide.clamp_stiffness(guide, deflection=stroke), h)
    Kg = _guide.at_centre(_guide.clamp_geometric_stiffness(guide), h)
    return _guide.stage_modes(guide, K + Kg)


def _result(guide: LeafGuide, stroke: float, *, drawn: bool, flexure, **terms) -> FlexureResult:
    mech = mechanics(guide, stroke)
    step, tol = flexure.thickness_step, flexure.thickness_tolerance
    return FlexureResult(
        feasible=True, reason="", drawn=drawn, mechanics=mech,
        modes_at_stroke=_modes_at_stroke(guide, stroke), stroke=stroke,
        stroke_limit=float(_leaf.stroke_limit(guide.allowed_stress, guide.youngs_modulus,
                                              guide.thickness, guide.length)),
        thickness_step=None if drawn else step, thickness_tolerance=tol,
        stiffness_range=stiffness_range(guide, tol),
        **terms)


def reevaluate(fx: FlexureResult, guide: LeafGuide) -> FlexureResult:
    """The same result for a changed guide (another stage mass, say), its terms kept.

    Parameters
    ----------
    fx : FlexureResult
        A feasible result.
    guide : LeafGuide
        The guide to evaluate in its place.
    """
    from dataclasses import replace

    mech = mechanics(guide, fx.stroke)
    return replace(fx, mechanics=mech, modes_at_stroke=_modes_at_stroke(guide, fx.stroke),
                   stiffness_range=stiffness_range(guide, fx.thickness_tolerance))


def drawn_guide(flexure, body: StageBody, *, stroke: float, maximum_stiffness: float,
                required_frequency: float, required_buckling: float,
                cart_mass: float = 0.0, stop_stiffness: float = math.inf) -> FlexureResult:
    """The guide the spec draws (one value per leaf dimension), evaluated.

    Parameters
    ----------
    flexure : fi_design.spec.Flexure
        The drawn guide (``flexure.drawn``).
    body : StageBody
        The stage it carries.
    stroke : float
        One-sided stroke [m].
    maximum_stiffness : float
        k_max [N/m], for the checks.
    required_frequency : float
        Lowest allowed parasitic frequency [Hz], for the checks.
    required_buckling : float
        Required buckling factor [-], for the checks.
    cart_mass : float, optional
        m2 [kg].
    stop_stiffness : float, optional
        The end stop's contact stiffness k_stop [N/m] (a vertical axis's cart may rest on it);
        default inf (rigid).
    """
    g = leaf_guide(flexure, body, length=flexure.length, width=flexure.width,
                   thickness=flexure.thickness, cart_mass=cart_mass,
                   stop_stiffness=stop_stiffness)
    return _result(g, stroke, drawn=True, flexure=flexure, maximum_stiffness=maximum_stiffness,
                   required_frequency=required_frequency, required_buckling=required_buckling)


def size_guide(flexure, body: StageBody, *, target_stiffness: float, maximum_stiffness: float,
               stroke: float, required_frequency: float, required_buckling: float,
               cart_mass: float = 0.0, stop_stiffness: float = math.inf,
               points: int = GRID_POINTS, bounds: dict | None = None) -> FlexureResult:
    """Size a parallel leaf-spring guide for a net drive stiffness.

    Parameters
    ----------
    flexure : fi_design.spec.Flexure
        Material, leaves, orientation, spacings and [min, max] bounds (or one
        value) of length, width and thickness [m].
    body : StageBody
        The stage the guide carries.
    target_stiffness : float
        Net drive stiffness to aim at, gravity included [N/m].
    maximum_stiffness : float
        k_max [N/m]; the net drive stiffness stays at or below it.
    stroke : float
        One-sided stroke [m].
    required_frequency : float
        Lowest allowed parasitic frequency [Hz].
    required_buckling : float
        Lowest allowed buckling factor [-].
    cart_mass : float, optional
        m2 [kg].
    stop_stiffness : float, optional
        The end stop's contact stiffness k_stop [N/m] (a vertical axis's cart may rest on it);
        default inf (rigid).
    points : int, optional
        Grid points of the length. Default :data:`GRID_POINTS`.
    bounds : dict, optional
        ``{"length": (min, max), ...}`` [m] in place of the flexure's bounds of those
        dimensions (a guide sized just beyond them, :mod:`.bounds`).

    Returns
    -------
    FlexureResult
        The design, or ``feasible=False`` with the binding constraint in ``reason``.
    """
    kt, kmax = float(target_stiffness), float(maximum_stiffness)
    terms = dict(target_stiffness=kt, maximum_stiffness=kmax, stroke=stroke,
                 required_frequency=required_frequency, required_buckling=required_buckling,
                 thickness_step=flexure.thickness_step,
                 thickness_tolerance=flexure.thickness_tolerance)
    (L0, L1), (b0, b1), (t0, t1) = (tuple((bounds or {}).get(n, flexure.bounds(n)))
                                     for n in ("length", "width", "thickness"))
    stock = stock_thicknesses((t0, t1), flexure.thickness_step, points)
    if stock.size == 0:
        return FlexureResult(feasible=False, drawn=False, mechanics=None, reason=(
            f"stock: no multiple of the {_mm(flexure.thickness_step)} thickness step lies "
            f"within the thickness bounds {_mm(t0)} to {_mm(t1)}"), **terms)
    base = leaf_guide(flexure, body, length=L0, width=b0, thickness=stock[0],
                      cart_mass=cart_mass, stop_stiffness=stop_stiffness)
    if base.leaves == 4:  # the two leaves of a row side by side: at most as wide as apart
        b1 = max(b0, min(b1, base.lateral_spacing))
    L = (np.geomspace(L0, L1, points) if L1 > L0 else np.array([L0]))[:, None]
    t = stock[None, :]
    n, E = base.leaves, base.youngs_modulus
    k_geo = n * 1.2 * _guide.leaf_force(base) / L
    per_width = n * E * t ** 3 / L ** 3
    b = np.clip((kt - k_geo) / per_width, b0, b1) if b1 > b0 else np.full(np.broadcast(
        L, t).shape, b0)
    for _ in range(2 if b1 > b0 else 0):  # the exact model: shear, rotations, gravity
        net = net_stiffness(base, L, b, t)
        slope = np.maximum(net - k_geo, 1e-12) / b
        b = np.clip(b + (kt - net) / slope, b0, b1)
    grid = evaluate(base, stroke, L, b, t)
    # a leaf thinner than wide, as a drawn one must be: else it bends across its width
    ok_shape = grid.thickness < grid.width
    ok_stress = ok_shape & (grid.stress <= base.allowed_stress)
    ok_stiff = (grid.net > 0.0) & (grid.net <= kmax * (1.0 + 1e-9))
    ok_buckle = grid.buckling >= required_buckling
    ok_modes = grid.lowest_mode >= required_frequency
    ok = ok_stress & ok_stiff & ok_buckle & ok_modes
    if not ok.any():
        return FlexureResult(feasible=False, drawn=False, mechanics=None, reason=_why(
            grid, base, stroke, kmax, required_frequency, required_buckling,
            (ok_shape, ok_stress, ok_stiff, ok_buckle, ok_modes), b1), **terms)
    err = np.where(ok, np.abs(np.log(np.maximum(grid.net, 1e-300) / kt)), np.inf)
    margin = np.min(_margins(grid, base, kmax, required_frequency, required_buckling,
                             flexure.thickness_tolerance), axis=0)
    close = err <= err.min() + STIFFNESS_TIE
    i, j = np.unravel_index(np.argmax(np.where(close, margin, -np.inf)), err.shape)
    chosen = leaf_guide(flexure, body, length=float(grid.length[i, j]),
                        width=float(grid.width[i, j]), thickness=float(grid.thickness[i, j]),
                        cart_mass=cart_mass, stop_stiffness=stop_stiffness)
    return _result(chosen, stroke, drawn=False, flexure=flexure, target_stiffness=kt,
                   maximum_stiffness=kmax, required_frequency=required_frequency,
                   required_buckling=required_buckling)


def _why(grid: GridMechanics, guide: LeafGuide, stroke: float, kmax: float, f_req: float,
         buckling_req: float, oks, widest: float) -> str:
    """Name the binding constraint of an infeasible sizing: the first, in the order shape,
    stress, stiffness, buckling, modes, that no design meeting the ones before it can meet
    (``widest``: the largest width the sizing may take [m])."""
    ok_shape, ok_stress, ok_stiff, ok_buckle, ok_modes = oks
    sa = guide.allowed_stress
    if not ok_shape.any():
        return ("shape: every leaf within the bounds is at least as thick as it is wide "
                f"(thickness from {_mm(float(grid.thickness.min()))}, width at most "
                f"{_mm(widest)}); a leaf must be thinner than wide")
    if not ok_stress.any():  # ok_stress holds the shape: the least stress of shaped leaves
        least = float(np.min(np.where(ok_shape, grid.stress, np.inf)))
        return ("stress: every leaf within the bounds reaches at least "
                f"{quantity(least, 'Pa', 4, shown=('MPa', 1e-6))} at {_mm(stroke)} stroke, above "
                "the allowed "
                f"{quantity(sa, 'Pa', 4, shown=('MPa', 1e-6))}")
    sel = ok_stress
    if not (sel & (grid.net > 0.0)).any():
        least = float(np.max(np.where(sel, grid.net, -np.inf)))
        return (f"gravity: the stage's {quantity(guide.weight, 'N', 3)} {guide.orientation} "
                f"outweighs the elastic drive stiffness of every leaf thin and long enough for "
                f"{_mm(stroke)} stroke within {quantity(sa, 'Pa', 4, shown=('MPa', 1e-6))}: "
                f"their net drive stiffness is at most {quantity(least, 'N/m', 4)}, the guide "
                "unstable")
    if not (sel & ok_stiff).any():
        least = float(np.min(np.where(sel & (grid.net > 0.0), grid.net, np.inf)))
        return (f"stiffness with stress: leaves thin and long enough for {_mm(stroke)} stroke "
                f"within {quantity(sa, 'Pa', 4, shown=('MPa', 1e-6))} are at least "
                f"{quantity(least, 'N/m', 4)} stiff (net of gravity), above k_max = "
                f"{quantity(kmax, 'N/m', 6)}")
    sel = sel & ok_stiff
    if not (sel & ok_buckle).any():
        best = float(np.max(np.where(sel, grid.buckling, -np.inf)))
        return (f"buckling: leaves within the stress limit and below k_max carry the stage's "
                f"{quantity(guide.weight, 'N', 3)} {guide.orientation} with a buckling factor of "
                f"at most {number(best, 3)}, below the {number(buckling_req, 6)} required")
    sel = sel & ok_buckle
    best = float(np.max(np.where(sel, grid.lowest_mode, -np.inf)))
    return (f"parasitic modes: among leaves within the stress limit, below k_max and safe "
            "against buckling, the lowest parasitic mode reaches at most "
            f"{quantity(best, 'Hz', 4)}, below the required {quantity(f_req, 'Hz', 4)}")
