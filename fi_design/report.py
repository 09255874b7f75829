"""Sign-off reports: one self-contained HTML file, or a PDF made from the same HTML.

How a report is made
--------------------
1. :func:`build_context` turns a result into plain data: strings, SI floats
   with their unit, lists and dicts. All arithmetic, comparison and wording
   happens here; the golden tests compare this dict (with ``figures=False``).
2. The figures (matplotlib's ``Figure`` API, :mod:`fi_design.plots`) are
   inlined as SVG (fixed id salt, no date, ids prefixed per figure), so the
   HTML makes no external request. Equations are written in a small TeX
   subset (:func:`math_nodes`) and rendered as HTML and CSS by
   ``equation.html.jinja`` (italic variables, sub- and superscripts, stacked
   fractions): no script, no MathML (WeasyPrint has none), identical in a
   browser and in the PDF, and searchable. (matplotlib mathtext as SVG paths
   was the first route; WeasyPrint draws SVG paths in Python, and the
   equations alone cost over a second of the PDF.)
3. One jinja environment (:func:`environment`: autoescape on,
   ``StrictUndefined``) renders each section with its own small template, which
   extends ``section.html.jinja``; ``report.html.jinja`` puts the title block,
   the contents and the sections on the page. Templates use only ``extends``,
   ``block``, ``for`` and ``if``; numbers reach them as SI values and are
   formatted by the filters :func:`num`, :func:`qty` and :func:`unit_text`
   (unit-tested), or as ready strings.
4. :func:`render_report` writes the HTML, or the PDF through WeasyPrint (A4,
   page numbers, the document id and revision in the running header),
   atomically (:func:`fi_design.output.atomic_path`).

The templates live in the repository's top-level ``templates/`` folder; the
wheel carries them as ``fi_design/templates`` (:func:`template_dir` finds
either).

Public functions
----------------
- :func:`render_report` -- ``render_report(result, "out.html" | "out.pdf", date=...,
  command=...)`` for a :class:`~fi_design.guideline.DesignResult`, a
  :class:`~fi_design.studies.SweepResult`, :class:`~fi_design.studies.StudyResult` or
  :class:`~fi_design.studies.RobustnessResult`; other results (the
  reconciliation) when they offer ``report_sections()`` (see below).
- :func:`render_document` -- for the other commands' reports: a title and a
  list of :class:`Section` values (paragraphs, :class:`Table` values,
  :class:`FigureBlock` values from :func:`figure_block`), rendered with the same
  title block, page layout, running header and appendix as the design report,
  each section by ``generic.html.jinja``. :mod:`fi_design.gapreport` (the
  reconciliation report) is built this way::

      from fi_design import report
      sections = [report.Section("summary", "Summary", paragraphs=("...",),
                                 tables=(report.Table(("Effect", "Score"), rows),),
                                 figures=(report.figure_block(fig, "Gap before and after"),))]
      report.render_document("gap.html", title="Model-measurement reconciliation",
                             spec=spec, sections=sections, kind="reconcile")

  A result class may instead define ``report_sections(self) -> list[Section]``
  and ``report_title`` (str); :func:`render_report` then renders it.
- :func:`build_context` (the design report's content), :func:`sweep_context` and
  :func:`document_context` (the others'), :func:`render_html`,
  :func:`design_map` (the crossover x stroke map), :func:`preload` (import the
  rendering libraries early), :func:`environment`, :func:`template_dir`, and
  the filters :func:`num`, :func:`qty` and :func:`unit_text`.

Reproducibility: the same spec and result give the same HTML apart from the
date (passed in; the CLI uses today, or ``SOURCE_DATE_EPOCH`` when set):
matplotlib's SVG ids are salted with a fixed string and carry no date, and
solver wall times are left out.
"""

from __future__ import annotations

import datetime as _dt
import functools
import math
import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Sequence

from .errors import OutputError
from . import spec as _spec
from .results import Status

__all__ = [
    "FORMATS", "Section", "Table", "FigureBlock", "figure_block", "template_dir", "environment",
    "num", "qty", "unit_text", "math_nodes", "math_text", "build_context", "sweep_context",
    "document_context", "design_map", "render_html", "render_report", "render_document",
    "report_date", "preload",
]

#: Output formats by file extension.
FORMATS = {".html": "html", ".pdf": "pdf"}

#: Title of each kind of report.
TITLES = {
    "design": "Friction isolator design report",
    "sweep": "Hunting map (parameter study)",
    "study": "Hunting maps of the paper's parameter study",
    "robustness": "Robustness of the hunting verdict",
    "reconcile": "Model and measurement reconciliation",
}

_NBSP = "\u00a0"
_NNBSP = "\u202f"  # narrow no-break space: thousands separator
_SUPERSCRIPT = str.maketrans("-0123456789", "\u207b\u2070\u00b9\u00b2\u00b3\u2074\u2075\u2076"
                                            "\u2077\u2078\u2079")


# --------------------------------------------------------------------------- filters


def num(value: Any, digits: int = 4) -> str:
    """A number for a reader: ``digits`` significant digits, plain where sensible.

    Parameters
    ----------
    value : float, int, bool, str or None
        The number; ``None`` gives an en dash, ``inf`` the infinity sign, ``nan``
        ``n/a``, a bool ``yes``/``no``; strings pass through.
    digits : int, optional
        Significant digits (default 4); integers and numbers with more integer
        digits are shown in full.

    Returns
    -------
    str
        Plain notation from 1e-4 to 1e6 (``0.0003``, ``13333``), else a power of
        ten (``3.2 × 10⁻⁸``); groups of three digits from 10 000 up are
        separated by a narrow no-break space.

    Examples
    --------
    >>> num(13333.33), num(0.3), num(2.0), num(3.2e-8), num(None)
    ('13\u202f333', '0.3', '2', '3.2 × 10⁻⁸', '–')
    """
    if value is None:
        return "\u2013"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, str):
        return value
    if isinstance(value, int) or (hasattr(value, "dtype") and value.dtype.kind in "iu"):
        return _group(str(int(value)))
    x = float(value)
    if math.isnan(x):
        return "n/a"
    if math.isinf(x):
        return "\u221e" if x > 0 else "-\u221e"
    if x == 0:
        return "0"
    ax = abs(x)
    if 1e-4 <= ax < 1e6:
        exp = math.floor(math.log10(ax))
        decimals = max(0, digits - 1 - exp)
        text = f"{x:.{decimals}f}"
        if "." in text:
            text = text.rstrip("0").rstrip(".")
        if text in ("-0", ""):
            text = "0"
        return _group(text)
    mant, exp = f"{x:.{digits - 1}e}".split("e")
    if "." in mant:
        mant = mant.rstrip("0").rstrip(".")
    return f"{mant} \u00d7 10{str(int(exp)).translate(_SUPERSCRIPT)}"


def _group(text: str) -> str:
    """Narrow-space thousands groups for integer parts of 5 digits and more."""
    sign = "-" if text.startswith("-") else ""
    body = text.lstrip("-")
    whole, dot, frac = body.partition(".")
    if len(whole) >= 5:
        groups = []
        while whole:
            groups.insert(0, whole[-3:])
            whole = whole[:-3]
        whole = _NNBSP.join(groups)
    return sign + whole + dot + frac


#: SI unit (as the spec and the checks store it) -> unit shown to readers.
UNIT_TEXT = {
    "N*s/m": "N\u00b7s/m", "N s/m": "N\u00b7s/m", "m/s**2": "m/s\u00b2", "m/s**3": "m/s\u00b3",
    "kg/m**3": "kg/m\u00b3", "deg": "\u00b0", "um": "\u00b5m", "1": "", "-": "",
    "N/(m s)": "N/(m\u00b7s)", "rad/s": "rad/s",
}

#: Units converted for display: SI unit -> list of (threshold, shown unit, factor), the first
#: threshold at or below |value| wins.
DISPLAY_SCALES = {
    "m": [(1e-4, "mm", 1e3), (0.0, "\u00b5m", 1e6)],
    "m/s": [(0.0, "mm/s", 1e3)],
    "Pa": [(1e9, "GPa", 1e-9), (1e6, "MPa", 1e-6), (1e3, "kPa", 1e-3), (0.0, "Pa", 1.0)],
}


def unit_text(unit: str) -> str:
    """A unit as readers write it: ``N*s/m`` -> ``N·s/m``, ``m/s**2`` -> ``m/s²``, ``1`` -> ````.

    Parameters
    ----------
    unit : str
        Unit as stored in the spec or a check.

    Returns
    -------
    str
    """
    if unit is None:
        return ""
    return UNIT_TEXT.get(unit, unit.replace("**2", "\u00b2").replace("**3", "\u00b3")
                         .replace("*", "\u00b7"))


def display_scale(unit: str, reference: Any) -> tuple[str, float]:
    """The shown unit and the factor from SI for a value of ``unit`` near ``reference``.

    Parameters
    ----------
    unit : str
        SI unit.
    reference : float or None
        A typical value (SI), which picks the prefix (``Pa`` -> ``MPa``).

    Returns
    -------
    shown : str
        The unit text to print.
    factor : float
        Multiply SI values by it.
    """
    scales = DISPLAY_SCALES.get(unit)
    if scales is None:
        return unit_text(unit), 1.0
    ref = abs(float(reference)) if isinstance(reference, (int, float)) and \
        not isinstance(reference, bool) and math.isfinite(reference) else None
    if ref is None or ref == 0:
        shown, factor = scales[0][1], scales[0][2]
        if unit == "Pa":
            shown, factor = "MPa", 1e-6
        return shown, factor
    for threshold, shown, factor in scales:
        if ref >= threshold:
            return shown, factor
    return scales[-1][1], scales[-1][2]


def qty(value: Any, unit: str = "", digits: int = 4) -> str:
    """A value with its unit, converted from SI for reading: ``qty(3e-4, "m")`` -> ``0.3 mm``.

    Parameters
    ----------
    value : float, int, bool, str, None or sequence
        SI value; a pair or list gives ``10 – 60 mm``; strings and bools pass
        through :func:`num`.
    unit : str, optional
        Its SI unit (``"m"``, ``"N/m"``, ``"Pa"``, ``"deg"``, ``"cycles"``, ...);
        lengths are shown in mm (µm below 0.1 mm), speeds in mm/s, stresses and
        moduli with a prefix.
    digits : int, optional
        Significant digits.

    Returns
    -------
    str
        Number, no-break space, unit (degrees follow the number directly).

    Examples
    --------
    >>> qty(3e-4, "m"), qty(2e11, "Pa"), qty(47.31, "deg"), qty(5, "cycles")
    ('0.3\u00a0mm', '200\u00a0GPa', '47.31°', '5\u00a0cycles')
    """
    if isinstance(value, (list, tuple)):
        if not value:
            return "\u2013"
        shown, factor = display_scale(unit, max((abs(v) for v in value
                                                 if isinstance(v, (int, float))), default=None))
        parts = [num(v * factor if isinstance(v, (int, float)) and not isinstance(v, bool)
                     else v, digits) for v in value]
        return _attach(" \u2013 ".join(parts), shown)
    if value is None or isinstance(value, (str, bool)):
        return num(value, digits)
    if unit == "m" and 0 < abs(value) < 5e-10:
        return _attach("< 0.001", "\u00b5m")
    shown, factor = display_scale(unit, value)
    scaled = value if factor == 1.0 else value * factor
    return _attach(num(scaled, digits), shown)


def _attach(text: str, shown: str) -> str:
    if not shown:
        return text
    if shown == "\u00b0":
        return text + shown
    return text + _NBSP + shown


# --------------------------------------------------------------------------- templates


def template_dir() -> Path:
    """The folder holding the report templates.

    An installed wheel carries them as ``fi_design/templates``; a source tree
    (an editable install) keeps them in the repository's top-level
    ``templates/`` folder, next to the package.

    Returns
    -------
    pathlib.Path

    Raises
    ------
    FileNotFoundError
        Neither place holds ``report.html.jinja`` (a broken installation).
    """
    here = Path(__file__).resolve().parent
    for candidate in (here / "templates", here.parent / "templates"):
        if (candidate / "report.html.jinja").is_file():
            return candidate
    raise FileNotFoundError(f"fi_design: report templates not found in {here / 'templates'} "
                            f"or {here.parent / 'templates'}; reinstall the package")


@functools.lru_cache(maxsize=1)
def environment() -> Any:
    """The one jinja environment of the reports: autoescape, ``StrictUndefined``, filters.

    Returns
    -------
    jinja2.Environment
        Loads from :func:`template_dir`; filters ``num``, ``qty`` and ``unit``.
    """
    import jinja2

    env = jinja2.Environment(
        loader=jinja2.FileSystemLoader(str(template_dir())),
        autoescape=jinja2.select_autoescape(default=True, default_for_string=True),
        undefined=jinja2.StrictUndefined, trim_blocks=True, lstrip_blocks=True,
        keep_trailing_newline=True)
    env.filters["num"] = num
    env.filters["qty"] = qty
    env.filters["unit"] = unit_text
    return env


def _render(name: str, **context: Any) -> Any:
    """Render one template to ``Markup`` (so the page template inlines it unescaped)."""
    from markupsafe import Markup

    return Markup(environment().get_template(name).render(**context))


def _css() -> Any:
    from markupsafe import Markup

    return Markup((template_dir() / "report.css").read_text(encoding="utf-8"))


# --------------------------------------------------------------------------- generic blocks


@dataclass(frozen=True)
class Table:
    """A table for a generic report section.

    Attributes
    ----------
    columns : tuple of str
        Column headers (with the unit in brackets where the cells are numbers).
    rows : tuple of tuple of str
        Cell texts, already formatted (use :func:`num` and :func:`qty`).
    caption : str
        Caption above the table.
    numeric : tuple of bool
        Right-align the column; default: every column but the first.
    """

    columns: tuple[str, ...]
    rows: tuple[tuple[str, ...], ...]
    caption: str = ""
    numeric: tuple[bool, ...] = ()

    def as_context(self) -> dict:
        """Plain data for the templates."""
        numeric = self.numeric or tuple(i > 0 for i in range(len(self.columns)))
        return {"caption": self.caption,
                "columns": [{"text": c, "numeric": bool(n)} for c, n in zip(self.columns, numeric)],
                "rows": [[{"text": str(cell), "numeric": bool(n)} for cell, n in zip(row, numeric)]
                         for row in self.rows]}


@dataclass(frozen=True)
class FigureBlock:
    """A figure for a report: inline SVG and a caption.

    Attributes
    ----------
    svg : str or None
        The ``<svg>`` element (:func:`fi_design.plots.figure_svg`); None leaves
        only the caption (the golden tests build contexts without figures).
    caption : str
        Caption below the figure.
    name : str
        Short identifier (the SVG id prefix).
    width : str
        ``"full"`` (text width) or ``"half"`` (two side by side).
    """

    svg: str | None
    caption: str
    name: str = "figure"
    width: str = "full"


def figure_block(fig: Any, caption: str, name: str = "figure", width: str = "full") -> FigureBlock:
    """Turn a matplotlib figure into a :class:`FigureBlock` with inline SVG.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure (never pyplot).
    caption : str
        Caption.
    name : str, optional
        Identifier; must be unique within a report (it prefixes the SVG ids).
    width : {"full", "half"}, optional
        Text width or half of it.

    Returns
    -------
    FigureBlock
    """
    from .plots import figure_svg

    return FigureBlock(svg=figure_svg(fig, name), caption=caption, name=name, width=width)


@dataclass(frozen=True)
class Section:
    """A generic report section: paragraphs, then tables, then figures.

    Attributes
    ----------
    id : str
        Anchor (letters, digits, ``-``).
    title : str
        Heading.
    paragraphs : tuple of str
        Plain text paragraphs (escaped, never HTML).
    tables : tuple of Table
        Tables.
    figures : tuple of FigureBlock
        Figures.
    notes : tuple of str
        Bulleted notes after the figures.
    """

    id: str
    title: str
    paragraphs: tuple[str, ...] = ()
    tables: tuple[Table, ...] = ()
    figures: tuple[FigureBlock, ...] = ()
    notes: tuple[str, ...] = ()


# --------------------------------------------------------------------------- helpers


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


def _fmt_format(path: str | os.PathLike) -> str:
    ext = Path(path).suffix.lower()
    if ext not in FORMATS:
        raise OutputError(f"{path}: a report must end with .html or .pdf")
    return FORMATS[ext]


def _versions() -> list[dict]:
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


def _spec_file(spec: Any) -> dict:
    """Where the spec came from: shown path, SHA-256, the mapping as written."""
    from .specfile import origin

    org = origin(spec)
    if org is None:
        import hashlib

        return {"path": "(spec given in code)",
                "sha256": hashlib.sha256(spec.model_dump_json().encode()).hexdigest(),
                "raw": None}
    path = str(org.path) if org.path is not None else "(spec given as a mapping)"
    return {"path": path, "sha256": org.sha256, "raw": org.raw}


def _yaml_text(raw: Any) -> str:
    import yaml

    if raw is None:
        return ""
    return yaml.safe_dump(raw, sort_keys=False, allow_unicode=True, default_flow_style=None,
                          width=88)


def _meta(spec: Any, kind: str, *, date: Any, command: str | None, sha256: str | None = None,
          version: str | None = None, title: str | None = None) -> dict:
    """The title block."""
    from . import __version__

    info = spec.report
    src = _spec_file(spec)
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


# --------------------------------------------------------------------------- checks


#: Where each guideline step comes from in the paper, for the checks' "source" column.
STEP_SOURCES = {
    "step 1 friction gap": "step 1; paper \u00a74, Fig. 4A",
    "step 2 crossover": "step 2; paper \u00a72.2, \u00a74, Fig. 2",
    "step 3 drive stiffness": "step 3; paper \u00a74, Fig. 4C",
    "step 3 flexure": "step 3; paper \u00a74, \u00a75",
    "step 3 refinement: landing": "step 3 (simulated landing)",
    "step 4 PID": "step 4; paper \u00a72.2",
    "simulation (paper section 2.3)": "simulation; paper \u00a72.3, Fig. 5",
}

#: Requirement sense of each check (by name, or by the name's part before the first dot).
SENSE = {
    "friction_gap": "<", "crossover_achievable": "\u2264", "phase_margin": "\u2265",
    "gain_margin": "\u2265", "modulus_margin": "\u2265", "parasitic_separation": "\u2265",
    "drive_stiffness": "\u2264", "flexure.stiffness": "\u2264", "flexure.stress": "\u2264",
    "flexure.support_frequency": "\u2265", "flexure.bending_frequency": "\u2265",
    "simulation_isolated": "=", "min_crossover_isolated": "\u2264", "landing_force": "<",
}


def check_label(name: str) -> str:
    """A check's name in words: ``phase_margin.stuck_free`` -> ``Phase margin, case 2 ...``.

    Parameters
    ----------
    name : str
        :attr:`fi_design.results.Check.name`.

    Returns
    -------
    str
    """
    head, _, tail = name.partition(".")
    case = _case_words(tail) if head in ("phase_margin", "gain_margin", "modulus_margin") else tail
    labels = {
        "friction_gap": "Friction gap Fs \u2212 Fc",
        "crossover_achievable": "Desired crossover within the achievable",
        "phase_margin": f"Phase margin, {case}",
        "gain_margin": f"Gain margin, {case}",
        "modulus_margin": f"Modulus margin, {case}",
        "parasitic_separation": f"Parasitic mode \u2018{tail}\u2019 above the crossover",
        "drive_stiffness": "Drive stiffness k within k_max",
        "flexure": "Leaf-spring flexure",
        "pid": "PID gains (proportional gain kp)",
        "simulation_isolated": "Simulated hunting with the isolator",
        "simulation_non_isolated": "Simulated hunting without the isolator",
        "min_crossover_isolated": "Lowest hunting-free crossover with the isolator",
        "min_crossover_non_isolated": "Lowest hunting-free crossover without the isolator",
        "isolator_needed": "Is the isolator needed at this crossover?",
        "landing_force": "Flexure force on the resting cart",
        "friction_model_cross_check": "Cross-check with the other friction model",
    }
    flex = {"stiffness": "Flexure drive stiffness within k_max",
            "stress": "Flexure bending stress at full stroke",
            "support_frequency": "Flexure support-direction frequency",
            "bending_frequency": "Flexure leaf bending resonance"}
    if head == "flexure" and tail in flex:
        return flex[tail]
    if head == "pid" and tail == "tuning_mass":
        return "PID tuning mass"
    return labels.get(head, name.replace("_", " ").capitalize())


def _case_words(name: str) -> str:
    try:
        from .linear import CASE_DESCRIPTIONS, CASE_NUMBERS
    except ImportError:  # pragma: no cover - python-control is a dependency
        return name
    if name in CASE_NUMBERS:
        return f"case {CASE_NUMBERS[name]} ({CASE_DESCRIPTIONS[name]})"
    return name


def _sense(name: str) -> str:
    if name in SENSE:
        return SENSE[name]
    return SENSE.get(name.split(".")[0], "")


def check_row(check: Any) -> dict:
    """One row of the verdict table: label, status, value and limit in a shared unit, source.

    Parameters
    ----------
    check : fi_design.results.Check
        The check.

    Returns
    -------
    dict
        ``name``, ``label``, ``status``, ``css`` (status class), ``value``,
        ``limit`` (numbers in the shown ``unit``; None when absent), ``sense``
        (the requirement's relation), ``unit`` (shown), ``source`` and
        ``message``.
    """
    status = check.status.value if isinstance(check.status, Status) else str(check.status)
    ref = check.limit if isinstance(check.limit, (int, float)) else check.value
    shown, factor = display_scale(check.unit, ref)
    if check.unit == "cycles":
        shown = "cycles"

    def conv(x):
        if x is None or not isinstance(x, (int, float)) or isinstance(x, bool):
            return x
        return float(x) * factor

    return {
        "name": check.name,
        "label": check_label(check.name),
        "status": status,
        "css": status.lower(),
        "value": conv(check.value),
        "limit": conv(check.limit),
        "sense": _sense(check.name) if check.limit is not None else "",
        "unit": shown,
        "source": STEP_SOURCES.get(check.step, check.step),
        "message": check.message,
    }


def _verdict(result: Any) -> dict:
    rows = [check_row(c) for c in result.checks]
    counts = {s.value: sum(1 for r in rows if r["status"] == s.value) for s in Status}
    if counts["FAIL"]:
        overall, css = "FAIL", "fail"
        headline = (f"{counts['FAIL']} of {len(rows)} checks fail: the design does not meet "
                    "its requirements as specified.")
    elif counts["WARN"]:
        overall, css = "PASS with warnings", "warn"
        headline = (f"No check fails; {counts['WARN']} warning"
                    f"{'s' if counts['WARN'] != 1 else ''} to review.")
    else:
        overall, css = "PASS", "pass"
        headline = "Every check passes."
    groups: list[dict] = []
    for row, check in zip(rows, result.checks):
        if not groups or groups[-1]["step"] != check.step:
            groups.append({"step": check.step, "title": _step_title(check.step), "rows": []})
        groups[-1]["rows"].append(row)
    return {
        "overall": overall, "css": css, "headline": headline,
        "counts": [{"status": s, "count": n, "css": s.lower()} for s, n in counts.items()],
        "total": len(rows),
        "groups": groups,
        "conclusion": result.conclusion,
        "warnings": [{"path": p, "message": m} for p, m in result.warnings],
    }


def _step_title(step: str) -> str:
    titles = {
        "step 1 friction gap": "Step 1 \u2013 friction gap",
        "step 2 crossover": "Step 2 \u2013 crossover and loop margins",
        "step 3 drive stiffness": "Step 3 \u2013 drive stiffness",
        "step 3 flexure": "Step 3 \u2013 leaf-spring flexure",
        "step 4 PID": "Step 4 \u2013 PID gains",
        "simulation (paper section 2.3)": "Nonlinear confirmation (simulated hunting)",
        "step 3 refinement: landing": "Step 3 refinement \u2013 where the cart comes to rest",
    }
    return titles.get(step, step[:1].upper() + step[1:] if step else "Other")


# --------------------------------------------------------------------------- inputs


#: Derived defaults: path -> (rule in words, function of the spec).
def _derived_rules() -> dict[str, tuple[str, Callable[[Any], float]]]:
    from . import spec as s

    return {
        "friction.bristle_damping": ("sqrt(sigma0 (m1 + m2))", s.bristle_damping),
        "isolator.stiffness": ("k_max / 2 (step 3)", s.drive_stiffness),
        "isolator.damping": ("2 \u00b7 0.05 \u00b7 sqrt(k m1 m2 / (m1 + m2))", s.joint_damping),
        "isolator.limiter.damping": ("2 \u00b7 0.2 \u00b7 sqrt(k_stop m1)", s.limiter_damping),
    }


_MISSING = object()


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
        return f"{value:g}"
    return str(value)


def _first_sentence(text: str) -> str:
    text = (text or "").split(" [")[0].split(". Default")[0].strip()
    return text.rstrip(".")


def spec_inputs(spec: Any) -> list[dict]:
    """Every value of a spec, grouped by section, with unit and whether it was given.

    Parameters
    ----------
    spec : fi_design.spec.Spec
        The spec (its origin tells given values from defaults).

    Returns
    -------
    list of dict
        One group per top-level section: ``title`` and ``rows``, each row with
        ``path``, ``description``, ``value`` (SI), ``unit`` (SI), ``written``
        (as in the file) and ``source`` (``given``, ``default``, ``derived
        default: RULE`` or ``not given``).
    """
    from pydantic import BaseModel

    from .specfile import path_unit

    src = _spec_file(spec)
    raw = src["raw"] if src["raw"] is not None else {}
    rules = _derived_rules()
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
                    row["value"] = float(rule[1](spec))
                    row["source"] = f"derived default: {rule[0]}"
                except (ValueError, AttributeError):
                    row["source"] = "not given"
            elif path.endswith(".antiresonance") and isinstance(parent, BaseModel):
                from .spec import antiresonance

                if getattr(parent, "collocated", False):
                    row["value"] = antiresonance(parent)
                    row["source"] = "derived default: frequency / sqrt(2)"
                else:
                    row["source"] = "not used (mode not collocated)"
            else:
                row["source"] = "not given"
        if isinstance(value, tuple) and not value:
            row["value"] = "none"
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


# --------------------------------------------------------------------------- equations


def tex_num(value: float, digits: int = 4) -> str:
    """A number for mathtext: thin-space thousands, ``\\times 10^{n}`` powers."""
    text = num(value, digits)
    if "\u00d7" in text:
        mant, power = text.split(" \u00d7 10")
        exp = power.translate(str.maketrans("\u207b\u2070\u00b9\u00b2\u00b3\u2074\u2075\u2076"
                                            "\u2077\u2078\u2079", "-0123456789"))
        return f"{mant} \\times 10^{{{exp}}}"
    return text.replace(_NNBSP, "\\,")


def tex_qty(value: float, unit: str, digits: int = 4) -> str:
    """A quantity for mathtext: converted as :func:`qty` does, unit upright."""
    shown, factor = display_scale(unit, value)
    number = tex_num(value * factor, digits)
    if not shown:
        return number
    if shown == "\u00b0":
        return number + "^\\circ"
    unit_tex = shown.replace(" ", "\\,").replace("\u00b5", "\\mu ").replace(
        "\u00b7", "\\cdot ").replace("\u00b2", "^2").replace("\u00b3", "^3")
    return f"{number}\\ \\mathrm{{{unit_tex}}}"


_GREEK = {"alpha": "\u03b1", "beta": "\u03b2", "gamma": "\u03b3", "delta": "\u03b4",
          "Delta": "\u0394", "epsilon": "\u03b5", "zeta": "\u03b6", "eta": "\u03b7",
          "theta": "\u03b8", "lambda": "\u03bb", "mu": "\u00b5", "pi": "\u03c0",
          "rho": "\u03c1", "sigma": "\u03c3", "tau": "\u03c4", "phi": "\u03c6",
          "omega": "\u03c9", "Omega": "\u03a9"}
_SYMBOLS = {"times": "\u00d7", "leq": "\u2264", "geq": "\u2265", "cdot": "\u00b7",
            "infty": "\u221e", "pm": "\u00b1", "approx": "\u2248", "neq": "\u2260",
            "circ": "\u00b0", "quad": "\u2003", ",": "\u2009", " ": " ", ";": " "}
_FUNCTIONS = ("min", "max", "ln", "log", "exp", "sin", "cos")
#: Characters set off by thin spaces at the top level of a formula.
_SPACED = set("=+<>\u00d7\u2264\u2265\u2248\u2260") | {"-"}
_THIN = "\u2009"


def _math_tokens(tex: str) -> list[tuple[str, str]]:
    out, i = [], 0
    while i < len(tex):
        c = tex[i]
        if c == "\\":
            j = i + 1
            if j < len(tex) and not tex[j].isalpha():
                out.append(("cmd", tex[j]))
                i = j + 1
                continue
            while j < len(tex) and tex[j].isalpha():
                j += 1
            out.append(("cmd", tex[i + 1:j]))
            i = j
        elif c in "{}_^":
            out.append((c, c))
            i += 1
        else:
            out.append(("char", c))
            i += 1
    return out


def _math_parse(tokens: list, i: int, upright: bool, until: str | None) -> tuple[list, int]:
    """Items: ("text", str, italic, sub, sup) or ("frac", items, items)."""
    items: list = []
    while i < len(tokens):
        kind, val = tokens[i]
        if until is not None and kind == until:
            return items, i + 1
        if kind in ("_", "^"):
            script, i = _math_atom(tokens, i + 1, True)
            text = "".join(_math_plain(script))
            if items and items[-1][0] == "text":
                k, s, it, sub, sup = items[-1]
                items[-1] = (k, s, it, sub + text if kind == "_" else sub,
                             sup + text if kind == "^" else sup)
            else:
                items.append(("text", "", False, text if kind == "_" else "",
                              text if kind == "^" else ""))
            continue
        atom, i = _math_atom(tokens, i, upright)
        items.extend(atom)
    return items, i


def _math_atom(tokens: list, i: int, upright: bool) -> tuple[list, int]:
    kind, val = tokens[i]
    if kind == "{":
        return _math_parse(tokens, i + 1, upright, "}")
    if kind == "cmd":
        if val == "frac":
            num, i = _math_atom(tokens, i + 1, upright)
            den, i = _math_atom(tokens, i, upright)
            return [("frac", num, den)], i
        if val in ("mathrm", "text"):
            return _math_atom(tokens, i + 1, True)
        if val in ("left", "right"):
            return [], i + 1
        if val in _GREEK:
            return [("text", _GREEK[val], not upright and val[0].islower(), "", "")], i + 1
        if val in _SYMBOLS:
            return [("text", _SYMBOLS[val], False, "", "")], i + 1
        if val in _FUNCTIONS:
            return [("text", val if upright else _THIN + val, False, "", "")], i + 1
        return [("text", val, False, "", "")], i + 1
    if kind == "char":
        if val == " ":
            return [], i + 1
        if val == "," and not upright:
            return [("text", "," + _THIN, False, "", "")], i + 1
        return [("text", val, val.isalpha() and not upright, "", "")], i + 1
    return [], i + 1


def _math_plain(items: list) -> list[str]:
    out = []
    for it in items:
        if it[0] == "frac":
            out.append("(" + "".join(_math_plain(it[1])) + ")/(" + "".join(_math_plain(it[2]))
                       + ")")
        else:
            out.append(it[1] + (f"_{it[3]}" if it[3] else "") + (f"^{it[4]}" if it[4] else ""))
    return out


def _math_leaves(items: list, spaced: bool) -> list[dict]:
    """Merge runs of upright text without scripts; set off relations and operators."""
    out: list[dict] = []
    for _, text, italic, sub, sup in items:
        if spaced and text in _SPACED:
            text = _THIN + ("\u2212" if text == "-" else text) + _THIN
        elif text == "-":
            text = "\u2212"
        if (out and not italic and not out[-1]["var"] and not out[-1]["sub"]
                and not out[-1]["sup"]):
            out[-1]["text"] += text
            out[-1]["sub"], out[-1]["sup"] = sub, sup
            continue
        out.append({"frac": False, "text": text, "var": bool(italic), "sub": sub, "sup": sup})
    return out


def math_nodes(tex: str) -> list[dict]:
    """A formula in a small TeX subset, as nodes for the ``equation.html.jinja`` template.

    Supported: letters (italic variables), ``_`` and ``^`` (with braces),
    ``\\frac{..}{..}`` (one level), ``\\mathrm{..}``, Greek letters, ``\\times``,
    ``\\leq``, ``\\geq``, ``\\cdot``, ``\\min``, ``\\max``, ``\\left``/``\\right``,
    and the spaces ``\\,``, ``\\ ``, ``\\quad``. Subscripts and superscripts are
    upright text. The result renders with HTML and CSS only, identically in
    browsers and in WeasyPrint (which has no MathML).

    Parameters
    ----------
    tex : str
        The formula, without ``$`` delimiters.

    Returns
    -------
    list of dict
        Leaves ``{"frac": False, "text", "var", "sub", "sup"}`` and fractions
        ``{"frac": True, "num": [leaves], "den": [leaves]}``.

    Examples
    --------
    >>> [n["text"] for n in math_nodes(r"F_s = 4")]
    ['F', '\u2009=\u20094']
    """
    items, _ = _math_parse(_math_tokens(tex), 0, False, None)
    nodes: list[dict] = []
    run: list = []
    for it in items + [None]:
        if it is None or it[0] == "frac":
            nodes.extend(_math_leaves(run, True))
            run = []
            if it is not None:
                nodes.append({"frac": True, "num": _math_leaves(it[1], True),
                              "den": _math_leaves(it[2], True)})
        else:
            run.append(it)
    return nodes


def math_text(tex: str) -> str:
    """Plain-text reading of a formula (for screen readers and text search).

    Parameters
    ----------
    tex : str
        The formula (TeX subset of :func:`math_nodes`).

    Returns
    -------
    str
    """
    def leaf(n: dict) -> str:
        return n["text"] + (f"_{n['sub']}" if n["sub"] else "") + \
            (f"^{n['sup']}" if n["sup"] else "")

    parts = []
    for n in math_nodes(tex):
        if n["frac"]:
            parts.append("(" + "".join(leaf(m) for m in n["num"]) + ")/("
                         + "".join(leaf(m) for m in n["den"]) + ")")
        else:
            parts.append(leaf(n))
    text = "".join(parts).replace(_THIN, " ").replace("\u2212", "-").replace("\u2003", " ")
    return re.sub(r"\s+", " ", text).strip()


def _equation(tex: str, render: bool = True) -> dict:
    """An equation: its TeX source, a plain-text reading and (when asked) its HTML."""
    out = {"tex": tex, "text": math_text(tex), "html": None}
    if render:
        out["html"] = _render("equation.html.jinja", nodes=math_nodes(tex))
    return out


# --------------------------------------------------------------------------- the design report


def _steps(result: Any, svg: bool) -> list[dict]:
    spec = result.spec
    gap = result.friction_gap
    xo = result.crossover
    st = result.stiffness
    g = result.pid.gains
    req = spec.requirements
    steps = []

    # step 1
    rel = "\\geq" if gap.hunting_risk else "<"
    steps.append({
        "number": 1, "title": "Friction gap", "source": "paper \u00a74 step 1; Figure 4A",
        "equations": [
            _equation(f"\\Delta F = F_s - F_c = {tex_qty(gap.static, 'N')} - "
                      f"{tex_qty(gap.coulomb, 'N')} = {tex_qty(gap.gap, 'N')}", svg),
            _equation(f"\\Delta F = {tex_qty(gap.gap, 'N')} \\ {rel}\\ \\Delta F_\\mathrm{{lim}}"
                      f" = {tex_qty(gap.threshold, 'N')}", svg),
        ],
        "results": [
            {"quantity": "friction gap Fs \u2212 Fc", "value": gap.gap, "unit": "N"},
            {"quantity": "threshold (requirements.friction_gap)", "value": gap.threshold,
             "unit": "N"},
            {"quantity": "hunting risk", "value": "yes" if gap.hunting_risk else "no",
             "unit": ""},
        ],
        "explanation": (
            "Hunting needs stick-slip: the integrator builds up force until the bearing breaks "
            "loose at static friction, the cart slips past the target because sliding friction "
            "is lower, and sticks again. The larger the gap between static and Coulomb friction, "
            "the larger the overshoot (paper Figure 4A: hunting appears above a gap of about "
            f"1 N). Here the gap is {qty(gap.gap, 'N')}, "
            + ("at or above the threshold: hunting is a risk and the next steps decide how to "
               "avoid it." if gap.hunting_risk else
               "below the threshold: stick-slip, and so hunting, is unlikely.")),
    })

    # step 2
    sep = req.parasitic_separation
    need = sep * xo.desired
    eqs = [_equation(f"\\omega_c = 2\\pi f_c = 2\\pi \\times {tex_qty(xo.desired, 'Hz')} = "
                     f"{tex_qty(2 * math.pi * xo.desired, 'rad/s')}", svg)]
    if xo.achievable is not None:
        ok = xo.desired <= xo.achievable * (1 + 1e-9)
        rel = "\\leq" if ok else ">"
        eqs.append(_equation(
            f"f_c = {tex_qty(xo.desired, 'Hz')}\\ {rel}\\ "
            f"f_{{c,\\mathrm{{ach}}}} = {tex_qty(xo.achievable, 'Hz')}", svg))
    eqs.append(_equation(f"f_\\mathrm{{par}} \\geq n_\\mathrm{{sep}}\\, f_c = {tex_num(sep)} "
                         f"\\times {tex_qty(xo.desired, 'Hz')} = {tex_qty(need, 'Hz')}", svg))
    pms = [c.phase_margin_deg for c in xo.cases]
    gms = [abs(c.gain_margin_db) for c in xo.cases]
    results = [
        {"quantity": "desired crossover fc", "value": xo.desired, "unit": "Hz"},
        {"quantity": "achievable crossover", "value": xo.achievable, "unit": "Hz"},
        {"quantity": "limited by", "value": xo.limited_by, "unit": ""},
        {"quantity": "smallest phase margin at fc (all cases)", "value": min(pms),
         "unit": "deg"},
        {"quantity": "smallest gain margin at fc (all cases)", "value": min(gms), "unit": "dB"},
        {"quantity": "loop delay in the analysis", "value": xo.delay, "unit": "s"},
        {"quantity": "lowest allowed parasitic frequency", "value": need, "unit": "Hz"},
    ]
    for m in xo.parasitic_modes:
        results.append({"quantity": f"parasitic mode \u2018{m.name}\u2019"
                                    f" ({'collocated' if m.collocated else 'non-collocated'})",
                        "value": m.frequency, "unit": "Hz"})
    steps.append({
        "number": 2, "title": "Desired and achievable crossover",
        "source": "paper \u00a72.2 and \u00a74 step 2; Figure 2",
        "equations": eqs, "results": results,
        "explanation": (
            "One PID must be stable, with the required margins "
            f"({qty(req.phase_margin, 'deg')} phase, {qty(req.gain_margin, 'dB')} gain), in every "
            "linear limit case the stage switches between near standstill (paper Figure 2). The "
            "achievable crossover is the highest at which all cases keep these margins and every "
            f"parasitic flexure mode stays {num(sep)} times above the crossover. A limited "
            "achievable crossover makes an isolator useful; a high one may avoid hunting by "
            "control alone. The margins of each case are in the linear analysis below."),
    })

    # step 3
    eqs = []
    results = []
    if spec.isolator is not None or st.suggested:
        gamma = st.safety
        eqs.append(_equation(
            f"k_\\max = \\frac{{F_s}}{{\\gamma\\, s}} = \\frac{{{tex_qty(st.static, 'N')}}}"
            f"{{{tex_num(gamma)} \\times {tex_qty(st.stroke, 'm')}}} = "
            f"{tex_qty(st.maximum, 'N/m')}", svg))
        ok = st.chosen <= st.maximum * (1 + 1e-12)
        rel = "<" if st.force_at_stroke < st.static else "\\geq"
        eqs.append(_equation(
            f"F_k = k\\, s = {tex_qty(st.chosen, 'N/m')} \\times {tex_qty(st.stroke, 'm')} = "
            f"{tex_qty(st.force_at_stroke, 'N')}\\ {rel}\\ F_s = {tex_qty(st.static, 'N')}", svg))
        results += [
            {"quantity": "stroke s", "value": st.stroke, "unit": "m"},
            {"quantity": "safety factor \u03b3 (requirements.stiffness_safety)",
             "value": st.safety, "unit": "1"},
            {"quantity": "maximum drive stiffness k_max", "value": st.maximum, "unit": "N/m"},
            {"quantity": "chosen drive stiffness k", "value": st.chosen, "unit": "N/m"},
            {"quantity": "source of k", "value": st.source, "unit": ""},
            {"quantity": "flexure force at full stroke k s", "value": st.force_at_stroke,
             "unit": "N"},
            {"quantity": "k within k_max", "value": "yes" if ok else "no", "unit": ""},
        ]
    fx = result.flexure
    if fx is not None and fx.feasible:
        E = spec.isolator.flexure.material.youngs_modulus
        eqs.append(_equation(
            f"k = \\frac{{n E b t^3}}{{L^3}} = \\frac{{{fx.leaves} \\times {tex_qty(E, 'Pa')} "
            f"\\times {tex_qty(fx.width, 'm')} \\times ({tex_qty(fx.thickness, 'm')})^3}}"
            f"{{({tex_qty(fx.length, 'm')})^3}} = {tex_qty(fx.drive_stiffness, 'N/m')}", svg))
        rel = "\\leq" if fx.stress <= fx.allowed_stress else ">"
        eqs.append(_equation(
            f"\\sigma = \\frac{{3 E t s}}{{L^2}} = {tex_qty(fx.stress, 'Pa')}\\ "
            f"{rel}\\ \\sigma_\\mathrm{{allow}} = "
            f"{tex_qty(fx.allowed_stress, 'Pa')}", svg))
        results += [
            {"quantity": "leaves n", "value": fx.leaves, "unit": "1"},
            {"quantity": "leaf length L", "value": fx.length, "unit": "m"},
            {"quantity": "leaf width b", "value": fx.width, "unit": "m"},
            {"quantity": "leaf thickness t", "value": fx.thickness, "unit": "m"},
            {"quantity": "bending stress at full stroke", "value": fx.stress, "unit": "Pa"},
            {"quantity": "stress margin allowed / actual", "value": fx.stress_margin, "unit": "1"},
            {"quantity": "support-direction frequency (with m1)", "value": fx.support_frequency,
             "unit": "Hz"},
            {"quantity": "leaf bending resonance (clamped-guided)", "value": fx.bending_frequency,
             "unit": "Hz"},
            {"quantity": "required parasitic frequency", "value": fx.required_frequency,
             "unit": "Hz"},
        ]
    elif fx is not None:
        results.append({"quantity": "leaf-spring flexure", "value": f"none fits: {fx.reason}",
                        "unit": ""})
    sim = result.simulation
    land = getattr(sim, "landing", None) if sim is not None else None
    if land is not None:
        eqs.append(_equation(
            f"F_\\mathrm{{rest}} = k \\min(|d|, s) = {tex_qty(land.stiffness, 'N/m')} \\times "
            f"{tex_qty(min(abs(land.deflection), land.stroke), 'm')} = {tex_qty(land.force, 'N')}", svg))
        results.append({"quantity": "simulated deflection at rest d", "value": land.deflection,
                        "unit": "m"})
        results.append({"quantity": "flexure force on the resting cart", "value": land.force,
                        "unit": "N"})
    if st.suggested:
        lead = ("The spec has no isolator; these are the values to start a design from, for the "
                "paper's 0.3 mm stroke. ")
    else:
        lead = ""
    steps.append({
        "number": 3, "title": "Maximum drive stiffness", "source": "paper \u00a74 step 3; "
                                                                    "Figure 4C",
        "equations": eqs, "results": results,
        "explanation": lead + (
            "At full stroke the flexure must push the cart with less than static friction, or it "
            "drags the cart along while the stage settles and the controller feels the friction "
            "again: k_max = Fs / (\u03b3 s). Lower stiffness mitigates hunting better (paper "
            "Figure 4C); the flexure's parasitic modes and support stiffness bound how low it can "
            "go. The simulated force on the resting cart refines the rule: the cart sees "
            "k min(|d|, s), not k s."),
    })

    # step 4
    m_text = ("m_1 + m_2" if spec.controller.tuning_mass == "total" else "m_1")
    eqs = [
        _equation(f"m = {m_text} = {tex_qty(g.tuning_mass, 'kg')}", svg),
        _equation("C(s) = k_s \\left(1 + \\frac{\\omega_i}{s}\\right)"
                  "\\frac{1 + s/\\omega_d}{1 + s/\\omega_t}", svg),
        _equation(f"k_s = \\frac{{m\\, \\omega_c^2}}{{r}} = \\frac{{{tex_qty(g.tuning_mass, 'kg')}"
                  f" \\times ({tex_qty(g.wc, 'rad/s')})^2}}{{{tex_num(result.pid.derivative_ratio)}"
                  f"}} = {tex_qty(g.ks, 'N/m')}", svg),
        _equation(f"\\omega_d = \\omega_c / r = {tex_qty(g.wd, 'rad/s')},\\quad \\omega_t = "
                  f"r\\, \\omega_c = {tex_qty(g.wt, 'rad/s')},\\quad \\omega_i = \\omega_c / r_i = "
                  f"{tex_qty(g.wi, 'rad/s')}", svg),
        _equation(f"k_p = k_s (1 + \\omega_i/\\omega_d) = {tex_qty(g.kp, 'N/m')},\\quad "
                  f"k_i = k_s \\omega_i = {tex_qty(g.ki, 'N/(m s)')},\\quad "
                  f"k_d = k_s / \\omega_d = {tex_qty(g.kd, 'N s/m')}", svg),
    ]
    steps.append({
        "number": 4, "title": "PID gains", "source": "paper \u00a72.2 and \u00a74 step 4",
        "equations": eqs,
        "results": [
            {"quantity": "tuning mass m", "value": g.tuning_mass, "unit": "kg"},
            {"quantity": "proportional gain kp", "value": g.kp, "unit": "N/m"},
            {"quantity": "integral gain ki", "value": g.ki, "unit": "N/(m s)"},
            {"quantity": "derivative gain kd", "value": g.kd, "unit": "N s/m"},
            {"quantity": "roll-off \u03c9t", "value": g.wt, "unit": "rad/s"},
        ],
        "explanation": (
            "The gains follow from the moving mass and the crossover: the lead-lag part has its "
            "phase maximum at \u03c9c, and k_s puts |C(j\u03c9c)| = m \u03c9c\u00b2, so a free "
            "mass m crosses over at \u03c9c. The paper tunes on the maximum moving mass m1 + m2 "
            "(the limiter engaged), which it found best. The simulation uses the parallel form "
            "(kp + ki/s + kd s) / (1 + s/\u03c9t)."),
    })
    return steps


def _cases_table(result: Any) -> list[dict]:
    from .linear import CASE_NUMBERS

    rows = []
    for c in result.crossover.cases:
        status = "PASS" if c.passed else "FAIL"
        rows.append({
            "number": CASE_NUMBERS.get(c.name, ""), "description": c.description,
            "crossover": c.crossover, "crossovers": len(c.crossovers),
            "phase_margin": c.phase_margin_deg, "gain_margin": c.gain_margin_db,
            "modulus_margin": c.modulus_margin, "delay_margin": c.delay_margin,
            "stable": "yes" if c.stable else "no", "status": status, "css": status.lower(),
            "failed": ", ".join(c.failed),
        })
    return rows


class _Numbering:
    """Figure numbers in order of appearance."""

    def __init__(self) -> None:
        self.n = 0

    def __call__(self) -> int:
        self.n += 1
        return self.n


def _figure(make: Callable[[], Any] | None, name: str, caption: str, number: int,
            width: str = "full") -> dict:
    from markupsafe import Markup

    svg = None
    if make is not None:
        from .plots import figure_svg

        svg = Markup(figure_svg(make(), name))
    return {"name": name, "number": number, "caption": caption, "svg": svg, "width": width}


def _linear(result: Any, figures: bool, fig_no: _Numbering) -> dict:
    from . import plots

    f = responses = None
    if figures:
        f = plots.frequency_grid(result)
        responses = plots.loop_responses(result, f)
    req = result.spec.requirements
    xo = result.crossover
    n = len(xo.cases)
    m = req.modulus_margin if req.modulus_margin is not None else 0.5
    return {
        "intro": (
            f"The loop L = C D P of each of the {n} linear limit cases (paper Figure 2) with the "
            f"PID of step 4 at the desired crossover of {qty(xo.desired, 'Hz')}"
            + (f" and a Pad\u00e9 model of the {qty(xo.delay, 's')} loop delay"
               if xo.delay > 0 else "")
            + ". Margins come from python-control's stability_margins; closed-loop stability "
            "from the roots of the characteristic polynomial. A case can cross 0 dB more than "
            "once; the table gives the crossing with the smallest phase margin and the "
            "number of crossings."),
        "bode": _figure((lambda: plots.bode_figure(result, responses, f)) if figures else None,
                        "bode", f"Open-loop Bode plot of the {n} limit cases. Dots: gain "
                        "crossovers; dashed: the desired crossover.", fig_no()),
        "nyquist": _figure((lambda: plots.nyquist_figure(result, responses, f))
                           if figures else None, "nyquist",
                           f"Nyquist plot near the critical point -1 (+). Dotted: |1 + L| = "
                           f"{num(m)}. Colours and line styles as in the Bode plot.",
                           fig_no(), "half"),
        "sensitivity": _figure((lambda: plots.sensitivity_figure(result, responses, f))
                               if figures else None, "sensitivity",
                               "Sensitivity |S| = |1/(1 + L)|; dots mark each peak "
                               "(1 / modulus margin).", fig_no(), "half"),
        "cases": _cases_table(result),
        "requirements": {"phase_margin": req.phase_margin, "gain_margin": req.gain_margin,
                         "modulus_margin": req.modulus_margin},
        "note": ("A negative gain margin marks a lower gain margin: the integrator on a free mass "
                 "starts the phase below -180\u00b0, and the loop goes unstable if the gain "
                 "falls by that much. An infinite gain margin means the phase never crosses "
                 "-180\u00b0."),
    }


#: Friction models as the literature names them.
_MODEL_NAMES = {"lugre": "LuGre", "switch": "switch (Karnopp-type)"}


def _plant_rows(sim: Any) -> list[dict]:
    mins = sim.min_hunting_free_crossover
    label = "suggested isolator" if sim.suggested_isolator else "with isolator"
    rows = []
    for key, name in (("isolated", label), ("non_isolated", "without isolator")):
        v = getattr(sim, key)
        other = sim.cross_check.get(key)
        rows.append({
            "plant": name, "verdict": v.verdict,
            "css": {"settled": "pass", "hunting": "fail"}.get(v.verdict, "warn"),
            "cycles": v.hunting_cycles, "amplitude": v.amplitude, "period": v.period,
            "settling_time": v.settling_time, "final_error": v.final_error,
            "minimum": mins.get(key), "other": other.verdict if other is not None else "",
            "other_model": other.friction_model if other is not None else "",
            "reason": v.reason,
        })
    return rows


def _nonlinear(result: Any, figures: bool, fig_no: _Numbering) -> dict | None:
    from . import plots

    sim = result.simulation
    if sim is None:
        return None
    spec = result.spec
    h = spec.requirements.hunting
    mins = sim.min_hunting_free_crossover
    iso = sim.results["isolated"]
    label = "the suggested isolator" if sim.suggested_isolator else "the isolator"
    land = sim.landing
    scan = sim.scans["isolated"]
    out = {
        "intro": (
            f"The stage is simulated with and without {label} at the design crossover, with "
            f"{_MODEL_NAMES.get(sim.isolated.friction_model, sim.isolated.friction_model)} "
            "friction, through the spec's moves and then at "
            "rest. The paper's hunting metric (section 2.3) counts the peaks of the position "
            f"error x1 - r of at least {qty(h.min_height, 'm')}, at least "
            f"{qty(h.min_distance, 's')} apart, in the window [{num(h.window_start)} s, "
            f"{num(h.window_start + h.window_length)} s); one peak is one hunting cycle. The "
            "verdict also names a stage that is stuck away from its target or moves too slowly to "
            "judge, which the count alone cannot see."),
        "plants": _plant_rows(sim),
        "resolution": mins["resolution"],
        "scan_range": mins["scan"],
        "error": _figure((lambda: plots.error_figure(sim, spec)) if figures else None, "error",
                         "Position error with and without the isolator (as the paper's Figure 5). "
                         "Grey: the counting window; dashed: the minimum peak height; circles: "
                         "the peaks the metric counts.", fig_no()),
        "deflection": _figure((lambda: plots.deflection_figure(sim, spec)) if figures else None,
                              "deflection", "Joint deflection of the isolated stage against the "
                              "stroke; beyond the dashed lines the limiter carries the cart.",
                              fig_no()),
        "scan": _figure((lambda: plots.scan_figure(sim, spec)) if figures else None, "scan",
                        f"Hunting cycles down the crossover scan (grid {num(scan.grid[0])} to "
                        f"{num(scan.grid[1])} Hz in steps of {num(scan.grid[2])} Hz), both "
                        "plants. The scan runs from the top down and stops at the first "
                        "crossover that does not settle; dotted: the lowest hunting-free "
                        "crossover, dashed: the design crossover.", fig_no()),
        "landing": None if land is None else {
            "deflection": land.deflection, "stroke": land.stroke, "force": land.force,
            "static_friction": land.static_friction, "rule_force": land.rule_force,
            "on_limiter": "yes" if land.on_limiter else "no",
        },
        "models_agree": sim.models_agree,
        "cross_check": (
            f"Cross-check with the {_MODEL_NAMES.get(sim.cross_check['isolated'].friction_model, '')}"
            " friction model: "
            + ("both models give the same hunting / no-hunting call for both plants."
               if sim.models_agree else
               "the models disagree on the verdict (see the checks); treat the margin to hunting "
               "as small.")),
        "solver": {"steps": iso.n_steps, "rejected": iso.n_rejected, "events": iso.n_events},
    }
    return out


def _map_section(result: Any, map_result: Any, figures: bool, fig_no: _Numbering,
                 note: str) -> dict | None:
    if map_result is None:
        return None
    from . import plots

    def make():
        from matplotlib.figure import Figure
        import matplotlib

        from matplotlib.ticker import FuncFormatter, NullFormatter

        with matplotlib.rc_context(plots.REPORT_RC):
            fig = Figure(figsize=(plots.REPORT_WIDTH, 3.8), layout="constrained")
            ax = fig.add_subplot()
            plots.draw_sweep(ax, map_result, title="")
            for axis, swept in ((ax.xaxis, map_result.x), (ax.yaxis, map_result.y)):
                if swept is not None and swept.log:  # plain numbers, not mathtext powers
                    _, factor = plots.display_unit(swept.unit)
                    axis.set_major_formatter(FuncFormatter(plots.plain_tick))
                    axis.set_minor_formatter(NullFormatter())
                    lo, hi = min(swept.values) * factor, max(swept.values) * factor
                    axis.set_ticks([v for v in _nice_ticks(lo, hi)])
        return fig

    counts = map_result.counts()
    x, y = map_result.x, map_result.y
    return {
        "intro": (
            f"Hunting cycles of the isolated stage around the design point (red cross) over "
            f"{x.path} \u00d7 {y.path}, as the paper's Figure 4D: {len(x.values)} \u00d7 "
            f"{len(y.values)} simulations with the PID retuned at every crossover. " + note),
        "figure": _figure(make if figures else None, "map",
                          f"Hunting cycles over {x.path} and {y.path} (isolated). Marks: "
                          "s stuck, ? undetermined, \u00d7 failed.", fig_no()),
        "counts": ", ".join(f"{k} {v}" for k, v in counts.items() if v),
    }


def _nice_ticks(lo: float, hi: float) -> list[float]:
    """1-2-5 ticks between lo and hi (log axes of the map)."""
    out = []
    for exp in range(math.floor(math.log10(lo)) - 1, math.ceil(math.log10(hi)) + 1):
        for m in (1.0, 2.0, 5.0):
            v = m * 10.0 ** exp
            if lo * 0.999 <= v <= hi * 1.001:
                out.append(float(f"{v:.6g}"))
    return out


def _assumptions(result: Any) -> dict:
    spec = result.spec
    sim = spec.simulation
    h = spec.requirements.hunting
    return {
        "model": [
            "Two rigid masses (stage m1, cart m2) joined by a linear spring-damper (k, c) with "
            "compliant end stops at \u00b1s; without the isolator one rigid mass m1 + m2. Motion "
            "along one axis only: tilt, yaw and support compliance enter only as the parasitic "
            "modes of the linear analysis.",
            "LuGre friction (Canudas de Wit et al. 1995) with constant parameters along the "
            "rail; the switch (Karnopp-type) model serves as a cross-check. Real friction varies "
            "with position, time, temperature and wear (paper \u00a73.2), so the simulated "
            "number of cycles is an indication, not a prediction.",
            "The PID is continuous-time unless a sample rate is given; actuator and sensor are "
            "ideal apart from the effects listed in the spec.",
            "The linear analysis linearises friction in four limit cases (cart sliding or stuck, "
            "joint free or on its limiter, paper Figure 2): the margins hold near each case, not "
            "during transitions between them.",
        ],
        "solver": [
            f"Fast path: a linearly implicit Rosenbrock method of order 4 (RODAS4, Hairer and "
            f"Wanner) with step-size control at relative tolerance {num(sim.tolerance)}, mode "
            "switches of limiter and stick-slip located as events; traces sampled at "
            f"{qty(sim.output_rate, 'Hz')}.",
            "The fast integrator is tested against scipy's solve_ivp (Radau) at a tolerance "
            "10\u2074 times tighter on the same equations.",
        ],
        "metric": [
            f"The metric counts peaks above +{qty(h.min_height, 'm')} only: a cycle with a "
            "smaller amplitude, or one offset below the target, counts as none.",
            f"A cycle slower than the {qty(h.window_length, 's')} window shows no peak; the "
            "verdict then says 'undetermined', not 'settled'.",
            "A stage resting away from its target (stuck) shows no peaks either; the verdict "
            f"calls it 'stuck' unless it lies within the settle band of {qty(h.settle_band, 'm')}.",
            "Hunting can come and go with the crossover (the paper saw a hunting-free run at "
            "9.5 Hz): the lowest hunting-free crossover is the one above which every scanned "
            "crossover settles, within one scan step.",
        ],
    }


#: The paper and the standard works it builds on.
REFERENCES = (
    ("Fix2024", "J. A. Fix et al., \u201cMitigating friction induced limit cycles by an "
                "intermediate flexure stage\u201d (the paper this tool implements; design "
                "guideline in \u00a74)."),
    ("Fix2023", "J. A. Fix, A Linearized Parameter Study of a Friction Isolator System: "
                "Towards a Frequency Domain Design Guideline, MSc thesis, University of Twente, "
                "2023."),
    ("Canudas1995", "C. Canudas de Wit, H. Olsson, K. J. \u00c5str\u00f6m and P. Lischinsky, "
                    "\u201cA new model for control of systems with friction\u201d, IEEE "
                    "Transactions on Automatic Control 40(3), 1995 (the LuGre model)."),
    ("Astrom2008", "K. J. \u00c5str\u00f6m and C. Canudas-de-Wit, \u201cRevisiting the LuGre "
                   "friction model\u201d, IEEE Control Systems Magazine 28(6), 2008."),
    ("Hensen2003", "R. H. A. Hensen, M. J. G. van de Molengraft and M. Steinbuch, \u201cFriction "
                   "induced hunting limit cycles: a comparison between the LuGre and switch "
                   "friction model\u201d, Automatica 39(12), 2003."),
    ("Hensen2002", "R. H. A. Hensen and M. J. G. van de Molengraft, \u201cFriction induced "
                   "hunting limit cycles: an event mapping approach\u201d, Proc. American "
                   "Control Conference, 2002."),
    ("Karnopp1985", "D. Karnopp, \u201cComputer simulation of stick-slip friction in mechanical "
                    "dynamic systems\u201d, ASME J. Dynamic Systems, Measurement and Control "
                    "107(1), 1985 (the switch model)."),
    ("Hairer1996", "E. Hairer and G. Wanner, Solving Ordinary Differential Equations II: Stiff "
                   "and Differential-Algebraic Problems, 2nd ed., Springer, 1996 (RODAS4)."),
    ("Dong2018", "X. Dong and C. E. Okwudire, \u201cAn experimental investigation of the effects "
                 "of the compliant joint method on feedback compensation of pre-sliding/"
                 "pre-rolling friction\u201d, Precision Engineering 54, 2018."),
    ("Dong2020", "X. Dong and C. E. Okwudire, \u201cInfluence of design parameters on the "
                 "effectiveness of friction isolators in mitigating pre-motion friction in "
                 "mechanical bearings\u201d, Mechatronics 71, 2020."),
    ("Wang2022", "J. Wang, X. Dong, O. R. Barry and C. Okwudire, \u201cFriction-induced "
                 "instability and vibration in a precision motion stage with a friction "
                 "isolator\u201d, Journal of Vibration and Control 28(15-16), 2022."),
    ("AlBender2008", "F. Al-Bender and J. Swevers, \u201cCharacterization of friction force "
                     "dynamics\u201d, IEEE Control Systems Magazine 28(6), 2008."),
    ("Maeda2013", "Y. Maeda and M. Iwasaki, \u201cRolling friction model-based analyses and "
                  "compensation for slow settling response in precise positioning\u201d, IEEE "
                  "Transactions on Industrial Electronics 60(12), 2013 (PID from mass and "
                  "crossover)."),
    ("Skogestad2005", "S. Skogestad and I. Postlethwaite, Multivariable Feedback Control, 2nd "
                      "ed., Wiley, 2005 (margins and sensitivity)."),
)


def _appendix(result: Any) -> dict:
    spec = result.spec
    src = _spec_file(spec)
    sim = spec.simulation
    scan = sim.crossover_scan
    solver = [
        {"quantity": "integrator", "value": "RODAS4 (fast kernel, numba)", "unit": ""},
        {"quantity": "relative tolerance", "value": sim.tolerance, "unit": "1"},
        {"quantity": "output rate", "value": sim.output_rate, "unit": "Hz"},
        {"quantity": "step budget per simulation", "value": sim.max_steps, "unit": "1"},
        {"quantity": "simulated time", "value": spec.motion.duration, "unit": "s"},
        {"quantity": "crossover scan", "value": [scan.start, scan.stop], "unit": "Hz"},
        {"quantity": "crossover scan step", "value": scan.step, "unit": "Hz"},
        {"quantity": "friction model", "value": spec.friction.model, "unit": ""},
        {"quantity": "loop delay (linear analysis, Pad\u00e9 order "
                     f"{spec.controller.pade_order})", "value": result.crossover.delay,
         "unit": "s"},
    ]
    sim_res = result.simulation
    if sim_res is not None:
        for key, res in sim_res.results.items():
            solver.append({"quantity": f"steps / rejected / events ({key.replace('_', '-')})",
                           "value": f"{res.n_steps} / {res.n_rejected} / {res.n_events}",
                           "unit": ""})
    return {
        "spec_yaml": _yaml_text(src["raw"]) if src["raw"] is not None else
        _yaml_text(_plain_spec(spec)),
        "spec_note": ("as read from the file (units as written; comments dropped)"
                      if src["raw"] is not None else "as given in code, in SI units"),
        "solver": solver,
        "versions": _versions(),
    }


def _plain_spec(spec: Any) -> dict:
    from .results import to_jsonable

    return to_jsonable(spec.model_dump())


def _design_sections(ctx: dict) -> list[dict]:
    sections = [
        {"id": "verdict", "title": "Verdict", "template": "verdict.html.jinja"},
        {"id": "inputs", "title": "Inputs", "template": "inputs.html.jinja"},
        {"id": "steps", "title": "The four guideline steps", "template": "steps.html.jinja"},
        {"id": "linear", "title": "Linear analysis", "template": "linear.html.jinja"},
        {"id": "nonlinear", "title": "Nonlinear confirmation", "template": "nonlinear.html.jinja"},
    ]
    if ctx.get("map") is not None:
        sections.append({"id": "map", "title": "Hunting map around the design point",
                         "template": "map.html.jinja"})
    sections += [
        {"id": "assumptions", "title": "Assumptions and limitations",
         "template": "assumptions.html.jinja"},
        {"id": "references", "title": "References", "template": "references.html.jinja"},
        {"id": "appendix", "title": "Appendix: spec, solver and software",
         "template": "appendix.html.jinja"},
    ]
    for i, s in enumerate(sections, 1):
        s["number"] = i
    return sections


def build_context(result: Any, *, date: Any = None, command: str | None = None,
                  map_result: Any = None, map_note: str = "", figures: bool = True) -> dict:
    """Everything a design report shows, as plain data.

    Parameters
    ----------
    result : fi_design.guideline.DesignResult
        The design (with its simulated confirmation, if any).
    date : str or datetime.date, optional
        The report date; default :func:`report_date` (today).
    command : str, optional
        The command line that made the report (shown in the title block).
    map_result : fi_design.studies.SweepResult, optional
        A crossover x stroke map to show (see :func:`design_map`).
    map_note : str, optional
        How the map was computed, for its section.
    figures : bool, optional
        Render figures and equations to SVG (default). False leaves ``svg``
        None everywhere: the golden tests compare the rest.

    Returns
    -------
    dict
        Keys ``meta`` (title block), ``sections`` (the contents, in order),
        ``verdict``, ``inputs``, ``steps``, ``linear``, ``nonlinear`` (None
        without simulation), ``map`` (None without map), ``assumptions``,
        ``references``, ``appendix``. Numbers are SI floats with a ``unit`` key
        beside them (the templates format them with :func:`qty`), or text.
    """
    spec = result.spec
    fig_no = _Numbering()
    ctx: dict[str, Any] = {
        "meta": _meta(spec, "design", date=date, command=command, sha256=result.spec_sha256,
                      version=result.fi_design_version),
        "verdict": _verdict(result),
        "inputs": spec_inputs(spec),
        "steps": _steps(result, figures),
        "linear": _linear(result, figures, fig_no),
        "nonlinear": _nonlinear(result, figures, fig_no),
    }
    if ctx["nonlinear"] is None:
        ctx["nonlinear_missing"] = ("The nonlinear confirmation was not run (fi-design "
                                    "--no-simulation, or design(spec, confirm=False)): the "
                                    "verdict rests on the linear steps alone.")
    ctx["map"] = _map_section(result, map_result, figures, fig_no, map_note)
    ctx["assumptions"] = _assumptions(result)
    ctx["references"] = [{"key": k, "text": t} for k, t in REFERENCES]
    ctx["appendix"] = _appendix(result)
    ctx["sections"] = _design_sections(ctx)
    return ctx


# --------------------------------------------------------------------------- the map


def design_map(result: Any, *, resolution: tuple[int, int] = (8, 6), progress: Any = None,
               executor: Any = None) -> tuple[Any, str]:
    """A small crossover x stroke hunting map around the design point (paper Figure 4D).

    Parameters
    ----------
    result : fi_design.guideline.DesignResult
        The design; its spec needs an isolator (a spec without one is mapped
        with the isolator the guideline suggests).
    resolution : (int, int), optional
        Points along the crossover and the stroke (default 8 x 6 = 48
        simulations, a few seconds).
    progress : callable, optional
        ``progress(text)`` with a short message.
    executor : concurrent.futures-style executor, optional
        Passed to :func:`fi_design.studies.sweep`.

    Returns
    -------
    map : fi_design.studies.SweepResult
        The map (x: ``controller.crossover``, y: ``isolator.stroke``).
    note : str
        How it was computed, for the report.
    """
    import numpy as np

    from .studies import make_axis, sweep

    spec = result.spec
    note = ""
    if spec.isolator is None:
        from .confirm import with_isolator

        adv = result.isolator_advice
        spec = with_isolator(spec, adv.stroke, adv.stiffness)
        note = (f"The spec has no isolator: the map uses the suggested one "
                f"({qty(adv.stroke, 'm')} stroke, {qty(adv.stiffness, 'N/m')}). ")
    fc = _spec.design_crossover(spec)
    s = spec.isolator.stroke
    nx, ny = resolution
    xs = np.linspace(0.125 * fc, 2.5 * fc, nx)
    ys = np.geomspace(s / 6.0, s * 10.0 / 3.0, ny)
    x = make_axis("controller.crossover", xs, spec=spec)
    y = make_axis("isolator.stroke", ys, log=True, spec=spec)

    def tick(done: int, total: int) -> None:
        if progress is not None:
            progress(f"hunting map: {done}/{total} simulations")

    out = sweep(spec, x, y, isolated=True, executor=executor, progress=tick)
    held = ("the drive stiffness held at the design value" if spec.isolator.stiffness is not None
            else "the drive stiffness following the stroke (k_max / 2: the spec gives none)")
    note += (f"Computed with fi_design.studies.sweep: crossover {num(xs[0])} to {num(xs[-1])} Hz, "
             f"stroke {qty(ys[0], 'm')} to {qty(ys[-1], 'm')} (log), {held}.")
    return out, note


# --------------------------------------------------------------------------- rendering


def render_html(context: dict) -> str:
    """Render a report context (from :func:`build_context` or a generic one) to HTML.

    Parameters
    ----------
    context : dict
        ``meta``, ``sections`` (each with ``id``, ``number``, ``title`` and
        ``template``) and the data each section's template reads under its
        ``id``.

    Returns
    -------
    str
        One self-contained HTML document (inline CSS and SVG, no script).
    """
    body = []
    for section in context["sections"]:
        body.append(_render(section["template"], section=section,
                            data=context.get(section["id"]), meta=context["meta"],
                            context=context))
    return environment().get_template("report.html.jinja").render(
        meta=context["meta"], sections=context["sections"], body=body, css=_css())


def _write(html: str, path: Path, fmt: str) -> Path:
    from .output import atomic_path, write_atomic

    if fmt == "html":
        return write_atomic(path, html)
    import logging

    # WeasyPrint logs every CSS property it does not know at WARNING; the report's
    # screen-only rules are expected to be skipped.
    logging.getLogger("weasyprint").setLevel(logging.ERROR)
    logging.getLogger("fontTools").setLevel(logging.ERROR)
    from weasyprint import HTML

    document = HTML(string=html, base_url=None, url_fetcher=_no_fetch).render()
    with atomic_path(path) as tmp:
        document.write_pdf(str(tmp))
    return path


def preload(path: str | os.PathLike) -> None:
    """Import the rendering libraries a report at ``path`` needs, ahead of time.

    matplotlib for the figures; WeasyPrint too for a ``.pdf``. The CLI calls it
    while it waits for the simulations, so the imports (about a second) cost no
    time later.

    Parameters
    ----------
    path : str or os.PathLike
        The report's file name (the extension selects the format).

    Returns
    -------
    None

    Raises
    ------
    fi_design.errors.OutputError
        The extension is not .html or .pdf.
    """
    fmt = _fmt_format(path)
    import matplotlib.backends.backend_svg  # noqa: F401
    import matplotlib.figure  # noqa: F401

    environment()
    if fmt == "pdf":
        import weasyprint  # noqa: F401


def _no_fetch(url: str, *args: Any, **kwargs: Any) -> dict:
    """URL fetcher that refuses everything: the report is self-contained by design."""
    raise ValueError(f"the report makes no external requests (refused {url!r})")


def render_report(result: Any, path: str | os.PathLike, *, date: Any = None,
                  command: str | None = None, map: bool | None = None,
                  map_result: Any = None, progress: Callable[[str], None] | None = None,
                  executor: Any = None) -> Path:
    """Write the report of a result as HTML or PDF (chosen by the extension).

    Parameters
    ----------
    result : DesignResult, SweepResult, StudyResult, RobustnessResult or object
        What to report. An object with ``report_sections()`` (a list of
        :class:`Section`) and ``report_title`` is rendered through
        :func:`render_document`.
    path : str or os.PathLike
        Output file, ``.html`` or ``.pdf``; an existing file is replaced
        (atomically). Any other extension raises before any work.
    date : str or datetime.date, optional
        Report date; default today (or ``SOURCE_DATE_EPOCH``).
    command : str, optional
        The command line, shown in the title block.
    map : bool, optional
        Design reports: add the crossover x stroke map (about 50 extra
        simulations); None follows the spec's ``report.map``.
    map_result : fi_design.studies.SweepResult, optional
        A map computed elsewhere, shown instead of computing one.
    progress : callable, optional
        ``progress(text)`` with a short message as the work proceeds.
    executor : concurrent.futures-style executor, optional
        Runs the map's simulations (:func:`fi_design.studies.sweep`).

    Returns
    -------
    pathlib.Path
        The written file.

    Raises
    ------
    fi_design.errors.OutputError
        The extension is not .html or .pdf, or the file cannot be written.
    TypeError
        ``result`` is of a kind there is no report for.
    """
    out = Path(path)
    fmt = _fmt_format(out)

    def say(text: str) -> None:
        if progress is not None:
            progress(text)

    kind = type(result).__name__
    if kind == "DesignResult":
        note = ""
        want_map = result.spec.report.map if map is None else bool(map)
        if map_result is None and want_map:
            map_result, note = design_map(result, progress=progress, executor=executor)
        elif map_result is not None:
            note = "Computed with fi_design.studies.sweep."
        say("drawing the report's figures ...")
        ctx = build_context(result, date=date, command=command, map_result=map_result,
                            map_note=note)
    elif kind in ("SweepResult", "StudyResult", "RobustnessResult"):
        say("drawing the report's figures ...")
        ctx = sweep_context(result, date=date, command=command)
    elif hasattr(result, "report_sections"):
        ctx = document_context(getattr(result, "report_title", "Report"),
                               getattr(result, "spec"), result.report_sections(), date=date,
                               command=command, kind=getattr(result, "report_kind", "report"))
    else:
        hint = ("; for a reconciliation use fi_design.gapreport.render_gap_report"
                if kind == "ReconcileResult" else "")
        raise TypeError(f"no report for a {kind}; expected a DesignResult, a sweep result or an "
                        f"object with report_sections(){hint}")
    html = render_html(ctx)
    say("writing the PDF ..." if fmt == "pdf" else "writing the HTML ...")
    return _write(html, out, fmt)


# --------------------------------------------------------------------------- generic documents


def document_context(title: str, spec: Any, sections: Sequence[Section], *, date: Any = None,
                     command: str | None = None, kind: str = "report",
                     conclusion: str = "") -> dict:
    """The context of a generic report: title block, :class:`Section` values, appendix.

    Parameters
    ----------
    title : str
        Report title (under the project name).
    spec : fi_design.spec.Spec
        The spec the work started from (title block, appendix).
    sections : sequence of Section
        The content, in order.
    date : str or datetime.date, optional
        Report date.
    command : str, optional
        The command line.
    kind : str, optional
        Short kind (``"sweep"``, ``"reconcile"``), kept in the metadata.
    conclusion : str, optional
        A paragraph shown first, under "Summary".

    Returns
    -------
    dict
        For :func:`render_html`.
    """
    ctx: dict[str, Any] = {"meta": _meta(spec, kind, date=date, command=command, title=title)}
    entries = []
    if conclusion:
        sections = [Section("summary", "Summary", paragraphs=(conclusion,))] + list(sections)
    for s in sections:
        entries.append({"id": s.id, "title": s.title, "template": "generic.html.jinja"})
        ctx[s.id] = {
            "paragraphs": list(s.paragraphs),
            "tables": [t.as_context() for t in s.tables],
            "figures": [{"name": f.name, "caption": f.caption, "svg": _markup(f.svg),
                         "width": f.width, "number": None} for f in s.figures],
            "notes": list(s.notes),
        }
    src = _spec_file(spec)
    ctx["appendix"] = {
        "spec_yaml": _yaml_text(src["raw"]) if src["raw"] is not None else
        _yaml_text(_plain_spec(spec)),
        "spec_note": ("as read from the file (units as written; comments dropped)"
                      if src["raw"] is not None else "as given in code, in SI units"),
        "solver": [], "versions": _versions()}
    entries.append({"id": "appendix", "title": "Appendix: spec and software",
                    "template": "appendix.html.jinja"})
    n = 0
    for e in entries:
        n += 1
        e["number"] = n
    fig = 0
    for e in entries:
        for f in (ctx[e["id"]].get("figures") or []) if e["id"] != "appendix" else []:
            fig += 1
            f["number"] = fig
    ctx["sections"] = entries
    return ctx


def _markup(svg: str | None) -> Any:
    from markupsafe import Markup

    return None if svg is None else Markup(svg)


def render_document(path: str | os.PathLike, *, title: str, spec: Any,
                    sections: Sequence[Section], date: Any = None, command: str | None = None,
                    kind: str = "report", conclusion: str = "") -> Path:
    """Write a generic report (HTML or PDF) from :class:`Section` values.

    The other commands' reports (reconciliation, parameter studies) use this:
    the same title block, page layout, running header and appendix as the
    design report, with their own sections.

    Parameters
    ----------
    path : str or os.PathLike
        ``.html`` or ``.pdf``.
    title : str
        Report title.
    spec : fi_design.spec.Spec
        The spec the work started from.
    sections : sequence of Section
        The content.
    date : str or datetime.date, optional
        Report date (default today).
    command : str, optional
        The command line.
    kind : str, optional
        Short kind of report.
    conclusion : str, optional
        A summary paragraph shown first.

    Returns
    -------
    pathlib.Path
        The written file.

    Raises
    ------
    fi_design.errors.OutputError
        Wrong extension or the file cannot be written.
    """
    out = Path(path)
    fmt = _fmt_format(out)
    ctx = document_context(title, spec, sections, date=date, command=command, kind=kind,
                           conclusion=conclusion)
    return _write(render_html(ctx), out, fmt)


# --------------------------------------------------------------------------- parameter studies


def _axis_text(axis: Any) -> str:
    vals = list(axis.values)
    return (f"{axis.path}: {len(vals)} values from {qty(vals[0], axis.unit)} to "
            f"{qty(vals[-1], axis.unit)}{' (log)' if axis.log else ''}")


def _sweep_section(result: Any, sid: str, title: str, lead: str = "",
                   figures: bool = True) -> Section:
    from . import plots

    counts = result.counts()
    plant = "with isolator" if result.isolated else "without isolator"
    paras = [p for p in (lead,) if p]
    axes = [_axis_text(result.x)] + ([_axis_text(result.y)] if result.y is not None else [])
    paras.append(f"Simulated {plant}; " + "; ".join(axes) + ". Design point: "
                 + ", ".join(qty(v, a.unit) if v is not None else "n/a"
                             for v, a in zip(result.design_point,
                                             [result.x] + ([result.y] if result.y else [])))
                 + ".")
    rows = tuple((k, num(v)) for k, v in counts.items())
    table = Table(("Verdict", "Points"), rows, caption="Points per verdict")
    figs: tuple[FigureBlock, ...] = ()
    if figures:
        import matplotlib

        with matplotlib.rc_context(plots.REPORT_RC):
            fig = plots.sweep_figure(result, title="")
        figs = (figure_block(fig, f"Hunting cycles: {' vs '.join(result.paths[::-1])} "
                                  f"({plant}).", name=sid),)
    return Section(sid, title, paragraphs=tuple(paras), tables=(table,), figures=figs)


def sweep_context(result: Any, *, date: Any = None, command: str | None = None,
                  figures: bool = True) -> dict:
    """The report context of a sweep, a paper study or a robustness study.

    Parameters
    ----------
    result : SweepResult, StudyResult or RobustnessResult
        The study.
    date : str or datetime.date, optional
        Report date.
    command : str, optional
        The command line.
    figures : bool, optional
        Render the figures (default).

    Returns
    -------
    dict
        For :func:`render_html`.
    """
    kind = type(result).__name__
    if kind == "SweepResult":
        sections = [_sweep_section(result, "sweep", "Hunting map", figures=figures)]
        return document_context(TITLES["sweep"], result.spec, sections, date=date,
                                command=command, kind="sweep")
    if kind == "StudyResult":
        sections = [_sweep_section(m.result, f"map-{m.definition.key.lower()}",
                                   f"Map {m.definition.key}: {m.definition.title}",
                                   lead=f"Paper: {m.definition.paper}.", figures=figures)
                    for m in result.maps]
        return document_context(TITLES["study"], result.spec, sections, date=date,
                                command=command, kind="study")
    # robustness
    from . import plots

    rows = []
    for label, p in (("with isolator", result.isolated), ("without isolator",
                                                          result.not_isolated)):
        if p is None:
            continue
        rows.append((label, num(p.hunting), num(p.valid),
                     qty(100 * p.probability, "%") if p.probability is not None else "n/a",
                     f"{num(100 * p.low, 3)} \u2013 {num(100 * p.high, 3)}\u00a0%"))
    table = Table(("Plant", "Hunting", "Valid samples", "Probability", "Confidence interval"),
                  tuple(rows), caption="Probability of hunting under the scatter")
    figs: tuple[FigureBlock, ...] = ()
    if figures:
        import matplotlib

        with matplotlib.rc_context(plots.REPORT_RC):
            fig = plots.robustness_figure(result, title="")
        figs = (figure_block(fig, "Probability of hunting with its confidence interval.",
                             name="robustness", width="half"),)
    sections = [Section("robustness", "Probability of hunting",
                        paragraphs=(f"{result.samples} samples of the spec with its values "
                                    "drawn around the nominal ones.",),
                        tables=(table,), figures=figs)]
    return document_context(TITLES["robustness"], result.spec, sections, date=date,
                            command=command, kind="robustness")
