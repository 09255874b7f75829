"""Results of the nonlinear confirmation: each plant's verdict, where the cart rests.

Produced by :func:`fi_design.stage.confirm.confirm` (the simulated confirmation) and
:func:`fi_design.guideline.evaluate.evaluate` (the isolator advice of a spec without one).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from .forces import StageForces
from . import Check, Result, to_jsonable
from .simulation import HuntingMetrics, SimulationResult

__all__ = ["IsolatorAdvice", "PlantVerdict", "Landing", "Confirmation"]


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
        friction, (Fs + |offset|) / kp with the larger static friction of the
        two directions [m] (:attr:`fi_design.model.Model.static_error_bound`);
        None when the loop integrates.
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

    def clearance(self, sag: float = 0.0) -> float:
        """The end stop's clearance at rest [m]: the stroke less the landing deflection and the
        static sag.

        The simulation carries no weight: the sag (``m2 g / k`` on a vertical drive axis, 0
        otherwise [m]), which the joint's spring adds to whatever deflection the friction
        leaves, is taken on the side that brings the cart closer to its stop. Negative where
        the joint rests on its end stop.
        """
        return self.stroke - (abs(self.deflection) + sag)


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
    forces : StageForces or None
        The forces over the move family of the spec's own plant: end-stop
        impacts and the actuator's peak.
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
    forces: StageForces | None = None
