"""Parameter studies: hunting maps over spec values, the paper's four maps, robustness.

Engineers choose an isolator from maps: the hunting metric over two design
parameters with the design point marked (paper Figure 4). This package
evaluates such maps and the probability of hunting under friction scatter,
one module per topic (the result types they return are in
:mod:`fi_design.results.studies`, re-exported here):

- :mod:`.axes` -- :func:`make_axis` (an :class:`Axis`, a swept spec value, from
  SI values), :func:`parse_axis` (from the command line's
  ``PATH=START:STOP:N``) and :func:`design_value`, the spec's own value at a
  dotted path;
- :mod:`.sweeps` -- :func:`sweep` over one or two axes, :class:`SweepResult`;
  :func:`design_map`, the crossover x stroke map around a design point;
- :mod:`.paper` -- :func:`paper_study`, the paper's maps A to D;
- :mod:`.scatter` -- :func:`robustness` under scatter
  (:func:`parse_scatter`, :func:`wilson_interval`);
- :mod:`.points` -- one point simulated and judged, many run in chunks;
- :mod:`.cache` -- :class:`PointCache`, the SQLite store of finished points;
- :mod:`.sensitivity` -- :func:`crossover_sensitivity`, the hunting-free
  crossover over the unidentified LuGre values sigma0, sigma1 and vs.

Execution. Points are independent; they are grouped in chunks (points of a
chunk interleaved over the grid, so chunks cost about the same) and the chunks
are submitted to the caller's executor (:class:`fi_design.execution.Executor`:
a :class:`concurrent.futures.ProcessPoolExecutor`, a
``dask.distributed.Client``, ...). With ``executor=None`` the chunks run in
the calling process, one after another. The library never creates pools or
clusters itself and never prints: progress goes to a ``progress(done, total)``
callback, called in the calling thread. Every point is simulated the same way
wherever it runs, so the results do not depend on the executor.

Workers must import the simulation kernel, which numba compiles once per
installation and then loads from its on-disk cache: call :func:`warm_up` in the
parent before starting workers (so the cache exists, and forked workers
inherit the compiled code) and pass it as the pool's ``initializer``.

Cache. A :class:`PointCache` stores the outcome of every point under a key
that hashes the spec, the point's values, the plant (isolated or not), the
fi_design version, a digest of the simulation code and the solver method. A
re-run, or a sweep resumed after an interruption, takes the finished points
from the cache and simulates only the rest. Outcomes that depend on the
machine (a worker that died, an unexpected exception) are never cached.

Outcomes. A point whose values the spec refuses (say ``friction.static``
below ``friction.coulomb``) is recorded with status ``"invalid"`` and the
validation message; a simulation that does not complete, or raises, is
``"failed"`` with its message. Neither stops the sweep.
"""

from __future__ import annotations

from ..results.studies import (POINT_VERDICTS, Axis, DesignMap, HuntingProbability,
                               MapDefinition, PointResult, PositionFriction, RobustnessResult,
                               RunInfo, Scatter, StudyMap, StudyResult, SweepResult)
from .axes import design_value, make_axis, parse_axis
from .cache import CACHE_ENV, PointCache, default_cache_dir
from .paper import PAPER_MAPS, paper_study
from .points import warm_up
from .scatter import parse_position_friction, parse_scatter, robustness, wilson_interval
from .sensitivity import crossover_sensitivity
from .sweeps import design_map, sweep

__all__ = [
    "Axis", "CACHE_ENV", "DesignMap", "HuntingProbability", "MapDefinition", "PAPER_MAPS",
    "POINT_VERDICTS", "PointCache", "PointResult", "PositionFriction", "RobustnessResult",
    "RunInfo", "Scatter", "StudyMap", "StudyResult", "SweepResult", "crossover_sensitivity",
    "default_cache_dir",
    "design_map", "design_value", "make_axis", "paper_study", "parse_axis",
    "parse_position_friction", "parse_scatter", "robustness", "sweep", "warm_up",
    "wilson_interval",
]
