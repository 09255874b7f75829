"""The hunting-free crossover: the fold of the cycle, bracketed and bisected.

Step 3 of the stage-level answer (:mod:`fi_design.stage`). The one fold
search is :func:`cycle_fold`: it follows a cycle up the crossover by
continuation (each existence test, :func:`~fi_design.stage.orbit.cycle_exists`,
starts from the orbit at the nearest crossover where the cycle still exists),
brackets the crossover where it ceases to exist, and bisects the bracket.
:func:`hunting_free_boundary` makes it the stage's answer: when no move hunts
at the design crossover it first looks for a cycle below, and above each fold
it runs the move family to make sure no other cycle is entered there (if one
is, that cycle is followed to its own fold).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import replace

import numpy as np

from ..display import quantity
from ..model import Model
from ..results import frozen_array
from ..results.stage import Boundary, Cycle
from .moves import stage_hunts
from .orbit import cycle_exists
from .runs import MoveRun
from .settings import FOLD_RELATIVE, FOLD_RESOLUTION, FOLD_STEP, watch_settings

__all__ = ["cycle_fold", "cycle_of_run", "hunting_free_boundary"]


def cycle_fold(model: Model, isolated: bool, cycle: Cycle, *, top: float | None = None,
               progress: Callable[[str], None] | None = None) -> Boundary:
    """The crossover above which a cycle no longer exists (its fold), by bisection.

    Parameters
    ----------
    model : Model
        The resolved model.
    isolated : bool
        Which plant.
    cycle : Cycle
        The cycle at ``cycle.crossover``.
    top : float, optional
        Highest crossover searched [Hz]; default ``simulation.crossover_scan.stop``.
    progress : callable, optional
        ``progress(text)``.

    Returns
    -------
    Boundary
        ``kind "fold"``: the cycle exists at ``bracket[0]`` and not at
        ``bracket[1]`` (= ``hunting_free_from``, not yet checked against the
        move family); ``kind "bound"``: it persists up to ``top``
        (``hunting_free_from`` None).
    """
    top = model.spec.simulation.crossover_scan.stop if top is None else top
    lo, state, q = cycle.crossover, np.array(cycle.section_state), cycle.crossings
    period = cycle.period
    branch = [(float(lo), float(cycle.amplitude), float(cycle.period))]
    tests = 0

    def exists(fc: float) -> bool:
        nonlocal tests, lo, state, q, period
        tests += 1
        at = model.at(crossover=fc)
        p = at.plant(isolated)
        found = cycle_exists(p, float(state[0]), state, watch_settings(at, p), period)
        if found is None:
            return False
        lo = fc
        if found.state is not None:
            state, q, period = found.state, found.crossings, found.period or period
            branch.append((float(fc), found.amplitude, found.period))
        return True

    while True:
        hi = None
        f = lo
        while f < top:
            f = min(top, f * FOLD_STEP)
            if progress is not None:
                progress(f"following the cycle to {quantity(f, 'Hz', 3)}")
            if not exists(f):
                hi = f
                break
        if hi is None:
            return Boundary(hunting_free_from=None, bracket=(lo, top), kind="bound",
                            resolution=0.0, tests=tests, branch=tuple(sorted(branch)),
                            note=f"the cycle persists up to {quantity(top, 'Hz', 4)}, "
                                 "the top of the search")
        while hi - lo > max(FOLD_RESOLUTION, FOLD_RELATIVE * hi):
            mid = 0.5 * (lo + hi)
            if not exists(mid):
                hi = mid
        # a test started far from the cycle may have missed it (a step or the first
        # midpoint): the upper end is tried again from the nearest cycle, and the search
        # goes on from there when the cycle is found after all
        if not exists(hi):
            return Boundary(hunting_free_from=hi, bracket=(lo, hi), kind="fold",
                            resolution=hi - lo, tests=tests, branch=tuple(sorted(branch)),
                            note="the fold of the cycle")


def cycle_of_run(run: MoveRun, crossover: float) -> Cycle:
    """The cycle a hunting move repeated, as its run left it (no Newton): enough to start the
    fold's continuation from, which converges on the cycle at every step anyway.

    Parameters
    ----------
    run : MoveRun
        A run whose move ends in a hunting cycle.
    crossover : float
        The crossover it ran at [Hz].

    Returns
    -------
    Cycle
        ``method "simulation"``, no Floquet multiplier.
    """
    m = run.outcome
    return Cycle(crossover=float(crossover), amplitude=float(m.amplitude or 0.0),
                 period=float(m.period or 0.0), stable=True, multiplier=None,
                 multiplier_check=None, method="simulation", residual=math.nan,
                 crossings=int(run.crossings), on_limiter=None, deflection_range=None,
                 section_state=frozen_array(run.section_state))


def hunting_free_boundary(model: Model, isolated: bool, cycle: Cycle | None = None, *,
                          family: Sequence[float] | None = None,
                          progress: Callable[[str], None] | None = None) -> Boundary:
    """The stage's hunting-free crossover: the fold of its cycle, confirmed by the family.

    Parameters
    ----------
    model : Model
        The resolved model, at the design crossover.
    isolated : bool
        Which plant.
    cycle : Cycle, optional
        The cycle at the design crossover; None when no move hunts there (a
        cycle is then looked for below it, down to ``crossover_scan.start``).
    family : sequence of float, optional
        Signed move distances [m] replacing ``motion.family``.
    progress : callable, optional
        ``progress(text)``.

    Returns
    -------
    Boundary
        A fold (no move of the family hunts just above it), or a bound: the
        bottom of the search when no move hunts from there up, or None when
        the cycle persists up to the top, or when moves still hunt just above
        the last of the folds followed (the note says so).
    """
    say = progress or (lambda text: None)
    scan = model.spec.simulation.crossover_scan
    fc = model.crossover
    top = max(scan.stop, fc)
    tests = 0
    branch: list = []
    if cycle is None:
        # no move hunts here: look for a cycle below, then follow it up to its fold
        f = fc
        found = None
        while f > scan.start * (1 + 1e-9):
            f = max(scan.start, f / FOLD_STEP)
            say(f"looking for a hunting cycle below the design crossover: {quantity(f, 'Hz', 3)}")
            _, runs = stage_hunts(model, isolated, crossover=f, family=family, first_only=True)
            tests += 1
            h = [r for r in runs if r.outcome.hunts]
            if h:
                found = cycle_of_run(h[0], f)
                break
        if found is None:
            return Boundary(hunting_free_from=scan.start, bracket=(scan.start, scan.start),
                            kind="bound", resolution=0.0, tests=tests, branch=(),
                            note="no move of the family hunts from "
                                 f"{quantity(scan.start, 'Hz', 6)} up")
        cycle = found
    for _ in range(4):
        fold = cycle_fold(model, isolated, cycle, top=top, progress=say)
        tests += fold.tests
        lo, hi = fold.bracket
        branch += fold.branch
        if fold.kind == "bound":
            return replace(fold, tests=tests, branch=tuple(sorted(branch)))
        # another cycle above the fold?
        say(f"checking every move just above the fold at {quantity(hi, 'Hz', 4)} ...")
        _, runs = stage_hunts(model, isolated, crossover=hi, family=family, first_only=True)
        tests += 1
        h = [r for r in runs if r.outcome.hunts]
        if not h:
            return replace(fold, tests=tests, branch=tuple(sorted(branch)),
                           note="the fold of the cycle, confirmed by the move family above it")
        cycle = cycle_of_run(h[0], hi)
    # moves still hunt just above the last fold: that fold ends no hunting, so no crossover
    # from which no move hunts was found (a cycle the continuation cannot follow leaves a
    # fold a bisection step above every crossover it starts from)
    return Boundary(hunting_free_from=None, bracket=(fold.bracket[0], top), kind="not_found",
                    resolution=0.0, tests=tests, branch=tuple(sorted(branch)),
                    note=f"not found: moves still hunt at {quantity(hi, 'Hz', 4)}, above "
                         "the last of several folds the cycles' continuation found")
