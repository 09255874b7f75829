"""Parameter studies: hunting maps over spec values, the paper's four maps, robustness.

Engineers choose an isolator from maps: the hunting metric over two design
parameters with the design point marked (paper Figure 4). This module
evaluates such maps and the probability of hunting under friction scatter.

- :func:`sweep` varies one or two spec values (dotted paths, see
  :func:`fi_design.specfile.with_values`) over a grid and simulates every
  point; :class:`SweepResult` holds the metric per point.
- :func:`paper_study` evaluates the paper's four maps (A: static vs Coulomb
  friction, B: crossover vs mass, both without isolator; C: stroke vs drive
  stiffness, D: crossover vs stroke, both with it) around a spec's design
  point.
- :func:`robustness` draws spec values around the nominal ones (and,
  optionally, friction that varies along the rail) and estimates the
  probability of hunting with and without the isolator, with a Wilson
  confidence interval.

Execution. Points are independent; they are grouped in chunks (points of a
chunk interleaved over the grid, so chunks cost about the same) and the chunks
are submitted to an executor: any object with a ``concurrent.futures``-style
``submit(fn, *args)`` returning futures with ``result()`` and
``add_done_callback()`` -- a :class:`concurrent.futures.ProcessPoolExecutor`,
a ``dask.distributed.Client``, ... With ``executor=None`` the chunks run in
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

import hashlib
import json
import math
import os
import queue
import sqlite3
import time as _time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from . import spec as _spec
from .errors import FiDesignError, SpecError
from .results import frozen_array, to_jsonable
from .specfile import path_unit, value_at, with_values

#: Environment variable naming the cache directory (tests and CI point it at a temporary one).
CACHE_ENV = "FI_DESIGN_CACHE_DIR"
#: Solver method the studies use (part of the cache key).
METHOD = "fast"
#: Verdicts of the hunting metric plus the two outcomes of a point that has no metric.
POINT_VERDICTS = ("settled", "hunting", "stuck", "undetermined", "invalid", "failed")
#: Modules whose source decides a point's outcome; their digest is part of the cache key.
_CODE_MODULES = ("kernel", "plant", "simulation", "metrics", "pid", "trajectory", "effects",
                 "spec", "specfile", "studies")
#: Largest number of points in one chunk (bounds the work lost by an interruption).
MAX_CHUNK = 64
#: Chunks per sweep when the chunk size is chosen automatically.
TARGET_CHUNKS = 16

ProgressCallback = Callable[[int, int], None]


# --------------------------------------------------------------------------- axes


@dataclass(frozen=True, eq=False)
class Axis:
    """One swept spec value.

    Attributes
    ----------
    path : str
        Dotted spec path (``"controller.crossover"``).
    values : ndarray, shape (n,)
        The values, in the path's unit (SI; frequencies in Hz).
    unit : str
        Unit of ``values`` (``"Hz"``, ``"m"``, ``"N/m"``, ...; ``"1"`` for a
        plain number).
    log : bool
        Whether the values are spaced logarithmically (plots use a log axis).
    """

    path: str
    values: np.ndarray
    unit: str = ""
    log: bool = False

    def __post_init__(self) -> None:
        vals = np.asarray(self.values, dtype=float)
        if vals.ndim != 1 or len(vals) == 0:
            raise SpecError("an axis needs at least one value", path=self.path)
        if not np.all(np.isfinite(vals)):
            raise SpecError("axis values must be finite numbers", path=self.path)
        if self.log and np.any(vals <= 0):
            raise SpecError("a logarithmic axis needs values above zero", path=self.path)
        object.__setattr__(self, "values", frozen_array(vals))

    def to_dict(self) -> dict:
        """Plain JSON data."""
        return {"path": self.path, "values": to_jsonable(self.values), "unit": self.unit,
                "log": self.log}


def make_axis(path: str, values: Sequence[float], log: bool = False,
              spec: _spec.Spec | None = None) -> Axis:
    """An :class:`Axis` for a dotted path, with the unit looked up in the spec schema.

    Parameters
    ----------
    path : str
        Dotted spec path.
    values : sequence of float
        Values in the path's SI unit.
    log : bool, optional
        Logarithmic spacing (for plots). Default False.
    spec : Spec, optional
        Resolves list indices into ``effects``.

    Returns
    -------
    Axis

    Raises
    ------
    SpecError
        Unknown path, a path to a section or to a value without a number.
    """
    unit = path_unit(path, spec)
    if unit == "":
        raise SpecError("is not a numeric value; only numbers can be swept", path=path)
    return Axis(path=path, values=np.asarray(values, dtype=float), unit=unit, log=log)


def parse_axis(text: str, log: bool = False, spec: _spec.Spec | None = None) -> Axis:
    """Read an axis written as ``PATH=START:STOP:N`` (or ``PATH=V1,V2,...``).

    Parameters
    ----------
    text : str
        ``"controller.crossover=2 Hz:30 Hz:15"``, ``"isolator.stroke=0.05 mm:1 mm:12"``
        or ``"stage.mass=1,2,4"``. START and STOP are SI numbers or strings
        with units; N is the number of values, end points included.
    log : bool, optional
        Space the N values logarithmically (START and STOP above zero).
    spec : Spec, optional
        Resolves list indices into ``effects``.

    Returns
    -------
    Axis

    Raises
    ------
    SpecError
        Unknown path, malformed range, wrong unit, N below 1.
    """
    from .units import to_si

    if "=" not in text:
        raise SpecError(f"axis {text!r}: expected PATH=START:STOP:N, e.g. "
                        "'controller.crossover=2 Hz:30 Hz:15'")
    path, rng = (part.strip() for part in text.split("=", 1))
    if not path:
        raise SpecError(f"axis {text!r}: the path before '=' is empty")
    unit = path_unit(path, spec)
    if unit == "":
        raise SpecError("is not a numeric value; only numbers can be swept", path=path)

    def number(word: str, what: str) -> float:
        word = word.strip()
        if not word:
            raise SpecError(f"range {rng!r}: {what} is empty", path=path)
        try:
            return to_si(float(word) if _is_float(word) else word, unit, path=path)
        except SpecError as exc:
            raise SpecError(f"range {rng!r}: {what}: {exc.message}", path=path) from None

    if ":" not in rng and "," in rng:
        values = [number(w, f"value {i + 1}") for i, w in enumerate(rng.split(","))]
        return Axis(path=path, values=np.array(values), unit=unit, log=log)
    parts = rng.split(":")
    if len(parts) != 3:
        raise SpecError(f"range {rng!r}: expected START:STOP:N (three parts separated by ':'), "
                        f"e.g. '0.05 mm:1 mm:12'", path=path)
    start, stop = number(parts[0], "START"), number(parts[1], "STOP")
    try:
        n = int(parts[2].strip())
    except ValueError:
        raise SpecError(f"range {rng!r}: N must be a whole number, got {parts[2].strip()!r}",
                        path=path) from None
    if n < 1:
        raise SpecError(f"range {rng!r}: N must be at least 1, got {n}", path=path)
    if n > 1 and start == stop:
        raise SpecError(f"range {rng!r}: START equals STOP; give N = 1 or a wider range",
                        path=path)
    if log:
        if start <= 0 or stop <= 0:
            raise SpecError(f"range {rng!r}: a logarithmic axis needs START and STOP above "
                            "zero", path=path)
        values = np.geomspace(start, stop, n)
    else:
        values = np.linspace(start, stop, n)
    return Axis(path=path, values=values, unit=unit, log=log)


def _is_float(word: str) -> bool:
    try:
        float(word)
    except ValueError:
        return False
    return True


def _as_axis(value: Any, spec: _spec.Spec, name: str) -> Axis:
    if isinstance(value, Axis):
        return value
    if isinstance(value, str):
        return parse_axis(value, spec=spec)
    if isinstance(value, (tuple, list)) and len(value) == 2 and isinstance(value[0], str):
        return make_axis(value[0], value[1], spec=spec)
    raise TypeError(f"{name} must be an Axis, a (path, values) pair or 'PATH=START:STOP:N'")


# --------------------------------------------------------------------------- point results


@dataclass(frozen=True)
class PointResult:
    """The outcome of one point of a study.

    Attributes
    ----------
    index : tuple of int
        Position in the grid: ``(iy, ix)`` for a map, ``(ix,)`` for a line,
        ``(sample,)`` for a robustness draw.
    values : tuple of float
        The varied values, in the order of the study's paths [SI].
    isolated : bool
        Whether the isolated plant was simulated.
    status : str
        ``"ok"``, ``"invalid"`` (the spec refused the values) or ``"failed"``
        (the simulation did not complete or raised).
    verdict : str
        ``settled``, ``hunting``, ``stuck`` or ``undetermined`` (the metric's
        verdict), or ``invalid`` / ``failed``.
    hunting_cycles : int or None
        Peaks counted in the window (the paper's metric); None without a metric.
    amplitude : float or None
        Peak-to-peak error in the window [m].
    period : float or None
        Mean time between counted peaks [s].
    settling_time : float or None
        Time after the end of the motion until the error stays in the band [s].
    final_error : float or None
        x1 - r at the end [m].
    message : str
        Why: the metric's reason, the validation error or the failure.
    """

    index: tuple[int, ...]
    values: tuple[float, ...]
    isolated: bool
    status: str
    verdict: str
    hunting_cycles: int | None
    amplitude: float | None
    period: float | None
    settling_time: float | None
    final_error: float | None
    message: str

    @property
    def hunting(self) -> bool:
        """Whether the metric counted hunting cycles."""
        return self.verdict == "hunting"

    def to_dict(self) -> dict:
        """Plain JSON data (SI)."""
        return to_jsonable({f: getattr(self, f) for f in self.__dataclass_fields__})


_OUTCOME_FIELDS = ("status", "verdict", "hunting_cycles", "amplitude", "period", "settling_time",
                   "final_error", "message")


def evaluate_point(spec: _spec.Spec, values: Mapping[str, Any], isolated: bool) -> dict:
    """Simulate one point and return its outcome as plain data (the cached form).

    Parameters
    ----------
    spec : Spec
        The base spec.
    values : mapping of str to value
        Dotted path to value, applied with :func:`~fi_design.specfile.with_values`.
    isolated : bool
        Simulate the isolated plant (True) or the stage without isolator.

    Returns
    -------
    dict
        Keys ``status``, ``verdict``, ``hunting_cycles``, ``amplitude``,
        ``period``, ``settling_time``, ``final_error``, ``message`` and
        ``cacheable`` (False for outcomes that depend on the machine).
    """
    from .simulation import simulate

    try:
        point = with_values(spec, values) if values else spec
    except SpecError as exc:
        return _outcome("invalid", "invalid", message=str(exc))
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


def run_chunk(spec: _spec.Spec, tasks: Sequence[tuple[tuple[tuple[str, Any], ...], bool]]) \
        -> list[dict]:
    """Evaluate a chunk of points (the unit of work sent to an executor).

    Parameters
    ----------
    spec : Spec
        The base spec.
    tasks : sequence of (values, isolated)
        ``values`` is a tuple of ``(path, value)`` pairs.

    Returns
    -------
    list of dict
        One outcome per task (see :func:`evaluate_point`), in order.
    """
    return [evaluate_point(spec, dict(values), isolated) for values, isolated in tasks]


def warm_up() -> None:
    """Compile or load the simulation kernel, and import what a point needs, in this process.

    Call it once in the parent before starting worker processes (numba then
    writes its on-disk cache, and forked workers inherit the compiled code),
    and pass it as the pool's ``initializer`` so that spawned workers load the
    kernel before their first chunk.

    Returns
    -------
    None
    """
    import scipy.signal  # noqa: F401  (the metric's peak finder, imported on first use)

    from . import kernel, simulation  # noqa: F401  (the kernel compiles at import or loads
    #                                  numba's on-disk cache)


# --------------------------------------------------------------------------- cache


def default_cache_dir() -> Path:
    """The cache directory: ``$FI_DESIGN_CACHE_DIR``, else the user cache directory.

    Returns
    -------
    pathlib.Path
        ``platformdirs.user_cache_dir("fi_design") / "studies"`` unless the
        environment variable names another directory.
    """
    env = os.environ.get(CACHE_ENV, "").strip()
    if env:
        return Path(env).expanduser()
    from platformdirs import user_cache_dir

    return Path(user_cache_dir("fi_design")) / "studies"


class PointCache:
    """Content-addressed store of point outcomes: one SQLite file in a directory.

    Keys are SHA-256 digests of everything that decides a point's outcome (see
    :func:`point_key`); values are the outcomes as JSON. Outcomes are written
    per finished chunk, in one transaction, so an interrupted sweep keeps all
    chunks that finished. Only the calling process reads and writes the file;
    SQLite's locking keeps two concurrent sweeps on one cache consistent.

    Parameters
    ----------
    directory : str or os.PathLike, optional
        Where the cache lives; default :func:`default_cache_dir`. Created on
        first write.
    """

    FILE = "points.sqlite"

    def __init__(self, directory: str | os.PathLike | None = None) -> None:
        self.directory = Path(directory) if directory is not None else default_cache_dir()
        self._conn: sqlite3.Connection | None = None

    @property
    def path(self) -> Path:
        """The SQLite file."""
        return self.directory / self.FILE

    def _connect(self, create: bool) -> sqlite3.Connection | None:
        if self._conn is not None:
            return self._conn
        if not create and not self.path.exists():
            return None
        try:
            self.directory.mkdir(parents=True, exist_ok=True)
            conn = sqlite3.connect(self.path, timeout=30.0, check_same_thread=False)
            conn.execute("CREATE TABLE IF NOT EXISTS points (key TEXT PRIMARY KEY, "
                         "outcome TEXT NOT NULL, created REAL NOT NULL)")
            conn.commit()
        except (OSError, sqlite3.Error) as exc:
            raise CacheError(f"cannot open the result cache {self.path}: {exc}; use --no-cache "
                             f"or set {CACHE_ENV} to a writable directory") from None
        self._conn = conn
        return conn

    def get_many(self, keys: Sequence[str]) -> dict[str, dict]:
        """Outcomes stored under ``keys`` (missing keys are left out).

        Parameters
        ----------
        keys : sequence of str
            Point keys.

        Returns
        -------
        dict
            Key to outcome.
        """
        conn = self._connect(create=False)
        if conn is None or not keys:
            return {}
        out: dict[str, dict] = {}
        keys = list(keys)
        try:
            for i in range(0, len(keys), 500):
                part = keys[i:i + 500]
                rows = conn.execute(f"SELECT key, outcome FROM points WHERE key IN "
                                    f"({','.join('?' * len(part))})", part).fetchall()
                out.update((k, json.loads(v)) for k, v in rows)
        except (sqlite3.Error, ValueError) as exc:
            raise CacheError(f"cannot read the result cache {self.path}: {exc}; use --no-cache "
                             "or delete the file") from None
        return out

    def put_many(self, items: Mapping[str, dict]) -> None:
        """Store outcomes (one transaction).

        Parameters
        ----------
        items : mapping of str to dict
            Key to outcome (JSON-able).
        """
        if not items:
            return
        conn = self._connect(create=True)
        now = _time.time()
        try:
            with conn:
                conn.executemany("INSERT OR REPLACE INTO points (key, outcome, created) "
                                 "VALUES (?, ?, ?)",
                                 [(k, json.dumps(v), now) for k, v in items.items()])
        except sqlite3.Error as exc:
            raise CacheError(f"cannot write the result cache {self.path}: {exc}; use "
                             "--no-cache") from None

    def __len__(self) -> int:
        conn = self._connect(create=False)
        if conn is None:
            return 0
        return int(conn.execute("SELECT COUNT(*) FROM points").fetchone()[0])

    def clear(self) -> None:
        """Delete every stored outcome."""
        conn = self._connect(create=False)
        if conn is not None:
            with conn:
                conn.execute("DELETE FROM points")

    def close(self) -> None:
        """Close the database connection (it reopens on the next use)."""
        if self._conn is not None:
            self._conn.close()
            self._conn = None

    def __getstate__(self) -> dict:  # picklable: the connection stays behind
        return {"directory": self.directory, "_conn": None}

    def __repr__(self) -> str:
        return f"PointCache({str(self.directory)!r})"


class CacheError(FiDesignError, OSError):
    """The result cache cannot be opened, read or written."""


_CODE_DIGEST: str | None = None


def code_digest() -> str:
    """SHA-256 over the source of the modules that decide a point's outcome.

    Part of every cache key, so editing the model, the solver or the metric
    never reuses outcomes computed by older code (even without a version bump).

    Returns
    -------
    str
        Hex digest.
    """
    global _CODE_DIGEST
    if _CODE_DIGEST is None:
        here = Path(__file__).resolve().parent
        h = hashlib.sha256()
        for name in _CODE_MODULES:
            h.update((here / f"{name}.py").read_bytes())
        _CODE_DIGEST = h.hexdigest()
    return _CODE_DIGEST


def spec_digest(spec: _spec.Spec) -> str:
    """SHA-256 of a spec's validated content (every value, defaults included).

    Parameters
    ----------
    spec : Spec
        The spec.

    Returns
    -------
    str
        Hex digest; equal for specs that simulate identically however they
        were written (units, key order, comments).
    """
    data = spec.model_dump(mode="json")
    return hashlib.sha256(json.dumps(data, sort_keys=True, default=str).encode()).hexdigest()


def point_key(spec_hash: str, values: Sequence[tuple[str, Any]], isolated: bool) -> str:
    """The cache key of one point.

    Parameters
    ----------
    spec_hash : str
        :func:`spec_digest` of the base spec.
    values : sequence of (path, value)
        The point's values.
    isolated : bool
        The plant simulated.

    Returns
    -------
    str
        SHA-256 hex digest over the spec, the values (exact float repr), the
        plant, the fi_design version, :func:`code_digest` and the solver method.
    """
    from . import __version__

    payload = json.dumps({"spec": spec_hash, "values": [[p, v] for p, v in values],
                          "isolated": bool(isolated), "version": __version__,
                          "code": code_digest(), "method": METHOD},
                         sort_keys=True, default=str)
    return hashlib.sha256(payload.encode()).hexdigest()


def _open_cache(cache: Any) -> PointCache | None:
    if cache is None or cache is False:
        return None
    if isinstance(cache, PointCache):
        return cache
    if cache is True:
        return PointCache()
    if isinstance(cache, (str, os.PathLike)):
        return PointCache(cache)
    raise TypeError("cache must be None, True, a PointCache or a directory path")


# --------------------------------------------------------------------------- engine


@dataclass(frozen=True)
class RunInfo:
    """How a study was run (not part of its physics).

    Attributes
    ----------
    points : int
        Points in the study.
    computed : int
        Points simulated in this run.
    cached : int
        Points taken from the cache.
    chunks : int
        Chunks submitted to the executor (or run in-process).
    executor : str
        Type name of the executor, ``"serial"`` without one.
    wall_time : float
        Time of the whole call [s].
    """

    points: int
    computed: int
    cached: int
    chunks: int
    executor: str
    wall_time: float

    def to_dict(self) -> dict:
        """Plain JSON data."""
        return to_jsonable({f: getattr(self, f) for f in self.__dataclass_fields__})


def _chunks(n: int, chunksize: int | None) -> list[list[int]]:
    """Interleaved chunks of task positions 0..n-1 (chunk k: k, k + K, k + 2K, ...)."""
    if n == 0:
        return []
    size = chunksize if chunksize else min(MAX_CHUNK, max(1, math.ceil(n / TARGET_CHUNKS)))
    count = math.ceil(n / size)
    return [list(range(k, n, count)) for k in range(count)]


def _evaluate(spec: _spec.Spec, tasks: list[tuple[tuple[tuple[str, Any], ...], bool]], *,
              executor: Any, progress: ProgressCallback | None, cache: Any,
              chunksize: int | None) -> tuple[list[dict], RunInfo]:
    """Outcomes of all tasks, from the cache or computed; in task order."""
    start = _time.perf_counter()
    if chunksize is not None and chunksize < 1:
        raise ValueError("chunksize must be at least 1")
    store = _open_cache(cache)
    n = len(tasks)
    outcomes: list[dict | None] = [None] * n
    keys: list[str] = []
    if store is not None:
        shash = spec_digest(spec)
        keys = [point_key(shash, values, iso) for values, iso in tasks]
        hits = store.get_many(keys)
        for i, k in enumerate(keys):
            if k in hits:
                outcomes[i] = hits[k]
    todo = [i for i in range(n) if outcomes[i] is None]
    cached = n - len(todo)
    done = cached
    if progress is not None:
        progress(done, n)
    groups = [[todo[j] for j in chunk] for chunk in _chunks(len(todo), chunksize)]

    def finish(group: list[int], results: list[dict]) -> None:
        nonlocal done
        fresh = {}
        for i, out in zip(group, results):
            outcomes[i] = out
            if store is not None and out.get("cacheable", True):
                fresh[keys[i]] = {k: out[k] for k in _OUTCOME_FIELDS}
        if store is not None:
            store.put_many(fresh)
        done += len(group)
        if progress is not None:
            progress(done, n)

    if executor is None:
        for group in groups:
            finish(group, run_chunk(spec, [tasks[i] for i in group]))
    elif groups:
        _run_on(executor, spec, tasks, groups, finish)
    info = RunInfo(points=n, computed=len(todo), cached=cached, chunks=len(groups),
                   executor="serial" if executor is None else type(executor).__name__,
                   wall_time=_time.perf_counter() - start)
    return [o for o in outcomes], info  # type: ignore[misc]


def _run_on(executor: Any, spec: _spec.Spec, tasks: list, groups: list[list[int]],
            finish: Callable[[list[int], list[dict]], None]) -> None:
    """Submit every chunk, then handle them in the calling thread as they complete."""
    ready: queue.SimpleQueue = queue.SimpleQueue()
    futures: list[Any] = []
    try:
        for g, group in enumerate(groups):
            fut = executor.submit(run_chunk, spec, [tasks[i] for i in group])
            fut.add_done_callback(lambda _f, g=g: ready.put(g))
            futures.append(fut)
        for _ in range(len(futures)):
            while True:
                try:
                    g = ready.get(timeout=0.2)
                    break
                except queue.Empty:
                    continue
            try:
                results = futures[g].result()
            except Exception as exc:  # noqa: BLE001 -- a dead worker fails its chunk only
                msg = f"the worker running this point failed: {type(exc).__name__}: {exc}"
                results = [dict(_outcome("failed", "failed", message=msg), cacheable=False)
                           for _ in groups[g]]
            finish(groups[g], results)
    except BaseException:
        for fut in futures:
            fut.cancel()
        raise


# --------------------------------------------------------------------------- sweep


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
            raise ValueError("free must be 'above' or 'below'")
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
        return _table(self.paths, self.points, prefix="")

    def to_csv(self) -> str:
        """The :meth:`table` as CSV text (one row per point; empty cells for no value).

        Returns
        -------
        str
        """
        return _csv(self.table())

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


def _table(paths: Sequence[str], points: Sequence[PointResult], prefix: str) -> dict[str, list]:
    cols: dict[str, list] = {p: [pt.values[i] for pt in points] for i, p in enumerate(paths)}
    for name in ("hunting_cycles", "amplitude", "period", "verdict", "status", "message"):
        cols[prefix + name] = [getattr(pt, name) for pt in points]
    return cols


def _csv(columns: Mapping[str, list]) -> str:
    import csv
    import io

    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    names = list(columns)
    w.writerow(names)
    n = len(next(iter(columns.values()))) if columns else 0
    for i in range(n):
        w.writerow([_cell(columns[c][i]) for c in names])
    return buf.getvalue()


def _cell(v: Any) -> str:
    if v is None:
        return ""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return repr(v) if math.isfinite(v) else ""
    return str(v)


_DERIVED = {
    "isolator.stiffness": lambda s: _spec.drive_stiffness(s),
    "isolator.damping": lambda s: _spec.joint_damping(s),
    "friction.bristle_damping": lambda s: _spec.bristle_damping(s),
    "isolator.limiter.damping": lambda s: _spec.limiter_damping(s),
}


def design_value(spec: _spec.Spec, path: str) -> float | None:
    """The spec's own value at a path, derived defaults resolved [SI].

    Parameters
    ----------
    spec : Spec
        The spec.
    path : str
        Dotted path.

    Returns
    -------
    float or None
        The value; derived defaults (``isolator.stiffness`` left to step 3,
        default dampings) are computed; None if the spec has no such value.
    """
    try:
        value = value_at(spec, path)
    except SpecError:
        return None
    if value is None and path in _DERIVED:
        try:
            value = _DERIVED[path](spec)
        except ValueError:
            return None
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return None
    return float(value)


def sweep(spec: _spec.Spec, x: Any, y: Any = None, *, isolated: bool | None = None,
          executor: Any = None, progress: ProgressCallback | None = None, cache: Any = None,
          chunksize: int | None = None) -> SweepResult:
    """Map the hunting metric over one or two spec values.

    Parameters
    ----------
    spec : Spec
        The design spec (the design point).
    x : Axis, (path, values) or str
        First swept value: an :class:`Axis`, a ``(dotted path, values in SI)``
        pair, or text ``"PATH=START:STOP:N"`` (see :func:`parse_axis`).
    y : Axis, (path, values) or str, optional
        Second swept value; None for a one-dimensional sweep.
    isolated : bool, optional
        Simulate the isolated plant (True) or the stage without isolator
        (False); None follows the spec (isolated when it has an isolator).
    executor : concurrent.futures-style executor, optional
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
    """
    from . import __version__

    ax = _as_axis(x, spec, "x")
    ay = _as_axis(y, spec, "y") if y is not None else None
    if ay is not None and ay.path == ax.path:
        raise SpecError("x and y sweep the same value", path=ax.path)
    iso = spec.has_isolator if isolated is None else bool(isolated)
    if iso and not spec.has_isolator:
        raise SpecError("the spec has no isolator: sweep without it (isolated=False / "
                        "--no-isolator) or add an isolator section", path="isolator")
    grid: list[tuple[tuple[int, ...], tuple[float, ...]]] = []
    if ay is None:
        grid = [((i,), (float(v),)) for i, v in enumerate(ax.values)]
        shape: tuple[int, ...] = (len(ax.values),)
    else:
        grid = [((j, i), (float(vx), float(vy))) for j, vy in enumerate(ay.values)
                for i, vx in enumerate(ax.values)]
        shape = (len(ay.values), len(ax.values))
    paths = (ax.path,) if ay is None else (ax.path, ay.path)
    tasks = [(tuple(zip(paths, vals)), iso) for _, vals in grid]
    outcomes, info = _evaluate(spec, tasks, executor=executor, progress=progress, cache=cache,
                               chunksize=chunksize)
    points = tuple(_point(idx, vals, iso, out) for (idx, vals), out in zip(grid, outcomes))
    design = tuple(design_value(spec, p) for p in paths)
    return SweepResult(
        spec=spec, x=ax, y=ay, isolated=iso, points=points,
        hunting_cycles=_grid(points, shape, "hunting_cycles"),
        amplitude=_grid(points, shape, "amplitude"), period=_grid(points, shape, "period"),
        verdict=_verdicts(points, shape), design_point=design, run=info,
        fi_design_version=__version__)


def _point(index: tuple[int, ...], values: tuple[float, ...], iso: bool, out: dict) \
        -> PointResult:
    return PointResult(index=index, values=values, isolated=iso,
                       **{k: out.get(k) for k in _OUTCOME_FIELDS})


def _grid(points: Sequence[PointResult], shape: tuple[int, ...], name: str) -> np.ndarray:
    vals = [getattr(p, name) if p.status == "ok" else None for p in points]
    return frozen_array(np.array([np.nan if v is None else float(v) for v in vals])
                        .reshape(shape))


def _verdicts(points: Sequence[PointResult], shape: tuple[int, ...]) -> np.ndarray:
    arr = np.array([p.verdict for p in points], dtype="<U12").reshape(shape)
    arr.flags.writeable = False
    return arr


# --------------------------------------------------------------------------- the paper's maps


@dataclass(frozen=True)
class MapDefinition:
    """One of the paper's maps (Figure 4), as factors on the spec's design values.

    Attributes
    ----------
    key : str
        ``"A"`` to ``"D"`` (the panel of Figure 4).
    title : str
        What the map shows.
    x_path, y_path : str
        Swept dotted paths.
    x_range, y_range : tuple of float
        (low, high) as factors on the design value.
    x_log, y_log : bool
        Logarithmic spacing.
    isolated : bool
        Plant simulated.
    paper : str
        The paper's finding for this map, in one sentence.
    """

    key: str
    title: str
    x_path: str
    x_range: tuple[float, float]
    x_log: bool
    y_path: str
    y_range: tuple[float, float]
    y_log: bool
    isolated: bool
    paper: str


#: The paper's four maps (Figure 4), ranges as factors on the design point.
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


@dataclass(frozen=True, eq=False)
class StudyMap:
    """One map of a study with its definition.

    Attributes
    ----------
    definition : MapDefinition
        Which map and how its ranges were chosen.
    result : SweepResult
        The map.
    """

    definition: MapDefinition
    result: SweepResult

    def to_dict(self) -> dict:
        """Plain JSON data."""
        d = to_jsonable({f: getattr(self.definition, f)
                         for f in self.definition.__dataclass_fields__})
        return {"definition": d, "result": self.result.to_dict()}


@dataclass(frozen=True, eq=False)
class StudyResult:
    """The paper's four maps around a design point.

    Attributes
    ----------
    spec : Spec
        The spec whose design point the maps surround.
    maps : tuple of StudyMap
        Maps A to D, in order.
    resolution : int
        Points per axis.
    run : RunInfo
        How the whole study ran (all maps together).
    """

    spec: _spec.Spec
    maps: tuple[StudyMap, ...]
    resolution: int
    run: RunInfo = field(repr=False)

    def map(self, key: str) -> SweepResult:
        """The map ``key`` (``"A"`` to ``"D"``).

        Parameters
        ----------
        key : str
            Panel letter.

        Returns
        -------
        SweepResult
        """
        for m in self.maps:
            if m.definition.key == key.upper():
                return m.result
        raise KeyError(key)

    def to_dict(self) -> dict:
        """Plain JSON data."""
        return {"spec_name": self.spec.name, "resolution": self.resolution,
                "maps": [m.to_dict() for m in self.maps], "run": self.run.to_dict()}


def paper_axes(spec: _spec.Spec, definition: MapDefinition, resolution: int) -> tuple[Axis, Axis]:
    """The axes of one of the paper's maps around a spec's design point.

    Parameters
    ----------
    spec : Spec
        The design spec.
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
    axes = []
    for path, (lo, hi), log in ((definition.x_path, definition.x_range, definition.x_log),
                                (definition.y_path, definition.y_range, definition.y_log)):
        ref = design_value(spec, path)
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


def paper_study(spec: _spec.Spec, resolution: int = 12, *, maps: str = "ABCD",
                executor: Any = None, progress: ProgressCallback | None = None,
                cache: Any = None, chunksize: int | None = None) -> StudyResult:
    """The paper's four maps (Figure 4) around a spec's design point.

    A: ``friction.static`` x ``friction.coulomb`` without isolator; B:
    ``controller.crossover`` x ``stage.mass`` without isolator; C:
    ``isolator.stroke`` x ``isolator.stiffness`` with it; D:
    ``controller.crossover`` x ``isolator.stroke`` with it. Ranges are
    factors on the design values (:data:`PAPER_MAPS`). All points of all maps
    go to the executor together.

    Parameters
    ----------
    spec : Spec
        The design spec; maps C and D need an isolator.
    resolution : int, optional
        Points per axis (default 12: 576 simulations).
    maps : str, optional
        Which maps, e.g. ``"AB"``. Default all four.
    executor : concurrent.futures-style executor, optional
        As for :func:`sweep`.
    progress : callable, optional
        ``progress(done, total)`` over all maps.
    cache : PointCache, path, True or None, optional
        As for :func:`sweep`.
    chunksize : int, optional
        As for :func:`sweep`.

    Returns
    -------
    StudyResult

    Raises
    ------
    SpecError
        Resolution below 2, an unknown map letter, or maps C/D for a spec
        without isolator.
    """
    from . import __version__

    if resolution < 2:
        raise SpecError(f"the resolution must be at least 2 points per axis, got {resolution}")
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
        ax, ay = paper_axes(spec, d, resolution)
        grid = [((j, i), (float(vx), float(vy))) for j, vy in enumerate(ay.values)
                for i, vx in enumerate(ax.values)]
        layouts.append((d, ax, ay, grid, len(tasks)))
        tasks += [(((ax.path, vals[0]), (ay.path, vals[1])), d.isolated) for _, vals in grid]
    outcomes, info = _evaluate(spec, tasks, executor=executor, progress=progress, cache=cache,
                               chunksize=chunksize)
    info = RunInfo(points=info.points, computed=info.computed, cached=info.cached,
                   chunks=info.chunks, executor=info.executor,
                   wall_time=_time.perf_counter() - start)
    out_maps = []
    for d, ax, ay, grid, offset in layouts:
        shape = (len(ay.values), len(ax.values))
        points = tuple(_point(idx, vals, d.isolated, outcomes[offset + n])
                       for n, (idx, vals) in enumerate(grid))
        res = SweepResult(
            spec=spec, x=ax, y=ay, isolated=d.isolated, points=points,
            hunting_cycles=_grid(points, shape, "hunting_cycles"),
            amplitude=_grid(points, shape, "amplitude"), period=_grid(points, shape, "period"),
            verdict=_verdicts(points, shape),
            design_point=(design_value(spec, ax.path), design_value(spec, ay.path)),
            run=info, fi_design_version=__version__)
        out_maps.append(StudyMap(d, res))
    return StudyResult(spec=spec, maps=tuple(out_maps), resolution=resolution, run=info)


# --------------------------------------------------------------------------- robustness


DISTRIBUTIONS = ("normal", "uniform")


@dataclass(frozen=True)
class Scatter:
    """How one spec value scatters around its nominal value.

    Attributes
    ----------
    path : str
        Dotted spec path.
    spread : float
        Standard deviation (normal) or half-width (uniform): a fraction of the
        nominal value when ``relative``, else in the path's unit [SI].
    relative : bool
        Whether ``spread`` is a fraction of the nominal value.
    """

    path: str
    spread: float
    relative: bool = True

    def to_dict(self) -> dict:
        """Plain JSON data."""
        return {"path": self.path, "spread": self.spread, "relative": self.relative}


def parse_scatter(text: str, spec: _spec.Spec | None = None) -> Scatter:
    """Read a scatter written as ``PATH=SPREAD``.

    Parameters
    ----------
    text : str
        ``"friction.static=10%"`` (relative), ``"friction.static=0.1"``
        (a bare number below 1 is relative too: 10 %) or
        ``"friction.static=0.3 N"`` (absolute, with units).
    spec : Spec, optional
        Resolves list indices into ``effects``.

    Returns
    -------
    Scatter

    Raises
    ------
    SpecError
        Unknown path, non-numeric value, malformed or negative spread.
    """
    from .units import to_si

    if "=" not in text:
        raise SpecError(f"scatter {text!r}: expected PATH=SPREAD, e.g. 'friction.static=10%'")
    path, word = (part.strip() for part in text.split("=", 1))
    unit = path_unit(path, spec)
    if unit == "":
        raise SpecError("is not a numeric value; only numbers can scatter", path=path)
    if word.endswith("%"):
        try:
            spread = float(word[:-1]) / 100.0
        except ValueError:
            raise SpecError(f"scatter {word!r}: expected a percentage such as '10%'",
                            path=path) from None
        relative = True
    elif _is_float(word):
        spread, relative = float(word), True
        if spread >= 1:
            raise SpecError(f"scatter {word!r}: a bare number is a fraction of the nominal value "
                            "(0.1 = 10 %); write '10%' or give units for an absolute spread",
                            path=path)
    else:
        try:
            spread, relative = to_si(word, unit, path=path), False
        except SpecError as exc:
            raise SpecError(f"scatter {word!r}: {exc.message}", path=path) from None
    if not math.isfinite(spread) or spread < 0:
        raise SpecError(f"scatter {word!r}: the spread must be zero or positive", path=path)
    return Scatter(path=path, spread=spread, relative=relative)


@dataclass(frozen=True)
class PositionFriction:
    """Friction that varies along the rail: the ``position_dependent_friction`` effect.

    Fs and Fc are scaled by 1 + a sin(2 pi x2 / wavelength + phase); every
    sample draws the phase uniformly in [-pi, pi) (where on the rail the stage
    happens to work).

    Attributes
    ----------
    amplitude : float
        Relative amplitude a [-].
    wavelength : float
        Spatial period [m].
    """

    amplitude: float
    wavelength: float

    def to_dict(self) -> dict:
        """Plain JSON data."""
        return {"amplitude": self.amplitude, "wavelength": self.wavelength}


def parse_position_friction(text: str) -> PositionFriction:
    """Read ``AMPLITUDE:WAVELENGTH``, e.g. ``"10%:20 mm"`` or ``"0.1:0.02"``.

    Parameters
    ----------
    text : str
        Relative amplitude (percent or fraction) and wavelength (SI or with
        units).

    Returns
    -------
    PositionFriction

    Raises
    ------
    SpecError
        Malformed text or values out of range.
    """
    from .units import to_si

    path = "effects[type=position_dependent_friction]"
    parts = text.split(":")
    if len(parts) != 2:
        raise SpecError(f"{text!r}: expected AMPLITUDE:WAVELENGTH, e.g. '10%:20 mm'", path=path)
    a, w = parts[0].strip(), parts[1].strip()
    try:
        amp = float(a[:-1]) / 100.0 if a.endswith("%") else float(a)
    except ValueError:
        raise SpecError(f"{text!r}: amplitude {a!r} is not a fraction or percentage",
                        path=path) from None
    wl = to_si(float(w) if _is_float(w) else w, "m", path=path)
    if not 0 <= amp < 1:
        raise SpecError(f"{text!r}: the amplitude must lie in [0, 1)", path=path)
    if wl <= 0:
        raise SpecError(f"{text!r}: the wavelength must be above zero", path=path)
    return PositionFriction(amplitude=amp, wavelength=wl)


def wilson_interval(successes: int, trials: int, confidence: float = 0.95) \
        -> tuple[float, float]:
    """Wilson score interval of a binomial proportion.

    Parameters
    ----------
    successes : int
        Count of the event.
    trials : int
        Number of trials.
    confidence : float, optional
        Two-sided confidence level, default 0.95.

    Returns
    -------
    low, high : float
        Bounds of the interval (0 and 1 when there are no trials).
    """
    if trials <= 0:
        return 0.0, 1.0
    from statistics import NormalDist

    z = NormalDist().inv_cdf(0.5 + confidence / 2.0)
    p = successes / trials
    denom = 1.0 + z * z / trials
    centre = (p + z * z / (2 * trials)) / denom
    half = z / denom * math.sqrt(p * (1 - p) / trials + z * z / (4 * trials * trials))
    low = 0.0 if successes <= 0 else max(0.0, centre - half)
    high = 1.0 if successes >= trials else min(1.0, centre + half)
    return low, high


@dataclass(frozen=True, eq=False)
class HuntingProbability:
    """Probability of hunting over the drawn samples, for one plant.

    Attributes
    ----------
    isolated : bool
        Whether the isolated plant was simulated.
    samples : int
        Samples drawn.
    valid : int
        Samples that were valid specs and simulated to the end (the trials).
    hunting : int
        Valid samples with the verdict ``hunting``.
    probability : float or None
        hunting / valid [-]; None without valid samples.
    low, high : float
        Wilson confidence interval of the probability [-].
    confidence : float
        Confidence level of the interval [-].
    counts : dict
        Samples per verdict (``settled``, ``hunting``, ``stuck``,
        ``undetermined``, ``invalid``, ``failed``).
    hunting_cycles : ndarray, shape (samples,)
        Cycles per sample; NaN for invalid or failed samples.
    verdict : ndarray of str, shape (samples,)
        Verdict per sample.
    """

    isolated: bool
    samples: int
    valid: int
    hunting: int
    probability: float | None
    low: float
    high: float
    confidence: float
    counts: dict
    hunting_cycles: np.ndarray
    verdict: np.ndarray

    def to_dict(self) -> dict:
        """Plain JSON data."""
        return to_jsonable({f: getattr(self, f) for f in self.__dataclass_fields__})


@dataclass(frozen=True, eq=False)
class RobustnessResult:
    """Probability of hunting under scatter, with and without the isolator.

    Attributes
    ----------
    spec : Spec
        The nominal spec.
    scatter : tuple of Scatter
        The scattered values.
    position_friction : PositionFriction or None
        Friction varying along the rail, if modelled.
    distribution : str
        ``"normal"`` or ``"uniform"``.
    seed : int
        Seed of the random generator (``numpy.random.default_rng``).
    draws : ndarray, shape (samples, len(scatter))
        Drawn values per sample, in the order of ``scatter`` [SI].
    phases : ndarray, shape (samples,) or (0,)
        Drawn phases of the position-dependent friction [rad].
    isolated : HuntingProbability or None
        With the isolator (None when the spec has none).
    not_isolated : HuntingProbability
        The same samples without the isolator.
    points : tuple of PointResult
        Every simulated sample, isolated ones first.
    run : RunInfo
        How the study ran.
    fi_design_version : str
        Version of fi_design that produced the result.
    """

    spec: _spec.Spec
    scatter: tuple[Scatter, ...]
    position_friction: PositionFriction | None
    distribution: str
    seed: int
    draws: np.ndarray
    phases: np.ndarray
    isolated: HuntingProbability | None
    not_isolated: HuntingProbability
    points: tuple[PointResult, ...] = field(repr=False)
    run: RunInfo = field(repr=False)
    fi_design_version: str = ""

    @property
    def samples(self) -> int:
        """Number of samples drawn."""
        return int(self.draws.shape[0])

    def table(self) -> dict[str, list]:
        """One row per sample: the drawn values [SI], then the outcome per plant.

        Returns
        -------
        dict of str to list
            Columns ``sample``, each scattered path, ``phase`` (with
            position-dependent friction), then ``isolated_hunting_cycles``,
            ``isolated_verdict`` (with an isolator) and
            ``not_isolated_hunting_cycles``, ``not_isolated_verdict``.
        """
        cols: dict[str, list] = {"sample": list(range(self.samples))}
        for k, sc in enumerate(self.scatter):
            cols[sc.path] = [float(v) for v in self.draws[:, k]]
        if self.position_friction is not None:
            cols["phase"] = [float(v) for v in self.phases]
        for name, prob in (("isolated", self.isolated), ("not_isolated", self.not_isolated)):
            if prob is None:
                continue
            cols[f"{name}_hunting_cycles"] = [None if math.isnan(c) else int(c)
                                              for c in prob.hunting_cycles]
            cols[f"{name}_verdict"] = prob.verdict.tolist()
        return cols

    def to_csv(self) -> str:
        """The :meth:`table` as CSV text.

        Returns
        -------
        str
        """
        return _csv(self.table())

    def to_dict(self) -> dict:
        """Plain JSON data."""
        return {
            "fi_design_version": self.fi_design_version,
            "spec_name": self.spec.name,
            "spec_sha256": spec_digest(self.spec),
            "samples": self.samples,
            "seed": self.seed,
            "distribution": self.distribution,
            "scatter": [s.to_dict() for s in self.scatter],
            "position_friction": self.position_friction.to_dict()
            if self.position_friction else None,
            "isolated": self.isolated.to_dict() if self.isolated else None,
            "not_isolated": self.not_isolated.to_dict(),
            "draws": to_jsonable(self.draws),
            "phases": to_jsonable(self.phases),
            "points": [p.to_dict() for p in self.points],
            "run": self.run.to_dict(),
        }


_PDF = "position_dependent_friction"


def robustness(spec: _spec.Spec, scatter: Sequence[Scatter | str] = (), samples: int = 100, *,
               seed: int = 0, distribution: str = "normal",
               position_friction: PositionFriction | None = None, confidence: float = 0.95,
               executor: Any = None, progress: ProgressCallback | None = None,
               cache: Any = None, chunksize: int | None = None) -> RobustnessResult:
    """Probability of hunting when spec values scatter around the design.

    Every sample draws each scattered value independently (normal: nominal
    times 1 + spread N(0, 1), or nominal + spread N(0, 1) for an absolute
    spread; uniform: within +-spread), and, with ``position_friction``, a
    phase of the friction variation along the rail. The same samples are
    simulated with the isolator (when the spec has one) and without it, so the
    two probabilities are a paired comparison. Draws depend only on ``seed``,
    the scatter list and ``samples``: the result is the same for a given seed
    whatever executor runs it.

    Parameters
    ----------
    spec : Spec
        The nominal design.
    scatter : sequence of Scatter or str
        Scattered values (``"friction.static=10%"``, see :func:`parse_scatter`).
    samples : int, optional
        Number of samples, default 100.
    seed : int, optional
        Seed of ``numpy.random.default_rng``, default 0.
    distribution : {"normal", "uniform"}, optional
        Default normal (spread = standard deviation).
    position_friction : PositionFriction, optional
        Add the ``position_dependent_friction`` effect with a random phase per
        sample (replacing one the spec may carry).
    confidence : float, optional
        Level of the Wilson interval, default 0.95.
    executor, progress, cache, chunksize
        As for :func:`sweep`.

    Returns
    -------
    RobustnessResult
        Samples the spec refuses (e.g. Fs drawn below Fc) are counted as
        ``invalid`` and left out of the trials.

    Raises
    ------
    SpecError
        No scatter and no position-dependent friction, a path twice, fewer
        than one sample, an unknown distribution, a confidence outside (0, 1).
    """
    from . import __version__

    start = _time.perf_counter()
    items = tuple(parse_scatter(s, spec) if isinstance(s, str) else s for s in scatter)
    if not items and position_friction is None:
        raise SpecError("nothing scatters: give at least one scatter (e.g. "
                        "'friction.static=10%') or position-dependent friction")
    paths = [s.path for s in items]
    dupes = sorted({p for p in paths if paths.count(p) > 1})
    if dupes:
        raise SpecError("scattered twice", path=dupes[0])
    if samples < 1:
        raise SpecError(f"samples must be at least 1, got {samples}")
    if distribution not in DISTRIBUTIONS:
        raise SpecError(f"unknown distribution {distribution!r}; choose from "
                        f"{', '.join(DISTRIBUTIONS)}")
    if not 0 < confidence < 1:
        raise SpecError(f"confidence must lie between 0 and 1, got {confidence}")
    base = spec
    if position_friction is not None:
        entries = [e.model_dump() for e in spec.effects if e.type != _PDF]
        entries.append({"type": _PDF, "amplitude": position_friction.amplitude,
                        "wavelength": position_friction.wavelength, "phase": "0 rad"})
        for e in entries:  # bare numbers the validators refuse (angles) as text
            if e.get("phase") is not None and not isinstance(e["phase"], str):
                e["phase"] = f"{float(e['phase'])!r} rad"
        base = with_values(spec, {"effects": entries})
    nominal = []
    for sc in items:
        v = design_value(base, sc.path)
        if v is None:
            raise SpecError("the spec has no value here to scatter around", path=sc.path)
        nominal.append(v)
    rng = np.random.default_rng(seed)
    shape = (samples, len(items))
    unit = rng.standard_normal(shape) if distribution == "normal" else \
        rng.uniform(-1.0, 1.0, shape)
    spread = np.array([s.spread for s in items])
    nom = np.array(nominal)
    rel = np.array([s.relative for s in items], dtype=bool)
    draws = np.where(rel, nom * (1.0 + spread * unit), nom + spread * unit) if items else \
        np.zeros(shape)
    phases = rng.uniform(-math.pi, math.pi, samples) if position_friction is not None else \
        np.zeros(0)
    plants = ([True] if spec.has_isolator else []) + [False]
    tasks: list = []
    sample_values = []
    for n in range(samples):
        vals: list[tuple[str, Any]] = [(p, float(draws[n, k])) for k, p in enumerate(paths)]
        if position_friction is not None:
            vals.append((f"effects[type={_PDF}].phase", float(phases[n])))
        sample_values.append(tuple(v for _, v in vals))
        tasks.append(tuple(vals))
    all_tasks = [(vals, iso) for iso in plants for vals in tasks]
    outcomes, info = _evaluate(base, all_tasks, executor=executor, progress=progress,
                               cache=cache, chunksize=chunksize)
    points = tuple(_point((n % samples,), sample_values[n % samples], iso, out)
                   for n, ((_, iso), out) in enumerate(zip(all_tasks, outcomes)))
    probs = {}
    for iso in plants:
        pts = [p for p in points if p.isolated == iso]
        probs[iso] = _probability(pts, iso, confidence)
    info = RunInfo(points=info.points, computed=info.computed, cached=info.cached,
                   chunks=info.chunks, executor=info.executor,
                   wall_time=_time.perf_counter() - start)
    return RobustnessResult(
        spec=spec, scatter=items, position_friction=position_friction, distribution=distribution,
        seed=int(seed), draws=frozen_array(draws), phases=frozen_array(phases),
        isolated=probs.get(True), not_isolated=probs[False], points=points, run=info,
        fi_design_version=__version__)


def _probability(points: Sequence[PointResult], iso: bool, confidence: float) \
        -> HuntingProbability:
    counts = {v: sum(p.verdict == v for p in points) for v in POINT_VERDICTS}
    valid = sum(p.status == "ok" for p in points)
    hunting = counts["hunting"]
    low, high = wilson_interval(hunting, valid, confidence)
    cycles = np.array([np.nan if p.hunting_cycles is None or p.status != "ok"
                       else float(p.hunting_cycles) for p in points])
    verdict = np.array([p.verdict for p in points], dtype="<U12")
    verdict.flags.writeable = False
    return HuntingProbability(
        isolated=iso, samples=len(points), valid=valid, hunting=hunting,
        probability=hunting / valid if valid else None, low=low, high=high,
        confidence=confidence, counts=counts, hunting_cycles=frozen_array(cycles),
        verdict=verdict)
