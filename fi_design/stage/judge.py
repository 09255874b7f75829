"""The stage as a whole: every move of the family, the cycles, the hunting-free crossover.

:func:`stage_hunting` answers per plant (:mod:`fi_design.stage`): the moves
(:func:`~fi_design.stage.moves.stage_hunts`), the distinct cycles they enter
converged as periodic orbits (:mod:`.orbit`), and the hunting-free crossover
(:mod:`.boundary`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

from .. import spec as _spec
from ..errors import ArgumentError
from ..kernel.layout import PlantParameters
from ..model import Model, as_model
from ..results.stage import Cycle, StageHunting
from .boundary import cycle_of_run, hunting_free_boundary
from .moves import ORDERS, stage_hunts
from .orbit import converge_cycle
from .runs import MoveRun
from .settings import integrates

__all__ = ["stage_hunting"]

def stage_hunting(model: Model | _spec.Spec, isolated: bool | None = None, *,
                  crossover: float | None = None,
                  family: Sequence[float] | None = None, first_only: bool = False,
                  converge: bool = True, boundary: bool = True, trace: bool = True,
                  order: str = ORDERS[0], progress: Callable[[str], None] | None = None) -> StageHunting:
    """The stage-level hunting answer of one plant.

    Parameters
    ----------
    model : Model or Spec
        The resolved model (a spec is resolved).
    isolated : bool, optional
        Which plant; None follows the spec.
    crossover : float, optional
        Controller crossover [Hz]; default the model's.
    family : sequence of float, optional
        Signed move distances [m] replacing ``motion.family``.
    first_only : bool
        Stop at the first hunting move (a study's cell needs only whether and
        how much the stage hunts).
    converge : bool
        Converge the cycle as a periodic orbit (Newton on the return map).
    boundary : bool
        Find the hunting-free crossover (the cycle's fold).
    trace : bool
        Keep one period of the cycle for plots.
    order : {"size", "spread"}
        The order the family's moves are run in
        (:func:`~fi_design.stage.moves.stage_hunts`); with ``first_only`` it
        decides which hunting move is met first, never whether one is.
    progress : callable, optional
        ``progress(text)`` as the work proceeds.

    Returns
    -------
    StageHunting
    """
    model = as_model(model, "model")
    if crossover is not None:
        model = model.at(crossover=crossover)
    iso = model.has_isolator if isolated is None else bool(isolated)
    if iso and not model.has_isolator:
        raise ArgumentError("the spec has no isolator: cannot judge the isolated plant")
    fc = model.crossover
    p = model.plant(iso)
    plant = "isolated" if iso else "non_isolated"
    say = progress or (lambda text: None)
    say(f"simulating the move family ({plant.replace('_', '-')} plant) ...")
    outcomes, runs = stage_hunts(model, iso, family=family, first_only=first_only,
                                  order=order)
    hunting = [r for r in runs if r.outcome.hunts]
    cycle = None
    others: list[Cycle] = []
    if hunting and converge:
        say("converging the hunting cycle ...")
        cycles = _distinct_cycles(p, hunting, fc, trace)
        if cycles:
            cycle, others = cycles[0], cycles[1:]
    bound = None
    if boundary and integrates(p):
        start = cycle
        if start is None and hunting:
            # moves hunt here but no cycle converged (a sampled loop's cycle is no exact
            # orbit of the section): follow the one a move repeated up from the design
            # crossover, never search below it as if no move hunted
            start = cycle_of_run(hunting[0], fc)
        bound = hunting_free_boundary(model, iso, start, family=family, progress=say)
    return StageHunting(plant=plant, crossover=float(fc), moves=outcomes, cycle=cycle,
                        other_cycles=tuple(others),
                        hunting_free_from=None if bound is None else bound.hunting_free_from,
                        boundary=bound, first_only=first_only,
                        static_error_bound=model.static_error_bound,
                        settle_band=model.spec.requirements.hunting.settle_band)


def _distinct_cycles(p: PlantParameters, hunting: Sequence[MoveRun], fc: float,
                     trace: bool) -> list[Cycle]:
    """Converge the cycles the hunting moves enter; one per distinct orbit, largest first."""
    cycles: list[Cycle] = []
    for r in hunting:
        seen = False
        for c in cycles:
            # same orbit: the run's amplitude and period agree with a converged one
            if (r.outcome.amplitude is not None and r.outcome.period is not None
                    and abs(r.outcome.amplitude - c.amplitude) <= 0.05 * c.amplitude
                    and abs(r.outcome.period - c.period) <= 0.05 * c.period):
                seen = True
                break
        if seen:
            continue
        c = converge_cycle(p, r.level, r.section_state, r.crossings, fc,
                           period=r.outcome.period, trace=trace)
        if c is not None:
            cycles.append(c)
    cycles.sort(key=lambda c: -c.amplitude)
    return cycles
