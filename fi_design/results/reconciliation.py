"""Results of the reconciliation of a model with a measured record.

Produced by :func:`fi_design.reconciliation.reconcile`: the named effect (or
``none``) with its honest uncertainty, the candidates and the tests each
passed, the gaps before and after, the lattice of the measured positions and
the structure diagnosis, with the model traces at the measured times.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from . import Result, to_jsonable

if TYPE_CHECKING:  # pragma: no cover
    from ..measured import Measurement

__all__ = ["Lattice", "NoiseLevels", "Segment", "Signature", "GapMetric", "Candidate",
           "SearchRound", "EffectStep", "Cause", "Diagnosis", "ModelTrace", "ReconcileResult"]


@dataclass(frozen=True)
class Lattice(Result):
    """The lattice the measured positions lie on (a quantizing sensor), read from the data.

    Attributes
    ----------
    step : float or None
        Lattice step q [m]; None when no lattice was found.
    step_error : float or None
        Standard error of the step [m] (the least-squares fit of the
        differences between samples on whole numbers of steps).
    offset : float
        Lattice offset x0 in [0, q): the positions lie on x0 + k q [m].
    fraction : float
        Share of the tested samples on the lattice (within a quarter step, or
        within 1 % of a step for an exact lattice) [-].
    chance : float
        Share expected on it by chance, without a lattice [-].
    tested : int
        Samples the test counted.
    p_value : float
        Binomial test of ``fraction`` against ``chance`` (one-sided) [-].
    jitter : float
        Spread of the samples around the lattice points (1.4826 MAD) [m]: the
        sensor noise apart from the quantization; 0 for an exact lattice.
    exact : bool
        Whether every sample is a whole number of steps (up to the file's
        number formatting).
    coarse : bool
        Whether the lattice is coarser than the noise explains (the counts,
        not a noise under them, make the record's scatter; see
        :mod:`fi_design.reconciliation.lattice`). Only then is
        ``quantization`` a candidate, with this step.
    detail : str
        One sentence for the report.
    """

    step: float | None
    step_error: float | None = None
    offset: float = 0.0
    fraction: float = 0.0
    chance: float = 0.0
    tested: int = 0
    p_value: float = 1.0
    jitter: float = 0.0
    exact: bool = False
    coarse: bool = False
    detail: str = "no lattice in the measured position"

    @property
    def found(self) -> bool:
        """Whether the positions lie on a lattice."""
        return self.step is not None


@dataclass(frozen=True)
class NoiseLevels(Result):
    """Sensor noise used to judge every gap.

    Attributes
    ----------
    position : float
        Position noise standard deviation [m].
    force : float or None
        Force noise standard deviation [N]; None without a force column (or
        when the force drives the model).
    deflection : float or None
        Deflection noise standard deviation [m]; None without a deflection
        column (or without isolator).
    source : dict of str to str
        Per channel: ``"spec"`` (the spec's ``measurement`` section),
        ``"estimated"`` (from the data) or ``"floor"`` (the model-accuracy
        floor, when the data are quieter).
    """

    position: float
    force: float | None
    deflection: float | None
    source: dict


@dataclass(frozen=True)
class Segment(Result):
    """A stretch of the trace compared one way.

    Attributes
    ----------
    kind : str
        ``"move"``, ``"settle"`` or ``"hold"``.
    start, end : float
        Start and end time [s], relative to the first sample.
    coherent : bool
        Compared sample by sample (True) or by phase-free features (a hold
        with stick-slip cycles).
    """

    kind: str
    start: float
    end: float
    coherent: bool = True


@dataclass(frozen=True)
class Signature(Result):
    """Evidence in the nominal residual that points at effects.

    Attributes
    ----------
    name : str
        What was looked for (``"velocity"``, ``"spatial_period"``, ...).
    effects : tuple of str
        The effects this signature points at.
    strength : float
        Fraction of the residual's variance the signature explains (R^2, 0-1).
    value : float or None
        The signature's own number (a slope, a period, a lag), in ``unit``.
    unit : str
        Unit of ``value``.
    detail : str
        One sentence for the report.
    """

    name: str
    effects: tuple
    strength: float
    value: float | None
    unit: str
    detail: str


@dataclass(frozen=True)
class GapMetric(Result):
    """One measure of disagreement, before and after the correction.

    Attributes
    ----------
    name : str
        Key in ``gap_before`` / ``gap_after``.
    unit : str
        Unit of the values.
    description : str
        What it measures.
    measured, nominal, corrected : float or None
        The feature on the measurement and the two models (None for
        sample-wise residual measures, which have no per-trace value).
    before, after : float or None
        The gap: residual RMS or absolute feature difference, nominal and
        corrected model.
    noise : float or None
        What noise alone would give, in ``unit``.
    significant_before, significant_after : bool or None
        Whether the gap exceeds noise clearly.
    """

    name: str
    unit: str
    description: str
    measured: float | None
    nominal: float | None
    corrected: float | None
    before: float | None
    after: float | None
    noise: float | None
    significant_before: bool | None
    significant_after: bool | None


@dataclass(frozen=True)
class Candidate(Result):
    """One catalogue effect fitted to the measurement, and how it was judged.

    Attributes
    ----------
    name : str
        Effect name (docs/effects.md).
    parameters : dict of str to float
        Fitted parameters, SI (keys as in the spec's effect entry).
    uncertainty : dict of str to float or None
        One standard deviation of each fitted parameter, SI: from the
        Jacobian, scaled by the fit's reduced chi-square and by the residual's
        autocorrelation time (effective samples), widened by the scatter of a
        noise-only refit where one ran. None where the fit cannot tell.
    reference : dict of str to float or None
        The value each parameter has in the model the search started from
        (the spec's nominal value, or the effect's neutral value), SI; None
        where there is none (a period, a phase).
    distance : dict of str to float or None
        (fitted - reference) / uncertainty per parameter [-]: how far from
        the model's own value the data put it, in honest standard errors (a
        force limit, whose reference is None, from the record's peak force,
        above which it never acts); None without a reference or a standard
        error.
    score : float
        Evidence against the model without it: the chi-square improvement in
        effective samples minus k ln(n_eff) (higher is better) [-].
    chi2 : float
        Weighted squared residual of the fit [-].
    delta_chi2 : float
        Reduction of chi2 against the model the search started from [-].
    explained : float
        Fraction of the gap above noise (chi2 - n) that the fit removes, 0-1.
    autocorrelation_time : float
        Integrated autocorrelation time of the fit's residual [samples of the
        comparison]; 1 for white residuals.
    n_effective : float
        Effective number of independent residuals, n / autocorrelation time.
    null_score : float or None
        The same improvement statistic for a refit on a noise-only record
        (the starting model's own trace plus sensor noise): what noise and
        the fit's freedom give without the effect. None when not run.
    effect_size : float
        RMS change the effect makes to the model's weighted residual [noise
        units].
    n_parameters : int
        Number of fitted coordinates.
    widened : int
        How many times a search bound was widened because the fit ended on it.
    at_bound : tuple of str
        Parameters still at a search bound (or a physical limit) after the
        widening: such a fit is not a finding.
    status : str
        ``"ok"``, ``"failed"`` (every simulation failed), ``"diverged"`` (the
        best point's simulation failed or ran away) or ``"at bound"``.
    from_data : bool
        Its value was read from the data (the lattice test of the measured
        positions), not fitted: that test is its evidence, and an eligible
        effect read from the data ranks before fitted ones.
    eligible : bool
        Whether it passed every test and could be named.
    reasons : tuple of str
        Why it could not be named (empty when eligible).
    n_simulations : int
        Simulations the fit used (refit included).
    n_failed : int
        Simulations of the fit that failed or ran away (an unstable loop):
        they counted ten times the nominal misfit and could never win.
    wall_time : float
        Time the fit took [s].
    message : str
        Notes (the failure message of its simulation, a bound reached).
    """

    name: str
    parameters: dict
    uncertainty: dict
    reference: dict
    distance: dict
    score: float
    chi2: float
    delta_chi2: float
    explained: float
    autocorrelation_time: float
    n_effective: float
    null_score: float | None
    effect_size: float
    n_parameters: int
    widened: int
    at_bound: tuple
    status: str
    from_data: bool
    eligible: bool
    reasons: tuple
    n_simulations: int
    n_failed: int
    wall_time: float
    message: str = ""

    @property
    def success(self) -> bool:
        """Whether the candidate's simulation ran (status not failed or diverged)."""
        return self.status not in ("failed", "diverged")

    def to_dict(self) -> dict:
        """Plain JSON data (SI), with ``success``."""
        d = super().to_dict()
        d["success"] = self.success
        return d


@dataclass(frozen=True)
class SearchRound(Result):
    """One pass over the catalogue (``max_effects`` > 1 runs several).

    Attributes
    ----------
    index : int
        0 for the first pass.
    chi2_start : float
        chi2 of the model the pass starts from [-].
    candidates : tuple of Candidate
        Ranked: eligible ones first, then by score.
    selected : str or None
        The effect added in this pass, None when none could be named.
    """

    index: int
    chi2_start: float
    candidates: tuple
    selected: str | None


@dataclass(frozen=True)
class EffectStep(Result):
    """One named effect and the gap it closes, in the order they were found.

    Attributes
    ----------
    name : str
        Effect name.
    parameters : dict of str to float
        Fitted parameters, SI (after the joint refinement when several).
    uncertainty : dict of str to float or None
        One standard deviation of each, SI.
    misfit_before, misfit_after : float
        RMS weighted residual before and after adding this effect (1 = noise).
    position_rms_before, position_rms_after : float
        RMS of measured minus modelled position before and after [m].
    force_rms_before, force_rms_after : float or None
        The same for the commanded force [N]; None without a force column.
    """

    name: str
    parameters: dict
    uncertainty: dict
    misfit_before: float
    misfit_after: float
    position_rms_before: float
    position_rms_after: float
    force_rms_before: float | None
    force_rms_after: float | None


@dataclass(frozen=True)
class Cause(Result):
    """A likely cause of a gap the catalogue cannot explain.

    Attributes
    ----------
    name : str
        ``"controller"`` (open loop ``"measured_force"``: no controller
        in the replay), ``"initial_state"``, ``"mass"`` or ``"disturbance"``
        (the model), or ``"force_sign"`` or ``"force_scale"`` (the record's
        ``force_N`` column, against the model after the best fit; open loop, against
        the motion it drives).
    share : float
        Share of the nominal residual's variance that points at it, 0-1
        (``force_sign``, ``force_scale``: the share of the force residual's
        energy that a factor and an offset on the measured force remove;
        open loop, the share of the sliding force's variance the inverse
        dynamics explain).
    detail : str
        What was measured and what to check, one or two sentences.
    """

    name: str
    share: float
    detail: str


@dataclass(frozen=True, eq=False)
class Diagnosis(Result):
    """Whether the model's structure, rather than a missing effect, is the problem.

    Attributes
    ----------
    mismatch : bool
        True when the nominal misfit is far above noise (at least
        ``misfit_limit``) and no candidate explains most of it or the best
        fit of the catalogue still leaves ``misfit_limit`` or more
        (``misfit_after``); or when the record's force looks wrong (a cause
        ``force_sign`` or ``force_scale``).
    misfit : float
        RMS weighted residual of the nominal model (1 = noise).
    misfit_limit : float
        Misfit from which a gap counts as structural.
    best_explained : float
        Largest share of the gap above noise any candidate removes, 0-1.
    channel : str
        The residual the causes were read from (``"force"`` or ``"position"``).
    causes : tuple of Cause
        Likely causes, strongest first.
    message : str
        One paragraph for a reader (empty when there is no mismatch).
    frequency : ndarray, shape (m,)
        Frequencies of the residual's spectrum [Hz].
    spectrum : ndarray, shape (m,)
        Amplitude spectral density of the nominal residual [unit of the
        channel / sqrt(Hz)].
    crossover : float
        The loop's crossover [Hz], marked in the spectrum.
    misfit_after : float
        RMS weighted residual left by the best fit of the catalogue (the
        model with the chosen effects, else the best candidate's fit; the
        nominal misfit when no candidate ran) (1 = noise).
    best_fit : str
        The effect(s) of that fit, comma-separated; empty when none ran.
    force_scale : float or None
        Least-squares factor of the measured force on the force of the model
        after the best fit (with an offset) [-]: about 1 when ``force_N``
        and the model agree in sign and scale, negative when the column's
        sign is flipped. Open loop (``drive="force"``): the factor on the
        spec's moving mass times the acceleration in the fit of the measured
        force to the motion it drives (about 1 likewise). None without a
        force column.
    """

    mismatch: bool
    misfit: float
    misfit_limit: float
    best_explained: float
    channel: str
    causes: tuple
    message: str
    frequency: np.ndarray = field(repr=False)
    spectrum: np.ndarray = field(repr=False)
    crossover: float = 0.0
    misfit_after: float = math.nan
    best_fit: str = ""
    force_scale: float | None = None



@dataclass(frozen=True, eq=False)
class ModelTrace(Result):
    """A model run sampled at the measured times.

    Attributes
    ----------
    time : ndarray, shape (n,)
        Time from the first sample [s].
    position : ndarray, shape (n,)
        Stage position x1 [m] (as the sensor reports it: quantized when the
        model quantizes); NaN after a failure.
    force : ndarray, shape (n,)
        Commanded force u [N]; NaN after a failure.
    deflection : ndarray, shape (n,), or None
        Joint deflection [m] (isolated plant).
    success : bool
        Whether the simulation completed and stayed within the measurement's
        envelope.
    message : str
        What failed, if anything.
    """

    time: np.ndarray
    position: np.ndarray
    force: np.ndarray
    deflection: np.ndarray | None
    success: bool
    message: str = ""


@dataclass(frozen=True, eq=False)
class ReconcileResult(Result):
    """What :func:`fi_design.reconciliation.reconcile` found.

    Attributes
    ----------
    effect : str
        The named effect (the first chosen), or ``"none"``.
    parameters : dict of str to float
        Its fitted parameters, SI ({} for none).
    uncertainty : dict of str to float
        One standard deviation of each, SI.
    effects : tuple of str
        All effects chosen, in order (several with ``max_effects`` > 1).
    entries : tuple of dict
        The spec ``effects`` entries to add (``{"type": name, param: value}``),
        SI.
    steps : tuple of EffectStep
        Every named effect with the gap it closed, in order.
    candidates : tuple of Candidate
        The first pass's candidates, ranked.
    rounds : tuple of SearchRound
        Every pass.
    ambiguous : tuple of str
        Eligible candidates of the first pass whose score is within
        ``threshold`` of the chosen one's: the data cannot tell them apart.
    skipped : dict of str to str
        Catalogue effects not tried, with the reason.
    gaps : tuple of GapMetric
        Every gap measure, before and after.
    noise : NoiseLevels
        The noise levels used.
    lattice : Lattice
        The lattice of the measured positions (quantization read from data).
    signatures : tuple of Signature
        Evidence in the nominal residual, strongest first.
    segments : tuple of Segment
        How the trace was split.
    diagnosis : Diagnosis
        Whether the model's structure misses the record, and why.
    isolated : bool
        Whether the isolated plant was modelled.
    drive : str
        ``"closed"`` (the model's controller closes the loop on the measured
        reference) or ``"force"`` (the plant driven by the measured force in
        re-anchored windows).
    threshold : float
        Score a candidate needs to be named.
    n_points : int
        Entries of the residual vector.
    initial_command : float or None
        The controller's output at the first sample the replays start from
        [N], fitted within the force noise (a nuisance parameter); None
        without a force column or in an open-loop replay.
    chi2_nominal, chi2_corrected : float
        Weighted squared residual of the nominal and the corrected model [-].
    conclusion : str
        One paragraph for a reader.
    n_simulations : int
        Simulations run in total.
    wall_time : float
        Time the reconciliation took [s].
    measurement : Measurement
        The measured trace.
    nominal, corrected : ModelTrace
        The two models at the measured times.
    spec : Spec
        The spec reconciled (without the new effects).
    effect_entries : tuple
        The spec ``effects`` entries of :attr:`entries`, validated.
    """

    effect: str
    parameters: dict
    uncertainty: dict
    effects: tuple
    entries: tuple
    steps: tuple
    candidates: tuple
    rounds: tuple
    ambiguous: tuple
    skipped: dict
    gaps: tuple
    noise: NoiseLevels
    lattice: Lattice
    signatures: tuple
    segments: tuple
    diagnosis: Diagnosis
    isolated: bool
    drive: str
    threshold: float
    n_points: int
    initial_command: float | None
    chi2_nominal: float
    chi2_corrected: float
    conclusion: str
    n_simulations: int
    wall_time: float
    measurement: Measurement = field(repr=False)
    nominal: ModelTrace = field(repr=False)
    corrected: ModelTrace = field(repr=False)
    spec: Any = field(repr=False)
    effect_entries: tuple = field(default=(), repr=False)

    @property
    def gap_before(self) -> dict:
        """Gap of the nominal model per metric (name to value, units in :attr:`gaps`)."""
        return {g.name: g.before for g in self.gaps}

    @property
    def gap_after(self) -> dict:
        """Gap of the corrected model per metric (same keys as :attr:`gap_before`)."""
        return {g.name: g.after for g in self.gaps}

    def corrected_spec(self):
        """The spec with the chosen effects in its ``effects`` list (a new Spec, validated).

        An entry of a type the spec already lists replaces it.
        """
        names = {e.type for e in self.effect_entries}
        kept = [e for e in self.spec.effects if e.type not in names]
        return self.spec.with_sections(effects=tuple(kept + list(self.effect_entries)))

    def to_dict(self) -> dict:
        """Plain JSON data: the contract keys first, then the details (SI)."""
        from ..provenance import header

        return {
            "effect": self.effect,
            "parameters": to_jsonable(self.parameters),
            "uncertainty": to_jsonable(self.uncertainty),
            "effects": list(self.effects),
            "entries": to_jsonable(self.entries),
            "steps": [s.to_dict() for s in self.steps],
            "candidates": [c.to_dict() for c in self.candidates],
            "gap_before": to_jsonable(self.gap_before),
            "gap_after": to_jsonable(self.gap_after),
            "noise": self.noise.to_dict(),
            "lattice": self.lattice.to_dict(),
            "diagnosis": self.diagnosis.to_dict(),
            "ambiguous": list(self.ambiguous),
            "skipped": dict(self.skipped),
            "gaps": [g.to_dict() for g in self.gaps],
            "units": {g.name: g.unit for g in self.gaps},
            "signatures": [s.to_dict() for s in self.signatures],
            "segments": [s.to_dict() for s in self.segments],
            "rounds": [r.to_dict() for r in self.rounds],
            "isolated": self.isolated,
            "drive": self.drive,
            "threshold": self.threshold,
            "n_points": self.n_points,
            "initial_command": to_jsonable(self.initial_command),
            "chi2_nominal": to_jsonable(self.chi2_nominal),
            "chi2_corrected": to_jsonable(self.chi2_corrected),
            "conclusion": self.conclusion,
            "n_simulations": self.n_simulations,
            "wall_time": self.wall_time,
            **header(),
            "measurement": self.measurement.to_dict(),
        }
