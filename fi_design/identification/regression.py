"""The inverse-dynamics least squares (IDIM-LS, steps 6 and 7 of the package docstring).

The equations of motion as linear regressions on the prepared signals
(:func:`equations`), their weighted least-squares solution with the
autocorrelation-corrected covariance (:func:`solve`), the fit statistics and
the parameters of the sliding friction and the masses.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..display import number, percent, quantity, with_error
from ..errors import DataError
from ..results import frozen_array
from .preprocess import Joint, Prepared
from ..results.identification import UNITS, Fit, Masses, Parameter, Processing, Samples

#: Fewest used (decimated, sliding) samples per direction of motion.
MIN_DIRECTION_SAMPLES = 10
#: A record sampled below this rate is named in the "too little sliding" error [Hz]: a servo
#: log runs at hundreds of Hz or more, and a time_s column written in ms reads 1000 x too
#: slow (its speeds 1000 x too low, under the velocity threshold).
SLOW_RECORD_RATE = 100.0
#: Largest condition number of the column-scaled regressor: beyond it two columns are the same
#: within the record's precision (one speed only: Coulomb and viscous friction alike).
MAX_CONDITION = 1e8

#: Why a mass or friction that comes out negative cannot be right.
IMPLAUSIBLE = ("physically impossible, so the model (mass, Coulomb and viscous friction "
               "constant along the travel) does not describe this record; an unmodelled effect "
               "(friction varying along the rail, a cable force, force ripple) or too little "
               "sliding can cause it, and fi-design reconcile names such effects")

#: An identified total mass beyond this factor of the spec's moving mass, either way, is
#: flagged: a spec's mass is a designer's estimate (drawing or CAD, within some ten or twenty
#: per cent, a referred screw or rotor inertia included), and a clean record identifies the
#: mass to a per cent or better; a factor of 1.5 is beyond both, and below the factor of two
#: at which a force logged in other units (reconcile's force check) is suspected first.
MASS_FACTOR = 1.5
#: Relative force residual of the fit from which the model leaves a force unexplained (a
#: clean simulated record fits to a fraction of a per cent, the real EMPS axis to 2.6 %):
#: such a force leaks into the mass through the filter, and the mass follows the cut-off.
FIT_LEAK = 0.05


def mass_far(total: Parameter, spec) -> bool:
    """Whether the identified total mass lies beyond :data:`MASS_FACTOR` of the spec's
    stage plus cart mass (False without a spec or a positive identified mass)."""
    if spec is None or total.value is None or total.value <= 0.0:
        return False
    ratio = total.value / float(spec.total_mass)
    return not 1.0 / MASS_FACTOR <= ratio <= MASS_FACTOR


def mass_leaks(total: Parameter, spec, fit: Fit) -> bool:
    """Whether the identified mass is not to be written into the spec: far from the spec's
    (:func:`mass_far`) with a fit that leaves :data:`FIT_LEAK` or more of the force
    unexplained, so that a force the model lacks leaks into it (:func:`mass_note` says so).
    """
    return mass_far(total, spec) and fit.relative_error >= FIT_LEAK


#: A unit's factor between the identified and the spec's moving mass (within 2 %), and the
#: slip of a column that gives it: m = F / a, so a force in mN gives 1000 x the mass and a
#: position in mm a thousandth.
UNIT_SLIPS = ((1e3, "force_N logged in mN"), (1e-3, "position_m logged in mm"),
              (1e-6, "position_m logged in µm"), (1e6, "force_N logged in µN"))


def unit_slip(mass: float | None, spec) -> str | None:
    """The column's unit slip an identified total mass [kg] points at, or None.

    The mass lies within 2 % of a unit's factor (:data:`UNIT_SLIPS`) times the spec's
    moving mass (stage + cart): a designer's estimate is off by tens of percent, never by
    exactly 1000.
    """
    if spec is None or mass is None or not mass > 0.0:
        return None
    ratio = mass / float(spec.total_mass)
    return next((what for k, what in UNIT_SLIPS if abs(ratio / k - 1.0) <= 0.02), None)


def mass_note(total: Parameter, spec, proc: Processing, fit: Fit,
              impossible: tuple[str, ...] = ()) -> str:
    """A note when the identified total mass is far from the spec's moving mass, with the cause.

    Empty without a spec, without a positive identified mass (a mass that is not positive
    has a note of its own), or within :data:`MASS_FACTOR` of the spec's stage plus cart mass.
    The likely cause is read from the fit: a relative force residual of :data:`FIT_LEAK` or
    more says the model lacks a force (the mass then depends on the low-pass cut-off, which
    the spec's crossover sets); so does a friction term that came out not positive
    (``impossible``, their names: the model does not describe the record, however close the
    fit); a close fit of plausible terms says the record is consistent with that mass.
    """
    if not mass_far(total, spec):
        return ""
    moving = float(spec.total_mass)
    ratio = total.value / moving
    text = (f"mass = {with_error(total.value, total.std_error, 'kg', 3)} is "
            f"{number(ratio, 3)} times the spec's moving mass (stage + cart = "
            f"{quantity(moving, 'kg', 4)}), beyond a factor of {number(MASS_FACTOR)} either way: ")
    if mass_leaks(total, spec, fit):
        return text + (
            f"the fit leaves {percent(fit.relative_error, 2)} of the force unexplained, so a "
            "force the model lacks (force ripple, a cable force, friction varying along the "
            "rail) most likely leaks into the mass through the low-pass filter, and the mass "
            f"follows its cut-off ({quantity(proc.cutoff, 'Hz', 3)}: {proc.cutoff_rule}), "
            "so another spec's crossover (or identify's cutoff argument) gives another mass. "
            "fi-design reconcile names such effects; do not write this mass into the spec")
    if impossible:
        return text + (
            f"{' and '.join(impossible)} came out not positive (see "
            f"{'their notes' if len(impossible) > 1 else 'its note'}), "
            "so the model does not describe this record and the mass is no evidence that "
            "the spec's masses are off: a force the model lacks (friction varying along the "
            "rail, a cable force, force ripple) most likely leaks into it. fi-design "
            "reconcile names such effects; do not write this mass into the spec")
    slip = unit_slip(total.value, spec)
    if slip is not None:
        return text + (
            f"a unit's factor, and the fit leaves only {percent(fit.relative_error, 2)} of the "
            f"force unexplained: most likely {slip} (the columns are read in N and m); every "
            "force identified here carries the same factor: fix the column, do not write these "
            "values into the spec")
    return text + (
        f"the fit leaves only {percent(fit.relative_error, 2)} of the force unexplained, so "
        "the record is consistent with this mass: most likely the spec's stage and cart "
        "masses are off (the payload, a screw's or rotor's inertia referred to the axis), or force_N is "
        "not in N (a unit slip or the drive's gain)")


def friction_columns(p: Prepared, form: str) -> dict[str, np.ndarray]:
    c = p.cols
    if form == "symmetric":
        return {"coulomb": c["sign"], "viscous": c["vpos"], "viscous_negative": c["vneg"]}
    return {"coulomb": c["pos"], "coulomb_negative": -c["neg"], "viscous": c["vpos"],
            "viscous_negative": c["vneg"]}


def equations(p: Prepared, form: str, joint: Joint,
              direction: int = 0) -> list[tuple[np.ndarray, dict]]:
    """The equations as (left-hand side, {parameter: column}), all on every sample.

    ``direction`` +1 or -1: the record slides that way only, so only that
    direction's Coulomb and viscous friction are columns; the offset is not
    one (a constant and sign(v) are the same column there).
    """
    if direction:
        c = p.cols
        fric = ({"coulomb": c["pos"], "viscous": c["vpos"]} if direction > 0 else
                {"coulomb_negative": -c["neg"], "viscous_negative": c["vneg"]})
        off = {}
    else:
        fric = friction_columns(p, form)
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
class Solution:
    names: list
    theta: np.ndarray
    cov: np.ndarray
    cond: float
    n_used: int
    n_eff: float


def solve(equations: list, used: np.ndarray, source: str | None = None) -> Solution:
    """Weighted least squares over the equations, with the autocorrelation-corrected covariance.

    ``source``: the record's file, named in the error of a record that does not excite every
    parameter.
    """
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
                        column="position_m", source=source)
    Aw = np.vstack([w * A for w, (A, _) in zip(weights, blocks)])
    rw = np.concatenate([w * r for w, r in zip(weights, res)])
    n, k = Aw.shape
    s2 = float(rw @ rw) / max(n - k, 1)
    from scipy.linalg import pinvh

    cov = s2 * pinvh(Aw.T @ Aw)
    n_eff = sum(len(r) / effective_fraction(w * r) for w, r in zip(weights, res))
    inflation = n / n_eff
    sv = svdvals(Aw / np.linalg.norm(Aw, axis=0))
    cond = float(sv[0] / sv[-1]) if sv[-1] > 0 else math.inf
    if cond > MAX_CONDITION:
        raise DataError(f"the record does not excite every parameter (the regressor's condition "
                        f"number is {number(cond, 3)}, above {number(MAX_CONDITION, 1)}, for "
                        f"{', '.join(names)}): it needs acceleration and sliding at varied "
                        "speeds (at one speed Coulomb and viscous friction are alike)",
                        column="position_m", source=source)
    return Solution(names=names, theta=theta, cov=cov * inflation, cond=cond,
                    n_used=int(used.sum()), n_eff=n / inflation)


def effective_fraction(r: np.ndarray) -> float:
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


def force_rss(prep: Prepared, sol: Solution, joint: Joint) -> float:
    """Residual sum of squares of the actuator force per used sample [N^2]."""
    _, fit = fit_statistics(prep, sol, joint)
    return fit.force_rms_residual ** 2


def check_directions(prep: Prepared, proc: Processing, source: str | None) -> int:
    """The directions the record slides in: 0 both, +1 or -1 one only.

    A direction counts with :data:`MIN_DIRECTION_SAMPLES` used samples; in one
    direction only, that direction's friction is identified and the rest is
    not identifiable (:func:`rigid_parameters`).

    Raises
    ------
    DataError
        Too little sliding in either direction.
    """
    used = prep.used
    pos = int(np.sum(used & (prep.v > 0)))
    neg = int(np.sum(used & (prep.v < 0)))
    if max(pos, neg) < MIN_DIRECTION_SAMPLES:
        raise DataError(
            f"too little sliding: {pos} usable samples moving in the positive direction and "
            f"{neg} in the negative one faster than {quantity(proc.velocity_threshold, 'm/s', 3)} "
            f"(at least {MIN_DIRECTION_SAMPLES} in one direction after decimation by "
            f"{proc.decimation}); identification needs sliding at varied speeds"
            + _slow_record_words(proc), column="position_m", source=source)
    if min(pos, neg) >= MIN_DIRECTION_SAMPLES:
        return 0
    return 1 if pos >= MIN_DIRECTION_SAMPLES else -1


def _slow_record_words(proc: Processing) -> str:
    """The record's rate named when it is below :data:`SLOW_RECORD_RATE`, else empty."""
    if proc.sample_rate >= SLOW_RECORD_RATE:
        return ""
    return (f"; the record is sampled at {quantity(proc.sample_rate, 'Hz', 4)}: time_s must be "
            "in s (a column in ms reads 1000 x too slow, its speeds 1000 x too low)")


def direction_words(direction: int) -> tuple[str, str]:
    """(the direction the record slides in, the other one) in words."""
    return ("positive", "negative") if direction > 0 else ("negative", "positive")


def symmetric_view(sol: Solution, direction: int) -> Solution:
    """A one-direction solution in the symmetric layout the dynamic estimates read.

    That direction's Coulomb friction becomes ``coulomb`` (the offset included)
    and its viscous friction stands in for both directions' (the record holds
    no other); a solution of both directions is returned as it is.
    """
    if not direction:
        return sol
    names = list(sol.names)
    level, visc, other = (("coulomb", "viscous", "viscous_negative") if direction > 0 else
                          ("coulomb_negative", "viscous_negative", "viscous"))
    names[names.index(level)] = "coulomb"
    i = names.index(visc)
    theta = np.append(sol.theta, sol.theta[i])
    cov = np.pad(sol.cov, ((0, 1), (0, 1)))
    cov[-1, :-1] = cov[i, :-1]
    cov[:-1, -1] = cov[:-1, i]
    cov[-1, -1] = cov[i, i]
    return Solution(names=names + [other], theta=theta, cov=cov, cond=sol.cond,
                    n_used=sol.n_used, n_eff=sol.n_eff)


def fit_statistics(prep: Prepared, sol: Solution, joint: Joint) -> tuple[Samples, Fit]:
    th = dict(zip(sol.names, sol.theta))
    fric = sum(th.get(n, 0.0) * c for n, c in friction_columns(
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


def rigid_parameters(sol: Solution, form: str, joint: Joint,
                     direction: int = 0) -> dict[str, Parameter]:
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
    if direction:
        return {**out, **_one_direction(est, direction)}
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


def _one_direction(est, direction: int) -> dict[str, Parameter]:
    """The friction of a record that slides one way: that direction's, the rest not identifiable."""
    side, other = direction_words(direction)
    level, visc = ("coulomb", "viscous") if direction > 0 else ("coulomb_negative",
                                                                 "viscous_negative")
    other_level, other_visc = ("coulomb_negative", "viscous_negative") if direction > 0 else \
        ("coulomb", "viscous")
    missing = (f"not identifiable: the record slides in the {side} direction only and holds "
               f"nothing of the {other} one; a record that slides both ways identifies it")
    return {
        level: est(level, f"Coulomb friction sliding in the {side} direction, the force offset "
                          "included (in one direction of motion a constant force and sign(v) "
                          "are the same column)"),
        other_level: Parameter(None, None, "N", False, missing),
        visc: est(visc, f"viscous friction sliding in the {side} direction"),
        other_visc: Parameter(None, None, "N*s/m", False, missing),
        "offset": Parameter(
            None, None, "N", False,
            f"not identifiable: the record slides in the {side} direction only, where a "
            f"constant force and Coulomb friction are the same column; it is included in {level}; "
            "a record that slides both ways separates them"),
    }


def split_masses(sol: Solution, joint: Joint, spec, total: Parameter) -> Masses:
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


def form_note(form: str) -> str:
    if form == "symmetric":
        return ("symmetric form: one Coulomb friction for both directions and a force offset "
                "(the default); the per-direction form (form='per_direction') fits the data "
                "identically with Fc+ = coulomb + offset and Fc- = coulomb - offset")
    return ("per-direction form: Coulomb friction per direction and no offset; the symmetric "
            "form fits the data identically with coulomb = (Fc+ + Fc-) / 2 and offset = "
            "(Fc+ - Fc-) / 2")


def threshold_note(proc: Processing) -> str:
    return (f"samples slower than {quantity(proc.velocity_threshold, 'm/s', 4)} are not used: "
            "near zero "
            "velocity friction is not Coulomb plus viscous (Stribeck effect, presliding, "
            "sticking)")
