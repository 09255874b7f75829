"""The parts every report shares: title block, date, spec provenance, software versions."""

from __future__ import annotations

import datetime as _dt
import os
from typing import Any

from .filters import WRAP_MARK, WRAP_WIDTH, wrapped_lines

__all__ = ["TITLES", "report_date", "title_block", "spec_file", "spec_listing", "versions"]

#: Title of each kind of report.
TITLES = {
    "design": "Friction isolator design report",
    "sweep": "Hunting map (parameter study)",
    "study": "Hunting maps of the paper's parameter study",
    "robustness": "Robustness of the hunting verdict",
    "reconcile": "Model and measurement reconciliation",
    "recommend": "Friction isolator recommendation (design search)",
    "identify": "Friction identification from a measured record",
}


def report_date(date: Any = None) -> str:
    """The report date as ``YYYY-MM-DD``.

    Parameters
    ----------
    date : str, datetime.date or None
        Given date (a string is used as written); None: ``SOURCE_DATE_EPOCH``
        when set (reproducible builds), else today.

    Returns
    -------
    str
    """
    if date is None:
        epoch = os.environ.get("SOURCE_DATE_EPOCH", "").strip()
        if epoch.isdigit():
            return _dt.datetime.fromtimestamp(int(epoch), _dt.timezone.utc).date().isoformat()
        return _dt.date.today().isoformat()
    if isinstance(date, (_dt.date, _dt.datetime)):
        return date.isoformat()[:10]
    return str(date)


def versions() -> list[dict]:
    """Python and the versions of the packages behind a report, for its appendix.

    Returns
    -------
    list of dict
        ``name`` and ``version`` (``not installed`` when missing).
    """
    import platform
    from importlib.metadata import PackageNotFoundError, version

    rows = [{"name": "Python", "version": platform.python_version()}]
    for dist in ("fi_design", "numpy", "scipy", "control", "numba", "pydantic", "pint",
                 "matplotlib", "jinja2", "weasyprint"):
        try:
            rows.append({"name": dist, "version": version(dist)})
        except PackageNotFoundError:
            rows.append({"name": dist, "version": "not installed"})
    return rows


def spec_file(spec: Any) -> dict:
    """Where the spec came from.

    Parameters
    ----------
    spec : fi_design.spec.Spec
        The spec.

    Returns
    -------
    dict
        ``path`` (as shown), ``sha256`` of the file (of the spec's JSON when
        given in code), ``raw``, the mapping as written (None when given in
        code), and ``text``, the file's text as read (None unless read from a
        file).
    """
    from ..spec.file import origin

    org = origin(spec)
    if org is None:
        return {"path": "(spec given in code)",
                "sha256": spec.sha256(),
                "raw": None, "text": None}
    path = str(org.path) if org.path is not None else "(spec given as a mapping)"
    return {"path": path, "sha256": spec.sha256(), "raw": org.raw, "text": org.text}


def _yaml_text(raw: Any) -> str:
    import yaml

    return yaml.safe_dump(raw, sort_keys=False, allow_unicode=True, default_flow_style=None,
                          width=88)


def spec_listing(spec: Any) -> dict:
    """The spec for an appendix: the file's own text, else the spec as given in code.

    A spec read from a file is printed verbatim, comments and layout kept, so
    that the SHA-256 printed beside it can be checked against the printed
    text: the SHA-256 of the text (UTF-8) is the file's. A spec given as a
    mapping or in code has no file; it is printed as YAML, and its hash is
    that of its canonical JSON, not of the printed text.

    Parameters
    ----------
    spec : fi_design.spec.Spec
        The spec.

    Returns
    -------
    dict
        ``spec_yaml`` (the text; the appendix prints it in the rows of
        :func:`~fi_design.report.filters.wrapped_lines`, marking every row that
        continues a line), ``spec_note`` (what it is), ``spec_sha256`` (the hash printed
        beside it) and ``spec_verbatim`` (True when the text is the file's and
        the hash is the text's).
    """
    out = _listing(spec)
    if any(len(rows) > 1 for rows in wrapped_lines(out["spec_yaml"])):
        out["spec_note"] += (f"; a line longer than {WRAP_WIDTH} characters continues in rows "
                             f"marked {WRAP_MARK.strip()}, a mark of the page that is not part "
                             "of the text (join each such row to the line above)")
    return out


def _listing(spec: Any) -> dict:
    src = spec_file(spec)
    if src["text"] is not None:
        note = ("the spec file exactly as read, comments kept; the SHA-256 of this text "
                "(UTF-8) is the file's")
        if "\r" in src["text"]:
            note += " (the file ends its lines with CR LF; the hash counts them)"
        if src["text"].startswith("\ufeff"):
            note += " (the file starts with a byte-order mark, which the hash counts)"
        return {"spec_yaml": src["text"], "spec_note": note, "spec_sha256": src["sha256"],
                "spec_verbatim": True}
    if src["raw"] is not None:
        return {"spec_yaml": _yaml_text(src["raw"]), "spec_sha256": src["sha256"],
                "spec_note": "given as a mapping, not a file, printed as YAML; the SHA-256 is "
                             "that of its canonical JSON", "spec_verbatim": False}
    from ..results import to_jsonable

    return {"spec_yaml": _yaml_text(to_jsonable(spec.model_dump())), "spec_sha256": src["sha256"],
            "spec_note": "given in code, in SI units, printed as YAML; the SHA-256 is that of "
                         "its JSON", "spec_verbatim": False}


def title_block(spec: Any, kind: str, *, date: Any, command: str | None,
                sha256: str | None = None, version: str | None = None,
                title: str | None = None, source: Any = None) -> dict:
    """The title block of a report: document control, provenance, signatures.

    Parameters
    ----------
    spec : fi_design.spec.Spec
        The spec (project name, the ``report`` section, provenance).
    kind : str
        Kind of report (``design``, ``sweep``, ...; a key of :data:`TITLES`).
        The document id is the spec's id for this kind
        (:meth:`fi_design.spec.ReportInfo.id_for`).
    date : str, datetime.date or None
        Report date (:func:`report_date`).
    command : str or None
        The command line that made the report.
    sha256 : str, optional
        SHA-256 of the spec file; default from the spec's origin.
    version : str, optional
        fi_design version that computed the result; default this one.
    title : str, optional
        Title; default from :data:`TITLES`.
    source : fi_design.provenance.Source, optional
        The code that computed the result (git commit, code digest); default
        the running package's.

    Returns
    -------
    dict
        What ``report.html.jinja`` reads under ``meta``.
    """
    from ..provenance import current_source

    info = spec.report
    src = spec_file(spec)
    source = source if source is not None else current_source()
    version = version or source.version
    document = info.id_for(kind)
    return {
        "kind": kind,
        "title": title or TITLES.get(kind, "Report"),
        "project": spec.name,
        "document_id": document,
        "revision": info.revision,
        "status": info.status,
        "date": report_date(date),
        "tool": f"fi-design {version}",
        "tool_footer": f"fi-design {version}, {source.short}",
        "tool_source": source.revision,
        "code_sha256": source.code_sha256,
        "spec_path": src["path"],
        "spec_sha256": sha256 or src["sha256"],
        "command": command or "(library call: fi_design.render_report)",
        "signatures": [{"role": "Prepared", "name": info.author or ""},
                       {"role": "Checked", "name": info.checked_by or ""},
                       {"role": "Approved", "name": info.approved_by or ""}],
        "revisions": [{"revision": r.revision,
                       "date": r.date.isoformat() if r.date is not None else "",
                       "description": r.description, "author": r.author or ""}
                      for r in info.revisions],
        "running": f"{document} rev. {info.revision} ({info.status})",
    }
