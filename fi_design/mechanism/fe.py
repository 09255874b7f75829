"""The parallel leaf-spring guide as a finite-element model: the independent check.

:func:`fe_mechanics` builds the guide of a :class:`~fi_design.results.mechanism.LeafGuide`
with the finite-element library pyfe3d (an optional dependency, imported when
the function runs) and returns its stiffness at the stage's centre of mass,
gravity's geometric stiffness, the buckling factor and the modes, as a
:class:`~fi_design.results.mechanism.FeMechanics`. It shares nothing with the
closed forms of :mod:`fi_design.mechanism` but the input.

The model (SI; the guide's frame: x drive, y width, z along the leaves)
----------------------------------------------------------------------
- Each leaf is a straight line of ``elements_per_leaf`` Timoshenko beam
  elements (pyfe3d ``BeamC``, consistent mass with rotary inertia) from the
  cart's clamp at ``z = -L`` (all six degrees of freedom fixed) to the stage's
  clamp at ``z = 0``. Cross-section b x t: ``A = b t``, ``I = b t^3 / 12`` for
  bending in x, ``t b^3 / 12`` in y, Saint-Venant torsion
  ``J = b t^3 / 3 (1 - 0.63 t / b)``, shear modulus ``G = E / (2 (1 + nu))``
  with the shear correction ``kappa = 5/6`` of a rectangle in both planes
  (pyfe3d applies none itself).
- The stage is a rigid body. Its degrees of freedom are those of one master
  node at the centre of mass ``(0, 0, com_height)``, carrying the stage's mass
  and principal inertia. The leaves' top nodes are eliminated by the rigid-body
  constraint ``u_s = u_m + theta x r_s`` (``r_s`` from the centre of mass to
  the top node), so no stiff link stands beside the light leaves.
- The weight ``m1 g`` acts at the centre of mass, along -z standing, +z
  hanging, -y flat and -x with a vertical drive axis. The leaves' own weight
  is left out of the pre-stress (their mass is in the modes): it is about
  half a percent of a typical stage's and would blur the load factor, which is
  defined against the stage's weight.
- Pre-stress: a linear static solve under the weight gives each element's
  axial force, hence its geometric stiffness (``BeamC.update_KG``). The rigid
  stage adds its own: the constraint is linear in ``theta`` only to first
  order; its second-order part, ``1/2 theta x (theta x r_s)``, times the force
  ``g_s`` each leaf exerts on the stage gives
  ``sum_s [-sym(g_s r_s^T) + (g_s . r_s) I]`` on the rotations. Standing, this
  is the pendulum term ``-m1 g h`` on rx and ry (the weight at the height h
  above the clamp), the same as the load stiffness of the weight about the
  clamp.

What it computes
----------------
- ``stiffness``: unit forces and moments at the centre of mass, one static
  solve each, no pre-stress; each direction's stiffness is 1 / the diagonal of
  that compliance (the other five directions free).
- ``geometric_stiffness``: the drive stiffness so found with the pre-stress
  minus without it [N/m], signed.
- ``buckling_factor``: the lowest positive load factor of
  ``(K + lambda K_G) u = 0`` (pyfe3d ``linear_buckling``, verified by an
  inertia count) when the weight compresses a leaf: standing (every leaf,
  the guide's sway buckling), with a vertical drive axis (the weight's moment
  pushes one row and pulls the other, ``m1 g (h + L/2) / spacing`` per row
  about the leaves' inflection points, and the pushed leaves buckle on their
  own, clamped at both ends, near ``4 pi^2 E I / L^2`` each) and flat with
  four leaves (the moment pushes one pair). None
  when no leaf is compressed: hanging (the eigenproblem then has only
  negative factors, those of the reversed load, standing) and flat with two
  leaves (no axial force; the only factors left come from the rigid stage's
  offset-weight term, tens of thousands, no buckling of the guide). pyfe3d's
  geometric stiffness holds the axial-force term only: the lateral-torsional
  buckling of leaves bent across their width (flat) is not in it.
- ``modes``: ``(K + K_G) phi = omega^2 M phi`` in shift-invert mode (pyfe3d
  ``natural_frequency``, verified not to miss a mode), not a dense generalised
  solve, which loses the lowest modes beside the leaves' tiny rotary inertias.
  Each mode is mass-normalised over the whole model; its stage share is the
  stage's kinetic energy ``sum_j phi_j^2 M_jj`` over the master's six degrees
  of freedom (the stage's own mass and inertia). The six modes with the
  largest share are the stage's modes, named by the master's direction with
  the largest share; the others are the leaves' own modes, named by the
  leaves' motion (bending across the thickness, lateral bending across the
  width, torsion, axial). The n leaves' copies of one mode (in phase, out of
  phase, within 5 %) count as one, represented by the copy the stage moves
  most in, the one the loop can see; the lowest of each kind is reported
  (``leaf bending``, ``leaf torsion``) and a higher one (``leaf bending 2``)
  when its coupling reaches 1 %, as a leaf mode mixed with a stage mode does.
  The
  participation ``m1 (c . phi)(b . phi)`` uses the master's components with
  the sensor row ``c = (1, 0, 0, 0, z_s, -y_s)`` and actuator column
  ``b = (1, 0, 0, 0, z_a, -y_a)``; the coupling is its modulus over the sum
  of the moduli of the six stage modes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import sparse

from ..results.mechanism import DIRECTIONS, FeMechanics, LeafGuide, Mode, Stiffness6

__all__ = ["fe_mechanics", "SHEAR_CORRECTION"]

#: Shear correction factor of a rectangular cross-section [-].
SHEAR_CORRECTION = 5.0 / 6.0

#: Unit vector of gravity in the guide's frame per orientation.
_GRAVITY_DIRECTION = {
    "standing": (0.0, 0.0, -1.0),
    "hanging": (0.0, 0.0, 1.0),
    "flat": (0.0, -1.0, 0.0),
    "vertical_axis": (-1.0, 0.0, 0.0),
}

#: The leaves' motion per degree of freedom of a node (x, y, z, rx, ry, rz) -> kind of leaf mode:
#: translation across the thickness and the cross-section's rotation with it are bending.
_LEAF_KINDS = ("leaf bending", "leaf lateral bending", "leaf axial", "leaf lateral bending",
               "leaf bending", "leaf torsion")

#: A leaf is compressed by the weight when its axial force is below -this fraction of it [-].
_COMPRESSED = 1e-6

#: The leaves' modes of one kind within this fraction above the lowest are one mode of the n
#: leaves (in phase, out of phase): the one the stage moves most in is reported [-].
_SAME_MODE = 0.05

#: A leaf mode beyond the first of its kind is reported when its coupling reaches this [-].
_VISIBLE = 0.01

#: A mode is a stage mode only with at least this share of its kinetic energy in the stage [-].
_STAGE_SHARE = 0.5


@dataclass(frozen=True)
class _Model:
    """The assembled guide, reduced to the free leaf nodes and the stage's master node.

    ``K``, ``M``: reduced stiffness and mass, the stage's included (sparse, n_red x n_red) [SI];
    ``T``: the leaves' nodal displacements from the reduced ones (sparse, n_full x n_red);
    ``K_full``: the leaves' stiffness over all their nodes (sparse, n_full x n_full);
    ``M_full_diag``: the diagonal of the leaves' mass over all their nodes (n_full,);
    ``master``: index of the master's first degree of freedom in the reduced set;
    ``slaves``: (first full DOF, r_s from the centre of mass [m]) per leaf top node;
    ``elements``, ``prop``: the pyfe3d BeamC elements and their BeamProp.
    """

    K: sparse.csc_matrix
    M: sparse.csc_matrix
    T: sparse.csc_matrix
    K_full: sparse.csc_matrix
    M_full_diag: np.ndarray
    master: int
    slaves: tuple[tuple[int, np.ndarray], ...]
    elements: tuple
    prop: object


def fe_mechanics(guide: LeafGuide, *, elements_per_leaf: int = 16) -> FeMechanics:
    """The guide's stiffness, gravity and modes from a finite-element model (pyfe3d).

    Parameters
    ----------
    guide : LeafGuide
        The leaves, their material and the stage (SI).
    elements_per_leaf : int, optional
        Beam elements along each leaf (at least 2). Default 16: the stiffness,
        load factor and modes then change by less than 0.5 % with 32.

    Returns
    -------
    FeMechanics
        Stiffness at the stage's centre of mass [N/m, N m/rad], the drive
        direction's geometric stiffness [N/m], the buckling factor [-] and the
        modes [Hz] (see the module's notes for each).

    Raises
    ------
    ImportError
        When pyfe3d is not installed.
    ValueError
        For fewer than 2 elements per leaf or an unknown orientation.
    """
    import pyfe3d
    from pyfe3d.solver.eigen import linear_buckling

    if elements_per_leaf < 2:
        raise ValueError(f"elements_per_leaf: {elements_per_leaf} (at least 2)")
    if guide.orientation not in _GRAVITY_DIRECTION:
        raise ValueError(f"orientation: {guide.orientation!r} (one of "
                         f"{', '.join(_GRAVITY_DIRECTION)})")
    model = _assemble(guide, elements_per_leaf)
    KG, axial = _prestress(model, guide)
    compliance = _compliance(model.K, model.master)
    stiffness = Stiffness6(*(float(1.0 / c) for c in np.diag(compliance)))
    kx_stressed = 1.0 / _compliance(model.K + KG, model.master)[0, 0]
    buckling = None
    if axial.min() < -_COMPRESSED * guide.weight:
        factors, _ = linear_buckling(model.K, KG, num_eigvalues=4)
        positive = [float(f.real) for f in np.atleast_1d(factors)
                    if np.isreal(f) and f.real > 0 and np.isfinite(f.real)]
        buckling = min(positive) if positive else None
    return FeMechanics(
        library=f"pyfe3d {pyfe3d.__version__}", elements_per_leaf=elements_per_leaf,
        stiffness=stiffness, geometric_stiffness=float(kx_stressed - stiffness.x),
        buckling_factor=buckling, modes=_modes(model, KG, guide))


def _leaf_property(guide: LeafGuide):
    """pyfe3d BeamProp of a leaf: element y along the width, element z across the thickness."""
    from pyfe3d.beamprop import BeamProp

    b, t = guide.width, guide.thickness
    E, G, rho = guide.youngs_modulus, guide.shear_modulus, guide.density
    prop = BeamProp()
    prop.A = b * t
    prop.E = E
    prop.G = G
    prop.G12 = prop.G13 = SHEAR_CORRECTION * G
    prop.Izz = t * b**3 / 12.0      # about element z (= -x): bending across the width
    prop.Iyy = b * t**3 / 12.0      # about element y (= y): bending across the thickness
    prop.GJ = G * b * t**3 / 3.0 * (1.0 - 0.63 * t / b)
    prop.intrho = rho * prop.A
    prop.intrhoy2 = rho * prop.Izz
    prop.intrhoz2 = rho * prop.Iyy
    return prop


def _cross(r: np.ndarray) -> np.ndarray:
    """The matrix [r]x with [r]x v = r x v."""
    return np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])


def _assemble(guide: LeafGuide, ne: int) -> _Model:
    """Mesh the leaves, assemble K and M with pyfe3d and eliminate the rigid stage's clamp."""
    import pyfe3d
    from pyfe3d import BeamC, BeamCProbe

    positions = guide.leaf_positions()
    per_leaf = ne + 1
    n_nodes = len(positions) * per_leaf
    coords = np.zeros(3 * n_nodes)
    z = np.linspace(-guide.length, 0.0, per_leaf)
    for i, (x, y) in enumerate(positions):
        block = coords[3 * i * per_leaf: 3 * (i + 1) * per_leaf].reshape(-1, 3)
        block[:, 0], block[:, 1], block[:, 2] = x, y, z

    prop = _leaf_property(guide)
    size = pyfe3d.BeamCData().KC0_SPARSE_SIZE
    n_el = len(positions) * ne
    rows = np.zeros(size * n_el, dtype=pyfe3d.INT)
    cols = np.zeros(size * n_el, dtype=pyfe3d.INT)
    kv = np.zeros(size * n_el)
    mr = np.zeros(size * n_el, dtype=pyfe3d.INT)
    mc = np.zeros(size * n_el, dtype=pyfe3d.INT)
    mv = np.zeros(size * n_el)
    elements = []
    for i in range(len(positions)):
        for j in range(ne):
            el = BeamC(BeamCProbe())
            el.n1, el.n2 = i * per_leaf + j, i * per_leaf + j + 1
            el.c1, el.c2 = 6 * el.n1, 6 * el.n2
            k = len(elements)
            el.init_k_KC0 = el.init_k_KG = el.init_k_M = k * size
            el.update_rotation_matrix(0.0, 1.0, 0.0, coords)   # element y along the width
            el.update_probe_xe(coords)
            el.update_KC0(rows, cols, kv, prop)
            el.update_M(mr, mc, mv, prop)
            elements.append(el)
    n_full = 6 * n_nodes
    K_full = sparse.coo_matrix((kv, (rows, cols)), shape=(n_full, n_full)).tocsc()
    M_full = sparse.coo_matrix((mv, (mr, mc)), shape=(n_full, n_full)).tocsc()

    # Reduced set: the leaves' inner nodes, then the master (the stage's centre of mass).
    n_inner = len(positions) * (ne - 1)
    master = 6 * n_inner
    com = np.array([0.0, 0.0, guide.com_height])
    t_rows, t_cols, t_vals = [], [], []
    slaves = []
    for i in range(len(positions)):
        for j in range(1, ne):
            full, red = 6 * (i * per_leaf + j), 6 * (i * (ne - 1) + j - 1)
            t_rows += range(full, full + 6)
            t_cols += range(red, red + 6)
            t_vals += [1.0] * 6
        top = 6 * (i * per_leaf + ne)
        r = coords[top // 2: top // 2 + 3] - com
        block = np.eye(6)
        block[:3, 3:] = -_cross(r)     # u_s = u_m + theta x r = u_m - [r]x theta
        nz = np.nonzero(block)
        t_rows += list(top + nz[0])
        t_cols += list(master + nz[1])
        t_vals += list(block[nz])
        slaves.append((top, r))
    T = sparse.coo_matrix((t_vals, (t_rows, t_cols)), shape=(n_full, master + 6)).tocsc()
    stage = np.zeros(master + 6)
    stage[master:] = (guide.stage_mass,) * 3 + tuple(guide.stage_inertia)
    K = (T.T @ K_full @ T).tocsc()
    M = (T.T @ M_full @ T + sparse.diags(stage)).tocsc()
    return _Model(K=K, M=M, T=T, K_full=K_full, M_full_diag=M_full.diagonal(), master=master,
                  slaves=tuple(slaves), elements=tuple(elements), prop=prop)


def _prestress(model: _Model, guide: LeafGuide) -> tuple[sparse.csc_matrix, np.ndarray]:
    """Geometric stiffness of the weight (reduced: the leaves' K_G plus the rigid stage's term)
    and each element's axial force under it [N] (positive in tension)."""
    import pyfe3d
    from pyfe3d.solver.static import solve

    weight = np.zeros(model.K.shape[0])
    weight[model.master: model.master + 3] = guide.weight * np.array(
        _GRAVITY_DIRECTION[guide.orientation])
    u = model.T @ solve(model.K, weight)
    size = pyfe3d.BeamCData().KG_SPARSE_SIZE
    n = size * len(model.elements)
    rows = np.zeros(n, dtype=pyfe3d.INT)
    cols = np.zeros(n, dtype=pyfe3d.INT)
    vals = np.zeros(n)
    axial = np.zeros(len(model.elements))
    for e, el in enumerate(model.elements):
        el.update_probe_ue(u)
        el.update_KG(rows, cols, vals, model.prop)
        axial[e] = model.prop.E * model.prop.A * (el.probe.ue[6] - el.probe.ue[0]) / el.length
    n_full = model.T.shape[0]
    KG_full = sparse.coo_matrix((vals, (rows, cols)), shape=(n_full, n_full)).tocsc()
    KG = model.T.T @ KG_full @ model.T
    # The rigid stage: second-order part of the constraint times the leaves' forces on it.
    held = model.K_full @ u            # force the stage applies to each leaf's top node
    rigid = np.zeros((3, 3))
    for top, r in model.slaves:
        g = -held[top: top + 3]           # force the leaf applies to the stage
        gr = np.outer(g, r)
        rigid += -0.5 * (gr + gr.T) + np.dot(g, r) * np.eye(3)
    m = model.master + 3
    extra = sparse.coo_matrix((rigid.ravel(), (np.repeat(np.arange(m, m + 3), 3),
                                               np.tile(np.arange(m, m + 3), 3))),
                              shape=KG.shape)
    return (KG + extra).tocsc(), axial


def _compliance(K: sparse.csc_matrix, master: int) -> np.ndarray:
    """6 x 6 compliance at the master node: static solves of unit loads there [m/N, rad/(N m)]."""
    from pyfe3d.solver.static import solve

    unit = np.zeros((K.shape[0], 6))
    unit[master: master + 6, :] = np.eye(6)
    return np.column_stack([solve(K, unit[:, j]) for j in range(6)])[master: master + 6, :]


def _modes(model: _Model, KG: sparse.csc_matrix, guide: LeafGuide) -> tuple[Mode, ...]:
    """The six stage modes with the pre-stress, then the lowest leaf mode of each kind.

    A mode the pre-stress makes unstable (a buckled guide, ``omega^2 < 0``) has frequency 0.
    """
    from pyfe3d.solver.eigen import natural_frequency

    K = (model.K + KG).tocsc()
    n = K.shape[0]
    s = slice(model.master, model.master + 6)
    stage_mass = np.array((guide.stage_mass,) * 3 + tuple(guide.stage_inertia))
    wanted = 6 + 4 * guide.leaves + 4
    while True:
        omega, phi = natural_frequency(K, model.M, num_eigvalues=min(wanted, n - 2))
        phi = phi / np.sqrt(np.einsum("ij,ij->j", phi, model.M @ phi))
        energy = phi[s, :] ** 2 * stage_mass[:, None]
        share = energy.sum(axis=0)
        if (share >= _STAGE_SHARE).sum() >= 6 and (share < _STAGE_SHARE).sum() >= 1:
            break
        if wanted >= n - 2:
            raise RuntimeError("fe_mechanics: the model's modes do not separate into six stage "
                               "modes and leaf modes")
        wanted *= 2
    ys, zs = guide.sensor_offset
    ya, za = guide.actuator_offset
    c = np.array([1.0, 0.0, 0.0, 0.0, zs, -ys])
    b = np.array([1.0, 0.0, 0.0, 0.0, za, -ya])
    participation = guide.stage_mass * (c @ phi[s, :]) * (b @ phi[s, :])
    stage = sorted(np.argsort(share)[-6:])
    total = float(np.sum(np.abs(participation[stage])))
    freq = omega.real / (2.0 * np.pi)

    def mode(i: int, name: str, direction: str) -> Mode:
        return Mode(name=name, frequency=float(freq[i]), damping_ratio=guide.damping_ratio,
                    direction=direction, coupling=float(abs(participation[i]) / total),
                    participation=float(participation[i]), source="computed",
                    drive=direction == "x")

    modes = [mode(i, f"stage {DIRECTIONS[d]}", DIRECTIONS[d])
             for i in stage for d in [int(np.argmax(energy[:, i]))]]
    leaf_energy = (model.T @ phi) ** 2 * model.M_full_diag[:, None]
    clusters: dict[str, list[list[int]]] = {}
    for i in range(phi.shape[1]):
        if i in stage:
            continue
        per_dof = leaf_energy[:, i].reshape(-1, 6).sum(axis=0)
        by_kind: dict[str, float] = {}
        for d, kind in enumerate(_LEAF_KINDS):
            by_kind[kind] = by_kind.get(kind, 0.0) + per_dof[d]
        found = clusters.setdefault(max(by_kind, key=by_kind.get), [])
        if found and freq[i] <= (1.0 + _SAME_MODE) * freq[found[-1][0]]:
            found[-1].append(i)
        else:
            found.append([i])
    leaves = []
    for kind, found in clusters.items():
        for order, members in enumerate(found):
            i = max(members, key=lambda j: share[j])
            if order == 0 or abs(participation[i]) >= _VISIBLE * total:
                leaves.append(mode(i, kind if order == 0 else f"{kind} {order + 1}", "leaf"))
    modes += sorted(leaves, key=lambda m: m.frequency)
    return tuple(modes)
