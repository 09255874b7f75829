"""Results of the sign-off: the verdict, its reasons, robustness, margins, advice.

Produced by :func:`fi_design.guideline.verdict.judge` from the guideline's steps and
the confirmation.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, field
from typing import Any

from . import Result, to_jsonable

__all__ = ["VERDICT_STATUSES", "FAIL_ON_LEVELS", "VerdictStatus", "Reason", "Verdict",
           "RobustnessCheck", "Margins", "Recommendation"]


#: Statuses of a design verdict, from best to worst.
VERDICT_STATUSES = ("PASS", "PASS_WITH_WARNINGS", "NOT_CONFIRMED", "FAIL")
#: The command line's ``--fail-on`` words and the status each means: ``fail`` whatever does
#: not pass, ``warn`` a pass with warnings too.
FAIL_ON_LEVELS = {"fail": "NOT_CONFIRMED", "warn": "PASS_WITH_WARNINGS"}


class VerdictStatus(str, enum.Enum):
    """Status of a design verdict, an enum like a check's
    :class:`~fi_design.results.Status`; it compares equal to its name
    (``verdict.status == "FAIL"``) and prints as it (``f"{status}"``)."""

    PASS = "PASS"
    PASS_WITH_WARNINGS = "PASS_WITH_WARNINGS"
    NOT_CONFIRMED = "NOT_CONFIRMED"
    FAIL = "FAIL"

    def __str__(self) -> str:
        return self.value

    def __format__(self, spec: str) -> str:
        return self.value.__format__(spec)  # the name, padded as asked: no number


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
    status : VerdictStatus
        ``PASS``, ``PASS_WITH_WARNINGS``, ``NOT_CONFIRMED`` or ``FAIL``
        (:data:`VERDICT_STATUSES`; equal to those strings). FAIL when a check fails, when the
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
    next_step : str
        After a FAIL, what to run next (the design search, ``fi-design
        recommend SPEC --write-spec OUT.yaml``); empty otherwise.
    """

    status: VerdictStatus
    reasons: tuple[Reason, ...]
    plant: str
    behaviour: str | None
    headline: str
    next_step: str = ""

    @property
    def passed(self) -> bool:
        """Whether the status is PASS or PASS_WITH_WARNINGS (a design not simulated never is)."""
        return self.status in ("PASS", "PASS_WITH_WARNINGS")

    def at_or_below(self, level: str) -> bool:
        """Whether the status is ``level`` or worse.

        Parameters
        ----------
        level : {"PASS", "PASS_WITH_WARNINGS", "NOT_CONFIRMED", "FAIL", "fail", "warn"}
            In the order of :data:`VERDICT_STATUSES`: NOT_CONFIRMED is below
            PASS_WITH_WARNINGS (it does not pass) and above FAIL, in any case; the
            command line's ``--fail-on`` words, lower case, as :data:`FAIL_ON_LEVELS`
            reads them (``"fail"``: NOT_CONFIRMED or worse).

        Returns
        -------
        bool

        Raises
        ------
        ArgumentError
            A level that is none of these.
        """
        word = str(level).strip() if isinstance(level, (str, VerdictStatus)) else None
        name = None if word is None else FAIL_ON_LEVELS.get(word, word.upper())
        if name not in VERDICT_STATUSES:
            from ..errors import ArgumentError

            raise ArgumentError(f"level {level!r}: expected one of "
                                f"{', '.join(VERDICT_STATUSES)} or the --fail-on words "
                                f"{', '.join(FAIL_ON_LEVELS)}")
        return VERDICT_STATUSES.index(self.status) >= VERDICT_STATUSES.index(name)

    def to_dict(self) -> dict:
        """JSON: ``status``, ``reasons`` (their texts), ``findings`` (severity, source and
        text of each), ``plant``, ``behaviour``, ``headline``, ``next_step``."""
        return {"status": str(self.status), "reasons": [r.text for r in self.reasons],
                "findings": [r.to_dict() for r in self.reasons], "plant": self.plant,
                "behaviour": self.behaviour, "headline": self.headline,
                "next_step": self.next_step}


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
        The lowest crossover from which no move of the family hunts [Hz]: the
        fold of the hunting cycle, bisected to the resolution in the stage's
        ``boundary`` (:attr:`fi_design.results.stage.StageHunting.boundary`).
    hunting_case : str or None
        The limit case the hunting cycle slides in (``sliding_limited`` when
        the joint rides its limiter, ``sliding_free``, or ``sliding`` without
        isolator): the loop whose actual crossovers the margin is read on.
    hunting_loop_crossover : float or None
        That case's 0 dB crossing at the design [Hz].
    hunting_free_loop_crossover : float or None
        That case's 0 dB crossing with the loop at the hunting-free
        crossover [Hz]. ``crossover_factor`` is the ratio of the set
        crossovers, the loop's frequency scale (every corner of the
        controller moves by it), which ``requirements.hunting_margin`` bounds;
        the ratio of these two crossings is the same to within the plant's
        own dynamics (under 1 % on the paper setup).
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
        The static error it may leave, (Fs + |offset|) / kp [m]
        (:attr:`fi_design.model.Model.static_error_bound`).
    notes : tuple of str
        Why a margin is left out or is a bound.
    """

    crossover_factor: float | None = None
    crossover_factor_bound: bool = False
    hunting_free_crossover: float | None = None
    hunting_case: str | None = None
    hunting_loop_crossover: float | None = None
    hunting_free_loop_crossover: float | None = None
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
