"""Results of the parameter studies: sweeps, the paper's maps, robustness.

Produced by :mod:`fi_design.studies` (:func:`~fi_design.studies.sweep`,
:func:`~fi_design.studies.design_map`, :func:`~fi_design.studies.paper_study`,
:func:`~fi_design.studies.robustness`). The CSV and JSON forms are the
results' own (``table()``, ``to_csv()``, ``to_dict()``).
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import ArgumentError, SpecError
from ..provenance import Source, current_source, header
from . import Result, frozen_array, to_jsonable

if TYPE_CHECKING:  # pragma: no cover
    from ..spec import Spec

__all__ = ["POINT_VERDICTS", "Axis", "PointResult", "RunInfo", "SweepResult", "DesignMap",
           "MapDefinition", "StudyMap", "StudyResult", "Scatter", "PositionFriction",
           "HuntingProbability", "RobustnessResult", "column_name", "columns",
           "outcome_columns", "csv_text"]

#: Verdicts of the hunting metric plus the outcomes of a point that has no metric: its
#: drawn guide buckled under the stage's weight (not simulated), refused by the spec, failed.
POINT_VERDICTS = ("settled", "hunting", "stuck", "undetermined", "buckled", "invalid", "failed")


@dataclass(frozen=True, eq=False)
class Axis(Result):
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



@dataclass(frozen=True)
class PointResult(Result):
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
        ``"ok"``, ``"invalid"`` (the spec refused the values, or the drawn
        guide buckles under the stage: not simulated) or ``"failed"`` (the
        simulation did not complete or raised).
    verdict : str
        ``settled``, ``hunting``, ``stuck`` or ``undetermined`` (the metric's
        verdict), ``buckled`` (the stage's weight buckles the drawn guide: net
        drive stiffness at or below 0), or ``invalid`` / ``failed``.
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



@dataclass(frozen=True)
class RunInfo(Result):
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



@dataclass(frozen=True, eq=False)
class SweepResult(Result):
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
    fi_design_source : fi_design.provenance.Source
        The code that produced it (git commit, SHA-256 of the source files).
    measure : str
        ``"stage"``: a point's verdict is the stage's over its move family
        and ``amplitude`` the peak to peak of the cycle it enters (0 where
        every move comes to rest), ``hunting_cycles`` NaN; ``"move"``: the
        paper's metric on the spec's own move.
    notes : tuple of str
        What the axes leave as the spec gives it and what that moves (a given
        joint damping held while the stiffness varies: its damping ratio).
    """

    spec: Spec
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
    fi_design_source: Source = field(default_factory=current_source)
    measure: str = "move"
    notes: tuple[str, ...] = ()

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
            ``stuck`` or ``undetermined`` do not count as hunting. The values
            are taken in increasing order, however the axis lists them (a
            range from START down to STOP, a list ``PATH=V1,V2,...``).
        """
        if free not in ("above", "below"):
            raise ArgumentError("free must be 'above' or 'below'")
        verdicts = self.verdict.reshape(-1, len(self.x.values))
        xs = self.x.values
        ascending = [int(i) for i in np.argsort(xs, kind="stable")]
        out = np.full(verdicts.shape[0], np.nan)
        for r, row in enumerate(verdicts):
            order = ascending[::-1] if free == "above" else ascending
            last = None
            for i in order:
                if row[i] in ("hunting", "buckled", "invalid", "failed"):
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
            Columns (in order) named by each swept dotted path with its unit
            (:func:`column_name`: ``controller.crossover_Hz``,
            ``isolator.stroke_m``), then ``hunting_cycles`` (a count),
            ``amplitude_m``, ``period_s``, ``verdict``, ``status`` and
            ``message``. ``None`` where a point has no value.
            ``pandas.DataFrame(result.table())`` gives a data frame.
        """
        axes = (self.x,) if self.y is None else (self.x, self.y)
        return columns([(a.path, a.unit) for a in axes], self.points)

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
            **header(self.fi_design_version, self.fi_design_source, self.spec),
            "spec_name": self.spec.name,
            "isolated": self.isolated,
            "measure": self.measure,
            "x": self.x.to_dict(),
            "y": self.y.to_dict() if self.y is not None else None,
            "design_point": to_jsonable(list(self.design_point)),
            "hunting_cycles": to_jsonable(self.hunting_cycles),
            "amplitude": to_jsonable(self.amplitude),
            "period": to_jsonable(self.period),
            "verdict": self.verdict.tolist(),
            "counts": self.counts(),
            "points": [p.to_dict() for p in self.points],
            "notes": list(self.notes),
            "run": self.run.to_dict(),
        }


@dataclass(frozen=True, eq=False)
class DesignMap(Result):
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


@dataclass(frozen=True)
class MapDefinition(Result):
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


@dataclass(frozen=True, eq=False)
class StudyMap(Result):
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



@dataclass(frozen=True, eq=False)
class StudyResult(Result):
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
    fi_design_source : fi_design.provenance.Source
        The code that produced it (git commit, SHA-256 of the source files).
    """

    spec: Spec
    maps: tuple[StudyMap, ...]
    resolution: int
    run: RunInfo = field(repr=False)
    fi_design_source: Source = field(default_factory=current_source)

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
        return {**header(source=self.fi_design_source),
                "spec_name": self.spec.name, "resolution": self.resolution,
                "maps": [m.to_dict() for m in self.maps], "run": self.run.to_dict()}


@dataclass(frozen=True)
class Scatter(Result):
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
    meaning : str
        What scatters when it is not the value at ``path`` itself (``the gap
        Fs - Fc`` for static friction drawn as Coulomb friction plus a drawn
        gap); empty otherwise.
    """

    path: str
    spread: float
    relative: bool = True
    meaning: str = ""



@dataclass(frozen=True)
class PositionFriction(Result):
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



@dataclass(frozen=True, eq=False)
class HuntingProbability(Result):
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
    unsettled : int
        Valid samples that do not settle, whatever the reason: ``hunting``,
        ``stuck`` (with an integrating loop; a loop without integrator rests
        with its static error) or ``undetermined``.
    unsettled_probability : float or None
        unsettled / valid [-]: what a sign-off compares with its limit.
    unsettled_low, unsettled_high : float
        Its Wilson interval [-].
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
    unsettled: int = 0
    unsettled_probability: float | None = None
    unsettled_low: float = 0.0
    unsettled_high: float = 1.0



@dataclass(frozen=True, eq=False)
class RobustnessResult(Result):
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
    fi_design_source : fi_design.provenance.Source
        The code that produced it (git commit, SHA-256 of the source files).
    measure : str
        ``"stage"`` (a sample hunts when any move of its family ends in a
        cycle) or ``"move"`` (the paper's metric on the spec's move).
    units : tuple of str
        Unit of each scattered value, in the order of ``scatter`` (the
        columns of ``draws``): the spec's SI unit (``"N"``, ``"Hz"``; ``"1"``
        for a plain number); empty when not known.
    """

    spec: Spec
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
    fi_design_source: Source = field(default_factory=current_source)
    measure: str = "move"
    units: tuple[str, ...] = ()

    @property
    def samples(self) -> int:
        """Number of samples drawn."""
        return int(self.draws.shape[0])

    def table(self) -> dict[str, list]:
        """One row per sample: the drawn values [SI], then the outcome per plant.

        Returns
        -------
        dict of str to list
            Columns ``sample`` (a count from 0), each scattered path with its
            unit (:func:`column_name`: ``friction.static_N``), ``phase_rad``
            (with position-dependent friction), then per plant, ``isolated_``
            (with an isolator) and ``not_isolated_``: ``hunting_cycles`` (a
            count; empty under the ``stage`` measure), ``amplitude_m`` (under
            ``stage`` the peak to peak of the cycle the first move found
            hunting ends in, the largest move tried first; 0 when none hunts),
            ``period_s``, ``verdict``, ``status`` and ``message`` (which move
            hunts). The sample's outcome as :attr:`points` (and the JSON) hold
            it. ``None`` where a sample has no value.
        """
        cols: dict[str, list] = {"sample": list(range(self.samples))}
        units = self.units or ("",) * len(self.scatter)
        for k, (sc, unit) in enumerate(zip(self.scatter, units)):
            cols[column_name(sc.path, unit)] = [float(v) for v in self.draws[:, k]]
        if self.position_friction is not None:
            cols[column_name("phase", "rad")] = [float(v) for v in self.phases]
        for name, iso in (("isolated", True), ("not_isolated", False)):
            pts = sorted((p for p in self.points if p.isolated == iso), key=lambda p: p.index)
            if pts:
                cols.update(outcome_columns(pts, prefix=f"{name}_"))
        return cols

    def to_csv(self) -> str:
        """The :meth:`table` as CSV text.

        Returns
        -------
        str
        """
        return csv_text(self.table())

    def to_dict(self) -> dict:
        """Plain JSON data.

        Each ``scatter`` entry carries, beside the :class:`Scatter`'s fields,
        ``unit`` (of the scattered value: its column of ``draws``, as in
        :attr:`units`) and ``spread_unit`` (``"1"`` for a relative spread, a
        fraction of the nominal value; else ``unit``).

        Returns
        -------
        dict
        """
        units = self.units or ("",) * len(self.scatter)
        return {
            **header(self.fi_design_version, self.fi_design_source, self.spec),
            "spec_name": self.spec.name,
            "samples": self.samples,
            "seed": self.seed,
            "distribution": self.distribution,
            "measure": self.measure,
            "scatter": [{**s.to_dict(), "unit": unit, "spread_unit": "1" if s.relative else unit}
                        for s, unit in zip(self.scatter, units)],
            "position_friction": self.position_friction.to_dict()
            if self.position_friction else None,
            "isolated": self.isolated.to_dict() if self.isolated else None,
            "not_isolated": self.not_isolated.to_dict(),
            "draws": to_jsonable(self.draws),
            "phases": to_jsonable(self.phases),
            "points": [p.to_dict() for p in self.points],
            "run": self.run.to_dict(),
        }


#: A point's outcome in a table: field, unit.
_OUTCOME_COLUMNS = (("hunting_cycles", "1"), ("amplitude", "m"), ("period", "s"),
                    ("verdict", ""), ("status", ""), ("message", ""))


def column_name(name: str, unit: str) -> str:
    """The name of a table's (a CSV file's) column: the quantity and its unit.

    The unit follows the name after an underscore, as in the measured-data
    layout (``time_s``, ``position_m``): ``amplitude_m``,
    ``controller.crossover_Hz``, ``isolator.damping_N*s/m``. A plain number
    (unit ``"1"``: a count, a ratio) and text (no unit) keep the bare name.

    Parameters
    ----------
    name : str
        The quantity: a field or a dotted spec path.
    unit : str
        Its unit as the spec stores it (``"m"``, ``"N/m"``, ``"Hz"``; ``"1"``).

    Returns
    -------
    str
    """
    return name if unit in ("", "1") else f"{name}_{unit}"


def columns(axes: Sequence[tuple[str, str]], points: Sequence[PointResult]) \
        -> dict[str, list]:
    """The points as columns: one per varied value [SI], then the outcome fields.

    Parameters
    ----------
    axes : sequence of (str, str)
        The varied values' dotted paths and units, in the order of a point's values.
    points : sequence of PointResult
        The rows.

    Returns
    -------
    dict of str to list
        Columns named by :func:`column_name`, then :func:`outcome_columns`.
    """
    cols: dict[str, list] = {column_name(p, unit): [pt.values[i] for pt in points]
                             for i, (p, unit) in enumerate(axes)}
    cols.update(outcome_columns(points))
    return cols


def outcome_columns(points: Sequence[PointResult], prefix: str = "") -> dict[str, list]:
    """The outcome of every point as columns: ``hunting_cycles`` (a count),
    ``amplitude_m``, ``period_s``, ``verdict``, ``status``, ``message``, each
    name after ``prefix``."""
    return {prefix + column_name(name, unit): [getattr(pt, name) for pt in points]
            for name, unit in _OUTCOME_COLUMNS}


def csv_text(columns: Mapping[str, list]) -> str:
    """Columns as CSV text: a header, one row per point, empty cells for no value."""
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
