"""Results of the linear analysis: the margins of the limit cases and the achievable crossover.

Produced by :mod:`fi_design.loop.linear` (:func:`~fi_design.loop.linear.loop_margins`,
:func:`~fi_design.loop.linear.analyse`, :func:`~fi_design.loop.achievable.achievable_crossover`).
A limit case is judged where its margins are computed: :class:`CaseMargins`
carries the status of each requirement and of the case, and the guideline's
checks, the report and the console read them.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Mapping, Sequence

from . import Result, Status
from .controller import ControlLaw

__all__ = ["CRITERIA", "NOT_JUDGED", "phase_margin_judged", "loop_crossover", "GainCrossing",
           "PhaseCrossing", "CaseMargins", "LoopAnalysis", "AchievableCrossover"]

#: The requirements a limit case is judged on, in the order they are listed.
CRITERIA = ("stability", "phase margin", "gain margin", "modulus margin")

#: Why a case's phase and delay margins are shown as "–" in the report's and the console's
#: tables: its loop crosses 0 dB only outside the loop's band, where they are not judged.
NOT_JUDGED = "outside the band"


def phase_margin_judged(criteria: Mapping[str, str]) -> bool:
    """Whether a case's phase and delay margins are judged (shown as numbers) or not ("–").

    The one rule the report's and the console's margins tables follow: a case
    whose phase margin criterion is INFO (:attr:`CaseMargins.criteria`: its
    loop crosses 0 dB only outside the loop's band, and the phase margin
    there holds) has no phase or delay margin to pass; one that fails is
    judged and shown.

    Parameters
    ----------
    criteria : mapping of str to Status or str
        :attr:`CaseMargins.criteria`, or its JSON form (``"INFO"``).

    Examples
    --------
    >>> phase_margin_judged({"phase margin": "INFO"}), phase_margin_judged({})
    (False, True)
    """
    return criteria.get("phase margin") != Status.INFO


@dataclass(frozen=True)
class GainCrossing(Result):
    """One 0 dB crossing of a loop (a gain crossover) and the margins read there.

    Attributes
    ----------
    frequency : float
        Where |L| = 1 [Hz].
    phase_margin_deg : float
        Phase distance of L from -180 deg there, ``|wrap(angle L + 180)|``
        [deg]; negative when the closed loop is unstable.
    delay_margin : float
        Extra loop delay that brings this crossing to -180 deg [s]; 0 when
        the closed loop is unstable.
    in_band : bool
        At or above :data:`fi_design.loop.linear.BAND_FACTOR` below the
        controller's crossover (True before the case is judged).
    """

    frequency: float
    phase_margin_deg: float
    delay_margin: float
    in_band: bool = True


@dataclass(frozen=True)
class PhaseCrossing(Result):
    """One -180 deg crossing of a loop (a phase crossover) and the gain margin read there.

    Attributes
    ----------
    frequency : float
        Where the phase of L is -180 deg [Hz].
    gain_margin_db : float
        ``-20 log10 |L|`` there [dB]: positive, the gain may rise by this
        much; negative, the loop goes unstable when the gain falls by this much.
    """

    frequency: float
    gain_margin_db: float


@dataclass(frozen=True)
class CaseMargins(Result):
    """Loop margins of one limit case at one tuned crossover, and their judgement.

    Attributes
    ----------
    name : str
        Case name (see :data:`fi_design.loop.linear.ISOLATED_CASES`).
    description : str
        The case in words.
    crossover : float or None
        Gain crossover [Hz] with the worst phase margin (the loop may cross
        0 dB several times; ``crossovers`` lists all). None without crossing.
    phase_margin_deg : float
        Worst phase margin over the crossings [deg]: the phase distance of
        L(j w) from -180 deg, ``|wrap(angle L + 180)|``. Negative when the
        closed loop is unstable. ``inf`` without a crossing.
    gain_margin_db : float
        Gain margin [dB] at the phase crossover nearest to 0 dB, signed:
        positive, the gain may rise by this much; negative, the loop goes
        unstable when the gain falls by this much (a conditionally stable
        loop: the integrator on an undamped mass starts the phase below
        -180 deg). Negative when the closed loop is unstable, as the phase
        margin (its size that of the crossing). ``inf`` without a phase
        crossover (``None`` in JSON).
    modulus_margin : float
        Smallest distance of L(j w) from -1, min |1 + L| = 1 / max |S| [-].
    delay_margin : float
        Smallest extra loop delay that makes the loop unstable [s]: over the
        crossings, the phase lag left to -180 deg [rad] divided by the
        crossing frequency [rad/s]. 0 when the closed loop is unstable.
    stable : bool
        All closed-loop poles (roots of den + num of L) in the open left half-plane.
    crossovers : tuple of float
        All gain crossovers [Hz], ascending.
    gain_crossings : tuple of GainCrossing
        Every 0 dB crossing with its phase and delay margin, ascending.
    phase_crossings : tuple of PhaseCrossing
        Every -180 deg crossing with its gain margin, ascending; where |L|
        is below 1e-6 (a full notch's zero, where the phase flips as the loop
        vanishes) none is counted.
    modulus_frequency : float or None
        Where |1 + L| is smallest, the peak of the sensitivity [Hz]; None
        when |1 + L| never falls below 1.
    passed : bool
        Stable, and phase, gain and (if required) modulus margins meet the
        spec's requirements.
    failed : tuple of str
        The requirements not met: ``stability``, ``phase margin``,
        ``gain margin``, ``modulus margin``.
    in_band : bool
        Whether a gain crossover lies within the loop's band, at or above
        :data:`fi_design.loop.linear.BAND_FACTOR` below the controller's
        crossover. A case that crosses 0 dB only far below (the integrator
        against the stiff bristles of a stuck cart crosses at millihertz) or
        never has no phase or delay margin worth reporting; its gain margin
        still counts.
    status : Status or None
        The case's judgement: FAIL when a requirement is not met, INFO when
        it passes without a crossing in the loop's band (its phase and delay
        margins are no margins to pass), PASS otherwise; None before the
        case is judged (:func:`fi_design.loop.linear.loop_margins` alone).
    criteria : dict of str to Status
        The judgement of each requirement judged (:data:`CRITERIA`; the
        modulus margin only when required): FAIL when it is not met or the
        closed loop is unstable (a margin of an unstable loop is no margin),
        INFO for a phase margin that holds outside the loop's band, PASS
        otherwise. ``status`` is the worst of them. Empty before judging.
    """

    name: str
    description: str
    crossover: float | None
    phase_margin_deg: float
    gain_margin_db: float
    modulus_margin: float
    delay_margin: float
    stable: bool
    crossovers: tuple[float, ...] = ()
    gain_crossings: tuple[GainCrossing, ...] = ()
    phase_crossings: tuple[PhaseCrossing, ...] = ()
    modulus_frequency: float | None = None
    passed: bool = True
    failed: tuple[str, ...] = ()
    in_band: bool = True
    status: Status | None = None
    criteria: dict[str, Status] = field(default_factory=dict)


@dataclass(frozen=True)
class LoopAnalysis(Result):
    """Margins of every limit case at one tuned crossover.

    Attributes
    ----------
    crossover : float
        Crossover of the controller [Hz].
    stiffness : float or None
        Joint drive stiffness used [N/m]; None without isolator.
    delay : float
        Loop delay modelled [s] (Pade approximation).
    controller : ControlLaw
        The loop's controller.
    cases : tuple of CaseMargins
        One per limit case, in the paper's order.
    passed : bool
        All cases meet the margin requirements.
    loop_crossover : float or None
        The loop's actual crossover: the highest in-band 0 dB crossing of
        any case [Hz] (:func:`fi_design.loop.linear.loop_crossover`); None when no
        case crosses in the band.
    loop_crossover_case : str or None
        The case it belongs to.
    """

    crossover: float
    stiffness: float | None
    delay: float
    controller: ControlLaw
    cases: tuple[CaseMargins, ...]
    passed: bool
    loop_crossover: float | None = None
    loop_crossover_case: str | None = None


@dataclass(frozen=True)
class AchievableCrossover(Result):
    """The highest crossover at which every limit case meets the requirements.

    Attributes
    ----------
    frequency : float or None
        Achievable crossover [Hz] (to the bisection tolerance); None when no
        scanned crossover is feasible.
    limited_by : str
        What limits it, in words: the case and margin, the parasitic mode,
        or ``nothing up to the scan limit ...``.
    kind : str
        ``margin`` (a loop margin or stability of a case), ``mode`` (parasitic
        separation), ``scan_limit`` (nothing found up to the top of the scan)
        or ``infeasible`` (no scanned crossover works).
    case : str or None
        Name of the limiting case (``kind == "margin"``; with ``mode``, the
        case whose 0 dB crossing the separation is judged on).
    criterion : str or None
        The failing requirement: ``stability``, ``phase margin``,
        ``gain margin``, ``modulus margin`` or ``parasitic separation``.
    scan_start, scan_stop : float
        Range of the scan [Hz].
    feasible_ranges : tuple of tuple of float
        Feasible stretches of the scan grid, ``(low, high)`` [Hz], at grid
        resolution (the top one refined). Several stretches mean that a lower
        crossover can fail where a higher one passes.
    evaluations : int
        Crossovers evaluated.
    mode : str or None
        The parasitic mode that limits it: the one the separation is judged
        on (``kind == "mode"``); for a margin, filled in by step 2 when a
        mode causes it (:func:`fi_design.loop.notch.limiting_mode`).
    mode_frequency : float or None
        That mode's frequency [Hz].
    """

    frequency: float | None
    limited_by: str
    kind: str
    case: str | None
    criterion: str | None
    scan_start: float
    scan_stop: float
    feasible_ranges: tuple[tuple[float, float], ...]
    evaluations: int
    mode: str | None = None
    mode_frequency: float | None = None


def loop_crossover(cases: Sequence[CaseMargins]) -> tuple[float | None, str | None]:
    """The loop's actual crossover: the highest in-band 0 dB crossing of any limit case.

    The bandwidth the parasitic modes must stay clear of
    (``requirements.parasitic_separation``): with the cart stuck and the
    joint free the loop may cross 0 dB well above the crossover the PID is
    tuned for (the joint's resonance lifts |L|).

    Parameters
    ----------
    cases : sequence of CaseMargins
        The judged margins of the limit cases (:func:`fi_design.loop.linear.analyse`).

    Returns
    -------
    frequency, case : float or None, str or None
        The crossing [Hz] and the name of the case it belongs to; None, None
        when no case crosses 0 dB in the loop's band.
    """
    best, which = None, None
    for c in cases:
        for g in c.gain_crossings:
            if g.in_band and (best is None or g.frequency > best):
                best, which = g.frequency, c.name
    return best, which
