"""The achievable crossover: the highest crossover at which every limit case keeps its margins.

:func:`achievable_crossover` retunes the loop (the rule's PID, or the hardware's
gains scaled in frequency) over a log scan of crossovers, judges the limit
cases of :mod:`~fi_design.loop.linear` at each, and refines the highest
feasible one by bisection; it says what limits it (a case's margin, the
parasitic separation, the scan's limit). The answer for a spec's own model is
kept by the spec's content: a design run and the design search ask for the
same ones.
"""

from __future__ import annotations

import logging
import math

import numpy as np

from ..display import number, quantity
from ..model import Model, require_model
from ..results.linear import AchievableCrossover, CaseMargins
from .linear import CASE_DESCRIPTIONS, CASE_NUMBERS, judged_margins, limit_cases, loop_crossover

log = logging.getLogger(__name__)

__all__ = ["SCAN_LIMIT", "SCAN_START", "MODE_SCAN_FACTOR", "SCAN_POINTS_PER_DECADE",
           "ACHIEVED_KEPT", "achievable_crossover"]

#: Highest crossover the achievable-crossover scan looks at [Hz].
SCAN_LIMIT = 1000.0
#: Lowest crossover of the scan [Hz] (lower still when the desired crossover is low).
SCAN_START = 0.1
#: The scan stops at this factor times the lowest mode over the parasitic separation [-]:
#: the separation itself is judged on the loop's actual crossover.
MODE_SCAN_FACTOR = 2.0
#: Scan points per decade before bisection.
SCAN_POINTS_PER_DECADE = 10


def _units(criterion: str) -> str:
    return {"phase margin": "deg", "gain margin": "dB", "modulus margin": ""}.get(criterion, "")


#: The achievable crossovers last worked out for models that are their spec's own (no
#: :meth:`~fi_design.model.Model.at`), by the spec's content and the scan's arguments: a
#: design run, the search's cap and its account of the spec ask for the same ones.
_ACHIEVED: dict[tuple, AchievableCrossover] = {}
#: How many :data:`_ACHIEVED` keeps.
ACHIEVED_KEPT = 16


def achievable_crossover(model: Model, start: float | None = None,
                         stop: float | None = None, rtol: float = 1e-3) -> AchievableCrossover:
    """The highest crossover at which all limit cases meet the requirements.

    At each crossover the PID is retuned by the spec's rule (explicit gains
    scale in frequency, :meth:`fi_design.model.Model.at`); a
    crossover is feasible when every case is stable and meets ``requirements.phase_margin``,
    ``requirements.gain_margin`` and ``requirements.modulus_margin`` (if set),
    and every parasitic mode lies at or above ``requirements.parasitic_separation``
    times the loop's actual crossover (:func:`~fi_design.loop.linear.loop_crossover`: the highest
    in-band 0 dB crossing of any case, not the set value). A log scan (:data:`SCAN_POINTS_PER_DECADE`) finds the
    highest feasible grid point; bisection refines the boundary above it.

    Parameters
    ----------
    model : fi_design.model.Model
        The resolved model (:func:`fi_design.model.resolve`); its joint stiffness and the
        desired crossover.
    start : float, optional
        Lowest crossover scanned [Hz]; default the smaller of :data:`SCAN_START`
        and a tenth of the desired crossover.
    stop : float, optional
        Scan limit [Hz]; default :data:`SCAN_LIMIT`, capped at the Nyquist
        frequency of a sampled controller. The parasitic separation caps the
        scan further.
    rtol : float, optional
        Relative tolerance of the bisection [-]. Default 1e-3.

    Returns
    -------
    AchievableCrossover
        The frequency and what limits it. A model that is its spec's own (no
        :meth:`~fi_design.model.Model.at`) is a function of the spec: the answer
        for a spec of the same content is kept and given again (the last
        :data:`ACHIEVED_KEPT`), the scan not repeated.
    """
    model = require_model(model)
    key = None if model.departures else (model.spec.model_dump_json(), start, stop, rtol)
    found = _ACHIEVED.get(key) if key is not None else None
    if found is not None:
        return found
    out = _achievable(model, start, stop, rtol)
    if key is not None:
        while len(_ACHIEVED) >= ACHIEVED_KEPT:
            del _ACHIEVED[next(iter(_ACHIEVED))]
        _ACHIEVED[key] = out
    return out


def _achievable(model: Model, start: float | None, stop: float | None,
                rtol: float) -> AchievableCrossover:
    """:func:`achievable_crossover` worked out."""
    lcs = limit_cases(model)
    req = model.requirements
    sep = req.parasitic_separation
    modes = model.modes
    f_lo = min(SCAN_START, model.crossover / 10.0) if start is None else float(start)
    scan_limit = SCAN_LIMIT if stop is None else float(stop)
    rate = model.spec.controller.sample_rate  # the setting as given (its Nyquist frequency)
    if rate is not None:
        scan_limit = min(scan_limit, 0.5 * rate)
    low_mode = min(modes, key=lambda m: m.frequency) if modes else None
    mode_limit = math.inf if low_mode is None else low_mode.frequency / sep
    # the separation is judged on the loop's actual crossover at each point; the set
    # crossover stops the scan where no loop could keep it (its crossings sit near the set one)
    f_hi = min(scan_limit, MODE_SCAN_FACTOR * mode_limit)
    if f_hi <= f_lo:
        f_lo = f_hi / 10.0
    n = max(2, int(math.ceil(SCAN_POINTS_PER_DECADE * math.log10(f_hi / f_lo))) + 1)
    grid = np.geomspace(f_lo, f_hi, n)
    count = 0

    def failures(fc: float, first_only: bool) -> list:
        """The failing cases at fc, or the separation [(loop crossover Hz, case)]; [] when fine."""
        nonlocal count
        count += 1
        at = model.at(crossover=fc)
        res = judged_margins(at, lcs, first_fail=first_only)
        bad = [c for c in res if not c.passed]
        if bad or low_mode is None:
            return bad
        top, which = loop_crossover(res)
        return [(top, which)] if top is not None and low_mode.frequency < sep * top else []

    ok = np.array([not failures(float(f), True) for f in grid])
    ranges = _ranges(grid, ok)

    def mode_words(top: float | None, which: str | None) -> str:
        where = ("" if top is None else f" (case {CASE_NUMBERS[which]}, "
                 f"{CASE_DESCRIPTIONS[which]}, crosses 0 dB at {quantity(top, 'Hz', 4)})")
        return (f"parasitic mode '{low_mode.name}' at {quantity(low_mode.frequency, 'Hz', 4)}, "
                f"which must lie above {number(sep, 6)} x the loop's crossover{where}")

    if ok[-1]:
        if f_hi < scan_limit:
            return AchievableCrossover(
                frequency=float(f_hi), limited_by=mode_words(None, None), kind="mode",
                case=None, criterion="parasitic separation", scan_start=f_lo, scan_stop=f_hi,
                feasible_ranges=ranges, evaluations=count, mode=low_mode.name,
                mode_frequency=low_mode.frequency)
        return AchievableCrossover(
            frequency=float(f_hi), limited_by="nothing up to the scan limit "
                                              f"{quantity(f_hi, 'Hz', 4)}",
            kind="scan_limit", case=None, criterion=None, scan_start=f_lo, scan_stop=f_hi,
            feasible_ranges=ranges, evaluations=count)
    if not ok.any():
        bad = failures(float(grid[0]), False)[0]
        if isinstance(bad, tuple):
            what, case, crit = mode_words(*bad), bad[1], "parasitic separation"
        else:
            what, case, crit = _describe(bad, req), bad.name, bad.failed[0]
        return AchievableCrossover(
            frequency=None,
            limited_by=(f"no crossover from {quantity(f_lo, 'Hz', 3)} to {quantity(f_hi, 'Hz', 4)} "
                        f"meets the requirements; at {quantity(f_lo, 'Hz', 3)} it is {what}"),
            kind="infeasible", case=case, criterion=crit, scan_start=f_lo,
            scan_stop=f_hi, feasible_ranges=(), evaluations=count)

    i = int(np.nonzero(ok)[0][-1])
    a, b = float(grid[i]), float(grid[i + 1])
    while b / a > 1.0 + rtol:
        mid = math.sqrt(a * b)
        if failures(mid, True):
            b = mid
        else:
            a = mid
    bad = failures(b, False)[0]
    ranges = ranges[:-1] + ((ranges[-1][0], a),)
    log.debug("achievable crossover %.4g Hz after %d evaluations", a, count)
    if isinstance(bad, tuple):
        return AchievableCrossover(
            frequency=a, limited_by=mode_words(*bad), kind="mode", case=bad[1],
            criterion="parasitic separation", scan_start=f_lo, scan_stop=f_hi,
            feasible_ranges=ranges, evaluations=count, mode=low_mode.name,
            mode_frequency=low_mode.frequency)
    return AchievableCrossover(
        frequency=a, limited_by=_describe(bad, req, above=a), kind="margin",
        case=bad.name, criterion=bad.failed[0], scan_start=f_lo, scan_stop=f_hi,
        feasible_ranges=ranges, evaluations=count)


def _describe(m: CaseMargins, requirements, above: float | None = None) -> str:
    """What fails in a case, in words.

    With ``above``: ``the gain margin of case 4 (cart stuck, limiter engaged)
    falls below 6 dB above 11.8 Hz``; without: ``the gain margin of case 4
    (...) is 5.2 dB, below the 6 dB required``.
    """
    req = requirements
    where = f"case {CASE_NUMBERS[m.name]} ({m.description})"
    crit = m.failed[0]
    if crit == "stability":
        if above is not None:
            return (f"the stability of {where}: its closed loop turns unstable above "
                    f"{quantity(above, 'Hz', 4)}")
        return f"the stability of {where}: its closed loop is unstable"
    value, limit = {
        "phase margin": (m.phase_margin_deg, req.phase_margin),
        "gain margin": (abs(m.gain_margin_db), req.gain_margin),
        "modulus margin": (m.modulus_margin, req.modulus_margin),
    }[crit]
    unit = _units(crit)
    unit = f" {unit}" if unit else ""
    if above is not None:
        return (f"the {crit} of {where}, which falls below {number(limit, 6)}{unit} above "
                f"{quantity(above, 'Hz', 4)}")
    return (f"the {crit} of {where}, {number(value, 3)}{unit}, below the "
            f"{number(limit, 6)}{unit} required")


def _ranges(grid: np.ndarray, ok: np.ndarray) -> tuple[tuple[float, float], ...]:
    out = []
    start = None
    for f, good in zip(grid, ok):
        if good and start is None:
            start = float(f)
        if good:
            end = float(f)
        if not good and start is not None:
            out.append((start, end))
            start = None
    if start is not None:
        out.append((start, end))
    return tuple(out)
