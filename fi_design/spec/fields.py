"""The spec's field types: quantities with units, plain text, the strict base model.

Every physical field accepts an SI number or a string with units
(:func:`fi_design.spec.units.to_si`, at this boundary only) and holds an SI float.
"""

from __future__ import annotations

import typing
from typing import Annotated, Any, Union

from pydantic import (AfterValidator, BaseModel, BeforeValidator, ConfigDict, ValidationInfo,
                      WithJsonSchema, field_validator)

from ..display import code_point
from .units import to_si


# --------------------------------------------------------------------------- quantities


def _parser(unit: str):
    def parse(value: Any) -> Any:
        if value is None:
            return None
        return to_si(value, unit)

    return parse


def Q(unit: str, **schema: Any):
    """A float field holding a quantity converted to ``unit`` (SI, Hz, deg or dB)."""
    shown = {"deg": "degree", "dB": "decibel", "1": "dimensionless"}.get(unit, unit)
    json = {"anyOf": [{"type": "number"}, {"type": "string"}], "x-unit": shown} \
        if unit not in ("deg", "dB") else {"type": "string", "x-unit": shown}
    json.update(schema)
    return Annotated[float, BeforeValidator(_parser(unit)), WithJsonSchema(json)]


def OptQ(unit: str):
    """Like :func:`Q` but ``null`` allowed."""
    shown = {"deg": "degree", "dB": "decibel", "1": "dimensionless"}.get(unit, unit)
    json = {"anyOf": [{"type": "number"}, {"type": "string"}, {"type": "null"}], "x-unit": shown}
    return Annotated[Union[float, None], BeforeValidator(_parser(unit)), WithJsonSchema(json)]


def _plain_text(value: str) -> str:
    """Refuse control characters in text (a ``"\\u0000"`` escape, terminal escapes): tabs and
    line breaks are the only ones text may hold."""
    for char in value:
        code = ord(char)
        if (code < 32 and char not in "\t\n\r") or 127 <= code < 160:
            raise ValueError(f"control character {code_point(code)} is not allowed in text (read "
                             f"{value!r}); write plain text")
    return value


#: A text field of the spec: plain text, control characters refused.
Text = Annotated[str, AfterValidator(_plain_text)]


def _numeric(annotation: Any) -> bool:
    """Whether a field's type takes numbers and no yes/no value (``int``, ``float``, a
    quantity, optional or not)."""
    origin = typing.get_origin(annotation)
    if origin is Annotated:
        return _numeric(typing.get_args(annotation)[0])
    if origin is Union:
        arms = [arm for arm in typing.get_args(annotation) if arm is not type(None)]
        return bool(arms) and all(_numeric(arm) for arm in arms)
    return annotation in (int, float)


class StrictModel(BaseModel):
    """Base of every spec section: unknown keys are errors, values immutable and finite."""

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False,
                              str_strip_whitespace=True)

    @field_validator("*", mode="before")
    @classmethod
    def _no_yes_no_for_a_number(cls, value: Any, info: ValidationInfo) -> Any:
        """A yes/no value (YAML's true or false) given to a number is refused, not read as
        1 or 0 (``samples: true`` would run one sample)."""
        if isinstance(value, bool) and info.field_name is not None \
                and _numeric(cls.model_fields[info.field_name].annotation):
            raise ValueError(f"expected a number, got {str(value).lower()} (a yes/no value in "
                             "YAML)")
        return value
