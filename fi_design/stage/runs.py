"""One move of the family, from rest to its answer: the kernel's watched runs.

:func:`move_outcome` runs one move until the stage rests for good
(:func:`fi_design.stage.rest.rest_is_final`) or its state at the Poincare
section (x1 - r = 0 crossed upwards) repeats, and says how the move ended
(:class:`MoveRun`). :func:`kernel_run` and :func:`watch_array` are the one
way the stage's modules call the kernel with its watch switched on.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from ..display import quantity
from ..kernel import run
from ..kernel.layout import (N_WATCH, W_ARM, W_BAND, W_LEVEL, W_MATCH, W_MAX_CROSSINGS,
                             W_QUIET, W_REPEAT, W_REST_ANYWHERE, W_START, Integration,
                             PlantParameters, state_index)
from ..results.stage import MoveOutcome, length_text
from ..simulation.run import tolerances
from ..trajectory import Trajectory
from .family import hold
from .rest import rest_ends_run
from .settings import (CROSSINGS, H_MAX, MATCH, MATCH_CAP, MATCH_SHARE, REPEAT, Watch, integrates,
                       kernel_arrays, restartable, translation_invariant)

__all__ = ["MoveRun", "watch_array", "kernel_run", "match_tolerance", "move_outcome", "guess_period"]


@dataclass(frozen=True, eq=False)
class MoveRun:
    """What one watched run of a move left: its outcome and the cycle's section state.

    Attributes
    ----------
    outcome : MoveOutcome
        How the move ended.
    section_state : ndarray, shape (n,) or None
        For a cycle, the last state at the section (SI); None otherwise.
    crossings : int
        Section crossings per period of the cycle (0 without one).
    level : float
        The held reference r of the move [m].
    cycle_states : ndarray, shape (crossings, n) or None
        Hunting runs that repeated: the section states of one period of the
        cycle, positions relative to ``level`` (what the match rule compares).
    """

    outcome: MoveOutcome
    section_state: np.ndarray | None
    crossings: int
    level: float
    cycle_states: np.ndarray | None = None


def _relative(params: PlantParameters, states: np.ndarray, level: float) -> np.ndarray:
    """Section states with the positions (x1, and x2 of the isolated plant) less ``level``."""
    out = np.array(states, dtype=float, ndmin=2)[:, :params.n_states]
    idx = state_index(bool(params.isolated))
    out[:, idx["x1"]] -= level
    if params.isolated:
        out[:, idx["x2"]] -= level
    return out


def watch_array(w: Watch, start: float, level: float, *, repeat: float = REPEAT,
                quiet: bool = True, max_crossings: int = CROSSINGS,
                known: np.ndarray | None = None, match: float | None = None) -> np.ndarray:
    """The kernel's watch array: when and how a run is stopped.

    Parameters
    ----------
    w : Watch
        Settle band, quiet time and whether a rest off the target ends a run.
    start : float
        When the watch starts [s] (the end of the motion).
    level : float
        The held reference r [m]: the section is x1 - r = 0, upwards.
    repeat : float
        Repeat tolerance of the section state, in physical scales [-].
    quiet : bool
        Whether a quiet stop (at rest for the quiet time) ends the run.
    max_crossings : int
        Section crossings after which the run stops.
    known : ndarray, shape (k, n), optional
        Section states of known cycles (positions relative to their level) for
        the match rule.
    match : float, optional
        Match tolerance [-] (default :data:`~fi_design.stage.settings.MATCH`).

    Returns
    -------
    ndarray
        The array :func:`fi_design.kernel.run` takes as ``watch``.
    """
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


def kernel_run(params: PlantParameters, y0: np.ndarray, ref: Trajectory, t_end: float,
               watch: np.ndarray, tol: float, max_steps: int, crossings: int = CROSSINGS,
               t_out: np.ndarray | None = None, h_max: float = H_MAX) -> Integration:
    """One watched run of the compiled kernel from ``y0`` along ``ref``.

    Parameters
    ----------
    params : PlantParameters
        The plant.
    y0 : ndarray, shape (n,)
        Initial state (SI).
    ref : Trajectory
        The reference [m].
    t_end : float
        Last time [s].
    watch : ndarray
        From :func:`watch_array`.
    tol : float
        Relative tolerance [-].
    max_steps : int
        Step budget.
    crossings : int
        Room for section crossings.
    t_out : ndarray, optional
        Output times [s]; none by default.
    h_max : float
        Largest step [s].

    Returns
    -------
    fi_design.kernel.layout.Integration
        What :func:`fi_design.kernel.run` returns (stop reason, final state,
        section crossings, sampled states).
    """
    n = params.n_states
    if len(y0) > n:  # a sampled loop's section state: its controller's states follow
        params = resumed(params, y0)
        y0 = np.asarray(y0[:n], dtype=float)
    p, atol = kernel_arrays(params, tol)
    out = run(p, y0, ref.breaks, ref.coeffs, ref.land, t_end,
              np.zeros(0) if t_out is None else t_out, tol, atol, h_max,
              max_steps, _x_bound(ref, y0), watch=watch, crossings=crossings)
    if params.sample_period > 0.0:
        out = replace(out, crossing_states=np.hstack([out.crossing_states,
                                                      out.crossing_controller]))
    return out


def resumed(params: PlantParameters, state: np.ndarray) -> PlantParameters:
    """A sampled loop's plant, its discrete controller set to a section state's.

    A section state of a sampled loop (:func:`kernel_run`'s crossing states)
    holds the plant's states followed by the controller's ``dx2`` and held
    output [N] (its ``dx1`` is the state ``I``). A run from it takes its first
    sample at once: the motion goes on from the crossing with the controller's
    memory intact, its sample instants shifted by less than a sample period
    (and a delayed output still pending at the crossing skipped): the cycle of a
    sampled loop is continued from the section to within that shift.

    Parameters
    ----------
    params : PlantParameters
        The plant (a discrete controller).
    state : ndarray, shape (n + 2,)
        The section state.

    Returns
    -------
    PlantParameters
        ``params`` with ``dx1``, ``dx2`` and ``u_initial`` from ``state``.
    """
    n = params.n_states
    ii = state_index(bool(params.isolated))["I"]
    return replace(params, dx1=float(state[ii]), dx2=float(state[n]),
                   u_initial=float(state[n + 1]))


def resumes_sampled(params: PlantParameters, out) -> bool:
    """Whether a sampled loop's run can be continued exactly from where it stopped.

    A quiet stop of a discrete controller comes on a sample instant, before the
    sample is taken (:class:`~fi_design.kernel.layout.Integration`
    ``controller``): a run from its end state, with the controller's states and
    held output as the new run's ``dx1``, ``dx2`` and ``u_initial``, takes that
    sample at its t = 0 and continues the motion exactly, as long as no
    delayed output is still pending (a loop delay shorter than the sample period).

    Parameters
    ----------
    params : PlantParameters
        The plant.
    out : fi_design.kernel.layout.Integration
        The run that stopped.

    Returns
    -------
    bool
    """
    return params.sample_period > 0.0 and out.stop == "quiet" and out.controller[3] == 0


def continued_state(params: PlantParameters, out) -> np.ndarray | None:
    """The state a run that stopped goes on from exactly, for :func:`kernel_run`; None if none.

    Its final state where that is the whole state (:func:`~.settings.restartable`); a
    sampled loop's, stopped on a sample instant with nothing pending
    (:func:`resumes_sampled`), followed by its controller's ``dx2`` and held output (a
    section state, :func:`resumed`); otherwise None (a run has to start over).

    Parameters
    ----------
    params : PlantParameters
        The plant.
    out : fi_design.kernel.layout.Integration
        The run that stopped.

    Returns
    -------
    ndarray or None
    """
    if restartable(params):
        return out.final_state.copy()
    if resumes_sampled(params, out):
        return np.concatenate([out.final_state, out.controller[1:3]])
    return None


def match_tolerance(params: PlantParameters, known: Sequence[MoveRun]) -> float:
    """How close to a known cycle a move's section state must come to have entered it [-].

    :data:`~fi_design.stage.settings.MATCH_SHARE` of the smallest known cycle's
    peak-to-peak amplitude, in the physical scale of positions (1 mm), between
    :data:`~fi_design.stage.settings.MATCH` and
    :data:`~fi_design.stage.settings.MATCH_CAP`: a cycle of millimetres draws in
    a state within a few tenths of a millimetre as surely as one of 10 um draws in
    a state within a hundredth; :data:`MATCH` 0 turns the rule off.

    Parameters
    ----------
    params : PlantParameters
        The plant (its scales).
    known : sequence of MoveRun
        The cycles found so far.

    Returns
    -------
    float
        The tolerance in physical scales [-].
    """
    amplitudes = [r.outcome.amplitude for r in known if r.outcome.amplitude]
    if MATCH <= 0.0 or not amplitudes:
        return MATCH
    scale = float(tolerances(params, 1.0)[0])  # positions [m]
    return min(MATCH_CAP, max(MATCH, MATCH_SHARE * min(amplitudes) / scale))


def move_outcome(params: PlantParameters, ref: Trajectory, move_end: float, w: Watch, *,
                 distance: float, label: str = "family", repeat: float = REPEAT,
                 known: Sequence[MoveRun] = ()) -> MoveRun:
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
    known : sequence of MoveRun
        Hunting runs of earlier moves of the same plant: once the section
        state comes within :func:`match_tolerance` of one of their cycles, the move has
        entered that cycle and the run stops there; its outcome takes that
        cycle's amplitude and period (for a plant whose state vector is whole
        and whose forces do not depend on where the stage is; otherwise the
        run goes on until its own motion repeats).

    Returns
    -------
    MoveRun
        The :class:`~fi_design.results.stage.MoveOutcome` and, for a cycle,
        the last section state and the crossings per period.
    """
    level = ref.final
    y0 = np.zeros(params.n_states)
    t_end = move_end + w.horizon
    restart = restartable(params)
    known = [r for r in known if r.cycle_states is not None] \
        if restart and translation_invariant(params) else []
    table = np.concatenate([r.cycle_states for r in known]) if known else None
    owner = [r for r in known for _ in range(len(r.cycle_states))]
    match = match_tolerance(params, known)
    start, offset, elapsed = move_end, 0.0, 0.0
    cur_ref, cur_y0, cur_end = ref, y0, t_end
    rested_at = None  # when the stage last came to rest inside the band, not for good [s]
    while True:
        out = kernel_run(params, cur_y0, cur_ref, cur_end,
                         watch_array(w, start, level, repeat=repeat, known=table, match=match),
                         w.tolerance,
                         w.max_steps)
        elapsed = offset + out.t_reached - move_end
        y = out.final_state
        if out.code != 0:
            return MoveRun(MoveOutcome(distance, label, "undetermined", float(y[0] - level), None,
                                    None, elapsed, f"the simulation failed: {out.status}",
                                    failed=True), None, 0, level)
        if out.stop == "quiet" and not rest_ends_run(params, y, level, w.band):
            # the integrator will break the cart loose again: keep going
            rested_at = offset + out.t_reached if abs(y[0] - level) <= w.band else None
            if offset + out.t_reached >= t_end * (1 - 1e-12):
                break
            go_on = continued_state(params, out)
            if go_on is not None:
                offset += out.t_reached
                cur_y0, cur_ref = go_on, hold(level, t_end - offset)
                cur_end, start = t_end - offset, 0.0
            else:  # run again from the start, watching from later on
                start = out.t_reached + 1e-9
            continue
        break
    e = float(y[0] - level)
    n = len(out.crossing_times)
    if out.stop == "quiet":
        if abs(e) <= w.band:
            word, why = "settles", f"at rest {length_text(abs(e))} from the target for good"
        elif integrates(params):
            word, why = "stuck", (f"at rest {length_text(abs(e))} from the target with the drive "
                                  f"at its {quantity(params.force_limit, 'N', 3)} force limit")
        else:
            word, why = "rests", (f"at rest {length_text(abs(e))} from the target (no "
                                  "integrator to pull it in)")
        return MoveRun(MoveOutcome(distance, label, word, e, None, None, elapsed, why), None, 0,
                    level)
    if out.stop == "match":
        seen = owner[out.period_crossings]
        m = seen.outcome
        why = (f"a sustained cycle: {length_text(m.amplitude)} peak to peak"
               + (f", period {quantity(m.period, 's', 3)}" if m.period else "")
               + f" (enters the cycle of the {length_text(abs(m.distance))} move)")
        return MoveRun(MoveOutcome(distance, label, "hunts", float(out.crossing_states[-1][0]
                                                                  - level),
                                m.amplitude, m.period, elapsed, why),
                    seen.section_state, seen.crossings, seen.level, seen.cycle_states)
    if out.stop in ("repeat", "crossings") or (out.stop == "end" and n >= 4):
        q = out.period_crossings if out.stop == "repeat" else guess_period(out.crossing_states)
        q = max(1, min(q, n - 1)) if n > 1 else 1
        period = float(out.crossing_times[-1] - out.crossing_times[-1 - q]) if n > q else None
        ext = out.crossing_extremes[-q:]
        amp = float(np.max(ext[:, 1]) - np.min(ext[:, 0])) if len(ext) else None
        how = {"repeat": "repeats at the section", "crossings": "keeps crossing the target",
               "end": "keeps crossing the target"}[out.stop]
        why = (f"a sustained cycle: {length_text(amp)} peak to peak"
               + (f", period {quantity(period, 's', 3)}" if period else "") + f" ({how})")
        return MoveRun(MoveOutcome(distance, label, "hunts", float(out.crossing_states[-1][0]
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
        why = (f"within the band for the rest of the {quantity(w.horizon, 's', 3)} horizon, "
               f"{length_text(abs(e))} from the target; the cart creeps at its static friction")
        return MoveRun(MoveOutcome(distance, label, "settles", e, None, None, elapsed, why), None,
                    0, level)
    if abs(e) > w.band:
        word = "stuck" if integrates(params) else "rests"
        why = (f"{length_text(abs(e))} from the target after {quantity(elapsed, 's', 3)}, "
               "neither at rest there for good nor cycling")
        return MoveRun(MoveOutcome(distance, label, word, e, None, None, elapsed, why), None, 0,
                    level)
    return MoveRun(MoveOutcome(distance, label, "undetermined", e, None, None, elapsed,
                            "neither at rest for good nor in a cycle after "
                            f"{quantity(elapsed, 's', 3)} (raise requirements.hunting.horizon)"),
                   None, 0, level)


def guess_period(states: np.ndarray, max_period: int = 4) -> int:
    """Crossings per period of a cycle that has not repeated within tolerance yet.

    Parameters
    ----------
    states : ndarray, shape (m, n)
        The section states of the run, in order (SI).
    max_period : int
        Most crossings per period considered.

    Returns
    -------
    int
        The period, in crossings, whose states come back closest (relative to
        their spread).
    """
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
