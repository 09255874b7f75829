"""Preparing a record for identification: checks, zero-phase filtering, differences, decimation.

The steps 1 to 5 of the package docstring (:mod:`fi_design.identification`):
the record's checks (:func:`check_record`), the documented default settings
(:func:`processing`), the joint of an isolated stage (:func:`joint_model`) and
the filtered, aligned, decimated signals of the inverse-dynamics fit
(:func:`prepare`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..display import number, quantity
from ..errors import DataError
from ..measured import Measurement, check_position_steps, check_time_steps
from ..results.identification import Processing

#: Fewest samples a record must have.
MIN_SAMPLES = 200
#: Order of the Butterworth low-pass (run forwards and backwards).
FILTER_ORDER = 4
#: With a spec: cut-off = this times the loop's crossover.
CROSSOVER_FACTOR = 5.0
#: Without a spec: cut-off = this fraction of the sample rate.
CUTOFF_FRACTION = 0.05
#: The cut-off never exceeds this fraction of the sample rate.
MAX_CUTOFF_FRACTION = 0.25
#: Default velocity threshold: this fraction of the peak speed (99.5th percentile of |v|).
THRESHOLD_FRACTION = 0.1
#: With a spec, the default threshold is at least this times its Stribeck velocity.
STRIBECK_FACTOR = 3.0
#: Samples dropped at each end of the record: this many cut-off periods.
EDGE_PERIODS = 4.0
#: A sample is used when the filtered, decimated sliding indicator is within this of one: a
#: direction change inside the filters' reach would leak up to this times 2 Fc into it.
SLIDE_TOLERANCE = 1e-3
#: Sampling jitter accepted as uniform: fraction of the median step.
JITTER = 0.01
#: Largest factor of one decimation stage (scipy recommends below 13).
MAX_STAGE = 10


def check_record(m: Measurement) -> None:
    """Refuse what the identification cannot take, naming the column and what is needed."""
    src = m.source
    if m.force is None:
        raise DataError("missing: identification needs the actuator force (the commanded "
                        "force in N, a column force_N)", column="force_N", source=src)
    if m.n < MIN_SAMPLES:
        raise DataError(f"too short for identification: {m.n} samples, at least {MIN_SAMPLES} "
                        "needed (a record of sliding motion in both directions)",
                        column="time_s", source=src)
    if float(np.ptp(m.position)) <= 0.0:
        raise DataError("constant: the stage never moves; identification needs a record of "
                        "sliding motion in both directions", column="position_m", source=src)
    if float(np.ptp(m.force)) <= 0.0:
        raise DataError(f"constant: the force is {quantity(float(m.force[0]), 'N', 6)} in every "
                        "row; the friction and the mass are read from how the force changes "
                        "with the motion (is the column the drive's force command, logged?)",
                        column="force_N", source=src)
    check_time_steps(m, jitter=JITTER, needs="the zero-phase filter needs uniform samples",
                     parts="identify each part on its own (fi_design.identification.segment "
                           "cuts a record)")
    check_position_steps(m)


def processing(measured: Measurement, spec=None, *, cutoff: float | None = None,
               decimation: int | None = None,
               velocity_threshold: float | None = None) -> Processing:
    """The filter, decimation and selection settings for a record (the documented defaults).

    Parameters
    ----------
    measured : Measurement
        The record (uniformly sampled).
    spec : fi_design.spec.Spec, optional
        Its loop's crossover sets the default cut-off; its computational delay
        adds to the force alignment.
    cutoff : float, optional
        Cut-off of the low-pass [Hz]; default :data:`CROSSOVER_FACTOR` times
        the loop's crossover with a spec, else :data:`CUTOFF_FRACTION` of the
        sample rate.
    decimation : int, optional
        Decimation factor; default the largest that keeps the cut-off band
        (see the module docstring).
    velocity_threshold : float, optional
        Slowest speed used [m/s]; default :data:`THRESHOLD_FRACTION` of the
        peak speed, with a spec at least :data:`STRIBECK_FACTOR` times its
        Stribeck velocity.

    Returns
    -------
    Processing

    Raises
    ------
    DataError
        A setting the record cannot take (cut-off above the allowed fraction
        of the sample rate, a non-positive threshold or factor).
    """
    fs = 1.0 / measured.sample_period
    top = MAX_CUTOFF_FRACTION * fs
    if cutoff is not None:
        rule = "given"
        if not 0.0 < cutoff <= top:
            raise DataError(f"cut-off {quantity(cutoff, 'Hz', 6)}: must lie in "
                            f"(0, {number(top, 6)}] Hz for a record sampled at "
                            f"{quantity(fs, 'Hz', 6)}", column="time_s", source=measured.source)
    elif spec is not None:
        from ..model import as_model

        fc = as_model(spec).crossover
        cutoff = CROSSOVER_FACTOR * fc
        rule = f"{number(CROSSOVER_FACTOR)} x the loop's crossover ({quantity(fc, 'Hz', 4)})"
    else:
        cutoff = CUTOFF_FRACTION * fs
        rule = f"{number(CUTOFF_FRACTION)} x the sample rate (no spec: loop crossover unknown)"
    if cutoff > top:
        cutoff = top
        rule += f", capped at {number(MAX_CUTOFF_FRACTION)} x the sample rate"
    if decimation is None:
        decimation = _smooth_factor(max(1, int(math.floor(0.8 * fs / (2.0 * cutoff)))))
    elif decimation < 1:
        raise DataError(f"decimation factor {decimation}: must be at least 1", column="time_s",
                        source=measured.source)
    decimation = min(decimation, max(1, measured.n // 50))
    if velocity_threshold is None:
        v = np.gradient(lowpass(measured.position, cutoff, fs), 1.0 / fs)
        velocity_threshold = THRESHOLD_FRACTION * float(np.percentile(np.abs(v), 99.5))
        if spec is not None:
            velocity_threshold = max(velocity_threshold,
                                     STRIBECK_FACTOR * spec.friction.stribeck_velocity)
    elif not velocity_threshold > 0.0:
        raise DataError(f"velocity threshold {velocity_threshold!r}: must be positive [m/s]",
                        column="position_m", source=measured.source)
    delay = spec.controller.delay if spec is not None else 0.0
    return Processing(sample_rate=fs, cutoff=float(cutoff), cutoff_rule=rule,
                      filter_order=FILTER_ORDER, decimation=int(decimation),
                      velocity_threshold=float(velocity_threshold), force_delay=float(delay),
                      force_hold=True, edge=EDGE_PERIODS / float(cutoff))


def _smooth_factor(n: int) -> int:
    """The largest factor <= n whose prime factors are all <= 7 (decimation in stages)."""
    for k in range(n, 0, -1):
        r = k
        for p in (2, 3, 5, 7):
            while r % p == 0:
                r //= p
        if r == 1:
            return k
    return 1


def lowpass(x: np.ndarray, cutoff: float, fs: float) -> np.ndarray:
    from scipy.signal import butter, sosfiltfilt

    sos = butter(FILTER_ORDER, cutoff, fs=fs, output="sos")
    return sosfiltfilt(sos, np.asarray(x, dtype=float))


def decimate(x: np.ndarray, q: int) -> np.ndarray:
    """scipy.signal.decimate (FIR, zero phase) in stages of at most :data:`MAX_STAGE`."""
    from scipy.signal import decimate

    y = np.asarray(x, dtype=float)
    while q > 1:
        f = max(d for d in range(2, MAX_STAGE + 1) if q % d == 0)
        y = decimate(y, f, ftype="fir", zero_phase=True)
        q //= f
    return y


@dataclass(frozen=True)
class Joint:
    """What the spec says about the joint of an isolated stage."""

    model: str                   # rigid | two_mass | two_mass_sum
    k: float | None              # flexure stiffness [N/m]
    c: float | None              # flexure damping [N s/m]
    ratio: float                 # m1 / (m1 + m2) from the spec
    notes: tuple[str, ...]


def joint_model(measured: Measurement, spec) -> Joint:
    has_defl = measured.deflection is not None
    ratio = spec.stage.mass / spec.total_mass if spec is not None else 1.0
    if spec is None:
        notes = ("no spec: the record is taken as one rigid moving mass"
                 + ("; its deflection_m column is not used (the flexure force needs the spec's "
                    "stiffness)" if has_defl else ""),)
        return Joint("rigid", None, None, ratio, notes)
    if not spec.has_isolator:
        notes = ("the spec has no isolator: one rigid moving mass"
                 + ("; the record's deflection_m column is not used" if has_defl else ""),)
        return Joint("rigid", None, None, ratio, notes)
    if not has_defl:
        return Joint("rigid", None, None, ratio, (
            "the spec has an isolator but the record no deflection_m column: the cart's motion "
            "is not measured, so stage and cart are taken as one rigid mass (the joint's "
            "deflection neglected); stage and cart mass are not separable",))
    from ..model import as_model

    iso = spec.isolator
    if iso.stiffness is None:
        return Joint("two_mass_sum", None, None, ratio, (
            "two-mass record without the flexure's stiffness (isolator.stiffness not given): the "
            "flexure force k d + c d' is unknown, so the stage and cart equations cannot be "
            "separated; their sum u = m1 a1 + m2 a2 + F_f(v2) + offset is used with the cart's "
            "motion x2 = x1 - d for the friction and the masses in the spec's ratio: the total "
            "mass is identified, its split between stage and cart is not",))
    c = as_model(spec).joint.damping
    c_note = ("given" if iso.damping is not None else
              "the spec's default (damping ratio 0.05), not a measured value")
    return Joint("two_mass", iso.stiffness, c, ratio, (
        "two-mass record: the flexure force k d + c d' (k = "
        f"{quantity(iso.stiffness, 'N/m', 6)} from the spec, c = {quantity(c, 'N*s/m', 6)}, "
        f"{c_note}) separates the stage equation (stage mass, offset) "
        "from the cart equation (cart mass, friction of the bearing at the cart's velocity); "
        "their accuracy rests on k and c: an error in k biases both masses and the friction",
        "on a two-mass record the offset (stage equation) and Coulomb friction per direction "
        "(cart equation) would both be identifiable, but only if the deflection sensor has no "
        "zero error (k times a zero error is indistinguishable from the offset); the forms are "
        "kept as on one mass for that reason",))


@dataclass
class Prepared:
    """Decimated signals of one record (internal)."""

    time: np.ndarray
    force: np.ndarray            # aligned actuator force u
    a1: np.ndarray               # stage acceleration
    a2: np.ndarray               # cart acceleration (a1 for one mass)
    v: np.ndarray                # velocity of the bearing side (friction)
    joint: np.ndarray | None     # flexure force k d + c d'
    cols: dict                   # nonlinear friction columns, decimated
    used: np.ndarray


def prepare(m: Measurement, proc: Processing, joint: Joint) -> Prepared:
    fs, q = proc.sample_rate, proc.decimation
    t = np.asarray(m.time, dtype=float)
    dt = 1.0 / fs
    x1 = lowpass(m.position, proc.cutoff, fs)
    u = lowpass(m.force, proc.cutoff, fs)
    if proc.force_delay > 0.0:  # the command acts this much later
        u = np.interp(t - proc.force_delay, t, u)
    if proc.force_hold:  # the mean of the two held samples around t_k
        u = np.concatenate([u[:1], 0.5 * (u[1:] + u[:-1])])
    v1 = np.gradient(x1, dt)
    a1 = second_difference(x1, dt)
    raw = np.gradient(np.asarray(m.position, dtype=float), dt)  # filtered once, below
    if joint.model == "rigid":
        v2, a2, fj = v1, a1, None
    else:
        d = lowpass(m.deflection, proc.cutoff, fs)
        dd = np.gradient(d, dt)
        v2 = v1 - dd
        a2 = a1 - second_difference(d, dt)
        raw = raw - np.gradient(np.asarray(m.deflection, dtype=float), dt)
        fj = joint.k * d + joint.c * dd if joint.model == "two_mass" else None
    # the direction from the filtered velocity; the one-sided velocities from the raw one, so
    # that, filtered like the force, they hold the velocity filtered once, as the force does
    pos, neg = (v2 > 0).astype(float), (v2 < 0).astype(float)
    cols = {"one": np.ones_like(v2), "sign": pos - neg, "pos": pos, "neg": neg,
            "vpos": pos * raw, "vneg": neg * raw,
            "slide": (np.abs(v2) > proc.velocity_threshold).astype(float)}
    # the same low-pass and decimation as the force: the equation holds on the filtered data
    dec = {k: decimate(lowpass(c, proc.cutoff, fs), q) for k, c in cols.items()}
    td = t[::q]
    vd = decimate(v2, q)
    # sliding faster than the threshold throughout the filters' reach ("one": their own gain)
    used = np.abs(dec["slide"] - dec["one"]) < SLIDE_TOLERANCE * dec["one"]
    used &= (td >= t[0] + proc.edge) & (td <= t[-1] - proc.edge)
    return Prepared(time=td, force=decimate(u, q), a1=decimate(a1, q), a2=decimate(a2, q),
                     v=vd, joint=None if fj is None else decimate(fj, q), cols=dec, used=used)


def second_difference(x: np.ndarray, dt: float) -> np.ndarray:
    """Acceleration by the second central difference (x[k+1] - 2 x[k] + x[k-1]) / dt^2."""
    a = np.empty_like(x)
    a[1:-1] = np.diff(x, 2) / (dt * dt)
    a[0], a[-1] = a[1], a[-2]
    return a


# --------------------------------------------------------------------------- full-rate trace


@dataclass
class Trace:
    """Filtered full-rate signals of the bearing side, for the dynamic parameters (internal).

    The friction force on the bearing is ``u - sum(theta[name] * inertia[name]) - offset``
    for the inverse-dynamics estimates ``theta``: see :func:`friction_force`.
    """

    time: np.ndarray             # [s]
    x: np.ndarray                # bearing-side position (stage, or cart x1 - d) [m]
    v: np.ndarray                # its velocity [m/s]
    u: np.ndarray                # aligned actuator force [N]
    inertia: dict                # IDIM mass parameter -> its acceleration column [m/s^2]
    sx: float                    # noise of the filtered position [m]
    su: float                    # noise of the filtered force [N]
    sv: float                    # noise of the filtered velocity [m/s]
    sa: float                    # noise of the filtered acceleration [m/s^2]
    resolution: float            # the position's resolution: one count or its noise [m]
    reach: int                   # samples within the zero-phase filter's reach
    compliance: float            # joint compliance in series with the bearing in x [m/N]


#: The zero-phase filter's reach on either side of an event: this many cut-off periods.
REACH_PERIODS = 2.0


def robust_std(x: np.ndarray) -> float:
    """Standard deviation from the median absolute deviation (robust to transients)."""
    from scipy.stats import median_abs_deviation

    return float(median_abs_deviation(np.asarray(x, dtype=float), scale="normal"))


def resolution(position: np.ndarray) -> float:
    """One count of a quantized position column [m]: its smallest nonzero step (0 if none)."""
    d = np.abs(np.diff(np.asarray(position, dtype=float)))
    scale = float(np.max(np.abs(position))) if len(d) else 0.0
    d = d[d > 1e-12 * max(scale, 1e-300)]
    return float(np.min(d)) if len(d) else 0.0


def noise_gains(cutoff: float, fs: float) -> tuple[float, float, float]:
    """RMS gains of white noise through the zero-phase low-pass: value, derivative, second.

    For white noise of standard deviation s sampled at ``fs``, the filtered
    signal has ``s * g0``, its derivative ``s * g1`` [1/s] and its second
    derivative ``s * g2`` [1/s^2], from the filter's response
    (:func:`scipy.signal.sosfreqz`; forwards and backwards: ``|H|^4`` in power).
    """
    from scipy.integrate import trapezoid
    from scipy.signal import butter, sosfreqz

    sos = butter(FILTER_ORDER, cutoff, fs=fs, output="sos")
    f, h = sosfreqz(sos, worN=4096, fs=fs)
    p = np.abs(h) ** 4 / (fs / 2.0)
    w = 2.0 * np.pi * f
    return (math.sqrt(trapezoid(p, f)), math.sqrt(trapezoid(p * w ** 2, f)),
            math.sqrt(trapezoid(p * w ** 4, f)))


def trace(m: Measurement, proc: Processing, joint: Joint, spec=None) -> Trace:
    """The filtered full-rate signals of the bearing side and their noise levels.

    Position, force (and deflection) pass the low-pass of the fit, the force
    is aligned as for the fit (delay, hold); velocity and acceleration are
    central differences. On a two-mass record the bearing side is the cart,
    x1 - d, and the inertia has a stage and a cart column. The noise levels
    are robust estimates (median absolute deviation) of the raw columns'
    noise, carried through the filter (:func:`noise_gains`); a quantized
    position adds its count / sqrt(12).
    """
    fs = proc.sample_rate
    fc = proc.cutoff
    dt = 1.0 / fs
    t = np.asarray(m.time, dtype=float)
    pos = np.asarray(m.position, dtype=float)
    x1 = lowpass(pos, fc, fs)
    u = lowpass(m.force, fc, fs)
    if proc.force_delay > 0.0:
        u = np.interp(t - proc.force_delay, t, u)
    if proc.force_hold:
        u = np.concatenate([u[:1], 0.5 * (u[1:] + u[:-1])])
    a1 = second_difference(x1, dt)
    raw_x = pos
    if joint.model == "rigid":
        x, inertia = x1, {"mass": a1}
    else:
        d = lowpass(m.deflection, fc, fs)
        x = x1 - d
        raw_x = pos - np.asarray(m.deflection, dtype=float)
        a2 = a1 - second_difference(d, dt)
        inertia = ({"stage_mass": a1, "cart_mass": a2} if joint.model == "two_mass" else
                   {"mass": joint.ratio * a1 + (1.0 - joint.ratio) * a2})
    count = resolution(raw_x)
    sx_raw = math.hypot(robust_std(raw_x - lowpass(raw_x, fc, fs)), count / math.sqrt(12))
    su_raw = robust_std(np.asarray(m.force, dtype=float) - lowpass(m.force, fc, fs))
    g0, g1, g2 = noise_gains(fc, fs)
    compliance = 0.0
    if (joint.model == "rigid" and spec is not None and spec.has_isolator
            and spec.isolator.stiffness is not None):
        compliance = 1.0 / spec.isolator.stiffness
    return Trace(time=t, x=x, v=np.gradient(x, dt), u=u, inertia=inertia, sx=sx_raw * g0,
                 su=su_raw * g0, sv=sx_raw * g1, sa=sx_raw * g2, resolution=max(count, sx_raw),
                 reach=max(1, int(round(REACH_PERIODS * fs / fc))),
                 compliance=compliance)
