"""Signatures in the nominal residual: what each effect would leave behind.

Regressions of the nominal residual (force when recorded, else position) on
what each effect would leave behind: velocity (viscous), a low-velocity bump
(Stribeck), a spatial period (position-dependent friction, force ripple;
Lomb-Scargle periodogram over position), position (cable), reference
acceleration (mass), the mean per direction (offset, asymmetric friction),
the lag between measured and modelled force (delay), force above a level
(saturation) and the deflection rate (joint damping). The lattice of the
measured positions (:mod:`.lattice`) is the quantization's signature. They
give the fits their starting values and are reported as evidence; they decide
nothing.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from .comparison import Comparison, ModelRun
from .periodogram import lomb_scargle
from ..results.reconciliation import Lattice, Signature
from ..display import fixed, number, quantities, quantity


class Line(NamedTuple):
    """Least-squares line y = intercept + slope x and its R^2."""

    intercept: float
    slope: float
    r2: float


class Period(NamedTuple):
    """A peak of a periodogram over position."""

    wavelength: float
    amplitude: float
    ratio: float


@dataclass(frozen=True)
class Evidence:
    """Signatures of the nominal residual and the starting values they suggest.

    Attributes
    ----------
    signatures : tuple of Signature
        Strongest first.
    guesses : dict of str to list of dict
        Per effect, starting parameter values (SI).
    periods : tuple of Period
        Peaks of the residual's periodogram over position, strongest first.
    """

    signatures: tuple
    guesses: dict = field(default_factory=dict)
    periods: tuple = ()


def fit_line(y: np.ndarray, x: np.ndarray) -> Line:
    """Least-squares y = a + b x with its R^2 (zeros for too few points or constant x)."""
    if len(y) < 5 or np.ptp(x) == 0:
        return Line(0.0, 0.0, 0.0)
    A = np.column_stack([np.ones_like(x), x])
    coef, *_ = np.linalg.lstsq(A, y, rcond=None)
    fit = A @ coef
    ss = float(np.sum((y - np.mean(y)) ** 2))
    r2 = 1.0 - float(np.sum((y - fit) ** 2)) / ss if ss > 0 else 0.0
    return Line(float(coef[0]), float(coef[1]), max(0.0, r2))


def spatial_periods(x: np.ndarray, y: np.ndarray, lo: float, hi: float,
                    n_peaks: int = 3) -> list[Period]:
    """Peaks of a Lomb-Scargle periodogram of y over position x, strongest first.

    The ratio of a peak is its power over the median power; the amplitude
    is in the unit of y.
    """
    if len(x) < 50 or np.ptp(x) < 2 * lo:
        return []
    span = float(np.ptp(x))
    hi = min(hi, span / 1.5)
    if hi <= lo:
        return []
    n_f = int(min(20000, max(500, 8 * span / lo)))
    k = np.linspace(2 * np.pi / hi, 2 * np.pi / lo, n_f)
    yc = y - np.mean(y)
    # detrend linearly in x so a cable-like slope does not leak into long periods
    line = fit_line(yc, x)
    yc = yc - (line.intercept + line.slope * x)
    if len(x) > 6000:
        sel = np.linspace(0, len(x) - 1, 6000).astype(int)
        x, yc = x[sel], yc[sel]
    p = lomb_scargle(x, yc, k)
    med = float(np.median(p)) or 1e-300
    out: list[Period] = []
    for j in np.argsort(p)[::-1]:
        lam = 2 * np.pi / k[j]
        if any(abs(lam - t.wavelength) / t.wavelength < 0.05 for t in out):
            continue
        out.append(Period(float(lam), float(math.sqrt(4.0 * p[j] / len(x))), float(p[j] / med)))
        if len(out) >= n_peaks:
            break
    return out


def scan(cmp: Comparison, nominal: ModelRun, lattice: Lattice, params) -> Evidence:
    """Signatures in the nominal residual and the starting guesses they imply.

    Parameters
    ----------
    cmp : Comparison
        The comparison (record, segments, reference velocity).
    nominal : ModelRun
        The nominal model's run.
    lattice : Lattice
        The lattice of the measured positions.
    params : PlantParameters
        Kernel parameters of the nominal model (the values guesses start from).
    """
    meas = cmp.meas
    sigs: list[Signature] = []
    guesses: dict[str, list[dict]] = {}
    use_force = cmp.has_force
    res = (meas.force - nominal.force) if use_force else (meas.position - nominal.position)
    unit = "N" if use_force else "m"
    coh = cmp.coherent
    move = (cmp.kind == "move") & coh
    v = cmp.v_ref
    x = meas.position
    periods: list[Period] = []

    def add(name, effects, r2, value, vunit, detail):
        sigs.append(Signature(name, tuple(effects), float(r2), value, vunit, detail))

    if move.sum() > 20:
        line = fit_line(res[move], v[move])
        add("velocity", ["viscous_friction"], line.r2, line.slope, f"{unit}/(m/s)",
            f"the {'force' if use_force else 'position'} residual follows the velocity during "
            f"moves (slope {quantity(line.slope, f'{unit} s/m', 3)}, R^2 {fixed(line.r2, 2)})")
        if use_force:
            guesses.setdefault("viscous_friction", []).append(
                {"viscous": params.sigma2 + line.slope})
        bump = np.sign(v) * np.exp(-(v / (3 * params.vs)) ** 2)
        sl = (cmp.kind != "hold") & coh
        low = fit_line(res[sl], bump[sl])
        add("low_velocity", ["stribeck_velocity"], low.r2, low.slope, unit,
            "the residual concentrates at low speed (amplitude "
            f"{quantity(low.slope, unit, 3)}, R^2 {fixed(low.r2, 2)})")
        acc = fit_line(res[sl], cmp.a_ref[sl])
        add("acceleration", ["mass_error"], acc.r2, acc.slope, f"{unit}/(m/s^2)",
            f"the residual follows the reference acceleration (slope {number(acc.slope, 3)}, "
            f"R^2 {fixed(acc.r2, 2)})")
        if use_force:
            f = 1.0 + acc.slope / (params.m1 + params.m2)
            guesses.setdefault("mass_error", []).append(
                {"stage_mass": params.m1 * f, "cart_mass": params.m2 * f})
            _direction(res, v, move, params, add, guesses)
        fast = move & (np.abs(v) > 0.2 * np.max(np.abs(v)))
        periods = spatial_periods(x[fast], res[fast], 2e-4, 0.05, n_peaks=5)
        if periods:
            top = periods[0]
            strength = min(1.0, top.amplitude ** 2 / 2 / max(np.var(res[fast]), 1e-300))
            add("spatial_period", ["position_dependent_friction", "force_ripple"], strength,
                top.wavelength, "m",
                f"the residual repeats along the travel with a period of "
                f"{quantity(top.wavelength, 'm', 4)} (amplitude "
                f"{quantity(top.amplitude, unit, 3)}, {number(top.ratio, 2)} x the median "
                "spectral power)")
    trend = fit_line(res[coh], x[coh] - x[0])
    add("position_trend", ["cable_force"], trend.r2, trend.slope, f"{unit}/m",
        f"the residual grows with position (slope {quantity(trend.slope, f'{unit}/m', 3)}, "
        f"R^2 {fixed(trend.r2, 2)})")
    if use_force:
        guesses.setdefault("cable_force", []).append(
            {"stiffness": trend.slope, "preload": trend.intercept})
    if use_force and move.sum() > 50:
        lag = force_lag(meas.force, nominal.force, cmp.t, max_lag=0.02)
        add("force_lag", ["time_delay"], lag.correlation if lag.lag > 0 else 0.0, lag.lag, "s",
            "the measured force lags the modelled one by "
            f"{quantity(lag.lag, 's', 3, shown=('ms', 1e3))} "
            f"(correlation {fixed(lag.correlation, 2)})")
        if lag.lag > 0:
            guesses.setdefault("time_delay", []).append({"delay": lag.lag})
    if lattice.found:
        add("lattice", ["quantization"], lattice.fraction, lattice.step, "m", lattice.detail)
    if use_force:
        _saturation(res, meas.force, coh, add, guesses)
    if cmp.has_defl:
        dres = meas.deflection - nominal.deflection
        rate = np.gradient(_smooth(meas.deflection, 11), cmp.t)
        dl = fit_line(dres[coh], rate[coh])
        add("deflection_rate", ["joint_damping"], dl.r2, dl.slope, "s",
            f"the deflection residual follows the deflection rate (R^2 {fixed(dl.r2, 2)})")
    sigs.sort(key=lambda s: -s.strength)
    return Evidence(signatures=tuple(sigs), guesses=guesses, periods=tuple(periods))


def _direction(res, v, move, params, add, guesses) -> None:
    """Mean force residual per direction: an offset shifts both, asymmetry only one."""
    pos, neg = move & (v > 0), move & (v < 0)
    if pos.sum() < 10 or neg.sum() < 10:
        return
    m_pos, m_neg = float(np.mean(res[pos])), float(np.mean(res[neg]))
    spread = float(np.std(res[move])) or 1e-300
    strength = min(1.0, (0.5 * (m_pos ** 2 + m_neg ** 2)) / spread ** 2)
    forward, back = quantities([m_pos, m_neg], "N", 3)
    add("direction", ["force_offset", "friction_asymmetry"], strength, m_neg - m_pos, "N",
        f"the force residual averages {forward} moving forward and {back} moving "
        "back (an offset shifts both alike, asymmetric friction only one)")
    guesses.setdefault("force_offset", []).append({"offset": params.offset + 0.5 * (m_pos + m_neg)})
    back = fit_line(res[neg], v[neg])
    fc_neg = params.Fc if math.isnan(params.Fc_neg) else params.Fc_neg
    s2_neg = params.sigma2 if math.isnan(params.sigma2_neg) else params.sigma2_neg
    guesses.setdefault("friction_asymmetry", []).append(
        {"coulomb_negative": fc_neg - back.intercept, "viscous_negative": s2_neg + back.slope})


def _saturation(res, force, coh, add, guesses) -> None:
    """The residual appearing where |force| exceeds a level (a force limit)."""
    umax = float(np.max(np.abs(force)))
    best_r2, best_level = 0.0, None
    for level in np.quantile(np.abs(force), [0.5, 0.7, 0.8, 0.9, 0.95, 0.98]):
        g = np.sign(force) * np.maximum(np.abs(force) - level, 0.0)
        if np.ptp(g) == 0:
            continue
        r2 = fit_line(res[coh], g[coh]).r2
        if r2 > best_r2:
            best_r2, best_level = r2, float(level)
    if best_level is not None:
        add("force_above_level", ["force_saturation"], best_r2, best_level, "N",
            f"the residual appears where |force| exceeds {quantity(best_level, 'N', 3)} "
            f"(peak {quantity(umax, 'N', 3)}, R^2 {fixed(best_r2, 2)})")
        guesses.setdefault("force_saturation", []).append({"limit": best_level})


def _smooth(y: np.ndarray, n: int) -> np.ndarray:
    if len(y) < n:
        return np.asarray(y, float)
    k = np.ones(n) / n
    return np.convolve(np.pad(y, n // 2, mode="edge"), k, mode="valid")


class Lag(NamedTuple):
    """Lag of one signal behind another and the correlation at that lag."""

    lag: float
    correlation: float


def force_lag(a: np.ndarray, b: np.ndarray, t: np.ndarray, max_lag: float) -> Lag:
    """Lag of ``a`` behind ``b`` [s] maximising the correlation of their changes."""
    dt = float(np.median(np.diff(t)))
    da = np.diff(a)
    db = np.diff(b)
    m = int(max_lag / dt)
    sa, sb = np.std(da), np.std(db)
    if sa == 0 or sb == 0 or len(da) < 4 * m + 10:
        return Lag(0.0, 0.0)
    best = Lag(0.0, -1.0)
    for k in range(0, m + 1):
        c = float(np.mean((da[k:] - da[k:].mean()) * (db[:len(db) - k] - db[:len(db) - k].mean()))
                  / (sa * sb))
        if c > best.correlation:
            best = Lag(k * dt, c)
    return Lag(best.lag, max(0.0, best.correlation))
