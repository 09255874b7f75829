"""The spec with the identified values: ``--write-spec`` (docs/interfaces.md).

:func:`spec_values` lists the values by dotted path, :func:`identified_spec`
validates them as a spec, :func:`identified_spec_text` writes the input
spec's own YAML text with the values replaced in place and commented
(:func:`fi_design.spec.edit.edited_spec_text`: comments and layout kept).
"""

from __future__ import annotations

import math

from ..display import number, percent, plain, quantity
from .regression import IMPLAUSIBLE, mass_leaks, unit_slip
from ..results.identification import DYNAMIC, IdentificationResult


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

    Where identify's note says not to write the mass (:func:`mass_kept`: far
    from the spec's with a fit that leaves a force unexplained, which leaks
    into it), ``stage.mass`` and ``cart.mass`` are the spec's own; the
    friction is the identified.

    A record that slides in one direction only identifies that direction's
    friction with the force offset included: the spec's offset is kept and
    that direction's Coulomb friction is the identified level less it
    (``coulomb = level - offset`` forwards, ``coulomb_negative = level +
    offset`` backwards); the other direction keeps the spec's own friction,
    written out (so that it no longer follows ``coulomb``).

    Parameters
    ----------
    result : IdentificationResult
        The identification (with a spec).
    """
    return _values(result.spec, result.parameters, result.masses, result.form,
                   result.direction, keep_mass=mass_kept(result))


def mass_kept(result: IdentificationResult) -> bool:
    """Whether ``--write-spec`` keeps the spec's stage and cart masses.

    True where identify's own note says not to write its mass into the spec
    (:func:`fi_design.identification.regression.mass_leaks`): the total mass
    lies beyond a factor of 1.5 from the spec's and the fit leaves 5 % or more
    of the force unexplained, so a force the model lacks leaks into the mass
    through the filter (it follows the filter's cut-off, not the stage).

    Parameters
    ----------
    result : IdentificationResult
        The identification.
    """
    return mass_leaks(result.parameters["mass"], result.spec, result.fit)


def kept_mass_message(result: IdentificationResult) -> str:
    """What ``--write-spec`` did with the masses when :func:`mass_kept`, else ``""``.

    Parameters
    ----------
    result : IdentificationResult
        The identification.
    """
    if not mass_kept(result):
        return ""
    spec, p = result.spec, result.parameters["mass"]
    return (f"kept the spec's stage and cart masses ({quantity(spec.stage.mass, 'kg', 4)} and "
            f"{quantity(spec.cart.mass, 'kg', 4)}): the identified mass "
            f"{quantity(p.value, 'kg', 4)} is far from them and, by the fit, a force the model "
            "lacks leaks into it (see the note), so it is not written; the identified friction "
            "is written")


def _values(spec, params, masses, form, direction: str = "both",
            keep_mass: bool = False) -> dict[str, float]:
    v = _identified_values(spec, params, masses, form, direction)
    if keep_mass and spec is not None:
        v["stage.mass"], v["cart.mass"] = spec.stage.mass, spec.cart.mass
    return v


def _identified_values(spec, params, masses, form, direction: str) -> dict[str, float]:
    if direction != "both":
        return _one_direction_values(spec, params, masses, direction)
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


def _one_direction_values(spec, params, masses, direction: str) -> dict[str, float]:
    """The values of a record that slides one way (see :func:`spec_values`)."""
    from ..errors import SpecError

    if spec is None:
        raise SpecError("identification without a spec: nothing to fill in (give --spec)")
    f = spec.friction
    v = {"stage.mass": masses.stage, "cart.mass": masses.cart}
    if direction == "positive":
        v["friction.coulomb"] = params["coulomb"].value - f.offset
        v["friction.viscous"] = params["viscous"].value
        v["friction.coulomb_negative"] = f.coulomb if f.coulomb_negative is None \
            else f.coulomb_negative
        v["friction.viscous_negative"] = f.viscous if f.viscous_negative is None \
            else f.viscous_negative
    else:
        v["friction.coulomb_negative"] = params["coulomb_negative"].value + f.offset
        v["friction.viscous_negative"] = params["viscous_negative"].value
    for name in DYNAMIC:
        p = params.get(name)
        if p is not None and p.identifiable and p.value is not None:
            v[f"friction.{name}"] = p.value
    if "friction.static" not in v and "friction.coulomb" in v:  # keep the spec's friction gap
        v["friction.static"] = v["friction.coulomb"] + f.static - f.coulomb
    return v


def identified_spec(spec, params, masses, form, direction: str = "both",
                    keep_mass: bool = False):
    """The spec with identified values (a :class:`~fi_design.spec.Spec`, no file origin).

    ``keep_mass``: the spec's stage and cart masses instead of the identified
    ones (see :func:`mass_kept`).

    Raises
    ------
    SpecError
        An identified value the spec refuses (e.g. a negative Coulomb friction
        in the per-direction form: then use the symmetric form).
    """
    from ..errors import SpecError
    from ..spec.file import with_values

    slip = unit_slip(params["mass"].value, spec)
    if slip is not None:
        raise SpecError(f"the identified mass {quantity(params['mass'].value, 'kg', 4)} is a "
                        f"unit's factor from the spec's {quantity(float(spec.total_mass), 'kg', 4)}:"
                        f" most likely {slip}, and every identified force carries the same "
                        "factor; fix the record's column and identify again", path="stage.mass")
    values = _values(spec, params, masses, form, direction, keep_mass)
    bad = [k for k in ("stage.mass", "cart.mass", "friction.coulomb",
                       "friction.coulomb_negative", "friction.viscous",
                       "friction.viscous_negative") if k in values and values[k] < 0.0
           or k in values and values[k] == 0.0 and "viscous" not in k]
    if bad:
        flipped = all(values[k] < 0.0 for k in ("stage.mass", "friction.coulomb")
                      if k in values)
        raise SpecError(f"the identified value {quantity(values[bad[0]], _SPEC_UNITS[bad[0]], 4)} "
                        "is not positive, which a spec cannot hold: " + (
                            "the mass and the friction are negative together, so force_N most "
                            "likely has the wrong sign: flip the column and identify again"
                            if flipped else IMPLAUSIBLE), path=bad[0])
    if values.get("friction.static", math.inf) < values.get("friction.coulomb", 0.0):
        raise SpecError("the identified static friction "
                        f"{quantity(values['friction.static'], 'N', 4)} lies below the Coulomb "
                        f"friction {quantity(values['friction.coulomb'], 'N', 4)}, which a "
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

    The spec file's own text is kept, comments and layout included
    (:func:`fi_design.spec.edit.edited_spec_text`): each value of
    :func:`spec_values` replaces the one written in the file, with a comment
    giving the estimate, its standard error and the value it replaced; a
    missing key is added to its section. A header comment names the record
    and the form. Where :func:`mass_kept`, the masses are the spec's own, and
    the header and their comments say why. The text is checked with :func:`fi_design.spec.file.load_spec`
    before it is returned.

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
    from ..spec.edit import edited_spec_text, spec_quantity
    from ..spec.file import origin

    spec = result.spec
    if spec is None:
        raise SpecError("identification without a spec: nothing to fill in (give --spec)")
    identified_spec(spec, result.parameters, result.masses, result.form,
                    result.direction, mass_kept(result))  # refuses bad values
    values = spec_values(result)
    org = origin(spec)
    raw = org.raw if org is not None else {}
    comments = {}
    for path in values:
        section, key = path.split(".")
        old = (raw.get(section) or {}).get(key) if isinstance(raw.get(section), dict) else None
        kept = path in ("stage.mass", "cart.mass") and mass_kept(result)
        comments[path] = _value_comment(result, path) + ("" if old is None or kept
                                                         else f" (was {old})")
    return edited_spec_text(spec, {p: spec_quantity(p, v, digits=6) for p, v in values.items()},
                            comments=comments, header=_header(result),
                            source="<identified spec>")


def _quantity(path: str, value: float) -> str:
    # a value in a spec's comment reads as the spec's own values do (copied into a field as is)
    return f"{plain(value, 6)} {_SPEC_UNITS[path]}"


def _value_comment(result: IdentificationResult, path: str) -> str:
    section, key = path.split(".")
    unit = _SPEC_UNITS[path]
    if section in ("stage", "cart"):
        if mass_kept(result):
            return ("the spec's own mass, kept: identify's mass is far from the spec's and a "
                    "force the model lacks leaks into it (see the header)")
        m = result.masses
        se = m.stage_std_error if section == "stage" else m.cart_std_error
        if se is not None:
            return f"identified {_quantity(path, getattr(m, section))} +- {plain(se, 2)} {unit}"
        return f"the identified total mass, {m.source}"
    if result.direction != "both":
        side = result.direction
        own = {"positive": ("coulomb", "viscous"),
               "negative": ("coulomb_negative", "viscous_negative")}[side]
        if key not in own and key in ("coulomb", "coulomb_negative", "viscous",
                                      "viscous_negative"):
            return f"the spec's own value: the record slides in the {side} direction only"
        if key in ("coulomb", "coulomb_negative"):
            p = result.parameters[key]
            return (f"identified {_quantity(path, p.value)} +- {plain(p.std_error, 2)} {unit} "
                    f"sliding {side}, the offset included, "
                    f"{'less' if key == 'coulomb' else 'plus'} the spec's offset (one direction "
                    "cannot separate them)")
    if key == "coulomb_negative" and result.form == "symmetric":
        return "symmetric form: equal to coulomb"
    if key == "offset" and result.form == "per_direction":
        return "per-direction form: the offset is absorbed in coulomb and coulomb_negative"
    if key == "static" and not result.parameters["static"].identifiable:
        f = result.spec.friction
        return (f"not identified: the spec's friction gap Fs - Fc = "
                f"{plain(f.static - f.coulomb, 4)} N kept on the identified coulomb")
    p = result.parameters[key]
    return f"identified {_quantity(path, p.value)} +- {plain(p.std_error, 2)} {unit}"


def _header(result: IdentificationResult) -> str:
    src = result.measurement.source or "a measured record"
    lines = [f"# Friction and masses identified by fi-design identify from {src}",
             f"# ({result.form.replace('_', '-')} form, {result.model} model, relative force "
             f"error {number(result.fit.relative_error, 3)}); values marked 'identified' below."]
    if mass_kept(result):
        p = result.parameters["mass"]
        lines += ["# stage.mass and cart.mass are the spec's own, kept: the identified total "
                  f"mass {_quantity('stage.mass', p.value)}",
                  f"# is far from them and the fit leaves {percent(result.fit.relative_error, 2)}"
                  " of the force unexplained, a force the model",
                  "# lacks that leaks into the mass; identify's note says not to write it into "
                  "the spec",
                  "# (fi-design reconcile names the missing force)."]
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
