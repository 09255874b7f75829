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
    """The spec-file form of an effect entry: each value a string with its unit.

    ``{"type": "quantization", "resolution": "1e-05 m"}``: every YAML reader
    reads the value back as written (a bare ``1e-05`` is a string to YAML 1.1
    readers), angles carry the unit a spec requires of them, and every digit
    is kept (``repr``); a plain fraction stays a number.
    """
    eff = _effects.get(name)
    out: dict = {"type": name}
    for k, v in values.items():
        if v is None:
            continue
        unit = eff.parameter(k).unit
        out[k] = float(v) if unit in ("1", "") else f"{float(v)!r} {unit}"
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

    The input spec's own text is edited (:func:`fi_design.spec.edit.edited_spec_text`:
    comments and layout kept): an entry of the same type is replaced, the
    others are kept; a header comment names the record and the conclusion.
    With the answer ``none`` the spec is written unchanged under that header.

    Parameters
    ----------
    result : ReconcileResult
        The reconciliation.

    Returns
    -------
    str
        YAML that ``load_spec`` reads back (checked).
    """
    from ..spec.edit import edited_spec_text
    from ..spec.file import origin

    spec = result.spec
    entries = [entry_input(e["type"], {k: v for k, v in e.items() if k != "type"})
               for e in result.entries]
    names = {e["type"] for e in entries}
    header = ("effects added by fi-design reconcile" if entries else
              "fi-design reconcile added no effect (the answer is none)")
    header += ((f" from {result.measurement.source}" if result.measurement.source else "")
               + ": " + result.conclusion.replace("\n", " "))
    values = {}
    if entries:
        org = origin(spec)
        written = (org.raw.get("effects") or []) if org is not None else \
            [_input_form(e) for e in spec.effects]
        kept = [e for e in written if not (isinstance(e, dict) and e.get("type") in names)]
        values["effects"] = kept + entries
    return edited_spec_text(spec, values, header=_wrap_comment(header),
                            source="<reconciled spec>")


def _input_form(entry) -> dict:
    """A validated effect entry of the spec in the spec-file form."""
    values = entry.model_dump(exclude={"type"}, exclude_none=True)
    return entry_input(entry.type, values)


def _wrap_comment(text: str, width: int = 96) -> str:
    import textwrap

    return "\n".join("# " + line for line in textwrap.wrap(text, width - 2))
