"""What a record holds for LuGre's dynamic parameters: rests, breakaways, reversals.

:func:`excitation` finds the events that excite static friction, the
Stribeck velocity and the bristle stiffness; :mod:`.dynamic` estimates them
from those events.
"""

from __future__ import annotations

import numpy as np

from ..measured import Measurement
from ..results.identification import Excitation, Processing
from .preprocess import lowpass

#: A rest: the stage moves less than REST_BAND (or 10 x the position noise) for DWELL.
DWELL = 0.05
#: See :data:`DWELL` [m].
REST_BAND = 1e-6
#: A presliding reversal: the excursion between two reversals stays below this [m].
PRESLIDING_BAND = 50e-6
#: Creeping slower than this fraction of the velocity threshold for DWELL also counts as a rest
#: (a stuck bearing moves by its presliding displacement, often more than REST_BAND).
STOP_FRACTION = 0.1


def excitation(measured: Measurement, proc: Processing, *, spec=None,
               dwell: float = DWELL, rest_band: float = REST_BAND,
               presliding_band: float = PRESLIDING_BAND) -> Excitation:
    """Detect breakaways from rest and presliding reversals in a record.

    The bearing side (the stage, or the cart x1 - d of an isolated stage with
    a deflection column) is low-passed as for the fit. A *rest* is a stretch
    of at least ``dwell`` in which it moves less than ``rest_band`` (or 10
    times the position noise, whichever is larger) or creeps slower than
    :data:`STOP_FRACTION` of the velocity threshold (a stuck bearing moves by
    its presliding displacement); a *breakaway* is a rest, after sliding
    above the velocity threshold, followed within 20 dwells by motion faster
    than twice :data:`STOP_FRACTION` of it. A *reversal* is an
    extremum of the position whose prominence exceeds 10 times the noise; a
    *presliding reversal* one whose excursion to the next reversal stays below
    ``presliding_band``.

    Parameters
    ----------
    measured : Measurement
        The record.
    proc : Processing
        Cut-off and velocity threshold.
    spec : fi_design.spec.Spec, optional
        With an isolator, the cart's motion is examined.
    dwell : float
        Shortest rest [s].
    rest_band : float
        Largest motion during a rest [m].
    presliding_band : float
        Largest excursion of a presliding reversal [m].

    Returns
    -------
    Excitation
    """
    from scipy.ndimage import maximum_filter1d, minimum_filter1d
    from scipy.signal import find_peaks

    fs = proc.sample_rate
    x = np.asarray(measured.position, dtype=float)
    if (measured.deflection is not None and spec is not None and spec.has_isolator):
        x = x - np.asarray(measured.deflection, dtype=float)
    xf = lowpass(x, proc.cutoff, fs)
    noise = float(np.std(x - xf))
    band = max(rest_band, 10.0 * noise)
    v = np.gradient(xf, 1.0 / fs)
    w = max(2, int(round(dwell * fs)))
    lo = minimum_filter1d(xf, w, mode="nearest")
    hi = maximum_filter1d(xf, w, mode="nearest")
    rest = ((hi - lo) < band) | (np.abs(v) < STOP_FRACTION * proc.velocity_threshold)
    edge = int(round(proc.edge * fs))
    inner = slice(edge, len(x) - edge) if len(x) > 2 * edge + 1 else slice(None)
    runs = _runs(rest)
    t = np.asarray(measured.time, dtype=float)
    sliding = np.abs(v) > proc.velocity_threshold
    moving = np.abs(v) > 2.0 * STOP_FRACTION * proc.velocity_threshold
    events = []
    for a, b in runs:
        later = np.nonzero(moving[b:])[0]
        if b - a >= w and len(later) and later[0] <= 20 * w and np.any(sliding[:a]):
            events.append((float(t[a]), float(t[b + int(later[0])])))
    breakaways = len(events)
    prom = max(10.0 * noise, 1e-12)
    ext = np.sort(np.concatenate([find_peaks(xf, prominence=prom)[0],
                                  find_peaks(-xf, prominence=prom)[0]]))
    excursions = np.abs(np.diff(xf[ext])) if len(ext) > 1 else np.zeros(0)
    small = [bool(e < presliding_band) and not np.any(sliding[a:b])
             for e, a, b in zip(excursions, ext[:-1], ext[1:])]
    segments, run = [], []
    for k, ok in enumerate(small):
        if ok:
            run = run or [float(t[ext[k]])]
            run.append(float(t[ext[k + 1]]))
        else:
            if len(run) > 2:
                segments.append(tuple(run))
            run = []
    if len(run) > 2:
        segments.append(tuple(run))
    return Excitation(breakaways=breakaways,
                      rest_time=float(sum(b - a for a, b in runs if b - a >= w) / fs),
                      reversals=int(len(ext)),
                      presliding_reversals=int(np.sum(excursions < presliding_band)),
                      low_speed_time=float(np.sum((np.abs(v) < proc.velocity_threshold)[inner]
                                                  & ~rest[inner]) / fs), dwell=float(dwell),
                      rest_band=float(band), presliding_band=float(presliding_band),
                      events=tuple(events), presliding_segments=tuple(segments))


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """Start and end (exclusive) of every run of True."""
    m = np.concatenate([[False], np.asarray(mask, bool), [False]])
    d = np.diff(m.astype(int))
    return list(zip(np.nonzero(d == 1)[0].tolist(), np.nonzero(d == -1)[0].tolist()))
