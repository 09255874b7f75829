"""The simulation kernel: the nonlinear plant, its fast integrator and its reference solver.

One module a job:

- :mod:`~fi_design.kernel.layout`: the parameter array, the states, the
  modes and mode events, what an integration returns, the watch array
  (plain Python: reading it loads no compiled code);
- :mod:`~fi_design.kernel.equations`: right-hand side, Jacobian, friction,
  controller and the mode switch (compiled);
- :mod:`~fi_design.kernel.integrator`: the RODAS4 integrator with events,
  the delay history, the discrete controller and the watch (compiled);
- :mod:`~fi_design.kernel.metric`: the hunting metric's loops (scipy's peak
  search, one peak per plateau), compiled with the kernel for
  :mod:`fi_design.simulation.metrics`;
- :mod:`~fi_design.kernel.jit`: how numba compiles a kernel function, and
  the signature types;
- :mod:`~fi_design.kernel.build`: the one seam between the source and
  machine code: the ahead-of-time build at install, the digest that ties it
  to the package's files, and the choice of build at run time;
- :mod:`~fi_design.kernel.reference`: scipy's ``solve_ivp`` on the same
  compiled equations and mode switch, for tests and benchmarks.

:func:`run` is the fast integrator's Python entry point.
"""

from __future__ import annotations

import numpy as np

from .layout import (N_STATS, N_WATCH, ST_CROSSINGS, ST_DX1, ST_DX2, ST_EVENTS, ST_HOLD, ST_OUT,
                     ST_PENDING, ST_PERIOD, ST_REJECTED, ST_STEPS, ST_STOP, ST_T, STATUS_TEXT,
                     STOP_TEXT, W_QUIET, W_START, Integration)

__all__ = ["run", "taken"]


def run(params, y0, breaks, coeffs, land, t_end, t_out, rtol, atol, h_max=0.1,
        max_steps=2_000_000, x_bound=10.0, input_time=None, input_force=None, watch=None,
        crossings: int = 0) -> Integration:
    """Allocate outputs and call the integrator (:func:`fi_design.kernel.integrator.integrate`).

    Returns a :class:`fi_design.kernel.layout.Integration`; see ``integrate``
    for the arguments (``input_time``, ``input_force``: the known input
    force's samples [s, N], None for none; ``watch``: the watch array,
    ``W_*`` in :mod:`fi_design.kernel.layout`, None for none; ``crossings``:
    room for this many section crossings). This thin wrapper is the
    integrator's only Python-level entry point, in whichever build
    :func:`fi_design.kernel.build.compiled` chose; :mod:`fi_design.simulation.run`
    wraps it in a result.
    """
    from .build import compiled  # not at import: `python -m fi_design.kernel.build` runs it

    p = taken(params)
    y = taken(y0)
    t_out = taken(t_out)
    in_t = _NO_INPUT if input_time is None else taken(input_time)
    in_f = _NO_INPUT if input_force is None else taken(input_force)
    n = y.shape[0]
    m = t_out.shape[0]
    # the kernel writes every output row up to where it stopped; the rest is NaN (below)
    out_y = np.empty((m, n))
    out_r = np.empty(m)
    out_fa = np.empty(m)
    out_cmd = np.empty(m)
    stats = np.zeros(N_STATS)
    w = _NO_WATCH.copy() if watch is None else np.array(watch, dtype=np.float64)
    k = max(int(crossings), 1)
    cross_t = _nans(k)
    cross_y = _nans((k, n))
    cross_e = _nans((k, 4))
    y_end = _nans(n)
    status = compiled().integrate(
        p, y, taken(breaks), taken(coeffs), bool(land), float(t_end), t_out, float(rtol),
        taken(atol), float(h_max), int(max_steps), float(x_bound), in_t, in_f, out_y, out_r,
        out_fa, out_cmd, stats, w, cross_t, cross_y, cross_e, y_end)
    written = int(stats[ST_OUT])
    if written < m:
        for arr in (out_y, out_r, out_fa, out_cmd):
            arr[written:] = np.nan
    c = int(stats[ST_CROSSINGS])
    return Integration(code=int(status), status=STATUS_TEXT[int(status)], states=out_y,
                       reference=out_r, applied_force=out_fa, command=out_cmd,
                       n_steps=int(stats[ST_STEPS]), n_rejected=int(stats[ST_REJECTED]),
                       n_events=int(stats[ST_EVENTS]), t_reached=float(stats[ST_T]),
                       final_state=y_end, stop=STOP_TEXT[int(stats[ST_STOP])],
                       crossing_times=cross_t[:c], crossing_states=cross_y[:c],
                       crossing_extremes=cross_e[:c, :2], crossing_controller=cross_e[:c, 2:],
                       period_crossings=int(stats[ST_PERIOD]),
                       controller=(float(stats[ST_DX1]), float(stats[ST_DX2]),
                                   float(stats[ST_HOLD]), int(stats[ST_PENDING])))


#: No known input force (an empty series; the integrator reads none of it).
_NO_INPUT = np.zeros(0)

#: The watch array of a run without a watch (copied for each run: the integrator writes it).
_NO_WATCH = np.zeros(N_WATCH)
_NO_WATCH[W_START] = np.inf
_NO_WATCH[W_QUIET] = np.inf


def _nans(shape) -> np.ndarray:
    """``np.full(shape, np.nan)`` without its Python layer."""
    out = np.empty(shape)
    out.fill(np.nan)
    return out


_FLOAT64 = np.dtype(np.float64)


def taken(values) -> np.ndarray:
    """``values`` as the compiled code takes them: float64, C-contiguous and writable (it
    types read-only arrays differently); copied only when they are not (it only reads them).

    ``np.require(values, np.float64, ("C", "W"))``, with its Python-level checks skipped for
    an array that already is (the common case)."""
    if type(values) is np.ndarray and values.dtype == _FLOAT64:
        flags = values.flags
        if flags.c_contiguous and flags.writeable:
            return values
    return np.require(values, dtype=np.float64, requirements=("C", "W"))
