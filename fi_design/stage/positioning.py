"""The positioning requirement over the move family: settle time and static error per move.

``requirements.positioning`` asks what the stage is for. The stage-level runs
(:func:`fi_design.stage.stage_hunting`) say how each move ends and where it
rests; the settle time needs the trace: each move that comes to rest is
simulated again, from rest to the instant its run stopped, with the output
sampled at ``simulation.output_rate``, and the settle time is the last
instant |x1 - r| lies outside the band, counted from the end of the move. A
move that hunts, rests outside the band or was not judged never settles.
"""

from __future__ import annotations

import numpy as np

from ..model import Model, require_model
from ..results.positioning import MovePosition, PositioningResult
from ..results.stage import StageHunting
from .family import family_reference, spec_reference
from .runs import kernel_run, watch_array
from .settings import watch_settings

__all__ = ["positioning", "settle_time"]


def settle_time(time_s: np.ndarray, error_m: np.ndarray, band: float, move_end: float
                ) -> float | None:
    """Time after ``move_end`` from which |error| stays within ``band`` [s].

    Parameters
    ----------
    time_s : ndarray, shape (m,)
        Sample times [s], increasing.
    error_m : ndarray, shape (m,)
        x1 - r at those times [m].
    band : float
        Settle band [m].
    move_end : float
        End of the move [s].

    Returns
    -------
    float or None
        0 when the error is within the band from the move's end on; None when
        the last sample lies outside it (it never settles in the trace).

    Examples
    --------
    >>> t = np.array([0.0, 1.0, 2.0, 3.0]); e = np.array([5.0, 2.0, 0.5, 0.1])
    >>> settle_time(t, e, 1.0, 1.0)
    1.0
    """
    after = time_s >= move_end
    outside = np.nonzero(after & (np.abs(error_m) > band))[0]
    if outside.size and outside[-1] == len(time_s) - 1:
        return None
    if not outside.size:
        return 0.0
    return float(time_s[outside[-1] + 1] - move_end)


def positioning(model: Model, stage: StageHunting) -> PositioningResult | None:
    """Judge ``requirements.positioning`` over the moves of one plant's stage-level answer.

    Parameters
    ----------
    model : Model
        The resolved model (its spec's positioning requirement and settings).
    stage : StageHunting
        The plant's stage-level answer (its moves, in the order run).

    Returns
    -------
    PositioningResult or None
        None when the spec requires no positioning.
    """
    model = require_model(model)
    req = model.requirements.positioning
    if req is None:
        return None
    spec = model.spec
    iso = stage.plant == "isolated"
    band = req.band if req.band is not None else spec.requirements.hunting.settle_band
    p = model.plant(iso)
    w = watch_settings(model, p)
    dt = 1.0 / spec.simulation.output_rate
    moves = []
    for m in stage.moves:
        settle = error = None
        if m.outcome in ("settles", "rests", "stuck"):
            error = abs(m.final_error)
        if m.outcome in ("settles", "rests") and error <= band:
            if m.label == "spec":
                ref, end = spec_reference(spec, w.horizon)
            else:
                ref, end = family_reference(spec, m.distance, w.horizon)
            t_end = end + m.time
            t_out = np.arange(0.0, t_end + 0.5 * dt, dt)
            # a watch that starts after the run's end: no rule stops it
            out = kernel_run(p, np.zeros(p.n_states), ref, t_end,
                             watch_array(w, t_end + 1.0, ref.final, quiet=False),
                             w.tolerance, w.max_steps, t_out=t_out)
            if out.code == 0:
                err = out.states[:, 0] - out.reference
                settle = settle_time(t_out, err, band, end)
        ok = True
        if req.settle_time is not None:
            ok &= settle is not None and settle <= req.settle_time
        if req.static_error is not None:
            ok &= error is not None and error <= req.static_error
        moves.append(MovePosition(distance=m.distance, label=m.label, outcome=m.outcome,
                                  settle_time=settle, static_error=error, passed=bool(ok)))
    return PositioningResult(plant=stage.plant, band=band, settle_time_limit=req.settle_time,
                             static_error_limit=req.static_error, moves=tuple(moves),
                             resolution=dt)


def positioning_checks(result: PositioningResult) -> tuple:
    """The positioning requirement as the design's checks (step ``"positioning"``).

    Parameters
    ----------
    result : PositioningResult
        From :func:`positioning`.

    Returns
    -------
    tuple of fi_design.results.Check
        ``positioning.settle_time`` (the longest settle time against the
        limit) and ``positioning.static_error`` (the largest rest error),
        each only where required; FAIL names the moves that miss it.
    """
    from ..display import number, quantity
    from ..results import Check
    from ..results.stage import length_range, length_text

    out = []
    step = "positioning"
    n = len(result.moves)
    band = length_text(result.band)

    def which(bad) -> str:
        d = sorted(abs(m.distance) for m in bad)
        return (f"the {length_text(d[0])} move" if len(d) == 1 else
                f"{len(d)} of {n} moves, from {length_range(d[0], d[-1])},")

    if result.settle_time_limit is not None:
        lim = result.settle_time_limit
        never = [m for m in result.moves if m.settle_time is None]
        slow = [m for m in result.moves if m.settle_time is not None and m.settle_time > lim]
        worst = result.worst_settle_time
        if never:
            text = (f"{which(never)} never stay within \u00b1{band} of the target (they "
                    + ", ".join(sorted({_never_words(m) for m in never})) + ")")
            if slow:
                text += f"; {which(slow)} take longer than {number(lim, 3)} s"
        elif slow:
            text = (f"{which(slow)} take longer than {number(lim, 3)} s to stay within "
                    f"\u00b1{band}: up to {number(worst, 3)} s after the end of the move")
        else:
            text = (f"every move of the family ({n}) stays within \u00b1{band} of its target "
                    f"at most {number(worst, 3)} s after its end (limit {number(lim, 3)} s)")
        out.append(Check("positioning.settle_time", not (never or slow), worst, lim, "s",
                         text, step))
    if result.static_error_limit is not None:
        lim = result.static_error_limit
        worst = result.worst_static_error
        loose = [m for m in result.moves if m.static_error is None]
        far = [m for m in result.moves if m.static_error is not None and m.static_error > lim]
        big = max((m.static_error for m in result.moves if m.static_error is not None),
                  default=None)
        if loose or far:
            parts = []
            if far:
                parts.append(f"{which(far)} rest up to {quantity(big, 'm', 3)} from the target, "
                             f"beyond the {quantity(lim, 'm', 3)} allowed")
            if loose:
                parts.append(f"{which(loose)} do not come to rest")
            text = "; ".join(parts)
        else:
            text = (f"every move of the family ({n}) rests at most {quantity(worst, 'm', 3)} "
                    f"from its target (limit {quantity(lim, 'm', 3)})")
        out.append(Check("positioning.static_error", not (loose or far), big, lim, "m", text,
                         step))
    return tuple(out)


def _never_words(m: MovePosition) -> str:
    if m.outcome == "hunts":
        return "a cycle"
    if m.outcome == "undetermined":
        return "not judged"
    return "at rest outside the band"
