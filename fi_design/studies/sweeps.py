"""Sweeps: the hunting metric over a grid of one or two spec values (paper Figure 4).

:func:`sweep` resolves the design once (:func:`~.points.study_model`),
simulates every point of the grid, the model varied by the point's values
(:mod:`.points`), and returns a :class:`SweepResult`; :func:`design_map` is
the small crossover x stroke map around a design point that the sign-off
report shows.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import Union

import numpy as np

from .. import spec as _spec
from ..errors import ArgumentError, SpecError
from ..execution import Executor
from ..model import Model
from ..results.design import DesignResult
from ..results.studies import Axis, DesignMap, SweepResult
from ..spec.file import value_at
from .axes import crossover_note, design_value, held_damping_note, make_axis
from .cache import PointCache
from .points import (MAX_POINTS, ProgressCallback, evaluate, grid, point_result, study_model,
                     verdict_grid)

__all__ = ["AxisLike", "sweep", "design_map"]


#: An axis as the library takes it: an :class:`~.axes.Axis` or a (dotted path, SI values) pair.
AxisLike = Union[Axis, tuple[str, Sequence[float]]]


def _as_axis(value: AxisLike, spec: _spec.Spec, name: str) -> Axis:
    if isinstance(value, Axis):
        return value
    if isinstance(value, (tuple, list)) and len(value) == 2 and isinstance(value[0], str):
        return make_axis(value[0], value[1], spec=spec)
    raise ArgumentError(f"{name} must be an Axis or a (path, values) pair; read text such as "
                        "'controller.crossover=2 Hz:30 Hz:15' with parse_axis")


def sweep(spec: _spec.Spec | Model, x: AxisLike, y: AxisLike | None = None, *,
          isolated: bool | None = None, executor: Executor | None = None,
          progress: ProgressCallback | None = None,
          cache: PointCache | str | os.PathLike | bool | None = None,
          chunksize: int | None = None, measure: str = "stage") -> SweepResult:
    """Map the hunting metric over one or two spec values.

    Parameters
    ----------
    spec : Spec, Model, path or mapping
        The design (the design point): a spec, resolved once here, or the
        model resolved from it (not one varied by :meth:`Model.at`).
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
    measure : {"stage", "move"}, optional
        ``"stage"`` (default): per point, whether any move of the family ends
        in a sustained cycle and that cycle's peak-to-peak amplitude
        (:mod:`fi_design.stage`); ``"move"``: the paper's hunting metric on
        the spec's own move.

    Returns
    -------
    SweepResult
        Invalid and failed points are recorded in the result, never raised.

    Raises
    ------
    SpecError
        Unknown path, a path to a non-numeric value, a path the spec cannot
        hold (a list entry out of range, a section it does not have), the same
        path twice, an isolated sweep of a spec without isolator, or a grid of more than
        :data:`~.points.MAX_POINTS` points.
    ArgumentError
        An axis that is neither an :class:`~.axes.Axis` nor a ``(path, values)``
        pair, or a model varied by :meth:`Model.at`.
    """
    from .. import __version__

    model = study_model(spec)
    spec = model.spec
    ax = _as_axis(x, spec, "x")
    ay = _as_axis(y, spec, "y") if y is not None else None
    if ay is not None and ay.path == ax.path:
        raise SpecError("x and y sweep the same value", path=ax.path)
    for axis in (ax, ay):
        if axis is not None:  # a list entry or section the spec lacks fails every point: say so now
            value_at(spec, axis.path)
    n_points = len(ax.values) * (1 if ay is None else len(ay.values))
    if n_points > MAX_POINTS:
        raise SpecError(f"{len(ax.values)} x {len(ay.values)} = {n_points} points; a study holds "
                        f"at most {MAX_POINTS} (a few ms to a few tens of ms each)",
                        path=f"{ax.path}, {ay.path}")
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
    ev = evaluate(model, tasks, executor=executor, progress=progress, cache=cache,
                  chunksize=chunksize, measure=measure)
    points = tuple(point_result(idx, vals, iso, out)
                   for (idx, vals), out in zip(cells, ev.outcomes))
    design = tuple(design_value(model, p) for p in paths)
    return SweepResult(
        spec=spec, x=ax, y=ay, isolated=iso, points=points,
        hunting_cycles=grid(points, shape, "hunting_cycles"),
        amplitude=grid(points, shape, "amplitude"), period=grid(points, shape, "period"),
        verdict=verdict_grid(points, shape), design_point=design, run=ev.run,
        fi_design_version=__version__, measure=measure,
        notes=tuple(n for n in (held_damping_note(model, (ax, ay)), crossover_note((ax, ay)))
                    if n))


def design_map(result: DesignResult, *, resolution: tuple[int, int] = (8, 6),
               executor: Executor | None = None, progress: ProgressCallback | None = None,
               cache: PointCache | str | os.PathLike | bool | None = None,
               measure: str = "stage") -> DesignMap:
    """A small crossover x stroke hunting map around the design point (paper Figure 4D).

    Crossover from 0.125 to 2.5 times the design's, stroke from 1/6 to 10/3
    times (logarithmic), the isolated plant with the PID retuned at every
    crossover.

    Parameters
    ----------
    result : fi_design.guideline.steps.DesignResult
        The design; a spec without isolator is mapped with the isolator the
        guideline suggests (``result.isolator_advice``).
    resolution : (int, int), optional
        Points along the crossover and the stroke (default 8 x 6 = 48
        simulations, a few seconds).
    executor, progress, cache, measure
        As for :func:`sweep`.

    Returns
    -------
    DesignMap
    """
    from ..stage.confirm import with_isolator

    model = study_model(result.model if result.model is not None else result.spec, "result")
    fc = model.crossover  # the design's (the control law does not depend on the isolator)
    suggested = not model.has_isolator
    if suggested:
        adv = result.isolator_advice
        model = with_isolator(model, adv.stroke, adv.stiffness)
    iso = model.spec.isolator
    s = iso.stroke
    nx, ny = resolution
    x = make_axis("controller.crossover", np.linspace(0.125 * fc, 2.5 * fc, nx), spec=model.spec)
    y = make_axis("isolator.stroke", np.geomspace(s / 6.0, s * 10.0 / 3.0, ny), log=True,
                  spec=model.spec)
    out = sweep(model, x, y, isolated=True, executor=executor, progress=progress, cache=cache,
                measure=measure)
    return DesignMap(sweep=out, suggested=suggested, stroke=s, stiffness=iso.stiffness)
