"""The reconciliation workflow: replay, look, fit, judge, and say what was found.

:func:`reconcile` reads the record's lattice and noise, replays the nominal
model on the record, collects the signatures of its residual, then searches
the catalogue once per effect allowed (each pass on the gap the earlier
effects leave), refines several chosen effects together, and measures the
gaps before and after. The steps live in their own modules; this one only
strings them together and words the conclusion.
"""

from __future__ import annotations

import math
import time as _time
from dataclasses import dataclass, replace
from typing import Callable, NamedTuple

import numpy as np

from .. import effects as _effects
from .. import display
from ..arguments import integer, number
from ..display import quantity
from ..errors import ArgumentError, DataError, SimulationError
from ..measured import Measurement
from ..model import resolve
from ..simulation.replay import DRIVES, check_record
from ..spec.file import as_spec
from .comparison import MAX_POINTS, Comparison, ModelRun
from .diagnosis import diagnose, drive_check, record_diagnosis, record_fault
from .fitting import (Baseline, FitOutcome, JointObjective, fit, fit_baseline, joint_fit,
                      marginal_covariance, polish_jointly)
from .gaps import gap_metrics
from .lattice import find_lattice
from .noise import channels_autocorrelation_time, estimate_noise, noise_levels
from ..results.reconciliation import (Candidate, Cause, Diagnosis, EffectStep,
                                      ReconcileResult, SearchRound)
from .signatures import Evidence, scan
from .significance import (NESTED, NULL_SEED, THRESHOLD, block_jackknife, judge,
                           noise_only_refit, numerical_error, passes_primary, prefer_simpler,
                           within_noise)
from .spaces import Space, candidate_spaces
from .records import check_duration, check_excitation, for_the_model
from .specout import make_entry

ProgressCallback = Callable[[str, float], None]

#: Most candidates of one pass that get a noise-only refit.
NULL_REFITS = 3


def reconcile(spec, measured: Measurement, *, isolated: bool | None = None,
              candidates=None, max_effects: int = 1, threshold: float = THRESHOLD,
              settle_window: float | None = None, max_points: int = MAX_POINTS,
              drive: str = "closed", progress: ProgressCallback | None = None) -> ReconcileResult:
    """Find the catalogue effect that explains where a measurement and the model disagree.

    Parameters
    ----------
    spec : Spec
        The spec of the stage (its ``effects`` stay in the model; an effect
        already listed is refitted as a candidate).
    measured : Measurement
        The measured trace (:func:`fi_design.measured.load_measurement`).
    isolated : bool, optional
        Model the isolated plant; default: whether the spec has an isolator.
    candidates : sequence of str, optional
        Effect names to try; default the whole catalogue (docs/effects.md).
    max_effects : int
        Effects to name at most (default 1); each later one is searched on
        the gap the earlier ones leave.
    threshold : float
        Score a candidate needs (:mod:`fi_design.reconciliation.significance`).
        Default 10.
    settle_window : float, optional
        Length of the settle segment after each move [s]; default five
        integrator time constants (five loop time constants without one).
    max_points : int
        Largest number of sample-wise residuals per channel (strided).
    drive : {"closed", "force"}
        ``"closed"``: the model and its controller replay the measured
        reference; ``"force"``: the plant alone is driven by the measured
        force in re-anchored windows (the force is then an input, not a
        compared channel).
    progress : callable, optional
        ``progress(message, fraction)`` with fraction in [0, 1].

    Returns
    -------
    ReconcileResult
        The named effect (or ``"none"``), its parameters and honest
        uncertainty, the ranked candidates with the tests each passed, the
        gaps before and after (per named effect too), the lattice, the
        structure diagnosis and the model traces. A record whose force_N
        has the wrong sign or scale (:func:`.diagnosis.force_check`; open
        loop :func:`.diagnosis.drive_check`, and then no effect is
        searched) names no effect.

    Raises
    ------
    DataError
        The trace is too short for the comparison (fewer than 50 samples, or
        shorter than one period of the loop's crossover), holds no excitation
        (neither the stage nor its reference moves), or is too long even
        thinned to the lowest rate the model allows (:mod:`.records`; a
        record logged faster than the model needs is thinned, and the
        conclusion says so).
    ArgumentError
        ``measured`` is not a Measurement, ``spec`` not a spec, path or
        mapping, or a number argument is not a number in its range.
    SimulationError
        The arguments are inconsistent (an isolated plant without isolator,
        an unknown effect or drive, ``drive="force"`` without a force column).

    Examples
    --------
    >>> import fi_design
    >>> spec = fi_design.load_spec("examples/measured_stage.yaml")
    >>> data = fi_design.load_measurement("examples/measured_trace.csv")
    >>> result = fi_design.reconcile(spec, data)  # about 15 s  # doctest: +SKIP
    >>> result.effect  # doctest: +SKIP
    'position_dependent_friction'
    >>> round(result.parameters["wavelength"] * 1e3, 2)  # [mm]  # doctest: +SKIP
    5.0
    """
    started = _time.perf_counter()
    say = progress or _silent
    spec = as_spec(spec)
    threshold = number(threshold, "threshold", "-", positive=True)
    max_points = integer(max_points, "max_points", minimum=100)
    settle_window = None if settle_window is None else \
        number(settle_window, "settle_window", "s", positive=True)
    args = _check_arguments(spec, measured, isolated, candidates, max_effects, drive)
    iso = args.isolated
    say("reading the record", 0.0)
    crossover = resolve(spec).crossover
    check_record(measured, crossover, "reconcile")
    lattice = find_lattice(measured.position, estimate_noise(measured.position))
    noise = noise_levels(spec, measured, iso, lattice, force_is_input=drive == "force")
    check_excitation(measured, noise.position)
    check_duration(measured, crossover)
    measured, thinning = for_the_model(measured, crossover)
    cmp = Comparison(spec, measured, iso, noise, lattice, settle_window, drive)
    say("nominal model", 0.02)
    nominal = _nominal(cmp, list(spec.effects), max_points)
    check = drive_check(cmp)
    if check.cause is not None:
        # open loop, force_N of the wrong sign or scale: the record alone says so, and every
        # effect fitted to a replay it drives would be bent by it
        return _unsearched(cmp, nominal, record_diagnosis(cmp, nominal.run, nominal.chi2, check),
                           started, threshold)
    if not nominal.run.ok:
        return _failed_nominal(cmp, nominal, started, threshold)
    evidence = scan(cmp, nominal.run, lattice, cmp.model.at(effects=nominal.entries).plant(iso))
    search = _search(cmp, evidence, args.names, nominal, max_effects, threshold, max_points, say)
    say("corrected model", 0.97)
    final = _final(cmp, search, nominal)
    first = search.rounds[0].candidates if search.rounds else ()
    best = max((c.explained for c in first if c.success), default=0.0)
    fitted = _best_fit(first, final, nominal)
    diagnosis = diagnose(cmp, nominal.run, nominal.chi2, best, after=final.run,
                         chi2_after=fitted.chi2, best_fit=fitted.name, drive=check)
    fault = record_fault(diagnosis)
    if fault is not None and search.chosen:
        # a force channel no effect can produce: nothing is named from it
        search = _withdrawn(search, fault)
        final = _final(cmp, search, nominal)
        first = search.rounds[0].candidates
    gaps = gap_metrics(cmp, nominal.run, final.run, nominal.chi2, final.chi2)
    ambiguous = _ambiguous(first, search.chosen, threshold)
    conclusion = _conclusion(final.steps, first, nominal.chi2, final.chi2, cmp.n_points,
                             ambiguous, diagnosis)
    conclusion = f"{conclusion} {thinning}" if thinning else conclusion
    conclusion = _warned(cmp, conclusion)
    say("done", 1.0)
    steps = final.steps
    return ReconcileResult(
        effect=steps[0].name if steps else "none",
        parameters=dict(steps[0].parameters) if steps else {},
        uncertainty=dict(steps[0].uncertainty) if steps else {},
        effects=tuple(s.name for s in steps), entries=final.entries, steps=steps,
        candidates=tuple(first), rounds=tuple(search.rounds), ambiguous=ambiguous,
        skipped=search.skipped, gaps=gaps, noise=noise, lattice=lattice,
        signatures=evidence.signatures, segments=cmp.segment_list(), diagnosis=diagnosis,
        isolated=iso, drive=drive, threshold=float(threshold), n_points=cmp.n_points,
        initial_command=None if cmp.initial_command is None else
        cmp.initial_command + final.command,
        chi2_nominal=nominal.chi2, chi2_corrected=final.chi2,
        conclusion=conclusion, n_simulations=cmp.n_sims + search.n_simulations,
        wall_time=_time.perf_counter() - started, measurement=measured,
        nominal=cmp.model_trace(nominal.run), corrected=cmp.model_trace(final.run), spec=spec,
        effect_entries=tuple(make_entry(e["type"], {k: v for k, v in e.items() if k != "type"})
                             for e in final.entries))


def _silent(message: str, fraction: float) -> None:
    """The progress callback when none is given."""


def _check_arguments(spec, measured, isolated, candidates, max_effects,
                     drive) -> "CheckedArguments":
    """Validated plant choice and candidate names (SimulationError / DataError otherwise)."""
    iso = spec.has_isolator if isolated is None else bool(isolated)
    if iso and not spec.has_isolator:
        raise SimulationError("isolated=True but the spec has no isolator")
    names = list(_effects.EFFECT_NAMES) if candidates is None else list(candidates)
    for name in names:
        if name not in _effects.CATALOGUE:
            raise SimulationError(f"unknown effect {name!r}; known: "
                                  + ", ".join(_effects.EFFECT_NAMES))
    if not isinstance(measured, Measurement):
        raise ArgumentError(f"measured must be a Measurement (fi_design.load_measurement), got "
                            f"{type(measured).__name__}")
    if isinstance(max_effects, int) and max_effects < 1:
        raise SimulationError("max_effects must be at least 1")
    integer(max_effects, "max_effects", minimum=1, maximum=len(_effects.EFFECT_NAMES))
    if drive not in DRIVES:
        raise SimulationError(f"drive must be one of {DRIVES}, got {drive!r}")
    if drive == "force" and measured.force is None:
        raise SimulationError("drive='force' replays the measured force: the record has no "
                              "force_N column")
    if measured.n < 50:
        raise DataError(f"too short for a reconciliation: {measured.n} samples, at least 50",
                        column="time_s", source=measured.source)
    moved = float(np.ptp(measured.reference))
    if float(np.ptp(measured.position)) <= 0.0 < moved:
        raise DataError(f"constant: position_m holds {quantity(float(measured.position[0]), 'm', 6)}"
                        f" in every row while the reference moves by {quantity(moved, 'm', 4)}: "
                        "the stage never moves in the record, so there is no motion to compare "
                        "with the model (was the encoder logged, the stage free?)",
                        column="position_m", source=measured.source)
    return CheckedArguments(iso, names)


@dataclass(frozen=True)
class CheckedArguments:
    """The plant to model and the effects to try."""

    isolated: bool
    names: list


def _nominal(cmp: Comparison, entries: list, max_points: int) -> Baseline:
    """The nominal model's run, with the segments decided and the initial command fitted."""
    run = cmp.run(entries)
    cmp.finish_setup(run, max_points)
    if not run.ok:
        return Baseline(entries, run, np.zeros(0), math.inf)
    nominal = fit_baseline(cmp, entries)
    cmp.set_fail_level(nominal.chi2)
    return nominal


# --------------------------------------------------------------------------- search


@dataclass(frozen=True, eq=False)
class Chosen:
    """An effect named in one pass: its fit and its judged candidate."""

    outcome: FitOutcome
    candidate: Candidate
    baseline: Baseline


@dataclass(frozen=True, eq=False)
class Search:
    """Every pass over the catalogue and the effects chosen, in order."""

    rounds: list
    chosen: list
    skipped: dict
    n_simulations: int


def _search(cmp, evidence: Evidence, names, nominal: Baseline, max_effects: int,
            threshold: float, max_points: int, say) -> Search:
    rounds: list[SearchRound] = []
    chosen: list[Chosen] = []
    skipped: dict[str, str] = {}
    baseline = nominal
    n_sims = 0
    for index in range(max_effects):
        remaining = [nm for nm in names if nm not in {c.candidate.name for c in chosen}]
        params = cmp.model.at(effects=baseline.entries).plant(cmp.iso)
        # later passes start from the signatures of the gap the earlier effects leave
        hints = evidence if index == 0 else scan(cmp, baseline.run, cmp.lattice, params)
        spaces = candidate_spaces(cmp, hints, remaining, cmp.lattice, params)
        if index == 0:
            skipped.update(spaces.skipped)
        if within_noise(baseline.chi2, cmp.n_points):
            break  # no gap above noise: no candidate could be named (significance.judge)
        done = _search_round(cmp, spaces.spaces, baseline, [c.outcome for c in chosen],
                             nominal.entries, threshold, max_points, index, max_effects, say)
        n_sims += done.n_simulations
        rounds.append(SearchRound(index=index, chi2_start=baseline.chi2,
                                  candidates=tuple(done.ranked),
                                  selected=done.pick.candidate.name if done.pick else None))
        if done.pick is None:
            break
        chosen.append(done.pick)
        out = done.pick.outcome
        baseline = Baseline(list(out.entries), out.run, out.residual, out.chi2, out.command)
    return Search(rounds, chosen, skipped, n_sims)


@dataclass(frozen=True, eq=False)
class RoundResult:
    """One pass: its candidates ranked, and the pick (None when nothing can be named)."""

    ranked: list
    pick: Chosen | None
    n_simulations: int


def _rank(c: Candidate) -> tuple:
    """Sort key: eligible first, an effect read from the data before fitted ones, then score."""
    return (not c.eligible, not (c.eligible and c.from_data), not c.success, -c.score)


def _search_round(cmp, spaces, baseline: Baseline, earlier: list, base: list, threshold,
                  max_points, index, max_effects, say) -> RoundResult:
    judged: dict[str, Candidate] = {}
    outcomes: dict[str, FitOutcome] = {}
    for j, sp in enumerate(spaces):
        say(f"fitting {sp.name}", 0.05 + 0.9 * (index + j / max(len(spaces), 1)) / max_effects)
        t0 = _time.perf_counter()
        outcome = fit(cmp, sp, baseline.entries, baseline.command)
        if earlier and outcome.run.ok and sp.coords:
            # an earlier effect may have absorbed part of this one: refit them together
            outcome = polish_jointly(cmp, earlier, outcome, base)
        outcomes[sp.name] = outcome
        judged[sp.name] = judge(cmp, outcome, baseline, threshold, _time.perf_counter() - t0)
    n_sims = 0  # the fits' runs are counted by the comparison; the refits run their own
    primary = sorted((c for c in judged.values() if passes_primary(c, outcomes[c.name].space)),
                     key=_rank)
    named: Candidate | None = None
    for j, c in enumerate(primary):
        close = named is None or c.score > named.score - threshold or \
            NESTED.get(named.name) == c.name  # the simpler form of the named one
        if j >= NULL_REFITS or not close:
            # not refitted: it cannot be named, and it is no close alternative to the named one
            judged[c.name] = replace(c, eligible=False, reasons=(
                "not refitted on noise alone: " + ("another effect scores decisively higher"
                                                   if named is not None else
                                                   f"only the best {NULL_REFITS} are"),))
            continue
        say(f"refitting {c.name} on noise alone", 0.05 + 0.9 * (index + 1) / max_effects)
        t0 = _time.perf_counter()
        real = outcomes[c.name]
        null = noise_only_refit(cmp, real.space, baseline, max_points,
                                NULL_SEED + 97 * index + j, start=real.u[real.columns])
        n_sims += null.n_simulations
        judged[c.name] = judge(cmp, outcomes[c.name], baseline, threshold,
                               c.wall_time + _time.perf_counter() - t0, null)
        if judged[c.name].eligible:
            # a finding: its uncertainty from the block jackknife and its numerical accuracy too
            jack = block_jackknife(cmp, outcomes[c.name])
            num = numerical_error(cmp, outcomes[c.name])
            judged[c.name] = judge(cmp, outcomes[c.name], baseline, threshold,
                                   c.wall_time + _time.perf_counter() - t0, null, jack, num)
        if judged[c.name].eligible and named is None:
            named = judged[c.name]
    ranked = sorted(prefer_simpler(judged).values(), key=_rank)
    pick = None
    if ranked and ranked[0].eligible:
        pick = Chosen(outcomes[ranked[0].name], ranked[0], baseline)
    return RoundResult(ranked, pick, n_sims)


class BestFit(NamedTuple):
    """The best fit of the catalogue: its chi2 and its effect(s), comma-separated."""

    chi2: float
    name: str


def _best_fit(first, final: Final, nominal: Baseline) -> BestFit:
    """The chosen effects' fit, else the best candidate that ran (the nominal model's when
    none did)."""
    if final.steps:
        return BestFit(final.chi2, ", ".join(s.name for s in final.steps))
    ran = [c for c in first if c.success and math.isfinite(c.chi2)]
    if not ran:
        return BestFit(nominal.chi2, "")
    top = min(ran, key=lambda c: c.chi2)
    return BestFit(min(top.chi2, nominal.chi2), top.name)


def _withdrawn(search: Search, fault: Cause) -> Search:
    """The search with nothing chosen: the record's fault makes every fitted value suspect.

    Only the first pass is kept (a later one searched the gap a withdrawn effect left); its
    candidates that could have been named say why they are not.
    """
    why = (f"force_N looks wrong ({fault.name.replace('_', ' ')}, see the diagnosis): no "
           "effect is named from a force channel the model cannot produce")
    first = search.rounds[0]
    cands = tuple(sorted((replace(c, eligible=False, reasons=(why,)) if c.eligible else c
                         for c in first.candidates), key=_rank))
    return Search([replace(first, candidates=cands, selected=None)], [], search.skipped,
                  search.n_simulations)


def _ambiguous(first, chosen: list[Chosen], threshold: float) -> tuple:
    """Eligible candidates of the first pass within ``threshold`` of the chosen one's score."""
    if not chosen or not first:
        return ()
    top = chosen[0].candidate
    return tuple(c.name for c in first if c.name != top.name and c.eligible
                 and c.score > top.score - threshold)


# --------------------------------------------------------------------------- the corrected model


@dataclass(frozen=True, eq=False)
class Final:
    """The corrected model: its entries, run, chi2 and the gap each effect closed."""

    entries: tuple
    run: ModelRun
    chi2: float
    steps: tuple
    command: float = 0.0


def _final(cmp: Comparison, search: Search, nominal: Baseline) -> Final:
    chosen = search.chosen
    if not chosen:
        return Final((), nominal.run, nominal.chi2, (), nominal.command)
    last = chosen[-1].outcome
    # a later effect was refitted with the earlier ones: their values are in its entries
    fitted = {e.type: e for e in last.entries}
    values = [{p: getattr(fitted[c.candidate.name], p) for p in c.outcome.values}
              for c in chosen]
    sigmas = [c.candidate.uncertainty for c in chosen]
    run, chi2, command = last.run, last.chi2, last.command
    if len(chosen) > 1:
        refined = _refine_jointly(cmp, chosen, nominal)
        if refined is not None and refined.chi2 < chi2:
            values, sigmas, run, chi2 = refined.values, refined.sigmas, refined.run, refined.chi2
            command = refined.command
    steps = []
    for c, v, s in zip(chosen, values, sigmas):
        before, after = c.baseline.run, c.outcome.run
        n = cmp.n_points
        steps.append(EffectStep(
            name=c.candidate.name, parameters=dict(v), uncertainty=dict(s),
            misfit_before=math.sqrt(c.baseline.chi2 / n),
            misfit_after=math.sqrt(c.outcome.chi2 / n),
            position_rms_before=_rms(before.position, cmp.meas.position),
            position_rms_after=_rms(after.position, cmp.meas.position),
            force_rms_before=_rms(before.force, cmp.meas.force) if cmp.has_force else None,
            force_rms_after=_rms(after.force, cmp.meas.force) if cmp.has_force else None))
    entries = tuple({"type": s.name, **{k: v for k, v in s.parameters.items() if v is not None}}
                    for s in steps)
    return Final(entries, run, chi2, tuple(steps), command)


def _rms(a: np.ndarray, b: np.ndarray) -> float:
    d = a - b
    d = d[np.isfinite(d)]
    return float(np.sqrt(np.mean(d ** 2))) if len(d) else math.nan


@dataclass(frozen=True, eq=False)
class Refined:
    """Several effects refined together: their values, uncertainties, run and chi2."""

    values: list
    sigmas: list
    run: ModelRun
    chi2: float
    command: float


def _refine_jointly(cmp: Comparison, chosen: list[Chosen], nominal: Baseline) -> Refined | None:
    spaces: list[Space] = [c.outcome.space for c in chosen]
    jo = JointObjective(cmp, spaces, nominal.entries)
    parts = [c.outcome.u[:len(c.outcome.space.coords)] for c in chosen]
    if jo.nuisance is not None:
        parts.append([jo.nuisance.u_of(chosen[-1].outcome.command)])
    jf = joint_fit(jo, np.concatenate(parts))
    if not math.isfinite(jf.chi2):
        return None
    run = jo.evaluate(jf.u).run
    if not run.ok:
        return None
    n = len(jf.residual)
    s2 = max(1.0, jf.chi2 / max(n - len(jf.u), 1))
    tau = channels_autocorrelation_time(cmp.channel_blocks(jf.residual))
    values, sigmas = [], []
    for ob, sl, c in zip(jo.obs, jo.slices, chosen):
        vals = ob.values(jf.u[sl])
        values.append(vals)
        cov = marginal_covariance(jf.jacobian, sl)
        if cov is None:
            sigmas.append(dict(c.candidate.uncertainty))
            continue
        G = ob.value_jacobian(jf.u[sl])
        var = np.diag(G @ (cov * s2 * tau) @ G.T)
        sig = {}
        for name, v in zip(vals, var):
            lin = math.sqrt(v) if v > 0 and math.isfinite(v) else 0.0
            old = c.candidate.uncertainty.get(name) or 0.0
            sig[name] = max(lin, old) or None  # never more certain than the one-by-one fit
        sigmas.append(sig)
    return Refined(values, sigmas, run, jf.chi2, jo.command(jf.u))


def _failed_nominal(cmp: Comparison, nominal: Baseline, started: float,
                    threshold: float) -> ReconcileResult:
    """The result when the nominal model cannot be replayed: what failed, and the traces."""
    diagnosis = Diagnosis(
        mismatch=True, misfit=math.inf, misfit_limit=0.0, best_explained=0.0,
        channel="position", causes=(),
        message=f"The nominal model fails on this record: {nominal.run.message}. No effect can "
                "be judged against a model that does not run; check the spec against the "
                "record (" + ("mass, friction, force_N's sign and unit" if cmp.drive == "force"
                              else "controller, mass, sample rate") + ").",
        frequency=np.zeros(0), spectrum=np.zeros(0), crossover=0.0)
    return _unsearched(cmp, nominal, diagnosis, started, threshold)


def _unsearched(cmp: Comparison, nominal: Baseline, diagnosis: Diagnosis, started: float,
                threshold: float) -> ReconcileResult:
    """The result without a search (a nominal model that fails, a faulty record): the
    diagnosis, the nominal gap when the model ran, and the traces."""
    run = nominal.run
    ran = run.ok and math.isfinite(nominal.chi2)
    chi2 = nominal.chi2 if ran else math.inf
    return ReconcileResult(
        effect="none", parameters={}, uncertainty={}, effects=(), entries=(), steps=(),
        candidates=(), rounds=(), ambiguous=(), skipped={},
        gaps=gap_metrics(cmp, run, run, chi2, chi2) if ran else (), noise=cmp.noise,
        lattice=cmp.lattice, signatures=(), segments=cmp.segment_list(), diagnosis=diagnosis,
        isolated=cmp.iso, drive=cmp.drive, threshold=float(threshold), n_points=cmp.n_points,
        initial_command=cmp.initial_command, chi2_nominal=chi2, chi2_corrected=chi2,
        conclusion=_warned(cmp, diagnosis.message), n_simulations=cmp.n_sims,
        wall_time=_time.perf_counter() - started, measurement=cmp.meas,
        nominal=cmp.model_trace(run), corrected=cmp.model_trace(run), spec=cmp.spec)


# --------------------------------------------------------------------------- wording


def _warned(cmp: Comparison, conclusion: str) -> str:
    """The conclusion led by the replay's warnings about the record (a closed loop that
    starts far from its reference: an offset between position_m and reference_m explains a
    gap no effect does, and a cause the diagnosis would call only the initial state)."""
    return " ".join([f"Warning: {n}." for n in cmp.notes] + [conclusion])


def _conclusion(steps, candidates, chi2_nom, chi2_cor, n, ambiguous, diagnosis) -> str:
    before, after = math.sqrt(chi2_nom / n), math.sqrt(chi2_cor / n)
    if diagnosis.mismatch:
        text = diagnosis.message
        if steps:
            text += " Named nonetheless: " + ", ".join(s.name for s in steps) + "."
        return text
    if not steps:
        if within_noise(chi2_nom, n):
            return (f"The nominal model agrees with the measurement within noise (misfit "
                    f"{display.number(before, 3)} noise units): no effect is missing, and "
                    "the catalogue was not fitted (there is no gap to explain).")
        best = next((c for c in candidates if c.success), None)
        tail = ""
        if best is not None:
            why = best.reasons[0] if best.reasons else "not significant"
            tail = f" The best candidate, {best.name}, is not a finding: {why}."
        return (f"The model misses the measurement by {display.number(before, 3)} noise units, "
                "but no catalogue "
                f"effect explains the gap beyond what noise and the fit's freedom give: the "
                f"answer is none.{tail}")
    lines = [f"{s.name} ({_effects.values_text(s.name, s.parameters, s.uncertainty)}"
             + ("" if len(steps) == 1 else  # one step: the next sentence gives its misfit
                f"; misfit {display.number(s.misfit_before, 3)} \u2192 "
                f"{display.number(s.misfit_after, 3)}") + ")"
             for s in steps]
    text = (f"The measurement shows {', then '.join(lines)}. With "
            f"{'them' if len(steps) > 1 else 'it'} the misfit drops from "
            f"{display.number(before, 3)} to {display.number(after, 3)} noise units.")
    if ambiguous:
        text += (" Also consistent with the data, not decisively worse: "
                 + ", ".join(ambiguous) + ".")
    return text
