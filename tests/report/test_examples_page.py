"""docs/examples.md: the examples' stage-level table and figures, written by docs/make_examples_page.py."""

from __future__ import annotations

import re
import subprocess
import sys

import pytest

from conftest import EXAMPLES, ROOT

PAGE = ROOT / "docs" / "examples.md"
SCRIPT = ROOT / "docs" / "make_examples_page.py"


def test_the_page_has_a_row_for_every_example_and_its_figures_exist():
    text = PAGE.read_text(encoding="utf-8")
    block = text.split("stage-table:begin", 1)[1].split("<!-- stage-table:end -->", 1)[0]
    named = set(re.findall(r"^\| `([\w-]+)` \|", block, flags=re.M))
    assert named == {p.stem for p in EXAMPLES.glob("*.yaml")}
    figures = re.findall(r"\]\((figures/[\w.-]+\.png)\)", text)
    assert len(figures) >= 4
    for fig in figures:
        path = PAGE.parent / fig
        assert path.is_file() and path.stat().st_size > 10_000, fig


@pytest.mark.slow
def test_the_table_is_what_the_code_gives():
    """Reruns the sign-off of every example (minutes) and compares the table."""
    p = subprocess.run([sys.executable, str(SCRIPT), "--check"], capture_output=True, text=True,
                       timeout=3600, cwd=ROOT)
    assert p.returncode == 0, p.stderr[-2000:]


def test_the_readme_quotes_the_page():
    """The README's short table of the examples gives the page's recommended designs and
    hunting-free crossovers (the page is written by the code; the README copies it)."""
    text = PAGE.read_text(encoding="utf-8")
    block = text.split("stage-table:begin", 1)[1].split("<!-- stage-table:end -->", 1)[0]
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    designs = re.findall(r"\| (stroke [\d.]+ mm, [\d.]+ N/m), ([\d.]+ Hz) \|", block)
    assert len(designs) >= 3
    for design, crossover in designs:
        assert f"{design} at {crossover} passes" in readme, (design, crossover)
    paper = next(ln for ln in block.splitlines() if ln.startswith("| `paper_setup`"))
    cells = [c.strip() for c in paper.split("|")]
    assert f"| {cells[7]} Hz |" in readme  # the isolated paper stage's hunting-free crossover
