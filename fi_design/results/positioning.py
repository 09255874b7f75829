"""Results of the positioning requirement: how fast and how close the stage comes to rest.

Produced by :func:`fi_design.stage.positioning`. ``requirements.positioning``
asks what the stage is for: after every move of its family, to be within a
band of its target within a settle time and to rest within a static error. A
stage that never hunts can still fail it (a loop without integrator resting
15 µm off its target, a slow settling).
"""

from __future__ import annotations

from dataclasses import dataclass

from . import Result, to_jsonable

__all__ = ["MovePosition", "PositioningResult"]


@dataclass(frozen=True)
class MovePosition(Result):
    """One move of the family, judged for positioning.

    Attributes
    ----------
    distance : float
        Signed move distance [m] (the spec's own motion: its largest move).
    label : str
        ``"family"`` or ``"spec"``.
    outcome : str
        The stage-level outcome of the move
        (:data:`fi_design.results.stage.MOVE_OUTCOMES`).
    settle_time : float or None
        Time from the end of the move until |x1 - r| stays within the band
        for good [s]; None when it never does (a cycle, a rest outside the
        band, a move not judged).
    static_error : float or None
        |x1 - r| where the stage rests [m]; None when it does not rest.
    passed : bool
        Whether this move meets every positioning requirement given.
    """

    distance: float
    label: str
    outcome: str
    settle_time: float | None
    static_error: float | None
    passed: bool


@dataclass(frozen=True)
class PositioningResult(Result):
    """``requirements.positioning`` judged over the move family of the spec's own plant.

    Attributes
    ----------
    plant : str
        ``"isolated"`` or ``"non_isolated"``: the spec's own plant.
    band : float
        Settle band on |x1 - r| [m].
    settle_time_limit : float or None
        Required settle time [s]; None: not required.
    static_error_limit : float or None
        Largest allowed rest error [m]; None: not required.
    moves : tuple of MovePosition
        Every move, the spec's own motion first.
    resolution : float
        Sampling step of the traces the settle times come from [s].
    """

    plant: str
    band: float
    settle_time_limit: float | None
    static_error_limit: float | None
    moves: tuple[MovePosition, ...]
    resolution: float

    @property
    def passed(self) -> bool:
        """Whether every move meets every requirement given."""
        return all(m.passed for m in self.moves)

    @property
    def failing(self) -> tuple[MovePosition, ...]:
        """The moves that do not meet it."""
        return tuple(m for m in self.moves if not m.passed)

    @property
    def worst_settle_time(self) -> float | None:
        """Longest settle time over the moves [s]; None when some move never settles."""
        times = [m.settle_time for m in self.moves]
        return None if any(t is None for t in times) else max(times, default=0.0)

    @property
    def worst_static_error(self) -> float | None:
        """Largest rest error over the moves [m]; None when some move does not rest."""
        errors = [m.static_error for m in self.moves]
        return None if any(e is None for e in errors) else max(errors, default=0.0)

    def to_dict(self) -> dict:
        """JSON: the requirement, ``passed``, the worst values and every move (SI)."""
        return {"plant": self.plant, "band": self.band,
                "settle_time_limit": self.settle_time_limit,
                "static_error_limit": self.static_error_limit, "passed": self.passed,
                "worst_settle_time": to_jsonable(self.worst_settle_time),
                "worst_static_error": to_jsonable(self.worst_static_error),
                "resolution": self.resolution,
                "moves": [to_jsonable(m) for m in self.moves]}
