"""Hunting as a property of the stage: every move of a family, the cycle itself, the boundary.

A PID loop around a mass with stick-slip friction is bistable: beside the
rest set (the cart stuck, the stage at its target, the friction force below
the static friction) lives a stable limit cycle, and which of the two a run
ends in depends on where the cart first sticks after the move. One simulated
move therefore says little about the stage. This package answers per plant,
one job per module, each importing only those listed after it:

- :mod:`.judge`: the answer of one plant (:func:`stage_hunting`);
- :mod:`.boundary`: the one fold search, the hunting-free crossover;
- :mod:`.moves`: every move of the family run (:func:`stage_hunts`);
  :mod:`.orbit`: the cycle as a periodic orbit; :mod:`.positioning` and
  :mod:`.forces`: the positioning requirement and the forces over the family;
- :mod:`.runs`: one move run to its answer (:func:`move_outcome`);
- :mod:`.family`: the move distances and references; :mod:`.rest`: when
  rest is final;
- :mod:`.settings`: the tolerances, the :class:`Watch`, the plant's traits.

The three steps:

1. *Which moves end in a cycle* (:func:`move_outcome`): a family of moves
   (``motion.family``, and always the spec's own motion), each simulated from
   rest with the kernel's watch switched on once the motion is over. The run
   stops as soon as the answer is certain: the stage has rested within the
   settle band for a few integrator time constants *and* the friction force
   the loop will ask of the resting cart stays below its static friction
   (:func:`rest_is_final`; otherwise the integrator would break it loose
   again and the run goes on), or its state at the Poincare section
   (x1 - r = 0 crossed upwards) repeats (a sustained cycle). A slow settling
   is never taken for a cycle, nor a long stick phase for rest.
2. *The cycle itself* (:func:`converge_cycle`): Newton's method on the
   return map of the section, from the state the hunting move repeated,
   with the Jacobian by finite differences (its eigenvalues are the Floquet
   multipliers, checked at two perturbation sizes); amplitude and period
   from one period of the converged orbit.
3. *The hunting-free crossover* (:func:`hunting_free_boundary`): the
   crossover above which the cycle no longer exists (:func:`cycle_fold`), by
   bisection on its existence, each test started from the orbit at the
   nearest crossover where it still exists (continuation); the family is
   then run just above to make sure no other cycle is entered there. The
   answer is a :class:`~fi_design.results.stage.Boundary`.

The kernel's watch (:func:`fi_design.kernel.integrator.integrate`) locates the section
crossings like mode events (the step is redone to end on them, never
interpolated), and a continuous-time controller without delay keeps its
whole state in the state vector, so a run can continue exactly from where
another stopped. A sampled or delayed controller holds state outside it:
such runs are repeated from the start rather than continued, and their
cycle is the one a long simulation settles on.
"""

from __future__ import annotations

from .boundary import cycle_fold, hunting_free_boundary
from .family import family_distances
from .judge import stage_hunting
from .moves import stage_hunts
from .orbit import converge_cycle, cycle_exists
from .positioning import positioning, positioning_checks, settle_time
from .rest import rest_is_final
from .runs import move_outcome
from .settings import Watch, watch_settings

__all__ = ["Watch", "watch_settings", "family_distances", "rest_is_final", "move_outcome",
           "converge_cycle", "cycle_exists", "cycle_fold", "hunting_free_boundary",
           "stage_hunting", "stage_hunts", "positioning", "positioning_checks", "settle_time"]
