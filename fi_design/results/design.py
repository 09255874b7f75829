"""Results of the design workflow: the four guideline steps, the loop, the confirmation.

Produced by :func:`fi_design.guideline.design` (steps 1 to 4, the loop
responses, the isolator advice), :func:`fi_design.flexure.size_flexure` and
:func:`fi_design.confirm.confirm` (the simulated confirmation).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from ..provenance import Source, current_source
from . import Check, Result, Status, to_jsonable
from .controller import ControlLaw, PidGains
from .linear import CaseMargins
from .simulation import HuntingMetrics, SimulationResult

if TYPE_CHECKING:  # pragma: no cover
    from ..model import Model
    from ..spec import Spec

__all__ = ["FrictionGapResult", "ModeSeparation", "CrossoverResult", "StiffnessResult",
           "FlexureResult", "PidResult", "CaseResponse", "LoopResponses", "IsolatorAdvice",
           "PlantVerdict", "Landing", "Confirmation", "VERDICT_STATUSES",
           "Reason", "Verdict", "RobustnessCheck", "Margins", "Recommendation",
           "DesignResult"]


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


@dataclass(frozen=True)
class IsolatorAdvice(Result):
    """Whether a stage without isolator looks like it needs one.

    Attributes
    ----------
    needed : bool or None
        True: an isolator is recommended; False: not needed; None: it depends
        on whether a higher crossover removes hunting (simulate to decide).
    reason : str
        Why, in words.
    stroke : float
        Stroke to start from [m] (the paper's 0.3 mm).
    stiffness : float
        Stiffness to start from, Fs / (2 x safety x stroke) [N/m].
    maximum_stiffness : float
        k_max for that stroke [N/m].
    """

    needed: bool | None
    reason: str
    stroke: float
    stiffness: float
    maximum_stiffness: float


@dataclass(frozen=True, eq=False)
class PlantVerdict(Result):
    """One simulated plant at the design crossover: its hunting metric and verdict.

    Attributes
    ----------
    plant : str
        ``"isolated"`` or ``"non_isolated"``.
    friction_model : str
        Friction model that produced the verdict (``lugre`` or ``switch``).
    crossover : float
        Crossover simulated [Hz].
    metrics : HuntingMetrics
        The paper's hunting metric of the trace and the verdict (``settled``,
        ``hunting``, ``stuck`` or ``undetermined``) with its reason.
    success : bool
        Whether the integration completed.
    message : str
        Failure description, empty on success.
    static_error_bound : float or None
        For a loop without integrator: the static error it may leave against
        friction, (Fc + |offset|) / kp with the larger Coulomb friction of the
        two directions [m]; None when the loop integrates.
    outcome : str
        What the stage does, with the loop in mind: the metric's verdict,
        except that a loop without integrator resting within
        ``static_error_bound`` (plus the settle band) is ``static_error``,
        not ``stuck``.
    """

    plant: str
    friction_model: str
    crossover: float
    metrics: HuntingMetrics
    success: bool
    message: str
    static_error_bound: float | None = None
    outcome: str = ""

    #: Fields of the metrics in the verdict's JSON (the counted peaks stay out).
    JSON_METRICS = ("hunting_cycles", "amplitude", "period", "settled", "settling_time",
                    "final_error", "verdict", "reason")

    def __post_init__(self) -> None:
        if not self.outcome:
            m = self.metrics
            bound = self.static_error_bound
            rests = (m.verdict == "stuck" and bound is not None
                     and abs(m.final_error) <= bound + m.settle_band)
            object.__setattr__(self, "outcome", "static_error" if rests else m.verdict)

    @classmethod
    def of(cls, plant: str, result: SimulationResult,
           static_error_bound: float | None = None) -> "PlantVerdict":
        """The verdict of a simulation result.

        Parameters
        ----------
        plant : str
            ``"isolated"`` or ``"non_isolated"``.
        result : SimulationResult
            The simulation.
        static_error_bound : float, optional
            The static error a loop without integrator may leave [m].

        Returns
        -------
        PlantVerdict
        """
        return cls(plant=plant, friction_model=result.friction_model, crossover=result.crossover,
                   metrics=result.metrics, success=result.success, message=result.message,
                   static_error_bound=static_error_bound)

    @property
    def acceptable(self) -> bool:
        """Settled, or at rest within the static error of a loop without integrator."""
        return self.outcome in ("settled", "static_error")

    def to_dict(self) -> dict:
        """Flat JSON: plant, model and crossover, the metric's figures and verdict, the
        outcome with the loop in mind, the solver's outcome (SI)."""
        m = self.metrics
        return {"plant": self.plant, "friction_model": self.friction_model,
                "crossover": to_jsonable(self.crossover),
                **{k: to_jsonable(getattr(m, k)) for k in self.JSON_METRICS},
                "outcome": self.outcome,
                "static_error_bound": to_jsonable(self.static_error_bound),
                "success": self.success, "message": self.message}


@dataclass(frozen=True)
class Landing(Result):
    """Where the cart comes to rest after the move (isolated plant).

    Attributes
    ----------
    deflection : float
        Joint deflection x1 - x2 at the end of the simulation [m].
    stroke : float
        One-sided stroke [m].
    stiffness : float
        Drive stiffness k [N/m].
    force : float
        Force the flexure exerts on the resting cart, k * min(|deflection|,
        stroke) [N].
    static_friction : float
        Fs [N].
    on_limiter : bool
        Whether the landing deflection reaches the stroke (the limiter then
        locks the joint and the controller feels the friction again).
    rule_force : float
        The paper's conservative bound k * stroke [N].
    """

    deflection: float
    stroke: float
    stiffness: float
    force: float
    static_friction: float
    on_limiter: bool
    rule_force: float



@dataclass(frozen=True, eq=False)
class Confirmation(Result):
    """The simulated confirmation of a design.

    Attributes
    ----------
    isolated, non_isolated : PlantVerdict
        The two plants after the spec's own motion at the design crossover
        (the paper's metric on one move).
    stage : dict of StageHunting
        The stage-level answer of each plant, by plant: every move of the
        family, the cycle, the hunting-free crossover
        (:class:`~fi_design.results.stage.StageHunting`).
    min_hunting_free_crossover : dict
        ``{"isolated": Hz or None, "non_isolated": Hz or None, "resolution":
        Hz, "search": [start, stop]}``: the stage-level hunting-free
        crossovers (the cycles' folds), the widest bisection bracket, and the
        crossover range searched.
    landing : Landing or None
        Landing of the isolated cart.
    cross_check : dict of PlantVerdict
        The same plants with the other friction model, by plant.
    models_agree : bool
        Whether both friction models give the same hunting/no-hunting call
        for both plants.
    suggested_isolator : bool
        True when the spec has no isolator and the isolated plant uses the
        isolator suggested by the guideline.
    checks : tuple of Check
        The simulation's checks for the design summary.
    results : dict of SimulationResult
        The two full simulations (traces for plots; not in the JSON).
    """

    isolated: PlantVerdict
    non_isolated: PlantVerdict
    stage: dict = field(repr=False)  # in the JSON as the design's "stage_hunting"
    min_hunting_free_crossover: dict
    landing: Landing | None
    cross_check: dict
    models_agree: bool
    suggested_isolator: bool
    checks: tuple[Check, ...]
    results: dict = field(repr=False)  # traces for plots; not in the JSON


#: Statuses of a design verdict, from best to worst.
VERDICT_STATUSES = ("PASS", "PASS_WITH_WARNINGS", "NOT_CONFIRMED", "FAIL")


@dataclass(frozen=True)
class Reason(Result):
    """One reason behind a verdict.

    Attributes
    ----------
    severity : str
        ``"FAIL"`` (the design does not pass because of it), ``"WARN"`` (to
        review before sign-off) or ``"PASS"`` (a requirement shown to hold).
    source : str
        Where it comes from: a check's name, ``"simulation"``,
        ``"robustness"``, ``"input"`` (a warning on a spec value) or
        ``"confirmation"``.
    text : str
        One sentence a reviewer can read.
    """

    severity: str
    source: str
    text: str


@dataclass(frozen=True)
class Verdict(Result):
    """The sign-off verdict on the hardware as specified.

    Attributes
    ----------
    status : str
        ``"PASS"``, ``"PASS_WITH_WARNINGS"``, ``"NOT_CONFIRMED"`` or ``"FAIL"``
        (:data:`VERDICT_STATUSES`). FAIL when a check fails, when the
        spec's own plant hunts, sticks away from its target or cannot be
        determined at the design crossover, or when it hunts under friction
        scatter more often than ``requirements.robustness.hunting_probability``;
        NOT_CONFIRMED when nothing fails but the stage was not simulated
        (``design(confirm=False)``, ``--no-simulation``): the linear steps alone
        cannot tell whether it hunts, so it does not pass; PASS_WITH_WARNINGS
        when nothing fails but something needs review.
    reasons : tuple of Reason
        Why: failures first, then warnings, then what holds.
    plant : str
        The plant judged, the spec's own: ``"isolated"`` when the spec has an
        isolator, else ``"non_isolated"``. An isolator the spec does not have
        is a :class:`Recommendation`, never part of the verdict.
    behaviour : str or None
        The judged plant's outcome at the design crossover: ``settled``,
        ``hunting``, ``stuck``, ``undetermined`` or ``static_error`` (a loop
        without integrator at rest within its expected static error); None
        without simulation.
    headline : str
        One sentence: what the stage does and the status.
    """

    status: str
    reasons: tuple[Reason, ...]
    plant: str
    behaviour: str | None
    headline: str

    @property
    def passed(self) -> bool:
        """Whether the status is PASS or PASS_WITH_WARNINGS (a design not simulated never is)."""
        return self.status in ("PASS", "PASS_WITH_WARNINGS")

    def at_or_below(self, level: str) -> bool:
        """Whether the status is ``level`` or worse.

        Parameters
        ----------
        level : {"PASS", "PASS_WITH_WARNINGS", "NOT_CONFIRMED", "FAIL"}
            In the order of :data:`VERDICT_STATUSES`: NOT_CONFIRMED is below
            PASS_WITH_WARNINGS (it does not pass) and above FAIL.

        Returns
        -------
        bool
        """
        return VERDICT_STATUSES.index(self.status) >= VERDICT_STATUSES.index(level)

    def to_dict(self) -> dict:
        """JSON: ``status``, ``reasons`` (their texts), ``findings`` (severity, source and
        text of each), ``plant``, ``behaviour``, ``headline``."""
        return {"status": self.status, "reasons": [r.text for r in self.reasons],
                "findings": [r.to_dict() for r in self.reasons], "plant": self.plant,
                "behaviour": self.behaviour, "headline": self.headline}


@dataclass(frozen=True, eq=False)
class RobustnessCheck(Result):
    """The probability that the stage as specified does not settle under friction scatter.

    Attributes
    ----------
    plant : str
        The plant judged (the spec's own).
    samples : int
        Samples drawn.
    valid : int
        Samples simulated to the end (the trials).
    hunting : int
        Valid samples whose stage does not settle after every move of its
        family, whatever the reason: it hunts, sticks (an integrating loop) or
        cannot be judged (``counts`` tells which).
    hunting_probability : float or None
        hunting / valid [-]: the probability the sign-off limits; None without
        valid samples.
    interval : tuple of float
        Wilson confidence interval of the probability (low, high) [-].
    confidence : float
        Level of the interval [-].
    limit : float
        ``requirements.robustness.hunting_probability`` [-].
    status : str
        ``"FAIL"`` when the estimate exceeds the limit, ``"WARN"`` when it
        does not but the interval reaches above it (not demonstrated with
        these samples), ``"PASS"`` when the whole interval lies at or below.
    scatter : dict
        Scattered spec path to its spread, a fraction of the nominal value [-].
    distribution : str
        ``"normal"`` (spread = standard deviation) or ``"uniform"`` (half-width).
    ripple : dict or None
        ``{"amplitude": -, "wavelength": m}`` of the friction ripple along the
        rail, or None.
    seed : int
        Seed of the draws.
    counts : dict
        Samples per verdict of the judged plant.
    comparison : dict or None
        The same samples on the other plant (without the isolator, or with
        the suggested one): ``plant``, ``hunting_probability``, ``interval``.
    study : fi_design.studies.RobustnessResult
        The full study (samples, draws; not in the JSON).
    """

    plant: str
    samples: int
    valid: int
    hunting: int
    hunting_probability: float | None
    interval: tuple[float, float]
    confidence: float
    limit: float
    status: str
    scatter: dict
    distribution: str
    ripple: dict | None
    seed: int
    counts: dict
    comparison: dict | None
    study: Any = field(repr=False)


@dataclass(frozen=True)
class Margins(Result):
    """How far the design is from its limits, where the figure means something.

    Attributes
    ----------
    crossover_factor : float or None
        Design crossover / lowest hunting-free crossover of the spec's own
        plant (from the simulated scan) [-]; above 1 the design lies above the
        hunting boundary. None without simulation, for a loop without
        integrator (it cannot hunt by the paper's mechanism) and when the
        plant hunts up to the top of the scan.
    crossover_factor_bound : bool
        True when the plant settles over the whole scan: the factor is then a
        lower bound (design crossover / the scan's lowest crossover).
    hunting_free_crossover : float or None
        The lowest hunting-free crossover used [Hz] (within one scan step).
    achievable_factor : float or None
        Achievable / desired crossover of step 2 [-]; None when the
        achievable crossover is only a bound (the search cap) or none.
    achievable_crossover_bound : float or None
        The search cap [Hz] when the linear model limits the crossover
        nowhere below it ("not limited below"); None otherwise.
    end_stop_clearance : float or None
        Stroke minus the joint deflection at rest, s - |d| [m], of the spec's
        own isolator; None without isolator or simulation.
    resting_deflection : float or None
        Joint deflection at rest d [m].
    stiffness_factor : float or None
        k_max / k [-]; None without isolator.
    stiffness_range : tuple of float or None
        Drive stiffness of the sized flexure at its thickness tolerance,
        ``k (1 -+ dt / t)^3`` [N/m]; None without a sized flexure.
    stiffness_factor_worst : float or None
        k_max / the highest stiffness of that range [-].
    thickness : float or None
        Stock thickness of the sized leaves [m].
    thickness_tolerance : float or None
        Its tolerance +- [m].
    static_error : float or None
        Resting error |x1 - r| of a loop without integrator [m].
    static_error_bound : float or None
        The static error it may leave, (Fc + |offset|) / kp [m].
    notes : tuple of str
        Why a margin is left out or is a bound.
    """

    crossover_factor: float | None = None
    crossover_factor_bound: bool = False
    hunting_free_crossover: float | None = None
    achievable_factor: float | None = None
    achievable_crossover_bound: float | None = None
    end_stop_clearance: float | None = None
    resting_deflection: float | None = None
    stiffness_factor: float | None = None
    stiffness_range: tuple[float, float] | None = None
    stiffness_factor_worst: float | None = None
    thickness: float | None = None
    thickness_tolerance: float | None = None
    static_error: float | None = None
    static_error_bound: float | None = None
    notes: tuple[str, ...] = ()


@dataclass(frozen=True)
class Recommendation(Result):
    """What to build so that the stage passes, apart from the verdict on it.

    Attributes
    ----------
    text : str
        The recommendation in words.
    isolator : dict or None
        The recommended (or nearest) isolator: ``stroke`` [m], ``stiffness``
        [N/m], ``damping`` [N s/m] or None (the default ratio).
    crossover : float or None
        The recommended controller crossover [Hz].
    feasible : bool
        Whether the search found a design the sign-off passes.
    search : fi_design.results.recommend.RecommendResult or None
        The design search behind it (:func:`fi_design.recommend.recommend`);
        its JSON is this recommendation's.
    """

    text: str
    isolator: dict | None = None
    crossover: float | None = None
    feasible: bool = False
    search: Any = field(default=None, repr=False)

    def to_dict(self) -> dict:
        """``text`` and the search's JSON (``feasible``, ``isolator``, ``crossover``,
        ``binding``, ...)."""
        out = {"text": self.text, "isolator": to_jsonable(self.isolator),
               "crossover": self.crossover, "feasible": self.feasible}
        if self.search is not None:
            out.update(self.search.to_dict())
        return out


@dataclass(frozen=True)
class DesignResult(Result):
    """The four guideline steps for one spec.

    Attributes
    ----------
    spec : fi_design.spec.Spec
        The spec that produced the result (not in JSON; see ``spec_sha256``).
    friction_gap : FrictionGapResult
        Step 1.
    crossover : CrossoverResult
        Step 2.
    stiffness : StiffnessResult
        Step 3 (a suggestion without isolator).
    flexure : fi_design.flexure.FlexureResult or None
        Step 3 leaf-spring sizing; None without ``isolator.flexure``.
    pid : PidResult
        Step 4.
    loop : LoopResponses
        The loop of every limit case over frequency, for the plots (not in
        JSON).
    isolator_advice : IsolatorAdvice or None
        Only for a spec without isolator.
    checks : tuple of Check
        All checks of the four steps, in step order.
    warnings : tuple of (str, str)
        ``(path, message)`` of suspicious spec values
        (:func:`fi_design.spec.warnings_for`).
    conclusion : str
        One paragraph in plain words.
    fi_design_version : str
        Version of fi_design that computed it.
    spec_sha256 : str
        SHA-256 of the spec file (of the spec's JSON when not read from a file).
    simulation : fi_design.confirm.Confirmation or None
        The nonlinear confirmation; None when it was not run (``confirm=False``),
        and then left out of the JSON.
    fi_design_source : fi_design.provenance.Source
        The code that computed it: git commit (from a checkout) and the SHA-256
        of the package's source files; default the running package's.
    verdict : Verdict or None
        The sign-off verdict on the hardware as specified (None only while
        :func:`fi_design.guideline.design` assembles the result).
    robustness : RobustnessCheck or None
        Hunting under friction scatter; None when not run
        (``confirm=False`` or ``requirements.robustness.samples: 0``).
    margins : Margins or None
        Distances to the limits.
    recommendation : Recommendation or None
        What would make the stage pass (a suggested isolator, a higher
        crossover); None when there is nothing to add.
    model : fi_design.model.Model or None
        The resolved model every step read (not in JSON); ``spec`` is the
        spec it was resolved from.
    """

    spec: Spec = field(repr=False)
    friction_gap: FrictionGapResult
    crossover: CrossoverResult
    stiffness: StiffnessResult
    flexure: FlexureResult | None
    pid: PidResult
    loop: LoopResponses = field(repr=False)
    isolator_advice: IsolatorAdvice | None
    checks: tuple[Check, ...]
    warnings: tuple[tuple[str, str], ...]
    conclusion: str
    fi_design_version: str
    spec_sha256: str
    simulation: "Confirmation | None" = None
    verdict: Verdict | None = None
    robustness: RobustnessCheck | None = None
    margins: Margins | None = None
    recommendation: Recommendation | None = None
    fi_design_source: Source = field(default_factory=current_source)
    model: "Model | None" = field(default=None, repr=False)

    @property
    def passed(self) -> bool:
        """The verdict is PASS or PASS_WITH_WARNINGS: simulated and nothing fails.

        Before the verdict is set, and without the simulation, False: a
        design that was not simulated cannot pass.
        """
        if self.verdict is not None:
            return self.verdict.passed
        return False

    @property
    def failed_checks(self) -> tuple[Check, ...]:
        """The checks with status FAIL."""
        return tuple(c for c in self.checks if c.status == Status.FAIL)

    def to_dict(self) -> dict:
        """The JSON contract: SI values, infinite margins as null.

        Keys: ``name``, ``passed``, ``verdict``, ``recommendation``, ``robustness``,
        ``margins``, ``friction_gap``, ``crossover``, ``stiffness``, ``flexure``,
        ``pid``, ``isolator_advice``, ``checks``, ``warnings``, ``conclusion``,
        ``fi_design_version``, ``fi_design_source`` (``commit``,
        ``modified``, ``code_sha256``: :class:`~fi_design.provenance.Source`),
        ``spec_sha256`` and, when set, ``simulation`` and ``stage_hunting``
        (``{"isolated": ..., "non_isolated": ...}``, each
        :meth:`~fi_design.results.stage.StageHunting.to_dict`).
        """
        out = {
            "name": self.spec.name,
            "passed": self.passed,
            "verdict": None if self.verdict is None else self.verdict.to_dict(),
            "recommendation": to_jsonable(self.recommendation),
            "robustness": to_jsonable(self.robustness),
            "margins": to_jsonable(self.margins),
            "friction_gap": self.friction_gap.to_dict(),
            "crossover": self.crossover.to_dict(),
            "stiffness": self.stiffness.to_dict(),
            "flexure": None if self.flexure is None else self.flexure.to_dict(),
            "pid": self.pid.to_dict(),
            "isolator_advice": to_jsonable(self.isolator_advice),
            "checks": [to_jsonable(c) for c in self.checks],
            "warnings": [{"path": p, "message": m} for p, m in self.warnings],
            "conclusion": self.conclusion,
            "fi_design_version": self.fi_design_version,
            "fi_design_source": self.fi_design_source.to_dict(),
            "spec_sha256": self.spec_sha256,
        }
        if self.simulation is not None:
            out["simulation"] = to_jsonable(self.simulation)
            out["stage_hunting"] = {k: v.to_dict() for k, v in self.simulation.stage.items()}
        return out
