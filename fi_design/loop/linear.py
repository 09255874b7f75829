"""The four linear limit cases and their loop margins (guideline step 2).

Near standstill the friction isolator's plant switches between four linear
limit cases (docs/model.md, paper Figure 2), from actuator force u [N]
to stage position x1 [m]:

====================  =====================================================================
name                  model
====================  =====================================================================
``sliding_free``      1: cart sliding, joint free: stage m1 on the joint (k, c) to the cart
                      m2, the cart damped by the viscous friction sigma2
``stuck_free``        2: cart stuck, joint free: as 1, the cart held by the presliding
                      bristles (spring sigma0, damper sigma1 + sigma2)
``sliding_limited``   3: cart sliding, limiter engaged: rigid m1 + m2 damped by sigma2
``stuck_limited``     4: cart stuck, limiter engaged: rigid m1 + m2 on the bristles
====================  =====================================================================

Without an isolator the stage is one rigid mass m1 + m2: cases ``sliding``
(damped by sigma2) and ``stuck`` (on the bristles). The limiter is taken as
rigid in cases 3 and 4 (its contact stiffness is far above the joint's).

Sliding linearises LuGre at a speed well above the Stribeck velocity, where the
friction slope is sigma2 (with direction-dependent friction the smaller of
``viscous`` and ``viscous_negative``: the less damped direction); sticking
linearises it at rest, where ``dz/dt = v`` and the friction force is
``sigma0 x2 + (sigma1 + sigma2) v2``.

Parasitic modes (``model.modes``) enter every isolated case: a mode the spec
gives multiplies it by :func:`mode_factor`; a mode computed from the flexure
guide adds its modal term :func:`mode_term` (modal superposition).

The controller is the loop's :class:`fi_design.controller.pid.ControlLaw` (the rule's
PID or the hardware's gains) in series with the drive's filter chain
(``controller.filters``, :func:`fi_design.controller.controller_polynomials`),
the same description the simulation uses. A sampled controller is analysed
in continuous time with its filters as given (the drive's prewarped Tustin
biquads match them at their own frequencies). The margins do not depend on where the D term acts (error or measurement: the
loop broken at the plant input is the same); the closed loop from the
reference does (:func:`complementary_sensitivity`). The loop's delay
(``controller.delay`` and a ``time_delay`` effect's, which the simulation adds
to it: :attr:`fi_design.model.Model.loop_delay`), plus half a sample period for
the zero-order hold when ``controller.sample_rate`` is set, enters as a Pade
approximation of order ``controller.pade_order``; otherwise the controller is
analysed in continuous time. The other effects of the spec the simulation
carries only.

Margins (:class:`CaseMargins`) come from :func:`control.stability_margins`
with ``returnall=True``; closed-loop stability from the roots of
``den + num`` of the loop. To keep the polynomial root finding well
conditioned, every loop is evaluated with the Laplace variable scaled by the
geometric mean of its poles' magnitudes (``s = w0 s'``; with a millihertz
integrator and kilohertz filters in one loop a scale by the crossover
overflows python-control's squared polynomials); frequencies are scaled back
before they are reported. The highest crossover at which every case keeps its margins is
:func:`fi_design.loop.achievable.achievable_crossover`.

``import control`` takes one to three seconds: callers import this module
lazily, where they use it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any, Sequence

import control
import numpy as np

from ..controller.polynomials import controller_polynomials, pid_polynomials, reference_polynomials
from ..errors import SpecError
from ..mechanism.modes import mode_factor, mode_term
from ..mechanism.plants import (BAND_FACTOR, balanced_scale, case_arguments, rigid_plant,
                                scaled, two_mass_plant)
from ..model import Model, require_model
from ..results import Status, frozen_array
from ..results.controller import ControlLaw, PidGains
from ..results.linear import (CRITERIA, CaseMargins, GainCrossing,
                              LoopAnalysis, PhaseCrossing, loop_crossover)
from ..spec import Requirements

__all__ = [
    "ISOLATED_CASES", "RIGID_CASES", "CASE_DESCRIPTIONS", "CASE_NUMBERS", "BAND_FACTOR",
    "LimitCase", "CaseMargins", "LoopAnalysis",
    "limit_cases", "mode_factor", "mode_term", "delay_time", "delay_polynomials", "controller_polynomials",
    "pid_polynomials", "reference_polynomials",
    "controller_tf", "delay_tf", "loop_polynomials", "loop_transfer_function", "sensitivity",
    "complementary_sensitivity", "loop_margins", "analyse", "judged_margins", "loop_crossover",
]


#: Names of the four limit cases of an isolated stage, in the paper's order.
ISOLATED_CASES = ("sliding_free", "stuck_free", "sliding_limited", "stuck_limited")
#: Names of the two limit cases of a stage without isolator.
RIGID_CASES = ("sliding", "stuck")
#: One line per case, for tables and messages.
CASE_DESCRIPTIONS = {
    "sliding_free": "cart sliding, joint free",
    "stuck_free": "cart stuck, joint free",
    "sliding_limited": "cart sliding, limiter engaged",
    "stuck_limited": "cart stuck, limiter engaged",
    "sliding": "cart sliding (no isolator)",
    "stuck": "cart stuck (no isolator)",
}

#: Number of each case in the paper's order (Figure 2).
CASE_NUMBERS = {**{n: i for i, n in enumerate(ISOLATED_CASES, 1)},
                **{n: i for i, n in enumerate(RIGID_CASES, 1)}}

#: A -180 deg crossing where |L| is below 1 / MUTE (120 dB down: a full notch's zero, where the
#: phase flips) is no crossing to report [-].
MUTE = 1e6


# --------------------------------------------------------------------------- plants


@dataclass(frozen=True, eq=False)
class LimitCase:
    """One linear limit case: the plant from actuator force u [N] to stage position x1 [m].

    Attributes
    ----------
    name : str
        ``sliding_free``, ``stuck_free``, ``sliding_limited``, ``stuck_limited``
        (isolated) or ``sliding``, ``stuck`` (no isolator).
    number : int
        1 to 4 in the paper's order (Figure 2); 1 and 2 without isolator.
    description : str
        The case in words.
    num : numpy.ndarray
        Numerator of P(s) = x1/u, descending powers of s [rad/s], parasitic
        modes included; read-only, shape (n,).
    den : numpy.ndarray
        Denominator of P(s), same convention; read-only.
    plant : control.StateSpace
        The same plant as a state-space model. Physical states first
        (isolated: x1, x2, v1, v2 [m, m/s]; rigid: x, v), then the states of
        the parasitic-mode filters.
    """

    name: str
    number: int
    description: str
    num: np.ndarray
    den: np.ndarray
    plant: Any

    def __call__(self, s):
        """Evaluate P(s) [m/N] at complex ``s`` [rad/s] (scalar or array)."""
        return np.polyval(self.num, s) / np.polyval(self.den, s)


def _rigid(mass: float, damping: float, stiffness: float):
    A = np.array([[0.0, 1.0], [-stiffness / mass, -damping / mass]])
    B = np.array([[0.0], [1.0 / mass]])
    return (control.ss(A, B, np.array([[1.0, 0.0]]), 0.0),
            *rigid_plant(mass, damping, stiffness))


def _two_mass(m1: float, m2: float, k: float, c: float, cart_stiffness: float,
              cart_damping: float):
    """Stage m1 on the joint (k, c) to cart m2; the cart on (cart_stiffness, cart_damping)."""
    A = np.array([
        [0.0, 0.0, 1.0, 0.0],
        [0.0, 0.0, 0.0, 1.0],
        [-k / m1, k / m1, -c / m1, c / m1],
        [k / m2, -(k + cart_stiffness) / m2, c / m2, -(c + cart_damping) / m2],
    ])
    B = np.array([[0.0], [0.0], [1.0 / m1], [0.0]])
    C = np.array([[1.0, 0.0, 0.0, 0.0]])
    sys = control.ss(A, B, C, 0.0)
    return (sys, *two_mass_plant(m1, m2, k, c, cart_stiffness, cart_damping))


def limit_cases(model: Model, modes=None) -> tuple[LimitCase, ...]:
    """The linear limit cases of a model.

    Parameters
    ----------
    model : fi_design.model.Model
        The resolved model (:func:`fi_design.model.resolve`): masses, friction, the joint's
        stiffness and damping (:meth:`~fi_design.model.Model.at` varies them),
        the parasitic modes.
    modes : sequence of fi_design.results.mechanism.Mode, optional
        The parasitic modes to add; default ``model.modes`` (fewer: what a
        mode does to the loop).

    Returns
    -------
    tuple of LimitCase
        Four cases for an isolated stage (:data:`ISOLATED_CASES`), two without
        isolator (:data:`RIGID_CASES`).
    """
    model = require_model(model)
    m1 = model.m1
    raw = {name: (_rigid if plant is rigid_plant else _two_mass)(*args)
           for name, (plant, args) in case_arguments(model).items()}
    modes = model.modes if modes is None else tuple(modes)
    factors = [mode_factor(m) for m in modes if m.source == "given"]
    terms = [mode_term(m, m1) for m in modes if m.source != "given" and m.participation != 0.0]
    out = []
    for i, (name, (sys, num, den)) in enumerate(raw.items(), start=1):
        num, den = np.asarray(num, float), np.asarray(den, float)
        for tn, td in terms:
            num, den = np.polyadd(np.polymul(num, td), np.polymul(den, tn)), np.polymul(den, td)
            # the modal term r/m1 / (s^2 + 2 zeta w s + w^2) as states (x, x')
            term = control.ss([[0.0, 1.0], [-td[2], -td[1]]], [[0.0], [1.0]], [[tn[0], 0.0]],
                              0.0)
            sys = control.parallel(sys, term)
        for fn, fd in factors:
            num, den = np.polymul(num, fn), np.polymul(den, fd)
            sys = control.series(sys, control.ss(control.tf(fn, fd)))
        out.append(LimitCase(name=name, number=i, description=CASE_DESCRIPTIONS[name],
                             num=frozen_array(num), den=frozen_array(den), plant=sys))
    return tuple(out)


def _case(model: Model, case) -> LimitCase:
    if isinstance(case, LimitCase):
        return case
    cases = limit_cases(model)
    for c in cases:
        if c.name == case or c.number == case:
            return c
    names = ", ".join(c.name for c in cases)
    raise SpecError(f"unknown limit case {case!r}; this spec has: {names}")


# --------------------------------------------------------------------------- controller, delay


def delay_time(model: Model) -> float:
    """Loop delay of the linear analysis.

    Parameters
    ----------
    model : fi_design.model.Model
        The resolved model (:func:`fi_design.model.resolve`).

    Returns
    -------
    float
        The loop's delay (:attr:`fi_design.model.Model.loop_delay`: the controller's
        computational delay and a ``time_delay`` effect's, which the simulation adds to it)
        plus half a sample period (zero-order hold) when it samples [s].
    """
    model = require_model(model)
    law = model.law
    t = model.loop_delay
    if law.sample_period > 0.0:
        t += 0.5 * law.sample_period
    return t


def delay_polynomials(model: Model) -> tuple[np.ndarray, np.ndarray]:
    """Pade approximation of :func:`delay_time` (order ``controller.pade_order``).

    Parameters
    ----------
    model : fi_design.model.Model
        The resolved model (:func:`fi_design.model.resolve`).

    Returns
    -------
    num, den : numpy.ndarray
        Descending powers of s [rad/s]; ``([1.], [1.])`` without delay.
    """
    model = require_model(model)
    t = delay_time(model)
    if t <= 0.0:
        return np.array([1.0]), np.array([1.0])
    num, den = control.pade(t, model.spec.controller.pade_order)
    return np.asarray(num, float), np.asarray(den, float)


def controller_tf(controller: ControlLaw | PidGains):
    """The loop's controller as a transfer function.

    Parameters
    ----------
    controller : ControlLaw or PidGains
        The loop's controller, or the rule's gains.

    Returns
    -------
    control.TransferFunction
        C(s) [N/m], s in rad/s.
    """
    return control.tf(*controller_polynomials(controller))


def delay_tf(model: Model):
    """The Pade delay model as a transfer function.

    Parameters
    ----------
    model : fi_design.model.Model
        The resolved model (:func:`fi_design.model.resolve`).

    Returns
    -------
    control.TransferFunction
        The all-pass approximation of :func:`delay_time`; 1 without delay.
    """
    return control.tf(*delay_polynomials(model))


def loop_polynomials(model: Model, case,
                     controller: ControlLaw | PidGains | None = None) \
        -> tuple[np.ndarray, np.ndarray]:
    """Numerator and denominator of the loop L = C D P of one case.

    Parameters
    ----------
    model : fi_design.model.Model
        The resolved model (:func:`fi_design.model.resolve`); ``model.at(crossover=...,
        stiffness=...)`` gives the loop at another crossover or stiffness.
    case : str, int or LimitCase
        Case name (``"stuck_free"``), number (1 to 4) or a :class:`LimitCase`.
    controller : ControlLaw or PidGains, optional
        Use this controller instead of the model's ``law``.

    Returns
    -------
    num, den : numpy.ndarray
        Descending powers of s [rad/s]; L is dimensionless.
    """
    model = require_model(model)
    lc = _case(model, case)
    cn, cd = controller_polynomials(model.law if controller is None else controller)
    dn, dd = delay_polynomials(model)
    return (np.polymul(np.polymul(cn, dn), lc.num), np.polymul(np.polymul(cd, dd), lc.den))


def loop_transfer_function(model: Model, case,
                           controller: ControlLaw | PidGains | None = None):
    """Loop transfer function L(s) = C(s) D(s) P(s) of one limit case.

    Parameters
    ----------
    model : fi_design.model.Model
        The resolved model (:func:`fi_design.model.resolve`).
    case : str, int or LimitCase
        Case name (``"stuck_free"``), number (1 to 4) or a :class:`LimitCase`.
    controller : ControlLaw or PidGains, optional
        Use this controller instead of the model's ``law``.

    Returns
    -------
    control.TransferFunction
        Dimensionless L(s), s in rad/s.
    """
    return control.tf(*loop_polynomials(model, case, controller))


def sensitivity(model: Model, case, controller: ControlLaw | PidGains | None = None):
    """Sensitivity S = 1 / (1 + L) of one limit case.

    Parameters
    ----------
    model : fi_design.model.Model
        The resolved model (:func:`fi_design.model.resolve`).
    case : str, int or LimitCase
        Case name (``"stuck_free"``), number (1 to 4) or a :class:`LimitCase`.
    controller : ControlLaw or PidGains, optional
        Use this controller instead of the model's ``law``.

    Returns
    -------
    control.TransferFunction
        S(s), dimensionless; ``1 / max|S|`` is the modulus margin.
    """
    num, den = loop_polynomials(model, case, controller)
    return control.tf(den, np.polyadd(den, num))


def complementary_sensitivity(model: Model, case,
                              controller: ControlLaw | PidGains | None = None):
    """The closed loop from the reference to x1 of one limit case.

    T = C_r D P / (1 + L), where C_r is the part of the controller acting on
    the error (all of C, or kp + ki/s when the D term acts on the
    measurement); with the D term on the error it is L / (1 + L).

    Parameters
    ----------
    model : fi_design.model.Model
        The resolved model (:func:`fi_design.model.resolve`).
    case : str, int or LimitCase
        Case name (``"stuck_free"``), number (1 to 4) or a :class:`LimitCase`.
    controller : ControlLaw or PidGains, optional
        Use this controller instead of the model's ``law``.

    Returns
    -------
    control.TransferFunction
        T(s), dimensionless.
    """
    model = require_model(model)
    ctl = model.law if controller is None else controller
    num, den = loop_polynomials(model, case, ctl)
    closed = np.polyadd(den, num)
    if isinstance(ctl, PidGains) or ctl.derivative_on == "error":
        return control.tf(num, closed)
    # reference path: C_r D P (1 + L)^-1 = rn dn pn (cd / rd) / closed, where rd divides cd
    lc = _case(model, case)
    cn, cd = controller_polynomials(ctl)
    rn, rd = reference_polynomials(ctl)
    dn, _ = delay_polynomials(model)
    q, _ = np.polydiv(cd, rd)
    return control.tf(np.polymul(np.polymul(rn, dn), np.polymul(lc.num, q)), closed)


# --------------------------------------------------------------------------- margins


def loop_margins(num: Sequence[float], den: Sequence[float], scale: float | None = None,
                 name: str = "", description: str = "") -> CaseMargins:
    """Margins and closed-loop stability of a loop L = num/den.

    Parameters
    ----------
    num, den : array_like
        Loop numerator and denominator, descending powers of s [rad/s].
    scale : float, optional
        Frequency [rad/s] the Laplace variable is scaled by before the
        polynomial root finding; default the geometric mean of the
        denominator's nonzero roots (:func:`fi_design.mechanism.plants.balanced_scale`), which keeps the
        coefficients balanced. Results are reported unscaled.
    name, description : str, optional
        Labels copied into the result.

    Returns
    -------
    CaseMargins
        The margins; ``passed`` is left True (see :func:`analyse`).
    """
    if scale is None:
        scale = balanced_scale(den)
    ns, ds = scaled(num, scale), scaled(den, scale)
    lead = ds[np.nonzero(ds)[0][0]]
    ns, ds = ns / lead, ds / lead
    sys = control.tf(ns, ds)
    gm, pm, sm, wpc, wgc, wms = control.stability_margins(sys, returnall=True)
    gm, pm, sm, wpc, wgc, wms = (np.atleast_1d(np.asarray(a, float))
                                 for a in (gm, pm, sm, wpc, wgc, wms))

    char = np.polyadd(ds, ns)
    char = char[np.nonzero(char)[0][0]:]
    poles = np.roots(char)
    stable = bool(poles.size == 0 or np.all(poles.real < 0.0))

    hz = scale / (2.0 * math.pi)
    if wgc.size:
        dist = np.abs(pm)
        i = int(np.argmin(dist))
        crossover = float(wgc[i] * hz)
        phase = float(dist[i]) if stable else -float(dist[i])
        lag = np.radians(np.mod(pm, 360.0)) / (wgc * scale)
        delay = float(np.min(lag)) if stable else 0.0
        crossings = tuple(float(w * hz) for w in wgc)
        gains = tuple(GainCrossing(frequency=float(w * hz),
                                   phase_margin_deg=float(d) if stable else -float(d),
                                   delay_margin=float(t) if stable else 0.0)
                      for w, d, t in zip(wgc, dist, lag))
    else:
        crossover, phase, delay, crossings = None, math.inf, math.inf if stable else 0.0, ()
        gains = ()
    ok = np.isfinite(gm) & (gm > 0)
    finite = gm[ok]
    if finite.size:
        db = 20.0 * np.log10(finite)
        gain = float(db[int(np.argmin(np.abs(db)))])
        gain = gain if stable else -abs(gain)  # as the phase margin: no margin when unstable
    else:
        gain = math.inf
    phases = tuple(PhaseCrossing(frequency=float(w * hz), gain_margin_db=float(20 * np.log10(g)))
                   for w, g in sorted(zip(wpc[ok], finite)) if g < MUTE)
    if sm.size and np.min(sm) < 1.0:
        modulus, peak_at = float(np.min(sm)), float(wms[int(np.argmin(sm))] * hz)
    else:
        modulus, peak_at = 1.0, None
    return CaseMargins(name=name, description=description, crossover=crossover,
                       phase_margin_deg=phase, gain_margin_db=gain, modulus_margin=modulus,
                       delay_margin=delay, stable=stable, crossovers=crossings,
                       gain_crossings=gains, phase_crossings=phases, modulus_frequency=peak_at)


def _judge(m: CaseMargins, requirements, band_low: float) -> CaseMargins:
    """The case judged against the requirements, with its crossings' band from ``band_low`` [Hz].

    The one place where a limit case is judged (:attr:`CaseMargins.status`,
    :attr:`CaseMargins.criteria`); the guideline's checks, the report and
    the console read the judgement.
    """
    req = requirements
    failed = []
    if not m.stable:
        failed.append("stability")
    if m.phase_margin_deg < req.phase_margin:
        failed.append("phase margin")
    if abs(m.gain_margin_db) < req.gain_margin:
        failed.append("gain margin")
    if req.modulus_margin is not None and m.modulus_margin < req.modulus_margin:
        failed.append("modulus margin")
    in_band = any(f >= band_low for f in m.crossovers)
    gains = tuple(replace(g, in_band=g.frequency >= band_low) for g in m.gain_crossings)
    criteria = {}
    for name in CRITERIA:
        if name == "modulus margin" and req.modulus_margin is None:
            continue
        if name in failed or not m.stable:  # a margin of an unstable loop is no margin
            criteria[name] = Status.FAIL
        elif name == "phase margin" and not in_band:  # no crossing in the loop's band
            criteria[name] = Status.INFO
        else:
            criteria[name] = Status.PASS
    status = (Status.FAIL if failed else Status.INFO if not in_band else Status.PASS)
    return replace(m, passed=not failed, failed=tuple(failed), in_band=in_band, status=status,
                   criteria=criteria, gain_crossings=gains)


def analyse(model: Model, cases: Sequence[LimitCase] | None = None,
            requirements: Requirements | None = None) -> LoopAnalysis:
    """Margins of all limit cases with the model's controller.

    Parameters
    ----------
    model : fi_design.model.Model
        The resolved model (:func:`fi_design.model.resolve`): plant, controller, delay,
        requirements. ``model.at(crossover=..., stiffness=...)`` analyses
        another crossover or stiffness.
    cases : sequence of LimitCase, optional
        Precomputed :func:`limit_cases` of the model (saves rebuilding them
        in a loop).
    requirements : fi_design.spec.Requirements, optional
        The requirements the margins are judged against; default the
        model's (the recommendation judges its candidates with the margins
        raised by their reserve).

    Returns
    -------
    LoopAnalysis
        Per-case margins judged against ``requirements``.
    """
    model = require_model(model)
    lcs = limit_cases(model) if cases is None else tuple(cases)
    law = model.law
    out = judged_margins(model, lcs, first_fail=False, requirements=requirements)
    k = model.joint.stiffness if model.joint is not None else None
    top, which = loop_crossover(out)
    return LoopAnalysis(crossover=law.crossover, stiffness=k, delay=delay_time(model),
                        controller=law, cases=tuple(out), passed=all(c.passed for c in out),
                        loop_crossover=top, loop_crossover_case=which)


def judged_margins(model: Model, lcs: Sequence[LimitCase], first_fail: bool,
             requirements: Requirements | None = None) -> list[CaseMargins]:
    """Judged margins of each case (stopping at the first failing one when ``first_fail``),
    against ``requirements`` (default the model's)."""
    req = model.requirements if requirements is None else requirements
    law = model.law
    cn, cd = controller_polynomials(law)
    dn, dd = delay_polynomials(model)
    ln, ld = np.polymul(cn, dn), np.polymul(cd, dd)
    out = []
    low = law.crossover / BAND_FACTOR
    for lc in lcs:
        m = _judge(loop_margins(np.polymul(ln, lc.num), np.polymul(ld, lc.den),
                                name=lc.name, description=lc.description),
                   req, low)
        out.append(m)
        if first_fail and not m.passed:
            break
    return out
