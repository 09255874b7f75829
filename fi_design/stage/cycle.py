"""The cycle itself and its fold: Newton on the return map, bisection on existence.

Steps 2 and 3 of the stage-level answer (:mod:`fi_design.stage`):
:func:`converge_cycle` converges the orbit a hunting move repeated and its
Floquet multiplier; :func:`cycle_exists` and :func:`cycle_fold` find the
crossover above which the cycle no longer exists.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..kernel.layout import W_ARM, PlantParameters, state_index
from ..model import Model
from ..results.stage import Cycle, CycleTrace
from ..simulation.run import tolerances
from .moves import (FOLD_RELATIVE, FOLD_RESOLUTION, FOLD_STEP, MULTIPLIER_AGREEMENT, ORBIT_RTOL,
                    PERTURBATION, REPEAT, Watch, _guess_period, _hold, _integrate, _rest_ends_run, _restartable,
                    _watch_array, watch_settings)

log = logging.getLogger(__name__)


# --------------------------------------------------------------------------- the cycle


def _return_map(params, level, state, crossings, tol, max_steps, horizon, t_out=None):
    """Run from a section state to the ``crossings``-th crossing; None if it comes to rest."""
    w = Watch(band=0.0, quiet=math.inf, horizon=horizon, rest_anywhere=False, tolerance=tol,
              max_steps=max_steps)
    arm = max(1e-9, 1e-6 * max(abs(level), 1e-3))
    arr = _watch_array(w, 0.0, level, repeat=0.0, quiet=False, max_crossings=crossings)
    arr[W_ARM] = arm
    out = _integrate(params, state, _hold(level, horizon), horizon, arr, tol, max_steps,
                     crossings=crossings, t_out=t_out, h_max=math.inf)
    if out.code != 0 or len(out.crossing_times) < crossings:
        return None
    return out


def _scales(params: PlantParameters, tol: float) -> np.ndarray:
    return tolerances(params, tol) / tol


def converge_cycle(params: PlantParameters, level: float, state: np.ndarray, crossings: int,
                   crossover: float, *, period: float | None = None, max_steps: int = 2_000_000,
                   trace: bool = True) -> Cycle | None:
    """Converge a hunting cycle as a periodic orbit (shooting on the section).

    Parameters
    ----------
    params : PlantParameters
        The plant (continuous-time controller without delay for shooting;
        otherwise the orbit of a long simulation is returned).
    level : float
        The held reference r [m]: the section is x1 - r = 0, upwards.
    state : ndarray, shape (n,)
        A state on (or near) the section on the cycle, e.g. the last section
        state of a hunting move.
    crossings : int
        Section crossings per period.
    crossover : float
        The crossover of ``params`` [Hz] (recorded in the result).
    period : float, optional
        A guess of the period [s] (bounds the runs).
    max_steps : int
        Step budget per run.
    trace : bool
        Sample one period of the converged orbit for plots.

    Returns
    -------
    Cycle or None
        None when the orbit falls to rest from every guess.
    """
    tol = ORBIT_RTOL
    scale = _scales(params, tol)
    horizon = 20.0 * period if period else 600.0
    s = np.array(state, dtype=float)
    s[0] = level
    if not _restartable(params):
        return _simulated_cycle(params, level, s, crossings, crossover, horizon, max_steps,
                                trace)
    free = _free_coordinates(params)
    residual = math.inf
    jac = None
    for _ in range(12):
        base = _return_map(params, level, s, crossings, tol, max_steps, horizon)
        if base is None:
            return None
        end = base.crossing_states[-1].copy()
        end[0] = level
        f = (end - s)[free] / scale[free]
        residual = float(np.max(np.abs(f)))
        horizon = 3.0 * float(base.crossing_times[-1]) + 1.0
        if residual < 1e-8:
            break
        jac = _map_jacobian(params, level, s, crossings, tol, max_steps, horizon, scale, free,
                            end, PERTURBATION)
        if jac is None:
            return None
        step = np.linalg.lstsq(jac - np.eye(len(free)), -f, rcond=None)[0]
        # damp the step until the map shrinks the residual
        for damping in (1.0, 0.5, 0.25, 0.125):
            trial = s.copy()
            trial[free] += damping * step * scale[free]
            again = _return_map(params, level, trial, crossings, tol, max_steps, horizon)
            if again is None:
                continue
            e2 = again.crossing_states[-1].copy()
            e2[0] = level
            r2 = float(np.max(np.abs((e2 - trial)[free] / scale[free])))
            if r2 < residual:
                s = trial
                break
        else:
            break
    final = _return_map(params, level, s, crossings, tol, max_steps, horizon)
    if final is None:
        return None
    end = final.crossing_states[-1].copy()
    end[0] = level
    residual = float(np.max(np.abs((end - s)[free] / scale[free])))
    period_out = float(final.crossing_times[-1])
    jac = _map_jacobian(params, level, s, crossings, tol, max_steps, horizon, scale, free, end,
                        PERTURBATION)
    check = _map_jacobian(params, level, s, crossings, tol, max_steps, horizon, scale, free,
                          end, 10.0 * PERTURBATION)
    mult = None if jac is None else float(np.max(np.abs(np.linalg.eigvals(jac))))
    mult_check = None if check is None else float(np.max(np.abs(np.linalg.eigvals(check))))
    if (mult is not None and mult_check is not None
            and abs(mult - mult_check) > MULTIPLIER_AGREEMENT * max(mult, mult_check)):
        # the two perturbations straddle a stick or slip event (the return map is not
        # smooth there): neither estimate is trusted
        mult = None
    return _finish_cycle(params, level, s, crossings, crossover, period_out, mult, mult_check,
                         "shooting", residual, tol, max_steps, trace)


def _free_coordinates(params: PlantParameters) -> np.ndarray:
    """State components the return map acts on: all but x1 (fixed on the section) and the
    inert ones (u without output filter, z of the switch model)."""
    idx = state_index(bool(params.isolated))
    skip = {idx["x1"]}
    if math.isinf(params.wt):
        skip.add(idx["u"])
    if params.switch_model != 0.0:
        skip.add(idx["z"])
    return np.array([j for j in range(params.n_states) if j not in skip])


def _map_jacobian(params, level, s, crossings, tol, max_steps, horizon, scale, free, end, eps):
    """Jacobian of the return map on the section (scaled coordinates), by forward differences."""
    m = len(free)
    jac = np.empty((m, m))
    for col, j in enumerate(free):
        trial = s.copy()
        trial[j] += eps * scale[j]
        out = _return_map(params, level, trial, crossings, tol, max_steps, horizon)
        if out is None:
            return None
        e2 = out.crossing_states[-1].copy()
        e2[0] = level
        jac[:, col] = ((e2 - end)[free] / scale[free]) / eps
    return jac


def _simulated_cycle(params, level, s, crossings, crossover, horizon, max_steps, trace):
    """The cycle a long run settles on (sampled or delayed controllers: no shooting)."""
    tol = 1e-7
    out = _return_map(params, level, s, crossings * 40, tol, max_steps, horizon * 40)
    if out is None:
        return None
    states = out.crossing_states
    last, before = states[-1], states[-1 - crossings]
    scale = _scales(params, tol)
    free = _free_coordinates(params)
    residual = float(np.max(np.abs((last - before)[free] / scale[free])))
    period = float(out.crossing_times[-1] - out.crossing_times[-1 - crossings])
    s = np.array(last)
    s[0] = level
    return _finish_cycle(params, level, s, crossings, crossover, period, None, None,
                         "simulation", residual, tol, max_steps, trace)


def _finish_cycle(params, level, s, crossings, crossover, period, mult, mult_check, method,
                  residual, tol, max_steps, trace) -> Cycle:
    """Sample one period from the section state: amplitude, limiter contact, the trace."""
    t_out = np.linspace(0.0, period, 2001)
    out = _return_map(params, level, s, crossings, tol, max_steps, 3.0 * period + 1.0,
                      t_out=t_out)
    Y = out.states if out is not None else np.full((len(t_out), len(s)), np.nan)
    ok = np.all(np.isfinite(Y), axis=1)
    idx = state_index(bool(params.isolated))
    err = Y[ok, idx["x1"]] - level
    amp = float(np.ptp(err)) if len(err) else math.nan
    defl = Y[ok, idx["x1"]] - Y[ok, idx["x2"]] if params.isolated else None
    on_lim = None if defl is None else bool(np.max(np.abs(defl)) >= params.s)
    stable = mult is None or mult < 1.0
    tr = None
    if trace:
        tr = CycleTrace(time=_ro(t_out[ok]), error=_ro(err), velocity=_ro(Y[ok, idx["v1"]]),
                        deflection=None if defl is None else _ro(defl),
                        cart_velocity=_ro(Y[ok, idx["v2"]]) if params.isolated else None)
    return Cycle(crossover=float(crossover), amplitude=amp, period=float(period), stable=stable,
                 multiplier=mult, multiplier_check=mult_check, method=method,
                 residual=float(residual), crossings=int(crossings), on_limiter=on_lim,
                 deflection_range=None if defl is None or not len(defl)
                 else (float(np.min(defl)), float(np.max(defl))),
                 section_state=_ro(s), trace=tr)


def _ro(a) -> np.ndarray:
    from ..results import frozen_array

    return frozen_array(a)


# --------------------------------------------------------------------------- the fold


@dataclass(frozen=True, eq=False)
class _Found:
    """A cycle a run from a nearby orbit settled on: its section state, crossings per period,
    peak-to-peak amplitude [m] (at the step ends) and period [s]."""

    state: np.ndarray | None
    crossings: int
    amplitude: float | None
    period: float | None


def cycle_exists(params: PlantParameters, level: float, guess: np.ndarray, w: Watch,
                 period: float | None = None) -> _Found | None:
    """Whether a cycle lives at ``params``, started from a nearby orbit's section state.

    The run starts on the section from ``guess`` and stops once its section
    state repeats (the cycle exists), or once it comes to rest for good (no
    cycle reached from there).

    Returns
    -------
    _Found or None
        The cycle's section state, crossings per period, amplitude and period;
        None when the run comes to rest.
    """
    s = np.array(guess, dtype=float)
    s[0] = level
    horizon = max(w.horizon, 40.0 * period) if period else w.horizon
    ref = _hold(level, horizon)
    start, offset = 0.0, 0.0
    y0 = s
    for _ in range(1000):
        out = _integrate(params, y0, ref, horizon - offset,
                         _watch_array(w, start, level, repeat=REPEAT), w.tolerance, w.max_steps)
        if out.code != 0:
            return None
        if out.stop == "quiet":
            if _rest_ends_run(params, out.final_state, level, w.band):
                return None
            if not _restartable(params):
                return _Found(None, 0, None, None)  # cannot continue exactly: not at rest yet
            offset += out.t_reached
            y0 = out.final_state.copy()
            ref = _hold(level, horizon - offset)
            continue
        n = len(out.crossing_times)
        if out.stop in ("repeat", "crossings") or n >= 4:
            q = max(1, min(out.period_crossings or _guess_period(out.crossing_states), n - 1))
            ext = out.crossing_extremes[-q:]
            return _Found(np.array(out.crossing_states[-1]), q,
                          float(np.max(ext[:, 1]) - np.min(ext[:, 0])),
                          float(out.crossing_times[-1] - out.crossing_times[-1 - q]))
        return None
    return None


def cycle_fold(model: Model, isolated: bool, cycle: Cycle, *, top: float | None = None,
               progress: Callable[[str], None] | None = None) -> dict:
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
    dict
        ``{"fold": Hz or None, "bracket": [lo, hi], "kind": "fold" | "bound",
        "tests": int, "state": section state at lo, "crossings": int}``.
    """
    top = model.spec.simulation.crossover_scan.stop if top is None else top
    lo, state, q = cycle.crossover, np.array(cycle.section_state), cycle.crossings
    period = cycle.period
    branch = [[float(lo), float(cycle.amplitude), float(cycle.period)]]
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
            branch.append([float(fc), found.amplitude, found.period])
        return True

    while True:
        hi = None
        f = lo
        while f < top:
            f = min(top, f * FOLD_STEP)
            if progress is not None:
                progress(f"following the cycle to {f:.3g} Hz")
            if not exists(f):
                hi = f
                break
        if hi is None:
            return {"fold": None, "bracket": [lo, top], "kind": "bound", "tests": tests,
                    "state": state, "crossings": q, "branch": sorted(branch)}
        while hi - lo > max(FOLD_RESOLUTION, FOLD_RELATIVE * hi):
            mid = 0.5 * (lo + hi)
            if not exists(mid):
                hi = mid
        # a test started far from the cycle may have missed it (a step or the first
        # midpoint): the upper end is tried again from the nearest cycle, and the search
        # goes on from there when the cycle is found after all
        if not exists(hi):
            return {"fold": hi, "bracket": [lo, hi], "kind": "fold", "tests": tests,
                    "state": state, "crossings": q, "branch": sorted(branch)}
