"""Gap metrics: how far the nominal and the corrected model miss the record.

Sample-wise measures (the weighted misfit and its excess over noise, RMS
position error per segment kind, force and deflection RMS) and features that
stay meaningful when stick-slip drifts out of phase (hunting cycles,
amplitude and period in the hunting window, the error's spread there,
settling time and final error), each with the noise it is judged against.
A run that failed has NaN after its failure: its gaps are taken over the
samples it has.
"""

from __future__ import annotations

import math

import numpy as np

from ..simulation.metrics import hunting_metrics
from .comparison import Comparison, ModelRun
from ..results.reconciliation import GapMetric


def play(values: np.ndarray, half_width: float) -> np.ndarray:
    """Play (backlash) operator: the output moves only when the input leaves +-half_width.

    Noise smaller than the play leaves a stuck plateau perfectly flat, so peak
    counting sees one peak per stick-slip cycle instead of many noise peaks.
    """
    x = np.asarray(values, dtype=float)
    out = np.empty_like(x)
    if len(x) == 0:
        return out
    y = x[0]
    h = float(half_width)
    for i in range(len(x)):
        v = x[i]
        if v - h > y:
            y = v - h
        elif v + h < y:
            y = v + h
        out[i] = y
    return out


class HuntingWindow:
    """The window the hunting features are counted in (the spec's, when the record has it)."""

    def __init__(self, cmp: Comparison) -> None:
        h = cmp.spec.requirements.hunting
        if (h.window_start + h.window_length <= cmp.duration + 1e-9
                and h.window_start >= cmp.last_move_end):
            self.start, self.length = h.window_start, h.window_length
        else:
            self.start = min(cmp.last_move_end, cmp.duration * 0.5)
            self.length = max(cmp.duration - self.start + 1e-9, 1e-6)


def _hunting(cmp: Comparison, win: HuntingWindow, x: np.ndarray):
    h = cmp.spec.requirements.hunting
    ok = np.isfinite(x)
    e = np.where(ok, x - cmp.meas.reference, 0.0)
    e = play(e, 4.0 * cmp.noise.position)
    return hunting_metrics(cmp.t, e, window_start=win.start, window_length=win.length,
                           min_distance=h.min_distance, min_height=h.min_height,
                           settle_band=h.settle_band, motion_end=cmp.last_move_end,
                           success=bool(ok.all()), failure="" if ok.all() else "failed run")


def _rms(a: np.ndarray, b: np.ndarray, mask: np.ndarray) -> float | None:
    d = (a - b)[mask]
    d = d[np.isfinite(d)]
    if len(d) == 0:
        return None
    return float(np.sqrt(np.mean(d ** 2)))


def _significant(value, noise, factor=1.5):
    if value is None or noise is None:
        return None
    return bool(value > factor * noise)


def gap_metrics(cmp: Comparison, nominal: ModelRun, corrected: ModelRun, chi2_nominal: float,
                chi2_corrected: float) -> tuple[GapMetric, ...]:
    """Every gap measure of the nominal and the corrected model.

    Parameters
    ----------
    cmp : Comparison
        The comparison.
    nominal, corrected : ModelRun
        The two runs.
    chi2_nominal, chi2_corrected : float
        Their weighted squared residuals [-].
    """
    meas, nz, n = cmp.meas, cmp.noise, cmp.n_points
    out: list[GapMetric] = []
    chi_noise = 1.0 + 3.0 * math.sqrt(2.0 / max(n, 1))
    mb, ma = math.sqrt(chi2_nominal / n), math.sqrt(chi2_corrected / n)
    out.append(GapMetric("misfit", "-", "RMS weighted residual of the comparison (1 = noise)",
                         None, None, None, mb, ma, 1.0, bool(mb > chi_noise),
                         bool(ma > chi_noise)))
    eb, ea = max(chi2_nominal / n - 1.0, 0.0), max(chi2_corrected / n - 1.0, 0.0)
    lim = 3.0 * math.sqrt(2.0 / max(n, 1))
    out.append(GapMetric("excess", "-", "mean squared weighted residual beyond noise, "
                                        "chi2 / n - 1 (0 = explained down to noise)",
                         None, None, None, eb, ea, lim, bool(eb > lim), bool(ea > lim)))
    for kind in ("move", "settle", "hold"):
        mask = cmp.kind == kind
        b = _rms(nominal.position, meas.position, mask)
        a = _rms(corrected.position, meas.position, mask)
        out.append(GapMetric(f"position_rms_{kind}", "m",
                             f"RMS of measured minus modelled position in the {kind} segments "
                             "(sample by sample)", None, None, None, b, a, nz.position,
                             _significant(b, nz.position), _significant(a, nz.position)))
    every = np.ones(cmp.n, bool)
    if cmp.has_force:
        b = _rms(nominal.force, meas.force, every)
        a = _rms(corrected.force, meas.force, every)
        out.append(GapMetric("force_rms", "N", "RMS of measured minus modelled commanded force",
                             None, None, None, b, a, nz.force, _significant(b, nz.force),
                             _significant(a, nz.force)))
    if cmp.has_defl:
        b = _rms(nominal.deflection, meas.deflection, every)
        a = _rms(corrected.deflection, meas.deflection, every)
        out.append(GapMetric("deflection_rms", "m", "RMS of measured minus modelled deflection",
                             None, None, None, b, a, nz.deflection,
                             _significant(b, nz.deflection), _significant(a, nz.deflection)))
    out.extend(_features(cmp, nominal, corrected))
    return tuple(out)


def _features(cmp: Comparison, nominal: ModelRun, corrected: ModelRun) -> list[GapMetric]:
    meas, nz = cmp.meas, cmp.noise
    win = HuntingWindow(cmp)
    hm = _hunting(cmp, win, meas.position)
    hn = _hunting(cmp, win, nominal.position)
    hc = _hunting(cmp, win, corrected.position)
    hold = cmp.t >= win.start

    def std_e(x):
        e = (x - meas.reference)[hold]
        e = e[np.isfinite(e)]
        return float(np.std(e)) if len(e) else None

    feats = [
        ("hunting_cycles", "-", "hunting cycles counted in the window (paper metric)",
         float(hm.hunting_cycles), float(hn.hunting_cycles), float(hc.hunting_cycles), 0.5),
        ("hunting_amplitude", "m", "peak-to-peak position error in the window",
         hm.amplitude, hn.amplitude, hc.amplitude, 8.0 * nz.position),
        ("hunting_period", "s", "mean time between hunting peaks",
         hm.period, hn.period, hc.period, None),
        ("error_std_hold", "m", "standard deviation of the position error in the window "
                                "(phase-free)", std_e(meas.position), std_e(nominal.position),
         std_e(corrected.position), 2.0 * nz.position),
        ("settling_time", "s", "time after the last move until the error stays in the "
                               "settle band", hm.settling_time, hn.settling_time,
         hc.settling_time, None),
        ("final_error", "m", "position error at the last sample", hm.final_error,
         hn.final_error, hc.final_error, 3.0 * nz.position),
    ]
    out = []
    for name, unit, desc, vm, vn, vc, noise in feats:
        b = None if vm is None or vn is None else abs(vn - vm)
        a = None if vm is None or vc is None else abs(vc - vm)
        if name == "hunting_period" and vm is not None and hm.hunting_cycles > 2:
            noise = float(np.std(np.diff(hm.peak_times))) or None
        if name == "settling_time":
            noise = max(cmp.settle_window * 0.05, float(np.median(np.diff(cmp.t))))
        out.append(GapMetric(name, unit, desc, vm, vn, vc, b, a, noise,
                             _significant(b, noise, 1.0), _significant(a, noise, 1.0)))
    return out
