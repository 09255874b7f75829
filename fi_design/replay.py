"""Replay of a measured record: the model's state taken from the data (DESIGN.md section 8).

A record may start in motion (the EMPS axis moves at 13 mm/s at its first
sample), so a replay never starts from rest: the stage position and velocity
come from the first samples, the cart and the bristles from steady sliding
at that velocity (or the measured joint deflection), and the controller's
internal state is made consistent with the first force sample. The same
estimate re-anchors the windows of an open-loop replay (``drive="force"``,
the plant driven by the measured force, no controller model), where a
rigid-body mode would otherwise drift without bound.

The functions here only read the record and the kernel parameters; the
integration itself stays in :mod:`fi_design.simulation`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from .errors import DataError
from .measured import Measurement
from .pid import ControlLaw
from .compiled import kernel
from .plant import P_SIGMA2_NEG, PlantParameters, state_index

#: Span of samples the local velocity estimate fits [s].
VELOCITY_SPAN = 0.01
#: Fewest samples the local velocity estimate needs.
MIN_FIT_SAMPLES = 5

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
        Measured stage position x1 [m].
    velocity : float
        Stage velocity from a local quadratic fit of the position [m/s].
    """

    index: int
    time: float
    position: float
    velocity: float


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
    """

    samples: int
    position_rms: float
    position_max: float
    tracking_rms_model: float
    tracking_rms_measured: float
    force_rms: float | None


def replay_fit(record: Measurement, position: np.ndarray, force: np.ndarray) -> ReplayFit:
    """Compare a replay's position [m] and commanded force [N] with the record."""
    ok = np.isfinite(position)

    def rms(x):
        return float(np.sqrt(np.mean(x[ok] ** 2))) if ok.any() else math.nan

    dx = position - record.position
    return ReplayFit(
        samples=int(ok.sum()), position_rms=rms(dx),
        position_max=float(np.max(np.abs(dx[ok]))) if ok.any() else math.nan,
        tracking_rms_model=rms(record.reference - position),
        tracking_rms_measured=rms(record.reference - record.position),
        force_rms=None if record.force is None else rms(force - record.force))


def record_state(record: Measurement, index: int = 0, span: float = VELOCITY_SPAN) -> RecordState:
    """Position and velocity of the stage at sample ``index``, from the data.

    A quadratic fitted by least squares to the positions within ``span``
    around the sample (one-sided at the ends of the record) gives the
    velocity at the sample: robust to encoder counts and sensor noise, and
    right while the stage accelerates.

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
    t = record.time
    n = len(t)
    if n < MIN_FIT_SAMPLES:
        raise DataError(f"too short to estimate the initial velocity: {n} sample(s), at least "
                        f"{MIN_FIT_SAMPLES} needed", column="position_m", source=record.source)
    half = max(span / 2.0, 0.5 * (MIN_FIT_SAMPLES - 1) * record.sample_period)
    lo = int(np.searchsorted(t, t[index] - half, side="left"))
    hi = int(np.searchsorted(t, t[index] + half, side="right"))
    if hi - lo < MIN_FIT_SAMPLES:  # at an end: extend to the other side
        lo, hi = max(0, min(lo, n - MIN_FIT_SAMPLES)), min(n, max(hi, MIN_FIT_SAMPLES))
    tau = t[lo:hi] - t[index]
    coef = np.polynomial.polynomial.polyfit(tau, record.position[lo:hi], 2)
    return RecordState(index=int(index), time=float(t[index]),
                       position=float(record.position[index]), velocity=float(coef[1]))


def initial_state(params: PlantParameters, law: ControlLaw, state: RecordState, *,
                  deflection: float | None, command: float | None, reference: tuple[float, ...],
                  feedforward: float) -> tuple[np.ndarray, PlantParameters]:
    """The kernel's initial state for a record, and the parameters with the controller's state.

    Parameters
    ----------
    params : PlantParameters
        Kernel parameters of the model.
    law : ControlLaw
        The loop's controller.
    state : RecordState
        Stage position and velocity from the data.
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

    Returns
    -------
    y0 : ndarray
        Initial state (layout of :func:`fi_design.plant.state_index`).
    params : PlantParameters
        ``params`` with ``x1_initial``, the discrete controller's states
        ``dx1``, ``dx2`` and the command held before t = 0 (``u_initial``).
    """
    iso = bool(params.isolated)
    idx = state_index(iso)
    p = params.to_array()
    x1, v1 = state.position, state.velocity
    sgn = 1.0 if v1 >= 0.0 else -1.0
    y0 = np.zeros(params.n_states)
    y0[idx["x1"]] = x1
    y0[idx["v1"]] = v1
    sigma2 = params.sigma2 if sgn > 0 else p[P_SIGMA2_NEG]
    friction = 0.0
    if v1 != 0.0 and not params.switch_model:
        g, _, _ = kernel().stribeck(v1, x1, sgn, p)
        y0[idx["z"]] = sgn * g / params.sigma0
        friction = sgn * g + sigma2 * v1
    elif v1 != 0.0:
        friction = sgn * kernel().stribeck(v1, x1, sgn, p)[0] + sigma2 * v1
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
    else:
        kf = law.kernel_form()
        v_wo_i = kf["kp"] * e + kf["kd"] * (rd - v1) - kf["kdm"] * v1
        target = v_wo_i if command is None else command - feedforward
        if law.integrator:  # the integrator takes what P and D leave of the first sample
            y0[idx["I"]] = target - v_wo_i
        if not math.isinf(kf["wt"]):  # the filter state is the output itself
            y0[idx["u"]] = target
    if command is not None:
        changes["u_initial"] = command
    return y0, replace(params, **changes)


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
