"""Friction identification from a measured record: guideline step 1 from data (DESIGN.md section 8).

:func:`identify` estimates the moving mass, Coulomb and viscous friction and a
force offset from a measured record (position and actuator force), with
standard errors, by the inverse-dynamics least squares of robot and
machine-tool identification (IDIM-LS, Gautier and Khalil; Janot et al. for the
EMPS axis):

1. **Zero-phase low-pass.** Position, force (and joint deflection) pass a
   Butterworth filter of order :data:`FILTER_ORDER` forwards and backwards
   (:func:`scipy.signal.sosfiltfilt`: no phase lag, the magnitude squared).
   Cut-off: :data:`CROSSOVER_FACTOR` times the loop's crossover when a spec is
   given (the filter must pass the closed-loop dynamics undistorted), else
   :data:`CUTOFF_FRACTION` of the sample rate; never above
   :data:`MAX_CUTOFF_FRACTION` of it. Because every term of the equation of
   motion but the sign of the velocity is linear, filtering both sides keeps
   the equation.
2. **Central differences** of the filtered position give the velocity
   (:func:`numpy.gradient`) and the acceleration (the second central
   difference ``(x[k+1] - 2 x[k] + x[k-1]) / T^2``). ``force_N`` is usually
   a command held by the controller's zero-order hold over the sample
   interval after it; the second difference of the position of a mass
   pushed by a held force is then exactly the mean of the two force samples
   around t_k (the hold equivalent of the double integrator,
   ``T^2 (z + 1) / (2 m (z - 1)^2)``), and that mean is used. Whether the
   force is held or a sampled continuous signal is decided from the data:
   the reading that fits better (:attr:`Processing.force_hold`). A
   computational delay of the spec shifts the force by interpolation.
4. **Parallel filtering and decimation.** Every regressor column, the
   nonlinear ones (sign and one-sided parts of the velocity) included, passes
   the same low-pass as the force, then :func:`scipy.signal.decimate` (a
   Hamming-window FIR low-pass without phase shift, then every n-th sample)
   with the force alike: the equation holds on the filtered data exactly,
   away from direction changes. The factor is the largest
   whose anti-alias edge (0.8 of the new Nyquist frequency) stays at or above
   the cut-off, so it removes no band the fit uses; it thins the strongly
   correlated samples.
5. **Sample selection.** Only sliding samples are used: speed above the
   velocity threshold throughout the filters' reach (the indicator of
   sliding, filtered and decimated like the data, stays within
   :data:`SLIDE_TOLERANCE` of one;
   default threshold :data:`THRESHOLD_FRACTION` of the peak speed,
   with a spec at least :data:`STRIBECK_FACTOR` times its Stribeck velocity;
   below it friction is not Coulomb plus viscous: Stribeck effect,
   presliding, sticking); the first and last :data:`EDGE_PERIODS` cut-off periods
   are dropped (filter transients).
6. **Weighted least squares** (:func:`scipy.linalg.lstsq` on
   column-normalised regressors). One equation (a rigid stage): ordinary least
   squares. Two equations (stage and cart of an isolated stage, see below):
   each equation is weighted by the inverse of its residual variance from a
   first unweighted pass (the IDIM-WLS of Gautier).
7. **Standard errors** from the residual variance, ``s^2 (A^T W A)^-1``,
   corrected for the autocorrelation of the residuals of filtered, decimated
   data by an **effective sample count** ``n_eff = n / (1 + 2 sum rho_k)``,
   the autocorrelations ``rho_k`` summed up to the first lag at which they are
   no longer positive (the initial positive sequence); the covariance is
   scaled by ``n / n_eff``. (Not a bootstrap.)

The model (DESIGN.md sections 2 and 8): the actuator force u (``force_N``,
the force that acts, an injected ``disturbance_N`` included) moves the total
mass against friction and a constant offset::

    u = M a + Fc sign(v) + Fv+ max(v, 0) + Fv- min(v, 0) + offset      (symmetric form)
    u = M a + Fc+ [v > 0] - Fc- [v < 0] + Fv+ max(v, 0) + Fv- min(v, 0)  (per-direction form)

On sliding data [v > 0] + [v < 0] = 1, so the Coulomb friction per
direction and an offset are collinear: only three of the four constants are
identifiable. The two forms fit the data identically; they are two readings
of the same direction-dependent constant force (Fc+ = Fc + offset,
Fc- = Fc - offset). They differ at standstill, which sliding data do not see.

With an isolator (a spec with one and a record with ``deflection_m``): the
flexure force k d + c d' (k, c from the spec) splits the record into the
stage equation ``u - k d - c d' = m1 a1 + offset`` and the cart equation
``k d + c d' = m2 a2 + F_f(v2)``, with the cart's motion x2 = x1 - d. Without
the spec's stiffness the flexure force is unknown: only the sum of the two
equations, ``u = m1 a1 + m2 a2 + F_f(v2) + offset``, is used, with the
masses in the spec's ratio (the total is identified, its split is not).

LuGre's dynamic parameters (static friction, Stribeck velocity, bristle
stiffness) need an excitation that sliding data do not hold: a breakaway
from rest, or a slow velocity sweep through zero (static friction and
Stribeck velocity), small-amplitude reversals in presliding (bristle
stiffness). :func:`excitation` detects them in the record. They are never
estimated here: every one is reported as not identifiable, with no value,
and a note that says whether the record holds its excitation (and where) and
which experiment identifies it. A fit of the replayed record
(:func:`fi_design.simulate` with ``record=``) to the breakaways was built and
validated on simulated records, and rejected: the replay of a stick-slip
record is so sensitive to the sliding friction that sub-percent errors in
it (within their standard errors) moved the static friction and Stribeck
velocity by many of their own standard errors.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from types import MappingProxyType
from typing import Any, Callable, Mapping

import numpy as np

from .errors import DataError
from .measured import Measurement, measurement_from_arrays
from .results import dataclass_dict, frozen_array

#: Parameters of an identification, in the order of DESIGN.md section 8.
NAMES = ("mass", "coulomb", "coulomb_negative", "viscous", "viscous_negative", "offset",
         "static", "stribeck_velocity", "bristle_stiffness")
#: SI unit of every parameter.
UNITS = MappingProxyType({"mass": "kg", "coulomb": "N", "coulomb_negative": "N",
                          "viscous": "N*s/m", "viscous_negative": "N*s/m", "offset": "N",
                          "static": "N", "stribeck_velocity": "m/s", "bristle_stiffness": "N/m"})
#: The forms of the Coulomb part: one Coulomb value and an offset, or one per direction.
FORMS = ("symmetric", "per_direction")
#: LuGre parameters that need a dynamic excitation.
DYNAMIC = ("static", "stribeck_velocity", "bristle_stiffness")

#: Fewest samples a record must have.
MIN_SAMPLES = 200
#: Fewest used (decimated, sliding) samples per direction of motion.
MIN_DIRECTION_SAMPLES = 10
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

#: A rest: the stage moves less than REST_BAND (or 10 x the position noise) for DWELL.
DWELL = 0.05
#: See :data:`DWELL` [m].
REST_BAND = 1e-6
#: A presliding reversal: the excursion between two reversals stays below this [m].
PRESLIDING_BAND = 50e-6
#: Fewest events (breakaways, presliding reversals) that count as an excitation.
MIN_EVENTS = 3

ProgressCallback = Callable[[str, float], None]

_IMPLAUSIBLE = ("physically impossible, so the model (mass, Coulomb and viscous friction "
                "constant along the travel) does not describe this record; an unmodelled effect "
                "(friction varying along the rail, a cable force, force ripple) or too little "
                "sliding can cause it, and fi-design reconcile names such effects")

_EXPERIMENT = {
    "static": "a slow velocity sweep through zero (the reference's velocity ramped slowly "
              "across zero), or moves that come to rest and break away again",
    "stribeck_velocity": "a slow velocity sweep through zero, from a few times the expected "
                         "Stribeck velocity in one direction to the same in the other, slow "
                         "enough that the inertial force stays small against friction",
    "bristle_stiffness": "a small-amplitude sine or small steps in presliding (excursions of "
                         "a few micrometres, below the breakaway displacement), resolved by "
                         "the position sensor",
}


# --------------------------------------------------------------------------- results


@dataclass(frozen=True)
class Parameter:
    """One identified parameter.

    Attributes
    ----------
    value : float or None
        Estimate in SI (``unit``); None when not identifiable from the record.
    std_error : float or None
        Standard error of the estimate (autocorrelation-corrected), in ``unit``;
        None when not identifiable.
    unit : str
        SI unit.
    identifiable : bool
        Whether the record holds the information to estimate it.
    note : str
        How it was estimated, or why not and which experiment would identify it.
    """

    value: float | None
    std_error: float | None
    unit: str
    identifiable: bool
    note: str

    def to_dict(self) -> dict:
        """Plain JSON data (DESIGN.md section 8)."""
        return dataclass_dict(self)


@dataclass(frozen=True)
class Fit:
    """Statistics of the inverse-dynamics fit, on the used samples.

    Attributes
    ----------
    force_rms_residual : float
        RMS of measured minus modelled actuator force [N] (filtered, decimated,
        sliding samples; for a two-mass record, of the summed equation).
    relative_error : float
        ||u - u_model|| / ||u|| on the same samples [-].
    condition_number : float
        Condition number of the (weighted) regressor with its columns scaled
        to unit norm [-]; large values mean nearly collinear parameters.
    samples_used : int
        Decimated samples in the fit (per equation for a two-mass record).
    effective_samples : float
        Effective number of independent samples after the autocorrelation
        correction.
    error_method : str
        How the standard errors were obtained.
    """

    force_rms_residual: float
    relative_error: float
    condition_number: float
    samples_used: int
    effective_samples: float
    error_method: str

    def to_dict(self) -> dict:
        """Plain JSON data."""
        return dataclass_dict(self)


@dataclass(frozen=True)
class Processing:
    """How the record was prepared; :func:`predict_force` reuses it on other records.

    Attributes
    ----------
    sample_rate : float
        Sample rate of the record [Hz].
    cutoff : float
        Cut-off of the zero-phase Butterworth low-pass [Hz].
    cutoff_rule : str
        Where the cut-off came from.
    filter_order : int
        Order of the Butterworth filter (applied forwards and backwards).
    decimation : int
        Decimation factor [-].
    velocity_threshold : float
        Samples slower than this are not used [m/s].
    force_delay : float
        The filtered force is read this much later [s]: the spec's
        computational delay.
    force_hold : bool
        Whether ``force_N`` is taken as a command held over each sample
        interval (zero-order hold) rather than a sampled continuous force;
        chosen by :func:`identify` as the reading that fits the record better.
    edge : float
        Time dropped at each end of the record [s].
    """

    sample_rate: float
    cutoff: float
    cutoff_rule: str
    filter_order: int
    decimation: int
    velocity_threshold: float
    force_delay: float
    force_hold: bool
    edge: float

    def to_dict(self) -> dict:
        """Plain JSON data."""
        return dataclass_dict(self)


@dataclass(frozen=True)
class Excitation:
    """What the record holds for LuGre's dynamic parameters.

    Attributes
    ----------
    breakaways : int
        Rests of at least ``dwell`` (the bearing side moves less than
        ``rest_band``) followed by sliding above the velocity threshold.
    rest_time : float
        Total time at rest [s].
    reversals : int
        Reversals of the direction of motion (resolved above the noise).
    presliding_reversals : int
        Reversals whose excursion to the next reversal stays below
        ``presliding_band``.
    low_speed_time : float
        Time the bearing side moves, but slower than the velocity threshold,
        between the edges of the record [s]: where static friction and the
        Stribeck effect act.
    dwell : float
        Shortest rest counted [s].
    rest_band : float
        Largest motion during a rest [m].
    presliding_band : float
        Largest excursion of a presliding reversal [m].
    events : tuple of (float, float)
        Per breakaway: the start of the rest and the time the stage slides
        again [s].
    """

    breakaways: int
    rest_time: float
    reversals: int
    presliding_reversals: int
    low_speed_time: float
    dwell: float
    rest_band: float
    presliding_band: float
    events: tuple[tuple[float, float], ...] = ()

    @property
    def breakaway(self) -> bool:
        """Whether the record excites static friction and the Stribeck velocity."""
        return self.breakaways >= MIN_EVENTS

    @property
    def presliding(self) -> bool:
        """Whether the record excites the bristle stiffness."""
        return self.presliding_reversals >= MIN_EVENTS

    def to_dict(self) -> dict:
        """Plain JSON data, with the two verdicts."""
        d = dataclass_dict(self)
        d.update(breakaway=self.breakaway, presliding=self.presliding)
        return d


@dataclass(frozen=True)
class Masses:
    """Stage and cart mass: identified separately (isolator with known stiffness) or split.

    Attributes
    ----------
    stage : float
        Stage mass m1 [kg].
    cart : float
        Cart mass m2 [kg].
    stage_std_error, cart_std_error : float or None
        Standard errors [kg]; None when the split is not identified.
    source : str
        ``"identified"`` or ``"split in the spec's ratio"``.
    """

    stage: float
    cart: float
    stage_std_error: float | None
    cart_std_error: float | None
    source: str

    def to_dict(self) -> dict:
        """Plain JSON data."""
        return dataclass_dict(self)


@dataclass(frozen=True, eq=False)
class Samples:
    """The samples of the fit, for plots (decimated rate).

    Attributes
    ----------
    time : ndarray, shape (n,)
        Sample times [s].
    velocity : ndarray, shape (n,)
        Velocity of the bearing side (the stage, or the cart of an isolated
        stage) [m/s].
    force : ndarray, shape (n,)
        Measured actuator force, filtered and aligned [N].
    model : ndarray, shape (n,)
        Modelled actuator force [N].
    inertia : ndarray, shape (n,)
        The modelled inertial force (mass times acceleration) [N].
    used : ndarray of bool, shape (n,)
        Samples in the fit (sliding, away from the edges).
    """

    time: np.ndarray
    velocity: np.ndarray
    force: np.ndarray
    model: np.ndarray
    inertia: np.ndarray
    used: np.ndarray

    @property
    def friction(self) -> np.ndarray:
        """Measured friction plus offset: force minus the modelled inertial force [N]."""
        return self.force - self.inertia

    @property
    def residual(self) -> np.ndarray:
        """Measured minus modelled force [N]."""
        return self.force - self.model

    def to_dict(self) -> dict:
        """Plain JSON data (lists)."""
        return dataclass_dict(self)


@dataclass(frozen=True, eq=False)
class IdentificationResult:
    """Friction and mass identified from a measured record (DESIGN.md section 8).

    Attributes
    ----------
    parameters : mapping of str to Parameter
        Every name of :data:`NAMES`, in that order: ``mass`` (total moving
        mass, kg), ``coulomb``, ``coulomb_negative`` (N), ``viscous``,
        ``viscous_negative`` (N s/m), ``offset`` (N), ``static`` (N),
        ``stribeck_velocity`` (m/s), ``bristle_stiffness`` (N/m).
    fit : Fit
        Statistics of the inverse-dynamics fit.
    form : str
        ``"symmetric"`` (one Coulomb friction and an offset) or
        ``"per_direction"`` (Coulomb friction per direction, no offset).
    model : str
        ``"rigid"`` (one mass), ``"two_mass"`` (stage and cart equations with
        the spec's flexure force) or ``"two_mass_sum"`` (their sum, the
        flexure force unknown).
    masses : Masses
        Stage and cart mass.
    processing : Processing
        Filter, decimation and selection settings.
    excitation : Excitation
        What the record holds for the dynamic parameters.
    notes : tuple of str
        What is and is not identifiable, and why.
    samples : Samples
        The fitted samples, for plots.
    measurement : Measurement
        The record.
    spec : fi_design.spec.Spec or None
        The spec, when given.
    """

    parameters: Mapping[str, Parameter]
    fit: Fit
    form: str
    model: str
    masses: Masses
    processing: Processing
    excitation: Excitation
    notes: tuple[str, ...]
    samples: Samples = field(repr=False)
    measurement: Measurement = field(repr=False)
    spec: Any = field(default=None, repr=False)

    def value(self, name: str) -> float | None:
        """The value of parameter ``name`` [SI], or None."""
        return self.parameters[name].value

    def to_dict(self) -> dict:
        """Plain JSON data: ``parameters``, ``fit`` (DESIGN.md section 8) and the context."""
        from . import __version__

        return {
            "parameters": {k: p.to_dict() for k, p in self.parameters.items()},
            "fit": self.fit.to_dict(),
            "form": self.form,
            "model": self.model,
            "masses": self.masses.to_dict(),
            "processing": self.processing.to_dict(),
            "excitation": self.excitation.to_dict(),
            "notes": list(self.notes),
            "measurement": self.measurement.to_dict(),
            "fi_design_version": __version__,
        }


@dataclass(frozen=True, eq=False)
class ForcePrediction:
    """The identified model's actuator force on a record (cross-validation, plots).

    Attributes
    ----------
    samples : Samples
        Measured and modelled force at the decimated samples.
    force_rms_residual : float
        RMS of measured minus modelled force on the used samples [N].
    relative_error : float
        ||u - u_model|| / ||u|| on the used samples [-].
    samples_used : int
        Samples compared.
    """

    samples: Samples
    force_rms_residual: float
    relative_error: float
    samples_used: int


# --------------------------------------------------------------------------- checks


def _check_record(m: Measurement) -> None:
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
    dt = np.diff(m.time)
    med = float(np.median(dt))
    worst = float(np.max(np.abs(dt - med)))
    if worst > JITTER * med:
        i = int(np.argmax(np.abs(dt - med)))
        raise DataError(
            f"non-uniform sampling: the step between rows {i + 1} and {i + 2} is {dt[i]:.6g} s, "
            f"the median step {med:.6g} s (at most {JITTER:.0%} jitter is taken as uniform); the "
            "zero-phase filter needs uniform samples: resample every column onto a uniform "
            f"grid first (e.g. numpy.interp onto t0 + k * {med:.6g} s, or "
            "scipy.signal.resample_poly for a rational rate change)",
            column="time_s", row=i + 2, source=src)


# --------------------------------------------------------------------------- processing


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
            raise DataError(f"cut-off {cutoff:g} Hz: must lie in (0, {top:g}] Hz for a record "
                            f"sampled at {fs:g} Hz", column="time_s", source=measured.source)
    elif spec is not None:
        from .spec import design_crossover

        fc = design_crossover(spec)
        cutoff = CROSSOVER_FACTOR * fc
        rule = f"{CROSSOVER_FACTOR:g} x the loop's crossover ({fc:.4g} Hz)"
    else:
        cutoff = CUTOFF_FRACTION * fs
        rule = f"{CUTOFF_FRACTION:g} x the sample rate (no spec: loop crossover unknown)"
    if cutoff > top:
        cutoff = top
        rule += f", capped at {MAX_CUTOFF_FRACTION:g} x the sample rate"
    if decimation is None:
        decimation = _smooth_factor(max(1, int(math.floor(0.8 * fs / (2.0 * cutoff)))))
    elif decimation < 1:
        raise DataError(f"decimation factor {decimation}: must be at least 1", column="time_s",
                        source=measured.source)
    decimation = min(decimation, max(1, measured.n // 50))
    if velocity_threshold is None:
        v = np.gradient(_lowpass(measured.position, cutoff, fs), 1.0 / fs)
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


def _lowpass(x: np.ndarray, cutoff: float, fs: float) -> np.ndarray:
    from scipy.signal import butter, sosfiltfilt

    sos = butter(FILTER_ORDER, cutoff, fs=fs, output="sos")
    return sosfiltfilt(sos, np.asarray(x, dtype=float))


def _decimate(x: np.ndarray, q: int) -> np.ndarray:
    """scipy.signal.decimate (FIR, zero phase) in stages of at most :data:`MAX_STAGE`."""
    from scipy.signal import decimate

    y = np.asarray(x, dtype=float)
    while q > 1:
        f = max(d for d in range(2, MAX_STAGE + 1) if q % d == 0)
        y = decimate(y, f, ftype="fir", zero_phase=True)
        q //= f
    return y


@dataclass(frozen=True)
class _Joint:
    """What the spec says about the joint of an isolated stage."""

    model: str                   # rigid | two_mass | two_mass_sum
    k: float | None              # flexure stiffness [N/m]
    c: float | None              # flexure damping [N s/m]
    ratio: float                 # m1 / (m1 + m2) from the spec
    notes: tuple[str, ...]


def _joint(measured: Measurement, spec) -> _Joint:
    has_defl = measured.deflection is not None
    ratio = spec.stage.mass / spec.total_mass if spec is not None else 1.0
    if spec is None:
        notes = ("no spec: the record is taken as one rigid moving mass"
                 + ("; its deflection_m column is not used (the flexure force needs the spec's "
                    "stiffness)" if has_defl else ""),)
        return _Joint("rigid", None, None, ratio, notes)
    if not spec.has_isolator:
        notes = ("the spec has no isolator: one rigid moving mass"
                 + ("; the record's deflection_m column is not used" if has_defl else ""),)
        return _Joint("rigid", None, None, ratio, notes)
    if not has_defl:
        return _Joint("rigid", None, None, ratio, (
            "the spec has an isolator but the record no deflection_m column: the cart's motion "
            "is not measured, so stage and cart are taken as one rigid mass (the joint's "
            "deflection neglected); stage and cart mass are not separable",))
    from .spec import joint_damping

    iso = spec.isolator
    if iso.stiffness is None:
        return _Joint("two_mass_sum", None, None, ratio, (
            "two-mass record without the flexure's stiffness (isolator.stiffness not given): the "
            "flexure force k d + c d' is unknown, so the stage and cart equations cannot be "
            "separated; their sum u = m1 a1 + m2 a2 + F_f(v2) + offset is used with the cart's "
            "motion x2 = x1 - d for the friction and the masses in the spec's ratio: the total "
            "mass is identified, its split between stage and cart is not",))
    c = joint_damping(spec)
    c_note = ("given" if iso.damping is not None else
              "the spec's default (damping ratio 0.05), not a measured value")
    return _Joint("two_mass", iso.stiffness, c, ratio, (
        f"two-mass record: the flexure force k d + c d' (k = {iso.stiffness:.6g} N/m from the "
        f"spec, c = {c:.6g} N s/m, {c_note}) separates the stage equation (stage mass, offset) "
        "from the cart equation (cart mass, friction of the bearing at the cart's velocity); "
        "their accuracy rests on k and c: an error in k biases both masses and the friction",
        "on a two-mass record the offset (stage equation) and Coulomb friction per direction "
        "(cart equation) would both be identifiable, but only if the deflection sensor has no "
        "zero error (k times a zero error is indistinguishable from the offset); the forms are "
        "kept as on one mass for that reason",))


@dataclass
class _Prepared:
    """Decimated signals of one record (internal)."""

    time: np.ndarray
    force: np.ndarray            # aligned actuator force u
    a1: np.ndarray               # stage acceleration
    a2: np.ndarray               # cart acceleration (a1 for one mass)
    v: np.ndarray                # velocity of the bearing side (friction)
    joint: np.ndarray | None     # flexure force k d + c d'
    cols: dict                   # nonlinear friction columns, decimated
    used: np.ndarray


def _prepare(m: Measurement, proc: Processing, joint: _Joint) -> _Prepared:
    fs, q = proc.sample_rate, proc.decimation
    t = np.asarray(m.time, dtype=float)
    dt = 1.0 / fs
    x1 = _lowpass(m.position, proc.cutoff, fs)
    u = _lowpass(m.force, proc.cutoff, fs)
    if proc.force_delay > 0.0:  # the command acts this much later
        u = np.interp(t - proc.force_delay, t, u)
    if proc.force_hold:  # the mean of the two held samples around t_k
        u = np.concatenate([u[:1], 0.5 * (u[1:] + u[:-1])])
    v1 = np.gradient(x1, dt)
    a1 = _second_difference(x1, dt)
    raw = np.gradient(np.asarray(m.position, dtype=float), dt)  # filtered once, below
    if joint.model == "rigid":
        v2, a2, fj = v1, a1, None
    else:
        d = _lowpass(m.deflection, proc.cutoff, fs)
        dd = np.gradient(d, dt)
        v2 = v1 - dd
        a2 = a1 - _second_difference(d, dt)
        raw = raw - np.gradient(np.asarray(m.deflection, dtype=float), dt)
        fj = joint.k * d + joint.c * dd if joint.model == "two_mass" else None
    # the direction from the filtered velocity; the one-sided velocities from the raw one, so
    # that, filtered like the force, they hold the velocity filtered once, as the force does
    pos, neg = (v2 > 0).astype(float), (v2 < 0).astype(float)
    cols = {"one": np.ones_like(v2), "sign": pos - neg, "pos": pos, "neg": neg,
            "vpos": pos * raw, "vneg": neg * raw,
            "slide": (np.abs(v2) > proc.velocity_threshold).astype(float)}
    # the same low-pass and decimation as the force: the equation holds on the filtered data
    dec = {k: _decimate(_lowpass(c, proc.cutoff, fs), q) for k, c in cols.items()}
    td = t[::q]
    vd = _decimate(v2, q)
    # sliding faster than the threshold throughout the filters' reach ("one": their own gain)
    used = np.abs(dec["slide"] - dec["one"]) < SLIDE_TOLERANCE * dec["one"]
    used &= (td >= t[0] + proc.edge) & (td <= t[-1] - proc.edge)
    return _Prepared(time=td, force=_decimate(u, q), a1=_decimate(a1, q), a2=_decimate(a2, q),
                     v=vd, joint=None if fj is None else _decimate(fj, q), cols=dec, used=used)


def _second_difference(x: np.ndarray, dt: float) -> np.ndarray:
    """Acceleration by the second central difference (x[k+1] - 2 x[k] + x[k-1]) / dt^2."""
    a = np.empty_like(x)
    a[1:-1] = np.diff(x, 2) / (dt * dt)
    a[0], a[-1] = a[1], a[-2]
    return a


# --------------------------------------------------------------------------- least squares


def _friction_columns(p: _Prepared, form: str) -> dict[str, np.ndarray]:
    c = p.cols
    if form == "symmetric":
        return {"coulomb": c["sign"], "viscous": c["vpos"], "viscous_negative": c["vneg"]}
    return {"coulomb": c["pos"], "coulomb_negative": -c["neg"], "viscous": c["vpos"],
            "viscous_negative": c["vneg"]}


def _equations(p: _Prepared, form: str, joint: _Joint) -> list[tuple[np.ndarray, dict]]:
    """The equations as (left-hand side, {parameter: column}), all on every sample."""
    fric = _friction_columns(p, form)
    off = {"offset": p.cols["one"]} if form == "symmetric" else {}
    if joint.model == "two_mass":
        stage = (p.force - p.joint, {"stage_mass": p.a1, **off})
        cart = (p.joint, {"cart_mass": p.a2, **fric})
        return [stage, cart]
    if joint.model == "two_mass_sum":
        a = joint.ratio * p.a1 + (1.0 - joint.ratio) * p.a2
    else:
        a = p.a1
    return [(p.force, {"mass": a, **fric, **off})]


@dataclass
class _Solution:
    names: list
    theta: np.ndarray
    cov: np.ndarray
    cond: float
    n_used: int
    n_eff: float


def _solve(equations: list, used: np.ndarray) -> _Solution:
    """Weighted least squares over the equations, with the autocorrelation-corrected covariance."""
    from scipy.linalg import lstsq, svdvals

    names: list[str] = []
    for _, cols in equations:
        names += [n for n in cols if n not in names]
    blocks = []
    for y, cols in equations:
        A = np.column_stack([cols[n][used] if n in cols else np.zeros(int(used.sum()))
                             for n in names])
        blocks.append((A, y[used]))
    A_all = np.vstack([b[0] for b in blocks])
    scale = np.linalg.norm(A_all, axis=0)
    scale[scale == 0.0] = 1.0
    weights = [1.0] * len(blocks)
    for _ in range(2 if len(blocks) > 1 else 1):  # OLS, then WLS with per-equation variances
        Aw = np.vstack([w * A for w, (A, _) in zip(weights, blocks)]) / scale
        yw = np.concatenate([w * y for w, (_, y) in zip(weights, blocks)])
        sol, _, rank, _ = lstsq(Aw, yw)
        theta = sol / scale
        res = [y - A @ theta for A, y in blocks]
        weights = [1.0 / max(float(np.std(r)), 1e-300) for r in res]
    if rank < len(names):
        raise DataError("the record does not excite every parameter (the regressor is rank "
                        f"deficient: rank {rank} of {len(names)} for {', '.join(names)}); it "
                        "needs acceleration and sliding at varied speeds in both directions",
                        column="position_m")
    Aw = np.vstack([w * A for w, (A, _) in zip(weights, blocks)])
    rw = np.concatenate([w * r for w, r in zip(weights, res)])
    n, k = Aw.shape
    s2 = float(rw @ rw) / max(n - k, 1)
    from scipy.linalg import pinvh

    cov = s2 * pinvh(Aw.T @ Aw)
    n_eff = sum(len(r) / _effective_fraction(w * r) for w, r in zip(weights, res))
    inflation = n / n_eff
    sv = svdvals(Aw / np.linalg.norm(Aw, axis=0))
    return _Solution(names=names, theta=theta, cov=cov * inflation, cond=float(sv[0] / sv[-1]),
                     n_used=int(used.sum()), n_eff=n / inflation)


def _effective_fraction(r: np.ndarray) -> float:
    """n / n_eff = 1 + 2 sum of the residual autocorrelations up to the first non-positive one."""
    from scipy.signal import correlate

    r = np.asarray(r, dtype=float) - float(np.mean(r))
    if len(r) < 3 or not np.any(r):
        return 1.0
    ac = correlate(r, r, mode="full", method="fft")[len(r) - 1:]
    ac = ac / ac[0]
    total = 0.0
    for rho in ac[1:len(r) // 2]:
        if rho <= 0.0:
            break
        total += float(rho)
    return 1.0 + 2.0 * total


# --------------------------------------------------------------------------- excitation


def excitation(measured: Measurement, proc: Processing, *, spec=None,
               dwell: float = DWELL, rest_band: float = REST_BAND,
               presliding_band: float = PRESLIDING_BAND) -> Excitation:
    """Detect breakaways from rest and presliding reversals in a record.

    The bearing side (the stage, or the cart x1 - d of an isolated stage with
    a deflection column) is low-passed as for the fit. A *rest* is a stretch
    of at least ``dwell`` in which it moves less than ``rest_band`` (or 10
    times the position noise, whichever is larger); a *breakaway* is a rest
    followed by sliding above the velocity threshold. A *reversal* is an
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
    xf = _lowpass(x, proc.cutoff, fs)
    noise = float(np.std(x - xf))
    band = max(rest_band, 10.0 * noise)
    v = np.gradient(xf, 1.0 / fs)
    w = max(2, int(round(dwell * fs)))
    lo = minimum_filter1d(xf, w, mode="nearest")
    hi = maximum_filter1d(xf, w, mode="nearest")
    rest = (hi - lo) < band
    edge = int(round(proc.edge * fs))
    inner = slice(edge, len(x) - edge) if len(x) > 2 * edge + 1 else slice(None)
    runs = _runs(rest)
    t = np.asarray(measured.time, dtype=float)
    sliding = np.abs(v) > proc.velocity_threshold
    events = []
    for a, b in runs:
        later = np.nonzero(sliding[b:])[0]
        if b - a >= w and len(later) and later[0] <= 20 * w and np.any(sliding[:a]):
            events.append((float(t[a]), float(t[b + int(later[0])])))
    breakaways = len(events)
    prom = max(10.0 * noise, 1e-12)
    ext = np.sort(np.concatenate([find_peaks(xf, prominence=prom)[0],
                                  find_peaks(-xf, prominence=prom)[0]]))
    excursions = np.abs(np.diff(xf[ext])) if len(ext) > 1 else np.zeros(0)
    return Excitation(breakaways=breakaways,
                      rest_time=float(sum(b - a for a, b in runs if b - a >= w) / fs),
                      reversals=int(len(ext)),
                      presliding_reversals=int(np.sum(excursions < presliding_band)),
                      low_speed_time=float(np.sum((np.abs(v) < proc.velocity_threshold)[inner]
                                                  & ~rest[inner]) / fs), dwell=float(dwell),
                      rest_band=float(band), presliding_band=float(presliding_band),
                      events=tuple(events))


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """Start and end (exclusive) of every run of True."""
    m = np.concatenate([[False], np.asarray(mask, bool), [False]])
    d = np.diff(m.astype(int))
    return list(zip(np.nonzero(d == 1)[0].tolist(), np.nonzero(d == -1)[0].tolist()))


# --------------------------------------------------------------------------- identify


def identify(measured: Measurement, spec=None, *, form: str = "symmetric",
             progress: ProgressCallback | None = None, cutoff: float | None = None,
             decimation: int | None = None,
             velocity_threshold: float | None = None) -> IdentificationResult:
    """Identify mass, friction and force offset from a measured record (guideline step 1).

    Parameters
    ----------
    measured : Measurement
        The record: ``time_s``, ``position_m`` and ``force_N`` (the force that
        acts, an injected disturbance included), uniformly sampled; with
        ``deflection_m`` and a spec with an isolator, the two-mass equations.
    spec : fi_design.spec.Spec, optional
        The stage: its loop's crossover sets the filter, its isolator's
        stiffness and damping give the flexure force, its mass ratio splits
        the total mass, its Stribeck velocity bounds the velocity threshold
        from below. Without it: one rigid mass.
    form : {"symmetric", "per_direction"}
        ``"symmetric"``: one Coulomb friction (``coulomb``) and an ``offset``;
        ``"per_direction"``: ``coulomb`` (positive direction) and
        ``coulomb_negative``, no offset. Viscous friction is per direction in
        both. The two fit the data identically (see the module docstring).
    progress : callable, optional
        Called as ``progress(message, fraction)`` with fraction in [0, 1].
    cutoff : float, optional
        Low-pass cut-off [Hz]; default from the spec's crossover or the sample
        rate (:func:`processing`).
    decimation : int, optional
        Decimation factor; default from the cut-off.
    velocity_threshold : float, optional
        Slowest speed used [m/s]; default 10 % of the peak speed, with a spec
        at least three times its Stribeck velocity. It must lie well above the
        Stribeck velocity, where friction is Coulomb plus viscous.

    Returns
    -------
    IdentificationResult
        ``to_dict()`` is the JSON of DESIGN.md section 8.

    Raises
    ------
    DataError
        No ``force_N`` column, too few samples, a constant position, sampling
        the filter cannot take, motion in one direction only, too few sliding
        samples; the message names the column and what is needed.
    ValueError
        An unknown ``form``.

    Examples
    --------
    >>> import numpy as np
    >>> from fi_design.measured import measurement_from_arrays
    >>> t = np.arange(0.0, 4.0, 1e-3)
    >>> x = 0.01 * np.sin(2 * np.pi * 0.5 * t)
    >>> v = np.gradient(x, t); a = np.gradient(v, t)
    >>> u = 2.0 * a + 3.0 * np.sign(v) + 40.0 * v + 0.5
    >>> m = measurement_from_arrays(t, x, x, force_N=u)
    >>> r = identify(m)
    >>> round(r.value("mass"), 1), round(r.value("coulomb"), 1), round(r.value("offset"), 1)
    (2.0, 3.0, 0.5)
    """
    if form not in FORMS:
        raise ValueError(f"form must be one of {FORMS}, got {form!r}")
    say = progress or (lambda message, fraction: None)
    _check_record(measured)
    say("filtering", 0.0)
    proc = processing(measured, spec, cutoff=cutoff, decimation=decimation,
                      velocity_threshold=velocity_threshold)
    joint = _joint(measured, spec)
    say("least squares", 0.3)
    fits = []
    for hold in (True, False):  # the force as a held command, or as a sampled force
        p = replace(proc, force_hold=hold)
        prep = _prepare(measured, p, joint)
        _check_directions(prep, p, measured.source)
        sol = _solve(_equations(prep, form, joint), prep.used)
        fits.append((_force_rss(prep, sol, joint), p, prep, sol))
    _, proc, prep, sol = min(fits, key=lambda f: f[0])
    samples, fit = _fit_statistics(prep, sol, joint)
    say("excitation", 0.5)
    exc = excitation(measured, proc, spec=spec)
    params = _rigid_parameters(sol, form, joint)
    masses = _masses(sol, joint, spec, params["mass"])
    notes = list(joint.notes) + [_form_note(form), _threshold_note(proc)]
    for name, p in list(params.items()):
        if p.value is not None and p.value <= 0.0 and name != "offset":
            params[name] = replace(p, note=p.note + "; " + _IMPLAUSIBLE)
            notes.append(f"{name} = {p.value:.4g} {p.unit} is not positive: {_IMPLAUSIBLE}")
    if measured.disturbance is not None:
        notes.append("force_N is used as the force that acts (the injected disturbance_N "
                     "included); the controller's own output force_N - disturbance_N is not")
    params.update(_dynamic(exc))
    say("done", 1.0)
    return IdentificationResult(
        parameters=MappingProxyType({k: params[k] for k in NAMES}), fit=fit, form=form,
        model=joint.model, masses=masses, processing=proc, excitation=exc,
        notes=tuple(notes), samples=samples, measurement=measured, spec=spec)


def _force_rss(prep: _Prepared, sol: _Solution, joint: _Joint) -> float:
    """Residual sum of squares of the actuator force per used sample [N^2]."""
    _, fit = _fit_statistics(prep, sol, joint)
    return fit.force_rms_residual ** 2


def _check_directions(prep: _Prepared, proc: Processing, source: str | None) -> None:
    used = prep.used
    pos = int(np.sum(used & (prep.v > 0)))
    neg = int(np.sum(used & (prep.v < 0)))
    if min(pos, neg) < MIN_DIRECTION_SAMPLES:
        raise DataError(
            f"too little sliding: {pos} usable samples moving in the positive direction and "
            f"{neg} in the negative one faster than {proc.velocity_threshold:.3g} m/s (at least "
            f"{MIN_DIRECTION_SAMPLES} each after decimation by {proc.decimation}); identification "
            "needs sliding in both directions (otherwise Coulomb friction and the offset are "
            "indistinguishable)", column="position_m", source=source)


def _fit_statistics(prep: _Prepared, sol: _Solution, joint: _Joint) -> tuple[Samples, Fit]:
    th = dict(zip(sol.names, sol.theta))
    fric = sum(th.get(n, 0.0) * c for n, c in _friction_columns(
        prep, "per_direction" if "coulomb_negative" in th else "symmetric").items())
    fric = fric + th.get("offset", 0.0) * prep.cols["one"]
    if joint.model == "two_mass":
        inertia = th["stage_mass"] * prep.a1 + th["cart_mass"] * prep.a2
    elif joint.model == "two_mass_sum":
        inertia = th["mass"] * (joint.ratio * prep.a1 + (1.0 - joint.ratio) * prep.a2)
    else:
        inertia = th["mass"] * prep.a1
    model = inertia + fric
    u = prep.force[prep.used]
    r = u - model[prep.used]
    samples = Samples(time=frozen_array(prep.time), velocity=frozen_array(prep.v),
                      force=frozen_array(prep.force), model=frozen_array(model),
                      inertia=frozen_array(inertia), used=frozen_array(prep.used, dtype=bool))
    fit = Fit(force_rms_residual=float(np.sqrt(np.mean(r ** 2))),
              relative_error=float(np.linalg.norm(r) / np.linalg.norm(u)),
              condition_number=sol.cond, samples_used=sol.n_used, effective_samples=sol.n_eff,
              error_method="residual variance, scaled by n / n_eff for the autocorrelation of "
                           "the residuals (effective sample count, initial positive sequence)")
    return samples, fit


def _rigid_parameters(sol: _Solution, form: str, joint: _Joint) -> dict[str, Parameter]:
    idx = {n: i for i, n in enumerate(sol.names)}
    se = np.sqrt(np.clip(np.diag(sol.cov), 0.0, None))

    def est(name: str, note: str) -> Parameter:
        i = idx[name]
        return Parameter(float(sol.theta[i]), float(se[i]), UNITS[name], True, note)

    out: dict[str, Parameter] = {}
    if joint.model == "two_mass":
        i, j = idx["stage_mass"], idx["cart_mass"]
        var = sol.cov[i, i] + sol.cov[j, j] + 2.0 * sol.cov[i, j]
        out["mass"] = Parameter(float(sol.theta[i] + sol.theta[j]), float(math.sqrt(max(var, 0))),
                                "kg", True, "total moving mass m1 + m2, the sum of the stage "
                                            "and cart masses identified separately")
    else:
        out["mass"] = est("mass", "total moving mass" + (
            "" if joint.model == "rigid" else " (stage and cart accelerations in the spec's "
                                              "mass ratio)"))
    if form == "symmetric":
        out["coulomb"] = est("coulomb", "Coulomb friction, both directions (symmetric form)")
        out["coulomb_negative"] = Parameter(
            None, None, "N", False,
            "symmetric form: taken equal to coulomb; per direction it is collinear with the "
            "offset on sliding data (sign(v) per direction sums to a constant): "
            "form='per_direction' estimates it, without an offset")
        out["offset"] = est("offset", "constant force on the stage (sign of a friction force: "
                                      "u = offset holds the stage)")
    else:
        out["coulomb"] = est("coulomb", "Coulomb friction sliding in the positive direction "
                                        "(per-direction form, the offset absorbed)")
        out["coulomb_negative"] = est("coulomb_negative", "Coulomb friction sliding in the "
                                                          "negative direction (per-direction "
                                                          "form, the offset absorbed)")
        out["offset"] = Parameter(
            None, None, "N", False,
            "per-direction form: absorbed into coulomb and coulomb_negative (collinear on "
            "sliding data: Fc+ = Fc + offset, Fc- = Fc - offset); form='symmetric' estimates it")
    out["viscous"] = est("viscous", "viscous friction sliding in the positive direction")
    out["viscous_negative"] = est("viscous_negative", "viscous friction sliding in the negative "
                                                      "direction")
    return out


def _masses(sol: _Solution, joint: _Joint, spec, total: Parameter) -> Masses:
    if joint.model == "two_mass":
        i, j = sol.names.index("stage_mass"), sol.names.index("cart_mass")
        return Masses(stage=float(sol.theta[i]), cart=float(sol.theta[j]),
                      stage_std_error=float(math.sqrt(max(sol.cov[i, i], 0.0))),
                      cart_std_error=float(math.sqrt(max(sol.cov[j, j], 0.0))),
                      source="identified")
    r = joint.ratio
    return Masses(stage=total.value * r, cart=total.value * (1.0 - r), stage_std_error=None,
                  cart_std_error=None,
                  source="split in the spec's ratio" if spec is not None else
                  "no spec: all on the stage")


def _form_note(form: str) -> str:
    if form == "symmetric":
        return ("symmetric form: one Coulomb friction for both directions and a force offset "
                "(the default); the per-direction form (form='per_direction') fits the data "
                "identically with Fc+ = coulomb + offset and Fc- = coulomb - offset")
    return ("per-direction form: Coulomb friction per direction and no offset; the symmetric "
            "form fits the data identically with coulomb = (Fc+ + Fc-) / 2 and offset = "
            "(Fc+ - Fc-) / 2")


def _threshold_note(proc: Processing) -> str:
    return (f"samples slower than {proc.velocity_threshold:.4g} m/s are not used: near zero "
            "velocity friction is not Coulomb plus viscous (Stribeck effect, presliding, "
            "sticking)")


# --------------------------------------------------------------------------- dynamic parameters


def _dynamic(exc: Excitation) -> dict[str, Parameter]:
    """Parameters static, stribeck_velocity, bristle_stiffness: never estimated here.

    Where the record holds the excitation the note says so and names the
    events; the estimate itself is left to a dedicated experiment and fit
    (see the module docstring): none is reported rather than an unreliable one.
    """
    out = {}
    for name in DYNAMIC:
        held = exc.presliding if name == "bristle_stiffness" else exc.breakaway
        if not held:
            out[name] = _not_identifiable(name, exc)
            continue
        what = (f"{exc.presliding_reversals} presliding reversals" if name == "bristle_stiffness"
                else f"{exc.breakaways} breakaways from rest, at t = " + ", ".join(
                    f"{e[1]:.3g} s" for e in exc.events[:6]) + (" ..." if len(exc.events) > 6
                                                                 else ""))
        out[name] = Parameter(None, None, UNITS[name], False,
                              f"the record holds an excitation for it ({what}), but it is not "
                              "estimated: a fit of the replayed breakaways and reversals was not "
                              "reliable in validation (its estimates moved by many standard "
                              "errors under sub-percent errors of the sliding friction); "
                              f"{_EXPERIMENT[name]} identifies it")
    return out


def _not_identifiable(name: str, exc: Excitation) -> Parameter:
    if name == "bristle_stiffness":
        why = (f"the record holds no presliding excitation ({exc.presliding_reversals} "
               f"reversal(s) with an excursion below {exc.presliding_band * 1e6:.3g} um, "
               f"{MIN_EVENTS} needed)")
    else:
        why = (f"the record holds no breakaway from rest ({exc.breakaways} rest(s) of at least "
               f"{exc.dwell * 1e3:.3g} ms followed by sliding, {MIN_EVENTS} needed); it moves "
               f"slower than the velocity threshold for {exc.low_speed_time:.3g} s in all, "
               "passing through, and those samples are left out of the fit")
    return Parameter(None, None, UNITS[name], False,
                     f"not identifiable: {why}; {_EXPERIMENT[name]} would identify it")


# --------------------------------------------------------------------------- spec and prediction


def spec_values(result: IdentificationResult) -> dict[str, float]:
    """The spec values the identification fills in, by dotted path (SI).

    ``friction.coulomb``, ``friction.coulomb_negative`` (per-direction form;
    in the symmetric form equal to ``coulomb``, written only where the spec
    gives one),
    ``friction.viscous``, ``friction.viscous_negative``, ``friction.offset``
    (0 in the per-direction form, which absorbs it), ``stage.mass`` and
    ``cart.mass`` (identified, or the total split in the spec's ratio), and
    the dynamic parameters that were identified. Where static friction is
    not identified, ``friction.static`` keeps the spec's friction gap
    Fs - Fc on the identified Coulomb friction: the gap (guideline step 1)
    stays the user's assumption, not a value derived from the record.

    Parameters
    ----------
    result : IdentificationResult
        The identification (with a spec).
    """
    return _values(result.spec, result.parameters, result.masses, result.form)


def _values(spec, params, masses, form) -> dict[str, float]:
    v = {"stage.mass": masses.stage, "cart.mass": masses.cart,
         "friction.coulomb": params["coulomb"].value,
         "friction.viscous": params["viscous"].value,
         "friction.viscous_negative": params["viscous_negative"].value}
    if form == "symmetric":
        v["friction.offset"] = params["offset"].value
        if spec is not None and spec.friction.coulomb_negative is not None:
            v["friction.coulomb_negative"] = params["coulomb"].value  # the form: the same
    else:
        v["friction.coulomb_negative"] = params["coulomb_negative"].value
        v["friction.offset"] = 0.0
    for name in DYNAMIC:
        p = params.get(name)
        if p is not None and p.identifiable and p.value is not None:
            v[f"friction.{name}"] = p.value
    if "friction.static" not in v and spec is not None:  # keep the spec's friction gap
        v["friction.static"] = v["friction.coulomb"] + spec.friction.static - \
            spec.friction.coulomb
    return v


def identified_spec(spec, params, masses, form):
    """The spec with identified values (a :class:`~fi_design.spec.Spec`, no file origin).

    Raises
    ------
    SpecError
        An identified value the spec refuses (e.g. a negative Coulomb friction
        in the per-direction form: then use the symmetric form).
    """
    from .errors import SpecError
    from .specfile import with_values

    values = _values(spec, params, masses, form)
    bad = [k for k in ("stage.mass", "cart.mass", "friction.coulomb",
                       "friction.coulomb_negative", "friction.viscous",
                       "friction.viscous_negative") if k in values and values[k] < 0.0
           or k in values and values[k] == 0.0 and "viscous" not in k]
    if bad:
        raise SpecError(f"the identified value {values[bad[0]]:.4g} {_SPEC_UNITS[bad[0]]} is "
                        f"not positive, which a spec cannot hold: {_IMPLAUSIBLE}", path=bad[0])
    return with_values(spec, {k: float(x) for k, x in values.items()})


#: Unit written for every spec path the identification fills in.
_SPEC_UNITS = {"stage.mass": "kg", "cart.mass": "kg", "friction.coulomb": "N",
               "friction.coulomb_negative": "N", "friction.viscous": "N*s/m",
               "friction.viscous_negative": "N*s/m", "friction.offset": "N",
               "friction.static": "N", "friction.stribeck_velocity": "m/s",
               "friction.bristle_stiffness": "N/m"}


def identified_spec_text(result: IdentificationResult) -> str:
    """YAML text of the input spec with the identified values filled in (``--write-spec``).

    The spec file's own text is kept, comments included: each value of
    :func:`spec_values` replaces the one written in the file (block or
    one-line flow mapping), with a comment giving the estimate, its
    standard error and the value it replaced; a missing key is added to its
    section. A header comment names the record and the form. Where the text
    cannot be edited in place (a spec given as a mapping, a section written
    in a multi-line flow style), the spec is written anew from its data with
    the same header, and says that comments were not kept. The text is
    checked with :func:`fi_design.specfile.load_spec` before it is returned.

    Parameters
    ----------
    result : IdentificationResult
        An identification with a spec.

    Returns
    -------
    str
        YAML that ``load_spec`` (and so ``fi-design SPEC.yaml``) accepts.

    Raises
    ------
    SpecError
        No spec, or an identified value the spec cannot hold.
    """
    from .errors import SpecError
    from .specfile import load_spec, origin, parse_yaml

    spec = result.spec
    if spec is None:
        raise SpecError("identification without a spec: nothing to fill in (give --spec)")
    identified_spec(spec, result.parameters, result.masses, result.form)  # refuses bad values
    values = spec_values(result)
    comments = {path: _value_comment(result, path) for path in values}
    org = origin(spec)
    header = _header(result)
    text = None
    if org is not None and org.path is not None:
        try:
            text = _edited(org.path.read_text(encoding="utf-8"), org, values, comments)
        except (OSError, UnicodeDecodeError):
            text = None
    if text is not None:
        text = header + "\n" + text
        try:
            data, _ = parse_yaml(text.encode("utf-8"), "<identified spec>")
            load_spec(data)
        except SpecError:
            text = None
    if text is None:
        text = _rewritten(org.raw if org is not None else spec.model_dump(exclude_none=True),
                          values, header)
        data, _ = parse_yaml(text.encode("utf-8"), "<identified spec>")
        load_spec(data)
    return text


def _quantity(path: str, value: float) -> str:
    return f"{value:.6g} {_SPEC_UNITS[path]}"


def _value_comment(result: IdentificationResult, path: str) -> str:
    section, key = path.split(".")
    unit = _SPEC_UNITS[path]
    if section in ("stage", "cart"):
        m = result.masses
        se = m.stage_std_error if section == "stage" else m.cart_std_error
        if se is not None:
            return f"identified {_quantity(path, getattr(m, section))} +- {se:.2g} {unit}"
        return f"the identified total mass, {m.source}"
    if key == "coulomb_negative" and result.form == "symmetric":
        return "symmetric form: equal to coulomb"
    if key == "offset" and result.form == "per_direction":
        return "per-direction form: the offset is absorbed in coulomb and coulomb_negative"
    if key == "static" and not result.parameters["static"].identifiable:
        f = result.spec.friction
        return (f"not identified: the spec's friction gap Fs - Fc = "
                f"{f.static - f.coulomb:.4g} N kept on the identified coulomb")
    p = result.parameters[key]
    return f"identified {_quantity(path, p.value)} +- {p.std_error:.2g} {unit}"


def _header(result: IdentificationResult) -> str:
    src = result.measurement.source or "a measured record"
    lines = [f"# Friction and masses identified by fi-design identify from {src}",
             f"# ({result.form.replace('_', '-')} form, {result.model} model, relative force "
             f"error {result.fit.relative_error:.3g}); values marked 'identified' below."]
    for name in DYNAMIC:
        p = result.parameters[name]
        if not p.identifiable:
            kept = ("keeps the spec's friction gap Fs - Fc" if name == "static" else
                    "is the spec's own value")
            lines.append(f"# friction.{name} {kept}: not identifiable from this record.")
    return "\n".join(lines)


def _edited(text: str, org, values: dict, comments: dict) -> str | None:
    """The spec text with values replaced or added in place; None where that is not safe."""
    import re

    lines = text.split("\n")
    inserts: dict[int, list[str]] = {}
    for path, value in values.items():
        section, key = path.split(".")
        new = _quantity(path, value)
        line_no = org.lines.get((section, key))
        if line_no is not None:
            i = line_no - 1
            block = re.match(rf"^(\s*){re.escape(key)}\s*:\s*([^#]*?)\s*(#.*)?$", lines[i])
            if block:
                old = block.group(2)
                extra = f"; {block.group(3)[1:].strip()}" if block.group(3) else ""
                lines[i] = f"{block.group(1)}{key}: {new}  # {comments[path]} (was {old}){extra}"
                continue
            flow = re.compile(rf"(\b{re.escape(key)}\s*:\s*)([^,}}#]+?)(\s*[,}}])")
            if lines[i].count("{") == 1 and lines[i].count("}") == 1 and \
                    len(flow.findall(lines[i])) == 1:
                body, _, old_comment = lines[i].partition("#")
                body = flow.sub(lambda m: m.group(1) + new + m.group(3), body).rstrip()
                note = f"{key}: {comments[path]}" + (f"; {old_comment.strip()}" if old_comment
                                                     else "")
                lines[i] = f"{body}  # {note}"
                continue
            return None
        keys = [ln for loc, ln in org.lines.items() if len(loc) >= 2 and loc[0] == section]
        head = org.lines.get((section,))
        if head is None or not keys or min(keys) == head:
            return None  # section missing or written in flow style: no safe place
        first = lines[min(keys) - 1]
        indent = first[:len(first) - len(first.lstrip())]
        inserts.setdefault(max(keys) - 1, []).append(f"{indent}{key}: {new}  # {comments[path]}")
    for i in sorted(inserts, reverse=True):
        lines[i + 1:i + 1] = inserts[i]
    return "\n".join(lines)


def _rewritten(raw: dict, values: dict, header: str) -> str:
    import yaml

    data = {k: (dict(v) if isinstance(v, dict) else v) for k, v in raw.items()}
    for path, value in values.items():
        section, key = path.split(".")
        data.setdefault(section, {})[key] = _quantity(path, value)
    return (header + "\n# (written anew from the spec's data: its comments are not kept)\n"
            + yaml.safe_dump(data, sort_keys=False, allow_unicode=True))


def predict_force(result: IdentificationResult, measured: Measurement) -> ForcePrediction:
    """The identified model's actuator force on a record, processed as the identification was.

    For cross-validation: identify on one record (or part of one), predict
    the force on another. The record is filtered, aligned, decimated and
    selected with ``result.processing`` (same cut-off, decimation and velocity
    threshold), and the inverse-dynamics model with the identified mass,
    friction and offset gives the force.

    Parameters
    ----------
    result : IdentificationResult
        The identification.
    measured : Measurement
        The record to predict (same sample rate).

    Returns
    -------
    ForcePrediction

    Raises
    ------
    DataError
        The record cannot be processed (see :func:`identify`) or has another
        sample rate.
    """
    _check_record(measured)
    proc = result.processing
    fs = 1.0 / measured.sample_period
    if abs(fs / proc.sample_rate - 1.0) > JITTER:
        raise DataError(f"sampled at {fs:g} Hz, the identification at {proc.sample_rate:g} Hz",
                        column="time_s", source=measured.source)
    joint = _joint(measured, result.spec)
    if joint.model != result.model:
        raise DataError(f"a {joint.model} record cannot be predicted by a {result.model} "
                        "identification", column="deflection_m", source=measured.source)
    prep = _prepare(measured, proc, joint)
    th = {n: p.value for n, p in result.parameters.items() if p.value is not None}
    if result.model == "two_mass":
        th["stage_mass"], th["cart_mass"] = result.masses.stage, result.masses.cart
    sol = _Solution(names=list(th), theta=np.array(list(th.values())),
                    cov=np.zeros((len(th), len(th))), cond=math.nan,
                    n_used=int(prep.used.sum()), n_eff=math.nan)
    samples, fit = _fit_statistics(prep, sol, joint)
    return ForcePrediction(samples=samples, force_rms_residual=fit.force_rms_residual,
                           relative_error=fit.relative_error, samples_used=fit.samples_used)


def segment(measured: Measurement, start: float | None = None,
            stop: float | None = None) -> Measurement:
    """The samples of a record with ``start <= time < stop`` [s] (for cross-validation).

    Parameters
    ----------
    measured : Measurement
        The record.
    start, stop : float, optional
        Time span [s]; None: from the first or to the last sample.

    Returns
    -------
    Measurement
        A new record with the same columns; its source names the span.
    """
    t = np.asarray(measured.time)
    a = 0 if start is None else int(np.searchsorted(t, start, side="left"))
    b = len(t) if stop is None else int(np.searchsorted(t, stop, side="left"))

    def col(values):
        return None if values is None else np.asarray(values)[a:b]

    span = f"{'' if start is None else f'{start:g} s '}to{'' if stop is None else f' {stop:g} s'}"
    return measurement_from_arrays(
        col(measured.time), col(measured.reference), col(measured.position),
        force_N=col(measured.force), deflection_m=col(measured.deflection),
        disturbance_N=col(measured.disturbance),
        source=f"{measured.source or 'record'} ({span.strip()})")


__all__ = ["identify", "IdentificationResult", "Parameter", "Fit", "Processing", "Excitation",
           "Masses", "Samples", "ForcePrediction", "predict_force", "processing", "excitation",
           "spec_values", "identified_spec", "identified_spec_text", "segment", "NAMES", "UNITS", "FORMS"]
