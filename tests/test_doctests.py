"""Every docstring example (``>>>``) in fi_design runs and prints what it shows.

The examples read files by paths relative to the repository (``examples/paper_setup.yaml``),
as a reader runs them from a clone's root; the tests run them from there.
"""

from __future__ import annotations

import doctest
import importlib
import io

import pytest

from conftest import ROOT

#: The source of every module of fi_design that holds a docstring example, by dotted name.
SOURCES = {".".join(p.relative_to(ROOT).with_suffix("").parts).removesuffix(".__init__"): text
           for p in sorted((ROOT / "fi_design").rglob("*.py"))
           if ">>>" in (text := p.read_text(encoding="utf-8"))}
MODULES = sorted(SOURCES)

#: Modules whose examples another test runs, and which.
ELSEWHERE = {"fi_design.display": "tests/report/test_display.py::test_doctests"}


def _run(name: str, *, lift_skip: bool = False) -> tuple[int, int, int, str]:
    """Run the examples of module ``name`` from the repository root: examples run, examples
    left out (``# doctest: +SKIP``, unless ``lift_skip``), failures and the failure report."""
    module = importlib.import_module(name)
    out = io.StringIO()
    runner = doctest.DocTestRunner(verbose=False)
    skipped = 0
    for test in doctest.DocTestFinder().find(module):
        for example in test.examples:
            if lift_skip:
                example.options.pop(doctest.SKIP, None)
            skipped += bool(example.options.get(doctest.SKIP))
        runner.run(test, out=out.write)
    return runner.tries, skipped, runner.failures, out.getvalue()


def test_the_modules_with_examples_are_found():
    assert "fi_design.model" in MODULES and "fi_design.spec.paths" in MODULES
    assert set(ELSEWHERE) <= set(MODULES)


@pytest.mark.parametrize("name", [m for m in MODULES if m not in ELSEWHERE])
def test_docstring_examples_run(name, monkeypatch):
    """Only fi_design.display's examples ran; the others (resolve, with_values, identify,
    the mechanism's formulas) could print something else than they show, and one did
    (stock_thicknesses: numpy 2 shows np.float64(0.15) for 0.15). Every example the module's
    source holds is found, and runs unless marked +SKIP (run by the slow test below)."""
    monkeypatch.chdir(ROOT)
    tried, skipped, failed, report = _run(name)
    written = sum(line.lstrip().startswith(">>>") for line in SOURCES[name].splitlines())
    assert failed == 0, report
    assert tried > 0 and tried + skipped == written, \
        f"{name}: {written} examples written, {tried} run and {skipped} skipped"


@pytest.mark.slow
@pytest.mark.parametrize("name", [m for m in MODULES if "doctest: +SKIP" in SOURCES[m]])
def test_skipped_docstring_examples_run(name, monkeypatch):
    """The examples marked +SKIP for their run time (reconcile: about 15 s) run here."""
    monkeypatch.chdir(ROOT)
    tried, _, failed, report = _run(name, lift_skip=True)
    assert failed == 0, report
