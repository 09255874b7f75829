"""A sized guide on the bounds of its sizing: which bound, and whether beyond it adds margin.

The sizing (:func:`.sizing.size_guide`) keeps, among the guides closest to
the target stiffness, the one with the largest smallest margin. Where that
margin keeps growing past a bound of the spec's ``isolator.flexure`` (a
longer leaf, say), the guide sits on the bound: the user's range, not the
physics, chose it. :func:`bound_notes` finds each leaf dimension on a bound
and sizes the guide again with that bound moved out by :data:`BEYOND` (a
stock thickness: by one step), the other dimensions within their bounds: the
note says whether that adds margin, and only then that the next dimension
would.
"""

from __future__ import annotations

import math

from ..display import millimetres as _mm
from ..display import number, quantity
from ..results.steps import BoundNote, FlexureResult
from .geometry import StageBody
from .sizing import GRID_POINTS, STIFFNESS_TIE, size_guide, sizing_margin

__all__ = ["BEYOND", "bound_notes"]

#: How far a bound is moved out to size the guide again: an upper bound times (1 + BEYOND), a
#: lower one over it [-] (a stock thickness: the next multiple of the step).
BEYOND = 0.1

#: Relative growth of the smallest margin that counts as adding margin [-] (the sizing's own
#: resolution: its widths are solved to about 1e-3).
GROWTH = 0.001

#: The direction beyond each bound in words.
_WORDS = {("length", "upper"): "longer", ("length", "lower"): "shorter",
          ("width", "upper"): "wider", ("width", "lower"): "narrower",
          ("thickness", "upper"): "thicker", ("thickness", "lower"): "thinner"}
_SIZE = {"length": "long", "width": "wide", "thickness": "thick"}


def _on_bound(value: float, lo: float, hi: float, step: float | None) -> tuple[str, ...]:
    """The sides whose bound ``value`` sits on (a stock thickness: no further multiple of the
    step within the bound)."""
    if step is not None:
        return tuple(side for side, out in (("lower", value - step < lo * (1 - 1e-9)),
                                            ("upper", value + step > hi * (1 + 1e-9))) if out)
    tol = 1e-6
    return tuple(side for side, at in (("lower", value <= lo * (1 + tol)),
                                       ("upper", value >= hi * (1 - tol))) if at)


def bound_notes(fx: FlexureResult, flexure, body: StageBody, *, cart_mass: float = 0.0,
                stop_stiffness: float = math.inf,
                points: int = GRID_POINTS) -> tuple[BoundNote, ...]:
    """The sized guide's leaf dimensions that sit on a bound of the sizing, each with its note.

    Parameters
    ----------
    fx : FlexureResult
        A guide sized by :func:`.sizing.size_guide` (a drawn or infeasible one has no notes).
    flexure : fi_design.spec.Flexure
        The spec's ``isolator.flexure`` it was sized within.
    body : StageBody
        The stage it carries.
    cart_mass : float, optional
        m2 [kg].
    stop_stiffness : float, optional
        The end stop's contact stiffness [N/m].
    points : int, optional
        Grid points of the length of the sizing beyond the bound.

    Returns
    -------
    tuple of BoundNote
        One per dimension and side on a bound, in the order length, width, thickness.
    """
    if not fx.feasible or fx.drawn or fx.mechanics is None or fx.target_stiffness is None:
        return ()
    kt = fx.target_stiffness
    mine = sizing_margin(fx)
    err = abs(math.log(fx.drive_stiffness / kt))
    out = []
    for name in ("length", "width", "thickness"):
        lo, hi = flexure.bounds(name)
        if lo == hi:
            continue
        value = float(getattr(fx, name))
        step = flexure.thickness_step if name == "thickness" else None
        for side in _on_bound(value, lo, hi, step):
            up = side == "upper"
            if step is not None:
                span = (value, value + step) if up else (value - step, value)
            else:
                span = (hi, hi * (1 + BEYOND)) if up else (lo / (1 + BEYOND), lo)
            if name == "thickness" and span[0] <= flexure.thickness_tolerance:
                continue  # no stock thinner than its tolerance
            other = size_guide(flexure, body, target_stiffness=kt,
                               maximum_stiffness=fx.maximum_stiffness, stroke=fx.stroke,
                               required_frequency=fx.required_frequency,
                               required_buckling=fx.required_buckling, cart_mass=cart_mass,
                               stop_stiffness=stop_stiffness, points=points,
                               bounds={name: span})
            ok = other.feasible and abs(math.log(other.drive_stiffness / kt)) <= err + STIFFNESS_TIE
            out.append(_note(name, side, value, (lo, hi), name in flexure.model_fields_set,
                             mine, span[1] if up else span[0], other if ok else None))
    return tuple(out)


def _note(name: str, side: str, value: float, bounds: tuple[float, float], given: bool, mine,
          limit: float, other: FlexureResult | None) -> BoundNote:
    key = f"isolator.flexure.{name}"
    theirs = None if other is None else sizing_margin(other).value
    adds = theirs is not None and theirs > mine.value * (1.0 + GROWTH)
    whose = "you set" if given else "by default"
    # the two margins with the digits that tell them apart (3 at least, 6 at most)
    digits = next((d for d in range(3, 7) if theirs is None
                   or number(mine.value, d) != number(theirs, d)), 6)
    text = (f"the leaves' {name}, {_mm(value)}, sits on the {side} bound of its range "
            f"{_mm(bounds[0])} to {_mm(bounds[1])} ({key}, {whose}); their smallest margin, "
            f"{mine.limited_by}, is x{number(mine.value, digits)}")
    past = f"with the bound moved to {_mm(limit)}"
    if other is None:
        text += (f"; {past} no guide meets the constraints as close to the target stiffness")
    else:
        got = (f"{past} the sizing keeps {_mm(other.length)} x {_mm(other.width)} x "
               f"{_mm(other.thickness)} with x{number(theirs, digits)}")
        text += (f"; {got}: {_WORDS[(name, side)]} leaves would add margin (widen {key} to "
                 "let the sizing choose)" if adds else
                 f"; {got}: {_WORDS[(name, side)]} leaves would add no margin")
    bound = value if name == "thickness" else bounds[0 if side == "lower" else 1]
    return BoundNote(dimension=name, key=key, side=side, bound=bound, given=given,
                     margin=mine.value, limited_by=mine.limited_by, beyond=limit,
                     margin_beyond=theirs, adds_margin=adds, text=text)
