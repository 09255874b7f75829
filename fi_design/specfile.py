"""Reading a spec: safe YAML with line numbers, validation, clear errors.

:func:`load_spec` is the one entry point. It accepts a path or an already
parsed mapping. YAML is read with ruamel.yaml in round-trip mode
(:func:`yaml_loader`), which builds plain data only and keeps each key's line
and the comments (a spec written back, :mod:`fi_design.specedit`, keeps them);
tags beyond YAML's core schema, duplicate keys and alias bombs are refused.
Validation errors become a :class:`~fi_design.errors.SpecError` naming the
dotted field path and the YAML line, with a suggestion for misspelt keys.
"""

from __future__ import annotations

import difflib
import functools
import hashlib
import json
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

from .errors import SpecError, SpecFileError
from .spec import Spec

#: Largest spec file accepted [bytes]; a design spec is a few kB.
MAX_BYTES = 1_000_000
#: Largest number of YAML nodes after alias expansion (alias-bomb guard).
MAX_NODES = 20_000
#: Deepest nesting of mappings and lists accepted; a spec nests five levels.
MAX_DEPTH = 32


@dataclass(frozen=True)
class SpecOrigin:
    """Where a spec came from.

    Attributes
    ----------
    path : pathlib.Path or None
        The file, or None for a mapping.
    sha256 : str
        SHA-256 of the file bytes (of canonical JSON for a mapping).
    raw : dict
        The mapping as written (before units and defaults), used to tell given
        values from defaults.
    document : ruamel.yaml.comments.CommentedMap or None
        The file as ruamel.yaml's round-trip loader read it: the YAML line of
        every key (:meth:`line`); None for a mapping.
    text : str or None
        The file's text exactly as read (comments, layout and line endings
        kept; ``text.encode("utf-8")`` are the bytes ``sha256`` was computed
        from); None for a mapping.
    """

    path: Path | None
    sha256: str
    raw: dict
    document: Any = field(default=None, repr=False, compare=False)
    text: str | None = field(default=None, repr=False)

    def line(self, loc: tuple) -> int | None:
        """The 1-based YAML line of the key or list entry at ``loc``, or of its nearest parent.

        Parameters
        ----------
        loc : tuple
            Location: keys and list indices (``("friction", "static")``,
            ``("motion", "moves", 0, "distance")``).

        Returns
        -------
        int or None
            None for a spec read from a mapping, or a location the file does
            not have at all.
        """
        return document_line(self.document, loc)


def document_line(document: Any, loc: tuple) -> int | None:
    """The 1-based line of ``loc`` in a round-trip document (or of its nearest parent)."""
    best = None
    node = document
    for part in loc:
        lc = getattr(node, "lc", None)
        try:
            if isinstance(part, int) and isinstance(node, list) and 0 <= part < len(node):
                best = lc.item(part)[0] + 1
            elif isinstance(node, dict) and part in node:
                best = lc.key(part)[0] + 1
            else:
                return best
        except (AttributeError, KeyError, TypeError):  # an entry ruamel has no position for
            return best
        node = node[part]
    return best


def load_spec(source: str | Path | Mapping[str, Any]) -> Spec:
    """Load and validate a design spec.

    Parameters
    ----------
    source : str, pathlib.Path or mapping
        Path of a YAML file, or a mapping with the same structure (values in
        SI or strings with units).

    Returns
    -------
    Spec
        The validated spec. ``origin(spec)`` tells where it came from.

    Raises
    ------
    SpecFileError
        The file is missing, a directory, too large or not text.
    SpecError
        Not valid YAML, not a mapping, or a value is missing or wrong; the
        message names the field path and line.
    """
    if isinstance(source, Mapping):
        raw = _plain(source)
        digest = hashlib.sha256(json.dumps(raw, sort_keys=True, default=str).encode()).hexdigest()
        return _validate(raw, SpecOrigin(None, digest, raw))
    path = Path(source)
    data = read_bytes(path)
    raw, document = parse_yaml(data, str(path))
    # parse_yaml decoded the bytes as UTF-8 already: the text encodes back to the same bytes
    return _validate(raw, SpecOrigin(path, hashlib.sha256(data).hexdigest(), raw, document,
                                     data.decode("utf-8")))


def as_spec(spec: Any, name: str = "spec") -> Spec:
    """The spec a library function was given: a :class:`Spec`, or a path or mapping to load.

    Every public workflow takes what :func:`fi_design.design` takes, so a
    script can pass the same mapping to each.

    Parameters
    ----------
    spec : Spec, str, pathlib.Path or mapping
        The spec, or what :func:`load_spec` reads.
    name : str, optional
        The argument's name, for the message.

    Returns
    -------
    Spec

    Raises
    ------
    ArgumentError
        ``spec`` is none of these (None, a number, a list).
    SpecFileError, SpecError
        As :func:`load_spec`.
    """
    from .errors import ArgumentError

    if isinstance(spec, Spec):
        return spec
    if isinstance(spec, (str, Path, Mapping)):
        return load_spec(spec)
    raise ArgumentError(f"{name} must be a Spec, a path to a YAML spec or a mapping, got "
                        f"{type(spec).__name__}")


def origin(spec: Spec) -> SpecOrigin | None:
    """Return the :class:`SpecOrigin` recorded by :func:`load_spec`, if any."""
    return spec._origin


def read_bytes(path: Path) -> bytes:
    """Read a spec file's bytes with clear errors for missing files and directories."""
    if not path.exists():
        raise SpecFileError(f"{path}: no such file")
    if path.is_dir():
        raise SpecFileError(f"{path}: is a directory, expected a YAML spec file")
    size = path.stat().st_size
    if size > MAX_BYTES:
        raise SpecFileError(f"{path}: {size} bytes is too large for a spec (limit {MAX_BYTES})")
    try:
        return path.read_bytes()
    except OSError as exc:
        raise SpecFileError(f"{path}: cannot read ({exc.strerror})") from None


#: Tags a spec may carry (YAML's core schema); any other tag is refused.
_PLAIN_TAGS = frozenset(f"tag:yaml.org,2002:{t}" for t in
                        ("str", "int", "float", "bool", "null", "map", "seq", "timestamp"))


def yaml_loader():
    """The YAML reader and writer of spec files: ruamel.yaml in round-trip mode.

    Round-trip mode builds plain data only (no tag constructs a Python object)
    and keeps what a writer needs: comments, key order, flow or block style and
    each key's line.
    """
    from ruamel.yaml import YAML

    yaml = YAML(typ="rt")
    yaml.width = 4096  # never re-wrap a user's long lines
    yaml.preserve_quotes = True
    return yaml


def parse_yaml(data: bytes, source: str = "<spec>") -> tuple[dict, Any]:
    """Parse YAML bytes safely into a mapping and its round-trip document.

    Returns
    -------
    raw : dict
        The top-level mapping as plain Python data.
    document : ruamel.yaml.comments.CommentedMap
        The same data as ruamel.yaml read it, with comments and the line of
        every key (:func:`document_line`).

    Raises
    ------
    SpecError
        Not UTF-8, empty, not valid YAML, a control character, a tag other
        than YAML's core schema, a key given twice, an alias bomb, or a top
        level that is not a mapping; the message names the line.
    """
    from ruamel.yaml.error import MarkedYAMLError, YAMLError
    from ruamel.yaml.reader import ReaderError

    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        raise SpecError("not a text file (not UTF-8)", source=source) from None
    if not text.strip() or all(ln.strip().startswith("#") or not ln.strip()
                               for ln in text.splitlines()):
        raise SpecError("the spec file is empty", source=source)
    yaml = yaml_loader()
    try:
        try:
            node = yaml.compose(text)
        except RecursionError:  # the composer recurses: a few hundred levels exhaust it
            raise SpecError(f"the YAML is nested more than {MAX_DEPTH} levels deep (mappings or "
                            "lists inside each other); a spec nests a few levels",
                            source=source) from None
        if node is None:
            raise SpecError("the spec file is empty", source=source)
        _check_nodes(node, (), source)  # depth first: the node count recurses
        _count_nodes(node, source)
        document = yaml.constructor.construct_document(node)
    except ReaderError as exc:  # a NUL or other control character
        line = text.count("\n", 0, exc.position) + 1
        raise SpecError(f"control character U+{exc.character:04X} is not allowed in a YAML "
                        "spec: the file is not plain text", line=line, source=source) from None
    except MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        line = mark.line + 1 if mark else None
        problem = exc.problem or exc.context or str(exc)
        raise SpecError(f"not valid YAML: {problem}", line=line, source=source) from None
    except YAMLError as exc:
        raise SpecError(f"not valid YAML: {exc}", source=source) from None
    if not isinstance(document, dict):
        kind = "a list" if isinstance(document, list) else f"a {type(document).__name__}"
        raise SpecError(f"the top level must be a mapping of sections (name, stage, cart, ...), "
                        f"got {kind}", line=1, source=source)
    return _plain(document), document


def _count_nodes(node, source: str) -> None:
    from ruamel.yaml.nodes import MappingNode, SequenceNode

    memo: dict[int, int] = {}

    def size(n) -> int:
        key = id(n)
        if key in memo:
            return memo[key]
        memo[key] = 1  # cycles count once
        if isinstance(n, SequenceNode):
            total = 1 + sum(size(c) for c in n.value)
        elif isinstance(n, MappingNode):
            total = 1 + sum(size(k) + size(v) for k, v in n.value)
        else:
            total = 1
        memo[key] = total
        if total > MAX_NODES:
            raise SpecError(f"the YAML expands to more than {MAX_NODES} nodes (an alias bomb?)",
                            line=n.start_mark.line + 1, source=source)
        return total

    size(node)


def _check_nodes(node, loc: tuple, source: str, seen: set | None = None) -> None:
    """Refuse tags beyond YAML's core schema and keys given twice, naming the line."""
    from ruamel.yaml.nodes import MappingNode, ScalarNode, SequenceNode

    seen = set() if seen is None else seen
    if id(node) in seen:  # an alias: checked where it was defined
        return
    seen.add(id(node))
    if len(loc) > MAX_DEPTH:
        raise SpecError(f"the YAML is nested more than {MAX_DEPTH} levels deep (mappings or "
                        "lists inside each other); a spec nests a few levels",
                        path=_dotted(loc[:3]) + ("..." if len(loc) > 3 else ""),
                        line=node.start_mark.line + 1, source=source)
    tag = str(node.tag) if node.tag is not None else None
    if tag is not None and tag not in _PLAIN_TAGS:
        shown = "!!" + tag[len("tag:yaml.org,2002:"):] if tag.startswith("tag:yaml.org,2002:") \
            else tag
        raise SpecError(f"YAML tag '{shown}' is not allowed: a spec holds plain data only",
                        line=node.start_mark.line + 1, source=source)
    if isinstance(node, MappingNode):
        keys: dict = {}
        for knode, vnode in node.value:
            line = knode.start_mark.line + 1
            if not isinstance(knode, ScalarNode):
                kind = "a list" if isinstance(knode, SequenceNode) else "a mapping"
                raise SpecError(f"a key must be a plain name, got {kind} (a YAML complex key "
                                "'? ...')", path=_dotted(loc) or None, line=line,
                                source=source)
            key = knode.value
            if isinstance(key, str) and key in keys:
                raise SpecError(f"key '{key}' appears twice (also on line {keys[key]})",
                                path=_dotted(loc + (key,)), line=line, source=source)
            keys[key] = line
            _check_nodes(knode, loc, source, seen)
            _check_nodes(vnode, loc + (key,), source, seen)
    elif isinstance(node, SequenceNode):
        for i, item in enumerate(node.value):
            _check_nodes(item, loc + (i,), source, seen)


def _plain(obj: Any) -> Any:
    """Plain Python data: dict, list, str, int, float, bool, None (ruamel's scalar types too)."""
    if isinstance(obj, Mapping):
        return {str(k): _plain(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_plain(v) for v in obj]
    if isinstance(obj, bool) or obj is None:
        return obj
    if isinstance(obj, str):
        return str(obj)
    if isinstance(obj, int):
        return int(obj)
    if isinstance(obj, float):
        return float(obj)
    return obj


# --------------------------------------------------------------------------- validation


def _validate(raw: dict, org: SpecOrigin) -> Spec:
    from pydantic import ValidationError

    source = str(org.path) if org.path else None
    try:
        spec = Spec.model_validate(raw)
    except ValidationError as exc:
        # an unknown key first: a misspelt required key also makes it "missing", and the
        # typo is the cause the user has to see
        errors = sorted(exc.errors(include_url=False),
                        key=lambda e: e["type"] != "extra_forbidden")
        msgs = [_describe(e, raw) for e in errors]
        first_loc = _clean_loc(errors[0]["loc"], raw)
        if not first_loc and msgs[0][0]:
            first_loc = tuple(msgs[0][0].split("."))
        line = org.line(first_loc)
        text = msgs[0][1]
        if len(msgs) > 1:
            extra = []
            for (p, m), e in list(zip(msgs, errors))[1:8]:
                ln = org.line(_clean_loc(e["loc"], raw))
                extra.append(f"  - {p or '(top level)'}{f' (line {ln})' if ln else ''}: {m}")
            text += f"\n{len(msgs) - 1} more problem(s):\n" + "\n".join(extra)
        raise SpecError(text, path=msgs[0][0] or None, line=line, source=source) from None
    spec._origin = org
    return spec


def _clean_loc(loc: tuple, raw: dict) -> tuple:
    """Drop union tags that pydantic inserts (``effects.0.time_delay.delay``).

    The tag is the entry's own ``type`` right after its index, even where a
    parameter has the effect's name (``effects.0.stribeck_velocity.stribeck_velocity``).
    """
    out: list = []
    node: Any = raw
    tagged = False
    for part in loc:
        if isinstance(node, dict) and isinstance(part, str) and not tagged and len(out) >= 2 \
                and isinstance(out[-1], int) and out[-2] == "effects" \
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


def _dotted(loc: tuple) -> str:
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

    from .spec import EFFECT_MODELS

    model: Any = Spec
    node: Any = raw
    for n, part in enumerate(loc[:-1]):
        node = node.get(part) if isinstance(node, dict) and not isinstance(part, int) else \
            node[part] if isinstance(node, list) and isinstance(part, int) \
            and part < len(node) else None
        if isinstance(part, int):
            if n >= 1 and loc[n - 1] == "effects":
                kind = node.get("type") if isinstance(node, dict) else None
                model = EFFECT_MODELS.get(kind) if isinstance(kind, str) else None
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


def _describe(err: dict, raw: dict) -> tuple[str, str]:
    from . import effects as _effects

    loc = _clean_loc(err["loc"], raw)
    path = _dotted(loc)
    kind = err["type"]
    msg = err["msg"]
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
        given = err.get("input", {}).get("type") if isinstance(err.get("input"), dict) else None
        if not isinstance(err.get("input"), dict):
            return path, _not_an_effect_entry(err.get("input"))
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
        return path, f"must be {words} {bound:g}{shown}, got {_shown(err['input'])}"
    if kind in ("finite_number",):
        return path, "must be a finite number"
    if isinstance(err.get("input"), int) and len(str(abs(err["input"]))) > 300:
        digits = len(str(abs(err["input"])))
        return path, f"the number {_shown(err['input'])} ({digits} digits) is too large"
    if kind in ("float_type", "float_parsing"):
        return path, f"expected a number or a string with units, got {_shown(err['input'])}"
    if kind in ("model_type", "model_attributes_type", "dict_type"):
        model = _model_at(loc + ("x",), raw)
        keys = ", ".join(model.model_fields) if model is not None else ""
        return path, (f"expected a mapping{' with keys ' + keys if keys else ''}, got "
                      f"{_shown(err['input'])}")
    return path, msg


def _shown(value: Any) -> str:
    """A value read from the spec, for a message: its repr, cut to 40 characters."""
    text = repr(value)
    return text if len(text) <= 40 else text[:28] + "..." + text[-8:]


def _not_an_effect_entry(given: Any) -> str:
    """The message for an ``effects`` entry that is not a mapping (``- time_delay``)."""
    from . import effects as _effects

    name = given if isinstance(given, str) and given in _effects.CATALOGUE else "time_delay"
    required = [p.name for p in _effects.get(name).parameters if p.required]
    example = "{type: " + name + "".join(f", {p}: ..." for p in required) + "}"
    return (f"an effect is a mapping with its type and parameters, e.g. {example}; got "
            f"{given!r}")


#: A top-level validator's message that names its field: ``"controller.crossover: ..."``.
_NAMED = re.compile(r"^([A-Za-z_][A-Za-z0-9_.\[\]=]*): (.+)$", re.S)


def _unit_at(loc: tuple, raw: Any = None) -> str:
    model = _model_at(loc, raw)
    if model is None or not loc or loc[-1] not in model.model_fields:
        return ""
    desc = model.model_fields[loc[-1]].description or ""
    if "[" in desc and "]" in desc:
        return desc[desc.rindex("[") + 1: desc.rindex("]")]
    return ""


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

    Examples
    --------
    >>> from fi_design.specfile import load_spec, with_values
    >>> spec = load_spec("examples/paper_setup.yaml")
    >>> with_values(spec, {"isolator.stroke": "0.5 mm"}).isolator.stroke
    0.0005
    """
    from pydantic import ValidationError

    root = _Open(spec)
    for path, value in values.items():
        _assign(root, str(path), _plain_value(value))
    data = root.plain()
    try:
        new = Spec.model_validate(data)
    except ValidationError as exc:
        errors = exc.errors(include_url=False)
        where, text = _describe(errors[0], data)
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
        Needed only to resolve a list index into ``effects`` (``effects[0]``);
        ``effects[type=NAME]`` works without it.

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


def _leaf(path: str, spec: Spec | None = None) -> tuple[Any, Any]:
    """The field info (None inside a list entry) and annotation of the value at ``path``."""
    model: Any = Spec
    instance: Any = spec
    tokens = _tokens(path)
    for n, (name, selectors) in enumerate(tokens):
        done = _dotted_tokens(tokens[:n + 1])
        fields = model.model_fields
        if name not in fields:
            raise SpecError(_unknown(name, fields, _dotted_tokens(tokens[:n])), path=done)
        info = fields[name]
        ann = info.annotation
        instance = getattr(instance, name, None) if instance is not None else None
        for sel in selectors:
            if isinstance(sel, tuple):  # [type=NAME]
                from .spec import EFFECT_MODELS

                if name != "effects" or sel[1] not in EFFECT_MODELS:
                    raise SpecError(f"no list entry of type '{sel[1]}' here", path=done)
                model, ann, info = EFFECT_MODELS[sel[1]], EFFECT_MODELS[sel[1]], None
                instance = None
            else:
                inner = _element(ann, sel)
                if inner is None and instance is not None and sel < len(instance):
                    inner = type(instance[sel])
                if inner is None:
                    raise SpecError("cannot resolve this list entry without a spec", path=done)
                if isinstance(instance, tuple) and sel < len(instance):
                    instance = instance[sel]
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
    raise SpecError("empty path", path=path)  # pragma: no cover - _tokens refuses it


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
    tokens = _tokens(path)
    node: Any = root
    for n, (name, selectors) in enumerate(tokens):
        done = _dotted_tokens(tokens[:n + 1])
        if not isinstance(node, _Open):
            raise SpecError(f"'{_dotted_tokens(tokens[:n])}' holds a value, not a section",
                            path=done)
        if name not in node.fields:
            raise SpecError(_unknown(name, node.model.model_fields, _dotted_tokens(tokens[:n])),
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


def _tokens(path: str) -> list[tuple[str, list]]:
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


def _dotted_tokens(tokens: list) -> str:
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
    return f"{value:g}" if isinstance(value, float) else repr(value) \
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
    tokens = _tokens(path)
    for n, (name, selectors) in enumerate(tokens):
        done = _dotted_tokens(tokens[:n + 1])
        if node is None:
            raise SpecError("is not set in this spec", path=_dotted_tokens(tokens[:n]))
        fields = getattr(type(node), "model_fields", None)
        if fields is None:
            raise SpecError(f"'{_dotted_tokens(tokens[:n])}' holds a value, not a section",
                            path=done)
        if name not in fields:
            raise SpecError(_unknown(name, fields, _dotted_tokens(tokens[:n])), path=done)
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
