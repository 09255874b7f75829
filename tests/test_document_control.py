"""Document control of the reports: the code that made them (version, commit, code digest),
the spec printed verbatim beside its hash, signatures and revision history, one document id
per kind of report.

The HTML is read with tinyhtml5, the WHATWG parser WeasyPrint itself reads it with, so the
text checked here is the text the PDF prints.
"""

from __future__ import annotations

import hashlib
import json
import shutil
import subprocess
from pathlib import Path

import pytest
import yaml

from fi_design import provenance, report
from fi_design.errors import SpecError
from fi_design.guideline.evaluate import evaluate as design
from fi_design.report.meta import title_block
from fi_design.spec import REPORT_KINDS
from fi_design.spec.file import load_spec

from conftest import EXAMPLES, ROOT

XHTML = "{http://www.w3.org/1999/xhtml}"
DATE = "2026-01-01"

needs_git = pytest.mark.skipif(shutil.which("git") is None, reason="git is not installed")


def _git(*args: str, cwd: Path) -> str:
    return subprocess.run(["git", *args], cwd=cwd, capture_output=True, text=True,
                          check=True).stdout.strip()


def _in_checkout() -> bool:
    if shutil.which("git") is None:
        return False
    done = subprocess.run(["git", "ls-files", "--error-unmatch", "fi_design/__init__.py"],
                          cwd=ROOT, capture_output=True, text=True)
    return done.returncode == 0


def _html_tree(text: str):
    import tinyhtml5

    return tinyhtml5.parse(text)


def _by_class(tree, tag: str, cls: str) -> list:
    return [e for e in tree.iter(XHTML + tag) if cls in (e.get("class") or "").split()]


def _text(element) -> str:
    return "".join(element.itertext())


# --------------------------------------------------------------------------- the code's source


def test_code_digest_covers_the_package_and_its_templates():
    files = provenance.code_files()
    assert "fi_design/report/meta.py" in files and "fi_design/provenance.py" in files
    assert "fi_design/templates/report.html.jinja" in files
    assert "fi_design/templates/report.css" in files
    assert "fi_design/example_spec.yaml" in files
    assert not any("__pycache__" in k or "/_aot." in k for k in files)
    digest = provenance.code_digest()
    assert len(digest) == 64 and digest == provenance.current_source().code_sha256


def test_code_digest_is_the_same_for_the_installed_layout(tmp_path):
    """An installed wheel has the templates inside the package; the digest does not change."""
    package = tmp_path / "site" / "fi_design"
    shutil.copytree(ROOT / "fi_design", package,
                    ignore=shutil.ignore_patterns("__pycache__", "_aot.*"))
    shutil.copytree(ROOT / "templates", package / "templates")
    assert provenance.code_files(package).keys() == provenance.code_files().keys()
    assert provenance.code_digest(package) == provenance.code_digest()
    (package / "templates" / "report.css").write_text("/* changed */", encoding="utf-8")
    assert provenance.code_digest(package) != provenance.code_digest()


@needs_git
def test_git_commit_and_local_changes(tmp_path):
    repo = tmp_path / "repo"
    package = repo / "fi_design"
    package.mkdir(parents=True)
    (repo / "templates").mkdir()
    (package / "__init__.py").write_text("x = 1\n")
    (repo / "templates" / "report.css").write_text("p {}\n")
    (repo / "notes.txt").write_text("outside the package\n")
    _git("init", "-q", cwd=repo)
    _git("add", ".", cwd=repo)
    _git("-c", "user.name=t", "-c", "user.email=t@example.com", "commit", "-q", "-m", "c",
         cwd=repo)
    head = _git("rev-parse", "HEAD", cwd=repo)
    assert provenance.git_commit(package) == (head, False)
    (repo / "notes.txt").write_text("changed outside the package\n")
    assert provenance.git_commit(package) == (head, False)
    (repo / "templates" / "report.css").write_text("p { color: red }\n")
    assert provenance.git_commit(package) == (head, True)
    _git("checkout", "-q", "--", "templates", cwd=repo)
    (package / "extra.py").write_text("y = 2\n")  # untracked code counts too
    assert provenance.git_commit(package) == (head, True)
    # a package that no checkout tracks has no commit
    lone = tmp_path / "lone" / "fi_design"
    lone.mkdir(parents=True)
    (lone / "__init__.py").write_text("")
    assert provenance.git_commit(lone) == (None, None)


@pytest.mark.skipif(not _in_checkout(), reason="not running from a git checkout")
def test_current_source_names_this_checkout():
    source = provenance.current_source()
    assert source.commit == _git("rev-parse", "HEAD", cwd=ROOT)
    assert source.commit in source.revision and source.modified in (True, False)


def test_source_in_words():
    installed = provenance.Source("1.2.0", None, None, "ab" * 32)
    assert installed.revision == f"code SHA-256 {'ab' * 32} (not run from a git checkout)"
    assert installed.short == "code abababababab"
    assert installed.to_dict() == {"commit": None, "modified": None, "code_sha256": "ab" * 32}
    dev = provenance.Source("1.2.0", "c" * 40, True, "ab" * 32)
    assert dev.revision == f"git commit {'c' * 40} with local changes"
    assert dev.short == "commit cccccccccccc+modified"


# --------------------------------------------------------------------------- title block, JSON


@pytest.fixture(scope="module")
def linear_design(paper_spec):
    return design(paper_spec, confirm=False)


def test_json_carries_version_commit_and_code_digest(linear_design):
    import fi_design

    data = json.loads(json.dumps(linear_design.to_dict()))
    source = provenance.current_source()
    assert data["fi_design_version"] == fi_design.__version__
    assert data["fi_design_source"] == {"commit": source.commit, "modified": source.modified,
                                        "code_sha256": source.code_sha256}


def test_title_block_carries_version_and_source(linear_design):
    import fi_design

    ctx = report.build_context(linear_design, date=DATE, command="x", figures=False)
    meta = ctx["meta"]
    source = provenance.current_source()
    assert meta["tool"] == f"fi-design {fi_design.__version__}"
    assert meta["code_sha256"] == source.code_sha256
    assert meta["tool_source"] == source.revision
    assert meta["tool_footer"] == f"fi-design {fi_design.__version__}, {source.short}"
    html = report.render_html(ctx)
    tree = _html_tree(html)
    header = _text(next(tree.iter(XHTML + "header")))
    assert source.code_sha256 in header and source.revision in header
    assert fi_design.__version__ in header
    # the PDF's running footer takes its text from this element (CSS string-set)
    assert [_text(e) for e in _by_class(tree, "p", "tool-footer")] == [meta["tool_footer"]]
    assert "string-set: tool content()" in (report.template_dir() / "report.css").read_text()


def test_title_block_shows_the_result_s_source_not_the_renderer_s(linear_design):
    from dataclasses import replace

    old = provenance.Source("0.0.9", "d" * 40, False, "ef" * 32)
    ctx = report.build_context(replace(linear_design, fi_design_version="0.0.9",
                                       fi_design_source=old), date=DATE, figures=False)
    assert ctx["meta"]["tool"] == "fi-design 0.0.9"
    assert ctx["meta"]["tool_source"] == f"git commit {'d' * 40}"
    assert ctx["meta"]["code_sha256"] == "ef" * 32


# --------------------------------------------------------------------------- the spec verbatim


def _appendix(html: str) -> tuple[str, str]:
    tree = _html_tree(html)
    (pre,) = _by_class(tree, "pre", "spec")
    (digest,) = _by_class(tree, "span", "spec-sha256")
    return pre.text or "", _text(digest)


def test_appendix_prints_the_spec_file_verbatim_beside_its_hash(paper_spec_path, linear_design):
    raw = paper_spec_path.read_bytes()
    html = report.render_html(report.build_context(linear_design, date=DATE, figures=False))
    printed, stated = _appendix(html)
    assert printed == raw.decode("utf-8")  # comments, layout, quoting: all kept
    assert "# " in printed
    assert hashlib.sha256(printed.encode("utf-8")).hexdigest() == stated
    assert stated == hashlib.sha256(raw).hexdigest() == linear_design.spec_sha256


def test_appendix_keeps_comments_blank_lines_and_markup_characters(tmp_path):
    text = (EXAMPLES / "paper_setup.yaml").read_text(encoding="utf-8")
    text = ("\n# leading blank line, then <b>markup</b> & 'quotes' in a comment\n"
            + text.replace("name: Paper setup with friction isolator",
                           "name: \"Stage <A> & B\"   # trailing comment\n\n\n# blank lines kept"))
    path = tmp_path / "stage.yaml"
    path.write_bytes(text.encode("utf-8"))
    result = design(load_spec(path), confirm=False)
    html = report.render_html(report.build_context(result, date=DATE, figures=False))
    printed, stated = _appendix(html)
    assert printed == text
    assert hashlib.sha256(printed.encode("utf-8")).hexdigest() == stated == \
        hashlib.sha256(path.read_bytes()).hexdigest()
    assert "<b>markup</b>" not in html  # escaped, not markup


def test_a_spec_without_file_says_what_its_hash_covers(paper_spec_path):
    raw = yaml.safe_load(paper_spec_path.read_text(encoding="utf-8"))
    result = design(raw, confirm=False)
    ctx = report.build_context(result, date=DATE, figures=False)
    assert ctx["appendix"]["spec_verbatim"] is False
    assert "canonical JSON" in ctx["appendix"]["spec_note"]
    assert ctx["appendix"]["spec_sha256"] == result.spec_sha256


# --------------------------------------------------------------------------- signatures, history


def _spec_with_report(tmp_path, section: dict, name: str = "spec.yaml") -> Path:
    raw = yaml.safe_load((EXAMPLES / "paper_setup.yaml").read_text(encoding="utf-8"))
    raw["report"] = section
    path = tmp_path / name
    path.write_text(yaml.safe_dump(raw, sort_keys=False), encoding="utf-8")
    return path


def test_checker_approver_and_revision_history_appear(tmp_path):
    path = _spec_with_report(tmp_path, {
        "document_id": "FI-0042", "status": "released", "author": "A. Author",
        "checked_by": "C. Checker", "approved_by": "P. Approver",
        "revisions": [
            {"revision": "A", "date": "2026-01-15", "description": "First issue",
             "author": "A. Author"},
            {"revision": "B", "date": "2026-02-20",
             "description": "Stroke 0.3 mm after review <R-7>", "author": "A. Author"},
        ]})
    spec = load_spec(path)
    assert spec.report.revision == "B"  # the last entry of the history
    assert spec.report.checked_by == "C. Checker"
    result = design(spec, confirm=False)
    meta = report.build_context(result, date=DATE, figures=False)["meta"]
    assert meta["signatures"] == [{"role": "Prepared", "name": "A. Author"},
                                  {"role": "Checked", "name": "C. Checker"},
                                  {"role": "Approved", "name": "P. Approver"}]
    assert meta["revisions"] == [
        {"revision": "A", "date": "2026-01-15", "description": "First issue",
         "author": "A. Author"},
        {"revision": "B", "date": "2026-02-20", "description": "Stroke 0.3 mm after review <R-7>",
         "author": "A. Author"}]
    assert meta["running"] == "FI-0042 rev. B (released)"
    tree = _html_tree(report.render_html(report.build_context(result, date=DATE,
                                                              figures=False)))
    (history,) = _by_class(tree, "table", "revisions")
    rows = [[_text(td) for td in tr.iter(XHTML + "td")] for tr in history.iter(XHTML + "tr")]
    assert [r for r in rows if r] == [
        ["A", "2026-01-15", "First issue", "A. Author"],
        ["B", "2026-02-20", "Stroke 0.3 mm after review <R-7>", "A. Author"]]
    (signatures,) = _by_class(tree, "table", "signatures")
    names = {_text(tr.find(XHTML + "th")): _text(tr.find(XHTML + "td"))
             for tr in signatures.iter(XHTML + "tr") if tr.find(XHTML + "td") is not None}
    assert names == {"Prepared": "A. Author", "Checked": "C. Checker",
                     "Approved": "P. Approver"}


def test_no_history_no_table(linear_design):
    meta = report.build_context(linear_design, date=DATE, figures=False)["meta"]
    tree = _html_tree(report.render_html(report.build_context(linear_design, date=DATE,
                                                              figures=False)))
    assert bool(_by_class(tree, "table", "revisions")) == bool(meta["revisions"])


@pytest.mark.parametrize("section,path,words", [
    ({"revision": "A", "revisions": [{"revision": "A"}, {"revision": "B"}]}, "report",
     "not the last entry"),
    ({"revisions": [{"revision": "A"}, {"revision": "A"}]}, "report", "listed twice"),
    ({"revisions": [{"revision": "A", "date": "2026-02-01"},
                    {"revision": "B", "date": "2026-01-01"}]}, "report", "must not decrease"),
    ({"revisions": [{"revision": "A", "date": "yesterday"}]}, "report.revisions[0].date", ""),
    ({"revisions": [{"revision": "A", "reviewer": "x"}]}, "report.revisions[0].reviewer",
     "unknown key"),
    ({"checked": "x"}, "report.checked", "did you mean 'checked_by'"),
    ({"document_ids": {"sweep": "FI-0001"}}, "report", "already the document id of the design"),
    ({"document_ids": {"sweep": "X-1", "study": "X-1"}}, "report", "every kind of report"),
    ({"document_ids": {"gap": "X-1"}}, "report.document_ids.gap", "unknown key"),
])
def test_bad_document_control_is_refused_with_the_field(tmp_path, section, path, words):
    spec_path = _spec_with_report(tmp_path, section)
    with pytest.raises(SpecError) as info:
        load_spec(spec_path)
    assert info.value.path == path, str(info.value)
    assert words in str(info.value)


def test_revision_without_history_defaults_to_a(tmp_path):
    assert load_spec(_spec_with_report(tmp_path, {})).report.revision == "A"
    assert load_spec(_spec_with_report(tmp_path, {"revision": "C"}, "c.yaml")).report.revision \
        == "C"


# --------------------------------------------------------------------------- one id per kind


def test_every_kind_of_report_has_its_own_document_id(paper_spec):
    ids = {kind: title_block(paper_spec, kind, date=DATE, command=None)["document_id"]
           for kind in REPORT_KINDS}
    assert ids == {"design": "FI-0001", "sweep": "FI-0001-SWEEP", "study": "FI-0001-STUDY",
                   "robustness": "FI-0001-ROBUSTNESS", "reconcile": "FI-0001-RECONCILE",
                   "identify": "FI-0001-IDENTIFY", "recommend": "FI-0001-RECOMMEND"}
    assert title_block(paper_spec, "sweep", date=DATE, command=None)["running"].startswith(
        "FI-0001-SWEEP rev. A")


def test_explicit_document_ids_are_used(tmp_path):
    spec = load_spec(_spec_with_report(tmp_path, {"document_id": "FI-0100",
                                                  "document_ids": {"sweep": "FI-0101"}}))
    assert spec.report.id_for("design") == "FI-0100"
    assert spec.report.id_for("sweep") == "FI-0101"
    assert spec.report.id_for("robustness") == "FI-0100-ROBUSTNESS"


def test_sweep_and_robustness_reports_do_not_reuse_the_design_id(paper_spec, tmp_path):
    from fi_design.studies import parse_scatter, robustness, sweep

    line = sweep(paper_spec, x=("controller.crossover", [8.0]))
    ctx = report.build_context(line, date=DATE, figures=False)
    assert ctx["meta"]["document_id"] == "FI-0001-SWEEP"
    assert ctx["meta"]["code_sha256"] == line.fi_design_source.code_sha256
    rob = robustness(paper_spec, [parse_scatter("friction.static=10%", paper_spec)], 1)
    assert report.build_context(rob, date=DATE, figures=False)["meta"]["document_id"] == \
        "FI-0001-ROBUSTNESS"
    assert rob.to_dict()["fi_design_source"]["code_sha256"] == provenance.code_digest()
    html = report.render_report(line, tmp_path / "sweep.html", date=DATE).read_text("utf-8")
    tree = _html_tree(html)
    header = _text(next(tree.iter(XHTML + "header")))
    assert "FI-0001-SWEEP" in header and "FI-0001 " not in header.replace("FI-0001-", "")


def test_generic_reports_take_their_kind_s_id(paper_spec):
    for kind, doc in (("reconcile", "FI-0001-RECONCILE"), ("identify", "FI-0001-IDENTIFY"),
                      ("calibration", "FI-0001-CALIBRATION")):
        ctx = report.document_context("t", paper_spec, [], date=DATE, kind=kind)
        assert ctx["meta"]["document_id"] == doc


def test_appendix_marks_the_rows_of_a_wrapped_spec_line(tmp_path):
    """The PDF wrapped long spec lines without a mark, so the printed text read differently
    from the text the SHA-256 is checked against."""
    import shutil
    import subprocess

    long_comment = "# " + " ".join(f"word{i}" for i in range(40))  # about 280 characters
    text = (EXAMPLES / "paper_setup.yaml").read_text(encoding="utf-8") + long_comment + "\n"
    path = tmp_path / "stage.yaml"
    path.write_bytes(text.encode("utf-8"))
    result = design(load_spec(path), confirm=False)
    ctx = report.build_context(result, date=DATE, figures=False)
    assert "continues in rows marked" in ctx["appendix"]["spec_note"]
    html = report.render_html(ctx)
    tree = _html_tree(html)
    (pre,) = _by_class(tree, "pre", "spec")
    assert "".join(pre.itertext()) == text  # the text itself is the file's, byte for byte
    rows = _by_class(tree, "span", "wrapped")
    assert len(rows) == 2 and all(len(r.text) <= 94 for r in rows)
    assert hashlib.sha256("".join(pre.itertext()).encode()).hexdigest() == result.spec_sha256
    if shutil.which("pdftotext") is None:
        return  # the mark in the PDF itself needs poppler-utils to read back
    pdf = report.render_report(result, tmp_path / "r.pdf", date=DATE)
    out = subprocess.run(["pdftotext", "-layout", str(pdf), "-"], capture_output=True,
                         text=True, timeout=60).stdout
    marked = [ln for ln in out.splitlines() if ln.strip().startswith("\u21aa")]
    assert len(marked) == 2 and "word39" in marked[-1], marked
