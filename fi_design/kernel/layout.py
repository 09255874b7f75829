"""The nonlinear plant's layout: its parameters, states, modes and the kernel's arrays.

One table each for the kernel's parameter array (:class:`PlantParameters`)
and the state vector; the modes and the mode events; what an integration
returns (:class:`Integration`, the status codes, the statistics array) and
the watch array (``W_*``) with its stop reasons. The equations themselves
(right-hand side, Jacobian, the mode switch) are in
:mod:`fi_design.kernel.equations`, compiled with numba and shared by the
fast integrator (:mod:`fi_design.kernel.integrator`) and the scipy reference
solver (:mod:`fi_design.kernel.reference`). This module is plain Python: the
simulation reads the layout without loading any compiled code.

Units of the kernel parameters (:class:`PlantParameters`, whose field order is
the kernel's parameter-array layout; the ``P_*`` indices are derived from it by
name at import, so a reordering can never mis-wire the kernel):

============== ========= =====================================================
symbol         unit      meaning
============== ========= =====================================================
m1, m2         kg        stage and cart mass (rigid plant: m1 + m2 moves)
k, c           N/m, Ns/m joint drive stiffness and damping
s              m         one-sided stroke before the limiter engages
k_stop, c_stop N/m, Ns/m limiter contact stiffness and damping
Fs, Fc         N         static and Coulomb friction (positive direction)
vs             m/s       Stribeck velocity
sigma0         N/m       bristle stiffness
sigma1         N s/m     bristle damping
sigma2         N s/m     viscous friction (positive direction)
kp, ki         N/m, N/(m s)  continuous controller: proportional and integral gain
kd, kdm        N s/m     derivative gains on the error and on the measured position
wt             rad/s     corner of the controller's output filter (inf: none)
Fc_neg         N         Coulomb friction for v < 0 (nan: Fc); Fs scales with it
sigma2_neg     N s/m     viscous friction for v < 0 (nan: sigma2)
offset         N         constant load force on the stage (m1 a1 = u - offset - ...)
ff_*           kg, N s/m, N  feedforward m r'' + c r' + F sign(r')
delay          s         delay between controller output and applied force
sample_period  s         discrete controller period (0: continuous)
quantization   m         position quantization the controller sees (0: none)
quantization_free -      levels one trial step must cross for the quantizer to be passed
                         through while the stage moves fast (0: never; replays of a record,
                         whose command the derivative's impulse per level marks)
force_limit    N         actuator saturation (inf: none)
pdf_*          -, m, rad position-dependent friction amplitude, wavelength, phase
ripple_*       N, m, rad force ripple amplitude, pitch, phase
cable_*        N/m, N    cable stiffness and preload
dp, dc, da, db N/m, N/m, -, N/m  discrete controller (see below)
dmeas          -         1: the discrete D term acts on the measurement
dx1, dx2       N         discrete controller states at t = 0
u_initial      N         command applied before the controller's first output
x1_initial     m         stage position at t = 0 (the cable force's zero)
filter_states  -         number of states of the drive's filter chain (0: none)
fK_order       -         section K of the chain (0..3, packed): 0 unused, 1 or 2
fK_b0 .. fK_a2 -, 1/s, 1/s^2  (b0 s^2 + b1 s + b2) / (s^2 + a1 s + a2), or
                         (b0 s + b1) / (s + a1) (order 1), continuous
fK_z0 .. fK_p2 -         the same sampled: (z0 + z1/z + z2/z^2) / (1 + p1/z + p2/z^2)
============== ========= =====================================================

States (one table, :data:`ISOLATED_STATES` and :data:`RIGID_STATES`). Isolated
plant (7): x1, v1, x2, v2, z, I, u. Rigid plant (5): x, v, z, I, u. Positions
in m, velocities in m/s, the bristle deflection z in m, the integrator force
I = ki * integral(e) and the controller output u in N. The last three are the
"leaves" the kernel's structured linear solve eliminates; the layout is checked
at import. The drive's filter chain (``controller.filters``) adds its states
after u (``filter_states`` of them, :func:`state_index` names them f0, f1,
...), in N; a plant with them is solved with a dense LU instead.

The filter chain acts on the controller's output u (or v without output
filter), the command that reaches the stage is its output w, section after
section, each with unit DC gain. Continuous, a second-order section
``(b0 s^2 + b1 s + b2) / (s^2 + a1 s + a2)`` with ``wn = sqrt(a2)`` has the
states P1 (its input low-passed to unit DC gain) and P2 = P1' / wn::

    P1' = wn P2,   P2' = wn (x - P1) - a1 P2
    out = b0 x + ((b2 - b0 a2) P1 + (b1 - b0 a1) wn P2) / a2

and a first-order one ``(b0 s + b1) / (s + a1)`` the state P with
``P' = a1 (x - P)``, ``out = b0 x + (b1 - b0 a1) P / a1``: every state is a
force, at rest equal to the command. Sampled, each section is a biquad (the
drive's Tustin rule prewarped at the filter's frequency, computed by
:mod:`fi_design.controller`) in transposed direct form II, its two memories
(one for a first-order section) held in the filter states between samples::

    out = z0 x + s1,   s1 <- z1 x - p1 out + s2,   s2 <- z2 x - p2 out

The continuous controller, one law for every controller the spec describes
(:mod:`fi_design.controller.pid` maps the tuning rule and explicit hardware gains onto
it)::

    v = kp e + I + kd e' - kdm x'       e = r - x, x the measured position
    I' = ki e
    u' = wt (v - u)                     (wt = inf: u = v, no filter)

with the derivatives taken from the velocity state instead of a numerical
difference (``x' = v1``; 0 between the levels of a quantized measurement).
With wt finite this is C(s) = (kp + ki/s + kd s)/(1 + s/wt) on the error plus
-kdm s/(1 + s/wt) on the measurement. The applied force is the saturated
command u + feedforward + a known input force, ``delay`` later.

The discrete controller (zero-order hold, period ``sample_period``) computes
at each sample ``u_k = dp e_k + (dx1 + dc e_k) + (dx2 + db d_k) + ff_k``,
then ``dx1 += 2 dc e_k`` and ``dx2 = da (dx2 + db d_k) - db d_k``, where
``d_k`` is ``e_k`` or, with ``dmeas``, the measurement ``-x_k``: a
trapezoidal integrator and a derivative by the Tustin rule (or, with
``da = 0``, the backward difference).

Modes (int array, frozen during a step so the right-hand side is smooth):
``MODE_SIGN`` direction of cart sliding (+1/-1; the LuGre |v|, the friction
values of a direction and the switch model's friction sign), ``MODE_LIMIT``
limiter state (-1, 0, +1), ``MODE_LEVEL`` quantization level n (the
controller sees n q; :data:`LEVEL_FREE` while a fast move passes the quantizer
through), ``MODE_STICK`` switch model: 1 while the cart sticks.
A mode event (``EV_*``) changes them: both solvers locate the crossing their
own way and switch with the one compiled
:func:`fi_design.kernel.equations.switch_mode`.
"""

from __future__ import annotations

import math
import operator
from dataclasses import dataclass, fields

import numpy as np

# --------------------------------------------------------------------------- parameters


@dataclass(frozen=True)
class PlantParameters:
    """All numbers the kernel needs, SI (see the module table for units).

    Field order is the kernel's parameter-array layout; the ``P_*`` indices
    below are derived from it by name.
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
    kdm: float = 0.0
    Fc_neg: float = math.nan
    sigma2_neg: float = math.nan
    offset: float = 0.0
    ff_mass: float = 0.0
    ff_viscous: float = 0.0
    ff_coulomb: float = 0.0
    delay: float = 0.0
    sample_period: float = 0.0
    quantization: float = 0.0
    quantization_free: float = 4.0
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
    # discrete controller, used when sample_period > 0
    dp: float = 0.0
    dc: float = 0.0
    da: float = 0.0
    db: float = 0.0
    dmeas: float = 0.0
    dx1: float = 0.0
    dx2: float = 0.0
    u_initial: float = 0.0
    x1_initial: float = 0.0
    # the drive's filter chain (see the module docstring): states after u, sections packed
    filter_states: float = 0.0
    f0_order: float = 0.0
    f0_b0: float = 0.0
    f0_b1: float = 0.0
    f0_b2: float = 0.0
    f0_a1: float = 0.0
    f0_a2: float = 0.0
    f0_z0: float = 0.0
    f0_z1: float = 0.0
    f0_z2: float = 0.0
    f0_p1: float = 0.0
    f0_p2: float = 0.0
    f1_order: float = 0.0
    f1_b0: float = 0.0
    f1_b1: float = 0.0
    f1_b2: float = 0.0
    f1_a1: float = 0.0
    f1_a2: float = 0.0
    f1_z0: float = 0.0
    f1_z1: float = 0.0
    f1_z2: float = 0.0
    f1_p1: float = 0.0
    f1_p2: float = 0.0
    f2_order: float = 0.0
    f2_b0: float = 0.0
    f2_b1: float = 0.0
    f2_b2: float = 0.0
    f2_a1: float = 0.0
    f2_a2: float = 0.0
    f2_z0: float = 0.0
    f2_z1: float = 0.0
    f2_z2: float = 0.0
    f2_p1: float = 0.0
    f2_p2: float = 0.0
    f3_order: float = 0.0
    f3_b0: float = 0.0
    f3_b1: float = 0.0
    f3_b2: float = 0.0
    f3_a1: float = 0.0
    f3_a2: float = 0.0
    f3_z0: float = 0.0
    f3_z1: float = 0.0
    f3_z2: float = 0.0
    f3_p1: float = 0.0
    f3_p2: float = 0.0

    def to_array(self) -> np.ndarray:
        """The kernel's float64 parameter array (negative-direction friction resolved)."""
        out = np.array(_VALUES(self), dtype=np.float64)
        if math.isnan(self.Fc_neg):
            out[P_FC_NEG] = self.Fc
        if math.isnan(self.sigma2_neg):
            out[P_SIGMA2_NEG] = self.sigma2
        return out

    def value(self, name: str) -> float:
        """The value the kernel uses for field ``name`` (negative-direction friction resolved)."""
        return float(self.to_array()[PARAMETER_INDEX[name]])

    @property
    def n_states(self) -> int:
        """Number of states: 7 isolated, 5 rigid, plus the filter chain's."""
        return len(ISOLATED_STATES if self.isolated else RIGID_STATES) + int(self.filter_states)

    def filter_rest(self, command: float) -> np.ndarray:
        """The filter chain's states at rest on a constant controller output [N].

        Continuous (``sample_period`` 0): each section's low-passed input
        ``P1`` (and ``P2 = 0`` of a second-order one) equals the command, all
        sections having unit DC gain. Sampled: the biquads' transposed direct
        form II memory that outputs the command for it.
        """
        out = []
        for i in range(MAX_FILTER_SECTIONS):
            c = [getattr(self, f"f{i}_{n}") for n in FILTER_FIELDS]
            order = int(c[0])
            if order == 0:
                break
            if self.sample_period == 0.0:
                out += [command, 0.0] if order == 2 else [command]
            elif order == 2:
                _, _, _, _, _, _, z0, z1, z2, p1, p2 = c
                out += [(z1 + z2 - p1 - p2) * command, (z2 - p2) * command]
            else:
                out += [(c[7] - c[9]) * command]
        return np.array(out, dtype=float)


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
    command : ndarray, shape (m,)
        Commanded actuator force before delay and saturation [N]: the
        controller output plus feedforward plus a known input force.
    n_steps, n_rejected, n_events : int
        Accepted steps, discarded trial steps, mode switches.
    t_reached : float
        Last time integrated [s].
    final_state : ndarray, shape (n,), optional
        State at ``t_reached`` (kernel path).
    stop : str
        Why the run ended: ``"end"`` (``t_end`` or a failure), or a rule of
        the watch: ``"quiet"``, ``"repeat"``, ``"crossings"``.
    crossing_times : ndarray, shape (c,), optional
        Times of the Poincare section's crossings (x1 - r = 0 upwards, after
        the watch starts) [s].
    crossing_states : ndarray, shape (c, n), optional
        States at those crossings.
    crossing_extremes : ndarray, shape (c, 2), optional
        Smallest and largest x1 - r at the step ends since the crossing before
        [m] (since the watch's start for the first).
    crossing_controller : ndarray, shape (c, 2), optional
        A discrete controller's ``dx2`` and held output at those crossings [N]
        (``dx1`` is the state's ``I``).
    period_crossings : int
        With ``stop == "repeat"``: crossings per period of the repeating
        motion; with ``stop == "match"``: the index of the known section
        state matched (0 otherwise).
    controller : (float, float, float, int)
        A discrete controller's ``dx1``, ``dx2`` and held output [N] where the
        run ended, and its delayed outputs still pending: a quiet stop of a
        sampled loop comes on a sample instant before the sample, so that a
        run from ``final_state`` with ``dx1``, ``dx2`` and ``u_initial`` set
        to these continues it exactly when none is pending.
    """

    code: int
    status: str
    states: np.ndarray
    reference: np.ndarray
    applied_force: np.ndarray
    command: np.ndarray
    n_steps: int
    n_rejected: int
    n_events: int
    t_reached: float
    final_state: np.ndarray | None = None
    stop: str = "end"
    crossing_times: np.ndarray | None = None
    crossing_states: np.ndarray | None = None
    crossing_extremes: np.ndarray | None = None
    crossing_controller: np.ndarray | None = None
    period_crossings: int = 0
    controller: tuple[float, float, float, int] = (0.0, 0.0, 0.0, 0)


#: Kernel parameter index of every :class:`PlantParameters` field, by name.
PARAMETER_INDEX = {f.name: i for i, f in enumerate(fields(PlantParameters))}
#: The fields' values in the layout's order, as a tuple (:meth:`PlantParameters.to_array`).
_VALUES = operator.attrgetter(*PARAMETER_INDEX)
N_PARAMS = len(PARAMETER_INDEX)
_P = PARAMETER_INDEX
(P_M1, P_M2, P_K, P_C, P_S, P_KSTOP, P_CSTOP, P_FS, P_FC, P_VS, P_SIGMA0, P_SIGMA1,
 P_SIGMA2, P_KP, P_KI, P_KD, P_WT, P_KDM, P_FC_NEG, P_SIGMA2_NEG, P_OFFSET, P_FF_M, P_FF_C,
 P_FF_F, P_DELAY, P_TS, P_QUANT, P_FLIMIT, P_PDF_A, P_PDF_L, P_PDF_PHI, P_RIP_A, P_RIP_P,
 P_RIP_PHI, P_CABLE_K, P_CABLE_F0, P_ISO, P_SWITCH, P_DP, P_DC, P_DA, P_DB, P_DMEAS, P_DX1,
 P_DX2, P_U0, P_X10) = (
    _P[n] for n in (
        "m1", "m2", "k", "c", "s", "k_stop", "c_stop", "Fs", "Fc", "vs", "sigma0", "sigma1",
        "sigma2", "kp", "ki", "kd", "wt", "kdm", "Fc_neg", "sigma2_neg", "offset", "ff_mass",
        "ff_viscous", "ff_coulomb", "delay", "sample_period", "quantization", "force_limit",
        "pdf_amplitude", "pdf_wavelength", "pdf_phase", "ripple_amplitude", "ripple_pitch",
        "ripple_phase", "cable_stiffness", "cable_preload", "isolated", "switch_model", "dp",
        "dc", "da", "db", "dmeas", "dx1", "dx2", "u_initial", "x1_initial"))
if len(set(_P)) != N_PARAMS or any(f.type not in ("float", float) for f in fields(PlantParameters)):
    raise RuntimeError("PlantParameters must be a flat table of distinct float fields")

#: Sections of the drive's filter chain the kernel carries, and each one's fields.
MAX_FILTER_SECTIONS = 4
FILTER_FIELDS = ("order", "b0", "b1", "b2", "a1", "a2", "z0", "z1", "z2", "p1", "p2")
FILT_STRIDE = len(FILTER_FIELDS)
#: Index of the filter chain's count and of its first section's first field.
P_NF = _P["filter_states"]
P_QFREE = _P["quantization_free"]
P_FILT = _P["f0_order"]
if [_P[f"f{i}_{n}"] for i in range(MAX_FILTER_SECTIONS) for n in FILTER_FIELDS] != list(
        range(P_FILT, P_FILT + MAX_FILTER_SECTIONS * FILT_STRIDE)):
    raise RuntimeError("the filter sections' fields must follow one another")

#: State names of the two plants; the index of a name is its place in the state vector.
ISOLATED_STATES = ("x1", "v1", "x2", "v2", "z", "I", "u")
RIGID_STATES = ("x1", "v1", "z", "I", "u")
#: The states the kernel's structured solve eliminates, last and in this order.
LEAVES = ("z", "I", "u")
#: Number of mechanical ("core") states before the leaves.
N_CORE_ISO = len(ISOLATED_STATES) - len(LEAVES)
N_CORE_RIGID = len(RIGID_STATES) - len(LEAVES)
if (ISOLATED_STATES[-3:] != LEAVES or RIGID_STATES[-3:] != LEAVES
        or ISOLATED_STATES[:2] != RIGID_STATES[:2] or ISOLATED_STATES[2:4] != ("x2", "v2")):
    raise RuntimeError("state layout: x1, v1 first, (x2, v2 isolated), then z, I, u")

MODE_SIGN, MODE_LIMIT, MODE_LEVEL, MODE_STICK = 0, 1, 2, 3
N_MODES = 4

#: ``MODE_LEVEL`` while the quantizer is passed through: a step of the integrator crossed
#: more than ``quantization_free`` levels, and the controller sees x1 itself until the stage
#: slows (the measured position's sawtooth then lies far above the loop's band); it is
#: quantized again once an accepted step travels less than half as many.
LEVEL_FREE = -(2 ** 62)

# Mode events: the cart's velocity reverses (LuGre: the sliding sign flips; switch model: the
# cart sticks or slides on), the switch model's cart breaks away, the joint enters or leaves a
# limiter, the measured position crosses to another quantization level. EV_SECTION is the
# watch's Poincare section (no mode change).
EV_NONE, EV_SIGN, EV_LIMIT, EV_LEVEL, EV_UNSTICK, EV_SECTION = 0, 1, 2, 3, 4, 5

TWO_PI = 2.0 * math.pi


def state_index(isolated: bool, filter_states: int = 0) -> dict[str, int]:
    """Names of the state components and their index for one plant.

    The rigid plant's cart is the stage: ``x2`` and ``v2`` name ``x1`` and ``v1``.
    The filter chain's states follow as ``f0``, ``f1``, ...
    """
    names = ISOLATED_STATES if isolated else RIGID_STATES
    names = names + tuple(f"f{i}" for i in range(int(filter_states)))
    out = {n: i for i, n in enumerate(names)}
    if not isolated:
        out.update(x2=out["x1"], v2=out["v1"])
    return out


# --------------------------------------------------------------------------- integrator outcome

# Status codes of the integrators.
OK = 0
TOO_MANY_STEPS = 1
STEP_UNDERFLOW = 2
NOT_FINITE = 3
DIVERGED = 4
HISTORY_OVERFLOW = 5
SINGULAR = 6

STATUS_TEXT = {
    OK: "ok",
    TOO_MANY_STEPS: "step budget exhausted",
    STEP_UNDERFLOW: "step size underflow",
    NOT_FINITE: "state became NaN or infinite",
    DIVERGED: "solution diverged",
    HISTORY_OVERFLOW: "delay history overflow",
    SINGULAR: "singular iteration matrix",
}

# Layout of the kernel's statistics array.
# ST_DX1, ST_DX2, ST_HOLD, ST_PENDING: a discrete controller's states where the run ended
# (dx1, dx2 [N], the held output [N], the delayed outputs still pending): a quiet stop of a
# sampled loop comes on a sample instant, before that sample is taken, so that a run from the
# end state with these as ``dx1``, ``dx2`` and ``u_initial`` continues it exactly when no
# output is pending.
(ST_STEPS, ST_REJECTED, ST_EVENTS, ST_T, ST_H, ST_OUT, ST_ZERO_EVENTS, ST_LIMIT_EVENTS,
 ST_CROSSINGS, ST_STOP, ST_PERIOD, ST_DX1, ST_DX2, ST_HOLD, ST_PENDING) = range(15)
N_STATS = 15

# --------------------------------------------------------------------------- the watch

# Layout of the kernel's watch array: what a run watches for once the motion is over, and
# when it stops early (see ``fi_design.kernel.integrator.integrate``). Times in s, lengths in m.
# W_START: time from which the watch is on (inf: off); W_LEVEL: the held reference r, the
# Poincare section is x1 - r = 0 crossed upwards; W_BAND: band [m] of the quiet rule;
# W_QUIET: stop once x1 has stayed within W_BAND of one position (and, unless
# W_REST_ANYWHERE is 1, within W_BAND of r) for this long (inf: never);
# W_REPEAT: stop once the state at a section crossing repeats the one 1 to
# MAX_PERIOD crossings before within this fraction of the physical scales atol / rtol (0:
# never; a sampled loop's, within at least how far its mechanical states move in one sample
# period at the crossing: where its samples fall scatters its section states by about that); W_MAX_CROSSINGS: stop after this many crossings (at most the rows of the crossing
# outputs); W_ARM: x1 - r must fall below -W_ARM between two counted crossings;
# W_MATCH: stop once the state at a section crossing comes within this fraction of the
# physical scales of a known section state (0: never). The known states follow the N_WATCH
# values, n each (n the number of states), positions relative to their section's level:
# the match rule compares the crossing state less W_LEVEL in x1 (and x2), so it holds for
# a plant whose forces do not depend on where the stage is.
(W_START, W_LEVEL, W_BAND, W_QUIET, W_REPEAT, W_MAX_CROSSINGS, W_REST_ANYWHERE,
 W_ARM, W_MATCH) = range(9)
N_WATCH = 9
#: Longest period, in section crossings, the repeat rule compares.
MAX_PERIOD = 4
# Why a run stopped (stats[ST_STOP]); with STOP_MATCH, stats[ST_PERIOD] is the index of the
# known state matched.
STOP_END, STOP_QUIET, STOP_REPEAT, STOP_CROSSINGS, STOP_MATCH = range(5)
STOP_TEXT = {STOP_END: "end", STOP_QUIET: "quiet", STOP_REPEAT: "repeat",
             STOP_CROSSINGS: "crossings", STOP_MATCH: "match"}
