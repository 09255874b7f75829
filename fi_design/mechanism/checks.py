"""Step 3's judgement of the guide: stiffness, stress, buckling, modes, sag, slenderness.

The one place the guide is judged (:func:`flexure_checks`); the design's
checks, the verdict, the report and the console read these checks.
"""

from __future__ import annotations

from ..display import millimetres as _mm
from ..display import number, percent, quantity
from ..results import Check, Status
from ..results.mechanism import GRAVITY
from ..results.steps import FlexureResult

__all__ = ["SLENDERNESS", "flexure_checks"]


def _g(x: float) -> str:
    return number(x, 4)


#: Slack beyond the stock's stiffness range within which a guide still realises the joint's
#: stiffness [-] (the sizing solves the width to about 1e-3 of its target).
STIFFNESS_MATCH = 0.02

#: Leaf length over thickness below which the beam model of a leaf is doubtful [-]: a stubby
#: leaf bends as a block (the clamps' compliance, plate and end effects) more than as a beam.
SLENDERNESS = 10.0


def flexure_checks(fx: FlexureResult | None, crossover: float,
                   separation: float, joint_stiffness: float | None = None,
                   k_max: float | None = None) -> tuple[Check, ...]:
    """Step 3's checks of the guide: stiffness, stress, buckling, modes, sag, slenderness.

    A leaf shorter than :data:`SLENDERNESS` times its thickness gets a warning
    (``flexure.slenderness``, WARN): the closed forms are beam theory.

    Parameters
    ----------
    fx : FlexureResult or None
        The guide (:func:`step3_flexure`).
    crossover : float
        The loop's crossover [Hz] (the highest 0 dB crossing of the limit cases in the loop's
        band, as step 2 judges the given modes on it; the desired crossover when no case
        crosses there); every parasitic mode must lie at ``separation`` times it.
    separation : float
        ``requirements.parasitic_separation`` [-].
    joint_stiffness : float, optional
        The joint's drive stiffness the analysis uses [N/m] (``isolator.stiffness``, or the
        one step 3 chose). When it is not the guide's own, a check that the guide realises
        it: within the guide's range over the stock's thickness tolerance, widened by
        :data:`STIFFNESS_MATCH`.
    k_max : float, optional
        Step 3's largest drive stiffness for the guide's stroke [N/m]. On a vertical drive
        axis a joint that sags onto its stop is told the window of stiffness that would
        hold the cart off it within k_max (none when the cart's weight is not below k_max
        times the stroke, about static friction).
    """
    if fx is None:
        return ()
    step = "step 3 flexure"
    if not fx.feasible:
        return (Check("flexure", False, None, None, "-",
                      f"no leaf-spring guide within the bounds fits: {fx.reason}", step=step),)
    m, g = fx.mechanics, fx.guide
    dims = (f"{g.leaves} leaves L x b x t = {_mm(g.length)} x {_mm(g.width)} x "
            f"{_mm(g.thickness)}, {g.orientation}"
            + (" (as drawn)" if fx.drawn else " (sized)"))
    k, kmax = m.net_drive_stiffness, fx.maximum_stiffness
    grav = m.gravity
    out = [Check("flexure.stiffness", 0.0 < k <= kmax * (1 + 1e-9), k, kmax, "N/m",
                 f"{dims}: net drive stiffness {_g(k)} N/m (elastic {_g(m.stiffness.x)} N/m, "
                 f"gravity {_g(grav.geometric_stiffness)} N/m), k_max {_g(kmax)} N/m"
                 + ("" if k > 0 else ": the weight has buckled the guide"), step=step)]
    if joint_stiffness is not None and joint_stiffness != k:
        out.append(_realises(fx, k, float(joint_stiffness), step))
    out.append(Check("flexure.stress", m.stress <= g.allowed_stress, m.stress, g.allowed_stress,
                 "Pa", f"stress at full stroke {quantity(m.stress, 'Pa')}, allowed "
                 f"{quantity(g.allowed_stress, 'Pa')} (margin x{number(m.stress_margin, 3)})",
                 step=step))
    if grav.buckling_factor is not None:
        f, need = grav.buckling_factor, fx.required_buckling
        out.append(Check(
            "flexure.buckling", f >= need, f, need, "-",
            f"buckling load {_g(grav.buckling_load)} N against the stage's weight "
            f"{_g(g.weight)} N standing on the leaves: factor {number(f, 3)}"
            + (f", at least {number(need, 6)} required" if f >= need else
               (": the guide buckles under the stage" if f <= 1.0 else
                f", below the {number(need, 6)} required")), step=step))
    low = fx.lowest_mode
    need = separation * crossover
    if low is not None:
        at_stroke = any(low is x for x in fx.modes_at_stroke)
        out.append(Check(
            "flexure.modes", low.frequency >= need, low.frequency, need, "Hz",
            f"lowest parasitic mode of the guide: {low.name} at {_g(low.frequency)} Hz"
            + (" at full stroke" if at_stroke else "")
            + (", above" if low.frequency >= need else ", below")
            + f" {number(separation, 6)} x the loop's crossover {quantity(crossover, 'Hz', 4)}: "
            + quantity(need, 'Hz', 4), step=step))
    if grav.sag > 0.0:
        out.append(Check(
            "flexure.sag", grav.sag < fx.stroke, grav.sag, fx.stroke, "m",
            f"on the vertical axis the joint carries the cart's weight: it sags "
            f"{_mm(grav.sag)} of its {_mm(fx.stroke)} stroke"
            + ("" if grav.sag < fx.stroke else ": it rests on its end stop"
               + _sag_window(g.cart_mass * GRAVITY, fx.stroke, k_max)), step=step))
    slender = g.length / g.thickness
    if slender < SLENDERNESS:
        out.append(Check(
            "flexure.slenderness", None, slender, SLENDERNESS, "-",
            f"the leaves are {_mm(g.length)} long and {_mm(g.thickness)} thick: L/t = "
            f"{number(slender, 3)}, below {number(SLENDERNESS, 3)}, where beam theory is "
            "doubtful (the model includes shear, but the clamps' compliance and the leaf's "
            "end and plate effects are left out): its stiffness, stress and modes are "
            "estimates; measure the guide or model it in FE, or draw longer, thinner leaves",
            step=step, status=Status.WARN))
    return tuple(out)


def _sag_window(weight: float, stroke: float, k_max: float | None) -> str:
    """Where a vertical axis's joint holds the cart off its stop within step 3's limit.

    The sag ``m2 g / k`` stays within the stroke for ``k > m2 g / stroke``; step 3 allows
    ``k <= k_max`` (about ``Fs / stroke``): a window only while the cart's weight is below
    ``k_max`` times the stroke, whatever the leaves.
    """
    if k_max is None:
        return ""
    least = weight / stroke
    text = (f"; off its stop needs k above m2 g / stroke = {number(least, 4)} N/m (the cart's "
            f"weight {quantity(weight, 'N', 3)}), and step 3 allows at most k_max = "
            f"{number(k_max, 4)} N/m")
    if least >= k_max:
        return text + (": no joint does both at this stroke; carry the cart's weight "
                       "otherwise (a counterweight or a preload spring)")
    return text + f": a window of {percent(k_max / least - 1.0, 2)} above the lower bound"


def _realises(fx: FlexureResult, k: float, joint: float, step: str) -> Check:
    """Whether the guide's net drive stiffness ``k`` realises the joint's ``joint`` [N/m]."""
    lo, hi = fx.stiffness_range or (k, k)
    lo, hi = min(lo, k), max(hi, k)
    ok = lo * (1.0 - STIFFNESS_MATCH) <= joint <= hi * (1.0 + STIFFNESS_MATCH)
    made = "sized" if not fx.drawn else "drawn"
    text = (f"the {made} guide's net drive stiffness {_g(k)} N/m"
            + (f" ({_g(lo)} to {_g(hi)} N/m over the stock's thickness tolerance)"
               if hi > lo else "")
            + f" against the joint's {_g(joint)} N/m that the analysis simulates")
    if ok:
        return Check("flexure.joint", True, k, joint, "N/m", text + ": it realises it",
                     step=step)
    if fx.drawn:
        why = ("; the analysis uses isolator.stiffness: leave it out to use the drawn guide's "
               "own stiffness, or redraw the guide")
    else:
        why = (f"; {number(k / joint, 3)} x: no guide within the flexure's bounds reaches it "
               "while meeting k_max, the stress, buckling and the parasitic modes (this is the "
               "closest that does): widen the bounds (longer or narrower leaves, thinner "
               "stock) or choose a drive stiffness near this one")
    return Check("flexure.joint", False, k, joint, "N/m", text + why, step=step)
