"""The parallel leaf-spring guide in closed form: six-by-six stiffness, gravity and modes.

The guide's leaves (:mod:`.leaf`) meet the stage at its clamp, the origin of
the guide's frame (x drive, y along the leaves' width, z along their length
towards the stage). A leaf whose centre line lies at ``r_i = (x_i, y_i, 0)``
moves with the clamp's translation ``u`` and rotation ``theta`` as
``u + theta x r_i``; its stiffness enters the clamp's as ``T_i^T K_i T_i``
with ``T_i = [[I, -[r_i]x], [0, I]]``. Moved to the stage's centre of mass,
``com_height`` beyond the clamp, the same transformation gives the stiffness
there.

Gravity: the stage's weight W = m1 g loads the leaves axially when the guide
stands (compression, ``-W / n`` per leaf) or hangs (tension), which changes
each leaf's bending stiffness (:func:`.leaf.geometric_block`, exact in the
drive plane), and it acts at the centre of mass, away from the clamp: the
load stiffness of a constant force F at r, ``K_theta = -sym(F r^T) + (F . r) I``
on the rotations (standing: ``-W h`` in rx and ry, the inverted pendulum).
The buckling factor is the lowest load factor lambda under which the
stiffness with lambda times the weight turns singular (:func:`buckling_factor`).

Modes: the six natural modes of the rigid stage (mass m1, inertia about its
centre of mass) on the guide's stiffness with gravity's, mass normalised.
The sensor reads x at ``(y_s, z_s)`` from the centre of mass, ``c = (1, 0,
0, 0, z_s, -y_s)``; the actuator pushes along x at ``(y_a, z_a)``, ``b = (1,
0, 0, 0, z_a, -y_a)``; a mode's participation in the drive coordinate is
``m1 (c . phi)(b . phi)``.

Every function broadcasts over arrays of the leaves' length, width and
thickness (keyword ``length``, ``width``, ``thickness``), for the sizing.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from ..results.mechanism import DIRECTIONS, GRAVITY, LeafGuide, Mode, Stiffness6
from . import leaf

__all__ = ["EFFECTIVE_MASS", "MODE_NAMES", "leaf_force", "weight_vector", "clamp_stiffness",
           "clamp_geometric_stiffness", "at_centre", "mass_matrix", "stiffness6",
           "drive_stiffness", "net_drive_stiffness", "buckling_factor", "largest_deflection",
           "stage_modes", "leaf_modes"]

#: Effective modal mass of a clamped-clamped beam's first bending mode over its mass [-];
#: half of it is taken to act on the stage's clamp (the other half on the cart's).
EFFECTIVE_MASS = 0.690

#: Names of the stage's modes by dominant direction.
MODE_NAMES = {"x": "stage x (drive)", "y": "stage y (lateral)", "z": "stage z (axial)",
              "rx": "stage rx (roll)", "ry": "stage ry (pitch)", "rz": "stage rz (yaw)"}


def _skew(r) -> np.ndarray:
    x, y, z = r
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


def _shift(r) -> np.ndarray:
    """T with ``T q`` the motion of the point r for the rigid motion q at the origin."""
    T = np.eye(6)
    T[:3, 3:] = -_skew(r)
    return T


def _dims(guide: LeafGuide, length, width, thickness):
    return (guide.length if length is None else np.asarray(length, float),
            guide.width if width is None else np.asarray(width, float),
            guide.thickness if thickness is None else np.asarray(thickness, float))


def leaf_force(guide: LeafGuide) -> float:
    """Axial force in each leaf from the stage's weight [N], tension positive."""
    w = guide.weight / guide.leaves
    return {"standing": -w, "hanging": w}.get(guide.orientation, 0.0)


def weight_vector(guide: LeafGuide) -> np.ndarray:
    """The weight the guide carries, as a force on the stage in the guide's frame [N].

    Standing along -z, hanging along +z, flat along -y; on a vertical drive
    axis the actuator carries the stage's weight, not the guide: zero.
    """
    w = guide.weight
    return {"standing": np.array([0.0, 0.0, -w]), "hanging": np.array([0.0, 0.0, w]),
            "flat": np.array([0.0, -w, 0.0])}.get(guide.orientation, np.zeros(3))


@functools.lru_cache(maxsize=256)
def _congruence(points: tuple[tuple[float, float, float], ...]) -> np.ndarray:
    """The linear map of a 6 x 6 block B to ``sum_i T_i^T B T_i`` (``T_i = _shift(r_i)``) on
    the row-major flattened matrices: ``vec(K) = vec(B) @ W`` with ``W = sum_i T_i (x) T_i``,
    since ``(T^T B T)[i, m] = sum_jk B[j, k] T[j, i] T[k, m]``. One product of a stack of
    blocks with a 36 x 36 matrix instead of two 6 x 6 products per block and point."""
    W = np.zeros((36, 36))
    for r in points:
        T = _shift(r)
        W += np.kron(T, T)
    W.setflags(write=False)
    return W


def _congruent(block: np.ndarray, points: tuple[tuple[float, float, float], ...]) -> np.ndarray:
    """``sum_i T_i^T block T_i`` over the points r_i (``T_i = _shift(r_i)``), for a stack of
    blocks of shape (..., 6, 6)."""
    block = np.asarray(block, float)
    # a row vector per block (a stack of products, which numpy does not hand to a threaded
    # BLAS: one (N, 36) x (36, 36) product woke BLAS threads that spun beside the workers)
    flat = block.reshape(block.shape[:-2] + (1, 36))
    return (flat @ _congruence(points)).reshape(block.shape)


def _sum_leaves(guide: LeafGuide, block: np.ndarray) -> np.ndarray:
    return _congruent(block, tuple((x, y, 0.0) for x, y in guide.leaf_positions()))


def clamp_stiffness(guide: LeafGuide, *, deflection: float = 0.0, length=None, width=None,
                    thickness=None) -> np.ndarray:
    """Elastic stiffness of the guide at the stage's clamp.

    Parameters
    ----------
    guide : LeafGuide
        The guide.
    deflection : float, optional
        Drive deflection the axial stiffness is taken at [m]
        (:func:`.leaf.axial_factor`). Default 0 (undeflected).
    length, width, thickness : float or numpy.ndarray, optional
        Leaf dimensions in place of the guide's [m]; arrays broadcast.

    Returns
    -------
    numpy.ndarray, shape (..., 6, 6)
    """
    L, b, t = _dims(guide, length, width, thickness)
    G = guide.shear_modulus
    block = leaf.stiffness_block(guide.youngs_modulus, G, L, b, t,
                                 axial=leaf.axial_factor(deflection, t))
    return _sum_leaves(guide, block)


def clamp_geometric_stiffness(guide: LeafGuide, *, load: float = 1.0, length=None, width=None,
                              thickness=None) -> np.ndarray:
    """Gravity's stiffness at the stage's clamp: the leaves' geometric stiffness and the load's.

    Parameters
    ----------
    guide : LeafGuide
        The guide.
    load : float, optional
        Factor on the weight (the buckling factor's search). Default 1.
    length, width, thickness : float or numpy.ndarray, optional
        Leaf dimensions in place of the guide's [m].

    Returns
    -------
    numpy.ndarray, shape (..., 6, 6)
        Zero without gravity's load on the guide.
    """
    L, b, t = _dims(guide, length, width, thickness)
    lam = np.asarray(load, float)
    shape = np.broadcast(L, b, t, lam).shape
    K = _sum_leaves(guide, leaf.geometric_block(guide.youngs_modulus, L, b, t,
                                                np.broadcast_to(lam * leaf_force(guide), shape)))
    F = weight_vector(guide)
    r = np.array([0.0, 0.0, guide.com_height])
    sym = 0.5 * (np.outer(F, r) + np.outer(r, F))
    K[..., 3:, 3:] += lam[..., None, None] * (-sym + float(F @ r) * np.eye(3))
    return K


def at_centre(K: np.ndarray, com_height: float) -> np.ndarray:
    """A stiffness at the clamp moved to the stage's centre of mass, ``T^T K T``."""
    return _congruent(K, ((0.0, 0.0, -float(com_height)),))


def mass_matrix(guide: LeafGuide) -> np.ndarray:
    """The rigid stage's mass matrix at its centre of mass, diag(m1, m1, m1, Ixx, Iyy, Izz)."""
    m = guide.stage_mass
    return np.diag([m, m, m, *guide.stage_inertia])


def stiffness6(K: np.ndarray) -> Stiffness6 | np.ndarray:
    """The six stiffnesses of a stiffness matrix: 1 / the diagonal of its compliance.

    Parameters
    ----------
    K : numpy.ndarray, shape (6, 6) or (..., 6, 6)

    Returns
    -------
    Stiffness6 for one matrix, else an array (..., 6).
    """
    d = 1.0 / np.diagonal(np.linalg.inv(K), axis1=-2, axis2=-1)
    if d.ndim == 1:
        return Stiffness6(*(float(v) for v in d))
    return d


def drive_stiffness(K: np.ndarray):
    """x stiffness at the centre of mass with the other directions free [N/m]."""
    return 1.0 / np.linalg.inv(K)[..., 0, 0]


def net_drive_stiffness(K: np.ndarray, Kg: np.ndarray):
    """x stiffness at the centre of mass with gravity's stiffness, the others free [N/m].

    Where gravity's share is round-off (within 1e-9 of the elastic drive
    stiffness: a weight across the drive direction, ``flat``), the elastic one.

    Parameters
    ----------
    K, Kg : numpy.ndarray, shape (..., 6, 6)
        Elastic and gravity's stiffness at the centre of mass.
    """
    elastic, net = drive_stiffness(K), drive_stiffness(K + Kg)
    return np.where(np.abs(net - elastic) <= 1e-9 * np.abs(elastic), elastic, net)


def largest_deflection(guide: LeafGuide, stroke: float, net):
    """The leaves' largest drive deflection [m]: the stroke, where the limiter stops the joint.

    The limiter engages at a joint deflection of +-s from the unloaded leaves,
    whatever rests on the joint. On a vertical drive axis the joint carries the
    cart's weight m2 g and rests at its sag m2 g / k: within the stroke the sag
    only moves where the joint rests, and the limiter still stops it at s. A
    sag beyond the stroke presses the joint onto its end stop, the leaves and
    the stop sharing the weight: k u + k_stop (u - s) = m2 g, so
    ``u = (m2 g + k_stop s) / (k + k_stop)``, s plus the stop's compression
    (exactly s for a rigid stop, ``guide.stop_stiffness`` inf).

    Parameters
    ----------
    guide : LeafGuide
        Its orientation, ``cart_mass`` and ``stop_stiffness``.
    stroke : float
        One-sided stroke s [m].
    net : float or numpy.ndarray
        The guide's net drive stiffness k [N/m]; arrays broadcast.

    Returns
    -------
    float or numpy.ndarray
        Largest deflection [m], of the shape of ``net``.

    Examples
    --------
    >>> from fi_design.results.mechanism import LeafGuide
    >>> g = LeafGuide(leaves=2, length=0.05, width=0.02, thickness=0.4e-3, spacing=0.03,
    ...               lateral_spacing=0.0, youngs_modulus=200e9, poisson_ratio=0.3,
    ...               density=7800.0, allowed_stress=300e6, orientation="vertical_axis",
    ...               stage_mass=1.0, stage_inertia=(1e-4,) * 3, com_height=0.025,
    ...               cart_mass=0.4, stop_stiffness=1e6)
    >>> round(largest_deflection(g, 0.3e-3, 2000.0) * 1e3, 4)  # sag 1.96 mm, on its stop
    0.3033
    >>> largest_deflection(g, 0.3e-3, 20000.0) * 1e3  # sag 0.196 mm, within the stroke
    0.3
    """
    k = np.asarray(net, float)
    ks = guide.stop_stiffness
    if guide.orientation != "vertical_axis" or math.isinf(ks):
        u = np.full(k.shape, float(stroke))
    else:
        u = np.maximum(stroke, (guide.cart_mass * GRAVITY + ks * stroke) / (k + ks))
    return float(u) if u.ndim == 0 else u


def buckling_factor(guide: LeafGuide, *, length=None, width=None, thickness=None,
                    rtol: float = 1e-4):
    """Lowest factor on the weight at which the guide's stiffness turns singular [-].

    The stiffness with lambda times the weight (the leaves' beam-column
    stiffness under lambda times their force, exact, and the load stiffness)
    loses positive definiteness at the buckling load. Bracketed from the
    linear eigenproblem of the consistent geometric stiffness (a close upper
    estimate), then narrowed to ``rtol`` by the Illinois method on the smallest
    eigenvalue of the stiffness scaled by its unloaded diagonal (positive
    exactly where the guide is stable): a regula falsi whose kept end is
    halved when it is kept twice, so both ends close in. The bracket is kept
    throughout (its lower end stable, its upper end not), as bisection's: the
    answer is its middle, within ``rtol`` of the buckling load, in about a
    third of bisection's steps.

    Parameters
    ----------
    guide : LeafGuide
        The guide; its weight must compress the leaves.
    length, width, thickness : float or numpy.ndarray, optional
        Leaf dimensions in place of the guide's [m]; arrays broadcast.
    rtol : float, optional
        Relative resolution of the factor.

    Returns
    -------
    float or numpy.ndarray
        inf where the weight does not compress the guide.
    """
    dims = dict(length=length, width=width, thickness=thickness)
    K = clamp_stiffness(guide, **dims)
    if leaf_force(guide) >= 0.0:
        out = np.full(K.shape[:-2], np.inf)
        return float(out) if out.ndim == 0 else out
    # the linear estimate: K + lambda Kg1 singular, Kg1 the first-order part per unit load
    Kg1 = clamp_geometric_stiffness(guide, load=1e-6, **dims) * 1e6
    mu = np.linalg.eigvals(np.linalg.solve(K, -Kg1))
    top = np.where(np.abs(mu.imag) <= 1e-9 * np.abs(mu).max(axis=-1, keepdims=True) + 1e-300,
                   mu.real, 0.0).max(axis=-1)
    shape = K.shape[:-2]
    # flat, each leaf size apart: the search works on the sizes not yet resolved only
    L, b, t = (np.broadcast_to(v, shape).ravel() for v in _dims(guide, length, width, thickness))
    Kf = K.reshape(-1, 6, 6)
    d = 1.0 / np.sqrt(np.abs(np.diagonal(Kf, axis1=-2, axis2=-1)))

    def smallest(load: np.ndarray, at: np.ndarray) -> np.ndarray:
        """The smallest eigenvalue of the stiffness of sizes ``at`` under ``load`` times the
        weight, scaled by the unloaded diagonal (a congruence: its sign is definiteness)."""
        s = d[at]
        A = (Kf[at] + clamp_geometric_stiffness(guide, load=load, length=L[at], width=b[at],
                                                thickness=t[at])) * s[:, :, None] * s[:, None, :]
        return np.linalg.eigvalsh(0.5 * (A + np.swapaxes(A, -1, -2)))[:, 0]

    every = np.arange(L.size)
    hi = 1.1 / np.where(top > 0.0, top, 1e-300).ravel()
    f_hi = smallest(hi, every)
    for _ in range(8):  # widen where the exact stiffness still holds at the estimate
        at = np.flatnonzero(f_hi > 0.0)
        if not at.size:
            break
        hi[at] *= 2.0
        f_hi[at] = smallest(hi[at], at)
    # the estimate is close: a lower end just below it (else 0) starts the bracket narrow
    lo = 0.85 * hi / 1.1
    f_lo = smallest(lo, every)
    at = np.flatnonzero(f_lo <= 0.0)
    if at.size:
        hi[at], f_hi[at], lo[at] = lo[at], f_lo[at], 0.0
        f_lo[at] = smallest(lo[at], at)
    kept = np.zeros(hi.shape, dtype=int)  # +1: lo kept last, -1: hi kept last
    at = np.flatnonzero(hi - lo > rtol * hi)
    while at.size:
        lo_, hi_, fl, fh = lo[at], hi[at], f_lo[at], f_hi[at]
        # the false position where the ends bracket a sign change, else (an upper end still
        # stable after the widening) the middle; never within 1e-3 of the bracket of an end
        with np.errstate(divide="ignore", invalid="ignore"):
            x = np.where((fl > 0.0) & (fh <= 0.0), (lo_ * fh - hi_ * fl) / (fh - fl),
                         0.5 * (lo_ + hi_))
        w = hi_ - lo_
        x = np.clip(np.where(np.isfinite(x), x, 0.5 * (lo_ + hi_)), lo_ + 1e-3 * w,
                    hi_ - 1e-3 * w)
        fx = smallest(x, at)
        ok, k = fx > 0.0, kept[at]
        # Illinois: an end kept a second time in a row has its value halved
        f_hi[at] = np.where(ok, np.where(k == -1, 0.5 * fh, fh), fx)
        f_lo[at] = np.where(ok, fx, np.where(k == 1, 0.5 * fl, fl))
        lo[at] = np.where(ok, x, lo_)
        hi[at] = np.where(ok, hi_, x)
        kept[at] = np.where(ok, -1, 1)
        at = at[hi[at] - lo[at] > rtol * hi[at]]
    out = (0.5 * (lo + hi)).reshape(shape)
    return float(out) if out.ndim == 0 else out


def _rows(guide: LeafGuide) -> tuple[np.ndarray, np.ndarray]:
    ys, zs = guide.sensor_offset
    ya, za = guide.actuator_offset
    return (np.array([1.0, 0.0, 0.0, 0.0, zs, -ys]), np.array([1.0, 0.0, 0.0, 0.0, za, -ya]))


def stage_modes(guide: LeafGuide, K: np.ndarray) -> tuple[Mode, ...]:
    """The stage's six modes on a stiffness at its centre of mass, by frequency.

    Parameters
    ----------
    guide : LeafGuide
        The stage's mass, inertia, sensor and actuator offsets, the damping.
    K : numpy.ndarray, shape (6, 6)
        Stiffness at the centre of mass (gravity's included) [SI].

    Returns
    -------
    tuple of Mode
        Frequency (0 for a mode the weight has made unstable), dominant
        direction by kinetic energy, participation and coupling; ``drive``
        for the x mode.
    """
    M = mass_matrix(guide)
    s = 1.0 / np.sqrt(np.diag(M))
    A = K * s[:, None] * s[None, :]
    w2, psi = np.linalg.eigh(0.5 * (A + A.T))
    phi = psi * s[:, None]  # mass normalised: phi^T M phi = I
    c, b = _rows(guide)
    part = guide.stage_mass * (c @ phi) * (b @ phi)
    part = np.where(np.abs(part) < 1e-12, 0.0, part)  # round-off of a mode x does not see
    total = float(np.sum(np.abs(part))) or 1.0
    energy = phi ** 2 * np.diag(M)[:, None]
    out = []
    for i in range(6):
        d = DIRECTIONS[int(np.argmax(energy[:, i]))]
        out.append(Mode(name=MODE_NAMES[d], frequency=math.sqrt(max(w2[i], 0.0)) / (2 * math.pi),
                        damping_ratio=guide.damping_ratio, direction=d,
                        coupling=float(abs(part[i]) / total), participation=float(part[i]),
                        source="computed", drive=d == "x"))
    return tuple(out)


def leaf_modes(guide: LeafGuide, stage: tuple[Mode, ...]) -> tuple[Mode, ...]:
    """The leaves' own first modes: bending in the drive direction and torsion.

    The bending mode moves the stage's clamp through the leaves' reaction: its
    participation is the share :data:`EFFECTIVE_MASS` / 2 of the leaves' mass
    over the stage's; torsion does not show in x.
    """
    g = guide
    n_leaf = leaf_force(g)
    total = sum(abs(m.participation) for m in stage) or 1.0
    r = 0.5 * EFFECTIVE_MASS * g.leaf_mass / g.stage_mass
    bend = float(leaf.bending_frequency(g.youngs_modulus, g.density, g.length, g.width,
                                        g.thickness, n_leaf))
    tors = float(leaf.torsion_frequency(g.shear_modulus, g.density, g.length, g.width,
                                        g.thickness))
    return (Mode(name="leaf bending", frequency=bend, damping_ratio=g.damping_ratio,
                 direction="leaf", coupling=min(1.0, r / total), participation=r,
                 source="computed"),
            Mode(name="leaf torsion", frequency=tors, damping_ratio=g.damping_ratio,
                 direction="leaf", coupling=0.0, participation=0.0, source="computed"))
