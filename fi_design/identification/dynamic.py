"""LuGre's dynamic parameters, each from the part of the record that carries it.

Static friction Fs, the Stribeck velocity vs and the bristle stiffness sigma0
act near zero velocity, where the inverse-dynamics fit leaves the samples
out. Each is estimated from its own excitation with the fits of
:mod:`.lugrefit`, the inverse-dynamics estimates (mass, Coulomb and viscous
friction, offset) fixed and their errors propagated, or reported
``identifiable: false`` with a note naming the experiment that would
identify it. The events behind every estimate are in
:class:`~.results.Dynamic` (JSON ``dynamic``).

**Static friction, from breakaways after a stop.** A breakaway
(:func:`~.events.excitation`: a rest, or creep slower than a tenth of
the velocity threshold, after sliding and followed by motion) is read on the
friction force F = u - m a - offset (the drive force minus the identified
inertia and offset) in the direction s of the motion that follows. Its
*onset* is the maximum of s F between the rest and that motion: the force at
which the bearing lets go, where its creep speed v_p is read. The *loading
branch* runs from the lowest s F since the previous sliding (after the last
motion against s beyond three velocity noise levels) to the onset, without
the samples within the zero-phase filter's reach of the onset
(:data:`~.preprocess.REACH_PERIODS` cut-off periods: the filter smears the
drop of friction after the onset into them). On it the bristles load up to
their saturation level Fs; one fit per event (:func:`~.lugrefit.fit_branches`)
gives one value. The force at the onset itself is not the estimate: LuGre's
friction peaks where the bearing already creeps, at g(v_p) = Fc + (Fs - Fc)
exp(-(v_p/vs)^2) < Fs (1 % to 10 % below Fs on the records of the tests), and
the filter moves the peak by as much again. With vs unknown the branch is
used only where the creep is slower than :data:`CREEP_FRACTION` of v_p
(never below three velocity noise levels), where g is Fs to within
(Fs - Fc)(v / vs)^2; when the record also identifies vs (below) the branches
are fitted again over their whole length with the level following the
Stribeck curve at the measured creep speed, vs's error propagated. An event
counts when its branch holds at least :data:`MIN_BRANCH_SAMPLES` samples and
rises by at least :data:`MIN_RISE` of the level, up to at least
:data:`SATURATION` of it (a bearing that stopped with its bristles loaded in
the breakaway's direction shows no branch). The estimate is the mean over
the events; its standard error combines the scatter between them (at least
their own fit errors) with the propagated errors, common to all events.
With one event the scatter is unknown: its fit error is widened by the
change of the estimate when the bristle damping is left out of the model.

**Bristle stiffness, from presliding.** The same branch fits give sigma0 per
breakaway (the slope of friction against displacement where the bristles
are far from saturation), and so does every full cycle of presliding
reversals (small reversals that never slide, e.g. a small-amplitude sine;
one fit per cycle, a branch per half cycle, the level fixed at the
identified static friction, its error propagated, or fitted when there is
none). An event counts when its presliding displacement spans at least
:data:`MIN_SPAN` position resolutions (one encoder count, or the position
noise if larger). The estimate combines the events as for static friction.
With an isolator the joint's compliance adds in series: on a record with
``deflection_m`` the cart's own position x1 - d is used; without it the
spec's joint compliance 1/k is removed from the displacement, and sigma0 is
identifiable only if the bristles' own compliance is at least
:data:`MIN_OWN_COMPLIANCE` of the total (else it would rest on the spec's k).

**Stribeck velocity, from steady low-speed sliding.** Samples sliding in one
direction between three times the velocity noise and the fit's velocity
threshold, *steadily* (the speed changing by less than :data:`STEADY_RATE`
while the bearing travels the bristles' relaxation distance Fs / sigma0,
identified, or the spec's, said so), with these conditions holding over the
filter's reach on both sides, are fitted with the steady-state Stribeck
curve (:func:`~.lugrefit.fit_stribeck`; a slow velocity sweep through zero
provides them): Fc fixed at the identified value and Fs at the breakaway
estimate when there is one (both errors propagated), else fitted as well.
vs is identifiable when at least :data:`MIN_STEADY_SAMPLES` samples lie below
:data:`STEADY_BELOW` x vs and as many above :data:`STEADY_ABOVE` x vs, and its
relative standard error stays below :data:`MAX_RELATIVE_ERROR`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..display import number, percent, quantity, with_error
from .lugrefit import (Branch, LsqFit, Sliding, extended, fit_branches, fit_stribeck,
                       friction_force)
from .preprocess import Joint, Trace, trace
from ..results.identification import (DYNAMIC, UNITS, BranchFit, Dynamic, Excitation, Parameter,
                                      Processing, SweepFit)

#: Branch samples creeping faster than this fraction of the creep speed at the onset are left out.
CREEP_FRACTION = 1.0 / 3.0
#: Fewest samples of a loading branch or presliding half cycle.
MIN_BRANCH_SAMPLES = 30
#: A breakaway counts for static friction when its branch rises by this fraction of the level...
MIN_RISE = 0.5
#: ... up to this fraction of it (the bristles' saturation is seen).
SATURATION = 0.5
#: Presliding displacement needed for the bristle stiffness, in position resolutions.
MIN_SPAN = 20.0
#: With a joint compliance in series, the bristles' own share of the compliance needed.
MIN_OWN_COMPLIANCE = 0.25
#: Steady samples below STEADY_BELOW x vs and above STEADY_ABOVE x vs are needed ...
STEADY_BELOW = 0.7
#: ... see :data:`STEADY_BELOW`.
STEADY_ABOVE = 1.5
#: ... at least this many on each side (full-rate samples).
MIN_STEADY_SAMPLES = 50
#: An estimate whose standard error exceeds this fraction of its value is not identifiable.
MAX_RELATIVE_ERROR = 0.5
#: Sliding counts as steady when the speed changes by less than this fraction while the bearing
#: travels its bristles' relaxation distance Fs / sigma0 (LuGre's friction then follows g(v)).
STEADY_RATE = 0.1

_EXPERIMENT = {
    "static": "moves that come to rest and break away again with a slow force ramp (a PID "
              "loop that hunts, a dwell-and-go move that starts gently or reverses), or a slow "
              "velocity sweep through zero",
    "stribeck_velocity": "a slow velocity sweep through zero, from a few times the expected "
                         "Stribeck velocity in one direction to the same in the other, slow "
                         "enough that the inertial force stays small against friction",
    "bristle_stiffness": "a small-amplitude sine or small steps in presliding (excursions of "
                         "a few micrometres, below the breakaway displacement), resolved by "
                         "the position sensor, or breakaways with a slow force ramp",
}


@dataclass(frozen=True, eq=False)
class _Fixed:
    """An estimate held fixed in a later fit: value, variance, covariance with the sliding ones."""

    value: float
    var: float
    cov: np.ndarray


@dataclass(frozen=True, eq=False)
class _Estimate:
    """One event's estimate: value, statistical error, sensitivity to P = (theta, kappa, vs)."""

    value: float
    stat: float
    row: np.ndarray


class _Context:
    """The record's trace, the sliding estimates and the fixed low-speed estimates (internal)."""

    def __init__(self, tr: Trace, sliding: Sliding, proc: Processing):
        self.tr, self.sliding, self.proc = tr, sliding, proc
        self.n = len(sliding.names)
        self.F = friction_force(tr, sliding.names, sliding.theta)

    def space(self, level: _Fixed | None, vs: _Fixed | None) -> np.ndarray:
        """Covariance of P = (sliding estimates, kappa = 1 / Fs, vs); zero where not fixed."""
        k = _kappa(level) if level is not None else None
        extras = [(0.0, 0.0, None) if e is None else (e.value, e.var, e.cov) for e in (k, vs)]
        return extended(self.sliding, extras)[1]

    def fit(self, branches: list[Branch], level: _Fixed | None, vs: _Fixed | None,
            damping: bool = True) -> tuple[LsqFit, list[str]]:
        """fit_branches with the level (as kappa) and vs fixed where given; (fit, fixed keys)."""
        k = _kappa(level) if level is not None else None
        keys = [name for name, e in (("kappa", k), ("vs", vs)) if e is not None]
        given = {"kappa": k, "vs": vs}
        p, C = extended(self.sliding, [(given[x].value, given[x].var, given[x].cov)
                                       for x in keys])
        fit = fit_branches(self.tr, self.sliding, branches, damping=damping,
                           fixed={x: given[x].value for x in keys}, cov_p=C)
        return fit, keys

    def row(self, fit: LsqFit, i: int, keys: list[str]) -> np.ndarray:
        """Sensitivity of component ``i`` to P = (sliding estimates, kappa, vs)."""
        g = np.zeros(self.n + 2)
        g[:self.n] = fit.G[i][:self.n]
        for j, key in enumerate(keys):
            g[self.n + ("kappa", "vs").index(key)] = fit.G[i][self.n + j]
        return g



def _speed_range(speed: np.ndarray) -> str:
    """The range of sliding speeds [m/s] of a selection, for a sentence (``0.2 to 1.5 mm/s``)."""
    return quantity((float(speed.min()), float(speed.max())), "m/s", 3, joiner=" to ")

def _kappa(level: _Fixed) -> _Fixed:
    """1 / Fs with its variance and covariance."""
    k = 1.0 / level.value
    return _Fixed(k, level.var * k ** 4, -level.cov * k ** 2)


def dynamic_parameters(measured, proc: Processing, joint: Joint, sol, form: str,
                       exc: Excitation, spec=None) -> tuple[dict[str, Parameter], Dynamic]:
    """Static friction, Stribeck velocity and bristle stiffness from a record.

    Parameters
    ----------
    measured : fi_design.measured.Measurement
        The record.
    proc : Processing
        Filter settings and velocity threshold of the inverse-dynamics fit.
    joint : Joint
        The joint model (rigid, two-mass).
    sol : fi_design.identification.regression.Solution
        The inverse-dynamics solution (its estimates fixed, their covariance
        propagated).
    form : str
        ``"symmetric"`` or ``"per_direction"``: static friction is reported
        in the same form (per direction: of the positive direction, the
        offset absorbed).
    exc : Excitation
        The events found in the record.
    spec : fi_design.spec.Spec, optional
        With an isolator and no deflection column, its joint compliance; its
        Fs / sigma0 judges steady sliding when the record does not give them.

    Returns
    -------
    (dict of str to Parameter, Dynamic)
        The three parameters (in the order of :data:`~.results.DYNAMIC`) and
        the per-event details.

    Notes
    -----
    Two passes when the record identifies the Stribeck velocity: the
    breakaways' branches are fitted with a constant level first; with vs
    from the steady sliding, they are fitted again with the level following
    the Stribeck curve at the measured creep speed (vs fixed, its error
    propagated), and vs again with the new Fs.
    """
    ctx = _Context(trace(measured, proc, joint, spec), Sliding.from_solution(
        sol.names, sol.theta, sol.cov), proc)
    vs = None
    for _ in range(2):
        events = [_breakaway(ctx, ev, vs) for ev in exc.events]
        static, level = _static(ctx, events, form, vs, exc)
        runs = [r for seg in exc.presliding_segments for r in _presliding(ctx, seg, level, vs)]
        stiffness = _stiffness(ctx, events, runs, level, vs, exc)
        sweep, stribeck, vs_new = _stribeck(ctx, level, _relaxation(level, stiffness, spec))
        if vs_new is None or vs is not None or level is None:
            break
        vs = vs_new
    details = Dynamic(branches=tuple(e[0] for e in events + runs), sweep=sweep)
    out = {"static": static, "stribeck_velocity": stribeck, "bristle_stiffness": stiffness}
    if ctx.tr.compliance > 0.0:  # an isolated stage recorded without its deflection
        why = ("; the record has no deflection_m column, so the stage's motion holds the joint's "
               "deflection (its compliance 1/k = "
               f"{quantity(ctx.tr.compliance, 'm/N', 3)} from the spec is "
               "removed from the displacement, but the speeds are the stage's): a record with "
               "deflection_m measures the cart's own motion")
        out = {k: p if p.identifiable else replace(p, note=p.note + why) for k, p in out.items()}
    return {k: out[k] for k in DYNAMIC}, details


def _combine(estimates: list[_Estimate], C: np.ndarray, extra: float = 0.0):
    """Mean of per-event values and its variances: (mean, statistical, propagated, row).

    The statistical variance of the mean is the scatter between events over n,
    at least their own fit errors; with one event its fit error widened by
    ``extra``. The propagated part is common to all events (the same fixed
    estimates), through the mean sensitivity row.
    """
    v = np.array([e.value for e in estimates])
    own = float(np.mean([e.stat ** 2 for e in estimates]))
    n = len(v)
    var = max(float(np.var(v, ddof=1)), own) / n if n > 1 else own + extra ** 2
    g = np.mean([e.row for e in estimates], axis=0)
    return float(np.mean(v)), var, float(g @ C @ g), g


# --------------------------------------------------------------------------- breakaways


def _breakaway(ctx: _Context, event, vs: _Fixed | None):
    """One breakaway: (BranchFit, (LsqFit, keys) or None, Branch or None)."""
    tr, F, proc = ctx.tr, ctx.F, ctx.proc
    t = tr.time
    ia, ib = (min(int(np.searchsorted(t, x)), len(t) - 1) for x in event)
    s = float(np.sign(tr.v[ib])) or 1.0
    ion = ia + int(np.argmax(s * F[ia:ib + 1]))  # the onset: the friction's maximum
    before = np.nonzero(np.abs(tr.v[:ia]) > proc.velocity_threshold)[0]
    start = int(before[-1]) if len(before) else 0
    i0 = start + int(np.argmin(s * F[start:ion + 1]))  # the branch starts at its lowest
    against = np.nonzero(s * tr.v[i0:ion] < -3.0 * tr.sv)[0]
    if len(against):  # moving against the breakaway's direction: the branch starts after it
        i0 += int(against[-1]) + 1
    vp = abs(float(tr.v[ion]))
    idx = np.arange(i0, max(i0, ion - tr.reach + 1))
    if vs is None:  # the level taken constant: only where the creep is slow
        idx = idx[s * tr.v[idx] < max(CREEP_FRACTION * vp, 3.0 * tr.sv)]
    base = dict(kind="breakaway", time=float(t[ion]), direction=int(s), samples=int(len(idx)),
                peak_force=float(s * F[ion]), creep_velocity=vp,
                span=float(np.ptp(tr.x[idx])) if len(idx) else 0.0)
    if len(idx) < MIN_BRANCH_SAMPLES:
        reach = quantity(tr.reach / proc.sample_rate, "s", 3, shown=("ms", 1e3))
        return _empty(base, f"its loading branch holds {len(idx)} samples "
                            f"({MIN_BRANCH_SAMPLES} needed): the force rose to the breakaway "
                            f"within the filter's reach ({reach})"), None, None
    branch = Branch(idx, s)
    fit, keys = ctx.fit([branch], None, vs)
    kappa, sigma0, sigma1 = (float(x) for x in fit.x[:3])
    y = s * F[idx]
    ok = fit.success and kappa > 0 and not fit.at_bound[0]
    level = 1.0 / kappa if ok else None
    rise = float((y[-1] - y[0]) * kappa) if ok else None
    sat = float(y[-1] * kappa) if ok else None
    used, why = [], []
    if not ok:
        why.append("the fit of its branch found no saturation level")
    elif rise < MIN_RISE or sat < SATURATION:
        why.append(f"its branch rises from {quantity(y[0], 'N', 4)} to {quantity(y[-1], 'N', 4)} "
                   f"against a level of {quantity(level, 'N', 4)} (a rise of at least "
                   f"{percent(MIN_RISE, 2)} of it, up to at least {percent(SATURATION, 2)}, "
                   "needed: the bearing had stopped with its bristles loaded "
                   "in the breakaway's direction, or broke away before they saturated)")
    else:
        used.append("static")
    if not ok or rise < MIN_RISE:
        why.append("its branch does not start far from saturation, where the slope is sigma0")
    elif base["span"] < MIN_SPAN * tr.resolution:
        why.append(_span_note(base["span"], tr))
    else:
        used.append("bristle_stiffness")
    (sk, pk), (ss, ps) = fit.std_error(0), fit.std_error(1)
    bf = BranchFit(**base, static=level,
                   static_std_error=math.hypot(sk, pk) * level ** 2 if ok else None,
                   bristle_stiffness=sigma0, bristle_stiffness_std_error=math.hypot(ss, ps),
                   bristle_damping=sigma1, saturation=sat, rise=rise, used_for=tuple(used),
                   note="; ".join(why))
    return bf, (fit, keys), branch


def _span_note(span: float, tr: Trace) -> str:
    return (f"its presliding displacement spans {quantity(span, 'm', 3)}, "
            f"{number(MIN_SPAN)} position resolutions "
            f"({quantity(MIN_SPAN * tr.resolution, 'm', 3)}) needed")


def _empty(base: dict, why: str):
    return BranchFit(**base, static=None, static_std_error=None, bristle_stiffness=None,
                     bristle_stiffness_std_error=None, bristle_damping=None, saturation=None,
                     rise=None, used_for=(), note=why)


def _static(ctx: _Context, events, form: str, vs: _Fixed | None, exc: Excitation):
    """(Parameter, _Fixed level or None): static friction from the breakaways."""
    name = "static"
    sliding, n = ctx.sliding, ctx.n
    use = [(bf, ft, br) for bf, ft, br in events if "static" in bf.used_for]
    if not use:
        if not events:
            why = (f"the record holds no breakaway after a stop (a rest of at least "
                   f"{quantity(exc.dwell, 's', 3, shown=('ms', 1e3))} after sliding, followed by "
                   "motion); it moves slower than the velocity threshold for "
                   f"{quantity(exc.low_speed_time, 's', 3)} in all without stopping, passing "
                   "through")
        else:
            why = (f"the record holds {len(events)} breakaway(s) after a stop, none with a "
                   "resolved loading branch (" + "; ".join(
                       f"t = {quantity(bf.time, 's', 4)}: {bf.note}" for bf, _, _ in events[:3])
                   + (" ..." if len(events) > 3 else "") + ")")
        return Parameter(None, None, UNITS[name], False,
                         f"not identifiable: {why}; {_EXPERIMENT[name]} would identify it"), None
    C = ctx.space(None, vs)
    est = []
    for _, (fit, keys), _ in use:
        k = fit.x[0]
        est.append(_Estimate(1.0 / k, fit.std_error(0)[0] / k ** 2,
                             -ctx.row(fit, 0, keys) / k ** 2))
    extra = 0.0
    if len(use) == 1:  # no scatter to measure: widen by the model's share
        _, _, br = use[0]
        alt, _ = ctx.fit([br], None, vs, damping=False)
        extra = abs(1.0 / alt.x[0] - est[0].value) if alt.x[0] > 0 else est[0].value
    value, var_stat, var_prop, g = _combine(est, C, extra)
    level = _Fixed(value, var_stat + var_prop, (g @ C)[:n])
    if form == "per_direction":  # the positive direction's, the offset absorbed
        g = g.copy()
        g[sliding.names.index("offset")] += 1.0
        value += sliding.value("offset")
        var_prop = float(g @ C @ g)
    k = len(use)
    times = ", ".join(quantity(bf.time, "s", 4) for bf, _, _ in use[:6]) + (" ..." if k > 6 else "")
    peak = float(np.mean([bf.peak_force for bf, _, _ in use]))
    creep = float(np.mean([bf.creep_velocity for bf, _, _ in use]))
    note = (f"the bristles' saturation level on the loading branch before {k} breakaway(s) "
            f"after a stop (onsets at t = {times}): LuGre's presliding curve fitted to the "
            "friction force (drive force minus the identified inertia and offset, in the "
            "direction of the breakaway) against displacement, "
            + ("the level following the Stribeck curve at the creep speed (the identified "
               "Stribeck velocity, its error propagated); " if vs is not None else
               "where the bearing creeps slowly; ")
            + (f"the mean of {k} events; standard error from their scatter (at least their fit "
               f"errors), {quantity(math.sqrt(var_stat), 'N', 2)}, and the propagated error of the "
               f"sliding friction, {quantity(math.sqrt(var_prop), 'N', 2)}" if k > 1 else
               "one event only, so the scatter between events is unknown: its fit error is "
               f"widened by {quantity(extra, 'N', 2)} (the change of the estimate when the bristle "
               "damping is left out of the model) and the propagated error of the sliding "
               f"friction, {quantity(math.sqrt(var_prop), 'N', 2)}, added; more breakaways "
               "would tighten it")
            + f". The force at the onsets, {quantity(peak, 'N', 4)}, is not the estimate: the "
              f"bearing already creeps there ({quantity(creep, 'm/s', 3)}), where LuGre's "
              "friction is g(v) < Fs, and the filter smears the drop after it")
    if form == "per_direction":
        note += ("; per-direction form: the static friction of the positive direction, Fs + "
                 "offset; the spec scales the negative direction's by coulomb_negative / "
                 "coulomb, which only approximates the record's Fs - offset (the symmetric form "
                 "describes both)")
    se = math.sqrt(var_stat + var_prop)
    return Parameter(float(value), float(se), UNITS[name], True, note), level


# --------------------------------------------------------------------------- presliding


def _presliding(ctx: _Context, seg, level: _Fixed | None, vs: _Fixed | None) -> list:
    """A run of presliding reversals, one fit per full cycle: [(BranchFit, fit, branches)]."""
    tr = ctx.tr
    t = tr.time
    idx = [min(int(np.searchsorted(t, x)), len(t) - 1) for x in seg]
    halves = [Branch(np.arange(a, b), float(np.sign(tr.x[b] - tr.x[a])) or 1.0)
              for a, b in zip(idx[:-1], idx[1:])]
    out = []
    for k in range(0, len(halves) - 1, 2):
        branches = halves[k:k + 2]
        every = np.concatenate([b.idx for b in branches])
        base = dict(kind="presliding", time=float(t[every[0]]), direction=0,
                    samples=int(len(every)), peak_force=None, creep_velocity=None,
                    span=float(np.ptp(tr.x[every])))
        if min(len(b.idx) for b in branches) < MIN_BRANCH_SAMPLES:
            out.append((_empty(base, f"a half cycle of fewer than {MIN_BRANCH_SAMPLES} samples"),
                        None, None))
            continue
        fit, keys = ctx.fit(branches, level, vs)
        i = 0 if level is not None else 1
        ok = fit.success and base["span"] >= MIN_SPAN * tr.resolution
        ss, ps = fit.std_error(i)
        bf = BranchFit(**base, static=None, static_std_error=None,
                       bristle_stiffness=float(fit.x[i]),
                       bristle_stiffness_std_error=math.hypot(ss, ps),
                       bristle_damping=float(fit.x[i + 1]), saturation=None, rise=None,
                       used_for=("bristle_stiffness",) if ok else (),
                       note="" if ok else _span_note(base["span"], tr))
        out.append((bf, (fit, keys), branches))
    return out


def _stiffness(ctx: _Context, events, runs, level: _Fixed | None, vs: _Fixed | None,
               exc: Excitation) -> Parameter:
    """Bristle stiffness from the breakaways' branches and the presliding runs."""
    name = "bristle_stiffness"
    tr = ctx.tr
    use = [(bf, ft, br) for bf, ft, br in events + runs if "bristle_stiffness" in bf.used_for]
    if not use:
        held = [bf for bf, _, _ in events + runs]
        if held:
            why = ("the record's breakaways and presliding runs do not resolve the presliding "
                   "curve (" + "; ".join(f"t = {quantity(bf.time, 's', 4)}: {bf.note}"
                                         for bf in held[:3])
                   + (" ..." if len(held) > 3 else "") + ")")
        else:
            why = (f"the record holds no presliding excitation ({exc.presliding_reversals} "
                   f"reversal(s) with an excursion below {quantity(exc.presliding_band, 'm', 3)}) "
                   "and no breakaway with a resolved loading branch")
        return Parameter(None, None, UNITS[name], False,
                         f"not identifiable: {why}; {_EXPERIMENT[name]} would identify it")
    est = []
    for bf, (fit, keys), _ in use:
        i = 0 if "kappa" in keys else 1
        est.append(_Estimate(float(fit.x[i]), fit.std_error(i)[0], ctx.row(fit, i, keys)))
    extra = 0.0
    if len(use) == 1:  # no scatter to measure: widen by the model's share
        bf, (fit, keys), br = use[0]
        alt, _ = ctx.fit(br if isinstance(br, list) else [br],
                         level if "kappa" in keys else None, vs, damping=False)
        extra = abs(float(alt.x[0 if "kappa" in keys else 1]) - est[0].value)
    value, var_stat, var_prop, _ = _combine(est, ctx.space(level, vs), extra)
    kinds = [bf.kind for bf, _, _ in use]
    nb, nr = kinds.count("breakaway"), kinds.count("presliding")
    where = " and ".join(x for x in (f"{nb} breakaway loading branch(es)" if nb else "",
                                     f"{nr} presliding cycle(s)" if nr else "") if x)
    note = (f"initial slope of friction against displacement on LuGre's presliding curve, from "
            f"{where}; " + (f"the mean of {len(use)}; standard error from their scatter (at "
                            "least their fit errors)" if len(use) > 1 else
                            "one event only, so the scatter between events is unknown: its fit "
                            f"error is widened by {quantity(extra, 'N/m', 2)} (the change of "
                            "the estimate when the bristle damping is left out of the model)")
            + (", the presliding curve's level fixed at the identified static friction, its "
               "error propagated" if nr and level is not None else "")
            + " and the propagated error of the sliding friction "
              f"({quantity(math.sqrt(var_prop), 'N/m', 2)})")
    if tr.compliance > 0.0:
        own = 1.0 / value
        share = own / (own + tr.compliance)
        note += (f"; the joint's compliance 1/k = {quantity(tr.compliance, 'm/N', 3)} (the spec's "
                 "stiffness, no deflection_m column) was removed from the displacement: the "
                 f"bristles' own compliance is {percent(share, 2)} of the total")
        if share < MIN_OWN_COMPLIANCE:
            return Parameter(None, None, UNITS[name], False,
                             f"not identifiable: the joint's compliance 1/k dominates the "
                             f"presliding displacement (the bristles' own {percent(share, 2)} of "
                             f"it, {percent(MIN_OWN_COMPLIANCE, 2)} needed), so sigma0 would "
                             "rest on the spec's stiffness; a record with the deflection_m "
                             "column measures the cart's own displacement")
    se = math.sqrt(var_stat + var_prop)
    if se > MAX_RELATIVE_ERROR * abs(value):
        return Parameter(None, None, UNITS[name], False,
                         "not identifiable: the presliding curve gives "
                         f"{with_error(value, se, 'N/m')}, a relative error above "
                         f"{percent(MAX_RELATIVE_ERROR, 2)}; {_EXPERIMENT[name]} would identify it")
    return Parameter(float(value), float(se), UNITS[name], True, note)


# --------------------------------------------------------------------------- Stribeck velocity


def _relaxation(level: _Fixed | None, stiffness: Parameter, spec):
    """(distance [m], where from) the bristles need to relax, Fs / sigma0; None if unknown."""
    if level is not None and stiffness.identifiable:
        return level.value / stiffness.value, "the identified Fs / sigma0"
    if spec is not None:
        f = spec.friction
        return f.static / f.bristle_stiffness, "the spec's Fs / sigma0 (assumed, not identified)"
    return None


def _steady(tr: Trace, proc: Processing, relax: float) -> np.ndarray:
    """Samples sliding steadily in one direction at low speed, away from stops (indices).

    Between three times the velocity noise and the velocity threshold, the
    speed changing by less than :data:`STEADY_RATE` while the bearing travels
    the relaxation distance ``relax`` [m] (the velocity compared half that
    distance before and after: a difference over time rather than the noisy
    acceleration), the direction the same and the conditions holding within
    the filter's reach on both sides.
    """
    from scipy.ndimage import binary_erosion

    speed = np.abs(tr.v)
    n = len(speed)
    band = (speed > 3.0 * tr.sv) & (speed < proc.velocity_threshold)
    half = np.ceil(0.5 * relax / np.maximum(speed, 1e-300) * proc.sample_rate)
    half = np.minimum(half, n).astype(int)
    k = np.arange(n)
    change = np.abs(tr.v[np.minimum(k + half, n - 1)] - tr.v[np.maximum(k - half, 0)])
    band &= (change < STEADY_RATE * speed) & (k - half >= 0) & (k + half < n)
    out = np.zeros(len(speed), dtype=bool)
    for s in (1.0, -1.0):
        run = band & (np.sign(tr.v) == s)
        out |= binary_erosion(run, structure=np.ones(2 * tr.reach + 1, dtype=bool))
    edge = int(round(proc.edge * proc.sample_rate))
    out[:edge] = False
    if edge:
        out[-edge:] = False
    return np.nonzero(out)[0]


def _stribeck(ctx: _Context, level: _Fixed | None, relax):
    """(SweepFit or None, Parameter, _Fixed vs or None) from steady low-speed sliding."""
    name = "stribeck_velocity"
    tr, proc, sliding, n = ctx.tr, ctx.proc, ctx.sliding, ctx.n
    if relax is None:
        return None, Parameter(
            None, None, UNITS[name], False,
            "not identifiable: whether low-speed sliding is steady (LuGre's friction following "
            "its steady curve) depends on the bristles' relaxation distance Fs / sigma0, which "
            "neither the record (no resolved breakaway or presliding) nor a spec gives; "
            f"{_EXPERIMENT[name]}, with breakaways at its reversals, would identify it"), None
    relax, relax_from = relax
    idx = _steady(tr, proc, relax)
    if len(idx) < 2 * MIN_STEADY_SAMPLES:
        return None, Parameter(
            None, None, UNITS[name], False,
            f"not identifiable: the record slides steadily below the velocity threshold "
            f"({quantity(proc.velocity_threshold, 'm/s', 3)}) for {len(idx)} samples "
            f"({quantity(len(idx) / proc.sample_rate, 's', 3)}; steady: away from stops and "
            "reversals by the filter's reach, the speed changing by less than "
            f"{percent(STEADY_RATE, 2)} over the "
            f"relaxation distance {quantity(relax, 'm', 3)}, {relax_from}); at least "
            f"{2 * MIN_STEADY_SAMPLES} spanning the Stribeck velocity are needed: "
            f"{_EXPERIMENT[name]} would identify it"), None
    if level is not None:
        fit = fit_stribeck(tr, sliding, idx, static=level.value, static_var=level.var,
                           static_cov=level.cov)
    else:
        fit = fit_stribeck(tr, sliding, idx)
    vs = float(fit.x[0])
    stat, prop = fit.std_error(0)
    se = math.hypot(stat, prop)
    speed = np.abs(tr.v[idx])
    below = int(np.sum(speed < STEADY_BELOW * vs))
    above = int(np.sum(speed > STEADY_ABOVE * vs))
    fs_fit = None if level is not None else float(fit.x[1])
    sweep = SweepFit(samples=int(len(idx)), effective_samples=fit.n_eff, below=below,
                     above=above, speed_min=float(speed.min()), speed_max=float(speed.max()),
                     stribeck_velocity=vs, stribeck_velocity_std_error=se, static=fs_fit,
                     static_std_error=(math.hypot(*fit.std_error(1)) if fs_fit is not None
                                       else None),
                     rms_residual=fit.rms)
    problems = []
    if not fit.success:
        problems.append("the fit did not converge")
    if below < MIN_STEADY_SAMPLES or above < MIN_STEADY_SAMPLES:
        problems.append(f"{below} samples below {number(STEADY_BELOW)} x vs and {above} above "
                        f"{number(STEADY_ABOVE)} x vs ({MIN_STEADY_SAMPLES} each needed to "
                        "span it)")
    if se > MAX_RELATIVE_ERROR * vs:
        problems.append(f"relative error {percent(se / vs, 2)} "
                        f"(at most {percent(MAX_RELATIVE_ERROR, 2)})")
    if problems:
        return sweep, Parameter(
            None, None, UNITS[name], False,
            f"not identifiable: {len(idx)} samples slide steadily below the velocity threshold "
            f"at {_speed_range(speed)}, but "
            + "; ".join(problems) + f" (a fit gave {quantity(vs, 'm/s', 3)}); "
            f"{_EXPERIMENT[name]} would identify it"), None
    note = (f"steady-state Stribeck curve Fc + (Fs - Fc) exp(-(v/vs)^2) + viscous fitted to "
            f"{len(idx)} samples sliding steadily at "
            f"{_speed_range(speed)} ({below} below {number(STEADY_BELOW)} vs, {above} above "
            f"{number(STEADY_ABOVE)} vs; steady: the speed changing by less than "
            f"{percent(STEADY_RATE, 2)} over the relaxation distance {quantity(relax, 'm', 3)}, "
            f"{relax_from}), Fc fixed at the identified Coulomb friction and "
            + ("Fs at the identified static friction, both errors propagated"
               if level is not None else
               f"Fs fitted as well ({with_error(fs_fit, sweep.static_std_error, 'N')}, not "
               "reported as the static friction: no breakaway resolves it), Fc's error "
               "propagated")
            + f"; standard error {quantity(stat, 'm/s', 2)} statistical "
              f"(autocorrelation-corrected), {quantity(prop, 'm/s', 2)} from the sliding "
              "friction")
    if 3.0 * vs > proc.velocity_threshold:
        note += ("; the fit's velocity threshold "
                 f"{quantity(proc.velocity_threshold, 'm/s', 3)} lies below "
                 "3 vs, so the Stribeck effect reaches into the sliding samples and biases "
                 "the Coulomb friction: identify again with velocity_threshold above 3 vs")
    # vs with its variance and covariance with the sliding estimates (through Fs as well)
    G = fit.G[0]
    cov = G[:n] @ sliding.cov + (G[n] * level.cov if level is not None else 0.0)
    return sweep, Parameter(vs, se, UNITS[name], True, note), _Fixed(vs, se ** 2, cov)
