"""The inputs section of a design report: every spec value, given or defaulted."""

from __future__ import annotations

import datetime
from typing import Any, Callable

from ..display import NBSP, plain, quantity
from .meta import spec_file

__all__ = ["spec_inputs", "split_inputs", "SETTINGS"]


#: Derived defaults: path -> (rule in words, its value in the resolved model).
_DERIVED: dict[str, tuple[str, Callable[[Any], float]]] = {
    "friction.bristle_damping": ("sqrt(sigma0 (m1 + m2))", lambda m: m.friction.sigma1),
    "isolator.stiffness": ("k_max / 2 (step 3)", lambda m: m.joint.stiffness),
    "isolator.damping": ("2 \u00b7 0.05 \u00b7 sqrt(k m1 m2 / (m1 + m2))",
                         lambda m: m.joint.damping),
    "isolator.limiter.damping": ("2 \u00b7 0.2 \u00b7 sqrt(k_stop m1)",
                                 lambda m: m.limiter.damping),
    "requirements.robustness.stiffness": ("the flexure's stock thickness tolerance, k going "
                                          "with t\u00b3 (5 % without a sized flexure)",
                                          lambda m: _stiffness_scatter(m)),
}


def _stiffness_scatter(model: Any) -> float:
    """The drive stiffness's scatter the robustness study draws [-] (AttributeError without
    an isolator: none scatters, the row reads "not given" as the other joint rules')."""
    if model.joint is None:
        raise AttributeError("no isolator")
    return model.stiffness_scatter


_MISSING = object()

#: Spec keys read so that specs giving them still load, used by nothing (a warning says so).
UNUSED = ("simulation.crossover_scan.step",)

#: Spec paths that set how the tool analyses, not the hardware or what it must meet: the
#: hunting metric and solver, the scatter, the search, the move family and the document.
SETTINGS = ("requirements.hunting.", "requirements.robustness.", "requirements.recommend.",
            "motion.family.", "controller.pade_order", "simulation.", "report.")

INPUTS_INTRO = ("Every value of the spec that describes the hardware, its motion and what it must "
                "meet, as the design used it, in engineering units, with its source: given in "
                "the spec file, a default of the spec schema, or a derived default computed "
                "from other values by the stated rule. How the tool analysed it (the hunting "
                "metric and solver, the scatter, the search, the document) is under Analysis "
                "settings.")
SETTINGS_INTRO = ("The spec's values that set how the design was analysed rather than what the "
                  "hardware is: the hunting metric, the solver and the crossover scan, the "
                  "robustness scatter, the recommendation's search, the move family and the "
                  "document's control, with their sources as under Inputs.")


def _raw_at(raw: Any, key: Any) -> Any:
    if isinstance(raw, dict):
        return raw.get(key, _MISSING)
    if isinstance(raw, (list, tuple)) and isinstance(key, int) and key < len(raw):
        return raw[key]
    return _MISSING


def _as_written(value: Any) -> str:
    if value is _MISSING:
        return ""
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_as_written(v) for v in value) + "]"
    if isinstance(value, bool):
        return "true" if value else "false"
    if value is None:
        return "null"
    if isinstance(value, float):
        return plain(value)  # as the spec file has it (YAML), not as a reader's number
    return str(value)


def _first_sentence(text: str) -> str:
    text = (text or "").split(" [")[0].split(". Default")[0].strip()
    return text.rstrip(".")


def spec_inputs(spec: Any, model: Any) -> list[dict]:
    """Every value of a spec, grouped by section, with unit and whether it was given.

    Parameters
    ----------
    spec : fi_design.spec.Spec
        The spec (its origin tells given values from defaults).
    model : fi_design.model.Model
        The spec resolved: the values of the derived defaults.

    Returns
    -------
    list of dict
        One group per top-level section: ``title`` and ``rows``, each row with
        ``path``, ``description``, ``value`` (SI), ``unit`` (SI), ``written``
        (as in the file) and ``source`` (``given``, ``default``, ``derived
        default: RULE`` or ``not given``).
    """
    from pydantic import BaseModel

    from ..spec.file import path_unit

    src = spec_file(spec)
    raw = src["raw"] if src["raw"] is not None else {}
    rules = _DERIVED
    groups: list[dict] = []

    def leaf(path: str, value: Any, written: Any, info: Any, parent: Any) -> dict:
        given = written is not _MISSING
        try:
            unit = path_unit(path, spec)
        except Exception:  # noqa: BLE001 -- a unit we cannot name is shown without one
            unit = ""
        row = {"path": path, "description": _first_sentence(getattr(info, "description", "")),
               "value": value, "unit": unit, "written": _as_written(written),
               "source": "given" if given else "default"}
        generic = path.split("[")[0] + ("" if "[" not in path else "")
        if value is None and not given:
            rule = rules.get(generic)
            if rule is not None:
                try:
                    row["value"] = float(rule[1](model))
                    row["source"] = f"derived default: {rule[0]}"
                except AttributeError:  # no joint or limiter: a stage without isolator
                    row["source"] = "not given"
            elif generic.startswith("report.document_ids."):
                kind = generic.rsplit(".", 1)[1]
                row["value"] = spec.report.id_for(kind)
                row["source"] = f"derived default: document_id-{kind.upper()}"
            elif path.endswith(".antiresonance") and isinstance(parent, BaseModel):
                from ..spec import antiresonance

                if getattr(parent, "collocated", False):
                    row["value"] = antiresonance(parent)
                    row["source"] = "derived default: frequency / sqrt(2)"
                else:
                    row["source"] = "not used (mode not collocated)"
            else:
                row["source"] = "not given"
        if isinstance(value, tuple) and not value:
            row["value"] = "none"
        elif (isinstance(value, tuple) and len(value) > 1
              and "[min, max]" not in (getattr(info, "description", "") or "")
              and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value)):
            # a list of values ([y, z], [x, y, z]), not a range: commas, not an en dash
            row["value"] = quantity(value, unit, sep=NBSP, joiner=", ")
        if path == "report.revision" and not given and spec.report.revisions:
            row["source"] = "derived default: the last entry of report.revisions"
        if isinstance(value, datetime.date):
            row["value"] = value.isoformat()
        return row

    def walk(model: Any, raw_node: Any, prefix: str, rows: list[dict]) -> None:
        for name, info in type(model).model_fields.items():
            value = getattr(model, name)
            path = f"{prefix}{name}"
            written = _raw_at(raw_node, name)
            if isinstance(value, BaseModel):
                walk(value, written if written is not _MISSING else {}, path + ".", rows)
            elif isinstance(value, tuple) and value and all(isinstance(v, BaseModel)
                                                            for v in value):
                for i, item in enumerate(value):
                    item_raw = _raw_at(written, i) if written is not _MISSING else _MISSING
                    walk(item, item_raw if item_raw is not _MISSING else {}, f"{path}[{i}].",
                         rows)
            elif value is None and info.annotation is not None and _is_section(info):
                rows.append({"path": path, "description": _first_sentence(info.description or ""),
                             "value": "none", "unit": "", "written": "",
                             "source": "not given (section omitted)"})
            elif path in UNUSED and written is _MISSING:
                continue  # read for old specs, used by nothing: listed only where given
            else:
                rows.append(leaf(path, value, written, info, model))

    for name, info in type(spec).model_fields.items():
        value = getattr(spec, name)
        written = _raw_at(raw, name)
        rows: list[dict] = []
        if isinstance(value, BaseModel):
            walk(value, written if written is not _MISSING else {}, name + ".", rows)
        elif isinstance(value, tuple) and value and all(isinstance(v, BaseModel) for v in value):
            for i, item in enumerate(value):
                item_raw = _raw_at(written, i) if written is not _MISSING else _MISSING
                walk(item, item_raw if item_raw is not _MISSING else {}, f"{name}[{i}].", rows)
        elif value is None or (isinstance(value, tuple) and not value):
            rows.append({"path": name, "description": _first_sentence(info.description or ""),
                         "value": "none", "unit": "", "written": _as_written(written),
                         "source": "given" if written is not _MISSING else "not given"})
        else:
            rows.append(leaf(name, value, written, info, spec))
        groups.append({"title": name, "rows": rows})
    return groups


def _is_section(info: Any) -> bool:
    from pydantic import BaseModel

    ann = info.annotation
    for arg in getattr(ann, "__args__", ()) or (ann,):
        if isinstance(arg, type) and issubclass(arg, BaseModel):
            return True
    return False


def split_inputs(groups: list[dict]) -> tuple[dict, dict]:
    """The inputs of :func:`spec_inputs` in two parts: the design and the analysis settings.

    Parameters
    ----------
    groups : list of dict
        :func:`spec_inputs`.

    Returns
    -------
    (dict, dict)
        ``{"intro", "groups"}`` of the hardware, motion and requirements, and of
        the settings (paths under :data:`SETTINGS`); a group without rows is left out.
    """
    design, settings = [], []
    for g in groups:
        own = [r for r in g["rows"] if not r["path"].startswith(SETTINGS)]
        other = [r for r in g["rows"] if r["path"].startswith(SETTINGS)]
        if own:
            design.append({"title": g["title"], "rows": own})
        if other:
            settings.append({"title": g["title"], "rows": other})
    return ({"intro": INPUTS_INTRO, "groups": design},
            {"intro": SETTINGS_INTRO, "groups": settings})

