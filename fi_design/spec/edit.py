"""Writing a spec back: the input's own YAML with values replaced, comments and layout kept.

Every ``--write-spec`` of the command line goes through :func:`edited_spec_text`:
the spec file is read again with ruamel.yaml's round-trip loader
(:func:`fi_design.spec.file.yaml_loader`), the values are set at their dotted
paths (``controller.gains``, ``friction.coulomb``, ``effects``), each with an
optional end-of-line comment, and the document is written out with the input's
comments, key order, flow or block style and indentation. The text is then
read back and validated like any spec (:func:`fi_design.spec.file.load_spec`),
so a spec the tool writes always loads in the tool.

:func:`spec_quantity` writes a value as a string with the unit of its field
(``"6842.91 N/m"``), so that the written file reads the same whatever YAML
reader opens it (a bare ``1e-05`` is a string to YAML 1.1 readers).
"""

from __future__ import annotations

import io
import math
import re
from typing import Any, Mapping, Sequence

from ..display import plain
from ..errors import SpecError
from . import Spec
from .file import load_spec, origin, parse_yaml, path_unit, yaml_loader
from .paths import parse_path
from .units import from_si, to_si

__all__ = ["edited_spec_text", "spec_quantity", "written_unit", "REMOVE"]


class _Remove:
    def __repr__(self) -> str:
        return "REMOVE"


#: A value of :func:`edited_spec_text` that removes the key.
REMOVE = _Remove()


def spec_quantity(path: str, value: float, digits: int | None = None, *,
                  unit: str | None = None) -> Any:
    """A value as the spec file takes it: a string with its field's unit (or ``unit``).

    Parameters
    ----------
    path : str
        Dotted spec path (``"controller.gains.kp"``, ``"isolator.stroke"``).
    value : float
        SI value (Hz for frequencies).
    digits : int, optional
        Significant digits; default all of them: the file gives the same
        float back (``repr`` in the field's unit; in another unit the
        shortest text the spec reads back as ``value``).
    unit : str, optional
        The unit to write it in, of the field's dimension (``"mm"`` for a
        length: the unit the user wrote, :func:`written_unit`); default the
        field's own.

    Returns
    -------
    str or float
        ``"6842.912 N/m"``; a plain number for a value without a unit.

    Raises
    ------
    UnitError
        ``unit`` is not of the field's dimension.

    Examples
    --------
    >>> spec_quantity("isolator.stroke", 0.0003)
    '0.0003 m'
    >>> spec_quantity("controller.gains.ki", 33073.41, digits=6)
    '33073.4 N/(m*s)'
    >>> spec_quantity("isolator.flexure.width", 0.02794631884116351, unit="mm")
    '27.94631884116351 mm'
    >>> spec_quantity("isolator.stroke", 0.0009, unit="mm")
    '0.9 mm'
    """
    si = path_unit(path)
    shown = si if unit is None or si in ("", "1") else unit
    if shown == si:
        number = repr(float(value)) if digits is None else plain(value, digits)
    else:
        number = _exact(path, float(value), si, shown) if digits is None else \
            plain(from_si(value, si, shown), digits)
    if shown in ("", "1"):
        return float(number)
    return f"{number} {shown}"


def _exact(path: str, value: float, si: str, shown: str) -> str:
    """The number of ``value`` [si] in ``shown`` that the spec reads back closest to ``value``
    (the same float where a text does; the unit's conversion may leave an ulp), the shortest
    such text, without an exponent where the value's own has none: ``0.9`` mm for 0.0009 m,
    not ``0.90000000000000002``; ``60`` mm, not ``6e+01``."""
    x = from_si(value, si, shown)
    best, error = repr(x), math.inf
    exponent = "e" in best
    for n in range(1, 18):
        text = plain(x, n)
        if "e" in text and not exponent:  # 6e+01: 60 follows
            continue
        e = abs(to_si(f"{text} {shown}", si, path) - value)
        if e < error:
            best, error = text, e
        if e == 0.0:
            break
    return best


def written_unit(spec: Spec, path: str) -> str | None:
    """The unit the spec's file wrote at a path: ``"mm"`` for ``0.3 mm`` or ``[10 mm, 60 mm]``.

    Parameters
    ----------
    spec : Spec
        A spec read from a file or mapping.
    path : str
        Dotted path (``"isolator.flexure.length"``, ``"motion.moves[0].distance"``).

    Returns
    -------
    str or None
        None where the value is a bare number, absent, or the spec has no
        written form.
    """
    org = origin(spec)
    node: Any = None if org is None else org.raw
    for name, selectors in parse_path(path):
        if not isinstance(node, Mapping) or name not in node:
            return None
        node = node[name]
        for sel in selectors:
            try:
                node = _entry(node, sel, path)
            except SpecError:
                return None
    if isinstance(node, (list, tuple)) and node:
        node = node[0]
    if not isinstance(node, str):
        return None
    m = re.match(r"\s*[-+]?[0-9.]+(?:[eE][-+]?[0-9]+)?\s*(.+?)\s*$", node)
    return m.group(1) if m else None


def edited_spec_text(spec: Spec, values: Mapping[str, Any] | None = None, *,
                     comments: Mapping[str, str] | None = None,
                     replace_comments: bool = False,
                     header: str | Sequence[str] | None = None,
                     source: str = "<written spec>") -> str:
    """The spec's YAML with values replaced at dotted paths; comments and layout kept.

    Parameters
    ----------
    spec : Spec
        The spec to start from. Read from a file, its own text is edited
        (comments, key order, flow or block style, indentation kept); given as
        a mapping, the mapping is written in block style.
    values : mapping of str to value, optional
        Dotted path (``"friction.coulomb"``, ``"controller.gains"``,
        ``"motion.moves[0].distance"``, ``"effects"``) to the value written
        there: a string (with units), a number, a bool, None, a mapping (a new
        section, block style) or a list (of mappings: flow-style entries, as
        effect entries are written); :data:`REMOVE` removes the key. A
        missing section on the way is added.
    comments : mapping of str to str, optional
        Dotted path to an end-of-line comment for that key; a comment the key
        already had is kept after it.
    replace_comments : bool, optional
        The given comments replace the keys' own (which state the values
        replaced) instead of going before them. Default False.
    header : str or sequence of str, optional
        Comment lines put at the top of the file (``#`` added where missing).
    source : str, optional
        Name of the text in an error message.

    Returns
    -------
    str
        YAML text that :func:`fi_design.spec.file.load_spec` reads (checked).

    Raises
    ------
    SpecError
        A value the spec refuses (the message names the path), or a path into
        a value rather than a section.

    Examples
    --------
    >>> from fi_design.spec.file import load_spec
    >>> spec = load_spec("examples/paper_setup.yaml")
    >>> text = edited_spec_text(spec, {"isolator.stroke": "0.5 mm"},
    ...                         comments={"isolator.stroke": "a longer stroke"})
    >>> [ln for ln in text.splitlines() if "stroke: 0.5 mm" in ln][0].split("#")[1].strip()
    'a longer stroke; one-sided, before the limiter engages'
    """
    yaml = yaml_loader()
    org = origin(spec)
    lines = [] if not header else [header] if isinstance(header, str) else list(header)
    if org is not None and org.text is not None:
        text = org.text
        yaml.indent(**_indents(text))
        document = yaml.load(text)
    else:
        lines.append("(written anew from the spec's data: it was not read from a file, so "
                     "there are no comments to keep)")
        from .file import plain

        raw = org.raw if org is not None else spec.model_dump(mode="json", exclude_none=True)
        document = _commented(plain(raw))
        yaml.indent(mapping=2, sequence=4, offset=2)
    for path, value in (values or {}).items():
        parent, key = _parent(document, path)
        if value is REMOVE:
            if key in parent:
                del parent[key]
        elif isinstance(parent, dict) and key not in parent:
            _append(parent, key, _commented(value), top=parent is document)
        else:
            parent[key] = _commented(value)
    for path, note in (comments or {}).items():
        parent, key = _parent(document, path)
        if key in parent:
            old = "" if replace_comments else _eol_comment(parent, key)
            _set_comment(parent, key, note + (f"; {old}" if old else ""))
    buf = io.StringIO()
    yaml.dump(document, buf)
    out = buf.getvalue()
    if org is not None and org.text is not None:
        out = _alias_comments(org.text, out)
    if lines:
        import textwrap

        head = "\n".join(ln if ln.startswith("#") else "\n".join(
            textwrap.wrap(ln, 96, initial_indent="# ", subsequent_indent="# "))
            for block in lines for ln in block.splitlines())
        out = head + "\n" + out
    data, _ = parse_yaml(out.encode("utf-8"), source)
    try:
        load_spec(data)
    except SpecError as exc:
        raise SpecError(f"the spec to write does not load: {exc.message}", path=exc.path) from None
    return out


#: A line whose value is an alias, with a comment after it: ``cart: *s   # same as the stage``.
_ALIAS_LINE = re.compile(r"^(?P<head>[^#\n]*\*[^\s,\]}#]+)[ \t]+(?P<comment>#[^\n]*)$", re.M)


def _alias_comments(text: str, out: str) -> str:
    """The comments after aliases put back on their lines.

    ruamel.yaml (0.19) keeps the comment after an alias (``cart: *s   # ...``)
    as a comment before the next key, and writes it on a line of its own under
    the alias; each such line that was written unchanged is restored as the
    file had it.
    """
    for m in _ALIAS_LINE.finditer(text):
        head, comment = m.group("head"), m.group("comment")
        moved = re.compile(r"^" + re.escape(head) + r"\n[ \t]*" + re.escape(comment.rstrip())
                           + r"[ \t]*$", re.M)
        out = moved.sub(lambda _, line=m.group(0): line, out, count=1)
    return out


def _indents(text: str) -> dict[str, int]:
    """ruamel.yaml's indentation settings that reproduce a file's own layout.

    The mapping indent is that of the first key nested under a top-level key;
    the sequence's dash offset and indent come from the first block list entry.
    """
    mapping, offset = 2, 2
    lines = [ln for ln in text.splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
    for prev, ln in zip(lines, lines[1:]):
        if not prev.startswith((" ", "-")) and prev.rstrip().split("#")[0].rstrip().endswith(":"):
            n = len(ln) - len(ln.lstrip(" "))
            if n and not ln.lstrip().startswith("-"):
                mapping = n
                break
    for prev, ln in zip(lines, lines[1:]):
        if ln.lstrip().startswith("- ") and prev.rstrip().split("#")[0].rstrip().endswith(":"):
            offset = (len(ln) - len(ln.lstrip(" "))) - (len(prev) - len(prev.lstrip(" ")))
            break
    offset = max(offset, 0)
    return {"mapping": mapping, "sequence": offset + 2, "offset": offset}


def _parent(document: Any, path: str) -> tuple[Any, Any]:
    """The container and key of a dotted path, adding missing sections on the way."""
    from ruamel.yaml.comments import CommentedMap

    tokens = parse_path(path)  # the one grammar of spec paths (fi_design.spec.paths)
    steps: list = []
    for name, selectors in tokens:
        steps += [name, *selectors]
    node = document
    for i, step in enumerate(steps[:-1]):
        done = _steps_text(steps[:i + 1])
        if isinstance(step, (int, tuple)):
            node = _entry(node, step, done)
            continue
        if not isinstance(node, dict):
            raise SpecError("holds a value, not a section", path=done)
        if node.get(step) is None:
            if step in node:
                node[step] = CommentedMap()
            else:
                _append(node, step, CommentedMap(), top=node is document)
        node = node[step]
    if not isinstance(node, (dict, list)):
        raise SpecError("holds a value, not a section", path=path)
    last = steps[-1]
    if isinstance(last, tuple):  # [type=NAME] as the last step: the entry's index
        if not isinstance(node, list):
            raise SpecError("is not a list; remove the [...]", path=path)
        _entry(node, last, path)
        last = next(i for i, e in enumerate(node) if isinstance(e, dict)
                    and e.get("type") == last[1])
    return node, last


def _steps_text(steps: list) -> str:
    """Steps of :func:`_parent` (keys, indices, type selectors) as a dotted path."""
    out = ""
    for s in steps:
        out += (f"[{s}]" if isinstance(s, int) else f"[type={s[1]}]" if isinstance(s, tuple)
                else ("." if out else "") + s)
    return out


def _entry(node: Any, selector: int | tuple, done: str) -> Any:
    """The list entry a selector of a spec path names (``[0]`` or ``[type=NAME]``)."""
    if not isinstance(node, list):
        raise SpecError("is not a list; remove the [...]", path=done)
    if isinstance(selector, tuple):
        hits = [e for e in node if isinstance(e, dict) and e.get("type") == selector[1]]
        if not hits:
            raise SpecError(f"the spec has no entry of type '{selector[1]}'", path=done)
        return hits[0]
    if selector >= len(node):
        raise SpecError(f"the spec has no entry {selector} here", path=done)
    return node[selector]


def _commented(value: Any, flow: bool = False) -> Any:
    """Plain data as ruamel's round-trip types: mappings in lists written in flow style."""
    from ruamel.yaml.comments import CommentedMap, CommentedSeq

    if isinstance(value, Mapping):
        out = CommentedMap((k, _commented(v, flow=flow)) for k, v in value.items())
        if flow:
            out.fa.set_flow_style()
        return out
    if isinstance(value, (list, tuple)):
        return CommentedSeq(_commented(v, flow=True) for v in value)
    return value


def _eol_comment(parent: Any, key: Any) -> str:
    """The end-of-line comment a key has in the file, without the ``#``."""
    token = _token(parent, key)
    if token is None or not getattr(token, "value", None):
        return ""
    first = token.value.split("\n")[0].strip()
    return first[1:].strip() if first.startswith("#") else ""


def _token(parent: Any, key: Any) -> Any:
    ca = getattr(parent, "ca", None)
    item = ca.items.get(key) if ca is not None else None
    return item[2] if item and len(item) > 2 else None


def _set_comment(parent: Any, key: Any, text: str) -> None:
    """Set a key's end-of-line comment, keeping its column and the blank lines after it."""
    from ruamel.yaml.error import CommentMark
    from ruamel.yaml.tokens import CommentToken

    old = _token(parent, key)
    tail, column = "", None
    if old is not None:
        tail = old.value.partition("\n")[2]
        column = old.column if old.value.lstrip().startswith("#") else None
    if column is None:  # align with the section's other comments
        columns = [t.column for t in (_token(parent, k) for k in parent)
                   if t is not None and t.value.lstrip().startswith("#")]
        column = max(columns, default=0)
    token = CommentToken(f"# {' '.join(text.split())}\n{tail}", CommentMark(column), None)
    item = parent.ca.items.setdefault(key, [None, None, None, None])
    item[2] = token


def _append(parent: Any, key: Any, value: Any, *, top: bool) -> None:
    """Add a new key at the end of a mapping, after the blank lines that closed it.

    ruamel.yaml keeps a section's closing blank line in the comment of its
    last key; the new key takes it over, so the section stays separated from
    the next. A new top-level section gets a blank line before it.
    """
    from ruamel.yaml.error import CommentMark
    from ruamel.yaml.tokens import CommentToken

    keys = list(parent)
    parent[key] = value
    if not keys:
        return
    if top:
        parent.yaml_set_comment_before_after_key(key, before="\n")
        return
    last = _token(parent, keys[-1])
    if last is None or "\n\n" not in last.value:
        return
    head, _, tail = last.value.partition("\n")
    last.value = head + "\n"
    parent.ca.items[key] = [None, None, CommentToken("\n" + tail, CommentMark(0), None), None]
