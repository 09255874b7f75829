"""Reading a spec: safe YAML with line numbers, validation, clear errors.

:func:`load_spec` is the one entry point. It accepts a path or an already
parsed mapping. YAML is read with PyYAML's safe loader; tags that would build
Python objects, duplicate keys and alias bombs are refused. Validation errors
become a :class:`~fi_design.errors.SpecError` naming the dotted field path and
the YAML line, with a suggestion for misspelt keys.
"""

from __future__ import annotations

import difflib
import hashlib
import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

from .errors import SpecError, SpecFileError
from .spec import Spec

#: Largest spec file accepted [bytes]; a design spec is a few kB.
MAX_BYTES = 1_000_000
#: Largest number of YAML nodes after alias expansion (alias-bomb guard).
MAX_NODES = 20_000


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
    lines : dict
        YAML line (1-based) of every key, by location tuple.
    """

    path: Path | None
    sha256: str
    raw: dict
    lines: dict = field(default_factory=dict, repr=False)


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
        return _validate(raw, SpecOrigin(None, digest, raw, {}))
    path = Path(source)
    data = read_bytes(path)
    raw, lines = parse_yaml(data, str(path))
    return _validate(raw, SpecOrigin(path, hashlib.sha256(data).hexdigest(), raw, lines))


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


def parse_yaml(data: bytes, source: str = "<spec>") -> tuple[dict, dict]:
    """Parse YAML bytes safely into a mapping and a line map.

    Returns
    -------
    raw : dict
        The top-level mapping.
    lines : dict
        1-based line of each key, keyed by location tuple (``("friction",
        "static")``, ``("motion", "moves", 0)``).
    """
    import yaml

    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        raise SpecError("not a text file (not UTF-8)", source=source) from None
    if not text.strip() or all(ln.strip().startswith("#") or not ln.strip()
                               for ln in text.splitlines()):
        raise SpecError("the spec file is empty", source=source)
    loader = yaml.SafeLoader(text)
    try:
        node = loader.get_single_node()
        if node is None:
            raise SpecError("the spec file is empty", source=source)
        _count_nodes(node, source)
        lines: dict = {}
        _walk(node, (), lines, source)
        raw = loader.construct_document(node)
    except yaml.constructor.ConstructorError as exc:
        line = exc.problem_mark.line + 1 if exc.problem_mark else None
        tag = getattr(exc.problem_mark, "name", "")
        what = exc.problem or "unsupported YAML"
        if "constructor for the tag" in what:
            what = (what.replace("could not determine a constructor for the tag",
                                 "YAML tag") + " is not allowed: a spec holds plain data only")
        raise SpecError(what, line=line, source=source) from None
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        line = mark.line + 1 if mark else None
        problem = getattr(exc, "problem", None) or str(exc)
        raise SpecError(f"not valid YAML: {problem}", line=line, source=source) from None
    finally:
        loader.dispose()
    if not isinstance(raw, dict):
        kind = "a list" if isinstance(raw, list) else f"a {type(raw).__name__}"
        raise SpecError(f"the top level must be a mapping of sections (name, stage, cart, ...), "
                        f"got {kind}", line=1, source=source)
    return raw, lines


def _count_nodes(node, source: str) -> None:
    import yaml

    memo: dict[int, int] = {}

    def size(n) -> int:
        key = id(n)
        if key in memo:
            return memo[key]
        memo[key] = 1  # cycles count once
        if isinstance(n, yaml.SequenceNode):
            total = 1 + sum(size(c) for c in n.value)
        elif isinstance(n, yaml.MappingNode):
            total = 1 + sum(size(k) + size(v) for k, v in n.value)
        else:
            total = 1
        memo[key] = total
        if total > MAX_NODES:
            raise SpecError(f"the YAML expands to more than {MAX_NODES} nodes (an alias bomb?)",
                            line=n.start_mark.line + 1, source=source)
        return total

    size(node)


def _walk(node, loc: tuple, lines: dict, source: str) -> None:
    import yaml

    if isinstance(node, yaml.MappingNode):
        seen: dict = {}
        for knode, vnode in node.value:
            key = knode.value
            line = knode.start_mark.line + 1
            if key in seen:
                path = _dotted(loc + (key,))
                raise SpecError(f"key '{key}' appears twice (also on line {seen[key]})", path=path,
                                line=line, source=source)
            seen[key] = line
            lines[loc + (key,)] = line
            _walk(vnode, loc + (key,), lines, source)
    elif isinstance(node, yaml.SequenceNode):
        for i, item in enumerate(node.value):
            lines[loc + (i,)] = item.start_mark.line + 1
            _walk(item, loc + (i,), lines, source)


def _plain(obj: Any) -> Any:
    if isinstance(obj, Mapping):
        return {str(k): _plain(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_plain(v) for v in obj]
    return obj


# --------------------------------------------------------------------------- validation


def _validate(raw: dict, org: SpecOrigin) -> Spec:
    from pydantic import ValidationError

    source = str(org.path) if org.path else None
    try:
        spec = Spec.model_validate(raw)
    except ValidationError as exc:
        errors = exc.errors(include_url=False)
        msgs = [_describe(e, raw) for e in errors]
        first_loc = _clean_loc(errors[0]["loc"], raw)
        line = _line_for(first_loc, org.lines)
        text = msgs[0][1]
        if len(msgs) > 1:
            extra = []
            for (p, m), e in list(zip(msgs, errors))[1:8]:
                ln = _line_for(_clean_loc(e["loc"], raw), org.lines)
                extra.append(f"  - {p or '(top level)'}{f' (line {ln})' if ln else ''}: {m}")
            text += f"\n{len(msgs) - 1} more problem(s):\n" + "\n".join(extra)
        raise SpecError(text, path=msgs[0][0] or None, line=line, source=source) from None
    spec._origin = org
    return spec


def _clean_loc(loc: tuple, raw: dict) -> tuple:
    """Drop union tags that pydantic inserts (``effects.0.time_delay.delay``)."""
    out: list = []
    node: Any = raw
    for part in loc:
        if isinstance(node, dict) and isinstance(part, str) and part not in node \
                and out and out[-1] != part and isinstance(out[-1], int) \
                and node.get("type") == part:
            continue
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


def _line_for(loc: tuple, lines: dict) -> int | None:
    for n in range(len(loc), 0, -1):
        if loc[:n] in lines:
            return lines[loc[:n]]
    return None


def _model_at(loc: tuple):
    """The pydantic model class that holds the field at ``loc`` (None if unknown)."""
    import typing

    model: Any = Spec
    for part in loc[:-1]:
        if isinstance(part, int):
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
        model = _model_at(loc)
        desc = ""
        if model is not None and loc and loc[-1] in model.model_fields:
            desc = model.model_fields[loc[-1]].description or ""
        return path, "required field is missing" + (f" ({desc})" if desc else "")
    if kind == "extra_forbidden":
        model = _model_at(loc)
        key = loc[-1] if loc else ""
        hint = ""
        if model is not None:
            close = difflib.get_close_matches(str(key), list(model.model_fields), n=1)
            hint = f"; did you mean '{close[0]}'?" if close else \
                f"; allowed: {', '.join(model.model_fields)}"
        return path, f"unknown key '{key}'{hint}"
    if kind == "unknown_effect":
        given = err.get("input", {}).get("type") if isinstance(err.get("input"), dict) else None
        close = difflib.get_close_matches(str(given), list(_effects.EFFECT_NAMES), n=1)
        hint = f" (did you mean '{close[0]}'?)" if close else ""
        return path + ".type", (f"unknown effect '{given}'{hint}; known: "
                                f"{', '.join(_effects.EFFECT_NAMES)}")
    if kind == "value_error":
        return path, msg.removeprefix("Value error, ")
    if kind in ("greater_than", "greater_than_equal", "less_than", "less_than_equal"):
        unit = _unit_at(loc)
        bound = list(err.get("ctx", {}).values())[0]
        words = {"greater_than": "greater than", "greater_than_equal": "at least",
                 "less_than": "less than", "less_than_equal": "at most"}[kind]
        return path, f"must be {words} {bound:g}{' ' + unit if unit else ''}, got {err['input']!r}"
    if kind in ("finite_number",):
        return path, "must be a finite number"
    if kind in ("float_type", "float_parsing"):
        return path, f"expected a number or a string with units, got {err['input']!r}"
    if kind in ("model_type", "model_attributes_type", "dict_type"):
        model = _model_at(loc + ("x",))
        keys = ", ".join(model.model_fields) if model is not None else ""
        return path, f"expected a mapping{' with keys ' + keys if keys else ''}, got {err['input']!r}"
    return path, msg


def _unit_at(loc: tuple) -> str:
    model = _model_at(loc)
    if model is None or not loc or loc[-1] not in model.model_fields:
        return ""
    desc = model.model_fields[loc[-1]].description or ""
    if "[" in desc and "]" in desc:
        return desc[desc.rindex("[") + 1: desc.rindex("]")]
    return ""
