"""The identification as one call: :func:`identify`, and its use on other records.

:func:`identify` runs the steps of the package docstring in order: checks,
processing, the inverse-dynamics fit (with the force read as held or sampled,
whichever fits better), the excitation and the dynamic parameters.
:func:`predict_force` applies an identification to another record
(cross-validation); :func:`segment` cuts a record.
"""

from __future__ import annotations

import math
from dataclasses import replace
from types import MappingProxyType
from typing import Callable

import numpy as np

from ..arguments import choice, integer, number
from ..display import number as number_text
from ..display import quantity
from ..errors import ArgumentError, DataError
from ..measured import Measurement, measurement_from_arrays
from ..spec.file import as_spec
from .dynamic import dynamic_parameters
from .events import excitation
from .preprocess import (CROSSOVER_FACTOR, JITTER, check_record, joint_model, prepare,
                         processing)
from .regression import (IMPLAUSIBLE, Solution, check_directions, direction_words, equations,
                         fit_statistics, force_rss, form_note, mass_note, rigid_parameters,
                         split_masses, solve, symmetric_view, threshold_note)
from ..results.identification import FORMS, NAMES, ForcePrediction, IdentificationResult

ProgressCallback = Callable[[str, float], None]


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
        ``to_dict()`` is the JSON of docs/interfaces.md. A record that slides
        in one direction only identifies the mass and that direction's
        friction (the offset included); the rest is not identifiable, with
        the reason (``direction``).

    Raises
    ------
    DataError
        No ``force_N`` column, too few samples, a constant position, sampling
        the filter cannot take, too few sliding samples in both directions;
        the message names the column and what is needed.
    ArgumentError
        An unknown ``form``, a ``spec`` that is not a spec, path or mapping,
        a cut-off, decimation or threshold that is not a positive number.
    SpecError
        A ``spec`` given as a path or mapping that does not validate.

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
    form = choice(form, "form", FORMS)
    if not isinstance(measured, Measurement):
        raise ArgumentError(f"measured must be a Measurement (fi_design.load_measurement), got "
                            f"{type(measured).__name__}")
    spec = None if spec is None else as_spec(spec)
    cutoff = None if cutoff is None else number(cutoff, "cutoff", "Hz", positive=True)
    decimation = None if decimation is None else integer(decimation, "decimation", minimum=1)
    velocity_threshold = None if velocity_threshold is None else \
        number(velocity_threshold, "velocity_threshold", "m/s", positive=True)
    say = progress or (lambda message, fraction: None)
    check_record(measured)
    say("filtering", 0.0)
    proc = processing(measured, spec, cutoff=cutoff, decimation=decimation,
                      velocity_threshold=velocity_threshold)
    joint = joint_model(measured, spec)
    say("least squares", 0.3)
    fits = []
    for hold in (True, False):  # the force as a held command, or as a sampled force
        p = replace(proc, force_hold=hold)
        prep = prepare(measured, p, joint)
        direction = check_directions(prep, p, measured.source)
        sol = solve(equations(prep, form, joint, direction), prep.used, measured.source)
        fits.append((force_rss(prep, sol, joint), p, prep, sol, direction))
    _, proc, prep, sol, direction = min(fits, key=lambda f: f[0])
    samples, fit = fit_statistics(prep, sol, joint)
    say("excitation", 0.5)
    exc = excitation(measured, proc, spec=spec)
    params = rigid_parameters(sol, form, joint, direction)
    masses = split_masses(sol, joint, spec, params["mass"])
    if direction:
        side, other = direction_words(direction)
        shape = (f"the record slides in the {side} direction only: the mass and that "
                 f"direction's Coulomb and viscous friction (the force offset included) are "
                 f"identified; the {other} direction's friction and the offset are not "
                 "identifiable from it")
    else:
        shape = form_note(form)
    notes = list(joint.notes) + [shape, threshold_note(proc)]
    signs = [p.value for k, p in params.items() if k != "offset" and p.value is not None]
    if signs and all(v < 0.0 for v in signs):
        notes.append("the mass and every friction term are negative: force_N most likely has "
                     "the wrong sign (positive force must push the stage towards positive "
                     "position_m); flip the column and identify again")
    for name, p in list(params.items()):
        if p.value is not None and p.value <= 0.0 and name != "offset":
            params[name] = replace(p, note=p.note + "; " + IMPLAUSIBLE)
            notes.append(f"{name} = {quantity(p.value, p.unit, 4)} is not positive: {IMPLAUSIBLE}")
    if cutoff is None and spec is not None:
        from ..model import as_model

        fc = as_model(spec).crossover
        if proc.cutoff < CROSSOVER_FACTOR * fc * (1.0 - 1e-9):
            notes.append(f"the record is sampled at {quantity(proc.sample_rate, 'Hz', 4)}, too "
                         f"slowly for the loop's {quantity(fc, 'Hz', 4)} crossover: the "
                         f"low-pass is capped at {quantity(proc.cutoff, 'Hz', 4)} instead of "
                         f"{number_text(CROSSOVER_FACTOR)} x the crossover, so the loop's own "
                         "dynamics are smeared into the friction and the mass read here; log at "
                         f"least {quantity(4.0 * CROSSOVER_FACTOR * fc, 'Hz', 3)} (a time_s "
                         "column in ms reads 1000 x too slow)")
    for name, m in (("stage mass", masses.stage), ("cart mass", masses.cart)):
        if masses.stage_std_error is not None and m <= 0.0:  # both fitted (a two-mass record)
            notes.append(f"the {name} = {quantity(m, 'kg', 4)} is not positive: {IMPLAUSIBLE}; "
                         "a negative mass also follows from force_N of the wrong sign")
    impossible = tuple(name for name, p in params.items() if name not in ("mass", "offset")
                       and p.value is not None and p.value <= 0.0)
    far = mass_note(params["mass"], spec, proc, fit, impossible)
    if far:
        params["mass"] = replace(params["mass"], note=params["mass"].note + "; far from the "
                                 "spec's moving mass (see the notes)")
        notes.append(far)
    if measured.disturbance is not None:
        notes.append("force_N is used as the force that acts (the injected disturbance_N "
                     "included); the controller's own output force_N - disturbance_N is not")
    say("dynamic parameters", 0.7)
    dynamic, details = dynamic_parameters(measured, proc, joint, symmetric_view(sol, direction),
                                          form if not direction else "symmetric", exc, spec)
    sliding = next((params[k].value for k in ("coulomb", "coulomb_negative")
                    if params[k].value is not None), None)  # a one-way record has one of them
    for name, p in dynamic.items():
        if name == "static" and p.value is not None and sliding is not None \
                and p.value < sliding:
            p = replace(p, note=p.note + f"; below the Coulomb friction: {IMPLAUSIBLE}")
            notes.append(f"static = {quantity(p.value, 'N', 4)} lies below the Coulomb friction: "
                         f"{IMPLAUSIBLE}")
        params[name] = p
    say("done", 1.0)
    return IdentificationResult(
        parameters=MappingProxyType({k: params[k] for k in NAMES}), fit=fit, form=form,
        model=joint.model, masses=masses, processing=proc, excitation=exc,
        notes=tuple(notes), samples=samples, measurement=measured, spec=spec,
        dynamic=details, direction={0: "both", 1: "positive", -1: "negative"}[direction])


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
    check_record(measured)
    proc = result.processing
    fs = 1.0 / measured.sample_period
    if abs(fs / proc.sample_rate - 1.0) > JITTER:
        raise DataError(f"sampled at {quantity(fs, 'Hz', 6)}, the identification at "
                        f"{quantity(proc.sample_rate, 'Hz', 6)}",
                        column="time_s", source=measured.source)
    joint = joint_model(measured, result.spec)
    if joint.model != result.model:
        raise DataError(f"a {joint.model} record cannot be predicted by a {result.model} "
                        "identification", column="deflection_m", source=measured.source)
    prep = prepare(measured, proc, joint)
    th = {n: p.value for n, p in result.parameters.items() if p.value is not None}
    if result.model == "two_mass":
        th["stage_mass"], th["cart_mass"] = result.masses.stage, result.masses.cart
    sol = Solution(names=list(th), theta=np.array(list(th.values())),
                    cov=np.zeros((len(th), len(th))), cond=math.nan,
                    n_used=int(prep.used.sum()), n_eff=math.nan)
    samples, fit = fit_statistics(prep, sol, joint)
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

    span = (f"{'' if start is None else quantity(start, 's', 6) + ' '}to"
            f"{'' if stop is None else ' ' + quantity(stop, 's', 6)}")
    return measurement_from_arrays(
        col(measured.time), col(measured.reference), col(measured.position),
        force_N=col(measured.force), deflection_m=col(measured.deflection),
        disturbance_N=col(measured.disturbance),
        source=f"{measured.source or 'record'} ({span.strip()})")

