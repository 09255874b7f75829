"""The spec with the identified values: ``--write-spec`` (DESIGN.md section 8).

:func:`spec_values` lists the values by dotted path, :func:`identified_spec`
validates them as a spec, :func:`identified_spec_text` writes the input
spec's own YAML text with the values replaced in place and commented.
"""

from __future__ import annotations

import math

from .regression import IMPLAUSIBLE
from .results import DYNAMIC, IdentificationResult


def spec_values(result: IdentificationResult) -> dict[str, float]:
    """The spec values the identification fills in, by dotted path (SI).

    ``friction.coulomb``, ``friction.coulomb_negative`` (per-direction form;
    in the symmetric form equal to ``coulomb``, written only where the spec
    gives one),
    ``friction.viscous``, ``friction.viscous_negative``, ``friction.offset``
    (0 in the per-direction form, which absorbs it), ``stage.mass`` and
    ``cart.mass`` (identified, or the total split in the spec's ratio), and
    the dynamic parameters that were identified (``friction.static``,
    ``friction.stribeck_velocity``, ``friction.bristle_stiffness``). Where
    static friction is not identified, ``friction.static`` keeps the spec's
    friction gap Fs - Fc on the identified Coulomb friction: the gap
    (guideline step 1) stays the user's assumption, not a value derived from
    the record; the Stribeck velocity and bristle stiffness not identified
    keep the spec's own values.

    Parameters
    ----------
    result : IdentificationResult
        The identification (with a spec).
    """
    return _values(result.spec, result.parameters, result.masses, result.form)


def _values(spec, params, masses, form) -> dict[str, float]:
    v = {"stage.mass": masses.stage, "cart.mass": masses.cart,
         "friction.coulomb": params["coulomb"].value,
         "friction.viscous": params["viscous"].value,
         "friction.viscous_negative": params["viscous_negative"].value}
    if form == "symmetric":
        v["friction.offset"] = params["offset"].value
        if spec is not None and spec.friction.coulomb_negative is not None:
            v["friction.coulomb_negative"] = params["coulomb"].value  # the form: the same
    else:
        v["friction.coulomb_negative"] = params["coulomb_negative"].value
        v["friction.offset"] = 0.0
    for name in DYNAMIC:
        p = params.get(name)
        if p is not None and p.identifiable and p.value is not None:
            v[f"friction.{name}"] = p.value
    if "friction.static" not in v and spec is not None:  # keep the spec's friction gap
        v["friction.static"] = v["friction.coulomb"] + spec.friction.static - \
            spec.friction.coulomb
    return v


def identified_spec(spec, params, masses, form):
    """The spec with identified values (a :class:`~fi_design.spec.Spec`, no file origin).

    Raises
    ------
    SpecError
        An identified value the spec refuses (e.g. a negative Coulomb friction
        in the per-direction form: then use the symmetric form).
    """
    from ..errors import SpecError
    from ..specfile import with_values

    values = _values(spec, params, masses, form)
    bad = [k for k in ("stage.mass", "cart.mass", "friction.coulomb",
                       "friction.coulomb_negative", "friction.viscous",
                       "friction.viscous_negative") if k in values and values[k] < 0.0
           or k in values and values[k] == 0.0 and "viscous" not in k]
    if bad:
        raise SpecError(f"the identified value {values[bad[0]]:.4g} {_SPEC_UNITS[bad[0]]} is "
                        f"not positive, which a spec cannot hold: {IMPLAUSIBLE}", path=bad[0])
    if values.get("friction.static", math.inf) < values["friction.coulomb"]:
        raise SpecError(f"the identified static friction {values['friction.static']:.4g} N lies "
                        f"below the Coulomb friction {values['friction.coulomb']:.4g} N, which a "
                        f"spec cannot hold: {IMPLAUSIBLE}", path="friction.static")
    return with_values(spec, {k: float(x) for k, x in values.items()})


#: Unit written for every spec path the identification fills in.
_SPEC_UNITS = {"stage.mass": "kg", "cart.mass": "kg", "friction.coulomb": "N",
               "friction.coulomb_negative": "N", "friction.viscous": "N*s/m",
               "friction.viscous_negative": "N*s/m", "friction.offset": "N",
               "friction.static": "N", "friction.stribeck_velocity": "m/s",
               "friction.bristle_stiffness": "N/m"}


def identified_spec_text(result: IdentificationResult) -> str:
    """YAML text of the input spec with the identified values filled in (``--write-spec``).

    The spec file's own text is kept, comments included: each value of
    :func:`spec_values` replaces the one written in the file (block or
    one-line flow mapping), with a comment giving the estimate, its
    standard error and the value it replaced; a missing key is added to its
    section. A header comment names the record and the form. Where the text
    cannot be edited in place (a spec given as a mapping, a section written
    in a multi-line flow style), the spec is written anew from its data with
    the same header, and says that comments were not kept. The text is
    checked with :func:`fi_design.specfile.load_spec` before it is returned.

    Parameters
    ----------
    result : IdentificationResult
        An identification with a spec.

    Returns
    -------
    str
        YAML that ``load_spec`` (and so ``fi-design SPEC.yaml``) accepts.

    Raises
    ------
    SpecError
        No spec, or an identified value the spec cannot hold.
    """
    from ..errors import SpecError
    from ..specfile import load_spec, origin, parse_yaml

    spec = result.spec
    if spec is None:
        raise SpecError("identification without a spec: nothing to fill in (give --spec)")
    identified_spec(spec, result.parameters, result.masses, result.form)  # refuses bad values
    values = spec_values(result)
    comments = {path: _value_comment(result, path) for path in values}
    org = origin(spec)
    header = _header(result)
    text = None
    if org is not None and org.path is not None:
        try:
            text = _edited(org.path.read_text(encoding="utf-8"), org, values, comments)
        except (OSError, UnicodeDecodeError):
            text = None
    if text is not None:
        text = header + "\n" + text
        try:
            data, _ = parse_yaml(text.encode("utf-8"), "<identified spec>")
            load_spec(data)
        except SpecError:
            text = None
    if text is None:
        text = _rewritten(org.raw if org is not None else spec.model_dump(exclude_none=True),
                          values, header)
        data, _ = parse_yaml(text.encode("utf-8"), "<identified spec>")
        load_spec(data)
    return text


def _quantity(path: str, value: float) -> str:
    return f"{value:.6g} {_SPEC_UNITS[path]}"


def _value_comment(result: IdentificationResult, path: str) -> str:
    section, key = path.split(".")
    unit = _SPEC_UNITS[path]
    if section in ("stage", "cart"):
        m = result.masses
        se = m.stage_std_error if section == "stage" else m.cart_std_error
        if se is not None:
            return f"identified {_quantity(path, getattr(m, section))} +- {se:.2g} {unit}"
        return f"the identified total mass, {m.source}"
    if key == "coulomb_negative" and result.form == "symmetric":
        return "symmetric form: equal to coulomb"
    if key == "offset" and result.form == "per_direction":
        return "per-direction form: the offset is absorbed in coulomb and coulomb_negative"
    if key == "static" and not result.parameters["static"].identifiable:
        f = result.spec.friction
        return (f"not identified: the spec's friction gap Fs - Fc = "
                f"{f.static - f.coulomb:.4g} N kept on the identified coulomb")
    p = result.parameters[key]
    return f"identified {_quantity(path, p.value)} +- {p.std_error:.2g} {unit}"


def _header(result: IdentificationResult) -> str:
    src = result.measurement.source or "a measured record"
    lines = [f"# Friction and masses identified by fi-design identify from {src}",
             f"# ({result.form.replace('_', '-')} form, {result.model} model, relative force "
             f"error {result.fit.relative_error:.3g}); values marked 'identified' below."]
    for name in DYNAMIC:
        p = result.parameters[name]
        if not p.identifiable:
            kept = ("keeps the spec's friction gap Fs - Fc" if name == "static" else
                    "is the spec's own value")
            lines.append(f"# friction.{name} {kept}: not identifiable from this record.")
    if (result.parameters["bristle_stiffness"].identifiable and result.spec is not None
            and result.spec.friction.bristle_damping is None):
        lines.append("# friction.bristle_damping is not identified: its default, sqrt(sigma0 "
                     "(m1 + m2)), follows the identified bristle stiffness.")
    return "\n".join(lines)


def _edited(text: str, org, values: dict, comments: dict) -> str | None:
    """The spec text with values replaced or added in place; None where that is not safe."""
    import re

    lines = text.split("\n")
    inserts: dict[int, list[str]] = {}
    for path, value in values.items():
        section, key = path.split(".")
        new = _quantity(path, value)
        line_no = org.lines.get((section, key))
        if line_no is not None:
            i = line_no - 1
            block = re.match(rf"^(\s*){re.escape(key)}\s*:\s*([^#]*?)\s*(#.*)?$", lines[i])
            if block:
                old = block.group(2)
                extra = f"; {block.group(3)[1:].strip()}" if block.group(3) else ""
                lines[i] = f"{block.group(1)}{key}: {new}  # {comments[path]} (was {old}){extra}"
                continue
            flow = re.compile(rf"(\b{re.escape(key)}\s*:\s*)([^,}}#]+?)(\s*[,}}])")
            if lines[i].count("{") == 1 and lines[i].count("}") == 1 and \
                    len(flow.findall(lines[i])) == 1:
                body, _, old_comment = lines[i].partition("#")
                body = flow.sub(lambda m: m.group(1) + new + m.group(3), body).rstrip()
                note = f"{key}: {comments[path]}" + (f"; {old_comment.strip()}" if old_comment
                                                     else "")
                lines[i] = f"{body}  # {note}"
                continue
            return None
        keys = [ln for loc, ln in org.lines.items() if len(loc) >= 2 and loc[0] == section]
        head = org.lines.get((section,))
        if head is None or not keys or min(keys) == head:
            return None  # section missing or written in flow style: no safe place
        first = lines[min(keys) - 1]
        indent = first[:len(first) - len(first.lstrip())]
        inserts.setdefault(max(keys) - 1, []).append(f"{indent}{key}: {new}  # {comments[path]}")
    for i in sorted(inserts, reverse=True):
        lines[i + 1:i + 1] = inserts[i]
    return "\n".join(lines)


def _rewritten(raw: dict, values: dict, header: str) -> str:
    import yaml

    data = {k: (dict(v) if isinstance(v, dict) else v) for k, v in raw.items()}
    for path, value in values.items():
        section, key = path.split(".")
        data.setdefault(section, {})[key] = _quantity(path, value)
    return (header + "\n# (written anew from the spec's data: its comments are not kept)\n"
            + yaml.safe_dump(data, sort_keys=False, allow_unicode=True))
