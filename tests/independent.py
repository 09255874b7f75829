"""An independent simulator of the stage and its controller: the "measured world" of the tests.

The project's estimators (reconciliation, friction identification) and its kernel must be
tested on data that the product's own kernel did not make. This module is a second, separate
transcription of the physics of ``docs/model.md`` and ``docs/effects.md``, written from the equations
only and integrated with :func:`scipy.integrate.solve_ivp` (implicit Radau, tight tolerance).
It imports nothing from fi_design's model code; :mod:`fi_design.measured` is used only to
package a record as a :class:`~fi_design.measured.Measurement` (:meth:`Record.measurement`).

Import it as ``from independent import generate, Truth`` in a test module (pytest puts
``tests/`` on ``sys.path`` through the rootdir ``conftest.py``), or as
``from tests.independent import generate, Truth`` where the repository root is on
``sys.path`` (the editable install puts it there; ``tests`` is then a namespace package).

Model (SI units throughout)
---------------------------
Isolated plant (``isolator`` given), stage m1 (actuator force, sensor) and cart m2 (bearing)::

    d = x1 - x2,  w = v1 - v2
    F_stop = k_stop (d - s) + c_stop w   if d >  s
             k_stop (d + s) + c_stop w   if d < -s
             0                           otherwise
    m1 dv1/dt = u_a - offset + F_ripple(x1) + F_cable(x1) - k d - c w - F_stop
    m2 dv2/dt = k d + c w + F_stop - F_f

Rigid plant (``isolator=None``): one mass m = m1 + m2, ``m dv/dt = u_a - offset + F_ripple +
F_cable - F_f`` (the cart is the stage: x2 = x1).

Friction on the cart (LuGre, with direction-dependent values for v2 < 0)::

    g(v) = h(x2) [Fc' + (Fs' - Fc') exp(-(v / vs)^2)]
    dz/dt = v - sigma0 |v| z / g(v)
    F_f = sigma0 z + sigma1 dz/dt + sigma2' v

with (Fc', Fs', sigma2') = (Fc, Fs, sigma2) for v >= 0 and (Fc_neg, Fs Fc_neg / Fc, sigma2_neg)
for v < 0, and h(x2) = 1 + a sin(2 pi x2 / wavelength + phase) (``position_dependent_friction``,
else 1). Without ``Fs, Fc, vs, sigma0`` the friction is viscous only (F_f = sigma2' v).

Actuator: ``u_a(t) = clip(u(t - delay), -limit, limit)``; ``u`` is the commanded force (feedback +
feedforward + known disturbance, or the open-loop drive), the ``force`` column of a record.

Controllers (e = r - x_m, x_m = x1 or round(x1 / q) q with ``quantization``):

* the paper's rule ``C(s) = ks (1 + wi/s)(1 + s/wd) / (1 + s/wt)``, wc = 2 pi fc, wd = wc / r,
  wt = r wc, wi = wc / ri, ks = m wc^2 / r, realised in parallel form
  ``C(s) = K [1 + A / s + B / (s + wt)]`` with K = ks wt / wd, A = wi wd / wt,
  B = wi + wd - wt - A (partial fractions of C(s));
* explicit gains ``u = kp e + ki int(e) + D``, ``D = kd dx/dt`` low-passed at ``roll_off``
  [rad/s] (ideal when None), with x = e (``derivative_on="error"``) or x = -x_m
  (``"measurement"``);
* continuous, or sampled at ``sample_rate`` with zero-order hold: trapezoidal integrator, ideal
  D as the backward difference ``(x[k] - x[k-1]) / T``, filtered D as the Tustin transform of
  ``kd s / (1 + s / wf)``; the rule as the Tustin transform of C(s);
* feedforward ``mass r'' + viscous r' + coulomb sign(r')`` added to the feedback;
* a drive's filter chain on the feedback (before the feedforward), in order, each with unit
  DC gain and w = 2 pi frequency: a notch ``(s^2 + 2 zz w s + w^2) / (s^2 + 2 zp w s +
  w^2)`` given by its -3 dB ``width`` [Hz] (zp = width / (2 frequency)) and ``depth`` [dB]
  (zz = zp 10^(-depth/20), full without) or ``damping=(zz, zp)``; a low-pass ``w / (s + w)``
  (``order=1``) or ``w^2 / (s^2 + 2 damping w s + w^2)`` (``order=2``, damping 1/sqrt(2) by
  default). Continuous: each section in controllable canonical form, its states in the ODE;
  sampled: scipy's ``bilinear`` at the sample rate prewarped to the filter's frequency (the
  drive's Tustin rule), run as a difference equation. Both start at steady state on their
  first input.

Integration
-----------
The run is split into segments at every instant where the right-hand side jumps: controller
samples and their application ``delay`` later, samples of the disturbance or drive (and
``delay`` later), corners of the trapezoidal reference (and ``delay`` later). Inside a segment a
zero-order-held force is a constant and the reference is one polynomial piece (chosen at the
segment's middle, so the end points see the same piece). A continuous controller with a delay
is a delay differential equation, solved by the method of steps: segments no longer than the
delay, the delayed command evaluated from the dense output of the earlier segments. Each
segment is one ``solve_ivp(method="Radau")`` call (LuGre is stiff: sqrt(sigma0 / m2) ~ 1.6 kHz
and a bristle relaxation rate sigma0 |v| / g up to ~1e5 1/s); outputs are read from its dense
output.

Figures (CPU time of :func:`generate`, best of two, Python 3.11, scipy 1.17, rtol = 1e-8; on
the 2 shared cores of the development machine the wall time was up to twice as long):

* paper stage (isolated, m1 = 1.6 kg, m2 = 0.4 kg, Fs = 4 N, Fc = 1 N, vs = 3 mm/s,
  sigma0 = 1e6 N/m, sigma1 = 1414 N s/m, sigma2 = 20 N s/m, k = 6667 N/m, s = 0.3 mm),
  continuous rule at fc = 8 Hz, one 10 mm move, 10 s: 0.22 s;
* the same without isolator (it hunts: stick-slip all along), 20 s: 2.2 s;
* the isolated stage with a 2 ms delay on the continuous rule (method of steps, 5000
  segments), 10 s: 3.3 s;
* the isolated stage with the rule sampled at 1 kHz (10 000 segments), 10 s: 3.5 s;
* a 100 kg rigid axis (LuGre, Fc = 20 N, sigma0 = 1e7 N/m, sigma2 = 100 N s/m), PD at 1 kHz
  with the derivative on the measurement (kp = 1.37e6 N/m, kd = 8557 N s/m), two 0.1 m
  moves, 5 s (5000 segments): 1.8 s.

A sampled controller or a delay costs about 0.3 ms per segment (one solve_ivp start each).

Edges and chattering: inside a segment the limiter cell (free or in contact on either side)
and, for a continuous controller, the quantization level are fixed, so the right-hand side is
smooth there; terminal events (solve_ivp's, located at step ends) end the segment where x1 - x2
or x1 reaches the edge of its cell, and the next segment starts in the neighbouring cell. A
contact entered and left within one solver step would be missed (at rtol = 1e-8 the steps are
far shorter than any contact); a state found outside its cell is re-synchronised (counted in
``Record.info["resyncs"]``). A continuous controller whose equilibrium lies on a quantization
edge switches infinitely often (a sliding mode); after ZENO_COUNT quick crossings the level is
read once per short segment instead (a sampled read-out, ``Record.info["zeno_holds"]``),
see ZENO_HOLD.

What it does not model: parasitic flexure modes, the Karnopp switch friction, jerk-limited
moves, sensor dynamics, sensor noise seen by the controller (noise is added to the record
only), actuator dynamics beyond delay and saturation. A zero-order-held force is delayed and
saturated like the command (the disturbance goes through the drive's delay); before t = 0 the
controller is taken to have output its t = 0 command (what the actuator applies for the first
``delay``).
"""

from __future__ import annotations

import bisect
import heapq
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp
from scipy.interpolate import CubicSpline

__all__ = ["Truth", "Record", "generate", "recorded_again"]

#: Two instants closer than this [s] are the same instant (breakpoints, sample look-ups).
TIME_TOL = 1e-9

#: Chattering on a quantization edge (a sliding mode: a continuous controller whose
#: equilibrium lies on the edge switches infinitely often). After ZENO_COUNT level crossings in
#: a row, each within ZENO_HOLD [s] of the previous restart, the level is read once per segment
#: (a sampled encoder): segments of ZENO_HOLD, doubling up to ``hold_cap`` (1 ms, at most a
#: tenth of the controller's fastest time constant), while x1 stays within ZENO_BAND * q of
#: the edge; then crossings are located by events again.
ZENO_COUNT = 8
ZENO_HOLD = 1e-6
ZENO_BAND = 0.01

#: Default limiter stiffness [N/m] (docs/model.md).
K_STOP = 1e6

_FRICTION_KEYS = {"Fs", "Fc", "vs", "sigma0", "sigma1", "sigma2", "Fc_neg", "sigma2_neg",
                  "offset"}
_ISOLATOR_KEYS = {"k", "c", "s", "k_stop", "c_stop"}
_COMMON_CONTROLLER_KEYS = {"sample_rate", "delay", "force_limit", "feedforward", "filters"}
_NOTCH_KEYS = {"type", "frequency", "width", "depth", "damping", "name"}
_LOW_PASS_KEYS = {"type", "frequency", "order", "damping", "name"}
_GAIN_KEYS = {"kp", "ki", "kd", "roll_off", "derivative_on"}
_RULE_KEYS = {"fc", "r", "ri", "mass"}
_MOVE_KEYS = {"distance", "velocity", "acceleration", "start"}
_EFFECTS = {
    "viscous_friction": {"viscous"},
    "stribeck_velocity": {"stribeck_velocity"},
    "position_dependent_friction": {"amplitude", "wavelength", "phase"},
    "force_ripple": {"amplitude", "pitch", "phase"},
    "cable_force": {"stiffness", "preload"},
    "time_delay": {"delay"},
    "quantization": {"resolution"},
    "force_saturation": {"limit"},
    "mass_error": {"stage_mass", "cart_mass"},
    "joint_damping": {"damping"},
    "force_offset": {"offset"},
    "friction_asymmetry": {"coulomb_negative", "viscous_negative"},
}


# --------------------------------------------------------------------------- results


def _frozen(a) -> np.ndarray | None:
    if a is None:
        return None
    a = np.array(a, dtype=float)
    a.setflags(write=False)
    return a


@dataclass(frozen=True, eq=False)
class Truth:
    """Noise-free state and forces of the simulated stage at the output times.

    Attributes
    ----------
    time : ndarray, shape (n,)
        Output times [s].
    x1, v1 : ndarray, shape (n,)
        Stage position [m] and velocity [m/s].
    x2, v2 : ndarray, shape (n,)
        Cart position [m] and velocity [m/s]; copies of x1, v1 on a rigid plant (one body).
    z : ndarray, shape (n,)
        LuGre bristle deflection [m] (zero without LuGre friction).
    friction : ndarray, shape (n,)
        Friction force on the cart F_f [N] (sigma0 z + sigma1 dz/dt + sigma2' v2).
    applied : ndarray, shape (n,)
        Actuator force acting on the stage [N]: the command ``delay`` earlier, saturated.
        Offset, ripple and cable forces are not included.
    command : ndarray, shape (n,)
        Commanded force [N] (feedback + feedforward + disturbance, or the open-loop drive),
        the noise-free ``force`` column.
    measured : ndarray, shape (n,)
        Position the controller sees [m]: x1, or round(x1 / q) q with ``quantization``.
    """

    time: np.ndarray
    x1: np.ndarray
    v1: np.ndarray
    x2: np.ndarray
    v2: np.ndarray
    z: np.ndarray
    friction: np.ndarray
    applied: np.ndarray
    command: np.ndarray
    measured: np.ndarray

    def __post_init__(self):
        for name in self.__dataclass_fields__:
            object.__setattr__(self, name, _frozen(getattr(self, name)))


@dataclass(frozen=True, eq=False)
class Record:
    """A simulated record in the measured-data layout (docs/interfaces.md).

    Attributes
    ----------
    time : ndarray, shape (n,)
        Sample times [s], uniform at the output ``rate``, from 0 to ``t_end``.
    reference : ndarray, shape (n,)
        Reference r [m] (noise-free).
    position : ndarray, shape (n,)
        Recorded stage position [m]: x1 plus position noise, rounded to whole counts of
        ``position_resolution`` when given.
    force : ndarray, shape (n,)
        Recorded commanded force [N] (feedback + feedforward + disturbance before delay and
        saturation, or the open-loop drive), plus force noise.
    deflection : ndarray, shape (n,), or None
        Recorded joint deflection x1 - x2 [m] plus deflection noise; None on a rigid plant.
    disturbance : ndarray, shape (n,), or None
        Known injected force at the output times [N] (part of ``force``), when given.
    truth : Truth
        The noise-free signals.
    info : dict
        Run statistics: ``segments`` (solve_ivp calls), ``nfev``, ``events``, ``seconds``
        (wall time of the integration).
    """

    time: np.ndarray
    reference: np.ndarray
    position: np.ndarray
    force: np.ndarray
    deflection: np.ndarray | None
    disturbance: np.ndarray | None
    truth: Truth
    info: dict = field(default_factory=dict)

    def __post_init__(self):
        for name in ("time", "reference", "position", "force", "deflection", "disturbance"):
            object.__setattr__(self, name, _frozen(getattr(self, name)))

    def measurement(self):
        """The record as a :class:`fi_design.measured.Measurement`.

        Returns
        -------
        fi_design.measured.Measurement
            Columns time_s, reference_m, position_m, force_N (commanded, disturbance included),
            deflection_m when isolated, disturbance_N when given.
        """
        from fi_design.measured import measurement_from_arrays

        return measurement_from_arrays(self.time, self.reference, self.position,
                                       force_N=self.force, deflection_m=self.deflection,
                                       disturbance_N=self.disturbance,
                                       source="tests/independent.py")

    def to_csv(self, path) -> Path:
        """Write the record as a measured-data CSV (header row, SI, full precision).

        Parameters
        ----------
        path : str or os.PathLike
            File to write.

        Returns
        -------
        pathlib.Path
            The path written.
        """
        names = ["time_s", "reference_m", "position_m", "force_N"]
        cols = [self.time, self.reference, self.position, self.force]
        for name, col in (("deflection_m", self.deflection), ("disturbance_N", self.disturbance)):
            if col is not None:
                names.append(name)
                cols.append(col)
        path = Path(path)
        np.savetxt(path, np.column_stack(cols), fmt="%.17g", delimiter=",",
                   header=",".join(names), comments="")
        return path


# --------------------------------------------------------------------------- inputs


def _check_keys(given, allowed, what):
    unknown = set(given) - set(allowed)
    if unknown:
        raise ValueError(f"{what}: unknown key(s) {sorted(unknown)}; allowed: {sorted(allowed)}")


class _Moves:
    """Trapezoidal point-to-point moves one after another, then hold (r, r', r'')."""

    def __init__(self, moves, r0):
        self.segments = []  # (t0, ta, tc, a, vp, sign, p0, distance)
        t_free, p = 0.0, float(r0)
        for i, mv in enumerate(moves):
            _check_keys(mv, _MOVE_KEYS, f"moves[{i}]")
            dist = float(mv["distance"])
            vmax = float(mv["velocity"])
            amax = float(mv["acceleration"])
            if vmax <= 0 or amax <= 0:
                raise ValueError(f"moves[{i}]: velocity and acceleration must be positive")
            start = mv.get("start")
            t0 = t_free if start is None else float(start)
            if t0 < t_free - TIME_TOL:
                raise ValueError(f"moves[{i}]: start {t0} s is before the previous move ends "
                                 f"({t_free} s)")
            length = abs(dist)
            if length * amax >= vmax * vmax:  # reaches the velocity limit: trapezoid
                vp, ta = vmax, vmax / amax
                tc = (length - vmax * ta) / vmax
            else:  # triangle
                vp = math.sqrt(length * amax)
                ta, tc = vp / amax, 0.0
            sign = 1.0 if dist >= 0 else -1.0
            self.segments.append((t0, ta, tc, amax, vp, sign, p, dist))
            t_free = t0 + 2 * ta + tc
            p += dist
        self.starts = [s[0] for s in self.segments]
        self.r0 = float(r0)

    def corners(self):
        """Instants where r'' jumps [s]."""
        out = []
        for t0, ta, tc, *_ in self.segments:
            out += [t0, t0 + ta, t0 + ta + tc, t0 + 2 * ta + tc]
        return out

    def __call__(self, t, at=None):
        """(r, r', r'') at t [s]; the piece of the profile is the one holding ``at``
        (default t), so that a solver segment between corners sees one smooth polynomial
        up to and including its end points."""
        at = t if at is None else at
        i = bisect.bisect_right(self.starts, at) - 1
        if i < 0:
            return self.r0, 0.0, 0.0
        t0, ta, tc, a, vp, sign, p0, dist = self.segments[i]
        tau, phase = t - t0, at - t0
        if phase < ta:
            return p0 + sign * 0.5 * a * tau * tau, sign * a * tau, sign * a
        if phase < ta + tc:
            return p0 + sign * (0.5 * a * ta * ta + vp * (tau - ta)), sign * vp, 0.0
        if phase < 2 * ta + tc:
            rest = 2 * ta + tc - tau
            return p0 + dist - sign * 0.5 * a * rest * rest, sign * a * rest, -sign * a
        return p0 + dist, 0.0, 0.0


class _SampledReference:
    """Reference given as samples: a cubic spline (r, r', r''); held outside the samples."""

    def __init__(self, t, r):
        t = np.asarray(t, dtype=float).ravel()
        r = np.asarray(r, dtype=float).ravel()
        if len(t) != len(r) or len(t) < 2 or np.any(np.diff(t) <= 0):
            raise ValueError("reference: (t_samples, r_samples) of equal length >= 2 with "
                             "increasing times")
        cs = CubicSpline(t, r)
        self.x = t.tolist()
        self.c = cs.c.T.tolist()  # per interval: [c0, c1, c2, c3], r = c0 dt^3 + ... + c3
        self.first, self.last = float(r[0]), float(r[-1])

    def corners(self):
        return [self.x[0], self.x[-1]]

    def __call__(self, t, at=None):
        """(r, r', r'') at t [s]. ``at`` (default t) decides between the holds before and
        after the samples and the spline (C2 inside: its knots need no such care)."""
        x = self.x
        at = t if at is None else at
        if at < x[0]:
            return self.first, 0.0, 0.0
        if at > x[-1]:
            return self.last, 0.0, 0.0
        i = min(max(bisect.bisect_right(x, t) - 1, 0), len(x) - 2)
        dt = t - x[i]
        c0, c1, c2, c3 = self.c[i]
        return (((c0 * dt + c1) * dt + c2) * dt + c3, (3 * c0 * dt + 2 * c1) * dt + c2,
                6 * c0 * dt + 2 * c1)


class _Held:
    """A force given as samples, held constant from each sample to the next (zero-order hold)."""

    def __init__(self, samples, what, before_first):
        try:
            t, f = samples
        except (TypeError, ValueError):
            raise ValueError(f"{what}: give (t_samples, F_samples)") from None
        t = np.asarray(t, dtype=float).ravel()
        f = np.asarray(f, dtype=float).ravel()
        if len(t) != len(f) or len(t) < 1 or np.any(np.diff(t) <= 0):
            raise ValueError(f"{what}: samples of equal length with increasing times")
        self.t = t.tolist()
        self.f = f.tolist()
        self.before = f[0] if before_first == "first" else 0.0

    def __call__(self, t):
        i = bisect.bisect_right(self.t, t + TIME_TOL) - 1
        return self.before if i < 0 else self.f[i]


# --------------------------------------------------------------------------- the simulator


class _Simulation:
    """One run: the true stage, its actuator path and controller, integrated piecewise."""

    def __init__(self, *, m1, m2, friction, isolator, controller, moves, reference, t_end,
                 rate, effects, disturbance, drive_force, initial, rtol, atol):
        effects = dict(effects or {})
        for name, params in effects.items():
            if name not in _EFFECTS:
                raise ValueError(f"effects: unknown effect {name!r}; known: {sorted(_EFFECTS)}")
            _check_keys(params, _EFFECTS[name], f"effects[{name!r}]")
            need = _EFFECTS[name] - {"phase"}
            if name in ("mass_error", "friction_asymmetry", "cable_force"):
                ok = bool(need & set(params))
            else:
                ok = need <= set(params)
            if not ok:
                raise ValueError(f"effects[{name!r}]: give {sorted(need)}")
        eff = {name: dict(params) for name, params in effects.items()}
        if float(t_end) <= 0 or float(rate) <= 0:
            raise ValueError("t_end and rate must be positive")
        self.t_end = float(t_end)
        self.rate = float(rate)
        self.rtol = float(rtol)

        # ---- masses (mass_error: the true masses differ from the nominal ones)
        m1, m2 = float(m1), float(m2)
        self.m_nominal = m1 + m2
        me = eff.get("mass_error", {})
        m1_true = float(me.get("stage_mass", m1))
        m2_true = float(me.get("cart_mass", m2))
        self.isolated = isolator is not None

        # ---- isolator
        if self.isolated:
            _check_keys(isolator, _ISOLATOR_KEYS, "isolator")
            if m1_true <= 0 or m2_true <= 0:
                raise ValueError("isolated plant: m1 and m2 must be positive")
            self.m1, self.m2 = m1_true, m2_true
            self.k = float(isolator["k"])
            self.s = float(isolator["s"])
            self.c = float(isolator.get("c", 0.0))
            if "joint_damping" in eff:
                self.c = float(eff["joint_damping"]["damping"])
            self.k_stop = float(isolator.get("k_stop", K_STOP))
            c_stop = isolator.get("c_stop")
            # the default of docs/model.md, from the nominal stage mass (a parameter default)
            self.c_stop = (2 * 0.2 * math.sqrt(self.k_stop * m1) if c_stop is None
                           else float(c_stop))
        else:
            if "joint_damping" in eff:
                raise ValueError("effects: joint_damping needs an isolated plant")
            self.m1, self.m2 = m1_true + m2_true, 0.0
            if self.m1 <= 0:
                raise ValueError("rigid plant: m1 + m2 must be positive")

        # ---- friction (effects replace the nominal values)
        fr = dict(friction or {})
        _check_keys(fr, _FRICTION_KEYS, "friction")
        lugre_keys = ("Fs", "Fc", "vs", "sigma0")
        present = [k for k in lugre_keys if fr.get(k) is not None]
        if present and len(present) != 4:
            raise ValueError(f"friction: LuGre needs all of {lugre_keys}, got {present}")
        self.lugre = len(present) == 4
        self.Fs = float(fr.get("Fs") or 0.0)
        self.Fc = float(fr.get("Fc") or 0.0)
        self.vs = float(fr.get("vs") or 1.0)
        self.sigma0 = float(fr.get("sigma0") or 0.0)
        self.sigma1 = float(fr.get("sigma1") or 0.0)
        self.sigma2 = float(fr.get("sigma2") or 0.0)
        self.offset = float(fr.get("offset") or 0.0)
        if "viscous_friction" in eff:
            self.sigma2 = float(eff["viscous_friction"]["viscous"])
        if "stribeck_velocity" in eff:
            self.vs = float(eff["stribeck_velocity"]["stribeck_velocity"])
        if "force_offset" in eff:
            self.offset = float(eff["force_offset"]["offset"])
        Fc_neg = fr.get("Fc_neg")
        sigma2_neg = fr.get("sigma2_neg")
        asym = eff.get("friction_asymmetry", {})
        Fc_neg = asym.get("coulomb_negative", Fc_neg)
        sigma2_neg = asym.get("viscous_negative", sigma2_neg)
        self.Fc_neg = self.Fc if Fc_neg is None else float(Fc_neg)
        self.sigma2_neg = self.sigma2 if sigma2_neg is None else float(sigma2_neg)
        if self.lugre:
            if min(self.Fc, self.Fc_neg, self.Fs, self.vs, self.sigma0) <= 0:
                raise ValueError("friction: Fs, Fc, Fc_neg, vs and sigma0 must be positive")
            self.Fs_neg = self.Fs * self.Fc_neg / self.Fc
        else:
            if Fc_neg is not None:
                raise ValueError("friction: Fc_neg needs LuGre friction (Fs, Fc, vs, sigma0)")
            self.Fs_neg = 0.0
        pdf = eff.get("position_dependent_friction")
        self.pdf = None
        if pdf is not None:
            a = float(pdf["amplitude"])
            if not self.lugre or not abs(a) < 1:
                raise ValueError("position_dependent_friction: needs LuGre friction and "
                                 "|amplitude| < 1")
            self.pdf = (a, 2 * math.pi / float(pdf["wavelength"]), float(pdf.get("phase", 0.0)))

        # ---- forces on the stage
        rip = eff.get("force_ripple")
        self.ripple = None if rip is None else (float(rip["amplitude"]),
                                                2 * math.pi / float(rip["pitch"]),
                                                float(rip.get("phase", 0.0)))
        cab = eff.get("cable_force")
        self.cable = None if cab is None else (float(cab.get("stiffness", 0.0)),
                                               float(cab.get("preload", 0.0)))

        # ---- actuator path and sensor
        ctl = dict(controller or {})
        self.delay = float(ctl.get("delay") or 0.0) + float(
            eff.get("time_delay", {}).get("delay", 0.0))
        limits = [v for v in (ctl.get("force_limit"),
                              eff.get("force_saturation", {}).get("limit")) if v is not None]
        self.limit = min(float(v) for v in limits) if limits else math.inf
        q = eff.get("quantization", {}).get("resolution")
        self.q = None if q is None else float(q)
        if self.delay < 0 or self.limit <= 0 or (self.q is not None and self.q <= 0):
            raise ValueError("delay must be >= 0, force limit and resolution > 0")

        # ---- reference
        ini = dict(initial or {})
        _check_keys(ini, {"x1", "v1", "integral"}, "initial")
        if moves is not None and reference is not None:
            raise ValueError("give moves or reference, not both")
        if reference is not None:
            try:
                rt, rr = reference
            except (TypeError, ValueError):
                raise ValueError("reference: give (t_samples, r_samples)") from None
            self.ref = _SampledReference(rt, rr)
            x1_0 = float(ini.get("x1", self.ref(0.0)[0]))
        else:
            x1_0 = float(ini.get("x1", 0.0))
            self.ref = _Moves(moves or [], x1_0)
        v1_0 = float(ini.get("v1", 0.0))
        self.x1_0 = x1_0

        # ---- the force source: controller or open-loop drive
        self.dist = None if disturbance is None else _Held(disturbance, "disturbance", "zero")
        self.drive = None
        if drive_force is not None:
            if controller is not None or disturbance is not None:
                raise ValueError("drive_force is open loop: give no controller and no "
                                 "disturbance (the drive is the whole force)")
            if ini.get("integral"):
                raise ValueError("initial: integral needs a controller")
            self.drive = _Held(drive_force, "drive_force", "first")
            self.kind = None
            self.fs = None
        else:
            if controller is None:
                raise ValueError("give a controller, or a drive_force for open loop")
            self._setup_controller(ctl)
        self.ff = ctl.get("feedforward")
        if self.ff is not None:
            _check_keys(self.ff, {"mass", "viscous", "coulomb"}, "controller.feedforward")
            self.ff = (float(self.ff.get("mass", 0.0)), float(self.ff.get("viscous", 0.0)),
                       float(self.ff.get("coulomb", 0.0)))

        self._setup_filters(ctl.get("filters") or ())

        # ---- state layout: x1, v1, [x2, v2], z, controller states, filter states
        self.iz = 4 if self.isolated else 2
        self.ic = self.iz + 1
        self.y0 = self._initial_state(x1_0, v1_0, float(ini.get("integral", 0.0)))
        self.atol = self._atol(atol)
        self.rhs = self._make_rhs()

    # ..................................................................... controller

    def _setup_controller(self, ctl):
        if "rule" in ctl:
            _check_keys(ctl, _COMMON_CONTROLLER_KEYS | {"rule"}, "controller")
            rule = dict(ctl["rule"])
            _check_keys(rule, _RULE_KEYS, "controller.rule")
            wc = 2 * math.pi * float(rule["fc"])
            ratio = float(rule.get("r", 3.0))
            ri = float(rule.get("ri", 10.0))
            mass = float(rule.get("mass", self.m_nominal))
            wd, wt, wi = wc / ratio, ratio * wc, wc / ri
            ks = mass * wc * wc / ratio
            self.kind = "rule"
            # partial fractions: C(s) = K [1 + A/s + B/(s + wt)]
            self.K = ks * wt / wd
            self.A = wi * wd / wt
            self.B = wi + wd - wt - self.A
            self.wt = wt
            self.n_ctrl = 2  # q = int(e), p = e / (s + wt)
            self.hold_cap = min(1e-3, 0.1 / wt)
        else:
            _check_keys(ctl, _COMMON_CONTROLLER_KEYS | _GAIN_KEYS, "controller")
            if "kp" not in ctl:
                raise ValueError("controller: give rule=dict(fc=...) or gains kp (ki, kd)")
            self.kind = "gains"
            self.kp = float(ctl["kp"])
            self.ki = float(ctl.get("ki") or 0.0)
            self.kd = float(ctl.get("kd") or 0.0)
            wf = ctl.get("roll_off")
            self.wf = None if wf is None else float(wf)
            self.on_error = {"error": True, "measurement": False}.get(
                ctl.get("derivative_on", "error"))
            if self.on_error is None:
                raise ValueError("controller.derivative_on: 'error' or 'measurement'")
            self.n_ctrl = 1 + (self.wf is not None)  # I = int(e), [f = low-passed x]
            self.hold_cap = 1e-3 if self.wf is None else min(1e-3, 0.1 / self.wf)
        sr = ctl.get("sample_rate")
        self.fs = None if sr is None else float(sr)
        if self.fs is not None:
            self.n_ctrl = 0  # the discrete controller's memory lives outside the ODE
        elif (self.q is not None and self.kind == "gains" and self.kd != 0
              and self.wf is None):
            raise ValueError("an ideal continuous derivative of a quantized position is "
                             "undefined: give roll_off or sample_rate")

    def _setup_filters(self, filters):
        """The filter chain as sections (b, a) in s: numerator and monic denominator."""
        self.sections = []
        for i, f in enumerate(filters):
            f = dict(f)
            kind = f.get("type")
            if kind == "notch":
                _check_keys(f, _NOTCH_KEYS, f"controller.filters[{i}]")
                f0 = float(f["frequency"])
                if "damping" in f:
                    zz, zp = (float(x) for x in f["damping"])
                else:
                    zp = float(f["width"]) / (2 * f0)
                    zz = 0.0 if f.get("depth") is None else zp * 10 ** (-float(f["depth"]) / 20)
                w = 2 * math.pi * f0
                self.sections.append(([1.0, 2 * zz * w, w * w], [1.0, 2 * zp * w, w * w], w))
            elif kind == "low_pass":
                _check_keys(f, _LOW_PASS_KEYS, f"controller.filters[{i}]")
                w = 2 * math.pi * float(f["frequency"])
                if int(f.get("order", 2)) == 1:
                    self.sections.append(([0.0, w], [1.0, w], w))
                else:
                    zeta = float(f.get("damping") or 1 / math.sqrt(2))
                    self.sections.append(([0.0, 0.0, w * w], [1.0, 2 * zeta * w, w * w], w))
            else:
                raise ValueError(f"controller.filters[{i}]: type 'notch' or 'low_pass'")
        if self.sections and self.kind is None:
            raise ValueError("controller.filters need a controller")
        self.n_filt = sum(len(a) - 1 for _, a, _ in self.sections)
        if self.sections:
            w_max = max(w for _, _, w in self.sections)
            self.hold_cap = min(self.hold_cap, 0.1 / w_max)

    def filter_chain(self, u, xs):
        """Continuous filters on the feedback u [N] with their states xs (controllable canonical
        form, per section: x1' = x2, x2' = -a2 x1 - a1 x2 + in, out = (b2 - b0 a2) x1 +
        (b1 - b0 a1) x2 + b0 in; first order: x' = -a1 x + in, out = (b1 - b0 a1) x + b0 in).

        Returns
        -------
        (float, list of float)
            The chain's output [N]; the state derivatives.
        """
        out, i, d = u, 0, []
        for b, a, _ in self.sections:
            if len(a) == 3:
                x1, x2 = xs[i], xs[i + 1]
                d += [x2, -a[2] * x1 - a[1] * x2 + out]
                out = (b[2] - b[0] * a[2]) * x1 + (b[1] - b[0] * a[1]) * x2 + b[0] * out
                i += 2
            else:
                x = xs[i]
                d.append(-a[1] * x + out)
                out = (b[1] - b[0] * a[1]) * x + b[0] * out
                i += 1
        return out, d

    def filter_steady(self, u):
        """Filter states at rest on a constant input u [N] (unit DC gain: output u)."""
        xs = []
        for _, a, _ in self.sections:
            xs += [u / a[2], 0.0] if len(a) == 3 else [u / a[1]]
        return xs

    def discrete_filters(self, u):
        """The sampled chain on u_k [N]: each section by scipy's bilinear map prewarped at its
        frequency, as a difference equation; steady state on the first input."""
        from scipy.signal import bilinear

        if not hasattr(self, "fmem"):
            T = 1.0 / self.fs
            self.fcoef = []
            for b, a, w in self.sections:
                # s = 2 fs' (z - 1)/(z + 1) with 2 fs' = w / tan(w T / 2): exact at w
                bz, az = bilinear(b, a, fs=w / (2 * math.tan(w * T / 2)))
                self.fcoef.append((np.asarray(bz, float), np.asarray(az, float)))
            self.fmem = None
        if self.fmem is None:
            self.fmem = [([u] * len(bz), [u] * (len(az) - 1)) for bz, az in self.fcoef]
        out = u
        for (bz, az), (xin, yout) in zip(self.fcoef, self.fmem):
            xin.insert(0, out)
            xin.pop()
            y = (sum(c * x for c, x in zip(bz, xin))
                 - sum(c * v for c, v in zip(az[1:], yout))) / az[0]
            yout.insert(0, y)
            yout.pop()
            out = y
        return out

    def measure(self, x1):
        """Position the controller sees [m]."""
        q = self.q
        return x1 if q is None else math.floor(x1 / q + 0.5) * q

    def feedforward(self, rd, rdd):
        if self.ff is None:
            return 0.0
        mass, visc, coul = self.ff
        return mass * rdd + visc * rd + (coul if rd > 0 else (-coul if rd < 0 else 0.0))

    # ..................................................................... friction

    def friction_values(self, v, x2):
        """(g(v), sigma2') for the cart velocity v [m/s] at the cart position x2 [m]."""
        if v >= 0:
            Fc, Fs, s2 = self.Fc, self.Fs, self.sigma2
        else:
            Fc, Fs, s2 = self.Fc_neg, self.Fs_neg, self.sigma2_neg
        if not self.lugre:
            return 0.0, s2
        g = Fc + (Fs - Fc) * math.exp(-(v / self.vs) ** 2)
        if self.pdf is not None:
            a, kw, ph = self.pdf
            g *= 1.0 + a * math.sin(kw * x2 + ph)
        return g, s2

    def steady_friction(self, v, x2):
        """Steady-state friction [N] at constant cart velocity v: sign(v) g(v) + sigma2' v."""
        g, s2 = self.friction_values(v, x2)
        return math.copysign(g, v) + s2 * v if v != 0 else 0.0

    def friction_force(self, v, z, x2):
        """(F_f, dz/dt) of the cart [N, m/s]."""
        g, s2 = self.friction_values(v, x2)
        if not self.lugre:
            return s2 * v, 0.0
        dz = v - self.sigma0 * abs(v) * z / g
        return self.sigma0 * z + self.sigma1 * dz + s2 * v, dz

    def stop_force(self, d, w, cell):
        """Limiter force F_stop [N] at deflection d [m], relative velocity w [m/s].

        ``cell`` is the contact state of the segment (see :meth:`cells`): 1 (d > s),
        -1 (d < -s) or 0 (free). Fixing it per segment keeps the right-hand side smooth
        inside a segment; events end the segment where d crosses the edge of the cell.
        """
        if cell > 0:
            return self.k_stop * (d - self.s) + self.c_stop * w
        if cell < 0:
            return self.k_stop * (d + self.s) + self.c_stop * w
        return 0.0

    def cells(self, y):
        """(limiter cell, quantization level) of state y; on an edge, the side it moves to.

        Returns
        -------
        (int, int or None)
            Limiter cell 1 (d > s), -1 (d < -s), 0 (free), always 0 on a rigid plant; the
            level n of the position a continuous controller sees (n q), None without
            quantization or with a sampled controller (it reads the position at its samples).
        """
        Y = y.tolist() if hasattr(y, "tolist") else list(y)
        cell = 0
        if self.isolated:
            d, w = Y[0] - Y[2], Y[1] - Y[3]
            s, tol = self.s, 1e-12 * self.s
            if d > s + tol or (d >= s - tol and w > 0):
                cell = 1
            elif d < -s - tol or (d <= -s + tol and w < 0):
                cell = -1
        level = None
        if self.q is not None and self.fs is None and self.drive is None:
            u = Y[0] / self.q
            level = math.floor(u + 0.5)
            frac = u - level
            if frac > 0.5 - 1e-9 and Y[1] > 0:  # on the upper edge, moving up
                level += 1
            elif frac < -0.5 + 1e-9 and Y[1] < 0:  # on the lower edge, moving down
                level -= 1
        return cell, level

    # ..................................................................... initial state

    def _initial_state(self, x1, v1, integral):
        y = [x1, v1]
        x2, z = x1, 0.0
        if v1 != 0:  # steady sliding of cart and bristles at v1
            for _ in range(4):  # the friction may depend on x2, x2 on the deflection
                F = self.steady_friction(v1, x2)
                if self.isolated:
                    d = F / self.k
                    if d > self.s:
                        d = (F + self.k_stop * self.s) / (self.k + self.k_stop)
                    elif d < -self.s:
                        d = (F - self.k_stop * self.s) / (self.k + self.k_stop)
                    x2 = x1 - d
            if self.lugre:
                g, _ = self.friction_values(v1, x2)
                z = math.copysign(g, v1) / self.sigma0
        if self.isolated:
            y += [x2, v1]
        y.append(z)
        self.integral0 = integral
        if self.drive is None:
            r, rd, _ = self.ref(0.0)
            e, ed = r - self.measure(x1), rd - v1
            if self.kind == "rule":
                q0 = integral / (self.K * self.A)
                p0 = e / self.wt - ed / self.wt ** 2  # steady state of 1/(s + wt) on a ramp
                ctrl = [q0, p0]
            else:
                if integral and self.ki == 0:
                    raise ValueError("initial: integral needs ki != 0")
                ctrl = [integral / self.ki if self.ki else 0.0]
                if self.wf is not None:
                    xd, xdd = (e, ed) if self.on_error else (-self.measure(x1), -v1)
                    ctrl.append(xd - xdd / self.wf)
            if self.fs is None:
                y += ctrl
                if self.sections:  # at rest on the first feedback (without feedforward)
                    yy = y + [0.0] * self.n_filt
                    fb = self._feedback_only(yy, x1)
                    y += self.filter_steady(fb)
            else:
                self._discrete_memory(e, ed, x1, v1)
        return np.array(y, dtype=float)

    def _feedback_only(self, Y, x1):
        """The unfiltered feedback [N] at t = 0 of a state Y (filter states ignored)."""
        sections, self.sections = self.sections, []
        try:
            u = self.control(0.0, Y, self.measure(x1))[0]
            r, rd, rdd = self.ref(0.0)
            return u - self.feedforward(rd, rdd)
        finally:
            self.sections = sections

    def _atol(self, atol):
        n = len(self.y0)
        if atol is not None:
            return np.full(n, float(atol))
        scale = [1e-3, 1e-3] + ([1e-3, 1e-3] if self.isolated else [])
        scale.append(max(self.Fc, self.Fc_neg) / self.sigma0 if self.lugre else 1.0)
        if self.fs is None and self.drive is None:
            if self.kind == "rule":
                scale += [1e-3, 1e-3 / self.wt]
            else:
                scale += [1e-3] + ([1e-3] if self.wf is not None else [])
            for _, a, w in self.sections:  # 1 N through the section: x1 ~ 1/w^2, x2 ~ 1/w
                scale += [1.0 / (w * w), 1.0 / w] if len(a) == 3 else [1.0 / w]
        return self.rtol * np.array(scale)

    # ..................................................................... continuous law

    def control(self, t, Y, xm, at=None):
        """Continuous controller at time t [s], state Y, measured position xm [m]; ``at``
        picks the piece of the reference (see :class:`_Moves`).

        Returns
        -------
        (float, list of float)
            Feedback + feedforward [N]; the controller state derivatives.
        """
        r, rd, rdd = self.ref(t, at)
        v1 = Y[1]
        e = r - xm
        c = Y[self.ic:self.ic + self.n_ctrl]
        if self.kind == "rule":
            q, p = c
            u = self.K * (e + self.A * q + self.B * p)
            dc = [e, -self.wt * p + e]
        else:
            u = self.kp * e
            dc = [e]
            if self.ki:
                u += self.ki * c[0]
            if self.kd:
                if self.wf is None:
                    u += self.kd * ((rd - v1) if self.on_error else -v1)
                else:
                    xd = e if self.on_error else -xm
                    u += self.kd * self.wf * (xd - c[1])
            if self.wf is not None:
                xd = e if self.on_error else -xm
                dc.append(self.wf * (xd - c[1]))
        if self.sections:
            u, df = self.filter_chain(u, Y[self.ic + self.n_ctrl:])
            dc = list(dc) + df
        return u + self.feedforward(rd, rdd), dc

    # ..................................................................... discrete law

    def _discrete_memory(self, e, ed, x1, v1):
        T = 1.0 / self.fs
        self.commands = []  # u_k (feedback + feedforward) [N] at t_k = k / fs
        if self.kind == "rule":
            e_prev = e - T * ed
            self.mem = dict(e=e_prev, q=self.integral0 / (self.K * self.A),
                            p=e_prev / self.wt - ed / self.wt ** 2, first=True)
        else:
            xd, xdd = (e, ed) if self.on_error else (-self.measure(x1), -v1)
            self.mem = dict(e=e - T * ed, I=self.integral0 / self.ki if self.ki else 0.0,
                            x=xd - T * xdd, D=self.kd * xdd, first=True)

    def discrete_step(self, t, x1):
        """Compute the command u_k [N] of the sample at t from the stage position x1."""
        T = 1.0 / self.fs
        r, rd, rdd = self.ref(t)
        xm = self.measure(x1)
        e = r - xm
        m = self.mem
        first = m.pop("first", False)
        if self.kind == "rule":
            if not first:  # trapezoidal integrator (the initial value holds at k = 0)
                m["q"] += 0.5 * T * (e + m["e"])
            # Tustin of 1 / (s + wt)
            m["p"] = (e + m["e"] - (self.wt - 2 / T) * m["p"]) / (2 / T + self.wt)
            u = self.K * (e + self.A * m["q"] + self.B * m["p"])
        else:
            if not first:
                m["I"] += 0.5 * T * (e + m["e"])
            xd = e if self.on_error else -xm
            if self.wf is None:
                D = self.kd * (xd - m["x"]) / T
            else:
                a = 2 / (T * self.wf)
                D = (self.kd * 2 / T * (xd - m["x"]) - (1 - a) * m["D"]) / (1 + a)
            m["x"], m["D"] = xd, D
            u = self.kp * e + self.ki * m["I"] + D
        m["e"] = e
        if self.sections:
            u = self.discrete_filters(u)
        u += self.feedforward(rd, rdd)
        self.commands.append(u)
        return u

    def held_command(self, t):
        """Zero-order-held command without the disturbance at time t [N] (discrete or drive)."""
        if self.drive is not None:
            return self.drive(t)
        k = math.floor((t + TIME_TOL) * self.fs)
        return self.commands[0] if k < 0 else self.commands[min(k, len(self.commands) - 1)]

    def disturbance_at(self, t):
        return 0.0 if self.dist is None else self.dist(t)

    def saturate(self, u):
        lim = self.limit
        return lim if u > lim else (-lim if u < -lim else u)

    # ..................................................................... right-hand side

    def _make_rhs(self):
        iso = self.isolated
        m1, m2 = self.m1, self.m2
        offset = self.offset
        ripple, cable, x1_0 = self.ripple, self.cable, self.x1_0
        friction_force, stop_force = self.friction_force, self.stop_force
        saturate = self.saturate
        k, c = (self.k, self.c) if iso else (0.0, 0.0)
        continuous = self.drive is None and self.fs is None
        delayed = continuous and self.delay > 0
        control = self.control if continuous else None
        # segment constants: held force, delayed disturbance, limiter cell, measured level
        seg = self.seg = {"u": 0.0, "dist": 0.0, "cell": 0, "xm": None, "mid": 0.0,
                          "xm_late": None}
        history = self.history_command
        delay = self.delay

        def rhs(t, y):
            Y = y.tolist()
            x1, v1 = Y[0], Y[1]
            if continuous:
                xm = seg["xm"]
                at = seg["mid"]
                u, dc = control(t, Y, x1 if xm is None else xm, at)
                if delayed:
                    u = history(t - delay, at - delay, seg["xm_late"])
                ua = saturate(u + seg["dist"])
            else:
                ua = seg["u"]
            fe = ua - offset
            if ripple is not None:
                fe += ripple[0] * math.sin(ripple[1] * x1 + ripple[2])
            if cable is not None:
                fe -= cable[0] * (x1 - x1_0) + cable[1]
            if iso:
                x2, v2, z = Y[2], Y[3], Y[4]
                Ff, dz = friction_force(v2, z, x2)
                d, w = x1 - x2, v1 - v2
                Fj = k * d + c * w + stop_force(d, w, seg["cell"])
                out = [v1, (fe - Fj) / m1, v2, (Fj - Ff) / m2, dz]
            else:
                z = Y[2]
                Ff, dz = friction_force(v1, z, x1)
                out = [v1, (fe - Ff) / m1, dz]
            if continuous:
                out += dc
            return out

        return rhs

    def history_command(self, t, at=None, xm=None):
        """Continuous command (no disturbance) at an earlier time t [s], from the dense
        output; ``at`` picks the reference piece, ``xm`` overrides the measured position."""
        if t <= 0:
            return self.u0
        i = bisect.bisect_right(self.hist_t, t) - 1
        Y = self.hist_sol[i](t).tolist()
        if xm is None:
            xm = self.seen(t if at is None else at, Y[0])
        return self.control(t, Y, xm, at)[0]

    def seen(self, t, x1):
        """Position the continuous controller saw at time t [m]: x1, or the quantization level
        of the segment holding t (the level the right-hand side used, so that the delayed
        command jumps exactly where the level changed)."""
        if self.q is None:
            return x1
        i = bisect.bisect_right(self.level_t, t + TIME_TOL * 1e-3) - 1
        return self.level_v[max(i, 0)] * self.q

    # ..................................................................... events

    def _events(self, cell, level):
        """Terminal events that end a segment: leaving the limiter cell or quantization level."""
        events = []
        if self.isolated:
            s = self.s
            if cell >= 0:  # the edge +s: downward out of contact, upward into it
                events.append(_event(lambda t, y: y[0] - y[2] - s, -1 if cell == 1 else 1,
                                     cell=0 if cell == 1 else 1))
            if cell <= 0:
                events.append(_event(lambda t, y: y[0] - y[2] + s, 1 if cell == -1 else -1,
                                     cell=0 if cell == -1 else -1))
        if level is not None:
            hi, lo = (level + 0.5) * self.q, (level - 0.5) * self.q
            events.append(_event(lambda t, y: y[0] - hi, 1, level=level + 1))
            events.append(_event(lambda t, y: y[0] - lo, -1, level=level - 1))
        return events

    def _consistent(self, y, cell, level):
        """Whether state y lies in the limiter cell and quantization level (edges included)."""
        if self.isolated:
            d, s = float(y[0] - y[2]), self.s
            tol = 1e-6 * s
            inside = {1: d >= s - tol, -1: d <= -s + tol, 0: abs(d) <= s + tol}[cell]
            if not inside:
                return False
        return level is None or abs(float(y[0]) / self.q - level) <= 0.5 + 1e-6

    def _set_cells(self, t, y):
        """Cell and level of state y at time t, recording a level change."""
        cell, level = self.cells(y)
        if level is not None and level != self.level_v[-1]:
            self.level_t.append(t)
            self.level_v.append(level)
        return cell, level

    # ..................................................................... the run

    def breakpoints(self):
        t_end, delay = self.t_end, self.delay
        pts = []
        if self.fs is not None:
            n = int(math.floor(t_end * self.fs + 1e-6)) + 1
            tk = np.arange(n) / self.fs
            pts += tk.tolist()
            if delay > 0:
                pts += (tk + delay).tolist()
        for held in (self.dist, self.drive):
            if held is not None:
                pts += held.t
                if delay > 0:
                    pts += [t + delay for t in held.t]
        if self.fs is None and self.drive is None:  # r'' enters the continuous command
            corners = self.ref.corners()
            pts += corners
            if delay > 0:
                pts += [t + delay for t in corners]
        pts = np.unique(np.asarray(pts, dtype=float))
        pts = pts[(pts > TIME_TOL) & (pts < t_end - TIME_TOL)]
        if len(pts) > 1:
            keep = np.concatenate([[True], np.diff(pts) > TIME_TOL])
            pts = pts[keep]
        return pts.tolist() + [t_end]

    def run(self):
        import time as _time

        t_out = np.arange(int(math.floor(self.t_end * self.rate + 1e-6)) + 1) / self.rate
        n_out = len(t_out)
        states = np.empty((len(self.y0), n_out))
        continuous = self.drive is None and self.fs is None
        delayed = continuous and self.delay > 0
        self.hist_t, self.hist_sol = [], []
        if continuous:
            self.u0 = self.control(0.0, self.y0.tolist(), self.measure(self.y0[0]))[0]
        bps = self.breakpoints()
        heap = list(bps)
        heapq.heapify(heap)
        t, y = 0.0, self.y0.copy()
        i_out = 0
        n_seg = nfev = n_events = 0
        next_k = 0
        cell, level = self.cells(self.y0)
        self.level_t, self.level_v = [0.0], [level]  # what a continuous controller saw
        short = resyncs = holds = zero_length = 0
        hold_len = hold_edge = None  # in a chattering hold: its length [s] and edge [m]
        start = _time.perf_counter()
        while t < self.t_end - TIME_TOL:
            # ---- what holds on this segment
            if self.fs is not None:
                while next_k / self.fs <= t + TIME_TOL:
                    self.discrete_step(next_k / self.fs, float(y[0]))
                    next_k += 1
            if not continuous:
                u = self.held_command(t - self.delay) + self.disturbance_at(t - self.delay)
                self.seg["u"] = self.saturate(u)
            else:
                self.seg["dist"] = self.disturbance_at(t - self.delay)
            while heap and heap[0] <= t + TIME_TOL:
                heapq.heappop(heap)
            t_b = heap[0] if heap else self.t_end
            if delayed:
                t_b = min(t_b, t + self.delay)
            if hold_len is None and short >= ZENO_COUNT:  # chattering on a level's edge
                hold_len = ZENO_HOLD
                hold_edge = (math.floor(float(y[0]) / self.q) + 0.5) * self.q
                short = 0
            hold = hold_len is not None
            if hold:  # read the level once for the whole segment, as a sampled encoder does
                t_b = min(t_b, t + hold_len)
                holds += 1
                new_cell, new_level = self._set_cells(t, y)
                if delayed and new_level != level:
                    heapq.heappush(heap, t + self.delay)
                    t_b = min(t_b, t + self.delay)
                cell, level = new_cell, new_level
            elif not self._consistent(y, cell, level):  # a missed crossing: trust the state
                cell, level = self._set_cells(t, y)
                resyncs += 1
            self.seg["cell"] = cell
            self.seg["xm"] = None if level is None else level * self.q
            self.seg["mid"] = 0.5 * (t + t_b)
            if delayed and self.q is not None:  # the level seen a delay ago: one per segment
                self.seg["xm_late"] = self.seen(self.seg["mid"] - self.delay, 0.0)
            events = self._events(cell, None if hold else level)
            # errstate: scipy's finite-difference Jacobian grows its step without bound in a
            # column the right-hand side does not depend on (a free mass's position, an unused
            # integrator); the overflow it reports is harmless there
            with np.errstate(over="ignore"):
                sol = solve_ivp(self.rhs, (t, t_b), y, method="Radau", rtol=self.rtol,
                                atol=self.atol, dense_output=True, events=events or None)
            if not sol.success and sol.status != 1:
                raise RuntimeError(f"solve_ivp failed at t = {t:.6g} s: {sol.message}")
            n_seg += 1
            nfev += sol.nfev
            t_new = float(sol.t[-1])
            if sol.status == 1:  # a terminal event: restart at the discontinuity
                n_events += 1
                quick = t_new - t < ZENO_HOLD
                zero_length = zero_length + 1 if t_new - t < 1e-12 else 0
                if zero_length > 1000:  # a safety net: no progress at all
                    raise RuntimeError(f"events without progress at t = {t:.9g} s")
                for ev, te in zip(events, sol.t_events):
                    if len(te) and te[-1] >= t_new - TIME_TOL:
                        if ev.cell is not None:
                            cell = ev.cell
                        if ev.level is not None:
                            level = ev.level
                            self.level_t.append(t_new)
                            self.level_v.append(level)
                            short = short + 1 if quick else 0
                            if delayed:  # the measured position jumps: so does u, later
                                heapq.heappush(heap, t_new + self.delay)
            elif not hold:
                short = 0
            if hold:  # still on the edge: a longer hold next; off it: events again
                if abs(float(sol.y[0, -1]) - hold_edge) > ZENO_BAND * self.q:
                    hold_len = hold_edge = None
                else:
                    hold_len = min(2 * hold_len, self.hold_cap)
            last = t_new >= self.t_end - TIME_TOL
            j = i_out
            while j < n_out and (t_out[j] < t_new - TIME_TOL or (last and j < n_out)):
                j += 1
            if j > i_out:
                states[:, i_out:j] = sol.sol(np.clip(t_out[i_out:j], t, t_new))
                i_out = j
            if delayed:
                self.hist_t.append(t)
                self.hist_sol.append(sol.sol)
            t, y = t_new, sol.y[:, -1].copy()
        while self.fs is not None and next_k / self.fs <= self.t_end + TIME_TOL:
            self.discrete_step(next_k / self.fs, float(y[0]))  # the sample at t_end
            next_k += 1
        self.info = dict(segments=n_seg, nfev=nfev, events=n_events, resyncs=resyncs,
                         zeno_holds=holds,
                         seconds=_time.perf_counter() - start)
        return t_out, states

    def signals(self, t_out, states):
        """Noise-free record columns and truth at the output times."""
        n = len(t_out)
        iso = self.isolated
        x1, v1 = states[0], states[1]
        x2, v2 = (states[2], states[3]) if iso else (x1, v1)
        z = states[self.iz]
        ref = np.empty(n)
        command = np.empty(n)
        applied = np.empty(n)
        friction = np.empty(n)
        measured = np.empty(n)
        dist = None if self.dist is None else np.empty(n)
        continuous = self.drive is None and self.fs is None
        for i, t in enumerate(t_out.tolist()):
            Y = states[:, i].tolist()
            ref[i] = self.ref(t)[0]
            measured[i] = self.seen(t, Y[0]) if continuous else self.measure(Y[0])
            friction[i] = self.friction_force(float(v2[i]), float(z[i]), float(x2[i]))[0]
            dt = self.disturbance_at(t)
            if dist is not None:
                dist[i] = dt
            if continuous:
                command[i] = self.control(t, Y, measured[i])[0] + dt
                u_late = self.history_command(t - self.delay) if self.delay > 0 else \
                    command[i] - dt
            else:
                command[i] = self.held_command(t) + dt
                u_late = self.held_command(t - self.delay)
            applied[i] = self.saturate(u_late + self.disturbance_at(t - self.delay))
        truth = Truth(time=t_out, x1=x1, v1=v1, x2=x2, v2=v2, z=z, friction=friction,
                      applied=applied, command=command, measured=measured)
        return ref, dist, truth


def _event(fun, direction, cell=None, level=None):
    """Mark ``fun`` as a terminal event of ``direction``; after it, the new cell or level."""
    fun.terminal = True
    fun.direction = direction
    fun.cell = cell
    fun.level = level
    return fun


# --------------------------------------------------------------------------- public entry


def generate(m1, m2=0.0, *, friction=None, isolator=None, controller=None, moves=None,
             reference=None, t_end=20.0, rate=1000.0, effects=None, noise=None,
             position_resolution=None, seed=0, disturbance=None, drive_force=None,
             initial=None, rtol=1e-8, atol=None) -> Record:
    """Simulate the true stage and record it as a measurement would.

    Parameters
    ----------
    m1 : float
        Stage mass [kg] (actuator, sensor).
    m2 : float
        Cart mass [kg] (bearing, friction). With ``isolator=None`` the plant is one rigid
        mass m1 + m2.
    friction : dict or None
        ``Fs`` [N], ``Fc`` [N], ``vs`` [m/s], ``sigma0`` [N/m] (LuGre: all four or none),
        ``sigma1`` [N s/m], ``sigma2`` [N s/m], ``Fc_neg`` [N], ``sigma2_neg`` [N s/m]
        (negative direction; None: as positive), ``offset`` [N] (constant force against the
        stage: m1 a1 = u - offset - ...). None: frictionless.
    isolator : dict or None
        ``k`` [N/m], ``s`` [m] (one-sided stroke), ``c`` [N s/m] (default 0), ``k_stop``
        [N/m] (default 1e6), ``c_stop`` [N s/m] (default 2 * 0.2 * sqrt(k_stop * m1), nominal
        m1). None: rigid plant.
    controller : dict or None
        Either ``rule=dict(fc [Hz], r=3, ri=10, mass=m1 + m2 [kg])`` or gains ``kp`` [N/m],
        ``ki`` [N/(m s)], ``kd`` [N s/m], ``roll_off`` [rad/s, unlike the spec's Hz]
        (None: ideal D; with a continuous controller and quantization a roll-off is needed),
        ``derivative_on`` ("error" or "measurement"); plus ``sample_rate`` [Hz] (None:
        continuous), ``delay`` [s], ``force_limit`` [N], ``feedforward=dict(mass [kg], viscous
        [N s/m], coulomb [N])``, ``filters`` (a list of ``dict(type="notch", frequency [Hz],
        width [Hz], depth [dB])`` or ``damping=(zz, zp)``, and ``dict(type="low_pass",
        frequency [Hz], order=1 or 2, damping)``, the spec's keys in Hz). None only with
        ``drive_force``.
    moves : list of dict or None
        Trapezoidal moves run one after another from the initial position: ``distance`` [m],
        ``velocity`` [m/s], ``acceleration`` [m/s^2], ``start`` [s] (optional, not earlier than
        the end of the previous move). None and no ``reference``: hold the initial position.
    reference : (array_like, array_like) or None
        Reference samples (t [s], r [m]), interpolated by a cubic spline, held outside.
    t_end : float
        Duration [s]; the record runs from 0 to t_end.
    rate : float
        Output sample rate [Hz].
    effects : dict or None
        Effects of docs/effects.md, ``{name: {parameter: value}}`` with the
        catalogue's names and SI parameters; each changes the true stage.
    noise : dict or None
        Standard deviations of Gaussian recording noise: ``position`` [m], ``deflection``
        [m], ``force`` [N]. The controller sees the noise-free position.
    position_resolution : float or None
        Recording resolution of the position column [m] (whole counts, after the noise). The
        ``quantization`` effect acts on what the controller sees only; give both the same
        value to record the encoder the controller reads.
    seed : int
        Seed of the noise generator.
    disturbance : (array_like, array_like) or None
        Known force (t [s], F [N]) added to the command, zero-order hold (zero before the first
        sample); it goes through the delay and saturation with the command.
    drive_force : (array_like, array_like) or None
        Open loop: the commanded force (t [s], F [N]), zero-order hold (the first value before
        the first sample), delayed and saturated like a command; no controller.
    initial : dict or None
        ``x1`` [m] (default 0, or r(0) with a sampled reference), ``v1`` [m/s] (default 0: at
        rest, joint relaxed; else cart and bristles in steady sliding at v1), ``integral`` [N]
        (integral term of the controller at t = 0, default 0).
    rtol : float
        Relative tolerance of the integration.
    atol : float or None
        Absolute tolerance for every state; None: rtol times the state's scale (1 mm, 1 mm/s,
        Fc / sigma0 for z).

    Returns
    -------
    Record

    Raises
    ------
    ValueError
        Unknown keys or effects, inconsistent or non-physical arguments.
    RuntimeError
        The integration failed.
    """
    nz = _checked_noise(noise, position_resolution)
    sim = _Simulation(m1=m1, m2=m2, friction=friction, isolator=isolator,
                      controller=controller, moves=moves, reference=reference, t_end=t_end,
                      rate=rate, effects=effects, disturbance=disturbance,
                      drive_force=drive_force, initial=initial, rtol=rtol, atol=atol)
    t_out, states = sim.run()
    ref, dist, truth = sim.signals(t_out, states)
    return _recorded(t_out, ref, dist, truth, sim.isolated, sim.info, nz, position_resolution,
                     seed)


def recorded_again(record: Record, *, seed: int, noise=None,
                   position_resolution=None) -> Record:
    """A record's noise-free signals recorded again with the noise of ``seed``.

    The seed draws the recording noise only (the controller sees the noise-free position):
    this is the record :func:`generate` gives for the same motion with this ``noise``,
    ``position_resolution`` and ``seed``, sample for sample, without simulating again.

    Parameters
    ----------
    record : Record
        A record of :func:`generate` (its ``truth`` is recorded again).
    seed : int
        Seed of the recording noise.
    noise, position_resolution
        As for :func:`generate`.

    Returns
    -------
    Record
    """
    nz = _checked_noise(noise, position_resolution)
    return _recorded(record.time, record.reference, record.disturbance, record.truth,
                     record.deflection is not None, record.info, nz, position_resolution, seed)


def _checked_noise(noise, position_resolution) -> dict:
    nz = dict(noise or {})
    _check_keys(nz, {"position", "deflection", "force"}, "noise")
    if position_resolution is not None and not float(position_resolution) > 0:
        raise ValueError("position_resolution must be positive")
    return nz


def _recorded(t_out, ref, dist, truth, isolated, info, nz, position_resolution, seed) -> Record:
    """The noise-free signals recorded: noise drawn from ``seed`` (position, deflection,
    force, in that order), the position rounded to whole counts."""
    rng = np.random.default_rng(seed)
    n = len(t_out)
    e_pos, e_def, e_force = (rng.standard_normal(n) for _ in range(3))
    position = truth.x1 + float(nz.get("position", 0.0)) * e_pos
    if position_resolution is not None:
        position = np.round(position / float(position_resolution)) * float(position_resolution)
    force = truth.command + float(nz.get("force", 0.0)) * e_force
    deflection = None
    if isolated:
        deflection = truth.x1 - truth.x2 + float(nz.get("deflection", 0.0)) * e_def
    return Record(time=t_out, reference=ref, position=position, force=force,
                  deflection=deflection, disturbance=dist, truth=truth, info=info)
