"""The design space of a recommendation: the base, the stroke envelope, the crossover, a candidate.

A candidate is a buildable isolator: a leaf-spring guide drawn from stock
(leaves, length, width, thickness) with its stroke, at a crossover. It is
written into the spec as values at dotted paths (:meth:`Candidate.values`)
and resolved once into its model (:meth:`Candidate.model`), so the design
command on the written spec runs the same computation: the guide drawn, its drive stiffness its own (net of gravity), its own computed
modes (the spec's measured modes that belong to the spec's own guide are
dropped; a ``structure`` mode stays, the stage's structure does not change
with the guide).

:func:`base_model` gives the model the search starts from: with the spec's
isolator, or the guideline's suggestion when it has none, and with the spec's
flexure section, or an assumed steel leaf-spring guide (:data:`ASSUMED_FLEXURE`)
when it has none, so that every candidate is a mechanism that can be built.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from .. import spec as _spec
from ..display import quantity
from ..model import Model

__all__ = ["ASSUMED_FLEXURE", "STROKE_FLOOR", "STROKE_SPAN", "Candidate", "base_model",
           "stroke_envelope", "damping_ratio"]

#: The guide assumed for a spec without ``isolator.flexure``: two spring-steel leaves standing
#: under the stage, sized from 0.05 mm stock within the spec's default bounds.
ASSUMED_FLEXURE = {"material": {"youngs_modulus": 200e9, "allowed_stress": 300e6,
                                "density": 7800.0},
                   "leaves": 2, "orientation": "standing"}

#: Shortest stroke a recommendation proposes [m]: an end-stop gap below it is hard to set and
#: to keep (tolerances, thermal drift).
STROKE_FLOOR = 0.05e-3

#: First stroke range searched: a factor either way of the spec's stroke [-]; widened to the
#: envelope when the best design lies on its edge.
STROKE_SPAN = 3.0


def base_model(model: Model) -> tuple[Model, tuple[str, ...]]:
    """The model the search starts from, and what it assumed.

    Parameters
    ----------
    model : Model
        The spec as written, resolved.

    Returns
    -------
    (Model, tuple of str)
        The model with an isolator (its own, or the guideline's suggestion)
        and a flexure section (its own, or :data:`ASSUMED_FLEXURE`), varied
        once (:meth:`~fi_design.model.Model.varied`); the assumptions in words.
    """
    assumed = []
    values: dict[str, Any] = {}
    if not model.has_isolator:
        from ..guideline.steps import suggested_isolator

        s, k = suggested_isolator(model)
        values["isolator"] = {"stroke": s, "stiffness": k}
        assumed.append("no isolator in the spec: the search starts from the guideline's "
                       "suggestion")
    if model.flexure_spec is None:
        if "isolator" in values:
            values["isolator"]["flexure"] = ASSUMED_FLEXURE
        else:
            values["isolator.flexure"] = ASSUMED_FLEXURE
        assumed.append("no isolator.flexure in the spec: a guide of two spring-steel leaves "
                       "(E 200 GPa, 300 MPa allowed, from 0.05 mm stock) standing under the "
                       "stage is assumed")
    return (model.varied(values) if values else model), tuple(assumed)


def damping_ratio(model: Model) -> float | None:
    """The joint damping ratio the spec's damping gives (None: the default ratio applies)."""
    iso = model.spec.isolator
    if iso is None or iso.damping is None:
        return None
    return model.joint_damping_ratio


def stroke_envelope(base: _spec.Spec) -> tuple[float, float, str, str]:
    """The strokes a guide can be built for, and what bounds them [m].

    The shortest: ``requirements.recommend.stroke`` or :data:`STROKE_FLOOR`.
    The longest: the bound, else the stroke at which the longest, thinnest
    leaf of the flexure's bounds reaches its allowed stress.

    Returns
    -------
    (lo, hi, why_lo, why_hi)
    """
    b = base.requirements.recommend
    flex = base.isolator.flexure
    if b.stroke is not None:
        return (b.stroke[0], b.stroke[1], "the shortest stroke of requirements.recommend.stroke",
                "the longest stroke of requirements.recommend.stroke")
    from ..mechanism.leaf import stroke_limit

    L1 = flex.bounds("length")[1]
    t0 = flex.bounds("thickness")[0]
    step = flex.thickness_step
    if step is not None:
        t0 = max(t0, math.ceil(t0 / step - 1e-9) * step)
    m = flex.material
    hi = float(stroke_limit(m.allowed_stress, m.youngs_modulus, t0, L1))
    return (STROKE_FLOOR, max(hi, STROKE_FLOOR),
            f"the shortest stroke worth a limiter ({quantity(STROKE_FLOOR, 'm', 6)})",
            "the stress of the longest, thinnest leaf the flexure's bounds allow")


@dataclass(frozen=True)
class Candidate:
    """A buildable isolator at a crossover (SI).

    Attributes
    ----------
    stroke : float
        One-sided stroke [m].
    length, width, thickness : float
        The guide's leaf dimensions [m].
    stiffness : float
        The guide's net drive stiffness [N/m] (gravity included).
    crossover : float
        The loop's crossover [Hz].
    damping : float or None
        Joint damping [N s/m] (the spec's damping ratio kept), or None for
        the default ratio.
    """

    stroke: float
    length: float
    width: float
    thickness: float
    stiffness: float
    crossover: float
    damping: float | None = None

    def values(self, base: _spec.Spec, rule: bool) -> dict[str, Any]:
        """The candidate as spec values at dotted paths (SI), for :meth:`Model.varied`."""
        iso = base.isolator
        out: dict[str, Any] = {
            "isolator.stroke": self.stroke, "isolator.stiffness": None,
            "isolator.flexure.length": self.length, "isolator.flexure.width": self.width,
            "isolator.flexure.thickness": self.thickness,
        }
        if self.damping is not None:
            out["isolator.damping"] = self.damping
        kept = [m.model_dump(exclude_none=True) for m in iso.parasitic_modes
                if m.direction == "structure"]
        if len(kept) != len(iso.parasitic_modes):
            out["isolator.parasitic_modes"] = kept
        if rule:
            out["controller.crossover"] = self.crossover
        return out

    def model(self, base: Model, rule: bool) -> Model:
        """The base model with the candidate written into its spec, validated and resolved once
        (:meth:`~fi_design.model.Model.varied`): every judgement of the candidate reads it."""
        return base.varied(self.values(base.spec, rule))
