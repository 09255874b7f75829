"""The stage as a whole: every move of the family, the cycles, the hunting-free crossover.

:func:`stage_hunting` answers per plant (:mod:`fi_design.stage`); 
:func:`stage_hunts` is the cheap yes/no a search asks.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable, Sequence

from .. import spec as _spec
from ..errors import ArgumentError
from ..model import Model, as_model
from ..results.stage import Cycle, MoveOutcome, StageHunting
from .cycle import _ro, converge_cycle, cycle_fold
from .moves import (FOLD_STEP, _Run, _family_reference, _integrates, _spec_reference,
                    family_distances, move_outcome, watch_settings)

log = logging.getLogger(__name__)


# --------------------------------------------------------------------------- the stage


def _moves(model, isolated, params, horizon, family):
    """(distance, label, reference, move end) of the spec's motion and the family."""
    spec = model.spec
    ref, end = _spec_reference(spec, horizon)
    net = ref.final
    out = [(net, "spec", ref, end)]
    dists = family_distances(model, isolated, params) if family is None else tuple(family)
    for d in dists:
        r, e = _family_reference(spec, d, horizon)
        out.append((float(d), "family", r, e))
    return out


def stage_hunts(model: Model | _spec.Spec, isolated: bool, *, crossover: float | None = None,
                family: Sequence[float] | None = None, first_only: bool = False) \
        -> tuple[tuple[MoveOutcome, ...], list[_Run]]:
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
    (tuple of MoveOutcome, list)
        The outcomes, and the runs behind them (for the cycles).
    """
    model = as_model(model)
    if crossover is not None:
        model = model.at(crossover=crossover)
    p = model.plant(isolated)
    w = watch_settings(model, p)
    runs: list[_Run] = []
    cycles: list[_Run] = []  # one run per cycle found: later moves stop on entering one
    for dist, label, ref, end in _moves(model, isolated, p, w.horizon, family):
        r = move_outcome(p, ref, end, w, distance=dist, label=label, known=cycles)
        runs.append(r)
        if r.cycle_states is not None and not any(c.cycle_states is r.cycle_states
                                                  for c in cycles):
            cycles.append(r)
        if first_only and r.outcome.hunts:
            break
    return tuple(r.outcome for r in runs), runs


def stage_hunting(model: Model | _spec.Spec, isolated: bool | None = None, *,
                  crossover: float | None = None,
                  family: Sequence[float] | None = None, first_only: bool = False,
                  converge: bool = True, boundary: bool = True, trace: bool = True,
                  progress: Callable[[str], None] | None = None) -> StageHunting:
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
    progress : callable, optional
        ``progress(text)`` as the work proceeds.

    Returns
    -------
    StageHunting
    """
    model = as_model(model)
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
    outcomes, runs = stage_hunts(model, iso, family=family, first_only=first_only)
    hunting = [r for r in runs if r.outcome.hunts]
    cycle = None
    others: list[Cycle] = []
    if hunting and converge:
        say("converging the hunting cycle ...")
        cycles = _distinct_cycles(p, hunting, fc, trace)
        if cycles:
            cycle, others = cycles[0], cycles[1:]
    free_from, bound = None, None
    if boundary and _integrates(p):
        bound = _boundary(model, iso, fc, cycle, family, say)
        free_from = bound.pop("hunting_free_from")
    fr = model.friction
    held = max(fr.static(1.0), fr.static(-1.0))  # what static friction can hold against the loop
    return StageHunting(plant=plant, crossover=float(fc), moves=outcomes, cycle=cycle,
                        other_cycles=tuple(others), hunting_free_from=free_from,
                        boundary=bound, first_only=first_only,
                        static_error_bound=model.law.static_error(held + abs(model.offset)),
                        settle_band=model.spec.requirements.hunting.settle_band)


def _distinct_cycles(p, hunting: Sequence[_Run], fc: float, trace: bool) -> list[Cycle]:
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


def _run_cycle(run: _Run, crossover: float) -> Cycle:
    """The cycle a hunting move repeated, as its run left it (no Newton): enough to start the
    fold's continuation from, which converges on the cycle at every step anyway."""
    m = run.outcome
    return Cycle(crossover=float(crossover), amplitude=float(m.amplitude or 0.0),
                 period=float(m.period or 0.0), stable=True, multiplier=None,
                 multiplier_check=None, method="simulation", residual=math.nan,
                 crossings=int(run.crossings), on_limiter=None, deflection_range=None,
                 section_state=_ro(run.section_state))


def _boundary(model, iso, fc, cycle, family, say) -> dict:
    """The hunting-free crossover: the fold of the cycle (found first if needed)."""
    scan = model.spec.simulation.crossover_scan
    top = max(scan.stop, fc)
    tests = 0
    branch: list = []
    if cycle is None:
        # no move hunts here: look for a cycle below, then follow it up to its fold
        f = fc
        found = None
        while f > scan.start * (1 + 1e-9):
            f = max(scan.start, f / FOLD_STEP)
            say(f"looking for a hunting cycle below the design crossover: {f:.3g} Hz")
            _, runs = stage_hunts(model, iso, crossover=f, family=family, first_only=True)
            tests += 1
            h = [r for r in runs if r.outcome.hunts]
            if h:
                found = _run_cycle(h[0], f)
                break
        if found is None:
            return {"hunting_free_from": scan.start, "bracket": [scan.start, scan.start],
                    "kind": "bound", "resolution": 0.0, "tests": tests, "branch": [],
                    "note": f"no move of the family hunts from {scan.start:g} Hz up"}
        cycle = found
    for _ in range(4):
        fold = cycle_fold(model, iso, cycle, top=top, progress=say)
        tests += fold["tests"]
        lo, hi = fold["bracket"]
        branch += fold["branch"]
        if fold["kind"] == "bound":
            return {"hunting_free_from": None, "bracket": [lo, hi], "kind": "bound",
                    "resolution": 0.0, "tests": tests, "branch": sorted(branch),
                    "note": f"the cycle persists up to {hi:.4g} Hz, the top of the search"}
        # another cycle above the fold?
        say(f"checking every move just above the fold at {hi:.4g} Hz ...")
        _, runs = stage_hunts(model, iso, crossover=hi, family=family, first_only=True)
        tests += 1
        h = [r for r in runs if r.outcome.hunts]
        if not h:
            return {"hunting_free_from": hi, "bracket": [lo, hi], "kind": "fold",
                    "resolution": hi - lo, "tests": tests, "branch": sorted(branch),
                    "note": "the fold of the cycle, confirmed by the move family above it"}
        cycle = _run_cycle(h[0], hi)
    return {"hunting_free_from": hi, "bracket": [lo, hi], "kind": "fold",
            "resolution": hi - lo, "tests": tests, "branch": sorted(branch),
            "note": "several cycles; the last fold found"}
