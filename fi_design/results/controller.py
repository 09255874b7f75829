"""The loop's controller as values: the rule's PID gains and the control law.

Produced by :func:`fi_design.controller.pid.pid_gains` (the tuning rule, guideline step 4)
and by :func:`fi_design.model.resolve` (the loop's controller of a spec,
through :func:`fi_design.controller.pid.control_law`). The linear analysis, the kernel's
parameters, the replay and the report all read these values; the arithmetic
here only restates a law in another form (parallel, filtered, kernel,
discrete), it never retunes one (that is :func:`fi_design.controller.pid.at_crossover`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from ..display import number, plain, quantity
from . import dataclass_dict

__all__ = ["PidGains", "Filter", "DriveUnits", "ControlLaw", "SampledFilter",
           "DiscreteController", "DriveGains", "DEFAULT_FILTER_NAMES", "filter_label"]

#: The name of a ``controller.filters`` entry the spec leaves unnamed, by type.
DEFAULT_FILTER_NAMES = {"notch": "notch", "low_pass": "low-pass"}


def filter_label(kind: str, name: str) -> str:
    """A filter's name as its description quotes it, after its type: `` 'tilt'``; empty
    where the name is its type's default (``notch 'notch'`` reads as a stutter)."""
    return "" if name == DEFAULT_FILTER_NAMES.get(kind) else f" '{name}'"


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
        return dataclass_dict(self)

    def series(self, s: complex) -> complex:
        """C(s) in series form, for a complex Laplace variable ``s`` [rad/s].

        Returns the controller's complex gain [N/m]; numpy arrays work too.
        """
        return self.ks * (1 + self.wi / s) * (1 + s / self.wd) / (1 + s / self.wt)

    def filtered_d(self) -> dict[str, float]:
        """The same C(s) as ``kp + ki/s + kd s / (1 + s/wt)`` (a filtered D term).

        ``(kp + ki/s + kd s) / (1 + s/wt)`` expands to this form with
        ``kp' = kp - ki/wt`` and ``kd' = kd - kp'/wt`` (expand both over
        s (1 + s/wt)). Returns ``kp`` [N/m], ``ki`` [N/(m s)], ``kd`` [N s/m]
        and the roll-off ``roll_off`` = wt [rad/s].
        """
        kp = self.kp - self.ki / self.wt
        return dict(kp=kp, ki=self.ki, kd=self.kd - kp / self.wt, roll_off=self.wt)


@dataclass(frozen=True)
class Filter:
    """One filter of the drive's chain, in series with the PID on its output.

    A notch ``(s^2 + 2 zeta_zero w s + w^2) / (s^2 + 2 zeta_pole w s + w^2)``;
    a low-pass ``w / (s + w)`` (order 1) or ``w^2 / (s^2 + 2 zeta_pole w s +
    w^2)`` (order 2); ``w = 2 pi frequency``. Unit DC gain.

    Attributes
    ----------
    kind : str
        ``"notch"`` or ``"low_pass"``.
    name : str
        Its label.
    frequency : float
        Centre (notch) or corner (low-pass) frequency [Hz].
    zeta_pole : float
        Damping ratio of the poles [-] (a first-order low-pass: 1, unused).
    zeta_zero : float
        Damping ratio of a notch's zeros [-] (0: a full notch; 0 for a low-pass, unused).
    order : int
        1 or 2 (a notch: 2).
    """

    kind: str
    name: str
    frequency: float
    zeta_pole: float
    zeta_zero: float = 0.0
    order: int = 2

    @property
    def width(self) -> float | None:
        """A notch's -3 dB bandwidth as a full notch, 2 zeta_pole frequency [Hz]; None for a low-pass."""
        return 2.0 * self.zeta_pole * self.frequency if self.kind == "notch" else None

    @property
    def depth(self) -> float | None:
        """A notch's attenuation at its centre, 20 log10(zeta_pole / zeta_zero) [dB] (inf: full)."""
        if self.kind != "notch":
            return None
        return math.inf if self.zeta_zero == 0.0 else 20.0 * math.log10(self.zeta_pole
                                                                        / self.zeta_zero)

    def describe(self) -> str:
        """The filter in words: ``notch 'tilt' at 150 Hz, 75 Hz wide (full depth)``."""
        if self.kind == "notch":
            d = self.depth
            depth = "full depth" if math.isinf(d) else f"{quantity(d, 'dB', 3)} deep"
            return (f"notch{filter_label(self.kind, self.name)} at "
                    f"{quantity(self.frequency, 'Hz', 4)}, "
                    f"{quantity(self.width, 'Hz', 3)} wide ({depth})")
        if self.order == 1:
            return (f"first-order low-pass{filter_label(self.kind, self.name)} at "
                    f"{quantity(self.frequency, 'Hz', 4)}")
        return (f"second-order low-pass{filter_label(self.kind, self.name)} at "
                f"{quantity(self.frequency, 'Hz', 4)}, "
                f"damping {number(self.zeta_pole, 3)}")

    def to_dict(self) -> dict:
        """JSON: ``type``, ``name``, ``frequency`` [Hz], ``order``, and a notch's ``width`` [Hz],
        ``depth`` [dB] (null: full) and ``damping`` [zeta of the zeros, zeta of the poles] or a
        second-order low-pass's ``damping`` [-]: the spec's keys."""
        out: dict = {"type": self.kind, "name": self.name, "frequency": self.frequency,
                     "order": self.order}
        if self.kind == "notch":
            d = self.depth
            out.update(width=self.width, depth=None if math.isinf(d) else d,
                       damping=[self.zeta_zero, self.zeta_pole])
        elif self.order == 2:
            out["damping"] = self.zeta_pole
        return out

    def spec_entry(self) -> dict:
        """The filter as ``controller.filters`` takes it in the spec file: a notch by its
        frequency and width (and depth unless full), a low-pass by its order (and damping)."""
        out: dict = {"type": self.kind, "name": self.name,
                     "frequency": f"{plain(self.frequency, 6)} Hz"}
        if self.kind == "notch":
            out["width"] = f"{plain(self.width, 6)} Hz"
            if not math.isinf(self.depth):
                out["depth"] = f"{plain(self.depth, 6)} dB"
        else:
            out["order"] = self.order
            if self.order == 2:
                out["damping"] = self.zeta_pole
        return out


@dataclass(frozen=True)
class DriveUnits:
    """The drive's units (``controller.drive``).

    Attributes
    ----------
    motor_constant : float
        Force constant [N/A].
    encoder_resolution : float
        Length of one encoder count [m].
    current_scaling : float
        Amperes per unit of the drive's current command [A].
    """

    motor_constant: float
    encoder_resolution: float
    current_scaling: float = 1.0

    @property
    def force_per_unit(self) -> float:
        """Force of one unit of current command [N]: motor_constant x current_scaling."""
        return self.motor_constant * self.current_scaling

    def to_dict(self) -> dict:
        """JSON: the three values [N/A, m, A]."""
        return dataclass_dict(self)


@dataclass(frozen=True)
class SampledFilter:
    """One filter of the chain as the drive computes it each period (a biquad).

    ``y_k = b0 x_k + b1 x_{k-1} + b2 x_{k-2} - a1 y_{k-1} - a2 y_{k-2}``
    (:func:`scipy.signal.lfilter`'s convention; a first-order low-pass has
    two coefficients each).

    Attributes
    ----------
    name : str
        The filter's label.
    b : tuple of float
        Numerator, descending powers of z [-].
    a : tuple of float
        Denominator, descending powers of z, ``a[0] = 1`` [-].
    """

    name: str
    b: tuple[float, ...]
    a: tuple[float, ...]


@dataclass(frozen=True)
class DiscreteController:
    """The controller as a drive computes it, once per sample period.

    Per sample, with ``e_k = r_k - x_k`` and ``d_k`` the D term's input
    (``e_k``, or ``-x_k`` with the D term on the measurement)::

        I_k = I_{k-1} + integrator_gain (e_k + e_{k-1})       (trapezoidal)
        D_k = derivative_pole D_{k-1} + derivative_gain (d_k - d_{k-1})
        v_k = kp e_k + I_k + D_k
        u_k = the filters' biquads in turn on v_k

    The integrator and a filtered D term by the Tustin rule (``ki T / 2``;
    ``(2 - wf T)/(2 + wf T)`` and ``2 kd wf / (2 + wf T)``), an ideal D by the
    backward difference (pole 0, gain ``kd / T``); each filter by the Tustin
    rule prewarped at its own frequency.

    Attributes
    ----------
    sample_rate : float
        Sample rate [Hz].
    kp : float
        Proportional gain [N/m].
    integrator_gain : float
        ki T / 2 [N/m].
    derivative_pole : float
        Pole of the D term's recursion [-].
    derivative_gain : float
        Gain of the D term's recursion [N/m].
    derivative_on : str
        ``"error"`` or ``"measurement"``.
    filters : tuple of SampledFilter
        The filter chain, in order.
    num, den : tuple of float
        The whole controller C(z) = F(z) C_pid(z) from the error to the force
        command [N/m], descending powers of z (equally long, ``den[0] = 1``):
        with the D term on the measurement, the loop's (from -x), which is
        what the margins see.
    """

    sample_rate: float
    kp: float
    integrator_gain: float
    derivative_pole: float
    derivative_gain: float
    derivative_on: str
    filters: tuple[SampledFilter, ...]
    num: tuple[float, ...]
    den: tuple[float, ...]


@dataclass(frozen=True)
class DriveGains:
    """The loop's gains in the drive's units: encoder counts in, current command out.

    A force F [N] is ``motor_constant x current_scaling`` times the drive's
    current command; a position x [m] is ``encoder_resolution`` times the
    count. Each gain [N/m, N/(m s), N s/m] times ``encoder_resolution /
    (motor_constant current_scaling)``.

    Attributes
    ----------
    current_unit : str
        The drive's unit of current command: ``A``, or the scaled unit
        (``unit of 0.01 A``).
    kp : float
        Proportional gain [current unit / count].
    ki : float
        Integral gain [current unit / (count s)].
    kd : float
        Derivative gain [current unit s / count].
    force_limit : float or None
        The actuator's saturation [current unit]; None: none.
    integrator_gain, derivative_gain : float or None
        A sampled law's recursion gains (:class:`DiscreteController`)
        [current unit / count]; None in continuous time.
    units : dict of str to str
        The unit of each value above, as text.
    """

    current_unit: str
    kp: float
    ki: float
    kd: float
    force_limit: float | None
    integrator_gain: float | None
    derivative_gain: float | None
    units: dict[str, str]


@dataclass(frozen=True)
class ControlLaw:
    """The controller of the loop: one description for the linear analysis, the kernel and the report.

    A parallel PID with a first-order low-pass on the D term, acting on the
    error e = r - x (x the measured position)::

        u = kp e + ki integral(e) + kd s / (1 + s / roll_off) d + feedforward

    where ``d`` is e (``derivative_on == "error"``) or -x (``"measurement"``:
    velocity feedback). The paper's rule is one such controller: its
    C(s) = (kp + ki/s + kd s) / (1 + s/wt) of :class:`PidGains` is exactly
    ``kp' + ki/s + kd' s / (1 + s/wt)`` (:meth:`PidGains.filtered_d`). Sampled
    with a zero-order hold when ``sample_period`` > 0 (integrator by the
    trapezoidal rule, the D term by the Tustin rule, or the backward
    difference for an ideal D); the command reaches the stage ``delay``
    later, saturated at ``force_limit``. ``filters`` (the drive's chain of
    notch and low-pass filters) act on the PID's output, before the
    feedforward is added; they keep their frequencies when the loop shifts
    to another crossover.

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
        The rule's gains at ``crossover`` (the recommendation beside explicit
        gains; not in the JSON).
    roll_off_given : bool
        Whether the spec gives the roll-off (``controller.roll_off``): the
        rule's law keeps a given roll-off where it is when the crossover
        shifts, and moves the default (its wt) with the crossover (not in the
        JSON).
    filters : tuple of Filter
        The drive's filter chain on the PID's output, in order (empty: none).
    drive : DriveUnits or None
        The drive's units (``controller.drive``), for the hand-off; None: SI only.
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
    roll_off_given: bool = field(default=False, repr=False)
    filters: tuple[Filter, ...] = ()
    drive: DriveUnits | None = None

    @property
    def integrator(self) -> bool:
        """Whether the loop integrates (ki > 0); a PD loop cannot hunt by the paper's mechanism."""
        return self.ki > 0.0

    @property
    def is_rule(self) -> bool:
        """The rule's own controller, unaltered (D on the error, roll-off at its wt)."""
        return (self.source == "rule" and self.derivative_on == "error"
                and self.roll_off == self.rule.wt)

    def kernel_form(self) -> dict[str, float]:
        """Gains of the kernel's continuous law v = kp e + I + kd e' - kdm x', u' = wt (v - u).

        Returns ``kp`` [N/m], ``ki`` [N/(m s)], ``kd`` and ``kdm`` [N s/m],
        ``wt`` [rad/s] of :mod:`fi_design.kernel.layout`: the D term's low-pass moved
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
        return self.rule.filtered_d()

    def to_dict(self) -> dict:
        """Plain JSON data: SI, frequencies in Hz like the spec (``roll_off`` [Hz], null for
        an ideal D; ``sample_period`` [s]), infinities as null; without ``rule``."""
        out = dataclass_dict(self)
        out["roll_off"] = None if math.isinf(self.roll_off) else self.roll_off / (2 * math.pi)
        return out
