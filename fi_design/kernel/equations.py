"""The nonlinear plant's equations: right-hand side, Jacobian and the mode switch.

Plain functions on floats, compiled with numba and shared by the fast
integrator (:mod:`fi_design.kernel.integrator`) and the scipy reference
solver (:mod:`fi_design.kernel.reference`), so both integrate the same
equations and switch modes the same way (:func:`switch_mode`). The parameter
array, the states and the modes are laid out in
:mod:`fi_design.kernel.layout`, whose module docstring gives the equations in
words.

Every function has an explicit signature (:mod:`fi_design.kernel.jit`):
numba compiles it once, at import, and caches it on disk; the build
(:mod:`fi_design.kernel.build`) compiles the same source into an extension
module instead.
"""

from __future__ import annotations

import math

from .jit import A1, A2, I1, b1, f8, i8, kernel_function
from .layout import (
    EV_LEVEL, EV_LIMIT, EV_SIGN, EV_UNSTICK, LEVEL_FREE, MODE_SIGN, MODE_LIMIT, MODE_LEVEL,
    MODE_STICK,
    N_CORE_ISO, N_CORE_RIGID, TWO_PI, P_C, P_CABLE_F0, P_CABLE_K, P_CSTOP, P_FC, P_FC_NEG,
    P_FF_C, P_FF_F, P_FF_M, P_FLIMIT, P_FS, P_ISO, P_K, P_KD, P_KDM, P_KI, P_KP, P_KSTOP, P_M1,
    P_M2, P_OFFSET, P_PDF_A, P_PDF_L, P_PDF_PHI, P_QUANT, P_RIP_A, P_RIP_P, P_RIP_PHI, P_S,
    P_SIGMA0, P_SIGMA1, P_SIGMA2, P_SIGMA2_NEG, P_SWITCH, P_TS, P_VS, P_WT, P_X10,
    FILT_STRIDE, MAX_FILTER_SECTIONS, P_FILT, P_NF)


# --------------------------------------------------------------------------- pieces


@kernel_function((f8, f8, f8, A1))
def stribeck(v, x2, sgn, p):
    """g(v) of the sliding direction ``sgn``, scaled by position-dependent friction.

    Returns ``(g, dg/dv, dg/dx2)`` [N, N s/m, N/m] with
    g = (1 + a sin(2 pi x2 / lambda + phi)) (Fc + (Fs - Fc) exp(-(v / vs)^2)),
    where for ``sgn < 0`` Fc is ``Fc_neg`` and Fs scales with it (Fs Fc_neg / Fc).
    """
    Fs = p[P_FS]
    Fc = p[P_FC]
    if sgn < 0.0:
        Fs = Fs * p[P_FC_NEG] / Fc
        Fc = p[P_FC_NEG]
    vs = p[P_VS]
    w = v / vs
    ex = (Fs - Fc) * math.exp(-w * w)
    g0 = Fc + ex
    dg0 = ex * (-2.0 * w / vs)
    a = p[P_PDF_A]
    if a == 0.0:
        return g0, dg0, 0.0
    kx = TWO_PI / p[P_PDF_L]
    arg = kx * x2 + p[P_PDF_PHI]
    sc = 1.0 + a * math.sin(arg)
    return sc * g0, sc * dg0, a * kx * math.cos(arg) * g0


@kernel_function((f8, A1))
def static_friction(direction, p):
    """Static friction Fs of a sliding direction (+1 or -1) [N] (the switch model's breakaway)."""
    if direction < 0.0:
        return p[P_FS] * p[P_FC_NEG] / p[P_FC]
    return p[P_FS]


@kernel_function((f8, A1))
def external_force(x1, p):
    """Force ripple, cable force and load offset on the stage, and the x1-derivative [N, N/m]."""
    F = -p[P_OFFSET]
    dF = 0.0
    A = p[P_RIP_A]
    if A != 0.0:
        kx = TWO_PI / p[P_RIP_P]
        arg = kx * x1 + p[P_RIP_PHI]
        F += A * math.sin(arg)
        dF += A * kx * math.cos(arg)
    kc = p[P_CABLE_K]
    F0 = p[P_CABLE_F0]
    if kc != 0.0 or F0 != 0.0:
        F += -kc * (x1 - p[P_X10]) - F0
        dF += -kc
    return F, dF


@kernel_function((f8, A1))
def actuator(fa, p):
    """Saturated actuator force and its derivative wrt the command [N, -]."""
    lim = p[P_FLIMIT]
    if fa > lim:
        return lim, 0.0
    if fa < -lim:
        return -lim, 0.0
    return fa, 1.0


@kernel_function((f8, f8, f8, f8, A1))
def lugre(v, x2, z, sgn, p):
    """LuGre bristle rate and friction force with partials (sliding sign frozen).

    Returns ``(zd, Ff, dzd_dx2, dzd_dv, dzd_dz, dFf_dx2, dFf_dv, dFf_dz)``:
    dz/dt = v - sigma0 |v| z / g(v), F = sigma0 z + sigma1 dz/dt + sigma2 v,
    with |v| = sgn * v and g, sigma2 those of the direction ``sgn``.
    """
    s0 = p[P_SIGMA0]
    s1 = p[P_SIGMA1]
    s2 = p[P_SIGMA2] if sgn > 0.0 else p[P_SIGMA2_NEG]
    g, dg_dv, dg_dx = stribeck(v, x2, sgn, p)
    av = sgn * v
    q = s0 * z / g
    zd = v - av * q
    dzd_dv = 1.0 - sgn * q + av * q * dg_dv / g
    dzd_dz = -s0 * av / g
    dzd_dx = av * q * dg_dx / g
    Ff = s0 * z + s1 * zd + s2 * v
    return zd, Ff, dzd_dx, dzd_dv, dzd_dz, s1 * dzd_dx, s1 * dzd_dv + s2, s0 + s1 * dzd_dz


@kernel_function((f8, A1, i8))
def measured_position(x1, p, level):
    """Position the controller sees [m]: x1, or level * q when quantized (x1 while the
    quantizer is passed through, ``level`` = :data:`~fi_design.kernel.layout.LEVEL_FREE`)."""
    q = p[P_QUANT]
    if q > 0.0 and level != LEVEL_FREE:
        return level * q
    return x1


@kernel_function((A1, I1))
def quantized(p, modes):
    """Whether the controller sees whole levels now (a quantizer, not passed through): its
    measured position is then constant between levels (x' = 0)."""
    return p[P_QUANT] > 0.0 and modes[MODE_LEVEL] != LEVEL_FREE


@kernel_function((f8, f8, f8, A1))
def feedforward(rd, rdd, r3, p):
    """Feedforward force and its time derivative [N, N/s].

    ``ff_mass r'' + ff_viscous r' + ff_coulomb sign(r')`` from the reference's
    velocity ``rd``, acceleration ``rdd`` and jerk ``r3``.
    """
    F = p[P_FF_M] * rdd + p[P_FF_C] * rd
    Fc = p[P_FF_F]
    if Fc != 0.0:
        if rd > 0.0:
            F += Fc
        elif rd < 0.0:
            F -= Fc
    return F, p[P_FF_M] * r3 + p[P_FF_C] * rdd


# --------------------------------------------------------------------------- the filter chain


@kernel_function((A1, i8))
def section_order(p, s):
    """Order of section ``s`` of the drive's filter chain (0: none)."""
    if s >= MAX_FILTER_SECTIONS:
        return 0
    return int(p[P_FILT + s * FILT_STRIDE])


@kernel_function((A1, i8, i8))
def section_weight(p, s, j):
    """How the output of section ``s`` depends on its own state ``j`` (0 or 1) [-] (continuous).

    ``(b2 - b0 a2) / a2`` on P1 and ``(b1 - b0 a1) wn / a2`` on P2 of a
    second-order section; ``(b1 - b0 a1) / a1`` on P of a first-order one.
    """
    b = P_FILT + s * FILT_STRIDE
    b0 = p[b + 1]
    b1 = p[b + 2]
    a1 = p[b + 4]
    if int(p[b]) == 1:
        return (b1 - b0 * a1) / a1
    b2 = p[b + 3]
    a2 = p[b + 5]
    if j == 0:
        return (b2 - b0 * a2) / a2
    return (b1 - b0 * a1) * math.sqrt(a2) / a2


@kernel_function((A1, i8, i8))
def feedthrough(p, s0, s1):
    """Product of the sections' direct terms b0 from section ``s0`` to ``s1 - 1`` [-]."""
    g = 1.0
    for s in range(s0, s1):
        if section_order(p, s) == 0:
            break
        g *= p[P_FILT + s * FILT_STRIDE + 1]
    return g


@kernel_function((f8, A1, A1, i8))
def filter_chain(c, y, p, i0):
    """The continuous filter chain's output on the controller output ``c`` [N].

    States from ``y[i0]`` on (layout in :mod:`fi_design.kernel.layout`).
    Returns ``(w, dw/dc)``; ``(c, 1)`` without filters.
    """
    x = c
    g = 1.0
    k = i0
    for s in range(MAX_FILTER_SECTIONS):
        order = section_order(p, s)
        if order == 0:
            break
        b0 = p[P_FILT + s * FILT_STRIDE + 1]
        if order == 2:
            x = b0 * x + section_weight(p, s, 0) * y[k] + section_weight(p, s, 1) * y[k + 1]
            k += 2
        else:
            x = b0 * x + section_weight(p, s, 0) * y[k]
            k += 1
        g *= b0
    return x, g


@kernel_function((f8, A1, A1, i8, A1))
def filter_rates(c, y, p, i0, f):
    """Rates of the continuous filter states into ``f[i0:]`` for the controller output ``c``."""
    x = c
    k = i0
    for s in range(MAX_FILTER_SECTIONS):
        order = section_order(p, s)
        if order == 0:
            break
        b = P_FILT + s * FILT_STRIDE
        b0 = p[b + 1]
        a1 = p[b + 4]
        if order == 2:
            wn = math.sqrt(p[b + 5])
            f[k] = wn * y[k + 1]
            f[k + 1] = wn * (x - y[k]) - a1 * y[k + 1]
            x = b0 * x + section_weight(p, s, 0) * y[k] + section_weight(p, s, 1) * y[k + 1]
            k += 2
        else:
            f[k] = a1 * (x - y[k])
            x = b0 * x + section_weight(p, s, 0) * y[k]
            k += 1


@kernel_function((f8, A1, A1, i8))
def filter_output_rate(dc, f, p, i0):
    """Rate of the chain's output [N/s] from the input's rate ``dc`` and the states' rates ``f``."""
    out = dc * feedthrough(p, 0, MAX_FILTER_SECTIONS)
    k = i0
    for s in range(MAX_FILTER_SECTIONS):
        order = section_order(p, s)
        if order == 0:
            break
        down = 1.0
        for t in range(s + 1, MAX_FILTER_SECTIONS):
            if section_order(p, t) == 0:
                break
            down *= p[P_FILT + t * FILT_STRIDE + 1]
        for j in range(order):
            out += down * section_weight(p, s, j) * f[k + j]
        k += order
    return out


@kernel_function((f8, A1, A1, i8))
def sample_filters(x, y, p, i0):
    """One sample of the chain's biquads on ``x`` [N], memories ``y[i0:]`` updated; the output."""
    k = i0
    for s in range(MAX_FILTER_SECTIONS):
        order = section_order(p, s)
        if order == 0:
            break
        b = P_FILT + s * FILT_STRIDE
        z0 = p[b + 6]
        z1 = p[b + 7]
        p1 = p[b + 9]
        out = z0 * x + y[k]
        if order == 2:
            y[k] = z1 * x - p1 * out + y[k + 1]
            y[k + 1] = p[b + 8] * x - p[b + 10] * out
            k += 2
        else:
            y[k] = z1 * x - p1 * out
            k += 1
        x = out
    return x


@kernel_function((A1, i8, f8, A1))
def filter_time_rate(p, i0, dc, ft):
    """The filter rows of the explicit time derivative of the right-hand side into ``ft``,
    for an explicit rate ``dc`` of the controller output [N/s] (a reference moving under it).
    Returns the chain output's share, ``dc`` times the product of the direct terms."""
    k = i0
    for s in range(MAX_FILTER_SECTIONS):
        order = section_order(p, s)
        if order == 0:
            break
        b = P_FILT + s * FILT_STRIDE
        g = feedthrough(p, 0, s)
        if order == 2:
            ft[k + 1] = math.sqrt(p[b + 5]) * g * dc
        else:
            ft[k] = p[b + 4] * g * dc
        k += order
    return dc * feedthrough(p, 0, MAX_FILTER_SECTIONS)


@kernel_function((A1, A1, i8, A2, f8, f8, i8, f8, f8, i8, i8, f8))
def filter_jacobian(y, p, i0, J, scale, dc_dx, ix, dc_dv, dc_dI, ii, iu, du):
    """The filter states' rows of the Jacobian, and the force row's share of the chain.

    The input of section s is ``g_s c + sum_j h_sj y_j`` over the states of the
    sections before it, ``g_s`` the product of their direct terms; ``c``
    depends on x1 (``dc_dx``), v1 (``dc_dv``), I (``dc_dI``) and u (``du``).
    Row ``ix`` (the stage's acceleration) gets ``scale`` times the chain
    output's dependence (``scale``: dFa / m, the force's weight there).
    """
    k = i0
    for s in range(MAX_FILTER_SECTIONS + 1):
        order = section_order(p, s)
        last = order == 0
        g = feedthrough(p, 0, s)
        # the row that sees this section's input, and its weight
        if last:
            row, wgt = ix, scale
        else:
            b = P_FILT + s * FILT_STRIDE
            a1 = p[b + 4]
            if order == 2:
                wn = math.sqrt(p[b + 5])
                J[k, k + 1] = wn
                J[k + 1, k] = -wn
                J[k + 1, k + 1] = -a1
                row, wgt = k + 1, wn
            else:
                J[k, k] = -a1
                row, wgt = k, a1
        if wgt != 0.0:
            J[row, 0] += wgt * g * dc_dx
            J[row, 1] += wgt * g * dc_dv
            J[row, ii] += wgt * g * dc_dI
            J[row, iu] += wgt * g * du
            kt = i0
            for t in range(s):
                ot = section_order(p, t)
                down = feedthrough(p, t + 1, s)
                for j in range(ot):
                    J[row, kt + j] += wgt * down * section_weight(p, t, j)
                kt += ot
        if last:
            break
        k += order


@kernel_function((A1, A1, I1, f8, f8, i8))
def control_law(y, p, modes, r, rd, ii):
    """The continuous controller's unfiltered output v and its partials.

    Returns ``(v, dv_dx1, dv_dv1, e)``: v = kp e + I + kd e' - kdm x' [N] with
    e = r - x and x the measured position (x' = v1, or 0 between quantization
    levels), its derivatives with respect to x1 and v1 [N/m, N s/m] (dv/dI = 1),
    and the error e [m].
    """
    quant = quantized(p, modes)
    x1 = y[0]
    xm = measured_position(x1, p, modes[MODE_LEVEL])
    xd = 0.0 if quant else y[1]
    e = r - xm
    kd = p[P_KD]
    kdm = p[P_KDM]
    v = p[P_KP] * e + y[ii] + kd * (rd - xd) - kdm * xd
    if quant:
        return v, 0.0, 0.0, e
    return v, -p[P_KP], -(kd + kdm), e


@kernel_function((A1, A1, I1, f8, f8, i8, i8))
def controller_output(y, p, modes, r, rd, ii, iu):
    """The continuous controller's command [N]: u (or v without output filter) through the
    drive's filter chain, whose states follow u."""
    if math.isinf(p[P_WT]):
        c, _, _, _ = control_law(y, p, modes, r, rd, ii)
    else:
        c = y[iu]
    if p[P_NF] == 0.0:
        return c
    w, _ = filter_chain(c, y, p, iu + 1)
    return w


@kernel_function((A1, A1, I1, f8, f8, f8, b1))
def drive_force(y, p, modes, r, rd, fa, fa_state):
    """Force that drives the cart apart from friction [N] (the switch model's stick test).

    Isolated: the joint and limiter force. Rigid: actuator plus external force,
    with the command ``fa`` or, when ``fa_state`` is true, the continuous
    controller's output (at reference ``r`` [m], ``rd`` [m/s]) plus ``fa``, as
    in :func:`rhs`.
    """
    if p[P_ISO] != 0.0:
        d = y[0] - y[2]
        dv = y[1] - y[3]
        F = p[P_K] * d + p[P_C] * dv
        s = p[P_S]
        if d > s:
            F += p[P_KSTOP] * (d - s) + p[P_CSTOP] * dv
        elif d < -s:
            F += p[P_KSTOP] * (d + s) + p[P_CSTOP] * dv
        return F
    if fa_state:
        ii = N_CORE_RIGID + 1
        fa = fa + controller_output(y, p, modes, r, rd, ii, ii + 1)
    Fa, _ = actuator(fa, p)
    Fe, _ = external_force(y[0], p)
    return Fa + Fe


# --------------------------------------------------------------------------- rhs + jacobian


@kernel_function((f8, A1, A1, I1, f8, f8, f8, b1, A1))
def rhs(t, y, p, modes, r, rd, fa, fa_state, f):
    """Right-hand side dy/dt for frozen modes, written into ``f``.

    Parameters
    ----------
    t : float
        Time [s] (the model is autonomous apart from ``r``, ``rd`` and ``fa``).
    y : ndarray
        State (7 isolated, 5 rigid).
    p : ndarray
        Parameter array (:class:`PlantParameters`).
    modes : ndarray of int64
        Frozen modes (``MODE_*``).
    r, rd : float
        Reference position [m] and velocity [m/s] at ``t``.
    fa : float
        With ``fa_state`` false: the actuator command [N] (delayed or held).
        With ``fa_state`` true: the part of the command that is not the
        controller's output (feedforward plus a known input force) [N].
    fa_state : bool
        True: the command is the continuous controller's output u plus ``fa``
        (continuous controller, no delay).
    f : ndarray
        Output, same shape as ``y``.
    """
    iso = p[P_ISO] != 0.0
    if iso:
        iz, ii, iu = N_CORE_ISO, N_CORE_ISO + 1, N_CORE_ISO + 2
        x1, v1, x2, v2 = y[0], y[1], y[2], y[3]
    else:
        iz, ii, iu = N_CORE_RIGID, N_CORE_RIGID + 1, N_CORE_RIGID + 2
        x1, v1 = y[0], y[1]
        x2, v2 = x1, v1
    z = y[iz]
    discrete = p[P_TS] > 0.0
    wt = p[P_WT]
    v = 0.0
    e = 0.0
    if not discrete:
        v, _, _, e = control_law(y, p, modes, r, rd, ii)
    nf = p[P_NF] > 0.0
    c = 0.0
    if not discrete:
        c = v if math.isinf(wt) else y[iu]
    if fa_state:
        u = c
        if nf:
            u, _ = filter_chain(c, y, p, iu + 1)
        Fa, _ = actuator(u + fa, p)
    else:
        Fa, _ = actuator(fa, p)
    Fe, _ = external_force(x1, p)
    stick = p[P_SWITCH] != 0.0 and modes[MODE_STICK] == 1
    sgn = float(modes[MODE_SIGN])
    if p[P_SWITCH] != 0.0:
        zd = 0.0
        if stick:
            Ff = 0.0
        else:
            g, _, _ = stribeck(v2, x2, sgn, p)
            s2 = p[P_SIGMA2] if sgn > 0.0 else p[P_SIGMA2_NEG]
            Ff = sgn * g + s2 * v2
    else:
        zd, Ff, _, _, _, _, _, _ = lugre(v2, x2, z, sgn, p)
    if iso:
        d = x1 - x2
        dv = v1 - v2
        lim = modes[MODE_LIMIT]
        Fj = p[P_K] * d + p[P_C] * dv
        if lim > 0:
            Fj += p[P_KSTOP] * (d - p[P_S]) + p[P_CSTOP] * dv
        elif lim < 0:
            Fj += p[P_KSTOP] * (d + p[P_S]) + p[P_CSTOP] * dv
        f[0] = v1
        f[1] = (Fa - Fj + Fe) / p[P_M1]
        if stick:
            f[2] = 0.0
            f[3] = 0.0
        else:
            f[2] = v2
            f[3] = (Fj - Ff) / p[P_M2]
    else:
        if stick:
            f[0] = 0.0
            f[1] = 0.0
        else:
            f[0] = v1
            f[1] = (Fa + Fe - Ff) / (p[P_M1] + p[P_M2])
    f[iz] = zd
    if discrete:
        f[ii] = 0.0
        f[iu] = 0.0
        for k in range(iu + 1, y.shape[0]):  # the biquads' memories: held between samples
            f[k] = 0.0
    else:
        f[ii] = p[P_KI] * e
        f[iu] = 0.0 if math.isinf(wt) else wt * (v - y[iu])
        if nf:
            filter_rates(c, y, p, iu + 1, f)


@kernel_function((f8, A1, A1, I1, f8, f8, f8, b1, A2))
def jacobian(t, y, p, modes, r, rd, fa, fa_state, J):
    """Analytic Jacobian d(rhs)/dy for frozen modes, written into ``J`` (n x n)."""
    n = y.shape[0]
    for i in range(n):
        for j in range(n):
            J[i, j] = 0.0
    iso = p[P_ISO] != 0.0
    if iso:
        iz, ii, iu = N_CORE_ISO, N_CORE_ISO + 1, N_CORE_ISO + 2
        x1, x2, v2 = y[0], y[2], y[3]
    else:
        iz, ii, iu = N_CORE_RIGID, N_CORE_RIGID + 1, N_CORE_RIGID + 2
        x1 = y[0]
        x2, v2 = x1, y[1]
    z = y[iz]
    discrete = p[P_TS] > 0.0
    algebraic = math.isinf(p[P_WT])
    v = 0.0
    dv_dx = 0.0
    dv_dv = 0.0
    if not discrete:
        v, dv_dx, dv_dv, _ = control_law(y, p, modes, r, rd, ii)
    nf = p[P_NF] > 0.0
    dFa = 0.0
    if fa_state:
        c = v if algebraic else y[iu]
        if nf:
            c, _ = filter_chain(c, y, p, iu + 1)
        _, dFa = actuator(c + fa, p)
    dFc = dFa  # the force's weight on the controller output: through the chain when it has one
    if nf:
        dFa = 0.0
    _, dFe = external_force(x1, p)
    stick = p[P_SWITCH] != 0.0 and modes[MODE_STICK] == 1
    sgn = float(modes[MODE_SIGN])
    dzd_dx = 0.0
    dzd_dv = 0.0
    dzd_dz = 0.0
    dF_dx = 0.0
    dF_dv = 0.0
    dF_dz = 0.0
    if p[P_SWITCH] != 0.0:
        if not stick:
            _, dg_dv, dg_dx = stribeck(v2, x2, sgn, p)
            dF_dv = sgn * dg_dv + (p[P_SIGMA2] if sgn > 0.0 else p[P_SIGMA2_NEG])
            dF_dx = sgn * dg_dx
    else:
        _, _, dzd_dx, dzd_dv, dzd_dz, dF_dx, dF_dv, dF_dz = lugre(v2, x2, z, sgn, p)
    # the actuator force's dependence on the states, through u (filtered) or v (algebraic)
    if algebraic:
        dA_dx = dFa * dv_dx
        dA_dv = dFa * dv_dv
        dA_dI = dFa
        dA_du = 0.0
    else:
        dA_dx = 0.0
        dA_dv = 0.0
        dA_dI = 0.0
        dA_du = dFa
    if iso:
        m1 = p[P_M1]
        m2 = p[P_M2]
        lim = modes[MODE_LIMIT]
        kk = p[P_K]
        cc = p[P_C]
        if lim != 0:
            kk += p[P_KSTOP]
            cc += p[P_CSTOP]
        J[0, 1] = 1.0
        J[1, 0] = (-kk + dFe + dA_dx) / m1
        J[1, 1] = (-cc + dA_dv) / m1
        J[1, 2] = kk / m1
        J[1, 3] = cc / m1
        J[1, ii] = dA_dI / m1
        J[1, iu] = dA_du / m1
        if not stick:
            J[2, 3] = 1.0
            J[3, 0] = kk / m2
            J[3, 1] = cc / m2
            J[3, 2] = (-kk - dF_dx) / m2
            J[3, 3] = (-cc - dF_dv) / m2
            J[3, iz] = -dF_dz / m2
        J[iz, 2] = dzd_dx
        J[iz, 3] = dzd_dv
        J[iz, iz] = dzd_dz
    else:
        m = p[P_M1] + p[P_M2]
        if not stick:
            J[0, 1] = 1.0
            J[1, 0] = (dFe - dF_dx + dA_dx) / m
            J[1, 1] = (-dF_dv + dA_dv) / m
            J[1, iz] = -dF_dz / m
            J[1, ii] = dA_dI / m
            J[1, iu] = dA_du / m
        J[iz, 0] = dzd_dx
        J[iz, 1] = dzd_dv
        J[iz, iz] = dzd_dz
    if not discrete:
        J[ii, 0] = 0.0 if quantized(p, modes) else -p[P_KI]
        if not algebraic:
            wt = p[P_WT]
            J[iu, 0] = wt * dv_dx
            J[iu, 1] = wt * dv_dv
            J[iu, ii] = wt
            J[iu, iu] = -wt
        if nf:
            if iso:
                scale = dFc / p[P_M1]
            else:
                scale = 0.0 if stick else dFc / (p[P_M1] + p[P_M2])
            if algebraic:
                filter_jacobian(y, p, iu + 1, J, scale, dv_dx, 1, dv_dv, 1.0, ii, iu, 0.0)
            else:
                filter_jacobian(y, p, iu + 1, J, scale, 0.0, 1, 0.0, 0.0, ii, iu, 1.0)


@kernel_function((A1, A1, I1))
def natural_modes(y, p, modes):
    """Modes implied by the state alone (sliding sign kept when the velocity is 0).

    Used to start a simulation and by the reference path, which does not
    freeze modes. The stick flag is left as given.
    """
    iso = p[P_ISO] != 0.0
    v2 = y[3] if iso else y[1]
    if v2 > 0.0:
        modes[MODE_SIGN] = 1
    elif v2 < 0.0:
        modes[MODE_SIGN] = -1
    if iso:
        d = y[0] - y[2]
        s = p[P_S]
        modes[MODE_LIMIT] = 1 if d > s else (-1 if d < -s else 0)
    q = p[P_QUANT]
    if q > 0.0 and modes[MODE_LEVEL] != LEVEL_FREE:
        modes[MODE_LEVEL] = int(math.floor(y[0] / q + 0.5))


# --------------------------------------------------------------------------- mode switch


@kernel_function((f8, f8))
def limit_mode(d, s):
    """Limiter state of the joint deflection ``d`` [m] with stroke ``s`` [m]: -1, 0 or +1."""
    if d > s:
        return 1
    if d < -s:
        return -1
    return 0


@kernel_function((f8, A1))
def breakaway(F, p):
    """Switch model: > 0 once the drive force ``F`` [N] exceeds static friction its way [N]."""
    return max(F - static_friction(1.0, p), -F - static_friction(-1.0, p))


@kernel_function((i8, i8, A1, A1, I1, i8, i8, f8, f8, f8, b1))
def switch_mode(kind, direction, y, p, modes, iv2, iu, r, rd, fa, fa_state):
    """Switch the modes for a located event at the state ``y`` (jumps included).

    The one mode switch of both solvers: the fast integrator and the
    reference solver locate a crossing each their own way, then call this.

    Parameters
    ----------
    kind : int
        The event (``EV_SIGN``, ``EV_UNSTICK``, ``EV_LIMIT``, ``EV_LEVEL``).
    direction : int
        Which way the crossing goes: for ``EV_LIMIT`` out of the free range
        the limiter engaged, +1 (d > s) or -1 (d < -s), ignored when leaving
        a limiter; for ``EV_LEVEL`` +1 up a level, -1 down; ignored otherwise.
    y : ndarray
        State at the crossing (changed in place: the switch model's stopped
        cart, the filtered controller's jump).
    p : ndarray
        Parameter array.
    modes : ndarray of int64
        Modes (changed in place).
    iv2, iu : int
        Index of the cart velocity and of the controller output u in ``y``.
    r, rd, fa, fa_state
        Reference [m, m/s] and command as for :func:`rhs` (the switch
        model's drive force).

    Notes
    -----
    A quantization level change with a filtered continuous controller makes
    its output u jump by the derivative terms' impulse, -wt (kd + kdm) q per
    level (:func:`pass_quantizer` jumps by that of the levels it moves over). A sampled
    controller (``sample_period`` > 0) reads the position at its samples and holds its output
    in u: nothing jumps.
    """
    if kind == EV_SIGN:
        if p[P_SWITCH] != 0.0:
            y[iv2] = 0.0
            F = drive_force(y, p, modes, r, rd, fa, fa_state)
            if breakaway(F, p) <= 0.0:
                modes[MODE_STICK] = 1
            else:
                modes[MODE_SIGN] = 1 if F > 0.0 else -1
        else:
            modes[MODE_SIGN] = -modes[MODE_SIGN]
    elif kind == EV_UNSTICK:
        F = drive_force(y, p, modes, r, rd, fa, fa_state)
        modes[MODE_STICK] = 0
        modes[MODE_SIGN] = 1 if F > 0.0 else -1
    elif kind == EV_LIMIT:
        if modes[MODE_LIMIT] == 0:
            modes[MODE_LIMIT] = 1 if direction > 0 else -1
        else:
            modes[MODE_LIMIT] = 0
    elif kind == EV_LEVEL:
        step = 1 if direction > 0 else -1
        modes[MODE_LEVEL] += step
        if p[P_TS] == 0.0 and not math.isinf(p[P_WT]):
            y[iu] += -p[P_WT] * (p[P_KD] + p[P_KDM]) * p[P_QUANT] * step


@kernel_function((A1, A1, I1, i8, b1))
def pass_quantizer(y, p, modes, iu, free):
    """Pass the quantizer through (``free``: the controller sees x1) or quantize at the level
    x1 lies in (from a pass or from a level left behind), with the derivative terms' impulse
    of the jump in the measured position, -wt (kd + kdm) (seen after - seen before), as at a
    level change."""
    q = p[P_QUANT]
    before = measured_position(y[0], p, modes[MODE_LEVEL])
    modes[MODE_LEVEL] = LEVEL_FREE if free else int(math.floor(y[0] / q + 0.5))
    after = measured_position(y[0], p, modes[MODE_LEVEL])
    if p[P_TS] == 0.0 and not math.isinf(p[P_WT]):
        y[iu] += -p[P_WT] * (p[P_KD] + p[P_KDM]) * (after - before)
