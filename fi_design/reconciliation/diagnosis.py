"""Structure diagnosis: when no missing effect explains the gap, what might.

When the nominal misfit is far above the noise (:data:`STRUCTURE_MISFIT`
noise units or more) and no candidate removes most of it, or the best fit of
the catalogue still leaves :data:`STRUCTURE_MISFIT` noise units or more, no
effect of the catalogue is "the" answer: the model's structure (or the
record) does not match. The nominal residual (force when recorded, else
position) then points at likely causes, each with the share of the residual
that points there:

- **controller**: energy at and above a third of the loop's crossover, where
  the controller shapes the response (gains, the derivative's filter and
  input, sample rate, delay); an open-loop replay (``drive="force"``) has no
  controller, and the same energy points at the **measured force** there
  (force_N's timing, filter or gain, or fast mechanics the spec lacks);
- **initial state**: residual concentrated at the start of the record (the
  replay's starting position, velocity or controller state; open loop, the
  state of the mechanics alone);
- **mass**: residual that follows the reference acceleration (moving mass,
  feedforward);
- **disturbance**: slow residual (below a thirtieth of the crossover) left
  after the velocity, direction and acceleration terms are taken out (a
  force the model lacks: cable, drift, a load; open loop, an offset of
  force_N too).

The record itself is checked too (:func:`force_check`): when the force
channel stays :data:`STRUCTURE_MISFIT` noise units (RMS) or more from the
model after the best fit, and a factor and an offset on the measured force
remove :data:`FORCE_FIX_SHARE` or more of that residual's energy, a negative
factor says that ``force_N``'s sign looks wrong (**force sign**), a factor
beyond :data:`FORCE_SCALE_LIMIT` either way that its scale does (**force
scale**: a unit or gain slip). Such a record cannot be explained by any
effect, and the reconciliation names none.

An open-loop replay has no model force to compare: the measured force drives
the model. There :func:`drive_check` fits the force to the motion it drives,
``force = factor * M * a + Fc sign(v) + b v + offset`` with the spec's moving
mass ``M`` while the stage slides (the identification's inverse dynamics,
every signal low-passed at the loop's crossover): a negative factor is a
flipped sign (the force pushes against the acceleration it is said to
cause), a factor beyond :data:`FORCE_SCALE_LIMIT` either way a unit or gain
slip. The record alone decides it, so no effect is searched.
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
#: A factor on the measured force within this ratio of 1 either way is the model's scale:
#: a spec's mass or friction off by up to a factor of two (the catalogue's mass_error and
#: friction effects) scales the force that much; a unit or gain slip (mN, kN, kgf: 9.81,
#: lbf: 4.45, a drive's current in A) scales it further.
FORCE_SCALE_LIMIT = 2.0
#: Share of the force residual's energy a factor and an offset on force_N must remove for
#: its sign or scale to be called wrong (two numbers that explain most of a channel the best
#: fit of the catalogue leaves far above noise).
FORCE_FIX_SHARE = 0.75
#: Causes that are faults of the record, not of the model: no effect is named with one.
RECORD_CAUSES = ("force_sign", "force_scale")
#: Share of the peak speed above which the open-loop check counts the stage as sliding
#: (where friction is Coulomb plus viscous, as the identification's default threshold).
SLIDING_SHARE = 0.1
#: Share of the sliding force's variance the inverse dynamics must explain for the open-loop
#: check to judge the factor (the motion must be what the force does).
DRIVE_FIT_MIN = 0.75
#: Standard errors by which the open-loop factor must lie beyond zero (sign) or beyond
#: :data:`FORCE_SCALE_LIMIT` (scale) to be called wrong (samples counted independent at twice
#: the cut-off).
DRIVE_FACTOR_SIGMAS = 2.0


def diagnose(cmp: Comparison, nominal: ModelRun, chi2_nominal: float,
             best_explained: float, after: ModelRun | None = None,
             chi2_after: float | None = None, best_fit: str = "",
             drive: ForceCheck | None = None) -> Diagnosis:
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
    after : ModelRun, optional
        The run of the model after the best fit of the catalogue (default
        the nominal run): the record's force is checked against it.
    chi2_after : float, optional
        The weighted squared residual of the best fit of the catalogue [-]
        (default ``chi2_nominal``).
    best_fit : str
        The effect(s) of that fit, for the message.
    drive : ForceCheck, optional
        Open loop: :func:`drive_check` of ``cmp`` where the caller has it already (it
        reads the record alone); default worked out here.
    """
    misfit = math.sqrt(chi2_nominal / cmp.n_points)
    misfit_after = misfit if chi2_after is None else math.sqrt(chi2_after / cmp.n_points)
    use_force = cmp.has_force
    channel = "force" if use_force else "position"
    meas = cmp.meas.force if use_force else cmp.meas.position
    model = nominal.force if use_force else nominal.position
    r = np.where(np.isfinite(model), meas - model, 0.0)
    crossover = cmp.model.crossover
    spec = _spectrum(r, cmp.t)
    if cmp.has_force:
        check = force_check(cmp, nominal if after is None else after)
    else:
        check = drive_check(cmp) if drive is None else drive
    causes = _causes(cmp, r, crossover, use_force)
    if check.cause is not None:
        causes.append(check.cause)
    causes = sorted(causes, key=lambda c: -c.share)
    record = check.cause is not None
    unexplained = best_explained < EXPLAINED_MIN or misfit_after >= STRUCTURE_MISFIT
    mismatch = record or (misfit >= STRUCTURE_MISFIT and unexplained)
    message = ""
    if mismatch:
        message = _message(misfit, misfit_after, best_explained, best_fit, causes, check)
    return Diagnosis(mismatch=mismatch, misfit=misfit, misfit_limit=STRUCTURE_MISFIT,
                     best_explained=float(best_explained), channel=channel,
                     causes=tuple(causes), message=message, frequency=_frozen(spec.frequency),
                     spectrum=_frozen(spec.density), crossover=float(crossover),
                     misfit_after=float(misfit_after), best_fit=best_fit,
                     force_scale=check.scale)


def record_fault(diagnosis: Diagnosis) -> Cause | None:
    """The cause that faults the record itself (force_N's sign or scale), if any."""
    return next((c for c in diagnosis.causes if c.name in RECORD_CAUSES), None)


def _message(misfit: float, misfit_after: float, best_explained: float, best_fit: str,
             causes: list, check: ForceCheck) -> str:
    """The paragraph of a mismatch: how far, what the catalogue does, the likely causes."""
    text = (f"The nominal model misses the record by {number(misfit, 3)} noise units (RMS)"
            + (", far above the noise" if misfit >= STRUCTURE_MISFIT else ""))
    verdict = "the model's structure does not match the record"
    if best_explained < EXPLAINED_MIN:
        text += (", and no catalogue effect explains most of it (the best removes "
                 f"{percent(best_explained, 2)} of the gap)")
    elif misfit_after >= STRUCTURE_MISFIT:
        text += (f", and the best fit of the catalogue ({best_fit or 'none'}) still leaves "
                 f"{number(misfit_after, 3)} noise units")
        verdict = ("no catalogue effect explains the record" if check.cause is not None else
                   "the model's structure does not match the record, and no catalogue effect "
                   "closes the gap")
    if check.cause is not None:
        what = "column" if check.cause.name == "force_sign" else "column (or the spec)"
        return (text + (f": {verdict}" if verdict.startswith("no catalogue") else "")
                + f". {check.cause.detail} No effect is named from such a record; correct the "
                f"{what} and reconcile again.")
    top = [c for c in causes if c.share >= 0.1] or causes[:1]
    return (text + f": {verdict}. Likely causes, strongest first: "
            + "; ".join(f"{c.name.replace('_', ' ')} ({percent(c.share, 2)})" for c in top)
            + ". See the residual and its spectrum.")


class ForceCheck(NamedTuple):
    """The record's force against the model's: the factor, and a fault when there is one."""

    scale: float | None
    cause: Cause | None


def force_check(cmp: Comparison, run: ModelRun) -> ForceCheck:
    """Whether force_N's sign or scale looks wrong against the model after the best fit.

    The measured force is fitted as ``scale * model + offset`` (least
    squares over every sample). A fault is reported only when the force
    residual stays :data:`STRUCTURE_MISFIT` noise levels (RMS) or more and
    that fit removes :data:`FORCE_FIX_SHARE` or more of its energy: then a
    negative ``scale`` is a flipped sign (its size is not judged: the replay
    started from the flipped first sample, which bends the model's force
    too), a positive one beyond :data:`FORCE_SCALE_LIMIT` either way a unit
    or gain slip.

    Parameters
    ----------
    cmp : Comparison
        The comparison (a compared force channel: closed loop with force_N).
    run : ModelRun
        The model after the best fit of the catalogue.
    """
    if not cmp.has_force or not run.ok:
        return ForceCheck(None, None)
    ok = np.isfinite(run.force)
    meas, model = cmp.meas.force[ok], run.force[ok]
    if len(model) < 3 or np.ptp(model) <= 0:
        return ForceCheck(None, None)
    A = np.column_stack([model, np.ones(len(model))])
    (scale, offset), *_ = np.linalg.lstsq(A, meas, rcond=None)
    r0 = meas - model
    r1 = meas - A @ np.array([scale, offset])
    rms0, rms1 = math.sqrt(float(r0 @ r0) / len(r0)), math.sqrt(float(r1 @ r1) / len(r1))
    share = 1.0 - (rms1 / rms0) ** 2 if rms0 > 0 else 0.0
    flipped = scale < 0
    # a flipped record starts the replay's controller from the wrong first force sample, so
    # the model's force is bent too and the factor's size says nothing: its sign alone counts
    scaled = not flipped and not 1.0 / FORCE_SCALE_LIMIT <= scale <= FORCE_SCALE_LIMIT
    if rms0 < STRUCTURE_MISFIT * cmp.noise.force or share < FORCE_FIX_SHARE or \
            not (flipped or scaled):
        return ForceCheck(float(scale), None)
    if float(np.ptp(meas)) <= 0.0:  # no correlation to speak of: say what the column holds
        return ForceCheck(float(scale), Cause("force_scale", float(min(max(share, 0.0), 1.0)), (
            f"force_N is {quantity(float(meas[0]), 'N', 3)} in every row, where the model's "
            f"force moves by {quantity(float(np.ptp(model)), 'N', 3)}: the record carries no "
            "force signal. Check that the logger records the drive's force (command) and "
            "that the column is the one meant.")))
    corr = float(np.corrcoef(meas, model)[0, 1])
    what = "sign" if flipped else "scale"
    detail = (f"force_N's {what} looks wrong: the measured force is {number(scale, 3)} times "
              f"the model's (correlation {fixed(corr, 2)}, after the best fit); with that "
              f"factor and an offset of {quantity(offset, 'N', 3)} its residual drops from "
              f"{quantity(rms0, 'N', 3)} to {quantity(rms1, 'N', 3)} RMS (noise "
              f"{quantity(cmp.noise.force, 'N', 3)}). ")
    detail += ("Check the sign convention of the logged force (positive pushes the stage "
               "towards positive position_m) and flip force_N." if flipped else
               "Check force_N's unit (N) and the logger's gain, and the spec's masses and "
               "friction: the model's force follows them, so a spec of another stage, or "
               "masses that far off, give the same factor.")
    return ForceCheck(float(scale), Cause("force_sign" if flipped else "force_scale",
                                          float(min(max(share, 0.0), 1.0)), detail))


def drive_check(cmp: Comparison) -> ForceCheck:
    """Whether force_N's sign or scale looks wrong against the motion it drives (open loop).

    Position and force are low-passed at the loop's crossover (zero phase),
    the velocity and acceleration taken from the filtered position, and
    where the stage slides (speed above :data:`SLIDING_SHARE` of its peak)
    the force is fitted as ``factor * M * a + Fc * sign(v) + b * v + offset``
    (``sign(v)`` filtered like the force; ``M`` the spec's moving mass, the
    cart included). The factor is judged when the fit explains
    :data:`DRIVE_FIT_MIN` of the force's variance, and only beyond
    :data:`DRIVE_FACTOR_SIGMAS` standard errors (the samples counted
    independent at twice the cut-off): below zero, the force pushes against
    the acceleration it is said to drive (**force sign**); beyond
    :data:`FORCE_SCALE_LIMIT` either way, a unit or gain slip (**force
    scale**).

    Parameters
    ----------
    cmp : Comparison
        The comparison of an open-loop replay (``drive="force"``).
    """
    meas = cmp.meas
    if cmp.drive != "force" or meas.force is None:
        return ForceCheck(None, None)
    t = cmp.t
    dt = float(np.median(np.diff(t)))
    cutoff = min(cmp.model.crossover, 0.4 / dt)
    x = _band(meas.position, t, None, cutoff)
    v = np.gradient(x, t)
    a = np.gradient(v, t)
    sliding = np.abs(v) > SLIDING_SHARE * float(np.max(np.abs(v)))
    mass = cmp.model.total_mass
    X = np.column_stack([mass * a, _band(np.sign(v), t, None, cutoff), v,
                         np.ones_like(v)])[sliding]
    f = _band(meas.force, t, None, cutoff)[sliding]
    n_eff = len(f) * min(1.0, 2.0 * cutoff * dt)
    if n_eff <= 2 * X.shape[1] or np.ptp(f) <= 0:
        return ForceCheck(None, None)
    coef, *_ = np.linalg.lstsq(X, f, rcond=None)
    r = f - X @ coef
    fit = 1.0 - float(np.var(r)) / float(np.var(f))
    cov = np.linalg.pinv(X.T @ X) * float(r @ r) / (len(f) - X.shape[1]) * len(f) / n_eff
    scale = float(coef[0])
    error = math.sqrt(max(float(cov[0, 0]), 0.0))
    low, high = scale - DRIVE_FACTOR_SIGMAS * error, scale + DRIVE_FACTOR_SIGMAS * error
    flipped = high < 0
    scaled = low > FORCE_SCALE_LIMIT or 0 < high < 1.0 / FORCE_SCALE_LIMIT
    if fit < DRIVE_FIT_MIN or not (flipped or scaled):
        return ForceCheck(scale, None)
    what = "sign" if flipped else "scale"
    detail = (f"force_N's {what} looks wrong: fitted to the motion it drives while the stage "
              f"slides (mass times acceleration plus friction and an offset, below "
              f"{quantity(cutoff, 'Hz', 3)}), the measured force is {number(scale, 3)} times "
              f"the force the spec's moving mass ({quantity(mass, 'kg', 3)}) needs (R^2 "
              f"{fixed(fit, 2)}, standard error {number(error, 2)}), and the open-loop replay "
              "drives the model with it. ")
    detail += ("Check the sign convention of the logged force (positive pushes the stage "
               "towards positive position_m) and flip force_N." if flipped else
               "Check force_N's unit (N) and the logger's gain (and the spec's masses, if the "
               "column is right).")
    return ForceCheck(scale, Cause("force_sign" if flipped else "force_scale",
                                   float(min(max(fit, 0.0), 1.0)), detail))


def record_diagnosis(cmp: Comparison, nominal: ModelRun, chi2_nominal: float,
                     check: ForceCheck) -> Diagnosis:
    """The diagnosis of an open-loop record whose force is at fault (:func:`drive_check`).

    No effect is searched. The fault is the one cause: the structural causes
    read the residual of a replay driven by the wrong force (and name a
    controller the open loop does not have).
    """
    ran = nominal.ok and math.isfinite(chi2_nominal)
    misfit = math.sqrt(chi2_nominal / cmp.n_points) if ran else math.inf
    if ran:
        r = np.where(np.isfinite(nominal.position), cmp.meas.position - nominal.position, 0.0)
        spec = _spectrum(r, cmp.t)
        text = (f"The nominal model misses the record by {number(misfit, 3)} noise units (RMS)"
                + (", far above the noise" if misfit >= STRUCTURE_MISFIT else "") + ". ")
    else:
        spec = Spectrum(np.zeros(0), np.zeros(0))
        # the check's finding replaces the simulator's guess at the cause
        text = f"The nominal model fails on this record ({nominal.message.split(';')[0]}). "
    message = (text + check.cause.detail + " No effect is searched or named from such a "
               "record; correct the column and reconcile again.")
    return Diagnosis(mismatch=True, misfit=misfit, misfit_limit=STRUCTURE_MISFIT,
                     best_explained=0.0, channel="position", causes=(check.cause,),
                     message=message, frequency=_frozen(spec.frequency),
                     spectrum=_frozen(spec.density), crossover=float(cmp.model.crossover),
                     misfit_after=misfit, best_fit="", force_scale=check.scale)


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


def _offset_text(cmp: Comparison) -> str:
    """The record's start offset for the initial-state cause, when the replay warns of one."""
    if not cmp.notes:
        return ""
    x0, r0 = float(cmp.meas.position[0]), float(cmp.meas.reference[0])
    return (f" The record's position_m starts {quantity(x0 - r0, 'm', 4)} from reference_m: "
            "see the warning (an encoder or homing offset between the columns?).")


def _causes(cmp: Comparison, r: np.ndarray, crossover: float, use_force: bool) -> list[Cause]:
    """Shares of the residual's energy (its mean included) that point at each cause."""
    unit = "N" if use_force else "m"
    t = cmp.t
    total = float(r @ r) or 1e-300
    out = []
    open_loop = cmp.drive == "force"
    fast = _band(r, t, crossover / 3.0, None)
    high = float(fast @ fast) / total
    band = (f"{percent(high, 2)} of the residual's energy lies at or above a third of the "
            f"loop's crossover ({quantity(crossover, 'Hz', 3)}), where ")
    if open_loop:
        # no controller in the replay: the recorded force shapes the fast response
        out.append(Cause("measured_force", min(high, 1.0), band +
                         "the recorded force alone drives the open-loop replay: check force_N "
                         "(its timing against position_m, the logger's filter, the drive's "
                         "gain) and fast dynamics of the mechanics the spec lacks (a "
                         "resonance, a compliance)."))
    else:
        out.append(Cause("controller", min(high, 1.0), band +
                         "the controller shapes the response: check the controller description "
                         "(gains, the derivative's input and filter, sample rate, delay)."))
    window = max(START_SHARE * cmp.duration, cmp.settle_window)
    first = t <= t[0] + window
    frac_t = float(np.mean(first))
    frac_ss = float(r[first] @ r[first]) / total
    start = max(0.0, (frac_ss - frac_t) / (1.0 - frac_t)) if frac_t < 1.0 else 0.0
    if open_loop:
        state = ("the state of the mechanics the open-loop replay starts from (position and "
                 "velocity from the record, the friction's presliding state"
                 + (", the isolator's deflection)." if cmp.iso else ")."))
    else:
        state = ("the state the replay starts from (position, velocity, the controller's "
                 "integrator).")
    out.append(Cause("initial_state", start,
                     f"{percent(frac_ss, 2)} of the residual's energy lies in the first "
                     f"{quantity(window, 's', 3)} ({percent(frac_t, 2)} of the record): check "
                     + state + _offset_text(cmp)))
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
                     "cable, a drift" + (", or an offset of force_N" if open_loop else "")
                     + ")."))
    return out
