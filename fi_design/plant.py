"""The nonlinear plant: parameters, right-hand side and Jacobian (DESIGN.md section 2).

Plain functions on floats, compiled with numba and shared by the fast
integrator (:mod:`fi_design.kernel`) and the scipy reference path, so both
integrate the same equations.

Units of the kernel parameters (:class:`PlantParameters`):

============== ========= =====================================================
symbol         unit      meaning
============== ========= =====================================================
m1, m2         kg        stage and cart mass (rigid plant: m1 + m2 moves)
k, c           N/m, Ns/m joint drive stiffness and damping
s              m         one-sided stroke before the limiter engages
k_stop, c_stop N/m, Ns/m limiter contact stiffness and damping
Fs, Fc         N         static and Coulomb friction
vs             m/s       Stribeck velocity
sigma0         N/m       bristle stiffness
sigma1         N s/m     bristle damping
sigma2         N s/m     viscous friction
kp, ki, kd     N/m, N/(m s), N s/m  parallel PID gains
wt             rad/s     roll-off of C(s) = (kp + ki/s + kd s) / (1 + s/wt)
delay          s         delay between controller output and applied force
sample_period  s         discrete controller period (0: continuous)
quantization   m         position quantization the controller sees (0: none)
force_limit    N         actuator saturation (inf: none)
pdf_*          -, m, rad position-dependent friction amplitude, wavelength, phase
ripple_*       N, m, rad force ripple amplitude, pitch, phase
cable_*        N/m, N    cable stiffness and preload
x1_initial     m         stage position at t = 0 (the cable force's zero)
============== ========= =====================================================

States. Isolated plant (7): x1, v1, x2, v2, z, I, u. Rigid plant (5): x, v, z,
I, u. Positions in m, velocities in m/s, the bristle deflection z in m, the
integrator force I = ki * integral(e) and the controller output u in N.

The continuous controller is realised as ``u' = wt (kp e + I + kd e' - u)``
with ``I' = ki e`` and ``e' = r' - v1``: exactly C(s) acting on e, with the
derivative taken from the velocity state instead of a numerical difference.

Modes (int array, frozen during a step so the right-hand side is smooth):
``MODE_SIGN`` direction of cart sliding (+1/-1; the LuGre |v| and the switch
model's friction sign), ``MODE_LIMIT`` limiter state (-1, 0, +1),
``MODE_LEVEL`` quantization level n (the controller sees n q),
``MODE_STICK`` switch model: 1 while the cart sticks.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np
from numba import njit
from numba import types as _nt

# Explicit signatures: one compilation per function (no literal or layout
# re-specialisation), done once at import and cached.
f8 = _nt.float64
i8 = _nt.int64
b1 = _nt.boolean
A1 = _nt.float64[::1]
A2 = _nt.float64[:, ::1]
I1 = _nt.int64[::1]

# --------------------------------------------------------------------------- parameters


@dataclass(frozen=True)
class PlantParameters:
    """All numbers the kernel needs, SI (see the module table for units).

    Field order is the kernel's parameter-array layout; :data:`P_M1` etc. are
    the matching indices.
    """

    m1: float
    m2: float
    k: float
    c: float
    s: float
    k_stop: float
    c_stop: float
    Fs: float
    Fc: float
    vs: float
    sigma0: float
    sigma1: float
    sigma2: float
    kp: float
    ki: float
    kd: float
    wt: float
    delay: float = 0.0
    sample_period: float = 0.0
    quantization: float = 0.0
    force_limit: float = math.inf
    pdf_amplitude: float = 0.0
    pdf_wavelength: float = 1.0
    pdf_phase: float = 0.0
    ripple_amplitude: float = 0.0
    ripple_pitch: float = 1.0
    ripple_phase: float = 0.0
    cable_stiffness: float = 0.0
    cable_preload: float = 0.0
    isolated: float = 1.0
    switch_model: float = 0.0
    # discrete controller (Tustin) state space, used when sample_period > 0
    ad11: float = 0.0
    ad12: float = 0.0
    ad21: float = 0.0
    ad22: float = 0.0
    bd1: float = 0.0
    bd2: float = 0.0
    cd1: float = 0.0
    cd2: float = 0.0
    dd: float = 0.0
    x1_initial: float = 0.0

    def to_array(self) -> np.ndarray:
        """The kernel's float64 parameter array."""
        return np.array([getattr(self, f.name) for f in fields(self)], dtype=np.float64)

    @property
    def n_states(self) -> int:
        """Number of states: 7 isolated, 5 rigid."""
        return 7 if self.isolated else 5


@dataclass(frozen=True, eq=False)
class Integration:
    """What an integrator of these equations returns (kernel or reference path).

    Attributes
    ----------
    code : int
        0 on success, a failure code otherwise.
    status : str
        ``"ok"`` or the failure kind.
    states : ndarray, shape (m, n)
        States at the output times (NaN after a failure).
    reference : ndarray, shape (m,)
        Reference r at the output times [m].
    applied_force : ndarray, shape (m,)
        Actuator force on the stage after delay and saturation [N].
    n_steps, n_rejected, n_events : int
        Accepted steps, discarded trial steps, mode switches.
    t_reached : float
        Last time integrated [s].
    """

    code: int
    status: str
    states: np.ndarray
    reference: np.ndarray
    applied_force: np.ndarray
    n_steps: int
    n_rejected: int
    n_events: int
    t_reached: float


(P_M1, P_M2, P_K, P_C, P_S, P_KSTOP, P_CSTOP, P_FS, P_FC, P_VS, P_SIGMA0, P_SIGMA1, P_SIGMA2,
 P_KP, P_KI, P_KD, P_WT, P_DELAY, P_TS, P_QUANT, P_FLIMIT, P_PDF_A, P_PDF_L, P_PDF_PHI,
 P_RIP_A, P_RIP_P, P_RIP_PHI, P_CABLE_K, P_CABLE_F0, P_ISO, P_SWITCH,
 P_AD11, P_AD12, P_AD21, P_AD22, P_BD1, P_BD2, P_CD1, P_CD2, P_DD, P_X10) = range(41)
N_PARAMS = 41

MODE_SIGN, MODE_LIMIT, MODE_LEVEL, MODE_STICK = 0, 1, 2, 3
N_MODES = 4

TWO_PI = 2.0 * math.pi


def state_index(isolated: bool) -> dict[str, int]:
    """Names of the state components and their index for one plant."""
    if isolated:
        return {"x1": 0, "v1": 1, "x2": 2, "v2": 3, "z": 4, "I": 5, "u": 6}
    return {"x1": 0, "v1": 1, "x2": 0, "v2": 1, "z": 2, "I": 3, "u": 4}


# --------------------------------------------------------------------------- pieces


@njit((f8, f8, A1), cache=True, error_model="numpy", _nrt=False)
def stribeck(v, x2, p):
    """g(v) scaled by position-dependent friction, and its partials.

    Returns ``(g, dg/dv, dg/dx2)`` [N, N s/m, N/m] with
    g = (1 + a sin(2 pi x2 / lambda + phi)) (Fc + (Fs - Fc) exp(-(v / vs)^2)).
    """
    Fs = p[P_FS]
    Fc = p[P_FC]
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


@njit((f8, A1), cache=True, error_model="numpy", _nrt=False)
def external_force(x1, p):
    """Force ripple plus cable force on the stage and its x1-derivative [N, N/m]."""
    F = 0.0
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


@njit((f8, A1), cache=True, error_model="numpy", _nrt=False)
def actuator(fa, p):
    """Saturated actuator force and its derivative wrt the command [N, -]."""
    lim = p[P_FLIMIT]
    if fa > lim:
        return lim, 0.0
    if fa < -lim:
        return -lim, 0.0
    return fa, 1.0


@njit((f8, f8, f8, f8, A1), cache=True, error_model="numpy", _nrt=False)
def lugre(v, x2, z, sgn, p):
    """LuGre bristle rate and friction force with partials (sliding sign frozen).

    Returns ``(zd, Ff, dzd_dx2, dzd_dv, dzd_dz, dFf_dx2, dFf_dv, dFf_dz)``:
    dz/dt = v - sigma0 |v| z / g(v), F = sigma0 z + sigma1 dz/dt + sigma2 v,
    with |v| = sgn * v.
    """
    s0 = p[P_SIGMA0]
    s1 = p[P_SIGMA1]
    s2 = p[P_SIGMA2]
    g, dg_dv, dg_dx = stribeck(v, x2, p)
    av = sgn * v
    q = s0 * z / g
    zd = v - av * q
    dzd_dv = 1.0 - sgn * q + av * q * dg_dv / g
    dzd_dz = -s0 * av / g
    dzd_dx = av * q * dg_dx / g
    Ff = s0 * z + s1 * zd + s2 * v
    return zd, Ff, dzd_dx, dzd_dv, dzd_dz, s1 * dzd_dx, s1 * dzd_dv + s2, s0 + s1 * dzd_dz


@njit((f8, A1, i8), cache=True, error_model="numpy", _nrt=False)
def measured_position(x1, p, level):
    """Position the controller sees [m]: x1, or level * q when quantized."""
    q = p[P_QUANT]
    if q > 0.0:
        return level * q
    return x1


@njit((A1, A1, f8, b1), cache=True, error_model="numpy", _nrt=False)
def drive_force(y, p, fa, fa_state):
    """Force that drives the cart apart from friction [N] (the switch model's stick test).

    Isolated: the joint and limiter force. Rigid: actuator plus external force,
    with the command ``fa`` or, when ``fa_state`` is true, the state u.
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
    Fa, _ = actuator(y[4] if fa_state else fa, p)
    Fe, _ = external_force(y[0], p)
    return Fa + Fe


# --------------------------------------------------------------------------- rhs + jacobian


@njit((f8, A1, A1, I1, f8, f8, f8, b1, A1), cache=True, error_model="numpy", _nrt=False)
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
        Actuator command [N] used when ``fa_state`` is false (delayed or held).
    fa_state : bool
        True: the command is the controller state u (continuous, no delay).
    f : ndarray
        Output, same shape as ``y``.
    """
    iso = p[P_ISO] != 0.0
    if iso:
        iz, ii, iu = 4, 5, 6
        x1, v1, x2, v2 = y[0], y[1], y[2], y[3]
    else:
        iz, ii, iu = 2, 3, 4
        x1, v1 = y[0], y[1]
        x2, v2 = x1, v1
    z = y[iz]
    Fa, _ = actuator(y[iu] if fa_state else fa, p)
    Fe, _ = external_force(x1, p)
    stick = p[P_SWITCH] != 0.0 and modes[MODE_STICK] == 1
    sgn = float(modes[MODE_SIGN])
    if p[P_SWITCH] != 0.0:
        zd = 0.0
        if stick:
            Ff = 0.0
        else:
            g, _, _ = stribeck(v2, x2, p)
            Ff = sgn * g + p[P_SIGMA2] * v2
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
    if p[P_TS] > 0.0:
        f[ii] = 0.0
        f[iu] = 0.0
    else:
        xm = measured_position(x1, p, modes[MODE_LEVEL])
        e = r - xm
        ed = rd if p[P_QUANT] > 0.0 else rd - v1
        f[ii] = p[P_KI] * e
        f[iu] = p[P_WT] * (p[P_KP] * e + y[ii] + p[P_KD] * ed - y[iu])


@njit((f8, A1, A1, I1, f8, f8, f8, b1, A2), cache=True, error_model="numpy", _nrt=False)
def jacobian(t, y, p, modes, r, rd, fa, fa_state, J):
    """Analytic Jacobian d(rhs)/dy for frozen modes, written into ``J`` (n x n)."""
    n = y.shape[0]
    for i in range(n):
        for j in range(n):
            J[i, j] = 0.0
    iso = p[P_ISO] != 0.0
    if iso:
        iz, ii, iu = 4, 5, 6
        x1, v1, x2, v2 = y[0], y[1], y[2], y[3]
    else:
        iz, ii, iu = 2, 3, 4
        x1, v1 = y[0], y[1]
        x2, v2 = x1, v1
    z = y[iz]
    _, dFa = actuator(y[iu] if fa_state else fa, p)
    if not fa_state:
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
            _, dg_dv, dg_dx = stribeck(v2, x2, p)
            dF_dv = sgn * dg_dv + p[P_SIGMA2]
            dF_dx = sgn * dg_dx
    else:
        _, _, dzd_dx, dzd_dv, dzd_dz, dF_dx, dF_dv, dF_dz = lugre(v2, x2, z, sgn, p)
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
        J[1, 0] = (-kk + dFe) / m1
        J[1, 1] = -cc / m1
        J[1, 2] = kk / m1
        J[1, 3] = cc / m1
        J[1, iu] = dFa / m1
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
            J[1, 0] = (dFe - dF_dx) / m
            J[1, 1] = -dF_dv / m
            J[1, iz] = -dF_dz / m
            J[1, iu] = dFa / m
        J[iz, 0] = dzd_dx
        J[iz, 1] = dzd_dv
        J[iz, iz] = dzd_dz
    if p[P_TS] == 0.0:
        de_dx = 0.0 if p[P_QUANT] > 0.0 else -1.0
        J[ii, 0] = p[P_KI] * de_dx
        wt = p[P_WT]
        J[iu, 0] = wt * p[P_KP] * de_dx
        if p[P_QUANT] == 0.0:
            J[iu, 1] = -wt * p[P_KD]
        J[iu, ii] = wt
        J[iu, iu] = -wt


@njit((A1, A1, I1), cache=True, error_model="numpy", _nrt=False)
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
    if q > 0.0:
        modes[MODE_LEVEL] = int(math.floor(y[0] / q + 0.5))
