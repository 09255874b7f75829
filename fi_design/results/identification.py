"""Result types of an identification (JSON: docs/interfaces.md): values, not behaviour.

Produced by :func:`fi_design.identification.identify`; the identification
report and the console read them.

:class:`IdentificationResult` holds one :class:`Parameter` per name of
:data:`NAMES` (value, standard error, unit, identifiable, note), the
statistics of the inverse-dynamics fit (:class:`Fit`), the processing
settings (:class:`Processing`), the stage and cart mass (:class:`Masses`),
what the record holds for LuGre's dynamic parameters
(:class:`Excitation`) and the fitted
samples (:class:`Samples`); ``to_dict()`` is the JSON of ``--json``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import TYPE_CHECKING, Any, Mapping

import numpy as np

from . import dataclass_dict
from .friction import FrictionLaw

if TYPE_CHECKING:  # pragma: no cover
    from ..measured import Measurement

#: Parameters of an identification, in the order of its JSON (docs/interfaces.md).
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


#: Fewest events (breakaways, presliding reversals) that count as an excitation.
MIN_EVENTS = 3


@dataclass(frozen=True)
class Excitation:
    """What the record holds for LuGre's dynamic parameters.

    Attributes
    ----------
    breakaways : int
        Rests of at least ``dwell`` after sliding (the bearing side moves less
        than ``rest_band``, or creeps slower than
        :data:`fi_design.identification.events.STOP_FRACTION` of the velocity
        threshold), followed by motion: see
        :func:`fi_design.identification.events.excitation`.
    rest_time : float
        Total time at rest (or creeping) [s].
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
        Per breakaway: the start of the rest and the time the bearing moves
        again [s].
    presliding_segments : tuple of tuple of float
        Per run of consecutive presliding reversals: the times of its
        reversals [s] (each pair of neighbours bounds a half cycle).
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
    presliding_segments: tuple[tuple[float, ...], ...] = ()

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
        """Plain JSON data (docs/interfaces.md)."""
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


@dataclass(frozen=True)
class BranchFit:
    """One event of the dynamic parameters: a breakaway's loading branch or a presliding run.

    Attributes
    ----------
    kind : str
        ``"breakaway"`` (the loading branch before a breakaway after a stop)
        or ``"presliding"`` (a run of small reversals that never slide).
    time : float
        The breakaway's onset, or the run's start [s].
    direction : int
        +1 or -1: the direction of the breakaway (0 for a presliding run).
    samples : int
        Samples fitted.
    peak_force : float or None
        Friction force at the onset (drive force minus inertia and offset,
        in the breakaway's direction) [N]; not the static friction (LuGre's
        friction there is g(v) at the creep speed, and filtered).
    creep_velocity : float or None
        Speed of the bearing at the onset [m/s].
    span : float
        Displacement of the bearing over the fitted samples [m].
    static : float or None
        The branch's saturation level: its static friction [N].
    static_std_error : float or None
        Its standard error from the fit [N] (statistical and propagated).
    bristle_stiffness : float or None
        Initial slope of friction against displacement, sigma0 [N/m].
    bristle_stiffness_std_error : float or None
        Its standard error from the fit [N/m].
    bristle_damping : float or None
        Bristle damping fitted with them, sigma1 [N s/m] (a nuisance parameter:
        not reported as identified).
    saturation : float or None
        The branch's last fitted friction over its level [-].
    rise : float or None
        The branch's rise of friction over its level [-].
    used_for : tuple of str
        The parameters this event counts for.
    note : str
        Why it does not count for a parameter (empty when it counts for all
        it can).
    """

    kind: str
    time: float
    direction: int
    samples: int
    peak_force: float | None
    creep_velocity: float | None
    span: float
    static: float | None
    static_std_error: float | None
    bristle_stiffness: float | None
    bristle_stiffness_std_error: float | None
    bristle_damping: float | None
    saturation: float | None
    rise: float | None
    used_for: tuple[str, ...]
    note: str

    def to_dict(self) -> dict:
        """Plain JSON data."""
        return dataclass_dict(self)


@dataclass(frozen=True)
class SweepFit:
    """The fit of the Stribeck curve to steady low-speed sliding.

    Attributes
    ----------
    samples : int
        Samples sliding steadily below the velocity threshold (full rate).
    effective_samples : float
        Their effective number after the autocorrelation correction.
    below, above : int
        Samples below 0.7 vs and above 1.5 vs.
    speed_min, speed_max : float
        Their speed range [m/s].
    stribeck_velocity : float
        The fitted Stribeck velocity [m/s].
    stribeck_velocity_std_error : float
        Its standard error [m/s].
    static : float or None
        Fs fitted with it when no breakaway resolves it [N]; None when fixed.
    static_std_error : float or None
        Its standard error [N].
    rms_residual : float
        RMS of the weighted residuals [-] (about 1 when the noise model holds).
    """

    samples: int
    effective_samples: float
    below: int
    above: int
    speed_min: float
    speed_max: float
    stribeck_velocity: float
    stribeck_velocity_std_error: float
    static: float | None
    static_std_error: float | None
    rms_residual: float

    def to_dict(self) -> dict:
        """Plain JSON data."""
        return dataclass_dict(self)


@dataclass(frozen=True)
class Dynamic:
    """How the dynamic parameters were estimated: the events and the sweep fit.

    Attributes
    ----------
    branches : tuple of BranchFit
        Every breakaway and presliding run examined.
    sweep : SweepFit or None
        The Stribeck fit, when the record slides steadily at low speed.
    """

    branches: tuple[BranchFit, ...] = ()
    sweep: SweepFit | None = None

    def to_dict(self) -> dict:
        """Plain JSON data."""
        return {"branches": [b.to_dict() for b in self.branches],
                "sweep": None if self.sweep is None else self.sweep.to_dict()}


@dataclass(frozen=True, eq=False)
class IdentificationResult:
    """Friction and mass identified from a measured record (docs/interfaces.md).

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
    dynamic : Dynamic
        The events and fits behind ``static``, ``stribeck_velocity`` and
        ``bristle_stiffness``.
    direction : str
        The directions the record slides in: ``"both"``, or ``"positive"`` or
        ``"negative"`` only (then the other direction's friction and the
        offset are not identifiable, and that direction's Coulomb friction
        includes the offset).
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
    dynamic: Dynamic = field(default_factory=Dynamic, repr=False)
    direction: str = "both"

    def value(self, name: str) -> float | None:
        """The value of parameter ``name`` [SI], or None."""
        return self.parameters[name].value

    @property
    def friction(self) -> FrictionLaw:
        """The identified friction as the model's friction law (its form's Coulomb values).

        Coulomb and viscous friction per direction as identified (the
        symmetric form: one Coulomb value both ways, the offset apart, see
        :meth:`friction_curve`); static friction and the Stribeck velocity
        only where both are identified, else no Stribeck term (Fs = Fc).
        A value not identified counts as 0.
        """
        p = {k: (x.value if x.value is not None else 0.0) for k, x in self.parameters.items()}
        stribeck = (self.parameters["static"].identifiable
                    and self.parameters["stribeck_velocity"].identifiable)
        symmetric = self.form == "symmetric"
        return FrictionLaw(
            model="lugre", Fs=p["static"] if stribeck else p["coulomb"], Fc=p["coulomb"],
            vs=p["stribeck_velocity"] if stribeck else math.nan,
            sigma0=p["bristle_stiffness"], sigma1=0.0, sigma2=p["viscous"],
            Fc_neg=None if symmetric else p["coulomb_negative"],
            sigma2_neg=p["viscous_negative"])

    def friction_curve(self, velocity) -> np.ndarray:
        """The identified steady-state friction plus offset at ``velocity`` [N].

        :meth:`fi_design.model.FrictionLaw.steady_state` of :attr:`friction`,
        plus the offset in the symmetric form (where it carries the
        difference between the two directions' Coulomb friction); at zero
        velocity the mean of the two sides.

        Parameters
        ----------
        velocity : array_like
            Velocities of the bearing side [m/s].

        Returns
        -------
        numpy.ndarray
            Force [N], the shape of ``velocity``.
        """
        v = np.asarray(velocity, dtype=float)
        if self.direction == "both":
            offset = self.parameters["offset"].value if self.form == "symmetric" else None
            return self.friction.steady_state(v) + (offset or 0.0)
        # a record that slides one way: that direction's level (offset in it), nothing of the
        # other direction (NaN there)
        p = {k: (x.value if x.value is not None else 0.0) for k, x in self.parameters.items()}
        negative = self.direction == "negative"
        level = p["coulomb_negative"] if negative else p["coulomb"] + p["offset"]
        slope = p["viscous_negative"] if negative else p["viscous"]
        curve = (-level if negative else level) + slope * v
        par = self.parameters
        if par["static"].identifiable and par["stribeck_velocity"].identifiable:
            gap = p["static"] - (level if negative else p["coulomb"])
            e = np.exp(-(v / p["stribeck_velocity"]) ** 2)
            curve = curve + (-gap if negative else gap) * e
        return np.where(v > 0 if negative else v < 0, np.nan, curve)

    def to_dict(self) -> dict:
        """Plain JSON data: ``parameters``, ``fit`` (docs/interfaces.md) and the context."""
        from ..provenance import header

        return {
            "parameters": {k: p.to_dict() for k, p in self.parameters.items()},
            "fit": self.fit.to_dict(),
            "form": self.form,
            "direction": self.direction,
            "model": self.model,
            "masses": self.masses.to_dict(),
            "processing": self.processing.to_dict(),
            "excitation": self.excitation.to_dict(),
            "dynamic": self.dynamic.to_dict(),
            "notes": list(self.notes),
            "measurement": self.measurement.to_dict(),
            **header(),
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
