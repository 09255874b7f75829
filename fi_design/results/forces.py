"""The forces the mechanism sees over the move family: end-stop impacts and the actuator's peak.

Produced by :func:`fi_design.stage.forces.move_forces`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from . import Result

__all__ = ["MoveForces", "StageForces"]


@dataclass(frozen=True)
class MoveForces(Result):
    """The forces of one move, from rest through the move and its settling.

    Attributes
    ----------
    distance : float
        Signed move distance [m] (the spec's own motion: its net travel).
    label : str
        ``"family"`` or ``"spec"``.
    impacts : int
        How often the joint runs onto its end stop (contact starts).
    peak_stop_force : float
        Largest contact force of the end stop [N] (0 without contact).
    peak_actuator_force : float
        Largest force the actuator applies [N] (after the delay and the
        saturation of ``controller.force_limit``), the weight it holds on a
        vertical drive axis included (:attr:`StageForces.held_weight`).
    contact_time : float
        Time the joint spends on its end stop [s].
    peak_command : float
        Largest force the controller commands [N] (before the saturation), the
        weight it holds on a vertical drive axis included.
    """

    distance: float
    label: str
    impacts: int
    peak_stop_force: float
    peak_actuator_force: float
    contact_time: float
    peak_command: float = 0.0


@dataclass(frozen=True)
class StageForces(Result):
    """The forces over the move family of one plant.

    Attributes
    ----------
    plant : str
        ``isolated`` or ``non_isolated``.
    moves : tuple of MoveForces
        Per move, the spec's own motion first.
    stop_stiffness, stop_damping : float or None
        The end stop's contact stiffness [N/m] and damping [N s/m]; None
        without isolator.
    stop_default : bool
        Whether the end stop's values are the spec's defaults (an assumption
        to name: the contact force goes with sqrt(k_stop)).
    settle : float
        Time simulated after each move's end [s].
    rate : float
        Output rate the peaks were taken at [Hz].
    held_weight : float
        The weight the actuator holds on a vertical drive axis, (m1 + m2) g
        [N]; 0 otherwise. The simulation carries no weight: every actuator
        and command peak adds it to the simulated force's largest magnitude.
    """

    plant: str
    moves: tuple[MoveForces, ...] = field(default=())
    stop_stiffness: float | None = None
    stop_damping: float | None = None
    stop_default: bool = True
    settle: float = 0.0
    rate: float = 0.0
    held_weight: float = 0.0

    @property
    def moves_on_stop(self) -> int:
        """Moves whose joint touches its end stop."""
        return sum(m.impacts > 0 for m in self.moves)

    @property
    def peak_stop_force(self) -> float:
        """Largest end-stop contact force over the family [N]."""
        return max((m.peak_stop_force for m in self.moves), default=0.0)

    @property
    def peak_actuator_force(self) -> float:
        """Largest actuator force over the family [N]."""
        return max((m.peak_actuator_force for m in self.moves), default=0.0)

    @property
    def peak_command(self) -> float:
        """Largest force the controller commands over the family [N]."""
        return max((m.peak_command for m in self.moves), default=0.0)

    @property
    def most_impacts(self) -> int:
        """Most end-stop impacts of one move."""
        return max((m.impacts for m in self.moves), default=0)

    def to_dict(self) -> dict:
        """JSON: the summary (``moves_on_stop``, ``peak_stop_force`` N, ``peak_actuator_force``
        N, ``most_impacts``), the end stop's values, ``held_weight`` N and every move."""
        return {"plant": self.plant, "moves_on_stop": self.moves_on_stop,
                "moves_tried": len(self.moves), "most_impacts": self.most_impacts,
                "peak_stop_force": self.peak_stop_force,
                "peak_actuator_force": self.peak_actuator_force,
                "peak_command": self.peak_command,
                "stop_stiffness": self.stop_stiffness, "stop_damping": self.stop_damping,
                "stop_default": self.stop_default, "settle": self.settle, "rate": self.rate,
                "held_weight": self.held_weight,
                "moves": [m.to_dict() for m in self.moves]}
