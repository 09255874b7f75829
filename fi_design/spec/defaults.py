"""Derived defaults: values that depend on other values of the spec, and its warnings.

Four defaults depend on other values (:func:`bristle_damping`,
:func:`joint_damping`, :func:`limiter_damping`, :func:`proposed_stiffness`);
the design crossover of a spec that gives gains is the one they achieve
(:func:`gains_crossover`). :func:`warnings_for` lists suspicious values.
"""

from __future__ import annotations

import math
import sys
from typing import TYPE_CHECKING

from ..display import number, quantity
from ..results.mechanism import GRAVITY
from .sections import Limiter, ParasiticMode

if TYPE_CHECKING:  # pragma: no cover
    from .document import Spec


# --------------------------------------------------------------------------- derived defaults

#: How closely a given crossover must agree with the crossover of given gains [-].
CROSSOVER_AGREEMENT = 0.10


def tuning_mass(spec: Spec) -> float:
    """Mass the controller is tuned on [kg]: m1 + m2 (``total``) or m1 (``stage``)."""
    return spec.total_mass if spec.controller.tuning_mass == "total" else spec.stage.mass


def gains_crossover(spec: Spec) -> float:
    """Crossover of the hardware's gains on the tuning mass [Hz].

    The frequency where |C(j w)| = m w^2, i.e. where the loop of the gains
    around a free tuning mass m crosses 0 dB (the rule's definition of the
    crossover, docs/model.md), with C(s) = kp + ki / s + kd s / (1 + s / wf)
    and wf the D term's roll-off (none when not given). |C| / (m w^2) falls
    with w for every such C, so ``log |C| - log(m w^2)`` has one root in
    ``log w``, found by scipy's ``brentq`` between 1e-6 and 1e9 rad/s (an end
    of that range when the root lies beyond it).
    """
    from scipy.optimize import brentq

    ctl = spec.controller
    g = ctl.gains
    m = tuning_mass(spec)
    wf = 2.0 * math.pi * ctl.roll_off if ctl.roll_off is not None else math.inf

    def excess(x: float) -> float:
        w = math.exp(x)
        d = 1j * w * g.kd if math.isinf(wf) else 1j * w * g.kd / (1.0 + 1j * w / wf)
        return math.log(abs(g.kp + g.ki / (1j * w) + d)) - math.log(m * w * w)

    lo, hi = math.log(1e-6), math.log(1e9)
    if excess(hi) >= 0.0:
        return math.exp(hi) / (2.0 * math.pi)
    if excess(lo) <= 0.0:
        return math.exp(lo) / (2.0 * math.pi)
    return math.exp(brentq(excess, lo, hi, xtol=1e-15, rtol=4.0 * sys.float_info.epsilon)) \
        / (2.0 * math.pi)


def design_crossover(spec: Spec) -> float:
    """The loop's crossover [Hz]: ``controller.crossover``, else the gains' own.

    With explicit gains a given crossover names the crossover they were tuned
    for (it must agree with where they cross the tuning mass over within
    :data:`CROSSOVER_AGREEMENT`): the rule's gains written as
    ``controller.gains`` beside the rule's ``crossover`` give the same design,
    crossover scan included. Without it, the gains' own crossover
    (:func:`gains_crossover`).
    """
    ctl = spec.controller
    return ctl.crossover if ctl.crossover is not None else gains_crossover(spec)


def bristle_damping(spec: Spec) -> float:
    """Bristle damping sigma1 [N s/m]: the given value, else sqrt(sigma0 (m1 + m2))."""
    f = spec.friction
    if f.bristle_damping is not None:
        return f.bristle_damping
    return math.sqrt(f.bristle_stiffness * spec.total_mass)


def limiter_damping(spec: Spec) -> float:
    """Limiter contact damping c_stop [N s/m]: given, else 2 * 0.2 * sqrt(k_stop m1)."""
    lim = spec.isolator.limiter if spec.isolator else Limiter()
    if lim.damping is not None:
        return lim.damping
    return default_limiter_damping(lim.stiffness, spec.stage.mass)


def default_limiter_damping(stiffness: float, stage_mass: float) -> float:
    """The default limiter damping 2 * 0.2 * sqrt(k_stop m1) [N s/m] (damping ratio 0.2).

    Parameters
    ----------
    stiffness : float
        Contact stiffness k_stop [N/m].
    stage_mass : float
        Stage mass m1 [kg].
    """
    return 2.0 * 0.2 * math.sqrt(stiffness * stage_mass)


def stiffness_limit(spec: Spec, stroke: float | None = None) -> float:
    """Maximum drive stiffness k_max = Fs / (safety * stroke) [N/m] (guideline step 3)."""
    s = stroke if stroke is not None else spec.isolator.stroke
    return spec.friction.static / (spec.requirements.stiffness_safety * s)


def proposed_stiffness(spec: Spec, stroke: float | None = None) -> float:
    """Drive stiffness proposed when the spec gives none [N/m]: k_max / 2.

    Half the maximum keeps the flexure force at full stroke at Fs / 2, leaving
    room for friction scatter along the rail, while the joint stays stiff
    enough to push the cart at Coulomb friction within the stroke as long as
    Fc < Fs / 2.
    """
    return 0.5 * stiffness_limit(spec, stroke)


def drive_stiffness(spec: Spec) -> float:
    """The joint stiffness k used for analysis [N/m]: given, else :func:`proposed_stiffness`."""
    iso = spec.isolator
    if iso is None:
        raise ValueError("spec has no isolator")
    return iso.stiffness if iso.stiffness is not None else proposed_stiffness(spec)


#: Damping ratio of the joint mode when the spec gives no joint damping [-].
JOINT_DAMPING_RATIO = 0.05


def joint_damping(spec: Spec, stiffness: float | None = None) -> float:
    """Joint damping c [N s/m]: given, else 2 * 0.05 * sqrt(k m1 m2 / (m1 + m2))."""
    iso = spec.isolator
    if iso is None:
        raise ValueError("spec has no isolator")
    if iso.damping is not None:
        return iso.damping
    k = stiffness if stiffness is not None else drive_stiffness(spec)
    return default_joint_damping(k, spec.stage.mass, spec.cart.mass)


def default_joint_damping(stiffness: float, stage_mass: float, cart_mass: float) -> float:
    """The default joint damping [N s/m]: :data:`JOINT_DAMPING_RATIO` of the joint mode.

    ``2 zeta sqrt(|k| m1 m2 / (m1 + m2))``: the joint's mode, stage against
    cart on the drive stiffness, damped at the ratio zeta (the magnitude of a
    negative stiffness, a guide the weight has buckled).

    Parameters
    ----------
    stiffness : float
        Drive stiffness k [N/m].
    stage_mass, cart_mass : float
        m1 and m2 [kg].
    """
    m1, m2 = stage_mass, cart_mass
    return 2.0 * JOINT_DAMPING_RATIO * math.sqrt(abs(stiffness) * m1 * m2 / (m1 + m2))


def antiresonance(mode: ParasiticMode) -> float:
    """Antiresonance of a collocated parasitic mode [Hz]: given, else frequency / sqrt(2)."""
    return mode.antiresonance if mode.antiresonance is not None else mode.frequency / math.sqrt(2.0)


# --------------------------------------------------------------------------- warnings

#: A move this many times the isolator's stroke is implausible (a unit slip, most likely: a
#: long-stroke stage moves up to about a metre on a stroke of half a millimetre, 2000 times).
MOVE_STROKE_PLAUSIBLE = 2000.0

#: An end stop's contact stiffness at least this many times the joint's (its given drive
#: stiffness, else k_max) limits the stroke, as the limit cases with the joint on its limiter
#: (rigid there) assume.
LIMITER_STIFFER = 10.0


#: Mean densities of a stage given by its box (``stage.size``), ``(least, most)`` [kg/m^3]:
#: denser than osmium (22,590) no solid is; an open frame in its bounding box is lighter than
#: a solid block, but not a hundredth of water. Outside, the size's unit is the likely slip,
#: and the inertia on the guide (its tilt modes) is off by as much.
STAGE_DENSITY = (10.0, 22600.0)


def _weight_twice(spec: Spec) -> list[tuple[str, str]]:
    """The warning on a load offset beside a vertical drive axis, whose weight the design
    adds to the simulated actuator force (:attr:`fi_design.model.Model.held_weight`): an
    offset that stands for the weight counts it twice."""
    iso = spec.isolator
    flexure = None if iso is None else iso.flexure
    if flexure is None or flexure.orientation != "vertical_axis":
        return []
    path, offset = "friction.offset", spec.friction.offset
    for i, e in enumerate(spec.effects):
        if e.type == "force_offset":  # the effect sets the simulated load in its place
            path, offset = f"effects[{i}].offset", e.offset
    if not offset:
        return []
    weight = spec.total_mass * GRAVITY
    return [(path, f"a load offset of {quantity(offset, 'N', 4)} on a vertical drive axis "
                   "(isolator.flexure.orientation: vertical_axis), whose weight (m1 + m2) g = "
                   f"{quantity(weight, 'N', 4)} the design already adds to the actuator's "
                   "simulated force (the simulation carries no weight): an offset that stands "
                   "for the weight counts it twice; give only the drive's own offset here "
                   "(0 without)")]


def warnings_for(spec: Spec) -> list[tuple[str, str]]:
    """Suspicious but legal input, as ``(path, message)`` pairs.

    A warning fires on the user's own values, and on a default only where the
    default is a poor fit for this spec (and then says so): a bristle damping
    the user gave that breaks the LuGre dissipativity condition sigma1 < sigma2
    Fc / (Fs - Fc) (the warning recommends a value within the bound and says
    what it costs: the presliding mode then rings; the default sqrt(sigma0
    (m1 + m2)), damping ratio 0.5 of the presliding mode, breaks the bound
    deliberately and is not warned about when left out, nor when given at
    its value), a stroke within five presliding ranges, a move
    :data:`MOVE_STROKE_PLAUSIBLE` times the stroke or more, a motion that
    outlasts the run, a hunting window that starts before the last move ends, an end stop
    the user made less than :data:`LIMITER_STIFFER` times stiffer than the joint, a stage
    box whose mean density lies outside :data:`STAGE_DENSITY`,
    a load offset (``friction.offset`` or a ``force_offset`` effect) on a vertical drive
    axis, whose weight the actuator's forces already add,
    a loop without the hardware's sampling and delay (a
    continuous controller without delay: the margins and the hunting depend
    on both), and a ``simulation.crossover_scan.step`` (read, not used).
    """
    out: list[tuple[str, str]] = []
    if spec.simulation.crossover_scan.step is not None:
        out.append(("simulation.crossover_scan.step",
                    "has no effect: the lowest hunting-free crossover is the fold of the "
                    "hunting cycle, bisected to 0.01 Hz or 0.1 % of the crossover, whichever is "
                    "larger, between simulation.crossover_scan.start and stop; leave the key "
                    "out"))
    f = spec.friction
    gap = f.static - f.coulomb
    if f.model == "lugre" and gap > 0 and f.bristle_damping is not None:
        s1 = f.bristle_damping
        default = math.sqrt(f.bristle_stiffness * spec.total_mass)
        bound = f.viscous * f.coulomb / gap
        if s1 >= bound and not math.isclose(s1, default, rel_tol=5e-3):
            within = 0.9 * bound
            ratio = within / (2.0 * default)  # sigma1 / (2 sqrt(sigma0 m)) of the presliding mode
            advice = (f"a value below the bound, e.g. {quantity(within, 'N*s/m', 3)}, keeps it "
                      f"dissipative but damps the presliding mode at a ratio of only "
                      f"{number(ratio, 2)}, where the default sqrt(sigma0 (m1 + m2)) = "
                      f"{quantity(default, 'N*s/m')} damps it at 0.5" if bound > 0 else
                      "only sigma1 = 0 meets it without viscous or Coulomb friction")
            out.append(("friction.bristle_damping",
                        f"sigma1 = {quantity(s1, 'N*s/m')} (given) is not below sigma2 Fc / "
                        f"(Fs - Fc) = {quantity(bound, 'N*s/m')}: the LuGre model is not "
                        f"guaranteed dissipative "
                        f"(Barabanov and Ortega); {advice}; leave the key out for the default"))
    if spec.isolator is not None:
        presl = f.static / f.bristle_stiffness
        if spec.isolator.stroke < 5 * presl:
            out.append(("isolator.stroke",
                        f"stroke {quantity(spec.isolator.stroke, 'm', 3)} is within 5x the presliding "
                        f"range Fs/sigma0 = {quantity(presl, 'm', 3)}: the joint can hardly isolate"))
    iso = spec.isolator
    if iso is not None and "stiffness" in iso.limiter.model_fields_set:
        k = iso.stiffness if iso.stiffness is not None else stiffness_limit(spec)
        if iso.limiter.stiffness < LIMITER_STIFFER * k:
            whose = ("the joint's drive stiffness" if iso.stiffness is not None else
                     "k_max = Fs / stroke (the stiffest joint step 3 allows)")
            out.append(("isolator.limiter.stiffness",
                        "the end stop's contact stiffness "
                        f"{quantity(iso.limiter.stiffness, 'N/m')} is less than "
                        f"{number(LIMITER_STIFFER)} times {whose}, {quantity(k, 'N/m')}: it "
                        "hardly limits the stroke, while the limit cases with the limiter "
                        "engaged (3 and 4) take the joint on its end stop as rigid"))
    out += _weight_twice(spec)
    size = spec.stage.size
    if size is not None:
        rho = spec.stage.mass / (size[0] * size[1] * size[2])
        least, most = STAGE_DENSITY
        if not least <= rho <= most:
            out.append(("stage.size",
                        f"the stage's {quantity(spec.stage.mass, 'kg', 4)} in a box of "
                        + " x ".join(quantity(v, 'm', 4) for v in size)
                        + f" is a mean density of {quantity(rho, 'kg/m**3', 3)}, "
                        + (f"denser than any solid (osmium, the densest, about {quantity(most, 'kg/m**3', 3)})"
                           if rho > most else
                           "less than a hundredth of water's")
                        + ": check the size's unit; the stage's inertia on the guide, and "
                        "so its tilt modes, follow from it"))
    if spec.isolator is not None:
        for i, mv in enumerate(spec.motion.moves):
            ratio = abs(mv.distance) / spec.isolator.stroke
            if ratio >= MOVE_STROKE_PLAUSIBLE:
                out.append((f"motion.moves[{i}].distance",
                            f"a move of {quantity(mv.distance, 'm', 3)} is {number(ratio, 3)} "
                            "times the isolator stroke of "
                            f"{quantity(spec.isolator.stroke, 'm', 3)}: check its unit (a bare "
                            "number is in metres); the family of moves the stage is judged on "
                            "grows with it"))
    t_end = spec.motion.end_time
    h = spec.requirements.hunting
    if t_end > spec.motion.duration:
        out.append(("motion.duration",
                    f"the last move ends at {quantity(t_end, 's', 4)}, after the run ends at "
                    f"{quantity(spec.motion.duration, 's', 6)}: the stage is still moving when "
                    "the simulation stops, and the spec's move is not finished (undetermined, "
                    "never settled)"))
    if t_end > h.window_start:
        whose = ("" if "window_start" in h.model_fields_set
                 else " (the default window start: set requirements.hunting.window_start and "
                      "motion.duration for this motion)")
        w1 = h.window_start + h.window_length
        where = ("inside the hunting window that starts at" if t_end < w1 else
                 f"after the hunting window [{quantity(h.window_start, 's', 6)}, "
                 f"{quantity(w1, 's', 6)}) ends; it starts at")
        out.append(("requirements.hunting.window_start",
                    f"the last move ends at {quantity(t_end, 's', 4)}, {where} "
                    f"{quantity(h.window_start, 's', 6)}{whose}"))
    for i, e in enumerate(spec.effects):
        if e.type == "quantization" and e.resolution > h.settle_band:
            out.append((f"effects[{i}].resolution",
                        f"the position quantization step {quantity(e.resolution, 'm', 4)} is "
                        "coarser than the settle band requirements.hunting.settle_band = "
                        f"{quantity(h.settle_band, 'm', 4)}: the controller cannot see an error "
                        "within the band it is judged on (check the unit: a bare number is in "
                        "metres; an encoder's step is nanometres to micrometres)"))
    ctl = spec.controller
    delayed = any(e.type == "time_delay" for e in spec.effects)
    if ctl.sample_rate is None and ctl.delay == 0 and not delayed:
        out.append(("controller.sample_rate",
                    "the loop is continuous-time without delay: the hardware samples and "
                    "computes with a delay, which takes phase margin and moves the crossover "
                    "where hunting stops; give controller.sample_rate and controller.delay of "
                    "the hardware to judge the loop it has"))
    return out
