"""Reading a spec: safe YAML with line numbers, validation, clear errors.

:func:`load_spec` is the one entry point. It accepts a path or an already
parsed mapping. YAML is read with ruamel.yaml in round-trip mode
(:func:`yaml_loader`), which builds plain data only and keeps each key's line
and the comments (a spec written back, :mod:`fi_design.spec.edit`, keeps them);
tags beyond YAML's core schema, duplicate keys and alias bombs are refused.
Validation errors become a :class:`~fi_design.errors.SpecError` naming the
dotted field path and the YAML line, with a suggestion for misspelt keys
(:mod:`fi_design.spec.errors` words them). Values at dotted paths
(:func:`with_values`, :func:`value_at`, ...) live in :mod:`fi_design.spec.paths`
and are named here too.
"""

from __future__ import annotations

import hashlib
import os
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

from ..display import code_point
from ..errors import SpecError, SpecFileError
from ..provenance import json_sha256
from . import Spec
from .errors import clean_loc, describe, dotted, real_errors
# the values at dotted paths live in fi_design.spec.paths; named here as well
from .paths import path_description, path_unit, value_at
from .paths import with_values as spec_with_values

__all__ = ["SpecOrigin", "load_spec", "as_spec", "origin", "parse_yaml", "yaml_loader",
           "read_bytes", "document_line", "with_values", "value_at", "path_unit",
           "path_description", "MAX_BYTES", "MAX_NODES", "MAX_DEPTH"]

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
    ArgumentError
        ``source`` is neither a path nor a mapping (None, a number, a list,
        bytes), or is the YAML text itself rather than a path to it.

    Examples
    --------
    YAML text is loaded as the mapping :func:`parse_yaml` reads from it (the
    checks of the file reader; the messages name no line):

    >>> text = open("examples/paper_setup.yaml", encoding="utf-8").read()
    >>> load_spec(parse_yaml(text.encode("utf-8"))[0]).stage.mass
    1.6
    """
    from ..errors import ArgumentError

    if not isinstance(source, (str, os.PathLike, Mapping)):
        hint = " (write the YAML to a file, or parse it into a mapping)" \
            if isinstance(source, (bytes, bytearray)) else ""
        raise ArgumentError(f"source must be a path to a YAML spec or a mapping, got "
                            f"{type(source).__name__}{hint}")
    if isinstance(source, str) and _is_yaml_text(source):
        first = source.strip().splitlines()[0] if source.strip() else source
        shown = first if len(first) <= 40 else first[:37] + "..."
        raise ArgumentError(f"source looks like YAML text ({shown!r}), not a path: load_spec "
                            "takes the path of a YAML spec file or a mapping; for text, pass "
                            "the mapping fi_design.spec.file.parse_yaml(text.encode('utf-8'))[0]"
                            ", or write the text to a file")
    if isinstance(source, Mapping):
        raw = plain(source)
        return _validate(raw, SpecOrigin(None, json_sha256(raw), raw))
    path = Path(source)
    data = read_bytes(path)
    raw, document = parse_yaml(data, str(path))
    # parse_yaml decoded the bytes as UTF-8 already: the text encodes back to the same bytes
    return _validate(raw, SpecOrigin(path, hashlib.sha256(data).hexdigest(), raw, document,
                                     data.decode("utf-8")))


def as_spec(spec: Any, name: str = "spec", *, model: bool = False) -> Spec:
    """The spec a library function was given: a :class:`Spec`, or a path or mapping to load.

    Every public workflow takes what :func:`fi_design.design` takes, so a
    script can pass the same mapping to each.

    Parameters
    ----------
    spec : Spec, str, pathlib.Path or mapping
        The spec, or what :func:`load_spec` reads.
    name : str, optional
        The argument's name, for the message.
    model : bool, optional
        Whether the caller also takes a resolved :class:`fi_design.model.Model`
        (and has taken it before asking here), for the message. Default False.

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
    from ..errors import ArgumentError

    if isinstance(spec, Spec):
        return spec
    if isinstance(spec, (str, Path, Mapping)):
        return load_spec(spec)
    raise ArgumentError(f"{name} must be a Spec, {'a Model, ' if model else ''}a path to a YAML "
                        f"spec or a mapping, got {type(spec).__name__}")


def with_values(spec: Spec | str | os.PathLike | Mapping[str, Any],
                values: Mapping[str, Any]) -> Spec:
    """Return a copy of a spec with values replaced at dotted paths, re-validated.

    :func:`fi_design.spec.paths.with_values` for what :func:`fi_design.design`
    takes as its spec (:func:`as_spec`): a script can pass the same mapping or
    path to each.

    Parameters
    ----------
    spec : Spec, str, pathlib.Path or mapping
        The spec to start from (not changed), or what :func:`load_spec` reads.
    values : mapping of str to value
        Dotted path (``"isolator.stroke"``, ``"motion.moves[0].distance"``,
        ``"effects[type=time_delay].delay"``) to the new value: an SI number or
        a string with units (``"0.3 mm"``), as the YAML file takes it; None
        clears an optional value.

    Returns
    -------
    Spec
        A new validated spec, with no file origin.

    Raises
    ------
    SpecError
        An unknown path or a refused value, naming the path and the value.
    ArgumentError
        ``spec`` is no spec, path or mapping, or ``values`` is no mapping.
    SpecFileError
        ``spec`` names a file that cannot be read.

    Examples
    --------
    >>> from fi_design.spec.file import load_spec, with_values
    >>> spec = load_spec("examples/paper_setup.yaml")
    >>> with_values(spec, {"isolator.stroke": "0.5 mm"}).isolator.stroke
    0.0005
    """
    return spec_with_values(as_spec(spec), values)


def origin(spec: Spec) -> SpecOrigin | None:
    """Return the :class:`SpecOrigin` recorded by :func:`load_spec`, if any."""
    return spec._origin


def _is_yaml_text(source: str) -> bool:
    """Whether a path argument is clearly YAML text: a newline, or a ``key:`` mapping (or
    ``{``) at its start that names no existing file."""
    if "\n" in source or "\r" in source:
        return True
    if not re.match(r"\s*(\{|[A-Za-z_][\w.-]*\s*:(\s|$))", source):
        return False
    try:
        return not Path(source).exists()
    except OSError:  # a name too long for the file system
        return True


def read_bytes(path: Path) -> bytes:
    """Read a spec file's bytes with clear errors for missing files and directories."""
    try:
        exists = path.exists()
    except OSError as exc:  # a name too long for the file system
        raise SpecFileError(f"{path}: cannot read ({exc.strerror})") from None
    if not exists:
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
    except UnicodeDecodeError as exc:
        raise _not_utf8(data, exc.start, source) from None
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
        raise SpecError(f"control character {code_point(exc.character)} is not allowed in a YAML "
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
        hint = ("; this is a CSV file (a measured record?), not a spec, which is YAML: the spec "
                "comes first, e.g. fi-design reconcile SPEC.yaml MEASURED.csv"
                if source is not None and source.lower().endswith(".csv") else "")
        raise SpecError(f"the top level must be a mapping of sections (name, stage, cart, ...), "
                        f"got {kind}{hint}", line=1, source=source)
    return plain(document), document


def _not_utf8(data: bytes, start: int, source: str) -> SpecError:
    """Where a spec stops being UTF-8: the line, column and byte offset of the first bad byte,
    and what the file is (binary, with a NUL byte; else text in another encoding)."""
    line_start = data.rfind(b"\n", 0, start) + 1
    column = len(data[line_start:start].decode("utf-8")) + 1  # valid up to the bad byte
    where = (f"byte {hex(data[start])} at column {column} (byte offset {start} of the file) "
             "is not UTF-8")
    if b"\x00" in data[:65536]:
        text = f"not a text file: {where}"
    else:
        text = (f"{where}: the text is in another encoding (Latin-1 or Windows-1252, as some "
                "editors write, perhaps); save the file as UTF-8")
    return SpecError(text, line=data.count(b"\n", 0, start) + 1, source=source)


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
                        path=dotted(loc[:3]) + ("..." if len(loc) > 3 else ""),
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
                                "'? ...')", path=dotted(loc) or None, line=line,
                                source=source)
            key = knode.value
            if isinstance(key, str) and key in keys:
                raise SpecError(f"key '{key}' appears twice (also on line {keys[key]})",
                                path=dotted(loc + (key,)), line=line, source=source)
            keys[key] = line
            _check_nodes(knode, loc, source, seen)
            _check_nodes(vnode, loc + (key,), source, seen)
    elif isinstance(node, SequenceNode):
        for i, item in enumerate(node.value):
            _check_nodes(item, loc + (i,), source, seen)
    elif isinstance(node, ScalarNode):
        _check_scalar(node, loc, source)


#: Most digits of an integer read from a spec: a float holds up to about 1.8e308.
MAX_DIGITS = 400


def _check_scalar(node, loc: tuple, source: str) -> None:
    """Refuse a scalar that YAML cannot construct: a date that is no date (``2026-13-45``), an
    integer of more digits than Python turns into a number (:data:`MAX_DIGITS`)."""
    from ruamel.yaml.constructor import RoundTripConstructor

    tag = str(node.tag)
    line = node.start_mark.line + 1
    if tag == "tag:yaml.org,2002:timestamp":
        try:
            RoundTripConstructor().construct_yaml_timestamp(node)
        except ValueError as exc:
            raise SpecError(f"{node.value!r} is not a valid date ({exc}); write YYYY-MM-DD",
                            path=dotted(loc) or None, line=line, source=source) from None
    elif tag == "tag:yaml.org,2002:int":
        digits = sum(c.isdigit() for c in node.value)
        if digits > MAX_DIGITS:
            raise SpecError(f"the number {node.value[:12]}... ({digits} digits) is too large for "
                            "a physical value", path=dotted(loc) or None, line=line,
                            source=source)


def plain(obj: Any) -> Any:
    """Plain Python data: dict, list, str, int, float, bool, None (ruamel's scalar types too)."""
    if isinstance(obj, Mapping):
        return {str(k): plain(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [plain(v) for v in obj]
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
        errors = sorted(real_errors(exc.errors(include_url=False)),
                        key=lambda e: e["type"] != "extra_forbidden")
        msgs = [describe(e, raw) for e in errors]
        first_loc = clean_loc(errors[0]["loc"], raw)
        if not first_loc and msgs[0][0]:
            first_loc = tuple(msgs[0][0].split("."))
        line = org.line(first_loc)
        text = msgs[0][1]
        if len(msgs) > 1:
            extra = []
            for (p, m), e in list(zip(msgs, errors))[1:8]:
                ln = org.line(clean_loc(e["loc"], raw))
                extra.append(f"  - {p or '(top level)'}{f' (line {ln})' if ln else ''}: {m}")
            text += f"\n{len(msgs) - 1} more problem(s):\n" + "\n".join(extra)
        raise SpecError(text, path=msgs[0][0] or None, line=line, source=source) from None
    spec._origin = org
    return spec
