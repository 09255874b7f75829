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

An axial force N (tension positive) changes the bending stiffness: in the
drive plane exactly, by the beam-column's stability functions
(:func:`beam_column`; to first order ``6 N / (5 L)`` in the drive direction,
the ``-1.2 m1 g / L`` of a standing guide, which a hanging slender leaf
outgrows), in the stiff lateral plane by the consistent geometric stiffness.

Every function broadcasts over arrays of L, b, t, so the sizing can evaluate
a whole grid of leaves at once; matrices have the shape ``(..., 6, 6)``.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["SHEAR_FACTOR", "CLAMPED_CLAMPED_ROOT", "CLAMPED_GUIDED_ROOT", "torsion_constant",
           "stiffness_block", "beam_column", "geometric_block", "axial_factor", "bending_stress",
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
    """Saint-Venant torsion constant of a rectangle, ``a c^3 / 3 (1 - 0.63 c / a)`` [m^4].

    ``a`` the longer side and ``c`` the shorter: ``b t^3 / 3 (1 - 0.63 t / b)``
    for a leaf (b >= t); a section thicker than wide takes its sides the
    other way round (the formula with b < t turns negative).

    Parameters
    ----------
    width, thickness : float or numpy.ndarray
        b, t [m].

    Examples
    --------
    >>> float(torsion_constant(2.0, 1.0)) == float(torsion_constant(1.0, 2.0))
    True
    """
    a, c = np.maximum(width, thickness), np.minimum(width, thickness)
    return a * c ** 3 / 3.0 * (1.0 - 0.63 * c / a)


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


def beam_column(E, I, length, force):
    """Drive-plane stiffness of a beam-column at its end, the other end clamped (exact).

    The stability functions of a prismatic beam under an axial force N
    (Livesley): with ``q = N L^2 / (E I)`` (tension positive) and ``u =
    sqrt(|q|)``, the end's deflection w and slope give

    ``k_ww = (2 s (1 + c) + q) E I / L^3``, ``k_wr = -s (1 + c) E I / L^2``,
    ``k_rr = s E I / L``

    with s and c the stability functions (trigonometric in compression,
    hyperbolic in tension; 4 and 1/2 without force, the Euler beam). Near
    ``q = 0`` their series: ``k_ww L^3 / E I = 12 + 6 q / 5 - q^2 / 700``,
    the consistent geometric stiffness and its next term.

    Parameters
    ----------
    E : float
        [Pa].
    I : float or numpy.ndarray
        Second moment of area of the bending plane [m^4].
    length : float or numpy.ndarray
        L [m].
    force : float or numpy.ndarray
        N [N], tension positive.

    Returns
    -------
    k_ww, k_wr, k_rr : numpy.ndarray
        [N/m], [N], [N m] (the coupling negative in the guide's drive plane,
        w along x and the slope the rotation ry).

    Examples
    --------
    >>> [round(float(k), 6) for k in beam_column(1.0, 1.0, 1.0, 0.0)]
    [12.0, -6.0, 4.0]
    """
    EI, L = E * np.asarray(I, float), np.asarray(length, float)
    q = np.asarray(force, float) * L ** 2 / EI
    q, EI, L = np.broadcast_arrays(q, EI, L)
    small = np.abs(q) < 1e-3
    u = np.sqrt(np.where(small, 1.0, np.abs(q)))
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        # compression: trigonometric
        sn, cs = np.sin(u), np.cos(u)
        s_c = u * (sn - u * cs) / (2.0 - 2.0 * cs - u * sn)
        c_c = (u - sn) / (sn - u * cs)
        # tension: hyperbolic, divided through by cosh u (no overflow)
        th, sech = np.tanh(u), 1.0 / np.cosh(np.minimum(u, 700.0))
        s_t = u * (u - th) / (2.0 * sech - 2.0 + u * th)
        c_t = (th - u * sech) / (u - th)
    s = np.where(q > 0.0, s_t, s_c)
    c = np.where(q > 0.0, c_t, c_c)
    kww = np.where(small, 12.0 + 1.2 * q - q * q / 700.0, 2.0 * s * (1.0 + c) + q)
    kwr = np.where(small, -(6.0 + q / 10.0 - q * q / 1400.0), -s * (1.0 + c))
    krr = np.where(small, 4.0 + 2.0 * q / 15.0 - 11.0 * q * q / 6300.0, s)
    return kww * EI / L ** 3, kwr * EI / L ** 2, krr * EI / L


def geometric_block(E, length, width, thickness, force):
    """Gravity's stiffness of one leaf under an axial force, at its stage end.

    The drive plane (x, ry) exactly (:func:`beam_column` under the force less
    without it); the lateral plane (y, rx), where the leaf is stiff, by the
    consistent geometric stiffness ``N / (30 L) [[36, 3 L], [3 L, 4 L^2]]``.

    Parameters
    ----------
    E : float
        [Pa].
    length, width, thickness : float or numpy.ndarray
        L, b, t [m].
    force : float or numpy.ndarray
        Axial force N in the leaf [N], tension positive.

    Returns
    -------
    numpy.ndarray, shape (..., 6, 6)
        Zero in z and rz.
    """
    N, L = np.asarray(force, float), np.asarray(length, float)
    It = np.asarray(width, float) * np.asarray(thickness, float) ** 3 / 12.0
    K = _zeros(N, L, It)
    kww, kwr, krr = beam_column(E, It, L, N)
    k0ww, k0wr, k0rr = beam_column(E, It, L, 0.0)
    K[..., 0, 0] = kww - k0ww
    K[..., 0, 4] = K[..., 4, 0] = kwr - k0wr
    K[..., 4, 4] = krr - k0rr
    c = N / (30.0 * L)
    K[..., 1, 1] = 36.0 * c
    K[..., 1, 3] = K[..., 3, 1] = 3.0 * L * c
    K[..., 3, 3] = 4.0 * L ** 2 * c
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
