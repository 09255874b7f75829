"""The result of the design workflow: the four guideline steps, the loop, the confirmation.

Produced by :func:`fi_design.guideline.evaluate.evaluate`. Its parts live by stage of
the work, and are named here too: :mod:`.steps` (steps 1 to 4, the loop
responses; :func:`fi_design.flexure.size_flexure`), :mod:`.confirmation`
(the simulated confirmation, :func:`fi_design.stage.confirm.confirm`; the isolator
advice) and :mod:`.verdict` (the sign-off: verdict, robustness, margins,
recommendation).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from ..provenance import Source, current_source, header
from . import Check, Result, Status, to_jsonable
from .confirmation import Confirmation, IsolatorAdvice, Landing, PlantVerdict
from .mechanism import FeMechanics
from .positioning import PositioningResult
from .sensitivity import CrossoverSensitivity
from .steps import (CaseResponse, CrossoverResult, FlexureResult, FrictionGapResult,
                    LoopResponses, ModeSeparation, NotchSuggestion, PidResult, StiffnessResult)
from .verdict import (VERDICT_STATUSES, Margins, Reason, Recommendation, RobustnessCheck,
                      Verdict, VerdictStatus)

if TYPE_CHECKING:  # pragma: no cover
    from ..model import Model
    from ..spec import Spec

__all__ = ["FrictionGapResult", "ModeSeparation", "NotchSuggestion", "CrossoverResult", "StiffnessResult",
           "FlexureResult", "PidResult", "CaseResponse", "LoopResponses", "IsolatorAdvice",
           "PlantVerdict", "Landing", "Confirmation", "VERDICT_STATUSES", "VerdictStatus",
           "Reason", "Verdict", "RobustnessCheck", "Margins", "Recommendation",
           "DesignResult"]


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
    flexure : fi_design.results.steps.FlexureResult or None
        Step 3: the leaf-spring guide as a mechanism, drawn or sized; None
        without ``isolator.flexure``.
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
    simulation : fi_design.stage.confirm.Confirmation or None
        The nonlinear confirmation; None when it was not run (``confirm=False``),
        and then left out of the JSON.
    fi_design_source : fi_design.provenance.Source
        The code that computed it: git commit (from a checkout) and the SHA-256
        of the package's source files; default the running package's.
    verdict : Verdict or None
        The sign-off verdict on the hardware as specified (None only while
        :func:`fi_design.guideline.evaluate.evaluate` assembles the result).
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
    flexure_fe : fi_design.results.mechanism.FeMechanics or None
        The guide as a finite-element model, the independent check of the
        closed forms (JSON: ``flexure.fe``); None when it did not run.
    sensitivity : fi_design.results.sensitivity.CrossoverSensitivity or None
        The hunting-free crossover of the spec's own plant with sigma0,
        sigma1 and vs divided and multiplied by 3; None when not run
        (``design(sensitivity=False)``, a loop without integrator).
    positioning : fi_design.results.positioning.PositioningResult or None
        ``requirements.positioning`` judged over the move family of the
        spec's own plant (its checks are among ``checks``); None when the
        spec requires none or the stage was not simulated.
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
    flexure_fe: FeMechanics | None = None
    positioning: PositioningResult | None = None
    sensitivity: CrossoverSensitivity | None = None

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
        ``pid``, ``isolator_advice``, ``positioning``, ``sensitivity``, ``checks``, ``warnings``, ``conclusion``,
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
            "flexure": None if self.flexure is None else {
                **self.flexure.to_dict(),
                **({} if self.flexure_fe is None else {"fe": self.flexure_fe.to_dict()})},
            "pid": self.pid.to_dict(),
            "isolator_advice": to_jsonable(self.isolator_advice),
            "positioning": to_jsonable(self.positioning),
            "sensitivity": to_jsonable(self.sensitivity),
            "checks": [to_jsonable(c) for c in self.checks],
            "warnings": [{"path": p, "message": m} for p, m in self.warnings],
            "conclusion": self.conclusion,
            **header(self.fi_design_version, self.fi_design_source, self.spec_sha256),
        }
        if self.simulation is not None:
            out["simulation"] = to_jsonable(self.simulation)
            out["stage_hunting"] = {k: v.to_dict() for k, v in self.simulation.stage.items()}
        return out
