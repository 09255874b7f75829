"""PID gains from the crossover and the moving mass (guideline step 4).

Light on purpose (``math`` only, no python-control), so the simulation can
import it without paying for ``import control``.

The rule (DESIGN.md section 2, paper section 2.2), with ``wc = 2 pi fc`` and
``r = derivative_ratio``, ``ri = integrator_ratio``::

    C(s) = ks (1 + wi/s) (1 + s/wd) / (1 + s/wt)      (series form)
    wd = wc / r,   wt = r wc,   wi = wc / ri,   ks = m wc^2 / r

The lead-lag part ``(1 + s/wd) / (1 + s/wt)`` has its phase maximum at the
geometric mean ``sqrt(wd wt) = wc`` and a gain ``r`` there, so ``ks = m wc^2 / r``
puts ``|C(j wc)| = m wc^2`` without the integrator: a free mass ``1/(m s^2)``
then crosses over at ``wc``. With the default ratio 3 this is DESIGN.md's
``kp = m wc^2 / 3``.

The integrator adds ``|1 + wi/(j wc)| = sqrt(1 + (wi/wc)^2) = sqrt(1 + 1/ri^2)``
(0.5 % for ``ri = 10``), so the exact crossover of a free mass lies a fraction
of a percent above ``wc``. The rule is kept as written; the tests compare with
the exactly solved crossover rather than with ``wc``.

The same controller in parallel form, as the simulation uses it::

    C(s) = (kp + ki/s + kd s) / (1 + s/wt)
    kp = ks (1 + wi/wd),   ki = ks wi,   kd = ks / wd
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .errors import ArgumentError

__all__ = ["PidGains", "tune_pid", "pid_gains"]


@dataclass(frozen=True)
class PidGains:
    """PID gains of the rule, in both series and parallel form.

    Attributes
    ----------
    crossover : float
        Crossover frequency fc the gains are tuned for [Hz].
    wc : float
        Crossover angular frequency 2 pi fc [rad/s].
    tuning_mass : float
        Mass the gains are tuned on [kg] (m1 + m2 or m1).
    ks : float
        Series-form gain [N/m]: ``m wc^2 / derivative_ratio``.
    wi : float
        Integrator corner [rad/s]: ``wc / integrator_ratio``.
    wd : float
        Lead (differentiator) corner [rad/s]: ``wc / derivative_ratio``.
    wt : float
        Roll-off (tamed differentiator) corner [rad/s]: ``derivative_ratio wc``.
    kp : float
        Parallel proportional gain [N/m]: ``ks (1 + wi/wd)``.
    ki : float
        Parallel integral gain [N/(m s)]: ``ks wi``.
    kd : float
        Parallel derivative gain [N s/m]: ``ks / wd``.
    """

    crossover: float
    wc: float
    tuning_mass: float
    ks: float
    wi: float
    wd: float
    wt: float
    kp: float
    ki: float
    kd: float

    def to_dict(self) -> dict:
        """Plain JSON data (SI floats)."""
        from .results import dataclass_dict

        return dataclass_dict(self)

    def series(self, s: complex) -> complex:
        """C(s) in series form, for a complex Laplace variable ``s`` [rad/s].

        Returns the controller's complex gain [N/m]; numpy arrays work too.
        """
        return self.ks * (1 + self.wi / s) * (1 + s / self.wd) / (1 + s / self.wt)


def pid_gains(mass: float, crossover: float, derivative_ratio: float = 3.0,
              integrator_ratio: float = 10.0) -> PidGains:
    """Apply the tuning rule to a mass and a crossover, without a spec.

    Parameters
    ----------
    mass : float
        Tuning mass m [kg], > 0.
    crossover : float
        Crossover frequency fc [Hz], > 0.
    derivative_ratio : float, optional
        r in ``wd = wc / r``, ``wt = r wc`` [-], > 1. Default 3.
    integrator_ratio : float, optional
        ri in ``wi = wc / ri`` [-], > 1. Default 10.

    Returns
    -------
    PidGains
        The gains in series and parallel form.

    Examples
    --------
    >>> g = pid_gains(2.0, 8.0)
    >>> round(g.ks, 1), round(g.kp, 1), round(g.wt, 2)
    (1684.4, 2189.7, 150.8)
    """
    if not (mass > 0 and crossover > 0):
        raise ArgumentError(f"mass and crossover must be positive, got {mass!r} kg, {crossover!r} Hz")
    if not (derivative_ratio > 1 and integrator_ratio > 1):
        raise ArgumentError("derivative_ratio and integrator_ratio must exceed 1")
    wc = 2.0 * math.pi * crossover
    wd = wc / derivative_ratio
    wt = derivative_ratio * wc
    wi = wc / integrator_ratio
    ks = mass * wc * wc / derivative_ratio
    return PidGains(crossover=float(crossover), wc=wc, tuning_mass=float(mass), ks=ks, wi=wi,
                    wd=wd, wt=wt, kp=ks * (1.0 + wi / wd), ki=ks * wi, kd=ks / wd)


def tune_pid(spec, crossover: float | None = None, mass: float | None = None) -> PidGains:
    """PID gains of a spec (guideline step 4).

    Parameters
    ----------
    spec : fi_design.spec.Spec
        The design spec; its ``controller`` section gives the ratios and the
        tuning-mass rule (``total``: m1 + m2, the paper's choice; ``stage``: m1).
    crossover : float, optional
        Crossover fc [Hz]; default ``spec.controller.crossover``. Parameter
        studies retune at each crossover through this argument.
    mass : float, optional
        Tuning mass [kg], overriding the spec's rule.

    Returns
    -------
    PidGains
        The gains. A free mass equal to the tuning mass crosses over a
        fraction of a percent above ``wc``: the integrator raises
        ``|L(j wc)|`` to ``sqrt(1 + 1/ri^2)`` (see the module docstring).
    """
    ctl = spec.controller
    fc = ctl.crossover if crossover is None else crossover
    if mass is None:
        mass = spec.total_mass if ctl.tuning_mass == "total" else spec.stage.mass
    return pid_gains(mass, fc, ctl.derivative_ratio, ctl.integrator_ratio)
