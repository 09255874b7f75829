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
from dataclasses import dataclass, field, replace

from .errors import SpecError

__all__ = ["PidGains", "tune_pid", "pid_gains", "ControlLaw", "control_law"]


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
    from .spec import design_crossover, tuning_mass

    ctl = spec.controller
    fc = design_crossover(spec) if crossover is None else crossover
    if mass is None:
        mass = tuning_mass(spec)
    return pid_gains(mass, fc, ctl.derivative_ratio, ctl.integrator_ratio)


# --------------------------------------------------------------------------- the loop's controller


@dataclass(frozen=True)
class ControlLaw:
    """The controller of the loop: one description for the linear analysis, the kernel and the report.

    A parallel PID with a first-order low-pass on the D term, acting on the
    error e = r - x (x the measured position)::

        u = kp e + ki integral(e) + kd s / (1 + s / roll_off) d + feedforward

    where ``d`` is e (``derivative_on == "error"``) or -x (``"measurement"``:
    velocity feedback). The paper's rule is one such controller: its
    C(s) = (kp + ki/s + kd s) / (1 + s/wt) of :class:`PidGains` is exactly
    ``kp' + ki/s + kd' s / (1 + s/wt)`` with ``kp' = kp - ki/wt`` and
    ``kd' = kd - kp'/wt`` (expand both over s (1 + s/wt)). Sampled with a
    zero-order hold when ``sample_period`` > 0 (integrator by the trapezoidal
    rule, the D term by the Tustin rule, or the backward difference for an
    ideal D); the command reaches the stage ``delay`` later, saturated at
    ``force_limit``.

    Attributes
    ----------
    source : str
        ``"rule"`` (tuned from the crossover) or ``"gains"`` (the hardware's).
    crossover : float
        The loop's crossover [Hz]: the rule's fc, or where the gains cross a
        free tuning mass over (|C(j w)| = m w^2).
    kp : float
        Proportional gain [N/m].
    ki : float
        Integral gain [N/(m s)]; 0 for a PD loop.
    kd : float
        Derivative gain [N s/m].
    roll_off : float
        Corner of the D term's low-pass [rad/s]; ``inf`` for an ideal D.
    derivative_on : str
        ``"error"`` or ``"measurement"``.
    sample_period : float
        Controller period [s]; 0 for continuous time.
    delay : float
        Computational delay [s].
    force_limit : float
        Actuator saturation [N]; ``inf`` for none.
    ff_mass, ff_viscous, ff_coulomb : float
        Feedforward mass [kg], viscous [N s/m] and Coulomb [N] terms.
    tuning_mass : float
        Mass the rule tunes on, and the crossover refers to [kg].
    derivative_ratio, integrator_ratio : float
        The rule's ratios (``controller`` section) [-].
    rule : PidGains
        The rule's gains at ``crossover`` (the recommendation beside explicit gains).
    """

    source: str
    crossover: float
    kp: float
    ki: float
    kd: float
    roll_off: float
    derivative_on: str
    sample_period: float
    delay: float
    force_limit: float
    ff_mass: float
    ff_viscous: float
    ff_coulomb: float
    tuning_mass: float
    derivative_ratio: float
    integrator_ratio: float
    rule: PidGains = field(repr=False)

    @property
    def integrator(self) -> bool:
        """Whether the loop integrates (ki > 0); a PD loop cannot hunt by the paper's mechanism."""
        return self.ki > 0.0

    @property
    def is_rule(self) -> bool:
        """The rule's own controller, unaltered (D on the error, roll-off at its wt)."""
        return (self.source == "rule" and self.derivative_on == "error"
                and self.roll_off == self.rule.wt)

    def at_crossover(self, crossover: float) -> "ControlLaw":
        """The same loop shifted to another crossover [Hz].

        The rule retunes (:func:`pid_gains`); explicit gains scale in
        frequency by ``lam = crossover / self.crossover`` (kp lam^2, ki lam^3,
        kd lam, roll-off lam), which keeps the loop's shape and is exactly
        what retuning the rule does.
        """
        lam = crossover / self.crossover
        rule = pid_gains(self.tuning_mass, crossover, self.derivative_ratio,
                         self.integrator_ratio)
        if self.source == "rule":
            kp, ki, kd = _filtered_d(rule)
            wf = rule.wt if self.roll_off == self.rule.wt else self.roll_off * lam
            return replace(self, crossover=float(crossover), kp=kp, ki=ki, kd=kd, roll_off=wf,
                           rule=rule)
        return replace(self, crossover=float(crossover), kp=self.kp * lam ** 2,
                       ki=self.ki * lam ** 3, kd=self.kd * lam, roll_off=self.roll_off * lam,
                       rule=rule)

    def kernel_form(self) -> dict[str, float]:
        """Gains of the kernel's continuous law v = kp e + I + kd e' - kdm x', u' = wt (v - u).

        Returns ``kp`` [N/m], ``ki`` [N/(m s)], ``kd`` and ``kdm`` [N s/m],
        ``wt`` [rad/s] of :mod:`fi_design.plant`: the D term's low-pass moved
        onto the whole output (kp + ki/wf on e, kp/wf + kd on e' or kd on -x'),
        which is the same transfer function; the rule's own gains exactly.
        """
        if self.is_rule:
            g = self.rule
            return dict(kp=g.kp, ki=g.ki, kd=g.kd, kdm=0.0, wt=g.wt)
        wf = self.roll_off
        on_error = self.derivative_on == "error"
        if math.isinf(wf):
            return dict(kp=self.kp, ki=self.ki, kd=self.kd if on_error else 0.0,
                        kdm=0.0 if on_error else self.kd, wt=math.inf)
        return dict(kp=self.kp + self.ki / wf, ki=self.ki,
                    kd=self.kp / wf + (self.kd if on_error else 0.0),
                    kdm=0.0 if on_error else self.kd, wt=wf)

    def discrete_form(self) -> dict[str, float]:
        """Coefficients of the kernel's discrete controller (``dp, dc, da, db, dmeas``).

        Per sample: ``u_k = dp e_k + I_k + D_k`` with the trapezoidal
        integrator ``I_k = I_{k-1} + dc (e_k + e_{k-1})`` (dc = ki T / 2) and
        ``D_k = da D_{k-1} + db (d_k - d_{k-1})``: the Tustin rule for a
        filtered D (da = (2 - wf T)/(2 + wf T), db = 2 kd wf/(2 + wf T)), the
        backward difference for an ideal one (da = 0, db = kd / T).
        """
        T = self.sample_period
        wf = self.roll_off
        if math.isinf(wf):
            da, db = 0.0, self.kd / T
        else:
            da, db = (2.0 - wf * T) / (2.0 + wf * T), 2.0 * self.kd * wf / (2.0 + wf * T)
        return dict(dp=self.kp, dc=0.5 * self.ki * T, da=da, db=db,
                    dmeas=1.0 if self.derivative_on == "measurement" else 0.0)

    def static_error(self, force: float) -> float | None:
        """Static position error of a loop without integrator against a force [m].

        ``force / kp``: what a PD loop leaves against, e.g., Coulomb friction;
        None when the loop integrates (no static error).
        """
        return None if self.integrator else force / self.kp

    def hand_off(self) -> dict[str, float | str | None]:
        """This loop in the form the spec's ``controller`` section takes (step 4's hand-off).

        ``controller.gains`` with ``controller.roll_off`` means
        ``kp + ki/s + kd s / (1 + s / (2 pi roll_off))``: the low-pass on the D
        term only. The rule's ``(kp + ki/s + kd s) / (1 + s/wt)``, with the
        roll-off on the whole PID, is the same controller with other numbers
        (see the class docstring); these are the numbers a drive, or the spec,
        takes.

        Returns
        -------
        dict
            ``kp`` [N/m], ``ki`` [N/(m s)], ``kd`` [N s/m], ``roll_off`` [Hz]
            (None for an ideal D), ``derivative_on``, ``sample_rate`` [Hz]
            (None: continuous) and ``delay`` [s], as the analysis used them.
        """
        return {"kp": self.kp, "ki": self.ki, "kd": self.kd,
                "roll_off": None if math.isinf(self.roll_off) else self.roll_off / (2 * math.pi),
                "derivative_on": self.derivative_on,
                "sample_rate": None if self.sample_period == 0 else 1.0 / self.sample_period,
                "delay": self.delay}

    def rule_in_this_form(self) -> dict[str, float]:
        """The rule's gains at this crossover in this controller's form, to set beside it.

        ``kp``, ``ki``, ``kd`` [N/m, N/(m s), N s/m] of ``kp + ki/s + kd s/(1 + s/wt)``
        with the rule's roll-off ``roll_off`` = wt [rad/s]: gains a drive
        with a filtered D term can take as they are.
        """
        kp, ki, kd = _filtered_d(self.rule)
        return dict(kp=kp, ki=ki, kd=kd, roll_off=self.rule.wt)

    def to_dict(self) -> dict:
        """Plain JSON data (SI; rad/s for ``roll_off``, infinities as null; without ``rule``)."""
        from .results import dataclass_dict

        return dataclass_dict(self)


def _filtered_d(g: PidGains) -> tuple[float, float, float]:
    """The rule's gains in the filtered-D form: (kp', ki, kd') with the roll-off wt."""
    kp = g.kp - g.ki / g.wt
    return kp, g.ki, g.kd - kp / g.wt


def control_law(spec, crossover: float | None = None) -> ControlLaw:
    """The loop's controller for a spec (the hardware's gains, or the rule's).

    Parameters
    ----------
    spec : fi_design.spec.Spec
        The design spec (``controller`` section and masses).
    crossover : float, optional
        Shift the loop to this crossover [Hz] (:meth:`ControlLaw.at_crossover`);
        default the spec's (with explicit gains: their own crossover).

    Returns
    -------
    ControlLaw
    """
    from .spec import design_crossover, tuning_mass

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
        derivative_ratio=ctl.derivative_ratio, integrator_ratio=ctl.integrator_ratio)
    if ctl.gains is None:
        fc = own if crossover is None else float(crossover)
        rule = pid_gains(m, fc, ctl.derivative_ratio, ctl.integrator_ratio)
        kp, ki, kd = _filtered_d(rule)
        wf = rule.wt if ctl.roll_off is None else 2.0 * math.pi * ctl.roll_off
        return ControlLaw(source="rule", crossover=fc, kp=kp, ki=ki, kd=kd, roll_off=wf,
                          rule=rule, **common)
    g = ctl.gains
    wf = math.inf if ctl.roll_off is None else 2.0 * math.pi * ctl.roll_off
    law = ControlLaw(source="gains", crossover=own, kp=g.kp, ki=g.ki, kd=g.kd, roll_off=wf,
                     rule=pid_gains(m, own, ctl.derivative_ratio, ctl.integrator_ratio),
                     **common)
    return law if crossover is None else law.at_crossover(crossover)
