"""Every move of a plant's family run to its answer, the spec's own motion first.

Step 1 of the stage-level answer (:mod:`fi_design.stage`):
:func:`stage_hunts` runs the spec's motion and each move of the family
(:mod:`.family`) from rest with :func:`~fi_design.stage.runs.move_outcome`;
a move that enters a cycle an earlier move repeated stops there.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Iterator, Sequence

from .. import spec as _spec
from ..errors import ArgumentError
from ..kernel.layout import PlantParameters
from ..model import Model, as_model
from ..results.stage import MoveOutcome
from ..trajectory import Trajectory
from .family import family_distances, family_reference, largest_move, spec_reference
from .runs import MoveRun, move_outcome
from .settings import watch_settings

__all__ = ["ORDERS", "spread", "stage_hunts"]

#: Orders of the family's moves (:func:`stage_hunts`): by size as given, or :func:`spread`.
ORDERS = ("size", "spread")


def _moves(model: Model, isolated: bool, params: PlantParameters, horizon: float,
           family: Sequence[float] | None, order: str = ORDERS[0]) \
        -> Iterator[tuple[float, str, Trajectory, float]]:
    """(distance [m], label, reference, move end [s]) of the spec's motion and the family,
    made as they are run (a run that stops at the first hunting move makes no more)."""
    spec = model.spec
    ref, end = spec_reference(spec, horizon)
    # the spec's motion stands for its largest move: a back-and-forth motion nets to 0, and
    # a move of 0 m is not a distance to state or to draw on a log axis
    yield float(largest_move(spec).distance), "spec", ref, end
    dists = family_distances(model, isolated, params) if family is None else tuple(family)
    if order == "spread":
        dists = spread(dists)
    for d in dists:
        r, e = family_reference(spec, d, horizon)
        yield float(d), "family", r, e


def spread(distances: Sequence[float]) -> tuple[float, ...]:
    """The moves in the order that finds a band of hunting moves soonest (a permutation).

    The largest move first (a move the isolator's stroke takes up never breaks
    the cart loose; a long one does), then the others by halving the range of
    sizes: the middle size, the middles of the halves, and so on, so that a
    band of k hunting sizes among n is met within about 2 n / k moves. Moves of
    one size (both directions) stay together, in the given order.

    Parameters
    ----------
    distances : sequence of float
        Signed move distances [m].

    Returns
    -------
    tuple of float
        The same distances, reordered.
    """
    sizes = sorted({abs(d) for d in distances})
    if not sizes:
        return ()
    ranks = [len(sizes) - 1]
    spans = deque([(0, len(sizes) - 2)])
    while spans:
        lo, hi = spans.popleft()
        if lo > hi:
            continue
        mid = (lo + hi + 1) // 2
        ranks.append(mid)
        spans.append((lo, mid - 1))
        spans.append((mid + 1, hi))
    return tuple(d for k in ranks for d in distances if abs(d) == sizes[k])


def stage_hunts(model: Model | _spec.Spec, isolated: bool, *, crossover: float | None = None,
                family: Sequence[float] | None = None, first_only: bool = False,
                order: str = ORDERS[0]) -> tuple[tuple[MoveOutcome, ...], list[MoveRun]]:
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
    order : {"size", "spread"}
        The family's moves by size (the given order, default), or
        :func:`spread` (the largest first, then halving the sizes: the first
        hunting move sooner, for a caller that reads only whether some move
        hunts). The spec's motion is always first.

    Returns
    -------
    (tuple of MoveOutcome, list of MoveRun)
        The outcomes, and the runs behind them (for the cycles).
    """
    if order not in ORDERS:
        raise ArgumentError(f"order must be one of {', '.join(ORDERS)}, got {order!r}")
    model = as_model(model, "model")
    if crossover is not None:
        model = model.at(crossover=crossover)
    p = model.plant(isolated)
    w = watch_settings(model, p)
    runs: list[MoveRun] = []
    cycles: list[MoveRun] = []  # one run per cycle found: later moves stop on entering one
    for dist, label, ref, end in _moves(model, isolated, p, w.horizon, family, order):
        r = move_outcome(p, ref, end, w, distance=dist, label=label, known=cycles)
        runs.append(r)
        if r.cycle_states is not None and not any(c.cycle_states is r.cycle_states
                                                  for c in cycles):
            cycles.append(r)
        if first_only and r.outcome.hunts:
            break
    return tuple(r.outcome for r in runs), runs
