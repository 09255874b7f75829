"""The parasitic mode that limits the achievable crossover, and what a notch at it allows.

A lightly damped mode that does not sit where the sensor and the actuator
are (non-collocated) turns the loop's phase through -180 deg at its
resonance: a loop that keeps its margins there is phase-stabilised, and its
gain margin at the mode sets the achievable crossover
(:func:`fi_design.loop.achievable.achievable_crossover`). A motion engineer
gain-stabilises such a mode with a notch. :func:`limiting_mode` finds the
mode behind a margin limit by taking it out: the mode is the one without
which the failing case passes at the crossover that fails.
:func:`notch_at` is the drive's notch a suggestion adds there, and
:func:`with_notch` the achievable crossover with it.
"""

from __future__ import annotations

import math

from . import linear
from .achievable import achievable_crossover
from ..display import quantity
from ..model import Model
from ..results.controller import Filter
from ..results.linear import AchievableCrossover
from ..results.mechanism import Mode

__all__ = ["NOTCH_WIDTH", "limiting_mode", "notched", "notch_at", "with_notch"]

#: Width of a suggested notch, as a fraction of the mode's frequency [-]: its -3 dB band
#: (pole damping 0.25), wide enough for the mode's tolerance, narrow enough to cost little
#: phase at the crossover.
NOTCH_WIDTH = 0.5
#: A mode further than this factor from the frequency where the margin fails is not tried [-].
NEAR = 3.0


def _critical_frequency(case, criterion: str) -> float | None:
    """Where the failing criterion is read [Hz]."""
    if criterion == "gain margin" and case.phase_crossings:
        return min(case.phase_crossings, key=lambda p: abs(p.gain_margin_db)).frequency
    if criterion == "phase margin" and case.gain_crossings:
        return min(case.gain_crossings, key=lambda g: abs(g.phase_margin_deg)).frequency
    if criterion in ("modulus margin", "stability") and case.modulus_frequency:
        return case.modulus_frequency
    return case.crossover


def limiting_mode(model: Model, achievable: AchievableCrossover) -> Mode | None:
    """The parasitic mode behind the limit of the achievable crossover, if one is.

    Parameters
    ----------
    model : fi_design.model.Model
        The resolved model the crossover was found for.
    achievable : AchievableCrossover
        Its achievable crossover.

    Returns
    -------
    fi_design.results.mechanism.Mode or None
        For a separation limit, the mode it names; for a margin limit, the
        mode nearest the frequency where the margin fails (within a factor
        :data:`NEAR`) without which the failing case meets its requirements
        just above the achievable crossover; None when no single mode is the
        cause (a margin limit of the rigid loop, delay or sampling).
    """
    modes = model.modes
    if achievable.kind == "mode" and achievable.mode is not None:
        return next((m for m in modes if m.name == achievable.mode), None)
    if achievable.kind != "margin" or achievable.frequency is None or not modes:
        return None
    above = achievable.frequency * 1.005
    at = model.at(crossover=above)
    case = next(c for c in linear.analyse(at).cases if c.name == achievable.case)
    if case.passed:
        return None
    where = _critical_frequency(case, achievable.criterion)
    if where is None or where <= 0.0:
        return None
    seen = [m for m in modes if m.source == "given" or m.participation != 0.0]
    near = sorted((m for m in seen if abs(math.log(m.frequency / where)) < math.log(NEAR)),
                  key=lambda m: abs(math.log(m.frequency / where)))
    for mode in near:
        rest = [m for m in modes if m is not mode]
        lc = next(c for c in linear.limit_cases(at, modes=rest) if c.name == achievable.case)
        without = linear.analyse(at, cases=(lc,)).cases[0]
        if without.passed:
            return mode
    return None


def notch_at(mode: Mode) -> Filter:
    """The notch a suggestion puts at a mode: its frequency, :data:`NOTCH_WIDTH` wide, full depth.

    Parameters
    ----------
    mode : fi_design.results.mechanism.Mode
        The mode.

    Returns
    -------
    fi_design.results.controller.Filter
    """
    return Filter("notch", mode.name, mode.frequency, zeta_pole=NOTCH_WIDTH / 2.0,
                  zeta_zero=0.0, order=2)


def notched(model: Model, mode: Mode) -> bool:
    """Whether the drive's chain already has a notch on the mode (within its -3 dB band)."""
    return any(f.kind == "notch" and abs(f.frequency - mode.frequency) <= 0.5 * f.width
               for f in model.law.filters)


def with_notch(model: Model, mode: Mode) -> tuple[Filter, AchievableCrossover]:
    """The achievable crossover with a notch at a mode added to the drive's chain.

    Parameters
    ----------
    model : fi_design.model.Model
        The resolved model.
    mode : fi_design.results.mechanism.Mode
        The mode that limits its crossover (:func:`limiting_mode`).

    Returns
    -------
    notch : Filter
        The notch (:func:`notch_at`), after the spec's own filters.
    achievable : AchievableCrossover
        The achievable crossover of the loop with it.
    """
    notch = notch_at(mode)
    period = model.law.sample_period
    if period > 0.0 and notch.frequency >= 0.5 / period:
        return notch, AchievableCrossover(
            frequency=None, limited_by=f"the mode at {quantity(mode.frequency, 'Hz', 4)} lies "
                                       "above the Nyquist frequency "
                                       f"{quantity(0.5 / period, 'Hz', 4)}: no notch there",
            kind="infeasible", case=None, criterion=None,
            scan_start=0.0, scan_stop=0.0, feasible_ranges=(), evaluations=0)
    notched = model.at(filters=model.law.filters + (notch,))
    return notch, achievable_crossover(notched)
