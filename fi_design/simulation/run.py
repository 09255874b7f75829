"""One nonlinear simulation of the stage, with or without the isolator.

:func:`simulate` takes the kernel parameters from the resolved model
(:meth:`fi_design.model.Model.plant`: the loop's controller, effects
applied), integrates with the fast RODAS4 kernel
(``method="fast"``) or with scipy's solve_ivp on the same equations
(``method="reference"``), and returns a :class:`SimulationResult` with the
traces at the output rate and the hunting metrics.

The two methods share the right-hand side, Jacobian and mode switch of
:mod:`fi_design.kernel.equations` (the reference locates mode changes with
solve_ivp's own event finder), so the comparison tests the integrator, not a
second transcription of the model.
"""

from __future__ import annotations

import math
import time as _time
import weakref
from dataclasses import replace
from functools import lru_cache

import numpy as np

from .. import spec as _spec
from ..arguments import number
from ..display import number as number_text, quantity  # number: the argument check
from ..errors import ArgumentError, DataError, SimulationError
from .metrics import HuntingMetrics, hunting_metrics
from ..model import Model, as_model
from ..kernel import run as _kernel_run
from ..kernel.build import compiled
from ..kernel.layout import PARAMETER_INDEX, PlantParameters, state_index
from .replay import (DRIVES, command_rate, command_state, initial_changes, record_reference,
                     record_state, rate_note, reference_state, replay_fit, start_note,
                     check_record, deflection_note, window_note)
from ..results import frozen_array
from ..results.simulation import SimulationResult
from ..trajectory import Trajectory, from_moves

METHODS = ("fast", "reference")

#: Default length of the re-anchored windows of an open-loop replay [s].
WINDOW = 0.1
#: Fewest record samples in a window of an open-loop replay.
MIN_WINDOW_SAMPLES = 10
#: Most windows of an open-loop replay (each one integration).
MAX_WINDOWS = 100_000


# --------------------------------------------------------------------------- tolerances


def tolerances(params: PlantParameters, rtol: float) -> np.ndarray:
    """Absolute tolerance per state [state units]: ``rtol`` times a physical scale.

    Scales: 1 mm for positions, 1 cm/s for velocities, the presliding range
    Fs / sigma0 for the bristle state, Fs for the controller forces and the
    filter chain's states (forces too).
    """
    zs = params.Fs / params.sigma0
    if params.isolated:
        scale = [1e-3, 1e-2, 1e-3, 1e-2, zs, params.Fs, params.Fs]
    else:
        scale = [1e-3, 1e-2, zs, params.Fs, params.Fs]
    scale += [params.Fs] * int(params.filter_states)
    return rtol * np.array(scale)


# --------------------------------------------------------------------------- simulate


def simulate(spec: _spec.Spec | Model, isolated: bool | None = None, method: str = "fast", *,
             crossover: float | None = None, reference: Trajectory | None = None,
             initial_position: float = 0.0, duration: float | None = None,
             effects=None, rtol: float | None = None, record=None, drive: str = "closed",
             window: float = WINDOW, initial_command: float | None = None,
             rate: float | None = None) -> SimulationResult:
    """Simulate the stage and evaluate the hunting metric.

    Parameters
    ----------
    spec : Spec or Model
        The design spec (resolved here, :func:`fi_design.model.resolve`), or
        a resolved model (:meth:`fi_design.model.Model.at` varies it).
    isolated : bool, optional
        Simulate the isolated plant (True) or the stage without isolator
        (False); None follows the model.
    method : {"fast", "reference"}
        RODAS4 kernel, or scipy solve_ivp (Radau, tight tolerance) on the same
        equations for checks and benchmarks.
    crossover : float, optional
        Shift the controller to this crossover [Hz] (``model.at(crossover=...)``);
        default the model's.
    reference : Trajectory, optional
        A given reference signal instead of the spec's moves.
    initial_position : float
        Stage and cart position at t = 0 [m], at rest.
    duration : float, optional
        Simulated time [s]; default ``spec.motion.duration`` (or the end of a
        given reference or record).
    effects : sequence, optional
        Effect entries replacing the model's (``model.at(effects=...)``).
    rtol : float, optional
        Relative tolerance of the chosen method; default
        ``spec.simulation.tolerance`` for the fast path and 1e-4 times it for
        the reference.
    record : fi_design.measured.Measurement, optional
        Replay this measured record (docs/interfaces.md) instead of the
        spec's motion: the model starts from the state in the data (position
        and velocity from the first samples, the controller consistent with
        the first force sample) and its outputs are at the record's times.
    drive : {"closed", "force"}
        With a record: ``"closed"`` drives the model and its controller with
        the measured reference (and ``disturbance_N``); ``"force"`` drives the
        plant open loop with the measured ``force_N`` (no controller model),
        re-anchored to the measurement every ``window`` seconds.
    window : float
        Length of the re-anchored windows of an open-loop replay [s].
    initial_command : float, optional
        Closed-loop replay: the controller's output at the first sample [N]
        that its initial state is made consistent with; default the record's
        first ``force_N`` less ``disturbance_N`` sample. A single sample holds
        the force sensor's noise: a caller that estimated the command better
        (the reconciliation fits it) passes it here.
    rate : float, optional
        Output rate of the traces [Hz]; default ``simulation.output_rate`` (the
        spec's motion and a given reference only).

    Returns
    -------
    SimulationResult
        Integration failures are reported in ``success``, ``status`` and
        ``message``, never raised.

    Raises
    ------
    SimulationError
        An unknown method or drive, or a drive that needs what the record
        lacks (``force_N`` for ``drive="force"``).
    ArgumentError
        ``spec`` is not a spec, path or mapping; a number argument is not a
        finite number (``crossover="5 Hz"``); a ``duration`` or a record of
        more than :data:`fi_design.spec.MAX_OUTPUT_SAMPLES` output samples;
        a ``window`` of fewer than :data:`MIN_WINDOW_SAMPLES` record samples
        or more than :data:`MAX_WINDOWS` windows.
    """
    if method not in METHODS:
        raise SimulationError(f"method must be one of {METHODS}, got {method!r}")
    if drive not in DRIVES:
        raise SimulationError(f"drive must be one of {DRIVES}, got {drive!r}")
    spec, crossover, duration, rtol, rate = _checked_arguments(spec, crossover, duration, rtol,
                                                             record, rate)
    initial_position = number(initial_position, "initial_position", "m")
    model = _model_of(spec)
    if crossover is not None or effects is not None:
        model = model.at(crossover=crossover, effects=effects)
    iso = model.has_isolator if isolated is None else bool(isolated)
    params, p, atols = _plant(model, iso)
    if record is not None:
        return _replay(model, iso, method, params, record, drive, window, rtol, initial_command)
    if drive != "closed":
        raise SimulationError("drive='force' replays a record: give record=")
    if params.x1_initial != initial_position:
        params = replace(params, x1_initial=float(initial_position))
        p = None
    motion = model.spec.motion
    if reference is None:
        t_end = motion.duration if duration is None else duration
        ref, move_end, r_max, pieces = _move_reference(motion, t_end, initial_position)
    else:
        ref, move_end, r_max, pieces = reference, 0.0, None, None
        t_end = float(ref.breaks[-1]) if duration is None else duration
    if rate is None:
        rate = model.spec.simulation.output_rate
    n_out = int(math.floor(t_end * rate + 1e-9)) + 1
    if n_out <= _KEPT_OUTPUT_SAMPLES:
        t_out, t_shown = _output_times(n_out, rate)
    else:  # a long run's times are not kept (nor worth keeping beside its integration)
        t_out, t_shown = np.arange(n_out) / rate, None
    y0 = np.zeros(params.n_states)
    idx = _STATE_INDEX[iso]
    y0[idx["x1"]] = initial_position
    y0[idx["x2"]] = initial_position
    out, wall = _integrate(model, method, params, y0, ref, t_end, t_out, rtol,
                           reference_max=r_max, array=p, atols=atols, pieces=pieces)
    return _result(model, iso, method, params, out, t_out, wall, move_end=move_end,
                   shown_time=t_shown)


# What simulate() works out again and again for the same spec, model or moves: kept, all of
# it immutable (the kernel only reads the arrays it is given).

#: The last spec resolved here and its model (the spec held, so its identity stays its own).
_LAST_RESOLVED: tuple | None = None

#: Per model (by identity, while it lives): ``{isolated: (PlantParameters, kernel array,
#: {rtol: absolute tolerances})}``.
_PLANTS: "weakref.WeakKeyDictionary[Model, dict]" = weakref.WeakKeyDictionary()

#: The state index of each plant (without filter states: their names are not read here).
_STATE_INDEX = {True: state_index(True), False: state_index(False)}


def _model_of(spec) -> Model:
    """``as_model(spec)``; the same spec object again gives the same model (resolved once)."""
    global _LAST_RESOLVED
    if isinstance(spec, Model):
        return spec
    last = _LAST_RESOLVED
    if last is not None and last[0] is spec:
        return last[1]
    model = as_model(spec)
    _LAST_RESOLVED = (spec, model)
    return model


def _plant(model: Model, iso: bool) -> tuple[PlantParameters, np.ndarray, dict]:
    """``model.plant(iso)``, its kernel array and its absolute tolerances per relative
    tolerance (filled by :func:`_integrate`), worked out once per model and plant."""
    kept = _PLANTS.get(model)
    if kept is None:
        kept = _PLANTS[model] = {}
    hit = kept.get(iso)
    if hit is None:
        params = model.plant(iso)
        hit = kept[iso] = (params, params.to_array(), {})
    return hit


@lru_cache(maxsize=32)
def _move_reference(motion, t_end: float, initial_position: float):
    """The reference of the spec's moves (``motion``, immutable) until ``t_end``, started at
    ``initial_position``, the end of the last move [s], the largest |r| [m] and the
    reference's breaks and coefficients as the kernel takes them (writable copies, which it
    only reads): kept by their values."""
    ref = from_moves(motion.moves, t_end)
    if initial_position:
        c = np.array(ref.coeffs)
        c[:, 0] += initial_position
        ref = Trajectory(ref.breaks, c, land=True)
    return ref, motion.end_time, _largest(ref), (np.array(ref.breaks), np.array(ref.coeffs))


#: Most output samples whose times are kept (:func:`_output_times`: 16 bytes a sample).
_KEPT_OUTPUT_SAMPLES = 100_000


@lru_cache(maxsize=4)
def _output_times(n_out: int, rate: float) -> tuple[np.ndarray, np.ndarray]:
    """The output times ``arange(n_out) / rate`` twice: for the kernel and the metric
    (writable, as the compiled code takes them; they only read it), and for the results (on
    an immutable buffer: no result can make it writable, so none can change another's)."""
    t = np.arange(n_out) / rate
    return t, np.frombuffer(t.tobytes(), dtype=np.float64)


def _checked_arguments(spec, crossover, duration, rtol, record, rate=None):
    """The spec or model (a spec loaded when given as a path or mapping) and the numeric
    arguments, checked."""
    from ..measured import Measurement
    from ..spec.file import as_spec

    if not isinstance(spec, Model):
        spec = as_spec(spec, model=True)
    settings = (spec.spec if isinstance(spec, Model) else spec).simulation
    if crossover is not None:
        crossover = number(crossover, "crossover", "Hz", positive=True)
    if rtol is not None:
        rtol = number(rtol, "rtol", "-", positive=True, maximum=0.1)
    if record is not None and not isinstance(record, Measurement):
        raise ArgumentError(f"record must be a Measurement (fi_design.load_measurement), got "
                            f"{type(record).__name__}")
    if record is not None and record.n > _spec.MAX_OUTPUT_SAMPLES:
        raise ArgumentError(f"the record has {record.n} samples; a replay holds at most "
                            f"{_spec.MAX_OUTPUT_SAMPLES} (about 150 bytes each): replay a part "
                            "of it (fi_design.identification.segment)")
    if rate is not None:
        rate = number(rate, "rate", "Hz", positive=True)
    if duration is not None:
        duration = number(duration, "duration", "s", positive=True)
        at = settings.output_rate if rate is None else rate
        samples = math.floor(duration * at + 1e-9) + 1
        if samples > _spec.MAX_OUTPUT_SAMPLES:
            raise ArgumentError(f"duration = {quantity(duration, 's', 6)} at "
                                + ("simulation.output_rate" if rate is None else "rate")
                                + f" = {quantity(at, 'Hz', 6)} makes "
                                f"{number_text(float(samples), 3)} output samples; at most "
                                f"{_spec.MAX_OUTPUT_SAMPLES}")
    return spec, crossover, duration, rtol, rate


def _integrate(model, method, params, y0, ref, t_end, t_out, rtol, input_time=None,
               input_force=None, reference_max=None, array=None, atols=None, pieces=None):
    """One integration with the chosen method; returns the Integration and its wall time [s].

    ``reference_max``: the largest |r| [m] the divergence bound is set from (default: of
    ``ref``; a window of a longer reference passes the whole reference's). ``array``:
    ``params.to_array()``, ``atols``: the kept ``{rtol: tolerances(params, rtol)}`` of
    that array's plant (filled here), ``pieces``: ``ref``'s breaks and coefficients as
    writable arrays, when the caller has them."""
    settings = model.spec.simulation
    tol = rtol if rtol is not None else settings.tolerance * (
        1.0 if method == "fast" else 1e-4)
    if reference_max is None:
        reference_max = _largest(ref)
    x_bound = 1.0 + 100.0 * (reference_max + abs(y0[0]))
    start = _time.perf_counter()
    if method == "fast":
        compiled()  # loads the built kernel (or compiles it) before the clock starts
        start = _time.perf_counter()
        breaks, coeffs = (ref.breaks, ref.coeffs) if pieces is None else pieces
        if array is None or atols is None:
            array, atol = params.to_array() if array is None else array, tolerances(params, tol)
        else:  # the kept plant's (the kernel only reads them)
            atol = atols.get(tol)
            if atol is None:
                atol = atols[tol] = tolerances(params, tol)
        out = _kernel_run(array, y0, breaks, coeffs, ref.land, t_end, t_out, tol, atol, 0.05,
                          settings.max_steps, x_bound, input_time, input_force)
    else:
        from ..kernel.reference import solve_reference

        out = solve_reference(params, y0, ref, t_end, t_out, tol, tolerances(params, tol),
                              x_bound, input_time=input_time, input_force=input_force)
    return out, _time.perf_counter() - start


def _largest(ref: Trajectory) -> float:
    """The largest |r| of a reference [m] (its pieces' start values, the end held)."""
    return float(np.max(np.abs(ref.coeffs[:, 0])))


def _result(model, iso, method, params, out, t_out, wall, *, move_end,
            time_offset=0.0, drive="closed", record=None, window=None, window_span=None,
            shown_time=None) -> SimulationResult:
    """The result of an integration; ``record`` (a Measurement) for a replay, ``window`` the
    open-loop replay's window number of every sample and ``window_span`` its window [s].
    ``shown_time``: ``t_out``'s values on a buffer of its own for the result (read-only)."""
    success = out.code == 0
    message = "" if success else _failure_message(out.status, out.t_reached, params, iso, drive)
    Y, R = out.states, out.reference
    idx = _STATE_INDEX[iso]
    t = t_out + time_offset if time_offset else t_out
    metrics = _metrics(model, t, Y[:, idx["x1"]] - R, success, message, move_end)

    def trace(values):  # the integration's own arrays, handed over without a copy
        return frozen_array(values, copy=False)

    return SimulationResult(
        spec=model.spec, isolated=iso, method=method, friction_model=model.friction.model,
        crossover=model.crossover, effects=tuple(e.type for e in model.effects),
        time=trace(t if shown_time is None or time_offset else shown_time), reference=trace(R),
        position=trace(Y[:, idx["x1"]]),
        cart_position=trace(Y[:, idx["x2"]]), velocity=trace(Y[:, idx["v1"]]),
        cart_velocity=trace(Y[:, idx["v2"]]), force=trace(out.command),
        applied_force=trace(out.applied_force), bristle=trace(Y[:, idx["z"]]),
        success=success, status=out.status, message=message, t_reached=out.t_reached + time_offset,
        n_steps=out.n_steps, n_rejected=out.n_rejected, n_events=out.n_events, wall_time=wall,
        metrics=metrics, parameters=params, drive=drive,
        record=None if record is None else (record.source or "record"),
        window=None if window is None else frozen_array(window, dtype=int),
        replay=None if record is None else replay_fit(
            record, Y[:, idx["x1"]], out.command,
            record_notes(model, record, drive, iso, None if window is None else window_span)))


def record_notes(model, record, drive: str, isolated: bool | None = None,
                 window: float | None = None) -> tuple[str, ...]:
    """Warnings about a replayed record: a closed loop that starts far from its reference, a
    record sampled too slowly for the loop's crossover, a deflection_m column that a spec
    without isolator does not compare, an open-loop window as long as the record.

    Parameters
    ----------
    model : Model
        The model replaying it (its largest move is the scale of a record at rest).
    record : Measurement
        The record.
    drive : {"closed", "force"}
        The replay's drive: an open loop (``"force"``) has no start warning (the
        reference drives nothing there).
    isolated : bool, optional
        Whether the replay models the isolator (default: when the spec has one).
    window : float, optional
        The open-loop replay's window [s], when there is one.

    Returns
    -------
    tuple of str
        :func:`~fi_design.simulation.replay.start_note`'s and
        :func:`~fi_design.simulation.replay.rate_note`'s,
        :func:`~fi_design.simulation.replay.deflection_note`'s and
        :func:`~fi_design.simulation.replay.window_note`'s warnings, those that apply.
    """
    notes = [rate_note(record, model.crossover),
             deflection_note(record, model.has_isolator if isolated is None else bool(isolated),
                             model.has_isolator)]
    if drive == "closed":
        notes.insert(0, start_note(record, max(abs(m.distance) for m in model.spec.motion.moves)))
    elif window is not None:
        notes.append(window_note(record, window))
    return tuple(n for n in notes if n)


def _replay(model, iso, method, params, record, drive, window, rtol, initial_command=None):
    """Replay a measured record, closed loop or open loop in re-anchored windows.

    A quantizer is never passed through on a fast move here: the record's command carries
    the derivative terms' impulse at every level, which the replay is compared with."""
    check_record(record, model.crossover)
    params = replace(params, quantization_free=0.0)
    t0 = float(record.time[0])
    t_out = np.asarray(record.time, dtype=float) - t0
    ref = record_reference(record)
    if drive == "closed":
        dist = record.disturbance
        command = command_state(record, 0) if initial_command is None else float(initial_command)
        y0, changes = _anchor(model.law, params, record, 0, ref, command)
        p0 = replace(params, **changes)
        out, wall = _integrate(model, method, p0, y0, ref, float(t_out[-1]), t_out, rtol,
                               None if dist is None else t_out, dist)
        return _result(model, iso, method, p0, out, t_out, wall, move_end=0.0,
                       time_offset=t0, record=record)
    if record.force is None:
        raise DataError("missing: an open-loop replay (--drive force) drives the plant with the "
                        "record's force, a column force_N", column="force_N", source=record.source)
    window = number(window, "window", "s", positive=True)
    least = MIN_WINDOW_SAMPLES * record.sample_period
    if window < least:
        raise ArgumentError(f"window = {quantity(window, 's', 6)} spans fewer than "
                            f"{MIN_WINDOW_SAMPLES} samples of the record "
                            f"({quantity(record.sample_period, 's', 6)} apart); give at least "
                            f"{quantity(least, 's', 3)}")
    count = math.ceil(float(t_out[-1]) / window)
    if count > MAX_WINDOWS:
        raise ArgumentError(f"window = {quantity(window, 's', 6)} cuts the "
                            f"{quantity(float(t_out[-1]), 's', 6)} record into {count} windows; "
                            f"at most {MAX_WINDOWS}: give at least "
                            f"{quantity(float(t_out[-1]) / MAX_WINDOWS, 's', 3)}")
    # the plant alone, driven by the measured force: no controller, no feedforward
    open_loop = replace(params, kp=0.0, ki=0.0, kd=0.0, kdm=0.0, wt=math.inf, ff_mass=0.0,
                        ff_viscous=0.0, ff_coulomb=0.0, sample_period=0.0, delay=0.0)
    starts = np.unique(np.append(
        np.searchsorted(t_out, np.arange(0.0, t_out[-1], window), side="left"), len(t_out)))
    pieces, wall = [], 0.0
    r_max = _largest(ref)
    # every window's plant is open_loop with its own start: its array with those entries
    # changed (the kernel only reads it), its tolerances the same (they scale with Fs, sigma0)
    base, atols = open_loop.to_array(), {}
    for a, b in zip(starts[:-1], starts[1:]):
        stop = min(b + 1, len(t_out))  # integrate to the next window's start
        y0, changes = _anchor(model.law, open_loop, record, a, ref, None, base)
        array = base.copy()
        for name, value in changes.items():
            array[PARAMETER_INDEX[name]] = value
        tw = t_out[a:stop] - t_out[a]
        # the reference's pieces over the window (and one more each side): the same values
        # as the whole reference there, without copying all of it for every window
        lo = max(int(np.searchsorted(ref.breaks, t_out[a], side="right")) - 2, 0)
        hi = min(int(np.searchsorted(ref.breaks, t_out[stop - 1], side="right")) + 1,
                 len(ref.coeffs))
        seg = Trajectory(ref.breaks[lo:hi + 1] - t_out[a], ref.coeffs[lo:hi], land=False)
        # the kernel reads the array; the reference solver the parameters themselves
        p0 = open_loop if method == "fast" else replace(open_loop, **changes)
        out, dt = _integrate(model, method, p0, y0, seg, float(tw[-1]), tw, rtol, tw,
                             record.force[a:stop], reference_max=r_max, array=array,
                             atols=atols)
        wall += dt
        pieces.append((int(a), int(b - a), out))
        if out.code != 0:
            break
    merged, labels = _merge(pieces, t_out)
    return _result(model, iso, method, open_loop, merged, t_out, wall, move_end=0.0,
                   time_offset=t0, drive="force", record=record, window=labels,
                   window_span=window)


def _anchor(law, params, record, index, ref, command, array=None):
    """Initial state and the parameters' changes for a replay starting at sample ``index``
    (``array``: ``params.to_array()``, when the caller has it)."""
    st = record_state(record, index)
    r, rd, rdd = reference_state(record, index)
    if array is None:
        array = params.to_array()
    ff = compiled().feedforward(rd, rdd, 0.0, array)[0]
    defl = None if record.deflection is None or not params.isolated else \
        float(record.deflection[index])
    rate = None if command is None else command_rate(record, index)
    return initial_changes(params, law, st, deflection=defl, command=command,
                           reference=(r, rd, rdd), feedforward=ff, rate=rate, array=array)


def _merge(pieces, t_out):
    """One Integration, and the window number per sample, from the windows of a replay.

    ``pieces`` holds ``(first sample, samples kept, Integration)`` per window;
    samples after a failed window stay NaN (window -1).
    """
    from ..kernel.layout import Integration

    n = len(t_out)
    states = np.full((n, pieces[0][2].states.shape[1]), np.nan)
    cols = {k: np.full(n, np.nan) for k in ("reference", "applied_force", "command")}
    labels = np.full(n, -1, dtype=int)
    for w, (a, m, out) in enumerate(pieces):
        states[a:a + m] = out.states[:m]
        for k in cols:
            cols[k][a:a + m] = getattr(out, k)[:m]
        labels[a:a + m] = w
    a, _, last = pieces[-1]
    return Integration(
        code=last.code, status=last.status, states=states, reference=cols["reference"],
        applied_force=cols["applied_force"], command=cols["command"],
        n_steps=sum(p[2].n_steps for p in pieces), n_rejected=sum(p[2].n_rejected for p in pieces),
        n_events=sum(p[2].n_events for p in pieces),
        t_reached=float(t_out[a]) + last.t_reached), labels


def _metrics(model, t, err, success, message, move_end) -> HuntingMetrics:
    h = model.requirements.hunting
    return hunting_metrics(t, err, window_start=h.window_start, window_length=h.window_length,
                           min_distance=h.min_distance, min_height=h.min_height,
                           settle_band=h.settle_band, motion_end=move_end, success=success,
                           failure=message)


def _failure_message(status: str, t: float, params: PlantParameters, iso: bool,
                     drive: str = "closed") -> str:
    """The failure and its likely cause; an open-loop replay (``drive="force"``) has no loop
    to be unstable: the recorded force itself drives the stage off."""
    causes = {
        "step budget exhausted": "very fast switching (chattering at a limiter or at standstill) or "
                                 "a budget too small for the run; raise simulation.max_steps",
        "step size underflow": "a discontinuity the integrator cannot pass, e.g. a very stiff "
                               "limiter (isolator.limiter.stiffness) or chattering stick-slip",
        "state became NaN or infinite": "an unstable closed loop or unphysical parameters",
        "solution diverged": "an unstable closed loop: check the crossover against the "
                             "achievable one (guideline step 2), the delay and the sample rate",
        "delay history overflow": "a delay much longer than the integration steps",
        "singular iteration matrix": "degenerate parameters (zero mass or stiffness)",
    }
    if drive == "force":
        pushed = ("the recorded force drives the stage beyond any plausible travel (open "
                  "loop, only the spec's friction and stiffness hold it): check force_N's sign "
                  "and unit (N), and the friction or stiffness terms of the spec")
        causes.update({"state became NaN or infinite": pushed + ", or unphysical parameters",
                       "solution diverged": pushed})
    return f"{status} at t = {quantity(t, 's', 6)}; likely cause: {causes.get(status, 'unknown')}"
