"""Judging a fitted candidate: honest uncertainties and when an improvement is a finding.

A fitted effect always lowers the misfit a little: it has parameters to
spend. It is a finding only when the improvement is beyond what noise, the
fit's freedom and the difference between two implementations of the same
equations give. Every test below must pass:

1. **It ran.** The simulation at the best point completed and stayed within
   the record's envelope (a diverging or unstable candidate never wins:
   its residual is the failure level, far above the nominal one).
2. **Not on a bound.** A fit that still ends on a search bound after
   widening it, or on a physical limit (a delay of zero, a coefficient of
   zero), has not found a value.
3. **Significant in effective samples.** Residuals of a model that misses
   the record are autocorrelated: ``n`` of them carry the information of
   ``n_eff = n / tau`` independent ones (``tau`` the integrated
   autocorrelation time of the fit's residual). The chi-square improvement,
   rescaled by the fit's reduced chi-square ``s2`` and by ``tau``, is a
   likelihood-ratio statistic; the score subtracts the Bayesian penalty
   ``k ln(n_eff)``::

       score = (chi2_start - chi2_fit) / (s2 tau) - k ln(n_eff)

   and must exceed ``threshold`` (default 10, "very strong" evidence on the
   Kass-Raftery scale).
4. **Most of the gap.** It removes at least :data:`EXPLAINED_MIN` of the gap
   above noise (chi2 - n). A parameter that absorbs a fraction of a
   mismatch it cannot explain (the model's structure, or another
   implementation's integrator) changes its value for the wrong reason.
5. **Away from the model's own value.** At least one parameter differs from
   its reference value by :data:`Z_MIN` honest standard errors.
6. **Better than noise alone.** The same candidate is refitted on a
   noise-only record (the starting model's own trace plus sensor noise of
   the estimated levels): its improvement statistic there is what noise and
   the fit's freedom give without the effect (large where stick-slip makes
   the objective rugged). The real statistic must exceed it
   :data:`NULL_FACTOR` times. The refit's parameter error joins the
   uncertainty.

An effect read from the data itself (``quantization``: the lattice test of
:mod:`.lattice` is the evidence, and its step is the lattice's) needs only
tests 1 and 3.

Uncertainties come from the Jacobian at the optimum, scaled by ``s2`` and
``tau`` (the effective-sample correction) and mapped to the parameters by
the derivative of the scaling; the noise-only refit's deviation from the
truth it was generated with is added in quadrature.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..display import fixed, number, percent
from ..measured import measurement_from_arrays
from .comparison import Comparison
from .fitting import Baseline, FitOutcome, Objective, fit, fit_baseline
from .noise import channels_autocorrelation_time
from ..results.reconciliation import Candidate, Lattice
from .spaces import Space

#: Default significance threshold on the score.
THRESHOLD = 10.0
#: Smallest share of the gap above noise a named effect must remove.
EXPLAINED_MIN = 0.5
#: Honest standard errors a named effect's parameter must lie from its reference value.
Z_MIN = 3.0
#: How many times the noise-only refit's statistic the real one must exceed.
NULL_FACTOR = 3.0
#: Seed of the noise-only records (reproducible results).
NULL_SEED = 20240611
#: Contiguous time blocks of the block jackknife of a finding's uncertainty.
JACKKNIFE_BLOCKS = 4
#: Function evaluations of each jackknife refit (it starts at the full fit's optimum).
JACKKNIFE_NFEV = 10

#: Standard deviations of a noise-only record's misfit within which a model agrees with the
#: measurement (:func:`within_noise`).
AGREE_Z = 3.0


def within_noise(chi2: float, n: int) -> bool:
    """Whether a model's weighted squared residual is that of noise alone.

    Its misfit sqrt(chi2 / n) lies within :data:`AGREE_Z` standard deviations
    sqrt(2 / n) of 1: there is no gap above noise for an effect to explain, and
    the search fits none (:func:`fi_design.reconciliation.workflow.reconcile`; a
    fit that still lowers chi2 there fits the noise, or the phase of a hunting
    record whose cycle a perturbation of 1e-15 shifts).

    Parameters
    ----------
    chi2 : float
        Weighted squared residual [-].
    n : int
        Residual entries.
    """
    return math.sqrt(chi2 / n) <= 1.0 + AGREE_Z * math.sqrt(2.0 / n)


#: Effects that contain another as a special case: a cable force of zero stiffness is a
#: force offset (its preload the offset).
NESTED = {"cable_force": "force_offset"}
#: Share of what the smaller of two nested effects leaves above noise that the larger must
#: remove to be named instead of it.
NESTED_MARGIN = 0.1


@dataclass(frozen=True)
class Statistic:
    """The improvement statistic of a fit against its baseline.

    Attributes
    ----------
    delta_chi2 : float
        chi2 reduction [-].
    s2 : float
        Reduced chi-square of the fit, at least 1 [-].
    tau : float
        Autocorrelation time of the fit's residual [samples].
    n_effective : float
        n / tau.
    value : float
        delta_chi2 / (s2 tau): the likelihood-ratio statistic in effective samples.
    """

    delta_chi2: float
    s2: float
    tau: float
    n_effective: float
    value: float


@dataclass(frozen=True)
class NullRefit:
    """A candidate refitted on a noise-only record.

    Attributes
    ----------
    statistic : float
        Its improvement statistic (:attr:`Statistic.value`).
    deviation : dict of str to float
        Fitted minus true (reference) value per parameter, SI.
    n_simulations : int
        Simulations used.
    """

    statistic: float
    deviation: dict
    n_simulations: int


def statistic(cmp: Comparison, outcome: FitOutcome, baseline: Baseline) -> Statistic:
    """Improvement of a fit over its baseline, in effective samples."""
    n = len(outcome.residual)
    k = max(len(outcome.space.coords), 1)  # the nuisance is in the baseline too
    delta = baseline.chi2 - outcome.chi2
    s2 = max(1.0, outcome.chi2 / max(n - k, 1))
    tau = channels_autocorrelation_time(cmp.channel_blocks(outcome.residual))
    return Statistic(delta_chi2=float(delta), s2=float(s2), tau=float(tau),
                     n_effective=float(n / tau), value=float(delta / (s2 * tau)))


def judge(cmp: Comparison, outcome: FitOutcome, baseline: Baseline, threshold: float,
          wall_time: float, null: NullRefit | None = None,
          jackknife: dict | None = None, numerical: dict | None = None) -> Candidate:
    """The candidate as a result value: parameters, honest uncertainty, score and verdict.

    Parameters
    ----------
    cmp : Comparison
        The comparison.
    outcome : FitOutcome
        The candidate's fit.
    baseline : Baseline
        The model the search started from.
    threshold : float
        Score needed.
    wall_time : float
        Time the fit took [s].
    null : NullRefit, optional
        The noise-only refit, when one ran.
    jackknife : dict, optional
        Block-jackknife standard error per parameter (:func:`block_jackknife`).
    numerical : dict, optional
        Numerical error per parameter (:func:`numerical_error`).
    """
    sp = outcome.space
    n = len(outcome.residual)
    k = max(len(sp.coords), 1)
    st = statistic(cmp, outcome, baseline)
    score = st.value - k * math.log(st.n_effective)
    excess = baseline.chi2 - n
    explained = float(min(max(st.delta_chi2 / excess, 0.0), 1.0)) if excess > 0 else 0.0
    effect_size = float(math.sqrt(np.mean((outcome.residual - baseline.residual) ** 2)))
    sigma = _uncertainty(cmp, outcome, st, null, jackknife or {}, numerical or {})
    values = outcome.values
    refs = {p: sp.references.get(p) for p in values}
    distance = {}
    for p, v in values.items():
        r, s = sp.origin(p), sigma.get(p)
        distance[p] = (float((v - r) / s) if r is not None and s is not None and s > 0
                       and v is not None else None)
    verdict = _verdict(outcome, st, score, explained, distance, threshold, null)
    status, reasons = verdict.status, verdict.reasons
    message = outcome.note if outcome.run.ok else outcome.run.message
    return Candidate(
        name=sp.name, parameters=dict(values), uncertainty=sigma, reference=refs,
        distance=distance, score=float(score), chi2=outcome.chi2, delta_chi2=st.delta_chi2,
        explained=explained, autocorrelation_time=st.tau, n_effective=st.n_effective,
        null_score=None if null is None else null.statistic, effect_size=effect_size,
        n_parameters=len(sp.coords), widened=outcome.widened, at_bound=outcome.at_bound,
        status=status, from_data=sp.from_data, eligible=not reasons, reasons=tuple(reasons),
        n_simulations=outcome.n_simulations + (null.n_simulations if null else 0),
        n_failed=outcome.n_failed, wall_time=float(wall_time), message=message)


def prefer_simpler(candidates: dict) -> dict:
    """Candidates with a larger nested effect made ineligible where the smaller one suffices.

    When both effects of a :data:`NESTED` pair can be named and the larger
    removes less than :data:`NESTED_MARGIN` of what the smaller leaves above
    noise, its extra parameters buy nothing a reader should act on: the
    smaller one is the finding. (Its likelihood ratio alone would favour the
    larger one on any record the model misses by more than noise.)

    Parameters
    ----------
    candidates : dict of str to Candidate
        The judged candidates of one pass, by name.
    """
    out = dict(candidates)
    for big, small in NESTED.items():
        b, s = out.get(big), out.get(small)
        if b is None or s is None or not (b.eligible and s.eligible):
            continue
        left = 1.0 - s.explained
        extra = (b.explained - s.explained) / left if left > 0 else 0.0
        if extra < NESTED_MARGIN:
            out[big] = replace(b, eligible=False, reasons=(
                f"contains {small} as a special case and removes only {percent(extra, 2)} of "
                f"the gap {small} leaves (needs {percent(NESTED_MARGIN, 2)})",))
    return out


def passes_primary(candidate: Candidate, space: Space) -> bool:
    """Whether only the noise-only refit is left to decide (every other test passed)."""
    return candidate.eligible and candidate.null_score is None and not space.from_data


@dataclass(frozen=True)
class Verdict:
    """A candidate's status and the tests it failed."""

    status: str
    reasons: list


def _verdict(outcome, st, score, explained, distance, threshold, null) -> Verdict:
    """Status and failed tests; an effect read from the data skips the tests the data replace."""
    reasons: list[str] = []
    status = "ok"
    if not outcome.run.ok:
        status = "diverged" if _ran_away(outcome.run.message) else "failed"
        reasons.append(f"its simulation {status}: {outcome.run.message}")
    elif outcome.at_bound:
        status = "at bound"
        reasons.append(f"the fit ends on a search bound or physical limit ({outcome.note}): "
                       "no value found")
    if score <= threshold:
        reasons.append(f"score {number(score, 3)} not above the threshold "
                       f"{number(threshold, 6)} (improvement {number(st.value, 3)} in "
                       f"{fixed(st.n_effective, 0)} effective samples)")
    if outcome.space.from_data:
        return Verdict(status, reasons)
    if explained < EXPLAINED_MIN:
        reasons.append(f"explains {percent(explained, 2)} of the gap above noise, less than "
                       f"{percent(EXPLAINED_MIN, 2)}")
    blind = [p for p, d in distance.items()
             if d is None and outcome.space.origin(p) is not None]
    if blind:
        # no standard error: the fit does not move with the parameter (a flat objective), so
        # nothing tells its value from the model's own
        reasons.append(f"no standard error for {', '.join(blind)}: the fit does not change "
                       "with it, so its value cannot be told from the model's")
    z = [abs(d) for d in distance.values() if d is not None]
    if z and max(z) < Z_MIN:
        reasons.append(f"within {number(max(z), 2)} standard errors of the model's own value "
                       f"(needs {number(Z_MIN)})")
    if null is not None and st.value < NULL_FACTOR * max(null.statistic, 0.0):
        reasons.append(f"a refit on noise alone improves by {number(null.statistic, 3)} "
                       f"(statistic {number(st.value, 3)}, needs {number(NULL_FACTOR)} times "
                       "more)")
    return Verdict(status, reasons)


def _ran_away(message: str) -> bool:
    m = message.lower()
    return "runaway" in m or "diverged" in m or "nan" in m or "infinite" in m


def _uncertainty(cmp, outcome: FitOutcome, st: Statistic, null: NullRefit | None,
                 jackknife: dict, numerical: dict) -> dict:
    """One standard deviation per parameter, SI.

    The Jacobian's covariance (the initial-command nuisance included, so its
    correlation with the effect counts) scaled by s2 and tau (effective
    samples), or the block jackknife's error where larger, with the
    noise-only refit's error and the numerical error added in quadrature.
    """
    names = list(outcome.values)
    out: dict[str, float | None] = {p: None for p in names}
    if outcome.covariance is not None:
        G = Objective(cmp, outcome.space, []).value_jacobian(outcome.u)
        var = np.diag(G @ (outcome.covariance * st.s2 * st.tau) @ G.T)
        for p, v in zip(names, var):
            out[p] = float(math.sqrt(v)) if v > 0 and math.isfinite(v) else None
    for p, err in jackknife.items():
        if p in out and err is not None and math.isfinite(err) and err > (out[p] or 0.0):
            out[p] = err
    for more in (outcome.space.data_error, numerical):
        for p, err in more.items():
            if p in out and err is not None and math.isfinite(err):
                out[p] = math.hypot(out[p] or 0.0, err) or None
    if null is not None:
        for p, dev in null.deviation.items():
            if dev is None or p not in out:
                continue
            total = math.hypot(out[p] or 0.0, dev)
            out[p] = total if total > 0 else out[p]
    return out


def noise_only_refit(cmp: Comparison, space: Space, baseline: Baseline, max_points: int,
                     seed: int, start: np.ndarray | None = None) -> NullRefit:
    """Refit a candidate on a record made of the baseline's own trace plus sensor noise.

    Two fits: the candidate's full search (all its starts), whose improvement
    is the statistic the real one must exceed, and a local fit from the real
    fit's optimum ``start``, whose distance from the reference values is the
    parameters' deviation. The search alone can wander off to another shape
    (a ripple of another wavelength, where any amplitude fits the noise
    alike); the amplitude such a fit ends at says nothing about the
    amplitude's error at the shape the real record gave.

    Parameters
    ----------
    cmp : Comparison
        The real comparison (its settings and noise levels are reused).
    space : Space
        The candidate as searched on the real record.
    baseline : Baseline
        The model the search started from: the noise-only record is its trace
        (an open-loop replay's as one continuous run,
        :meth:`~.comparison.Comparison.trace_source`).
    max_points : int
        Residuals per channel.
    seed : int
        Seed of the noise.
    start : ndarray, optional
        The real fit's optimum in the space's coordinates (u); default the
        deviation of the full search.
    """
    rng = np.random.default_rng(seed)
    meas, nz = cmp.meas, cmp.noise
    run = baseline.run
    if cmp.drive != "closed":
        whole = cmp.trace_source(baseline.entries)
        run = whole if whole.ok else run
    n = cmp.n
    position = run.position + nz.position * rng.standard_normal(n)
    if cmp.has_force:
        force = run.force + nz.force * rng.standard_normal(n)
    else:
        force = meas.force
    deflection = None
    if cmp.has_defl:
        deflection = run.deflection + nz.deflection * rng.standard_normal(n)
    synthetic = measurement_from_arrays(meas.time, meas.reference, position, force, deflection,
                                        disturbance_N=meas.disturbance, source="noise-only refit")
    null_cmp = Comparison(cmp.model, synthetic, cmp.iso, nz, Lattice(step=None), cmp.settle_window,
                          cmp.drive)
    # the record was made from the baseline's run: it started from the baseline's command
    if cmp.initial_command is not None:
        null_cmp.initial_command = cmp.initial_command + baseline.command
    null_cmp.finish_setup(baseline.run, max_points)
    null_base = fit_baseline(null_cmp, baseline.entries)
    null_cmp.set_fail_level(null_base.chi2)
    outcome = fit(null_cmp, space, baseline.entries, null_base.command)
    st = statistic(null_cmp, outcome, null_base)
    n_sims = outcome.n_simulations
    near, st_near = outcome, st
    if start is not None and len(start) and space.coords:
        near = fit(null_cmp, replace(space, starts=[np.asarray(start, float)], method="ls"),
                   baseline.entries, null_base.command)
        st_near = statistic(null_cmp, near, null_base)
        n_sims += near.n_simulations
    deviation = {}
    for p, v in near.values.items():
        ref = space.references.get(p)
        # a refit that ends on the bound standing for "absent", or finds nothing better than
        # the truth it was made from, has found the truth
        absent = p in near.at_bound or st_near.delta_chi2 <= 0.0
        deviation[p] = None if ref is None or v is None or absent else float(v - ref)
    return NullRefit(statistic=st.value, deviation=deviation,
                     n_simulations=n_sims + null_cmp.n_sims)


def block_jackknife(cmp: Comparison, outcome: FitOutcome,
                    blocks: int = JACKKNIFE_BLOCKS) -> dict:
    """Standard error of each parameter from refits that leave out one time block each.

    The record is cut into ``blocks`` contiguous stretches that each hold an
    equal share of the fit's information about the effect (the squared
    Jacobian of its coordinates, summed over the channels: an effect seen in
    one short move gets short blocks around it, so that no deletion leaves
    it unidentifiable); each refit (from the full fit's optimum,
    :data:`JACKKNIFE_NFEV` evaluations) drops one.
    The spread of the refitted values, ``(B - 1) / B`` times their sum of
    squared deviations, is the jackknife's variance: it holds the residual's
    autocorrelation and a mismatch between model and record that differs
    along the record (an implementation difference rarely biases every
    stretch alike), which the Jacobian does not.

    Parameters
    ----------
    cmp : Comparison
        The comparison.
    outcome : FitOutcome
        The full fit.
    blocks : int
        Number of blocks.

    Returns
    -------
    dict of str to float
        Standard error per parameter, SI ({} for an effect read from the data).
    """
    from scipy.optimize import least_squares

    sp = outcome.space
    if not sp.coords or outcome.covariance is None:
        return {}
    base = [e for e in outcome.entries if e.type != sp.name]
    ob = Objective(cmp, sp, base)
    m = len(cmp.idx)
    channels = len(cmp.channel_blocks(outcome.residual))
    n = len(outcome.residual)
    J = outcome.jacobian[:, outcome.columns]
    J = J / np.maximum(np.sqrt(np.sum(J ** 2, axis=0)), 1e-300)
    info = np.sum(J[:channels * m] ** 2, axis=1).reshape(channels, m).sum(axis=0)
    share = np.cumsum(info) / max(float(info.sum()), 1e-300)
    cuts = np.searchsorted(share, np.arange(1, blocks) / blocks)
    values = []
    for part in np.split(np.arange(m), cuts):
        if len(part) == 0:
            continue
        keep = np.ones(n, bool)
        for j in range(channels):
            keep[j * m + part] = False
        u0 = np.clip(outcome.u, 1e-9, 1 - 1e-9)
        try:
            sol = least_squares(lambda u: ob(u)[keep], u0, jac=lambda u: ob.jac(u)[keep],
                                bounds=(np.zeros(len(u0)), np.ones(len(u0))), method="trf",
                                max_nfev=JACKKNIFE_NFEV, ftol=1e-8, xtol=1e-8, gtol=1e-10)
        except (ValueError, np.linalg.LinAlgError):
            continue
        values.append(ob.values(sol.x))
    if len(values) < 2:
        return {}
    out = {}
    for p in outcome.values:
        v = np.array([x[p] for x in values], dtype=float)
        d = v - v.mean()
        if p == "phase":
            d = (d + math.pi) % (2 * math.pi) - math.pi
        out[p] = float(math.sqrt((len(v) - 1) / len(v) * float(d @ d)))
    return out


def numerical_error(cmp: Comparison, outcome: FitOutcome) -> dict:
    """How far each parameter moves when the model is integrated much more accurately, SI.

    One run at :data:`~.comparison.ACCURACY_CHECK` times the tolerance; its
    residual change, mapped through the fit's Jacobian (linearised, no
    refit), is the parameter's share of the integrator's error: a precise
    fit must not quote an uncertainty below its own numerical accuracy.
    """
    from .comparison import ACCURACY_CHECK

    J = outcome.jacobian
    if J is None or not outcome.run.ok or outcome.columns.stop == outcome.columns.start:
        return {}
    run = cmp.run(outcome.entries, quantize=outcome.space.quantize,
                  command_correction=outcome.command, rtol=cmp.rtol * ACCURACY_CHECK)
    if not run.ok:
        return {}
    du = -np.linalg.lstsq(J, cmp.residuals(run) - outcome.residual, rcond=None)[0]
    ob = Objective(cmp, outcome.space, [])
    dp = ob.value_jacobian(outcome.u) @ du[outcome.columns]
    return {p: float(abs(v)) for p, v in zip(outcome.values, dp) if math.isfinite(v)}
