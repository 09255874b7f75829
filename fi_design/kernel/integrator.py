"""The fast integrator: RODAS4 with events, compiled with numba.

Method (Hairer and Wanner, *Solving ODEs II*, section IV.7): RODAS4, a
six-stage, L-stable, stiffly accurate Rosenbrock method of order 4 with an
embedded order-3 error estimate and a continuous extension of order 3 for
dense output. It uses the analytic Jacobian of :mod:`fi_design.kernel.equations`
(one LU decomposition per step, six back-substitutions) and the explicit time
derivative of the right-hand side, which the reference motion makes
non-autonomous.

Why this method: breakaway of the light cart is a locally unstable fast
transient (real eigenvalues up to about +1.7e3 1/s) next to stiff bristle and
limiter dynamics (down to -1e5 1/s). Explicit or fixed-step methods must use a
step near 1e-4 s everywhere; the adaptive Rosenbrock method resolves the
transients and takes long steps while the stage rests.

Discontinuities are never stepped over:

- *Time events*: steps land exactly on the reference breakpoints (where the
  acceleration jumps), on the sample instants of a discrete controller and on
  the instants its delayed output is applied.
- *State events*: the right-hand side is evaluated with frozen modes (sliding
  direction of the cart, limiter contact, quantization level, switch-model
  stick flag), so it is smooth within a step. When a trial step ends in a
  different mode, the crossing is located on the dense output (Illinois
  method), the step is redone to end there and the mode switches. Guards
  stop grazing contacts and creep velocities that touch zero from forcing
  ever-shorter steps: a crossing located at the very start of a step switches
  the mode without stepping, and a run of such switches falls back to the
  modes the state implies.
- *Delay*: the applied force u(t - delay) comes from a history of the
  controller output (cubic Hermite between accepted steps); steps are capped
  at the delay so every stage only needs the past.
- *Input force*: a known force (a measured disturbance, or the whole measured
  force of an open-loop replay) given as samples held constant between them
  (zero-order hold) is added to the command; steps land on its samples.

Failures (step budget exhausted, step-size underflow, NaN, divergence,
history overflow) end the run with a status code and the time reached; the
caller reports them, never silent garbage.

Compilation: this module is the kernel's source. Installing the package
compiles it ahead of time into an extension module (:mod:`fi_design.kernel.build`),
which :func:`fi_design.kernel.run` calls; this module is then never imported.
Where that build is missing or older than the source, numba compiles it
here instead: every function has an explicit signature, so it compiles once,
at import, and numba caches it on disk (``cache=True``) in the package's
``__pycache__`` (or, in a read-only install, the user-wide
``~/.cache/numba`` or ``$NUMBA_CACHE_DIR``). A cold compile takes about
10-15 s on a 2-core machine, loading from the cache about 0.5 s.
"""

from __future__ import annotations

import math

import numpy as np

from .equations import (actuator, breakaway, control_law, controller_output, drive_force,
                        feedforward, filter_output_rate, filter_time_rate, jacobian, limit_mode,
                        measured_position, natural_modes, pass_quantizer, quantized, rhs,
                        sample_filters, switch_mode)
from .jit import A1, A2, I1, b1, f8, i8, kernel_function
from .layout import (DIVERGED, EV_LEVEL, EV_LIMIT, EV_NONE, EV_SECTION, EV_SIGN, EV_UNSTICK,
                     HISTORY_OVERFLOW, LEVEL_FREE, MAX_PERIOD, MODE_LEVEL, MODE_LIMIT, MODE_SIGN,
                     MODE_STICK, N_CORE_ISO, N_CORE_RIGID, N_STATS, NOT_FINITE, OK, P_DA, P_DB,
                     P_DC, P_DELAY, P_NF, P_QFREE, P_DMEAS, P_DP, P_DX1, P_DX2, P_FF_C, P_FF_F,
                     P_FF_M, P_ISO, P_KD, P_KDM,
                     P_KI, P_KP, P_M1, P_M2, P_QUANT, P_S, P_SWITCH, P_TS, P_U0, P_WT,
                     ST_CROSSINGS, ST_DX1, ST_DX2, ST_EVENTS, ST_H, ST_HOLD, ST_LIMIT_EVENTS,
                     ST_OUT, ST_PENDING, ST_PERIOD, ST_REJECTED, ST_STEPS, ST_STOP, ST_T,
                     ST_ZERO_EVENTS, STEP_UNDERFLOW,
                     STOP_CROSSINGS, STOP_END, STOP_MATCH, STOP_QUIET, STOP_REPEAT,
                     TOO_MANY_STEPS, W_ARM, W_BAND, W_LEVEL, W_MATCH, W_MAX_CROSSINGS, W_QUIET,
                     W_REPEAT, W_REST_ANYWHERE, W_START, N_WATCH)

HIST = 8192  # delay history ring size
HT, HU, HDU, HUR, HDUR = range(5)  # rows of the history: time, value and rate in, out
H_REF, H_FF, H_IN, H_OUT = range(4)  # search hints: reference, delayed reference, input, output
N_HINTS = 4
FIFO = 256  # pending discrete outputs (delay / sample period < FIFO)

# RODAS4 coefficients (Hairer and Wanner, rodas.f, METH = 1).
GAMMA = 0.25
C2, C3, C4 = 0.386, 0.21, 0.63
D1, D2, D3, D4 = 0.25, -0.1043, 0.1035, -0.3620000000000023e-01
A21 = 0.1544000000000000e+01
A31, A32 = 0.9466785280815826e+00, 0.2557011698983284e+00
A41, A42, A43 = 0.3314825187068521e+01, 0.2896124015972201e+01, 0.9986419139977817e+00
A51, A52, A53, A54 = (0.1221224509226641e+01, 0.6019134481288629e+01, 0.1253708332932087e+02,
                      -0.6878860361058950e+00)
C21 = -0.5668800000000000e+01
C31, C32 = -0.2430093356833875e+01, -0.2063599157091915e+00
C41, C42, C43 = -0.1073529058151375e+00, -0.9594562251023355e+01, -0.2047028614809616e+02
C51, C52, C53, C54 = (0.7496443313967647e+01, -0.1024680431464352e+02, -0.3399990352819905e+02,
                      0.1170890893206160e+02)
C61, C62, C63, C64, C65 = (0.8083246795921522e+01, -0.7981132988064893e+01,
                           -0.3152159432874371e+02, 0.1631930543123136e+02,
                           -0.6058818238834054e+01)
DD21, DD22, DD23, DD24, DD25 = (0.1012623508344586e+02, -0.7487995877610167e+01,
                                -0.3480091861555747e+02, -0.7992771707568823e+01,
                                0.1025137723295662e+01)
DD31, DD32, DD33, DD34, DD35 = (-0.6762803392801253e+00, 0.6087714651680015e+01,
                                0.1643084320892478e+02, 0.2476722511418386e+02,
                                -0.6594389125716872e+01)

SAFE = 0.9
FAC_MIN = 0.2  # hnew / h >= 0.2
FAC_MAX = 6.0  # hnew / h <= 6


# --------------------------------------------------------------------------- small helpers


@kernel_function((f8, A1, A2, i8), inline=True)
def _reference_at(t, breaks, coeffs, k):
    """:func:`reference_at`, inlined where the integrator steps and writes its outputs: as a
    call there it made the integrator a third slower (around a call the caller keeps its
    live values in memory)."""
    nseg = coeffs.shape[0]
    if t >= breaks[nseg]:
        k = nseg - 1
        tau = breaks[nseg] - breaks[k]
        c0, c1, c2, c3 = coeffs[k, 0], coeffs[k, 1], coeffs[k, 2], coeffs[k, 3]
        return c0 + tau * (c1 + tau * (c2 + tau * c3)), 0.0, 0.0, 0.0, k
    if t < breaks[0]:
        return coeffs[0, 0], 0.0, 0.0, 0.0, 0
    while k < nseg - 1 and t >= breaks[k + 1]:
        k += 1
    while k > 0 and t < breaks[k]:
        k -= 1
    tau = t - breaks[k]
    c0, c1, c2, c3 = coeffs[k, 0], coeffs[k, 1], coeffs[k, 2], coeffs[k, 3]
    r = c0 + tau * (c1 + tau * (c2 + tau * c3))
    rd = c1 + tau * (2.0 * c2 + 3.0 * tau * c3)
    rdd = 2.0 * c2 + 6.0 * tau * c3
    return r, rd, rdd, 6.0 * c3, k


@kernel_function((f8, A1, A2, i8))
def reference_at(t, breaks, coeffs, k):
    """Reference position, velocity, acceleration and jerk at ``t``, and the segment index.

    ``k`` is a hint (the last segment used); the search walks from there.
    Before the first break the reference holds ``coeffs[0, 0]`` and after the
    last its end value, at rest; at a break it takes the values of the segment
    that starts there (right-continuous).
    """
    return _reference_at(t, breaks, coeffs, k)


@kernel_function((f8, A1, A1, i8))
def input_at(t, in_t, in_f, j):
    """Known input force at ``t`` [N], held from sample to sample, and the sample index.

    ``in_t`` (increasing) and ``in_f`` are the samples; before the first the
    input is 0, after the last it holds. ``j`` is a hint; a time within a
    relative 1e-12 of a sample counts as at the sample (steps land there).
    """
    m = in_t.shape[0]
    if m == 0 or t < in_t[0] - 1e-12 * max(1.0, abs(t)):
        return 0.0, 0
    if j < 0:
        j = 0
    while j < m - 1 and t >= in_t[j + 1] - 1e-12 * max(1.0, abs(t)):
        j += 1
    while j > 0 and t < in_t[j] - 1e-12 * max(1.0, abs(t)):
        j -= 1
    return in_f[j], j


@kernel_function((f8, A1, A1, A2, i8, A1, A1, i8, b1))
def extra_at(tq, p, breaks, coeffs, kref, in_t, in_f, j, with_ff):
    """The command's parts beyond the feedback at ``tq``: feedforward and input force.

    Returns ``(F, dF/dt, kref, j)`` [N, N/s] with the updated hints. The
    feedforward is included when ``with_ff`` (a continuous controller; a
    discrete one adds it at its samples).
    """
    F = 0.0
    dF = 0.0
    if with_ff:
        _, rd, rdd, r3, kref = reference_at(tq, breaks, coeffs, kref)
        F, dF = feedforward(rd, rdd, r3, p)
    if in_t.shape[0] > 0:
        fin, j = input_at(tq, in_t, in_f, j)
        F += fin
    return F, dF, kref, j


@kernel_function((A1, A1, I1, f8, f8, f8, A1, i8))
def law_rate(y, p, modes, r, rd, rdd, f, ii):
    """Time derivative of the unfiltered continuous controller output v [N/s].

    ``f`` is the right-hand side at the state ``y`` (for the acceleration).
    """
    _, _, _, e = control_law(y, p, modes, r, rd, ii)
    quant = quantized(p, modes)
    xd = 0.0 if quant else y[1]
    xdd = 0.0 if quant else f[1]
    return p[P_KI] * e + p[P_KP] * (rd - xd) + p[P_KD] * (rdd - xdd) - p[P_KDM] * xdd


@kernel_function((A2, I1, i8), inline=True)
def _lu(A, piv, n):
    """:func:`lu_factor` of the leading ``n`` x ``n`` block (inlined: a constant ``n``
    unrolls its loops)."""
    for k in range(n):
        m = k
        big = abs(A[k, k])
        for i in range(k + 1, n):
            if abs(A[i, k]) > big:
                big = abs(A[i, k])
                m = i
        piv[k] = m
        if big == 0.0:
            return False
        if m != k:
            for j in range(n):
                tmp = A[k, j]
                A[k, j] = A[m, j]
                A[m, j] = tmp
        inv = 1.0 / A[k, k]
        for i in range(k + 1, n):
            A[i, k] *= inv
            lik = A[i, k]
            if lik != 0.0:
                for j in range(k + 1, n):
                    A[i, j] -= lik * A[k, j]
    return True


@kernel_function((A2, I1))
def lu_factor(A, piv):
    """In-place LU decomposition with partial pivoting; returns False if singular."""
    return _lu(A, piv, A.shape[0])


@kernel_function((A2, f8, A2, I1, A2, i8), inline=True)
def _struct_factor(J, sigma, M, piv, w, nc):
    """:func:`struct_factor` with a core of ``nc`` states."""
    iz = nc
    ii = nc + 1
    iu = nc + 2
    dI = 1.0 / (sigma - J[ii, ii])
    du = 1.0 / (sigma - J[iu, iu])
    dz = 1.0 / (sigma - J[iz, iz])
    w[3, 0] = dI
    w[3, 1] = du
    w[3, 2] = dz
    for c in range(nc):
        cI = J[ii, c] * dI
        w[0, c] = cI
        w[1, c] = (J[iu, c] + J[iu, ii] * cI) * du
        w[2, c] = J[iz, c] * dz
    for i in range(nc):
        for c in range(nc):
            v = -J[i, c] - J[i, iu] * w[1, c] - J[i, iz] * w[2, c] - J[i, ii] * w[0, c]
            if i == c:
                v += sigma
            M[i, c] = v
    if not _lu(M, piv, nc):
        return False
    # the diagonal of U as its reciprocal: the six solves of a step multiply instead of
    # dividing (a division's latency, four in a row per solve, was much of their time)
    for i in range(nc):
        M[i, i] = 1.0 / M[i, i]
    return True


@kernel_function((A2, f8, A2, I1, A2), inline=True)
def struct_factor(J, sigma, M, piv, w):
    """Factor E = sigma I - J using the plant's structure.

    The last three states (bristle z, integrator I, controller output u) are
    "leaves": each depends only on the mechanical core and itself (u also on
    I), and the core sees them through its own rows of J. Eliminating them
    leaves a Schur complement on the core (4 x 4 isolated, 2 x 2 rigid),
    factored with partial pivoting, U's diagonal stored as its reciprocal.
    ``w`` (shape (4, max(nc, 3))) keeps the elimination coefficients for
    :func:`struct_solve`. Returns False if singular.

    Each plant's core size is a constant in its branch (:func:`_struct_factor`
    inlined), so the small loops unroll; this function is inlined into
    :func:`factor_e` in turn.
    """
    if J.shape[0] - 3 == N_CORE_RIGID:
        return _struct_factor(J, sigma, M, piv, w, N_CORE_RIGID)
    return _struct_factor(J, sigma, M, piv, w, N_CORE_ISO)


@kernel_function((A2, A2, I1, A2, A1, A1, i8), inline=True)
def _struct_solve(J, M, piv, w, b, tmp, nc):
    """:func:`struct_solve` with a core of ``nc`` states."""
    iz = nc
    ii = nc + 1
    iu = nc + 2
    gI = b[ii] * w[3, 0]
    gu = (b[iu] + J[iu, ii] * gI) * w[3, 1]
    gz = b[iz] * w[3, 2]
    for i in range(nc):
        tmp[i] = b[i] + J[i, iu] * gu + J[i, iz] * gz + J[i, ii] * gI
    # forward and back substitution on the core
    for k in range(nc):
        m = piv[k]
        if m != k:
            t = tmp[k]
            tmp[k] = tmp[m]
            tmp[m] = t
    for i in range(nc):
        s = tmp[i]
        for j in range(i):
            s -= M[i, j] * tmp[j]
        tmp[i] = s
    for i in range(nc - 1, -1, -1):
        s = tmp[i]
        for j in range(i + 1, nc):
            s -= M[i, j] * tmp[j]
        tmp[i] = s * M[i, i]  # the reciprocal of U's diagonal (struct_factor)
    yI = gI
    yu = gu
    yz = gz
    for c in range(nc):
        x = tmp[c]
        b[c] = x
        yI += w[0, c] * x
        yu += w[1, c] * x
        yz += w[2, c] * x
    b[ii] = yI
    b[iu] = yu
    b[iz] = yz


@kernel_function((A2, A2, I1, A2, A1, A1), inline=True)
def struct_solve(J, M, piv, w, b, tmp):
    """Solve (sigma I - J) x = b in place with the factors of :func:`struct_factor`
    (the core's size a constant in each branch, as there)."""
    if J.shape[0] - 3 == N_CORE_RIGID:
        _struct_solve(J, M, piv, w, b, tmp, N_CORE_RIGID)
    else:
        _struct_solve(J, M, piv, w, b, tmp, N_CORE_ISO)


@kernel_function((A2, f8, A2, I1, A2, b1))
def factor_e(J, sigma, M, piv, w, full):
    """Factor E = sigma I - J: by its structure (:func:`struct_factor`), or, with ``full``
    (a plant with the filter chain's states after the leaves), as a dense LU with U's
    diagonal as its reciprocal. Returns False if singular."""
    if not full:
        return struct_factor(J, sigma, M, piv, w)
    n = J.shape[0]
    for i in range(n):
        for j in range(n):
            M[i, j] = -J[i, j]
        M[i, i] += sigma
    if not lu_factor(M, piv):
        return False
    for i in range(n):
        M[i, i] = 1.0 / M[i, i]
    return True


@kernel_function((A2, A2, I1, A2, A1, A1, b1))
def solve_e(J, M, piv, w, b, tmp, full):
    """Solve (sigma I - J) x = b in place with the factors of :func:`factor_e`."""
    if not full:
        struct_solve(J, M, piv, w, b, tmp)
        return
    n = b.shape[0]
    for k in range(n):
        m = piv[k]
        if m != k:
            t = b[k]
            b[k] = b[m]
            b[m] = t
    for i in range(n):
        s = b[i]
        for j in range(i):
            s -= M[i, j] * b[j]
        b[i] = s
    for i in range(n - 1, -1, -1):
        s = b[i]
        for j in range(i + 1, n):
            s -= M[i, j] * b[j]
        b[i] = s * M[i, i]


@kernel_function((A1, A1, A1, A1, f8, A1))
def dense(y0, y1, k2, k3, theta, out):
    """RODAS4 continuous extension at ``theta`` in [0, 1] into ``out``."""
    s1 = 1.0 - theta
    for i in range(y0.shape[0]):
        out[i] = y0[i] * s1 + theta * (y1[i] + s1 * (k2[i] + theta * k3[i]))


@kernel_function((A1, A1, A1, A1, f8, i8))
def dense_component(y0, y1, k2, k3, theta, i):
    """One component of :func:`dense`."""
    s1 = 1.0 - theta
    return y0[i] * s1 + theta * (y1[i] + s1 * (k2[i] + theta * k3[i]))


@kernel_function((f8, A2, i8, i8, f8))
def history_at(tq, hist, head, count, u_before):
    """Delayed controller output u(tq) and its rate from the history ring.

    Each entry i holds the time (row ``HT``), the value and rate arriving from
    the left (``HU``, ``HDU``) and leaving to the right (``HUR``, ``HDUR``),
    which differ only where u jumps. Before t = 0 the output is
    ``u_before``. Returns ``(u, du, ok)``; ``ok`` is False when ``tq`` is
    older than the oldest entry.
    """
    if count == 0 or tq <= 0.0:
        return u_before, 0.0, True
    newest = (head - 1) % HIST
    if tq >= hist[HT, newest]:
        return hist[HUR, newest], hist[HDUR, newest], True
    oldest = (head - count) % HIST
    if tq < hist[HT, oldest]:
        return 0.0, 0.0, False
    lo = 0
    hi = count - 1  # logical indices; entry lo <= tq < entry hi
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if hist[HT, (head - count + mid) % HIST] <= tq:
            lo = mid
        else:
            hi = mid
    a = (head - count + lo) % HIST
    b = (head - count + hi) % HIST
    h = hist[HT, b] - hist[HT, a]
    if h <= 0.0:
        return hist[HUR, b], hist[HDUR, b], True
    s = (tq - hist[HT, a]) / h
    u0 = hist[HUR, a]
    u1 = hist[HU, b]
    m0 = hist[HDUR, a] * h
    m1 = hist[HDU, b] * h
    s2 = s * s
    s3 = s2 * s
    u = (2 * s3 - 3 * s2 + 1) * u0 + (s3 - 2 * s2 + s) * m0 + (-2 * s3 + 3 * s2) * u1 + (s3 - s2) * m1
    du = ((6 * s2 - 6 * s) * u0 + (3 * s2 - 4 * s + 1) * m0 + (-6 * s2 + 6 * s) * u1
          + (3 * s2 - 2 * s) * m1) / h
    return u, du, True


# --------------------------------------------------------------------------- events


@kernel_function((f8, f8, A1, A1, A1, A1, i8, i8, i8, f8, A1, I1, f8, f8, f8, b1, A1))
def _root(g0, g1, y0, y1, k2, k3, kind, idx, idx2, offset, p, modes, r, rd, fa, fa_state, ybuf):
    """Locate the zero of a switching function on the dense output, theta in [0, 1].

    kind 0: y[idx] - offset; kind 1: y[idx] - y[idx2] - offset;
    kind 2: :func:`breakaway` of the drive force (switch model).
    """
    a, b = 0.0, 1.0
    ga, gb = g0, g1
    side = 0
    theta = 1.0
    for _ in range(60):
        theta = (a * gb - b * ga) / (gb - ga)
        if not (theta > a and theta < b):
            theta = 0.5 * (a + b)
        if kind == 0:
            g = dense_component(y0, y1, k2, k3, theta, idx) - offset
        elif kind == 1:
            g = (dense_component(y0, y1, k2, k3, theta, idx)
                 - dense_component(y0, y1, k2, k3, theta, idx2) - offset)
        else:
            dense(y0, y1, k2, k3, theta, ybuf)
            g = breakaway(drive_force(ybuf, p, modes, r, rd, fa, fa_state), p)
        if g == 0.0:
            return theta
        if (g > 0.0) == (gb > 0.0):
            b = theta
            gb = g
            if side == 1:
                ga *= 0.5
            side = 1
        else:
            a = theta
            ga = g
            if side == -1:
                gb *= 0.5
            side = -1
        if b - a < 1e-12:
            break
    return b


@kernel_function((A1, A1, A1, A1, A1, I1, i8, f8, f8, f8, b1, A1, i8))
def find_event(y0, y1, k2, k3, p, modes, iv2, r, rd, fa, fa_state, ybuf, skip):
    """Earliest mode change within a trial step.

    Returns ``(kind, theta)``: the event kind (``EV_*``) and where it happens
    as a fraction of the step. ``skip`` is an event kind to ignore (the one
    the step was shortened to reach). ``r``, ``rd`` and ``fa`` are taken at
    the start of the step.
    """
    best = EV_NONE
    tbest = 2.0
    iso = p[P_ISO] != 0.0
    sw = p[P_SWITCH] != 0.0
    sgn = modes[MODE_SIGN]
    # sliding direction (LuGre |v|) or switch-model velocity reversal
    stuck = sw and modes[MODE_STICK] == 1
    if not stuck and skip != EV_SIGN:
        v0 = y0[iv2] * sgn
        v1 = y1[iv2] * sgn
        if v1 < 0.0:
            th = 0.0 if v0 < 0.0 else _root(v0, v1, y0, y1, k2, k3, 0, iv2, 0, 0.0, p, modes, r,
                                            rd, fa, fa_state, ybuf)
            if th < tbest:
                tbest = th
                best = EV_SIGN
    if sw and stuck and skip != EV_UNSTICK:
        g1 = breakaway(drive_force(y1, p, modes, r, rd, fa, fa_state), p)
        if g1 > 0.0:
            g0 = breakaway(drive_force(y0, p, modes, r, rd, fa, fa_state), p)
            th = 0.0 if g0 > 0.0 else _root(g0, g1, y0, y1, k2, k3, 2, 0, 0, 0.0, p, modes, r, rd,
                                            fa, fa_state, ybuf)
            if th < tbest:
                tbest = th
                best = EV_UNSTICK
    if iso and skip != EV_LIMIT:
        s = p[P_S]
        lim = modes[MODE_LIMIT]
        d1 = y1[0] - y1[2]
        l1 = limit_mode(d1, s)
        if l1 != lim:
            d0 = y0[0] - y0[2]
            # boundary crossed first when leaving `lim` towards l1
            if lim == 1 or (lim == 0 and l1 == 1):
                off = s
            else:
                off = -s
            g0 = d0 - off
            g1 = d1 - off
            if limit_mode(d0, s) != lim or g0 == 0.0 or (g0 > 0.0) == (g1 > 0.0):
                th = 0.0
            else:
                th = _root(g0, g1, y0, y1, k2, k3, 1, 0, 2, off, p, modes, r, rd, fa, fa_state,
                           ybuf)
            if th < tbest:
                tbest = th
                best = EV_LIMIT
    q = p[P_QUANT]
    if q > 0.0 and p[P_TS] == 0.0 and skip != EV_LEVEL and modes[MODE_LEVEL] != LEVEL_FREE:
        lev = modes[MODE_LEVEL]
        l1 = int(math.floor(y1[0] / q + 0.5))
        free = p[P_QFREE]
        if free > 0.0 and (l1 - lev > free or lev - l1 > free):
            # a fast move: the quantizer is passed through from the step's start
            tbest = 0.0
            best = EV_LEVEL
        elif l1 != lev:
            off = (lev + 0.5) * q if l1 > lev else (lev - 0.5) * q
            g0 = y0[0] - off
            g1 = y1[0] - off
            l0 = int(math.floor(y0[0] / q + 0.5))
            if l0 != lev or g0 == 0.0 or (g0 > 0.0) == (g1 > 0.0):
                th = 0.0
            else:
                th = _root(g0, g1, y0, y1, k2, k3, 0, 0, 0, off, p, modes, r, rd, fa, fa_state,
                           ybuf)
            if th < tbest:
                tbest = th
                best = EV_LEVEL
    return best, tbest


@kernel_function((i8, A1, A1, I1, i8, i8, f8, f8, f8, b1, A1))
def apply_event(kind, y, p, modes, iv2, iu, r, rd, fa, fa_state, y_trial):
    """Switch the modes for event ``kind`` at the current state ``y`` (jumps included).

    ``y_trial`` is the end of the trial step that detected the event: it tells
    the direction of limiter and quantization crossings, which
    :func:`fi_design.kernel.equations.switch_mode` then applies.
    """
    direction = 0
    if kind == EV_LIMIT:
        direction = limit_mode(y_trial[0] - y_trial[2], p[P_S])
    elif kind == EV_LEVEL:
        if modes[MODE_LEVEL] == LEVEL_FREE:  # the stage slowed: quantized again
            pass_quantizer(y, p, modes, iu, False)
            return
        level = int(math.floor(y_trial[0] / p[P_QUANT] + 0.5))
        free = p[P_QFREE]
        if free > 0.0 and (level - modes[MODE_LEVEL] > free or modes[MODE_LEVEL] - level > free):
            pass_quantizer(y, p, modes, iu, True)
            return
        direction = 1 if level > modes[MODE_LEVEL] else -1
    switch_mode(kind, direction, y, p, modes, iv2, iu, r, rd, fa, fa_state)


# --------------------------------------------------------------------------- commands


@kernel_function((f8, A1, A1, A2, A1, A1, I1, f8, A2, i8, i8))
def stage_command(ts, p, breaks, coeffs, in_t, in_f, hints, fa_hold, hist, head, count):
    """The ``fa`` argument of :func:`fi_design.kernel.equations.rhs` at time ``ts``, and its rate.

    Continuous controller without delay: the command's parts beyond the
    controller output (feedforward, input force). With a delay: the whole
    command ``delay`` earlier (controller output from the history, plus those
    parts then). Discrete controller: the held output plus the input force
    ``delay`` earlier. Returns ``(fa, dfa/dt, ok)`` [N, N/s]; ``ok`` is False
    when the history no longer reaches back far enough. ``hints`` holds the
    search hints of the lookups (updated).
    """
    discrete = p[P_TS] > 0.0
    delay = p[P_DELAY]
    tq = ts - delay
    if discrete:
        if in_t.shape[0] == 0:
            return fa_hold, 0.0, True
        fin, j = input_at(tq, in_t, in_f, hints[H_IN])
        hints[H_IN] = j
        return fa_hold + fin, 0.0, True
    with_ff = p[P_FF_M] != 0.0 or p[P_FF_C] != 0.0 or p[P_FF_F] != 0.0
    F, dF, kff, j = extra_at(tq, p, breaks, coeffs, hints[H_FF], in_t, in_f, hints[H_IN], with_ff)
    hints[H_FF] = kff
    hints[H_IN] = j
    if delay == 0.0:
        return F, dF, True
    u, du, ok = history_at(tq, hist, head, count, p[P_U0])
    return u + F, du + dF, ok


@kernel_function((i8, f8, A1, A1, I1, A1, A2, A1, A1, I1, f8, A2, i8, i8, b1, A2, A1, A1, A1))
def write_output(i, tq, yq, p, modes, breaks, coeffs, in_t, in_f, hints, fa_hold, hist, head,
                 count, need_cmd, out_y, out_r, out_fa, out_cmd):
    """Store the state ``yq`` at output time ``tq`` as output row ``i``, with r and the forces.

    ``out_cmd`` gets the commanded force (controller output plus feedforward
    plus input force, before delay and saturation), ``out_fa`` the force
    applied to the stage. ``need_cmd`` false (a continuous controller without
    delay, feedforward or input force) takes the short way: the command is
    the controller's output.
    """
    n = yq.shape[0]
    nc = N_CORE_ISO if p[P_ISO] != 0.0 else N_CORE_RIGID
    ii = nc + 1
    iu = nc + 2
    for j in range(n):
        out_y[i, j] = yq[j]
    rr, rdr, _, _, kout = reference_at(tq, breaks, coeffs, hints[H_OUT])
    hints[H_OUT] = kout
    out_r[i] = rr
    if not need_cmd:
        uc = controller_output(yq, p, modes, rr, rdr, ii, iu)
        out_cmd[i] = uc
        out_fa[i], _ = actuator(uc, p)
        return
    discrete = p[P_TS] > 0.0
    fa, _, _ = stage_command(tq, p, breaks, coeffs, in_t, in_f, hints, fa_hold, hist, head,
                             count)
    if discrete:
        fin = 0.0
        if in_t.shape[0] > 0:
            fin, _ = input_at(tq, in_t, in_f, hints[H_IN])
        out_cmd[i] = yq[iu] + fin
        out_fa[i], _ = actuator(fa, p)
        return
    uc = controller_output(yq, p, modes, rr, rdr, ii, iu)
    if p[P_DELAY] == 0.0:
        out_cmd[i] = uc + fa
        out_fa[i], _ = actuator(uc + fa, p)
        return
    with_ff = p[P_FF_M] != 0.0 or p[P_FF_C] != 0.0 or p[P_FF_F] != 0.0
    F, _, _, _ = extra_at(tq, p, breaks, coeffs, hints[H_OUT], in_t, in_f, hints[H_IN], with_ff)
    out_cmd[i] = uc + F
    out_fa[i], _ = actuator(fa, p)


# --------------------------------------------------------------------------- the integrator


@kernel_function((A1, A1, A1, A2, b1, f8, A1, f8, A1, f8, i8, f8, A1, A1, A2, A1, A1, A1, A1,
                  A1, A1, A2, A2, A1), refcounted=True)
def integrate(p, y0, breaks, coeffs, land, t_end, t_out, rtol, atol, h_max, max_steps, x_bound,
              in_t, in_f, out_y, out_r, out_fa, out_cmd, stats, watch, cross_t, cross_y,
              cross_e, y_end):
    """Integrate the plant from ``y0`` at t = 0 to ``t_end``.

    Parameters
    ----------
    p : ndarray, float64
        Plant parameters (:class:`fi_design.kernel.layout.PlantParameters`).
    y0 : ndarray, float64, shape (n,)
        Initial state (7 isolated, 5 rigid).
    breaks, coeffs : ndarray
        Reference as a piecewise cubic (:class:`fi_design.trajectory.Trajectory`).
    land : bool
        Land steps on the reference breaks.
    t_end : float
        Final time [s].
    t_out : ndarray, shape (m,)
        Increasing output times [s] within [0, t_end].
    rtol : float
        Relative tolerance.
    atol : ndarray, shape (n,)
        Absolute tolerance per state component (state units).
    h_max : float
        Largest step [s].
    max_steps : int
        Step budget (accepted and rejected).
    x_bound : float
        |x1| beyond which the solution counts as diverged [m].
    in_t, in_f : ndarray, shape (k,)
        Known input force added to the command, held between its samples:
        sample times [s] (increasing) and values [N]; empty for none.
    out_y : ndarray, shape (m, n)
        Output: states at ``t_out``.
    out_r : ndarray, shape (m,)
        Output: reference at ``t_out`` [m].
    out_fa : ndarray, shape (m,)
        Output: applied actuator force at ``t_out`` [N] (after delay and
        saturation).
    out_cmd : ndarray, shape (m,)
        Output: commanded force at ``t_out`` [N] (controller output,
        feedforward and input force, before delay and saturation).
    stats : ndarray, shape (N_STATS,)
        Output: counters (``ST_*``).
    watch : ndarray, shape (N_WATCH + k n,)
        What to watch for once the motion is over (``W_*`` in
        :mod:`fi_design.kernel.layout`): from ``watch[W_START]`` on, the upward
        crossings of x1 - r = 0 (r = ``watch[W_LEVEL]``, the held reference)
        are located like mode events (the step is redone to end on them) and
        recorded, and the run stops early when the stage has come to rest (the
        quiet rule), its motion repeats at the section (the repeat rule) or its
        state at the section matches a known one (the match rule: the known
        states follow the ``N_WATCH`` values).
        ``watch[W_START] = inf`` turns it off.
    cross_t : ndarray, shape (K,)
        Output: times of the crossings [s] (the first ``stats[ST_CROSSINGS]``).
    cross_y : ndarray, shape (K, n)
        Output: states at the crossings.
    cross_e : ndarray, shape (K, 4)
        Output: smallest and largest x1 - r at the step ends since the
        crossing before (since the watch's start for the first) [m], and a
        discrete controller's ``dx2`` and held output at the crossing [N].
    y_end : ndarray, shape (n,)
        Output: the state where the run ended.

    Returns
    -------
    int
        Status code (``OK`` or a failure code, see ``STATUS_TEXT``).
    """
    n = y0.shape[0]
    iso = p[P_ISO] != 0.0
    nc = N_CORE_ISO if iso else N_CORE_RIGID
    iv2 = 3 if iso else 1
    iz = nc
    ii = nc + 1
    iu = nc + 2
    Ts = p[P_TS]
    delay = p[P_DELAY]
    discrete = Ts > 0.0
    fa_state = (not discrete) and delay == 0.0
    cont_delay = (not discrete) and delay > 0.0
    algebraic = math.isinf(p[P_WT])
    has_ff = p[P_FF_M] != 0.0 or p[P_FF_C] != 0.0 or p[P_FF_F] != 0.0
    n_in = in_t.shape[0]
    # the command needs computing at every stage unless it is the bare controller state
    # or (``held``) the discrete controller's held output; calls with many array
    # arguments cost about 0.2 us each, so the common cases stay inline
    need_cmd = (not fa_state) or has_ff or n_in > 0
    held = discrete and n_in == 0
    m_acc = p[P_M1] if iso else p[P_M1] + p[P_M2]
    if cont_delay and h_max > delay:
        h_max = delay
    sw = p[P_SWITCH] != 0.0

    y = y0.copy()
    ynew = np.empty(n)
    ytmp = np.empty(n)
    ybuf = np.empty(n)
    yev = np.empty(n)
    f0 = np.empty(n)
    fs = np.empty(n)
    ft = np.zeros(n)
    k1 = np.empty(n)
    k2 = np.empty(n)
    k3 = np.empty(n)
    k4 = np.empty(n)
    k5 = np.empty(n)
    k6 = np.empty(n)
    cd2 = np.empty(n)
    cd3 = np.empty(n)
    J = np.empty((n, n))
    # the filter chain's states follow the leaves: a plant with them takes the dense LU
    full = p[P_NF] > 0.0
    nm = n if full else n - 3
    M = np.empty((nm, nm))
    piv = np.empty(nm, dtype=np.int64)
    w = np.empty((4, n - 3 if n - 3 > 3 else 3))
    tmp = np.empty(n)
    modes = np.zeros(4, dtype=np.int64)
    modes[MODE_SIGN] = 1
    natural_modes(y, p, modes)
    if sw:
        modes[MODE_STICK] = 1 if y[iv2] == 0.0 else 0
    hints = np.zeros(N_HINTS, dtype=np.int64)

    # delay history of the continuous controller's output (rows HT, HU, HDU, HUR, HDUR);
    # only a delayed continuous controller reads it (no need to zero 320 kB every run)
    hist = np.zeros((5, HIST if cont_delay else 1))
    head = 0
    count = 0
    jump_pending = False
    jump_u = 0.0
    jump_du = 0.0
    # discrete controller
    dx1 = p[P_DX1]
    dx2 = p[P_DX2]
    k_sample = 0
    t_sample = 0.0 if discrete else math.inf
    fa_hold = p[P_U0]
    fifo_t = np.zeros(FIFO)
    fifo_u = np.zeros(FIFO)
    f_head = 0
    f_count = 0

    for i in range(N_STATS):
        stats[i] = 0.0
    # the watch (section crossings, quiet and repeat rules)
    t_watch = watch[W_START]
    level = watch[W_LEVEL]
    band = watch[W_BAND]
    quiet = watch[W_QUIET]
    repeat = watch[W_REPEAT]
    rest_anywhere = watch[W_REST_ANYWHERE] != 0.0
    arm = watch[W_ARM]
    match = watch[W_MATCH]
    n_known = (watch.shape[0] - N_WATCH) // n
    max_cross = min(int(watch[W_MAX_CROSSINGS]), cross_t.shape[0])
    n_cross = 0
    armed = False
    quiet_t0 = -1.0
    quiet_x = 0.0
    quiet_due = False  # a sampled loop's quiet stop, due at its next sample instant
    e_lo = math.inf
    e_hi = -math.inf
    stop = STOP_END
    period = 0
    m_out = t_out.shape[0]
    i_out = 0
    kref = 0
    t = 0.0
    h = min(1e-5, h_max)
    h_acc = h
    err_acc = 1.0
    reject = False
    n_steps = 0
    n_rej = 0
    n_events = 0
    n_zero = 0
    zero_run = 0
    suppress = False
    status = OK
    nb = breaks.shape[0]
    ib = 0
    while ib < nb and breaks[ib] <= 0.0:
        ib += 1
    i_in = 0

    while True:
        # ---------------------------------------------------- time events at t
        if discrete and quiet_due and t >= t_sample - 1e-12 * max(1.0, t):
            # the quiet stop, before this sample is taken (the outputs due now are applied
            # first): the run continues exactly from here (ST_DX1 ... in the stats)
            stop = STOP_QUIET
        elif discrete and t >= t_sample - 1e-12 * max(1.0, t):
            r_s, rd_s, rdd_s, r3_s, kref = reference_at(t, breaks, coeffs, kref)
            lev = int(math.floor(y[0] / p[P_QUANT] + 0.5)) if p[P_QUANT] > 0.0 else 0
            xm = measured_position(y[0], p, lev)
            e_k = r_s - xm
            d_k = -xm if p[P_DMEAS] != 0.0 else e_k
            u_k = p[P_DP] * e_k + dx1 + p[P_DC] * e_k + dx2 + p[P_DB] * d_k
            if full:  # the drive's biquads on the PID's output, before the feedforward
                u_k = sample_filters(u_k, y, p, iu + 1)
            if has_ff:
                ff_k, _ = feedforward(rd_s, rdd_s, r3_s, p)
                u_k += ff_k
            dx1 += 2.0 * p[P_DC] * e_k
            dx2 = p[P_DA] * (dx2 + p[P_DB] * d_k) - p[P_DB] * d_k
            y[iu] = u_k
            y[ii] = dx1
            if delay == 0.0:
                fa_hold = u_k
            else:
                if f_count == FIFO:
                    status = HISTORY_OVERFLOW
                    break
                fifo_t[(f_head + f_count) % FIFO] = t + delay
                fifo_u[(f_head + f_count) % FIFO] = u_k
                f_count += 1
            k_sample += 1
            t_sample = k_sample * Ts
        while f_count > 0 and t >= fifo_t[f_head] - 1e-12 * max(1.0, t):
            fa_hold = fifo_u[f_head]
            f_head = (f_head + 1) % FIFO
            f_count -= 1
        if sw and modes[MODE_STICK] == 1:
            r_n, rd_n, _, _, kref = reference_at(t, breaks, coeffs, kref)
            fa_now, _, _ = stage_command(t, p, breaks, coeffs, in_t, in_f, hints, fa_hold, hist,
                                         head, count)
            F = drive_force(y, p, modes, r_n, rd_n, fa_now, fa_state)
            if breakaway(F, p) > 0.0:
                modes[MODE_STICK] = 0
                modes[MODE_SIGN] = 1 if F > 0.0 else -1
                n_events += 1

        # ---------------------------------------------------- outputs at t
        while i_out < m_out and t_out[i_out] <= t + 1e-12 * max(1.0, t):
            write_output(i_out, t_out[i_out], y, p, modes, breaks, coeffs, in_t, in_f, hints,
                         fa_hold, hist, head, count, need_cmd, out_y, out_r, out_fa, out_cmd)
            i_out += 1

        if t >= t_end * (1.0 - 1e-14) or stop != STOP_END:
            break
        if n_steps + n_rej >= max_steps:
            status = TOO_MANY_STEPS
            break

        # ---------------------------------------------------- next landing time
        t_land = t_end
        if land:
            while ib < nb and breaks[ib] <= t + 1e-12 * max(1.0, t):
                ib += 1
            if ib < nb and breaks[ib] < t_land:
                t_land = breaks[ib]
        if discrete and t_sample < t_land:
            t_land = t_sample
        if f_count > 0 and fifo_t[f_head] < t_land:
            t_land = fifo_t[f_head]
        if n_in > 0:  # the input's next change (an unchanged sample is no event)
            while i_in < n_in and (in_t[i_in] + delay <= t + 1e-12 * max(1.0, t)
                                   or (i_in > 0 and in_f[i_in] == in_f[i_in - 1])):
                i_in += 1
            if i_in < n_in and in_t[i_in] + delay < t_land:
                t_land = in_t[i_in] + delay

        # ---------------------------------------------------- f, J, f_t at (t, y)
        r0, rd0, rdd0, _, kref = _reference_at(t, breaks, coeffs, kref)
        fa0 = 0.0
        dfa0 = 0.0
        if need_cmd:
            fa0, dfa0, ok = stage_command(t, p, breaks, coeffs, in_t, in_f, hints, fa_hold, hist,
                                          head, count)
            if not ok:
                status = HISTORY_OVERFLOW
                break
        rhs(t, y, p, modes, r0, rd0, fa0, fa_state, f0)
        jacobian(t, y, p, modes, r0, rd0, fa0, fa_state, J)
        for j in range(n):
            ft[j] = 0.0
        if not discrete:
            ft[ii] = p[P_KI] * rd0
            dv_dt = p[P_KP] * rd0 + p[P_KD] * rdd0  # explicit time derivative of v
            if not algebraic:
                ft[iu] = p[P_WT] * dv_dt
            dw_dt = dv_dt  # the explicit rate of the command: through the chain when it has one
            if full:
                dw_dt = filter_time_rate(p, iu + 1, dv_dt if algebraic else 0.0, ft)
            if fa_state:
                if algebraic or has_ff or n_in > 0:
                    uc = controller_output(y, p, modes, r0, rd0, ii, iu)
                    _, dsat = actuator(uc + fa0, p)
                    ft[1] = dsat * (dfa0 + (dw_dt if algebraic else 0.0)) / m_acc
            else:
                _, dsat = actuator(fa0, p)
                ft[1] = dsat * dfa0 / m_acc
        if cont_delay:
            # record the controller output for the delayed force
            uc = controller_output(y, p, modes, r0, rd0, ii, iu)
            duc = law_rate(y, p, modes, r0, rd0, rdd0, f0, ii) if algebraic else f0[iu]
            if full:
                duc = filter_output_rate(duc, f0, p, iu + 1)
            newest = (head - 1) % HIST
            if count > 0 and t == hist[HT, newest]:
                hist[HUR, newest] = uc
                hist[HDUR, newest] = duc
            else:
                if count == HIST:
                    count -= 1
                hist[HT, head] = t
                hist[HUR, head] = uc
                hist[HDUR, head] = duc
                if jump_pending:
                    hist[HU, head] = jump_u
                    hist[HDU, head] = jump_du
                else:
                    hist[HU, head] = uc
                    hist[HDU, head] = duc
                head = (head + 1) % HIST
                count += 1
            jump_pending = False

        # ---------------------------------------------------- step attempts
        pending = EV_NONE
        n_nan = 0
        restart = False
        while True:
            landing = False
            if h > h_max:
                h = h_max
            if t + h >= t_land - 1e-12 * max(1.0, t_land):
                h = t_land - t
                landing = True
            if h < 1e-14 * max(1.0, t):
                status = STEP_UNDERFLOW
                break
            if n_steps + n_rej >= max_steps:
                status = TOO_MANY_STEPS
                break
            if not factor_e(J, 1.0 / (h * GAMMA), M, piv, w, full):
                h *= 0.5
                n_rej += 1
                continue
            hinv = 1.0 / h  # the stages multiply by it (a division per component was slow)
            # stage 1
            for j in range(n):
                k1[j] = f0[j] + h * D1 * ft[j]
            solve_e(J, M, piv, w, k1, tmp, full)
            # stage 2
            for j in range(n):
                ytmp[j] = y[j] + A21 * k1[j]
            ts = t + C2 * h
            rs, rds, _, _, kref = _reference_at(ts, breaks, coeffs, kref)
            fas = 0.0
            if held:
                fas = fa_hold
            elif need_cmd:
                fas, _, _ = stage_command(ts, p, breaks, coeffs, in_t, in_f, hints, fa_hold,
                                          hist, head, count)
            rhs(ts, ytmp, p, modes, rs, rds, fas, fa_state, fs)
            for j in range(n):
                k2[j] = fs[j] + C21 * hinv * k1[j] + h * D2 * ft[j]
            solve_e(J, M, piv, w, k2, tmp, full)
            # stage 3
            for j in range(n):
                ytmp[j] = y[j] + A31 * k1[j] + A32 * k2[j]
            ts = t + C3 * h
            rs, rds, _, _, kref = _reference_at(ts, breaks, coeffs, kref)
            if need_cmd and not held:
                fas, _, _ = stage_command(ts, p, breaks, coeffs, in_t, in_f, hints, fa_hold,
                                          hist, head, count)
            rhs(ts, ytmp, p, modes, rs, rds, fas, fa_state, fs)
            for j in range(n):
                k3[j] = fs[j] + (C31 * k1[j] + C32 * k2[j]) * hinv + h * D3 * ft[j]
            solve_e(J, M, piv, w, k3, tmp, full)
            # stage 4
            for j in range(n):
                ytmp[j] = y[j] + A41 * k1[j] + A42 * k2[j] + A43 * k3[j]
            ts = t + C4 * h
            rs, rds, _, _, kref = _reference_at(ts, breaks, coeffs, kref)
            if need_cmd and not held:
                fas, _, _ = stage_command(ts, p, breaks, coeffs, in_t, in_f, hints, fa_hold,
                                          hist, head, count)
            rhs(ts, ytmp, p, modes, rs, rds, fas, fa_state, fs)
            for j in range(n):
                k4[j] = fs[j] + (C41 * k1[j] + C42 * k2[j] + C43 * k3[j]) * hinv + h * D4 * ft[j]
            solve_e(J, M, piv, w, k4, tmp, full)
            # stage 5
            for j in range(n):
                ytmp[j] = y[j] + A51 * k1[j] + A52 * k2[j] + A53 * k3[j] + A54 * k4[j]
            ts = t + h
            rs, rds, _, _, kref = _reference_at(ts, breaks, coeffs, kref)
            if need_cmd and not held:
                fas, _, _ = stage_command(ts, p, breaks, coeffs, in_t, in_f, hints, fa_hold,
                                          hist, head, count)
            rhs(ts, ytmp, p, modes, rs, rds, fas, fa_state, fs)
            for j in range(n):
                k5[j] = fs[j] + (C51 * k1[j] + C52 * k2[j] + C53 * k3[j] + C54 * k4[j]) * hinv
            solve_e(J, M, piv, w, k5, tmp, full)
            # stage 6 (embedded solution + correction)
            for j in range(n):
                ytmp[j] += k5[j]
            rhs(ts, ytmp, p, modes, rs, rds, fas, fa_state, fs)
            for j in range(n):
                k6[j] = fs[j] + (C61 * k1[j] + C62 * k2[j] + C63 * k3[j] + C64 * k4[j]
                                 + C65 * k5[j]) * hinv
            solve_e(J, M, piv, w, k6, tmp, full)
            err = 0.0
            for j in range(n):
                ynew[j] = ytmp[j] + k6[j]
                sk = atol[j] + rtol * max(abs(y[j]), abs(ynew[j]))
                err += (k6[j] / sk) ** 2
            err = math.sqrt(err / n)
            if not (err == err) or err == math.inf:
                n_nan += 1
                n_rej += 1
                if n_nan > 30:
                    status = NOT_FINITE
                    break
                h *= 0.25
                reject = True
                continue
            fac = max(1.0 / FAC_MAX, min(1.0 / FAC_MIN, math.sqrt(math.sqrt(err)) / SAFE))
            h_new = h / fac
            if err > 1.0:
                n_rej += 1
                reject = True
                h = h_new
                pending = EV_NONE
                continue
            # dense output coefficients
            for j in range(n):
                cd2[j] = DD21 * k1[j] + DD22 * k2[j] + DD23 * k3[j] + DD24 * k4[j] + DD25 * k5[j]
                cd3[j] = DD31 * k1[j] + DD32 * k2[j] + DD33 * k3[j] + DD34 * k4[j] + DD35 * k5[j]
            # state events
            kind = EV_NONE
            theta = 2.0
            if not suppress:
                kind, theta = find_event(y, ynew, cd2, cd3, p, modes, iv2, r0, rd0, fa0, fa_state,
                                         ybuf, pending)
            if armed and pending != EV_SECTION and t >= t_watch:
                g0 = y[0] - level
                g1 = ynew[0] - level
                if g0 < 0.0 and g1 >= 0.0:
                    ths = _root(g0, g1, y, ynew, cd2, cd3, 0, 0, 0, level, p, modes, r0, rd0,
                                fa0, fa_state, ybuf)
                    if ths < theta:
                        if ths * h < 1e-12 * max(1.0, t):
                            # on the section at the step's start: record the state there
                            if n_cross < max_cross:
                                cross_t[n_cross] = t
                                for j in range(n):
                                    cross_y[n_cross, j] = y[j]
                                cross_e[n_cross, 0] = e_lo
                                cross_e[n_cross, 1] = e_hi
                                n_cross += 1
                            armed = False
                            e_lo = math.inf
                            e_hi = -math.inf
                        else:
                            kind = EV_SECTION
                            theta = ths
            if kind != EV_NONE:
                if theta * h < 1e-12 * max(1.0, t) or theta <= 0.0:
                    # crossing at the start of the step: switch now, no step
                    for j in range(n):
                        ybuf[j] = ynew[j]
                    u_before = 0.0
                    if cont_delay:
                        u_before = controller_output(y, p, modes, r0, rd0, ii, iu)
                    apply_event(kind, y, p, modes, iv2, iu, r0, rd0, fa0, fa_state, ybuf)
                    if zero_run >= 8 and quantized(p, modes) and p[P_TS] == 0.0:
                        # the level the state is at, with the impulses of the levels skipped
                        # (natural_modes below would set it without them)
                        pass_quantizer(y, p, modes, iu, False)
                    if cont_delay:
                        u_after = controller_output(y, p, modes, r0, rd0, ii, iu)
                        if u_after != u_before:
                            jump_pending = True
                            jump_u = u_before
                            jump_du = f0[iu]
                            if full:
                                jump_du = filter_output_rate(jump_du, f0, p, iu + 1)
                    n_events += 1
                    n_zero += 1
                    zero_run += 1
                    if zero_run > 8:
                        natural_modes(y, p, modes)
                        suppress = True
                        zero_run = 0
                    restart = True
                    break
                # redo the step so that it ends at the crossing
                for j in range(n):
                    yev[j] = ynew[j]  # keep the trial end (direction of the crossing)
                pending = kind
                if theta < 1.0 - 1e-9:
                    h = theta * h
                    t_land = t + h
                    continue
                # The crossing is at the very end of this step: accept the step as it
                # is and switch after it. (Redoing it with the same h looped forever
                # when two events, e.g. a sign change and a limiter contact, fell on
                # the same step end: each redo skipped one and found the other.)
            # ------------------------------------------------ accept
            n_steps += 1
            t_new = t_land if landing else t + h
            # outputs inside (t, t_new); those at t_new follow its time events (a
            # controller sample there shows its new output, as a drive records it)
            while i_out < m_out and t_out[i_out] < t_new - 1e-12 * max(1.0, t_new):
                th = (t_out[i_out] - t) / h
                if th > 1.0:
                    th = 1.0
                if need_cmd and not held:
                    dense(y, ynew, cd2, cd3, th, ybuf)
                    write_output(i_out, t_out[i_out], ybuf, p, modes, breaks, coeffs, in_t, in_f,
                                 hints, fa_hold, hist, head, count, need_cmd, out_y, out_r,
                                 out_fa, out_cmd)
                else:  # the common cases inline (see ``held``): as write_output would
                    s1 = 1.0 - th
                    for j in range(n):  # the dense output, as dense() computes it
                        out_y[i_out, j] = y[j] * s1 + th * (ynew[j] + s1 * (cd2[j] + th * cd3[j]))
                        ybuf[j] = out_y[i_out, j]
                    rr, rdr, _, _, kref = _reference_at(t_out[i_out], breaks, coeffs, kref)
                    out_r[i_out] = rr
                    if held:
                        out_cmd[i_out] = ybuf[iu]
                        out_fa[i_out], _ = actuator(fa_hold, p)
                    else:
                        uc = ybuf[iu] if not (algebraic or full) else controller_output(
                            ybuf, p, modes, rr, rdr, ii, iu)
                        out_cmd[i_out] = uc
                        out_fa[i_out], _ = actuator(uc, p)
                i_out += 1
            # predictive step control (Gustafsson)
            if n_steps > 1:
                facg = (h_acc / h) * math.sqrt(math.sqrt(err * err / err_acc)) / SAFE
                facg = max(1.0 / FAC_MAX, min(1.0 / FAC_MIN, facg))
                fac = max(fac, facg)
                h_new = h / fac
            h_acc = h
            err_acc = max(1e-2, err)
            if reject:
                h_new = min(h_new, h)
            reject = False
            travel = abs(ynew[0] - y[0])
            jitter = 0.0
            if discrete and pending == EV_SECTION:
                # how far the state moves in one sample period here, in the physical scales:
                # a sampled loop's section states scatter by about that much (where its
                # samples fall), so its repeat rule holds to that rather than to less
                for j in range(nc):
                    dj = abs(ynew[j] - y[j]) * (Ts / (t_new - t)) * rtol / atol[j]
                    if dj > jitter:
                        jitter = dj
            for j in range(n):
                y[j] = ynew[j]
            t = t_new
            suppress = False
            if pending == EV_SECTION:
                # the step ended on the section: record the crossing
                if n_cross < max_cross:
                    cross_t[n_cross] = t
                    for j in range(n):
                        cross_y[n_cross, j] = y[j]
                    cross_e[n_cross, 0] = e_lo
                    cross_e[n_cross, 1] = e_hi
                    cross_e[n_cross, 2] = dx2
                    cross_e[n_cross, 3] = fa_hold
                    n_cross += 1
                armed = False
                e_lo = math.inf
                e_hi = -math.inf
                pending = EV_NONE
                if match > 0.0 and n_known > 0:
                    c = n_cross - 1
                    for kk in range(n_known):
                        worst = 0.0
                        for j in range(n):
                            dj = cross_y[c, j] - watch[N_WATCH + kk * n + j]
                            if j == 0 or (iso and j == 2):
                                dj -= level
                            dj = abs(dj) * rtol / atol[j]
                            if dj > worst:
                                worst = dj
                        if worst <= match:
                            stop = STOP_MATCH
                            period = kk
                            break
                if stop != STOP_END:
                    pass
                elif n_cross >= max_cross:
                    stop = STOP_CROSSINGS
                elif repeat > 0.0:
                    c = n_cross - 1
                    rep = repeat if jitter <= repeat else jitter
                    for q in range(1, min(MAX_PERIOD, c) + 1):
                        worst = 0.0
                        for j in range(n):
                            dj = abs(cross_y[c, j] - cross_y[c - q, j]) * rtol / atol[j]
                            if dj > worst:
                                worst = dj
                        if worst <= rep:
                            stop = STOP_REPEAT
                            period = q
                            break
            if t >= t_watch:
                g = y[0] - level
                if g < -arm:
                    armed = True
                if g < e_lo:
                    e_lo = g
                if g > e_hi:
                    e_hi = g
                if rest_anywhere or abs(g) <= band:
                    if quiet_t0 < 0.0 or abs(y[0] - quiet_x) > band:
                        quiet_t0 = t
                        quiet_x = y[0]
                        quiet_due = False
                    elif t - quiet_t0 >= quiet:
                        if discrete:
                            quiet_due = True  # stop at the next sample instant
                        else:
                            stop = STOP_QUIET
                else:
                    quiet_t0 = -1.0
                    quiet_due = False
            if (pending == EV_NONE and modes[MODE_LEVEL] == LEVEL_FREE
                    and 2.0 * travel < p[P_QFREE] * p[P_QUANT]):
                pending = EV_LEVEL  # the stage slowed: quantize again (apply_event)
            if pending != EV_NONE:
                # the step ended at a located crossing: switch the mode
                if pending == EV_LIMIT:
                    stats[ST_LIMIT_EVENTS] += 1.0
                r_e, rd_e, rdd_e, _, kref = reference_at(t, breaks, coeffs, kref)
                u_before = 0.0
                du_before = 0.0
                if cont_delay and pending == EV_LEVEL:
                    fa_e, _, _ = stage_command(t, p, breaks, coeffs, in_t, in_f, hints, fa_hold,
                                               hist, head, count)
                    rhs(t, y, p, modes, r_e, rd_e, fa_e, False, fs)
                    u_before = controller_output(y, p, modes, r_e, rd_e, ii, iu)
                    du_before = law_rate(y, p, modes, r_e, rd_e, rdd_e, fs, ii) if algebraic \
                        else fs[iu]
                    if full:
                        du_before = filter_output_rate(du_before, fs, p, iu + 1)
                apply_event(pending, y, p, modes, iv2, iu, r_e, rd_e, fa0, fa_state, yev)
                if cont_delay and pending == EV_LEVEL:
                    if controller_output(y, p, modes, r_e, rd_e, ii, iu) != u_before:
                        jump_pending = True
                        jump_u = u_before
                        jump_du = du_before
                n_events += 1
                zero_run = 0
                # after an event the old step size may be far too large
                h_new = min(h_new, max(h_acc, 1e-6))
            h = h_new
            if abs(y[0]) > x_bound or not (y[0] == y[0]):
                status = DIVERGED if y[0] == y[0] else NOT_FINITE
            break
        if status != OK:
            break
        if restart:
            continue

    stats[ST_STEPS] = n_steps
    stats[ST_REJECTED] = n_rej
    stats[ST_EVENTS] = n_events
    stats[ST_T] = t
    stats[ST_H] = h
    stats[ST_OUT] = i_out
    stats[ST_ZERO_EVENTS] = n_zero
    stats[ST_CROSSINGS] = n_cross
    stats[ST_STOP] = stop
    stats[ST_PERIOD] = period
    stats[ST_DX1] = dx1
    stats[ST_DX2] = dx2
    stats[ST_HOLD] = fa_hold
    stats[ST_PENDING] = f_count
    for j in range(n):
        y_end[j] = y[j]
    return status
