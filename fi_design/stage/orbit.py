"""The hunting cycle as a periodic orbit: the return map, shooting, the Floquet multiplier.

Step 2 of the stage-level answer (:mod:`fi_design.stage`):
:func:`converge_cycle` converges the orbit a hunting move repeated by
Newton's method on the return map of the Poincare section (x1 - r = 0,
upwards), with its Floquet multiplier from the map's Jacobian;
:func:`cycle_exists` tells whether a cycle lives at a plant, started from a
nearby orbit (what the fold search in :mod:`.boundary` asks at each step).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..kernel.layout import W_ARM, PlantParameters, state_index
from ..results import frozen_array
from ..results.stage import Cycle, CycleTrace
from ..simulation.run import tolerances
from .family import hold
from .rest import rest_ends_run
from .runs import continued_state, guess_period, kernel_run, watch_array
from .settings import MULTIPLIER_AGREEMENT, ORBIT_RTOL, PERTURBATION, REPEAT, Watch, restartable

__all__ = ["converge_cycle", "FoundCycle", "cycle_exists"]

#: Periods a sampled or delayed loop's cycle is run before its repeat is looked for.
SETTLE_PERIODS = 5


def _return_map(params, level, state, crossings, tol, max_steps, horizon, t_out=None,
                repeat=0.0):
    """Run from a section state to the ``crossings``-th crossing; None if it comes to rest.

    With ``repeat`` > 0 the run may stop earlier, once its section state repeats
    (the kernel's repeat rule)."""
    w = Watch(band=0.0, quiet=math.inf, horizon=horizon, rest_anywhere=False, tolerance=tol,
              max_steps=max_steps)
    arm = max(1e-9, 1e-6 * max(abs(level), 1e-3))
    arr = watch_array(w, 0.0, level, repeat=repeat, quiet=False, max_crossings=crossings)
    arr[W_ARM] = arm
    out = kernel_run(params, state, hold(level, horizon), horizon, arr, tol, max_steps,
                     crossings=crossings, t_out=t_out, h_max=math.inf)
    if out.code != 0 or (len(out.crossing_times) < crossings and out.stop != "repeat"):
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
    if not restartable(params):
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
    """The cycle a long run settles on (sampled or delayed controllers: no shooting).

    The run goes on until its section state repeats (within :data:`REPEAT`, or a
    sampled loop's scatter of where its samples fall) after at least
    :data:`SETTLE_PERIODS` periods, at most 40."""
    tol = 1e-7
    start = _return_map(params, level, s, crossings * SETTLE_PERIODS, tol, max_steps,
                        horizon * SETTLE_PERIODS)
    if start is None:
        return None
    out = _return_map(params, level, start.crossing_states[-1], crossings * 40, tol, max_steps,
                      horizon * 40, repeat=REPEAT)
    if out is None or len(out.crossing_times) < 2:
        return None
    if out.stop == "repeat":
        crossings = out.period_crossings
    states = out.crossing_states
    crossings = min(crossings, len(states) - 1)
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
    Y = out.states if out is not None else np.full((len(t_out), params.n_states), np.nan)
    ok = np.all(np.isfinite(Y), axis=1)
    idx = state_index(bool(params.isolated))
    err = Y[ok, idx["x1"]] - level
    amp = float(np.ptp(err)) if len(err) else math.nan
    defl = Y[ok, idx["x1"]] - Y[ok, idx["x2"]] if params.isolated else None
    on_lim = None if defl is None else bool(np.max(np.abs(defl)) >= params.s)
    stable = mult is None or mult < 1.0
    tr = None
    if trace:
        tr = CycleTrace(time=frozen_array(t_out[ok]), error=frozen_array(err),
                        velocity=frozen_array(Y[ok, idx["v1"]]),
                        deflection=None if defl is None else frozen_array(defl),
                        cart_velocity=frozen_array(Y[ok, idx["v2"]]) if params.isolated else None)
    return Cycle(crossover=float(crossover), amplitude=amp, period=float(period), stable=stable,
                 multiplier=mult, multiplier_check=mult_check, method=method,
                 residual=float(residual), crossings=int(crossings), on_limiter=on_lim,
                 deflection_range=None if defl is None or not len(defl)
                 else (float(np.min(defl)), float(np.max(defl))),
                 section_state=frozen_array(s), trace=tr)


# --------------------------------------------------------------------------- existence


@dataclass(frozen=True, eq=False)
class FoundCycle:
    """A cycle a run from a nearby orbit settled on.

    Attributes
    ----------
    state : ndarray, shape (n,) or None
        Its last section state (SI); None when the run could not be continued
        exactly to the cycle (a sampled or delayed controller, not at rest yet).
    crossings : int
        Section crossings per period.
    amplitude : float or None
        Peak-to-peak x1 - r over one period [m] (at the step ends).
    period : float or None
        Period [s].
    """

    state: np.ndarray | None
    crossings: int
    amplitude: float | None
    period: float | None


def cycle_exists(params: PlantParameters, level: float, guess: np.ndarray, w: Watch,
                 period: float | None = None) -> FoundCycle | None:
    """Whether a cycle lives at ``params``, started from a nearby orbit's section state.

    The run starts on the section from ``guess`` and stops once its section
    state repeats (the cycle exists), or once it comes to rest for good (no
    cycle reached from there).

    Parameters
    ----------
    params : PlantParameters
        The plant.
    level : float
        The held reference r [m].
    guess : ndarray, shape (n,)
        The nearby orbit's section state (SI).
    w : Watch
        How the run is judged.
    period : float, optional
        The nearby orbit's period [s] (lengthens the horizon to 40 periods).

    Returns
    -------
    FoundCycle or None
        The cycle's section state, crossings per period, amplitude and period;
        None when the run comes to rest.
    """
    s = np.array(guess, dtype=float)
    s[0] = level
    horizon = max(w.horizon, 40.0 * period) if period else w.horizon
    ref = hold(level, horizon)
    start, offset = 0.0, 0.0
    y0 = s
    for _ in range(1000):
        out = kernel_run(params, y0, ref, horizon - offset,
                         watch_array(w, start, level, repeat=REPEAT), w.tolerance, w.max_steps)
        if out.code != 0:
            return None
        if out.stop == "quiet":
            if rest_ends_run(params, out.final_state, level, w.band):
                return None
            go_on = continued_state(params, out)
            if go_on is None:
                return FoundCycle(None, 0, None, None)  # cannot continue exactly: not at rest yet
            offset += out.t_reached
            if offset >= horizon:  # quiet to the end of the horizon: no cycle repeated in it
                return None
            y0 = go_on
            ref = hold(level, horizon - offset)
            continue
        n = len(out.crossing_times)
        if out.stop in ("repeat", "crossings") or n >= 4:
            q = max(1, min(out.period_crossings or guess_period(out.crossing_states), n - 1))
            ext = out.crossing_extremes[-q:]
            return FoundCycle(np.array(out.crossing_states[-1]), q,
                          float(np.max(ext[:, 1]) - np.min(ext[:, 0])),
                          float(out.crossing_times[-1] - out.crossing_times[-1 - q]))
        return None
    return None
