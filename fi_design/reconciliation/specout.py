"""Writing the result back: spec effect entries and the corrected spec file.

The chosen effects become entries of the spec's ``effects`` list; the
corrected spec keeps the input file's text and comments where it can.
"""

from __future__ import annotations

from .. import effects as _effects
from .. import spec as _spec
from ..errors import SimulationError


def make_entry(name: str, values: dict):
    """A validated spec ``effects`` entry (the model of ``spec.EFFECT_MODELS``) from SI values."""
    return _spec.EFFECT_MODELS[name].model_validate(entry_input(name, values))


def entry_input(name: str, values: dict) -> dict:
    """The spec-file form of an effect entry: SI numbers, angles as ``"<value> rad"``.

    Angles need their unit in a spec (a bare number is ambiguous), so phases are
    written with ``rad``; every other value is a plain SI float.
    """
    eff = _effects.get(name)
    out: dict = {"type": name}
    for k, v in values.items():
        if v is None:
            continue
        unit = eff.parameter(k).unit
        out[k] = f"{float(v)!r} rad" if unit == "rad" else float(v)
    return out


def spec_with_entries(spec, entries):
    """A copy of ``spec`` with effect entries added (an entry of the same type is replaced).

    Parameters
    ----------
    spec : Spec
        The spec.
    entries : sequence of dict
        ``{"type": name, param: value, ...}`` in SI.

    Returns
    -------
    Spec
        A new spec, validated again (:meth:`fi_design.spec.Spec.with_sections`);
        the other sections are shared.
    """
    new = [make_entry(e["type"], {k: v for k, v in e.items() if k != "type"}) for e in entries]
    names = {e.type for e in new}
    kept = [e for e in spec.effects if e.type not in names]
    if "joint_damping" in names and spec.isolator is None:
        raise SimulationError("effect joint_damping needs an isolator")
    return spec.with_sections(effects=tuple(kept + new))


def fixed_spec_text(result) -> str:
    """YAML text of the spec with the chosen effects added to its ``effects`` list.

    When the spec was read from a file without an ``effects`` key, the file's
    text is kept (comments included) and an ``effects:`` block is appended;
    otherwise the spec as written is re-emitted with the new entries. The
    text is validated with :func:`fi_design.specfile.load_spec` before it is
    returned.

    Parameters
    ----------
    result : ReconcileResult
        The reconciliation.

    Returns
    -------
    str
        YAML that ``load_spec`` reads back.
    """
    import yaml

    from ..specfile import load_spec, origin, parse_yaml

    spec = result.spec
    org = origin(spec)
    entries = [entry_input(e["type"], {k: v for k, v in e.items() if k != "type"})
               for e in result.entries]
    names = {e["type"] for e in entries}
    comment = ("# effects added by fi-design reconcile"
               + (f" from {result.measurement.source}" if result.measurement.source else "")
               + ": " + result.conclusion.replace("\n", " "))
    raw_text = None
    if org is not None and org.path is not None:
        try:
            raw_text = org.path.read_text(encoding="utf-8")
        except OSError:
            raw_text = None
    if raw_text is not None and "effects" not in org.raw:
        lines = [raw_text.rstrip("\n"), "", _wrap_comment(comment), "effects:"]
        for e in entries:
            lines.append("  - " + _flow(e))
        text = "\n".join(lines) + "\n"
    else:
        raw = dict(org.raw) if org is not None else spec.model_dump(exclude_none=True)
        old = [e for e in (raw.get("effects") or []) if not (isinstance(e, dict)
                                                             and e.get("type") in names)]
        raw["effects"] = old + entries
        text = _wrap_comment(comment) + "\n" + yaml.safe_dump(raw, sort_keys=False,
                                                              allow_unicode=True)
    data, _ = parse_yaml(text.encode("utf-8"), "<fixed spec>")
    load_spec(data)
    return text


def _wrap_comment(text: str, width: int = 96) -> str:
    import textwrap

    return "\n".join("# " + line if not line.startswith("#") else line
                     for line in textwrap.wrap(text.lstrip("# "), width - 2))


def _flow(entry: dict) -> str:
    parts = [f"type: {entry['type']}"]
    for k, v in entry.items():
        if k == "type":
            continue
        parts.append(f"{k}: {v!r}" if isinstance(v, float) else f"{k}: '{v}'")
    return "{" + ", ".join(parts) + "}"
