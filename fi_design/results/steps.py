"""Results of the four guideline steps: friction gap, crossover, stiffness, flexure, gains.

Produced by :func:`fi_design.guideline.design` (steps 1 to 4 and the loop
responses of the four limit cases) and :func:`fi_design.flexure.size_flexure`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from . import Check, Result, to_jsonable
from .controller import ControlLaw, DiscreteController, DriveGains, Filter, PidGains
from .linear import CaseMargins
from .mechanism import GuideMechanics

__all__ = ["FrictionGapResult", "ModeSeparation", "NotchSuggestion", "CrossoverResult", "StiffnessResult", "FlexureResult", "RULE_FORM", "CONTROLLER_FORM", "HAND_OFF_FORM", "PidResult", "CaseResponse", "LoopResponses"]


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
        ``parasitic_separation`` x the loop's crossover [Hz]
        (:attr:`CrossoverResult.loop_crossover`).
    collocated : bool
        Collocated (antiresonance first) or not.
    passed : bool
        ``frequency >= required``.
    source : str
        ``computed`` (from the flexure guide) or ``given`` (the spec's).
    direction : str
        Dominant direction (x, y, z, rx, ry, rz, leaf; ``given`` for the spec's).
    coupling : float
        How strongly it shows in the measured drive coordinate, 0 to 1.
    """

    name: str
    frequency: float
    required: float
    collocated: bool
    passed: bool
    source: str = "given"
    direction: str = "given"
    coupling: float = 1.0


@dataclass(frozen=True)
class NotchSuggestion(Result):
    """What a notch at the mode that limits the crossover would allow.

    Attributes
    ----------
    notch : fi_design.results.controller.Filter
        The notch, added after the spec's own filters (``controller.filters``).
    achievable : float or None
        The achievable crossover with it [Hz]; None when none is.
    limited_by : str
        What limits that one, in words.
    limit_kind : str
        ``margin``, ``mode``, ``scan_limit`` or ``infeasible``.
    """

    notch: Filter
    achievable: float | None
    limited_by: str
    limit_kind: str


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
        Each parasitic mode against ``parasitic_separation`` x the loop's
        crossover (``loop_crossover``).
    loop_crossover : float or None
        The loop's actual crossover at the desired one: the highest in-band
        0 dB crossing of any limit case [Hz]; the parasitic separation is
        judged on it. None when no case crosses in the band (then the
        desired crossover stands in).
    loop_crossover_case : str or None
        The case that crossing belongs to.
    limiting_mode : str or None
        The parasitic mode that limits the achievable crossover (through a
        margin at its resonance, or the separation); None when none does.
    limiting_mode_frequency : float or None
        Its frequency [Hz].
    notch : NotchSuggestion or None
        What a notch at that mode would allow (a margin limit only).
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
    loop_crossover: float | None = None
    loop_crossover_case: str | None = None
    limiting_mode: str | None = None
    limiting_mode_frequency: float | None = None
    notch: NotchSuggestion | None = None
    checks: tuple[Check, ...] = field(default=(), repr=False)

    @property
    def separation_crossover(self) -> float:
        """The crossover the parasitic separation is judged on [Hz]: the loop's, else the desired."""
        return self.desired if self.loop_crossover is None else self.loop_crossover


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
    """The isolator's leaf-spring guide: drawn in the spec or sized from stock, or why none fits.

    Attributes
    ----------
    feasible : bool
        A guide exists (drawn, or sized within the bounds meeting every
        constraint). A drawn guide is always "feasible"; the checks judge it.
    reason : str
        Empty when feasible; else the binding constraint of the sizing in words.
    drawn : bool
        True when the spec draws the guide (one value per leaf dimension).
    mechanics : fi_design.results.mechanism.GuideMechanics or None
        The guide as a mechanism: six stiffnesses, gravity, stress, modes.
    modes_at_stroke : tuple of fi_design.results.mechanism.Mode
        The stage's modes with the joint at full stroke (the support
        directions softer).
    target_stiffness : float or None
        Net drive stiffness the sizing aimed at [N/m]; None for a drawn guide.
    maximum_stiffness : float
        k_max the net drive stiffness must not exceed [N/m].
    stroke : float
        One-sided stroke [m].
    required_frequency : float
        Every parasitic mode must reach this: separation x crossover [Hz].
    required_buckling : float
        ``requirements.buckling_factor`` [-].
    stroke_limit : float or None
        Largest stroke within the allowed stress [m].
    thickness_step : float or None
        Stock step the thickness was chosen from [m]; None: unrounded.
    thickness_tolerance : float
        Thickness tolerance of the stock, +- [m].
    stiffness_range : tuple of float or None
        Drive stiffness at the thickness tolerance (lowest, highest) [N/m].
    """

    feasible: bool
    reason: str
    drawn: bool
    mechanics: GuideMechanics | None
    modes_at_stroke: tuple = ()
    target_stiffness: float | None = None
    maximum_stiffness: float = 0.0
    stroke: float = 0.0
    required_frequency: float = 0.0
    required_buckling: float = 1.0
    stroke_limit: float | None = None
    thickness_step: float | None = None
    thickness_tolerance: float = 0.0
    stiffness_range: tuple[float, float] | None = None

    # ---- views of the guide

    @property
    def guide(self):
        """The guide's geometry (LeafGuide), or None."""
        return None if self.mechanics is None else self.mechanics.guide

    @property
    def leaves(self) -> int | None:
        """Number of leaves, or None."""
        return None if self.guide is None else self.guide.leaves

    @property
    def length(self) -> float | None:
        """Leaf length L [m], or None."""
        return None if self.guide is None else self.guide.length

    @property
    def width(self) -> float | None:
        """Leaf width b [m], or None."""
        return None if self.guide is None else self.guide.width

    @property
    def thickness(self) -> float | None:
        """Leaf thickness t [m], or None."""
        return None if self.guide is None else self.guide.thickness

    @property
    def drive_stiffness(self) -> float | None:
        """Net drive stiffness (gravity included) [N/m], or None."""
        return None if self.mechanics is None else self.mechanics.net_drive_stiffness

    @property
    def stress(self) -> float | None:
        """Peak stress at full stroke [Pa], or None."""
        return None if self.mechanics is None else self.mechanics.stress

    @property
    def allowed_stress(self) -> float | None:
        """Allowed stress [Pa], or None."""
        return None if self.guide is None else self.guide.allowed_stress

    @property
    def stress_margin(self) -> float | None:
        """Allowed over actual stress [-], or None."""
        return None if self.mechanics is None else self.mechanics.stress_margin

    @property
    def lowest_mode(self):
        """The lowest parasitic mode, undeflected or at full stroke (Mode), or None."""
        if self.mechanics is None:
            return None
        cands = [m for m in self.mechanics.parasitic_modes]
        cands += [m for m in self.modes_at_stroke if not m.drive]
        return min(cands, key=lambda m: m.frequency) if cands else None

    def to_dict(self) -> dict:
        """JSON ``flexure``: the guide as in its mechanics, with the sizing's terms."""
        out = {"feasible": self.feasible, "reason": self.reason, "drawn": self.drawn,
               "target_stiffness": self.target_stiffness,
               "maximum_stiffness": self.maximum_stiffness,
               "required_frequency": self.required_frequency,
               "required_buckling": self.required_buckling,
               "stroke_limit": self.stroke_limit, "thickness_step": self.thickness_step,
               "thickness_tolerance": self.thickness_tolerance,
               "stiffness_range": to_jsonable(self.stiffness_range)}
        if self.mechanics is not None:
            out.update(self.mechanics.to_dict())
            out["modes_at_stroke"] = [m.to_dict() for m in self.modes_at_stroke]
        return out


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
        Ascending frequencies [Hz]: from a third of the lowest gain crossover
        of any case (and a thirtieth of the desired crossover) to thirty times
        the desired crossover or twice the highest parasitic mode (a sampled
        controller's Nyquist frequency at most); log-spaced, packed at every
        resonance and antiresonance, holding every crossing and sensitivity
        peak (:func:`fi_design.responses.loop_responses`).
    cases : tuple of CaseResponse
        One per limit case, in the paper's order.
    nyquist : float or None
        The Nyquist frequency of a sampled controller [Hz], where the grid
        ends; None in continuous time.
    """

    frequency: np.ndarray
    cases: tuple[CaseResponse, ...]
    nyquist: float | None = None
