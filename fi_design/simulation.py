"""One nonlinear simulation of the stage, with or without the isolator.

:func:`simulate` builds the kernel parameters from a spec (PID tuned by the
guideline rule, effects applied), integrates with the fast RODAS4 kernel
(``method="fast"``) or with scipy's solve_ivp on the same equations
(``method="reference"``), and returns a :class:`SimulationResult` with the
traces at the output rate and the hunting metrics.

The two methods share the right-hand side and Jacobian of
:mod:`fi_design.plant` and the mode logic of :mod:`fi_design.kernel`
(the reference locates mode changes with solve_ivp's own event finder), so
the comparison tests the integrator, not a second transcription of the model.
"""

from __future__ import annotations

import math
import time as _time
from dataclasses import dataclass, replace

import numpy as np

from . import effects as _effects
from . import spec as _spec
from .errors import SimulationError
from .metrics import HuntingMetrics, hunting_metrics
from .pid import tune_pid
from .plant import PlantParameters, state_index
from .trajectory import Trajectory, from_moves
from .results import frozen_array, to_jsonable

METHODS = ("fast", "reference")


@dataclass(frozen=True, eq=False)
class SimulationResult:
    """Traces and metrics of one simulation.

    Attributes
    ----------
    isolated : bool
        Whether the isolated (two-mass) plant was simulated.
    method : str
        ``"fast"`` (RODAS4 kernel) or ``"reference"`` (solve_ivp).
    friction_model : str
        ``"lugre"`` or ``"switch"``.
    crossover : float
        Controller crossover the PID was tuned for [Hz].
    effects : tuple of str
        Names of the effects in the model.
    time : ndarray, shape (n,)
        Sample times [s] at the output rate.
    reference : ndarray, shape (n,)
        Reference r [m].
    position : ndarray, shape (n,)
        Stage position x1 [m] (the measured position).
    cart_position : ndarray, shape (n,)
        Cart position x2 [m] (equal to x1 without isolator).
    velocity : ndarray, shape (n,)
        Stage velocity v1 [m/s].
    cart_velocity : ndarray, shape (n,)
        Cart velocity v2 [m/s].
    force : ndarray, shape (n,)
        Commanded actuator force u [N], before delay and saturation.
    applied_force : ndarray, shape (n,)
        Force acting on the stage [N], after delay and saturation.
    bristle : ndarray, shape (n,)
        LuGre bristle deflection z [m] (zero for the switch model).
    success : bool
        Whether the integration reached the end time.
    status : str
        ``"ok"`` or the failure kind.
    message : str
        Failure description with the time reached and a likely cause.
    t_reached : float
        Last time integrated [s].
    n_steps, n_rejected, n_events : int
        Accepted steps, discarded trial steps (rejected by the error test or
        redone to end at a mode change) and mode switches.
    wall_time : float
        Integration time [s] (excluding JIT compilation on first use only if
        the kernel was already compiled).
    metrics : HuntingMetrics
        Hunting metric and verdict of this trace.
    parameters : PlantParameters
        The kernel parameters used.
    """

    isolated: bool
    method: str
    friction_model: str
    crossover: float
    effects: tuple[str, ...]
    time: np.ndarray
    reference: np.ndarray
    position: np.ndarray
    cart_position: np.ndarray
    velocity: np.ndarray
    cart_velocity: np.ndarray
    force: np.ndarray
    applied_force: np.ndarray
    bristle: np.ndarray
    success: bool
    status: str
    message: str
    t_reached: float
    n_steps: int
    n_rejected: int
    n_events: int
    wall_time: float
    metrics: HuntingMetrics
    parameters: PlantParameters

    @property
    def error(self) -> np.ndarray:
        """Position error x1 - r [m]."""
        return self.position - self.reference

    @property
    def deflection(self) -> np.ndarray | None:
        """Joint deflection x1 - x2 [m]; None without isolator."""
        return self.position - self.cart_position if self.isolated else None

    def traces(self) -> dict[str, np.ndarray]:
        """Columns in the measured-data layout (DESIGN.md section 4).

        ``time_s``, ``reference_m``, ``position_m``, ``force_N`` and, for the
        isolated plant, ``deflection_m``.
        """
        cols = {"time_s": self.time, "reference_m": self.reference, "position_m": self.position,
                "force_N": self.force}
        if self.isolated:
            cols["deflection_m"] = self.deflection
        return cols

    def to_dict(self, traces: bool = False) -> dict:
        """Plain JSON data: metadata and metrics; the traces only when asked."""
        from dataclasses import fields

        return {f.name: to_jsonable(getattr(self, f.name)) for f in fields(self)
                if traces or not isinstance(getattr(self, f.name), np.ndarray)}


# --------------------------------------------------------------------------- parameters


def plant_parameters(spec: _spec.Spec, isolated: bool, crossover: float | None = None,
                     effects=None) -> PlantParameters:
    """Kernel parameters of a spec.

    Parameters
    ----------
    spec : Spec
        The design spec.
    isolated : bool
        Two-mass plant with joint and limiters (True) or one rigid mass.
    crossover : float, optional
        Crossover to tune the PID for [Hz]; default the spec's.
    effects : sequence, optional
        Effect entries (spec ``effects`` items) to apply; default the spec's.

    Returns
    -------
    PlantParameters
        PID gains from the nominal masses; effects then change the true
        plant (a mass error does not retune the controller).
    """
    if isolated and spec.isolator is None:
        raise SimulationError("the spec has no isolator: cannot simulate the isolated plant")
    pid = tune_pid(spec, crossover)
    fr = spec.friction
    ctl = spec.controller
    iso = spec.isolator
    if isolated:
        k = _spec.drive_stiffness(spec)
        joint = dict(k=k, c=_spec.joint_damping(spec, k), s=iso.stroke,
                     k_stop=iso.limiter.stiffness, c_stop=_spec.limiter_damping(spec))
    else:
        joint = dict(k=0.0, c=0.0, s=0.0, k_stop=0.0, c_stop=0.0)
    params = PlantParameters(
        m1=spec.stage.mass, m2=spec.cart.mass, **joint,
        Fs=fr.static, Fc=fr.coulomb, vs=fr.stribeck_velocity, sigma0=fr.bristle_stiffness,
        sigma1=_spec.bristle_damping(spec), sigma2=fr.viscous,
        kp=pid.kp, ki=pid.ki, kd=pid.kd, wt=pid.wt, delay=ctl.delay,
        isolated=1.0 if isolated else 0.0, switch_model=1.0 if fr.model == "switch" else 0.0)
    if ctl.sample_rate:
        params = replace(params, sample_period=1.0 / ctl.sample_rate,
                         **_discrete_controller(pid, 1.0 / ctl.sample_rate))
    return apply_effects(params, spec.effects if effects is None else effects)


def apply_effects(params: PlantParameters, entries) -> PlantParameters:
    """Set the kernel parameters of effect entries (neutral values change nothing)."""
    changes: dict[str, float] = {}
    for entry in entries:
        eff = _effects.get(entry.type)
        for par in eff.parameters:
            value = getattr(entry, par.name)
            if value is None:
                continue
            if par.combine == "add":
                value = getattr(params, par.kernel_field) + value
            changes[par.kernel_field] = float(value)
    return replace(params, **changes) if changes else params


def _discrete_controller(pid, Ts: float) -> dict:
    """Tustin discretisation of C(s) = (kd s^2 + kp s + ki) / (s (1 + s/wt))."""
    from scipy.signal import cont2discrete

    wt, kp, ki, kd = pid.wt, pid.kp, pid.ki, pid.kd
    A = np.array([[0.0, 1.0], [0.0, -wt]])
    B = np.array([[0.0], [1.0]])
    C = np.array([[wt * ki, wt * (kp - wt * kd)]])
    D = np.array([[wt * kd]])
    Ad, Bd, Cd, Dd, _ = cont2discrete((A, B, C, D), Ts, method="bilinear")
    return dict(ad11=Ad[0, 0], ad12=Ad[0, 1], ad21=Ad[1, 0], ad22=Ad[1, 1], bd1=Bd[0, 0],
                bd2=Bd[1, 0], cd1=Cd[0, 0], cd2=Cd[0, 1], dd=Dd[0, 0])


def tolerances(params: PlantParameters, rtol: float) -> np.ndarray:
    """Absolute tolerance per state [state units]: ``rtol`` times a physical scale.

    Scales: 1 mm for positions, 1 cm/s for velocities, the presliding range
    Fs / sigma0 for the bristle state, Fs for the controller forces.
    """
    zs = params.Fs / params.sigma0
    if params.isolated:
        scale = [1e-3, 1e-2, 1e-3, 1e-2, zs, params.Fs, params.Fs]
    else:
        scale = [1e-3, 1e-2, zs, params.Fs, params.Fs]
    return rtol * np.array(scale)


# --------------------------------------------------------------------------- simulate


def simulate(spec: _spec.Spec, isolated: bool | None = None, method: str = "fast", *,
             crossover: float | None = None, reference: Trajectory | None = None,
             initial_position: float = 0.0, duration: float | None = None,
             effects=None, rtol: float | None = None) -> SimulationResult:
    """Simulate the stage and evaluate the hunting metric.

    Parameters
    ----------
    spec : Spec
        The design spec.
    isolated : bool, optional
        Simulate the isolated plant (True) or the stage without isolator
        (False); None follows the spec.
    method : {"fast", "reference"}
        RODAS4 kernel, or scipy solve_ivp (Radau, tight tolerance) on the same
        equations for checks and benchmarks.
    crossover : float, optional
        Crossover to tune the PID for [Hz]; default the spec's.
    reference : Trajectory, optional
        A given reference signal (measured data) instead of the spec's moves.
    initial_position : float
        Stage and cart position at t = 0 [m], at rest.
    duration : float, optional
        Simulated time [s]; default ``spec.motion.duration`` (or the end of a
        given reference).
    effects : sequence, optional
        Effect entries replacing the spec's ``effects`` list.
    rtol : float, optional
        Relative tolerance of the chosen method; default
        ``spec.simulation.tolerance`` for the fast path and 1e-4 times it for
        the reference.

    Returns
    -------
    SimulationResult
        Integration failures are reported in ``success``, ``status`` and
        ``message``, never raised.
    """
    if method not in METHODS:
        raise SimulationError(f"method must be one of {METHODS}, got {method!r}")
    iso = spec.has_isolator if isolated is None else bool(isolated)
    params = plant_parameters(spec, iso, crossover, effects)
    params = replace(params, x1_initial=float(initial_position))
    if reference is None:
        t_end = spec.motion.duration if duration is None else duration
        ref = from_moves(spec.motion.moves, t_end)
        if initial_position:
            c = np.array(ref.coeffs)
            c[:, 0] += initial_position
            ref = Trajectory(ref.breaks, c, land=True)
    else:
        ref = reference
        t_end = float(ref.breaks[-1]) if duration is None else duration
    rate = spec.simulation.output_rate
    n_out = int(math.floor(t_end * rate + 1e-9)) + 1
    t_out = np.arange(n_out) / rate
    if rtol is not None:
        tol = rtol
    else:
        tol = spec.simulation.tolerance * (1.0 if method == "fast" else 1e-4)
    n = params.n_states
    y0 = np.zeros(n)
    y0[0] = initial_position
    if iso:
        y0[2] = initial_position
    x_bound = 1.0 + 100.0 * float(np.max(np.abs(ref.coeffs[:, 0])) + abs(initial_position))

    start = _time.perf_counter()
    if method == "fast":
        from .kernel import run  # compiles or loads the kernel on first use

        start = _time.perf_counter()
        out = run(params.to_array(), y0, ref.breaks, ref.coeffs, ref.land, t_end, t_out, tol,
                  tolerances(params, tol), 0.05, spec.simulation.max_steps, x_bound)
    else:
        from .refsolve import solve_reference

        out = solve_reference(params, y0, ref, t_end, t_out, tol, tolerances(params, tol),
                              x_bound)
    wall = _time.perf_counter() - start
    success = out.code == 0
    message = "" if success else _failure_message(out.status, out.t_reached, params, iso)
    Y, R = out.states, out.reference
    idx = state_index(iso)
    metrics = _metrics(spec, t_out, Y[:, idx["x1"]] - R, success, message,
                       spec.motion.end_time if reference is None else 0.0)
    return SimulationResult(
        isolated=iso, method=method, friction_model=spec.friction.model,
        crossover=spec.controller.crossover if crossover is None else float(crossover),
        effects=tuple(e.type for e in (spec.effects if effects is None else effects)),
        time=frozen_array(t_out), reference=frozen_array(R), position=frozen_array(Y[:, idx["x1"]]),
        cart_position=frozen_array(Y[:, idx["x2"]]), velocity=frozen_array(Y[:, idx["v1"]]),
        cart_velocity=frozen_array(Y[:, idx["v2"]]), force=frozen_array(Y[:, idx["u"]]),
        applied_force=frozen_array(out.applied_force), bristle=frozen_array(Y[:, idx["z"]]),
        success=success, status=out.status, message=message, t_reached=out.t_reached,
        n_steps=out.n_steps, n_rejected=out.n_rejected, n_events=out.n_events, wall_time=wall,
        metrics=metrics,
        parameters=params)


def _metrics(spec, t, err, success, message, move_end) -> HuntingMetrics:
    h = spec.requirements.hunting
    return hunting_metrics(t, err, window_start=h.window_start, window_length=h.window_length,
                           min_distance=h.min_distance, min_height=h.min_height,
                           settle_band=h.settle_band, motion_end=move_end, success=success,
                           failure=message)


def _failure_message(status: str, t: float, params: PlantParameters, iso: bool) -> str:
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
    return f"{status} at t = {t:.6g} s; likely cause: {causes.get(status, 'unknown')}"
