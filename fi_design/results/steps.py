"""Results of the four guideline steps: friction gap, crossover, stiffness, flexure, gains.

Produced by :func:`fi_design.guideline.design` (steps 1 to 4 and the loop
responses of the four limit cases) and :func:`fi_design.flexure.size_flexure`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from . import Check, Result, to_jsonable
from .controller import ControlLaw, PidGains
from .linear import CaseMargins

__all__ = ["FrictionGapResult", "ModeSeparation", "CrossoverResult", "StiffnessResult", "FlexureResult", "RULE_FORM", "CONTROLLER_FORM", "HAND_OFF_FORM", "PidResult", "CaseResponse", "LoopResponses"]


@dataclass(frozen=True)
class FrictionGapResult(Result):
    """Step 1: the gap between static and Coulomb friction.

    Attributes
    ----------
    static : float
        Static friction Fs [N].
    coulomb : float
        Coulomb friction Fc [N].
    gap : float
        Fs - Fc [N].
    threshold : float
        ``requirements.friction_gap`` [N]: above it hunting is a risk.
    hunting_risk : bool
        ``gap >= threshold``.
    checks : tuple of Check
        The step's checks (also in :attr:`DesignResult.checks`).
    """

    static: float
    coulomb: float
    gap: float
    threshold: float
    hunting_risk: bool
    checks: tuple[Check, ...] = field(default=(), repr=False)


@dataclass(frozen=True)
class ModeSeparation(Result):
    """A parasitic mode against the crossover.

    Attributes
    ----------
    name : str
        The mode's label.
    frequency : float
        Its frequency [Hz].
    required : float
        ``parasitic_separation`` x desired crossover [Hz].
    collocated : bool
        Collocated (antiresonance first) or not.
    passed : bool
        ``frequency >= required``.
    """

    name: str
    frequency: float
    required: float
    collocated: bool
    passed: bool


@dataclass(frozen=True)
class CrossoverResult(Result):
    """Step 2: desired and achievable crossover, margins per limit case.

    Attributes
    ----------
    desired : float
        ``controller.crossover`` [Hz].
    achievable : float or None
        Highest crossover meeting all requirements [Hz]; None if none does.
    limited_by : str
        What limits the achievable crossover, in words.
    limit_kind : str
        ``margin``, ``mode``, ``scan_limit`` or ``infeasible``
        (see :class:`fi_design.results.linear.AchievableCrossover`).
    limiting_case : str or None
        Case name when a margin limits.
    feasible_ranges : tuple of tuple of float
        Feasible crossover stretches of the scan [Hz].
    delay : float
        Loop delay in the linear analysis [s] (computational plus half a
        sample period).
    stiffness : float or None
        Joint stiffness the cases use [N/m]; None without isolator.
    cases : tuple of fi_design.results.linear.CaseMargins
        Margins of each limit case with the PID tuned at the desired
        crossover, each judged (its ``status`` and ``criteria``).
    parasitic_modes : tuple of ModeSeparation
        Each parasitic mode against ``parasitic_separation`` x desired crossover.
    checks : tuple of Check
        The step's checks.
    """

    desired: float
    achievable: float | None
    limited_by: str
    limit_kind: str
    limiting_case: str | None
    feasible_ranges: tuple[tuple[float, float], ...]
    delay: float
    stiffness: float | None
    cases: tuple[CaseMargins, ...]
    parasitic_modes: tuple[ModeSeparation, ...]
    checks: tuple[Check, ...] = field(default=(), repr=False)


@dataclass(frozen=True)
class StiffnessResult(Result):
    """Step 3: the maximum and the chosen drive stiffness.

    Attributes
    ----------
    maximum : float
        k_max = Fs / (stiffness_safety x stroke) [N/m].
    chosen : float
        The spec's stiffness, else the proposed k_max / 2 [N/m]. Without an
        isolator: the stiffness suggested to start from.
    source : str
        Where ``chosen`` comes from, in words.
    stroke : float
        One-sided stroke [m] (the suggested one without isolator).
    static : float
        Static friction Fs [N].
    safety : float
        ``requirements.stiffness_safety`` [-].
    force_at_stroke : float
        Flexure force at full stroke, chosen x stroke [N]; stays below Fs.
    suggested : bool
        True when the spec has no isolator and the values are a suggestion.
    checks : tuple of Check
        The step's checks.
    """

    maximum: float
    chosen: float
    source: str
    stroke: float
    static: float
    safety: float
    force_at_stroke: float
    suggested: bool
    checks: tuple[Check, ...] = field(default=(), repr=False)


@dataclass(frozen=True)
class FlexureResult(Result):
    """A sized parallel leaf-spring guide, or why none fits.

    Attributes
    ----------
    feasible : bool
        A design within the bounds meets every constraint.
    reason : str
        Empty when feasible; else the binding constraint in words.
    leaves : int
        Number of leaves n.
    length, width, thickness : float or None
        Leaf dimensions L, b, t [m]; None when infeasible.
    drive_stiffness : float or None
        Drive stiffness of the design [N/m].
    target_stiffness : float
        Stiffness aimed at (step 3's chosen stiffness) [N/m].
    maximum_stiffness : float
        k_max the drive stiffness must not exceed [N/m].
    support_stiffness : float or None
        Undeflected support stiffness [N/m].
    stroke : float
        Required one-sided stroke [m].
    stroke_limit : float or None
        Largest stroke within the allowed stress [m].
    stress : float or None
        Peak bending stress at full stroke [Pa].
    allowed_stress : float
        Allowed stress of the material [Pa].
    stress_margin : float or None
        allowed_stress / stress [-]; above 1 is within the limit.
    support_frequency : float or None
        First parasitic (support-direction) frequency with the stage mass [Hz].
    bending_frequency : float or None
        Leaf's own first bending resonance, clamped-guided (conservative) [Hz].
    required_frequency : float
        Parasitic frequencies must reach this: separation x crossover [Hz].
    frequency_margin : float or None
        min(support, bending frequency) / required_frequency [-].
    leaf_mass : float or None
        Mass of all leaves [kg].
    thickness_step : float or None
        Stock step the thickness was chosen from [m]; None: unrounded.
    thickness_tolerance : float
        Thickness tolerance of the stock, +- [m].
    stiffness_range : tuple of float or None
        Drive stiffness at the thickness tolerance, ``k (1 -+ dt / t)^3``
        (lowest, highest) [N/m]; None when infeasible.
    """

    feasible: bool
    reason: str
    leaves: int
    length: float | None
    width: float | None
    thickness: float | None
    drive_stiffness: float | None
    target_stiffness: float
    maximum_stiffness: float
    support_stiffness: float | None
    stroke: float
    stroke_limit: float | None
    stress: float | None
    allowed_stress: float
    stress_margin: float | None
    support_frequency: float | None
    bending_frequency: float | None
    required_frequency: float
    frequency_margin: float | None
    leaf_mass: float | None
    thickness_step: float | None = None
    thickness_tolerance: float = 0.0
    stiffness_range: tuple[float, float] | None = None


#: What the top-level gains of ``pid`` in the JSON are (the rule's, roll-off on the whole PID).
RULE_FORM = ("the rule's gains: C(s) = ks (1 + wi/s) (1 + s/wd) / (1 + s/wt) = (kp + ki/s + kd s) "
             "/ (1 + s/wt), the roll-off wt [rad/s] on the whole PID; not the form of "
             "controller.gains (see hand_off)")


#: What ``pid.controller`` is.
CONTROLLER_FORM = ("the loop as analysed and simulated: kp + ki/s + kd s / (1 + s/roll_off), the "
                   "roll-off [rad/s] on the D term only (inf: an ideal D)")


#: What ``pid.hand_off`` is.
HAND_OFF_FORM = ("the loop in the form the spec takes: controller.gains {kp, ki, kd} with "
                 "controller.roll_off [Hz] on the D term only, controller.derivative_on, "
                 "controller.sample_rate [Hz] and controller.delay [s]")


@dataclass(frozen=True)
class PidResult(Result):
    """Step 4: the PID gains, and the loop's controller.

    Attributes
    ----------
    gains : fi_design.results.controller.PidGains
        The rule's gains at the loop's crossover (JSON: flattened into the
        ``pid`` object); with explicit hardware gains, the recommendation.
    tuning_rule : str
        ``total`` (m1 + m2, the paper's choice) or ``stage`` (m1).
    derivative_ratio : float
        wd = wc / ratio, wt = ratio x wc [-].
    integrator_ratio : float
        wi = wc / ratio [-].
    controller : fi_design.results.controller.ControlLaw
        The loop's controller: the rule's, or the hardware's own gains
        (``source``), as the analysis and the simulation use it.
    static_error : float or None
        Static position error of a loop without integrator against Coulomb
        friction, Fc / kp [m]; None when the loop integrates.
    checks : tuple of Check
        The step's checks.
    """

    gains: PidGains
    tuning_rule: str
    derivative_ratio: float
    integrator_ratio: float
    controller: ControlLaw
    static_error: float | None
    checks: tuple[Check, ...] = field(default=(), repr=False)

    def to_dict(self) -> dict:
        """JSON: the rule's gains (flat, labelled by ``form``), the rule and its ratios, the
        loop's controller and ``hand_off``, the loop in the form the spec's
        ``controller.gains`` takes (with ``roll_off`` in Hz on the D term, the sampling and
        the delay the analysis used)."""
        out = {"form": RULE_FORM, **self.gains.to_dict(), "tuning_rule": self.tuning_rule,
               "derivative_ratio": self.derivative_ratio,
               "integrator_ratio": to_jsonable(self.integrator_ratio),
               "source": self.controller.source, "integrator": self.controller.integrator,
               "static_error": self.static_error,
               "controller": {"form": CONTROLLER_FORM, **self.controller.to_dict()},
               "hand_off": {"form": HAND_OFF_FORM, **self.controller.hand_off()}}
        if self.controller.source == "gains":
            out["rule_in_hardware_form"] = to_jsonable(self.controller.rule_in_this_form())
        return out


@dataclass(frozen=True, eq=False)
class CaseResponse(Result):
    """The open loop of one linear limit case over a frequency grid.

    Attributes
    ----------
    name : str
        Case name (``sliding_free``, ``stuck_free``, ...).
    number : int
        1 to 4 in the paper's order (Figure 2).
    description : str
        The case in words.
    loop : ndarray of complex, shape (n,)
        L(j 2 pi f) = C D P at the grid's frequencies [-].
    """

    name: str
    number: int
    description: str
    loop: np.ndarray


@dataclass(frozen=True, eq=False)
class LoopResponses(Result):
    """Frequency responses of the loop in every limit case (for the Bode, Nyquist and
    sensitivity plots), as the margins of step 2 used it.

    Attributes
    ----------
    frequency : ndarray, shape (n,)
        Log-spaced frequencies [Hz]: from a third of the lowest gain crossover
        of any case (and a thirtieth of the desired crossover) to thirty times
        the desired crossover or twice the highest parasitic mode.
    cases : tuple of CaseResponse
        One per limit case, in the paper's order.
    """

    frequency: np.ndarray
    cases: tuple[CaseResponse, ...]
