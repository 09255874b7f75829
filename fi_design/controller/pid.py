"""PID gains from the crossover and the moving mass (guideline step 4).

Light on purpose (``math`` only, no python-control), so the simulation can
import it without paying for ``import control``.

The rule (paper section 2.2; docs/model.md), with ``wc = 2 pi fc`` and
``r = derivative_ratio``, ``ri = integrator_ratio``::

    C(s) = ks (1 + wi/s) (1 + s/wd) / (1 + s/wt)      (series form)
    wd = wc / r,   wt = r wc,   wi = wc / ri,   ks = m wc^2 / r

The lead-lag part ``(1 + s/wd) / (1 + s/wt)`` has its phase maximum at the
geometric mean ``sqrt(wd wt) = wc`` and a gain ``r`` there, so ``ks = m wc^2 / r``
puts ``|C(j wc)| = m wc^2`` without the integrator: a free mass ``1/(m s^2)``
then crosses over at ``wc``. With the default ratio 3 this is
``kp = m wc^2 / 3`` of docs/model.md.

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
from dataclasses import replace

from ..errors import SpecError
from ..results.controller import ControlLaw, DriveUnits, Filter, PidGains

__all__ = ["tune_pid", "pid_gains", "control_law", "at_crossover", "spec_filter"]


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
        raise SpecError(f"mass and crossover must be positive, got {mass!r} kg, {crossover!r} Hz")
    if not (derivative_ratio > 1 and integrator_ratio > 1):
        raise SpecError("derivative_ratio and integrator_ratio must exceed 1")
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
        Crossover fc [Hz]; default ``spec.controller.crossover`` (with
        explicit gains and no crossover, the gains' own). Parameter studies
        retune at each crossover through this argument.
    mass : float, optional
        Tuning mass [kg], overriding the spec's rule.

    Returns
    -------
    PidGains
        The gains. A free mass equal to the tuning mass crosses over a
        fraction of a percent above ``wc``: the integrator raises
        ``|L(j wc)|`` to ``sqrt(1 + 1/ri^2)`` (see the module docstring).
    """
    from ..spec import design_crossover, tuning_mass

    ctl = spec.controller
    fc = design_crossover(spec) if crossover is None else crossover
    if mass is None:
        mass = tuning_mass(spec)
    return pid_gains(mass, fc, ctl.derivative_ratio, ctl.integrator_ratio)


# --------------------------------------------------------------------------- the loop's controller


def control_law(spec, crossover: float | None = None) -> ControlLaw:
    """The loop's controller of a spec (the hardware's gains, or the rule's).

    :func:`fi_design.model.resolve` builds it once per spec; the analyses
    read it from the model (``model.law``) and shift it with
    :meth:`fi_design.model.Model.at`.

    Parameters
    ----------
    spec : fi_design.spec.Spec
        The design spec (``controller`` section and masses).
    crossover : float, optional
        Shift the loop to this crossover [Hz] (:func:`at_crossover`);
        default the spec's (with explicit gains: their own crossover).

    Returns
    -------
    ControlLaw
    """
    from ..spec import design_crossover, tuning_mass

    ctl = spec.controller
    own = design_crossover(spec)
    m = tuning_mass(spec)
    ff = ctl.feedforward
    common = dict(
        derivative_on=ctl.derivative_on,
        sample_period=0.0 if ctl.sample_rate is None else 1.0 / ctl.sample_rate,
        delay=ctl.delay, force_limit=math.inf if ctl.force_limit is None else ctl.force_limit,
        ff_mass=ff.mass if ff else 0.0, ff_viscous=ff.viscous if ff else 0.0,
        ff_coulomb=ff.coulomb if ff else 0.0, tuning_mass=m,
        derivative_ratio=ctl.derivative_ratio, integrator_ratio=ctl.integrator_ratio,
        roll_off_given=ctl.roll_off is not None,
        filters=tuple(spec_filter(f) for f in ctl.filters),
        drive=None if ctl.drive is None else DriveUnits(
            ctl.drive.motor_constant, ctl.drive.encoder_resolution,
            1.0 if ctl.drive.current_scaling is None else ctl.drive.current_scaling))
    if ctl.gains is None:
        rule = pid_gains(m, own, ctl.derivative_ratio, ctl.integrator_ratio)
        f = rule.filtered_d()
        wf = rule.wt if ctl.roll_off is None else 2.0 * math.pi * ctl.roll_off
        law = ControlLaw(source="rule", crossover=own, kp=f["kp"], ki=f["ki"], kd=f["kd"],
                         roll_off=wf, rule=rule, **common)
    else:
        g = ctl.gains
        wf = math.inf if ctl.roll_off is None else 2.0 * math.pi * ctl.roll_off
        law = ControlLaw(source="gains", crossover=own, kp=g.kp, ki=g.ki, kd=g.kd, roll_off=wf,
                         rule=pid_gains(m, own, ctl.derivative_ratio, ctl.integrator_ratio),
                         **common)
    return law if crossover is None else at_crossover(law, crossover)


def spec_filter(entry) -> Filter:
    """One entry of ``controller.filters`` as the law's :class:`~fi_design.results.controller.Filter`.

    Parameters
    ----------
    entry : fi_design.spec.Notch or fi_design.spec.LowPass
        The spec's filter.

    Returns
    -------
    Filter
        A notch with its zeros' and poles' damping; a low-pass of order 1
        (``zeta_pole`` 1, unused) or 2 (its damping, Butterworth by default).
    """
    if entry.type == "notch":
        return Filter("notch", entry.name, entry.frequency, zeta_pole=entry.zeta_pole,
                      zeta_zero=entry.zeta_zero, order=2)
    from ..spec import BUTTERWORTH

    zeta = 1.0 if entry.order == 1 else (BUTTERWORTH if entry.damping is None
                                         else entry.damping)
    return Filter("low_pass", entry.name, entry.frequency, zeta_pole=zeta, order=entry.order)


def at_crossover(law: ControlLaw, crossover: float) -> ControlLaw:
    """The same loop shifted to another crossover [Hz].

    The rule retunes (:func:`pid_gains`; a roll-off the spec gives stays
    where it is, the default moves with the rule's wt); explicit gains
    scale in frequency by ``lam = crossover / law.crossover`` (kp lam^2,
    ki lam^3, kd lam, roll-off lam), which keeps the loop's shape and is
    exactly what retuning the rule does. The filters stay where they are
    (a notch sits at a mode, a low-pass where the hardware needs it).

    Parameters
    ----------
    law : ControlLaw
        The loop's controller.
    crossover : float
        The new crossover [Hz], > 0.

    Returns
    -------
    ControlLaw
        A new law; ``law`` is unchanged.
    """
    rule = pid_gains(law.tuning_mass, crossover, law.derivative_ratio, law.integrator_ratio)
    if law.source == "rule":
        f = rule.filtered_d()
        wf = law.roll_off if law.roll_off_given else rule.wt
        return replace(law, crossover=float(crossover), kp=f["kp"], ki=f["ki"], kd=f["kd"],
                       roll_off=wf, rule=rule)
    lam = crossover / law.crossover
    return replace(law, crossover=float(crossover), kp=law.kp * lam ** 2,
                   ki=law.ki * lam ** 3, kd=law.kd * lam, roll_off=law.roll_off * lam, rule=rule)
