"""The result of the design search (:func:`fi_design.recommend.recommend`).

A recommendation is a design the tool itself would sign off: the isolator's
stroke and drive stiffness and, for a spec tuned by the rule, the controller
crossover, found by a search over the design space (:class:`DesignCandidate`
per point), with what binds it and the design space as a map.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from ..provenance import Source, current_source
from . import Result, to_jsonable

if TYPE_CHECKING:  # pragma: no cover
    from ..spec import Spec

__all__ = ["CANDIDATE_STATUSES", "DesignCandidate", "RecommendResult"]

#: Status of a point of the design space, from best to worst: meets every constraint;
#: hunts under friction scatter more often than the limit; the cart rests on its end stop
#: (or pushes with more than Fs) after the spec's motion; another check of the sign-off
#: fails; some move ends in a hunting cycle at the crossover; a limit case misses its
#: margins; the flexure cannot be built (stress, leaf or support frequency, thickness
#: range); the stiffness exceeds k_max; outside the bounds of requirements.recommend; no
#: move hunts, but not signed off (less margin than a feasible one); the simulation failed.
CANDIDATE_STATUSES = ("feasible", "robustness", "end_stop", "checks", "hunts", "margins",
                      "flexure", "k_max", "bounds", "not_evaluated", "failed")


@dataclass(frozen=True)
class DesignCandidate(Result):
    """One point of the design space and how it fares.

    Attributes
    ----------
    stroke : float
        Isolator stroke, one-sided [m].
    stiffness : float
        Drive stiffness [N/m] (as built: the stock thickness of a sized
        flexure rounds it).
    damping : float or None
        Joint damping [N s/m]; None: the default ratio of the joint mode.
    crossover : float
        Controller crossover [Hz].
    status : str
        One of :data:`CANDIDATE_STATUSES`.
    violations : tuple of str
        What it violates, in words (empty when feasible).
    hunting_free_from : float or None
        Stage-level hunting-free crossover of this isolator [Hz] (the fold
        of its cycle); None when not computed or not found in the search.
    crossover_factor : float or None
        crossover / hunting_free_from [-]: the objective's first figure.
    unsettled_probability : float or None
        Probability that a friction-scatter sample does not settle [-]; None
        when not computed.
    end_stop_clearance : float or None
        Stroke minus the joint deflection at rest after the spec's motion [m].
    """

    stroke: float
    stiffness: float
    damping: float | None
    crossover: float
    status: str
    violations: tuple[str, ...] = ()
    hunting_free_from: float | None = None
    crossover_factor: float | None = None
    unsettled_probability: float | None = None
    end_stop_clearance: float | None = None


@dataclass(frozen=True, eq=False)
class RecommendResult(Result):
    """The recommended design (or, when none is feasible, the nearest and what it violates).

    Attributes
    ----------
    spec : Spec
        The spec searched from (not in the JSON).
    feasible : bool
        Whether a design meets every constraint.
    design : DesignCandidate
        The recommended design, or the nearest one.
    binding : tuple of str
        What stops the design from more margin: the constraints of its
        neighbours in the design space, and the crossover's own limit.
    violates : tuple of str
        With none feasible: what the nearest design violates.
    advice : str
        One sentence a person acts on (what binds, or what would open the
        space when nothing is feasible).
    stage_hunting : StageHunting or None
        The design's stage-level hunting answer at its crossover.
    robustness : RobustnessCheck or None
        The design's robustness under the spec's friction scatter.
    margins : dict
        ``crossover_factor`` (crossover / hunting-free crossover),
        ``stiffness_factor`` (k_max / k), ``end_stop_clearance`` [m].
    strokes : tuple of float
        The stroke axis of the design-space map [m].
    stiffnesses : tuple of float
        The stiffness axis of the map [N/m] (nominal, before stock rounding).
    candidates : tuple of DesignCandidate
        Every point of the map, strokes outer, stiffnesses inner.
    spec_design : dict
        The spec's own ``stroke`` [m], ``stiffness`` [N/m] and ``crossover``
        [Hz] (the suggested isolator for a spec without one).
    rule : bool
        Whether the crossover was searched (a spec tuned by the rule) or
        kept (explicit gains).
    evaluations : int
        Stage-level evaluations (one move family each) the search made.
    wall_time : float
        Time the search took [s].
    fi_design_source : fi_design.provenance.Source
        The code that produced it.
    """

    spec: "Spec" = field(repr=False)
    feasible: bool
    design: DesignCandidate
    binding: tuple[str, ...]
    violates: tuple[str, ...]
    advice: str
    stage_hunting: Any
    robustness: Any
    margins: dict
    strokes: tuple[float, ...]
    stiffnesses: tuple[float, ...]
    candidates: tuple[DesignCandidate, ...]
    spec_design: dict
    rule: bool
    evaluations: int
    wall_time: float
    fi_design_source: Source = field(default_factory=current_source)

    @property
    def isolator(self) -> dict:
        """``{"stroke": m, "stiffness": N/m, "damping": N s/m or None}`` of the design."""
        d = self.design
        return {"stroke": d.stroke, "stiffness": d.stiffness, "damping": d.damping}

    @property
    def crossover(self) -> float:
        """The design's crossover [Hz]."""
        return self.design.crossover

    def to_dict(self) -> dict:
        """The contract: ``feasible``, ``isolator``, ``crossover``, ``binding``,
        ``stage_hunting``, ``robustness``, ``margins``; the nearest design's
        ``violates``, the ``advice`` and the map's ``candidates``."""
        return {
            "feasible": self.feasible, "isolator": to_jsonable(self.isolator),
            "crossover": self.crossover, "binding": list(self.binding),
            "violates": list(self.violates), "advice": self.advice,
            "stage_hunting": to_jsonable(self.stage_hunting),
            "robustness": to_jsonable(self.robustness), "margins": to_jsonable(self.margins),
            "design": self.design.to_dict(), "spec_design": to_jsonable(self.spec_design),
            "rule": self.rule,
            "map": {"strokes": list(self.strokes), "stiffnesses": list(self.stiffnesses),
                    "candidates": [c.to_dict() for c in self.candidates]},
            "evaluations": self.evaluations, "wall_time": self.wall_time,
            "fi_design_source": self.fi_design_source.to_dict()}
