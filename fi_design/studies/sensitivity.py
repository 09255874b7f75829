"""How the hunting-free crossover depends on the LuGre values nobody identified.

sigma0, sigma1 and vs shape the stick phase and the breakaway, and so the
hunting cycle and its fold; a datasheet gives none of them, and an
identification needs a record that holds the excitation (presliding
reversals, slow breakaways). :func:`crossover_sensitivity` divides and
multiplies each by a factor (3 by default), the others held at the values the
design used (the design's model varied, :meth:`fi_design.model.Model.varied`), and finds the stage-level hunting-free crossover of the spec's
own plant for each (:func:`fi_design.stage.stage_hunting`, the fold of the
cycle by bisection): six stage-level answers, about a second each on the
paper setup.
"""

from __future__ import annotations

from typing import Any

from .. import spec as _spec
from ..model import Model
from ..results.sensitivity import SENSITIVITY_PARAMETERS, CrossoverSensitivity, SensitivityPoint
from .points import study_model

__all__ = ["crossover_sensitivity", "started_sensitivity", "PendingSensitivity", "DEFAULT_FACTORS"]

#: The factors each parameter is scaled by [-].
DEFAULT_FACTORS = (1.0 / 3.0, 3.0)


def _nominal(model: Model) -> dict[str, float]:
    f = model.friction
    return {"friction.bristle_stiffness": f.sigma0, "friction.bristle_damping": f.sigma1,
            "friction.stribeck_velocity": f.vs}


def _fold(model: Model, isolated: bool, values: dict) -> tuple[float | None, str]:
    """The hunting-free crossover of the model with some spec values varied (one task)."""
    from ..stage import stage_hunting

    st = stage_hunting(model.varied(values), isolated, converge=False, trace=False)
    kind = "none" if st.boundary is None else st.boundary.kind
    return st.hunting_free_from, kind


def crossover_sensitivity(model: Model | _spec.Spec, nominal: float | None = None, *,
                          factors: tuple[float, ...] = DEFAULT_FACTORS,
                          executor: Any = None) -> CrossoverSensitivity | None:
    """The spec's own plant's hunting-free crossover with sigma0, sigma1 and vs scaled.

    Parameters
    ----------
    model : Model or Spec
        The resolved model (a spec is resolved once here); it is varied by
        :meth:`~fi_design.model.Model.varied`, so it must not be one varied by
        :meth:`~fi_design.model.Model.at`.
    nominal : float, optional
        The nominal hunting-free crossover [Hz] when already known (the
        design's); computed when None.
    factors : tuple of float, optional
        Factors other than 1 to scale each parameter by [-]; default 1/3 and 3.
    executor : concurrent.futures-style executor, optional
        Runs the six answers; None runs them here.

    Returns
    -------
    CrossoverSensitivity or None
        None for a loop without integrator (no hunting by the paper's
        mechanism, no crossover to find) or a friction model without these
        parameters (the switch model).
    """
    return started_sensitivity(study_model(model, "model"), factors=factors,
                               executor=executor).result(nominal)


def started_sensitivity(model: Model, *, factors: tuple[float, ...] = DEFAULT_FACTORS,
                        executor: Any = None) -> "PendingSensitivity":
    """:func:`crossover_sensitivity` with its six answers submitted to ``executor`` now and
    read later (:meth:`PendingSensitivity.result`): a design submits them with its other
    simulations, so that they fill the workers' idle time instead of following them.

    Parameters
    ----------
    model : Model
        The resolved model, not one varied by :meth:`~fi_design.model.Model.at`.
    factors, executor
        As :func:`crossover_sensitivity`.

    Returns
    -------
    PendingSensitivity
    """
    return PendingSensitivity(study_model(model, "model"), factors, executor)


class PendingSensitivity:
    """The six answers of :func:`crossover_sensitivity`, submitted (:func:`started_sensitivity`)."""

    def __init__(self, model: Model, factors: tuple[float, ...], executor: Any) -> None:
        self._model = model
        self._factors = factors
        self._jobs: list[tuple[str, float, float, dict]] = []
        self._futures: list[Any] | None = None
        if not model.law.integrator or model.friction.model != "lugre":
            return
        base = _nominal(model)
        # the others held at the values the design used (sigma1's default follows sigma0
        # otherwise)
        for path in SENSITIVITY_PARAMETERS:
            for f in factors:
                values = dict(base)
                values[path] = base[path] * f
                self._jobs.append((path, f, values[path], values))
        if executor is not None:
            iso = model.has_isolator
            self._futures = [executor.submit(_fold, model, iso, values)
                             for *_, values in self._jobs]

    def result(self, nominal: float | None = None) -> CrossoverSensitivity | None:
        """The sensitivity (None where :func:`crossover_sensitivity` gives none); ``nominal``
        the nominal hunting-free crossover [Hz] when known, else computed here."""
        model = self._model
        if not self._jobs:
            return None
        iso = model.has_isolator
        if nominal is None:
            nominal = _fold(model, iso, _nominal(model))[0]
        if self._futures is None:
            found = [_fold(model, iso, values) for *_, values in self._jobs]
        else:
            found = [fut.result() for fut in self._futures]
        points = tuple(SensitivityPoint(path=path, factor=float(f), value=float(v),
                                        hunting_free_from=m, kind=kind)
                       for (path, f, v, _), (m, kind) in zip(self._jobs, found))
        return CrossoverSensitivity(plant="isolated" if iso else "non_isolated",
                                    nominal=nominal,
                                    factors=tuple(sorted((1.0, *self._factors))),
                                    points=points)

    def cancel(self) -> None:
        """Cancel the answers not yet started (the design failed, or needs none)."""
        for fut in self._futures or ():
            fut.cancel()
