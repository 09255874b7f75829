"""The result of the design search (:func:`fi_design.recommend.recommend`).

A recommendation is a design the tool itself would sign off, found by search:
a leaf-spring guide drawn from stock with its stroke and, for a spec tuned by
the rule, the loop's crossover; the stiffest joint that keeps the hunting
margin, with its reserves. Beside it, the least change of the spec that
passes. Every point the search judged is a :class:`DesignCandidate`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from ..provenance import Source, current_source, header
from . import Result, to_jsonable

if TYPE_CHECKING:  # pragma: no cover
    from ..spec import Spec

__all__ = ["CANDIDATE_STATUSES", "DesignCandidate", "LeastChange", "RecommendResult"]

#: Status of a point of the design space, from best to worst: meets every constraint; fails
#: the robustness of the sign-off; fails a reserve corner (masses, stiffness, modes, delay);
#: the cart rests on its end stop or another check of the sign-off fails; no move hunts but
#: the crossover lies within the hunting margin of the fold; some move hunts at the crossover;
#: a limit case misses its margins with the reserve; no guide can be built (stress, buckling,
#: modes, stock); the stiffness exceeds k_max; outside requirements.recommend; judged but not
#: signed off (a stiffer one passed first); the simulation failed.
CANDIDATE_STATUSES = ("feasible", "robustness", "reserve", "checks", "margin", "hunts",
                      "margins", "flexure", "k_max", "bounds", "not_evaluated", "failed")


@dataclass(frozen=True)
class DesignCandidate(Result):
    """One point of the design space and how it fares.

    Attributes
    ----------
    stroke : float
        Isolator stroke, one-sided [m].
    stiffness : float
        Net drive stiffness of its guide, gravity included [N/m] (the target
        where no guide could be built).
    damping : float or None
        Joint damping [N s/m]; None: the default ratio of the joint mode.
    crossover : float
        Controller crossover [Hz].
    status : str
        One of :data:`CANDIDATE_STATUSES`.
    violations : tuple of str
        What it violates, in words (empty when feasible).
    length, width, thickness : float or None
        Its guide's leaf dimensions [m]; None where none could be built.
    lowest_mode : float or None
        Its guide's lowest parasitic mode [Hz].
    hunting_free_from : float or None
        Stage-level hunting-free crossover of this isolator [Hz] (the fold
        of its cycle); None when not computed, or when no cycle was found.
    hunting_margin : float or None
        crossover / hunting_free_from [-] (0: some move hunts at the
        crossover; inf: no cycle at any crossover searched).
    unsettled_probability : float or None
        Probability that a scatter sample does not settle [-].
    end_stop_clearance : float or None
        Stroke minus the joint deflection at rest after the spec's motion [m].
    """

    stroke: float
    stiffness: float
    damping: float | None
    crossover: float
    status: str
    violations: tuple[str, ...] = ()
    length: float | None = None
    width: float | None = None
    thickness: float | None = None
    lowest_mode: float | None = None
    hunting_free_from: float | None = None
    hunting_margin: float | None = None
    unsettled_probability: float | None = None
    end_stop_clearance: float | None = None

    @property
    def crossover_factor(self) -> float | None:
        """The same as :attr:`hunting_margin` (the crossover over the hunting-free one)."""
        return self.hunting_margin


@dataclass(frozen=True)
class LeastChange(Result):
    """The smallest edit of the spec that passes the sign-off.

    Attributes
    ----------
    changes : dict
        Dotted spec path to the new value, with its unit (as the spec file
        takes it), one or two of them.
    feasible : bool
        Whether an edit of at most two values passes.
    binding : tuple of str
        What the edit runs into, in words.
    text : str
        The edit in one sentence.
    tried : tuple of str
        The edits tried, in order, with why each failed.
    """

    changes: dict
    feasible: bool
    binding: tuple[str, ...] = ()
    text: str = ""
    tried: tuple[str, ...] = ()


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
        What stops a stiffer joint: each constraint physical (k_max at the
        stroke, the hunting margin, the guide's stress, buckling or modes, the
        envelope of strokes), never the end of a searched range.
    violates : tuple of str
        With none feasible: what the nearest design violates.
    advice : str
        One sentence a person acts on.
    flexure : FlexureResult or None
        The recommended guide as a mechanism (sized at full resolution).
    least_change : LeastChange or None
        The smallest edit of the spec that passes.
    stage_hunting : StageHunting or None
        The design's stage-level hunting answer at its crossover.
    robustness : RobustnessCheck or None
        The design's robustness under the spec's scatter.
    reserves : tuple of dict
        The reserve corners of the design (``name``, ``passed``, ``why``).
    forces : fi_design.results.forces.StageForces or None
        The design's forces over its move family (end-stop impacts, the
        actuator's peak), from its sign-off.
    margins : dict
        ``hunting_margin`` (crossover / hunting-free crossover),
        ``stiffness_factor`` (k_max / k), ``end_stop_clearance`` [m],
        ``achievable_factor`` (the achievable crossover over the design's).
    pareto : tuple of dict
        The trade-off: the judged designs no other beats on both joint
        stiffness and hunting margin (``stroke`` m, ``stiffness`` N/m,
        ``hunting_margin``, ``lowest_mode`` Hz), stiffest first.
    strokes : tuple of float
        The strokes searched [m], ascending.
    stiffnesses : tuple of float
        Every target stiffness searched [N/m], ascending.
    candidates : tuple of DesignCandidate
        Every point judged.
    spec_design : dict
        The spec's own ``stroke`` [m], ``stiffness`` [N/m] and ``crossover``
        [Hz] (the suggested isolator for a spec without one).
    crossover_limit : str
        Why the crossover is what it is.
    assumptions : tuple of str
        What the search assumed (an isolator or guide the spec does not give).
    rule : bool
        Whether the crossover was searched (a spec tuned by the rule) or
        kept (explicit gains).
    evaluations : int
        Stage-level evaluations (one move family each) the search made.
    wall_time : float
        Time the search took when it ran [s] (a result read from the cache
        keeps the time of the run that computed it: see ``from_cache``).
    notch : fi_design.results.controller.Filter or None
        The notch the search added to the drive's chain
        (``requirements.recommend.filters``); None: the chain as the spec has it.
    flexure_bounds : tuple of fi_design.results.steps.BoundNote
        The recommended guide's leaf dimensions that sit on a bound of
        ``isolator.flexure`` (which bound, its key), each saying whether a guide
        sized past the bound has more margin (:func:`fi_design.mechanism.bounds.bound_notes`).
    from_cache : str or None
        The cache entry this result was read from
        (:mod:`fi_design.recommend.stored`): a search of the same spec by the
        same code, run earlier; None when the search ran in this call.
    fi_design_source : fi_design.provenance.Source
        The code that produced it (for a result read from the cache, the run
        that computed it: the same version and code digest).
    """

    spec: "Spec" = field(repr=False)
    feasible: bool
    design: DesignCandidate
    binding: tuple[str, ...]
    violates: tuple[str, ...]
    advice: str
    flexure: Any
    least_change: LeastChange | None
    stage_hunting: Any
    robustness: Any
    reserves: tuple[dict, ...]
    forces: Any
    margins: dict
    pareto: tuple[dict, ...]
    strokes: tuple[float, ...]
    stiffnesses: tuple[float, ...]
    candidates: tuple[DesignCandidate, ...]
    spec_design: dict
    crossover_limit: str
    assumptions: tuple[str, ...]
    rule: bool
    evaluations: int
    wall_time: float
    notch: Any = None
    flexure_bounds: tuple = ()
    from_cache: str | None = None
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
        """The contract: ``feasible``, ``isolator``, ``crossover``, ``flexure``, ``binding``,
        ``least_change``, ``stage_hunting``, ``robustness``, ``reserves``, ``forces``,
        ``margins``, ``pareto``, the ``notch`` the search added (null: none), ``flexure_bounds``
        (the guide's dimensions on a bound of the flexure's, each with its note); the nearest
        design's ``violates``, the ``advice``, every judged ``candidate``, the search's
        ``evaluations`` and ``wall_time`` [s], and ``from_cache`` (the cache entry it was read
        from; null: computed by this run)."""
        return {
            "feasible": self.feasible, "isolator": to_jsonable(self.isolator),
            "crossover": self.crossover,
            "flexure": None if self.flexure is None else self.flexure.to_dict(),
            "binding": list(self.binding), "violates": list(self.violates),
            "advice": self.advice,
            "least_change": None if self.least_change is None else self.least_change.to_dict(),
            "stage_hunting": to_jsonable(self.stage_hunting),
            "robustness": to_jsonable(self.robustness),
            "reserves": to_jsonable(self.reserves), "forces": to_jsonable(self.forces),
            "margins": to_jsonable(self.margins), "pareto": to_jsonable(self.pareto),
            "design": self.design.to_dict(), "spec_design": to_jsonable(self.spec_design),
            "crossover_limit": self.crossover_limit, "assumptions": list(self.assumptions),
            "rule": self.rule,
            "notch": None if self.notch is None else self.notch.to_dict(),
            "flexure_bounds": [n.to_dict() for n in self.flexure_bounds],
            "map": {"strokes": list(self.strokes), "stiffnesses": list(self.stiffnesses),
                    "candidates": [c.to_dict() for c in self.candidates]},
            "evaluations": self.evaluations, "wall_time": self.wall_time,
            "from_cache": self.from_cache,
            **header(source=self.fi_design_source)}
