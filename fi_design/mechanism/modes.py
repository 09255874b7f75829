"""How a mode enters the loop's plant: a given mode's factor, a computed mode's modal term.

A parasitic mode the spec gives (``isolator.parasitic_modes``, measured)
multiplies each limit case's plant P(s) by :func:`mode_factor` (unit DC
gain): a non-collocated mode by ``wr^2 / (s^2 + 2 zeta wr s + wr^2)``, a
collocated one also by ``(s^2 + 2 zeta wa s + wa^2) / wa^2`` with its
antiresonance ``wa`` below ``wr``. A mode computed from the flexure guide
adds its modal term :func:`mode_term` by modal superposition, ``P + (r / m1)
/ (s^2 + 2 zeta wr s + wr^2)`` with its participation r from the actuator to
the sensor (zero for a mode that does not show in the drive coordinate).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["mode_factor", "mode_term"]


def mode_factor(mode) -> tuple[np.ndarray, np.ndarray]:
    """Numerator and denominator of one given parasitic mode's factor (unit DC gain).

    Parameters
    ----------
    mode : fi_design.results.mechanism.Mode
        A given mode: frequency [Hz], damping ratio [-], collocated or not
        (with its antiresonance [Hz]).

    Returns
    -------
    num, den : numpy.ndarray
        Descending powers of s [rad/s]: ``wr^2 / (s^2 + 2 zeta wr s + wr^2)``,
        times ``(s^2 + 2 zeta wa s + wa^2) / wa^2`` when collocated.
    """
    wr = 2.0 * math.pi * mode.frequency
    z = mode.damping_ratio
    den = np.array([1.0, 2.0 * z * wr, wr * wr])
    num = np.array([wr * wr])
    if mode.collocated:
        wa = 2.0 * math.pi * mode.antiresonance
        num = (wr * wr / (wa * wa)) * np.array([1.0, 2.0 * z * wa, wa * wa])
    return num, den


def mode_term(mode, stage_mass: float) -> tuple[np.ndarray, np.ndarray]:
    """Numerator and denominator of a computed mode's modal term [m/N].

    Parameters
    ----------
    mode : fi_design.results.mechanism.Mode
        A computed mode: frequency [Hz], damping ratio [-], participation r [-].
    stage_mass : float
        m1 [kg].

    Returns
    -------
    num, den : numpy.ndarray
        ``(r / m1) / (s^2 + 2 zeta wr s + wr^2)``, descending powers of s [rad/s].
    """
    wr = 2.0 * math.pi * mode.frequency
    return (np.array([mode.participation / stage_mass]),
            np.array([1.0, 2.0 * mode.damping_ratio * wr, wr * wr]))
