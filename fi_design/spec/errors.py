"""From pydantic's validation errors to messages: the dotted path, the value, the unit.

:func:`describe` turns one validation error of a spec into ``(path, message)``:
the dotted field path (``friction.static``, ``effects[0].delay``), what was
read and why it is refused, with a suggestion for a misspelt key. Reading
a file (:mod:`fi_design.spec.file`) and changing values at dotted paths
(:mod:`fi_design.spec.paths`) both report through it.
"""

from __future__ import annotations

import difflib
import re
from typing import Any

from ..display import number
from . import Spec
from .units import huge, shown_digits


def clean_loc(loc: tuple, raw: dict) -> tuple:
    """Drop union tags that pydantic inserts (``effects.0.time_delay.delay``,
    ``controller.filters.0.notch.width``, a value-or-range's ``tuple[...]``).

    The tag is the entry's own ``type`` right after its index, even where a
    parameter has the effect's name (``effects.0.stribeck_velocity.stribeck_velocity``).
    """
    out: list = []
    node: Any = raw
    tagged = False
    for part in loc:
        if isinstance(part, str) and not part.isidentifier() \
                and not (isinstance(node, dict) and part in node):
            # a union member's tag: "tuple[...]", "function-before[parse(), float]"; a key
            # the user wrote ("stribeck-velocity", "static friction") is no tag
            continue
        if isinstance(node, dict) and isinstance(part, str) and not tagged and len(out) >= 2 \
                and isinstance(out[-1], int) and out[-2] in ("effects", "filters") \
                and node.get("type") == part:
            tagged = True
            continue
        tagged = False
        out.append(part)
        if isinstance(node, dict):
            node = node.get(part)
        elif isinstance(node, list) and isinstance(part, int) and part < len(node):
            node = node[part]
        else:
            node = None
    return tuple(out)


def _value_at(loc: tuple, raw: Any) -> Any:
    """The value of the validated data at ``loc`` (None where it has none)."""
    node = raw
    for part in loc:
        if isinstance(node, dict):
            node = node.get(part)
        elif isinstance(node, (list, tuple)) and isinstance(part, int) and part < len(node):
            node = node[part]
        else:
            return None
    return node


def dotted(loc: tuple) -> str:
    """A location as a dotted path: ``("motion", "moves", 0, "distance")`` is
    ``motion.moves[0].distance``."""
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += ("." if out else "") + str(part)
    return out


def _model_at(loc: tuple, raw: Any = None):
    """The pydantic model class that holds the field at ``loc`` (None if unknown).

    An entry of ``effects`` is the model of its ``type`` in ``raw`` (the
    mapping as written), so its keys and units are that effect's.
    """
    import typing

    from . import EFFECT_MODELS, FILTER_TYPES

    model: Any = Spec
    node: Any = raw
    for n, part in enumerate(loc[:-1]):
        node = node.get(part) if isinstance(node, dict) and not isinstance(part, int) else \
            node[part] if isinstance(node, list) and isinstance(part, int) \
            and part < len(node) else None
        if isinstance(part, int):
            if n >= 1 and loc[n - 1] in ("effects", "filters"):
                kind = node.get("type") if isinstance(node, dict) else None
                models = EFFECT_MODELS if loc[n - 1] == "effects" else FILTER_TYPES
                model = models.get(kind) if isinstance(kind, str) else None
                if model is None:
                    return None
            continue
        if not (isinstance(model, type) and hasattr(model, "model_fields")):
            return None
        info = model.model_fields.get(part)
        if info is None:
            return None
        model = _inner_model(info.annotation, typing)
    return model if isinstance(model, type) and hasattr(model, "model_fields") else None


def _inner_model(ann, typing):
    if isinstance(ann, type) and hasattr(ann, "model_fields"):
        return ann
    for arg in typing.get_args(ann):
        m = _inner_model(arg, typing)
        if m is not None:
            return m
    return None


def real_errors(errors: list[dict]) -> list[dict]:
    """The validation errors without those another one causes.

    A sequence with a minimum length (``motion.moves``) whose items fail is
    also "too short" to pydantic, which counts the items that passed; the
    entries as written are enough, so only the items' own errors are real.

    Parameters
    ----------
    errors : list of dict
        ``ValidationError.errors()``.

    Returns
    -------
    list of dict
        The same errors, in order, without the consequential ones.
    """
    def caused(err: dict) -> bool:
        if err["type"] != "too_short":
            return False
        given, least = err.get("input"), (err.get("ctx") or {}).get("min_length")
        loc = tuple(err["loc"])
        inner = any(tuple(o["loc"])[:len(loc)] == loc and len(o["loc"]) > len(loc)
                    for o in errors)
        return inner and least is not None and hasattr(given, "__len__") and len(given) >= least

    def field(err: dict) -> tuple:
        """The location up to a union member's tag ("tuple[...]", "function-before[...]")."""
        loc = tuple(err["loc"])
        tag = next((n for n, p in enumerate(loc) if isinstance(p, str) and not p.isidentifier()),
                   None)
        return loc if tag is None else loc[:tag]

    def other_branch(err: dict) -> bool:
        # a value-or-range (a value or [min, max]) tried both: the branch that does not take
        # the input's shape (the range for a scalar, the value for a list) is no problem of
        # its own where the other branch has one
        loc, base = tuple(err["loc"]), field(err)
        if len(loc) != len(base) + 1 or not any(
                field(o) == base and tuple(o["loc"]) != loc for o in errors):
            return False
        listed = isinstance(err.get("input"), (list, tuple))
        return (err["type"] == "tuple_type" and not listed) or \
            (not str(loc[-1]).startswith("tuple[") and listed)

    kept = [e for e in errors if not caused(e) and not other_branch(e)]
    return kept or errors


def describe(err: dict, raw: dict) -> tuple[str, str]:
    """One pydantic validation error of a spec as ``(dotted path, message)``.

    Parameters
    ----------
    err : dict
        One entry of ``ValidationError.errors()``.
    raw : dict
        The data that was validated (to read the value and the section at the path).

    Returns
    -------
    (str, str)
        The dotted path (empty for the top level) and the message: what was
        read, why it is refused, with a suggestion for a misspelt key.
    """
    from .. import effects as _effects

    loc = clean_loc(err["loc"], raw)
    path = dotted(loc)
    kind = err["type"]
    msg = err["msg"]
    if kind == "missing" and loc and isinstance(loc[-1], int):  # a fixed list too short
        given = _value_at(loc[:-1], raw)
        count = len(given) if isinstance(given, (list, tuple)) else 0
        return dotted(loc[:-1]), (f"too few values: the list gives {count}, value "
                                  f"{loc[-1] + 1} is missing")
    if kind == "missing":
        model = _model_at(loc, raw)
        desc = ""
        if model is not None and loc and loc[-1] in model.model_fields:
            desc = model.model_fields[loc[-1]].description or ""
        return path, "required field is missing" + (f" ({desc})" if desc else "")
    if kind == "extra_forbidden":
        model = _model_at(loc, raw)
        key = loc[-1] if loc else ""
        hint = ""
        if model is not None:
            close = difflib.get_close_matches(str(key), list(model.model_fields), n=1)
            hint = f"; did you mean '{close[0]}'?" if close else \
                f"; allowed: {', '.join(model.model_fields)}"
        return path, f"unknown key '{key}'{hint}"
    if kind == "unknown_effect":
        if not isinstance(err.get("input"), dict):
            return path, _not_an_effect_entry(err.get("input"))
        given = err["input"].get("type")
        if given is None:  # no `type:` key, or one without a value
            return path + ".type", (f"required field is missing (the effect's type, one of: "
                                    f"{', '.join(_effects.EFFECT_NAMES)})")
        close = difflib.get_close_matches(str(given), list(_effects.EFFECT_NAMES), n=1)
        hint = f" (did you mean '{close[0]}'?)" if close else ""
        return path + ".type", (f"unknown effect '{given}'{hint}; known: "
                                f"{', '.join(_effects.EFFECT_NAMES)}")
    if kind == "value_error":
        text = msg.removeprefix("Value error, ")
        named = _NAMED.match(text) if not path else None
        if named and named.group(1).split(".")[0].split("[")[0] in Spec.model_fields:
            return named.group(1), named.group(2)
        return path, text
    if kind in ("greater_than", "greater_than_equal", "less_than", "less_than_equal"):
        unit = _unit_at(loc, raw)
        bound = list(err.get("ctx", {}).values())[0]
        words = {"greater_than": "greater than", "greater_than_equal": "at least",
                 "less_than": "less than", "less_than_equal": "at most"}[kind]
        shown = f" {unit}" if unit not in ("", "1") else ""
        written = _value_at(loc, raw)  # as the user wrote it ('-0.3 mm'), not in SI
        given = written if isinstance(written, str) else err["input"]
        return path, f"must be {words} {number(bound, 6)}{shown}, got {_shown(given)}"
    if kind in ("too_short", "too_long"):
        ctx = err.get("ctx") or {}
        given = ctx.get("actual_length")
        if kind == "too_short":
            return path, (f"needs at least {_items(ctx.get('min_length'), loc)}, got "
                          f"{given or 'none'}")
        return path, f"takes at most {_items(ctx.get('max_length'), loc)}, got {given}"
    if kind in ("finite_number",):
        return path, "must be a finite number"
    if huge(err.get("input")):
        return path, f"the number {shown_digits(err['input'])} is too large"
    if kind in ("float_type", "float_parsing"):
        given = err["input"]
        if isinstance(given, str) and _unit_at(loc, raw) == "":
            return path, f"is a plain number [-], written without a unit; got {_plain(given)}"
        return path, f"expected a number or a string with units, got {_shown(given)}"
    if kind == "string_type" and isinstance(err["input"], (int, float)) \
            and not isinstance(err["input"], bool):
        return path, (f"is text; YAML read {_shown(err['input'])} as a number: write it in "
                      f"quotes as you mean it, e.g. '{_shown(err['input'])}'")
    if kind in ("model_type", "model_attributes_type", "dict_type"):
        model = _model_at(loc + ("x",), raw)
        keys = ", ".join(model.model_fields) if model is not None else ""
        return path, (f"expected a mapping{' with keys ' + keys if keys else ''}, got "
                      f"{_shown(err['input'])}")
    return path, msg


def _items(count: Any, loc: tuple) -> str:
    """``count`` entries of the list at ``loc`` in words: ``one move``, ``4 filters``."""
    key = next((str(p) for p in reversed(loc) if isinstance(p, str)), "")
    item = key[:-1].replace("_", " ") if key.endswith("s") else "value"
    return f"one {item}" if count == 1 else f"{count} {item}s"


def _shown(value: Any) -> str:
    """A value read from the spec, for a message: its repr, cut to 40 characters."""
    if huge(value):
        return f"the number {shown_digits(value)}"
    text = repr(value)
    return text if len(text) <= 40 else text[:28] + "..." + text[-8:]


def _plain(given: str) -> str:
    """A string given to a plain-number field, with the number it means where it is a
    percentage (``'20 %'``: write 0.2; a decibel is no plain ratio of one meaning)."""
    from .units import to_si

    try:
        meant = to_si(given, "1") if given.rstrip().endswith("%") else None
    except Exception:  # not one number and its percent sign: nothing to suggest
        meant = None
    if meant is None:
        return _shown(given)
    return f"{_shown(given)}: write {number(meant, 6)}"


def _not_an_effect_entry(given: Any) -> str:
    """The message for an ``effects`` entry that is not a mapping (``- time_delay``)."""
    from .. import effects as _effects

    name = given if isinstance(given, str) and given in _effects.CATALOGUE else "time_delay"
    required = [p.name for p in _effects.get(name).parameters if p.required]
    example = "{type: " + name + "".join(f", {p}: ..." for p in required) + "}"
    return (f"an effect is a mapping with its type and parameters, e.g. {example}; got "
            f"{given!r}")


#: A top-level validator's message that names its field: ``"controller.crossover: ..."``.
_NAMED = re.compile(r"^([A-Za-z_][A-Za-z0-9_.\[\]=]*): (.+)$", re.S)


def _unit_at(loc: tuple, raw: Any = None) -> str:
    """The unit of the field at ``loc`` as its description states it (``[N/m]``); empty for
    none and for a dimensionless field (``[-]``), whose bounds are plain numbers."""
    model = _model_at(loc, raw)
    if model is None or not loc or loc[-1] not in model.model_fields:
        return ""
    desc = model.model_fields[loc[-1]].description or ""
    if "[" in desc and "]" in desc:
        unit = desc[desc.rindex("[") + 1: desc.rindex("]")]
        return "" if unit in ("-", "1") else unit
    return ""
