"""Sweeps: the hunting metric over a grid of one or two spec values (paper Figure 4).

:func:`sweep` simulates every point of the grid (:mod:`.points`) and returns a
:class:`SweepResult`; :func:`design_map` is the small crossover x stroke map
around a design point that the sign-off report shows.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Union

import numpy as np

from .. import spec as _spec
from ..errors import ArgumentError, SpecError
from ..execution import Executor
from ..results import frozen_array, to_jsonable
from .axes import Axis, design_value, make_axis
from .cache import PointCache, spec_digest
from .points import (POINT_VERDICTS, PointResult, ProgressCallback, RunInfo, columns, csv_text,
                     evaluate, grid, point_result, verdict_grid)

if TYPE_CHECKING:  # pragma: no cover
    from ..guideline import DesignResult

__all__ = ["AxisLike", "SweepResult", "sweep", "DesignMap", "design_map"]


@dataclass(frozen=True, eq=False)
class SweepResult:
    """A map (or line) of the hunting metric over one or two spec values.

    Attributes
    ----------
    spec : Spec
        The base spec; every point is this spec with the swept values replaced.
    x : Axis
        The first swept value (columns of a map).
    y : Axis or None
        The second swept value (rows of a map); None for a line.
    isolated : bool
        Whether the isolated plant was simulated.
    points : tuple of PointResult
        Every point, rows (y) outer, columns (x) inner.
    hunting_cycles : ndarray, shape (ny, nx) or (nx,)
        Hunting cycles counted per point; NaN where the point is invalid or
        failed.
    amplitude : ndarray, same shape
        Peak-to-peak error in the counting window [m]; NaN without a metric.
    period : ndarray, same shape
        Mean period of the counted cycles [s]; NaN with fewer than two peaks.
    verdict : ndarray of str, same shape
        Verdict per point (``settled``, ``hunting``, ``stuck``,
        ``undetermined``, ``invalid``, ``failed``).
    design_point : tuple of float or None
        The spec's own value of x and of y (None when the spec leaves it to a
        derived default that cannot be computed) [SI].
    run : RunInfo
        How the sweep ran (points computed and cached, executor, wall time).
    fi_design_version : str
        Version of fi_design that produced the result.
    """

    spec: _spec.Spec
    x: Axis
    y: Axis | None
    isolated: bool
    points: tuple[PointResult, ...]
    hunting_cycles: np.ndarray
    amplitude: np.ndarray
    period: np.ndarray
    verdict: np.ndarray
    design_point: tuple[float | None, ...]
    run: RunInfo = field(repr=False)
    fi_design_version: str = ""

    @property
    def paths(self) -> tuple[str, ...]:
        """The swept paths, x first."""
        return (self.x.path,) if self.y is None else (self.x.path, self.y.path)

    @property
    def shape(self) -> tuple[int, ...]:
        """``(ny, nx)`` for a map, ``(nx,)`` for a line."""
        return self.hunting_cycles.shape

    def counts(self) -> dict[str, int]:
        """Number of points per verdict (every verdict listed, zeros included).

        Returns
        -------
        dict
            Verdict to count.
        """
        return {v: int(np.sum(self.verdict == v)) for v in POINT_VERDICTS}

    def boundary(self, free: str = "above") -> np.ndarray:
        """Where hunting stops along x, for each row of the map.

        Parameters
        ----------
        free : {"above", "below"}
            ``"above"``: the lowest x from which no point up to the end of the
            row hunts (for values where more is better, like the crossover);
            ``"below"``: the highest x up to which no point from the start of
            the row hunts (like the drive stiffness).

        Returns
        -------
        ndarray, shape (ny,) or (1,)
            The x value [x.unit] per row; NaN when the row's last (first) point
            hunts or is not a valid, complete simulation. Points that are
            ``stuck`` or ``undetermined`` do not count as hunting.
        """
        if free not in ("above", "below"):
            raise ArgumentError("free must be 'above' or 'below'")
        verdicts = self.verdict.reshape(-1, len(self.x.values))
        xs = self.x.values
        out = np.full(verdicts.shape[0], np.nan)
        for r, row in enumerate(verdicts):
            order = range(len(xs) - 1, -1, -1) if free == "above" else range(len(xs))
            last = None
            for i in order:
                if row[i] in ("hunting", "invalid", "failed"):
                    break
                last = i
            if last is not None:
                out[r] = xs[last]
        return frozen_array(out)

    def table(self) -> dict[str, list]:
        """The points as columns: one per swept path [SI], then the metric.

        Returns
        -------
        dict of str to list
            Columns (in order) named by each swept dotted path, then
            ``hunting_cycles``, ``amplitude`` [m], ``period`` [s], ``verdict``,
            ``status`` and ``message``. ``None`` where a point has no value.
            ``pandas.DataFrame(result.table())`` gives a data frame.
        """
        return columns(self.paths, self.points)

    def to_csv(self) -> str:
        """The :meth:`table` as CSV text (one row per point; empty cells for no value).

        Returns
        -------
        str
        """
        return csv_text(self.table())

    def to_dict(self) -> dict:
        """Plain JSON data: axes, metric arrays, points, design point, run info."""
        return {
            "fi_design_version": self.fi_design_version,
            "spec_name": self.spec.name,
            "spec_sha256": spec_digest(self.spec),
            "isolated": self.isolated,
            "x": self.x.to_dict(),
            "y": self.y.to_dict() if self.y is not None else None,
            "design_point": to_jsonable(list(self.design_point)),
            "hunting_cycles": to_jsonable(self.hunting_cycles),
            "amplitude": to_jsonable(self.amplitude),
            "period": to_jsonable(self.period),
            "verdict": self.verdict.tolist(),
            "counts": self.counts(),
            "points": [p.to_dict() for p in self.points],
            "run": self.run.to_dict(),
        }


#: An axis as the library takes it: an :class:`~.axes.Axis` or a (dotted path, SI values) pair.
AxisLike = Union[Axis, tuple[str, Sequence[float]]]


def _as_axis(value: AxisLike, spec: _spec.Spec, name: str) -> Axis:
    if isinstance(value, Axis):
        return value
    if isinstance(value, (tuple, list)) and len(value) == 2 and isinstance(value[0], str):
        return make_axis(value[0], value[1], spec=spec)
    raise ArgumentError(f"{name} must be an Axis or a (path, values) pair; read text such as "
                        "'controller.crossover=2 Hz:30 Hz:15' with parse_axis")


def sweep(spec: _spec.Spec, x: AxisLike, y: AxisLike | None = None, *,
          isolated: bool | None = None, executor: Executor | None = None,
          progress: ProgressCallback | None = None,
          cache: PointCache | str | os.PathLike | bool | None = None,
          chunksize: int | None = None) -> SweepResult:
    """Map the hunting metric over one or two spec values.

    Parameters
    ----------
    spec : Spec
        The design spec (the design point).
    x : Axis or (path, values)
        First swept value: an :class:`~.axes.Axis` or a ``(dotted path, values
        in SI)`` pair (text ``"PATH=START:STOP:N"`` is read by
        :func:`~.axes.parse_axis`).
    y : Axis or (path, values), optional
        Second swept value; None for a one-dimensional sweep.
    isolated : bool, optional
        Simulate the isolated plant (True) or the stage without isolator
        (False); None follows the spec (isolated when it has an isolator).
    executor : fi_design.execution.Executor, optional
        Runs the chunks (``submit`` and futures with ``result`` and
        ``add_done_callback``); None runs them in this process.
    progress : callable, optional
        ``progress(done, total)`` in points, called in the calling thread
        after the cache lookup and after every chunk.
    cache : PointCache, path, True or None, optional
        Where finished points are stored and looked up (True: the default
        cache directory); None: no cache.
    chunksize : int, optional
        Points per chunk; default about 1/16 of the points, at most 64.

    Returns
    -------
    SweepResult
        Invalid and failed points are recorded in the result, never raised.

    Raises
    ------
    SpecError
        Unknown path, a path to a non-numeric value, the same path twice, or
        an isolated sweep of a spec without isolator.
    ArgumentError
        An axis that is neither an :class:`~.axes.Axis` nor a ``(path, values)``
        pair.
    """
    from .. import __version__

    ax = _as_axis(x, spec, "x")
    ay = _as_axis(y, spec, "y") if y is not None else None
    if ay is not None and ay.path == ax.path:
        raise SpecError("x and y sweep the same value", path=ax.path)
    iso = spec.has_isolator if isolated is None else bool(isolated)
    if iso and not spec.has_isolator:
        raise SpecError("the spec has no isolator: sweep without it (isolated=False / "
                        "--no-isolator) or add an isolator section", path="isolator")
    if ay is None:
        cells = [((i,), (float(v),)) for i, v in enumerate(ax.values)]
        shape: tuple[int, ...] = (len(ax.values),)
    else:
        cells = [((j, i), (float(vx), float(vy))) for j, vy in enumerate(ay.values)
                for i, vx in enumerate(ax.values)]
        shape = (len(ay.values), len(ax.values))
    paths = (ax.path,) if ay is None else (ax.path, ay.path)
    tasks = [(tuple(zip(paths, vals)), iso) for _, vals in cells]
    ev = evaluate(spec, tasks, executor=executor, progress=progress, cache=cache,
                  chunksize=chunksize)
    points = tuple(point_result(idx, vals, iso, out)
                   for (idx, vals), out in zip(cells, ev.outcomes))
    design = tuple(design_value(spec, p) for p in paths)
    return SweepResult(
        spec=spec, x=ax, y=ay, isolated=iso, points=points,
        hunting_cycles=grid(points, shape, "hunting_cycles"),
        amplitude=grid(points, shape, "amplitude"), period=grid(points, shape, "period"),
        verdict=verdict_grid(points, shape), design_point=design, run=ev.run,
        fi_design_version=__version__)


@dataclass(frozen=True, eq=False)
class DesignMap:
    """A crossover x stroke hunting map around a design point (paper Figure 4D).

    Attributes
    ----------
    sweep : SweepResult
        The map: x ``controller.crossover``, y ``isolator.stroke`` (log), the
        isolated plant, the PID retuned at every crossover.
    suggested : bool
        True when the design's spec has no isolator and the map uses the
        isolator the guideline suggests.
    stroke : float
        Stroke of that suggested isolator [m] (the spec's own when not
        suggested).
    stiffness : float or None
        Drive stiffness of the suggested isolator [N/m]; the spec's given
        stiffness otherwise, None when the spec leaves it to step 3 (it then
        follows the stroke across the map, k_max / 2).
    """

    sweep: SweepResult
    suggested: bool
    stroke: float
    stiffness: float | None


def design_map(result: DesignResult, *, resolution: tuple[int, int] = (8, 6),
               executor: Executor | None = None, progress: ProgressCallback | None = None,
               cache: PointCache | str | os.PathLike | bool | None = None) -> DesignMap:
    """A small crossover x stroke hunting map around the design point (paper Figure 4D).

    Crossover from 0.125 to 2.5 times the design's, stroke from 1/6 to 10/3
    times (logarithmic), the isolated plant with the PID retuned at every
    crossover.

    Parameters
    ----------
    result : fi_design.guideline.DesignResult
        The design; a spec without isolator is mapped with the isolator the
        guideline suggests (``result.isolator_advice``).
    resolution : (int, int), optional
        Points along the crossover and the stroke (default 8 x 6 = 48
        simulations, a few seconds).
    executor, progress, cache
        As for :func:`sweep`.

    Returns
    -------
    DesignMap
    """
    from ..confirm import with_isolator

    spec = result.spec
    suggested = spec.isolator is None
    if suggested:
        adv = result.isolator_advice
        spec = with_isolator(spec, adv.stroke, adv.stiffness)
    fc = _spec.design_crossover(spec)
    s = spec.isolator.stroke
    nx, ny = resolution
    x = make_axis("controller.crossover", np.linspace(0.125 * fc, 2.5 * fc, nx), spec=spec)
    y = make_axis("isolator.stroke", np.geomspace(s / 6.0, s * 10.0 / 3.0, ny), log=True,
                  spec=spec)
    out = sweep(spec, x, y, isolated=True, executor=executor, progress=progress, cache=cache)
    return DesignMap(sweep=out, suggested=suggested, stroke=s,
                     stiffness=spec.isolator.stiffness)
