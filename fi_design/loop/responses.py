"""The loop of every limit case over frequency, on a grid that resolves what the tables report.

The Bode, Nyquist and sensitivity plots draw these responses, and a drawn peak
must be the peak the margins table reports. A log-spaced grid undersamples a
lightly damped resonance (a 150 Hz mode with 2 % damping is 6 Hz wide), so
the grid here holds, besides a log-spaced base:

- points packed around every lightly damped pole and zero of each case's
  loop and closed loop (resonances and antiresonances of the loop and of the
  sensitivity), ``f_n (1 + zeta t)`` for ``|t| <= 8``;
- every gain and phase crossing and the frequency of each case's
  sensitivity peak (:attr:`~fi_design.results.linear.CaseMargins.modulus_frequency`),
  exactly, so a marked crossing lies on its curve and the drawn peak is the
  table's;
- midpoints inserted where consecutive points of a case lie far apart, in
  the complex plane near the critical point or in magnitude and phase, so
  that the Nyquist curves are smooth, not polygons.

A sampled controller is drawn up to its Nyquist frequency, no further: above
it the continuous model stands for nothing the drive does.
"""

from __future__ import annotations

import math
from typing import Sequence

import numpy as np

from . import linear
from ..model import Model, require_model
from ..results import frozen_array
from ..results.steps import CaseResponse, CrossoverResult, LoopResponses

__all__ = ["loop_responses", "frequency_grid"]

#: Damping ratio below which a pole or zero counts as a resonance to resolve [-].
RESONANT = 0.5
#: Points packed around each resonance: f_n (1 + zeta t), t in [-PACK, PACK] [-].
PACK = 8.0
#: Largest step of a curve between grid points, near the critical point (|L| < 4) [-].
STEP_COMPLEX = 0.03
#: Largest step of the magnitude [dB] and of the phase [deg] between grid points.
STEP_DB, STEP_DEG = 1.0, 5.0
#: Refinement rounds, and the most points the grid may reach.
ROUNDS, MAX_POINTS = 10, 20000


def _roots_hz(p: np.ndarray, w0: float) -> np.ndarray:
    """Roots of a polynomial in s [rad/s] as complex s [rad/s], found in s / w0."""
    p = np.trim_zeros(np.asarray(p, float), "f")
    if p.size < 2:
        return np.zeros(0, complex)
    scaled = p * w0 ** np.arange(p.size - 1, -1, -1, dtype=float)
    return np.roots(scaled / scaled[0]) * w0


def _resonances(loops: Sequence[tuple[np.ndarray, np.ndarray]], w0: float, lo: float,
                hi: float) -> list[float]:
    """Grid points [Hz] packed around the lightly damped roots of the loops and closed loops."""
    out: list[float] = []
    t = np.linspace(-PACK, PACK, 65)
    for num, den in loops:
        for p in (num, den, np.polyadd(num, den)):
            for r in _roots_hz(p, w0):
                wn = abs(r)
                if wn == 0.0 or abs(r.imag) == 0.0:
                    continue
                zeta = -r.real / wn
                fn = wn / (2 * math.pi)
                if abs(zeta) >= RESONANT or not lo <= fn <= hi:
                    continue
                z = max(abs(zeta), 1e-4)
                out.extend(f for f in fn * (1.0 + z * t) if lo <= f <= hi)
    return out


def frequency_grid(loops: Sequence[tuple[np.ndarray, np.ndarray]], lo: float, hi: float,
                   marks: Sequence[float] = (), points: int = 500,
                   scale: float = 1.0) -> np.ndarray:
    """A frequency grid that resolves every resonance of the loops and holds the marks.

    Parameters
    ----------
    loops : sequence of (num, den)
        Each loop L = num / den, descending powers of s [rad/s].
    lo, hi : float
        The span [Hz].
    marks : sequence of float, optional
        Frequencies the grid must hold exactly [Hz] (crossings, peaks); those
        outside the span are left out.
    points : int, optional
        Points of the log-spaced base.
    scale : float, optional
        Frequency [rad/s] the root finding is scaled by (the crossover).

    Returns
    -------
    numpy.ndarray
        Ascending frequencies [Hz], refined until no case's curve steps more
        than :data:`STEP_COMPLEX` near the critical point, :data:`STEP_DB` in
        magnitude or :data:`STEP_DEG` in phase between neighbours.
    """
    f = np.concatenate([np.geomspace(lo, hi, points), _resonances(loops, scale, lo, hi),
                        [m for m in marks if m is not None and lo <= m <= hi]])
    f = np.unique(f)
    for _ in range(ROUNDS):
        s = 2j * math.pi * f
        coarse = np.zeros(f.size - 1, bool)
        for num, den in loops:
            L = np.polyval(num, s) / np.polyval(den, s)
            step = np.abs(np.diff(L))
            near = np.minimum(np.abs(L[:-1]), np.abs(L[1:])) < 4.0
            db = np.abs(np.diff(20.0 * np.log10(np.abs(L))))
            deg = np.abs(np.diff(np.degrees(np.unwrap(np.angle(L)))))
            coarse |= (near & (step > STEP_COMPLEX)) | (db > STEP_DB) | (deg > STEP_DEG)
        coarse &= f[1:] / f[:-1] > 1.0 + 1e-9
        if not coarse.any() or f.size + coarse.sum() > MAX_POINTS:
            break
        f = np.unique(np.concatenate([f, np.sqrt(f[:-1][coarse] * f[1:][coarse])]))
    return f


def loop_responses(model: Model, crossover: CrossoverResult,
                   points: int = 500) -> LoopResponses:
    """The loop of every limit case over a grid that holds every crossover, mode and peak.

    The loop is the one whose margins step 2 reports: the model's controller
    (its filters in series) at the desired crossover, its joint stiffness.

    Parameters
    ----------
    model : fi_design.model.Model
        The resolved model (:func:`fi_design.model.resolve`).
    crossover : CrossoverResult
        Step 2 (desired crossover, the gain and phase crossings and the
        sensitivity peak of each case).
    points : int, optional
        Points of the log-spaced base grid (:func:`frequency_grid` adds more).

    Returns
    -------
    LoopResponses
        From a third of the lowest gain crossover (and a thirtieth of the
        desired crossover) to thirty times the desired crossover or twice the
        highest mode, on whole decades; a sampled controller's up to its
        Nyquist frequency.
    """
    model = require_model(model)
    fc = crossover.desired
    lows = [fc / 30.0] + [c / 3.0 for case in crossover.cases for c in case.crossovers
                          if c and c > 0]
    # the modes the loop shows: the given ones, and the computed ones that show in x by 1 %
    highs = [30.0 * fc] + [2.0 * m.frequency for m in model.modes
                           if m.source == "given" or abs(m.participation) >= 0.01]
    highs += [2.0 * f.frequency for f in model.law.filters]
    lo = 10.0 ** math.floor(math.log10(min(lows)))
    hi = 10.0 ** math.ceil(math.log10(max(highs)))
    nyquist = None
    if model.law.sample_period > 0.0:
        nyquist = 0.5 / model.law.sample_period
        hi = min(hi, nyquist)
    lcs = linear.limit_cases(model)
    loops = [linear.loop_polynomials(model, lc) for lc in lcs]
    marks = [x for case in crossover.cases
             for x in ([g.frequency for g in case.gain_crossings]
                       + [p.frequency for p in case.phase_crossings]
                       + [case.modulus_frequency])]
    f = frequency_grid(loops, lo, hi, marks, points, scale=2 * math.pi * fc)
    s = 2j * math.pi * f
    cases = [CaseResponse(name=lc.name, number=lc.number, description=lc.description,
                          loop=frozen_array(np.polyval(num, s) / np.polyval(den, s),
                                            dtype=complex))
             for lc, (num, den) in zip(lcs, loops)]
    return LoopResponses(frequency=frozen_array(f), cases=tuple(cases), nyquist=nyquist)
