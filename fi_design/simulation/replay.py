"""Replay of a measured record: the model's state taken from the data (docs/interfaces.md).

A record may start in motion (the EMPS axis moves at 13 mm/s at its first
sample), so a replay never starts from rest: the stage position and velocity
come from the first samples, the cart and the bristles from steady sliding
at that velocity (or the measured joint deflection), and the controller's
internal state is made consistent with the first force sample. The same
estimate re-anchors the windows of an open-loop replay (``drive="force"``,
the plant driven by the measured force, no controller model), where a
rigid-body mode would otherwise drift without bound.

The functions here only read the record and the kernel parameters; the
integration itself stays in :mod:`fi_design.simulation.run`.
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from ..display import number, percent, quantity
from ..errors import DataError
from ..kernel.build import compiled
from ..kernel.layout import P_SIGMA2_NEG, PlantParameters, state_index
from ..measured import Measurement, check_position_steps, check_time_steps
from ..trajectory import Trajectory, from_samples
from ..controller.pid import ControlLaw

#: Span of samples the local velocity estimate fits [s].
VELOCITY_SPAN = 0.01
#: Fewest samples the local velocity estimate needs.
MIN_FIT_SAMPLES = 5

#: Two-sided probability that a stage at rest is taken as moving: the velocity estimate must
#: exceed this quantile of Student's t (with the fit's degrees of freedom) in standard errors.
MOVING_P = 1e-3

#: Drives of a replay: the model's controller closes the loop, or the measured force drives it.
DRIVES = ("closed", "force")


@dataclass(frozen=True)
class RecordState:
    """The stage's state at one sample of a record, estimated from the data.

    Attributes
    ----------
    index : int
        Sample index.
    time : float
        Sample time [s].
    position : float
        Measured stage position x1 at the sample [m].
    velocity : float
        Stage velocity from a local quadratic fit of the position [m/s].
    velocity_error : float
        Standard error of ``velocity`` from the fit's residuals [m/s] (0 for
        an exact fit).
    dof : int
        Degrees of freedom of the fit's residuals.

    The stage counts as moving when a t-test rejects zero velocity at
    :data:`MOVING_P` (:attr:`moving`); otherwise the record starts at rest and a
    noisy velocity estimate must not start the friction model sliding.
    """

    index: int
    time: float
    position: float
    velocity: float
    velocity_error: float = 0.0
    dof: int = 0

    @property
    def moving(self) -> bool:
        """Whether a t-test rejects zero velocity (two-sided, :data:`MOVING_P`)."""
        if self.velocity_error <= 0.0 or self.dof < 1:
            return self.velocity != 0.0
        from scipy.special import stdtrit

        limit = float(stdtrit(self.dof, 1.0 - MOVING_P / 2.0))
        return abs(self.velocity) > limit * self.velocity_error


class LocalFit(NamedTuple):
    """A local quadratic: coefficients (value, slope, half curvature), covariance, dof."""

    coef: np.ndarray
    cov: np.ndarray
    dof: int


def _local_fit(record: Measurement, values: np.ndarray, index: int, span: float,
               measured: bool = True) -> LocalFit:
    """Quadratic least-squares fit of ``values`` within ``span`` around sample ``index``.

    At an end of the record the stretch is one-sided, at least
    :data:`MIN_FIT_SAMPLES` samples: for a ``measured`` (noisy) column as
    wide as ``span`` (a derivative taken at the end of its stretch is the
    noisiest, and a record that starts in motion is read there), else half
    of it (a noise-free reference is fitted best where its polynomial
    pieces are shortest). Returns the coefficients (value, first and second
    derivative over 1, 1 and 2 at the sample) and their covariance from the
    residuals.
    """
    t = record.time
    n = len(t)
    half = max(span / 2.0, 0.5 * (MIN_FIT_SAMPLES - 1) * record.sample_period)
    lo = int(np.searchsorted(t, t[index] - half, side="left"))
    hi = int(np.searchsorted(t, t[index] + half, side="right"))
    if measured and lo == 0 and t[index] - half < t[0]:  # at the start: the span after it
        hi = int(np.searchsorted(t, t[0] + 2.0 * half, side="right"))
    if measured and hi == n and t[index] + half > t[-1]:  # at the end: the span before it
        lo = int(np.searchsorted(t, t[-1] - 2.0 * half, side="left"))
    if hi - lo < MIN_FIT_SAMPLES:  # a short record: extend to the other side
        lo, hi = max(0, min(lo, n - MIN_FIT_SAMPLES)), min(n, max(hi, MIN_FIT_SAMPLES))
    A = np.vander(t[lo:hi] - t[index], 3, increasing=True)
    coef, ssr, _, _ = np.linalg.lstsq(A, np.asarray(values[lo:hi], dtype=float), rcond=None)
    dof = hi - lo - 3
    s2 = float(ssr[0]) / dof if len(ssr) and dof > 0 else 0.0
    return LocalFit(coef, s2 * np.linalg.pinv(A.T @ A), int(dof))


#: What a replay works out of its record alone, kept per record (a frozen Measurement of
#: read-only arrays): a reconciliation replays one record in each of its many simulations,
#: an open-loop replay anchoring every window at the same samples.
_KEPT: "weakref.WeakKeyDictionary[Measurement, dict]" = weakref.WeakKeyDictionary()


def _fit_of(record: Measurement, column: str, index: int, span: float) -> LocalFit:
    """:func:`_local_fit` of the record's ``column`` at ``index``, worked out once per record."""
    kept = _KEPT.setdefault(record, {})
    key = (column, int(index), float(span))
    fit = kept.get(key)
    if fit is None:
        fit = kept[key] = _local_fit(record, getattr(record, column), index, span,
                                     column != "reference")
    return fit


def record_reference(record: Measurement) -> Trajectory:
    """The record's reference as a C2 cubic spline over its time from its first sample.

    :func:`fi_design.trajectory.from_samples` of ``reference_m``, worked out once per
    record.
    """
    kept = _KEPT.setdefault(record, {})
    ref = kept.get("reference")
    if ref is None:
        t = np.asarray(record.time, dtype=float)
        ref = kept["reference"] = from_samples(t - t[0], record.reference)
    return ref


@dataclass(frozen=True)
class ReplayFit:
    """How a replay agrees with the record it replays.

    Attributes
    ----------
    samples : int
        Samples compared (those the replay reached).
    position_rms : float
        RMS of model minus measured stage position [m].
    position_max : float
        Largest absolute position difference [m].
    tracking_rms_model : float
        RMS tracking error r - x1 of the model [m].
    tracking_rms_measured : float
        RMS tracking error r - x1 of the measurement [m].
    force_rms : float or None
        RMS of model minus measured commanded force [N]; None without ``force_N``.
    notes : tuple of str
        Warnings about the record as the replay reads it (:func:`start_note`).
    """

    samples: int
    position_rms: float
    position_max: float
    tracking_rms_model: float
    tracking_rms_measured: float
    force_rms: float | None
    notes: tuple[str, ...] = ()


#: A first position_m farther than this share of the move distance from the first reference_m
#: is an offset between the two columns, not the loop's error: a stage at rest sits within its
#: settle band (micrometres), one in motion within its following error (a few per cent of the
#: move for a sluggish loop), while two zeros (an encoder or homing offset, another unit)
#: differ by the order of the travel.
START_OFFSET_SHARE = 0.1
#: A record sampled below this many times the loop's crossover cannot show the loop's
#: dynamics (its Nyquist frequency lies below the crossover) [-].
RATE_FACTOR = 2.0


def check_record(record: Measurement, crossover: float, use: str = "replay") -> None:
    """Refuse a record a replay cannot follow: a gap in its time, a jump of its position.

    A replay drives the model through every instant of the record, by a spline
    through its reference (or, open loop, its force) between samples. Across a
    gap, a step of ``time_s`` :data:`~fi_design.measured.GAP_FACTOR` times the
    median step or more and longer than half a period of the loop's crossover
    (below :data:`RATE_FACTOR` samples per period: over it the record cannot
    show the loop), nothing is known of the stage: the spline invents the
    reference there, the model moves on it, and the comparison after the gap
    measures the invention (read as a missing disturbance). A record that
    does not hold the stage's motion cannot be replayed either: a jump of the
    position (:func:`~fi_design.measured.check_position_steps`). Shorter
    gaps pass: a logger that changes its rate, or drops a few samples, is
    bridged as any step is. A record that passed is not checked again.

    Parameters
    ----------
    record : Measurement
        The record.
    crossover : float
        The loop's crossover [Hz].
    use : str
        What the record is used for, in the message: ``"replay"`` or
        ``"reconcile"``.

    Raises
    ------
    DataError
        The gap or the jump, with its rows and times and what to do.
    """
    kept = _KEPT.setdefault(record, {})
    checked = kept.get("checked")
    if checked is True or checked == crossover:
        return
    longest = 1.0 / (RATE_FACTOR * crossover)
    check_time_steps(
        record, longest=longest,
        longest_is=(f"half a period of the loop's {quantity(crossover, 'Hz', 4)} crossover "
                    f"({quantity(longest, 's', 3)})"),
        needs=("nothing is known of the stage in it, and a replay would drive the model "
               "across it on a spline through the reference and compare what it invented "
               "with the samples after it"),
        parts=f"{use} each part on its own")
    check_position_steps(record)
    kept["checked"] = crossover


def vouch(record: Measurement) -> None:
    """Mark a record as one :func:`check_record` need not check: a record it passed, thinned,
    or a trace of the model itself (its position continuous by construction)."""
    _KEPT.setdefault(record, {})["checked"] = True


def deflection_note(record: Measurement, isolated: bool, has_isolator: bool) -> str:
    """A note when the record's ``deflection_m`` is not compared: the spec has no isolator.

    Parameters
    ----------
    record : Measurement
        The record.
    isolated : bool
        Whether the replay models the isolator.
    has_isolator : bool
        Whether the spec describes one.

    Returns
    -------
    str
        The note, empty when the column is compared, absent, or left out by choice (a spec
        with an isolator replayed without it).
    """
    if record.deflection is None or isolated or has_isolator:
        return ""
    largest = float(np.max(np.abs(record.deflection)))
    return (f"the record has a deflection_m column (up to {quantity(largest, 'm', 3)}), but the "
            "spec has no isolator: the model is one rigid mass on the bearing, so the column "
            "is not compared; if the stage has a joint between stage and cart, describe it in "
            "the spec's isolator section")


def window_note(record: Measurement, window: float) -> str:
    """A note when an open-loop replay's window spans the whole record: one run, never
    re-anchored.

    Parameters
    ----------
    record : Measurement
        The record.
    window : float
        The window [s].

    Returns
    -------
    str
        The note, empty when the record holds more than one window.
    """
    if window < record.duration:
        return ""
    return (f"the window ({quantity(window, 's', 4)}) is not shorter than the record "
            f"({quantity(record.duration, 's', 4)}): the replay is one open-loop run from the "
            "first sample, never re-anchored to the measurement, and its rigid-body drift "
            "grows over the whole record; give a shorter --window (default 0.1 s) for "
            "multiple shooting")


def rate_note(record: Measurement, crossover: float) -> str:
    """A warning when the record is sampled too slowly to show the loop it is compared with.

    Below :data:`RATE_FACTOR` times the crossover the record's Nyquist
    frequency lies below the loop's crossover: the comparison reads only the
    record's slow part. A ``time_s`` column written in ms is the usual cause
    (it reads 1000 times too slow).

    Parameters
    ----------
    record : Measurement
        The record.
    crossover : float
        The loop's crossover [Hz].

    Returns
    -------
    str
        The warning, empty when the record is sampled fast enough.
    """
    rate = 1.0 / record.sample_period
    if rate >= RATE_FACTOR * crossover:
        return ""
    return (f"the record is sampled at {quantity(rate, 'Hz', 4)}, below {number(RATE_FACTOR)} "
            f"x the loop's {quantity(crossover, 'Hz', 4)} crossover: it cannot show the loop's "
            "dynamics, so the comparison reads only its slow part; time_s must be in s (a "
            "column in ms reads 1000 x too slow)")


def start_note(record: Measurement, distance: float) -> str:
    """A warning when the record's first position is far from where its motion starts.

    A closed-loop replay starts from the position in the data and drives the
    model's controller with ``reference_m``, so its first control error is
    ``reference_m - position_m`` at the first sample. Far means more than
    :data:`START_OFFSET_SHARE` of the move distance: the larger of the
    record's reference travel and ``distance``.

    Parameters
    ----------
    record : Measurement
        The record.
    distance : float
        The spec's largest move distance [m] (the scale of a record whose
        reference does not move).

    Returns
    -------
    str
        The warning, empty when the start is near.
    """
    x0, r0 = float(record.position[0]), float(record.reference[0])
    travel = max(float(np.ptp(record.reference)), abs(float(distance)))
    offset = x0 - r0
    if travel <= 0.0 or abs(offset) <= START_OFFSET_SHARE * travel:
        return ""
    return (f"the record's first position_m ({quantity(x0, 'm', 4)}) lies "
            f"{quantity(offset, 'm', 4)} from its first reference_m ({quantity(r0, 'm', 4)}), "
            f"more than {percent(START_OFFSET_SHARE, 2)} of the move distance "
            f"({quantity(travel, 'm', 4)}): the replay starts at the measured position, so "
            "the model's controller starts with that error and closes it. Different zeros of "
            "position_m and reference_m (an encoder or homing offset) give such a start, and "
            "the measured error then never closes: if so, subtract the offset from one column "
            "and replay again")


def replay_fit(record: Measurement, position: np.ndarray, force: np.ndarray,
               notes: tuple[str, ...] = ()) -> ReplayFit:
    """Compare a replay's position [m] and commanded force [N] with the record.

    ``notes``: warnings about the record (:func:`start_note`), kept with the comparison.
    """
    ok = np.isfinite(position)

    def rms(x):
        return float(np.sqrt(np.mean(x[ok] ** 2))) if ok.any() else math.nan

    dx = position - record.position
    return ReplayFit(
        samples=int(ok.sum()), position_rms=rms(dx),
        position_max=float(np.max(np.abs(dx[ok]))) if ok.any() else math.nan,
        tracking_rms_model=rms(record.reference - position),
        tracking_rms_measured=rms(record.reference - record.position),
        force_rms=None if record.force is None else rms(force - record.force),
        notes=tuple(notes))


def record_state(record: Measurement, index: int = 0, span: float = VELOCITY_SPAN) -> RecordState:
    """Position and velocity of the stage at sample ``index``, from the data.

    A quadratic fitted by least squares to the positions within ``span``
    around the sample (one-sided at the ends of the record) gives the
    velocity at the sample: robust to encoder counts and sensor
    noise, and right while the stage accelerates.

    Parameters
    ----------
    record : Measurement
        The measured record.
    index : int
        Sample index.
    span : float
        Width of the fitted stretch [s]; at least :data:`MIN_FIT_SAMPLES`
        samples are used.

    Raises
    ------
    DataError
        The record has too few samples to estimate a velocity.
    """
    n = record.n
    if n < MIN_FIT_SAMPLES:
        raise DataError(f"too short to estimate the initial velocity: {n} sample(s), at least "
                        f"{MIN_FIT_SAMPLES} needed", column="position_m", source=record.source)
    fit = _fit_of(record, "position", index, span)
    return RecordState(index=int(index), time=float(record.time[index]),
                       position=float(record.position[index]), velocity=float(fit.coef[1]),
                       velocity_error=float(np.sqrt(max(fit.cov[1, 1], 0.0))), dof=fit.dof)


def reference_state(record: Measurement, index: int = 0,
                    span: float = VELOCITY_SPAN) -> tuple[float, float, float]:
    """Reference position, velocity and acceleration at sample ``index``, from the samples.

    The same local quadratic fit as :func:`record_state`, on ``reference_m``:
    a reference that starts accelerating at the first sample has zero
    velocity there, which an interpolating spline's end condition would not
    give (and the controller's state would carry the difference).

    Returns
    -------
    (r, r', r'') : tuple of float
        [m, m/s, m/s^2].
    """
    coef = _fit_of(record, "reference", index, span).coef
    return float(record.reference[index]), float(coef[1]), float(2.0 * coef[2])


def command_state(record: Measurement, index: int = 0) -> float | None:
    """The controller's own output at sample ``index`` [N]: force_N less disturbance_N.

    None without a ``force_N`` column.
    """
    if record.force is None:
        return None
    dist = 0.0 if record.disturbance is None else float(record.disturbance[index])
    return float(record.force[index]) - dist


def command_rate(record: Measurement, index: int = 0) -> float | None:
    """Rate of the controller's own output at sample ``index`` [N/s], from the data.

    The local quadratic of :func:`record_state` on ``force_N`` less
    ``disturbance_N``; None without a ``force_N`` column.
    """
    if record.force is None:
        return None
    rate = float(_fit_of(record, "force", index, VELOCITY_SPAN).coef[1])
    if record.disturbance is not None:
        rate -= float(_fit_of(record, "disturbance", index, VELOCITY_SPAN).coef[1])
    return rate


def initial_changes(params: PlantParameters, law: ControlLaw, state: RecordState, *,
                    deflection: float | None, command: float | None,
                    reference: tuple[float, ...], feedforward: float, rate: float | None = None,
                    array: np.ndarray | None = None) -> tuple[np.ndarray, dict[str, float]]:
    """The kernel's initial state for a record, and the parameters' changes for it.

    Parameters
    ----------
    params : PlantParameters
        Kernel parameters of the model.
    law : ControlLaw
        The loop's controller.
    state : RecordState
        Stage position and velocity from the data. A stage that is not
        :attr:`RecordState.moving` starts at rest, its bristles carrying the
        static load (the first command less the offset, within the
        breakaway force).
    deflection : float or None
        Measured joint deflection x1 - x2 [m]; None: the deflection of steady
        sliding (the joint force carrying the friction), within the stroke.
    command : float or None
        The controller's own output at the first sample [N] (force_N minus
        disturbance_N); None: the controller starts from its steady state.
    reference : (r, r', r'')
        Reference position, velocity, acceleration at the sample [m, m/s, m/s^2].
    feedforward : float
        The feedforward force at the sample [N].
    rate : float or None
        Rate of ``command`` [N/s] (:func:`command_rate`). A continuous
        controller's derivative roll-off lags the PID's output, by ``rate``
        over its corner [rad/s]: with it the integrator takes the PID's
        output, not the lagging command (a stage caught mid-move, its command
        changing, otherwise starts with its integrator off by that much); the
        feedforward is taken as steady. None, or a stage at rest: the roll-off
        taken at rest.
    array : ndarray, optional
        ``params.to_array()``, when the caller has it.

    Returns
    -------
    y0 : ndarray
        Initial state (layout of :func:`fi_design.kernel.layout.state_index`).
    changes : dict
        New values of ``params``' fields ``x1_initial``, the discrete
        controller's states ``dx1``, ``dx2`` and the command held before
        t = 0 (``u_initial``).
    """
    iso = bool(params.isolated)
    idx = state_index(iso)
    p = params.to_array() if array is None else array
    x1 = state.position
    v1 = state.velocity if state.moving else 0.0
    sgn = 1.0 if v1 >= 0.0 else -1.0
    y0 = np.zeros(params.n_states)
    y0[idx["x1"]] = x1
    y0[idx["v1"]] = v1
    sigma2 = params.sigma2 if sgn > 0 else p[P_SIGMA2_NEG]
    friction = 0.0
    if v1 != 0.0 and not params.switch_model:
        g, _, _ = compiled().stribeck(v1, x1, sgn, p)
        y0[idx["z"]] = sgn * g / params.sigma0
        friction = sgn * g + sigma2 * v1
    elif v1 != 0.0:
        friction = sgn * compiled().stribeck(v1, x1, sgn, p)[0] + sigma2 * v1
    elif command is not None:
        # at rest: the bristles carry the static load, up to the breakaway force
        load = command - params.offset
        if iso and deflection is not None:
            load = params.k * deflection
        breakaway = compiled().stribeck(0.0, x1, 1.0 if load >= 0.0 else -1.0, p)[0]
        friction = max(-breakaway, min(breakaway, load))
        if not params.switch_model:
            y0[idx["z"]] = friction / params.sigma0
    if iso:
        d = deflection if deflection is not None else _sliding_deflection(params, friction)
        y0[idx["x2"]] = x1 - d
        y0[idx["v2"]] = v1
    r, rd, rdd = reference
    xm = x1 if params.quantization <= 0 else math.floor(x1 / params.quantization + 0.5) * \
        params.quantization
    e = r - xm
    changes = dict(x1_initial=x1)
    if params.sample_period > 0.0:
        changes.update(_discrete_state(params, law, e, xm, rd - v1, v1, command, feedforward))
        d_in = -xm if law.derivative_on == "measurement" else e
        target = (params.dp * e + changes["dx1"] + params.dc * e + changes["dx2"]
                  + params.db * d_in)  # the PID's first output
    else:
        kf = law.kernel_form()
        v_wo_i = kf["kp"] * e + kf["kd"] * (rd - v1) - kf["kdm"] * v1
        target = v_wo_i if command is None else command - feedforward
        pid = target  # the PID's output, before the roll-off
        if command is not None and rate is not None and state.moving \
                and not math.isinf(kf["wt"]) and not params.filter_states:
            # u' = wt (pid - u), u the command (at rest the rate is the force's noise)
            pid = target + rate / kf["wt"]
        if law.integrator:  # the integrator takes what P and D leave of the first sample
            y0[idx["I"]] = pid - v_wo_i
        if not math.isinf(kf["wt"]):  # the filter state is the output itself
            y0[idx["u"]] = target
    nf = int(params.filter_states)
    if nf:  # the drive's filter chain at rest on the PID's first output (unit DC gain)
        y0[len(y0) - nf:] = params.filter_rest(target)
    if command is not None:
        changes["u_initial"] = command
    return y0, changes


def _sliding_deflection(params: PlantParameters, friction: float) -> float:
    """Joint deflection that carries the cart's friction in steady sliding [m], within the stroke."""
    if params.k <= 0.0:
        return 0.0
    d = friction / params.k
    return max(-params.s, min(params.s, d))


def _discrete_state(params: PlantParameters, law: ControlLaw, e: float, xm: float, ed: float,
                    xd: float, command: float | None, feedforward: float) -> dict[str, float]:
    """States ``dx1``, ``dx2`` of the discrete controller so its first output fits the data.

    The D term is taken in steady state for the present rate of its input
    (``ed`` = e' or ``-xd``), which both the Tustin and the backward-difference
    form reproduce exactly. What the first force sample needs beyond P and
    that D goes to the integrator when the loop has one, else to the D term
    (whose state is then the one the drive really had).
    """
    on_meas = law.derivative_on == "measurement"
    d_in, d_rate = (-xm, -xd) if on_meas else (e, ed)
    D0 = law.kd * d_rate
    dx1 = 0.0
    if command is not None:
        rest = command - feedforward - params.dp * e - params.dc * e - D0
        if law.integrator:
            dx1 = rest
        else:
            D0 += rest
    return dict(dx1=dx1, dx2=D0 - params.db * d_in)
