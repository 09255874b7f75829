"""The loop's controller C(s) as polynomials: the PID in series with the drive's filters.

The linear analysis (:mod:`fi_design.loop.linear`) builds every loop from these.
C(s) = F(s) C_pid(s), with F the filter chain (:mod:`.filters`, unit DC gain)
on the PID's output; the rule's PID in its series form, any other law in
parallel form with a filtered (or ideal) D term.
"""

from __future__ import annotations

import math

import numpy as np

from ..results.controller import ControlLaw, PidGains
from .filters import chain_polynomials

__all__ = ["pid_polynomials", "controller_polynomials", "reference_polynomials",
           "parallel_polynomials"]


def pid_polynomials(controller: ControlLaw | PidGains) -> tuple[np.ndarray, np.ndarray]:
    """The PID alone (without the filters) as numerator and denominator.

    Parameters
    ----------
    controller : ControlLaw or PidGains
        The loop's controller, or the rule's gains.

    Returns
    -------
    num, den : numpy.ndarray
        Descending powers of s [rad/s], C in N/m. The rule:
        ``ks wt (s + wi)(s + wd) / (wd s (s + wt))``; in general
        ``kp + ki/s + kd s wf / (s + wf)``. Without an integrator the factor
        s cancels (no pole at the origin).
    """
    if isinstance(controller, PidGains) or controller.is_rule:
        g = controller if isinstance(controller, PidGains) else controller.rule
        if g.wi == 0.0:
            return (g.ks * g.wt / g.wd) * np.array([1.0, g.wd]), np.array([1.0, g.wt])
        num = (g.ks * g.wt / g.wd) * np.polymul([1.0, g.wi], [1.0, g.wd])
        return num, np.array([1.0, g.wt, 0.0])
    c = controller
    return parallel_polynomials(c.kp, c.ki, c.kd, c.roll_off)


def _with_filters(controller: ControlLaw | PidGains,
                  pair: tuple[np.ndarray, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    filters = () if isinstance(controller, PidGains) else controller.filters
    if not filters:
        return pair
    fn, fd = chain_polynomials(filters)
    return np.polymul(pair[0], fn), np.polymul(pair[1], fd)


def controller_polynomials(controller: ControlLaw | PidGains) -> tuple[np.ndarray, np.ndarray]:
    """The loop's controller C(s) = F(s) C_pid(s) as numerator and denominator.

    Parameters
    ----------
    controller : ControlLaw or PidGains
        The loop's controller (``model.law``, its ``filters`` in series), or
        the rule's gains (no filters).

    Returns
    -------
    num, den : numpy.ndarray
        Descending powers of s [rad/s], C in N/m (:func:`pid_polynomials`
        times the filter chain).
    """
    return _with_filters(controller, pid_polynomials(controller))


def parallel_polynomials(kp: float, ki: float, kd: float,
                         wf: float) -> tuple[np.ndarray, np.ndarray]:
    """kp + ki/s + kd s wf / (s + wf) (wf = inf: an ideal D) as polynomials in s [rad/s]."""
    if math.isinf(wf):
        num, den = np.array([kd, kp, ki]), np.array([1.0, 0.0])
    else:
        num, den = np.array([kp + kd * wf, kp * wf + ki, ki * wf]), np.array([1.0, wf, 0.0])
    if ki == 0.0:  # no integrator: cancel the common s
        num, den = num[:-1], den[:-1]
    nz = np.nonzero(num)[0]
    return (num[nz[0]:] if nz.size else np.array([0.0])), den


def reference_polynomials(controller: ControlLaw) -> tuple[np.ndarray, np.ndarray]:
    """The part of C(s) that acts on the error (the reference path) [N/m].

    All of C with the D term on the error; F (kp + ki/s) with the D term on
    the measurement (velocity feedback does not see the reference). The
    denominator divides that of :func:`controller_polynomials`.
    """
    if controller.derivative_on == "error":
        return controller_polynomials(controller)
    return _with_filters(controller, parallel_polynomials(controller.kp, controller.ki, 0.0,
                                                          math.inf))
