"""The record as the reconciliation uses it: evidence checked, thinned to what the model needs.

A reconciliation replays the model on the record tens to hundreds of times;
every run has a sample for every record sample, and the comparison strides
them to :data:`~.comparison.MAX_POINTS` per channel anyway. A record logged
at 10 kHz for minutes (millions of samples) is thinned to the rate the model
needs, :func:`model_rate`: plain subsampling, so that every sample kept has
its sensor noise and quantization as recorded. The noise levels and the
position lattice are read from the whole record first. A record that still
holds more than :data:`MAX_SAMPLES` samples at the lowest rate the model
can be compared at is refused, naming the limit.

A record in which neither the stage nor its reference moves holds no
evidence: there is nothing a model could disagree with, and "agrees within
noise" would be an answer without a test. It is refused, and so is a record
shorter than one period of the loop's crossover (:func:`check_duration`).
"""

from __future__ import annotations

import math

import numpy as np

from ..display import number, quantities, quantity
from ..errors import DataError
from ..measured import Measurement, thinned

#: A record at or below this rate is used as recorded [Hz].
RATE_FLOOR = 1000.0
#: The rate the model needs, in crossovers: about a hundred samples per loop period.
CROSSOVER_SAMPLES = 100.0
#: The lowest rate a record may be thinned to, in crossovers (above the D term's roll-off).
MIN_CROSSOVER_SAMPLES = 20.0
#: Most samples of the record a reconciliation works on (a few kB each while it searches).
MAX_SAMPLES = 100_000
#: Movement that counts as excitation, in position-noise levels.
EXCITATION = 10.0


def model_rate(crossover: float) -> float:
    """The sample rate the model needs [Hz]: 100 x the crossover, at least 1 kHz."""
    return max(RATE_FLOOR, CROSSOVER_SAMPLES * crossover)


def check_excitation(measured: Measurement, position_noise: float) -> None:
    """Refuse a record in which neither the stage nor its reference moves.

    Parameters
    ----------
    measured : Measurement
        The record.
    position_noise : float
        The position noise level [m].

    Raises
    ------
    DataError
        The reference and the position stay within :data:`EXCITATION` noise
        levels; the message says what was read.
    """
    band = EXCITATION * position_noise
    ref, pos = float(np.ptp(measured.reference)), float(np.ptp(measured.position))
    if ref <= band and pos <= band:
        ref_text, pos_text, band_text = quantities([ref, pos, band], "m", 3)
        raise DataError(
            f"no excitation: the reference spans {ref_text} and the position {pos_text}, "
            f"within {number(EXCITATION)} noise levels ({band_text}); a record in which nothing "
            "moves cannot show where the model is wrong: record a move (or a hold that hunts)",
            column="position_m", source=measured.source)


def check_duration(measured: Measurement, crossover: float) -> None:
    """Refuse a record shorter than one period of the loop's crossover.

    Such a record cannot show the loop's dynamics: a replay started from its
    first samples (the controller's state read from the first force sample)
    has not left them, and the residual is the start's, not the stage's: any
    effect fitted to it (a mass error, a force offset, a flipped force) would
    be named for the start alone.

    Parameters
    ----------
    measured : Measurement
        The record.
    crossover : float
        The loop's crossover [Hz].

    Raises
    ------
    DataError
        The record spans less than ``1 / crossover``.
    """
    period = 1.0 / crossover
    if measured.duration < period:
        raise DataError(
            f"too short for a reconciliation: the record spans "
            f"{quantity(measured.duration, 's', 3)}, less than one period of the loop's "
            f"{quantity(crossover, 'Hz', 3)} crossover ({quantity(period, 's', 3)}): it cannot "
            "show the loop's dynamics (a replay started from its first samples has not left "
            f"them); record at least {quantity(period, 's', 3)}, a move and its settling",
            column="time_s", source=measured.source)


def for_the_model(measured: Measurement, crossover: float) -> tuple[Measurement, str]:
    """The record thinned to the rate the model needs, and a note saying so ("" if unchanged).

    Parameters
    ----------
    measured : Measurement
        The record as read.
    crossover : float
        The loop's crossover [Hz].

    Returns
    -------
    Measurement, str

    Raises
    ------
    DataError
        Even at :data:`MIN_CROSSOVER_SAMPLES` samples per crossover the record
        holds more than :data:`MAX_SAMPLES` samples.
    """
    rate = 1.0 / measured.sample_period
    step = max(1, int(math.floor(rate / model_rate(crossover) + 1e-9)))
    if math.ceil(measured.n / step) > MAX_SAMPLES:
        step = int(math.ceil(measured.n / MAX_SAMPLES))
        least = MIN_CROSSOVER_SAMPLES * crossover
        if rate / step < least:
            longest = MAX_SAMPLES / least
            raise DataError(
                f"{measured.n} samples over {quantity(measured.duration, 's', 4)}: compared at "
                f"the lowest rate the model allows ({number(MIN_CROSSOVER_SAMPLES)} x the "
                f"{quantity(crossover, 'Hz', 3)} crossover = {quantity(least, 'Hz', 4)}) that is "
                f"{math.ceil(measured.duration * least)} samples; a reconciliation holds at "
                f"most {MAX_SAMPLES}: reconcile at most {quantity(longest, 's', 4)} of the "
                "record at a time", column="time_s", source=measured.source)
    if step == 1:
        return measured, ""
    kept = thinned(measured, step)
    return kept, (f"The record ({measured.n} samples at {quantity(rate, 'Hz', 4)}) was "
                  f"compared at every {step}th sample ({kept.n} samples at "
                  f"{quantity(rate / step, 'Hz', 4)}): the model needs "
                  f"{quantity(model_rate(crossover), 'Hz', 4)}; noise and lattice were read "
                  "from every sample.")
