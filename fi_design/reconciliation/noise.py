"""Sensor noise and the effective number of independent residuals.

The noise per channel sets the unit every gap is measured in. The
residual of a model that misses the record is not white: neighbouring
samples share the same mismatch, so ``n`` residuals carry the information of
``n / tau`` independent ones, with ``tau`` the integrated autocorrelation
time. Every statistic of the reconciliation counts effective samples.
"""

from __future__ import annotations

import math

import numpy as np

from ..measured import Measurement
from ..results.reconciliation import Lattice, NoiseLevels

#: Model-accuracy floor of the noise per channel (position and deflection in m, force in N):
#: a simulation at the default tolerance (1e-6, so 1 nm absolute on positions) is accurate to
#: a few nm over a run, an error correlated in time that the noise estimate (third
#: differences) does not see. Below these floors a record is compared more finely than a
#: model can be simulated: a record the spec's own simulation wrote read as a gap of 2.6
#: noise units with a 1 nm position floor.
NOISE_FLOOR = {"position": 1e-8, "deflection": 1e-9, "force": 1e-5}
#: Sokal's window constant for the integrated autocorrelation time.
SOKAL_C = 5.0


def estimate_noise(values: np.ndarray) -> float:
    """Robust white-noise standard deviation of a sampled signal.

    The median absolute deviation of the third differences (which remove
    polynomials up to second order, i.e. the smooth motion), scaled to a
    standard deviation (1.4826 MAD) and divided by sqrt(20), the gain of the
    third-difference filter on white noise. Sparse jumps (slips) do not move
    the median.

    Parameters
    ----------
    values : ndarray, shape (n,)
        The signal, n >= 4.

    Returns
    -------
    float
        Standard deviation, in the unit of ``values``.
    """
    d = np.diff(np.asarray(values, dtype=float), n=3)
    if len(d) == 0:
        return 0.0
    mad = float(np.median(np.abs(d - np.median(d))))
    return 1.4826 * mad / math.sqrt(20.0)


def noise_levels(spec, measured: Measurement, isolated: bool, lattice: Lattice,
                 force_is_input: bool = False) -> NoiseLevels:
    """Noise per channel: the spec's ``measurement`` section, else estimated from the data.

    A position recorded on a lattice of step q differs from any unquantized
    position by up to q / 2: the resolution's q / sqrt(12) is added in
    quadrature to the estimate (whose third differences miss it wherever
    the stage rests on one count). No level falls below :data:`NOISE_FLOOR`.

    Parameters
    ----------
    spec : Spec
        The spec (its optional ``measurement`` section).
    measured : Measurement
        The record.
    isolated : bool
        Whether the deflection channel takes part.
    lattice : Lattice
        The lattice of the measured positions.
    force_is_input : bool
        The measured force drives the model (open-loop replay): it is not
        compared, and has no noise level.
    """
    given = spec.measurement
    source: dict[str, str] = {}

    def level(channel: str, values, spec_value, resolution=None):
        if values is None:
            return None
        if spec_value is not None and spec_value > 0:
            source[channel] = "spec"
            return float(spec_value)
        est = estimate_noise(values)
        if resolution:
            est = math.hypot(est, resolution / math.sqrt(12.0))
        if est < NOISE_FLOOR[channel]:
            source[channel] = "floor"
            return NOISE_FLOOR[channel]
        source[channel] = "estimated"
        return float(est)

    pos = level("position", measured.position, given.position_noise if given else None,
                lattice.step if lattice.found else None)
    force = level("force", None if force_is_input else measured.force,
                  given.force_noise if given else None)
    defl = level("deflection", measured.deflection if isolated else None,
                 given.deflection_noise if given else None)
    return NoiseLevels(position=pos, force=force, deflection=defl, source=source)


def autocorrelation_time(series: np.ndarray) -> float:
    """Integrated autocorrelation time of a residual series [samples], at least 1.

    ``tau = 1 + 2 sum_k rho_k`` over lags up to Sokal's automatic window (the
    smallest ``M`` with ``M >= 5 tau(M)``), from the FFT autocorrelation of
    the mean-removed series. White noise gives 1; a slowly varying mismatch
    gives about the number of samples it stays correlated over. Capped at a
    tenth of the series length (at least ten effective samples remain).

    Parameters
    ----------
    series : ndarray, shape (n,)
        Residuals in time order.
    """
    x = np.asarray(series, dtype=float)
    n = len(x)
    if n < 20:
        return 1.0
    x = x - x.mean()
    var = float(x @ x)
    if var == 0.0:
        return 1.0
    m = 1 << int(math.ceil(math.log2(2 * n)))
    f = np.fft.rfft(x, m)
    acf = np.fft.irfft(f * np.conj(f), m)[:n] / var
    tau = 1.0
    for k in range(1, n):
        tau += 2.0 * acf[k]
        if k >= SOKAL_C * tau:
            break
    return float(min(max(tau, 1.0), n / 10.0))


def channels_autocorrelation_time(blocks: list[np.ndarray]) -> float:
    """Autocorrelation time of a residual made of several channels [samples].

    The longest autocorrelation time of the channels (each in time order)
    counts for all, so the effective number of independent residuals is
    ``n / tau`` with ``n`` all entries.

    Parameters
    ----------
    blocks : list of ndarray
        The residual of each channel, in time order.
    """
    taus = [autocorrelation_time(b) for b in blocks if len(b) >= 20]
    return max(taus) if taus else 1.0
