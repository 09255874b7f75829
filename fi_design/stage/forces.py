"""The forces over the move family: how hard the joint hits its end stop, and the actuator's peak.

Every move of the family (:func:`fi_design.stage.family_distances`, and the
spec's own motion) is simulated from rest through the move and ``settle``
seconds after it, with traces at ``rate``: the end stop's contact force
``k_stop (|d| - s) sign(d) + c_stop (v1 - v2)`` while the joint deflection
``|d|`` exceeds the stroke s (the kernel's own contact law), the number of
contacts, the time in contact, and the largest force the controller commands.
On a vertical drive axis the actuator also holds the weight (m1 + m2) g, which
the simulation does not carry (:attr:`fi_design.model.Model.held_weight`): it is
added to the largest force either way (the spec does not say which way is up),
the force applied capped at the saturation ``force_limit``.
The contact lasts milliseconds (a 1e6 N/m stop under a 1.6 kg stage rings at
about 125 Hz), so the traces are sampled at 5 kHz by default; a family of long
moves (slow scans of hundreds of seconds) at a lower rate, so that no run holds
more than :data:`MAX_SAMPLES` samples.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .. import spec as _spec
from ..model import Model, require_model
from ..results.forces import MoveForces, StageForces
from ..trajectory import from_moves, profile_duration
from .family import family_distances

__all__ = ["SETTLE", "RATE", "MAX_SAMPLES", "move_forces"]

#: Time simulated after each move's end [s].
SETTLE = 2.0
#: Output rate of the force runs [Hz].
RATE = 5000.0
#: Output samples of the longest force run at most: the rate is lowered to keep it.
MAX_SAMPLES = 1_000_000


def _one(model: Model, isolated: bool, moves, end: float, settle: float, rate: float,
         distance: float, label: str, weight: float, limit: float) -> MoveForces:
    from ..simulation.run import simulate

    duration = end + settle
    res = simulate(model, isolated, reference=from_moves(moves, duration), duration=duration,
                   rate=rate)
    def peak(x) -> float:
        a = np.abs(x[np.isfinite(x)])
        return float(a.max()) if a.size else 0.0

    # the weight the loop holds and the simulation leaves out: on top of the largest force
    # either way, the force applied no more than the saturation
    peak_u = min(peak(res.applied_force) + weight, limit)
    peak_cmd = peak(res.force) + weight
    if not isolated:
        return MoveForces(distance=distance, label=label, impacts=0, peak_stop_force=0.0,
                          peak_actuator_force=peak_u, contact_time=0.0, peak_command=peak_cmd)
    j, lim = model.joint, model.limiter
    d = res.position - res.cart_position
    dv = res.velocity - res.cart_velocity
    s = j.stroke
    over = np.where(d > s, d - s, np.where(d < -s, d + s, 0.0))
    contact = over != 0.0
    force = np.where(contact, lim.stiffness * over + lim.damping * dv, 0.0)
    starts = int(np.count_nonzero(contact[1:] & ~contact[:-1]) + int(contact[0]))
    finite = np.isfinite(force)
    return MoveForces(distance=distance, label=label, impacts=starts,
                      peak_stop_force=float(np.max(np.abs(force[finite]), initial=0.0)),
                      peak_actuator_force=peak_u,
                      contact_time=float(np.count_nonzero(contact)) / rate,
                      peak_command=peak_cmd)


def move_forces(model: Model, isolated: bool | None = None, *,
                family: Sequence[float] | None = None, settle: float = SETTLE,
                rate: float = RATE) -> StageForces:
    """The forces of every move of the family, the spec's own motion first.

    Parameters
    ----------
    model : Model
        The resolved model (:func:`fi_design.model.resolve`).
    isolated : bool, optional
        Which plant; None follows the model.
    family : sequence of float, optional
        Signed move distances [m] in place of ``motion.family``.
    settle : float, optional
        Time after each move's end [s]. Default :data:`SETTLE`.
    rate : float, optional
        Output rate [Hz]. Default :data:`RATE`, lowered where the longest run
        would hold more than :data:`MAX_SAMPLES` samples (the result's ``rate``
        is the one used).

    Returns
    -------
    StageForces
    """
    model = require_model(model)
    iso = model.has_isolator if isolated is None else bool(isolated)
    spec = model.spec
    motion = spec.motion
    params = model.plant(iso)
    dists = family_distances(model, iso, params) if family is None else family
    big = max(motion.moves, key=lambda m: abs(m.distance))
    runs = [(motion.moves, motion.end_time, float(sum(m.distance for m in motion.moves)),
             "spec")]
    for d in dists:
        mv = _spec.Move(distance=float(d), velocity=big.velocity,
                        acceleration=big.acceleration, jerk=big.jerk)
        end = profile_duration(float(d), big.velocity, big.acceleration, big.jerk)
        runs.append(((mv,), end, float(d), "family"))
    longest = max(end for _, end, _, _ in runs) + settle
    rate = min(float(rate), MAX_SAMPLES / longest)
    weight = model.held_weight
    out = [_one(model, iso, moves, end, settle, rate, d, label, weight, params.force_limit)
           for moves, end, d, label in runs]
    lim = model.limiter if iso else None
    given = spec.isolator.limiter.model_fields_set if iso and spec.isolator is not None \
        else set()
    return StageForces(plant="isolated" if iso else "non_isolated", moves=tuple(out),
                       stop_stiffness=None if lim is None else lim.stiffness,
                       stop_damping=None if lim is None else lim.damping,
                       stop_default=not {"stiffness", "damping"} <= set(given),
                       settle=settle, rate=rate, held_weight=weight)
