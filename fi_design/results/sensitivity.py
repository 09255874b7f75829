"""Results of the sensitivity study: the hunting-free crossover against the unidentified LuGre values.

Produced by :func:`fi_design.studies.crossover_sensitivity`. The dynamic
LuGre parameters (bristle stiffness sigma0, bristle damping sigma1, Stribeck
velocity vs) are seldom identified for a real guide; the study says how far
the lowest crossover from which no move hunts moves when each of them is
divided or multiplied by a factor, the others held.
"""

from __future__ import annotations

from dataclasses import dataclass

from . import Result, to_jsonable

__all__ = ["SENSITIVITY_PARAMETERS", "SensitivityPoint", "CrossoverSensitivity"]

#: The parameters the study varies: spec path -> symbol.
SENSITIVITY_PARAMETERS = {"friction.bristle_stiffness": "sigma0",
                          "friction.bristle_damping": "sigma1",
                          "friction.stribeck_velocity": "vs"}


@dataclass(frozen=True)
class SensitivityPoint(Result):
    """The hunting-free crossover with one parameter changed.

    Attributes
    ----------
    path : str
        The varied spec path (:data:`SENSITIVITY_PARAMETERS`).
    factor : float
        The value over the nominal one [-].
    value : float
        The value used, SI (N/m, N s/m, m/s).
    hunting_free_from : float or None
        Lowest crossover from which no move of the family hunts [Hz]; None
        when the cycle persists to the top of the search, or none was found.
    kind : str
        How it was found: ``"fold"``, ``"bound"`` (no move hunts from the
        bottom of the search up, or the cycle persists to its top),
        ``"not_found"`` (moves still hunt above the last fold the search
        followed) or ``"none"`` (no search).
    """

    path: str
    factor: float
    value: float
    hunting_free_from: float | None
    kind: str


@dataclass(frozen=True)
class CrossoverSensitivity(Result):
    """The hunting-free crossover of the spec's own plant over the unidentified LuGre values.

    Attributes
    ----------
    plant : str
        ``"isolated"`` or ``"non_isolated"``.
    nominal : float or None
        The nominal hunting-free crossover [Hz] (the design's).
    factors : tuple of float
        The factors each parameter was scaled by, nominal (1) included [-].
    points : tuple of SensitivityPoint
        One per parameter and factor other than 1.
    """

    plant: str
    nominal: float | None
    factors: tuple[float, ...]
    points: tuple[SensitivityPoint, ...]

    def of(self, path: str) -> tuple[SensitivityPoint, ...]:
        """The points of one parameter, by factor."""
        return tuple(sorted((p for p in self.points if p.path == path), key=lambda p: p.factor))

    def span(self) -> tuple[float | None, float | None]:
        """Lowest and highest hunting-free crossover over every point and the nominal [Hz]
        (None where a crossover was not found)."""
        vals = [p.hunting_free_from for p in self.points] + [self.nominal]
        known = [v for v in vals if v is not None]
        if not known:
            return None, None
        return min(known), (None if any(v is None for v in vals) else max(known))

    def to_dict(self) -> dict:
        """JSON: ``plant``, ``nominal``, ``factors`` and the ``points`` (SI)."""
        return {"plant": self.plant, "nominal": to_jsonable(self.nominal),
                "factors": list(self.factors), "points": [to_jsonable(p) for p in self.points]}
