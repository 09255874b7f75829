"""LuGre's dynamic parameters: static friction, Stribeck velocity, bristle stiffness.

They act near zero velocity, where the inverse-dynamics fit leaves the
samples out, and need an excitation that sliding data do not hold.
"""

from __future__ import annotations

from .excitation import MIN_EVENTS, Excitation
from .results import DYNAMIC, UNITS, Parameter

_EXPERIMENT = {
    "static": "a slow velocity sweep through zero (the reference's velocity ramped slowly "
              "across zero), or moves that come to rest and break away again",
    "stribeck_velocity": "a slow velocity sweep through zero, from a few times the expected "
                         "Stribeck velocity in one direction to the same in the other, slow "
                         "enough that the inertial force stays small against friction",
    "bristle_stiffness": "a small-amplitude sine or small steps in presliding (excursions of "
                         "a few micrometres, below the breakaway displacement), resolved by "
                         "the position sensor",
}


def dynamic_parameters(exc: Excitation) -> dict[str, Parameter]:
    """Parameters static, stribeck_velocity, bristle_stiffness: never estimated here.

    Where the record holds the excitation the note says so and names the
    events; the estimate itself is left to a dedicated experiment and fit
    (see the module docstring): none is reported rather than an unreliable one.
    """
    out = {}
    for name in DYNAMIC:
        held = exc.presliding if name == "bristle_stiffness" else exc.breakaway
        if not held:
            out[name] = _not_identifiable(name, exc)
            continue
        what = (f"{exc.presliding_reversals} presliding reversals" if name == "bristle_stiffness"
                else f"{exc.breakaways} breakaways from rest, at t = " + ", ".join(
                    f"{e[1]:.3g} s" for e in exc.events[:6]) + (" ..." if len(exc.events) > 6
                                                                 else ""))
        out[name] = Parameter(None, None, UNITS[name], False,
                              f"the record holds an excitation for it ({what}), but it is not "
                              "estimated: a fit of the replayed breakaways and reversals was not "
                              "reliable in validation (its estimates moved by many standard "
                              "errors under sub-percent errors of the sliding friction); "
                              f"{_EXPERIMENT[name]} identifies it")
    return out


def _not_identifiable(name: str, exc: Excitation) -> Parameter:
    if name == "bristle_stiffness":
        why = (f"the record holds no presliding excitation ({exc.presliding_reversals} "
               f"reversal(s) with an excursion below {exc.presliding_band * 1e6:.3g} um, "
               f"{MIN_EVENTS} needed)")
    else:
        why = (f"the record holds no breakaway from rest ({exc.breakaways} rest(s) of at least "
               f"{exc.dwell * 1e3:.3g} ms followed by sliding, {MIN_EVENTS} needed); it moves "
               f"slower than the velocity threshold for {exc.low_speed_time:.3g} s in all, "
               "passing through, and those samples are left out of the fit")
    return Parameter(None, None, UNITS[name], False,
                     f"not identifiable: {why}; {_EXPERIMENT[name]} would identify it")
