"""One leaf of the guide in closed form: its stiffness, geometric stiffness, stress and modes.

A leaf is a prismatic beam of length L (along z), width b (along y) and
thickness t (along x), clamped at the cart's end and at the stage's clamp.
Its six-by-six stiffness at the stage's end (the cart's end fixed) is the
node block of the Timoshenko beam element, in the order of
:data:`~fi_design.results.mechanism.DIRECTIONS` (x, y, z, rx, ry, rz):

=====================  =====================================================
drive (x, ry)          ``E I_t / ((1 + phi_x) L^3) [[12, -6 L], [-6 L, (4 + phi_x) L^2]]``
lateral (y, rx)        ``E I_b / ((1 + phi_y) L^3) [[12, 6 L], [6 L, (4 + phi_y) L^2]]``
axial (z)              ``E A / L`` (times :func:`axial_factor` at a deflection)
torsion (rz)           ``G J / L``
=====================  =====================================================

with ``I_t = b t^3 / 12``, ``I_b = t b^3 / 12``, ``A = b t``, the shear
parameter ``phi = 12 E I / (kappa G A L^2)`` (``kappa = 5/6``: short wide
leaves lose lateral stiffness to shear) and Saint-Venant's torsion constant
``J = b t^3 / 3 (1 - 0.63 t / b)``. Clamped-guided (the clamp not rotating),
the drive stiffness is ``12 E I_t / L^3 = E b t^3 / L^3`` per leaf.

An axial force N (tension positive) adds the consistent geometric stiffness
``N / (30 L) [[36, -3 L], [-3 L, 4 L^2]]`` to each bending plane (``+3 L``
in the lateral plane): ``6 N / (5 L)`` in the drive direction, the
``-1.2 m1 g / L`` of a standing guide.

Every function broadcasts over arrays of L, b, t, so the sizing can evaluate
a whole grid of leaves at once; matrices have the shape ``(..., 6, 6)``.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["SHEAR_FACTOR", "CLAMPED_CLAMPED_ROOT", "CLAMPED_GUIDED_ROOT", "torsion_constant",
           "stiffness_block", "geometric_block", "axial_factor", "bending_stress",
           "stroke_limit", "bending_frequency", "torsion_frequency", "sway_buckling_load"]

#: Shear correction factor of a rectangular section [-].
SHEAR_FACTOR = 5.0 / 6.0
#: First root of cos(x) cosh(x) = 1: the clamped-clamped beam's first bending mode [-].
CLAMPED_CLAMPED_ROOT = 4.730040744862704
#: First root of tan(x) + tanh(x) = 0: the clamped-guided beam's first bending mode [-].
CLAMPED_GUIDED_ROOT = 2.365020372431352
#: Coefficient of the elastokinematic axial compliance of a clamped-guided beam in Awtar's
#: beam constraint model: the normalised axial compliance is 1/d + (u/L)^2 / 700 [-].
BCM_AXIAL = 700.0


def torsion_constant(width, thickness):
    """Saint-Venant torsion constant of a thin rectangle, ``b t^3 / 3 (1 - 0.63 t / b)`` [m^4].

    Parameters
    ----------
    width, thickness : float or numpy.ndarray
        b >= t [m].
    """
    return width * thickness ** 3 / 3.0 * (1.0 - 0.63 * thickness / width)


def _zeros(*arrays):
    shape = np.broadcast(*arrays).shape
    return np.zeros(shape + (6, 6))


def stiffness_block(E, G, length, width, thickness, axial=1.0):
    """Stiffness of one leaf at its stage end, the cart's end clamped [N/m, N, N m/rad].

    Parameters
    ----------
    E, G : float
        Young's and shear modulus [Pa].
    length, width, thickness : float or numpy.ndarray
        L, b, t [m]; arrays broadcast.
    axial : float or numpy.ndarray, optional
        Factor on the axial stiffness E A / L (:func:`axial_factor` at a
        deflection). Default 1.

    Returns
    -------
    numpy.ndarray, shape (..., 6, 6)
        In the order x, y, z, rx, ry, rz.
    """
    L, b, t = np.asarray(length, float), np.asarray(width, float), np.asarray(thickness, float)
    A = b * t
    It, Ib = b * t ** 3 / 12.0, t * b ** 3 / 12.0
    phx = 12.0 * E * It / (SHEAR_FACTOR * G * A * L ** 2)
    phy = 12.0 * E * Ib / (SHEAR_FACTOR * G * A * L ** 2)
    K = _zeros(L, b, t, axial)
    cx = E * It / ((1.0 + phx) * L ** 3)
    cy = E * Ib / ((1.0 + phy) * L ** 3)
    K[..., 0, 0] = 12.0 * cx
    K[..., 0, 4] = K[..., 4, 0] = -6.0 * L * cx
    K[..., 4, 4] = (4.0 + phx) * L ** 2 * cx
    K[..., 1, 1] = 12.0 * cy
    K[..., 1, 3] = K[..., 3, 1] = 6.0 * L * cy
    K[..., 3, 3] = (4.0 + phy) * L ** 2 * cy
    K[..., 2, 2] = E * A / L * axial
    K[..., 5, 5] = G * torsion_constant(b, t) / L
    return K


def geometric_block(force, length):
    """Consistent geometric stiffness of one leaf under an axial force, at its stage end.

    Parameters
    ----------
    force : float or numpy.ndarray
        Axial force N in the leaf [N], tension positive.
    length : float or numpy.ndarray
        L [m].

    Returns
    -------
    numpy.ndarray, shape (..., 6, 6)
        ``N / (30 L) [[36, -+3 L], [-+3 L, 4 L^2]]`` in the planes (x, ry) and
        (y, rx); zero in z and rz.
    """
    N, L = np.asarray(force, float), np.asarray(length, float)
    K = _zeros(N, L)
    c = N / (30.0 * L)
    for u, r, sign in ((0, 4, -1.0), (1, 3, 1.0)):
        K[..., u, u] = 36.0 * c
        K[..., u, r] = K[..., r, u] = sign * 3.0 * L * c
        K[..., r, r] = 4.0 * L ** 2 * c
    return K


def axial_factor(deflection, thickness):
    """Share of the axial stiffness left at a drive deflection (Awtar's beam constraint model).

    A clamped-guided leaf deflected by u loses axial stiffness: its
    normalised axial compliance ``1/d + (u/L)^2 / 700`` with ``d = 12 L^2 / t^2``
    gives the factor ``1 / (1 + 12 u^2 / (700 t^2))``, independent of L.

    Parameters
    ----------
    deflection : float or numpy.ndarray
        Drive deflection u [m].
    thickness : float or numpy.ndarray
        t [m].

    Returns
    -------
    float or numpy.ndarray
        The factor, 1 undeflected [-].

    Examples
    --------
    >>> round(float(axial_factor(0.9e-3, 0.1e-3)), 3)
    0.419
    """
    u, t = np.asarray(deflection, float), np.asarray(thickness, float)
    return 1.0 / (1.0 + 12.0 * u ** 2 / (BCM_AXIAL * t ** 2))


def bending_stress(E, thickness, length, deflection):
    """Peak bending stress ``3 E t u / L^2`` of a clamped-guided leaf deflected by u [Pa]."""
    return 3.0 * E * thickness * deflection / length ** 2


def stroke_limit(allowed_stress, E, thickness, length):
    """Largest deflection ``sigma_allow L^2 / (3 E t)`` within the allowed stress [m]."""
    return allowed_stress * length ** 2 / (3.0 * E * thickness)


def bending_frequency(E, density, length, width, thickness, force=0.0):
    """First bending mode of one leaf in the drive direction, clamped at both ends [Hz].

    ``lambda^2 / (2 pi L^2) sqrt(E I / (rho A))`` with ``lambda`` =
    :data:`CLAMPED_CLAMPED_ROOT` (the stage far heavier than the leaf), times
    ``sqrt(1 + N / N_cr)`` for an axial force N against the clamped-clamped
    buckling load ``N_cr = 4 pi^2 E I / L^2``.

    Parameters
    ----------
    E, density : float
        [Pa], [kg/m^3].
    length, width, thickness : float or numpy.ndarray
        L, b, t [m].
    force : float or numpy.ndarray, optional
        Axial force in the leaf [N], tension positive.

    Examples
    --------
    >>> round(float(bending_frequency(200e9, 7800.0, 50.7e-3, 23.9e-3, 0.45e-3)), 1)
    911.2
    """
    L, b, t = np.asarray(length, float), np.asarray(width, float), np.asarray(thickness, float)
    f0 = CLAMPED_CLAMPED_ROOT ** 2 / (2.0 * math.pi * L ** 2) * t * np.sqrt(E / (12.0 * density))
    n_cr = 4.0 * math.pi ** 2 * E * b * t ** 3 / 12.0 / L ** 2
    return f0 * np.sqrt(np.maximum(0.0, 1.0 + force / n_cr))


def torsion_frequency(G, density, length, width, thickness):
    """First torsion mode of one leaf, clamped at both ends: ``sqrt(G J / (rho I_p)) / (2 L)`` [Hz]."""
    L, b, t = np.asarray(length, float), np.asarray(width, float), np.asarray(thickness, float)
    ip = b * t * (b * b + t * t) / 12.0
    return np.sqrt(G * torsion_constant(b, t) / (density * ip)) / (2.0 * L)


def sway_buckling_load(leaves, E, length, width, thickness):
    """Euler sway load of a parallel guide, ``n pi^2 E I_t / L^2`` [N] (clamped-guided leaves)."""
    return leaves * math.pi ** 2 * E * width * thickness ** 3 / 12.0 / length ** 2
