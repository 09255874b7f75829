"""Robustness: the probability of hunting when spec values scatter around the design.

:func:`robustness` resolves the design once and draws samples of it
(:class:`Scatter` per spec value, optionally friction that varies along the
rail, :class:`PositionFriction`), each the model varied by its draws
(:meth:`fi_design.model.Model.varied`), simulates each with and without the
isolator, and estimates the probability
of hunting with a Wilson confidence interval (:func:`wilson_interval`).
:func:`parse_scatter` and :func:`parse_position_friction` read the command
line's text.
"""

from __future__ import annotations

import math
import numbers
import os
import time as _time
from collections.abc import Sequence
from dataclasses import replace
from typing import Any

import numpy as np

from .. import spec as _spec
from ..errors import ArgumentError, SpecError
from ..execution import Executor
from ..model import Model
from ..results import frozen_array
from ..results.studies import (POINT_VERDICTS, HuntingProbability, PointResult, PositionFriction,
                               RobustnessResult, Scatter)
from ..spec.file import path_unit
from ..spec.paths import split_assignment
from .axes import design_value, is_number
from .cache import PointCache
from .points import (MAX_POINTS, STAGE_FIRST, ProgressCallback, evaluate, point_result,
                     study_model)

__all__ = ["DISTRIBUTIONS", "parse_scatter", "parse_position_friction", "wilson_interval",
           "robustness"]

#: Distributions of the scatter.
DISTRIBUTIONS = ("normal", "uniform")


def parse_scatter(text: str, spec: _spec.Spec | None = None) -> Scatter:
    """Read a scatter written as ``PATH=SPREAD``.

    Parameters
    ----------
    text : str
        ``"friction.static=10%"`` (relative), ``"friction.static=0.1"``
        (a bare number below 1 is relative too: 10 %) or
        ``"friction.static=0.3 N"`` (absolute, with units).
    spec : Spec, optional
        Resolves list indices into ``effects`` and ``controller.filters``.

    Returns
    -------
    Scatter

    Raises
    ------
    SpecError
        Unknown path, non-numeric value, malformed or negative spread.
    """
    from ..spec.units import to_si

    parts = split_assignment(text)
    if parts is None:
        raise SpecError(f"scatter {text!r}: expected PATH=SPREAD, e.g. 'friction.static=10%'")
    path, word = parts
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
    elif is_number(word):
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
    from ..spec.units import to_si

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
    wl = to_si(float(w) if is_number(w) else w, "m", path=path)
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


_PDF = "position_dependent_friction"


def robustness(spec: _spec.Spec | Model, scatter: Sequence[Scatter] = (), samples: int = 100, *,
               seed: int = 0, distribution: str = "normal",
               position_friction: PositionFriction | None = None, confidence: float = 0.95,
               executor: Executor | None = None, progress: ProgressCallback | None = None,
               cache: PointCache | str | os.PathLike | bool | None = None,
               chunksize: int | None = None, measure: str = "stage",
               friction_gap: float | None = None) -> RobustnessResult:
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
    spec : Spec, Model, path or mapping
        The nominal design: a spec, resolved once here, or the model resolved
        from it (not one varied by :meth:`Model.at`).
    scatter : sequence of Scatter
        Scattered values (text such as ``"friction.static=10%"`` is read by
        :func:`parse_scatter`).
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
        As for :func:`~.sweeps.sweep`.
    measure : {"stage", "move"}, optional
        ``"stage"`` (default): per point, whether any move of the family ends
        in a sustained cycle (:mod:`fi_design.stage`; the moves, the largest
        first (:func:`~fi_design.stage.moves.spread`), stop at the first that
        does, so the amplitude is that move's cycle, not the largest); ``"move"``: the paper's hunting metric on the spec's own
        move.
    friction_gap : float, optional
        Draw friction jointly: static friction is the sample's Coulomb
        friction (its own draw, or the nominal) plus the nominal gap Fs - Fc
        scattered by this fraction, the gap clipped at zero, so Fs never falls
        below Fc and no sample is lost. ``friction.static`` must not scatter
        on its own then; a drawn Coulomb friction is clipped at zero.

    Returns
    -------
    RobustnessResult
        Samples the spec refuses (e.g. Fs drawn below Fc by independent
        draws) are counted as ``invalid`` and left out of the trials.

    Raises
    ------
    SpecError
        No scatter and no position-dependent friction, a path twice, fewer
        than one sample or more than :data:`~.points.MAX_POINTS`, an unknown
        distribution, a confidence outside (0, 1).
    ArgumentError
        A scatter that is not a :class:`Scatter`, or a model varied by :meth:`Model.at`.
    """
    from .. import __version__

    start = _time.perf_counter()
    model = study_model(spec)
    spec = model.spec
    items = tuple(scatter)
    if not all(isinstance(s, Scatter) for s in items):
        raise ArgumentError("scatter must be a list of Scatter values; read text such as "
                            "'friction.static=10%' with parse_scatter")
    if not items and position_friction is None and friction_gap is None:
        raise SpecError("nothing scatters: give at least one scatter (e.g. "
                        "'friction.static=10%') or position-dependent friction")
    if friction_gap is not None and "friction.static" in [s.path for s in items]:
        raise SpecError("scatters on its own and as Coulomb friction plus the gap; give one",
                        path="friction.static")
    paths = [s.path for s in items]
    dupes = sorted({p for p in paths if paths.count(p) > 1})
    if dupes:
        raise SpecError("scattered twice", path=dupes[0])
    if isinstance(samples, bool) or not isinstance(samples, numbers.Integral):
        raise ArgumentError(f"samples must be a whole number, got {samples!r}")
    if samples < 1:
        raise SpecError(f"samples must be at least 1, got {samples}")
    if samples > MAX_POINTS:
        raise SpecError(f"samples = {samples}; a study holds at most {MAX_POINTS} (each sample "
                        "a few ms to a few tens of ms per plant)")
    if distribution not in DISTRIBUTIONS:
        raise SpecError(f"unknown distribution {distribution!r}; choose from "
                        f"{', '.join(DISTRIBUTIONS)}")
    if not 0 < confidence < 1:
        raise SpecError(f"confidence must lie between 0 and 1, got {confidence}")
    if isinstance(seed, bool) or not isinstance(seed, numbers.Integral) or seed < 0:
        raise ArgumentError(f"seed must be a whole number of 0 or more, got {seed!r}")
    base = model
    if position_friction is not None:
        entries = [e.model_dump() for e in spec.effects if e.type != _PDF]
        entries.append({"type": _PDF, "amplitude": position_friction.amplitude,
                        "wavelength": position_friction.wavelength, "phase": "0 rad"})
        for e in entries:  # bare numbers the validators refuse (angles) as text
            if e.get("phase") is not None and not isinstance(e["phase"], str):
                e["phase"] = f"{float(e['phase'])!r} rad"
        base = model.varied({"effects": entries})
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
    if friction_gap is not None:  # Fs = Fc + the gap, each drawn and clipped at zero
        gap_unit = rng.standard_normal(samples) if distribution == "normal" else \
            rng.uniform(-1.0, 1.0, samples)
        f = base.spec.friction
        if "friction.coulomb" in paths:
            i = paths.index("friction.coulomb")
            draws[:, i] = np.maximum(draws[:, i], 0.0)
            fc = draws[:, i]
        else:
            fc = np.full(samples, f.coulomb)
        static = fc + (f.static - f.coulomb) * np.maximum(1.0 + friction_gap * gap_unit, 0.0)
        items = items + (Scatter("friction.static", friction_gap, True,
                                 meaning="the gap Fs - Fc"),)
        paths = paths + ["friction.static"]
        draws = np.column_stack([draws, static])
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
    # a sample asks only whether some move does not settle: its moves stop at the first
    # that hunts
    ev = evaluate(base, all_tasks, executor=executor, progress=progress, cache=cache,
                  chunksize=chunksize, measure=STAGE_FIRST if measure == "stage" else measure)
    points = tuple(point_result((n % samples,), sample_values[n % samples], iso, out)
                   for n, ((_, iso), out) in enumerate(zip(all_tasks, ev.outcomes)))
    integrates = model.law.integrator
    probs = {}
    for iso in plants:
        pts = [p for p in points if p.isolated == iso]
        probs[iso] = _probability(pts, iso, confidence, integrates)
    info = replace(ev.run, wall_time=_time.perf_counter() - start)
    return RobustnessResult(
        spec=spec, scatter=items, position_friction=position_friction, distribution=distribution,
        seed=int(seed), draws=frozen_array(draws), phases=frozen_array(phases),
        isolated=probs.get(True), not_isolated=probs[False], points=points, run=info,
        fi_design_version=__version__, measure=measure,
        units=tuple(path_unit(s.path, base.spec) for s in items))


def _probability(points: Sequence[PointResult], iso: bool, confidence: float,
                 integrates: bool = True) -> HuntingProbability:
    counts = {v: sum(p.verdict == v for p in points) for v in POINT_VERDICTS}
    valid = sum(p.status == "ok" for p in points)
    hunting = counts["hunting"]
    low, high = wilson_interval(hunting, valid, confidence)
    unsettled = hunting + counts["undetermined"] + (counts["stuck"] if integrates else 0)
    u_low, u_high = wilson_interval(unsettled, valid, confidence)
    cycles = np.array([np.nan if p.hunting_cycles is None or p.status != "ok"
                       else float(p.hunting_cycles) for p in points])
    verdict = np.array([p.verdict for p in points], dtype="<U12")
    verdict.flags.writeable = False
    return HuntingProbability(
        isolated=iso, samples=len(points), valid=valid, hunting=hunting,
        probability=hunting / valid if valid else None, low=low, high=high,
        confidence=confidence, counts=counts, hunting_cycles=frozen_array(cycles),
        verdict=verdict, unsettled=unsettled,
        unsettled_probability=unsettled / valid if valid else None, unsettled_low=u_low,
        unsettled_high=u_high)
