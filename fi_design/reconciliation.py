"""Reconciliation: where do model and measurement disagree, and which effect is missing?

:func:`reconcile` compares the nominal model of a spec with a measured trace
(:mod:`fi_design.measured`), names the physical effect of the catalogue
(DESIGN.md section 5, :mod:`fi_design.effects`) that explains the
disagreement, fits its parameters with uncertainties, and shows the gap
before and after.

Method
------
1. **Replay.** The model is driven by the measured ``reference_m`` column (a
   C2 spline through the samples) and starts at rest at the first sample, at
   the median measured position while the reference still rests. It is
   sampled at the measured times.
2. **Segments.** From the reference velocity: *move* (the reference moves),
   *settle* (a window after each move, ``settle_window``, default five
   integrator time constants ``5 * integrator_ratio / (2 pi fc)``) and *hold*
   (the rest). A hold in which the measured or the nominal error reverses
   direction three times or more by more than the hysteresis band (ten
   position-noise levels, at least the settle band) is *incoherent*:
   stick-slip cycles drift out of phase after a slip, so there the
   comparison uses phase-free features (mean, standard deviation and reversal
   rate of the position error; mean and standard deviation of force and
   deflection) instead of samples.
3. **Noise.** Per channel from the spec's ``measurement`` section, else from
   the data: the median absolute deviation of the third differences (robust
   to the smooth motion and to the sparse slips), scaled to a standard
   deviation, and never below a model-accuracy floor (:data:`NOISE_FLOOR`).
   A staircase in the measured position (a lattice of step ``q`` much larger
   than the noise) is reported as the sensor resolution.
4. **Objective.** The weighted residual vector stacks the sample-wise
   residuals of position, force and deflection in the coherent segments
   (each divided by its noise; strided to at most ``max_points`` samples per
   channel) and the feature residuals of incoherent holds (each divided by
   its uncertainty: the spread over four chunks of the segment, 5 % of the
   value and the noise). ``chi2`` is its squared norm over ``n`` entries;
   ``chi2 / n`` is about 1 when the model agrees within noise.
5. **Signatures.** Regressions of the nominal residual (force when recorded,
   else position) on what each effect would leave behind: velocity
   (viscous), a low-velocity bump (Stribeck), a spatial period (position
   dependent friction, force ripple; Lomb-Scargle periodogram over position),
   position (cable), reference acceleration (mass), the lag between measured
   and modelled force (delay), a lattice in the measured position
   (quantization), force above a level (saturation) and the deflection rate
   (joint damping). They give the starting values and are reported as
   evidence; they decide nothing.
6. **Fits.** Every applicable candidate is fitted by bounded least squares
   (scipy ``least_squares``, trust-region reflective) on coordinates scaled to
   [0, 1] (logarithmic where the catalogue says so), from the two best of a
   grid of starts plus the signature's guess. Each start is first fitted on
   the move samples alone with a robust loss (soft L1; the moves keep the
   objective smooth where slips in the settle and hold segments make it
   rugged), then on everything. Spatial periods are searched over the
   periodogram peaks times a phase grid (the phase fitted at the middle of
   the travel, where it does not trade off against the period); the
   quantization step, whose objective is a staircase, by nested scans around
   the step the staircase signature measured. The uncertainty comes from the
   Jacobian at the optimum (or the curvature of the scan), scaled by the
   reduced chi-square when above one, and mapped to the parameters with the
   derivative of the scaling. The replays run at a tolerance that keeps the
   integration error a hundredth of the smallest noise
   (:func:`model_tolerance`), so that no fit can "explain" numerical jitter.
7. **Score and selection.** For a candidate with ``k`` parameters the score is
   a Bayesian information criterion difference with the variance rescaled by
   the candidate's own reduced chi-square::

       score = (chi2_nominal - chi2_fit) / max(1, chi2_fit / (n - k)) - k ln(n)

   The best-scoring candidate is the answer if its score exceeds
   ``threshold`` (default 10: "very strong" evidence on the Kass-Raftery
   scale); otherwise the answer is ``none``. Candidates within ``threshold`` of
   the best are reported as ambiguous. With ``max_effects`` > 1 the search
   repeats on the remaining gap with the chosen effects in the model, and the
   chosen effects are finally refined together.

The library never prints; pass ``progress`` to follow the work.
"""

from __future__ import annotations

import math
import time as _time
from dataclasses import dataclass, field, replace
from typing import Any, Callable

import numpy as np

from . import effects as _effects
from . import spec as _spec
from .errors import DataError, SimulationError
from .measured import Measurement
from .metrics import hunting_metrics
from .trajectory import from_samples
from .results import dataclass_dict, frozen_array, to_jsonable
from .simulation import SimulationResult, simulate

#: Default significance threshold on the score (BIC difference).
THRESHOLD = 10.0
#: Default largest number of sample-wise residuals per channel.
MAX_POINTS = 3000
#: Model-accuracy floor of the noise per channel (position and deflection in m, force in N).
NOISE_FLOOR = {"position": 1e-9, "deflection": 1e-10, "force": 1e-5}
#: Residual assigned to every entry when a candidate's simulation fails [noise units].
FAIL_RESIDUAL = 1e3

ProgressCallback = Callable[[str, float], None]


# --------------------------------------------------------------------------- results


@dataclass(frozen=True)
class NoiseLevels:
    """Sensor noise used to judge every gap.

    Attributes
    ----------
    position : float
        Position noise standard deviation [m].
    force : float or None
        Force noise standard deviation [N]; None without a force column.
    deflection : float or None
        Deflection noise standard deviation [m]; None without a deflection
        column (or without isolator).
    source : dict of str to str
        Per channel: ``"spec"`` (the spec's ``measurement`` section),
        ``"estimated"`` (from the data) or ``"floor"`` (the model-accuracy
        floor, when the data are quieter).
    resolution : float or None
        Step of a staircase found in the measured position [m], or None.
    """

    position: float
    force: float | None
    deflection: float | None
    source: dict
    resolution: float | None = None

    def to_dict(self) -> dict:
        """Plain JSON data (SI)."""
        return dataclass_dict(self)


@dataclass(frozen=True)
class Segment:
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

    def to_dict(self) -> dict:
        """Plain JSON data (SI)."""
        return dataclass_dict(self)


@dataclass(frozen=True)
class Signature:
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

    def to_dict(self) -> dict:
        """Plain JSON data (SI)."""
        return dataclass_dict(self)


@dataclass(frozen=True)
class GapMetric:
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

    def to_dict(self) -> dict:
        """Plain JSON data (SI)."""
        return dataclass_dict(self)


@dataclass(frozen=True)
class Candidate:
    """One catalogue effect fitted to the measurement.

    Attributes
    ----------
    name : str
        Effect name (DESIGN.md section 5).
    parameters : dict of str to float
        Fitted parameters, SI (keys as in the spec's effect entry).
    uncertainty : dict of str to float
        One standard deviation of each fitted parameter, SI (None where the
        fit cannot tell).
    score : float
        BIC difference against the model without it (higher is better; above
        the threshold it is significant).
    chi2 : float
        Weighted squared residual of the fit [-].
    delta_chi2 : float
        Reduction of chi2 against the starting model [-].
    explained : float
        Fraction of the gap above noise (chi2 - n) that the fit removes, 0-1.
    n_parameters : int
        Number of fitted coordinates.
    n_simulations : int
        Simulations the fit used.
    wall_time : float
        Time the fit took [s].
    success : bool
        Whether the fit ran; False with ``message`` when every simulation failed.
    message : str
        Notes (a bound reached, a failure).
    """

    name: str
    parameters: dict
    uncertainty: dict
    score: float
    chi2: float
    delta_chi2: float
    explained: float
    n_parameters: int
    n_simulations: int
    wall_time: float
    success: bool = True
    message: str = ""

    def to_dict(self) -> dict:
        """Plain JSON data (SI)."""
        return dataclass_dict(self)


@dataclass(frozen=True)
class SearchRound:
    """One pass over the catalogue (``max_effects`` > 1 runs several).

    Attributes
    ----------
    index : int
        0 for the first pass.
    chi2_start : float
        chi2 of the model the pass starts from [-].
    candidates : tuple of Candidate
        Ranked best first.
    selected : str or None
        The effect added in this pass, None when none beat the threshold.
    """

    index: int
    chi2_start: float
    candidates: tuple
    selected: str | None

    def to_dict(self) -> dict:
        """Plain JSON data (SI)."""
        return dataclass_dict(self)


@dataclass(frozen=True, eq=False)
class ModelTrace:
    """A model run sampled at the measured times.

    Attributes
    ----------
    time : ndarray, shape (n,)
        Time from the first sample [s].
    position : ndarray, shape (n,)
        Stage position x1 [m] (as the sensor reports it: quantized when the
        model quantizes).
    force : ndarray, shape (n,)
        Commanded force u [N].
    deflection : ndarray, shape (n,), or None
        Joint deflection [m] (isolated plant).
    success : bool
        Whether the simulation completed.
    message : str
        The simulation's failure message, if any.
    """

    time: np.ndarray
    position: np.ndarray
    force: np.ndarray
    deflection: np.ndarray | None
    success: bool
    message: str = ""

    def to_dict(self) -> dict:
        """Plain JSON data (SI)."""
        return dataclass_dict(self)


@dataclass(frozen=True, eq=False)
class ReconcileResult:
    """What :func:`reconcile` found.

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
    candidates : tuple of Candidate
        The first pass's candidates, ranked best first.
    rounds : tuple of SearchRound
        Every pass.
    ambiguous : tuple of str
        Candidates of the first pass whose score is within ``threshold`` of
        the chosen one's: the data cannot tell them apart with confidence.
    skipped : dict of str to str
        Catalogue effects not tried, with the reason.
    gaps : tuple of GapMetric
        Every gap measure, before and after.
    noise : NoiseLevels
        The noise levels used.
    signatures : tuple of Signature
        Evidence in the nominal residual, strongest first.
    segments : tuple of Segment
        How the trace was split.
    isolated : bool
        Whether the isolated plant was modelled.
    threshold : float
        Score a candidate needs to be chosen.
    n_points : int
        Entries of the residual vector.
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
    """

    effect: str
    parameters: dict
    uncertainty: dict
    effects: tuple
    entries: tuple
    candidates: tuple
    rounds: tuple
    ambiguous: tuple
    skipped: dict
    gaps: tuple
    noise: NoiseLevels
    signatures: tuple
    segments: tuple
    isolated: bool
    threshold: float
    n_points: int
    chi2_nominal: float
    chi2_corrected: float
    conclusion: str
    n_simulations: int
    wall_time: float
    measurement: Measurement = field(repr=False)
    nominal: ModelTrace = field(repr=False)
    corrected: ModelTrace = field(repr=False)
    spec: Any = field(repr=False)

    @property
    def gap_before(self) -> dict:
        """Gap of the nominal model per metric (name to value, units in :attr:`gaps`)."""
        return {g.name: g.before for g in self.gaps}

    @property
    def gap_after(self) -> dict:
        """Gap of the corrected model per metric (same keys as :attr:`gap_before`)."""
        return {g.name: g.after for g in self.gaps}

    def corrected_spec(self):
        """The spec with the chosen effects in its ``effects`` list (a new Spec)."""
        return spec_with_entries(self.spec, self.entries)

    def to_dict(self) -> dict:
        """Plain JSON data: the contract keys first, then the details (SI)."""
        from . import __version__
        from .provenance import current_source

        d = {
            "effect": self.effect,
            "parameters": to_jsonable(self.parameters),
            "uncertainty": to_jsonable(self.uncertainty),
            "effects": list(self.effects),
            "entries": to_jsonable(self.entries),
            "candidates": [c.to_dict() for c in self.candidates],
            "gap_before": to_jsonable(self.gap_before),
            "gap_after": to_jsonable(self.gap_after),
            "noise": self.noise.to_dict(),
            "ambiguous": list(self.ambiguous),
            "skipped": dict(self.skipped),
            "gaps": [g.to_dict() for g in self.gaps],
            "units": {g.name: g.unit for g in self.gaps},
            "signatures": [s.to_dict() for s in self.signatures],
            "segments": [s.to_dict() for s in self.segments],
            "rounds": [r.to_dict() for r in self.rounds],
            "isolated": self.isolated,
            "threshold": self.threshold,
            "n_points": self.n_points,
            "chi2_nominal": to_jsonable(self.chi2_nominal),
            "chi2_corrected": to_jsonable(self.chi2_corrected),
            "conclusion": self.conclusion,
            "n_simulations": self.n_simulations,
            "wall_time": self.wall_time,
            "fi_design_version": __version__,
            "fi_design_source": current_source().to_dict(),
            "measurement": self.measurement.to_dict(),
        }
        return d


# --------------------------------------------------------------------------- entries


def make_entry(name: str, values: dict):
    """A validated spec ``effects`` entry (the model of ``spec.EFFECT_MODELS``) from SI values."""
    return _spec.EFFECT_MODELS[name].model_validate(entry_input(name, values))


def entry_input(name: str, values: dict) -> dict:
    """The spec-file form of an effect entry: SI numbers, angles as ``"<value> rad"``.

    Angles need their unit in a spec (a bare number is ambiguous), so phases are
    written with ``rad``; every other value is a plain SI float.
    """
    eff = _effects.get(name)
    out: dict = {"type": name}
    for k, v in values.items():
        if v is None:
            continue
        unit = eff.parameter(k).unit
        out[k] = f"{float(v)!r} rad" if unit == "rad" else float(v)
    return out


def spec_with_entries(spec, entries):
    """A copy of ``spec`` with effect entries added (an entry of the same type is replaced).

    Parameters
    ----------
    spec : Spec
        The spec.
    entries : sequence of dict
        ``{"type": name, param: value, ...}`` in SI.

    Returns
    -------
    Spec
        The entries are validated; the rest of the spec is shared.
    """
    new = [make_entry(e["type"], {k: v for k, v in e.items() if k != "type"}) for e in entries]
    names = {e.type for e in new}
    kept = [e for e in spec.effects if e.type not in names]
    if "joint_damping" in names and spec.isolator is None:
        raise SimulationError("effect joint_damping needs an isolator")
    return spec.model_copy(update={"effects": tuple(kept + new)})


# --------------------------------------------------------------------------- noise


def estimate_noise(values: np.ndarray) -> float:
    """Robust white-noise standard deviation of a sampled signal.

    The median absolute deviation of the third differences (which remove
    polynomials up to second order, i.e. the smooth motion), scaled to a
    standard deviation (1.4826 MAD) and divided by sqrt(20), the gain of the
    third-difference filter on white noise. Sparse jumps (slips, quantization
    steps) do not move the median.

    Parameters
    ----------
    values : ndarray, shape (n,)
        The signal, n >= 4.

    Returns
    -------
    float
        Standard deviation, in the unit of ``values``.
    """
    d = np.diff(np.asarray(values, dtype=float), n=3)
    if len(d) == 0:
        return 0.0
    mad = float(np.median(np.abs(d - np.median(d))))
    return 1.4826 * mad / math.sqrt(20.0)


def sawtooth(x: np.ndarray, q: float) -> np.ndarray:
    """Quantization error round(x / q) q - x of positions x for a step q [m]."""
    return np.round(x / q) * q - x


def quantization_step(x_model: np.ndarray, residual: np.ndarray, noise: float,
                      lo: float = 1e-8, hi: float = 1e-4) -> tuple[float | None, float]:
    """The step of a staircase in the measured position, from the residual to a smooth model.

    When the sensor quantizes, measured minus modelled position is the
    quantization error round(x / q) q - x: a sawtooth over position with
    spatial period q. Its fundamental is found in the power spectrum of the
    residual over the modelled position (binned at an eighth of the smallest
    step and Fourier transformed; this works through the
    aliasing of a regularly sampled constant-velocity move, where a test of the
    raw samples would find the sampling pitch v dt instead), then refined by
    the correlation of the residual with the sawtooth predicted for q.

    Parameters
    ----------
    x_model : ndarray, shape (n,)
        Modelled (continuous) position at the samples [m].
    residual : ndarray, shape (n,)
        Measured minus modelled position [m].
    noise : float
        Position noise standard deviation [m]; steps below three noise levels
        are not tried.
    lo, hi : float
        Range of steps tried [m].

    Returns
    -------
    step : float or None
        The step [m], or None when the residual does not follow a sawtooth
        (correlation below 0.3).
    correlation : float
        Correlation of the residual with the sawtooth of the step (0-1).
    """
    x = np.asarray(x_model, dtype=float)
    r = np.asarray(residual, dtype=float)
    if len(x) < 50:
        return None, 0.0
    span = float(np.ptp(x))
    bottom = max(lo, 3.0 * noise)
    top = min(hi, span / 20.0)
    if not top > bottom:
        return None, 0.0
    rc = r - np.mean(r)
    b = max(bottom / 8.0, span / 2 ** 21)
    idx = np.floor((x - x.min()) / b).astype(np.int64)
    m = 1 << int(math.ceil(math.log2(2 * (int(idx.max()) + 1))))
    series = np.bincount(idx, weights=rc, minlength=m)
    power = np.abs(np.fft.rfft(series)) ** 2
    freq = np.arange(len(power)) / (m * b)  # cycles per metre
    band = np.nonzero((freq >= 1.0 / top) & (freq <= 1.0 / bottom))[0]
    if len(band) == 0:
        return None, 0.0
    best_q, best_c = None, 0.0
    df = 1.0 / (m * b)
    for j in band[np.argsort(power[band])[::-1][:5]]:
        q0 = 1.0 / freq[j]
        dq = df / freq[j] * q0  # one frequency bin, as a step change
        for q in np.linspace(q0 - 1.5 * dq, q0 + 1.5 * dq, 31):
            s = sawtooth(x, q)
            if np.std(s) == 0:
                continue
            c = float(np.corrcoef(s, r)[0, 1])
            if c > best_c:
                best_q, best_c = float(q), c
    if best_q is None or best_c < 0.3:
        return None, max(best_c, 0.0)
    return best_q, best_c


# --------------------------------------------------------------------------- the problem


@dataclass
class _Trace:
    position: np.ndarray
    force: np.ndarray
    deflection: np.ndarray | None
    success: bool
    message: str


class _Problem:
    """Measured data, segments, weights and the model runner (internal)."""

    def __init__(self, spec, meas: Measurement, isolated: bool, settle_window: float | None,
                 base_entries: list, noise: NoiseLevels) -> None:
        self.noise = noise
        self.spec = spec
        self.meas = meas
        self.iso = isolated
        self.t = np.asarray(meas.time - meas.time[0], dtype=float)
        self.n = len(self.t)
        self.duration = float(self.t[-1])
        if self.duration <= 0:
            raise DataError("the trace has no duration", column="time_s", source=meas.source)
        self.ref = from_samples(self.t, meas.reference)
        rate = 1.0 / float(np.median(np.diff(self.t)))
        self.spec_sim = spec.model_copy(update={
            "simulation": spec.simulation.model_copy(update={"output_rate": rate})})
        self.t_model = np.arange(int(math.floor(self.duration * rate + 1e-9)) + 1) / rate
        self.aligned = (len(self.t_model) == self.n
                        and np.allclose(self.t_model, self.t, rtol=0, atol=1e-6 / rate))
        self.base_entries = list(base_entries)
        self.n_sims = 0
        self.has_force = meas.force is not None
        self.has_defl = meas.deflection is not None and isolated
        self._segments(settle_window)
        self.x0 = self._initial_position()
        self.rtol = model_tolerance(spec, noise)

    # ---- model runs

    def _initial_position(self) -> float:
        """Start at rest: at the reference, unless the first samples say otherwise.

        The median measured position over the leading samples in which the
        reference has moved by less than the position noise (at most 200) is
        used when it differs from the reference by more than three standard
        errors; otherwise the stage starts exactly at the reference (its noise
        would otherwise start the model with a spurious error).
        """
        r = self.meas.reference
        sigma = self.noise.position
        moved = np.nonzero(np.abs(r - r[0]) > sigma)[0]
        k = int(moved[0]) if len(moved) else self.n
        k = max(1, min(k, 200))
        m = float(np.median(self.meas.position[:k]))
        if abs(m - r[0]) <= 3.0 * sigma / math.sqrt(k):
            return float(r[0])
        return m

    def run(self, entries, quantize: float | None = None) -> _Trace:
        """Simulate with effect entries (model objects) and sample at the measured times."""
        self.n_sims += 1
        res = simulate(self.spec_sim, self.iso, reference=self.ref, initial_position=self.x0,
                       duration=self.duration, effects=list(entries), rtol=self.rtol)
        return self.sample(res, quantize)

    def sample(self, res: SimulationResult, quantize: float | None) -> _Trace:
        if self.aligned and len(res.position) == self.n:
            x, u = np.asarray(res.position), np.asarray(res.force)
            d = np.asarray(res.deflection) if self.iso else None
        else:
            tm = np.asarray(res.time)
            x = np.interp(self.t, tm, res.position)
            u = np.interp(self.t, tm, res.force)
            d = np.interp(self.t, tm, res.deflection) if self.iso else None
        if quantize:
            x = np.round(x / quantize) * quantize
        ok = bool(res.success and np.all(np.isfinite(x)) and np.all(np.isfinite(u)))
        return _Trace(x, u, d, ok, res.message)

    # ---- segments

    def _segments(self, settle_window: float | None) -> None:
        t = self.t
        v = np.asarray(self.ref(t, 1))
        self.v_ref = v
        self.a_ref = np.asarray(self.ref(t, 2))
        vmax = float(np.max(np.abs(v))) if len(v) else 0.0
        moving = np.abs(v) > 1e-3 * vmax if vmax > 0 else np.zeros(self.n, bool)
        runs = _runs(moving)
        merged: list[list[int]] = []
        gap = 0.02
        for i0, i1 in runs:
            if merged and t[i0] - t[merged[-1][1] - 1] < gap:
                merged[-1][1] = i1
            else:
                merged.append([i0, i1])
        self.moves = [(i0, i1) for i0, i1 in merged if i1 - i0 >= 2]
        ctl = self.spec.controller
        if settle_window is None:
            ri = ctl.integrator_ratio if math.isfinite(ctl.integrator_ratio) else 1.0
            settle_window = 5.0 * ri / (2.0 * math.pi * _spec.design_crossover(self.spec))
        self.settle_window = float(settle_window)
        kind = np.full(self.n, "hold", dtype=object)
        for k, (i0, i1) in enumerate(self.moves):
            kind[i0:i1] = "move"
            nxt = self.moves[k + 1][0] if k + 1 < len(self.moves) else self.n
            j = int(np.searchsorted(t, t[i1 - 1] + self.settle_window, side="right"))
            kind[i1:min(j, nxt)] = "settle"
        self.kind = kind
        self.holds = [(i0, i1) for i0, i1 in _runs(kind == "hold")]
        self.last_move_end = float(t[self.moves[-1][1] - 1]) if self.moves else 0.0
        r = self.meas.reference
        self.travel_center = float(0.5 * (np.max(r) + np.min(r)))

    def finish_setup(self, nominal: _Trace, max_points: int) -> None:
        """Decide coherent/incoherent holds, the strided samples and the features' scales."""
        noise = self.noise
        band = max(10.0 * noise.position, self.spec.requirements.hunting.settle_band)
        self.band = band
        e_meas = self.meas.position - self.meas.reference
        e_nom = nominal.position - self.meas.reference
        coherent = np.ones(self.n, bool)
        self.feature_segments: list[tuple[int, int]] = []
        for i0, i1 in self.holds:
            if i1 - i0 < 20:
                continue
            if (_reversals(e_meas[i0:i1], band) >= 3 or _reversals(e_nom[i0:i1], band) >= 3):
                coherent[i0:i1] = False
                self.feature_segments.append((i0, i1))
        self.coherent = coherent
        idx = np.nonzero(coherent)[0]
        stride = max(1, int(math.ceil(len(idx) / max_points)))
        self.idx = idx[::stride]
        self.stride = stride
        channels = 1 + int(self.has_force) + int(self.has_defl)
        in_move = np.asarray(self.kind[self.idx] == "move")
        nf = self.n_points - channels * len(self.idx)
        self.move_entries = np.concatenate([np.tile(in_move, channels), np.zeros(nf, bool)])
        # feature scales from the measurement
        self.feat_meas = []
        self.feat_sigma = []
        for i0, i1 in self.feature_segments:
            f = self._features(self.meas.position, self.meas.force, self.meas.deflection, i0, i1)
            chunks = np.array_split(np.arange(i0, i1), 4)
            fc = np.array([self._features(self.meas.position, self.meas.force,
                                          self.meas.deflection, c[0], c[-1] + 1) for c in chunks])
            spread = np.std(fc, axis=0, ddof=1) / 2.0
            floor = self._feature_noise(i0, i1)
            sig = np.sqrt(spread ** 2 + (0.05 * np.abs(f)) ** 2 + floor ** 2)
            self.feat_meas.append(f)
            self.feat_sigma.append(sig)

    def _feature_noise(self, i0: int, i1: int) -> np.ndarray:
        nz = self.noise
        dur = self.t[i1 - 1] - self.t[i0]
        out = [nz.position, nz.position, 1.0 / max(dur, 1e-3)]
        if self.has_force:
            out += [nz.force, nz.force]
        if self.has_defl:
            out += [nz.deflection, nz.deflection]
        return np.array(out)

    def _features(self, x, u, d, i0: int, i1: int) -> np.ndarray:
        e = x[i0:i1] - self.meas.reference[i0:i1]
        dur = max(self.t[i1 - 1] - self.t[i0], 1e-3)
        out = [float(np.mean(e)), float(np.std(e)), _reversals(e, self.band) / dur]
        if self.has_force:
            out += [float(np.mean(u[i0:i1])), float(np.std(u[i0:i1]))]
        if self.has_defl:
            out += [float(np.mean(d[i0:i1])), float(np.std(d[i0:i1]))]
        return np.array(out)

    # ---- residuals

    def residuals(self, tr: _Trace) -> np.ndarray:
        """The weighted residual vector of a model trace [noise units]."""
        n_total = self.n_points
        if not tr.success:
            return np.full(n_total, FAIL_RESIDUAL)
        i = self.idx
        parts = [(tr.position[i] - self.meas.position[i]) / self.noise.position]
        if self.has_force:
            parts.append((tr.force[i] - self.meas.force[i]) / self.noise.force)
        if self.has_defl:
            parts.append((tr.deflection[i] - self.meas.deflection[i]) / self.noise.deflection)
        for (i0, i1), fm, fs in zip(self.feature_segments, self.feat_meas, self.feat_sigma):
            parts.append((self._features(tr.position, tr.force, tr.deflection, i0, i1) - fm) / fs)
        r = np.concatenate(parts)
        if not np.all(np.isfinite(r)):
            return np.full(n_total, FAIL_RESIDUAL)
        return r

    @property
    def n_points(self) -> int:
        k = 1 + int(self.has_force) + int(self.has_defl)
        nf = 3 + 2 * int(self.has_force) + 2 * int(self.has_defl)
        return k * len(self.idx) + nf * len(self.feature_segments)

    def segment_list(self) -> tuple[Segment, ...]:
        out = []
        for i0, i1 in _runs_labels(self.kind):
            kind = self.kind[i0]
            coh = bool(self.coherent[i0])
            out.append(Segment(kind=str(kind), start=float(self.t[i0]),
                               end=float(self.t[i1 - 1]), coherent=coh))
        return tuple(out)


def model_tolerance(spec, noise: NoiseLevels) -> float:
    """Relative tolerance of the reconciliation's simulations.

    The integrator's absolute position tolerance is ``rtol`` times 1 mm
    (:func:`fi_design.simulation.tolerances`). Integration errors of the size of
    a fraction of the sensor noise, summed over thousands of samples, would
    otherwise let a fit "explain" numerical jitter: the tolerance is set so
    that the position tolerance is a hundredth of the smallest position or
    deflection noise (at most the spec's ``simulation.tolerance``, at least
    1e-9).
    """
    sig = min(v for v in (noise.position, noise.deflection) if v is not None)
    return float(min(spec.simulation.tolerance, max(1e-9, sig / 100.0 / 1e-3)))


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """Half-open index ranges where ``mask`` is true."""
    m = np.concatenate([[False], np.asarray(mask, bool), [False]])
    d = np.diff(m.astype(int))
    starts = np.nonzero(d == 1)[0]
    ends = np.nonzero(d == -1)[0]
    return [(int(a), int(b)) for a, b in zip(starts, ends)]


def _runs_labels(labels: np.ndarray) -> list[tuple[int, int]]:
    out = []
    i0 = 0
    for i in range(1, len(labels) + 1):
        if i == len(labels) or labels[i] != labels[i0]:
            out.append((i0, i))
            i0 = i
    return out


def _reversals(e: np.ndarray, band: float) -> int:
    """Direction reversals of ``e`` by more than ``band`` (a zig-zag count)."""
    if len(e) < 2:
        return 0
    count = 0
    direction = 0
    ext = e[0]
    for v in e[1:] if len(e) < 4000 else e[1::max(1, len(e) // 4000)]:
        if direction >= 0:
            if v > ext:
                ext = v
            elif ext - v > band:
                if direction > 0:
                    count += 1
                direction = -1
                ext = v
        if direction < 0:
            if v < ext:
                ext = v
            elif v - ext > band:
                count += 1
                direction = 1
                ext = v
        if direction == 0:
            pass
    return count


# --------------------------------------------------------------------------- signatures


def _fit_line(y: np.ndarray, x: np.ndarray) -> tuple[float, float, float]:
    """Least-squares y = a + b x; returns (a, b, R^2)."""
    if len(y) < 5 or np.ptp(x) == 0:
        return 0.0, 0.0, 0.0
    A = np.column_stack([np.ones_like(x), x])
    coef, *_ = np.linalg.lstsq(A, y, rcond=None)
    fit = A @ coef
    ss = float(np.sum((y - np.mean(y)) ** 2))
    r2 = 1.0 - float(np.sum((y - fit) ** 2)) / ss if ss > 0 else 0.0
    return float(coef[0]), float(coef[1]), max(0.0, r2)


def _spatial_periods(x: np.ndarray, y: np.ndarray, lo: float, hi: float,
                     n_peaks: int = 3) -> list[tuple[float, float, float]]:
    """Peaks of a Lomb-Scargle periodogram of y over position x.

    Returns a list of ``(wavelength [m], amplitude [unit of y], power ratio)``,
    strongest first; the ratio is the peak power over the median power.
    """
    from scipy.signal import lombscargle

    if len(x) < 50 or np.ptp(x) < 2 * lo:
        return []
    span = float(np.ptp(x))
    hi = min(hi, span / 1.5)
    if hi <= lo:
        return []
    n_f = int(min(20000, max(500, 8 * span / lo)))
    k = np.linspace(2 * np.pi / hi, 2 * np.pi / lo, n_f)
    yc = y - np.mean(y)
    # detrend linearly in x so a cable-like slope does not leak into long periods
    a, b, _ = _fit_line(yc, x)
    yc = yc - (a + b * x)
    if len(x) > 6000:
        sel = np.linspace(0, len(x) - 1, 6000).astype(int)
        x, yc = x[sel], yc[sel]
    p = lombscargle(x, yc, k)
    med = float(np.median(p)) or 1e-300
    out = []
    order = np.argsort(p)[::-1]
    taken: list[float] = []
    for j in order:
        lam = 2 * np.pi / k[j]
        if any(abs(lam - t) / t < 0.05 for t in taken):
            continue
        amp = math.sqrt(4.0 * p[j] / len(x))
        taken.append(lam)
        out.append((float(lam), float(amp), float(p[j] / med)))
        if len(out) >= n_peaks:
            break
    return out


def _signatures(pb: _Problem, nom: _Trace) -> tuple[list[Signature], dict]:
    """Signatures in the nominal residual and the starting guesses they imply."""
    meas = pb.meas
    sigs: list[Signature] = []
    guesses: dict[str, list[dict]] = {}
    use_force = pb.has_force
    res = (meas.force - nom.force) if use_force else (meas.position - nom.position)
    unit = "N" if use_force else "m"
    coh = pb.coherent
    move = (pb.kind == "move") & coh
    v = pb.v_ref
    x = meas.position
    fr = pb.spec.friction
    quant = unit

    def add(name, effects, r2, value, vunit, detail):
        sigs.append(Signature(name, tuple(effects), float(r2), value, vunit, detail))

    if move.sum() > 20:
        a, b, r2 = _fit_line(res[move], v[move])
        add("velocity", ["viscous_friction"], r2, b, f"{quant}/(m/s)",
            f"the {'force' if use_force else 'position'} residual follows the velocity during "
            f"moves (slope {b:.3g} {quant} s/m, R^2 {r2:.2f})")
        if use_force:
            guesses.setdefault("viscous_friction", []).append(
                {"viscous": fr.viscous + b})
        vs = fr.stribeck_velocity
        bump = np.sign(v) * np.exp(-(v / (3 * vs)) ** 2)
        sl = (pb.kind != "hold") & coh
        a2, b2, r22 = _fit_line(res[sl], bump[sl])
        add("low_velocity", ["stribeck_velocity"], r22, b2, quant,
            f"the residual concentrates at low speed (amplitude {b2:.3g} {quant}, R^2 {r22:.2f})")
        a3, b3, r23 = _fit_line(res[sl], pb.a_ref[sl])
        add("acceleration", ["mass_error"], r23, b3, f"{quant}/(m/s^2)",
            f"the residual follows the reference acceleration (slope {b3:.3g}, R^2 {r23:.2f})")
        if use_force:
            m1, m2 = pb.spec.stage.mass, pb.spec.cart.mass
            f = 1.0 + b3 / (m1 + m2)
            guesses.setdefault("mass_error", []).append({"stage_mass": m1 * f, "cart_mass": m2 * f})
        # spatial period
        fast = move & (np.abs(v) > 0.2 * np.max(np.abs(v)))
        peaks = _spatial_periods(x[fast], res[fast], 2e-4, 0.05, n_peaks=5)
        pb.periods = peaks
        if peaks:
            lam, amp, ratio = peaks[0]
            strength = min(1.0, amp ** 2 / 2 / max(np.var(res[fast]), 1e-300))
            add("spatial_period", ["position_dependent_friction", "force_ripple"], strength, lam,
                "m", f"the residual repeats along the travel with a period of {lam * 1e3:.4g} mm "
                     f"(amplitude {amp:.3g} {quant}, {ratio:.0f} x the median spectral power)")
    else:
        pb.periods = []
    # position trend (cable)
    sl = coh
    a4, b4, r24 = _fit_line(res[sl], x[sl] - pb.x0)
    add("position_trend", ["cable_force"], r24, b4, f"{quant}/m",
        f"the residual grows with position (slope {b4:.3g} {quant}/m, R^2 {r24:.2f})")
    if use_force:
        guesses.setdefault("cable_force", []).append({"stiffness": b4, "preload": a4})
    # lag between measured and modelled force
    if use_force and move.sum() > 50:
        lag, corr = _lag(meas.force, nom.force, pb.t, max_lag=0.02)
        add("force_lag", ["time_delay"], corr if lag > 0 else 0.0, lag, "s",
            f"the measured force lags the modelled one by {lag * 1e3:.3g} ms "
            f"(correlation {corr:.2f})")
        if lag > 0:
            guesses.setdefault("time_delay", []).append({"delay": lag})
    # staircase: the residual to the smooth model is a sawtooth over position
    sel = (pb.kind != "hold") & coh
    q, corr_q = quantization_step(nom.position[sel], (meas.position - nom.position)[sel],
                                  pb.noise.position)
    if q is not None:
        pb.noise = replace(pb.noise, resolution=q)
        add("staircase", ["quantization"], corr_q, q, "m",
            f"the measured position lies on a lattice of {q * 1e6:.4g} um steps (the residual "
            f"follows the quantization sawtooth with correlation {corr_q:.2f})")
        guesses.setdefault("quantization", []).append({"resolution": q})
    # force above a level (saturation)
    if use_force:
        umax = float(np.max(np.abs(meas.force)))
        best = (0.0, None)
        for level in np.quantile(np.abs(meas.force), [0.5, 0.7, 0.8, 0.9, 0.95, 0.98]):
            g = np.sign(meas.force) * np.maximum(np.abs(meas.force) - level, 0.0)
            if np.ptp(g) == 0:
                continue
            _, _, r2 = _fit_line(res[coh], g[coh])
            if r2 > best[0]:
                best = (r2, float(level))
        if best[1] is not None:
            add("force_above_level", ["force_saturation"], best[0], best[1], "N",
                f"the residual appears where |force| exceeds {best[1]:.3g} N "
                f"(peak {umax:.3g} N, R^2 {best[0]:.2f})")
            guesses.setdefault("force_saturation", []).append({"limit": best[1]})
    # deflection dynamics
    if pb.has_defl:
        dres = meas.deflection - nom.deflection
        dd = np.gradient(_smooth(meas.deflection, 11), pb.t)
        a5, b5, r25 = _fit_line(dres[coh], dd[coh])
        add("deflection_rate", ["joint_damping"], r25, b5, "s",
            f"the deflection residual follows the deflection rate (R^2 {r25:.2f})")
    sigs.sort(key=lambda s: -s.strength)
    return sigs, guesses


def _smooth(y: np.ndarray, n: int) -> np.ndarray:
    if len(y) < n:
        return np.asarray(y, float)
    k = np.ones(n) / n
    return np.convolve(np.pad(y, n // 2, mode="edge"), k, mode="valid")


def _lag(a: np.ndarray, b: np.ndarray, t: np.ndarray, max_lag: float) -> tuple[float, float]:
    """Lag of a behind b [s] maximising the correlation of their changes, and the correlation."""
    dt = float(np.median(np.diff(t)))
    da = np.diff(a)
    db = np.diff(b)
    m = int(max_lag / dt)
    best = (0.0, -1.0)
    sa = np.std(da)
    sb = np.std(db)
    if sa == 0 or sb == 0 or len(da) < 4 * m + 10:
        return 0.0, 0.0
    for k in range(0, m + 1):
        c = float(np.mean((da[k:] - da[k:].mean()) * (db[:len(db) - k] - db[:len(db) - k].mean()))
                  / (sa * sb))
        if c > best[1]:
            best = (k * dt, c)
    return best[0], max(0.0, best[1])


# --------------------------------------------------------------------------- candidate spaces


@dataclass
class _Coord:
    """One fitted coordinate u in [0, 1] mapped to an SI value."""

    name: str
    lo: float
    hi: float
    log: bool = False
    periodic: bool = False

    def value(self, u: float) -> float:
        if self.log:
            return float(self.lo * (self.hi / self.lo) ** u)
        return float(self.lo + (self.hi - self.lo) * u)

    def u_of(self, value: float) -> float:
        if self.log:
            value = min(max(value, self.lo), self.hi)
            return float(math.log(value / self.lo) / math.log(self.hi / self.lo))
        return float(min(max((value - self.lo) / (self.hi - self.lo), 0.0), 1.0))

    @property
    def step(self) -> float:
        """Finite-difference step in u (about 1e-3 relative in the value)."""
        if self.log:
            return 1e-3 / math.log(self.hi / self.lo)
        return 1e-3


@dataclass
class _Space:
    name: str
    coords: list
    build: Callable[[dict], dict]
    method: str = "ls"
    starts: list = field(default_factory=list)
    quantize: bool = False
    guess_u: list = field(default_factory=list)


def _spaces(pb: _Problem, guesses: dict, names: list[str]) -> tuple[list[_Space], dict]:
    spec = pb.spec
    skipped: dict[str, str] = {}
    spaces = []
    umax = float(np.max(np.abs(pb.meas.force))) if pb.has_force else None
    for name in names:
        eff = _effects.get(name)
        if name == "joint_damping" and not pb.iso:
            skipped[name] = "not applicable: the stage has no isolator (no joint)"
            continue
        coords: list[_Coord] = []
        method = "ls"
        build: Callable[[dict], dict]
        if name == "mass_error":
            m1, m2 = spec.stage.mass, spec.cart.mass
            p = eff.parameter("stage_mass")
            if pb.iso:
                coords = [_Coord("stage_mass", m1 * p.bounds[0], m1 * p.bounds[1], log=True),
                          _Coord("cart_mass", m2 * p.bounds[0], m2 * p.bounds[1], log=True)]
                build = lambda v: dict(v)  # noqa: E731
            else:
                coords = [_Coord("scale", p.bounds[0], p.bounds[1], log=True)]
                build = lambda v, m1=m1, m2=m2: {"stage_mass": m1 * v["scale"],  # noqa: E731
                                                 "cart_mass": m2 * v["scale"]}
        elif name in ("position_dependent_friction", "force_ripple"):
            # The phase is fitted at the middle of the travel, x_c, where it does not
            # trade off against the period (the phase at x = 0 does, by 2 pi x_c / period).
            method = "periodic"
            amp, per, _ = eff.parameters
            coords = [_Coord(amp.name, amp.bounds[0], amp.bounds[1], log=amp.log),
                      _Coord(per.name, per.bounds[0], per.bounds[1], log=per.log),
                      _Coord("phase_center", -2 * math.pi, 2 * math.pi, periodic=True)]
            xc = pb.travel_center

            def build(v, per=per.name, xc=xc):
                phase = v["phase_center"] - 2 * math.pi * xc / v[per]
                phase = float((phase + math.pi) % (2 * math.pi) - math.pi)
                return {"amplitude": v["amplitude"], per: v[per], "phase": phase}
        elif name == "time_delay":
            lo = max(2e-4, 0.02 / (2 * math.pi * _spec.design_crossover(spec)))
            p = eff.parameters[0]
            coords = [_Coord("delay", lo, p.bounds[1], log=True)]
            build = lambda v: dict(v)  # noqa: E731
        elif name == "quantization":
            method = "scan"
            travel = float(np.ptp(pb.meas.reference)) or float(np.ptp(pb.meas.position))
            p = eff.parameters[0]
            lo = max(p.bounds[0], pb.noise.position / 2.0, travel / 2e4)
            hi = min(p.bounds[1], max(travel / 20.0, 2 * lo))
            if not hi > lo:
                skipped[name] = "not identifiable: the travel is too short for any step"
                continue
            coords = [_Coord("resolution", lo, hi, log=True)]
            build = lambda v: dict(v)  # noqa: E731
        elif name == "force_saturation":
            p = eff.parameters[0]
            peak = umax if umax is not None else None
            if peak is None:
                peak = float(np.max(np.abs(pb.nominal_force)))
            lo = p.bounds[0]
            hi = min(p.bounds[1], 1.05 * peak)
            if not hi > lo:
                skipped[name] = "not identifiable: the force stays too small"
                continue
            coords = [_Coord("limit", lo, hi, log=True)]
            build = lambda v: dict(v)  # noqa: E731
        else:
            for p in eff.parameters:
                lo, hi = p.bounds
                coords.append(_Coord(p.name, lo, hi, log=p.log))
            build = lambda v: dict(v)  # noqa: E731
        sp = _Space(name, coords, build, method, quantize=(name == "quantization"))
        sp.starts = _starts(sp, pb, guesses.get(name, []))
        if len(coords) == 1:
            sp.guess_u = [coords[0].u_of(g[coords[0].name]) for g in guesses.get(name, [])
                          if g.get(coords[0].name) is not None]
        spaces.append(sp)
    return spaces, skipped


def _nominal_value(pb: _Problem, name: str, par: str) -> float | None:
    spec = pb.spec
    table = {("viscous_friction", "viscous"): spec.friction.viscous,
             ("stribeck_velocity", "stribeck_velocity"): spec.friction.stribeck_velocity}
    if name == "joint_damping" and spec.isolator is not None:
        return _spec.joint_damping(spec)
    return table.get((name, par))


def _starts(sp: _Space, pb: _Problem, guesses: list[dict]) -> list[np.ndarray]:
    """Grid of starting points in u plus the signature guesses."""
    k = len(sp.coords)
    starts: list[np.ndarray] = []
    for g in guesses:
        vals = {c.name: g.get(c.name) for c in sp.coords}
        if sp.name == "mass_error" and not pb.iso and "stage_mass" in g:
            vals = {"scale": g["stage_mass"] / pb.spec.stage.mass}
        if all(v is not None and math.isfinite(v) for v in vals.values()):
            starts.append(np.array([c.u_of(vals[c.name]) for c in sp.coords]))
    if sp.method == "periodic":
        return starts
    if k == 1:
        c = sp.coords[0]
        grid = list(np.linspace(0.02, 0.98, 9))
        nom = _nominal_value(pb, sp.name, c.name)
        if nom is not None:
            grid += [c.u_of(nom * f) for f in (0.5, 0.8, 1.25, 2.0)]
        starts += [np.array([u]) for u in grid]
    else:
        if sp.name == "cable_force":
            ks = [0.5, 0.35, 0.65, 0.45, 0.55]
            fs = [0.5, 0.4, 0.6, 0.47, 0.53]
            starts += [np.array([a, b]) for a in ks for b in fs]
        else:
            g = np.linspace(0.1, 0.9, 5)
            starts += [np.array([a, b]) for a in g for b in g]
            if sp.name == "mass_error":
                starts.append(np.array([c.u_of(v) for c, v in zip(
                    sp.coords, (pb.spec.stage.mass, pb.spec.cart.mass))]))
    return starts


# --------------------------------------------------------------------------- fitting


class _Objective:
    """Residuals of one candidate as a function of u, with a cache."""

    def __init__(self, pb: _Problem, sp: _Space, base_entries: list) -> None:
        self.pb = pb
        self.sp = sp
        self.base = [e for e in base_entries if e.type != sp.name]
        self.cache: dict[tuple, np.ndarray] = {}
        self.n_sims = 0
        self.n_ok = 0

    def values(self, u: np.ndarray) -> dict:
        v = {c.name: c.value(float(x)) for c, x in zip(self.sp.coords, u)}
        return self.sp.build(v)

    def value_jacobian(self, u: np.ndarray) -> tuple[list[str], np.ndarray]:
        """d(parameter)/du by central differences of the mapping (phases unwrapped)."""
        base = self.values(u)
        names = list(base)
        G = np.zeros((len(names), len(u)))
        for j in range(len(u)):
            h = 1e-6
            up = np.array(u, float)
            dn = np.array(u, float)
            up[j] = min(up[j] + h, 1.0)
            dn[j] = max(dn[j] - h, 0.0)
            a, b = self.values(up), self.values(dn)
            for i, k in enumerate(names):
                d = a[k] - b[k]
                if k == "phase":
                    d = (d + math.pi) % (2 * math.pi) - math.pi
                G[i, j] = d / (up[j] - dn[j])
        return names, G

    def __call__(self, u: np.ndarray) -> np.ndarray:
        key = tuple(np.round(np.asarray(u, float), 12))
        hit = self.cache.get(key)
        if hit is not None:
            return hit
        vals = self.values(u)
        # values lie inside the catalogue bounds: build the entry without re-validating
        entry = _spec.EFFECT_MODELS[self.sp.name].model_construct(type=self.sp.name, **vals)
        self.n_sims += 1
        tr = self.pb.run(self.base + [entry],
                         quantize=vals["resolution"] if self.sp.quantize else None)
        self.n_ok += int(tr.success)
        r = self.pb.residuals(tr)
        self.cache[key] = r
        return r

    def chi2(self, u) -> float:
        r = self(u)
        return float(r @ r)

    def jac(self, u: np.ndarray) -> np.ndarray:
        r0 = self(u)
        J = np.empty((len(r0), len(u)))
        for j, c in enumerate(self.sp.coords):
            h = c.step
            up = np.array(u, float)
            if up[j] + h <= 1.0:
                up[j] += h
            else:
                up[j] -= h
                h = -h
            J[:, j] = (self(up) - r0) / h
        return J


def _fit(ob: _Objective) -> tuple[np.ndarray, float, np.ndarray | None, str]:
    """Best u, its chi2, the u-covariance (unscaled) and a note."""
    from scipy.optimize import least_squares

    sp = ob.sp
    starts = list(sp.starts)
    if sp.method == "periodic":
        starts += _periodic_starts(ob)
    if sp.method == "scan":
        return _scan(ob)
    # Stage A works on the move samples only (robust loss): stick-slip in the settle
    # and hold segments makes the full objective rugged, the moves keep it smooth.
    mask = ob.pb.move_entries
    staged = mask is not None and 0 < mask.sum() < len(mask)

    def sub(u):
        return ob(u)[mask]

    def sub_jac(u):
        return ob.jac(u)[mask]

    def score(u):
        r = sub(u) if staged else ob(u)
        return float(r @ r)

    scored = sorted(((score(u), i, u) for i, u in enumerate(starts)), key=lambda s: s[0])
    chosen: list[np.ndarray] = []
    for _, _, u in scored:
        if all(np.max(np.abs(u - c)) > 0.05 for c in chosen):
            chosen.append(u)
        if len(chosen) >= 2:
            break
    best = (math.inf, None, None)
    lo = np.zeros(len(sp.coords))
    hi = np.ones(len(sp.coords))
    for u0 in chosen:
        u0 = np.clip(u0, 1e-6, 1 - 1e-6)
        try:
            if staged:
                sol = least_squares(sub, u0, jac=sub_jac, bounds=(lo, hi), method="trf",
                                    loss="soft_l1", f_scale=3.0, x_scale=1.0, max_nfev=25,
                                    ftol=1e-6, xtol=1e-5, gtol=1e-8)
                u0 = np.clip(sol.x, 1e-6, 1 - 1e-6)
            sol = least_squares(ob, u0, jac=ob.jac, bounds=(lo, hi), method="trf",
                                x_scale=1.0, max_nfev=30, ftol=1e-6, xtol=1e-5, gtol=1e-8)
        except (ValueError, np.linalg.LinAlgError):
            continue
        c2 = float(sol.fun @ sol.fun)
        if c2 < best[0]:
            best = (c2, sol.x, sol.jac)
    if best[1] is None:
        u = scored[0][2]
        return u, scored[0][0], None, "the local fit failed; grid point reported"
    c2, u, J = best
    try:
        cov = np.linalg.pinv(J.T @ J)
    except np.linalg.LinAlgError:
        cov = None
    note = ""
    at = [c.name for c, x in zip(sp.coords, u) if (x < 1e-3 or x > 1 - 1e-3) and not c.periodic]
    if at:
        note = "at the search bound: " + ", ".join(at)
    return u, c2, cov, note


class _JointObjective:
    """Residuals of several effects fitted together (u concatenated)."""

    def __init__(self, pb: _Problem, spaces: list, base_entries: list) -> None:
        self.obs = [_Objective(pb, sp, []) for sp in spaces]
        names = {sp.name for sp in spaces}
        self.base = [e for e in base_entries if e.type not in names]
        self.pb = pb
        self.slices = []
        i = 0
        for sp in spaces:
            self.slices.append(slice(i, i + len(sp.coords)))
            i += len(sp.coords)
        self.coords = [c for sp in spaces for c in sp.coords]
        self.cache: dict[tuple, np.ndarray] = {}

    def parts(self, u: np.ndarray):
        out = []
        for ob, sl in zip(self.obs, self.slices):
            names, G = ob.value_jacobian(u[sl])
            out.append((ob.values(u[sl]), names, G, sl))
        return out

    def __call__(self, u: np.ndarray) -> np.ndarray:
        key = tuple(np.round(np.asarray(u, float), 12))
        if key in self.cache:
            return self.cache[key]
        entries = list(self.base)
        q = None
        for ob, sl in zip(self.obs, self.slices):
            vals = ob.values(u[sl])
            entries.append(_spec.EFFECT_MODELS[ob.sp.name].model_construct(type=ob.sp.name,
                                                                            **vals))
            if ob.sp.quantize:
                q = vals["resolution"]
        r = self.pb.residuals(self.pb.run(entries, quantize=q))
        self.cache[key] = r
        return r

    def jac(self, u: np.ndarray) -> np.ndarray:
        r0 = self(u)
        J = np.empty((len(r0), len(u)))
        for j, c in enumerate(self.coords):
            h = c.step
            up = np.array(u, float)
            if up[j] + h <= 1.0:
                up[j] += h
            else:
                up[j] -= h
                h = -h
            J[:, j] = (self(up) - r0) / h
        return J


def _joint_fit(jo: _JointObjective, u0: np.ndarray) -> tuple[float, np.ndarray, np.ndarray | None]:
    from scipy.optimize import least_squares

    u0 = np.clip(u0, 1e-6, 1 - 1e-6)
    try:
        sol = least_squares(jo, u0, jac=jo.jac, bounds=(np.zeros(len(u0)), np.ones(len(u0))),
                            method="trf", max_nfev=60, ftol=1e-6, xtol=1e-6, gtol=1e-8)
    except (ValueError, np.linalg.LinAlgError):
        r = jo(u0)
        return float(r @ r), u0, None
    return float(sol.fun @ sol.fun), sol.x, np.linalg.pinv(sol.jac.T @ sol.jac)


def _periodic_starts(ob: _Objective) -> list[np.ndarray]:
    """Starting points of a spatially periodic effect: periodogram peaks x phase grid."""
    pb, sp = ob.pb, ob.sp
    amp_c, lam_c, ph_c = sp.coords
    peaks = getattr(pb, "periods", []) or []
    peaks = [p for p in peaks if lam_c.lo <= p[0] <= lam_c.hi][:3]
    lams = [p[0] for p in peaks]
    amps = []
    for p in peaks:
        a = p[1]
        if not pb.has_force:
            a = None
        elif sp.name == "position_dependent_friction":
            a = a / max(pb.spec.friction.coulomb, 1e-9)
        amps.append(a)
    if not lams:
        lams = list(np.geomspace(lam_c.lo * 1.5, lam_c.hi / 1.5, 8))
        amps = [None] * len(lams)
    phases = np.linspace(-math.pi, math.pi, 12, endpoint=False)
    out = []
    for lam, a in zip(lams, amps):
        # the closed loop shapes the residual: the periodogram amplitude is only a scale
        alist = ([0.6 * a, a, 1.6 * a] if a is not None else
                 [amp_c.lo + f * (amp_c.hi - amp_c.lo) for f in (0.02, 0.06, 0.2)])
        for a_ in alist:
            for ph in phases:
                out.append(np.array([amp_c.u_of(min(a_, amp_c.hi)), lam_c.u_of(lam),
                                     ph_c.u_of(ph)]))  # ph: phase at the travel centre
    return out


def _scan(ob: _Objective) -> tuple[np.ndarray, float, np.ndarray | None, str]:
    """1-D nested scan (for staircase objectives such as the quantization step)."""
    # quantized simulations are slow (every level crossing is an event): a coarse
    # grid, plus a fine neighbourhood of a step the staircase signature measured
    grid = list(np.linspace(0.0, 1.0, 13 if not ob.sp.guess_u else 7))
    grid += [float(u[0]) for u in ob.sp.starts]
    c = ob.sp.coords[0]
    span = float(np.ptp(ob.pb.meas.position)) or 1.0
    for u in ob.sp.guess_u:
        # a lattice step is known to about q / travel: scan that neighbourhood finely
        q = c.value(u)
        du = math.log1p(0.25 * q / span) / math.log(c.hi / c.lo) if c.log else 0.25 * q / span
        grid += [min(max(u + k * du, 0.0), 1.0) for k in range(-4, 5)]
    vals = {u: ob.chi2(np.array([u])) for u in grid}
    width = 1.0 / 12 if not ob.sp.guess_u else 1.0 / 200
    best = min(vals, key=vals.get)
    for _ in range(2 if not ob.sp.guess_u else 1):
        fine = np.clip(np.linspace(best - width, best + width, 9), 0.0, 1.0)
        for u in fine:
            if float(u) not in vals:
                vals[float(u)] = ob.chi2(np.array([u]))
        best = min(vals, key=vals.get)
        width /= 4
    # curvature from the points around the best (Delta chi2 = 1 -> one sigma)
    us = np.array(sorted(vals))
    cs = np.array([vals[u] for u in us])
    near = np.argsort(np.abs(us - best))[:7]
    cov = None
    if len(near) >= 3:
        a = np.polyfit(us[near], cs[near], 2)[0]
        if a > 0:
            cov = np.array([[1.0 / a]])
    return np.array([best]), vals[best], cov, ""


# --------------------------------------------------------------------------- gap metrics


def _window(pb: _Problem) -> tuple[float, float]:
    h = pb.spec.requirements.hunting
    if h.window_start + h.window_length <= pb.duration + 1e-9 and h.window_start >= pb.last_move_end:
        return h.window_start, h.window_length
    start = min(pb.last_move_end, pb.duration * 0.5)
    return start, max(pb.duration - start + 1e-9, 1e-6)


def play(values: np.ndarray, half_width: float) -> np.ndarray:
    """Play (backlash) operator: the output moves only when the input leaves +-half_width.

    Noise smaller than the play leaves a stuck plateau perfectly flat, so peak
    counting sees one peak per stick-slip cycle instead of many noise peaks.
    """
    x = np.asarray(values, dtype=float)
    out = np.empty_like(x)
    if len(x) == 0:
        return out
    y = x[0]
    h = float(half_width)
    for i in range(len(x)):
        v = x[i]
        if v - h > y:
            y = v - h
        elif v + h < y:
            y = v + h
        out[i] = y
    return out


def _hunting(pb: _Problem, x: np.ndarray):
    h = pb.spec.requirements.hunting
    w0, wl = _window(pb)
    e = play(x - pb.meas.reference, 4.0 * pb.noise.position)
    return hunting_metrics(pb.t, e, window_start=w0, window_length=wl,
                           min_distance=h.min_distance, min_height=h.min_height,
                           settle_band=h.settle_band, motion_end=pb.last_move_end)


def _gaps(pb: _Problem, nom: _Trace, cor: _Trace, chi2_nom: float, chi2_cor: float
          ) -> tuple[GapMetric, ...]:
    meas = pb.meas
    nz = pb.noise
    n = pb.n_points
    out: list[GapMetric] = []

    def sig(value, noise, factor=1.5):
        if value is None or noise is None:
            return None
        return bool(value > factor * noise)

    chi_noise = 1.0 + 3.0 * math.sqrt(2.0 / max(n, 1))
    mb, ma = math.sqrt(chi2_nom / n), math.sqrt(chi2_cor / n)
    out.append(GapMetric("misfit", "-", "RMS weighted residual of the comparison (1 = noise)",
                         None, None, None, mb, ma, 1.0, bool(mb > chi_noise),
                         bool(ma > chi_noise)))
    eb, ea = max(chi2_nom / n - 1.0, 0.0), max(chi2_cor / n - 1.0, 0.0)
    lim = 3.0 * math.sqrt(2.0 / max(n, 1))
    out.append(GapMetric("excess", "-", "mean squared weighted residual beyond noise, "
                                        "chi2 / n - 1 (0 = explained down to noise)",
                         None, None, None, eb, ea, lim, bool(eb > lim), bool(ea > lim)))

    def rms(a, b, mask):
        if mask.sum() == 0:
            return None
        return float(np.sqrt(np.mean((a[mask] - b[mask]) ** 2)))

    for kind in ("move", "settle", "hold"):
        mask = pb.kind == kind
        b = rms(nom.position, meas.position, mask)
        a = rms(cor.position, meas.position, mask)
        out.append(GapMetric(f"position_rms_{kind}", "m",
                             f"RMS of measured minus modelled position in the {kind} segments "
                             "(sample by sample)", None, None, None, b, a, nz.position,
                             sig(b, nz.position), sig(a, nz.position)))
    allm = np.ones(pb.n, bool)
    if pb.has_force:
        b = rms(nom.force, meas.force, allm)
        a = rms(cor.force, meas.force, allm)
        out.append(GapMetric("force_rms", "N", "RMS of measured minus modelled commanded force",
                             None, None, None, b, a, nz.force, sig(b, nz.force),
                             sig(a, nz.force)))
    if pb.has_defl:
        b = rms(nom.deflection, meas.deflection, allm)
        a = rms(cor.deflection, meas.deflection, allm)
        out.append(GapMetric("deflection_rms", "m", "RMS of measured minus modelled deflection",
                             None, None, None, b, a, nz.deflection, sig(b, nz.deflection),
                             sig(a, nz.deflection)))
    hm = _hunting(pb, meas.position)
    hn = _hunting(pb, nom.position)
    hc = _hunting(pb, cor.position)
    w0, wl = _window(pb)
    hold = (pb.t >= w0)
    def std_e(x):
        e = (x - meas.reference)[hold]
        return float(np.std(e)) if len(e) else None
    feats = [
        ("hunting_cycles", "-", "hunting cycles counted in the window (paper metric)",
         float(hm.hunting_cycles), float(hn.hunting_cycles), float(hc.hunting_cycles), 0.5),
        ("hunting_amplitude", "m", "peak-to-peak position error in the window",
         hm.amplitude, hn.amplitude, hc.amplitude, 8.0 * nz.position),
        ("hunting_period", "s", "mean time between hunting peaks",
         hm.period, hn.period, hc.period, None),
        ("error_std_hold", "m", "standard deviation of the position error in the window "
                                "(phase-free)", std_e(meas.position), std_e(nom.position),
         std_e(cor.position), 2.0 * nz.position),
        ("settling_time", "s", "time after the last move until the error stays in the "
                               "settle band", hm.settling_time, hn.settling_time,
         hc.settling_time, None),
        ("final_error", "m", "position error at the last sample", hm.final_error,
         hn.final_error, hc.final_error, 3.0 * nz.position),
    ]
    for name, unit, desc, vm, vn, vc, noise in feats:
        b = None if vm is None or vn is None else abs(vn - vm)
        a = None if vm is None or vc is None else abs(vc - vm)
        if name == "hunting_period" and noise is None and vm is not None and hm.hunting_cycles > 2:
            noise = float(np.std(np.diff(hm.peak_times))) or None
        if name == "settling_time":
            noise = max(pb.settle_window * 0.05, float(np.median(np.diff(pb.t))))
        out.append(GapMetric(name, unit, desc, vm, vn, vc, b, a, noise,
                             sig(b, noise, 1.0), sig(a, noise, 1.0)))
    return tuple(out)


# --------------------------------------------------------------------------- main entry


def reconcile(spec, measured: Measurement, *, isolated: bool | None = None,
              candidates=None, max_effects: int = 1, threshold: float = THRESHOLD,
              settle_window: float | None = None, max_points: int = MAX_POINTS,
              progress: ProgressCallback | None = None) -> ReconcileResult:
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
        Effect names to try; default the whole catalogue (DESIGN.md section 5).
    max_effects : int
        Effects to add at most (default 1); later ones are searched on the
        gap the earlier ones leave.
    threshold : float
        Score (BIC difference) a candidate needs to be chosen. Default 10.
    settle_window : float, optional
        Length of the settle segment after each move [s]; default five
        integrator time constants, 5 * integrator_ratio / (2 pi crossover).
    max_points : int
        Largest number of sample-wise residuals per channel (strided).
    progress : callable, optional
        ``progress(message, fraction)`` with fraction in [0, 1].

    Returns
    -------
    ReconcileResult
        The named effect (or ``"none"``), its parameters and uncertainty, the
        ranked candidates, the gaps before and after and the model traces.

    Raises
    ------
    DataError
        The trace is too short for the comparison.
    SimulationError
        The nominal model cannot be simulated on this trace (it fails to
        integrate), or the arguments are inconsistent.

    Examples
    --------
    >>> import fi_design
    >>> spec = fi_design.load_spec("examples/measured_stage.yaml")
    >>> data = fi_design.load_measurement("examples/measured_trace.csv")
    >>> result = fi_design.reconcile(spec, data)    # doctest: +SKIP
    >>> result.effect, result.parameters            # doctest: +SKIP
    """
    start = _time.perf_counter()
    say = progress or (lambda message, fraction: None)
    iso = spec.has_isolator if isolated is None else bool(isolated)
    if iso and not spec.has_isolator:
        raise SimulationError("isolated=True but the spec has no isolator")
    names = list(_effects.EFFECT_NAMES) if candidates is None else list(candidates)
    for nm in names:
        _effects.get(nm)  # KeyError for unknown names -> reported below
    if max_effects < 1:
        raise SimulationError("max_effects must be at least 1")
    if measured.n < 50:
        raise DataError(f"too short for a reconciliation: {measured.n} samples, at least 50",
                        column="time_s", source=measured.source)

    say("nominal model", 0.0)
    noise = _noise(spec, measured, iso)
    pb = _Problem(spec, measured, iso, settle_window, list(spec.effects), noise)
    res0 = simulate(pb.spec_sim, iso, reference=pb.ref, initial_position=pb.x0,
                    duration=pb.duration, rtol=pb.rtol)
    pb.n_sims += 1
    nom = pb.sample(res0, None)
    if not nom.success:
        raise SimulationError(f"the nominal model fails on this trace: {res0.message}")
    pb.nominal_force = nom.force
    pb.finish_setup(nom, max_points)
    r0 = pb.residuals(nom)
    chi2_nom = float(r0 @ r0)
    n = len(r0)
    signatures, guesses = _signatures(pb, nom)

    chosen_entries: list = []
    chosen_names: list[str] = []
    chosen_params: list[dict] = []
    chosen_unc: list[dict] = []
    chosen_spaces: list[tuple] = []
    rounds: list[SearchRound] = []
    skipped_all: dict[str, str] = {}
    chi2_cur = chi2_nom
    base = list(spec.effects)
    for rnd in range(max_effects):
        remaining = [nm for nm in names if nm not in chosen_names]
        spaces, skipped = _spaces(pb, guesses if rnd == 0 else {}, remaining)
        if rnd == 0:
            skipped_all.update(skipped)
        cands: list[Candidate] = []
        fitted: dict[str, tuple] = {}
        for j, sp in enumerate(spaces):
            frac0 = (rnd + j / max(len(spaces), 1)) / max_effects
            say(f"fitting {sp.name}", frac0)
            t0 = _time.perf_counter()
            ob = _Objective(pb, sp, base + chosen_entries)
            u, c2, cov, note = _fit(ob)
            k = len(sp.coords)
            vals = ob.values(u)
            scale = max(1.0, c2 / max(n - k, 1))
            pnames, G = ob.value_jacobian(u)
            if cov is not None:
                var = np.diag(G @ (cov * scale) @ G.T)
                unc = {nm: (float(math.sqrt(v)) if v >= 0 and math.isfinite(v) else None)
                       for nm, v in zip(pnames, var)}
            else:
                unc = {nm: None for nm in pnames}
            delta = chi2_cur - c2
            score = delta / scale - k * math.log(n)
            excess = chi2_cur - n
            explained = float(min(max(delta / excess, 0.0), 1.0)) if excess > 0 else 0.0
            ok = ob.n_ok > 0
            cands.append(Candidate(
                name=sp.name, parameters=vals, uncertainty=unc, score=float(score), chi2=c2,
                delta_chi2=float(delta), explained=explained, n_parameters=k,
                n_simulations=ob.n_sims, wall_time=_time.perf_counter() - t0, success=bool(ok),
                message=note if ok else "every simulation of this candidate failed"))
            fitted[sp.name] = (vals, unc, sp, u)
        cands.sort(key=lambda c: -c.score)
        pick = cands[0] if cands and cands[0].score > threshold and cands[0].success else None
        rounds.append(SearchRound(index=rnd, chi2_start=chi2_cur, candidates=tuple(cands),
                                  selected=pick.name if pick else None))
        if pick is None:
            break
        vals, unc, sp, u_pick = fitted[pick.name]
        chosen_spaces.append((sp, u_pick))
        entry = make_entry(pick.name, vals)
        chosen_entries.append(entry)
        chosen_names.append(pick.name)
        chosen_params.append(vals)
        chosen_unc.append(unc)
        chi2_cur = pick.chi2
    if len(chosen_spaces) > 1:
        # the effects were chosen one after another: refine them together
        say("refining the chosen effects together", 0.95)
        jo = _JointObjective(pb, [sp for sp, _ in chosen_spaces], base)
        u0 = np.concatenate([u for _, u in chosen_spaces])
        c2, u, cov = _joint_fit(jo, u0)
        if c2 < chi2_cur:
            chi2_cur = c2
            scale = max(1.0, c2 / max(n - len(u), 1))
            chosen_params, chosen_unc, chosen_entries = [], [], []
            for (sp, _), (vals, names_j, G, sl) in zip(chosen_spaces, jo.parts(u)):
                chosen_params.append(vals)
                if cov is not None:
                    sub = cov[sl, sl] * scale
                    var = np.diag(G @ sub @ G.T)
                    chosen_unc.append({nm: (float(math.sqrt(v)) if v >= 0 else None)
                                       for nm, v in zip(names_j, var)})
                else:
                    chosen_unc.append({nm: None for nm in names_j})
                chosen_entries.append(make_entry(sp.name, vals))
    # corrected model
    say("corrected model", 0.97)
    q = None
    for nm, vals in zip(chosen_names, chosen_params):
        if nm == "quantization":
            q = vals["resolution"]
    if chosen_entries:
        cor = pb.run(base + chosen_entries, quantize=q)
        rc = pb.residuals(cor)
        chi2_cor = float(rc @ rc)
    else:
        cor, chi2_cor = nom, chi2_nom
    gaps = _gaps(pb, nom, cor, chi2_nom, chi2_cor)
    first = rounds[0].candidates if rounds else ()
    ambiguous: tuple = ()
    if chosen_names and first:
        ambiguous = tuple(c.name for c in first[1:] if c.score > first[0].score - threshold
                          and c.score > threshold)
    entries = tuple({"type": nm, **{k: v for k, v in vals.items() if v is not None}}
                    for nm, vals in zip(chosen_names, chosen_params))
    effect = chosen_names[0] if chosen_names else "none"
    conclusion = _conclusion(effect, chosen_names, chosen_params, chosen_unc, first, chi2_nom,
                             chi2_cor, n, threshold, ambiguous)
    say("done", 1.0)
    return ReconcileResult(
        effect=effect, parameters=dict(chosen_params[0]) if chosen_params else {},
        uncertainty=dict(chosen_unc[0]) if chosen_unc else {}, effects=tuple(chosen_names),
        entries=entries, candidates=tuple(first), rounds=tuple(rounds), ambiguous=ambiguous,
        skipped=skipped_all, gaps=gaps, noise=pb.noise, signatures=tuple(signatures),
        segments=pb.segment_list(), isolated=iso, threshold=float(threshold), n_points=n,
        chi2_nominal=chi2_nom, chi2_corrected=chi2_cor, conclusion=conclusion,
        n_simulations=pb.n_sims, wall_time=_time.perf_counter() - start, measurement=measured,
        nominal=_model_trace(pb, nom), corrected=_model_trace(pb, cor), spec=spec)


def _model_trace(pb: _Problem, tr: _Trace) -> ModelTrace:
    return ModelTrace(time=frozen_array(pb.t), position=frozen_array(tr.position),
                      force=frozen_array(tr.force),
                      deflection=None if tr.deflection is None else frozen_array(tr.deflection),
                      success=tr.success, message=tr.message)


def _noise(spec, meas: Measurement, iso: bool) -> NoiseLevels:
    given = spec.measurement
    src: dict[str, str] = {}

    def level(channel: str, values, spec_value):
        if values is None:
            return None
        if spec_value is not None and spec_value > 0:
            src[channel] = "spec"
            return float(spec_value)
        est = estimate_noise(values)
        if est < NOISE_FLOOR[channel]:
            src[channel] = "floor"
            return NOISE_FLOOR[channel]
        src[channel] = "estimated"
        return est

    pos = level("position", meas.position, given.position_noise if given else None)
    force = level("force", meas.force, given.force_noise if given else None)
    defl = level("deflection", meas.deflection if iso else None,
                 given.deflection_noise if given else None)
    return NoiseLevels(position=pos, force=force, deflection=defl, source=src, resolution=None)


def _fmt_params(vals: dict, unc: dict) -> str:
    units = {}
    parts = []
    for k, v in vals.items():
        if v is None:
            continue
        s = unc.get(k)
        u = units.get(k, "")
        parts.append(f"{k} = {v:.4g}" + (f" +- {s:.2g}" if s else "") + u)
    return ", ".join(parts)


def _conclusion(effect, names, params, uncs, cands, chi2_nom, chi2_cor, n, threshold,
                ambiguous) -> str:
    before = math.sqrt(chi2_nom / n)
    after = math.sqrt(chi2_cor / n)
    if effect == "none":
        if before <= 1.0 + 3.0 * math.sqrt(2.0 / n):
            return (f"The nominal model agrees with the measurement within noise (misfit "
                    f"{before:.3g} noise units): no effect is missing.")
        best = cands[0] if cands else None
        tail = (f" The best candidate, {best.name}, scores {best.score:.3g} (threshold "
                f"{threshold:g})." if best else "")
        return (f"The model misses the measurement by {before:.3g} noise units, but no catalogue "
                f"effect explains the gap better than noise does: the answer is none.{tail}")
    lines = []
    for nm, v, u in zip(names, params, uncs):
        lines.append(f"{nm} ({_fmt_params(v, u)}, SI)")
    text = (f"The measurement shows {' and '.join(lines)}. With it the misfit drops from "
            f"{before:.3g} to {after:.3g} noise units.")
    if ambiguous:
        text += (" Also consistent with the data, not decisively worse: "
                 + ", ".join(ambiguous) + ".")
    return text


# --------------------------------------------------------------------------- writing the spec


def fixed_spec_text(result: ReconcileResult) -> str:
    """YAML text of the spec with the chosen effects added to its ``effects`` list.

    When the spec was read from a file without an ``effects`` key, the file's
    text is kept (comments included) and an ``effects:`` block is appended;
    otherwise the spec as written is re-emitted with the new entries. The
    text is validated with :func:`fi_design.specfile.load_spec` before it is
    returned.

    Parameters
    ----------
    result : ReconcileResult
        The reconciliation.

    Returns
    -------
    str
        YAML that ``load_spec`` reads back.
    """
    import yaml

    from .specfile import origin, parse_yaml, load_spec

    spec = result.spec
    org = origin(spec)
    entries = [entry_input(e["type"], {k: v for k, v in e.items() if k != "type"})
               for e in result.entries]
    names = {e["type"] for e in entries}
    comment = ("# effects added by fi-design reconcile"
               + (f" from {result.measurement.source}" if result.measurement.source else "")
               + ": " + result.conclusion.replace("\n", " "))
    raw_text = None
    if org is not None and org.path is not None:
        try:
            raw_text = org.path.read_text(encoding="utf-8")
        except OSError:
            raw_text = None
    if raw_text is not None and "effects" not in org.raw:
        lines = [raw_text.rstrip("\n"), "", _wrap_comment(comment), "effects:"]
        for e in entries:
            lines.append("  - " + _flow(e))
        text = "\n".join(lines) + "\n"
    else:
        raw = dict(org.raw) if org is not None else spec.model_dump(exclude_none=True)
        old = [e for e in (raw.get("effects") or []) if not (isinstance(e, dict)
                                                             and e.get("type") in names)]
        raw["effects"] = old + entries
        text = _wrap_comment(comment) + "\n" + yaml.safe_dump(raw, sort_keys=False,
                                                              allow_unicode=True)
    data, _ = parse_yaml(text.encode("utf-8"), "<fixed spec>")
    load_spec(data)
    return text


def _wrap_comment(text: str, width: int = 96) -> str:
    import textwrap

    return "\n".join("# " + line if not line.startswith("#") else line
                     for line in textwrap.wrap(text.lstrip("# "), width - 2))


def _flow(entry: dict) -> str:
    parts = [f"type: {entry['type']}"]
    for k, v in entry.items():
        if k == "type":
            continue
        parts.append(f"{k}: {v!r}" if isinstance(v, float) else f"{k}: '{v}'")
    return "{" + ", ".join(parts) + "}"
