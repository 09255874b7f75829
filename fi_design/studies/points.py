"""Points of a parameter study: simulate one, run many in chunks, record the outcomes.

Every point is the study's base model, resolved once from the spec at the
study's edge (:func:`study_model`), varied by the point's values
(:meth:`fi_design.model.Model.varied`: the spec validated again and resolved
once), simulated with the fast kernel and judged (:func:`evaluate_point`) by
one of two measures: ``"stage"`` (the
default: whether any move of the family ends in a sustained cycle, and that
cycle's amplitude, :mod:`fi_design.stage`) or ``"move"`` (the paper's hunting
metric on the spec's own move). A point whose values the
spec refuses is ``invalid``, a simulation that does not complete (or raises)
``failed``: neither stops the study. :func:`evaluate` takes the finished
points from the cache and runs the rest in chunks on the caller's executor
(:func:`fi_design.execution.run_chunks`); the outcomes do not depend on where
they ran. A chunk sends the base model to its worker once (about the spec's
size pickled: the spec and a kilobyte of resolved numbers) with the values of
its points.
"""

from __future__ import annotations

import math
import os
import time as _time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from .. import spec as _spec
from ..display import quantity
from ..errors import ArgumentError, FiDesignError, SpecError
from ..execution import Executor, check_executor, chunks, run_chunks
from ..model import Model, require_model, resolve
from ..results import frozen_array
from ..results.studies import PointResult, RunInfo
from .cache import METHOD, PointCache, open_cache, point_key

__all__ = ["MEASURES", "MAX_CHUNK", "MAX_POINTS", "TARGET_CHUNKS", "Task", "ProgressCallback",
           "Evaluation",
           "study_model", "evaluate_point", "run_chunk", "warm_up", "chunk_size", "evaluate",
           "point_result",
           "grid", "verdict_grid"]

#: ``progress(done, total)`` in points.
ProgressCallback = Callable[[int, int], None]


_OUTCOME_FIELDS = ("status", "verdict", "hunting_cycles", "amplitude", "period", "settling_time",
                   "final_error", "message")

#: What a point measures: the stage over its move family, or the spec's own move.
MEASURES = ("stage", "move")
#: The stage over its move family, stopping at the first move that hunts: a yes or no
#: answer without the largest cycle (robustness samples, the recommendation's screen).
STAGE_FIRST = "stage_first"
_MEASURES = MEASURES + (STAGE_FIRST,)


def study_model(spec: _spec.Spec | Model, name: str = "spec") -> Model:
    """The base model of a study: a spec (or what :func:`fi_design.spec.file.load_spec`
    reads) resolved once, or a model resolved from its spec.

    The studies' edge: every point is this model varied (:meth:`Model.varied`),
    and the cache keys every point by this model's spec (:func:`.cache.point_key`),
    so the model must be its spec's own: one varied by :meth:`Model.at`
    (values that are not in its spec) is refused.

    Parameters
    ----------
    spec : Spec, Model, path or mapping
        The design.
    name : str, optional
        The argument's name, for the message.

    Returns
    -------
    Model

    Raises
    ------
    ArgumentError
        A model varied by :meth:`Model.at`, or neither a spec nor a model.
    """
    from ..spec.file import as_spec

    if not isinstance(spec, Model):
        return resolve(as_spec(spec, name, model=True))
    if spec.departures:
        raise ArgumentError(f"{name}: this model differs from its spec at "
                            f"{', '.join(spec.departures)} (Model.at), "
                            "so a study cannot vary it by spec paths nor cache its points: "
                            "give the spec (or the model resolved from it) and sweep these "
                            "values as axes")
    return spec


def evaluate_point(model: Model, values: Mapping[str, Any], isolated: bool,
                   measure: str = "move") -> dict:
    """Simulate one point and return its outcome as plain data (the cached form).

    Parameters
    ----------
    model : Model
        The base model (:func:`study_model`).
    values : mapping of str to value
        Dotted spec path to value: the point is ``model.varied(values)``
        (:meth:`fi_design.model.Model.varied`), the base model itself when empty.
    isolated : bool
        Simulate the isolated plant (True) or the stage without isolator.
    measure : {"move", "stage", "stage_first"}
        ``"move"``: the paper's hunting metric on the spec's move
        (``hunting_cycles`` counted in the window, ``amplitude`` its peak to
        peak). ``"stage"``: every move of the family is run; when some end in
        a sustained cycle the verdict is ``hunting`` and ``amplitude`` the
        largest of their cycles' peak to peak (``hunting_cycles`` None); when
        all come to rest, ``settled`` with amplitude 0; a move that sticks or
        cannot be judged makes the point ``stuck`` or ``undetermined``.
        Either way, an isolated point whose drawn guide the stage's weight
        buckles (net drive stiffness at or below 0, which step 3 fails) is
        not simulated: status ``invalid``, verdict ``buckled``.
        ``"stage_first"``: the same, but the moves, the largest first
        (:func:`~fi_design.stage.moves.spread`), stop at the first that
        hunts (``amplitude`` is that move's cycle).

    Returns
    -------
    dict
        Keys ``status``, ``verdict``, ``hunting_cycles``, ``amplitude``,
        ``period``, ``settling_time``, ``final_error``, ``message`` and
        ``cacheable`` (False for outcomes that depend on the machine).
    """
    from ..simulation.run import simulate

    model = require_model(model)
    if measure not in _MEASURES:
        raise ArgumentError(f"measure must be one of {MEASURES}, got {measure!r}")
    try:
        point = model.varied(values) if values else model
    except SpecError as exc:
        return _outcome("invalid", "invalid", message=str(exc))
    if isolated and point.joint is not None and point.joint.stiffness <= 0.0:
        return _buckled(point.joint.stiffness)
    if measure != "move":
        return _stage_point(point, isolated, first_only=measure == STAGE_FIRST)
    try:
        res = simulate(point, isolated, METHOD)
    except FiDesignError as exc:  # a request the simulation refuses: deterministic
        return _outcome("failed", "failed", message=str(exc))
    except Exception as exc:  # noqa: BLE001 -- one bad point must not stop a sweep
        out = _outcome("failed", "failed", message=f"{type(exc).__name__}: {exc}")
        out["cacheable"] = False
        return out
    m = res.metrics
    if not res.success:
        return _outcome("failed", "failed", message=res.message)
    return _outcome("ok", m.verdict, hunting_cycles=int(m.hunting_cycles),
                    amplitude=_num(m.amplitude), period=_num(m.period),
                    settling_time=_num(m.settling_time), final_error=_num(m.final_error),
                    message=m.reason)


def _stage_point(point: Model, isolated: bool, first_only: bool = False) -> dict:
    """The stage-level outcome of one point (see :func:`evaluate_point`)."""
    from ..stage import stage_hunts

    try:
        moves, _ = stage_hunts(point, isolated, first_only=first_only,
                               order="spread" if first_only else "size")
    except FiDesignError as exc:
        return _outcome("failed", "failed", message=str(exc))
    except Exception as exc:  # noqa: BLE001 -- one bad point must not stop a sweep
        out = _outcome("failed", "failed", message=f"{type(exc).__name__}: {exc}")
        out["cacheable"] = False
        return out
    final = _num(moves[0].final_error)
    broken = next((m for m in moves if m.failed), None)
    if broken is not None:
        return _outcome("failed", "failed", message=f"the {_distance(broken.distance)} move: "
                                                    f"{broken.reason}")
    hunting = [m for m in moves if m.hunts]
    if hunting:
        # the cell's value: the largest cycle any move of the family ends in
        hunt = max(hunting, key=lambda m: m.amplitude or 0.0)
        return _outcome("ok", "hunting", amplitude=_num(hunt.amplitude),
                        period=_num(hunt.period), final_error=final,
                        message=(f"the {_distance(hunt.distance)} move hunts (the moves stop "
                                 f"at the first that does): {hunt.reason}" if first_only else
                                 f"{len(hunting)} of {len(moves)} moves hunt; the largest cycle, "
                                 f"after the {_distance(hunt.distance)} move: {hunt.reason}"))
    for word, verdict in (("stuck", "stuck"), ("undetermined", "undetermined")):
        bad = next((m for m in moves if m.outcome == word), None)
        if bad is not None:
            return _outcome("ok", verdict, amplitude=0.0, final_error=final,
                            message=f"the {_distance(bad.distance)} move: {bad.reason}")
    return _outcome("ok", "settled", amplitude=0.0, final_error=final,
                    message=f"all {len(moves)} moves come to rest")


def _buckled(stiffness: float) -> dict:
    """The outcome of a point whose drawn guide the stage's weight buckles (not simulated).

    Its net drive stiffness, gravity included, is at or below zero: the design fails it
    in step 3, and a simulation would only show the stage leaning on its end stop (a
    cycle of the stroke's size that is no hunting of the isolated stage).
    """
    return _outcome("invalid", "buckled",
                    message=f"the weight has buckled the guide: net drive stiffness "
                            f"{quantity(stiffness, 'N/m', 4)} (at or below 0; step 3 fails "
                            "it); not simulated")


def _distance(x: float) -> str:
    """A move's distance [m] for a message, 4 digits (``0.5 mm``)."""
    return quantity(x, "m", 4)


def _num(x: Any) -> float | None:
    if x is None:
        return None
    x = float(x)
    return x if math.isfinite(x) else None


def _outcome(status: str, verdict: str, *, hunting_cycles: int | None = None,
             amplitude: float | None = None, period: float | None = None,
             settling_time: float | None = None, final_error: float | None = None,
             message: str = "") -> dict:
    return {"status": status, "verdict": verdict, "hunting_cycles": hunting_cycles,
            "amplitude": amplitude, "period": period, "settling_time": settling_time,
            "final_error": final_error, "message": message, "cacheable": True}


def run_chunk(model: Model, tasks: Sequence[tuple[tuple[tuple[str, Any], ...], bool]],
              measure: str = "move") -> list[dict]:
    """Evaluate a chunk of points (the unit of work sent to an executor).

    Parameters
    ----------
    model : Model
        The base model (:func:`study_model`).
    tasks : sequence of (values, isolated)
        ``values`` is a tuple of ``(path, value)`` pairs.
    measure : {"move", "stage"}
        See :func:`evaluate_point`.

    Returns
    -------
    list of dict
        One outcome per task (see :func:`evaluate_point`), in order.
    """
    return [evaluate_point(model, dict(values), isolated, measure)
            for values, isolated in tasks]


def warm_up() -> None:
    """Compile or load the simulation kernel, and import what a point needs, in this process.

    Call it once in the parent before starting worker processes (forked
    workers inherit the loaded kernel; with numba's JIT it writes its on-disk
    cache first),
    and pass it as the pool's ``initializer`` so that spawned workers load the
    kernel before their first chunk.

    Returns
    -------
    None
    """
    import scipy.signal  # noqa: F401  (the metric's peak finder, imported on first use)

    from ..simulation import run as simulation  # noqa: F401
    from ..kernel.build import compiled

    compiled()  # the extension built at install, or numba's JIT (compiles or loads its cache)


#: Largest number of points in one chunk (bounds the work lost by an interruption).
MAX_CHUNK = 64
#: Most points (grid cells, samples) of one study: a few ms to a few tens of ms each, so
#: 100 000 points are about an hour on two cores.
MAX_POINTS = 100_000
#: Chunks per study when the chunk size is chosen automatically.
TARGET_CHUNKS = 16

#: A point: its ``(path, value)`` pairs and the plant (True: isolated).
Task = tuple[tuple[tuple[str, float], ...], bool]


def chunk_size(n: int, chunksize: int | None = None) -> int:
    """Points per chunk: as given, else about 1/16 of the points, at most :data:`MAX_CHUNK`.

    Parameters
    ----------
    n : int
        Points to run.
    chunksize : int, optional
        A given size (at least 1).

    Returns
    -------
    int
    """
    if chunksize is not None:
        if chunksize < 1:
            raise ArgumentError(f"chunksize must be at least 1, got {chunksize}")
        return chunksize
    return min(MAX_CHUNK, max(1, math.ceil(n / TARGET_CHUNKS)))


@dataclass(frozen=True)
class Evaluation:
    """The outcomes of a study's points and how they were obtained.

    Attributes
    ----------
    outcomes : tuple of dict
        One per task, in task order (see :func:`evaluate_point`).
    run : RunInfo
        Points computed and cached, chunks, executor, wall time.
    """

    outcomes: tuple[dict, ...]
    run: RunInfo


def evaluate(model: Model, tasks: Sequence[Task], *, executor: Executor | None = None,
             progress: ProgressCallback | None = None,
             cache: PointCache | str | os.PathLike | bool | None = None,
             chunksize: int | None = None, measure: str = "move") -> Evaluation:
    """The outcomes of all points of a study: from the cache, or simulated in chunks.

    Parameters
    ----------
    model : Model
        The base model (:func:`study_model`): its spec's own, so that the
        cache keys of its points (its spec's hash and the point's values)
        decide them.
    tasks : sequence of (values, isolated)
        The points: ``(path, value)`` pairs and the plant.
    executor : Executor, optional
        Runs the chunks; None runs them here, one after another.
    progress : callable, optional
        ``progress(done, total)`` in points, after the cache lookup and after
        every chunk, in the calling thread.
    cache : PointCache, path, bool or None, optional
        Where finished points are looked up and stored (:func:`~.cache.open_cache`).
    chunksize : int, optional
        Points per chunk (:func:`chunk_size`).
    measure : {"move", "stage", "stage_first"}
        What a point measures (:func:`evaluate_point`).

    Returns
    -------
    Evaluation
    """
    model = study_model(require_model(model), "model")
    if measure not in _MEASURES:
        raise ArgumentError(f"measure must be one of {MEASURES}, got {measure!r}")
    check_executor(executor)
    start = _time.perf_counter()
    store = open_cache(cache)
    n = len(tasks)
    outcomes: list[dict | None] = [None] * n
    keys: list[str] = []
    if store is not None:
        shash = model.spec.content_sha256()
        keys = [point_key(shash, values, iso, measure) for values, iso in tasks]
        hits = store.get_many(keys)
        for i, k in enumerate(keys):
            if k in hits:
                outcomes[i] = hits[k]
    todo = [i for i in range(n) if outcomes[i] is None]
    cached = n - len(todo)
    done = cached
    if progress is not None:
        progress(done, n)
    groups = [[todo[j] for j in chunk]
              for chunk in chunks(len(todo), chunk_size(len(todo), chunksize))]

    def finish(g: int, results: list[dict]) -> None:
        nonlocal done
        fresh = {}
        for i, out in zip(groups[g], results):
            outcomes[i] = out
            if store is not None and out.get("cacheable", True):
                fresh[keys[i]] = {k: out[k] for k in _OUTCOME_FIELDS}
        if store is not None:
            store.put_many(fresh)
        done += len(groups[g])
        if progress is not None:
            progress(done, n)

    def lost(g: int, exc: Exception) -> list[dict]:
        msg = f"the worker running this point failed: {type(exc).__name__}: {exc}"
        return [dict(_outcome("failed", "failed", message=msg), cacheable=False)
                for _ in groups[g]]

    arguments = [(model, [tasks[i] for i in group], measure) for group in groups]
    if executor is None:
        for g, args in enumerate(arguments):
            finish(g, run_chunk(*args))
    elif groups:
        run_chunks(executor, run_chunk, arguments, finish, lost)
    run = RunInfo(points=n, computed=len(todo), cached=cached, chunks=len(groups),
                  executor="serial" if executor is None else type(executor).__name__,
                  wall_time=_time.perf_counter() - start)
    return Evaluation(outcomes=tuple(outcomes), run=run)  # type: ignore[arg-type]


def point_result(index: tuple[int, ...], values: tuple[float, ...], iso: bool, out: dict) \
        -> PointResult:
    """A :class:`PointResult` from a point's place, values, plant and outcome."""
    return PointResult(index=index, values=values, isolated=iso,
                       **{k: out.get(k) for k in _OUTCOME_FIELDS})


def grid(points: Sequence[PointResult], shape: tuple[int, ...], name: str) -> np.ndarray:
    """One outcome field of the points as a read-only array of ``shape`` (NaN without value)."""
    vals = [getattr(p, name) if p.status == "ok" else None for p in points]
    return frozen_array(np.array([np.nan if v is None else float(v) for v in vals])
                        .reshape(shape))


def verdict_grid(points: Sequence[PointResult], shape: tuple[int, ...]) -> np.ndarray:
    """The points' verdicts as a read-only string array of ``shape``."""
    arr = np.array([p.verdict for p in points], dtype="<U12").reshape(shape)
    arr.flags.writeable = False
    return arr
