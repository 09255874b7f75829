"""The paper's parameter study: its four hunting maps (Figure 4) around a design point."""

from __future__ import annotations

import os
import time as _time
from dataclasses import replace

import numpy as np

from .. import spec as _spec
from ..errors import SpecError
from ..execution import Executor
from ..model import Model, require_model
from ..results.studies import Axis, MapDefinition, StudyMap, StudyResult, SweepResult
from .axes import design_value, make_axis
from .cache import PointCache
from .points import ProgressCallback, evaluate, grid, point_result, study_model, verdict_grid

__all__ = ["PAPER_MAPS", "paper_axes", "paper_study"]


#: The paper's four maps (Figure 4), ranges as factors on the design point.
#: Most points per axis of a map: four maps of 150 x 150 are 90 000 points, within a study's
#: :data:`~.points.MAX_POINTS`.
MAX_RESOLUTION = 150

PAPER_MAPS: tuple[MapDefinition, ...] = (
    MapDefinition("A", "static vs Coulomb friction, without isolator",
                  "friction.static", (0.25, 1.5), False,
                  "friction.coulomb", (0.125, 1.0), False, False,
                  "hunting only when Fs - Fc exceeds roughly 1 N; a larger gap, more cycles"),
    MapDefinition("B", "crossover vs mass, without isolator",
                  "controller.crossover", (0.25, 4.0), False,
                  "stage.mass", (0.25, 2.5), False, False,
                  "no hunting above a crossover of around 20 Hz"),
    MapDefinition("C", "stroke vs drive stiffness, with isolator",
                  "isolator.stroke", (1 / 6, 10 / 3), True,
                  "isolator.stiffness", (0.15, 15.0), True, True,
                  "the drive stiffness must be limited; a smaller stroke allows a higher "
                  "stiffness (k s < Fs)"),
    MapDefinition("D", "crossover vs stroke, with isolator",
                  "controller.crossover", (0.125, 2.5), False,
                  "isolator.stroke", (1 / 6, 10 / 3), True, True,
                  "hunting only below a crossover of about 5 Hz; a 0.3 mm stroke is "
                  "sufficient"),
)


def paper_axes(model: Model, definition: MapDefinition, resolution: int) -> tuple[Axis, Axis]:
    """The axes of one of the paper's maps around a design point.

    Parameters
    ----------
    model : Model
        The design, resolved from its spec.
    definition : MapDefinition
        The map.
    resolution : int
        Points per axis.

    Returns
    -------
    x, y : Axis
        Ranges are the definition's factors on the design value; for map A the
        Coulomb range is widened so that it covers the spec's Fc.

    Raises
    ------
    SpecError
        The spec lacks a value the map needs (an isolator for maps C and D).
    """
    model = require_model(model)
    spec = model.spec
    axes = []
    for path, (lo, hi), log in ((definition.x_path, definition.x_range, definition.x_log),
                                (definition.y_path, definition.y_range, definition.y_log)):
        ref = design_value(model, path)
        if path == "friction.coulomb":  # ranges relative to Fs keep the map around the gap
            ref = spec.friction.static
            lo = min(lo, 0.5 * spec.friction.coulomb / ref)
        if ref is None or ref <= 0:
            raise SpecError(f"map {definition.key} ({definition.title}) needs a value here",
                            path=path.split(".")[0] if path.startswith("isolator") else path)
        values = np.geomspace(lo * ref, hi * ref, resolution) if log else \
            np.linspace(lo * ref, hi * ref, resolution)
        axes.append(make_axis(path, values, log=log, spec=spec))
    return axes[0], axes[1]


def paper_study(spec: _spec.Spec | Model, resolution: int = 12, *, maps: str = "ABCD",
                executor: Executor | None = None, progress: ProgressCallback | None = None,
                cache: PointCache | str | os.PathLike | bool | None = None,
                chunksize: int | None = None, measure: str = "stage") -> StudyResult:
    """The paper's four maps (Figure 4) around a spec's design point.

    A: ``friction.static`` x ``friction.coulomb`` without isolator; B:
    ``controller.crossover`` x ``stage.mass`` without isolator; C:
    ``isolator.stroke`` x ``isolator.stiffness`` with it; D:
    ``controller.crossover`` x ``isolator.stroke`` with it. Ranges are
    factors on the design values (:data:`PAPER_MAPS`). All points of all maps
    go to the executor together.

    Parameters
    ----------
    spec : Spec, Model, path or mapping
        The design: a spec, resolved once here, or the model resolved from it
        (not one varied by :meth:`Model.at`); maps C and D need an isolator.
    resolution : int, optional
        Points per axis (default 12: 576 simulations).
    maps : str, optional
        Which maps, e.g. ``"AB"``. Default all four.
    executor : fi_design.execution.Executor, optional
        As for :func:`~.sweeps.sweep`.
    progress : callable, optional
        ``progress(done, total)`` over all maps.
    cache : PointCache, path, True or None, optional
        As for :func:`~.sweeps.sweep`.
    chunksize : int, optional
        As for :func:`~.sweeps.sweep`.
    measure : {"stage", "move"}, optional
        ``"stage"`` (default): per point, whether any move of the family ends
        in a sustained cycle and that cycle's peak-to-peak amplitude
        (:mod:`fi_design.stage`); ``"move"``: the paper's hunting metric on
        the spec's own move.

    Returns
    -------
    StudyResult

    Raises
    ------
    SpecError
        Resolution below 2, an unknown map letter, or maps C/D for a spec
        without isolator.
    ArgumentError
        A resolution that is not a whole number or above :data:`MAX_RESOLUTION`, or a
        model varied by :meth:`Model.at`.
    """
    from .. import __version__

    from ..arguments import integer

    model = study_model(spec)
    spec = model.spec
    if isinstance(resolution, int) and resolution < 2:
        raise SpecError(f"the resolution must be at least 2 points per axis, got {resolution}")
    resolution = integer(resolution, "resolution", minimum=2, maximum=MAX_RESOLUTION)
    keys = [k.upper() for k in maps]
    known = {d.key: d for d in PAPER_MAPS}
    bad = [k for k in keys if k not in known]
    if bad or not keys:
        raise SpecError(f"unknown map(s) {''.join(bad) or '(none)'}; choose from "
                        f"{''.join(known)}")
    start = _time.perf_counter()
    defs = [known[k] for k in dict.fromkeys(keys)]
    if any(d.isolated for d in defs) and not spec.has_isolator:
        raise SpecError("maps C and D simulate the isolated stage: the spec needs an isolator "
                        "section (or choose maps A and B)", path="isolator")
    layouts = []
    tasks: list = []
    for d in defs:
        ax, ay = paper_axes(model, d, resolution)
        cells = [((j, i), (float(vx), float(vy))) for j, vy in enumerate(ay.values)
                for i, vx in enumerate(ax.values)]
        layouts.append((d, ax, ay, cells, len(tasks)))
        tasks += [(((ax.path, vals[0]), (ay.path, vals[1])), d.isolated) for _, vals in cells]
    ev = evaluate(model, tasks, executor=executor, progress=progress, cache=cache,
                  chunksize=chunksize, measure=measure)
    info = replace(ev.run, wall_time=_time.perf_counter() - start)
    out_maps = []
    for d, ax, ay, cells, offset in layouts:
        shape = (len(ay.values), len(ax.values))
        points = tuple(point_result(idx, vals, d.isolated, ev.outcomes[offset + n])
                       for n, (idx, vals) in enumerate(cells))
        res = SweepResult(
            spec=spec, x=ax, y=ay, isolated=d.isolated, points=points,
            hunting_cycles=grid(points, shape, "hunting_cycles"),
            amplitude=grid(points, shape, "amplitude"), period=grid(points, shape, "period"),
            verdict=verdict_grid(points, shape),
            design_point=(design_value(model, ax.path), design_value(model, ay.path)),
            run=info, fi_design_version=__version__, measure=measure)
        out_maps.append(StudyMap(d, res))
    return StudyResult(spec=spec, maps=tuple(out_maps), resolution=resolution, run=info)
