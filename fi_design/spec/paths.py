"""Values at dotted spec paths: read one, replace some and validate again, unit and meaning.

Parameter studies vary a spec by the dotted path of a value
(``controller.crossover``, ``motion.moves[0].distance``,
``effects[type=time_delay].delay``): :func:`with_values` replaces values and
validates the spec again, :func:`value_at` reads one, :func:`path_unit` and
:func:`path_description` give its SI unit and the schema's description.
"""

from __future__ import annotations

import difflib
import functools
import re
from typing import Any, Mapping

from ..display import number
from ..errors import SpecError
from . import Spec
from .errors import describe, real_errors

__all__ = ["with_values", "value_at", "path_unit", "path_description", "parse_path", "path_text",
           "split_assignment", "typed_readings"]


# --------------------------------------------------------------------------- dotted-path values
# (parameter studies: fi_design.studies varies spec values by their dotted path)

_PART = re.compile(r"^([A-Za-z_][A-Za-z0-9_]*)((?:\[[^\]]*\])*)$")
_SELECTOR = re.compile(r"\[([^\]]*)\]")
#: Units whose bare numbers the validators refuse (ambiguous): numbers are re-written with them.
_EXPLICIT_UNITS = {"degree": "deg", "deg": "deg", "rad": "rad", "decibel": "dB", "dB": "dB"}


def with_values(spec: Spec, values: Mapping[str, Any]) -> Spec:
    """Return a copy of ``spec`` with values replaced at dotted paths, re-validated.

    Parameters
    ----------
    spec : Spec
        The spec to start from; it is not changed.
    values : mapping of str to value
        Dotted path (as in the YAML file and in error messages:
        ``"friction.static"``, ``"isolator.stroke"``,
        ``"motion.moves[0].distance"``, ``"effects[type=time_delay].delay"``
        or ``"effects[0].delay"``) to the new value: an SI number or a string
        with units (``"0.3 mm"``), exactly as the YAML file would take it.

    Returns
    -------
    Spec
        A new validated spec. Sections that were not touched are shared with
        ``spec``; the new spec has no file origin.

    Raises
    ------
    SpecError
        An unknown path (with a suggestion for a misspelt key), a path into a
        section the spec does not have (``isolator.stroke`` of a stage without
        isolator), or a value the spec refuses (``friction.static`` below
        ``friction.coulomb``); the message names the path and the value.
    ArgumentError
        ``spec`` is no :class:`Spec` (:func:`fi_design.with_values`, which is
        :func:`fi_design.spec.file.with_values`, also reads a path or a
        mapping), or ``values`` is no mapping.

    Examples
    --------
    >>> from fi_design.spec.file import load_spec, with_values
    >>> spec = load_spec("examples/paper_setup.yaml")
    >>> with_values(spec, {"isolator.stroke": "0.5 mm"}).isolator.stroke
    0.0005
    """
    from pydantic import ValidationError

    from ..errors import ArgumentError

    if not isinstance(spec, Spec):
        raise ArgumentError("spec must be a Spec (read a path or a mapping with "
                            "fi_design.load_spec), got " + type(spec).__name__)
    if not isinstance(values, Mapping):
        raise ArgumentError("values must be a mapping of dotted path to value, such as "
                            "{'isolator.stroke': '0.5 mm'}, got " + type(values).__name__)
    root = _Open(spec)
    for path, value in values.items():
        _assign(root, str(path), _plain_value(value))
    data = root.plain()
    try:
        new = Spec.model_validate(data)
    except ValidationError as exc:
        errors = real_errors(exc.errors(include_url=False))
        where, text = describe(errors[0], data)
        given = ", ".join(f"{p} = {_show(v)}" for p, v in values.items())
        raise SpecError(f"{text} (with {given})", path=where or None) from None
    return new


def path_unit(path: str, spec: Spec | None = None) -> str:
    """The unit of the value at a dotted spec path.

    Parameters
    ----------
    path : str
        Dotted path, as for :func:`with_values`.
    spec : Spec, optional
        Needed only to resolve a list index into a list of typed entries
        (``effects[0]``, ``controller.filters[0]``); ``[type=NAME]``
        (``controller.filters[type=notch].frequency``) works without it.

    Returns
    -------
    str
        The unit the validated spec stores the value in: an SI unit such as
        ``"m"``, ``"N/m"`` or ``"N*s/m"``, or ``"Hz"``, ``"deg"``, ``"dB"``,
        ``"rad"``; ``"1"`` for plain numbers (ratios, counts) and ``""`` for
        values without a unit (text, flags).

    Raises
    ------
    SpecError
        Unknown path, or a path to a section rather than a value.
    """
    info, ann = _leaf(path, spec)
    return _unit_of(info) if info is not None else _unit_of_annotation(ann)


def path_description(path: str, spec: Spec | None = None) -> str:
    """The schema's description of the value at a dotted spec path.

    Parameters
    ----------
    path : str
        Dotted path, as for :func:`with_values`.
    spec : Spec, optional
        As for :func:`path_unit`.

    Returns
    -------
    str
        The field's description (``"Static friction force Fs [N]."``); ``""``
        when it has none.

    Raises
    ------
    SpecError
        Unknown path, or a path to a section rather than a value.
    """
    info, _ = _leaf(path, spec)
    return (getattr(info, "description", None) or "") if info is not None else ""


def typed_readings(path: str) -> list[str]:
    """A path whose index into a list of typed entries only a spec resolves, read by its type.

    ``effects[0].delay`` names a value only once the spec says what entry 0 is;
    read as each entry type, the rest of the path leaves the types that have it.

    Parameters
    ----------
    path : str
        Dotted path, as for :func:`with_values`.

    Returns
    -------
    list of str
        The path with that index as ``[type=NAME]``, one for each type that has
        the rest of the path; empty when the path needs no spec or none fits.

    Examples
    --------
    >>> typed_readings("effects[0].delay")
    ['effects[type=time_delay].delay']
    """
    found: list[str] = []
    try:
        _leaf(path, None, found)
    except SpecError:
        pass
    out = []
    for reading in found:
        try:
            _leaf(reading)
        except SpecError:
            continue
        out.append(reading)
    return out


def _leaf(path: str, spec: Spec | None = None,
          readings: list[str] | None = None) -> tuple[Any, Any]:
    """The field info (None inside a list entry) and annotation of the value at ``path``;
    ``readings`` collects the path read by each entry type where only a spec resolves an index
    (:func:`typed_readings`)."""
    model: Any = Spec
    instance: Any = spec
    tokens = parse_path(path)
    for n, (name, selectors) in enumerate(tokens):
        done = path_text(tokens[:n + 1])
        fields = model.model_fields
        if name not in fields:
            raise SpecError(_unknown(name, fields, path_text(tokens[:n])), path=done)
        info = fields[name]
        ann = info.annotation
        instance = getattr(instance, name, None) if instance is not None else None
        for sel in selectors:
            if isinstance(sel, tuple):  # [type=NAME]
                kinds = _entry_types(ann)
                if not kinds:
                    raise SpecError(f"'{name}' is not a list of typed entries, so [type=...] "
                                    "cannot select in it" + ("; select an entry by its index "
                                                             f"('{name}[0]')"
                                                             if _is_sequence_of_models(ann)
                                                             else ""), path=done)
                if sel[1] not in kinds:
                    close = difflib.get_close_matches(sel[1], list(kinds), n=1)
                    raise SpecError(f"no list entry of type '{sel[1]}' here"
                                    + (f"; did you mean '{close[0]}'?" if close else "")
                                    + f" (the types: {', '.join(kinds)})", path=done)
                model = ann = kinds[sel[1]]
                info = None
                hits = [e for e in instance if getattr(e, "type", None) == sel[1]] \
                    if isinstance(instance, tuple) else []
                instance = hits[0] if hits else None
            else:
                inner = _element(ann, sel)
                if isinstance(instance, tuple) and sel < len(instance):
                    inner = inner or type(instance[sel])
                    instance = instance[sel]
                elif inner is None:
                    if readings is not None and spec is None:
                        k = selectors.index(sel)
                        readings += [path_text(tokens[:n] + [(name, selectors[:k] + [("type", t)]
                                                              + selectors[k + 1:])]
                                               + tokens[n + 1:]) for t in _entry_types(ann)]
                    raise SpecError(_unresolved_entry(name, sel, ann, instance, spec),
                                    path=done)
                else:
                    instance = None
                ann = inner
                info = None if _model_class(inner) is not None else info
        last = n == len(tokens) - 1
        sub = _model_class(ann)
        if last:
            if sub is not None or (not selectors and _is_sequence_of_models(ann)):
                raise SpecError("is a section, not a value; name a value inside it, e.g. "
                                f"'{done}.{next(iter(sub.model_fields))}'" if sub is not None
                                else "is a list; name an entry and a value, e.g. "
                                f"'{done}[0]....'", path=done)
            return info, ann
        if sub is None:
            raise SpecError(f"'{name}' holds a value, not a section", path=done)
        model = sub
    raise SpecError("empty path", path=path)  # pragma: no cover - parse_path refuses it


def _entry_types(ann: Any) -> dict[str, Any]:
    """The entry models of a list of typed entries by their ``type`` (``{}`` for other fields).

    ``effects`` and ``controller.filters`` are such lists: each entry's model follows
    its ``type``, so ``[type=NAME]`` names the model without a spec.
    """
    import typing

    out: dict[str, Any] = {}

    def walk(a: Any, in_list: bool) -> None:
        if typing.get_origin(a) in (tuple, list):
            in_list = True
        if in_list and isinstance(a, type) and "type" in getattr(a, "model_fields", {}):
            for kind in typing.get_args(a.model_fields["type"].annotation):
                out[kind] = a
        for arg in typing.get_args(a):
            if isinstance(arg, type) or typing.get_args(arg):
                walk(arg, in_list)

    walk(ann, False)
    return out


def _unresolved_entry(name: str, index: int, ann: Any, instance: Any, spec: Any) -> str:
    """Why entry ``index`` of a list of typed entries has no model to resolve a path in."""
    kinds = list(_entry_types(ann))
    by_type = f"'{name}[type={kinds[0]}]'" if kinds else "its type"
    if isinstance(instance, tuple) and not instance:
        return f"the spec has no entry {index}: its '{name}' list is empty; add the entry first"
    if isinstance(instance, tuple):
        return (f"index {index} is out of range: the spec's '{name}' list has {len(instance)} "
                f"entr{'y' if len(instance) == 1 else 'ies'}")
    if spec is not None:
        return f"is not set in this spec; add '{name}' to the spec first"
    return (f"the type of entry {index} depends on the spec: pass the spec, or name the "
            f"entry by its type ({by_type})")


class _Open:
    """A spec section opened for editing: field values by name, untouched ones shared."""

    def __init__(self, obj: Any) -> None:
        self.model = type(obj)
        units = _field_units(self.model)
        self.fields: dict[str, Any] = {name: _input_form(getattr(obj, name), unit)
                                       for name, unit in units.items()}

    def plain(self) -> dict:
        return {k: _plain_tree(v) for k, v in self.fields.items()}


@functools.lru_cache(maxsize=None)
def _field_units(model: type) -> dict[str, str]:
    """Unit of every field of a spec section (``""`` for values without a unit)."""
    return {name: _unit_of(info) for name, info in model.model_fields.items()}


def _plain_tree(value: Any) -> Any:
    if isinstance(value, _Open):
        return value.plain()
    if isinstance(value, list):
        return [_plain_tree(v) for v in value]
    return value


def _input_form(value: Any, unit: str) -> Any:
    """A validated value as the validators take it again (numbers in deg/dB/rad as text)."""
    if unit in ("deg", "rad", "dB") and isinstance(value, (int, float)) \
            and not isinstance(value, bool):
        return f"{float(value)!r} {unit}"
    return value


def _plain_value(value: Any) -> Any:
    """numpy scalars to Python numbers (the validators check for int and float)."""
    if type(value).__module__ == "numpy" and hasattr(value, "item"):
        return value.item()
    return value


def _assign(root: _Open, path: str, value: Any) -> None:
    tokens = parse_path(path)
    node: Any = root
    for n, (name, selectors) in enumerate(tokens):
        done = path_text(tokens[:n + 1])
        if not isinstance(node, _Open):
            raise SpecError(f"'{path_text(tokens[:n])}' holds a value, not a section",
                            path=done)
        if name not in node.fields:
            raise SpecError(_unknown(name, node.model.model_fields, path_text(tokens[:n])),
                            path=done)
        container, key = node.fields, name
        unit = _field_units(node.model)[name]
        for sel in selectors:
            seq = container[key]
            if seq is None:
                raise SpecError("is not set in this spec", path=done)
            if not isinstance(seq, (tuple, list)):
                raise SpecError("is not a list; remove the [...]", path=done)
            seq = list(seq)
            container[key] = seq
            if isinstance(sel, tuple):
                hits = [i for i, e in enumerate(seq)
                        if getattr(e, "type", None) == sel[1]
                        or (isinstance(e, _Open) and e.fields.get("type") == sel[1])]
                if not hits:
                    have = [getattr(e, "type", None) or (e.fields.get("type")
                                                         if isinstance(e, _Open) else None)
                            for e in seq]
                    have = [h for h in have if h]
                    raise SpecError(f"the spec has no entry of type '{sel[1]}'"
                                    + (f" (it has: {', '.join(have)})" if have else
                                       " (the list is empty)"), path=done)
                index = hits[0]
            else:
                index = sel
                if index >= len(seq):
                    raise SpecError(f"index {index} is out of range: the list has {len(seq)} "
                                    f"entr{'y' if len(seq) == 1 else 'ies'}", path=done)
            container, key = seq, index
        last = n == len(tokens) - 1
        current = container[key]
        if last:
            container[key] = _input_form(value, unit)
            return
        if current is None:
            raise SpecError(f"is not set in this spec, so '{path}' cannot be varied; add the "
                            f"'{name}' section to the spec first", path=done)
        if hasattr(type(current), "model_fields") and not isinstance(current, _Open):
            current = _Open(current)
            container[key] = current
        node = current


def parse_path(path: str) -> list[tuple[str, list]]:
    """The one grammar of dotted spec paths: keys, each with list selectors.

    ``motion.moves[0].distance``, ``effects[type=time_delay].delay``: keys
    separated by dots, each optionally followed by ``[INDEX]`` (a list entry by
    position) or ``[type=NAME]`` (the first entry of that type). Every reader
    and writer of spec paths parses them here (:func:`with_values`,
    :func:`value_at`, :func:`fi_design.spec.edit.edited_spec_text`).

    Parameters
    ----------
    path : str
        The dotted path.

    Returns
    -------
    list of (str, list)
        Each key with its selectors: an int index or ``("type", NAME)``.

    Raises
    ------
    SpecError
        An empty path, a malformed key or selector; the message names the path.

    Examples
    --------
    >>> parse_path("motion.moves[0].distance")
    [('motion', []), ('moves', [0]), ('distance', [])]
    >>> parse_path("effects[type=time_delay].delay")
    [('effects', [('type', 'time_delay')]), ('delay', [])]
    """
    text = path.strip()
    if not text:
        raise SpecError("empty spec path; give a dotted path such as 'friction.static'")
    out: list[tuple[str, list]] = []
    for part in text.split("."):
        m = _PART.match(part.strip())
        if not m:
            raise SpecError(f"'{part}' is not a valid path element (expected a key such as "
                            "'static', optionally with [INDEX] or [type=NAME])", path=text)
        selectors: list = []
        for sel in _SELECTOR.findall(m.group(2)):
            sel = sel.strip()
            if sel.isdigit():
                selectors.append(int(sel))
            elif sel.startswith("type="):
                selectors.append(("type", sel[5:].strip()))
            else:
                raise SpecError(f"'[{sel}]' is not a list selector (use [0], [1], ... or "
                                "[type=NAME])", path=text)
        out.append((m.group(1), selectors))
    return out


def split_assignment(text: str) -> tuple[str, str] | None:
    """``PATH=VALUE`` split at its first ``=`` outside a list selector.

    The ``=`` of ``[type=NAME]`` belongs to the path: ``effects[type=time_delay].delay=1 ms``
    is the path ``effects[type=time_delay].delay`` and the value ``1 ms``.

    Parameters
    ----------
    text : str
        The text as written (``--x``, ``--scatter``).

    Returns
    -------
    (str, str) or None
        The path and the value, each stripped; None when no ``=`` lies outside brackets.

    Examples
    --------
    >>> split_assignment("effects[type=time_delay].delay=10%")
    ('effects[type=time_delay].delay', '10%')
    >>> split_assignment("friction.static") is None
    True
    """
    depth = 0
    for i, char in enumerate(text):
        if char == "[":
            depth += 1
        elif char == "]":
            depth = max(depth - 1, 0)
        elif char == "=" and depth == 0:
            return text[:i].strip(), text[i + 1:].strip()
    return None


def path_text(tokens: list) -> str:
    """A parsed path (:func:`parse_path`) written back: ``motion.moves[0].distance``."""
    out = ""
    for name, selectors in tokens:
        out += ("." if out else "") + name
        for sel in selectors:
            out += f"[type={sel[1]}]" if isinstance(sel, tuple) else f"[{sel}]"
    return out


def _unknown(name: str, fields: Mapping[str, Any], parent: str) -> str:
    close = difflib.get_close_matches(name, list(fields), n=1)
    where = f"'{parent}'" if parent else "the spec"
    hint = f"; did you mean '{close[0]}'?" if close else f"; known keys: {', '.join(fields)}"
    return f"unknown spec path: {where} has no key '{name}'{hint}"


def _unit_of(info: Any) -> str:
    if info is None:
        return ""
    return _unit_from_metadata(getattr(info, "metadata", ())) or \
        _unit_of_annotation(info.annotation)


def _unit_from_metadata(metadata: Any) -> str:
    for meta in metadata or ():
        schema = getattr(meta, "json_schema", None)
        if isinstance(schema, dict) and "x-unit" in schema:
            unit = schema["x-unit"]
            return {"degree": "deg", "decibel": "dB", "dimensionless": "1"}.get(unit, unit)
    return ""


def _unit_of_annotation(ann: Any) -> str:
    import typing

    if ann is None:
        return ""
    if typing.get_origin(ann) is typing.Annotated:
        return _unit_from_metadata(getattr(ann, "__metadata__", ()))
    if ann in (int, float):
        return "1"
    for arg in typing.get_args(ann):
        unit = _unit_of_annotation(arg)
        if unit:
            return unit
    return ""


def _model_class(ann: Any) -> Any:
    import typing

    if isinstance(ann, type) and hasattr(ann, "model_fields"):
        return ann
    if typing.get_origin(ann) in (tuple, list):
        return None
    for arg in typing.get_args(ann):
        m = _model_class(arg)
        if m is not None:
            return m
    return None


def _is_sequence_of_models(ann: Any) -> bool:
    import typing

    return typing.get_origin(ann) in (tuple, list) and any(
        _model_class(a) is not None for a in typing.get_args(ann))


def _element(ann: Any, index: int) -> Any:
    """The annotation of entry ``index`` of a tuple field (None if it depends on the value)."""
    import typing

    args = typing.get_args(ann)
    if typing.get_origin(ann) is not tuple:
        for arg in args:
            inner = _element(arg, index)
            if inner is not None:
                return inner
        return None
    if len(args) == 2 and args[1] is Ellipsis:
        inner = args[0]
    elif index < len(args):
        inner = args[index]
    else:
        return None
    if typing.get_origin(inner) is typing.Annotated and typing.get_origin(
            typing.get_args(inner)[0]) is typing.Union:
        return None  # a discriminated union: the entry's type depends on its value
    return inner


def _show(value: Any) -> str:
    from .units import huge, shown_digits

    if huge(value):
        return f"the number {shown_digits(value)}"
    return number(value, 6) if isinstance(value, float) else repr(value) \
        if isinstance(value, str) else str(value)


def value_at(spec: Spec, path: str) -> Any:
    """The value at a dotted spec path (as stored: SI floats, None when not given).

    Parameters
    ----------
    spec : Spec
        The spec to read.
    path : str
        Dotted path, as for :func:`with_values`.

    Returns
    -------
    object
        The stored value; ``None`` for an optional value left at its derived
        default (e.g. ``isolator.stiffness`` when step 3 proposes it).

    Raises
    ------
    SpecError
        An unknown path, or a path into a section the spec does not have.
    """
    node: Any = spec
    tokens = parse_path(path)
    for n, (name, selectors) in enumerate(tokens):
        done = path_text(tokens[:n + 1])
        if node is None:
            raise SpecError("is not set in this spec", path=path_text(tokens[:n]))
        fields = getattr(type(node), "model_fields", None)
        if fields is None:
            raise SpecError(f"'{path_text(tokens[:n])}' holds a value, not a section",
                            path=done)
        if name not in fields:
            raise SpecError(_unknown(name, fields, path_text(tokens[:n])), path=done)
        node = getattr(node, name)
        for sel in selectors:
            if not isinstance(node, tuple):
                raise SpecError("is not a list; remove the [...]", path=done)
            if isinstance(sel, tuple):
                hits = [e for e in node if getattr(e, "type", None) == sel[1]]
                if not hits:
                    raise SpecError(f"the spec has no entry of type '{sel[1]}'", path=done)
                node = hits[0]
            elif sel < len(node):
                node = node[sel]
            else:
                raise SpecError(f"index {sel} is out of range: the list has {len(node)} "
                                f"entr{'y' if len(node) == 1 else 'ies'}", path=done)
    return node
