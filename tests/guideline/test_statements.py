"""Every example's sign-off documents read one judged value per statement, never two.

A review board cannot sign a page that says both "nothing to review" and "an isolator is
recommended". Each example spec (examples/*.yaml) is designed once for the session (no
recommendation: the search is not what is read here) and rendered as a reviewer meets it:
the console summary, the JSON, the HTML report's text and the PDF's text (pdftotext). The
texts are then read for contradictions:

- a PASS verdict beside advice to change the hardware;
- one quantity stated with two values (a formula named with two results; the static error
  bound under two formulas; the rule's kp twice; the hunting-free crossover, the fold's
  resolution and the robustness probability as anything but the judged value);
- "stuck" beside "not stuck", or "stuck" where no judged outcome is stuck;
- a boundary "not computed", or "hunts for some move", for a plant that hunts for no move;
- an advice the same report shows failing (the rule's isolator advised while it hunts);
- a warning count that is not the checks table's, internal check ids in a headline, a
  probability printed as a fraction beside its percentage, terms printed but not defined.

The default run reads every example but :data:`SLOW_ONLY` (whose terms another example's
documents hold); the slow run reads them all, and every example's PDF.
"""

from __future__ import annotations

import enum
import io
import json
import re
import shutil
import subprocess
from html.parser import HTMLParser

import pytest

from conftest import EXAMPLES, sharing_designs

NAMES = sorted(p.stem for p in EXAMPLES.glob("*.yaml"))
DATE = "2026-11-28"
#: The example whose PDF is read in the default run (every example's in the slow one).
FLAGSHIP = "paper_setup"
#: Examples read in the slow run only. emps_axis (a PD loop computed at 1 kHz, D on the
#: measured velocity, no isolator, PASS) states nothing industrial_axis's documents do not
#: state too: the same loop, the static error bound (Fs + |offset|) / kp, the rule's kp, a
#: passing verdict with the rule's isolator beside it, no boundary for a plant that hunts for
#: no move; industrial_axis adds a drive offset, friction by direction and a stage resting
#: within its static error (a 'static error' outcome), and the rest of the outcomes (settles,
#: hunts, undetermined) are the other examples'. Its design is 14 s of CPU.
SLOW_ONLY = {"emps_axis"}
#: Every example, those of :data:`SLOW_ONLY` marked slow.
EXAMPLE_PARAMS = [pytest.param(n, marks=pytest.mark.slow) if n in SLOW_ONLY else n
                  for n in NAMES]

needs_poppler = pytest.mark.skipif(shutil.which("pdftotext") is None,
                                   reason="poppler-utils (pdftotext) is not installed")


# --------------------------------------------------------------------------- the documents


def _design(name: str, sensitivity: bool, quick):
    """An example's sign-off; industrial_axis read from ``quick`` (conftest's
    ``INDUSTRIAL_ROBUSTNESS``: fewer scatter samples), its design shared with test_console's."""
    from fi_design.signoff import design
    from fi_design.spec.file import load_spec

    path = quick if name == "industrial_axis" else EXAMPLES / f"{name}.yaml"
    with sharing_designs():
        return design(load_spec(path), recommend=False, sensitivity=sensitivity)


def _selected_examples(session) -> list[str]:
    """The examples the selected tests of this file read (by their ``name`` parameter), and
    the flagship (the docs' figures and the PDF read)."""
    names = {item.callspec.params["name"] for item in session.items
             if getattr(getattr(item, "module", None), "__name__", None) == __name__
             and "name" in getattr(getattr(item, "callspec", None), "params", {})}
    return sorted(names | {FLAGSHIP})


@pytest.fixture(scope="session")
def example_designs(request, industrial_quick):
    """Every example the selected tests read designed once (its sign-off, no recommendation),
    in this process (a pool's workers cost more CPU than they save: they import the design's
    modules again and send the results back); the flagship with its sensitivity study, which
    the validation section shows; industrial_axis with fewer scatter samples (conftest's
    ``INDUSTRIAL_ROBUSTNESS``)."""
    return {n: _design(n, n == FLAGSHIP, industrial_quick)
            for n in _selected_examples(request.session)}


class _Text(HTMLParser):
    """The text of an HTML report as a reader sees it: one line per block, no CSS or SVG."""

    BLOCKS = {"p", "li", "tr", "h1", "h2", "h3", "div", "caption", "figcaption", "dt", "dd",
              "table", "ul", "ol", "br"}

    def __init__(self) -> None:
        super().__init__()
        self.parts: list[str] = []
        self.skip = 0

    def handle_starttag(self, tag, attrs):
        if tag in ("style", "script", "svg"):
            self.skip += 1
        if tag in self.BLOCKS:
            self.parts.append("\n")
        if tag in ("td", "th"):
            self.parts.append(" | ")

    def handle_endtag(self, tag):
        if tag in ("style", "script", "svg"):
            self.skip -= 1
        if tag in ("span",):
            self.parts.append(" ")

    def handle_data(self, data):
        if not self.skip:
            self.parts.append(data)


def html_text(html: str) -> str:
    p = _Text()
    p.feed(html)
    text = "".join(p.parts).replace("\xa0", " ")
    return re.sub(r"\n\s*\n+", "\n", re.sub(r"[ \t]+", " ", text))


def console_text(result, width: int = 400) -> str:
    """The console summary, wide enough that no sentence wraps (test_console reads 80 columns)."""
    from rich.console import Console

    from fi_design.console import print_design

    c = Console(record=True, width=width, file=io.StringIO(), color_system=None)
    print_design(c, result)
    return c.export_text()


@pytest.fixture(scope="session")
def documents(example_designs):
    """Per example: the console summary, the JSON (text and data) and the HTML report's text."""
    from fi_design.report import build_context
    from fi_design.report.render import render_html

    out = {}
    for name, r in example_designs.items():
        html = render_html(build_context(r, date=DATE, figures=False))
        data = json.loads(json.dumps(r.to_dict(), allow_nan=False))
        out[name] = {"console": console_text(r).replace("\xa0", " "),
                     "json": json.dumps(data, ensure_ascii=False).replace("\xa0", " "),
                     "data": data, "html": html_text(html), "raw_html": html}
    return out


def pdf_text(html: str, tmp_path) -> str:
    from fi_design.report.render import write_document

    pdf = write_document(html, tmp_path / "report.pdf")
    out = subprocess.run(["pdftotext", "-layout", str(pdf), "-"], capture_output=True,
                         text=True, check=True)
    # pdftotext breaks lines where the page does: join them for sentences
    return re.sub(r"\s+", " ", out.stdout.replace("\xa0", " "))


def texts(doc: dict) -> dict[str, str]:
    return {k: doc[k] for k in ("console", "json", "html")}


def section(text: str, title: str) -> str:
    """One numbered section of a report's text (``7 Validation`` to the next heading)."""
    m = re.search(rf"^\d+ {re.escape(title)}$", text, flags=re.M)
    assert m, f"no section {title!r}"
    rest = text[m.end():]
    nxt = re.search(r"^\d+ [A-Z][^\n|]*$", rest, flags=re.M)
    return rest[:nxt.start()] if nxt else rest


# --------------------------------------------------------------------------- reading them

#: A number as the documents print it: 18.5, 1.37 × 10⁶, 13333, -0.278, 6.21.
NUM = r"[-−]?\d+(?:\.\d+)?(?:\s?×\s?10[⁻⁰¹²³⁴⁵⁶⁷⁸⁹]+)?"
UNIT = r"(?:µm|mm|m|N/m|N|Hz|%|s|kg)"
_SUP = str.maketrans("⁻⁰¹²³⁴⁵⁶⁷⁸⁹", "-0123456789")
_SCALE = {"µm": 1e-6, "mm": 1e-3, "m": 1.0, "N/m": 1.0, "N": 1.0, "Hz": 1.0, "%": 0.01,
          "s": 1.0, "kg": 1.0}


def si(number: str, unit: str) -> float:
    """A printed number with its unit, in SI (``"18.5", "µm"`` -> 1.85e-5)."""
    t = number.replace("−", "-").replace(" ", "")
    if "×10" in t:
        mant, exp = t.split("×10")
        x = float(mant) * 10.0 ** int(exp.translate(_SUP))
    else:
        x = float(t)
    return x * _SCALE[unit]


def sig(x: float, digits: int = 3) -> float:
    return float(f"{x:.{digits - 1}e}")


#: Two printed values of one quantity agree when they differ by less than the rounding of
#: the coarser print (three significant digits) [-].
AGREE = 6e-3


def distinct(values) -> list[float]:
    """The values that differ beyond printing precision (:data:`AGREE`)."""
    out: list[float] = []
    for v in sorted(values):
        if not out or abs(v - out[-1]) > AGREE * max(abs(v), abs(out[-1])):
            out.append(v)
    return out


def formula_values(text: str) -> dict[str, set[float]]:
    """``formula = value unit`` statements by formula, for formulas with an operator
    (``(Fs + |offset|) / kp``, ``Fs / stroke``, ``k_max / 2``) and ``k_max``, ``Fs``."""
    term = r"(?:\([^()=]*\)|[A-Za-z_][\w|]*)"
    pattern = re.compile(rf"({term}(?: [/+] {term})+|k_max|\bFs\b|Fs - Fc|Fs − Fc)\s=\s({NUM})"
                         rf"\s?({UNIT})(?![\w/])")
    found: dict[str, set[float]] = {}
    for m in pattern.finditer(text.replace("\xa0", " ")):
        key = re.sub(r"\s+", " ", m.group(1).replace("−", "-"))
        found.setdefault(key, set()).add(si(m.group(2), m.group(3)))
    return found


def sentences(text: str) -> list[str]:
    return [s for s in re.split(r"(?<=[.;:])\s+|\n", text) if s.strip()]


#: Console rows that state an outcome, one cell per plant.
OUTCOME_ROWS = ("Stage, after every move", "Spec's motion: outcome", "Cross-check")


def stated_outcomes(doc: dict) -> dict[str, set[str]]:
    """The outcome words the documents state where they state an outcome: the console's
    outcome rows and the HTML's badges (the verdict stamp and the plants' tables)."""
    console = set()
    for line in doc["console"].splitlines():
        if line.strip().startswith(OUTCOME_ROWS):
            console.update(re.findall(r"\b(settles|settled|hunts|hunting|stuck|static error|"
                                      r"undetermined)\b", line.split("  ", 1)[-1]))
    html = set(re.findall(r'class="(?:badge|verdict-stamp)[^"]*">([^<]*)<', doc["raw_html"]))
    return {"console": console, "html": {w.strip() for w in html}}


def judged_outcomes(data: dict) -> set[str]:
    """Every outcome the JSON judges: the plants' stage-level answers and their moves, the
    spec's motion per plant and its cross-check."""
    out = set()
    for st in (data.get("stage_hunting") or {}).values():
        out.add(st["outcome"])
        out.update(m["outcome"] for m in st["moves"])
    sim = data.get("simulation") or {}
    for key in ("isolated", "non_isolated"):
        if key in sim:
            out.add(sim[key]["outcome"])
            out.add((sim.get("cross_check") or {}).get(key, {}).get("outcome"))
    return out


#: Phrases that advise changing the hardware.
ADVICE = re.compile(r"(?<!no )(?<!no friction )\bisolator (?:is|looks) (?:recommended|needed)|"
                    r"\bstart from\b|"
                    r"\brevise the design\b|\bBuild an?\b|\bis a start\b", re.IGNORECASE)


# --------------------------------------------------------------------------- the tests


@pytest.mark.parametrize("name", EXAMPLE_PARAMS)
def test_a_passing_verdict_never_advises_new_hardware(documents, name):
    doc = documents[name]
    if not doc["data"]["passed"]:
        pytest.skip("the verdict does not pass: advice is expected")
    for kind, text in texts(doc).items():
        hits = [s for s in sentences(text) if ADVICE.search(s)]
        assert not hits, (kind, hits)
    assert doc["data"]["recommendation"] is None and not doc["data"]["verdict"]["next_step"]


@pytest.mark.parametrize("name", EXAMPLE_PARAMS)
def test_one_quantity_is_stated_with_one_value(documents, name):
    doc = documents[name]
    data = doc["data"]
    for kind, text in texts(doc).items():
        for formula, values in formula_values(text).items():
            assert len(distinct(values)) == 1, (kind, formula, values)
    every = " ".join(texts(doc).values())
    # the static error bound: one formula, one value (the judged one)
    named = set(re.findall(r"\((F[sc]) \+ \|offset\|\) / kp|\bF([sc]) / kp\b", every))
    assert len(named) <= 1, named
    bound = data["pid"]["static_error"]
    for kind, text in texts(doc).items():
        for m in re.finditer(rf"static error[^.;]*?/ kp = ({NUM}) ({UNIT})", text):
            assert len(distinct([si(m.group(1), m.group(2)), bound])) == 1, (kind, m.group(0))
    # the rule's gains: one kp wherever the rule is named
    rule_kp = {si(m.group(1), "N/m")
               for text in texts(doc).values()
               for m in re.finditer(rf"rule[^.;]{{0,80}}?\bkp = ({NUM}) N/m", text)}
    assert len(distinct(rule_kp)) <= 1, rule_kp
    stages = data.get("stage_hunting") or {}
    # the hunting-free crossover and the fold's resolution: the judged values only
    folds = {sig(v["hunting_free_from"], 4) for v in stages.values()
             if v["hunting_free_from"] is not None}
    widths = {sig(v["boundary"]["resolution"], 2) for v in stages.values()
              if v.get("boundary") and v["boundary"].get("resolution")}
    for kind, text in texts(doc).items():
        for m in re.finditer(rf"hunts from ({NUM}) Hz", text):
            assert sig(si(m.group(1), "Hz"), 4) in folds, (kind, m.group(0), folds)
        for m in re.finditer(rf"bisected to ({NUM}) Hz", text):
            assert sig(si(m.group(1), "Hz"), 2) in widths, (kind, m.group(0), widths)
    # the robustness probability: the judged one, in %, wherever it is printed
    rob = data["robustness"]
    if rob is not None and rob["hunting_probability"] is not None:
        p = 100 * rob["hunting_probability"]
        for kind in ("console", "html"):
            text = doc[kind]
            for m in re.finditer(rf"does not settle[^.;]*? in ({NUM}) % of", text):
                assert sig(float(m.group(1)), 3) == sig(p, 3), (kind, m.group(0))
            row = next(ln for ln in text.splitlines()
                       if "Probability of not settling under friction scatter" in ln
                       or ln.strip().startswith("the stage as specified does not settle"))
            assert row  # printed
            assert not re.search(r"\b0\.\d+\s+≤ 0\.\d", text), "a probability as a fraction"


@pytest.mark.parametrize("name", EXAMPLE_PARAMS)
def test_stuck_only_where_a_judged_outcome_is_stuck(documents, name):
    doc = documents[name]
    outcomes = judged_outcomes(doc["data"])
    for kind, words in stated_outcomes(doc).items():
        assert words, kind     # the outcome rows and badges were found
        if "stuck" in words:
            assert "stuck" in outcomes, (kind, words, outcomes)
    for kind, text in texts(doc).items():
        assert not re.search(r"\bnot stuck\b", text, re.IGNORECASE), kind


@pytest.mark.parametrize("name", EXAMPLE_PARAMS)
def test_no_boundary_claim_for_a_plant_that_hunts_for_no_move(documents, name):
    doc = documents[name]
    stages = doc["data"].get("stage_hunting") or {}
    if any(v["moves_hunting"] for v in stages.values()):
        pytest.skip("a plant hunts: the boundary is stated for it")
    for kind, text in texts(doc).items():
        assert "hunts for some move" not in text, kind
        assert "persists up to" not in text, kind
        for s in re.split(r"(?<=[.;])\s+|\n", text):
            if "not computed" in s and "sensitivity" not in s:
                assert "integrator" in s or "not computed for" in s, (kind, s)


@pytest.mark.parametrize("name", EXAMPLE_PARAMS)
def test_no_advice_the_same_report_shows_failing(documents, name):
    doc = documents[name]
    data = doc["data"]
    sim = data.get("simulation")
    adv = data.get("isolator_advice")
    if not (sim and adv and sim["suggested_isolator"]):
        pytest.skip("no isolator simulated for comparison")
    k = adv["stiffness"]
    fails = not data["stage_hunting"]["isolated"]["acceptable"]
    shown = rf"\bk = {re.escape(f'{k:.0f}')} N/m"
    for kind, text in texts(doc).items():
        for s in sentences(text):
            if re.search(shown, s) and ADVICE.search(s):
                assert not fails, (kind, s)
    if fails:
        assert adv["needed"] is not False and "not that one" in adv["reason"]


@pytest.mark.parametrize("name", EXAMPLE_PARAMS)
def test_the_headline_counts_what_the_checks_table_counts(documents, name):
    doc = documents[name]
    data = doc["data"]
    v = data["verdict"]
    warn_checks = sum(c["status"] == "WARN" for c in data["checks"])
    m = re.search(r"(\d+) warnings? to review(?: \((.*?)\))?", v["headline"])
    findings = [f for f in v["findings"] if f["severity"] == "WARN"]
    if m is None:
        assert not findings
        return
    assert int(m.group(1)) == len(findings)
    said = re.search(r"(\d+) checks?\b", m.group(2) or "")
    assert (int(said.group(1)) if said else 0) == warn_checks, (v["headline"], warn_checks)
    # the HTML's banner counts the same checks
    banner = re.search(r"(\d+) WARN", doc["html"])
    assert banner and int(banner.group(1)) == sum(c["status"] == "WARN" for c in data["checks"])
    # never a check's internal name in the headline
    for c in data["checks"]:
        assert c["name"] not in v["headline"], c["name"]


@pytest.mark.parametrize("name", EXAMPLE_PARAMS)
def test_statuses_are_enums_and_printed_alike(example_designs, documents, name):
    from fi_design.results import Status
    from fi_design.results.design import VerdictStatus

    r = example_designs[name]
    assert isinstance(r.verdict.status, VerdictStatus) and isinstance(r.verdict.status,
                                                                        enum.Enum)
    assert all(isinstance(c.status, Status) for c in r.checks)
    assert f"{r.verdict.status}" == documents[name]["data"]["verdict"]["status"]
    assert f"Verdict: {r.verdict.status}" in documents[name]["console"]


@pytest.mark.parametrize("name", EXAMPLE_PARAMS)
def test_step_1_screens_and_the_stage_level_answer_decides(documents, name):
    data = documents[name]["data"]
    gap = next(c for c in data["checks"] if c["name"] == "friction_gap")
    assert gap["status"] == "INFO"
    own = "isolated" if data["verdict"]["plant"] == "isolated" else "non_isolated"
    outcome = data["stage_hunting"][own]["outcome"]
    words = {"hunts": "hunts", "settles": "comes to rest", "static_error": "static error",
             "stuck": "sticks", "undetermined": "cannot be judged"}[outcome]
    assert "paper's rule" in gap["message"] and words in gap["message"], gap["message"]


def test_step_1_below_its_threshold_beside_a_hunting_stage_is_no_pass():
    """Canudas de Wit et al. (1995): Fs - Fc = 0.5 N, below the 1 N threshold, and a 127.8 mm
    cycle. Step 1 must not read as a pass the simulation refutes."""
    from fi_design.model import resolve
    from fi_design.guideline.steps import friction_gap_judged, step1_friction_gap
    from fi_design.stage import stage_hunting

    from published import canudas_spec

    spec = canudas_spec()
    before = step1_friction_gap(resolve(spec))
    assert before.checks[0].status.value == "PASS"      # the rule alone
    st = stage_hunting(spec, False, family=[1.0], boundary=False)
    after = friction_gap_judged(before, st, True)
    c = after.checks[0]
    assert c.status.value == "INFO" and c.passed is None
    assert "below the 1 N threshold" in c.message and "hunts" in c.message
    assert after.gap == before.gap


@pytest.mark.parametrize("name", EXAMPLE_PARAMS)
def test_terms_printed_are_defined(documents, name):
    doc = documents[name]
    glossary = section(doc["html"], "Glossary")
    body = doc["html"].replace(glossary, "")
    for term, pattern in (("fold", r"\bfold\b"), ("Floquet multiplier", r"Floquet"),
                          ("limit case", r"limit case"), ("landing", r"\blands\b")):
        if re.search(pattern, body):
            assert re.search(rf"^ *{re.escape(term)}$", glossary, re.M), term
        if re.search(pattern, doc["console"]) and term in ("fold", "Floquet multiplier",
                                                           "limit case", "landing"):
            assert re.search(rf"^\s+{re.escape(term)}: ", doc["console"], re.M), term


def test_a_failing_headline_names_steps_not_check_ids(paper_spec):
    """A design failing its margins (no simulation needed): the headline names the step."""
    from fi_design.guideline.evaluate import evaluate as design

    from conftest import variant

    r = design(variant(paper_spec, **{"requirements.phase_margin": "80 deg"}), confirm=False)
    assert r.verdict.status == "FAIL"
    h = r.verdict.headline
    assert "step 2 (the crossover and the loop's margins)" in h, h
    for c in r.checks:
        assert c.name not in h, (c.name, h)


@pytest.mark.parametrize("name", EXAMPLE_PARAMS)
def test_the_assumptions_describe_the_method_that_ran(documents, example_designs, name):
    text = section(documents[name]["html"], "Assumptions and limitations")
    r = example_designs[name]
    h = r.spec.requirements.hunting
    for stale in ("peaks above +", "within one scan step", "the verdict then says"):
        assert stale not in text, stale
    assert "no sensor noise" in text and "no actuator dynamics" in text
    assert f"{h.horizon:g} s after the motion" in text
    if r.model.has_isolator:
        assert "k_stop = " in text and "c_stop = " in text
    if r.flexure is not None:
        assert "Gravity is modelled on the leaf-spring guide" in text
    if r.robustness is not None:       # what the scatter varies, and what it does not
        assert "the gap Fs \u2212 Fc" in text and "stay nominal" in text


@pytest.mark.parametrize("name", EXAMPLE_PARAMS)
def test_the_validation_section_states_the_registry(documents, example_designs, name):
    from fi_design.report.validation import VALIDATIONS

    text = section(documents[name]["html"], "Validation")
    for v in VALIDATIONS:
        assert v.test in text
    r = example_designs[name]
    if r.sensitivity is not None:
        lo, hi = r.sensitivity.span()
        assert "÷ 3" in text and "× 3" in text and "between" in text
        assert f"{r.sensitivity.nominal:.4g}" in text
    else:
        assert "not computed" in text


def test_every_validation_names_a_test_that_asserts_what_it_states(repo_root):
    """The registry says no more than the tests show: each named test exists and its source
    holds the tolerances and figures the fact states."""
    import ast

    from fi_design.report.validation import VALIDATIONS

    for v in VALIDATIONS:
        path, _, func = v.test.partition("::")
        tree = ast.parse((repo_root / path).read_text(encoding="utf-8"))
        node = next((n for n in tree.body if isinstance(n, ast.FunctionDef) and n.name == func),
                    None)
        assert node is not None, v.test
        source = ast.get_source_segment((repo_root / path).read_text(encoding="utf-8"), node)
        for fragment in v.asserts:
            assert fragment in source, (v.test, fragment)


@needs_poppler
def test_the_flagship_pdf_reads_as_its_html(documents, tmp_path):
    doc = documents[FLAGSHIP]
    text = pdf_text(doc["raw_html"], tmp_path)
    for formula, values in formula_values(text).items():
        assert len(distinct(values)) == 1, (formula, values)
    assert doc["data"]["verdict"]["headline"][:60] in text
    assert "Glossary" in text and "Validation" in text


@pytest.mark.slow
@needs_poppler
@pytest.mark.parametrize("name", EXAMPLE_PARAMS)
def test_every_pdf_states_one_value_per_quantity(documents, name, tmp_path):
    doc = documents[name]
    text = pdf_text(doc["raw_html"], tmp_path)
    for formula, values in formula_values(text).items():
        assert len(distinct(values)) == 1, (formula, values)
    if doc["data"]["passed"]:
        assert not [s for s in sentences(text) if ADVICE.search(s)]
    assert not re.search(r"\bnot stuck\b", text, re.IGNORECASE)


def test_the_docs_quote_a_fresh_run(example_designs, repo_root):
    """docs/commands.md and docs/library.md quote the paper setup's sign-off: its robustness
    (they said 6 % where a run gives 91 %), the end-stop clearance, the guide's stiffness
    range, the moves that hunt and the hunting-free crossover are this run's."""
    r = example_designs["paper_setup"]
    commands = re.sub(r"\s+", " ", (repo_root / "docs" / "commands.md").read_text("utf-8"))
    library = re.sub(r"\s+", " ", (repo_root / "docs" / "library.md").read_text("utf-8"))
    rob = r.robustness
    m = re.search(rf"does not settle in ({NUM}) % of the (\d+) default samples \(({NUM}) % to "
                  rf"({NUM}) %\)", commands)
    assert m, "the robustness figure is not quoted"
    assert int(m.group(2)) == rob.samples
    for said, got in zip((m.group(1), m.group(3), m.group(4)),
                         (rob.hunting_probability, *rob.interval)):
        assert len(distinct([float(said), 100 * got])) == 1, (said, got)
    st = r.simulation.stage["isolated"]
    m = re.search(r"hunts for (\d+) of its (\d+) moves", commands)
    assert m and (int(m.group(1)), int(m.group(2))) == (len(st.hunting_moves), len(st.moves))
    m = re.search(rf"rests ({NUM}) µm from its end stop", commands)
    assert m and len(distinct([si(m.group(1), "µm"), r.margins.end_stop_clearance])) == 1
    m = re.search(rf"leaves are ({NUM}) mm, ({NUM}) to ({NUM}) N/m", commands)
    assert m
    assert len(distinct([si(m.group(1), "mm"), r.margins.thickness])) == 1
    for said, got in zip(m.groups()[1:], r.margins.stiffness_range):
        assert len(distinct([float(said), got])) == 1, (said, got)
    m = re.search(rf"`margins.hunting_free_crossover`, ({NUM}) Hz", library)
    assert m and len(distinct([float(m.group(1)), r.margins.hunting_free_crossover])) == 1


def test_the_docs_name_the_one_static_error_bound(repo_root):
    """The bound was stated as Fc / kp, (Fc + |offset|) / kp and (Fs + |offset|) / kp."""
    from fi_design.results.stage import STATIC_ERROR_FORMULA

    for page in [repo_root / "README.md", *sorted((repo_root / "docs").glob("*.md"))]:
        text = page.read_text(encoding="utf-8")
        for m in re.finditer(r"\(F[sc] \+ \|offset\|\) / kp|\bF[sc] / kp\b", text):
            assert m.group(0) == STATIC_ERROR_FORMULA, (page.name, m.group(0))


@pytest.mark.slow
def test_a_failing_design_with_its_recommendation_reads_as_one():
    """With the design search on (the default), the advice box and the conclusion agree:
    the conclusion never advises the rule's isolator the report shows hunting, and the
    recommendation is the search's design (a minute on two cores)."""
    from fi_design.signoff import design
    from fi_design.spec.file import load_spec

    r = design(load_spec(EXAMPLES / "no_isolator.yaml"))
    rec = r.recommendation
    assert r.verdict.status == "FAIL" and rec is not None
    assert "not that one" in r.isolator_advice.reason and "start from" not in r.conclusion
    doc = console_text(r)
    assert rec.text in doc.replace("\n", " ") or rec.text[:40] in doc
    if rec.feasible:
        from fi_design.spec.paths import with_values

        values = {"isolator": {k: v for k, v in rec.isolator.items() if v is not None}}
        if rec.crossover is not None:
            values["controller.crossover"] = rec.crossover
        again = design(with_values(r.spec, values), recommend=False)
        assert again.simulation.stage["isolated"].acceptable
