"""The sampled controller a drive computes each period: the PID's recursion and the filters' biquads.

The PID samples as the simulation kernel samples it
(:meth:`fi_design.results.controller.ControlLaw.discrete_form`): a
trapezoidal integrator, a filtered D term by the Tustin rule, an ideal D by
the backward difference; each filter of the chain by the Tustin rule
prewarped at its own frequency (:func:`.filters.tustin_biquad`). For a
filtered D term the PID is python-control's ``c2d(C, T, "tustin")`` of the
continuous one; the tests hold both against it.
"""

from __future__ import annotations

import numpy as np

from ..results.controller import ControlLaw, DiscreteController, SampledFilter
from .filters import tustin_biquad

__all__ = ["discrete_controller", "pid_z"]


def pid_z(law: ControlLaw) -> tuple[np.ndarray, np.ndarray]:
    """The sampled PID alone as C(z) [N/m], descending powers of z.

    Parameters
    ----------
    law : ControlLaw
        A sampled law (``sample_period > 0``).

    Returns
    -------
    num, den : numpy.ndarray
        ``kp + dc (z + 1)/(z - 1) + db (z - 1)/(z - da)`` over one
        denominator (the integrator's term only when ``ki > 0``), equally
        long, ``den[0] = 1``.
    """
    d = law.discrete_form()
    kp, dc, da, db = d["dp"], d["dc"], d["da"], d["db"]
    dpole = np.array([1.0, -da])
    if law.ki > 0.0:
        integ = np.array([1.0, -1.0])
        num = (kp * np.polymul(integ, dpole) + dc * np.polymul([1.0, 1.0], dpole)
               + db * np.polymul(integ, integ))
        den = np.polymul(integ, dpole)
    else:
        num = kp * dpole + db * np.array([1.0, -1.0])
        den = dpole
    return num, den


def discrete_controller(law: ControlLaw) -> DiscreteController | None:
    """The controller as a drive computes it each period, or None for a continuous law.

    Parameters
    ----------
    law : ControlLaw
        The loop's controller; sampled when ``sample_period > 0``.

    Returns
    -------
    DiscreteController or None
        The PID's recursion coefficients, the filters' biquads and the whole
        C(z) (PID times filters).
    """
    T = law.sample_period
    if T <= 0.0:
        return None
    d = law.discrete_form()
    num, den = pid_z(law)
    sampled = []
    for f in law.filters:
        b, a = tustin_biquad(f, T)
        sampled.append(SampledFilter(f.name, tuple(float(x) for x in b),
                                     tuple(float(x) for x in a)))
        num, den = np.polymul(num, b), np.polymul(den, a)
    num = np.concatenate([np.zeros(len(den) - len(num)), num]) / den[0]
    den = den / den[0]
    return DiscreteController(
        sample_rate=1.0 / T, kp=d["dp"], integrator_gain=d["dc"], derivative_pole=d["da"],
        derivative_gain=d["db"], derivative_on=law.derivative_on, filters=tuple(sampled),
        num=tuple(float(x) for x in num), den=tuple(float(x) for x in den))
