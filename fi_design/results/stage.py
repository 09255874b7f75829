"""Results of the stage-level hunting analysis: every move, the cycle itself, the boundary.

Produced by :func:`fi_design.stage.stage_hunting`. Hunting is a property of
the stage, not of one move: the closed loop with stick-slip friction is
bistable (a stable rest set beside a stable limit cycle), and which one a run
ends in depends on where the cart first sticks after the move. The answer per
plant is therefore taken over a family of moves (:class:`MoveOutcome`), the
cycle a hunting move enters is converged as a periodic orbit (:class:`Cycle`),
and the hunting-free crossover is the crossover above which that cycle no
longer exists (its fold), found by bisection (:class:`StageHunting`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..display import number, quantity
from . import Result, dataclass_dict, to_jsonable

__all__ = ["STATIC_ERROR_FORMULA", "MOVE_OUTCOMES", "BOUNDARY_KINDS", "MoveOutcome", "CycleTrace",
           "Cycle", "Boundary", "StageHunting", "length_text", "length_range"]

def length_text(x: float) -> str:
    """A length [m] for a sentence, 3 digits (:func:`fi_design.display.quantity`)."""
    return quantity(float(x), "m", 3)


def length_range(lo: float, hi: float) -> str:
    """Two lengths [m] in the unit of the larger: ``"0.396 to 50 mm"``."""
    return quantity((lo, hi), "m", 3, joiner=" to ")


#: The static error bound of a loop without integrator, as every statement names it
#: (:attr:`fi_design.model.Model.static_error_bound`): the larger static friction of the two
#: directions and the load offset over kp.
STATIC_ERROR_FORMULA = "(Fs + |offset|) / kp"


#: How a move can end: at rest at the target, in a sustained cycle, at rest
#: off the target (a loop without integrator: its static error; with an
#: integrator: stuck), or not judged within the horizon (``undetermined``,
#: also a failed simulation).
MOVE_OUTCOMES = ("settles", "hunts", "rests", "stuck", "undetermined")


#: What the stage does after a move of each outcome (:data:`MOVE_OUTCOMES`), after "it".
_OWN_MOTION = {"settles": "settles", "hunts": "hunts", "rests": "comes to rest off its target",
               "stuck": "sticks away from its target", "undetermined": "cannot be judged"}


@dataclass(frozen=True)
class MoveOutcome(Result):
    """How the stage ends after one move of the family.

    Attributes
    ----------
    distance : float
        Signed move distance [m]; for the spec's own motion, the distance of
        its largest move (a back-and-forth motion nets to 0).
    label : str
        ``"family"`` or ``"spec"`` (the spec's own motion, all its moves).
    outcome : str
        One of :data:`MOVE_OUTCOMES`.
    final_error : float
        x1 - r where the run ended [m] (at a section crossing for a cycle).
    amplitude : float or None
        Peak-to-peak x1 - r over the last period of a cycle [m] (at the
        integrator's step ends); None when the move does not hunt.
    period : float or None
        Period of that cycle [s].
    time : float
        Time simulated after the motion ended [s].
    reason : str
        Why, in one sentence.
    failed : bool
        The simulation did not complete (the outcome is then ``undetermined``).
    """

    distance: float
    label: str
    outcome: str
    final_error: float
    amplitude: float | None
    period: float | None
    time: float
    reason: str
    failed: bool = False

    @property
    def hunts(self) -> bool:
        """Whether the move ends in a sustained cycle."""
        return self.outcome == "hunts"


@dataclass(frozen=True, eq=False)
class CycleTrace(Result):
    """One period of a cycle, sampled from its section crossing.

    Attributes
    ----------
    time : ndarray, shape (m,)
        Time since the section crossing [s].
    error : ndarray, shape (m,)
        Position error x1 - r [m].
    velocity : ndarray, shape (m,)
        Stage velocity v1 [m/s].
    deflection : ndarray, shape (m,) or None
        Joint deflection x1 - x2 [m] (isolated plant only).
    cart_velocity : ndarray, shape (m,) or None
        Cart velocity v2 [m/s] (isolated plant only).
    """

    time: np.ndarray
    error: np.ndarray
    velocity: np.ndarray
    deflection: np.ndarray | None
    cart_velocity: np.ndarray | None


@dataclass(frozen=True, eq=False)
class Cycle(Result):
    """A hunting cycle, converged as a periodic orbit.

    The Poincare section is x1 - r = 0 crossed upwards (always mid-slip). With
    a continuous-time controller without delay the state is complete and the
    orbit is converged by Newton's method on the return map (``method
    "shooting"``), whose Jacobian (finite differences, checked at two
    perturbation sizes) gives the Floquet multipliers. A sampled or delayed
    controller has a state the section does not hold: the orbit is then the
    one a long simulation settles on (``method "simulation"``) and its
    multiplier is not computed.

    Attributes
    ----------
    crossover : float
        Controller crossover the cycle was computed at [Hz].
    amplitude : float
        Peak-to-peak x1 - r over one period [m].
    period : float
        Period [s].
    stable : bool
        Whether the cycle attracts (largest multiplier below 1; a cycle found
        by a long simulation attracted it).
    multiplier : float or None
        Largest Floquet multiplier in magnitude [-]; None when not computed, or
        when the two perturbation sizes disagree by more than 10 % (they
        straddle a stick or slip event, where the return map is not smooth);
        the cycle's moves then show whether it attracts.
    multiplier_check : float or None
        The same from a ten times larger perturbation [-] (they agree when the
        finite differences are trustworthy).
    method : str
        ``"shooting"`` or ``"simulation"``.
    residual : float
        Return-map residual of the converged orbit, in units of the state's
        physical scales (1 mm, 1 cm/s, Fs / sigma0, Fs) [-].
    crossings : int
        Section crossings per period.
    on_limiter : bool or None
        Whether the joint reaches its stroke limiter during the cycle
        (isolated plant); None without isolator.
    deflection_range : tuple of float or None
        Smallest and largest joint deflection over the cycle [m].
    section_state : ndarray, shape (n,)
        The state at the section crossing (the orbit's initial condition).
    trace : CycleTrace or None
        One period, for plots.
    """

    crossover: float
    amplitude: float
    period: float
    stable: bool
    multiplier: float | None
    multiplier_check: float | None
    method: str
    residual: float
    crossings: int
    on_limiter: bool | None
    deflection_range: tuple[float, float] | None
    section_state: np.ndarray = field(repr=False)
    trace: CycleTrace | None = field(default=None, repr=False)

    def to_dict(self) -> dict:
        """``amplitude``, ``period``, ``stable``, ``multiplier`` and the rest (SI)."""
        return dataclass_dict(self)


#: How a boundary was found: ``"fold"`` (the crossover where the cycle ceases to exist,
#: bisected), ``"bound"`` (the cycle persists up to the top of the search, or no move
#: hunts from its bottom up) or ``"not_found"`` (moves still hunt just above the last of
#: the folds the search followed: no crossover from which no move hunts was found).
BOUNDARY_KINDS = ("fold", "bound", "not_found")


@dataclass(frozen=True, eq=False)
class Boundary(Result):
    """The hunting-free crossover and how it was found (the fold search).

    Produced by :func:`fi_design.stage.cycle_fold` (one cycle followed up to
    its fold) and by the stage's whole search, which also looks for a cycle
    below the crossover when no move hunts there and runs the move family
    just above each fold found.

    Attributes
    ----------
    hunting_free_from : float or None
        The crossover from which no move of the family hunts [Hz]: the upper
        end of the bracket of a fold, the bottom of the search when no move
        hunts from there up; None when the cycle persists up to the top of
        the search (``kind`` ``"bound"``) or when none was found
        (``"not_found"``).
    bracket : tuple of float
        The last bracket [lo, hi] of the search [Hz]: the cycle exists at lo
        and not at hi (a fold), or the range searched (a bound).
    kind : str
        One of :data:`BOUNDARY_KINDS`.
    resolution : float
        Width of the fold's bracket [Hz]; 0 for a bound.
    tests : int
        Existence tests and family runs the search took.
    branch : tuple of tuple
        The cycle followed up the crossover: (crossover [Hz], peak-to-peak
        amplitude [m], period [s]) per point, by crossover.
    note : str
        How the answer was reached, in one phrase.
    """

    hunting_free_from: float | None
    bracket: tuple[float, float]
    kind: str
    resolution: float
    tests: int
    branch: tuple[tuple[float, float | None, float | None], ...]
    note: str

    def to_dict(self) -> dict:
        """``bracket``, ``kind``, ``resolution``, ``tests``, ``branch`` and ``note`` (Hz, m,
        s); the crossover itself is stated by :attr:`StageHunting.hunting_free_from`."""
        out = dataclass_dict(self)
        del out["hunting_free_from"]
        return out


@dataclass(frozen=True, eq=False)
class StageHunting(Result):
    """Whether a plant hunts for any move of its family, the cycle, and the boundary.

    Attributes
    ----------
    plant : str
        ``"isolated"`` or ``"non_isolated"``.
    crossover : float
        Controller crossover of the answer [Hz].
    moves : tuple of MoveOutcome
        Every move tried, the spec's own motion first.
    cycle : Cycle or None
        The cycle the hunting moves enter (the largest when they enter
        several), converged; None when no move hunts.
    other_cycles : tuple of Cycle
        Further distinct cycles some moves enter.
    hunting_free_from : float or None
        Stage-level hunting-free crossover [Hz]: the fold of the cycle, above
        which it no longer exists (and no move of the family hunts). None
        when not computed, or when the cycle persists up to the search's top.
    boundary : Boundary or None
        How ``hunting_free_from`` was found (its bracket, resolution, kind,
        tests, the cycle's branch); None when not computed.
    first_only : bool
        Whether the family was cut short at the first hunting move (studies).
    static_error_bound : float or None
        For a loop without integrator, the largest error static friction can
        hold against it, (Fs + |offset|) / kp [m] (a move too short to break
        the cart loose never starts); None when the loop integrates.
    settle_band : float
        The settle band [m].
    """

    plant: str
    crossover: float
    moves: tuple[MoveOutcome, ...]
    cycle: Cycle | None
    other_cycles: tuple[Cycle, ...] = ()
    hunting_free_from: float | None = None
    boundary: Boundary | None = None
    first_only: bool = False
    static_error_bound: float | None = None
    settle_band: float = 1e-5

    @property
    def hunts(self) -> bool:
        """Whether any move ends in a sustained cycle."""
        return any(m.hunts for m in self.moves)

    @property
    def hunting_moves(self) -> tuple[MoveOutcome, ...]:
        """The moves that end in a cycle."""
        return tuple(m for m in self.moves if m.hunts)

    @property
    def entered_by(self) -> tuple[float, ...]:
        """Distances of the moves that enter a cycle [m], in the order tried."""
        return tuple(m.distance for m in self.moves if m.hunts)

    def _rests_too_far(self, m: MoveOutcome) -> bool:
        bound = self.static_error_bound
        return m.outcome == "rests" and (bound is None
                                         or abs(m.final_error) > bound + self.settle_band)

    def _first_bad(self) -> MoveOutcome:
        """The first move that makes the outcome stuck (or undetermined)."""
        if self.outcome == "stuck":
            return next(m for m in self.moves
                        if m.outcome == "stuck" or self._rests_too_far(m))
        return next(m for m in self.moves if m.outcome == "undetermined")

    @property
    def outcome(self) -> str:
        """The plant in a word: ``hunts`` (some move ends in a cycle), ``stuck`` (some
        move rests off its target beyond what the loop explains), ``undetermined``,
        ``static_error`` (a loop without integrator, every move at rest within its
        static error) or ``settles``."""
        if any(m.hunts for m in self.moves):
            return "hunts"
        if any(m.outcome == "stuck" or self._rests_too_far(m) for m in self.moves):
            return "stuck"
        if any(m.outcome == "undetermined" for m in self.moves):
            return "undetermined"
        if any(m.outcome == "rests" for m in self.moves):
            return "static_error"
        return "settles"

    @property
    def acceptable(self) -> bool:
        """Whether every move comes to rest (at its target, or within a PD loop's static
        error)."""
        return self.outcome in ("settles", "static_error")

    @property
    def spec_move(self) -> MoveOutcome | None:
        """The outcome of the spec's own motion."""
        return next((m for m in self.moves if m.label == "spec"), None)

    @property
    def largest_amplitude(self) -> float:
        """Largest cycle amplitude over the moves [m]; 0 where none hunts."""
        amps = [c.amplitude for c in (self.cycle, *self.other_cycles) if c is not None]
        amps += [m.amplitude for m in self.moves if m.hunts and m.amplitude is not None]
        return float(max(amps)) if amps else 0.0

    def summary(self) -> str:
        """What the plant does after its moves, in a short phrase without a subject.

        The same judged outcome :meth:`describe` states in full, for the
        sentences that refer to it (step 1, the isolator advice, the
        verdict's headline): ``"hunts at 8 Hz (7 of 25 moves end in a
        cycle)"``, ``"comes to rest at its target at 8 Hz after every move (25
        moves)"``.
        """
        n = len(self.moves)
        out = self.outcome
        at = f"at {number(self.crossover, 4)} Hz"
        if out == "hunts":
            return f"hunts {at} ({len(self.hunting_moves)} of {n} moves end in a cycle)"
        if out in ("stuck", "undetermined"):
            m = self._first_bad()
            verb = "sticks away from its target" if out == "stuck" else "cannot be judged"
            return f"{verb} {at} after the {length_text(abs(m.distance))} move"
        if out == "static_error":
            return f"rests within its static error {at} after every move ({n} moves)"
        return f"comes to rest at its target {at} after every move ({n} moves)"

    def boundary_text(self) -> str:
        """The hunting-free crossover in words, with how it was found.

        ``"no move of the family hunts from 11.28 Hz up (the fold of its cycle,
        bisected to 0.011 Hz)"``; the cycle persisting to the top of the
        search, a bound at its bottom, or not computed (a loop without
        integrator, which cannot hunt by the paper's mechanism).
        """
        b = self.boundary
        m = self.hunting_free_from
        if b is None:
            if self.static_error_bound is not None:
                return ("not computed: the loop has no integrator, so no crossover bounds "
                        "hunting (it rests with a static error instead)")
            return "not computed"
        if m is None:
            return b.note or "the cycle persists up to the top of the search"
        if b.kind == "fold":
            return (f"no move of the family hunts from {number(m, 4)} Hz up (the fold of its "
                    f"cycle, bisected to {number(b.resolution, 2)} Hz)")
        return f"{b.note or f'no move of the family hunts from {number(m, 4)} Hz up'} (a bound)"

    def describe(self, label: str) -> str:
        """The plant's stage-level answer in one sentence, beginning with ``label``.

        Parameters
        ----------
        label : str
            What the sentence is about, e.g. ``"The isolated stage as specified"``.

        Returns
        -------
        str
        """
        fc = self.crossover
        n = len(self.moves)
        if self.hunts:
            h = self.hunting_moves
            dist = sorted(abs(m.distance) for m in h)
            c = self.cycle
            if c is not None:
                cyc = (f"a cycle of {length_text(c.amplitude)} peak to peak, period "
                       f"{quantity(c.period, 's', 3)}")
                if c.on_limiter:
                    cyc += ", the joint on its limiter"
            else:
                m = h[0]
                cyc = (f"a cycle of {length_text(m.amplitude)} peak to peak" if m.amplitude else "a cycle")
            moves = (f"the {length_text(dist[0])} move" if len(dist) == 1 else
                     f"{len(h)} of {n} moves, from {length_range(dist[0], dist[-1])},")
            sm = self.spec_move
            own = ("" if sm is None or sm.hunts else
                   f"; after the spec's own motion it {_OWN_MOTION[sm.outcome]}"
                   + (f" ({sm.reason})" if sm.outcome == "undetermined" and sm.reason else ""))
            end = "ends" if len(dist) == 1 else "end"
            return f"{label} hunts at {number(fc, 4)} Hz: {moves} {end} in {cyc}{own}"
        if self.outcome == "stuck":
            m = self._first_bad()
            return (f"{label} sticks at {number(fc, 4)} Hz: after the {length_text(abs(m.distance))} move it "
                    f"rests {length_text(abs(m.final_error))} from its target ({m.reason})")
        if self.outcome == "undetermined":
            m = next(m for m in self.moves if m.outcome == "undetermined")
            return (f"{label} cannot be judged at {number(fc, 4)} Hz after the {length_text(abs(m.distance))} move: "
                    f"{m.reason}")
        if self.outcome == "static_error":
            worst = max(abs(m.final_error) for m in self.moves)
            return (f"{label} comes to rest at {number(fc, 4)} Hz after all {n} moves, at most "
                    f"{length_text(worst)} from the target, within the {STATIC_ERROR_FORMULA} = "
                    f"{length_text(self.static_error_bound)} that static friction can hold against a "
                    "loop without integrator")
        return f"{label} comes to rest at its target at {number(fc, 4)} Hz after all {n} moves"

    def to_dict(self) -> dict:
        """The contract's form: ``hunts``, ``moves_tried``, ``moves_hunting``,
        ``entered_by``, ``cycle``, ``hunting_free_from``, plus the moves."""
        return {
            "plant": self.plant, "crossover": self.crossover, "hunts": self.hunts,
            "outcome": self.outcome, "acceptable": self.acceptable,
            "moves_tried": len(self.moves),
            "moves_hunting": len(self.hunting_moves), "entered_by": list(self.entered_by),
            "cycle": None if self.cycle is None else self.cycle.to_dict(),
            "other_cycles": [c.to_dict() for c in self.other_cycles],
            "hunting_free_from": to_jsonable(self.hunting_free_from),
            "boundary": None if self.boundary is None else self.boundary.to_dict(),
            "first_only": self.first_only,
            "moves": [m.to_dict() for m in self.moves]}
