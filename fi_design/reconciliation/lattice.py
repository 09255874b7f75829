"""The lattice of the measured positions: quantization read from the data itself.

An encoder reports whole counts, so the samples lie on a lattice ``x0 + k q``.
Two tests, each a binomial test of the share of samples on the lattice
against the share chance puts there:

1. **Exact lattice** (counts written as they are, no noise added after the
   quantization): the smallest nonzero difference between samples is a
   candidate step; the lattice holds when the differences are whole
   multiples of it within 1 % of a step (chance 2 %).
2. **Lattice under noise** (noise added after the quantization): for a
   grid of steps, the sample-to-sample differences are compared with the
   differences of a smooth curve through the samples (Savitzky-Golay). Where
   the smooth curve says a difference is *not* a whole number of steps
   (more than a quarter step off), a quantized sensor still reports one
   (chance at most one half: noise spreads the differences, it cannot pull
   them onto the lattice). This comparison with the smooth curve keeps the
   regular pitch ``v dt`` of a constant-velocity move, which puts raw
   samples on a lattice of its own, from passing for a sensor's.

The step is refined on differences at doubling lags (each rounded to whole
steps), so its relative error is about the noise over the travel; the
largest step that passes is the lattice (every divisor of the step passes
too). The jitter, the spread around the lattice points, is the sensor noise
apart from the quantization. The lattice is *coarser than the noise
explains* when the counts, not a noise under them, make the record's
scatter: under noise, when the quantization error ``q / sqrt(12)`` exceeds
:data:`COARSE_FACTOR` times the jitter; for whole counts (the noise before
the rounding is not in the record), when the record's noise estimate
(:func:`~.noise.estimate_noise`) is at most :data:`COARSE_FACTOR` times
``q / sqrt(12)`` (a logger rounding a much noisier signal onto a fine grid
has a lattice, but no coarse one).
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import NamedTuple

import numpy as np

from ..display import percent, quantities, quantity
from ..results.reconciliation import Lattice

#: Tolerance of an exact lattice, as a fraction of the step (the file's number formatting).
EXACT_TOLERANCE = 0.01
#: Half-width of "on the lattice" for a lattice under noise, as a fraction of the step.
ON_TOLERANCE = 0.25
#: Smallest share of the differences on an exact lattice.
EXACT_FRACTION = 0.99
#: Fewest tested samples.
MIN_TESTED = 50
#: Largest p-value of the binomial test for a lattice to be reported.
MAX_P = 1e-9
#: Window of the smoothing curve [samples] and its polynomial order.
SMOOTH_WINDOW = 21
SMOOTH_ORDER = 3
#: Steps tried by the test under noise, per decade.
GRID_PER_DECADE = 250
#: Smallest step tried [m].
MIN_STEP = 1e-9
#: Margin between the quantization error q / sqrt(12) and the noise for a coarse lattice.
COARSE_FACTOR = 1.5


class StepEstimate(NamedTuple):
    """A lattice step and its standard error [m]."""

    step: float
    error: float


class LatticeCount(NamedTuple):
    """Differences on the lattice among those tested."""

    on: int
    tested: int


def find_lattice(position: np.ndarray, noise: float) -> Lattice:
    """The lattice of measured positions, if there is one.

    Parameters
    ----------
    position : ndarray, shape (n,)
        Measured positions in time order [m].
    noise : float
        Position noise estimated from the data as for any record [m] (whole
        counts are a coarse lattice when it is at most :data:`COARSE_FACTOR`
        times q / sqrt(12)).

    Returns
    -------
    Lattice
        ``step`` None when no lattice passes the test (at most a twentieth
        of the travel is tried).
    """
    x = np.asarray(position, dtype=float)
    n = len(x)
    span = float(np.ptp(x)) if n else 0.0
    if n < MIN_TESTED or span <= 0.0:
        return Lattice(step=None, detail="too few samples or no travel to test for a lattice")
    found = _exact_lattice(x, span)
    if found is None:
        found = _noisy_lattice(x, span)
    if found.found:
        qe = found.step / math.sqrt(12.0)
        if found.exact:
            coarse = noise <= COARSE_FACTOR * qe
            noise_text, qe_text = quantities([noise, qe], "m", 3)
            why = (f"the record's noise ({noise_text}) is "
                   + ("no more than" if coarse else "well above")
                   + f" its quantization error ({qe_text})")
        else:
            coarse = qe > COARSE_FACTOR * found.jitter
            qe_text, jitter_text = quantities([qe, found.jitter], "m", 3)
            why = (f"its quantization error ({qe_text}) is "
                   + ("coarser than" if coarse else "within")
                   + f" the noise around it ({jitter_text})")
        found = replace(found, coarse=coarse, detail=found.detail + "; " + why)
    return found


def _binomial_p(k: int, m: int, chance: float) -> float:
    """One-sided binomial p-value of k or more of m on the lattice."""
    from scipy.stats import binom

    return float(binom.sf(k - 1, m, chance)) if m else 1.0


def _exact_lattice(x: np.ndarray, span: float) -> Lattice | None:
    d = np.abs(np.diff(x))
    scale = max(float(np.max(np.abs(x))), span)
    nz = d[d > 1e-9 * scale]
    if len(nz) < MIN_TESTED:
        return None
    q = float(np.min(nz))
    ratio = nz / q
    if np.median(ratio) > 1e7:  # a tiny difference is noise, not a count
        return None
    if np.mean(np.abs(ratio - np.round(ratio)) <= EXACT_TOLERANCE) < EXACT_FRACTION:
        return None
    est = refine_step(x, q)
    # whole counts: the step is known to the number formatting of the record (ten digits)
    est = est._replace(error=max(est.error, 1e-10 * est.step))
    q = est.step
    x0 = _offset(x, q)
    e = _wrapped(x, x0, q)
    on = int(np.sum(np.abs(e) <= EXACT_TOLERANCE * q))
    chance = 2.0 * EXACT_TOLERANCE
    p = _binomial_p(on, len(x), chance)
    if p >= MAX_P:
        return None
    jitter = 1.4826 * float(np.median(np.abs(e)))
    return Lattice(step=q, step_error=est.error, offset=x0, fraction=on / len(x), chance=chance,
                   tested=len(x), p_value=p, jitter=jitter, exact=True,
                   detail=f"every sample is a whole number of {quantity(q, 'm')} steps "
                          f"({percent(on / len(x), 3)} within 1 % of a step; chance "
                          f"{percent(chance, 2)})")


def _noisy_lattice(x: np.ndarray, span: float) -> Lattice:
    from scipy.signal import savgol_filter

    n = len(x)
    window = min(SMOOTH_WINDOW, n if n % 2 else n - 1)
    d = np.diff(x)
    ds = np.diff(savgol_filter(x, window, SMOOTH_ORDER))
    hi = span / 20.0

    def test(q: float) -> LatticeCount:
        """Differences on the lattice among those the smooth curve puts off it."""
        r = ds / q
        sel = np.abs(r - np.round(r)) > ON_TOLERANCE
        m = int(sel.sum())
        if m < MIN_TESTED:
            return LatticeCount(0, m)
        rx = d[sel] / q
        return LatticeCount(int(np.sum(np.abs(rx - np.round(rx)) < ON_TOLERANCE)), m)

    if hi <= MIN_STEP:
        return Lattice(step=None, detail="the travel is too short to test for a lattice")
    grid = np.geomspace(MIN_STEP, hi, int(GRID_PER_DECADE * math.log10(hi / MIN_STEP)) + 2)
    counts = [test(q) for q in grid]
    logp = [_log_p(k, m) for k, m in counts]
    j = int(np.argmin(logp))
    if not logp[j] < math.log(MAX_P):
        k, m = counts[j]
        return Lattice(step=None, fraction=k / m if m else 0.0, chance=0.5, tested=m,
                       p_value=math.exp(logp[j]) if logp[j] > -700 else 0.0,
                       detail="no lattice in the measured position: where a smooth curve "
                              "through the samples puts a step off every lattice, the samples "
                              "are off it as often as chance says")
    est = refine_step(x, float(grid[j]))
    k, m = test(est.step)
    # every divisor of the step is a lattice as well: the step is the largest that holds
    for mult in range(10, 1, -1):
        if mult * est.step > hi:
            continue
        other = refine_step(x, mult * est.step)
        kk, mm = test(other.step)
        if mm and _log_p(kk, mm) < math.log(MAX_P) and kk / mm >= k / m - 0.05:
            est, k, m = other, kk, mm
            break
    q = est.step
    x0 = _offset(x, q)
    e = _wrapped(x, x0, q)
    jitter = 1.4826 * float(np.median(np.abs(e)))
    p = _binomial_p(k, m, 0.5)
    if p >= MAX_P:
        return Lattice(step=None, detail="no lattice in the measured position")
    return Lattice(step=q, step_error=est.error, offset=x0, fraction=k / m, chance=0.5,
                   tested=m, p_value=p, jitter=jitter, exact=False,
                   detail=f"the samples lie on a lattice of {quantity(q, 'm')} steps with "
                          f"{quantity(jitter, 'm', 3)} of noise around it ({percent(k / m, 3)} of "
                          f"{m} tested steps on it; chance at most 50 %)")


def _log_p(k: int, m: int) -> float:
    from scipy.stats import binom

    return float(binom.logsf(k - 1, m, 0.5)) if m >= MIN_TESTED else 0.0


def refine_step(x: np.ndarray, q: float) -> StepEstimate:
    """Refine a lattice step on differences at doubling lags.

    At each lag the differences are rounded to whole steps (those within a
    quarter step of a whole number, at most ``limit`` steps, which doubles
    with the lag) and the step is their least-squares ratio; each doubling
    halves the step's relative error, so it ends at about the noise over the
    travel.

    Parameters
    ----------
    x : ndarray, shape (n,)
        Positions in time order [m].
    q : float
        Starting step [m], within a few percent.

    Returns
    -------
    StepEstimate
        The step and its standard error: the last lag's least-squares error
        or the last lag's change of the step, whichever is larger (the
        rounding to whole steps anchors each lag to the one before).
    """
    n = len(x)
    lag, limit = 1, 5
    error = math.inf
    previous = None
    while lag < n // 2:
        D = x[lag:] - x[:-lag]
        if len(D) > 20000:
            D = D[:: len(D) // 20000 + 1]
        r = D / q
        k = np.round(r)
        ok = (np.abs(r - k) < ON_TOLERANCE) & (k != 0) & (np.abs(k) <= limit)
        if ok.sum() < MIN_TESTED:
            break
        kk = np.sum(k[ok] ** 2)
        q = float(np.sum(D[ok] * k[ok]) / kk)
        res = D[ok] - q * k[ok]
        error = float(math.sqrt(float(res @ res) / max(int(ok.sum()) - 1, 1) / kk))
        if previous is not None:
            error = max(error, abs(q - previous))
        previous = q
        lag *= 2
        limit *= 2
    return StepEstimate(q, error)


def _offset(x: np.ndarray, q: float) -> float:
    """Lattice offset in [0, q) from the circular mean of the samples' phases [m]."""
    z = np.exp(2j * np.pi * x / q).mean()
    return float(np.angle(z) / (2 * np.pi) * q) % q


def _wrapped(x: np.ndarray, x0: float, q: float) -> np.ndarray:
    """Distance of each sample from the nearest lattice point, in [-q/2, q/2) [m]."""
    return (x - x0 + q / 2) % q - q / 2
