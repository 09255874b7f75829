"""The spec as a whole: its sections, the effects list, the checks across sections.
"""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal, Union

from pydantic import Discriminator, Field, PrivateAttr, Tag, create_model, model_validator

from .. import effects as _effects
from ..display import number, percent, quantity, unit_text
from ..provenance import json_sha256
from .defaults import CROSSOVER_AGREEMENT, gains_crossover, tuning_mass
from .fields import OptQ, Q, StrictModel, Text
from .requirements import Requirements
from .sections import (MAX_OUTPUT_SAMPLES, Body, Controller, Stage, Friction, Isolator, Measurement,
                       Motion, ReportInfo, Simulation)


# --------------------------------------------------------------------------- effects


def _effect_model(effect: _effects.Effect):
    fields: dict[str, Any] = {"type": (Literal[effect.name], Field(description=effect.description))}
    for p in effect.parameters:
        kind = p.unit
        shown = unit_text(kind) or "-"  # as every output writes it: N·s/m
        limits = dict(p.limits)
        if p.required:
            fields[p.name] = (Q(kind), Field(description=f"{p.description} [{shown}].",
                                             **limits))
        else:
            fields[p.name] = (OptQ(kind), Field(None, description=f"{p.description} [{shown}]. "
                                                                  "Optional.", **limits))
    model = create_model("Effect_" + effect.name, __base__=StrictModel, **fields)
    model.__doc__ = effect.description
    return model


EFFECT_MODELS = {name: _effect_model(e) for name, e in _effects.CATALOGUE.items()}
# Module attributes under their own names, so that specs with effects pickle (process pools).
globals().update({m.__name__: m for m in EFFECT_MODELS.values()})


def _effect_tag(value: Any) -> str | None:
    if isinstance(value, dict):
        return value.get("type")
    return getattr(value, "type", None)


EffectEntry = Annotated[
    Union[tuple(Annotated[m, Tag(n)] for n, m in EFFECT_MODELS.items())],
    Discriminator(_effect_tag, custom_error_type="unknown_effect",
                  custom_error_message="unknown effect type; known: " +
                  ", ".join(_effects.EFFECT_NAMES)),
]


# --------------------------------------------------------------------------- the spec


class Spec(StrictModel):
    """A friction-isolator design spec, values in SI (the keys: docs/interfaces.md)."""

    name: Text = Field("Unnamed stage", description="Project or stage name.")
    stage: Stage = Field(description="The actuated stage (m1, carries the sensor).")
    cart: Body = Field(description="The bearing cart (m2, friction acts on it).")
    friction: Friction
    isolator: Isolator | None = Field(None, description="Omit for a stage without isolator.")
    controller: Controller
    motion: Motion
    requirements: Requirements = Field(default_factory=Requirements)
    measurement: Measurement | None = None
    effects: tuple[EffectEntry, ...] = Field((), description="Effects added to the model, "
                                                             "from the effects catalogue "
                                                             "(fi-design schema --markdown "
                                                             "lists them).")
    report: ReportInfo = Field(default_factory=ReportInfo)
    simulation: Simulation = Field(default_factory=Simulation)

    #: Where the spec was read from (set by fi_design.spec.file.load_spec).
    _origin: Any = PrivateAttr(default=None)

    def sha256(self) -> str:
        """The spec's SHA-256, as every result's provenance writes it (``spec_sha256``).

        Returns
        -------
        str
            Hex digest of the file's bytes when the spec was read from a file
            (what ``sha256sum`` prints), of the mapping it was given as, else
            of its validated values (:meth:`content_sha256`).
        """
        return self._origin.sha256 if self._origin is not None else self.content_sha256()

    def content_sha256(self) -> str:
        """SHA-256 of the spec's validated values (every value, defaults included).

        Returns
        -------
        str
            Hex digest (:func:`fi_design.provenance.json_sha256`); equal for specs
            that simulate identically however they were written (units, key order,
            comments): the key of cached study points.
        """
        return json_sha256(self.model_dump(mode="json"))

    @model_validator(mode="after")
    def _consistent(self) -> "Spec":
        h = self.requirements.hunting
        end = h.window_start + h.window_length
        if end > self.motion.duration * (1 + 1e-9):
            # name the value the user gave: the window's start or length, else the duration
            given = [k for k in ("window_start", "window_length") if k in h.model_fields_set]
            where = f"requirements.hunting.{given[0]}" if given else "motion.duration"
            raise ValueError(f"{where}: the hunting window ends at {quantity(end, 's', 6)}, "
                             f"after motion.duration = {quantity(self.motion.duration, 's', 6)}")
        rate = self.simulation.output_rate
        samples = math.floor(self.motion.duration * rate + 1e-9) + 1
        if samples > MAX_OUTPUT_SAMPLES:
            where = "simulation.output_rate" if "output_rate" in self.simulation.model_fields_set \
                else "motion.duration"
            raise ValueError(f"{where}: {quantity(rate, 'Hz', 6)} over motion.duration = "
                             f"{quantity(self.motion.duration, 's', 6)} makes "
                             f"{number(float(samples), 3)} output samples; at "
                             f"most {MAX_OUTPUT_SAMPLES} fit in memory (about 150 bytes each): "
                             "lower simulation.output_rate or motion.duration")
        names = [e.type for e in self.effects]
        dupes = sorted({n for n in names if names.count(n) > 1})
        if dupes:
            raise ValueError(f"effects: effect listed twice: {', '.join(dupes)}")
        if "joint_damping" in names and self.isolator is None:
            raise ValueError("effects: effect joint_damping needs an isolator")
        flex = self.isolator.flexure if self.isolator is not None else None
        if flex is not None and self.stage.size is None and self.stage.inertia is not None:
            if flex.spacing is None:
                raise ValueError("isolator.flexure.spacing: needed when the stage is given by "
                                 "its inertia (without stage.size, which sets its default)")
            if flex.leaves == 4 and flex.lateral_spacing is None:
                raise ValueError("isolator.flexure.lateral_spacing: needed for 4 leaves when the "
                                 "stage is given by its inertia (without stage.size)")
        ctl = self.controller
        if ctl.gains is not None and ctl.crossover is not None:
            achieved = gains_crossover(self)
            if abs(achieved / ctl.crossover - 1.0) > CROSSOVER_AGREEMENT:
                raise ValueError(
                    f"controller.crossover: {quantity(ctl.crossover, 'Hz', 4)} contradicts "
                    f"controller.gains, which cross over at {quantity(achieved, 'Hz', 4)} on the "
                    f"tuning mass {quantity(tuning_mass(self), 'kg', 4)}; give one of the two, "
                    f"or a crossover within {percent(CROSSOVER_AGREEMENT, 2)} of the gains'")
        return self

    # convenience views, all SI
    @property
    def has_isolator(self) -> bool:
        """Whether the spec describes a stage with a friction isolator."""
        return self.isolator is not None

    @property
    def total_mass(self) -> float:
        """m1 + m2 [kg]."""
        return self.stage.mass + self.cart.mass

    def with_sections(self, **sections: Any) -> "Spec":
        """A new spec with whole sections replaced, validated again.

        Unlike pydantic's ``model_copy(update=...)``, which skips
        validation, the new spec passes every check of the spec (sections
        given as mappings are validated as in the YAML file, and the checks
        across sections run); the sections not named are shared. For single
        values at dotted paths, with units, use
        :func:`fi_design.spec.file.with_values`.

        Parameters
        ----------
        **sections
            Top-level section name (``isolator``, ``friction``, ``effects``,
            ...) to its new value: a validated section, a mapping in SI, or
            None to drop an optional section.

        Returns
        -------
        Spec
            A new spec without file origin.

        Raises
        ------
        SpecError
            An unknown section, or a value the spec refuses; the message
            names the path.

        Examples
        --------
        >>> from fi_design.spec.file import load_spec
        >>> spec = load_spec("examples/paper_setup.yaml")
        >>> spec.with_sections(isolator=None).has_isolator
        False
        """
        from pydantic import ValidationError

        from ..errors import SpecError

        fields = type(self).model_fields
        for name in sections:
            if name not in fields:
                raise SpecError(f"unknown section '{name}'; the spec has: {', '.join(fields)}",
                                path=name)
        data = {name: getattr(self, name) for name in self.model_fields_set}
        data.update(sections)
        try:
            return type(self).model_validate(data)
        except ValidationError as exc:
            err = exc.errors(include_url=False)[0]
            path = ".".join(str(p) for p in err["loc"]) or None
            raise SpecError(err["msg"].removeprefix("Value error, "), path=path) from None
