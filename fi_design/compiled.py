"""Which build of the simulation kernel runs, and the integrator's Python entry point.

Two builds of one source (:mod:`fi_design.kernel`, :mod:`fi_design.equations`):

- ``aot``: the extension module compiled when the package was installed
  (:mod:`fi_design.aot`). It loads in a fraction of a millisecond and needs
  neither numba nor a compile, so a first run is as fast as any other.
- ``jit``: numba compiles the source at first use (10-15 s once, then about
  0.5 s to load from numba's cache).

:func:`kernel` takes the extension when it exists and was built from the
sources as they are now (a digest of them is compiled into it), and numba's
JIT otherwise: after an edit of the kernel, without a C compiler at install,
or when ``FI_DESIGN_KERNEL=jit`` asks for it. Both run the same code at the
same speed.
"""

from __future__ import annotations

import functools
import hashlib
import logging
import os
from pathlib import Path
from types import SimpleNamespace

import numpy as np

from .plant import (N_STATS, N_WATCH, ST_CROSSINGS, ST_EVENTS, ST_PERIOD, ST_REJECTED, ST_STEPS,
                    ST_STOP, ST_T, STATUS_TEXT, STOP_TEXT, W_QUIET, W_START, Integration)

log = logging.getLogger(__name__)

#: The kernel's source files: the digest over them ties the built extension to them.
SOURCES = ("_jit.py", "plant.py", "equations.py", "kernel.py")
#: ``jit`` forces numba's JIT of the source even when the extension is current.
BACKEND_ENV = "FI_DESIGN_KERNEL"
#: The functions both builds provide to Python.
FUNCTIONS = ("integrate", "rhs", "jacobian", "natural_modes", "drive_force", "controller_output",
             "actuator", "static_friction", "stribeck", "feedforward")


def source_digest() -> int:
    """A 60-bit digest of the kernel's sources (:data:`SOURCES`) [-]."""
    here = Path(__file__).resolve().parent
    h = hashlib.sha256()
    for name in SOURCES:
        h.update((here / name).read_bytes())
    return int(h.hexdigest()[:15], 16)


@functools.lru_cache(maxsize=1)
def kernel() -> SimpleNamespace:
    """The compiled functions (:data:`FUNCTIONS`) and ``backend`` (``"aot"`` or ``"jit"``)."""
    reason = "asked for by FI_DESIGN_KERNEL=jit"
    if os.environ.get(BACKEND_ENV, "").lower() != "jit":
        try:
            from . import _kernel_aot as aot
        except ImportError:
            reason = "no extension built at install (no C compiler then?)"
        else:
            if aot.source_digest() == source_digest():
                return SimpleNamespace(backend="aot", **{n: getattr(aot, n) for n in FUNCTIONS})
            reason = "the extension was built from other sources (rebuild: python -m fi_design.aot)"
    log.info("simulation kernel: numba's JIT (%s)", reason)
    from . import equations, kernel as source

    return SimpleNamespace(backend="jit", reason=reason,
                           **{n: getattr(source, n, None) or getattr(equations, n)
                              for n in FUNCTIONS})


def backend() -> str:
    """``"aot"`` (the extension built at install) or ``"jit"`` (numba at first use)."""
    return kernel().backend


def run(params, y0, breaks, coeffs, land, t_end, t_out, rtol, atol, h_max=0.1,
        max_steps=2_000_000, x_bound=10.0, input_time=None, input_force=None, watch=None,
        crossings: int = 0) -> Integration:
    """Allocate outputs and call the integrator (:func:`fi_design.kernel.integrate`).

    Returns a :class:`fi_design.plant.Integration`; see ``integrate`` for the
    arguments (``input_time``, ``input_force``: the known input force's
    samples [s, N], None for none; ``watch``: the watch array, ``W_*`` in
    :mod:`fi_design.plant`, None for none; ``crossings``: room for this many
    section crossings). This thin wrapper is the kernel's only Python-level
    entry point; :mod:`fi_design.simulation` wraps it in a result.
    """
    # fresh writable copies: compiled code types read-only arrays differently
    p = np.array(params, dtype=np.float64)
    y = np.array(y0, dtype=np.float64)
    t_out = np.array(t_out, dtype=np.float64)
    in_t = np.zeros(0) if input_time is None else np.array(input_time, dtype=np.float64)
    in_f = np.zeros(0) if input_force is None else np.array(input_force, dtype=np.float64)
    n = y.shape[0]
    m = t_out.shape[0]
    out_y = np.full((m, n), np.nan)
    out_r = np.full(m, np.nan)
    out_fa = np.full(m, np.nan)
    out_cmd = np.full(m, np.nan)
    stats = np.zeros(N_STATS)
    if watch is None:
        w = np.zeros(N_WATCH)
        w[W_START] = np.inf
        w[W_QUIET] = np.inf
    else:
        w = np.array(watch, dtype=np.float64)
    k = max(int(crossings), 1)
    cross_t = np.full(k, np.nan)
    cross_y = np.full((k, n), np.nan)
    cross_e = np.full((k, 2), np.nan)
    y_end = np.full(n, np.nan)
    status = kernel().integrate(
        p, y, np.array(breaks, dtype=np.float64), np.array(coeffs, dtype=np.float64, order="C"),
        bool(land), float(t_end), t_out, float(rtol), np.array(atol, dtype=np.float64),
        float(h_max), int(max_steps), float(x_bound), in_t, in_f, out_y, out_r, out_fa, out_cmd,
        stats, w, cross_t, cross_y, cross_e, y_end)
    c = int(stats[ST_CROSSINGS])
    return Integration(code=int(status), status=STATUS_TEXT[int(status)], states=out_y,
                       reference=out_r, applied_force=out_fa, command=out_cmd,
                       n_steps=int(stats[ST_STEPS]), n_rejected=int(stats[ST_REJECTED]),
                       n_events=int(stats[ST_EVENTS]), t_reached=float(stats[ST_T]),
                       final_state=y_end, stop=STOP_TEXT[int(stats[ST_STOP])],
                       crossing_times=cross_t[:c], crossing_states=cross_y[:c],
                       crossing_extremes=cross_e[:c], period_crossings=int(stats[ST_PERIOD]))
