"""Structure diagnosis: when no missing effect explains the gap, what might.

When the nominal misfit is far above the noise (:data:`STRUCTURE_MISFIT`
noise units or more) and no candidate removes most of it, no effect of the
catalogue is "the" answer: the model's structure does not match the record.
The nominal residual (force when recorded, else position) then points at
likely causes, each with the share of the residual that points there:

- **controller**: energy at and above a third of the loop's crossover, where
  the controller shapes the response (gains, the derivative's filter and
  input, sample rate, delay);
- **initial state**: residual concentrated at the start of the record (the
  replay's starting position, velocity or controller state);
- **mass**: residual that follows the reference acceleration (moving mass,
  feedforward);
- **disturbance**: slow residual (below a thirtieth of the crossover) left
  after the velocity, direction and acceleration terms are taken out (a
  force the model lacks: cable, drift, a load).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from ..display import fixed, number, percent, quantity
from .comparison import Comparison, ModelRun
from ..results.reconciliation import Cause, Diagnosis
from .significance import EXPLAINED_MIN

#: RMS misfit of the nominal model [noise units] from which a gap counts as structural.
STRUCTURE_MISFIT = 10.0
#: Share of the record that counts as its start, at least the settle window.
START_SHARE = 0.05


def diagnose(cmp: Comparison, nominal: ModelRun, chi2_nominal: float,
             best_explained: float) -> Diagnosis:
    """Whether the model's structure misses the record, and the likely causes.

    Parameters
    ----------
    cmp : Comparison
        The comparison.
    nominal : ModelRun
        The nominal model's run.
    chi2_nominal : float
        Its weighted squared residual [-].
    best_explained : float
        Largest share of the gap above noise a candidate removes, 0-1.
    """
    misfit = math.sqrt(chi2_nominal / cmp.n_points)
    use_force = cmp.has_force
    channel = "force" if use_force else "position"
    meas = cmp.meas.force if use_force else cmp.meas.position
    model = nominal.force if use_force else nominal.position
    r = np.where(np.isfinite(model), meas - model, 0.0)
    crossover = cmp.model.crossover
    spec = _spectrum(r, cmp.t)
    causes = sorted(_causes(cmp, r, crossover, use_force), key=lambda c: -c.share)
    mismatch = misfit >= STRUCTURE_MISFIT and best_explained < EXPLAINED_MIN
    message = ""
    if mismatch:
        top = [c for c in causes if c.share >= 0.1] or causes[:1]
        message = (f"The nominal model misses the record by {number(misfit, 3)} noise units "
                   "(RMS), far above the noise, and no catalogue effect explains most of it (the "
                   f"best removes {percent(best_explained, 2)} of the gap): the model's "
                   "structure does not match the record. Likely causes, strongest first: "
                   + "; ".join(f"{c.name.replace('_', ' ')} ({percent(c.share, 2)})" for c in top)
                   + ". See the residual and its spectrum.")
    return Diagnosis(mismatch=mismatch, misfit=misfit, misfit_limit=STRUCTURE_MISFIT,
                     best_explained=float(best_explained), channel=channel,
                     causes=tuple(causes), message=message, frequency=_frozen(spec.frequency),
                     spectrum=_frozen(spec.density), crossover=float(crossover))


def _frozen(a):
    from ..results import frozen_array

    return frozen_array(a)


class Spectrum(NamedTuple):
    """Frequencies [Hz] and amplitude spectral density [unit / sqrt(Hz)]."""

    frequency: np.ndarray
    density: np.ndarray


def _spectrum(r: np.ndarray, t: np.ndarray) -> Spectrum:
    """Welch amplitude spectral density of a residual."""
    from scipy.signal import welch

    dt = float(np.median(np.diff(t)))
    nper = int(min(len(r), 2 ** int(math.log2(max(len(r) // 4, 16)))))
    f, p = welch(r - np.mean(r), fs=1.0 / dt, nperseg=nper)
    return Spectrum(f, np.sqrt(p))


def _band(r: np.ndarray, t: np.ndarray, low: float | None, high: float | None) -> np.ndarray:
    """Zero-phase Butterworth filter: low-pass below ``high``, high-pass above ``low`` [Hz]."""
    from scipy.signal import butter, sosfiltfilt

    fs = 1.0 / float(np.median(np.diff(t)))
    nyq = fs / 2.0
    out = np.asarray(r, dtype=float)
    if high is not None and high < nyq:
        out = sosfiltfilt(butter(2, high, btype="lowpass", fs=fs, output="sos"), out)
    if low is not None:
        if low >= nyq:
            return np.zeros_like(out)
        out = sosfiltfilt(butter(2, low, btype="highpass", fs=fs, output="sos"), out)
    return out


def _causes(cmp: Comparison, r: np.ndarray, crossover: float, use_force: bool) -> list[Cause]:
    """Shares of the residual's energy (its mean included) that point at each cause."""
    unit = "N" if use_force else "m"
    t = cmp.t
    total = float(r @ r) or 1e-300
    out = []
    fast = _band(r, t, crossover / 3.0, None)
    high = float(fast @ fast) / total
    out.append(Cause("controller", min(high, 1.0),
                     f"{percent(high, 2)} of the residual's energy lies at or above a third of "
                     f"the loop's crossover ({quantity(crossover, 'Hz', 3)}), where the "
                     "controller shapes the response: check the controller description (gains, "
                     "the derivative's input and filter, sample rate, delay)."))
    window = max(START_SHARE * cmp.duration, cmp.settle_window)
    first = t <= t[0] + window
    frac_t = float(np.mean(first))
    frac_ss = float(r[first] @ r[first]) / total
    start = max(0.0, (frac_ss - frac_t) / (1.0 - frac_t)) if frac_t < 1.0 else 0.0
    out.append(Cause("initial_state", start,
                     f"{percent(frac_ss, 2)} of the residual's energy lies in the first "
                     f"{quantity(window, 's', 3)} ({percent(frac_t, 2)} of the record): check "
                     "the state the replay starts from (position, velocity, the controller's "
                     "integrator)."))
    moving = cmp.kind != "hold"
    a, v = cmp.a_ref, cmp.v_ref
    mass, slope = 0.0, 0.0
    if moving.sum() > 10 and np.ptp(a[moving]) > 0:
        A = np.column_stack([np.ones(moving.sum()), a[moving]])
        coef, *_ = np.linalg.lstsq(A, r[moving], rcond=None)
        var = float(np.var(r[moving])) or 1e-300
        mass = max(0.0, 1.0 - float(np.var(r[moving] - A @ coef)) / var)
        slope = float(coef[1])
    out.append(Cause("mass", mass,
                     "the residual follows the reference acceleration (R^2 "
                     f"{fixed(mass, 2)}, slope {quantity(slope, f'{unit} s^2/m', 3)}"
                     + (": the moving mass or the feedforward is off by about that many kg)."
                        if use_force else ")")))
    # what velocity, direction and acceleration terms (friction, mass: the catalogue's) leave
    X = np.column_stack([v, np.sign(v), a])
    coef, *_ = np.linalg.lstsq(X, r, rcond=None)
    slow_part = _band(r - X @ coef, t, None, crossover / 30.0)
    slow = min(float(slow_part @ slow_part) / total, 1.0)
    out.append(Cause("disturbance", slow,
                     f"{percent(slow, 2)} of the residual's energy is slow (below "
                     f"{quantity(crossover / 30.0, 'Hz', 3)}, a constant included) and not a "
                     "velocity, direction or acceleration term: a force the model lacks (a load, a "
                     "cable, a drift)."))
    return out
