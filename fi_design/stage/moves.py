"""One move of the family, from rest to an answer: the watch, the family, the rest test.

Step 1 of the stage-level answer (:mod:`fi_design.stage`): the kernel's
watch settings, the family of move distances, when rest is final, and
:func:`move_outcome`, which runs one move until the stage rests for good
or its state at the Poincare section repeats.
"""

from __future__ import annotations

import functools
import logging
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .. import spec as _spec
from ..kernel import run
from ..kernel.build import compiled
from ..kernel.layout import (N_WATCH, W_ARM, W_BAND, W_LEVEL, W_MATCH, W_MAX_CROSSINGS,
                             W_QUIET, W_REPEAT, W_REST_ANYWHERE, W_START, PlantParameters,
                             state_index)
from ..model import Model, as_model
from ..results.stage import MoveOutcome, length_text
from ..simulation.run import tolerances
from ..trajectory import Trajectory, from_moves, profile_duration

log = logging.getLogger(__name__)


#: Room for section crossings per run (the crossings rule stops a run there).
CROSSINGS = 400
#: Repeat tolerance of the family runs: the section state repeats within this
#: fraction of the physical scales (1 mm, 1 cm/s, Fs / sigma0, Fs) [-].
REPEAT = 1e-3
#: Match tolerance of the family runs: a move whose section state comes within this
#: fraction of the physical scales of a cycle an earlier move of the same plant repeated
#: has entered that cycle (an attracting cycle draws it in, by the cycle's multiplier,
#: about 0.5, at every crossing; the repeat rule needs about five crossings more) [-].
MATCH = 1e-2
#: Relative tolerance of the orbit computations (shooting, multipliers) [-].
ORBIT_RTOL = 1e-9
#: Finite-difference perturbation of the return map, in physical scales [-].
PERTURBATION = 1e-6
#: The Floquet multiplier at PERTURBATION and at ten times it must agree this closely, or
#: the multiplier is not reported (relative to the larger) [-].
MULTIPLIER_AGREEMENT = 0.1
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


def _translation_invariant(p: PlantParameters) -> bool:
    """Whether the plant's forces do not depend on where the stage is (a cycle about one
    target is the same cycle about another, shifted): no position-dependent friction, force
    ripple, cable spring or quantization."""
    return (p.pdf_amplitude == 0.0 and p.ripple_amplitude == 0.0 and p.cable_stiffness == 0.0
            and p.quantization == 0.0)


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
    """What one watched run of a move left: its outcome and the cycle's section state.

    ``cycle_states`` (hunting runs): the section states of one period of the cycle, shape
    (crossings, n), positions relative to ``level`` (what the match rule compares).
    """

    outcome: MoveOutcome
    section_state: np.ndarray | None
    crossings: int
    level: float
    cycle_states: np.ndarray | None = None


def _relative(params: PlantParameters, states: np.ndarray, level: float) -> np.ndarray:
    """Section states with the positions (x1, and x2 of the isolated plant) less ``level``."""
    out = np.array(states, dtype=float, ndmin=2)
    idx = state_index(bool(params.isolated))
    out[:, idx["x1"]] -= level
    if params.isolated:
        out[:, idx["x2"]] -= level
    return out


def _watch_array(w: Watch, start: float, level: float, *, repeat: float = REPEAT,
                 quiet: bool = True, max_crossings: int = CROSSINGS,
                 known: np.ndarray | None = None, match: float | None = None) -> np.ndarray:
    """The kernel's watch array; ``known`` (k, n) section states (positions relative to
    their level) for the match rule, within ``match`` (default :data:`MATCH`)."""
    k = 0 if known is None else len(known)
    arr = np.zeros(N_WATCH + (0 if k == 0 else known.size))
    if k:
        arr[W_MATCH] = MATCH if match is None else match
        arr[N_WATCH:] = np.ravel(known)
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
                 distance: float, label: str = "family", repeat: float = REPEAT,
                 known: Sequence[_Run] = ()) -> _Run:
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
    known : sequence of _Run
        Hunting runs of earlier moves of the same plant: once the section
        state comes within :data:`MATCH` of one of their cycles, the move has
        entered that cycle and the run stops there; its outcome takes that
        cycle's amplitude and period (for a plant whose state vector is whole
        and whose forces do not depend on where the stage is; otherwise the
        run goes on until its own motion repeats).

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
    known = [r for r in known if r.cycle_states is not None] \
        if restart and _translation_invariant(params) else []
    table = np.concatenate([r.cycle_states for r in known]) if known else None
    owner = [r for r in known for _ in range(len(r.cycle_states))]
    start, offset, elapsed = move_end, 0.0, 0.0
    cur_ref, cur_y0, cur_end = ref, y0, t_end
    rested_at = None  # when the stage last came to rest inside the band, not for good [s]
    while True:
        out = _integrate(params, cur_y0, cur_ref, cur_end,
                         _watch_array(w, start, level, repeat=repeat, known=table), w.tolerance,
                         w.max_steps)
        elapsed = offset + out.t_reached - move_end
        y = out.final_state
        if out.code != 0:
            return _Run(MoveOutcome(distance, label, "undetermined", float(y[0] - level), None,
                                    None, elapsed, f"the simulation failed: {out.status}",
                                    failed=True), None, 0, level)
        if out.stop == "quiet" and not _rest_ends_run(params, y, level, w.band):
            # the integrator will break the cart loose again: keep going
            rested_at = offset + out.t_reached if abs(y[0] - level) <= w.band else None
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
    if out.stop == "match":
        seen = owner[out.period_crossings]
        m = seen.outcome
        why = (f"a sustained cycle: {m.amplitude * 1e3:.3g} mm peak to peak"
               + (f", period {m.period:.3g} s" if m.period else "")
               + f" (enters the cycle of the {length_text(abs(m.distance))} move)")
        return _Run(MoveOutcome(distance, label, "hunts", float(out.crossing_states[-1][0]
                                                                  - level),
                                m.amplitude, m.period, elapsed, why),
                    seen.section_state, seen.crossings, seen.level, seen.cycle_states)
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
                    np.array(out.crossing_states[-1]), q, level,
                    _relative(params, out.crossing_states[-q:], level)
                    if out.stop == "repeat" else None)
    if (rested_at is not None and out.stop == "end" and n == 0 and abs(e) <= w.band
            and t_end - rested_at <= w.quiet):
        # at rest inside the band, and still inside it at the horizon, too soon after for
        # another quiet time and without a crossing: the cart creeps with its force at the
        # static friction (not at rest for good by the static balance, but nothing breaks
        # it loose within the horizon)
        why = (f"within the band for the rest of the {w.horizon:.3g} s horizon, "
               f"{length_text(abs(e))} from the target; the cart creeps at its static friction")
        return _Run(MoveOutcome(distance, label, "settles", e, None, None, elapsed, why), None,
                    0, level)
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
