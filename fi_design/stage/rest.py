"""When a stage at rest stays at rest: the static balance of the stuck cart.

A stage resting near its target is not done: the integrator still drives
x1 to the target, and the stuck cart stays stuck only while the friction
force it then carries stays below its static friction. :func:`rest_is_final`
predicts that force; :func:`rest_ends_run` says whether a quiet stop ends a
run (at the target for good, or off it with nothing left to move it).
"""

from __future__ import annotations

import numpy as np

from ..kernel.build import compiled
from ..kernel.layout import PlantParameters, state_index
from .settings import integrates, kernel_arrays

__all__ = ["rest_is_final", "rest_ends_run", "presliding_shift"]


def _joint_force(p: PlantParameters, d: float) -> float:
    """Static force of the joint at deflection ``d`` [m]: spring and limiter contact [N]."""
    f = p.k * d
    if d > p.s:
        f += p.k_stop * (d - p.s)
    elif d < -p.s:
        f += p.k_stop * (d + p.s)
    return f


def presliding_shift(p: PlantParameters, z: float, d0: float) -> float:
    """The stuck cart's presliding displacement D [m] at which its bristles balance the joint
    held at the deflection ``d0`` [m] less D: sigma0 (z + D) = k (d0 - D) + F_stop.

    With e = d0 - D the balance reads k e + F_stop(e) + sigma0 e = sigma0 (z + d0), its left
    side rising in straight pieces (the limiter's contact adds k_stop beyond +-s): the
    piece whose e lies in its own range is the answer, exactly.
    """
    target = p.sigma0 * (z + d0)
    e = target / (p.k + p.sigma0)
    if e > p.s:
        e = (target + p.k_stop * p.s) / (p.k + p.k_stop + p.sigma0)
    elif e < -p.s:
        e = (target - p.k_stop * p.s) / (p.k + p.k_stop + p.sigma0)
    return d0 - e


def rest_is_final(params: PlantParameters, y: np.ndarray, level: float) -> bool:
    """Whether a stage resting near its target stays at rest for good.

    At rest the integrator drives x1 to the target r; the cart, stuck, then
    carries a friction force set by where it stuck, and stays stuck only if
    that force stays below its static friction. With LuGre friction the stuck
    cart moves only by presliding, dz = dx: without isolator the bristle
    force at the target is sigma0 (z + r - x1); with the isolator the joint
    force at the target deflection balances the bristles,
    sigma0 (z + D) = k (r - x2 - D) + F_stop, solved for the presliding
    displacement D. With the switch model the cart cannot move at all: a
    stage without isolator rests for good only exactly on target. A loop
    without integrator asks nothing more of friction than it does now.

    Parameters
    ----------
    params : PlantParameters
        The plant.
    y : ndarray, shape (n,)
        The resting state (SI).
    level : float
        The held reference r [m].

    Returns
    -------
    bool
        True when the predicted force stays below the static friction (of
        its direction, at the cart's position).
    """
    p = params
    if not integrates(p):
        return True
    idx = state_index(bool(p.isolated))
    x1, z = float(y[idx["x1"]]), float(y[idx["z"]])
    switch = p.switch_model != 0.0
    if p.isolated:
        x2 = float(y[idx["x2"]])
        d0 = level - x2
        shift = 0.0 if switch else presliding_shift(p, z, d0)
        force = _joint_force(p, d0 - shift)
        x_cart = x2 + shift
    else:
        if switch:
            return abs(level - x1) <= 1e-12 * max(1.0, abs(level))
        force = p.sigma0 * (z + level - x1)
        x_cart = level
    sign = 1.0 if force >= 0.0 else -1.0
    g0 = compiled().stribeck(0.0, x_cart, sign, kernel_arrays(p, 1.0)[0])[0]
    return abs(force) < g0


def rest_ends_run(params: PlantParameters, y: np.ndarray, level: float, band: float) -> bool:
    """Whether a quiet stop ends the run.

    It does at the target for good (:func:`rest_is_final`), or off it with
    nothing left to move it (no integrator, or a drive at its force limit).

    Parameters
    ----------
    params : PlantParameters
        The plant.
    y : ndarray, shape (n,)
        The state where the stage came to rest (SI).
    level : float
        The held reference r [m].
    band : float
        Settle band on x1 - r [m].

    Returns
    -------
    bool
    """
    if abs(y[0] - level) <= band:
        return rest_is_final(params, y, level)
    if not integrates(params):
        return True
    iu = state_index(bool(params.isolated))["u"]
    return abs(y[iu]) >= params.force_limit * (1.0 - 1e-9)
