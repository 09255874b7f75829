"""Reports: filters, the design report's context (golden), HTML structure and escaping, the
PDF (pdftotext), headless Chromium, the CLI's --report and --map, templates in the wheel.

The design of the paper setup is computed once per session (``paper_confirmed_design``);
the artifacts a person looks at (report.html, report.pdf, page images, the Chromium
screenshot) are kept under tests/artifacts/ (gitignored).
"""

from __future__ import annotations

import html.parser
import math
import os
import re
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest
import yaml
from typer.testing import CliRunner

from fi_design import report
from fi_design.errors import OutputError, ReportError
from fi_design.cli.app import app

from conftest import EXAMPLES, ROOT

ARTIFACTS = ROOT / "tests" / "artifacts"
DATE = "2026-01-01"
COMMAND = "fi-design examples/paper_setup.yaml --report report.html"
NNBSP = "\u202f"
NBSP = "\u00a0"

#: Sections of the design report, in the order the issue asks for.
DESIGN_SECTIONS = ["verdict", "inputs", "steps", "guide", "linear", "nonlinear",
                   "validation", "assumptions", "glossary", "references", "settings", "appendix"]

runner = CliRunner()


def _artifacts() -> Path:
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    return ARTIFACTS


# --------------------------------------------------------------------------- filters


@pytest.mark.parametrize("value,expected", [
    (None, "\u2013"), (True, "yes"), (False, "no"), ("text", "text"), (0, "0"), (0.0, "0"),
    (2.0, "2"), (0.3, "0.3"), (47.306, "47.31"), (47.30, "47.3"), (13333.33, "13333"),
    (6667.0, "6667"), (-0.6247, "-0.6247"), (1e6, f"1{NBSP}\u00d7{NBSP}10\u2076"),
    (3.2e-8, f"3.2{NBSP}\u00d7{NBSP}10\u207b\u2078"), (2.5e-4, "0.00025"), (float("inf"), "\u221e"),
    (float("-inf"), "-\u221e"), (float("nan"), "n/a"), (12345, "12345"),
    (150.8, "150.8"), (0.001348, "0.001348"),
])
def test_num(value, expected):
    assert report.num(value) == expected


def test_num_digits():
    assert report.num(math.pi, 3) == "3.14"
    assert report.num(123456.7, 3) == "123457"


@pytest.mark.parametrize("value,unit,expected", [
    (3e-4, "m", f"0.3{NBSP}mm"), (1e-5, "m", f"10{NBSP}\u00b5m"), (-2.78e-4, "m", f"-0.278{NBSP}mm"),
    (1.4e-12, "m", f"< 0.001{NBSP}\u00b5m"), (3e-3, "m/s", f"3{NBSP}mm/s"),
    (2e11, "Pa", f"200{NBSP}GPa"), (3.155e7, "Pa", f"31.55{NBSP}MPa"),
    (47.31, "deg", "47.31\u00b0"), (6.0, "dB", f"6{NBSP}dB"), (5, "cycles", f"5{NBSP}cycles"),
    (20.0, "N*s/m", f"20{NBSP}N\u00b7s/m"), (1.0, "m/s**2", f"1{NBSP}m/s\u00b2"),
    (7800.0, "kg/m**3", f"7800{NBSP}kg/m\u00b3"), (0.02, "1", "0.02"), (None, "Hz", "\u2013"),
    ("lugre", "", "lugre"), ([0.01, 0.06], "m", f"10 \u2013 60{NBSP}mm"),
    ([1.0, 30.0], "Hz", f"1 \u2013 30{NBSP}Hz"), ((), "m", "\u2013"),
])
def test_qty(value, unit, expected):
    assert report.qty(value, unit) == expected


@pytest.mark.parametrize("unit,expected", [
    ("N*s/m", "N\u00b7s/m"), ("m/s**2", "m/s\u00b2"), ("kg/m**3", "kg/m\u00b3"), ("1", ""),
    ("-", ""), ("Hz", "Hz"), ("deg", "\u00b0"), ("N/(m s)", "N/(m\u00b7s)"), (None, ""),
])
def test_unit_text(unit, expected):
    assert report.unit_text(unit) == expected


def test_display_scale_shares_a_unit_between_value_and_limit():
    row = report.check_row(_check("flexure.stress", 3.155e7, 3e8, "Pa"))
    assert row["unit"] == "MPa"
    assert row["value"] == pytest.approx(31.55) and row["limit"] == pytest.approx(300.0)
    assert row["sense"] == "\u2264" and row["status"] == "PASS" and row["css"] == "pass"
    assert row["label"] == "Flexure stress at full stroke"


def _check(name, value, limit, unit, passed=True):
    from fi_design.results import Check

    return Check(name, passed, value, limit, unit, "msg", step="step 3 flexure")


def test_check_labels_name_the_limit_case(paper_confirmed_design):
    cases = {c.name: c for c in paper_confirmed_design.loop.cases}
    assert report.check_label("phase_margin.stuck_free", cases) == \
        "Phase margin, case 2 (cart stuck, joint free)"
    assert report.check_label("phase_margin.stuck_free") == "Phase margin, stuck_free"
    assert report.check_label("parasitic_separation.tilt").startswith("Parasitic mode \u2018tilt")
    assert report.check_label("some_new_check") == "Some new check"


def test_tex_quantities():
    assert report.tex_num(13333.3) == "13333"
    assert report.tex_num(2e11) == "2 \\times 10^{11}"
    assert report.tex_qty(3e-4, "m") == "0.3\\ \\mathrm{mm}"
    assert report.tex_qty(100.5, "N s/m") == "100.5\\ \\mathrm{N\\cdot s/m}"
    assert report.tex_qty(47.3, "deg") == "47.3^\\circ"


def test_math_text_is_readable():
    assert report.math_text(r"\Delta F = F_s - F_c") == "\u0394F = F_s - F_c"
    assert report.math_text(r"k = \frac{F_s}{s}") == "k = (F_s)/(s)"
    assert report.math_text(r"k_\max = \frac{F_s}{\gamma\, s} = 13\,333\ \mathrm{N/m}") == \
        "k_max = (F_s)/(\u03b3 s) = 13 333 N/m"
    assert report.math_text(r"(0.4\ \mathrm{mm})^3 \leq \omega_c^2") == "(0.4 mm)^3 \u2264 \u03c9_c^2"
    assert report.math_text(r"f_{c,\mathrm{ach}} = k \min(|d|, s)") == "f_c,ach = k min(|d|, s)"
    assert report.math_text(r"10^{-8} - x") == "10^-8 - x"


def test_equations_are_mathtext_svg():
    from fi_design.report.equations import equation

    import matplotlib
    from matplotlib.font_manager import FontProperties
    from matplotlib.textpath import TextPath

    from fi_design.cachedir import cache_dir
    from fi_design.report.equations import EQUATION_RC, EQUATION_SIZE

    tex = r"k_\max = \frac{F_s}{\gamma\, s}"
    eq = equation(tex, "eq-9")
    svg = str(eq["svg"])
    assert svg.startswith("<svg") and "<path" in svg and "<text" not in svg  # glyph outlines
    assert not re.findall(r'\sid="', svg)  # nothing for two equations on one page to clash on
    width, height = (float(v) for v in re.search(r'width="([\d.]+)pt" height="([\d.]+)pt"',
                                                   svg).groups())
    assert 40 < width < 300 and 15 < height < 60   # one line with a display fraction
    # the picture is mathtext's outline of the formula (display fractions) plus the margin
    with matplotlib.rc_context(EQUATION_RC):
        box = TextPath((0, 0), "$" + tex.replace("\\frac", "\\dfrac") + "$",
                       prop=FontProperties(size=EQUATION_SIZE)).get_extents()
    assert width == pytest.approx(box.width + 2.0, abs=0.01)
    assert height == pytest.approx(box.height + 2.0, abs=0.01)
    assert eq["text"] == "k_max = (F_s)/(\u03b3 s)"
    assert equation("x", "eq-1", render=False)["svg"] is None
    # drawn once, then read from the cache: the same element
    cached = list(cache_dir("equations").glob("*.svg"))
    assert cached and str(equation(tex, "eq-10")["svg"]) == svg


def test_report_date(monkeypatch):
    import datetime as dt

    assert report.report_date("2026-01-01") == "2026-01-01"
    assert report.report_date(dt.date(2025, 3, 4)) == "2025-03-04"
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "0")
    assert report.report_date() == "1970-01-01"


# --------------------------------------------------------------------------- templates


ALLOWED_TAGS = {"extends", "block", "endblock", "for", "endfor", "if", "else", "endif"}
OPERATORS = re.compile(r"==|!=|<=|>=|<|>|\+|(?<![\w.])-|\*|/|%|\band\b|\bor\b|\bnot\b|~")


def _templates():
    return sorted(report.template_dir().glob("*.jinja"))


def test_templates_found_in_the_source_tree():
    assert report.template_dir() == ROOT / "templates"
    names = {p.name for p in _templates()}
    shared = {"settings": "inputs"}  # the analysis settings are drawn as the inputs' table
    for section in DESIGN_SECTIONS + ["map", "generic", "section", "report"]:
        assert f"{shared.get(section, section)}.html.jinja" in names


@pytest.mark.parametrize("path", _templates(), ids=lambda p: p.name)
def test_templates_are_logic_free(path):
    text = path.read_text(encoding="utf-8")
    tags = set(re.findall(r"{%-?\s*(\w+)", text))
    assert tags <= ALLOWED_TAGS, f"{path.name}: {sorted(tags - ALLOWED_TAGS)}"
    if path.name not in ("section.html.jinja", "report.html.jinja"):
        assert text.lstrip().startswith('{% extends "section.html.jinja" %}'), path.name
    exprs = re.findall(r"{{(.*?)}}", text) + re.findall(r"{%-?\s*(?:if|for)\s(.*?)%}", text)
    for expr in exprs:
        bare = re.sub(r"\"[^\"]*\"|'[^']*'", "", expr)
        bare = re.sub(r"^\s*\w+\s+in\s+", "", bare)  # the `x in xs` of a for loop
        filters = re.findall(r"\|\s*(\w+)", bare)
        assert set(filters) <= set(report.filters.FILTERS), f"{path.name}: {expr}"
        assert not OPERATORS.search(bare.replace("|", " ")), f"{path.name}: {{{{{expr}}}}}"


def test_filters_are_registered_in_the_environment():
    env = report.environment()
    assert env.filters["num"] is report.num and env.filters["qty"] is report.qty
    assert env.filters["unit"] is report.unit_text
    assert env.filters["rows"] is report.filters.wrapped_lines
    assert env.from_string("{{ x|qty('m') }}").render(x=3e-4) == f"0.3{NBSP}mm"


def test_environment_escapes_and_is_strict():
    import jinja2

    env = report.environment()
    assert env.undefined is jinja2.StrictUndefined
    tmpl = env.from_string("{{ x }}")
    assert tmpl.render(x="<b>&") == "&lt;b&gt;&amp;"
    with pytest.raises(jinja2.UndefinedError):
        tmpl.render()
    assert env.get_template("section.html.jinja").render(
        section={"id": "a", "number": 1, "title": "<i>"}).count("&lt;i&gt;") == 1


# --------------------------------------------------------------------------- golden context


def _for_golden(obj, key=None):
    """Drop rendered markup and machine-dependent parts; round floats to 4 significant digits."""
    if isinstance(obj, dict):
        return {k: _for_golden(v, k) for k, v in obj.items()
                if k not in ("html", "svg", "versions")}
    if isinstance(obj, (list, tuple)):
        return [_for_golden(v) for v in obj]
    if isinstance(obj, float):
        if not math.isfinite(obj):
            return str(obj)
        if abs(obj) < 1e-10:
            return 0.0
        return float(f"{obj:.4g}")
    return obj


def test_design_context_golden(paper_confirmed_design, data_regression):
    ctx = report.build_context(paper_confirmed_design, date=DATE, command=COMMAND,
                               figures=False)
    ctx["meta"]["spec_path"] = Path(ctx["meta"]["spec_path"]).name
    ctx["meta"]["tool"] = "fi-design VERSION"  # the code's provenance: test_document_control
    ctx["meta"]["tool_footer"] = "fi-design VERSION, SOURCE"
    ctx["meta"]["tool_source"] = "SOURCE"
    ctx["meta"]["code_sha256"] = "CODE-SHA256"
    for row in ctx["appendix"]["solver"]:  # solver statistics: not the report's findings
        if row["quantity"].startswith("steps / rejected / events"):
            row["value"] = "steps / rejected / events"
    assert [s["id"] for s in ctx["sections"]] == DESIGN_SECTIONS
    data_regression.check(_for_golden(ctx))


def test_context_numbers(paper_confirmed_design):
    ctx = report.build_context(paper_confirmed_design, date=DATE, command=COMMAND,
                               figures=False)
    rows = {r["name"]: r for g in ctx["verdict"]["groups"] for r in g["rows"]}
    assert rows["drive_stiffness"]["value"] == pytest.approx(6667.0)
    assert rows["drive_stiffness"]["limit"] == pytest.approx(4.0 / 0.3e-3)
    assert rows["friction_gap"]["status"] == "INFO"   # the isolator answers the risk
    assert len(rows) == len(paper_confirmed_design.checks)
    # its own move settles at 8 Hz, but 7 other moves of its family end in a 1.8 mm cycle
    assert ctx["verdict"]["overall"] == "FAIL" and ctx["verdict"]["behaviour"] == "hunts"
    stage = {r["plant"]: r for r in ctx["nonlinear"]["stage"]}
    iso = stage["with isolator (as specified)"]
    assert iso["outcome"] == "hunts" and iso["moves"] == "7 of 25"
    assert iso["entered"] == "0.396 to 50 mm" and iso["limiter"] == "yes"
    assert iso["free_from"] == pytest.approx(11.28, abs=0.02)
    inputs = {r["path"]: r for g in ctx["inputs"]["groups"] for r in g["rows"]}
    settings = {r["path"]: r for g in ctx["settings"]["groups"] for r in g["rows"]}
    assert "simulation.tolerance" in settings and "simulation.tolerance" not in inputs
    assert "requirements.hunting.horizon" in settings and "requirements.phase_margin" in inputs
    assert inputs["friction.static"]["source"] == "given"
    assert inputs["friction.static"]["written"] == "4 N"
    assert inputs["isolator.limiter.stiffness"]["source"] == "default"
    assert inputs["isolator.limiter.damping"]["source"].startswith("derived default")
    assert inputs["isolator.limiter.damping"]["value"] == pytest.approx(
        2 * 0.2 * math.sqrt(1e6 * 1.6))
    assert [s["number"] for s in ctx["steps"]] == [1, 2, 3, 4]
    assert all(s["equations"] for s in ctx["steps"])


# --------------------------------------------------------------------------- HTML


class _Tags(html.parser.HTMLParser):
    """Collects tags with attributes, section ids and text."""

    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.tags: list[tuple[str, dict]] = []
        self.text: list[str] = []

    def handle_starttag(self, tag, attrs):
        self.tags.append((tag, dict(attrs)))

    def handle_startendtag(self, tag, attrs):
        self.tags.append((tag, dict(attrs)))

    def handle_data(self, data):
        self.text.append(data)


def _parse(text: str) -> _Tags:
    p = _Tags()
    p.feed(text)
    p.close()
    return p


@pytest.fixture(scope="module")
def design_html(paper_confirmed_design) -> str:
    ctx = report.build_context(paper_confirmed_design, date=DATE, command=COMMAND)
    text = report.render_html(ctx)
    (_artifacts() / "report.html").write_text(text, encoding="utf-8")
    return text


def test_html_has_every_section_in_order(design_html):
    p = _parse(design_html)
    ids = [a["id"] for t, a in p.tags if t == "section"]
    assert ids == DESIGN_SECTIONS
    toc = [a["href"] for t, a in p.tags if t == "a"]
    assert toc[:len(ids)] == [f"#{i}" for i in ids]
    text = " ".join(p.text)
    for words in ("Friction isolator design report", "Prepared", "Checked", "Approved",
                  "Spec SHA-256", COMMAND, DATE, "Canudas de Wit", "Hensen", "Hairer",
                  "Okwudire", "RODAS4"):
        assert words in text, words


def test_html_is_self_contained(design_html):
    p = _parse(design_html)
    assert not any(t == "script" for t, _ in p.tags)
    assert not any(t in ("link", "img", "iframe", "object", "embed") for t, _ in p.tags)
    for tag, attrs in p.tags:
        for name, value in attrs.items():
            if name in ("href", "src", "xlink:href", "action", "data"):
                assert value is None or value.startswith("#"), (tag, name, value)
            if name.startswith("on"):
                pytest.fail(f"event handler {name} on <{tag}>")
            if name not in ("xmlns", "xmlns:xlink") and value:
                assert not re.search(r"https?://", value), (tag, name, value)
    styles = re.findall(r"<style>(.*?)</style>", design_html, flags=re.S)
    assert styles and not any(re.search(r"url\(\s*['\"]?(?!#)", s) for s in styles)
    assert "@import" not in design_html


def test_html_figures_and_equations_inline(design_html):
    p = _parse(design_html)
    figures = [a["id"] for t, a in p.tags if t == "figure"]
    assert figures == ["fig-guide", "fig-bode", "fig-nyquist", "fig-sensitivity", "fig-moves",
                       "fig-cycle", "fig-boundary", "fig-error", "fig-deflection"]
    svgs = re.findall(r"<figure[^>]*>\s*<svg", design_html)
    assert len(svgs) == len(figures)
    ids = re.findall(r'\sid="([^"]+)"', design_html)
    assert len(ids) == len(set(ids)), "duplicate ids across the inline figures"
    equations = re.findall(r'<div class="eq" role="math" aria-label="[^"]+"><svg', design_html)
    assert len(equations) >= 12


def test_figures_are_numbered_in_the_order_they_appear(design_html):
    """The stage-level boundary (Figure 8) stood before Figures 6 and 7: the numbers follow
    the page."""
    numbers = [int(n) for n in re.findall(r'class="fignum">Figure (\d+)\.', design_html)]
    assert len(numbers) >= 8
    assert numbers == list(range(1, len(numbers) + 1)), numbers


def test_html_is_reproducible(paper_confirmed_design, design_html):
    again = report.render_html(report.build_context(paper_confirmed_design, date="2027-12-31",
                                                    command=COMMAND))
    assert again.replace("2027-12-31", DATE) == design_html


@pytest.fixture(scope="module")
def hostile_design():
    raw = yaml.safe_load((EXAMPLES / "paper_setup.yaml").read_text(encoding="utf-8"))
    raw["name"] = "<script>alert('x')</script> & \"Co\""
    raw["report"] = {"document_id": "<b>FI-9</b>", "revision": "B&C", "status": "for review",
                     "author": "<img src=x onerror=alert(1)>"}
    from fi_design.guideline.evaluate import evaluate as design

    return design(raw, confirm=False)


def test_user_text_is_escaped(hostile_design):
    text = report.render_html(report.build_context(hostile_design, date=DATE, command="x",
                                                   figures=False))
    p = _parse(text)
    assert not any(t in ("script", "img", "b") for t, _ in p.tags)
    assert "&lt;script&gt;alert(&#39;x&#39;)&lt;/script&gt; &amp; &#34;Co&#34;" in text
    assert "&lt;b&gt;FI-9&lt;/b&gt;" in text and "B&amp;C" in text
    assert "<script" not in text and "onerror=alert" not in text.replace("onerror=alert(1)&gt;",
                                                                         "")
    assert "not run" in " ".join(p.text)  # no simulation: the section says so
    assert "FOR REVIEW" not in text and "for review" in text


# --------------------------------------------------------------------------- PDF


needs_poppler = pytest.mark.skipif(shutil.which("pdftotext") is None,
                                   reason="poppler-utils (pdftotext) is not installed")


def _import_weasyprint():
    """WeasyPrint's module, imported as the report imports it (its library search skipped)."""
    from fi_design.report.render import _import_weasyprint

    _import_weasyprint()
    import weasyprint

    return weasyprint


@pytest.fixture(scope="module")
def design_pdf_written(paper_confirmed_design):
    """The design report's PDF drawn in one process, watched as it is written: (the PDF,
    WeasyPrint's layout of it (the document whose pages went into the file), the page as
    laid out (its figures placed by name), the figures in the order the report places them,
    each as drawn here). The tests of the PDF read this one file, layout and set of figures
    rather than lay the report out or draw its figures again."""
    from fi_design.report import render

    weasyprint = _import_weasyprint()
    written, pages, drawn, placed = [], [], {}, []
    real_write, real_document, real_png = (weasyprint.Document.write_pdf,
                                           render.write_document, render._Figures.png)

    def write_pdf(self, *args, **kwargs):
        written.append(self)
        return real_write(self, *args, **kwargs)

    def write_document(html, *args, **kwargs):
        pages.append(html)
        return real_document(html, *args, **kwargs)

    def png(self, name):
        drawn[name] = real_png(self, name)
        placed[:] = self._placed.makers
        return drawn[name]

    out = _artifacts() / "report.pdf"
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(weasyprint.Document, "write_pdf", write_pdf)
        patch.setattr(render, "write_document", write_document)
        patch.setattr(render._Figures, "png", png)
        report.render_report(paper_confirmed_design, out, date=DATE, command=COMMAND,
                             force=True)  # the artifact of an earlier run replaced
    assert written and len(pages) == 1, "no PDF was written"
    assert sorted(drawn) == sorted(placed), "a figure placed but not drawn, or drawn twice"
    return out, written[-1], pages[0], {name: drawn[name] for name in placed}


@pytest.fixture(scope="module")
def design_pdf(design_pdf_written) -> Path:
    return design_pdf_written[0]


@needs_poppler
def test_pdf_opens_with_page_numbers_and_key_numbers(design_pdf):
    info = subprocess.run(["pdfinfo", str(design_pdf)], capture_output=True, text=True,
                          timeout=60)
    assert info.returncode == 0, info.stderr
    pages = int(re.search(r"Pages:\s+(\d+)", info.stdout).group(1))
    assert pages >= 8
    assert re.search(r"Page size:\s+595\.\d* x 841\.\d*", info.stdout), "not A4"
    out = subprocess.run(["pdftotext", "-layout", str(design_pdf), "-"], capture_output=True,
                         text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    text = out.stdout.replace(NNBSP, " ").replace(NBSP, " ")
    for n in range(1, pages + 1):
        assert f"Page {n} of {pages}" in text
    assert text.count("FI-0001 rev. A (draft)") >= pages  # the running header
    for number in ("13333", "6667", "11.82", "2134", "8467", "86.38", "11.28 Hz", "24.54 Hz",
                   "FAIL", "HUNTS", "Conclusion", "k_max", DATE):
        assert number in text, number
    if shutil.which("pdftoppm"):
        subprocess.run(["pdftoppm", "-r", "50", "-png", str(design_pdf),
                        str(_artifacts() / "report-page")], check=True, timeout=120)


@needs_poppler
def test_pdf_contents_give_each_section_s_page(design_pdf):
    """The PDF's contents listed the twelve sections without a page number (26 pages, no
    reader of the paper can follow a link): each entry now ends with the page its section's
    heading stands on."""
    text = subprocess.run(["pdftotext", "-layout", str(design_pdf), "-"], capture_output=True,
                          text=True, check=True, timeout=120).stdout
    pages = [[re.sub(r"\s+", " ", line.strip()) for line in page.splitlines() if line.strip()]
             for page in text.replace(NNBSP, " ").replace(NBSP, " ").split("\f")]
    entries = [re.fullmatch(r"(\d+)\. (.+?)[ .]*?\s(\d+)", line)
               for line in pages[0][pages[0].index("Contents") + 1:]]
    listed = [(m.group(1), m.group(2).rstrip(" ."), int(m.group(3))) for m in entries if m]
    assert len(listed) >= 10, pages[0]
    for number, title, page in listed:
        heading = f"{number} {title}"
        assert heading in pages[page - 1], (heading, page)
        assert not any(heading in lines for lines in pages[:page - 1]), (heading, page)


def _page_leaves(box, in_heading=False):
    """(box, inside a heading) for every leaf box of a laid-out page, in document order."""
    tag = getattr(box, "element_tag", None)
    here = in_heading or tag in ("h2", "h3")
    children = getattr(box, "children", None)
    if not children:
        yield box, here
        return
    for child in children:
        yield from _page_leaves(child, here)


def test_pdf_never_ends_a_page_with_a_heading(design_pdf_written):
    """A heading stays with the first lines of what it heads (report.css), on every page.

    Read from WeasyPrint's own layout of the report, the one written to the PDF
    (:func:`design_pdf_written`): the last thing laid out on a page (text, a figure, an
    equation) is never part of a section heading.
    """
    from weasyprint.formatting_structure.boxes import MarginBox

    _, document, _, _ = design_pdf_written
    assert len(document.pages) >= 8
    headings = 0
    for n, page in enumerate(document.pages, 1):
        leaves = [leaf for child in page._page_box.children
                  if not isinstance(child, MarginBox) for leaf in _page_leaves(child)]
        headings += sum(1 for _, h in leaves if h)
        content = [(b, h) for b, h in leaves if getattr(b, "text", None) is None
                   or b.text.strip()]
        assert content, f"page {n} is empty"
        box, in_heading = content[-1]
        assert not in_heading, f"page {n} ends with a heading ({getattr(box, 'text', box)!r})"
    assert headings > 15


@needs_poppler
@pytest.mark.parametrize("options", [0, 2])
def test_pdf_keeps_a_heading_with_its_first_lines_after_a_long_command(
        paper_confirmed_design, design_pdf, tmp_path, options):
    """A long command line in the title block moves the contents down page 1; whatever it
    pushes over the page's end, no page of the PDF (pdftotext, page by page) ends with a
    heading, and "1 Verdict" stands on the page of the verdict's status (with one option
    more than COMMAND, "1 Verdict" stood alone at the foot of page 1, its box on page 2).

    With two options more, a PDF of the report without its figures is written and read page
    by page. With COMMAND itself the report's own PDF (:func:`design_pdf`) is read for the
    page of "1 Verdict"; its page ends are read from WeasyPrint's layout of it in
    test_pdf_never_ends_a_page_with_a_heading (pdftotext sees no equation or figure, and
    an equation below a heading leaves the heading the last text of its page)."""
    command = COMMAND + " --sweep-point friction.static=3N" * options
    html = report.render_html(report.build_context(paper_confirmed_design, date=DATE,
                                                   command=command, figures=False))
    headings = {re.sub(r"\s+", " ", re.sub(r"<[^>]+>", " ", h)).strip()
                for h in re.findall(r"<h[23][^>]*>(.*?)</h[23]>", html, re.S)}
    assert "1 Verdict" in headings
    pdf = design_pdf if not options else report.write_document(html, tmp_path / "long.pdf")
    text = subprocess.run(["pdftotext", "-layout", str(pdf), "-"], capture_output=True,
                          text=True, check=True, timeout=120).stdout
    pages = [[re.sub(r"\s+", " ", line.strip()) for line in page.splitlines() if line.strip()]
             for page in text.split("\f") if page.strip()]
    for n, lines in enumerate(pages if options else (), 1):
        body = lines[1:-1]  # without the running head and the footer
        assert body and body[-1] not in headings, f"page {n} ends with {body[-1:]}"
    page = next(lines for lines in pages if "1 Verdict" in lines)
    after = page[page.index("1 Verdict") + 1:]
    assert after and after[0].split()[:2] == ["FAIL", "HUNTS"], page[-4:]



def _laid_out(document):
    """(page index, box) of every box of WeasyPrint's layout, page by page."""
    for n, page in enumerate(document.pages):
        stack = [page._page_box]
        while stack:
            box = stack.pop()
            yield n, box
            stack.extend(getattr(box, "children", None) or ())


def _classes(element) -> list[str]:
    return (element.get("class") or "").split()


#: The page-end cases: the section, where the page is made to end (half-way down a row of
#: a table), and the HTML a spacer goes before to move that row there.
_PAGE_ENDS = {"key figures": ("verdict", "figures", -1, "<h3>Key figures</h3>"),
              "inputs": ("inputs", "inputs", 0, '<section id="inputs"')}


@pytest.mark.parametrize("case", list(_PAGE_ENDS))
def test_pdf_keeps_small_tables_whole_and_headings_with_their_first_rows(
        paper_confirmed_design, case):
    """The reviewer's PDF of the paper setup left the key-figures table's last row and its
    footnote alone on page 3, and the heading, intro and table header of "2 Inputs" at the
    foot of page 5 with the table's rows on page 6. Where a page ends depends on fonts and
    on everything above; here the page is made to end there: the section alone is laid out
    (WeasyPrint, no figures) with a spacer above it, sized from a first layout so that the
    page ends half-way down the key figures' last row, or the inputs' first row. The key
    figures then stand on one page with their heading and notes, and "Inputs" with its intro
    on the page of its table's first row."""
    weasyprint = _import_weasyprint()
    section, table_class, index, before = _PAGE_ENDS[case]
    context = report.build_context(paper_confirmed_design, date=DATE, command=COMMAND,
                                   figures=False)
    context["sections"] = [s for s in context["sections"] if s["id"] == section]
    html = report.render_html(context)
    assert html.count(before) == 1

    def laid_out(spacer):
        page = html.replace(before, f'<div style="height: {spacer:.3f}px"></div>{before}')
        document = weasyprint.HTML(string=page).render()
        boxes = list(_laid_out(document))
        table = next(b.element for _, b in boxes if b.element_tag == "table" and
                     table_class in _classes(b.element))
        rows = {id(r) for r in table.iter("tr") if r.find("td") is not None}
        on = {}  # element -> the pages it has a box on
        for n, b in boxes:
            if getattr(b, "element", None) is not None:
                on.setdefault(id(b.element), set()).add(n)
        placed = sorted(((n, b) for n, b in boxes if b.element_tag == "tr" and
                         id(b.element) in rows), key=lambda nb: (nb[0], nb[1].position_y))
        return document, boxes, placed, on

    document, _, placed, _ = laid_out(1)
    n, row = placed[index]
    page = document.pages[n]._page_box
    end = page.content_box_y() + page.height
    _, boxes, placed, on = laid_out(1 + end - row.position_y - row.height / 2)

    def pages(tag, pick=lambda e: True):
        found = [id(b.element) for _, b in boxes if b.element_tag == tag and pick(b.element)]
        assert found, tag
        return set().union(*(on[e] for e in found))

    rows = {n for n, _ in placed}
    if case == "key figures":
        assert len(rows) == 1, f"the key figures run over pages {sorted(rows)}"
        assert pages("h3", lambda e: "".join(e.itertext()) == "Key figures") == rows
        assert pages("ul", lambda e: "margin-notes" in _classes(e)) == rows
    else:
        first = placed[0][0]
        intro = context["inputs"]["intro"]
        assert pages("h2", lambda e: "".join(e.itertext()).endswith("Inputs")) == {first}, \
            "the Inputs heading stands apart from its table's first row"
        assert pages("p", lambda e: "".join(e.itertext()) == intro) == {first}


@needs_poppler
def test_pdf_key_figures_and_inputs_start_on_the_page_of_their_heading(
        paper_confirmed_design, design_pdf):
    """The report's own PDF (:func:`design_pdf`), page by page (pdftotext): the key figures,
    their last row and notes on the page of their heading, the Inputs heading on the page
    of its table's first row."""
    text = subprocess.run(["pdftotext", "-layout", str(design_pdf), "-"], capture_output=True,
                          text=True, check=True, timeout=120).stdout
    pages = [re.sub(r"\s+", " ", page.replace(NNBSP, " ").replace(NBSP, " "))
             for page in text.split("\f")]
    verdict = report.build_context(paper_confirmed_design, date=DATE, command=COMMAND,
                                   figures=False)["verdict"]

    def page_of(words):
        found = [n for n, page in enumerate(pages) if words in page]
        assert found, words
        return found[0]

    heading = page_of(" Key figures ")
    for words in ("Figure Value Unit Requirement Basis",
                  " ".join(verdict["figures"][-1]["label"].split()[:3]),
                  " ".join(verdict["notes"][-1].split()[:4])):
        assert page_of(words) == heading, words
    assert page_of(" 2 Inputs ") == page_of("Key Value As written Source") == \
        page_of("Project or stage name")


def _pdf_images(pdf: Path) -> list[tuple[str, ...]]:
    """(page, width, height, colour, x-ppi) of every image of a PDF, from poppler's pdfimages."""
    out = subprocess.run(["pdfimages", "-list", str(pdf)], capture_output=True, text=True,
                         check=True, timeout=60).stdout.splitlines()[2:]
    return [(f[0], f[3], f[4], f[5], f[12]) for f in (line.split() for line in out)]


@pytest.fixture(scope="module")
def fork_pool():
    """One forked worker, as the command line's report pool (fi_design.cli.pools)."""
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    if "fork" not in multiprocessing.get_all_start_methods():
        pytest.skip("no fork start method")
    with ProcessPoolExecutor(1, mp_context=multiprocessing.get_context("fork")) as pool:
        yield pool


@pytest.fixture(scope="module")
def figures_drawn_here(design_pdf_written):
    """The PDF report's page with its figures placed by name, and each figure as this
    process drew it for :func:`design_pdf`: (html, name -> PNG bytes in the order the
    report places them)."""
    _, _, html, drawn = design_pdf_written
    return html, drawn


def test_pdf_figures_drawn_by_a_worker_are_the_ones_drawn_here(paper_confirmed_design,
                                                                figures_drawn_here,
                                                                fork_pool):
    """A PDF's figures are placed by name and drawn apart (render_report with an executor):
    the worker's figures are those this process places, in the same order, byte for byte."""
    html, here = figures_drawn_here
    names = list(here)
    assert len(names) >= 8 and len(set(names)) == len(names)
    for name in names:  # placed by name, not drawn into the page
        assert f'<img src="figure:{name}"' in html
    assert "data:image/png" in html  # the equations stay inline images
    drawn = fork_pool.submit(report.report_figures, paper_confirmed_design, {}).result()
    assert list(drawn) == names
    for name in names:
        assert drawn[name] == here[name], name
        assert drawn[name].startswith(b"\x89PNG")


@pytest.fixture(scope="module")
def pdf_drawn_by_workers(paper_confirmed_design, tmp_path_factory):
    """The design report's PDF written with its figures drawn by a pool of two forked
    workers (a library caller's pool: each figure's task may land on a worker that did not
    make the report's figures; the command line's report pool is one such worker), watched:
    (the PDF, the figures the PDF asked for with whether it was writing the file by then,
    what fi_design.report.render logged). One PDF for the tests below, which read it."""
    import logging
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    from fi_design.report import render

    if "fork" not in multiprocessing.get_all_start_methods():
        pytest.skip("no fork start method")
    weasyprint = _import_weasyprint()
    asked, writing = [], [False]
    real_png, real_write = render._Figures.png, weasyprint.Document.write_pdf

    def png(self, name):
        asked.append((name, writing[0]))
        return real_png(self, name)

    def write_pdf(self, *args, **kwargs):
        writing[0] = True
        return real_write(self, *args, **kwargs)

    class Logged(logging.Handler):
        def __init__(self):
            super().__init__(logging.INFO)
            self.messages = []

        def emit(self, record):
            self.messages.append(record.getMessage())

    logged, logger = Logged(), logging.getLogger("fi_design.report.render")
    level = logger.level
    logger.addHandler(logged)
    logger.setLevel(logging.INFO)
    try:
        with pytest.MonkeyPatch.context() as patch, \
                ProcessPoolExecutor(2, mp_context=multiprocessing.get_context("fork")) as pool:
            patch.setattr(render._Figures, "png", png)
            patch.setattr(weasyprint.Document, "write_pdf", write_pdf)
            out = report.render_report(paper_confirmed_design,
                                       tmp_path_factory.mktemp("apart") / "apart.pdf",
                                       date=DATE, command=COMMAND, executor=pool)
    finally:
        logger.removeHandler(logged)
        logger.setLevel(level)
    return out, asked, logged.messages


@pytest.mark.skipif(shutil.which("pdfimages") is None, reason="poppler-utils is not installed")
def test_pdf_is_the_same_with_its_figures_drawn_by_a_worker(pdf_drawn_by_workers, design_pdf):
    """The PDF written with the figures drawn by workers holds the images of the one drawn
    in one process (every figure and equation, at 200 dpi, RGB, on the same pages) and the
    same text."""
    apart, _, _ = pdf_drawn_by_workers
    images = _pdf_images(apart)
    assert images == _pdf_images(design_pdf)
    assert len(images) >= 20 and {i[3] for i in images} == {"rgb"}
    text = [subprocess.run(["pdftotext", "-layout", str(p), "-"], capture_output=True,
                           text=True, check=True, timeout=60).stdout for p in (apart, design_pdf)]
    assert text[0] == text[1]


def test_pdf_figures_drawn_by_a_pool_of_two_workers(pdf_drawn_by_workers, figures_drawn_here):
    """A library caller's pool of several workers: each figure's task may land on a worker
    that did not make the report's figures; every one is drawn there (none falls back to
    this process, which would log it), and each is asked for once (the images are those of
    the PDF drawn in one process: test_pdf_is_the_same_with_its_figures_drawn_by_a_worker)."""
    _, asked, logged = pdf_drawn_by_workers
    assert not [m for m in logged if "could not" in m], logged
    assert sorted(n for n, _ in asked) == sorted(figures_drawn_here[1])


def test_a_figure_stand_in_is_an_rgb_png_of_its_size_that_names_it():
    import io

    import numpy as np
    from PIL import Image

    from fi_design.report.render import _STAND_IN_KEY, _rgb_png_rows, _stand_in

    with Image.open(io.BytesIO(_stand_in("bode", 37, 11))) as image:
        assert image.format == "PNG" and image.mode == "RGB" and image.size == (37, 11)
        assert image.info[_STAND_IN_KEY] == "bode"
        assert _rgb_png_rows(image) is not None
        assert (np.asarray(image) == 255).all()


@pytest.mark.skipif(shutil.which("pdfimages") is None, reason="poppler-utils is not installed")
def test_pdf_laid_out_with_stand_ins_holds_the_figures_drawn_by_the_worker(
        pdf_drawn_by_workers, figures_drawn_here, tmp_path):
    """With a worker, WeasyPrint lays the page out with a stand-in of each figure's size (it
    asks for every image while it builds the page's boxes, long before the worker has drawn
    them all) and takes the figures themselves when it writes the PDF: every figure is in
    the PDF with its own pixels (as drawn here), no stand-in is left, and the layout asked
    for no figure before the output."""
    import io

    import numpy as np
    from PIL import Image

    out, asked, _ = pdf_drawn_by_workers
    _, here = figures_drawn_here
    assert sorted(n for n, _ in asked) == sorted(here)
    assert all(during_output for _, during_output in asked)  # none while laying out
    subprocess.run(["pdfimages", "-png", str(out), str(tmp_path / "img")], check=True,
                   timeout=120)
    got = [_pixels(p) for p in sorted(tmp_path.glob("img-*.png"))]
    for name, png in here.items():
        with Image.open(io.BytesIO(png)) as image:
            want = np.asarray(image.convert("RGB"))
        assert any(g.shape == want.shape and (g == want).all() for g in got), name
    assert not any(g.size > 100_000 and (g == 255).all() for g in got)  # no white stand-in


class _Here:
    """An executor that runs each task at once, here."""

    def submit(self, fn, *args, **kwargs):
        from concurrent.futures import Future

        future = Future()
        try:
            future.set_result(fn(*args, **kwargs))
        except Exception as exc:  # noqa: BLE001 (a future carries any error, as a pool's)
            future.set_exception(exc)
        return future


@pytest.fixture(scope="module")
def unconfirmed_design(paper_spec):
    """The paper setup designed without its simulation (``confirm=False``): a design report
    of fewer pages and figures (the guide, Bode, Nyquist and sensitivity plots), for the tests
    of how a PDF's figures are drawn and placed rather than of what the report says."""
    from fi_design.guideline.evaluate import evaluate as design

    return design(paper_spec, confirm=False)


def test_a_figure_drawn_at_another_size_than_laid_out_fails_and_writes_no_pdf(
        unconfirmed_design, tmp_path, monkeypatch):
    """The layout took the figure's size from the worker; a figure drawn at another size
    (a bug) fails loudly when the PDF is written, and no file is left. (The report of the
    linear steps: the same figures drawn apart as the confirmed design's, in fewer pages.)"""
    import io

    from PIL import Image

    from fi_design.report import render

    real = render.report_figures

    def resized(*args, **kwargs):
        drawn = real(*args, **kwargs)
        if "bode" in drawn:
            buf = io.BytesIO()
            Image.new("RGB", (50, 40), "white").save(buf, format="png")
            drawn["bode"] = buf.getvalue()
        return drawn

    monkeypatch.setattr(render, "report_figures", resized)
    out = tmp_path / "resized.pdf"
    with pytest.raises(RuntimeError, match="figure 'bode': drawn RGB \\(50, 40\\)"):
        report.render_report(unconfirmed_design, out, date=DATE, executor=_Here())
    assert not out.exists() and not list(tmp_path.iterdir())


_IMPORT_WEASYPRINT = """\
import ctypes.util, json, resource, sys
calls = []
search = ctypes.util.find_library
def counted(name):
    calls.append(name)
    return search(name)
ctypes.util.find_library = counted
if sys.argv[1] == "fail-once":  # the first import of WeasyPrint's library module fails
    class FailOnce:
        done = False
        def find_spec(self, name, path=None, target=None):
            if name == "weasyprint.text.ffi" and not FailOnce.done:
                FailOnce.done = True
                raise OSError("no such library")
    sys.meta_path.insert(0, FailOnce())
from fi_design.report.render import _import_weasyprint
_import_weasyprint()
import weasyprint.text.ffi as ffi
children = resource.getrusage(resource.RUSAGE_CHILDREN)
print(json.dumps(dict(calls=len(calls), restored=ctypes.util.find_library is counted,
                      subset=ffi.harfbuzz_subset is not None, pango=ffi.pango is not None,
                      children=children.ru_utime + children.ru_stime > 0)))
"""


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the search skipped on Linux")
def test_weasyprint_is_imported_without_a_library_search():
    """WeasyPrint's import asked ctypes.util.find_library for each name it tries (ldconfig,
    gcc and ld: some 200 processes, 0.3 s); the report imports it with the search skipped,
    the same libraries loaded by their sonames, the search restored after; when that import
    fails, the usual one follows, quietly."""
    import json

    def run(mode):
        out = subprocess.run([sys.executable, "-c", _IMPORT_WEASYPRINT, mode],
                             capture_output=True, text=True, timeout=120, check=True).stdout
        return json.loads(out.strip().splitlines()[-1]), out

    fast, out = run("fast")
    assert fast == dict(calls=0, restored=True, subset=True, pango=True, children=False), out
    again, out = run("fail-once")
    assert again["calls"] > 0 and again["restored"] and again["pango"] and again["children"]
    assert len(out.strip().splitlines()) == 1, out  # no installation advice printed


def test_the_garbage_collector_rests_while_weasyprint_works(tmp_path, monkeypatch):
    """WeasyPrint lays the PDF out with the cyclic collector paused (it traversed WeasyPrint's
    growing objects again and again), and the collector's state is restored after, also when
    the layout fails."""
    import gc

    import weasyprint

    seen = []
    real = weasyprint.HTML.render

    def render(self, *args, **kwargs):
        seen.append(gc.isenabled())
        return real(self, *args, **kwargs)

    monkeypatch.setattr(weasyprint.HTML, "render", render)
    html = "<!DOCTYPE html><html><body><p>one page</p></body></html>"
    assert gc.isenabled()
    report.write_document(html, tmp_path / "a.pdf")
    assert seen == [False] and gc.isenabled()
    gc.disable()
    try:
        report.write_document(html, tmp_path / "b.pdf")
        assert not gc.isenabled()  # a caller's choice is kept
    finally:
        gc.enable()

    def broken(self, *args, **kwargs):
        raise RuntimeError("layout failed")

    monkeypatch.setattr(weasyprint.HTML, "render", broken)
    with pytest.raises(RuntimeError, match="layout failed"):
        report.write_document(html, tmp_path / "c.pdf")
    assert gc.isenabled() and not (tmp_path / "c.pdf").exists()


def _idat(png: bytes) -> bytes:
    """The joined IDAT chunks of a PNG (its compressed pixel rows), read chunk by chunk."""
    import struct

    at, rows = 8, []
    while at < len(png):
        length, kind = struct.unpack("!I4s", png[at:at + 8])
        if kind == b"IDAT":
            rows.append(png[at + 8:at + 8 + length])
        at += 12 + length
    return b"".join(rows)


def _pixels(png_path: Path):
    import numpy as np
    from PIL import Image

    with Image.open(png_path) as image:
        return np.asarray(image.convert("RGB"))


@pytest.mark.skipif(shutil.which("pdfimages") is None, reason="poppler-utils is not installed")
def test_pdf_takes_the_figures_rows_as_they_are(figures_drawn_here, design_pdf, tmp_path):
    """An opaque 8-bit RGB PNG goes into the PDF as it is: each figure's compressed rows are in
    the file byte for byte (not decoded and compressed again), and poppler reads every image
    back with the figure's own pixels."""
    import io

    from PIL import Image

    _, drawn = figures_drawn_here
    assert drawn
    pdf = design_pdf.read_bytes()
    for name, png in drawn.items():
        assert _idat(png) in pdf, name
    subprocess.run(["pdfimages", "-png", str(design_pdf), str(tmp_path / "img")], check=True,
                   timeout=120)
    extracted = [_pixels(p) for p in sorted(tmp_path.glob("img-*.png"))]
    for name, png in drawn.items():
        with Image.open(io.BytesIO(png)) as image:
            want = __import__("numpy").asarray(image.convert("RGB"))
        assert any(e.shape == want.shape and (e == want).all() for e in extracted), name


def _png(width: int, height: int, depth: int, colour: int, rows: bytes,
         interlace: int = 0) -> bytes:
    """A PNG written chunk by chunk (``rows``: each scanline with its filter byte)."""
    import struct
    import zlib

    def chunk(kind: bytes, body: bytes) -> bytes:
        return (struct.pack("!I", len(body)) + kind + body
                + struct.pack("!I", zlib.crc32(kind + body)))

    head = struct.pack("!IIBBBBB", width, height, depth, colour, 0, 0, interlace)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", head) + chunk(b"IDAT", zlib.compress(rows))
            + chunk(b"IEND", b""))


@pytest.mark.skipif(shutil.which("pdfimages") is None, reason="poppler-utils is not installed")
def test_pdf_encodes_other_images_again(tmp_path):
    """Images that are not opaque 8-bit RGB PNGs (alpha, a palette, grey, 16 bits per
    channel) are decoded and encoded again by WeasyPrint, as before: each reads back with
    its own pixels; interlaced or damaged files are not taken as they are either; and
    WeasyPrint's encoder is as it was once the PDF is written."""
    import base64
    import io

    import numpy as np
    from PIL import Image
    from weasyprint.images import RasterImage

    from fi_design.report.render import _rgb_png_rows

    rng = np.random.default_rng(0)
    rgb = rng.integers(0, 256, (24, 40, 3), dtype=np.uint8)

    def pillow_png(image: Image.Image) -> bytes:
        buf = io.BytesIO()
        image.save(buf, format="png")
        return buf.getvalue()

    rows16 = b"".join(b"\0" + (row.astype(">u2") * 257).tobytes() for row in rgb)
    plain = _png(40, 24, 8, 2, b"".join(b"\0" + row.tobytes() for row in rgb))
    others = {
        "alpha": pillow_png(Image.fromarray(np.dstack([rgb, rgb[..., :1]]))),
        "palette": pillow_png(Image.fromarray(rgb).quantize(16)),
        "grey": pillow_png(Image.fromarray(rgb[..., 0])),
        "sixteen": _png(40, 24, 16, 2, rows16),
    }
    interlaced = _png(40, 24, 8, 2, b"", interlace=1)
    damaged = bytearray(plain)
    damaged[45] ^= 0xFF  # in the IDAT chunk: its CRC no longer matches
    for name, data in [*others.items(), ("interlaced", interlaced), ("damaged", damaged)]:
        with Image.open(io.BytesIO(bytes(data))) as image:
            assert _rgb_png_rows(image) is None, name
    with Image.open(io.BytesIO(others["sixteen"])) as image:
        assert image.mode == "RGB"  # what Pillow calls it: the depth is read from the file
    with Image.open(io.BytesIO(plain)) as image:
        assert _rgb_png_rows(image) == _idat(plain)
    assert _rgb_png_rows(Image.fromarray(rgb)) is None  # no file behind it

    encoder = RasterImage.__dict__["_get_png_data"]
    images = [plain, *others.values()]
    tags = "".join(f'<img src="data:image/png;base64,{base64.b64encode(d).decode()}" '
                   f'style="width:40px">' for d in images)
    out = report.write_document(f"<!DOCTYPE html><html><body>{tags}</body></html>",
                                tmp_path / "images.pdf")
    assert RasterImage.__dict__["_get_png_data"] is encoder
    assert _idat(plain) in out.read_bytes()
    subprocess.run(["pdfimages", "-png", str(out), str(tmp_path / "img")], check=True,
                   timeout=60)
    got = [_pixels(p) for p in sorted(tmp_path.glob("img-*.png"))]
    for data in images:
        with Image.open(io.BytesIO(data)) as image:
            want = np.asarray(image.convert("RGB"))
        assert any(g.shape == want.shape and (g == want).all() for g in got)


def test_pdf_leaves_an_encoder_of_another_form_alone(tmp_path, monkeypatch):
    """The rows are taken over only where WeasyPrint's encoder is the static method of the
    versions this was written for: another form (here a class method) is left in place,
    called for every image, and the PDF is written as WeasyPrint writes it."""
    import base64
    import io

    import numpy as np
    from PIL import Image
    from weasyprint.images import RasterImage

    encode = RasterImage.__dict__["_get_png_data"].__func__
    calls = []

    def counted(cls, pillow_image):
        calls.append(pillow_image.size)
        return encode(pillow_image)

    monkeypatch.setattr(RasterImage, "_get_png_data", classmethod(counted))
    buf = io.BytesIO()
    Image.fromarray(np.full((24, 40, 3), 90, np.uint8)).save(buf, format="png")
    tag = f'<img src="data:image/png;base64,{base64.b64encode(buf.getvalue()).decode()}">'
    out = report.write_document(f"<!DOCTYPE html><html><body>{tag}</body></html>",
                                tmp_path / "other.pdf")
    assert calls == [(40, 24)] and out.read_bytes().startswith(b"%PDF")

    # nor is a figure laid out as a stand-in: nothing would put the figure in its place
    from fi_design.plots import FIGURE_SCHEME
    from fi_design.report.render import _self_contained

    class Figures:
        asked: list = []

        def stand_in(self, name):
            self.asked.append(("stand_in", name))
            return b"stand-in"

        def png(self, name):
            self.asked.append(("png", name))
            return buf.getvalue()

    figures = Figures()
    _self_contained(figures).fetch(f"{FIGURE_SCHEME}:bode")
    assert figures.asked == [("png", "bode")]


@pytest.mark.skipif(shutil.which("pdfimages") is None, reason="poppler-utils is not installed")
def test_a_stand_in_the_writing_did_not_replace_is_laid_out_again_with_its_figure(
        tmp_path, monkeypatch, caplog):
    """Should a WeasyPrint write the stand-in itself (its encoder not called for it), the PDF
    is laid out again with the figure: never a blank box in a sign-off document."""
    import contextlib
    import io
    import logging

    import numpy as np
    from PIL import Image

    from fi_design.plots import FIGURE_SCHEME
    from fi_design.report import render

    drawn = np.zeros((30, 50, 3), np.uint8)
    drawn[:, :25] = (200, 30, 30)
    buf = io.BytesIO()
    Image.fromarray(drawn).save(buf, format="png")

    class Figures:
        asked: list = []

        def stand_in(self, name):
            return render._stand_in(name, 50, 30)

        def png(self, name):
            self.asked.append(name)
            return buf.getvalue()

    @contextlib.contextmanager
    def untouched(figure=None):
        yield set()  # as a WeasyPrint that never asks the encoder for the stand-in's rows

    monkeypatch.setattr(render, "_png_as_is", untouched)
    html = f'<!DOCTYPE html><html><body><img src="{FIGURE_SCHEME}:bode"></body></html>'
    with caplog.at_level(logging.WARNING, logger="fi_design.report.render"):
        out = render.write_document(html, tmp_path / "again.pdf", figures=Figures())
    assert Figures.asked == ["bode"] and "laid out again" in caplog.text
    subprocess.run(["pdfimages", "-png", str(out), str(tmp_path / "img")], check=True,
                   timeout=60)
    (got,) = [_pixels(p) for p in sorted(tmp_path.glob("img-*.png"))]
    assert got.shape == drawn.shape and (got == drawn).all()


class _FailedFuture:
    def result(self):
        raise RuntimeError("worker gone")


class _Gone:
    """An executor whose every task fails (a worker killed under it)."""

    def submit(self, *args, **kwargs):
        return _FailedFuture()


@pytest.mark.skipif(shutil.which("pdfimages") is None, reason="poppler-utils is not installed")
def test_pdf_figures_drawn_here_when_the_worker_fails(paper_confirmed_design, design_pdf,
                                                      tmp_path):
    out = report.render_report(paper_confirmed_design, tmp_path / "here.pdf", date=DATE,
                               command=COMMAND, executor=_Gone())
    assert _pdf_images(out) == _pdf_images(design_pdf)


def test_html_figures_drawn_by_a_worker_and_here_make_the_same_page(paper_confirmed_design,
                                                                     design_html, fork_pool,
                                                                     tmp_path):
    """An HTML report with an executor: its figures are drawn there from the first and here
    from the last, each put in its place; the page is the one drawn in one process, byte for
    byte, with every figure inline and no mark left."""
    from fi_design.plots import FIGURE_MARK

    out = report.render_report(paper_confirmed_design, tmp_path / "apart.html", date=DATE,
                               command=COMMAND, executor=fork_pool)
    text = out.read_text(encoding="utf-8")
    assert text == design_html
    assert FIGURE_MARK.split("{")[0] not in text and text.count("<svg") >= 9


def test_html_figures_drawn_here_when_the_worker_fails(paper_confirmed_design, design_html,
                                                       tmp_path):
    out = report.render_report(paper_confirmed_design, tmp_path / "here.html", date=DATE,
                               command=COMMAND, executor=_Gone())
    assert out.read_text(encoding="utf-8") == design_html


def test_an_html_figure_that_fails_raises_its_own_error_and_writes_no_file(
        paper_confirmed_design, tmp_path, monkeypatch):
    """A figure that fails (in the worker and drawn again here) raises its own error from an
    HTML report drawn with an executor, and no file is left."""
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    from fi_design import plots

    def broken(*args, **kwargs):
        raise ZeroDivisionError("the Bode plot broke")

    monkeypatch.setattr(plots, "bode_figure", broken)
    out = tmp_path / "broken.html"
    # forked after the patch, as the command forks its report worker after the design
    with ProcessPoolExecutor(1, mp_context=multiprocessing.get_context("fork")) as pool, \
            pytest.raises(ZeroDivisionError, match="Bode plot broke"):
        report.render_report(paper_confirmed_design, out, date=DATE, executor=pool)
    assert not out.exists() and not list(tmp_path.iterdir())


def test_a_worker_builds_the_report_for_its_figures_without_the_equations(
        paper_confirmed_design, monkeypatch):
    """A worker makes the report's context only for its figures' makers: it draws none of
    the equations (17 of them took a cold worker 2 s before its first figure)."""
    from fi_design.report import equations, render

    def drawn(*args, **kwargs):
        raise AssertionError("an equation was drawn")

    monkeypatch.setattr(equations, "_draw", drawn)
    monkeypatch.setattr(equations, "_draw_img", drawn)
    monkeypatch.setattr(equations, "_cached", drawn)
    monkeypatch.setattr(render, "_PLACED", None)
    png = render.report_figures(paper_confirmed_design, {}, names=("bode",))
    svg = render.report_figures(paper_confirmed_design, {}, names=("bode",), svg=True)
    assert png["bode"].startswith(b"\x89PNG") and svg["bode"].startswith("<svg")


def test_a_figure_that_fails_raises_its_own_error_and_writes_no_pdf(paper_confirmed_design,
                                                                    tmp_path, monkeypatch):
    """A figure drawn while WeasyPrint lays the PDF out fails with its own error (not
    WeasyPrint's 'Error fetching figure:...'), and no file is left."""
    from fi_design import plots

    def broken(*args, **kwargs):
        raise ZeroDivisionError("the Bode plot broke")

    monkeypatch.setattr(plots, "bode_figure", broken)
    out = tmp_path / "broken.pdf"
    with pytest.raises(ZeroDivisionError, match="Bode plot broke"):
        report.render_report(paper_confirmed_design, out, date=DATE)
    assert not out.exists() and not list(tmp_path.iterdir())


# --------------------------------------------------------------------------- Chromium


def _chromium() -> str | None:
    for name in ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable"):
        if shutil.which(name):
            return shutil.which(name)
    return None


needs_chromium = pytest.mark.skipif(_chromium() is None,
                                    reason="no headless Chromium (apt install chromium) to "
                                           "render the HTML report")


def _headless(page: Path, tmp: Path, *extra: str) -> subprocess.CompletedProcess:
    cmd = [_chromium(), "--headless", "--no-sandbox", "--disable-gpu",
           "--disable-background-networking", "--disable-component-update", "--no-first-run",
           f"--user-data-dir={tmp / 'chromium-profile'}", "--hide-scrollbars",
           "--enable-logging=stderr", "--v=0", *extra, page.as_uri()]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=120)


CONSOLE = re.compile(r":CONSOLE[:(]")


@needs_chromium
def test_chromium_console_check_sees_errors(tmp_path):
    """The check below is real: a page with a script error shows up on the console log."""
    page = tmp_path / "bad.html"
    page.write_text("<!DOCTYPE html><p>x</p><script>console.error('boom')</script>")
    p = _headless(page, tmp_path, "--dump-dom")
    assert CONSOLE.search(p.stderr), p.stderr[-2000:]


@needs_chromium
def test_html_renders_in_chromium_without_console_errors(design_html, tmp_path):
    """One headless run takes the screenshot and dumps the DOM it rendered."""
    page = _artifacts() / "report.html"
    shot = _artifacts() / "report-chromium.png"
    shot.unlink(missing_ok=True)
    p = _headless(page, tmp_path, f"--screenshot={shot}", "--window-size=1000,9000",
                  "--dump-dom")
    assert p.returncode == 0, p.stderr[-2000:]
    assert not CONSOLE.search(p.stderr), [ln for ln in p.stderr.splitlines()
                                          if CONSOLE.search(ln)]
    assert shot.is_file() and shot.stat().st_size > 50_000
    for sid in DESIGN_SECTIONS:
        assert f'id="{sid}"' in p.stdout


# --------------------------------------------------------------------------- CLI


def _refuse_work(monkeypatch):
    import fi_design.spec.file

    def boom(*a, **k):
        raise AssertionError("the spec was read: the output path was not checked first")

    monkeypatch.setattr(fi_design.spec.file, "load_spec", boom)


def test_cli_refuses_a_wrong_extension_before_any_work(tmp_path, monkeypatch, paper_spec_path):
    _refuse_work(monkeypatch)
    out = tmp_path / "report.docx"
    r = runner.invoke(app, [str(paper_spec_path), "--report", str(out)])
    assert r.exit_code == 2, r.output
    assert ".html or .pdf" in r.output and not out.exists()
    assert list(tmp_path.iterdir()) == []


def test_cli_refuses_an_existing_report_without_force(tmp_path, monkeypatch, paper_spec_path):
    _refuse_work(monkeypatch)
    out = tmp_path / "report.pdf"
    out.write_text("old")
    r = runner.invoke(app, [str(paper_spec_path), "--report", str(out)])
    assert r.exit_code == 2 and "--force" in r.output
    assert out.read_text() == "old"


def test_cli_refuses_the_spec_as_report_even_with_force(tmp_path, monkeypatch):
    _refuse_work(monkeypatch)
    spec = tmp_path / "stage.html"
    shutil.copy(EXAMPLES / "paper_setup.yaml", spec)
    before = spec.read_bytes()
    r = runner.invoke(app, [str(spec), "--report", str(spec), "--force"])
    assert r.exit_code == 2 and "input file" in r.output
    assert spec.read_bytes() == before


def test_cli_refuses_report_and_json_on_one_file(tmp_path, monkeypatch, paper_spec_path):
    _refuse_work(monkeypatch)
    out = tmp_path / "x.html"
    r = runner.invoke(app, [str(paper_spec_path), "--report", str(out), "--json", str(out)])
    assert r.exit_code == 2


def test_cli_map_needs_a_report(monkeypatch, paper_spec_path):
    _refuse_work(monkeypatch)
    r = runner.invoke(app, [str(paper_spec_path), "--map"])
    assert r.exit_code == 2 and "--report" in r.output


def test_cli_writes_the_html_report_with_force(tmp_path, paper_spec_path, shared_designs):
    """The command replaces an existing report with --force, atomically, every section in
    order. How the command writes the report is checked here, not what it computes: the
    design of the linear steps (--no-simulation, a report of every section, the nonlinear
    one saying it was not run); the README's first command, the simulation, the design
    search and their report included, is run twice by
    tests/test_docs.py::test_readme_run_command_succeeds_on_every_run."""
    out = tmp_path / "report.html"
    out.write_text("old")
    r = runner.invoke(app, [str(paper_spec_path), "--report", str(out), "--force",
                            "--no-simulation"])
    assert r.exit_code == 0, r.output
    assert f"wrote {out}" in r.output.replace("\n", "")
    text = out.read_text(encoding="utf-8")
    assert text.startswith("<!DOCTYPE html>") and "fi-design" in text
    assert [a["id"] for t, a in _parse(text).tags if t == "section"] == DESIGN_SECTIONS
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".report.html.")]


# --------------------------------------------------------------------------- map, other reports


def test_design_map_section(paper_confirmed_design):
    from fi_design.studies import design_map

    small = design_map(paper_confirmed_design, resolution=(3, 2))
    assert small.sweep.shape == (2, 3) and not small.suggested
    ctx = report.build_context(paper_confirmed_design, date=DATE, design_map=small)
    assert [s["id"] for s in ctx["sections"]][6] == "map"
    assert "fi_design.studies.sweep: crossover 1 to 20 Hz" in ctx["map"]["intro"]
    text = report.render_html(ctx)
    assert 'id="fig-map"' in text and re.search(r'id="fig-map">\s*<svg', text)


def test_generic_document(tmp_path, paper_spec):
    from matplotlib.figure import Figure

    fig = Figure(figsize=(3, 2))
    fig.add_subplot().plot([0, 1], [1, 0])
    sections = [report.Section("finding", "Finding <1>", paragraphs=("a <b>bold</b> claim",),
                               tables=(report.Table(("Effect", "Score [-]"),
                                                    (("none", report.num(1.5)),)),),
                               figures=(report.figure_block(fig, "A line", name="line"),),
                               notes=("n1",))]
    out = report.render_document(tmp_path / "doc.html", title="Reconciliation",
                                 spec=paper_spec, sections=sections, kind="reconcile",
                                 date=DATE, conclusion="All good.")
    text = out.read_text(encoding="utf-8")
    p = _parse(text)
    assert [a["id"] for t, a in p.tags if t == "section"] == ["summary", "finding", "appendix"]
    assert "a &lt;b&gt;bold&lt;/b&gt; claim" in text and "Finding &lt;1&gt;" in text
    assert re.search(r'id="fig-line">\s*<svg', text) and "Figure 1." in text
    with pytest.raises(OutputError):
        report.render_document(tmp_path / "doc.txt", title="x", spec=paper_spec, sections=[])


def test_sweep_report(tmp_path, paper_spec):
    from fi_design.studies import sweep

    result = sweep(paper_spec, x=("controller.crossover", [4.0, 8.0]),
                   y=("isolator.stroke", [2e-4, 3e-4]))
    out = report.render_report(result, tmp_path / "map.html", date=DATE, command="fi-design sweep")
    text = out.read_text(encoding="utf-8")
    assert "Hunting map" in text and re.search(r"<figure[^>]*>\s*<svg", text)
    assert "Points per verdict" in text


def test_render_report_refuses_other_extensions_and_kinds(tmp_path, paper_confirmed_design):
    with pytest.raises(OutputError, match=r"\.html or \.pdf"):
        report.render_report(paper_confirmed_design, tmp_path / "r.htm")
    with pytest.raises(ReportError, match="no report for a object"):
        report.render_report(object(), tmp_path / "r.html")
    assert list(tmp_path.iterdir()) == []


def test_a_report_from_the_library_keeps_an_existing_file_without_force(tmp_path, paper_spec):
    """render_report and render_document replaced any existing file (a user's notes, an
    earlier report) without a word; they refuse it now, before any work, as the command line
    does without --force, and replace it with force=True. Each call checks again."""
    out = tmp_path / "notes.html"
    out.write_text("my notes", encoding="utf-8")
    with pytest.raises(OutputError, match="file exists; use force=True to overwrite it"):
        report.render_report(object(), out)  # refused before the result is looked at
    with pytest.raises(OutputError, match="file exists"):
        report.render_document(out, title="x", spec=paper_spec, sections=[])
    assert out.read_text(encoding="utf-8") == "my notes"
    folder = tmp_path / "folder.html"
    folder.mkdir()
    with pytest.raises(OutputError, match="is a directory"):
        report.render_report(object(), folder, force=True)
    assert report.render_document(out, title="x", spec=paper_spec, sections=[], date=DATE,
                                  force=True) == out
    assert "<html" in out.read_text(encoding="utf-8")
    with pytest.raises(OutputError, match="file exists"):  # its own file too, without force
        report.render_document(out, title="x", spec=paper_spec, sections=[])


def test_public_api_exports_render_report():
    import fi_design

    assert fi_design.render_report is report.render_report


# --------------------------------------------------------------------------- packaging


@pytest.mark.slow
def test_templates_ship_in_the_wheel_and_load_from_an_installed_copy(tmp_path):
    """Build the wheel, install it into a target directory, find the templates from there."""
    import importlib.util

    wheels = tmp_path / "wheels"
    # Built from a copy of the source tree: pip builds in the tree, and the build hook
    # replaces the kernel's extension there, which other tests running at the same time
    # (pytest -n) load.
    source = tmp_path / "source"
    shutil.copytree(ROOT, source, ignore=shutil.ignore_patterns(
        ".git", ".venv", "__pycache__", ".pytest_cache", ".hypothesis", ".import_linter_cache",
        "artifacts", "build", "dist", "*.egg-info", "_aot.*"))
    # The build backend from this environment when it has one (no network needed), else pip
    # fetches it into an isolated build environment as `pip install` does.
    isolation = ["--no-build-isolation"] if importlib.util.find_spec("hatchling") else []
    build = subprocess.run([sys.executable, "-m", "pip", "wheel", str(source), "--no-deps",
                            *isolation, "-q", "-w", str(wheels)],
                           capture_output=True, text=True, timeout=600)
    assert build.returncode == 0, build.stderr[-3000:]
    wheel = next(wheels.glob("fi_design-*.whl"))
    with zipfile.ZipFile(wheel) as zf:
        names = set(zf.namelist())
    expected = {f"fi_design/templates/{p.name}" for p in (ROOT / "templates").iterdir()
                if p.is_file()}
    assert expected and expected <= names, sorted(expected - names)
    site = tmp_path / "site"
    inst = subprocess.run([sys.executable, "-m", "pip", "install", "--no-deps", "-q",
                           "--target", str(site), str(wheel)], capture_output=True, text=True,
                          timeout=300)
    assert inst.returncode == 0, inst.stderr[-3000:]
    probe = ("import fi_design, fi_design.report as r\n"
             "from importlib.resources import files\n"
             "from fi_design.provenance import current_source\n"
             "from fi_design.report.meta import title_block\n"
             "from fi_design.spec.file import load_spec\n"
             "print(fi_design.__file__)\n"
             "print(r.template_dir())\n"
             "spec = load_spec(str(files('fi_design').joinpath('example_spec.yaml')))\n"
             "meta = title_block(spec, 'design', date='x', command='c')\n"
             "print(len(r.environment().get_template('report.html.jinja').render("
             "meta=meta, sections=[], body=[], css='')))\n"
             "print(current_source().commit, current_source().code_sha256)\n")
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env["PYTHONPATH"] = str(site)
    run = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                         cwd=tmp_path, env=env, timeout=120)
    assert run.returncode == 0, run.stderr[-3000:]
    module, templates, size, commit, digest = run.stdout.split()
    assert Path(module).resolve().is_relative_to(site.resolve())
    assert Path(templates) == (site / "fi_design" / "templates").resolve()
    assert int(size) > 1000
    # the installed copy is no git checkout: its source is the digest of its code, the same
    # digest as the source tree it was built from
    from fi_design.provenance import code_digest

    assert commit == "None" and digest == code_digest()


def _visible_text(html: str) -> str:
    """The text a reader sees: no figures, styles or tags."""
    html = re.sub(r"<(svg|style|script)\b.*?</\1>", " ", html, flags=re.S)
    return re.sub(r"<[^>]+>", " ", html)


def test_no_markup_of_another_format_in_the_html(design_html):
    """Literal backticks (Markdown) stood in the recommendation; RST roles and the developers'
    design document have no place in a report either."""
    text = _visible_text(design_html)
    for mark in ("`", ":func:", ":class:", "DESIGN.md"):
        assert mark not in text, (mark, text[max(0, text.find(mark) - 80):text.find(mark) + 80])


def test_the_inputs_table_lists_values_with_commas_and_ranges_with_a_dash(paper_spec):
    """The stage's [x, y, z] size and [y, z] offsets read '40 – 50 – 60 mm' and '0 – 0 mm',
    as if they were ranges, beside the flexure's real [min, max] bounds."""
    from fi_design.model import resolve
    from fi_design.report.filters import qty
    from fi_design.report.inputs import spec_inputs

    from conftest import variant

    spec = variant(paper_spec, **{"stage.size": ["40 mm", "50 mm", "60 mm"]})
    rows = {r["path"]: qty(r["value"], r["unit"])
            for g in spec_inputs(spec, resolve(spec)) for r in g["rows"]}
    assert rows["stage.size"] == "40, 50, 60\u00a0mm"
    assert rows["stage.sensor_offset"] == "0, 0\u00a0mm"
    assert rows["isolator.flexure.length"] == "10 \u2013 60\u00a0mm"


def test_the_inputs_give_the_stiffness_scatter_the_study_drew(paper_confirmed_design):
    """Analysis settings read requirements.robustness.stiffness as '- / not given' while the
    verdict and the assumptions said the study scattered k by 6 % (the flexure's stock
    tolerance): the report contradicted itself. The row now gives the derived default."""
    from fi_design.model import resolve
    from fi_design.report.inputs import spec_inputs

    r = paper_confirmed_design
    drawn = r.robustness.scatter["isolator.stiffness"]
    rows = {row["path"]: row for g in spec_inputs(r.spec, resolve(r.spec)) for row in g["rows"]}
    row = rows["requirements.robustness.stiffness"]
    assert row["value"] == pytest.approx(drawn, rel=1e-12) and drawn == pytest.approx(0.06)
    assert row["source"].startswith("derived default: the flexure's stock thickness tolerance")


def test_step3_says_the_resting_deflection_was_not_determined_when_the_run_failed(
        paper_confirmed_design):
    """A run that did not complete (diverged: its traces end in nan) showed 'n/a' for the
    deflection at rest and its force, and an equation 'k x n/a = n/a'."""
    from dataclasses import replace

    from fi_design.report.steps import guideline_steps

    r = paper_confirmed_design
    failed = replace(r, simulation=replace(r.simulation, landing=replace(
        r.simulation.landing, deflection=float("nan"), force=float("nan"))))
    step3 = next(s for s in guideline_steps(failed, figures=False) if s["number"] == 3)
    rows = {row["quantity"]: row["value"] for row in step3["results"]}
    assert rows["simulated deflection at rest d"].startswith("not determined")
    assert "flexure force on the resting cart" not in rows
    assert not any("nan" in str(e).lower() or "n/a" in str(e) for e in step3["equations"])
    ok = next(s for s in guideline_steps(r, figures=False) if s["number"] == 3)
    assert {row["quantity"]: row["value"] for row in ok["results"]}[
        "simulated deflection at rest d"] == r.simulation.landing.deflection
