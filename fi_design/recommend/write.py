"""The recommended design written into the user's spec: their units, a drawing's digits.

:func:`recommended_values` gives the design's values at dotted paths as the
spec file takes them, in the unit the user wrote at that path (``mm`` stays
``mm``) and rounded to what a drawing carries (:data:`DIGITS` significant
digits); :func:`recommended_spec_text` writes them into the spec's own text
(comments and layout kept), replaces the comments of the keys it changes
(they stated the old values) and adds a revision to the document's history.
The design command on the written spec runs the same computation that signed
the design off.
"""

from __future__ import annotations

import datetime
import math
import re
from typing import Any

from ..display import plain
from ..errors import ArgumentError
from ..results.recommend import RecommendResult

__all__ = ["DIGITS", "written", "recommended_values", "recommended_spec_text", "next_revision"]

#: Significant digits of a written value: what a drawing carries.
DIGITS = 4


def written(spec: Any, path: str, value: float, *, down: bool = False) -> Any:
    """The value at a path in the unit the spec wrote there (else its field's), DIGITS digits;
    ``down`` rounds towards zero (a leaf's width: the stiffness stays at or below the
    design's)."""
    from ..spec.file import path_unit
    from ..spec.edit import written_unit
    from ..spec.units import from_si

    unit = written_unit(spec, path)
    si = path_unit(path)
    shown = si if unit is None else unit
    x = value if unit is None or unit == si else from_si(value, si, unit)
    if down and x > 0:
        scale = 10.0 ** (math.floor(math.log10(x)) - DIGITS + 1)
        x = math.floor(x / scale * (1 + 1e-12)) * scale
    text = plain(x, DIGITS)
    return float(text) if shown in ("", "1") else f"{text} {shown}"


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

        flexure = {**ASSUMED_FLEXURE, **{k: written(spec, f"isolator.flexure.{k}", v,
                                                    down=k == "width")
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
                values[f"isolator.flexure.{k}"] = written(spec, f"isolator.flexure.{k}", v,
                                                          down=k == "width")
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
