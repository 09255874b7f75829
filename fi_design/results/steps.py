"""Results of the four guideline steps: friction gap, crossover, stiffness, flexure, gains.

Produced by :func:`fi_design.guideline.evaluate.evaluate` (steps 1 to 4 and the loop
responses of the four limit cases) and :func:`fi_design.flexure.size_flexure`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from . import Check, Result, to_jsonable
from .controller import ControlLaw, DiscreteController, DriveGains, Filter, PidGains
from .linear import CaseMargins
from .mechanism import GuideMechanics

__all__ = ["FrictionGapResult", "ModeSeparation", "NotchSuggestion", "CrossoverResult", "StiffnessResult", "FlexureResult", "BoundNote", "DRIVE_FORM", "RULE_FORM", "DRIVE_UNITS", "RULE_UNITS", "DISCRETE_UNITS", "DISCRETE_METHOD", "PidResult", "CaseResponse", "LoopResponses"]


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
    def sag(self) -> float:
        """Static sag of the joint under the weight it carries [m] (``m2 g / k`` on a vertical
        drive axis; 0 in the other orientations and without a guide)."""
        return 0.0 if self.mechanics is None else float(self.mechanics.gravity.sag)

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


@dataclass(frozen=True)
class BoundNote(Result):
    """A sized guide's leaf dimension on a bound of its sizing, and whether beyond it adds margin.

    The sizing keeps, among the guides closest to the target stiffness, the one
    with the largest smallest margin; where that grows beyond a bound, the
    bound and not the physics chose the dimension.

    Attributes
    ----------
    dimension : str
        ``length``, ``width`` or ``thickness``.
    key : str
        The spec path of its bounds (``isolator.flexure.length``).
    side : str
        ``lower`` or ``upper``.
    bound : float
        The bound the dimension sits on [m] (for a stock thickness, the last
        multiple of the step within it).
    given : bool
        Whether the spec sets the bounds (False: the default bounds).
    margin : float
        The guide's smallest margin [-] (:func:`fi_design.mechanism.sizing.sizing_margin`).
    limited_by : str
        What that margin compares.
    beyond : float
        The bound moved out, the guide sized again up to it [m].
    margin_beyond : float or None
        The smallest margin of the guide sized so [-]; None where no guide
        there meets the constraints as close to the target stiffness.
    adds_margin : bool
        Whether going beyond the bound adds margin (``margin_beyond`` above ``margin``).
    text : str
        The note in words.
    """

    dimension: str
    key: str
    side: str
    bound: float
    given: bool
    margin: float
    limited_by: str
    beyond: float
    margin_beyond: float | None
    adds_margin: bool
    text: str


#: What ``pid.drive`` is: the one gain set to give a drive.
DRIVE_FORM = ("the gains a drive takes: u = F(s) [kp e + ki integral(e) + kd s / (1 + s / (2 pi "
              "roll_off)) d], e = r - x, d = e or -x (derivative_on), the low-pass on the D term "
              "only, F the filters in series on the output; the spec's controller.gains, "
              "roll_off, derivative_on and filters; frequencies in Hz")

#: What ``pid.rule`` is: the tuning rule's parameters, not gains to copy.
RULE_FORM = ("the tuning rule (series form): C(s) = ks (1 + wi/s) (1 + s/wd) / (1 + s/wt), its "
             "corners given in Hz (integrator_corner = wi / 2 pi, lead_corner = wd / 2 pi, "
             "roll_off = wt / 2 pi, on the whole PID); with the rule, the same loop as drive")

#: Units of the keys of ``pid.drive``, spelt as a spec writes them (``1234 N*s/m``), so that a
#: value with its unit goes back into a spec as it is.
DRIVE_UNITS = {"kp": "N/m", "ki": "N/(m*s)", "kd": "N*s/m", "roll_off": "Hz",
               "sample_rate": "Hz", "delay": "s", "force_limit": "N",
               "filters.frequency": "Hz", "filters.width": "Hz", "filters.depth": "dB",
               "filters.damping": "-", "feedforward.mass": "kg",
               "feedforward.viscous": "N*s/m", "feedforward.coulomb": "N"}

#: Units of the keys of ``pid.rule``.
RULE_UNITS = {"crossover": "Hz", "tuning_mass": "kg", "ks": "N/m", "integrator_corner": "Hz",
              "lead_corner": "Hz", "roll_off": "Hz"}

#: Units of the keys of ``pid.drive.discrete``.
DISCRETE_UNITS = {"sample_rate": "Hz", "kp": "N/m", "integrator_gain": "N/m",
                  "derivative_pole": "-", "derivative_gain": "N/m", "filters.b": "-",
                  "filters.a": "-", "num": "N/m", "den": "-"}

#: How a sampled controller is discretised, in words (JSON ``pid.drive.discrete.method``).
DISCRETE_METHOD = ("per sample: I_k = I_(k-1) + integrator_gain (e_k + e_(k-1)) (trapezoidal), "
                   "D_k = derivative_pole D_(k-1) + derivative_gain (d_k - d_(k-1)) (Tustin; an "
                   "ideal D by the backward difference), u_k = kp e_k + I_k + D_k through each "
                   "filter's biquad y_k = b0 x_k + b1 x_(k-1) + b2 x_(k-2) - a1 y_(k-1) - a2 "
                   "y_(k-2) (Tustin prewarped at the filter's frequency); num/den: the whole "
                   "C(z), descending powers of z")


@dataclass(frozen=True)
class PidResult(Result):
    """Step 4: the PID gains, and the loop's controller.

    Attributes
    ----------
    gains : fi_design.results.controller.PidGains
        The rule's gains at the loop's crossover; with explicit hardware
        gains, the recommendation.
    tuning_rule : str
        ``total`` (m1 + m2, the paper's choice) or ``stage`` (m1).
    derivative_ratio : float
        wd = wc / ratio, wt = ratio x wc [-].
    integrator_ratio : float
        wi = wc / ratio [-].
    controller : fi_design.results.controller.ControlLaw
        The loop's controller: the rule's, or the hardware's own gains
        (``source``), with its filters, as the analysis and the simulation
        use it.
    static_error : float or None
        Static position error of a loop without integrator against Coulomb
        friction, (Fs + |offset|) / kp [m]
        (:attr:`fi_design.model.Model.static_error_bound`); None when the
        loop integrates.
    discrete : fi_design.results.controller.DiscreteController or None
        The controller as a sampled drive computes it; None in continuous time.
    drive_gains : fi_design.results.controller.DriveGains or None
        The gains in the drive's units (``controller.drive``); None without.
    checks : tuple of Check
        The step's checks.
    """

    gains: PidGains
    tuning_rule: str
    derivative_ratio: float
    integrator_ratio: float
    controller: ControlLaw
    static_error: float | None
    discrete: DiscreteController | None = None
    drive_gains: DriveGains | None = None
    checks: tuple[Check, ...] = field(default=(), repr=False)

    def drive(self) -> dict:
        """The one gain set a drive takes (JSON ``pid.drive``), frequencies in Hz.

        ``kp`` [N/m], ``ki`` [N/(m s)], ``kd`` [N s/m], ``roll_off`` [Hz] (null:
        an ideal D), ``derivative_on``, ``sample_rate`` [Hz] (null:
        continuous), ``delay`` [s], ``force_limit`` [N] (null: none),
        ``filters`` (the spec's keys), ``feedforward``, ``units``, and
        ``in_drive_units`` (with ``controller.drive``) and ``discrete`` (a
        sampled loop) or null.
        """
        law = self.controller
        out = {"form": DRIVE_FORM, **law.hand_off(),
               "force_limit": to_jsonable(law.force_limit),
               "filters": [f.to_dict() for f in law.filters],
               "feedforward": {"mass": law.ff_mass, "viscous": law.ff_viscous,
                               "coulomb": law.ff_coulomb},
               "units": dict(DRIVE_UNITS),
               "in_drive_units": to_jsonable(self.drive_gains),
               "discrete": None}
        if self.discrete is not None:
            out["discrete"] = {"method": DISCRETE_METHOD, **to_jsonable(self.discrete),
                               "units": dict(DISCRETE_UNITS)}
        return out

    def rule(self) -> dict:
        """The tuning rule's parameters (JSON ``pid.rule``), corners in Hz.

        ``crossover`` [Hz], ``tuning_mass`` [kg], ``ks`` [N/m],
        ``integrator_corner``, ``lead_corner``, ``roll_off`` [Hz], ``units``;
        with the hardware's gains ``in_drive_form``: the rule's gains at the
        same crossover in the drive's form (``kp``, ``ki``, ``kd``,
        ``roll_off`` [Hz] on the D term), the recommendation.
        """
        g = self.gains
        two_pi = 2.0 * math.pi
        out = {"form": RULE_FORM, "crossover": g.crossover, "tuning_mass": g.tuning_mass,
               "ks": g.ks, "integrator_corner": g.wi / two_pi, "lead_corner": g.wd / two_pi,
               "roll_off": g.wt / two_pi, "units": dict(RULE_UNITS)}
        if self.controller.source == "gains":
            r = self.controller.rule_in_this_form()
            out["in_drive_form"] = {"kp": r["kp"], "ki": r["ki"], "kd": r["kd"],
                                    "roll_off": r["roll_off"] / two_pi}
        return out

    def to_dict(self) -> dict:
        """JSON: ``drive`` (the one gain set a drive takes, :meth:`drive`), ``rule`` (the
        tuning rule's parameters, :meth:`rule`), the source, the ratios and the static error."""
        return {"source": self.controller.source, "integrator": self.controller.integrator,
                "static_error": self.static_error, "tuning_rule": self.tuning_rule,
                "derivative_ratio": self.derivative_ratio,
                "integrator_ratio": to_jsonable(self.integrator_ratio),
                "drive": self.drive(), "rule": self.rule()}


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
        peak (:func:`fi_design.loop.responses.loop_responses`).
    cases : tuple of CaseResponse
        One per limit case, in the paper's order.
    nyquist : float or None
        The Nyquist frequency of a sampled controller [Hz], where the grid
        ends; None in continuous time.
    """

    frequency: np.ndarray
    cases: tuple[CaseResponse, ...]
    nyquist: float | None = None
