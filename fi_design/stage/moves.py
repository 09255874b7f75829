"""Every move of a plant's family run to its answer, the spec's own motion first.

Step 1 of the stage-level answer (:mod:`fi_design.stage`):
:func:`stage_hunts` runs the spec's motion and each move of the family
(:mod:`.family`) from rest with :func:`~fi_design.stage.runs.move_outcome`;
a move that enters a cycle an earlier move repeated stops there.
"""

from __future__ import annotations

from collections.abc import Sequence

from .. import spec as _spec
from ..kernel.layout import PlantParameters
from ..model import Model, as_model
from ..results.stage import MoveOutcome
from ..trajectory import Trajectory
from .family import family_distances, family_reference, largest_move, spec_reference
from .runs import MoveRun, move_outcome
from .settings import watch_settings

__all__ = ["stage_hunts"]


def _moves(model: Model, isolated: bool, params: PlantParameters, horizon: float,
           family: Sequence[float] | None) -> list[tuple[float, str, Trajectory, float]]:
    """(distance [m], label, reference, move end [s]) of the spec's motion and the family."""
    spec = model.spec
    ref, end = spec_reference(spec, horizon)
    # the spec's motion stands for its largest move: a back-and-forth motion nets to 0, and
    # a move of 0 m is not a distance to state or to draw on a log axis
    out = [(float(largest_move(spec).distance), "spec", ref, end)]
    dists = family_distances(model, isolated, params) if family is None else tuple(family)
    for d in dists:
        r, e = family_reference(spec, d, horizon)
        out.append((float(d), "family", r, e))
    return out


def stage_hunts(model: Model | _spec.Spec, isolated: bool, *, crossover: float | None = None,
                family: Sequence[float] | None = None, first_only: bool = False) \
        -> tuple[tuple[MoveOutcome, ...], list[MoveRun]]:
    """Run the spec's motion and every move of the family; the outcomes and the runs.

    Parameters
    ----------
    model : Model or Spec
        The resolved model (a spec is resolved).
    isolated : bool
        Which plant.
    crossover : float, optional
        Judge at this crossover [Hz] (``model.at(crossover=...)``).
    family : sequence of float, optional
        Signed move distances [m] replacing ``motion.family``.
    first_only : bool
        Stop at the first move that hunts.

    Returns
    -------
    (tuple of MoveOutcome, list of MoveRun)
        The outcomes, and the runs behind them (for the cycles).
    """
    model = as_model(model)
    if crossover is not None:
        model = model.at(crossover=crossover)
    p = model.plant(isolated)
    w = watch_settings(model, p)
    runs: list[MoveRun] = []
    cycles: list[MoveRun] = []  # one run per cycle found: later moves stop on entering one
    for dist, label, ref, end in _moves(model, isolated, p, w.horizon, family):
        r = move_outcome(p, ref, end, w, distance=dist, label=label, known=cycles)
        runs.append(r)
        if r.cycle_states is not None and not any(c.cycle_states is r.cycle_states
                                                  for c in cycles):
            cycles.append(r)
        if first_only and r.outcome.hunts:
            break
    return tuple(r.outcome for r in runs), runs
