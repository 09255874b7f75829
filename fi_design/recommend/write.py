"""The recommended design written into the user's spec: their units, every digit.

:func:`recommended_values` gives the design's values at dotted paths as the
spec file takes them, in the unit the user wrote at that path (``mm`` stays
``mm``) and with every digit (the spec reads each back as the design's value,
:func:`fi_design.spec.edit.spec_quantity`); :func:`recommended_spec_text`
writes them into the spec's own text (comments and layout kept), replaces the
comments of the keys it changes (they stated the old values) and adds a
revision to the document's history. The design command on the written spec
runs the same computation that signed the design off: the same guide, joint
stiffness and crossover, not a drawing's rounding of them (a width rounded to
four digits gave 4399 N/m for the 4400 N/m signed off).
"""

from __future__ import annotations

import datetime
import re
from typing import Any

from ..errors import ArgumentError
from ..results.recommend import RecommendResult

__all__ = ["DIGITS", "written", "recommended_values", "recommended_spec_text", "next_revision"]

#: Significant digits of a value shown to a person (the least change's edits); a value written
#: into a spec carries every digit.
DIGITS = 4


def written(spec: Any, path: str, value: float, *, digits: int | None = None) -> Any:
    """The value at a path in the unit the spec wrote there (else its field's), as the spec
    file takes it: every digit, the spec reading it back as ``value``
    (:func:`fi_design.spec.edit.spec_quantity`); or ``digits`` significant digits."""
    from ..spec.edit import spec_quantity, written_unit

    return spec_quantity(path, value, digits, unit=written_unit(spec, path))


def recommended_values(result: RecommendResult) -> dict[str, Any]:
    """The spec values of a recommended design, by dotted path, as the spec file takes them.

    Parameters
    ----------
    result : RecommendResult
        The search.

    Returns
    -------
    dict
        ``isolator.stroke``, the guide's ``isolator.flexure.length``,
        ``width`` and ``thickness`` (the joint's stiffness then follows from
        the guide: ``isolator.stiffness`` removed), ``isolator.damping`` when
        the spec gives a damping (its ratio kept), the measured modes that
        belong to the spec's own guide removed, and ``controller.crossover``
        for a spec tuned by the rule, ``controller.filters`` with the notch the
        search added; for a spec without isolator or flexure the sections as a
        whole.
    """
    from ..spec.edit import REMOVE

    d, spec = result.design, result.spec
    values: dict[str, Any] = {}
    iso = spec.isolator
    guide = {"length": d.length, "width": d.width, "thickness": d.thickness}
    if iso is None or iso.flexure is None:
        from .space import ASSUMED_FLEXURE

        flexure = {**ASSUMED_FLEXURE, **{k: written(spec, f"isolator.flexure.{k}", v)
                                         for k, v in guide.items()}}
        flexure["material"] = {"youngs_modulus": "200 GPa", "allowed_stress": "300 MPa",
                               "density": "7800 kg/m^3"}
    if iso is None:
        section = {"stroke": written(spec, "isolator.stroke", d.stroke), "flexure": flexure}
        if d.damping is not None:
            section["damping"] = written(spec, "isolator.damping", d.damping)
        values["isolator"] = section
    else:
        values["isolator.stroke"] = written(spec, "isolator.stroke", d.stroke)
        values["isolator.stiffness"] = REMOVE
        if iso.flexure is None:
            values["isolator.flexure"] = flexure
        else:
            for k, v in guide.items():
                values[f"isolator.flexure.{k}"] = written(spec, f"isolator.flexure.{k}", v)
        if d.damping is not None:
            values["isolator.damping"] = written(spec, "isolator.damping", d.damping)
        kept = [m for m in iso.parasitic_modes if m.direction == "structure"]
        if len(kept) != len(iso.parasitic_modes):
            values["isolator.parasitic_modes"] = (
                [m.model_dump(mode="json", exclude_none=True) for m in kept] if kept else REMOVE)
    if result.rule:
        values["controller.crossover"] = written(spec, "controller.crossover", d.crossover)
    if result.notch is not None:
        from .constraints import notch_entries

        values["controller.filters"] = notch_entries(spec, result.notch)
    return values


def next_revision(label: str) -> str:
    """The revision after ``label``: ``A`` -> ``B``, ``Z`` -> ``AA``, ``3`` -> ``4``, ``B2`` ->
    ``B3``.

    Examples
    --------
    >>> [next_revision(x) for x in ("A", "Z", "7", "B2", "draft")]
    ['B', 'AA', '8', 'B3', 'draft.1']
    """
    m = re.match(r"^(.*?)(\d+)$", label)
    if m:
        return f"{m.group(1)}{int(m.group(2)) + 1}"
    if re.fullmatch(r"[A-Z]+", label):
        n = 0
        for ch in label:
            n = n * 26 + ord(ch) - 64
        n += 1
        out = ""
        while n:
            n, r = divmod(n - 1, 26)
            out = chr(65 + r) + out
        return out
    return f"{label}.1"


def recommended_spec_text(result: RecommendResult, *, date: datetime.date | None = None) -> str:
    """YAML text of the input spec with the recommended design written in.

    The input's text is edited (comments and layout kept,
    :func:`fi_design.spec.edit.edited_spec_text`), the comments of the keys
    changed replaced, and a revision added to ``report.revisions``; the design
    command on it runs the same computation that signed the design off.

    Parameters
    ----------
    result : RecommendResult
        A feasible search (the nearest design of an infeasible one is not
        written: it does not pass).
    date : datetime.date, optional
        The new revision's date; default today.

    Returns
    -------
    str

    Raises
    ------
    ArgumentError
        The search found no design that passes.
    """
    from ..spec.edit import REMOVE, edited_spec_text

    if not result.feasible:
        raise ArgumentError("no design of the searched space passes: there is no "
                            "recommendation to write (the nearest one fails the sign-off)")
    spec = result.spec
    values = recommended_values(result)
    info = spec.report
    rev = next_revision(info.revision if not info.revisions else info.revisions[-1].revision)
    revisions = [r.model_dump(exclude_none=True) for r in info.revisions]
    revisions.append({"revision": rev, "date": date or datetime.date.today(),
                      "description": "the isolator recommended by fi-design recommend"})
    values["report.revisions"] = revisions
    if "revision" in (getattr(spec, "_origin", None).raw.get("report", {})
                      if getattr(spec, "_origin", None) is not None else {}):
        values["report.revision"] = rev
    comments = {p: "recommended" for p, v in values.items()
                if v is not REMOVE and not p.startswith("report.")
                and not isinstance(v, dict)}
    header = ["the isolator and crossover written by fi-design recommend: the stiffest "
              "buildable joint that keeps the hunting margin with its reserves;",
              f"{result.advice}"]
    return edited_spec_text(spec, values, comments=comments, replace_comments=True,
                            header=header, source="<spec with the recommended design>")
