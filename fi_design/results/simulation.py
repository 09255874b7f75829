"""Results of one simulation: the hunting metric of a trace, and the simulation itself.

Produced by :func:`fi_design.simulation.metrics.hunting_metrics` and
:func:`fi_design.simulation.run.simulate`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from . import Result, dataclass_dict

if TYPE_CHECKING:  # pragma: no cover
    from ..spec import Spec

# The kernel's PlantParameters (fi_design.kernel.layout) and a replay's ReplayFit (fi_design.simulation.replay) are
# typed Any here: the results layer imports no physics, not even for a type.

__all__ = ["HuntingMetrics", "SimulationResult"]

#: Verdicts of the hunting metric.
VERDICTS = ("settled", "hunting", "stuck", "undetermined")


@dataclass(frozen=True, eq=False)
class HuntingMetrics(Result):
    """Hunting metric and settling figures of one trace.

    Attributes
    ----------
    hunting_cycles : int
        Peaks of x1 - r counted in the window (the paper's metric).
    peak_times : ndarray, shape (hunting_cycles,)
        Times of the counted peaks [s].
    peak_heights : ndarray, shape (hunting_cycles,)
        Error at the counted peaks [m].
    amplitude : float
        Peak-to-peak error in the window [m].
    period : float or None
        Mean time between counted peaks [s]; None with fewer than two.
    settled : bool
        Whether |x1 - r| stays within the settle band over the last quarter of
        the window.
    settling_time : float or None
        Time after the end of the motion until |x1 - r| stays within the
        settle band to the end of the trace [s]; None if it never does.
    final_error : float
        x1 - r at the last sample [m].
    verdict : str
        ``settled``, ``hunting``, ``stuck`` or ``undetermined``.
    reason : str
        Why, in one sentence.
    window : tuple of float
        The counting window (start, end) [s].
    settle_band : float
        The band used for ``settled`` and the settling time [m].
    """

    hunting_cycles: int
    peak_times: np.ndarray
    peak_heights: np.ndarray
    amplitude: float
    period: float | None
    settled: bool
    settling_time: float | None
    final_error: float
    verdict: str
    reason: str
    window: tuple[float, float]
    settle_band: float


@dataclass(frozen=True, eq=False)
class SimulationResult(Result):
    """Traces and metrics of one simulation.

    Attributes
    ----------
    spec : fi_design.spec.Spec
        The spec simulated (not in the JSON).
    isolated : bool
        Whether the isolated (two-mass) plant was simulated.
    method : str
        ``"fast"`` (RODAS4 kernel) or ``"reference"`` (solve_ivp).
    friction_model : str
        ``"lugre"`` or ``"switch"``.
    crossover : float
        Crossover of the controller [Hz] (the rule's, or the hardware gains').
    effects : tuple of str
        Names of the effects in the model.
    time : ndarray, shape (n,)
        Sample times [s] at the output rate.
    reference : ndarray, shape (n,)
        Reference r [m].
    position : ndarray, shape (n,)
        Stage position x1 [m] (the measured position).
    cart_position : ndarray, shape (n,)
        Cart position x2 [m] (equal to x1 without isolator).
    velocity : ndarray, shape (n,)
        Stage velocity v1 [m/s].
    cart_velocity : ndarray, shape (n,)
        Cart velocity v2 [m/s].
    force : ndarray, shape (n,)
        Commanded actuator force [N], before delay and saturation: the
        controller's output plus feedforward plus a known input force (a
        record's disturbance; in an open-loop replay the measured force).
    applied_force : ndarray, shape (n,)
        Force acting on the stage [N], after delay and saturation.
    bristle : ndarray, shape (n,)
        LuGre bristle deflection z [m] (zero for the switch model).
    success : bool
        Whether the integration reached the end time.
    status : str
        ``"ok"`` or the failure kind.
    message : str
        Failure description with the time reached and a likely cause.
    t_reached : float
        Last time integrated [s].
    n_steps, n_rejected, n_events : int
        Accepted steps, discarded trial steps (rejected by the error test or
        redone to end at a mode change) and mode switches.
    wall_time : float
        Integration time [s] (excluding JIT compilation on first use only if
        the kernel was already compiled).
    metrics : HuntingMetrics
        Hunting metric and verdict of this trace.
    parameters : fi_design.kernel.layout.PlantParameters
        The kernel parameters used.
    drive : str
        ``"closed"`` (the model's controller closes the loop) or ``"force"``
        (open-loop replay of a record's measured force).
    record : str or None
        Source of the replayed record; None for the spec's own motion.
    window : ndarray of int, shape (n,), or None
        Open-loop replay: the number of the re-anchored window of each
        sample (the state is reset to the measurement at each window's
        start); None otherwise.
    replay : fi_design.simulation.replay.ReplayFit or None
        How a record's replay agrees with the measurement; None otherwise.
    """

    spec: Spec = field(repr=False)
    isolated: bool
    method: str
    friction_model: str
    crossover: float
    effects: tuple[str, ...]
    time: np.ndarray
    reference: np.ndarray
    position: np.ndarray
    cart_position: np.ndarray
    velocity: np.ndarray
    cart_velocity: np.ndarray
    force: np.ndarray
    applied_force: np.ndarray
    bristle: np.ndarray
    success: bool
    status: str
    message: str
    t_reached: float
    n_steps: int
    n_rejected: int
    n_events: int
    wall_time: float
    metrics: HuntingMetrics
    parameters: Any
    drive: str = "closed"
    record: str | None = None
    window: np.ndarray | None = None
    replay: Any = None

    @property
    def error(self) -> np.ndarray:
        """Position error x1 - r [m]."""
        return self.position - self.reference

    @property
    def deflection(self) -> np.ndarray | None:
        """Joint deflection x1 - x2 [m]; None without isolator."""
        return self.position - self.cart_position if self.isolated else None

    def traces(self) -> dict[str, np.ndarray]:
        """Columns in the measured-data layout (docs/interfaces.md).

        ``time_s``, ``reference_m``, ``position_m``, ``force_N`` and, for the
        isolated plant, ``deflection_m``. A simulation that did not complete
        gives the samples it reached: the rows end before the first sample it
        holds no value for (the result's arrays are NaN there), so that a
        spreadsheet, pandas and the measured-data reader never meet a ``nan``.
        """
        cols = {"time_s": self.time, "reference_m": self.reference, "position_m": self.position,
                "force_N": self.force}
        if self.isolated:
            cols["deflection_m"] = self.deflection
        if self.window is not None:
            cols["window"] = self.window
        finite = np.all([np.isfinite(np.asarray(v, dtype=float)) for v in cols.values()], axis=0)
        if not finite.all():
            end = int(np.argmin(finite))
            cols = {name: v[:end] for name, v in cols.items()}
        return cols

    def to_dict(self, traces: bool = False) -> dict:
        """Plain JSON data: metadata and metrics; the traces only when asked.

        Parameters
        ----------
        traces : bool, optional
            Include the arrays (time, positions, forces, ...).

        Returns
        -------
        dict
        """
        return dataclass_dict(self, None if traces else
                              (lambda value: isinstance(value, np.ndarray)))
