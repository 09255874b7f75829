"""The bearing's friction as a value: LuGre parameters per sliding direction.

Produced by :func:`fi_design.model.resolve` (the spec's friction, defaults
filled in) and by an identification (the friction a record shows); the
kernel's parameters, the linear analysis and the identification report read
it. :meth:`FrictionLaw.steady_state` is the one steady-state friction curve
(the Stribeck curve of LuGre and of the switch model alike).

Units: forces N, velocities m/s, stiffness N/m, dampings N s/m.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["FrictionLaw"]


@dataclass(frozen=True)
class FrictionLaw:
    """The bearing's friction, resolved: LuGre parameters per sliding direction.

    The negative direction's Coulomb friction and viscous coefficient are
    None where the spec gives none: they then follow the positive
    direction's (the kernel's convention, so that an effect that changes
    ``Fc`` or ``sigma2`` changes both directions). :meth:`coulomb`,
    :meth:`static` and :meth:`viscous` give the value of either direction.

    Attributes
    ----------
    model : str
        ``"lugre"`` or ``"switch"`` (Karnopp-type cross-check).
    Fs : float
        Static friction sliding in the positive direction [N].
    Fc : float
        Coulomb friction in the positive direction [N].
    vs : float
        Stribeck velocity [m/s]; it does not enter where ``Fs == Fc`` (no
        Stribeck term).
    sigma0 : float
        Bristle stiffness [N/m].
    sigma1 : float
        Bristle damping [N s/m] (the spec's default filled in).
    sigma2 : float
        Viscous friction coefficient in the positive direction [N s/m].
    Fc_neg : float or None
        Coulomb friction sliding in the negative direction [N]; None: ``Fc``.
        Static friction that way scales with it: ``Fs Fc_neg / Fc``.
    sigma2_neg : float or None
        Viscous coefficient in the negative direction [N s/m]; None: ``sigma2``.
    """

    model: str
    Fs: float
    Fc: float
    vs: float
    sigma0: float
    sigma1: float
    sigma2: float
    Fc_neg: float | None = None
    sigma2_neg: float | None = None

    def coulomb(self, direction: float) -> float:
        """Coulomb friction [N] sliding in ``direction`` (> 0 positive, < 0 negative)."""
        return self.Fc if direction > 0 or self.Fc_neg is None else self.Fc_neg

    def static(self, direction: float) -> float:
        """Static friction [N] in ``direction``: ``Fs``, scaled by the Coulomb ratio for < 0."""
        return self.Fs if direction > 0 or self.Fc_neg is None else self.Fs * self.Fc_neg / self.Fc

    def viscous(self, direction: float) -> float:
        """Viscous coefficient [N s/m] in ``direction``."""
        return self.sigma2 if direction > 0 or self.sigma2_neg is None else self.sigma2_neg

    @property
    def symmetric(self) -> bool:
        """Whether both directions have the same friction."""
        return self.coulomb(-1) == self.Fc and self.viscous(-1) == self.sigma2

    def steady_state(self, velocity) -> np.ndarray:
        """The steady-state friction force at a constant sliding velocity [N].

        ``sign(v) g(v) + sigma2 v`` with ``g(v) = Fc + (Fs - Fc) exp(-(v/vs)^2)``,
        each term with the values of the sliding direction (the Stribeck
        curve of LuGre and of the switch model alike). At ``v = 0`` the force
        is not determined by the velocity (the bristles carry anything up to
        the breakaway force): the mean of the two one-sided limits,
        ``(Fs - Fs_neg) / 2``, 0 for symmetric friction.

        Parameters
        ----------
        velocity : float or array_like
            Sliding velocity of the cart v [m/s].

        Returns
        -------
        numpy.ndarray
            Friction force [N] acting against the motion, the shape of
            ``velocity``.
        """
        v = np.asarray(velocity, dtype=float)
        sides = []
        for d in (1.0, -1.0):
            side = d * self.coulomb(d) + self.viscous(d) * v
            if self.Fs != self.Fc:  # a Stribeck term (vs does not enter without one)
                gap = self.static(d) - self.coulomb(d)
                side = side + d * gap * np.exp(-(v / self.vs) ** 2)
            sides.append(side)
        pos, neg = sides
        return np.where(v > 0, pos, np.where(v < 0, neg, 0.5 * (pos + neg)))
