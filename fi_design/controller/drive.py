"""The loop's gains in the drive's own units: encoder counts in, current command out.

With ``controller.drive`` (motor force constant Kf [N/A], encoder resolution
q [m per count], current scaling c [A per unit of the drive's current
command]) a force F = Kf c u and a position x = q n, so each gain in SI
times ``q / (Kf c)`` is the drive's: kp in units per count, ki per count and
second, kd in unit seconds per count.
"""

from __future__ import annotations

import math

from ..display import quantity
from ..results.controller import ControlLaw, DiscreteController, DriveGains

__all__ = ["drive_gains"]


def drive_gains(law: ControlLaw, discrete: DiscreteController | None = None) -> DriveGains | None:
    """The law's gains in the drive's units, or None without ``controller.drive``.

    Parameters
    ----------
    law : ControlLaw
        The loop's controller (its ``drive``).
    discrete : DiscreteController, optional
        Its sampled form, whose recursion gains are converted too.

    Returns
    -------
    DriveGains or None
    """
    drv = law.drive
    if drv is None:
        return None
    per_count = drv.encoder_resolution / drv.force_per_unit
    unit = "A" if drv.current_scaling == 1.0 else f"unit of {quantity(drv.current_scaling, 'A', 6)}"
    short = "A" if unit == "A" else "unit"
    limit = None if math.isinf(law.force_limit) else law.force_limit / drv.force_per_unit
    units = {"kp": f"{short}/count", "ki": f"{short}/(count s)", "kd": f"{short} s/count",
             "force_limit": short}
    ig = dg = None
    if discrete is not None:
        ig, dg = discrete.integrator_gain * per_count, discrete.derivative_gain * per_count
        units.update(integrator_gain=f"{short}/count", derivative_gain=f"{short}/count")
    return DriveGains(current_unit=unit, kp=law.kp * per_count, ki=law.ki * per_count,
                      kd=law.kd * per_count, force_limit=limit, integrator_gain=ig,
                      derivative_gain=dg, units=units)
