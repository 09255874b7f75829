"""The reference trajectory r(t) (the setpoint the stage follows) as a piecewise cubic.

Both kinds of reference the simulation needs are stored the same way, so the
kernel evaluates one representation:

- the spec's moves (trapezoidal velocity, or jerk-limited "S-curve" when a jerk
  is given): exact polynomials with breakpoints where the acceleration or jerk
  jumps; the integrator lands its steps on these breakpoints;
- a sampled reference (measured data): a C2 cubic spline through the samples,
  smooth enough that no landing is needed.

On segment ``k`` (``breaks[k] <= t < breaks[k+1]``) with ``tau = t - breaks[k]``:
``r = c0 + c1 tau + c2 tau^2 + c3 tau^3`` with ``coeffs[k] = (c0, c1, c2, c3)``.
Before the first break r holds ``coeffs[0, 0]``; after the last it holds the end
value of the last segment.
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np


@dataclass(frozen=True, eq=False)
class Trajectory:
    """A piecewise cubic reference trajectory r(t).

    Attributes
    ----------
    breaks : ndarray, shape (n + 1,)
        Segment boundaries [s], increasing.
    coeffs : ndarray, shape (n, 4)
        Power-form coefficients per segment [m, m/s, m/s^2, m/s^3].
    land : bool
        Whether the integrator must land its steps on the breaks (true for
        move profiles, whose acceleration jumps there).
    """

    breaks: np.ndarray
    coeffs: np.ndarray
    land: bool = True

    def __post_init__(self) -> None:
        b = np.array(self.breaks, dtype=float)
        c = np.array(self.coeffs, dtype=float).reshape(-1, 4)
        if b.ndim != 1 or len(b) != len(c) + 1 or np.any(np.diff(b) <= 0):
            raise ValueError("breaks must be increasing with one more entry than coeffs rows")
        b.flags.writeable = False
        c.flags.writeable = False
        object.__setattr__(self, "breaks", b)
        object.__setattr__(self, "coeffs", c)

    def __call__(self, t, derivative: int = 0) -> np.ndarray:
        """Evaluate r (``derivative=0``), dr/dt (1) or d2r/dt2 (2) at times ``t`` [s]."""
        t = np.asarray(t, dtype=float)
        b, c = self.breaks, self.coeffs
        k = np.clip(np.searchsorted(b, t, side="right") - 1, 0, len(c) - 1)
        tau = np.clip(t - b[k], 0.0, b[k + 1] - b[k])
        before = t < b[0]
        tau = np.where(before, 0.0, tau)
        out = _cubic(c[k, 0], c[k, 1], c[k, 2], c[k, 3], tau, derivative)
        if derivative == 0:
            return out
        outside = before | (t >= b[-1])  # the derivatives of the holds are zero
        return np.where(outside, 0.0, out)

    @cached_property
    def _lists(self) -> tuple[list, list]:
        """The breaks and coefficients as Python lists, made at the first :meth:`at`."""
        return self.breaks.tolist(), self.coeffs.tolist()

    def at(self, t: float, derivative: int = 0) -> float:
        """r (``derivative=0``), dr/dt (1) or d2r/dt2 (2) at one time ``t`` [s], as a float.

        The same arithmetic as calling the trajectory, bit for bit, without numpy's
        cost per call: for solvers that evaluate r at every right-hand side.
        """
        b, c = self._lists
        k = min(max(bisect.bisect_right(b, t) - 1, 0), len(c) - 1)
        before = t < b[0]
        tau = 0.0 if before else min(max(t - b[k], 0.0), b[k + 1] - b[k])
        out = _cubic(*c[k], tau, derivative)
        return 0.0 if derivative and (before or t >= b[-1]) else out

    @property
    def final(self) -> float:
        """The held end position [m]."""
        return float(_cubic(*self.coeffs[-1], self.breaks[-1] - self.breaks[-2], 0))


def _cubic(c0, c1, c2, c3, tau, derivative: int):
    """One segment's r (``derivative=0``), dr/dt (1) or d2r/dt2 (2) at ``tau`` [s] after its
    start, for floats and arrays alike (one expression for both evaluations of a trajectory)."""
    if derivative == 0:
        return c0 + tau * (c1 + tau * (c2 + tau * c3))
    if derivative == 1:
        return c1 + tau * (2 * c2 + 3 * tau * c3)
    if derivative == 2:
        return 2 * c2 + 6 * tau * c3
    raise ValueError("derivative must be 0, 1 or 2")


def jerk_profile_times(d: float, v: float, a: float, j: float) -> tuple[float, float, float]:
    """Phase durations of a jerk-limited move over distance ``d`` > 0.

    Returns ``(tj, ta, tv)``: jerk phase, constant-acceleration phase and
    constant-velocity phase [s]. The move takes ``4 tj + 2 ta + tv``.
    """

    def accel_phase(vp: float) -> tuple[float, float]:
        ap = min(a, math.sqrt(vp * j))
        tj = ap / j
        ta = max(vp / ap - tj, 0.0)
        return tj, ta

    tj, ta = accel_phase(v)
    if v * (2 * tj + ta) <= d:
        return tj, ta, (d - v * (2 * tj + ta)) / v
    lo, hi = 0.0, v
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        tj, ta = accel_phase(mid)
        if mid * (2 * tj + ta) > d:
            hi = mid
        else:
            lo = mid
    tj, ta = accel_phase(lo)
    return tj, ta, max(d / lo - (2 * tj + ta), 0.0) if lo > 0 else 0.0


def _move_jerks(distance: float, v: float, a: float, j: float | None) -> list[tuple[float, float, float]]:
    """Segments of one move as ``(duration, jerk, acceleration at start)`` for a positive move."""
    d = abs(distance)
    if j is None:
        if v * v / a >= d:
            ta = math.sqrt(d / a)
            return [(ta, 0.0, a), (ta, 0.0, -a)]
        ta, tv = v / a, d / v - v / a
        segs = [(ta, 0.0, a)]
        if tv > 0:
            segs.append((tv, 0.0, 0.0))
        segs.append((ta, 0.0, -a))
        return segs
    tj, ta, tv = jerk_profile_times(d, v, a, j)
    ap = j * tj
    segs = [(tj, j, 0.0)]
    if ta > 0:
        segs.append((ta, 0.0, ap))
    segs.append((tj, -j, ap))
    if tv > 0:
        segs.append((tv, 0.0, 0.0))
    segs.append((tj, -j, 0.0))
    if ta > 0:
        segs.append((ta, 0.0, -ap))
    segs.append((tj, j, -ap))
    return segs


def profile_duration(distance: float, velocity: float, acceleration: float,
                     jerk: float | None = None) -> float:
    """Duration [s] of one move over ``distance`` [m] with the given limits (SI)."""
    return sum(seg[0] for seg in _move_jerks(distance, velocity, acceleration, jerk))


def from_moves(moves, duration: float) -> Trajectory:
    """Build the reference of a sequence of moves starting from r = 0 at rest.

    Parameters
    ----------
    moves : sequence of fi_design.spec.Move
        The moves, run one after another; a move's ``start`` [s] delays it.
    duration : float
        End time [s]; the last position is held until then.
    """
    breaks = [0.0]
    coeffs: list[tuple[float, float, float, float]] = []
    t, p = 0.0, 0.0

    def hold(until: float) -> None:
        nonlocal t
        if until > t + 1e-12:
            coeffs.append((p, 0.0, 0.0, 0.0))
            breaks.append(until)
            t = until

    for mv in moves:
        if mv.start is not None:
            hold(mv.start)
        sgn = 1.0 if mv.distance > 0 else -1.0
        vel = 0.0
        for dur, jerk, acc in _move_jerks(mv.distance, mv.velocity, mv.acceleration, mv.jerk):
            if dur <= 1e-12:  # a phase the limits leave out (round-off of the bisection)
                continue
            jk, ak = sgn * jerk, sgn * acc
            coeffs.append((p, vel, ak / 2.0, jk / 6.0))
            p = p + vel * dur + ak * dur ** 2 / 2.0 + jk * dur ** 3 / 6.0
            vel = vel + ak * dur + jk * dur ** 2 / 2.0
            t += dur
            breaks.append(t)
    hold(max(duration, t + 1e-9))
    return Trajectory(np.array(breaks), np.array(coeffs), land=True)


def from_samples(time_s: np.ndarray, reference_m: np.ndarray) -> Trajectory:
    """A C2 cubic spline through sampled reference values (measured data).

    Parameters
    ----------
    time_s : ndarray, shape (n,)
        Sample times [s], increasing.
    reference_m : ndarray, shape (n,)
        Reference positions [m].
    """
    from scipy.interpolate import CubicSpline

    t = np.asarray(time_s, dtype=float)
    r = np.asarray(reference_m, dtype=float)
    cs = CubicSpline(t, r, bc_type="natural")
    c = cs.c[::-1].T  # scipy stores highest power first, shape (4, n-1)
    return Trajectory(t, c, land=False)
