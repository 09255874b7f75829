"""What makes one design better than another, what binds the best one, and the trade-off.

The objective: the stiffest joint that keeps the hunting margin. "Lower is
better" holds for hunting only; the guide's support stiffness, its modes,
gravity and handling all want the joint stiff. Among designs the margin
admits, the stiffer one wins, then the one with more margin (:func:`order`).
"""

from __future__ import annotations

import math
from typing import Any

from ..display import number, quantity

__all__ = ["order", "nearest", "pareto", "binding", "advice", "STATUS_WORDS"]

#: The statuses in words, for what binds.
STATUS_WORDS = {
    "robustness": "the robustness under scatter", "reserve": "a reserve corner",
    "checks": "a check of the sign-off", "margin": "the hunting margin",
    "hunts": "hunting at the crossover", "margins": "the loop's margins with their reserve",
    "flexure": "building the guide", "k_max": "k_max = Fs / stroke",
    "bounds": "the bounds of requirements.recommend",
}

#: How far each status is from feasible (the nearest design has the smallest): a design
#: that keeps the hunting margin and fails the sign-off (robustness, a reserve corner, a
#: check) is nearer than one that misses the margin.
_DISTANCE = {"feasible": 0, "robustness": 1, "reserve": 1, "checks": 2, "margin": 3,
             "margins": 3, "hunts": 3, "flexure": 4, "k_max": 5, "bounds": 6,
             "not_evaluated": 7, "failed": 8, None: 7}
#: Statuses that miss the hunting margin: among them more margin is nearer.
_SHORT_OF_MARGIN = ("margin", "margins", "hunts")


def _dimensions(c: Any) -> str:
    """A leaf's length x width x thickness [m] in one unit: ``40 x 10 x 0.5 mm``."""
    return quantity((c.length, c.width, c.thickness), "m", 3, joiner=" x ")


def order(p: Any) -> tuple:
    """The objective as a sort key, larger is better: stiffness, then hunting margin."""
    m = p.margin if p.margin is not None else 0.0
    return (round(math.log(p.stiffness), 3), min(m, 1e9))


def nearest(points: list) -> Any:
    """With none feasible: the point closest to feasible.

    Among the points of the nearest status, those short of the hunting margin
    are ranked by their margin (then the stiffer); the others by the objective
    (the stiffer, then the margin): they kept the margin, and what they miss
    (the guide's sag on a vertical axis, its modes, a reserve) a stiffer joint
    misses less. Ranked by margin alone, the softest design that sags past its
    stroke was the nearest of a vertical axis (12.6 mm of sag on a 2.92 mm
    stroke, beside one sagging 0.93 mm on 0.9 mm).
    """
    def key(p: Any) -> tuple:
        margin = min(p.margin, 1e9) if p.margin is not None else 0.0
        if p.status in _SHORT_OF_MARGIN:
            return (_DISTANCE[p.status], -margin, -p.stiffness)
        return (_DISTANCE.get(p.status, 7), -round(math.log(p.stiffness), 3), -margin)

    return min(points, key=key)


def pareto(points: list) -> tuple[dict, ...]:
    """The judged designs no other beats on both joint stiffness and hunting margin.

    Returns
    -------
    tuple of dict
        ``stroke`` [m], ``stiffness`` [N/m], ``hunting_margin`` [-] (None:
        no cycle at any crossover), ``lowest_mode`` [Hz], ``status``;
        stiffest first.
    """
    judged = [p for p in points if p.candidate is not None and p.margin]  # hunting: no design
    front = []
    for p in judged:
        mp = min(p.margin, 1e9)
        if not any(q is not p and q.stiffness >= p.stiffness and min(q.margin, 1e9) >= mp
                   and (q.stiffness > p.stiffness or min(q.margin, 1e9) > mp) for q in judged):
            front.append(p)
    front.sort(key=lambda p: -p.stiffness)
    return tuple({"stroke": p.stroke, "stiffness": p.stiffness,
                  "hunting_margin": None if math.isinf(p.margin) else p.margin,
                  "lowest_mode": p.lowest_mode, "status": p.status} for p in front)


def _why(p: Any) -> str:
    word = STATUS_WORDS.get(p.status, p.status)
    return word + (f" ({p.violations[0].rstrip('.')})" if p.violations else "")


#: Statuses of a point nothing is known against: signed off, or kept the margin and not
#: signed off because a stiffer design was (every other status fails a constraint).
_KEPT = ("feasible", "not_evaluated")


def _neighbour(search: Any, stroke: float, side: str) -> str | None:
    """Why a neighbouring stroke gives no stiffer joint than the chosen one.

    k_max = Fs / stroke rises at a shorter stroke and falls at a longer one; what
    stops the joint there is said with the numbers of that stroke's own points:
    the stiffest that keeps the margin (``kept``) and the softest stiffer one that
    fails (``fails``), or, where none is kept, the stiffest judged and why it fails.
    """
    from .. import spec as _spec

    row = sorted((p for p in search.points if p.stroke == stroke), key=lambda p: p.target)
    if not row:
        return None
    kmax = _spec.stiffness_limit(search.base, stroke)
    head = (f"a {side} stroke ({quantity(stroke, 'm')}) "
            f"{'raises' if side == 'shorter' else 'lowers'} k_max to {quantity(kmax, 'N/m', 4)}")
    kept = max((p for p in row if p.status in _KEPT), key=lambda p: p.stiffness, default=None)
    if kept is None:
        judged = [p for p in row if p.candidate is not None] or row
        worst = max(judged, key=lambda p: p.stiffness)
        return (f"{head}, but no joint there passes: {quantity(worst.stiffness, 'N/m', 4)} "
                f"fails on {_why(worst)}")
    fails = next((p for p in row if p.status not in _KEPT and p.target > kept.target), None)
    text = f"the stiffest joint there that keeps the margin is {quantity(kept.stiffness, 'N/m', 4)}"
    if fails is None:
        return f"{head}, and {text}"
    return (f"{head}, but {text}: {quantity(fails.stiffness, 'N/m', 4)} fails on "
            f"{_why(fails)}")


def binding(search: Any, chosen: Any) -> tuple[str, ...]:
    """What stops a stiffer joint than the chosen one, each a physical limit.

    At the chosen stroke: the next stiffer point judged (the hunting margin,
    the guide, k_max); across strokes: why the stiffest design of each
    neighbouring stroke is softer; the envelope of strokes when the chosen one
    lies at it; the crossover's own limit.
    """
    out: list[str] = []
    row = sorted((p for p in search.points if p.stroke == chosen.stroke),
                 key=lambda p: p.target)
    stiffer = [p for p in row if p.target > chosen.target * (1 + 1e-9)]
    from .. import spec as _spec

    kmax = _spec.stiffness_limit(search.base, chosen.stroke)
    high = chosen.thickest
    if chosen.stiffness >= 0.97 * kmax:
        out.append(f"k_max = Fs / stroke = {quantity(kmax, 'N/m', 4)} at "
                   f"{quantity(chosen.stroke, 'm')} stroke")
    elif high is not None and high >= 0.97 * kmax:
        dt = search.base_model.flexure_spec.thickness_tolerance
        thick = quantity(chosen.candidate.thickness + dt, "m", 3, shown=("mm", 1e3))
        out.append(f"k_max = Fs / stroke = {quantity(kmax, 'N/m', 4)} at "
                   f"{quantity(chosen.stroke, 'm')} stroke, which leaves of the stock's "
                   f"thickest ({thick}) reach")
    elif stiffer:
        out.append(f"what fails a stiffer joint ({quantity(stiffer[0].target, 'N/m', 4)}) at "
                   f"{quantity(chosen.stroke, 'm')} stroke: {_why(stiffer[0])}")
    strokes = sorted({p.stroke for p in search.points})
    i = strokes.index(chosen.stroke)
    for j, side in ((i - 1, "shorter"), (i + 1, "longer")):
        if 0 <= j < len(strokes):
            text = _neighbour(search, strokes[j], side)
            if text is not None:
                out.append(text)
    lo, hi = search.envelope
    if chosen.stroke <= lo * (1 + 1e-9):
        out.append(f"the stroke at {search.why_lo}")
    if chosen.stroke >= hi * (1 - 1e-9):
        out.append(f"the stroke at {search.why_hi}")
    if search.rule:
        out.append(f"the crossover {quantity(search.fc, 'Hz', 4)}: {search.fc_why}")
    return tuple(out)


def advice(search: Any, chosen: Any, feasible: bool, binding: tuple[str, ...],
           least: Any, bounds: tuple = ()) -> str:
    """One sentence a person acts on (and, for a guide on a bound the user set past which the
    sizing finds more margin, that bound: ``bounds``, :class:`~fi_design.results.steps.BoundNote`)."""
    c = chosen.candidate
    if feasible:
        text = (f"Build {_dimensions(c)} leaves for a {quantity(chosen.stroke, 'm')} stroke (k = "
                f"{number(chosen.stiffness, 4)} N/m with gravity)"
                + (f" and tune the loop to {quantity(search.fc, 'Hz', 4)}" if search.rule else "")
                + (f": no move hunts from {quantity(chosen.free_from, 'Hz', 4)}, "
                   f"{number(chosen.margin, 3)} x below the crossover" if chosen.free_from else
                   ": no move of the family hunts")
                + (f"; what binds it: {binding[0]}" if binding else "") + ".")
        for n in (n for n in bounds if n.adds_margin):
            text += (f" The leaves' {n.dimension} sits on the {n.side} bound of "
                     f"{n.key}; past it the guide would have more margin.")
        if least is not None and least.feasible:
            text += f" The least change that passes: {least.text}."
        return text
    text = (f"No design of the searched space passes; the nearest "
            f"({quantity(chosen.stroke, 'm')}, {quantity(chosen.stiffness, 'N/m', 4)}, "
            f"{quantity(search.fc, 'Hz', 4)}) fails on {_why(chosen)}.")
    if least is not None and least.feasible:
        text += f" The least change that passes: {least.text}."
    return text
