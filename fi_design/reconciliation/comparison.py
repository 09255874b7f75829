"""The comparison of one model run with the record: replay, segments, weighted residual.

:class:`Comparison` holds the record, the noise levels and the way the trace
is split, runs the model on the record (:func:`fi_design.simulation.run.simulate`
with ``record=``: the replay starts from the state in the data) and turns a
run into the weighted residual vector every fit and score works on.

Segments come from the reference velocity: *move*, *settle* (a window after
each move) and *hold*. A hold in which the measured or the nominal error
reverses direction three times or more by more than the hysteresis band (ten
position-noise levels, at least the settle band) is *incoherent*:
stick-slip cycles drift out of phase after a slip, so there the comparison
uses phase-free features (mean, standard deviation and reversal rate of the
position error; mean and standard deviation of force and deflection) instead
of samples.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..display import number, quantity
from ..errors import DataError
from ..measured import Measurement
from ..model import as_model
from ..simulation.replay import command_state
from ..simulation.replay import vouch
from ..simulation.run import record_notes, simulate
from ..trajectory import from_samples
from ..results.reconciliation import Lattice, ModelTrace, NoiseLevels, Segment

#: Default largest number of sample-wise residuals per channel.
MAX_POINTS = 3000
#: A failed or runaway run counts this many times the nominal misfit in every residual entry.
FAIL_FACTOR = 10.0
#: A run whose position error exceeds this many times the largest measured error has run away.
RUNAWAY_FACTOR = 10.0
#: Tolerance factor of the check of a finding's numerical accuracy (one run this much tighter).
ACCURACY_CHECK = 1e-3
#: Range the initial command is fitted in, in force-noise standard deviations either side.
INITIAL_COMMAND_RANGE = 4.0


@dataclass(frozen=True, eq=False)
class ModelRun:
    """One simulation of the model at the measured times (internal to the reconciliation).

    Attributes
    ----------
    position, force : ndarray, shape (n,)
        Stage position as the sensor reports it [m] and commanded force [N].
    deflection : ndarray, shape (n,), or None
        Joint deflection [m] (isolated plant).
    ok : bool
        The simulation completed and stayed within the record's envelope.
    message : str
        What failed, if anything.
    """

    position: np.ndarray
    force: np.ndarray
    deflection: np.ndarray | None
    ok: bool
    message: str = ""


class Comparison:
    """The record, its segments and noise, and the model runner.

    Parameters
    ----------
    spec : Spec or Model
        The spec of the stage, or its resolved model (``model``; the spec is
        resolved once here).
    measured : Measurement
        The record.
    isolated : bool
        Model the isolated plant.
    noise : NoiseLevels
        Noise per channel.
    lattice : Lattice
        The lattice of the measured positions (the sensor's quantization).
    settle_window : float or None
        Length of the settle segment after each move [s]; default five
        integrator time constants (or five loop time constants without one).
    drive : {"closed", "force"}
        Closed-loop replay, or the plant driven by the measured force.
    """

    def __init__(self, spec, measured: Measurement, isolated: bool, noise: NoiseLevels,
                 lattice: Lattice, settle_window: float | None, drive: str) -> None:
        self.model = as_model(spec)
        self.spec = self.model.spec
        self.meas = measured
        self.iso = isolated
        self.noise = noise
        self.lattice = lattice
        self.drive = drive
        self.t = np.asarray(measured.time - measured.time[0], dtype=float)
        self.n = len(self.t)
        self.duration = float(self.t[-1])
        if self.duration <= 0:
            raise DataError("the trace has no duration", column="time_s", source=measured.source)
        self.has_force = measured.force is not None and drive == "closed"
        self.has_defl = measured.deflection is not None and isolated
        self.rtol = model_tolerance(self.spec, noise)
        self.initial_command = command_state(measured, 0) if self.has_force else None
        self.n_sims = 0
        self.fail_level = FAIL_FACTOR
        err = np.abs(measured.position - measured.reference)
        self.runaway = RUNAWAY_FACTOR * (float(np.max(err)) + 10.0 * noise.position)
        #: The replay's warnings about the record (a closed loop that starts far from its
        #: reference: :func:`fi_design.simulation.run.record_notes`).
        self.notes = record_notes(self.model, measured, drive, isolated)
        # its record is reconcile()'s, checked there before the thinning
        # (fi_design.simulation.replay.check_record), or a trace of the model itself
        vouch(measured)
        self._segments(settle_window)

    # ---- model runs

    def run(self, entries, quantize: float | None = None, command_correction: float = 0.0,
            rtol: float | None = None) -> ModelRun:
        """Simulate with effect entries (model objects) on the record.

        Parameters
        ----------
        entries : list
            Effect entries (spec ``effects`` items) of the model.
        quantize : float, optional
            Report the position on the sensor's lattice of this step [m] (the
            model's controller quantizes through its own ``quantization``
            effect).
        command_correction : float
            Added to the initial command [N] (the nuisance, see
            :attr:`command_width`).
        rtol : float, optional
            Relative tolerance; default :func:`model_tolerance`.
        """
        self.n_sims += 1
        u0 = None if self.initial_command is None else self.initial_command + command_correction
        res = simulate(self.model, self.iso, effects=list(entries),
                       rtol=self.rtol if rtol is None else rtol,
                       record=self.meas, drive=self.drive, initial_command=u0)
        x = np.asarray(res.position, dtype=float)
        u = np.asarray(res.force, dtype=float)
        d = np.asarray(res.deflection, dtype=float) if self.iso else None
        if quantize:
            x0 = self.lattice.offset if self.lattice.found else 0.0
            x = np.round((x - x0) / quantize) * quantize + x0
        ok, message = bool(res.success), res.message
        if ok and not (np.all(np.isfinite(x)) and np.all(np.isfinite(u))):
            ok, message = False, "the simulation returned non-finite values"
        if ok:
            worst = float(np.max(np.abs(x - self.meas.reference)))
            if worst > self.runaway:
                ok = False
                message = ("runaway: the model's position error reached "
                           f"{quantity(worst, 'm', 3)}, more than {number(RUNAWAY_FACTOR)} "
                           "times the largest measured error (an unstable loop)")
        return ModelRun(position=x, force=u, deflection=d, ok=ok, message=message)

    def trace_source(self, entries) -> ModelRun:
        """A run that a record made from the model can be: one continuous trajectory.

        Closed loop it is :meth:`run`. An open-loop replay re-anchors every
        window to the measurement, so its position jumps at the window starts;
        a record made from it would not be one the model could have produced.
        Here the plant is driven by the measured force in a single window
        from the first sample.

        Parameters
        ----------
        entries : list
            Effect entries of the model.
        """
        if self.drive == "closed":
            return self.run(entries)
        self.n_sims += 1
        span = float(self.meas.time[-1] - self.meas.time[0])
        res = simulate(self.model, self.iso, effects=list(entries), rtol=self.rtol,
                       record=self.meas, drive=self.drive, window=2.0 * span + 1.0)
        x = np.asarray(res.position, dtype=float)
        u = np.asarray(res.force, dtype=float)
        d = np.asarray(res.deflection, dtype=float) if self.iso else None
        ok = bool(res.success) and bool(np.all(np.isfinite(x)))
        return ModelRun(position=x, force=u, deflection=d, ok=ok, message=res.message)

    @property
    def command_width(self) -> float:
        """Half-range of the initial-command nuisance [N] (0 when there is none).

        One force sample carries the sensor's noise, and the replay makes the
        controller's state (its integrator) consistent with it: a noisy
        sample offsets the whole replay until the integrator forgets it. The
        initial command is therefore fitted with every model, within
        ``INITIAL_COMMAND_RANGE`` force-noise levels of the sample.
        """
        if not self.has_force or self.initial_command is None:
            return 0.0
        return INITIAL_COMMAND_RANGE * self.noise.force

    # ---- segments

    def _segments(self, settle_window: float | None) -> None:
        t = self.t
        ref = from_samples(t, self.meas.reference)
        v = np.asarray(ref(t, 1))
        self.v_ref = v
        self.a_ref = np.asarray(ref(t, 2))
        vmax = float(np.max(np.abs(v))) if len(v) else 0.0
        moving = np.abs(v) > 1e-3 * vmax if vmax > 0 else np.zeros(self.n, bool)
        merged: list[list[int]] = []
        for run in runs(moving):
            if merged and t[run.start] - t[merged[-1][1] - 1] < 0.02:
                merged[-1][1] = run.stop
            else:
                merged.append([run.start, run.stop])
        self.moves = [range(i0, i1) for i0, i1 in merged if i1 - i0 >= 2]
        if settle_window is None:
            law = self.model.law
            tau = law.kp / law.ki if law.ki > 0 else 1.0 / (2.0 * math.pi * law.crossover)
            settle_window = 5.0 * tau
        self.settle_window = float(settle_window)
        kind = np.full(self.n, "hold", dtype=object)
        for k, move in enumerate(self.moves):
            kind[move.start:move.stop] = "move"
            nxt = self.moves[k + 1].start if k + 1 < len(self.moves) else self.n
            j = int(np.searchsorted(t, t[move.stop - 1] + self.settle_window, side="right"))
            kind[move.stop:min(j, nxt)] = "settle"
        self.kind = kind
        self.holds = runs(kind == "hold")
        self.last_move_end = float(t[self.moves[-1].stop - 1]) if self.moves else 0.0
        r = self.meas.reference
        self.travel_center = float(0.5 * (np.max(r) + np.min(r)))

    def finish_setup(self, nominal: ModelRun, max_points: int) -> None:
        """Decide coherent/incoherent holds, the strided samples and the features' scales."""
        noise = self.noise
        self.nominal_force = nominal.force
        self.band = max(10.0 * noise.position, self.spec.requirements.hunting.settle_band)
        e_meas = self.meas.position - self.meas.reference
        e_nom = nominal.position - self.meas.reference
        coherent = np.ones(self.n, bool)
        self.feature_segments: list[range] = []
        for hold in self.holds:
            i0, i1 = hold.start, hold.stop
            if i1 - i0 < 20:
                continue
            if reversals(e_meas[i0:i1], self.band) >= 3 or reversals(e_nom[i0:i1], self.band) >= 3:
                coherent[i0:i1] = False
                self.feature_segments.append(hold)
        self.coherent = coherent
        idx = np.nonzero(coherent)[0]
        stride = max(1, int(math.ceil(len(idx) / max_points)))
        self.idx = idx[::stride]
        channels = 1 + int(self.has_force) + int(self.has_defl)
        in_move = np.asarray(self.kind[self.idx] == "move")
        nf = self.n_points - channels * len(self.idx)
        self.move_entries = np.concatenate([np.tile(in_move, channels), np.zeros(nf, bool)])
        self.feat_meas = []
        self.feat_sigma = []
        m = self.meas
        for seg in self.feature_segments:
            i0, i1 = seg.start, seg.stop
            f = self._features(m.position, m.force, m.deflection, i0, i1)
            chunks = np.array_split(np.arange(i0, i1), 4)
            fc = np.array([self._features(m.position, m.force, m.deflection, c[0], c[-1] + 1)
                           for c in chunks])
            spread = np.std(fc, axis=0, ddof=1) / 2.0
            floor = self._feature_noise(i0, i1)
            self.feat_meas.append(f)
            self.feat_sigma.append(np.sqrt(spread ** 2 + (0.05 * np.abs(f)) ** 2 + floor ** 2))

    def set_fail_level(self, chi2_nominal: float) -> None:
        """Residual of every entry of a failed run: FAIL_FACTOR times the nominal RMS misfit."""
        self.fail_level = FAIL_FACTOR * max(1.0, math.sqrt(chi2_nominal / self.n_points))

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
        out = [float(np.mean(e)), float(np.std(e)), reversals(e, self.band) / dur]
        if self.has_force:
            out += [float(np.mean(u[i0:i1])), float(np.std(u[i0:i1]))]
        if self.has_defl:
            out += [float(np.mean(d[i0:i1])), float(np.std(d[i0:i1]))]
        return np.array(out)

    # ---- residuals

    @property
    def n_points(self) -> int:
        """Entries of the residual vector."""
        k = 1 + int(self.has_force) + int(self.has_defl)
        nf = 3 + 2 * int(self.has_force) + 2 * int(self.has_defl)
        return k * len(self.idx) + nf * len(self.feature_segments)

    def residuals(self, run: ModelRun) -> np.ndarray:
        """The weighted residual vector of a model run [noise units].

        A failed or runaway run gives :attr:`fail_level` in every entry, far
        above any run that completes, so it can never win a fit.
        """
        if not run.ok:
            return np.full(self.n_points, self.fail_level)
        i = self.idx
        parts = [(run.position[i] - self.meas.position[i]) / self.noise.position]
        if self.has_force:
            parts.append((run.force[i] - self.meas.force[i]) / self.noise.force)
        if self.has_defl:
            parts.append((run.deflection[i] - self.meas.deflection[i]) / self.noise.deflection)
        for seg, fm, fs in zip(self.feature_segments, self.feat_meas, self.feat_sigma):
            parts.append((self._features(run.position, run.force, run.deflection, seg.start,
                                         seg.stop) - fm) / fs)
        r = np.concatenate(parts)
        if not np.all(np.isfinite(r)):
            return np.full(self.n_points, self.fail_level)
        return r

    def channel_blocks(self, r: np.ndarray) -> list[np.ndarray]:
        """The sample-wise channels of a residual vector, each in time order."""
        m = len(self.idx)
        k = 1 + int(self.has_force) + int(self.has_defl)
        return [r[j * m:(j + 1) * m] for j in range(k)]

    def segment_list(self) -> tuple[Segment, ...]:
        """The segments as result values."""
        out = []
        for seg in label_runs(self.kind):
            out.append(Segment(kind=str(self.kind[seg.start]), start=float(self.t[seg.start]),
                               end=float(self.t[seg.stop - 1]),
                               coherent=bool(self.coherent[seg.start])))
        return tuple(out)

    def model_trace(self, run: ModelRun) -> ModelTrace:
        """A run as a result value (NaN where a failed run has no samples)."""
        return ModelTrace(time=_frozen(self.t), position=_frozen(run.position),
                          force=_frozen(run.force),
                          deflection=None if run.deflection is None else _frozen(run.deflection),
                          success=run.ok, message=run.message)


def _frozen(values) -> np.ndarray:
    from ..results import frozen_array

    return frozen_array(values)


def model_tolerance(spec, noise: NoiseLevels) -> float:
    """Relative tolerance of the reconciliation's simulations.

    The integrator's absolute position tolerance is ``rtol`` times 1 mm
    (:func:`fi_design.simulation.run.tolerances`). Integration errors of the size of
    a fraction of the sensor noise, summed over thousands of samples, would
    otherwise let a fit "explain" numerical jitter: the tolerance is set so
    that the position tolerance is a hundredth of the smallest position or
    deflection noise (at most the spec's ``simulation.tolerance``, at least
    1e-9).
    """
    sig = min(v for v in (noise.position, noise.deflection) if v is not None)
    return float(min(spec.simulation.tolerance, max(1e-9, sig / 100.0 / 1e-3)))


def runs(mask: np.ndarray) -> list[range]:
    """Index ranges where ``mask`` is true."""
    m = np.concatenate([[False], np.asarray(mask, bool), [False]])
    d = np.diff(m.astype(int))
    return [range(int(a), int(b)) for a, b in zip(np.nonzero(d == 1)[0], np.nonzero(d == -1)[0])]


def label_runs(labels: np.ndarray) -> list[range]:
    """Index ranges of equal consecutive labels."""
    out = []
    i0 = 0
    for i in range(1, len(labels) + 1):
        if i == len(labels) or labels[i] != labels[i0]:
            out.append(range(i0, i))
            i0 = i
    return out


def reversals(e: np.ndarray, band: float) -> int:
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
    return count
