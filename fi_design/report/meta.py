"""The parts every report shares: title block, date, spec provenance, software versions."""

from __future__ import annotations

import datetime as _dt
import hashlib
import os
from typing import Any

__all__ = ["TITLES", "report_date", "title_block", "spec_file", "spec_listing", "versions"]

#: Title of each kind of report.
TITLES = {
    "design": "Friction isolator design report",
    "sweep": "Hunting map (parameter study)",
    "study": "Hunting maps of the paper's parameter study",
    "robustness": "Robustness of the hunting verdict",
    "reconcile": "Model and measurement reconciliation",
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
        given in code) and ``raw``, the mapping as written (None when given in
        code).
    """
    from ..specfile import origin

    org = origin(spec)
    if org is None:
        return {"path": "(spec given in code)",
                "sha256": hashlib.sha256(spec.model_dump_json().encode()).hexdigest(),
                "raw": None}
    path = str(org.path) if org.path is not None else "(spec given as a mapping)"
    return {"path": path, "sha256": org.sha256, "raw": org.raw}


def _yaml_text(raw: Any) -> str:
    import yaml

    return yaml.safe_dump(raw, sort_keys=False, allow_unicode=True, default_flow_style=None,
                          width=88)


def spec_listing(spec: Any) -> dict:
    """The spec for an appendix: as read from the file, else as given in code.

    Parameters
    ----------
    spec : fi_design.spec.Spec
        The spec.

    Returns
    -------
    dict
        ``spec_yaml`` (YAML text) and ``spec_note`` (what it is).
    """
    raw = spec_file(spec)["raw"]
    if raw is not None:
        return {"spec_yaml": _yaml_text(raw),
                "spec_note": "as read from the file (units as written; comments dropped)"}
    from ..results import to_jsonable

    return {"spec_yaml": _yaml_text(to_jsonable(spec.model_dump())),
            "spec_note": "as given in code, in SI units"}


def title_block(spec: Any, kind: str, *, date: Any, command: str | None,
                sha256: str | None = None, version: str | None = None,
                title: str | None = None) -> dict:
    """The title block of a report.

    Parameters
    ----------
    spec : fi_design.spec.Spec
        The spec (project name, the ``report`` section, provenance).
    kind : str
        Kind of report (``design``, ``sweep``, ...; a key of :data:`TITLES`).
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

    Returns
    -------
    dict
        What ``report.html.jinja`` reads under ``meta``.
    """
    from .. import __version__

    info = spec.report
    src = spec_file(spec)
    author = info.author or ""
    return {
        "kind": kind,
        "title": title or TITLES.get(kind, "Report"),
        "project": spec.name,
        "document_id": info.document_id,
        "revision": info.revision,
        "status": info.status,
        "date": report_date(date),
        "tool": f"fi-design {version or __version__}",
        "spec_path": src["path"],
        "spec_sha256": sha256 or src["sha256"],
        "command": command or "(library call: fi_design.render_report)",
        "signatures": [{"role": "Prepared", "name": author}, {"role": "Checked", "name": ""},
                       {"role": "Approved", "name": ""}],
        "running": f"{info.document_id} rev. {info.revision} ({info.status})",
    }
