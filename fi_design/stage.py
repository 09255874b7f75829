"""Hunting as a property of the stage: every move of a family, the cycle itself, the boundary.

A PID loop around a mass with stick-slip friction is bistable: beside the
rest set (the cart stuck, the stage at its target, the friction force below
the static friction) lives a stable limit cycle, and which of the two a run
ends in depends on where the cart first sticks after the move. One simulated
move therefore says little about the stage. This module answers per plant:

1. *Which moves end in a cycle* (:func:`move_outcome`): a family of moves
   (``motion.family``, and always the spec's own motion), each simulated from
   rest with the kernel's watch switched on once the motion is over. The run
   stops as soon as the answer is certain: the stage has rested within the
   settle band for a few integrator time constants *and* the friction force
   the loop will ask of the resting cart stays below its static friction
   (:func:`rest_is_final`; otherwise the integrator would break it loose
   again and the run goes on), or its state at the Poincare section
   (x1 - r = 0 crossed upwards) repeats (a sustained cycle). A slow settling
   is never taken for a cycle, nor a long stick phase for rest.
2. *The cycle itself* (:func:`converge_cycle`): Newton's method on the
   return map of the section, from the state the hunting move repeated,
   with the Jacobian by finite differences (its eigenvalues are the Floquet
   multipliers, checked at two perturbation sizes); amplitude and period
   from one period of the converged orbit.
3. *The hunting-free crossover* (:func:`cycle_fold`): the crossover above
   which the cycle no longer exists, by bisection on its existence, each
   test started from the orbit at the nearest crossover where it still
   exists (continuation); the family is then run just above to make sure no
   other cycle is entered there.

The kernel's watch (:func:`fi_design.kernel.integrator.integrate`) locates the section
crossings like mode events (the step is redone to end on them, never
interpolated), and a continuous-time controller without delay keeps its
whole state in the state vector, so a run can continue exactly from where
another stopped. A sampled or delayed controller holds state outside it:
such runs are repeated from the start rather than continued, and their
cycle is the one a long simulation settles on.
"""

from __future__ import annotations

import functools
import logging
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from . import spec as _spec
from .errors import ArgumentError
from .kernel import run
from .kernel.build import compiled
from .kernel.layout import (N_WATCH, W_ARM, W_BAND, W_LEVEL, W_MAX_CROSSINGS, W_QUIET,
                            W_REPEAT, W_REST_ANYWHERE, W_START, PlantParameters, state_index)
from .results.stage import Cycle, CycleTrace, MoveOutcome, StageHunting, length_text
from .model import Model, as_model
from .simulation import tolerances
from .trajectory import Trajectory, from_moves, profile_duration

log = logging.getLogger(__name__)

__all__ = ["Watch", "watch_settings", "family_distances", "rest_is_final", "move_outcome",
           "converge_cycle", "cycle_exists", "cycle_fold", "stage_hunting", "stage_hunts"]

#: Room for section crossings per run (the crossings rule stops a run there).
CROSSINGS = 400
#: Repeat tolerance of the family runs: the section state repeats within this
#: fraction of the physical scales (1 mm, 1 cm/s, Fs / sigma0, Fs) [-].
REPEAT = 1e-3
#: Relative tolerance of the orbit computations (shooting, multipliers) [-].
ORBIT_RTOL = 1e-9
#: Finite-difference perturbation of the return map, in physical scales [-].
PERTURBATION = 1e-6
#: Bisection of the fold: stop when the bracket is this narrow [Hz] ...
FOLD_RESOLUTION = 0.01
#: ... or this narrow relative to the crossover [-].
FOLD_RELATIVE = 1e-3
#: Step of the search for a crossover on the other side of the fold [-].
FOLD_STEP = 1.25
#: Largest step between the kernel's outputs and the h_max of the family runs [s].
H_MAX = 0.05


# --------------------------------------------------------------------------- settings


@dataclass(frozen=True)
class Watch:
    """How the runs of one plant are judged (all SI).

    Attributes
    ----------
    band : float
        Settle band on x1 - r [m] (``requirements.hunting.settle_band``).
    quiet : float
        Time the stage must rest within the band before the rest is judged
        [s]: ten integrator time constants kp / ki, at least 1 s.
    horizon : float
        Longest time after the motion [s] (``requirements.hunting.horizon``).
    rest_anywhere : bool
        A rest off the target ends a run too: a loop without integrator rests
        wherever friction holds it (its static error), and a saturated drive
        may not push harder than its force limit (stuck for good); an
        integrating loop with force to spare goes on.
    tolerance : float
        Relative tolerance of the family runs [-] (``simulation.tolerance``).
    max_steps : int
        Step budget per run (``simulation.max_steps``).
    """

    band: float
    quiet: float
    horizon: float
    rest_anywhere: bool
    tolerance: float
    max_steps: int


def watch_settings(model: Model, params: PlantParameters) -> Watch:
    """The :class:`Watch` of a model's plant.

    Parameters
    ----------
    model : Model
        The resolved model (its spec's hunting settings, tolerance, step budget).
    params : PlantParameters
        The plant (its controller's gains).
    """
    spec = model.spec
    h = spec.requirements.hunting
    integrates = _integrates(params)
    if integrates:
        ki, kp = _gains(params)
        quiet = max(1.0, 10.0 * kp / ki) if kp > 0 else 1.0
    else:
        quiet = 1.0
    return Watch(band=h.settle_band, quiet=quiet, horizon=h.horizon,
                 rest_anywhere=not integrates or math.isfinite(params.force_limit),
                 tolerance=spec.simulation.tolerance, max_steps=spec.simulation.max_steps)


def _gains(p: PlantParameters) -> tuple[float, float]:
    """Integral and proportional gain [N/(m s), N/m] of the continuous or sampled law."""
    if p.sample_period > 0.0:
        # trapezoidal integrator: dc = ki Ts / 2; dp = kp - dc
        ki = 2.0 * p.dc / p.sample_period
        return ki, p.dp + p.dc
    return p.ki, p.kp


def _integrates(p: PlantParameters) -> bool:
    return (p.dc if p.sample_period > 0.0 else p.ki) > 0.0


def _restartable(p: PlantParameters) -> bool:
    """Whether the state vector holds the whole state (a continuous controller without delay)."""
    return p.sample_period == 0.0 and p.delay == 0.0


def _symmetric(p: PlantParameters) -> bool:
    """Whether a move and its mirror image behave alike (friction and loads odd in x)."""
    return (p.value("Fc_neg") == p.Fc and p.value("sigma2_neg") == p.sigma2
            and p.offset == 0.0 and p.cable_preload == 0.0 and p.cable_stiffness == 0.0
            and p.ripple_amplitude == 0.0 and p.pdf_amplitude == 0.0
            and p.ff_coulomb == 0.0)


# --------------------------------------------------------------------------- the family


def _largest_move(spec: _spec.Spec) -> _spec.Move:
    return max(spec.motion.moves, key=lambda mv: abs(mv.distance))


def family_distances(model: Model | _spec.Spec, isolated: bool,
                     params: PlantParameters | None = None) -> tuple[float, ...]:
    """Signed distances of the move family of one plant [m].

    Parameters
    ----------
    model : Model or Spec
        The resolved model (its spec's ``motion.family``; a spec is resolved).
    isolated : bool
        Which plant: the default smallest distance is a tenth of the stroke
        with the isolator, 0.1 mm without.
    params : PlantParameters, optional
        The plant, to tell whether it is symmetric (``directions: auto``).

    Returns
    -------
    tuple of float
        Positive distances first, increasing, then the negative ones.
    """
    model = as_model(model)
    spec = model.spec
    fam = spec.motion.family
    if fam.distances is not None:
        return tuple(float(d) for d in fam.distances)
    if fam.smallest is not None:
        lo = fam.smallest
    elif isolated and model.joint is not None:
        lo = 0.1 * model.joint.stroke
    else:
        lo = 1e-4
    hi = fam.largest if fam.largest is not None else 5.0 * abs(_largest_move(spec).distance)
    hi = max(hi, lo * 1.0001)
    base = tuple(float(d) for d in np.geomspace(lo, hi, fam.count))
    both = fam.directions == "both" or (
        fam.directions == "auto" and params is not None and not _symmetric(params))
    return base + tuple(-d for d in base) if both else base


def _family_reference(spec: _spec.Spec, distance: float, horizon: float) \
        -> tuple[Trajectory, float]:
    """One move of the family from rest, held for ``horizon``; and the move's end [s]."""
    mv = _largest_move(spec)
    move = _spec.Move(distance=distance, velocity=mv.velocity, acceleration=mv.acceleration,
                      jerk=mv.jerk)
    end = profile_duration(distance, mv.velocity, mv.acceleration, mv.jerk)
    return from_moves((move,), end + horizon), end


def _spec_reference(spec: _spec.Spec, horizon: float) -> tuple[Trajectory, float]:
    end = spec.motion.end_time
    return from_moves(spec.motion.moves, end + horizon), end


def _hold(level: float, duration: float) -> Trajectory:
    """The reference held at ``level`` [m] for ``duration`` [s] (no landing)."""
    return Trajectory(np.array([0.0, duration]), np.array([[level, 0.0, 0.0, 0.0]]), land=False)


# --------------------------------------------------------------------------- rest


def _joint_force(p: PlantParameters, d: float) -> float:
    """Static force of the joint at deflection ``d`` [m]: spring and limiter contact [N]."""
    f = p.k * d
    if d > p.s:
        f += p.k_stop * (d - p.s)
    elif d < -p.s:
        f += p.k_stop * (d + p.s)
    return f


def rest_is_final(params: PlantParameters, y: np.ndarray, level: float) -> bool:
    """Whether a stage resting near its target stays at rest for good.

    At rest the integrator drives x1 to the target r; the cart, stuck, then
    carries a friction force set by where it stuck, and stays stuck only if
    that force stays below its static friction. With LuGre friction the stuck
    cart moves only by presliding, dz = dx: without isolator the bristle
    force at the target is sigma0 (z + r - x1); with the isolator the joint
    force at the target deflection balances the bristles,
    sigma0 (z + D) = k (r - x2 - D) + F_stop, solved for the presliding
    displacement D. With the switch model the cart cannot move at all: a
    stage without isolator rests for good only exactly on target. A loop
    without integrator asks nothing more of friction than it does now.

    Parameters
    ----------
    params : PlantParameters
        The plant.
    y : ndarray, shape (n,)
        The resting state.
    level : float
        The held reference r [m].

    Returns
    -------
    bool
        True when the predicted force stays below the static friction (of
        its direction, at the cart's position).
    """
    p = params
    if not _integrates(p):
        return True
    idx = state_index(bool(p.isolated))
    x1, z = float(y[idx["x1"]]), float(y[idx["z"]])
    switch = p.switch_model != 0.0
    if p.isolated:
        x2 = float(y[idx["x2"]])
        d0 = level - x2
        if switch:
            shift = 0.0
        else:
            def gap(dd: float) -> float:
                return p.sigma0 * (z + dd) - _joint_force(p, d0 - dd)

            span = abs(d0) + abs(z) + p.s + 1e-6
            from scipy.optimize import brentq

            shift = brentq(gap, -span, span, xtol=1e-15, rtol=1e-12)
        force = _joint_force(p, d0 - shift)
        x_cart = x2 + shift
    else:
        if switch:
            return abs(level - x1) <= 1e-12 * max(1.0, abs(level))
        force = p.sigma0 * (z + level - x1)
        x_cart = level
    sign = 1.0 if force >= 0.0 else -1.0
    g0 = compiled().stribeck(0.0, x_cart, sign, _kernel_arrays(p, 1.0)[0])[0]
    return abs(force) < g0


def _rest_ends_run(params: PlantParameters, y: np.ndarray, level: float, band: float) -> bool:
    """Whether a quiet stop ends the run: at the target for good (:func:`rest_is_final`), or
    off it with nothing left to move it (no integrator, or a drive at its force limit)."""
    if abs(y[0] - level) <= band:
        return rest_is_final(params, y, level)
    if not _integrates(params):
        return True
    iu = state_index(bool(params.isolated))["u"]
    return abs(y[iu]) >= params.force_limit * (1.0 - 1e-9)


# --------------------------------------------------------------------------- one move


@dataclass(frozen=True, eq=False)
class _Run:
    """What one watched run of a move left: its outcome and the cycle's section state."""

    outcome: MoveOutcome
    section_state: np.ndarray | None
    crossings: int
    level: float


def _watch_array(w: Watch, start: float, level: float, *, repeat: float = REPEAT,
                 quiet: bool = True, max_crossings: int = CROSSINGS) -> np.ndarray:
    arr = np.zeros(N_WATCH)
    arr[W_START] = start
    arr[W_LEVEL] = level
    arr[W_BAND] = w.band
    arr[W_QUIET] = w.quiet if quiet else math.inf
    arr[W_REPEAT] = repeat
    arr[W_MAX_CROSSINGS] = max_crossings
    arr[W_REST_ANYWHERE] = 1.0 if w.rest_anywhere else 0.0
    arr[W_ARM] = w.band
    return arr


def _x_bound(ref: Trajectory, y0: np.ndarray) -> float:
    return 1.0 + 100.0 * float(np.max(np.abs(ref.coeffs[:, 0])) + abs(y0[0]))


@functools.lru_cache(maxsize=64)
def _kernel_arrays(params: PlantParameters, tol: float) -> tuple[np.ndarray, np.ndarray]:
    """The kernel's parameter array and absolute tolerances of a plant (made once per plant)."""
    return params.to_array(), tolerances(params, tol)


def _integrate(params, y0, ref, t_end, watch, tol, max_steps, crossings=CROSSINGS,
               t_out=None, h_max=H_MAX):
    p, atol = _kernel_arrays(params, tol)
    return run(p, y0, ref.breaks, ref.coeffs, ref.land, t_end,
               np.zeros(0) if t_out is None else t_out, tol, atol, h_max,
               max_steps, _x_bound(ref, y0), watch=watch, crossings=crossings)


def move_outcome(params: PlantParameters, ref: Trajectory, move_end: float, w: Watch, *,
                 distance: float, label: str = "family", repeat: float = REPEAT) -> _Run:
    """Simulate one move from rest and judge how the stage ends.

    Parameters
    ----------
    params : PlantParameters
        The plant.
    ref : Trajectory
        The move, held at its end position until ``move_end + w.horizon``.
    move_end : float
        When the motion is over [s]; the watch starts there.
    w : Watch
        Settle band, quiet time, horizon.
    distance : float
        The move's signed distance [m] (for the outcome).
    label : str
        ``"family"`` or ``"spec"``.
    repeat : float
        Repeat tolerance of the section state [-].

    Returns
    -------
    _Run
        The :class:`~fi_design.results.stage.MoveOutcome` and, for a cycle,
        the last section state and the crossings per period.
    """
    level = ref.final
    y0 = np.zeros(params.n_states)
    t_end = move_end + w.horizon
    restart = _restartable(params)
    start, offset, elapsed = move_end, 0.0, 0.0
    cur_ref, cur_y0, cur_end = ref, y0, t_end
    while True:
        out = _integrate(params, cur_y0, cur_ref, cur_end,
                         _watch_array(w, start, level, repeat=repeat), w.tolerance, w.max_steps)
        elapsed = offset + out.t_reached - move_end
        y = out.final_state
        if out.code != 0:
            return _Run(MoveOutcome(distance, label, "undetermined", float(y[0] - level), None,
                                    None, elapsed, f"the simulation failed: {out.status}",
                                    failed=True), None, 0, level)
        if out.stop == "quiet" and not _rest_ends_run(params, y, level, w.band):
            # the integrator will break the cart loose again: keep going
            if offset + out.t_reached >= t_end * (1 - 1e-12):
                break
            if restart:
                offset += out.t_reached
                cur_y0, cur_ref = y.copy(), _hold(level, t_end - offset)
                cur_end, start = t_end - offset, 0.0
            else:
                start = out.t_reached + 1e-9
            continue
        break
    e = float(y[0] - level)
    n = len(out.crossing_times)
    if out.stop == "quiet":
        if abs(e) <= w.band:
            word, why = "settles", f"at rest {length_text(abs(e))} from the target for good"
        elif _integrates(params):
            word, why = "stuck", (f"at rest {length_text(abs(e))} from the target with the drive "
                                  f"at its {params.force_limit:.3g} N force limit")
        else:
            word, why = "rests", (f"at rest {length_text(abs(e))} from the target (no "
                                  "integrator to pull it in)")
        return _Run(MoveOutcome(distance, label, word, e, None, None, elapsed, why), None, 0,
                    level)
    if out.stop in ("repeat", "crossings") or (out.stop == "end" and n >= 4):
        q = out.period_crossings if out.stop == "repeat" else _guess_period(out.crossing_states)
        q = max(1, min(q, n - 1)) if n > 1 else 1
        period = float(out.crossing_times[-1] - out.crossing_times[-1 - q]) if n > q else None
        ext = out.crossing_extremes[-q:]
        amp = float(np.max(ext[:, 1]) - np.min(ext[:, 0])) if len(ext) else None
        how = {"repeat": "repeats at the section", "crossings": "keeps crossing the target",
               "end": "keeps crossing the target"}[out.stop]
        why = (f"a sustained cycle: {amp * 1e3:.3g} mm peak to peak"
               + (f", period {period:.3g} s" if period else "") + f" ({how})")
        return _Run(MoveOutcome(distance, label, "hunts", float(out.crossing_states[-1][0]
                                                                  - level),
                                amp, period, elapsed, why),
                    np.array(out.crossing_states[-1]), q, level)
    if abs(e) > w.band:
        word = "stuck" if _integrates(params) else "rests"
        why = (f"{length_text(abs(e))} from the target after {elapsed:.3g} s, neither at rest "
               "there for good nor cycling")
        return _Run(MoveOutcome(distance, label, word, e, None, None, elapsed, why), None, 0,
                    level)
    return _Run(MoveOutcome(distance, label, "undetermined", e, None, None, elapsed,
                            f"neither at rest for good nor in a cycle after {elapsed:.3g} s "
                            "(raise requirements.hunting.horizon)"), None, 0, level)


def _guess_period(states: np.ndarray, max_period: int = 4) -> int:
    """Crossings per period of a cycle that has not repeated within tolerance yet."""
    n = len(states)
    if n < 3:
        return 1
    best, score = 1, math.inf
    scale = np.maximum(np.ptp(states, axis=0), 1e-300)
    for q in range(1, min(max_period, n - 1) + 1):
        s = float(np.max(np.abs(states[-1] - states[-1 - q]) / scale))
        if s < score - 1e-12:
            best, score = q, s
    return best


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
    from .results import frozen_array

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
    for dist, label, ref, end in _moves(model, isolated, p, w.horizon, family):
        r = move_outcome(p, ref, end, w, distance=dist, label=label)
        runs.append(r)
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
