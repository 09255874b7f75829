"""The move family: its distances, and the references of its moves and of the spec's motion.

One simulated move says little about a bistable stage, so each plant is
judged over a family of moves (``motion.family``) beside the spec's own
motion. This module says which moves (:func:`family_distances`) and what
reference each follows: the move from rest, then the target held for the
horizon (:func:`family_reference`, :func:`spec_reference`), or the target
held alone (:func:`hold`, to continue a run from a state).
"""

from __future__ import annotations

import functools

import numpy as np

from .. import spec as _spec
from ..kernel.layout import PlantParameters
from ..model import Model, require_model
from ..trajectory import Trajectory, from_moves, profile_duration
from .settings import symmetric

__all__ = ["largest_move", "family_distances", "family_reference", "spec_reference", "hold"]


def largest_move(spec: _spec.Spec) -> _spec.Move:
    """The move of the spec's motion with the largest distance (either sign).

    Parameters
    ----------
    spec : Spec
        The spec (its ``motion.moves``).

    Returns
    -------
    Move
        Its distance [m], velocity [m/s], acceleration [m/s^2] and jerk [m/s^3]
        set the profile of every move of the family.
    """
    return max(spec.motion.moves, key=lambda mv: abs(mv.distance))


def family_distances(model: Model, isolated: bool,
                     params: PlantParameters | None = None) -> tuple[float, ...]:
    """Signed distances of the move family of one plant [m].

    Parameters
    ----------
    model : Model
        The resolved model (its spec's ``motion.family``).
    isolated : bool
        Which plant: the default smallest distance is a tenth of the stroke
        with the isolator, 0.1 mm without.
    params : PlantParameters, optional
        The plant, to tell whether it is symmetric (``directions: auto``).

    Returns
    -------
    tuple of float
        Positive distances first, increasing, then the negative ones [m].
    """
    model = require_model(model)
    spec = model.spec
    fam = spec.motion.family
    if fam.distances is not None:
        return tuple(float(d) for d in fam.distances)
    if fam.smallest is not None:
        lo = fam.smallest
    elif isolated and model.joint is not None:
        lo = 0.1 * model.joint.stroke
    else:
        lo = 1e-4
    hi = fam.largest if fam.largest is not None else 5.0 * abs(largest_move(spec).distance)
    hi = max(hi, lo * 1.0001)
    base = tuple(float(d) for d in np.geomspace(lo, hi, fam.count))
    both = fam.directions == "both" or (
        fam.directions == "auto" and params is not None and not symmetric(params))
    return base + tuple(-d for d in base) if both else base


def family_reference(spec: _spec.Spec, distance: float, horizon: float) \
        -> tuple[Trajectory, float]:
    """One move of the family from rest, then its target held for ``horizon``.

    Parameters
    ----------
    spec : Spec
        The spec: the move takes the profile (velocity, acceleration, jerk) of
        its largest move.
    distance : float
        Signed move distance [m].
    horizon : float
        Time the target is held after the move [s].

    Returns
    -------
    (Trajectory, float)
        The reference, and when the move ends [s].
    """
    mv = largest_move(spec)
    return _reference(float(distance), mv.velocity, mv.acceleration, mv.jerk, float(horizon))


@functools.lru_cache(maxsize=512)
def _reference(distance: float, velocity: float, acceleration: float, jerk: float | None,
               horizon: float) -> tuple[Trajectory, float]:
    """:func:`family_reference` of a profile, made once per process (a Trajectory is
    read-only: the runs of every sample and candidate share it)."""
    move = _spec.Move(distance=distance, velocity=velocity, acceleration=acceleration,
                      jerk=jerk)
    end = profile_duration(distance, velocity, acceleration, jerk)
    return from_moves((move,), end + horizon), end


def spec_reference(spec: _spec.Spec, horizon: float) -> tuple[Trajectory, float]:
    """The spec's own motion (all its moves), then its end held for ``horizon``.

    Parameters
    ----------
    spec : Spec
        The spec (its ``motion``).
    horizon : float
        Time the end position is held after the motion [s].

    Returns
    -------
    (Trajectory, float)
        The reference, and when the motion ends [s].
    """
    end = spec.motion.end_time
    return from_moves(spec.motion.moves, end + horizon), end


def hold(level: float, duration: float) -> Trajectory:
    """The reference held at ``level`` [m] for ``duration`` [s] (no landing).

    Parameters
    ----------
    level : float
        The held position r [m].
    duration : float
        How long [s].

    Returns
    -------
    Trajectory
    """
    return Trajectory(np.array([0.0, duration]), np.array([[level, 0.0, 0.0, 0.0]]), land=False)
