"""Reference solution with scipy's solve_ivp on the same equations.

A deliberately plain path for tests and benchmarks: the right-hand side and
Jacobian are those of :mod:`fi_design.kernel.equations`; mode changes (sliding
direction, limiter contact, quantization level, switch-model sticking) are
located by solve_ivp's own event finder, independently of the fast
integrator's event location, and switched by the same compiled
:func:`~fi_design.kernel.equations.switch_mode` the integrator calls; time
events (reference breakpoints, controller samples, delayed outputs) split the
integration.
A continuous delay is integrated by the method of steps: chunks no longer
than the delay, each reading the applied force from the dense output of the
chunks before it.

Slow by design (Python-level calls), exact to tight tolerances.
"""

from __future__ import annotations

import bisect
import math

import numpy as np

from ..trajectory import Trajectory
from .build import compiled
from .layout import (EV_LEVEL, EV_LIMIT, EV_SIGN, EV_UNSTICK, MODE_LEVEL, MODE_LIMIT, MODE_SIGN,
                     MODE_STICK, Integration, PlantParameters, state_index)

#: The solver's terminal events: the mode event (``EV_*``) each is and its direction
#: (:func:`fi_design.kernel.equations.switch_mode`).
EVENTS = {"sign": (EV_SIGN, 0), "unstick": (EV_UNSTICK, 0), "limit+": (EV_LIMIT, 1),
          "limit-": (EV_LIMIT, -1), "limit0": (EV_LIMIT, 0), "level+": (EV_LEVEL, 1),
          "level-": (EV_LEVEL, -1)}


class _History:
    """Controller output u(t) from the dense outputs of finished chunks (u0 before t = 0)."""

    def __init__(self, u0: float, output) -> None:
        self.starts: list[float] = []
        self.pieces: list = []
        self.u0 = u0
        self.output = output  # (t, y, modes) -> controller output

    def add(self, t0: float, sol, modes) -> None:
        self.starts.append(t0)
        self.pieces.append((sol, modes.copy()))

    def __call__(self, t: float) -> float:
        if t <= 0.0 or not self.pieces:
            return self.u0
        k = max(bisect.bisect_right(self.starts, t) - 1, 0)
        sol, modes = self.pieces[k]
        return self.output(t, np.ascontiguousarray(sol(t), dtype=float), modes)


def solve_reference(params: PlantParameters, y0, ref: Trajectory, t_end: float, t_out,
                    rtol: float, atol, x_bound: float, method: str = "Radau",
                    input_time=None, input_force=None):
    """Integrate with solve_ivp; same outputs as :func:`fi_design.kernel.run`.

    ``input_time``, ``input_force``: a known input force added to the
    command, held between its samples [s, N] (None for none). Returns a
    :class:`fi_design.kernel.layout.Integration`: code 0 on success, 3 on a solver
    failure, 4 on divergence.
    """
    from scipy.integrate import solve_ivp

    k = compiled()  # the compiled equations and mode switch
    actuator, controller_output, drive_force = k.actuator, k.controller_output, k.drive_force
    feedforward, jacobian, natural_modes, rhs = k.feedforward, k.jacobian, k.natural_modes, k.rhs
    breakaway, sample_filters = k.breakaway, k.sample_filters
    p = params.to_array()
    n = len(y0)
    iso = bool(params.isolated)
    idx = state_index(iso)
    iv2, ii, iu = idx["v2"], idx["I"], idx["u"]
    Ts = params.sample_period
    delay = params.delay
    discrete = Ts > 0
    fa_state = (not discrete) and delay == 0
    cont_delay = (not discrete) and delay > 0
    sw = bool(params.switch_model)
    q = params.quantization
    s = params.s
    in_t = np.zeros(0) if input_time is None else np.asarray(input_time, dtype=float)
    in_f = np.zeros(0) if input_force is None else np.asarray(input_force, dtype=float)
    # times at which the delayed input changes value
    changes = (in_t[np.r_[True, np.diff(in_f) != 0]] + delay) if len(in_t) else in_t

    t_out = np.asarray(t_out, dtype=float)
    out_y = np.full((len(t_out), n), np.nan)
    out_r = np.full(len(t_out), np.nan)
    out_fa = np.full(len(t_out), np.nan)
    out_cmd = np.full(len(t_out), np.nan)

    y = np.array(y0, dtype=float)
    modes = np.zeros(4, dtype=np.int64)
    modes[MODE_SIGN] = 1
    natural_modes(y, p, modes)
    if sw:
        modes[MODE_STICK] = 1 if y[iv2] == 0.0 else 0
    dx = [params.dx1, params.dx2]
    fa_hold = params.u_initial
    fifo: list[tuple[float, float]] = []
    k_sample = 0
    t = 0.0
    n_steps = n_rej = n_ev = 0
    breaks = list(ref.breaks) if ref.land else []

    def r_of(tt: float) -> tuple[float, float]:
        return ref.at(tt), ref.at(tt, 1)

    def u_of(tt: float, yy, mm) -> float:
        return controller_output(yy, p, mm, *r_of(tt), ii, iu)

    hist = _History(params.u_initial, u_of)

    def input_of(tt: float) -> float:
        k = bisect.bisect_right(in_t, tt + 1e-12 * max(1.0, abs(tt))) - 1
        return float(in_f[k]) if k >= 0 else 0.0

    def extras(tt: float) -> float:
        """Feedforward (continuous controller) plus input force at tt [N]."""
        F = input_of(tt)
        if not discrete:
            F += feedforward(ref.at(tt, 1), ref.at(tt, 2), 0.0, p)[0]
        return F

    def fa_at(tt: float) -> float:
        if fa_state:
            return extras(tt)
        if cont_delay:
            return hist(tt - delay) + extras(tt - delay)
        return fa_hold + input_of(tt - delay)

    def fun(tt, yy):
        yy = np.ascontiguousarray(yy, dtype=float)
        f = np.empty(n)
        rhs(tt, yy, p, modes, *r_of(tt), fa_at(tt), fa_state, f)
        return f

    def jac(tt, yy):
        yy = np.ascontiguousarray(yy, dtype=float)
        J = np.empty((n, n))
        jacobian(tt, yy, p, modes, *r_of(tt), fa_at(tt), fa_state, J)
        return J

    def drive(tt, yy) -> float:
        return drive_force(np.ascontiguousarray(yy, dtype=float), p, modes, *r_of(tt), fa_at(tt),
                           fa_state)

    def events():
        evs = []
        sgn = modes[MODE_SIGN]
        stuck = sw and modes[MODE_STICK] == 1
        if not stuck:
            evs.append(("sign", lambda tt, yy: sgn * yy[iv2], -1))
        if sw and stuck:
            evs.append(("unstick", lambda tt, yy: breakaway(drive(tt, yy), p), 1))
        if iso:
            lim = modes[MODE_LIMIT]
            if lim == 0:
                evs.append(("limit+", lambda tt, yy: yy[0] - yy[2] - s, 1))
                evs.append(("limit-", lambda tt, yy: yy[0] - yy[2] + s, -1))
            elif lim > 0:
                evs.append(("limit0", lambda tt, yy: yy[0] - yy[2] - s, -1))
            else:
                evs.append(("limit0", lambda tt, yy: yy[0] - yy[2] + s, 1))
        if q > 0 and not discrete:
            lev = modes[MODE_LEVEL]
            evs.append(("level+", lambda tt, yy: yy[0] - (lev + 0.5) * q, 1))
            evs.append(("level-", lambda tt, yy: yy[0] - (lev - 0.5) * q, -1))
        funcs = []
        for name, g, direction in evs:
            g.terminal = True
            g.direction = direction
            funcs.append(g)
        return [e[0] for e in evs], funcs

    def write_outputs(t0, t1, sol):
        """Outputs in [t0, t1) from ``sol`` (at t0 only, from the state, when ``sol`` is None):
        those at t1 follow its time events."""
        lo = bisect.bisect_left(t_out, t0 - 1e-12)
        hi = bisect.bisect_left(t_out, t1 - 1e-12) if sol is not None else \
            bisect.bisect_right(t_out, t0 + 1e-12)
        for i in range(lo, hi):
            if not np.isnan(out_r[i]):
                continue
            tt = t_out[i]
            yy = np.ascontiguousarray(sol(tt) if sol is not None else y, dtype=float)
            out_y[i] = yy
            out_r[i] = ref.at(tt)
            if discrete:
                out_cmd[i] = yy[iu] + input_of(tt)
                out_fa[i] = actuator(fa_at(tt), p)[0]
            else:
                out_cmd[i] = u_of(tt, yy, modes) + extras(tt)
                out_fa[i] = actuator(out_cmd[i] if fa_state else fa_at(tt), p)[0]

    status = "ok"
    code = 0
    zero_run = 0

    def time_events(t: float) -> None:
        """The controller's sample and the delayed outputs due at ``t`` (and a stuck cart's
        breakaway): before the outputs at ``t``, the end's too, as the fast integrator."""
        nonlocal k_sample, dx, fa_hold
        if discrete and t >= k_sample * Ts - 1e-12:
            lev = math.floor(y[0] / q + 0.5) if q > 0 else 0
            xm = lev * q if q > 0 else y[0]
            e_k = ref.at(t) - xm
            d_k = -xm if params.dmeas else e_k
            u_k = params.dp * e_k + dx[0] + params.dc * e_k + dx[1] + params.db * d_k
            if params.filter_states:  # the drive's biquads, their memories in y after u
                u_k = sample_filters(u_k, y, p, iu + 1)
            u_k += feedforward(ref.at(t, 1), ref.at(t, 2), 0.0, p)[0]
            dx = [dx[0] + 2.0 * params.dc * e_k,
                  params.da * (dx[1] + params.db * d_k) - params.db * d_k]
            y[iu] = u_k
            y[ii] = dx[0]
            if delay == 0:
                fa_hold = u_k
            else:
                fifo.append((t + delay, u_k))
            k_sample += 1
        while fifo and t >= fifo[0][0] - 1e-12:
            fa_hold = fifo.pop(0)[1]
        if sw and modes[MODE_STICK] == 1:
            F = drive(t, y)
            if breakaway(F, p) > 0:
                modes[MODE_STICK] = 0
                modes[MODE_SIGN] = 1 if F > 0 else -1

    while t < t_end - 1e-12:
        time_events(t)
        write_outputs(t, t, None)
        # next time event
        t_next = t_end
        k = bisect.bisect_right(breaks, t + 1e-12)
        if k < len(breaks):
            t_next = min(t_next, breaks[k])
        if discrete:
            t_next = min(t_next, k_sample * Ts)
        if fifo:
            t_next = min(t_next, fifo[0][0])
        if cont_delay:
            t_next = min(t_next, t + delay)
        k = bisect.bisect_right(changes, t + 1e-12 * max(1.0, t))
        if k < len(changes):
            t_next = min(t_next, changes[k])
        names, funcs = events()
        if zero_run > 2:
            # grazing: the state sits on a switching surface (a cart at rest has
            # no sliding direction); take a short step with the modes the state
            # implies and no state events
            natural_modes(y, p, modes)
            names, funcs = [], []
            t_next = min(t_next, t + 1e-4)
            zero_run = 0
        sol = solve_ivp(fun, (t, t_next), y, method=method, rtol=rtol, atol=atol, jac=jac,
                        events=funcs or None, dense_output=True)
        n_steps += len(sol.t) - 1
        if sol.status == -1:
            code, status = 3, "solver failure: " + sol.message
            break
        t1 = float(sol.t[-1])
        if cont_delay:
            hist.add(t, sol.sol, modes)
        write_outputs(t, t1, sol.sol)
        y = sol.y[:, -1].copy()
        if sol.status == 1:  # an event
            for name, te, ye in zip(names, sol.t_events, sol.y_events):
                if len(te):
                    y = ye[0].copy()
                    t1 = float(te[0])
                    switch(name, y, p, modes, iv2, iu, *r_of(t1), fa_at(t1), fa_state)
                    n_ev += 1
                    zero_run = zero_run + 1 if t1 - t <= 1e-12 * max(1.0, t) else 0
                    break
        t = t1
        if abs(y[0]) > x_bound or not np.all(np.isfinite(y)):
            code, status = 4, "solution diverged"
            break
    if code == 0:
        time_events(t)
        write_outputs(t, t, None)
    return Integration(code=code, status=status, states=out_y, reference=out_r,
                       applied_force=out_fa, command=out_cmd, n_steps=n_steps, n_rejected=n_rej,
                       n_events=n_ev, t_reached=t)


def switch(name: str, y, p, modes, iv2: int, iu: int, r: float, rd: float, fa: float,
           fa_state: bool) -> None:
    """Switch the modes (and jump the state) at the solver's event ``name`` (:data:`EVENTS`).

    The compiled :func:`fi_design.kernel.equations.switch_mode`, the fast
    integrator's own; the arguments are those of that function.
    """
    kind, direction = EVENTS[name]
    compiled().switch_mode(kind, direction, y, p, modes, iv2, iu, r, rd, fa, fa_state)
